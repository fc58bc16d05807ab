/* test_analysis_data.c — statics and modes on a data object (issue 35 item 2: "fmbData owns the
 * run"; flexmbd.h fmb_static_data, fmb_modes_data; docs/api.md "Analyses on a data object").
 *
 * 1. On a rotating beam's steady state (scenes/campbell_beam.yaml: the rotating-frame terms, the
 *    sparse eigen-solver) and on the paper's pendulum under gravity (the dense one), the entries
 *    taking (model, data) give the very bytes of fmb_static and of the dense fmb_modes: state,
 *    result and every mode's frequency, damping and shape, the sparse modes too (ARPACK starts
 *    from a fixed vector, engine/modes.c: fmb_modes twice in one process gives the same bytes).
 * 2. Given a data object they make no workspace (the engine's count of fmb_workspace_new, which
 *    fmb_data_new alone calls), where fmb_static and fmb_modes make one each (so the count sees it).
 * 3. fmb_modes_data between the advances of a run on IDA (which reuses the bodies' blocks of its
 *    last fresh Jacobian for up to 50 steps) changes nothing in the run: the state and the
 *    counters at the end are those of the same run without it (with the blocks' cache not held
 *    during the analysis they are not); and its modes are fmb_modes' at the run's state.
 * 4. After fmb_static_data the data holds the equilibrium: fmb_data_time is its time, fmb_advance
 *    asks for fmb_init; misuse (NULL, no state yet) is refused with FMB_EXIT_BAD_INPUT.
 * 5. fmb_data_set_timing(d, 0) (no clock read per advance: bench/inputs.sh) leaves st.cpu_s at 0
 *    and the run's bytes as they are with the clock. With the clock, st.cpu_s counts the calls,
 *    not the caller's own work between them (0.1 s of CPU spent between the advances: st.cpu_s
 *    stays below half of it), and never exceeds the thread's CPU time since fmb_init. */
#include <stdlib.h>
#include <string.h>
#include <time.h>

#include "internal.h" /* fmb_workspace_count: the engine's, exposed to tests only */
#include "testlib.h"

/* ENSURE with a message saying which case and what differed */
#define ENSURE_MSG(cond, ...)                                       \
  do {                                                              \
    ++fmbt_checks;                                                  \
    if (!(cond)) {                                                  \
      fprintf(stderr, "%s:%d: check failed: ", __FILE__, __LINE__); \
      fprintf(stderr, __VA_ARGS__);                                 \
      fputc('\n', stderr);                                          \
      ++fmbt_failures;                                              \
    }                                                               \
  } while (0)

static int same_bytes(const double* a, const double* b, size_t n) { return memcmp(a, b, n * sizeof(double)) == 0; }

static int same_modes(const fmbModes* a, const fmbModes* b) {
  if (!a || !b || a->count != b->count || a->nq != b->nq || a->nreduced != b->nreduced || a->sparse != b->sparse ||
      memcmp(&a->speed, &b->speed, sizeof a->speed))
    return 0;
  const size_t n = (size_t)a->count, nshape = n * (size_t)a->nq;
  return same_bytes(a->frequency, b->frequency, n) && same_bytes(a->damping_ratio, b->damping_ratio, n) &&
         same_bytes(a->shape_re, b->shape_re, nshape) && same_bytes(a->shape_im, b->shape_im, nshape);
}

