/* test_step.c — the stepping API (flexmbd.h "Stepping", issue 24) against fmb_run.
 * (solver.singular_scan: off: formulation auto without its scan for singular configurations,
 * engine/singular.c, so that IDA meets the flat parallelogram and the advance switches there.)
 *
 * 1. For every shipped scene (scenes/ and its folders, found on disk so a new scene is covered
 *    without editing this file) and for runs that take the driver's other paths (formulation: auto
 *    leaving IDA at a flat parallelogram, ggl failing there with exit 3, radau5), a program that calls fmb_init, then fmb_advance to
 *    each output time and fmb_outputs, and writes its rows through the public fmb_write_table,
 *    produces the very bytes of fmb_run's CSV, the same exit code and the same counters.
 * 2. Two models loaded and advanced at once in two threads, and two data objects of one model in
 *    two more, give the values one thread gives (nothing shared between runs: the quadrature
 *    table, the warn handler, the quarantine; the model only read).
 * 3. One data object run twice (fmb_init again = restart) gives the same values both times.
 * 4. Messages go where they are sent: a load-time warning to the thread's default handler, a run's
 *    notes to its own handler (fmb_data_set_warn) and not the default, nothing anywhere after
 *    fmb_set_warn(NULL, NULL). */
#include <glob.h>
#include <math.h>
#include <pthread.h>
#include <stdlib.h>
#include <string.h>

#include "testlib.h"

typedef struct {
  int ncol, nrow, cap;
  double* values; /* row-major, t first */
  int rc;
  int time_wrong; /* an advance ended elsewhere than asked (counted here: threads call step_run) */
  fmbStats stats;
  char why[1024];
} Table;

/* fmb_run's loop written with the public calls only: every output time t0 + k output_step (the
   last one t_end), the values at each; stops where fmb_run stops (an advance failing, a value not
   finite) */
static void step_run(const fmbModel* m, Table* tab) {
  memset(tab, 0, sizeof *tab);
  fmbDiag diag;
  fmbSolverInfo si;
  fmb_model_solver(m, &si);
  tab->ncol = fmb_noutput(m) + 1;
  fmbData* d = fmb_data_new(m, &diag);
  if (!d) {
    tab->rc = diag.code;
    return;
  }
  tab->rc = fmb_init(m, d, &diag);
  const long nrow = fmb_row_count(m);
  for (long k = 0; !tab->rc && k < nrow; ++k) {
    if (k > 0) {
      const double tout = fmb_row_time(m, k);
      if ((tab->rc = fmb_advance(m, d, tout, &diag))) break;
      tab->time_wrong += fmb_data_time(d) != tout;
    }
    if (tab->nrow == tab->cap) {
      tab->cap = tab->cap ? 2 * tab->cap : 256;
      tab->values = realloc(tab->values, sizeof(double) * (size_t)tab->cap * (size_t)tab->ncol);
    }
    double* row = tab->values + (size_t)tab->nrow * (size_t)tab->ncol;
    row[0] = fmb_data_time(d);
    if (fmb_outputs(m, d, row + 1)) { /* fmb_run: "an output is not finite", no row */
      tab->rc = FMB_EXIT_SOLVER;
      break;
    }
    tab->nrow++;
  }
  snprintf(tab->why, sizeof tab->why, "%s", diag.msg);
  fmb_data_stats(d, &tab->stats);
  fmb_data_free(d);
}

/* fmb_run_rows' callback: the row appended to the table; stops after `stop_after` rows (0: never) */
typedef struct {
  Table* tab;
  int stop_after;
} RowSink;

static int take_row(void* user, double t, const double* values, int n) {
  RowSink* sink = user;
  Table* tab = sink->tab;
  if (n != tab->ncol - 1) tab->time_wrong++;
  if (tab->nrow == tab->cap) {
    tab->cap = tab->cap ? 2 * tab->cap : 256;
    tab->values = realloc(tab->values, sizeof(double) * (size_t)tab->cap * (size_t)tab->ncol);
  }
  double* row = tab->values + (size_t)tab->nrow * (size_t)tab->ncol;
  row[0] = t;
  memcpy(row + 1, values, sizeof(double) * (size_t)n);
  tab->nrow++;
  return sink->stop_after && tab->nrow >= sink->stop_after;
}

/* the same run through the library's loop and a row callback (fmb_run_rows) */
static void rows_run(const fmbModel* m, Table* tab, int stop_after) {
  memset(tab, 0, sizeof *tab);
  tab->ncol = fmb_noutput(m) + 1;
  fmbDiag diag;
  fmbData* d = fmb_data_new(m, &diag);
  RowSink sink = {tab, stop_after};
  tab->rc = d ? fmb_run_rows(m, d, take_row, &sink, &diag) : diag.code;
  snprintf(tab->why, sizeof tab->why, "%s", diag.msg);
  if (d) fmb_data_stats(d, &tab->stats);
  fmb_data_free(d);
}

