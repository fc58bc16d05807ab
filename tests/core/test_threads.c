/* test_threads.c — the library from many threads at once (issue 35 item 3, issue 36 item 6).
 *
 * Eight threads start together; each copies a different shipped scene (with its table file, for
 * the rotor) into a folder of its own, so that every load reads files no thread has read before,
 * then loads it (fmb_load, on fmb_builtin_registry(), which no thread has asked for yet: the
 * threads race for its first use), runs it with fmb_run to a CSV, steps it with fmb_advance to
 * every output time writing the rows through fmb_write_table, and asks fmb_run to write onto its
 * own scene (refused: a model guards the files it read, without any process-wide list). The same
 * work is then done by one thread, scene after scene, into other folders. Every CSV must hold the
 * same bytes both ways (and the stepped one the same bytes as fmb_run's).
 *
 * On the tree before this test, the load path noted every file read in one unlocked process-wide
 * list (engine/safe_file.c) and made the built-in registry lazily without a lock: four threads
 * loading new scene files aborted or crashed 7 runs in 8. tools/tsan.sh runs this test under
 * ThreadSanitizer (CI's robustness step), which reports any such race even when the run survives.
 *
 * Then NMODES threads compute the sparse modes (ARPACK) of one rotating beam's steady state at
 * once, twice each, and every result must hold the bytes one thread computed first. ARPACK keeps
 * the state of a computation in Fortran SAVE variables and drew its start vector from a seed it
 * kept between calls: on the tree before, a second computation in one process differed at
 * roundoff, and threads ran on each other's state (engine/modes.c now gives the start vector and
 * serialises the computation). */
#include <errno.h>
#include <pthread.h>
#include <stdlib.h>
#include <string.h>
#include <sys/stat.h>

#include "testlib.h"

#define NJOB 8

typedef struct {
  const char* scene; /* under scenes/ */
  const char* table; /* a table file the scene reads, copied beside it, or NULL */
  const char* t_end; /* short runs: the test is about sharing, not about long integrations */
} Case;

static const Case cases[NJOB] = {
    {"pendulum.yaml", NULL, "solver.t_end=1"},
    {"double_pendulum.yaml", NULL, "solver.t_end=0.5"},
    {"fourbar.yaml", NULL, "solver.t_end=0.3"},
    {"slider_crank.yaml", NULL, "solver.t_end=0.01"},
    {"rotor.yaml", "rotor_torque.csv", "solver.t_end=0.1"},
    {"spinup_bar.yaml", NULL, "solver.t_end=0.5"},
    {"parallelogram.yaml", NULL, "solver.t_end=0.4"},
    {"campbell_beam.yaml", NULL, "solver.t_end=0.05"},
};

typedef struct {
  const Case* c;
  char dir[1000];
  pthread_barrier_t* start; /* NULL: no waiting (the single-thread pass) */
  int rc_run, rc_step, refused;
  char why[2600];
} Job;

static int copy_file(const char* from, const char* to) {
  FILE* in = fopen(from, "rb");
  FILE* out = in ? fopen(to, "wb") : NULL;
  char buf[8192];
  size_t n;
  int rc = in && out ? 0 : -1;
  while (!rc && (n = fread(buf, 1, sizeof buf, in)) > 0)
    if (fwrite(buf, 1, n, out) != n) rc = -1;
  if (in) fclose(in);
  if (out && fclose(out)) rc = -1;
  return rc;
}

/* fmb_run's rows again with the stepping calls, written through fmb_write_table */
static int step_to_csv(const fmbModel* m, const char* out, char* why, size_t whylen) {
  fmbDiag diag;
  memset(&diag, 0, sizeof diag);
  fmbSolverInfo si;
  fmb_model_solver(m, &si);
  const int ncol = fmb_noutput(m) + 1;
  const int cap = (int)((si.t_end - si.t0) / si.output_step + 1e-9) + 3;
  double* values = malloc(sizeof(double) * (size_t)ncol * (size_t)cap);
  const char** names = malloc(sizeof(char*) * (size_t)ncol);
  fmbData* d = values && names ? fmb_data_new(m, &diag) : NULL;
  int rc = d ? fmb_init(m, d, &diag) : FMB_EXIT_SOLVER, nrow = 0;
  for (int c = 0; names && c < ncol; ++c) names[c] = c ? fmb_output_name(m, c - 1) : "t";
  if (!rc) {
    values[0] = fmb_data_time(d);
    fmb_outputs(m, d, values + 1);
    nrow = 1;
  }
  for (long k = 1; !rc && nrow < cap; ++k) {
    double t = si.t0 + (double)k * si.output_step;
    const int last = t >= si.t_end - 1e-9 * si.output_step;
    if (last) t = si.t_end;
    rc = fmb_advance(m, d, t, &diag);
    if (rc) break;
    values[(size_t)nrow * (size_t)ncol] = fmb_data_time(d);
    fmb_outputs(m, d, values + (size_t)nrow * (size_t)ncol + 1);
    ++nrow;
    if (last) break;
  }
  if (rc) snprintf(why, whylen, "step: %s", diag.msg);
  fmbDiag wd;
  if (!rc && fmb_write_table(out, ncol, names, nrow, values, &wd)) {
    rc = FMB_EXIT_BAD_INPUT;
    snprintf(why, whylen, "write_table: %s", wd.msg);
  }
  fmb_data_free(d);
  free(values);
  free(names);
  return rc;
}