/* 1, 2 and 4 on one scene: `count` modes by `method` about its equilibrium */
static void static_and_modes(const char* rel, int count, int method, int expect_sparse) {
  char path[1024];
  fmbDiag diag;
  fmbModel* m = fmb_load(fmbt_path(rel, path, sizeof path), NULL, 0, fmb_builtin_registry(), &diag);
  ENSURE_MSG(m != NULL, "%s: %s", rel, diag.msg);
  if (!m) return;
  const int n = fmb_state_size(m);
  double *y_old = calloc((size_t)n, sizeof(double)), *yp_old = calloc((size_t)n, sizeof(double));
  double *y_new = calloc((size_t)n, sizeof(double)), *yp_new = calloc((size_t)n, sizeof(double));
  fmbStaticResult r_old, r_new;
  fmbModes *md_old = NULL, *md_new = NULL;

  long made = fmb_workspace_count();
  ENSURE(fmb_static(m, NULL, y_old, yp_old, &r_old, &diag) == 0);
  ENSURE_MSG(fmb_workspace_count() == made + 1, "%s: fmb_static made %ld workspaces (its data object's: 1)", rel,
             fmb_workspace_count() - made);
  made = fmb_workspace_count();
  ENSURE(fmb_modes(m, r_old.t, y_old, yp_old, count, method, &md_old, &diag) == 0);
  ENSURE(fmb_workspace_count() == made + 1);

  fmbData* d = fmb_data_new(m, &diag);
  ENSURE(d != NULL);
  if (!d) return;
  /* no state yet: modes refused, not computed about zeros */
  ENSURE(fmb_modes_data(m, d, count, method, &md_new, &diag) == FMB_EXIT_BAD_INPUT && md_new == NULL &&
         strstr(diag.msg, "no state yet"));
  made = fmb_workspace_count();
  ENSURE(fmb_static_data(m, d, NULL, &r_new, &diag) == 0);
  ENSURE(fmb_data_state(d, y_new, yp_new) == 0);
  ENSURE(fmb_modes_data(m, d, count, method, &md_new, &diag) == 0);
  ENSURE_MSG(fmb_workspace_count() == made, "%s: statics and modes on a data object made %ld workspaces", rel,
             fmb_workspace_count() - made);

  ENSURE_MSG(same_bytes(y_new, y_old, (size_t)n) && same_bytes(yp_new, yp_old, (size_t)n),
             "%s: fmb_static_data's equilibrium differs from fmb_static's", rel);
  ENSURE(memcmp(&r_new, &r_old, sizeof r_new) == 0);
  if (expect_sparse) { /* the old entry against itself: a start vector that ARPACK drew anew differed here */
    fmbModes* md_again = NULL;
    ENSURE(fmb_modes(m, r_old.t, y_old, yp_old, count, method, &md_again, &diag) == 0);
    ENSURE_MSG(same_modes(md_again, md_old), "%s: fmb_modes twice in one process gave other bytes", rel);
    fmb_modes_free(md_again);
  }
  ENSURE_MSG(same_modes(md_new, md_old), "%s: fmb_modes_data's modes differ from fmb_modes'", rel);
  ENSURE(md_new && md_new->count == count && md_new->sparse == expect_sparse);
  if (md_new)
    printf("%s: speed %g rad/s, first frequency %.9g rad/s (%s)\n", rel, md_new->speed, md_new->frequency[0],
           md_new->sparse ? "sparse" : "dense");
  ENSURE(fmb_data_time(d) == r_new.t);
  ENSURE(fmb_advance(m, d, r_new.t + 1e-3, &diag) == FMB_EXIT_BAD_INPUT && strstr(diag.msg, "fmb_init"));
  /* a run starts from the scene's initial conditions again */
  ENSURE(fmb_init(m, d, &diag) == 0);

  ENSURE(fmb_static_data(NULL, d, NULL, &r_new, &diag) == FMB_EXIT_BAD_INPUT);
  ENSURE(fmb_static_data(m, NULL, NULL, &r_new, &diag) == FMB_EXIT_BAD_INPUT);
  ENSURE(fmb_static_data(m, d, NULL, NULL, &diag) == FMB_EXIT_BAD_INPUT);
  fmbModes* md_bad = NULL; /* a refused call sets its *out to NULL: not md_new, which still holds modes */
  ENSURE(fmb_modes_data(m, NULL, count, method, &md_bad, &diag) == FMB_EXIT_BAD_INPUT && md_bad == NULL);
  fmb_modes_free(md_old);
  fmb_modes_free(md_new);
  fmb_data_free(d);
  free(y_old), free(yp_old), free(y_new), free(yp_new);
  fmb_free(m);
}

