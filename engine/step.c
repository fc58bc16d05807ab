/* step.c — the stepping API (flexmbd.h "Stepping", docs/api.md): the state of a run in an
 * fmbData, advanced by fmb_advance(m, d, t_out) as MuJoCo's mj_step(const mjModel*, mjData*).
 *
 * What every advance does, wherever the caller stops: one integrator backend (integrator.h) from
 * time() to t_out, then the checks a CSV row had (mass definiteness, a body's own validity,
 * redundant rows still holding), the work integrals, and the backend's after-row hook. The
 * `formulation: auto` switch lives here too, not in the run loop: it is part of how the state gets
 * from time() to t_out (where IDA fails at a singular configuration the advance goes on with the
 * projected formulation from the state the advance started from, so a caller never sees it half
 * done), and a program stepping by itself gets it exactly as fmb_run does.
 *
 * Output files, progress and signals are the run loop's (run.c): nothing here writes a file.
 *
 * A freed fmbData is kept in a quarantine of the last FMB_DATA_QUARANTINE freed ones before its
 * memory goes back to malloc, its magic changed: a call with a stale pointer finds FREED and
 * refuses, without reading freed memory (so AddressSanitizer accepts the test of that path), and
 * a double free is ignored. (Box2D's ids carry a generation for the same purpose; a pointer API
 * cannot, so the memory itself is held back.) */
#include <float.h>
#include <math.h>
#include <pthread.h>
#include <stdlib.h>
#include <string.h>
#include <time.h>

#include "data.h"

/* how close to rank-deficient Phi_q must be where IDA failed for `formulation: auto` to switch to
   the projected formulation: a row whose part independent of the others is below 1e-2 of the
   largest row (a parallelogram within about half a degree of flat; IDA on the GGL system gave up
   at 0.3 mrad before the flat position in scenes/parallelogram.yaml) */
#define FMB_AUTO_SWITCH_RANK_TOL 1e-2

static pthread_mutex_t quarantine_lock = PTHREAD_MUTEX_INITIALIZER;
static fmbData* quarantine[FMB_DATA_QUARANTINE];
static int quarantine_next;

static int live(const fmbData* d) { return d && d->magic == FMB_DATA_LIVE; }

/* the misuse every call on (m, d) refuses; 0 when usable */
static int misused(const fmbModel* m, const fmbData* d, const char* fn, fmbDiag* diag) {
  const char* path = m ? m->path : "";
  if (!m)
    fmb_diag_set(diag, FMB_EXIT_BAD_INPUT, path, 0, 0, "%s: no model (NULL)", fn);
  else if (!d)
    fmb_diag_set(diag, FMB_EXIT_BAD_INPUT, path, 0, 0, "%s: no data object (NULL)", fn);
  else if (d->magic == FMB_DATA_FREED)
    fmb_diag_set(diag, FMB_EXIT_BAD_INPUT, path, 0, 0, "%s: the data object was freed (fmb_data_free)", fn);
  else if (d->magic != FMB_DATA_LIVE)
    fmb_diag_set(diag, FMB_EXIT_BAD_INPUT, path, 0, 0, "%s: not a data object made by fmb_data_new", fn);
  else if (d->m != m)
    fmb_diag_set(diag, FMB_EXIT_BAD_INPUT, path, 0, 0,
                 "%s: the data object belongs to another model (fmb_data_new was given a different one)", fn);
  else
    return 0;
  return FMB_EXIT_BAD_INPUT;
}

int fmb_data_misused(const fmbModel* m, const fmbData* d, const char* fn, fmbDiag* diag) {
  return misused(m, d, fn, diag);
}

/* CPU seconds of the calling thread: two runs in two threads each count their own */
double fmb_thread_cpu_seconds(void) {
  struct timespec ts;
  if (clock_gettime(CLOCK_THREAD_CPUTIME_ID, &ts)) return (double)clock() / CLOCKS_PER_SEC;
  return (double)ts.tv_sec + 1e-9 * (double)ts.tv_nsec;
}

/* How fmb_data_stats' cpu_s is kept (docs/api.md "What a controller in the loop costs"). The thread's CPU clock is a system
   call, and on a virtual machine a slow one (1-10 us on the KVM of docs/performance.md): read
   before and after every advance it was 19 % of a controller's run that sets an input every
   millisecond (bench/inputs.sh). So each fmb_init and fmb_advance is timed on the monotonic clock,
   which Linux reads in user space (vDSO), and fmb_data_stats bounds the sum by the thread's CPU
   time since fmb_init (one system call there): both are at least the thread's CPU time in the
   calls, the first equals it while the thread keeps its core, the second counts the caller's own
   work between the calls too. The bound holds only for one thread: a data object advanced from
   another thread than the one that called fmb_init reports the plain sum. */