static void* job_main(void* arg) {
  Job* j = arg;
  fmb_set_warn(NULL, NULL); /* quiet: the thread's own handler */
  char src[1200], scene[1200], csv[1200];
  if (j->start) pthread_barrier_wait(j->start);
  j->rc_run = j->rc_step = -1;
  snprintf(scene, sizeof scene, "%s/%s", j->dir, j->c->scene);
  snprintf(src, sizeof src, "%s/scenes/%s", FLEXMBD_SOURCE_DIR, j->c->scene);
  if (copy_file(src, scene)) snprintf(j->why, sizeof j->why, "cannot copy %s", src);
  if (!j->why[0] && j->c->table) {
    char tsrc[1200], tdst[1200];
    snprintf(tsrc, sizeof tsrc, "%s/scenes/%s", FLEXMBD_SOURCE_DIR, j->c->table);
    snprintf(tdst, sizeof tdst, "%s/%s", j->dir, j->c->table);
    if (copy_file(tsrc, tdst)) snprintf(j->why, sizeof j->why, "cannot copy %s", tsrc);
  }
  const char* sets[] = {j->c->t_end};
  fmbDiag diag;
  fmbModel* m = fmb_load(scene, sets, 1, fmb_builtin_registry(), &diag);
  if (!m) {
    snprintf(j->why, sizeof j->why, "load %s: %s", scene, diag.msg);
    return NULL;
  }
  snprintf(csv, sizeof csv, "%s/run.csv", j->dir);
  const fmbRunOptions opt = {.csv_path = csv, .quiet = 1};
  fmbStats st;
  j->rc_run = fmb_run(m, &opt, &st, &diag);
  if (j->rc_run) snprintf(j->why, sizeof j->why, "run: %s", diag.msg);
  snprintf(csv, sizeof csv, "%s/step.csv", j->dir);
  j->rc_step = step_to_csv(m, csv, j->why, sizeof j->why);
  /* the scene is this model's input: its run may not replace it, in whichever thread */
  const fmbRunOptions onto = {.csv_path = scene, .quiet = 1};
  j->refused = fmb_run(m, &onto, &st, &diag) == FMB_EXIT_BAD_INPUT && strstr(diag.msg, "refusing to overwrite");
  fmb_free(m);
  return NULL;
}

/* ---- sparse modes from NMODES threads at once ---- */
#define NMODES 4
#define MODES_COUNT 4

typedef struct {
  const fmbModel* m;
  double t;
  const double *y, *yp;
  pthread_barrier_t* start;
  fmbModes* md[2];
} ModesJob;

static void* modes_main(void* arg) {
  ModesJob* j = arg;
  fmbDiag diag;
  pthread_barrier_wait(j->start);
  for (int k = 0; k < 2; ++k)
    if (fmb_modes(j->m, j->t, j->y, j->yp, MODES_COUNT, FMB_EIGEN_SPARSE, &j->md[k], &diag)) j->md[k] = NULL;
  return NULL;
}

static int same_doubles(const double* a, const double* b, size_t n) {
  return (!n || (a && b)) && memcmp(a, b, n * sizeof(double)) == 0;
}

static int same_modes(const fmbModes* a, const fmbModes* b) {
  if (!a || !b || a->count != b->count || a->nq != b->nq || !a->sparse || !b->sparse || a->count < 1) return 0;
  const size_t n = (size_t)a->count, nshape = n * (size_t)a->nq;
  return same_doubles(a->frequency, b->frequency, n) && same_doubles(a->damping_ratio, b->damping_ratio, n) &&
         same_doubles(a->shape_re, b->shape_re, nshape) && same_doubles(a->shape_im, b->shape_im, nshape);
}