/* the paper's pendulum on IDA to t_end, stopping every `every` s (and computing its modes there,
   when asked; md: the last ones) */
static int run_pendulum(const fmbModel* m, double every, double t_end, int modes, double* y, fmbStats* st,
                        fmbModes** md) {
  fmbDiag diag;
  fmbData* d = fmb_data_new(m, &diag);
  int rc = d ? fmb_init(m, d, &diag) : -1;
  for (int k = 1; !rc && k * every <= t_end * (1 + 1e-12); ++k) {
    rc = fmb_advance(m, d, k * every, &diag);
    if (!rc && modes) {
      const long made = fmb_workspace_count();
      fmb_modes_free(*md);
      rc = fmb_modes_data(m, d, 4, FMB_EIGEN_DENSE, md, &diag);
      ENSURE(fmb_workspace_count() == made);
    }
  }
  if (!rc) rc = fmb_data_state(d, y, NULL) || fmb_data_stats(d, st);
  ENSURE_MSG(rc == 0, "the pendulum's run: %s", diag.msg);
  fmb_data_free(d);
  return rc;
}

static void modes_between_advances(void) {
  char path[1024];
  fmbDiag diag;
  const char* sets[] = {"solver.integrator=ida", "solver.t_end=0.06"};
  fmbModel* m =
      fmb_load(fmbt_path("scenes/paper/pendulum.yaml", path, sizeof path), sets, 2, fmb_builtin_registry(), &diag);
  ENSURE_MSG(m != NULL, "%s", diag.msg);
  if (!m) return;
  const int n = fmb_state_size(m);
  double *y_plain = calloc((size_t)n, sizeof(double)), *y_modes = calloc((size_t)n, sizeof(double));
  fmbStats st_plain, st_modes;
  memset(&st_plain, 0, sizeof st_plain);
  memset(&st_modes, 0, sizeof st_modes);
  fmbModes* md = NULL;
  const double every = 0.003, t_end = 0.06;
  ENSURE(run_pendulum(m, every, t_end, 0, y_plain, &st_plain, NULL) == 0);
  ENSURE(run_pendulum(m, every, t_end, 1, y_modes, &st_modes, &md) == 0);
  ENSURE(st_plain.jacobians_reused > 0); /* else the cache the analysis must leave alone is never used */
  ENSURE_MSG(same_bytes(y_modes, y_plain, (size_t)n), "modes every %g s moved the run's state at t = %g", every, t_end);
  ENSURE_MSG(st_modes.steps == st_plain.steps && st_modes.jacobians == st_plain.jacobians &&
                 st_modes.residuals == st_plain.residuals && st_modes.newton_iters == st_plain.newton_iters,
             "modes every %g s changed the run: steps %ld/%ld, jacobians %ld/%ld", every, st_modes.steps,
             st_plain.steps, st_modes.jacobians, st_plain.jacobians);
  printf("pendulum on IDA: %ld steps, %ld Jacobians (%ld with reused blocks), the same with modes every %g s\n",
         st_plain.steps, st_plain.jacobians, st_plain.jacobians_reused, every);

  /* the modes at the run's state are fmb_modes' there */
  fmbData* d = fmb_data_new(m, &diag);
  double* yp = calloc((size_t)n, sizeof(double));
  fmbModes* md_old = NULL;
  ENSURE(fmb_init(m, d, &diag) == 0);
  for (int k = 1; k * every <= t_end * (1 + 1e-12); ++k) ENSURE(fmb_advance(m, d, k * every, &diag) == 0);
  ENSURE(fmb_data_state(d, y_plain, yp) == 0);
  ENSURE(fmb_modes(m, fmb_data_time(d), y_plain, yp, 4, FMB_EIGEN_DENSE, &md_old, &diag) == 0);
  ENSURE_MSG(same_modes(md, md_old), "fmb_modes_data at a run's state differs from fmb_modes there");
  fmb_modes_free(md_old);
  fmb_modes_free(md);
  fmb_data_free(d);
  free(yp), free(y_plain), free(y_modes);
  fmb_free(m);
}