static double monotonic_seconds(void) {
  struct timespec ts;
  if (clock_gettime(CLOCK_MONOTONIC, &ts)) return 0.0;
  return (double)ts.tv_sec + 1e-9 * (double)ts.tv_nsec;
}

static double timing_start(fmbData* d) {
  if (d->untimed) return 0.0;
  if (d->one_thread && !pthread_equal(pthread_self(), d->init_thread)) d->one_thread = 0;
  return monotonic_seconds();
}

static void timing_stop(fmbData* d, double started) {
  if (!d->untimed) d->cpu_s += fmax(monotonic_seconds() - started, 0.0);
}

static void add_stats(fmbStats* to, const fmbStats* from) {
  to->steps += from->steps;
  to->residuals += from->residuals;
  to->jacobians += from->jacobians;
  to->newton_iters += from->newton_iters;
  to->error_test_fails += from->error_test_fails;
  to->conv_fails += from->conv_fails;
  to->jacobians_reused += from->jacobians_reused;
  if (from->integrator) to->integrator = from->integrator; /* the latest backend names the run */
}

/* ------------------------------------------------------------------------------------------ */

void fmb_data_free(fmbData* d) {
  if (!d) return;
  pthread_mutex_lock(&quarantine_lock);
  if (d->magic != FMB_DATA_LIVE) { /* freed already (still in quarantine), or not ours */
    pthread_mutex_unlock(&quarantine_lock);
    return;
  }
  fmb_data_release(d);
  d->magic = FMB_DATA_FREED;
  fmbData* evicted = quarantine[quarantine_next];
  quarantine[quarantine_next] = d;
  quarantine_next = (quarantine_next + 1) % FMB_DATA_QUARANTINE;
  pthread_mutex_unlock(&quarantine_lock);
  free(evicted);
}

/* the quarantine's memory goes back at exit (or when the library is unloaded): a leak checker
   that counts reachable blocks (valgrind --show-leak-kinds=all, tools/valgrind_paper.sh) sees
   none */
#if defined(__GNUC__)
__attribute__((destructor))
#endif
static void
quarantine_release(void) {
  pthread_mutex_lock(&quarantine_lock);
  for (int i = 0; i < FMB_DATA_QUARANTINE; ++i) {
    free(quarantine[i]);
    quarantine[i] = NULL;
  }
  pthread_mutex_unlock(&quarantine_lock);
}

void fmb_data_set_timing(fmbData* d, int on) {
  if (live(d)) d->untimed = !on;
}

void fmb_data_watch(fmbData* d, const volatile sig_atomic_t* stop) {
  if (live(d)) d->stop = stop ? stop : &d->cancel;
}

void fmb_data_cancel(fmbData* d) {
  if (d) fmb_stop_set(&d->cancel, 1); /* one atomic store: another thread or a signal handler may call it */
}

void fmb_data_set_warn(fmbData* d, fmbWarnFn fn, void* user) {
  if (!live(d)) return;
  fmbWarnSink* sink = fmb_workspace_warn(d->w);
  sink->fn = fn;
  sink->user = user;
}

/* ------------------------------------------------------------------------------------------ */

/* the backend's counters join the run's, its work integrals the work done before; the next
   advance creates a new one (after a consistent state at time() when restart is set) */
static void retire_backend(fmbData* d, int restart) {
  const fmbModel* m = d->m;
  if (d->integ) {
    fmbStats sofar;
    memset(&sofar, 0, sizeof sofar);
    d->ops->stats(d->integ, &sofar);
    add_stats(&d->before, &sofar);
    d->ops->destroy(d->integ);
    d->integ = NULL;
    if (m->need_work && m->njoint > 0)
      memcpy(d->work_before, fmb_workspace_work(d->w), sizeof(double) * (size_t)m->njoint);
  }
  d->reinit_pending = 0;
  d->restart |= restart;
}

/* An input changed at time(): the equations change there, so no step history may cross it (a BDF
   or Radau polynomial across the jump would be wrong). A backend with a reinit op keeps its memory
   and starts again at the next advance (ensure_backend), its work integrals from 0 on top of the
   work done so far; one without is retired and created anew. */