static int write_table(const fmbModel* m, const Table* tab, const char* path) {
  const char** names = malloc(sizeof(char*) * (size_t)tab->ncol);
  names[0] = "t";
  for (int i = 1; i < tab->ncol; ++i) names[i] = fmb_output_name(m, i - 1);
  fmbDiag diag;
  const int rc = fmb_write_table(path, tab->ncol, names, tab->nrow, tab->values, &diag);
  free(names);
  return rc;
}

/* one scene (absolute path) with overrides: fmb_run's CSV against the stepped one */
static void compare(const char* scene, const char* const* sets, int nsets, const char* tag, int expect_rc) {
  fmbDiag diag;
  fmbModel* m = fmb_load(scene, sets, nsets, fmb_builtin_registry(), &diag);
  ENSURE(m != NULL);
  if (!m) {
    fprintf(stderr, "%s: %s\n", scene, diag.msg);
    return;
  }
  char run_csv[1024], step_csv[1024], name[300];
  snprintf(name, sizeof name, "step-%s-run.csv", tag);
  fmbt_out_path(name, run_csv, sizeof run_csv);
  snprintf(name, sizeof name, "step-%s-step.csv", tag);
  fmbt_out_path(name, step_csv, sizeof step_csv);
  fmbStats rs;
  fmbRunOptions opt = {.csv_path = run_csv, .quiet = 1};
  const int rrc = fmb_run(m, &opt, &rs, &diag);
  Table tab;
  step_run(m, &tab);
  ENSURE(write_table(m, &tab, step_csv) == 0);
  size_t na = 0, nb = 0;
  char* a = fmbt_slurp(run_csv, &na);
  char* b = fmbt_slurp(step_csv, &nb);
  const int same = a && b && na == nb && memcmp(a, b, na) == 0;
  ENSURE(same);
  /* and through fmb_run_rows: the same bytes, the same counters */
  Table cb;
  rows_run(m, &cb, 0);
  snprintf(name, sizeof name, "step-%s-rows.csv", tag);
  fmbt_out_path(name, step_csv, sizeof step_csv);
  ENSURE(write_table(m, &cb, step_csv) == 0);
  size_t nc = 0;
  char* c = fmbt_slurp(step_csv, &nc);
  ENSURE(c && nc == na && memcmp(a, c, na) == 0);
  ENSURE(cb.rc == rrc && cb.time_wrong == 0 && cb.stats.steps == rs.steps && cb.nrow == rs.rows_written);
  free(c);
  free(cb.values);
  ENSURE(rrc == tab.rc);
  ENSURE(rrc == expect_rc);
  ENSURE(tab.time_wrong == 0);
  ENSURE(rs.rows_written == tab.nrow);
  ENSURE(rs.steps == tab.stats.steps && rs.residuals == tab.stats.residuals && rs.jacobians == tab.stats.jacobians &&
         rs.newton_iters == tab.stats.newton_iters && rs.error_test_fails == tab.stats.error_test_fails);
  ENSURE(rs.t_reached == tab.stats.t_reached);
  printf("%-44s %s: %ld rows, %zu bytes, exit %d/%d, %ld/%ld steps%s%s\n", tag, same ? "identical" : "DIFFER",
         rs.rows_written, na, rrc, tab.rc, rs.steps, tab.stats.steps, tab.rc ? ": " : "", tab.rc ? tab.why : "");
  free(a);
  free(b);
  free(tab.values);
  fmb_free(m);
}

typedef struct {
  const fmbModel* m; /* a model to run, or NULL: load `path` in the thread */
  const char* path;
  Table tab;
} Job;

static void* job_main(void* arg) {
  Job* j = arg;
  fmb_set_warn(NULL, NULL); /* this thread's runs say nothing */
  fmbDiag diag;
  fmbModel* own = j->m ? NULL : fmb_load(j->path, NULL, 0, fmb_builtin_registry(), &diag);
  memset(&j->tab, 0, sizeof j->tab);
  j->tab.rc = -1;
  if (j->m || own) step_run(j->m ? j->m : own, &j->tab);
  fmb_free(own);
  return NULL;
}

static int same_table(const Table* a, const Table* b) {
  return a->rc == b->rc && a->nrow == b->nrow && a->ncol == b->ncol &&
         memcmp(a->values, b->values, sizeof(double) * (size_t)a->nrow * (size_t)a->ncol) == 0;
}

typedef struct {
  int count;
  char last[600];
} Heard;

static void hear(void* user, const char* message) {
  Heard* h = user;
  h->count++;
  snprintf(h->last, sizeof h->last, "%s", message);
}