static double thread_cpu(void) {
  struct timespec ts;
  clock_gettime(CLOCK_THREAD_CPUTIME_ID, &ts);
  return (double)ts.tv_sec + 1e-9 * (double)ts.tv_nsec;
}

/* fmb_data_set_timing(d, 0): no clock read, st.cpu_s 0, the run itself the same bytes; with it,
   st.cpu_s is the calls' time, not the caller's */
static void timing_switch(void) {
  char path[1024];
  fmbDiag diag;
  const char* sets[] = {"solver.t_end=0.2"};
  fmbModel* m = fmb_load(fmbt_path("scenes/pendulum.yaml", path, sizeof path), sets, 1, fmb_builtin_registry(), &diag);
  ENSURE(m != NULL);
  if (!m) return;
  const int n = fmb_state_size(m);
  double* y[2] = {calloc((size_t)n, sizeof(double)), calloc((size_t)n, sizeof(double))};
  fmbStats st[2];
  for (int timed = 0; timed < 2; ++timed) {
    fmbData* d = fmb_data_new(m, &diag);
    fmb_data_set_timing(d, timed);
    ENSURE(fmb_init(m, d, &diag) == 0);
    for (long k = 1; k < fmb_row_count(m); ++k) ENSURE(fmb_advance(m, d, fmb_row_time(m, k), &diag) == 0);
    ENSURE(fmb_data_state(d, y[timed], NULL) == 0 && fmb_data_stats(d, &st[timed]) == 0);
    fmb_data_free(d);
  }
  ENSURE(st[0].cpu_s == 0.0 && st[1].cpu_s > 0.0);
  ENSURE(st[0].steps == st[1].steps && st[0].steps > 0 && same_bytes(y[0], y[1], (size_t)n));
  fmb_data_set_timing(NULL, 0); /* nothing */

  /* the caller's work between the advances is not the library's: 0.1 s of it in all (the run
     itself takes a few ms) */
  const long rows = fmb_row_count(m);
  const double busy_each = 0.1 / (double)rows;
  double busy = 0.0, sink = 0.0;
  fmbStats st_busy;
  const double cpu_start = thread_cpu();
  fmbData* d = fmb_data_new(m, &diag);
  ENSURE(fmb_init(m, d, &diag) == 0);
  for (long k = 1; k < rows; ++k) {
    ENSURE(fmb_advance(m, d, fmb_row_time(m, k), &diag) == 0);
    const double c0 = thread_cpu();
    for (double c = c0; c - c0 < busy_each; c = thread_cpu())
      for (int i = 0; i < 1000; ++i) sink += 1e-9 * (double)i;
    busy += thread_cpu() - c0;
  }
  ENSURE(fmb_data_stats(d, &st_busy) == 0);
  const double cpu_total = thread_cpu() - cpu_start;
  fmb_data_free(d);
  ENSURE_MSG(st_busy.cpu_s > 0.0 && st_busy.cpu_s < 0.5 * busy && st_busy.cpu_s <= cpu_total,
             "st.cpu_s = %.4f s with %.4f s of the caller's work between the advances (thread: %.4f s; the run "
             "alone: %.4f s)%s",
             st_busy.cpu_s, busy, cpu_total, st[1].cpu_s, sink < 0 ? "" : "");
  printf("timing: st.cpu_s %.4f s alone, %.4f s with %.3f s of the caller's work between the advances\n", st[1].cpu_s,
         st_busy.cpu_s, busy);
  free(y[0]), free(y[1]);
  fmb_free(m);
}

int main(void) {
  static_and_modes("scenes/campbell_beam.yaml", 4, FMB_EIGEN_AUTO, 1);
  static_and_modes("scenes/paper/pendulum.yaml", 3, FMB_EIGEN_DENSE, 0);
  modes_between_advances();
  timing_switch();
  return fmbt_finish("test_analysis_data");
}