static void restart_backend(fmbData* d) {
  const fmbModel* m = d->m;
  if (!d->integ || !d->ops->reinit) {
    retire_backend(d, 1);
    return;
  }
  if (!d->reinit_pending && m->need_work && m->njoint > 0) /* the run's work at time(), update_work's */
    memcpy(d->work_before, fmb_workspace_work(d->w), sizeof(double) * (size_t)m->njoint);
  d->reinit_pending = 1;
  d->restart = 1;
}

void fmb_data_hold_analysis_state(fmbData* d, double t, const double* y, const double* yp) {
  if (!live(d)) return;
  retire_backend(d, 0); /* its counters stay the run's (fmb_data_stats) */
  d->restart = 0;
  if (y != d->y) memcpy(d->y, y, sizeof(double) * (size_t)d->m->ny);
  if (yp != d->yp) memcpy(d->yp, yp, sizeof(double) * (size_t)d->m->ny);
  d->t = t;
  d->ic_done = 1;
  d->initialised = 0;
  d->failed = 0;
  d->analysis_state = 1;
}

static void mass_failure(const fmbModel* m, int bad, double t, fmbDiag* diag) {
  const fmbBodyInst* b = &m->body[bad - 1];
  const char* hint = (b->type && b->type->indefinite_mass) ? b->type->indefinite_mass(b->self) : NULL;
  fmb_diag_set(diag, FMB_EXIT_SOLVER, m->path, 0, 0,
               "stopped at t = %.6g: the mass matrix is no longer positive definite (singular or indefinite) on the "
               "constraint manifold (body '%s')%s%s",
               t, b->name, hint ? ": " : "", hint ? hint : "");
}

int fmb_init(const fmbModel* m, fmbData* d, fmbDiag* diag) {
  fmbDiag local;
  if (!diag) diag = &local;
  memset(diag, 0, sizeof *diag);
  if (misused(m, d, "fmb_init", diag)) return FMB_EXIT_BAD_INPUT;
  d->cpu_s = 0.0; /* the bound's start: fmb_data_stats */
  d->cpu_at_init = fmb_thread_cpu_seconds();
  d->init_thread = pthread_self();
  d->one_thread = 1;
  const double c0 = timing_start(d);
  fmbWorkspace* w = d->w;
  if (d->integ) d->ops->destroy(d->integ);
  d->integ = NULL;
  d->ops = fmb_integrator_for(m);
  d->restart = d->reinit_pending = 0;
  d->initialised = d->ic_done = d->interrupted = d->analysis_state = 0;
  fmb_stop_set(&d->cancel, 0);
  memset(&d->before, 0, sizeof d->before);
  memset(&d->ic, 0, sizeof d->ic);
  d->switched.t = -1.0;
  d->switched.h = 0.0;
  d->switched.why[0] = '\0';
  memset(d->work_before, 0, sizeof(double) * (size_t)(m->njoint + 1));
  memset(fmb_workspace_work(w), 0, sizeof(double) * (size_t)(m->njoint + 1));
  fmb_workspace_inputs_reset(m, w);
  fmb_workspace_warn(w)->warnings = 0;
  d->t = m->solver.t0;
  int rc = fmb_initial_conditions(m, w, d->y, d->yp, &d->ic, diag);
  if (!rc) {
    d->ic_done = 1;
    const int bad = fmb_check_mass(m, w, d->t, d->y, d->y + m->nq, 0.0);
    if (bad) {
      mass_failure(m, bad, d->t, diag);
      rc = FMB_EXIT_SOLVER;
    }
  }
  memset(d->range_warned, 0, (size_t)m->nbody + 1);
  if (!rc) fmb_warn_model_range(m, d->w, d->t, d->y, d->range_warned);
  if (!rc && m->need_work) { /* the force elements' potential at t0 enters energy.balance */
    fmbEnergy e0;
    fmb_energy(m, w, d->t, d->y, d->y + m->nq, &e0);
    *fmb_workspace_spring_energy0(w) = e0.spring;
  }
  d->initialised = rc == 0;
  d->failed = rc != 0;
  timing_stop(d, c0);
  return rc;
}

/* A row left out as redundant must keep holding: if it stops (the joints were dependent only at
   t0, or only on part of the motion) the run would silently lose a joint. Checked after every
   advance. */
