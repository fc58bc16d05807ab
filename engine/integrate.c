/* integrate.c — run a model with SUNDIALS IDA (BDF, variable order and step) on the GGL system
 * of system.c, with KLU (default) or SUNDIALS' dense solver for the Newton systems.
 * The default solver eliminates the position rows first (schur.c).
 * The BDF order is capped by the bodies (fmbBodyType.max_bdf_order) or solver.max_order: BDF2 is
 * A-stable, while orders 3-5 have an instability wedge at the imaginary axis that amplifies
 * undamped structural modes (a 16-element beam has modes from 4 to 1e5 rad/s); the error test
 * then forces tiny steps (the omega0 = 1 spin-up took >100 s at order 3, 0.17 s at order 2).
 * lambda and mu are algebraic and excluded from the error test (IDASetId + IDASetSuppressAlg), so
 * the error control acts on positions and velocities only. Output rows are written at the scene's
 * output step; on any failure every row so far is already on disk and the message says when,
 * why, and what to try. */
#include <errno.h>
#include <idas/idas.h> /* IDA plus quadratures (the work outputs); the same BDF integrator */
#include <math.h>
#include <nvector/nvector_serial.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>
#include <sundials/sundials_context.h>
#include <sunlinsol/sunlinsol_dense.h>
#include <sunlinsol/sunlinsol_klu.h>
#include <sunmatrix/sunmatrix_dense.h>
#include <sunmatrix/sunmatrix_sparse.h>
#include <time.h>
#include <unistd.h>

#include "internal.h"


typedef struct {
  const fmbModel* m;
  fmbWorkspace* w;
  void* ida;
  N_Vector ewt;
  char ida_msg[512];
  long fresh_steps, fresh_conv_fails; /* IDA's counters at the last fresh Jacobian */
  long fresh, reused;
  const volatile sig_atomic_t* stop; /* set by the program's SIGINT/SIGTERM handler */
  /* formulation: projected — IDA integrates [q, v] only; the multipliers come from the augmented
     system at each evaluation */
  int projected;
  fmbAugmented* aug;
  double *accel, *lambda; /* nq, nc */
  fmbStats before_reinit; /* IDA's counters up to the last IDAReInit (which zeroes them) */
} RunCtx;

static int stop_requested(const RunCtx* c) { return c->stop && *c->stop; }

/* IDA asks for a new iteration matrix when cj has changed by more than 25 % or after a Newton
   convergence failure. Only the first needs nothing new from the bodies: their K, C, M do not
   depend on cj, so they are reassembled from the last evaluation unless Newton has failed since
   or 50 steps have passed. (A stiff beam under full error control otherwise recomputed its
   finite differences at almost every step: 37,524 Jacobians for 20,358 steps.) */
static int reuse_body_blocks(RunCtx* c) {
  long nst = 0, ncf = 0;
  IDAGetNumSteps(c->ida, &nst);
  IDAGetNumNonlinSolvConvFails(c->ida, &ncf);
  const int reuse = !c->m->fresh_body_blocks && c->fresh > 0 && ncf == c->fresh_conv_fails && nst - c->fresh_steps < 50;
  if (reuse) {
    c->reused++;
  } else {
    c->fresh++;
    c->fresh_steps = nst;
    c->fresh_conv_fails = ncf;
  }
  return reuse;
}

/* the joints' powers, integrated by IDAS alongside the DAE into their work (JOINT.work,
   energy.balance): W_j = int P_j dt to the integrator's order, without a Newton unknown */
static int power_fn(sunrealtype t, N_Vector y, N_Vector yp, N_Vector P, void* ud) {
  (void)yp;
  RunCtx* c = ud;
  double* p = N_VGetArrayPointer(P);
  const double* yv = N_VGetArrayPointer(y);
  const double* lam = yv + 2 * c->m->nq;
  if (c->projected) {
    if (fmb_augmented_solve(c->m, c->w, c->aug, t, yv, yv + c->m->nq, NULL, FMB_MIN_NORM_SHIFT, NULL, c->lambda)) return 1;
    lam = c->lambda;
  }
  for (int j = 0; j < c->m->njoint; ++j) {
    p[j] = fmb_joint_power(c->m, c->w, j, t, yv, yv + c->m->nq, lam);
    if (!isfinite(p[j])) return 1;
  }
  return 0;
}

