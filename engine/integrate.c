/* integrate.c — the run driver: initial conditions, one integrator backend (integrator.h: IDA on
 * the GGL system, or the projected formulation) from output time to output time, and at every
 * output row the checks and the CSV/VTK rows. On any failure every row so far is already on disk
 * and the message says when, why, and what to try. */
#include <errno.h>
#include <math.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>
#include <time.h>
#include <unistd.h>

#include "integrator.h"

/* how close to rank-deficient Phi_q must be where IDA failed for `formulation: auto` to switch to
   the projected formulation: a row whose part independent of the others is below 1e-2 of the
   largest row (a parallelogram within about half a degree of flat; IDA on the GGL system gave up
   at 0.3 mrad before the flat position in scenes/parallelogram.yaml) */
#define FMB_AUTO_SWITCH_RANK_TOL 1e-2

static void add_stats(fmbStats* to, const fmbStats* from) {
  to->steps += from->steps;
  to->residuals += from->residuals;
  to->jacobians += from->jacobians;
  to->newton_iters += from->newton_iters;
  to->error_test_fails += from->error_test_fails;
  to->conv_fails += from->conv_fails;
  to->jacobians_reused += from->jacobians_reused;
}

static void mass_failure(const fmbModel* m, int bad, double t, fmbDiag* diag) {
  const fmbBodyInst* b = &m->body[bad - 1];
  const char* hint = (b->type && b->type->indefinite_mass) ? b->type->indefinite_mass(b->self) : NULL;
  fmb_diag_set(diag, FMB_EXIT_SOLVER, m->path, 0, 0,
               "stopped at t = %.6g: the mass matrix is no longer positive definite (singular or indefinite) on the "
               "constraint manifold (body '%s')%s%s",
               t, b->name, hint ? ": " : "", hint ? hint : "");
}

/* a CSV row that could not be written (wr < 0) or held a non-finite value (wr > 0) */
static int row_failed(const fmbModel* m, int wr, double t, fmbDiag* diag) {
  if (wr < 0)
    fmb_diag_set(diag, FMB_EXIT_SOLVER, m->path, 0, 0, "writing the output failed at t = %.6g (disk full?)", t);
  else if (wr > 0)
    fmb_diag_set(diag, FMB_EXIT_SOLVER, m->path, 0, 0,
                 "stopped at t = %.6g: an output is not finite (the solution blew up): check the initial values "
                 "and parameters for a zero-length spring or an extreme value, try a tighter rtol or a smaller "
                 "solver.max_step, and check the model for instability",
                 t);
  return wr != 0;
}

/* the CSV row, then the animation's frame (if any): what row_failed reads */
static int write_outputs(fmbCsv* csv, fmbVtk* vtk, const fmbModel* m, fmbWorkspace* w, double t, const double* y,
                         const double* yp) {
  int wr = fmb_csv_row(csv, m, w, t, y, yp);
  if (wr == 0 && vtk && fmb_vtk_step(vtk, m, w, t, y)) wr = -1;
  return wr;
}

/* The progress line: silent for the first `after` seconds of wall time (short runs print
   nothing), then at most 5 updates a second. On a terminal the line is rewritten in place and
   ended with a newline when the run ends, so the stats line stays the last line; elsewhere
   (--progress into a file or pipe) one line per second. */
typedef struct {
  int on, tty, shown;
  double after, start, last;
} Progress;

static double wall_seconds(void) {
  struct timespec ts;
  clock_gettime(CLOCK_MONOTONIC, &ts);
  return (double)ts.tv_sec + 1e-9 * (double)ts.tv_nsec;
}

static void progress_update(Progress* pr, const fmbModel* m, double t, long steps) {
  if (!pr->on) return;
  const double now = wall_seconds(), elapsed = now - pr->start;
  if (elapsed < pr->after || now - pr->last < (pr->tty ? 0.2 : 1.0)) return;
  const double done = (t - m->solver.t0) / (m->solver.t_end - m->solver.t0);
  char remaining[32] = "?";
  if (done > 0.0) snprintf(remaining, sizeof remaining, "%.1f s", elapsed * (1.0 - done) / done);
  fprintf(stderr, "%sprogress: t = %.6g of %g (%.0f %%), %ld steps, %.1f s elapsed, ~%s remaining%s",
          pr->tty ? "\r" : "", t, m->solver.t_end, 100.0 * done, steps, elapsed, remaining, pr->tty ? "\033[K" : "\n");
  fflush(stderr);
  pr->last = now;
  pr->shown = 1;
}