static int redundant_row_broken(const fmbModel* m, fmbWorkspace* w, double t, const double* y, double* phi,
                                fmbDiag* diag) {
  int count = 0;
  const unsigned char* drop = fmb_workspace_redundant(w, &count);
  if (!count || fmb_constraints_all(m, w, t, y, y + m->nq, phi, NULL, NULL, NULL)) return 0;
  double scale = 1.0;
  for (int i = 0; i < m->nq; ++i) scale = fmax(scale, fabs(y[i]));
  for (int r = 0; r < m->nc; ++r)
    if (drop[r] && fabs(phi[r]) > 1e3 * (m->solver.atol + m->solver.rtol * scale)) {
      unsigned char one[1024] = {0};
      char name[200] = "";
      if (r < (int)sizeof one) {
        one[r] = 1;
        fmb_name_rows(m, one, name, sizeof name);
      }
      fmb_diag_set(diag, FMB_EXIT_SOLVER, m->path, 0, 0,
                   "stopped at t = %.6g: %s, left out as redundant at the start, no longer holds (residual %.3g): the "
                   "joints repeat each other only on part of the motion; remove the repeated joint",
                   t, name, phi[r]);
      return 1;
    }
  return 0;
}

/* a body's own validity check (e.g. a beam deforming beyond its length: a runaway solution) */
static int invalid_state(const fmbModel* m, double t, const double* y, fmbDiag* diag) {
  for (int b = 1; b < m->nbody; ++b) {
    const fmbBodyInst* bi = &m->body[b];
    if (!bi->type->invalid_state) continue;
    const char* why = bi->type->invalid_state(bi->self, y + bi->qadr, y + m->nq + bi->qadr);
    if (why) {
      fmb_diag_set(diag, FMB_EXIT_SOLVER, m->path, 0, 0, "stopped at t = %.6g: body '%s': %s", t, bi->name, why);
      return 1;
    }
  }
  return 0;
}

/* a backend at time(): created from the state there, made consistent first after a change */
static int ensure_backend(const fmbModel* m, fmbData* d, fmbDiag* diag) {
  if (d->integ && !d->reinit_pending) return 0;
  if (d->restart) {
    const int rc = fmb_consistent_state(m, d->w, d->t, d->y, d->yp, diag);
    if (rc) return rc;
    d->restart = 0;
  }
  if (d->integ) { /* restart_backend's: the backend starts again where it is */
    d->reinit_pending = 0;
    if (!d->ops->reinit(d->integ, d->t, d->y, d->yp, diag)) return 0;
    memset(diag, 0, sizeof *diag); /* it could not: a new one, as without the op */
    retire_backend(d, 0);
  }
  const fmbIntegratorSetup setup = {m, d->w, d->stop, d->atol};
  d->integ = d->ops->create(&setup, d->t, d->y, d->yp, diag);
  return d->integ ? 0 : diag->code ? diag->code : FMB_EXIT_SOLVER;
}

/* the joints' work since t0 into the workspace (the outputs read it): the backend's integrals
   from where it started, plus the work done before */
static void update_work(const fmbModel* m, fmbData* d) {
  /* a backend waiting for its restart still holds the work of before it (in work_before now) */
  if (!m->need_work || m->njoint == 0 || !d->integ || d->reinit_pending) return;
  double* work = fmb_workspace_work(d->w);
  d->ops->work(d->integ, work);
  for (int j = 0; j < m->njoint; ++j) work[j] += d->work_before[j];
}

static int interrupted(const fmbModel* m, fmbData* d, fmbDiag* diag) {
  update_work(m, d); /* up to where it stopped: a run that goes on keeps its energy balance */
  d->interrupted = 1;
  if (d->stop == &d->cancel) fmb_stop_set(&d->cancel, 0); /* used up; fmb_run's flag stays as its signal set it */
  retire_backend(d, 1);
  fmb_diag_set(diag, FMB_EXIT_INTERRUPTED, m->path, 0, 0, "interrupted at t = %.6g", d->t);
  return FMB_EXIT_INTERRUPTED;
}

/* every value of the state and the work integrals finite */
static int state_finite(const fmbModel* m, const fmbData* d) {
  if (!isfinite(d->t)) return 0;
  for (int i = 0; i < m->ny; ++i)
    if (!isfinite(d->y[i]) || !isfinite(d->yp[i])) return 0;
  const double* work = fmb_workspace_work(d->w);
  for (int j = 0; m->need_work && j < m->njoint; ++j)
    if (!isfinite(work[j])) return 0;
  return 1;
}

/* A backend that gave up on values that are not finite (a load of 1e300, a runaway) may leave
   them in y and yp (IDA does, at the time of its last step): the state goes back to where the
   advance started, the last good one, so the outputs are finite, fmb_data_state is usable and a
   later advance (after the cause is removed, e.g. the input set back) restarts from there. */