/* formulation: projected. The index-1 equations q' = v, v' = a(q, v, t) with a and the
   multipliers from the augmented system [M Phi_q^T; Phi_q -eps I] (ic.c): with eps a Tikhonov
   shift the multipliers are the minimum-norm ones and stay defined where Phi_q loses rank, so the
   motion passes singular configurations. Drift off the constraints is removed by projecting at
   every output row (fmb_project_state). */
static int projected_residual_fn(sunrealtype t, N_Vector y, N_Vector yp, N_Vector F, void* ud) {
  RunCtx* c = ud;
  const int nq = c->m->nq;
  const double *q = N_VGetArrayPointer(y), *v = q + nq, *qp = N_VGetArrayPointer(yp), *vp = qp + nq;
  double* f = N_VGetArrayPointer(F);
  for (int i = 0; i < 2 * nq; ++i)
    if (!isfinite(q[i]) || !isfinite(qp[i])) return 1;
  if (fmb_augmented_solve(c->m, c->w, c->aug, t, q, v, NULL, FMB_MIN_NORM_SHIFT, c->accel, c->lambda)) return 1;
  for (int i = 0; i < nq; ++i) {
    f[i] = qp[i] - v[i];
    f[nq + i] = vp[i] - c->accel[i];
  }
  return 0;
}


static void accumulate_counters(void* ida, fmbStats* acc) {
  long v;
  if (IDAGetNumSteps(ida, &v) == IDA_SUCCESS) acc->steps += v;
  if (IDAGetNumResEvals(ida, &v) == IDA_SUCCESS) acc->residuals += v;
  if (IDAGetNumJacEvals(ida, &v) == IDA_SUCCESS) acc->jacobians += v;
  if (IDAGetNumNonlinSolvIters(ida, &v) == IDA_SUCCESS) acc->newton_iters += v;
  if (IDAGetNumErrTestFails(ida, &v) == IDA_SUCCESS) acc->error_test_fails += v;
  if (IDAGetNumNonlinSolvConvFails(ida, &v) == IDA_SUCCESS) acc->conv_fails += v;
}

static int residual_fn(sunrealtype t, N_Vector y, N_Vector yp, N_Vector F, void* ud) {
  RunCtx* c = ud;
  /* an interrupt ends the step in progress: IDA returns the last completed step */
  if (stop_requested(c)) return -1;
  return fmb_system_residual(c->m, c->w, t, N_VGetArrayPointer(y), N_VGetArrayPointer(yp), N_VGetArrayPointer(F));
}

void fmb_sparse_pattern_into(const fmbModel* m, SUNMatrix J) {
  sunindextype* colptr = SUNSparseMatrix_IndexPointers(J);
  sunindextype* rowind = SUNSparseMatrix_IndexValues(J);
  for (int i = 0; i <= m->ny; ++i) colptr[i] = (sunindextype)m->colptr[i];
  for (long k = 0; k < m->nnz; ++k) rowind[k] = (sunindextype)m->rowind[k];
}

static int jacobian_fn(sunrealtype t, sunrealtype cj, N_Vector y, N_Vector yp, N_Vector r, SUNMatrix J, void* ud,
                       N_Vector t1, N_Vector t2, N_Vector t3) {
  (void)r;
  (void)t1;
  (void)t2;
  (void)t3;
  RunCtx* c = ud;
  const fmbModel* m = c->m;
  IDAGetErrWeights(c->ida, c->ewt);
  const int reuse = reuse_body_blocks(c);
  if (m->solver.linear_solver == FMB_LS_DENSE)
    return fmb_system_jacobian(m, c->w, t, cj, N_VGetArrayPointer(y), N_VGetArrayPointer(yp),
                               N_VGetArrayPointer(c->ewt), reuse, NULL, SUNDenseMatrix_Data(J));
  /* the pattern is fixed at load, but IDA zeroes the matrix before each call and SUNDIALS'
     sparse zero clears the index arrays too (copying them out here is measured necessary:
     without it every run fails its first Newton step), O(nnz) next to the assembly */
  fmb_sparse_pattern_into(m, J);
  return fmb_system_jacobian(m, c->w, t, cj, N_VGetArrayPointer(y), N_VGetArrayPointer(yp), N_VGetArrayPointer(c->ewt),
                             reuse, SUNSparseMatrix_Data(J), NULL);
}