static void sparse_modes_together(void) {
  char path[1200];
  snprintf(path, sizeof path, "%s/scenes/campbell_beam.yaml", FLEXMBD_SOURCE_DIR);
  fmbDiag diag;
  fmbModel* m = fmb_load(path, NULL, 0, fmb_builtin_registry(), &diag);
  ENSURE(m != NULL);
  if (!m) return;
  const int n = fmb_state_size(m);
  double *y = calloc((size_t)n, sizeof(double)), *yp = calloc((size_t)n, sizeof(double));
  fmbStaticResult r;
  fmbModes* alone = NULL;
  ENSURE(y && yp && fmb_static(m, NULL, y, yp, &r, &diag) == 0);
  ENSURE(fmb_modes(m, r.t, y, yp, MODES_COUNT, FMB_EIGEN_SPARSE, &alone, &diag) == 0);
  ModesJob jobs[NMODES];
  pthread_t tid[NMODES];
  pthread_barrier_t start;
  pthread_barrier_init(&start, NULL, NMODES);
  for (int i = 0; i < NMODES; ++i) {
    jobs[i] = (ModesJob){.m = m, .t = r.t, .y = y, .yp = yp, .start = &start};
    ENSURE(pthread_create(&tid[i], NULL, modes_main, &jobs[i]) == 0);
  }
  for (int i = 0; i < NMODES; ++i) pthread_join(tid[i], NULL);
  pthread_barrier_destroy(&start);
  int same = 0;
  for (int i = 0; i < NMODES; ++i)
    for (int k = 0; k < 2; ++k) {
      same += same_modes(jobs[i].md[k], alone);
      fmb_modes_free(jobs[i].md[k]);
    }
  ENSURE(same == 2 * NMODES);
  printf("campbell_beam.yaml    sparse modes, %d threads x 2 vs 1: %d of %d identical (%d modes, first %.9g rad/s)\n",
         NMODES, same, 2 * NMODES, alone ? alone->count : 0, alone && alone->count ? alone->frequency[0] : 0.0);
  fmb_modes_free(alone);
  free(y);
  free(yp);
  fmb_free(m);
}

static void make_dir(const char* dir) {
  if (mkdir(dir, 0777) && errno != EEXIST) fprintf(stderr, "cannot make %s: %s\n", dir, strerror(errno));
}

int main(void) {
  char root[900];
  fmbt_out_path("threads", root, sizeof root);
  make_dir(root);
  Job together[NJOB], alone[NJOB];
  pthread_barrier_t start;
  pthread_barrier_init(&start, NULL, NJOB);
  pthread_t tid[NJOB];
  /* all at once first, so that the threads are the first to ask for the built-in registry */
  for (int i = 0; i < NJOB; ++i) {
    together[i] = (Job){.c = &cases[i], .start = &start};
    snprintf(together[i].dir, sizeof together[i].dir, "%s/together%d", root, i);
    make_dir(together[i].dir);
    ENSURE(pthread_create(&tid[i], NULL, job_main, &together[i]) == 0);
  }
  for (int i = 0; i < NJOB; ++i) pthread_join(tid[i], NULL);
  pthread_barrier_destroy(&start);
  for (int i = 0; i < NJOB; ++i) {
    alone[i] = (Job){.c = &cases[i]};
    snprintf(alone[i].dir, sizeof alone[i].dir, "%s/alone%d", root, i);
    make_dir(alone[i].dir);
    job_main(&alone[i]);
  }
  for (int i = 0; i < NJOB; ++i) {
    const Job *a = &together[i], *b = &alone[i];
    ENSURE(a->rc_run == 0 && a->rc_step == 0 && b->rc_run == 0 && b->rc_step == 0);
    ENSURE(a->refused && b->refused);
    int same = 1;
    size_t rows = 0, bytes = 0;
    const char* files[] = {"run.csv", "step.csv"};
    char* first = NULL;
    for (int f = 0; f < 2; ++f) {
      char pa[1200], pb[1200];
      snprintf(pa, sizeof pa, "%s/%s", a->dir, files[f]);
      snprintf(pb, sizeof pb, "%s/%s", b->dir, files[f]);
      size_t na, nb;
      char* xa = fmbt_slurp(pa, &na);
      char* xb = fmbt_slurp(pb, &nb);
      ENSURE(xa && xb && na > 0);
      if (!xa || !xb || na != nb || memcmp(xa, xb, na) != 0) same = 0;
      /* the stepped rows are fmb_run's rows */
      if (f == 0) {
        first = xa;
        bytes = na;
        for (size_t k = 0; xa && k < na; ++k) rows += xa[k] == '\n';
      } else if (!first || !xa || strcmp(first, xa) != 0) {
        same = 0;
      }
      if (f == 1) free(xa);
      free(xb);
    }
    free(first);
    ENSURE(same);
    printf("%-20s 8 threads vs 1: %s (%zu lines, %zu bytes; stepped = run: %s; own scene refused: %s)%s%s%s%s\n",
           cases[i].scene, same ? "identical" : "DIFFER", rows, bytes, same ? "yes" : "no",
           a->refused && b->refused ? "yes" : "no", a->why[0] ? " together: " : "", a->why, b->why[0] ? " alone: " : "",
           b->why);
  }
  sparse_modes_together();
  return fmbt_finish("test_threads");
}