static void back_to_start(const fmbModel* m, fmbData* d) {
  d->t = d->start.t;
  memcpy(d->y, d->start.y, sizeof(double) * (size_t)m->ny);
  memcpy(d->yp, d->start.yp, sizeof(double) * (size_t)m->ny);
  if (m->need_work && m->njoint > 0)
    memcpy(fmb_workspace_work(d->w), d->start.work, sizeof(double) * (size_t)m->njoint);
}

static int step_to(const fmbModel* m, fmbData* d, double t_out, fmbDiag* diag) {
  fmbWorkspace* w = d->w;
  const size_t ny = (size_t)m->ny;
  int rc = ensure_backend(m, d, diag);
  if (rc) return rc;
  {
    d->start.t = d->t;
    memcpy(d->start.y, d->y, sizeof(double) * ny);
    memcpy(d->start.yp, d->yp, sizeof(double) * ny);
    if (m->need_work && m->njoint > 0) memcpy(d->start.work, fmb_workspace_work(w), sizeof(double) * (size_t)m->njoint);
  }
  for (;;) {
    double tret = d->t, h = 0.0;
    char why[1200]; /* not "= """: that zeroes all 1,200 bytes every advance (every output row) */
    why[0] = '\0';
    const int flag = d->ops->advance(d->integ, t_out, &tret, d->y, d->yp, &h, why, sizeof why);
    d->t = tret;
    if (flag == FMB_ADVANCE_INTERRUPTED || (flag != FMB_ADVANCE_OK && fmb_stop_requested(d->stop)))
      return interrupted(m, d, diag);
    if (flag == FMB_ADVANCE_FAILED && !d->ops->projected && d->may_switch &&
        fmb_rank_deficient_at(m, w, tret, d->y, d->y + m->nq, FMB_AUTO_SWITCH_RANK_TOL)) {
      /* a singular configuration: the GGL system's Newton matrix (IDA's or radau5's) is singular
         here; the projected formulation (minimum-norm multipliers) passes it, for the rest of the
         run. It starts from where this advance started (fmb_run: the last output row), not from
         the last good step: that one lies next to the singular configuration, where a start with
         no step history failed (scenes/parallelogram.yaml at rtol 1e-8: IDA gave up 2e-4 rad
         before the flat position, CVODE started there stopped at it). The work integrals go on
         from their values there. */
      if (!d->quiet)
        fmb_warn(w,
                 "note: t = %.6g: the constraint Jacobian is rank-deficient here (a singular configuration, where "
                 "the mechanism can change branch); continuing with the projected formulation (set solver.formulation: "
                 "ggl to stop instead)",
                 tret);
      retire_backend(d, 0);
      d->ops = &fmb_integrator_projected;
      d->t = d->start.t;
      memcpy(d->y, d->start.y, sizeof(double) * ny);
      memcpy(d->yp, d->start.yp, sizeof(double) * ny);
      if ((rc = ensure_backend(m, d, diag))) return rc;
      d->switched.t = tret;
      d->switched.h = h;
      snprintf(d->switched.why, sizeof d->switched.why, "%s", why);
      continue;
    }
    if (flag != FMB_ADVANCE_OK) {
      const int bad = fmb_check_mass(m, w, tret, d->y, d->y + m->nq, 1e-5);
      if (bad)
        mass_failure(m, bad, tret, diag);
      else if (d->switched.t >= 0 && tret - d->switched.t < m->solver.output_step) /* no further: IDA's reason */
        fmb_diag_set(diag, FMB_EXIT_SOLVER, m->path, 0, 0,
                     "solver failed at t = %.6g (step size %.3g): %s (the projected "
                     "formulation, tried from t = %.6g, did not get further)",
                     tret, d->switched.h, d->switched.why, d->switched.t);
      else
        fmb_diag_set(diag, FMB_EXIT_SOLVER, m->path, 0, 0, "solver failed at t = %.6g (step size %.3g): %s", tret, h,
                     why);
      update_work(m, d);
      if (!state_finite(m, d)) back_to_start(m, d);
      retire_backend(d, 1);
      return FMB_EXIT_SOLVER;
    }
    update_work(m, d);
    int nred = 0;
    fmb_workspace_redundant(w, &nred);
    if (invalid_state(m, d->t, d->y, diag) || (nred && redundant_row_broken(m, w, d->t, d->y, d->redundant_phi, diag)))
      return FMB_EXIT_SOLVER;
    const int bad = fmb_check_mass(m, w, d->t, d->y, d->y + m->nq, 0.0);
    if (bad) {
      mass_failure(m, bad, d->t, diag);
      return FMB_EXIT_SOLVER;
    }
    fmb_warn_model_range(m, d->w, d->t, d->y, d->range_warned);
    if (d->ops->after_row) d->ops->after_row(d->integ, d->t);
    return 0;
  }
}

