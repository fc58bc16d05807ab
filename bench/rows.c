/* rows.c — what a run's output rows cost: the scene stepped over its own output grid exactly as
 * fmb_run steps it (engine/run.c: fmb_init, then fmb_advance to every output time, no CPU clock
 * read per advance), three ways, interleaved:
 *   none    the stepping alone (fmb_init, fmb_advance; the after-row checks step.c makes anyway);
 *   values  + the row's values (fmb_outputs_eval: dense output, energies, tip outputs);
 *   csv     + the row written: the values, formatted and written by the one CSV writer into a
 *           temporary file renamed at the end (what fmb_run writes; --out names the file).
 * Each repeat runs the three once (new data objects, the model loaded once), timed in CPU time of
 * the process (CLOCK_PROCESS_CPUTIME_ID, as fmb_run's cpu_s); the medians are printed with the step
 * counts of each way, which must be equal: the outputs only read the state (the program fails
 * otherwise). The rows' share of the run is (csv - none) / csv.
 *
 *   rows SCENE.yaml [-s PATH=VALUE]... [-r REPEATS] [-o OUT.csv]
 * prints one CSV line (header with -H):
 *   scene,rows,columns,steps,cpu_none_s,cpu_values_s,cpu_csv_s,rows_s,rows_share
 * (docs/performance.md, "Row output"; bench/rows.sh runs it) */
#include <math.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>
#include <time.h>

#include "bench_cpu.h"
#include "builtin.h"
#include "data.h"

enum { WAY_NONE, WAY_VALUES, WAY_CSV, NWAY };
static const char* const way_names[NWAY] = {"none", "values", "csv"};

/* one run the given way: its CPU seconds, its steps in *steps; -1 when it failed */
static double one_run(const fmbModel* m, int way, const char* out, long* steps, long* rows) {
  fmbDiag diag;
  const double c0 = cpu_now();
  fmbData* d = fmb_data_new(m, &diag);
  if (!d) return -1.0;
  d->quiet = 1;
#ifndef FMB_ROWS_BEFORE_UNTIMED /* defined to build this against a tree older than fmbData.untimed */
  d->untimed = 1;               /* as fmb_run: no CPU clock read per advance */
#endif
  fmbCsv* csv = way == WAY_CSV ? fmb_csv_open(out, &diag) : NULL;
  int rc = fmb_init(m, d, &diag);
  if (!rc && csv && fmb_csv_header(csv, m)) rc = -1;
  const long nrow = fmb_row_count(m);
  *rows = 0;
  for (long k = 0; !rc && k < nrow; ++k) {
    if (k > 0 && (rc = fmb_advance(m, d, fmb_row_time(m, k), &diag))) break;
    if (way == WAY_VALUES && fmb_outputs_eval(m, d->w, d->t, d->y, d->yp, d->row)) rc = -1;
    if (way == WAY_CSV && fmb_csv_row(csv, m, d->w, d->t, d->y, d->yp)) rc = -1;
    ++*rows;
  }
  if (csv && fmb_csv_close(csv)) rc = -1;
  fmbStats st;
  fmb_data_stats(d, &st);
  *steps = st.steps;
  fmb_data_destroy(d);
  const double cpu = cpu_now() - c0;
  if (rc) fprintf(stderr, "rows: the run (%s) failed: %s\n", way_names[way], diag.msg);
  return rc ? -1.0 : cpu;
}

int main(int argc, char** argv) {
  const char* scene = NULL;
  const char* out = "/tmp/flexmbd-bench-rows.csv";
  const char* sets[32];
  int nset = 0, reps = 7, header = 0;
  for (int i = 1; i < argc; ++i) {
    if (strcmp(argv[i], "-s") == 0 && i + 1 < argc && nset < 32)
      sets[nset++] = argv[++i];
    else if (strcmp(argv[i], "-r") == 0 && i + 1 < argc)
      reps = atoi(argv[++i]);
    else if (strcmp(argv[i], "-o") == 0 && i + 1 < argc)
      out = argv[++i];
    else if (strcmp(argv[i], "-H") == 0)
      header = 1;
    else if (argv[i][0] != '-' && !scene)
      scene = argv[i];
    else {
      fprintf(stderr, "usage: rows SCENE.yaml [-s PATH=VALUE]... [-r REPEATS] [-o OUT.csv] [-H]\n");
      return 2;
    }
  }
  if (!scene || reps < 1 || reps > 1000) {
    fprintf(stderr, "usage: rows SCENE.yaml [-s PATH=VALUE]... [-r REPEATS (1..1000)] [-o OUT.csv] [-H]\n");
    return 2;
  }
  fmbDiag diag;
  fmbModel* m = fmb_load(scene, sets, nset, fmb_builtin_registry(), &diag);
  if (!m) {
    fprintf(stderr, "rows: %s: %s\n", scene, diag.msg);
    return 2;
  }
  double* cpu[NWAY];
  for (int w = 0; w < NWAY; ++w) cpu[w] = calloc((size_t)reps, sizeof(double));
  long steps[NWAY] = {0, 0, 0}, rows = 0;
  for (int r = 0; r < reps; ++r)
    for (int k = 0; k < NWAY; ++k) {
      const int w = (k + r) % NWAY; /* rotate the order: no way always runs first */
      long s = 0;
      if ((cpu[w][r] = one_run(m, w, out, &s, &rows)) < 0) return 3;
      if (r > 0 && s != steps[w]) {
        fprintf(stderr, "rows: %s: %ld steps, %ld in the repeat before\n", way_names[w], s, steps[w]);
        return 3;
      }
      steps[w] = s;
    }
  if (steps[WAY_VALUES] != steps[WAY_NONE] || steps[WAY_CSV] != steps[WAY_NONE]) {
    fprintf(stderr, "rows: the outputs changed the steps: %ld none, %ld values, %ld csv\n", steps[WAY_NONE],
            steps[WAY_VALUES], steps[WAY_CSV]);
    return 3;
  }
  double med[NWAY];
  for (int w = 0; w < NWAY; ++w) med[w] = median(cpu[w], reps);
  if (header) printf("scene,rows,columns,steps,cpu_none_s,cpu_values_s,cpu_csv_s,rows_s,rows_share\n");
  printf("%s,%ld,%d,%ld,%.5f,%.5f,%.5f,%.5f,%.3f\n", scene, rows, m->noutput, steps[WAY_NONE], med[WAY_NONE],
         med[WAY_VALUES], med[WAY_CSV], med[WAY_CSV] - med[WAY_NONE], (med[WAY_CSV] - med[WAY_NONE]) / med[WAY_CSV]);
  for (int w = 0; w < NWAY; ++w) free(cpu[w]);
  fmb_free(m);
  return 0;
}
