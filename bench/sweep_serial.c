/* sweep_serial.c — the serial in-process loop that bench/sweep.sh measures `flexmbd sweep`
 * against: one process loads and runs the scene once per line of a plan, through the library,
 * writing each run's CSV as `flexmbd run -o` does. No process start-up, no isolation.
 *   usage: bench_sweep_serial SCENE.yaml PLAN.csv OUT.csv
 * PLAN.csv is a sweep's plan.csv (`flexmbd sweep --dry-run`): index, run_id, PATH columns. */
#include <stdio.h>
#include <stdlib.h>
#include <string.h>

#include "builtin.h" /* fmb_builtin_registry: the built-in body and joint types */
#include "flexmbd.h"

#define MAXP 16

int main(int argc, char** argv) {
  if (argc != 4) {
    fprintf(stderr, "usage: bench_sweep_serial SCENE.yaml PLAN.csv OUT.csv\n");
    return 2;
  }
  FILE* f = fopen(argv[2], "r");
  if (!f) return 2;
  char header[4096], line[4096];
  char* path[MAXP];
  int np = 0;
  if (!fgets(header, sizeof header, f)) return 2;
  header[strcspn(header, "\n")] = '\0';
  char* save = NULL;
  for (char* t = strtok_r(header, ",", &save); t && np < MAXP + 2; t = strtok_r(NULL, ",", &save), ++np)
    if (np >= 2) path[np - 2] = t;
  np -= 2;
  long runs = 0, failed = 0;
  while (fgets(line, sizeof line, f)) {
    line[strcspn(line, "\n")] = '\0';
    char sets[MAXP][512];
    const char* ov[MAXP];
    char* s2 = NULL;
    int k = 0;
    for (char* t = strtok_r(line, ",", &s2); t; t = strtok_r(NULL, ",", &s2), ++k)
      if (k >= 2 && k - 2 < np)
        snprintf(sets[k - 2], sizeof sets[k - 2], "%s=%s", path[k - 2], t), ov[k - 2] = sets[k - 2];
    fmbDiag diag;
    fmbStats st;
    memset(&st, 0, sizeof st);
    fmbModel* m = fmb_load(argv[1], ov, np, fmb_builtin_registry(), &diag);
    fmbRunOptions opt = {.csv_path = argv[3], .quiet = 1};
    if (!m || fmb_run(m, &opt, &st, &diag) != 0) ++failed;
    fmb_free(m);
    ++runs;
  }
  fclose(f);
  printf("serial: %ld runs, %ld failed\n", runs, failed);
  return failed ? 3 : 0;
}