int fmb_advance(const fmbModel* m, fmbData* d, double t_out, fmbDiag* diag) {
  fmbDiag local;
  if (!diag) diag = &local;
  memset(diag, 0, sizeof *diag);
  if (misused(m, d, "fmb_advance", diag)) return FMB_EXIT_BAD_INPUT;
  if (!d->initialised) {
    fmb_diag_set(diag, FMB_EXIT_BAD_INPUT, m->path, 0, 0,
                 d->analysis_state
                     ? "fmb_advance: the data object holds fmb_static_data's equilibrium, not a run's state: call "
                       "fmb_init to start a run (`initial: static` starts one from the equilibrium)"
                     : "fmb_advance: the data object has no state yet: call fmb_init first (or it failed)");
    return FMB_EXIT_BAD_INPUT;
  }
  if (isnan(t_out) || t_out < d->t) {
    fmb_diag_set(
        diag, FMB_EXIT_BAD_INPUT, m->path, 0, 0,
        "fmb_advance: t_out = %g is before the run's time %.17g: a run goes forward (fmb_init starts it again)", t_out,
        d->t);
    return FMB_EXIT_BAD_INPUT;
  }
  if (t_out > m->solver.t_end) {
    fmb_diag_set(diag, FMB_EXIT_BAD_INPUT, m->path, 0, 0,
                 "fmb_advance: t_out = %.17g is beyond the scene's t_end = %.17g (set solver.t_end for a longer run)",
                 t_out, m->solver.t_end);
    return FMB_EXIT_BAD_INPUT;
  }
  if (fmb_stop_requested(d->stop)) { /* cancelled between two advances */
    d->failed = 1;
    return interrupted(m, d, diag);
  }
  if (t_out == d->t) return 0;
  const double c0 = timing_start(d);
  const int rc = step_to(m, d, t_out, diag);
  if (rc == FMB_EXIT_SOLVER && !state_finite(m, d)) { /* a check after the step found it so */
    back_to_start(m, d);
    retire_backend(d, 1); /* its history is of the values dropped: the next advance restarts */
  }
  d->failed = rc != 0;
  d->interrupted = rc == FMB_EXIT_INTERRUPTED;
  timing_stop(d, c0);
  return rc;
}

/* ------------------------------------------------------------------------------------------ */

double fmb_data_time(const fmbData* d) { return live(d) ? d->t : NAN; }

int fmb_data_state(const fmbData* d, double* y, double* yp) {
  if (!live(d) || !d->ic_done) return FMB_EXIT_BAD_INPUT;
  if (y) memcpy(y, d->y, sizeof(double) * (size_t)d->m->ny);
  if (yp) memcpy(yp, d->yp, sizeof(double) * (size_t)d->m->ny);
  return 0;
}

int fmb_data_set_state(const fmbModel* m, fmbData* d, double t, const double* y, const double* yp, fmbDiag* diag) {
  fmbDiag local;
  if (!diag) diag = &local;
  memset(diag, 0, sizeof *diag);
  if (misused(m, d, "fmb_data_set_state", diag)) return FMB_EXIT_BAD_INPUT;
  const char* why = !d->ic_done                                    ? "before fmb_init"
                    : !y                                           ? "no state (y is NULL)"
                    : !(t >= m->solver.t0 && t <= m->solver.t_end) ? "t outside the scene's [t0, t_end]"
                                                                   : NULL;
  for (int i = 0; !why && i < m->ny; ++i)
    if (!isfinite(y[i]) || (yp && !isfinite(yp[i]))) why = "a value that is not finite";
  if (why) {
    fmb_diag_set(diag, FMB_EXIT_BAD_INPUT, m->path, 0, 0, "fmb_data_set_state: %s; the state is unchanged", why);
    return FMB_EXIT_BAD_INPUT;
  }
  /* no step history crosses the jump: the next advance makes the state consistent at t (the
     constraints, then the accelerations and multipliers) and starts a new backend from it */
  retire_backend(d, 1);
  d->t = t;
  memcpy(d->y, y, sizeof(double) * (size_t)m->ny);
  if (yp)
    memcpy(d->yp, yp, sizeof(double) * (size_t)m->ny);
  else
    memset(d->yp, 0, sizeof(double) * (size_t)m->ny);
  d->failed = d->interrupted = 0;
  return 0;
}