static void messages(void) {
  Heard by_default = {0, ""}, by_run = {0, ""};
  fmb_set_warn(hear, &by_default);
  char path[1024];
  FILE* f = fopen(fmbt_out_path("step-warning.yaml", path, sizeof path), "w");
  if (!f) return;
  fputs("solver: {t_end: 0.1}\nbodies: [{name: a, type: rigid, mass: 1, inertia: 1, angle: 10}]\n", f);
  fclose(f);
  fmbDiag diag;
  fmbModel* m = fmb_load(path, NULL, 0, fmb_builtin_registry(), &diag); /* angle 10: radians, or degrees? */
  ENSURE(m != NULL);
  ENSURE(by_default.count == 1 && strstr(by_default.last, "step-warning.yaml:2:") &&
         strstr(by_default.last, "warning:"));
  ENSURE(by_default.last[strlen(by_default.last) - 1] != '\n'); /* one message, no newline */
  printf("load-time warning to the thread's handler: %s\n", by_default.last);
  fmb_free(m);

  char scene[1024];
  /* no scan: IDA fails at the flat and the run says so */
  const char* sets[] = {"solver.formulation=auto", "solver.t_end=1", "solver.singular_scan=off"};
  m = fmb_load(fmbt_path("scenes/parallelogram.yaml", scene, sizeof scene), sets, 3, fmb_builtin_registry(), &diag);
  ENSURE(m != NULL);
  if (m) {
    fmbData* d = fmb_data_new(m, &diag);
    fmb_data_set_warn(d, hear, &by_run);
    by_default.count = 0;
    ENSURE(fmb_init(m, d, &diag) == 0 && fmb_advance(m, d, 1.0, &diag) == 0);
    ENSURE(by_run.count >= 1 && strstr(by_run.last, "continuing with the projected formulation"));
    ENSURE(by_default.count == 0);
    printf("the run's notes to its own handler: %d, the last: %.60s...\n", by_run.count, by_run.last);
    /* without its own handler the run's notes go to the thread's; with none set, nowhere */
    fmb_data_set_warn(d, NULL, NULL);
    ENSURE(fmb_init(m, d, &diag) == 0 && fmb_advance(m, d, 1.0, &diag) == 0);
    ENSURE(by_default.count == by_run.count);
    fmb_set_warn(NULL, NULL);
    const int before = by_default.count + by_run.count;
    ENSURE(fmb_init(m, d, &diag) == 0 && fmb_advance(m, d, 1.0, &diag) == 0);
    ENSURE(by_default.count + by_run.count == before);
    fmb_data_free(d);
    fmb_free(m);
  }
}

/* fmb_run_rows: a callback that asks to stop ends the run after its row (interrupted, the rows
   kept); misuse is refused with a message; the row grid is fmb_row_time's */
static void row_callback_contract(void) {
  char path[1024];
  fmbDiag diag;
  fmbModel* m = fmb_load(fmbt_path("scenes/pendulum.yaml", path, sizeof path), NULL, 0, fmb_builtin_registry(), &diag);
  ENSURE(m != NULL);
  if (!m) return;
  Table tab;
  rows_run(m, &tab, 3);
  ENSURE(tab.rc == FMB_EXIT_INTERRUPTED && tab.nrow == 3 && strstr(tab.why, "row function"));
  for (int k = 0; k < tab.nrow; ++k) ENSURE(tab.values[(size_t)k * (size_t)tab.ncol] == fmb_row_time(m, k));
  ENSURE(tab.stats.t_reached == fmb_row_time(m, 2) && !tab.stats.status_ok);
  free(tab.values);
  fmbData* d = fmb_data_new(m, &diag);
  ENSURE(fmb_run_rows(m, d, NULL, NULL, &diag) == FMB_EXIT_BAD_INPUT && strstr(diag.msg, "no row function"));
  ENSURE(fmb_run_rows(NULL, d, take_row, NULL, &diag) == FMB_EXIT_BAD_INPUT);
  fmb_data_free(d);
  fmbSolverInfo si;
  fmb_model_solver(m, &si);
  const long n = fmb_row_count(m);
  ENSURE(n > 2 && fmb_row_time(m, 0) == si.t0 && fmb_row_time(m, n - 1) == si.t_end);
  ENSURE(isnan(fmb_row_time(m, n)) && isnan(fmb_row_time(m, -1)) && isnan(fmb_row_time(NULL, 0)) &&
         fmb_row_count(NULL) == 0);
  printf("fmb_run_rows: stopped by its callback after 3 rows (t = %g), misuse refused; %ld rows from %g to %g\n",
         tab.stats.t_reached, n, fmb_row_time(m, 0), fmb_row_time(m, n - 1));
  fmb_free(m);
}