static void progress_end(Progress* pr) {
  if (pr->on && pr->tty && pr->shown) fputc('\n', stderr);
}

/* A row left out as redundant must keep holding: if it stops (the joints were dependent only at
   t0, or only on part of the motion) the run would silently lose a joint. Checked at each row. */
static int redundant_row_broken(const fmbModel* m, fmbWorkspace* w, double t, const double* y, double* phi, fmbDiag* diag) {
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
                   "joints repeat each other only on part of the motion; remove the repeated joint", t, name, phi[r]);
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

int fmb_run(const fmbModel* m, const fmbRunOptions* opt, fmbStats* st, fmbDiag* diag) {
  fmbStats local_stats;
  fmbDiag local_diag;
  if (!st) st = &local_stats;
  if (!diag) diag = &local_diag;
  if (!m) {
    memset(st, 0, sizeof *st);
    memset(diag, 0, sizeof *diag);
    fmb_diag_set(diag, FMB_EXIT_BAD_INPUT, "", 0, 0, "fmb_run: no model (NULL)");
    return FMB_EXIT_BAD_INPUT;
  }
  clock_t c0 = clock();
  memset(st, 0, sizeof *st);
  memset(diag, 0, sizeof *diag);
  st->t_reached = m->solver.t0;
  const int ny = m->ny;
  fmbCsv* csv = fmb_csv_open(opt ? opt->csv_path : NULL, diag);
  if (!csv) return diag->code ? diag->code : FMB_EXIT_BAD_INPUT;
  const char* vtk_dir = (opt && opt->vtk_dir) ? opt->vtk_dir : (m->vtk_dir[0] ? m->vtk_dir : NULL);
  fmbVtk* vtk = NULL;
  if (vtk_dir && (vtk = fmb_vtk_open(m, vtk_dir, diag))) fmb_vtk_set_every(vtk, opt ? opt->vtk_every : 1);
  if (vtk_dir && !vtk) {
    fmb_csv_close(csv);
    return diag->code ? diag->code : FMB_EXIT_SOLVER;
  }
  Progress progress = {opt && opt->progress && !opt->quiet, isatty(fileno(stderr)), 0, opt ? opt->progress_after_s : 0.0,
                       wall_seconds(), 0.0};
  const volatile sig_atomic_t* stop = opt ? opt->stop : NULL;
  const fmbIntegratorOps* ops = fmb_integrator_for(m);
  void* integ = NULL;
  double* redundant_phi = NULL; /* the redundant rows' residuals, checked at each row */
  int rc = 0;
  double t = m->solver.t0;

  fmbWorkspace* w = fmb_workspace_new(m);
  /* y, yp: the whole state (q, v, multipliers, auxiliary unknowns), as the outputs read it */
  double* y = calloc((size_t)ny + 1, sizeof(double));
  double* yp = calloc((size_t)ny + 1, sizeof(double));
  double* atol = calloc((size_t)ny + 1, sizeof(double));
  double* work_before = calloc((size_t)m->njoint + 1, sizeof(double)); /* work done before a switch */
  fmbStats before_switch;                                               /* counters of the backend before it */
  struct {
    double t, h;
    char why[1200];
  } switched = {-1.0, 0.0, ""}; /* where formulation: auto left IDA, and IDA's reason */
  /* formulation: auto keeps the last row's state to start the projected formulation from */
  const int may_switch = m->solver.formulation == FMB_FORM_AUTO && m->nc > 0 && m->nz == 0;
  struct {
    double t, *y, *yp;
  } row = {m->solver.t0, may_switch ? calloc((size_t)ny + 1, sizeof(double)) : NULL,
           may_switch ? calloc((size_t)ny + 1, sizeof(double)) : NULL};
  memset(&before_switch, 0, sizeof before_switch);
  if (!w || !y || !yp || !atol || !work_before || (may_switch && (!row.y || !row.yp))) {
    fmb_diag_set(diag, FMB_EXIT_SOLVER, m->path, 0, 0, "out of memory setting up the integrator");
    rc = FMB_EXIT_SOLVER;
    goto done;
  }
  rc = fmb_initial_conditions(m, w, y, yp, st, diag);
  if (rc) goto done;
  if (!opt || !opt->quiet)
    fprintf(stderr, "initial conditions: position correction %.3g, velocity correction %.3g\n",
            st->ic_position_correction, st->ic_velocity_correction);
  int nredundant = 0;
  const unsigned char* redundant = fmb_workspace_redundant(w, &nredundant);
  if (nredundant) redundant_phi = calloc((size_t)m->nc, sizeof(double));
  if (nredundant && (!opt || !opt->quiet)) {
    char rows[600];
    fmb_name_rows(m, redundant, rows, sizeof rows);
    fprintf(stderr, "redundant constraints: %s repeat%s the other joints' equations: left out of the equations, their "
            "share of the reactions by the minimum-norm rule\n", rows, nredundant == 1 ? "s" : "");
  }

  int bad = fmb_check_mass(m, w, t, y, y + m->nq, 0.0);
  if (bad) {
    mass_failure(m, bad, t, diag);
    rc = FMB_EXIT_SOLVER;
    goto done;
  }
  if (m->need_work) { /* the force elements' potential at t0 enters energy.balance */
    fmbEnergy e0;
    fmb_energy(m, w, t, y, y + m->nq, &e0);
    *fmb_workspace_spring_energy0(w) = e0.spring;
  }
  if (stop && *stop) goto done;
  if (fmb_csv_header(csv, m)) {
    row_failed(m, -1, t, diag);
    rc = FMB_EXIT_SOLVER;
    goto done;
  }
  if (row_failed(m, write_outputs(csv, vtk, m, w, t, y, yp), t, diag)) {
    rc = FMB_EXIT_SOLVER;
    goto done;
  }
  st->rows_written = 1;
  if (may_switch) {
    memcpy(row.y, y, sizeof(double) * (size_t)ny);
    memcpy(row.yp, yp, sizeof(double) * (size_t)ny);
  }

  fmb_absolute_tolerances(m, atol);
  const fmbIntegratorSetup setup = {m, w, stop, atol};
  integ = ops->create(&setup, t, y, yp, diag);
  if (!integ) {
    rc = diag->code ? diag->code : FMB_EXIT_SOLVER;
    goto done;
  }

  const double dt = m->solver.output_step, t_end = m->solver.t_end, t0 = m->solver.t0;
  const long nout = (long)ceil((t_end - t0) / dt - 1e-9);
  for (long k = 1; k <= nout; ++k) {
    const double tout = k == nout ? t_end : t0 + (double)k * dt;
    double tret = t, h = 0.0;
    char why[1200] = "";
    const int flag = ops->advance(integ, tout, &tret, y, yp, &h, why, sizeof why);
    t = tret;
    if (flag == FMB_ADVANCE_INTERRUPTED || (flag != FMB_ADVANCE_OK && stop && *stop)) break;
    if (flag == FMB_ADVANCE_FAILED && ops != &fmb_integrator_projected && may_switch &&
        fmb_rank_deficient_at(m, w, tret, y, y + m->nq, FMB_AUTO_SWITCH_RANK_TOL)) {
      /* a singular configuration: the GGL system's Newton matrix (IDA's or radau5's) is singular
         here; the projected formulation (minimum-norm multipliers) passes it, for the rest of the
         run. It starts from the last output row, not from the last good step: that one lies next
         to the singular configuration, where a start with no step history failed
         (scenes/parallelogram.yaml at rtol 1e-8: IDA gave up 2e-4 rad before the flat position,
         CVODE started there stopped at it). The work integrals go on from the row's values. */
      if (!opt || !opt->quiet)
        fprintf(stderr, "note: t = %.6g: the constraint Jacobian is rank-deficient here (a singular configuration, where "
                "the mechanism can change branch); continuing with the projected formulation (set solver.formulation: "
                "ggl to stop instead)\n", tret);
      fmbStats sofar;
      memset(&sofar, 0, sizeof sofar);
      ops->stats(integ, &sofar);
      ops->destroy(integ);
      ops = &fmb_integrator_projected;
      if (m->need_work && m->njoint > 0) memcpy(work_before, fmb_workspace_work(w), sizeof(double) * (size_t)m->njoint);
      t = row.t;
      memcpy(y, row.y, sizeof(double) * (size_t)ny);
      memcpy(yp, row.yp, sizeof(double) * (size_t)ny);
      integ = ops->create(&setup, t, y, yp, diag);
      if (!integ) {
        rc = diag->code ? diag->code : FMB_EXIT_SOLVER;
        break;
      }
      add_stats(&before_switch, &sofar);
      switched.t = tret;
      switched.h = h;
      snprintf(switched.why, sizeof switched.why, "%s", why);
      --k;
      continue;
    }
    if (flag != FMB_ADVANCE_OK) {
      bad = fmb_check_mass(m, w, tret, y, y + m->nq, 1e-5);
      if (bad)
        mass_failure(m, bad, tret, diag);
      else if (switched.t >= 0 && tret - switched.t < dt) /* no further: IDA's reason is the one to give */
        fmb_diag_set(diag, FMB_EXIT_SOLVER, m->path, 0, 0, "solver failed at t = %.6g (step size %.3g): %s (the projected "
                     "formulation, tried from t = %.6g, did not get further)", tret, switched.h, switched.why, switched.t);
      else
        fmb_diag_set(diag, FMB_EXIT_SOLVER, m->path, 0, 0, "solver failed at t = %.6g (step size %.3g): %s", tret, h, why);
      rc = FMB_EXIT_SOLVER;
      break;
    }
    if (m->need_work && m->njoint > 0) {
      double* work = fmb_workspace_work(w);
      ops->work(integ, work);
      for (int j = 0; j < m->njoint; ++j) work[j] += work_before[j];
    }
    if (invalid_state(m, t, y, diag) || (redundant_phi && redundant_row_broken(m, w, t, y, redundant_phi, diag))) {
      rc = FMB_EXIT_SOLVER;
      break;
    }
    bad = fmb_check_mass(m, w, t, y, y + m->nq, 0.0);
    if (bad) {
      mass_failure(m, bad, t, diag);
      rc = FMB_EXIT_SOLVER;
      break;
    }
    if (row_failed(m, write_outputs(csv, vtk, m, w, t, y, yp), t, diag)) {
      rc = FMB_EXIT_SOLVER;
      break;
    }
    st->rows_written++;
    if (may_switch && ops != &fmb_integrator_projected) {
      row.t = t;
      memcpy(row.y, y, sizeof(double) * (size_t)ny);
      memcpy(row.yp, yp, sizeof(double) * (size_t)ny);
    }
    if (ops->after_row) ops->after_row(integ, t);
    if (progress.on) {
      fmbStats now;
      memset(&now, 0, sizeof now);
      ops->stats(integ, &now);
      progress_update(&progress, m, t, now.steps);
    }
    if (stop && *stop) break;
  }
  progress_end(&progress);

done:
  if (stop && *stop && !rc) {
    st->interrupted = 1;
    rc = FMB_EXIT_INTERRUPTED;
    fmb_diag_set(diag, rc, m->path, 0, 0, "interrupted at t = %.6g (SIGINT or SIGTERM): the %ld rows written so far are kept",
                 t, st->rows_written);
  }
  st->t_reached = t;
  st->status_ok = rc == 0;
  if (integ) {
    ops->stats(integ, st);
    ops->destroy(integ);
  }
  add_stats(st, &before_switch);
  free(work_before);
  free(row.y);
  free(row.yp);
  free(redundant_phi);
  free(y);
  free(yp);
  free(atol);
  fmb_workspace_free(w);
  fmb_vtk_close(vtk);
  if (fmb_csv_close(csv) && !rc) {
    fmb_diag_set(diag, FMB_EXIT_SOLVER, m->path, 0, 0, "could not put the output in place: %s", strerror(errno));
    rc = FMB_EXIT_SOLVER;
    st->status_ok = 0;
  }
  st->cpu_s = (double)(clock() - c0) / CLOCKS_PER_SEC;
  return rc;
}