int fmb_noutput(const fmbModel* m) { return m && m->noutput > 0 ? m->noutput - 1 : 0; }

const char* fmb_output_name(const fmbModel* m, int i) {
  return (m && i >= 0 && i < m->noutput - 1) ? m->output[i + 1].name : NULL;
}

int fmb_outputs(const fmbModel* m, fmbData* d, double* out) {
  if (misused(m, d, "fmb_outputs", NULL) || !out || !d->ic_done) return FMB_EXIT_BAD_INPUT;
  const int not_finite = fmb_outputs_eval(m, d->w, d->t, d->y, d->yp, d->row);
  if (m->noutput > 1) memcpy(out, d->row + 1, sizeof(double) * (size_t)(m->noutput - 1));
  return not_finite ? FMB_EXIT_SOLVER : 0;
}

int fmb_data_stats(const fmbData* d, fmbStats* st) {
  if (!live(d) || !st) return FMB_EXIT_BAD_INPUT;
  memset(st, 0, sizeof *st);
  if (d->integ) d->ops->stats(d->integ, st);
  const char* running = st->integrator; /* the live backend, not an earlier one retired */
  add_stats(st, &d->before);
  if (running) st->integrator = running;
  st->t_reached = d->t;
  st->status_ok = d->initialised && !d->failed;
  st->interrupted = d->interrupted;
  st->ic_position_correction = d->ic.ic_position_correction;
  st->ic_velocity_correction = d->ic.ic_velocity_correction;
  st->cpu_s = d->cpu_s;
  if (st->cpu_s > 0.0 && d->one_thread && pthread_equal(pthread_self(), d->init_thread)) {
    const double thread_cpu = fmb_thread_cpu_seconds() - d->cpu_at_init; /* timing_start's bound */
    if (thread_cpu < st->cpu_s) st->cpu_s = thread_cpu;
  }
  st->warnings = fmb_workspace_warn(d->w)->warnings;
  return 0;
}

/* ------------------------------------------------------------------------------------------ */

int fmb_ninput(const fmbModel* m) { return m ? m->ninput : 0; }

const char* fmb_input_name(const fmbModel* m, int i) {
  return (m && i >= 0 && i < m->ninput) ? m->joint[m->input_joint[i]].name : NULL;
}

static int input_index(const fmbModel* m, const char* name) {
  for (int i = 0; name && i < m->ninput; ++i)
    if (strcmp(m->joint[m->input_joint[i]].name, name) == 0) return i;
  return -1;
}

/* A value a scene's `value:` would be refused for: one that puts the mechanism where a double
   cannot resolve the joints' tolerance (a drive's angle or a slide of 1e300: the scene's rule,
   ic.c), or that the joints cannot follow. Only a value that large could do so (a coordinate it
   sets is the value itself, give or take the mechanism's size), so only then is the restart's
   projection tried, on a copy (the start buffers are free between advances): a load of any
   finite size is accepted, as a scene accepts it. 1 after saying why (d's warn handler). */
static int refused_value(const fmbModel* m, fmbData* d, const char* fn, const char* name, double value) {
  const size_t ny = (size_t)m->ny;
  memcpy(d->start.y, d->y, sizeof(double) * ny);
  memcpy(d->start.yp, d->yp, sizeof(double) * ny);
  fmbDiag diag;
  memset(&diag, 0, sizeof diag);
  double qmax = 0.0;
  const int rc = fmb_consistent_state(m, d->w, d->t, d->start.y, d->start.yp, &diag);
  for (int k = 0; !rc && k < m->nq; ++k) qmax = fmax(qmax, fabs(d->start.y[k]));
  if (!rc && isfinite(qmax) && qmax * DBL_EPSILON <= FMB_IC_PHI_TOL) return 0;
  if (rc)
    fmb_warn(d->w, "%s: input '%s' = %g refused: %s", fn, name, value, diag.msg);
  else
    fmb_warn(d->w,
             "%s: input '%s' = %g refused: the coordinates would reach %.3g (m or rad), where a double "
             "resolves only %.2g, coarser than the joints' tolerance %g (a scene's `value:` is refused the same)",
             fn, name, value, qmax, qmax * DBL_EPSILON, FMB_IC_PHI_TOL);
  return 1;
}