static void ida_error_handler(int code, const char* module, const char* function, char* msg, void* ud) {
  (void)code;
  (void)module;
  RunCtx* c = ud;
  snprintf(c->ida_msg, sizeof c->ida_msg, "%s: %s", function, msg);
}

/* What to try after IDA gives up with `flag`. The advice names only causes this scene can have
   (a dead point needs joints) and says when the state has left any physical scale, since
   extreme values, not the mechanism's geometry, then explain a singular matrix. */
static void failure_advice(const fmbModel* m, int flag, double ymax, char* buf, size_t len) {
  const int joints = m->nc > 0;
  if (ymax > 1e100 && (flag == IDA_CONV_FAIL || flag == IDA_LSETUP_FAIL || flag == IDA_LSOLVE_FAIL || flag == IDA_ERR_FAIL)) {
    snprintf(buf, len,
             "the solution reached a magnitude of %.3g: the state is blowing up or a parameter is far beyond a physical "
             "scale (check masses, stiffnesses, forces and their units)",
             ymax);
    return;
  }
  const char* s = "the integrator stopped";
  switch (flag) {
    case IDA_TOO_MUCH_WORK:
      s = "too many steps between two outputs: the problem is very stiff or changing very fast here. "
          "Try a larger solver.max_steps, a looser rtol, or check for unphysical parameters";
      break;
    case IDA_TOO_MUCH_ACC: s = "the tolerances are tighter than machine precision allows: loosen rtol/atol"; break;
    case IDA_ERR_FAIL:
      s = "the error test failed repeatedly down to the minimum step: the solution is blowing up or jumps "
          "(an unstable model or a discontinuous input)";
      break;
    case IDA_CONV_FAIL:
      s = joints ? "Newton's method failed repeatedly: the mechanism may be passing a singular configuration or the model "
                   "has become unstable. Try a smaller solver.max_step or a tighter rtol"
                 : "Newton's method failed repeatedly: the model has become unstable or too stiff for the step. Try a "
                   "smaller solver.max_step or a tighter rtol";
      break;
    case IDA_LSETUP_FAIL:
      s = joints ? "the Newton matrix could not be factorized (it is singular): a singular mechanism configuration "
                   "(a dead point, where the joints no longer fix the motion) or a mass matrix that lost definiteness. "
                   "Check the mechanism's geometry; a drive that forces it through a dead point cannot be integrated"
                 : "the Newton matrix could not be factorized (it is singular): a mass matrix that lost definiteness";
      break;
    case IDA_LSOLVE_FAIL: s = "the linear solver failed: the Newton matrix is singular or ill-conditioned"; break;
    case IDA_REP_RES_ERR:
      s = "the equations kept returning non-finite values: the state is blowing up. Check parameters and initial values";
      break;
    case IDA_RES_FAIL: s = "a plugin could not evaluate its equations"; break;
    default: break;
  }
  snprintf(buf, len, "%s", s);
}