int main(void) {
  row_callback_contract();
  char pattern[1024];
  int nscenes = 0;
  const char* const levels[] = {"scenes/*.yaml", "scenes/*/*.yaml", "scenes/*/*/*.yaml"};
  for (int l = 0; l < 3; ++l) {
    glob_t g;
    if (glob(fmbt_path(levels[l], pattern, sizeof pattern), 0, NULL, &g) != 0) continue;
    for (size_t i = 0; i < g.gl_pathc; ++i) {
      const char* rel = g.gl_pathv[i] + strlen(FLEXMBD_SOURCE_DIR) + 1;
      char tag[200];
      snprintf(tag, sizeof tag, "%s", rel);
      for (char* c = tag; *c; ++c)
        if (*c == '/') *c = '_';
      compare(g.gl_pathv[i], NULL, 0, tag, 0);
      nscenes++;
    }
    globfree(&g);
  }
  ENSURE(nscenes >= 14); /* the scenes shipped when this test was written */
  printf("%d shipped scenes\n", nscenes);

  /* the driver's other paths: auto leaves IDA at the flat position (0.277 s) for the projected
     formulation, restarting from the last row; ggl stops there (rows so far, exit 3); radau5 */
  char scene[1024];
  fmbt_path("scenes/parallelogram.yaml", scene, sizeof scene);
  const char* auto_set[] = {"solver.formulation=auto"};
  compare(scene, auto_set, 1, "parallelogram-auto", 0); /* the scan finds the flat: projected from t0 */
  const char* switch_set[] = {"solver.formulation=auto", "solver.singular_scan=off"}; /* no scan: IDA's failure */
  compare(scene, switch_set, 2, "parallelogram-auto-switch", 0);                      /* at the flat, the switch */
  const char* ggl_set[] = {"solver.formulation=ggl"};
  compare(scene, ggl_set, 1, "parallelogram-ggl-fails", FMB_EXIT_SOLVER);
  fmbt_path("scenes/paper/spinup_w4.yaml", scene, sizeof scene);
  const char* radau_set[] = {"solver.integrator=radau5"};
  compare(scene, radau_set, 1, "spinup_w4-radau5", 0);

  /* two models loaded and run in two threads at once, and two data objects of one model in two
     more, against the same runs one after the other */
  fmbDiag diag;
  char s1[1024], s2[1024];
  fmbt_path("scenes/slider_crank.yaml", s1, sizeof s1);
  fmbt_path("scenes/exact/spinup_w15_exact.yaml", s2, sizeof s2);
  fmbModel* m1 = fmb_load(s1, NULL, 0, fmb_builtin_registry(), &diag);
  ENSURE(m1 != NULL);
  if (m1) {
    Job alone[2] = {{NULL, s1, {0}}, {NULL, s2, {0}}};
    Job together[4] = {{NULL, s1, {0}}, {NULL, s2, {0}}, {m1, NULL, {0}}, {m1, NULL, {0}}};
    job_main(&alone[0]);
    job_main(&alone[1]);
    pthread_t th[4];
    for (int k = 0; k < 4; ++k) pthread_create(&th[k], NULL, job_main, &together[k]);
    for (int k = 0; k < 4; ++k) pthread_join(th[k], NULL);
    for (int k = 0; k < 4; ++k) {
      const Job* ref = &alone[k == 1];
      ENSURE(ref->tab.rc == 0 && ref->tab.nrow > 10 && together[k].tab.time_wrong == 0);
      ENSURE(same_table(&ref->tab, &together[k].tab));
      printf("thread %d (%s): %d rows x %d columns, %s alone\n", k, k < 2 ? "own model" : "shared model",
             together[k].tab.nrow, together[k].tab.ncol,
             same_table(&ref->tab, &together[k].tab) ? "identical to" : "DIFFERENT from");
      free(together[k].tab.values);
    }
    free(alone[0].tab.values);
    free(alone[1].tab.values);
    /* fmb_init again restarts: the same run twice on one data object */
    fmbData* d = fmb_data_new(m1, &diag);
    double first[64], second[64];
    const int n = fmb_noutput(m1);
    ENSURE(n > 0 && n <= 64);
    fmbSolverInfo si;
    fmb_model_solver(m1, &si);
    for (int pass = 0; pass < 2 && n <= 64; ++pass) {
      ENSURE(fmb_init(m1, d, &diag) == 0);
      ENSURE(fmb_data_time(d) == si.t0);
      ENSURE(fmb_advance(m1, d, 0.5 * (si.t0 + si.t_end), &diag) == 0);
      ENSURE(fmb_outputs(m1, d, pass ? second : first) == 0);
    }
    ENSURE(memcmp(first, second, sizeof(double) * (size_t)n) == 0);
    fmb_data_free(d);
  }
  fmb_free(m1);
  messages();
  return fmbt_finish("test_step");
}