/* fmb_set_input and fmb_set_input_motion: the input `name` is value + rate tau + accel tau^2 / 2
   from time() on */
static int set_input(const fmbModel* m, fmbData* d, const char* fn, const char* name, double value, double rate,
                     double accel) {
  fmbDiag diag;
  memset(&diag, 0, sizeof diag);
  if (misused(m, d, fn, &diag)) return FMB_EXIT_BAD_INPUT;
  const int i = input_index(m, name);
  if (i < 0) {
    fmb_warn(d->w,
             "%s: no input named '%s' (%d inputs: a drive with `profile: input` or a load with `law: input` is one, "
             "named by its joint)",
             fn, name ? name : "(NULL)", m->ninput);
    return FMB_EXIT_BAD_INPUT;
  }
  if (!isfinite(value) || !isfinite(rate) || !isfinite(accel)) {
    fmb_warn(d->w, "%s: input '%s' = %g (rate %g, second rate %g): not a finite number", fn, name, value, rate, accel);
    return FMB_EXIT_BAD_INPUT;
  }
  fmbInputSetting* in = &fmb_workspace_inputs(d->w)[i];
  double now_value, now_rate, now_accel;
  fmb_input_at(in, d->t, &now_value, &now_rate, &now_accel);
  if (now_value == value && now_rate == rate && now_accel == accel) return 0; /* no change: the history holds */
  /* A drive's motion that jumps (in position or in rate, beyond the solver's tolerance on that
     scale) is projected anew, and the motion its last setting led to is lost: a drive held by
     fmb_set_input comes to rest at every change. Said once per input, with what to do instead. */
  const fmbJointInst* j = &m->joint[m->input_joint[i]];
  const double tol = m->solver.atol + m->solver.rtol * fmax(in->magnitude, fmax(fabs(value), fabs(now_value)));
  const double h = fmax(d->t - in->t_set, 0.0); /* how long the last setting held */
  const double jump = fabs(value - now_value), rate_jump = fabs(rate - now_rate);
  const fmbInputSetting before = *in;
  in->value = value;
  in->rate = rate;
  in->accel = accel;
  in->t_set = d->t;
  in->magnitude = fmax(in->magnitude, fabs(value));
  /* a value a scene's `value:` would be refused for is refused here too (refused_value) */
  if (d->ic_done && fabs(value) * DBL_EPSILON > FMB_IC_PHI_TOL && refused_value(m, d, fn, name, value)) {
    *in = before;
    return FMB_EXIT_BAD_INPUT;
  }
  if (j->nrows > 0 && (jump > tol || rate_jump * h > tol) && in->jumps++ == 0)
    fmb_warn(d->w,
             "warning: %s: drive input '%s' jumps at t = %.6g by %.3g (rate %.3g -> %.3g): the velocities are "
             "projected onto the new setting%s (further jumps of this input are not reported)",
             fn, name, d->t, value - now_value, now_rate, rate,
             rate == 0.0 ? "; a drive set by value alone is at rest between settings: give the motion's rate with "
                           "fmb_set_input_motion (docs/api.md)"
                         : "");
  /* A setting that lands where the last one led, within the solver's tolerance in value and in
     rate over the time it held (a controller feeding a smooth law with its rate, as
     fmb_set_input_motion does), changes the equations by no more than the error the steps are
     allowed anyway: the step history holds across it, and the run costs what the continuous law's
     does (bench/inputs.sh: a 1 kHz controller restarting at every setting took 56x the steps).
     Any other setting is a jump: the next advance starts afresh from a state made consistent with
     it, no BDF or Radau history across it. */
  if (jump > tol || rate_jump * h > tol) restart_backend(d);
  return 0;
}

int fmb_set_input(const fmbModel* m, fmbData* d, const char* name, double value) {
  return set_input(m, d, "fmb_set_input", name, value, 0.0, 0.0);
}

int fmb_set_input_motion(const fmbModel* m, fmbData* d, const char* name, double value, double rate, double accel) {
  return set_input(m, d, "fmb_set_input_motion", name, value, rate, accel);
}

int fmb_get_input(const fmbModel* m, const fmbData* d, const char* name, double* value) {
  if (misused(m, d, "fmb_get_input", NULL) || !value) return FMB_EXIT_BAD_INPUT;
  const int i = input_index(m, name);
  if (i < 0) return FMB_EXIT_BAD_INPUT;
  fmb_input_at(&fmb_workspace_inputs(d->w)[i], d->t, value, NULL, NULL);
  return 0;
}