void fmb_print_stats(const fmbStats* s, FILE* f) {
  if (!s || !f) return;
  fprintf(f,
          "stats: status=%s t_reached=%.10g steps=%ld residuals=%ld jacobians=%ld newton_iters=%ld error_test_fails=%ld "
          "conv_fails=%ld jacobians_reused=%ld cpu_s=%.4f\n",
          s->status_ok ? "ok" : s->interrupted ? "interrupted" : "failed", s->t_reached, s->steps, s->residuals, s->jacobians, s->newton_iters,
          s->error_test_fails, s->conv_fails, s->jacobians_reused, s->cpu_s);
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

static void progress_update(Progress* pr, const fmbModel* m, double t, void* ida) {
  if (!pr->on) return;
  const double now = wall_seconds(), elapsed = now - pr->start;
  if (elapsed < pr->after || now - pr->last < (pr->tty ? 0.2 : 1.0)) return;
  long steps = 0;
  if (ida) IDAGetNumSteps(ida, &steps);
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

/* `error_control: full` on a body that prefers positions (a finite-element beam) is right for
   smooth prescribed motion and a trap after any sudden load: the undamped stiff modes' velocities
   then set the step (a user's hub spin-up took 394k steps, 850x the positions run). Once per run,
   at an output time where the run is on course for many steps (over 1e5, or 20x its rate over
   the first 2 % of the run) and the velocities' weighted local error estimate exceeds 30x the
   positions', say so and what to set. */
typedef struct {
  double t_early;   /* simulated time at which the early rate was taken (0: not yet) */
  double rate_early; /* steps per simulated second up to then */
  long steps_last;
  double t_last;
  int warned;
} StepWatch;

static void watch_step_rate(const fmbModel* m, void* ida, N_Vector ele, N_Vector ewt, double t, StepWatch* sw) {
  const fmbSolverSettings* so = &m->solver;
  long nst = 0;
  IDAGetNumSteps(ida, &nst);
  const double span = so->t_end - so->t0, elapsed = t - so->t0;
  if (sw->t_early == 0.0 && elapsed >= 0.02 * span) {
    sw->t_early = elapsed;
    sw->rate_early = (double)nst / elapsed;
  }
  const double rate = (double)(nst - sw->steps_last) / fmax(t - sw->t_last, 1e-300);
  sw->steps_last = nst;
  sw->t_last = t;
  if (sw->warned || so->positions_only || !m->bodies_prefer_positions || elapsed < 0.01 * span) return;
  const double projected = (double)nst + rate * (so->t_end - t);
  if (projected < 1e5 && !(sw->t_early > 0.0 && rate > 20.0 * sw->rate_early && nst > 2000)) return;
  if (IDAGetEstLocalErrors(ida, ele) != IDA_SUCCESS || IDAGetErrWeights(ida, ewt) != IDA_SUCCESS) return;
  const double *e = N_VGetArrayPointer(ele), *w = N_VGetArrayPointer(ewt);
  double eq = 0.0, ev = 0.0;
  for (int i = 0; i < m->nq; ++i) {
    eq += (e[i] * w[i]) * (e[i] * w[i]);
    ev += (e[m->nq + i] * w[m->nq + i]) * (e[m->nq + i] * w[m->nq + i]);
  }
  if (ev <= 900.0 * eq) return; /* RMS ratio 30 */
  sw->warned = 1;
  fprintf(stderr, /* on a terminal, over the progress line (it is redrawn at its next update) */
          "%swarning: t = %.6g: %ld steps so far, %.3g per simulated second (on course for %.3g): the velocities set the "
          "step (their local error is %.0fx the positions'), i.e. undamped stiff modes that the positions do not "
          "notice. error_control: full suits smooth prescribed motion only; set solver.error_control: positions "
          "(the default for beams) after a sudden load (docs/performance.md)\n",
          isatty(fileno(stderr)) ? "\r\033[K" : "", t, nst, rate, projected, sqrt(ev / fmax(eq, 1e-300)));
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
  if (vtk_dir && !(vtk = fmb_vtk_open(m, vtk_dir, diag))) {
    fmb_csv_close(csv);
    return diag->code ? diag->code : FMB_EXIT_SOLVER;
  }
  Progress progress = {opt && opt->progress && !opt->quiet, isatty(fileno(stderr)), 0, opt ? opt->progress_after_s : 0.0,
                       wall_seconds(), 0.0};

  RunCtx ctx;
  memset(&ctx, 0, sizeof ctx);
  ctx.m = m;
  ctx.stop = opt ? opt->stop : NULL;
  SUNContext sun = NULL;
  N_Vector y = NULL, yp = NULL, id = NULL, atol = NULL, work = NULL, workatol = NULL, watch_ele = NULL;
  N_Vector yi = NULL, ypi = NULL, idi = NULL; /* what IDA integrates: y, yp, or [q, v] (projected) */
  double* redundant_phi = NULL; /* the redundant rows' residuals, checked at each row */
  SUNMatrix A = NULL;
  SUNLinearSolver LS = NULL;
  void* ida = NULL;
  int rc = 0;
  double t = m->solver.t0;

  ctx.w = fmb_workspace_new(m);
  if (!ctx.w || SUNContext_Create(NULL, &sun) != 0) {
    fmb_diag_set(diag, FMB_EXIT_SOLVER, m->path, 0, 0, "out of memory setting up the integrator");
    rc = FMB_EXIT_SOLVER;
    goto done;
  }
  y = N_VNew_Serial(ny, sun);
  yp = N_VNew_Serial(ny, sun);
  id = N_VNew_Serial(ny, sun);
  ctx.ewt = N_VNew_Serial(ny, sun);
  /* our vector arithmetic (vector.c: Debian's SUNDIALS is built unoptimized); IDA clones its own
     vectors from y, so they inherit it */
  if (y) fmb_vector_use_fast_ops(y);
  if (!y || !yp || !id || !ctx.ewt) {
    fmb_diag_set(diag, FMB_EXIT_SOLVER, m->path, 0, 0, "out of memory setting up the integrator");
    rc = FMB_EXIT_SOLVER;
    goto done;
  }
  rc = fmb_initial_conditions(m, ctx.w, N_VGetArrayPointer(y), N_VGetArrayPointer(yp), st, diag);
  if (rc) goto done;
  if (!opt || !opt->quiet)
    fprintf(stderr, "initial conditions: position correction %.3g, velocity correction %.3g\n",
            st->ic_position_correction, st->ic_velocity_correction);
  int nredundant = 0;
  const unsigned char* redundant = fmb_workspace_redundant(ctx.w, &nredundant);
  if (nredundant) redundant_phi = calloc((size_t)m->nc, sizeof(double));
  if (nredundant && (!opt || !opt->quiet)) {
    char rows[600];
    fmb_name_rows(m, redundant, rows, sizeof rows);
    fprintf(stderr, "redundant constraints: %s repeat%s the other joints' equations: left out of the equations, their "
            "share of the reactions by the minimum-norm rule\n", rows, nredundant == 1 ? "s" : "");
  }

  int bad = fmb_check_mass(m, ctx.w, t, N_VGetArrayPointer(y), N_VGetArrayPointer(y) + m->nq, 0.0);
  if (bad) {
    mass_failure(m, bad, t, diag);
    rc = FMB_EXIT_SOLVER;
    goto done;
  }
  if (m->need_work) { /* the force elements' potential at t0 enters energy.balance */
    fmbEnergy e0;
    fmb_energy(m, ctx.w, t, N_VGetArrayPointer(y), N_VGetArrayPointer(y) + m->nq, &e0);
    *fmb_workspace_spring_energy0(ctx.w) = e0.spring;
  }
  if (stop_requested(&ctx)) goto done;
  if (fmb_csv_header(csv, m)) {
    row_failed(m, -1, t, diag);
    rc = FMB_EXIT_SOLVER;
    goto done;
  }
  if (row_failed(m, write_outputs(csv, vtk, m, ctx.w, t, N_VGetArrayPointer(y), N_VGetArrayPointer(yp)), t, diag)) {
    rc = FMB_EXIT_SOLVER;
    goto done;
  }
  st->rows_written = 1;

  ctx.projected = m->solver.formulation == FMB_FORM_PROJECTED;
  const int nyi = ctx.projected ? 2 * m->nq : ny;
  if (ctx.projected) {
    yi = N_VNew_Serial(nyi, sun);
    ypi = N_VNew_Serial(nyi, sun);
    ctx.aug = fmb_augmented_new(m);
    ctx.accel = calloc((size_t)m->nq + 1, sizeof(double));
    ctx.lambda = calloc((size_t)m->nc + 1, sizeof(double));
    if (!yi || !ypi || !ctx.aug || !ctx.accel || !ctx.lambda) {
      fmb_diag_set(diag, FMB_EXIT_SOLVER, m->path, 0, 0, "out of memory setting up the integrator");
      rc = FMB_EXIT_SOLVER;
      goto done;
    }
    memcpy(N_VGetArrayPointer(yi), N_VGetArrayPointer(y), sizeof(double) * (size_t)nyi);
    memcpy(N_VGetArrayPointer(ypi), N_VGetArrayPointer(yp), sizeof(double) * (size_t)nyi);
    fmb_vector_use_fast_ops(yi);
  } else {
    yi = y;
    ypi = yp;
  }
  /* q and v are differential; lambda and mu algebraic. The multipliers of an index-2 system
     carry roundoff of order eps/h^2 (Hairer & Wanner VII.3), so weighing them like positions in
     IDA's Newton test makes small steps fail: they get an absolute tolerance so large that only
     q and v decide convergence. They are already out of the error test (suppressalg). */
  double* idv = NULL;
  atol = N_VNew_Serial(nyi, sun);
  idi = ctx.projected ? N_VNew_Serial(nyi, sun) : id;
  if (!atol || !idi) {
    fmb_diag_set(diag, FMB_EXIT_SOLVER, m->path, 0, 0, "out of memory setting up the integrator");
    rc = FMB_EXIT_SOLVER;
    goto done;
  }
  double* atv = N_VGetArrayPointer(atol);
  /* solver.error_control = positions also leaves the velocities out of the error test: after a
     sudden load an undamped finite-element model carries every mode, and a mode's velocity
     amplitude falls only like 1/omega (its displacement like 1/omega^2), so controlling
     velocities makes the steps resolve modes at 1e5 rad/s that positions do not notice. */
  const int ndiff = m->solver.positions_only ? m->nq : 2 * m->nq;
  idv = N_VGetArrayPointer(idi);
  for (int i = 0; i < nyi; ++i) {
    idv[i] = i < ndiff ? 1.0 : 0.0;
    atv[i] = i < 2 * m->nq ? m->solver.atol : 1e30;
  }
  /* a body that gives its coordinates' length scales (fmbBodyType.length_scale) gets atol in
     metres of motion: atol / scale for a coordinate and its velocity (atv[nq + i]) */
  for (int b = 1; b < m->nbody; ++b) {
    const fmbBodyInst* bi = &m->body[b];
    if (!bi->type->length_scale) continue;
    bi->type->length_scale(bi->self, atv + m->nq + bi->qadr); /* the velocity slot as scratch */
    for (int i = bi->qadr; i < bi->qadr + bi->nq; ++i) {
      const double scale = atv[m->nq + i] > 0.0 ? atv[m->nq + i] : 1.0;
      atv[i] = atv[m->nq + i] = m->solver.atol / scale;
    }
  }
  ida = IDACreate(sun);
  ctx.ida = ida;
  if (!ida || IDAInit(ida, ctx.projected ? projected_residual_fn : residual_fn, t, yi, ypi) != IDA_SUCCESS ||
      IDASVtolerances(ida, m->solver.rtol, atol) != IDA_SUCCESS || IDASetUserData(ida, &ctx) != IDA_SUCCESS ||
      IDASetErrHandlerFn(ida, ida_error_handler, &ctx) != IDA_SUCCESS || IDASetId(ida, idi) != IDA_SUCCESS ||
      IDASetSuppressAlg(ida, SUNTRUE) != IDA_SUCCESS || IDASetMaxOrd(ida, m->solver.max_order) != IDA_SUCCESS ||
      IDASetMaxNumSteps(ida, m->solver.max_steps_per_output) != IDA_SUCCESS ||
      (m->solver.max_step > 0 && IDASetMaxStep(ida, m->solver.max_step) != IDA_SUCCESS) ||
      IDASetMinStep(ida, m->solver.min_step) != IDA_SUCCESS) {
    fmb_diag_set(diag, FMB_EXIT_SOLVER, m->path, 0, 0, "could not set up IDA: %s", ctx.ida_msg);
    rc = FMB_EXIT_SOLVER;
    goto done;
  }
  if (ctx.projected) { /* small dense systems; IDA's difference-quotient Jacobian */
    A = SUNDenseMatrix(nyi, nyi, sun);
    LS = A ? SUNLinSol_Dense(yi, A, sun) : NULL;
  } else if (m->solver.linear_solver == FMB_LS_DENSE) {
    A = SUNDenseMatrix(ny, ny, sun);
    LS = A ? SUNLinSol_Dense(y, A, sun) : NULL;
  } else {
    A = SUNSparseMatrix(ny, ny, m->nnz, CSC_MAT, sun);
    if (A) LS = m->solver.linear_solver == FMB_LS_KLU_FULL ? SUNLinSol_KLU(y, A, sun) : fmb_schur_klu_new(m, sun);
  }
  if (!A || !LS || IDASetLinearSolver(ida, LS, A) != IDA_SUCCESS ||
      (!ctx.projected && IDASetJacFn(ida, jacobian_fn) != IDA_SUCCESS)) {
    fmb_diag_set(diag, FMB_EXIT_SOLVER, m->path, 0, 0, "could not set up the linear solver");
    rc = FMB_EXIT_SOLVER;
    goto done;
  }
  if (m->need_work && m->njoint > 0) {
    /* Applied forces' work is in the error test: a load law with a kink (ramp, table) is
       otherwise integrated across the kink by one polynomial (2.7e-2 J error against the kinetic
       energy, tests/mechanisms/test_loads.c). A constraint's work is not: its power goes through
       the multipliers, whose roundoff grows like eps/h^2, and in the test it cut a slider's steps
       200-fold (359 -> 66,935); outside it the drives' work matches the kinetic energy gained to
       3e-7 J at rtol 1e-9. */
    work = N_VNew_Serial(m->njoint, sun);
    workatol = N_VNew_Serial(m->njoint, sun);
    if (!work || !workatol) {
      fmb_diag_set(diag, FMB_EXIT_SOLVER, m->path, 0, 0, "out of memory setting up the integrator");
      rc = FMB_EXIT_SOLVER;
      goto done;
    }
    N_VConst(0.0, work);
    for (int j = 0; j < m->njoint; ++j) N_VGetArrayPointer(workatol)[j] = m->joint[j].nrows > 0 ? 1e30 : m->solver.atol;
    if (IDAQuadInit(ida, power_fn, work) != IDA_SUCCESS || IDASetQuadErrCon(ida, SUNTRUE) != IDA_SUCCESS ||
        IDAQuadSVtolerances(ida, m->solver.rtol, workatol) != IDA_SUCCESS) {
      fmb_diag_set(diag, FMB_EXIT_SOLVER, m->path, 0, 0, "could not set up the work integrals: %s", ctx.ida_msg);
      rc = FMB_EXIT_SOLVER;
      goto done;
    }
  }

  const double dt = m->solver.output_step, t_end = m->solver.t_end, t0 = m->solver.t0;
  StepWatch watch = {0.0, 0.0, 0, t0, 0};
  /* NULL: no watch (the projected formulation integrates a shorter vector) */
  watch_ele = ctx.projected ? NULL : N_VClone(y);
  const long nout = (long)ceil((t_end - t0) / dt - 1e-9);
  for (long k = 1; k <= nout; ++k) {
    double tout = k == nout ? t_end : t0 + (double)k * dt;
    double tret = t;
    int flag = IDASolve(ida, tout, &tret, yi, ypi, IDA_NORMAL);
    if (ctx.projected) { /* back onto the constraints, with the multipliers for the outputs */
      double* yv = N_VGetArrayPointer(y);
      double* ypv = N_VGetArrayPointer(yp);
      memcpy(yv, N_VGetArrayPointer(yi), sizeof(double) * (size_t)nyi);
      if (flag >= 0) {
        /* every row (measured on scenes/parallelogram.yaml: projecting only once the drift exceeds
           the tolerance, or Baumgarte's stabilization instead, let the linkage slip onto the
           crossed branch at a flat passage or made the error erratic in alpha; every row gives
           errors that fall with rtol: 4.7e-5, 3.4e-6, 2.1e-7 rad at rtol 1e-8, 1e-9, 1e-10) */
        if (fmb_project_state(m, ctx.w, ctx.aug, tret, yv, yv + m->nq) ||
            fmb_augmented_solve(m, ctx.w, ctx.aug, tret, yv, yv + m->nq, NULL, FMB_MIN_NORM_SHIFT, ypv + m->nq, yv + 2 * m->nq))
          flag = IDA_RES_FAIL;
        memcpy(ypv, yv + m->nq, sizeof(double) * (size_t)m->nq);
        memcpy(N_VGetArrayPointer(yi), yv, sizeof(double) * (size_t)nyi);
        memcpy(N_VGetArrayPointer(ypi), ypv, sizeof(double) * (size_t)nyi);
        accumulate_counters(ida, &ctx.before_reinit);
        if (flag >= 0 && IDAReInit(ida, tret, yi, ypi) != IDA_SUCCESS) flag = IDA_RES_FAIL;
      }
    }
    if (flag < 0 && stop_requested(&ctx)) {
      t = tret;
      break;
    }
    if (flag < 0) {
      t = tret;
      bad = fmb_check_mass(m, ctx.w, tret, N_VGetArrayPointer(y), N_VGetArrayPointer(y) + m->nq, 1e-5);
      if (bad) {
        mass_failure(m, bad, tret, diag);
      } else {
        double hcur = 0.0, ymax = 0.0;
        IDAGetCurrentStep(ida, &hcur);
        const double* yv = N_VGetArrayPointer(y);
        for (int i = 0; i < ny; ++i) ymax = fmax(ymax, fabs(yv[i]));
        char advice[600], floor_note[200] = "";
        failure_advice(m, flag, ymax, advice, sizeof advice);
        /* a stop at the step floor names the key that sets it and where its value came from */
        if (fabs(hcur) <= 1.5 * m->solver.min_step)
          snprintf(floor_note, sizeof floor_note, "; the step reached solver.min_step = %.3g (%s)", m->solver.min_step,
                   m->solver.min_step_given ? "as given" : "the default, 1e-12 x (t_end - t0)");
        char* flag_name = IDAGetReturnFlagName(flag); /* allocated by SUNDIALS */
        fmb_diag_set(diag, FMB_EXIT_SOLVER, m->path, 0, 0, "solver failed at t = %.6g (step size %.3g): %s%s [IDA %s: %s]",
                     tret, hcur, advice, floor_note, flag_name ? flag_name : "?", ctx.ida_msg);
        free(flag_name);
      }
      rc = FMB_EXIT_SOLVER;
      break;
    }
    t = tret;
    if (work) {
      double tq = t;
      IDAGetQuad(ida, &tq, work);
      if (ctx.projected) IDAQuadReInit(ida, work); /* IDAReInit restarted the integration */
      memcpy(fmb_workspace_work(ctx.w), N_VGetArrayPointer(work), sizeof(double) * (size_t)m->njoint);
    }
    if (invalid_state(m, t, N_VGetArrayPointer(y), diag) ||
        (redundant_phi && redundant_row_broken(m, ctx.w, t, N_VGetArrayPointer(y), redundant_phi, diag))) {
      rc = FMB_EXIT_SOLVER;
      break;
    }
    bad = fmb_check_mass(m, ctx.w, t, N_VGetArrayPointer(y), N_VGetArrayPointer(y) + m->nq, 0.0);
    if (bad) {
      mass_failure(m, bad, t, diag);
      rc = FMB_EXIT_SOLVER;
      break;
    }
    if (row_failed(m, write_outputs(csv, vtk, m, ctx.w, t, N_VGetArrayPointer(y), N_VGetArrayPointer(yp)), t, diag)) {
      rc = FMB_EXIT_SOLVER;
      break;
    }
    st->rows_written++;
    if (watch_ele) watch_step_rate(m, ida, watch_ele, ctx.ewt, t, &watch);
    progress_update(&progress, m, t, ida);
    if (stop_requested(&ctx)) break;
  }
  progress_end(&progress);

done:
  if (stop_requested(&ctx) && !rc) {
    st->interrupted = 1;
    rc = FMB_EXIT_INTERRUPTED;
    fmb_diag_set(diag, rc, m->path, 0, 0, "interrupted at t = %.6g (SIGINT or SIGTERM): the %ld rows written so far are kept",
                 t, st->rows_written);
  }
  st->t_reached = t;
  st->status_ok = rc == 0;
  if (ida) {
    fmbStats acc = ctx.before_reinit; /* zero unless the projected formulation restarted IDA */
    accumulate_counters(ida, &acc);
    st->steps = acc.steps;
    st->residuals = acc.residuals;
    st->jacobians = acc.jacobians;
    st->newton_iters = acc.newton_iters;
    st->error_test_fails = acc.error_test_fails;
    st->conv_fails = acc.conv_fails;
    st->jacobians_reused = ctx.reused;
    IDAFree(&ida);
  }
  if (LS) SUNLinSolFree(LS);
  if (A) SUNMatDestroy(A);
  if (y) N_VDestroy(y);
  if (yp) N_VDestroy(yp);
  if (id) N_VDestroy(id);
  if (atol) N_VDestroy(atol);
  if (watch_ele) N_VDestroy(watch_ele);
  if (work) N_VDestroy(work);
  if (workatol) N_VDestroy(workatol);
  if (ctx.projected) {
    if (yi) N_VDestroy(yi);
    if (ypi) N_VDestroy(ypi);
    if (idi) N_VDestroy(idi);
  }
  fmb_augmented_free(ctx.aug);
  free(ctx.accel);
  free(ctx.lambda);
  free(redundant_phi);
  if (ctx.ewt) N_VDestroy(ctx.ewt);
  if (sun) SUNContext_Free(&sun);
  fmb_workspace_free(ctx.w);
  fmb_vtk_close(vtk);
  if (fmb_csv_close(csv) && !rc) {
    fmb_diag_set(diag, FMB_EXIT_SOLVER, m->path, 0, 0, "could not put the output in place: %s", strerror(errno));
    rc = FMB_EXIT_SOLVER;
    st->status_ok = 0;
  }
  st->cpu_s = (double)(clock() - c0) / CLOCKS_PER_SEC;
  return rc;
}
