/* integrator_ida.c — SUNDIALS IDA (BDF, variable order and step) on the GGL system of system.c,
 * the rigid mechanisms' backend under solver.integrator: auto (integrator_select.c), with KLU
 * (default; the position rows eliminated first, schur.c), KLU on the whole matrix, or SUNDIALS'
 * dense solver for the Newton systems.
 * The BDF order is capped by the bodies (fmbBodyType.max_bdf_order) or solver.max_order: BDF2 is
 * A-stable, while orders 3-5 have an instability wedge at the imaginary axis that amplifies
 * undamped structural modes (a 16-element beam has modes from 4 to 1e5 rad/s); the error test
 * then forces tiny steps (the omega0 = 1 spin-up took >100 s at order 3, 0.17 s at order 2).
 * lambda and mu are algebraic and excluded from the error test (IDASetId + IDASetSuppressAlg), so
 * the error control acts on positions and velocities only. */
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

#include "integrator.h"

typedef struct {
  double t_early;    /* simulated time at which the early rate was taken (0: not yet) */
  double rate_early; /* steps per simulated second up to then */
  long steps_last;
  double t_last;
  int warned;
} StepWatch;

typedef struct {
  const fmbModel* m;
  fmbWorkspace* w;
  const volatile sig_atomic_t* stop;
  SUNContext sun;
  void* ida;
  N_Vector y, yp, id, atol, ewt, work, workatol, watch_ele;
  SUNMatrix A;
  SUNLinearSolver LS;
  char ida_msg[512];
  long fresh_steps, fresh_conv_fails; /* IDA's counters at the last fresh Jacobian */
  long fresh, reused;
  StepWatch watch;
  int fell_back;          /* the reduced Newton solve failed once: KLU on the whole matrix since */
  fmbStats before_reinit; /* IDA's counters up to the last IDAReInit (fallback, ida_reinit: it zeroes them) */
} IdaRun;

static int stop_requested(const IdaRun* c) { return fmb_stop_requested(c->stop); }

/* IDA asks for a new iteration matrix when cj has changed by more than 25 % or after a Newton
   convergence failure. Only the first needs nothing new from the bodies: their K, C, M do not
   depend on cj, so they are reassembled from the last evaluation unless Newton has failed since
   or 50 steps have passed. (A stiff beam under full error control otherwise recomputed its
   finite differences at almost every step: 37,524 Jacobians for 20,358 steps.) */
static int reuse_body_blocks(IdaRun* c) {
  long nst = 0, ncf = 0;
  IDAGetNumSteps(c->ida, &nst);
  IDAGetNumNonlinSolvConvFails(c->ida, &ncf);
  nst += c->before_reinit.steps; /* the run's, across an IDAReInit (ida_reinit) */
  ncf += c->before_reinit.conv_fails;
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
  IdaRun* c = ud;
  double* p = N_VGetArrayPointer(P);
  const double* yv = N_VGetArrayPointer(y);
  for (int j = 0; j < c->m->njoint; ++j) {
    p[j] = fmb_joint_power(c->m, c->w, j, t, yv, yv + c->m->nq, yv + 2 * c->m->nq);
    if (!isfinite(p[j])) return 1;
  }
  return 0;
}

static void add_counters(void* ida, fmbStats* acc) {
  long v;
  if (IDAGetNumSteps(ida, &v) == IDA_SUCCESS) acc->steps += v;
  if (IDAGetNumResEvals(ida, &v) == IDA_SUCCESS) acc->residuals += v;
  if (IDAGetNumJacEvals(ida, &v) == IDA_SUCCESS) acc->jacobians += v;
  if (IDAGetNumNonlinSolvIters(ida, &v) == IDA_SUCCESS) acc->newton_iters += v;
  if (IDAGetNumErrTestFails(ida, &v) == IDA_SUCCESS) acc->error_test_fails += v;
  if (IDAGetNumNonlinSolvConvFails(ida, &v) == IDA_SUCCESS) acc->conv_fails += v;
}

static int residual_fn(sunrealtype t, N_Vector y, N_Vector yp, N_Vector F, void* ud) {
  IdaRun* c = ud;
  /* an interrupt ends the step in progress: IDA returns the last completed step */
  if (stop_requested(c)) return -1;
  return fmb_system_residual_eliminated(c->m, c->w, t, N_VGetArrayPointer(y), N_VGetArrayPointer(yp),
                                        N_VGetArrayPointer(F));
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
  (void)t2;
  (void)t3;
  IdaRun* c = ud;
  const fmbModel* m = c->m;
  IDAGetErrWeights(c->ida, c->ewt);
  if (m->nz > 0) { /* the auxiliary unknowns, placeholders in the residual, made consistent (system.c) */
    N_VScale(1.0, y, t1);
    if (fmb_system_aux_eliminate(m, c->w, N_VGetArrayPointer(t1), N_VGetArrayPointer(yp))) return 1;
    y = t1;
  }
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
  IdaRun* c = ud;
  snprintf(c->ida_msg, sizeof c->ida_msg, "%s: %s", function, msg);
}

/* What to try after IDA gives up with `flag`. The advice names only causes this scene can have
   (a dead point needs joints) and says when the state has left any physical scale, since
   extreme values, not the mechanism's geometry, then explain a singular matrix. */
static void failure_advice(const fmbModel* m, int flag, double ymax, char* buf, size_t len) {
  const int joints = m->nc > 0;
  if (ymax > 1e100 && flag == IDA_REP_RES_ERR) { /* both: what happened, and the likely cause */
    snprintf(buf, len,
             "the equations kept returning non-finite values: the state is blowing up. Check parameters and initial "
             "values: the state reached a magnitude of %.3g, a parameter is far beyond a physical scale (check masses, "
             "stiffnesses, forces and their units)",
             ymax);
    return;
  }
  if (ymax > 1e100 &&
      (flag == IDA_CONV_FAIL || flag == IDA_LSETUP_FAIL || flag == IDA_LSOLVE_FAIL || flag == IDA_ERR_FAIL)) {
    snprintf(
        buf, len,
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
      s = joints
              ? "Newton's method failed repeatedly: the mechanism may be passing a singular configuration or the model "
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
      s = "the equations kept returning non-finite values: the state is blowing up. Check parameters and initial "
          "values";
      break;
    case IDA_RES_FAIL: s = "a plugin could not evaluate its equations"; break;
    default: break;
  }
  snprintf(buf, len, "%s", s);
}

/* `error_control: full` on a body that prefers positions (a finite-element beam) is right for
   smooth prescribed motion and a trap after any sudden load: the undamped stiff modes' velocities
   then set the step (a user's hub spin-up took 394k steps, 850x the positions run). Once per run,
   at an output time where the run is on course for many steps (over 1e5, or 20x its rate over
   the first 2 % of the run) and the velocities' weighted local error estimate exceeds 30x the
   positions', say so and what to set. */

static void watch_step_rate(const fmbModel* m, fmbWorkspace* w_run, void* ida, long steps_before, N_Vector ele,
                            N_Vector ewt, double t, StepWatch* sw) {
  const fmbSolverSettings* so = &m->solver;
  long nst = 0;
  IDAGetNumSteps(ida, &nst);
  nst += steps_before; /* the run's steps, also across an IDAReInit (ida_reinit) */
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
  fmb_warn(w_run,
           "warning: t = %.6g: %ld steps so far, %.3g per simulated second (on course for %.3g): the velocities "
           "set the step (their local error is %.0fx the positions'), i.e. undamped stiff modes that the positions do "
           "not notice. error_control: full suits smooth prescribed motion only; set solver.error_control: positions "
           "(the default for beams) after a sudden load (docs/performance.md)",
           t, nst, rate, projected, sqrt(ev / fmax(eq, 1e-300)));
}

static void ida_destroy(void* self) {
  IdaRun* c = self;
  if (!c) return;
  if (c->ida) IDAFree(&c->ida);
  if (c->LS) SUNLinSolFree(c->LS);
  if (c->A) SUNMatDestroy(c->A);
  N_Vector* vs[] = {&c->y, &c->yp, &c->id, &c->atol, &c->ewt, &c->work, &c->workatol, &c->watch_ele};
  for (size_t i = 0; i < sizeof vs / sizeof vs[0]; ++i)
    if (*vs[i]) N_VDestroy(*vs[i]);
  if (c->sun) SUNContext_Free(&c->sun);
  free(c);
}

static void* ida_create(const fmbIntegratorSetup* s, double t0, const double* y0, const double* yp0, fmbDiag* diag) {
  const fmbModel* m = s->m;
  const int ny = m->ny;
  IdaRun* c = calloc(1, sizeof *c);
  if (!c || SUNContext_Create(NULL, &c->sun) != 0) goto oom;
  c->m = m;
  c->w = s->w;
  c->stop = s->stop;
  c->watch.t_last = t0;
  c->y = N_VNew_Serial(ny, c->sun);
  c->yp = N_VNew_Serial(ny, c->sun);
  c->id = N_VNew_Serial(ny, c->sun);
  c->atol = N_VNew_Serial(ny, c->sun);
  c->ewt = N_VNew_Serial(ny, c->sun);
  if (!c->y || !c->yp || !c->id || !c->atol || !c->ewt) goto oom;
  /* our vector arithmetic (vector.c: Debian's SUNDIALS is built unoptimized); IDA clones its own
     vectors from y, so they inherit it */
  fmb_vector_use_fast_ops(c->y);
  memcpy(N_VGetArrayPointer(c->y), y0, sizeof(double) * (size_t)ny);
  memcpy(N_VGetArrayPointer(c->yp), yp0, sizeof(double) * (size_t)ny);
  memcpy(N_VGetArrayPointer(c->atol), s->atol, sizeof(double) * (size_t)ny);
  /* q and v are differential, lambda and mu algebraic (they carry an absolute tolerance so large
     that only q and v decide Newton's convergence, integrate.c). solver.error_control = positions
     also leaves the velocities out of the error test: after a sudden load an undamped
     finite-element model carries every mode, and a mode's velocity amplitude falls only like
     1/omega (its displacement like 1/omega^2), so controlling velocities makes the steps resolve
     modes at 1e5 rad/s that positions do not notice. */
  const int ndiff = m->solver.positions_only ? m->nq : 2 * m->nq;
  double* idv = N_VGetArrayPointer(c->id);
  for (int i = 0; i < ny; ++i) idv[i] = i < ndiff ? 1.0 : 0.0;
  c->ida = IDACreate(c->sun);
  if (!c->ida || IDAInit(c->ida, residual_fn, t0, c->y, c->yp) != IDA_SUCCESS ||
      IDASVtolerances(c->ida, m->solver.rtol, c->atol) != IDA_SUCCESS || IDASetUserData(c->ida, c) != IDA_SUCCESS ||
      IDASetErrHandlerFn(c->ida, ida_error_handler, c) != IDA_SUCCESS || IDASetId(c->ida, c->id) != IDA_SUCCESS ||
      IDASetSuppressAlg(c->ida, SUNTRUE) != IDA_SUCCESS || IDASetMaxOrd(c->ida, m->solver.max_order) != IDA_SUCCESS ||
      IDASetMaxNumSteps(c->ida, m->solver.max_steps_per_output) != IDA_SUCCESS ||
      (m->solver.max_step > 0 && IDASetMaxStep(c->ida, m->solver.max_step) != IDA_SUCCESS) ||
      IDASetMinStep(c->ida, m->solver.min_step) != IDA_SUCCESS) {
    fmb_diag_set(diag, FMB_EXIT_SOLVER, m->path, 0, 0, "could not set up IDA: %s", c->ida_msg);
    ida_destroy(c);
    return NULL;
  }
  if (m->solver.linear_solver == FMB_LS_DENSE) {
    c->A = SUNDenseMatrix(ny, ny, c->sun);
    c->LS = c->A ? SUNLinSol_Dense(c->y, c->A, c->sun) : NULL;
  } else {
    c->A = SUNSparseMatrix(ny, ny, m->nnz, CSC_MAT, c->sun);
    if (c->A)
      c->LS =
          m->solver.linear_solver == FMB_LS_KLU_FULL ? SUNLinSol_KLU(c->y, c->A, c->sun) : fmb_schur_klu_new(m, c->sun);
  }
  if (!c->A || !c->LS || IDASetLinearSolver(c->ida, c->LS, c->A) != IDA_SUCCESS ||
      IDASetJacFn(c->ida, jacobian_fn) != IDA_SUCCESS) {
    fmb_diag_set(diag, FMB_EXIT_SOLVER, m->path, 0, 0, "could not set up the linear solver");
    ida_destroy(c);
    return NULL;
  }
  if (m->need_work && m->njoint > 0) {
    /* Applied forces' work is in the error test: a load law with a kink (ramp, table) is
       otherwise integrated across the kink by one polynomial (2.7e-2 J error against the kinetic
       energy, tests/mechanisms/test_loads.c). A constraint's work is not: its power goes through
       the multipliers, whose roundoff grows like eps/h^2, and in the test it cut a slider's steps
       200-fold (359 -> 66,935); outside it the drives' work matches the kinetic energy gained to
       3e-7 J at rtol 1e-9. */
    c->work = N_VNew_Serial(m->njoint, c->sun);
    c->workatol = N_VNew_Serial(m->njoint, c->sun);
    if (!c->work || !c->workatol) goto oom;
    N_VConst(0.0, c->work);
    for (int j = 0; j < m->njoint; ++j)
      N_VGetArrayPointer(c->workatol)[j] = m->joint[j].nrows > 0 ? 1e30 : m->solver.atol;
    if (IDAQuadInit(c->ida, power_fn, c->work) != IDA_SUCCESS || IDASetQuadErrCon(c->ida, SUNTRUE) != IDA_SUCCESS ||
        IDAQuadSVtolerances(c->ida, m->solver.rtol, c->workatol) != IDA_SUCCESS) {
      fmb_diag_set(diag, FMB_EXIT_SOLVER, m->path, 0, 0, "could not set up the work integrals: %s", c->ida_msg);
      ida_destroy(c);
      return NULL;
    }
  }
  c->watch_ele = N_VClone(c->y);
  if (!c->watch_ele) goto oom;
  return c;
oom:
  fmb_diag_set(diag, FMB_EXIT_SOLVER, m->path, 0, 0, "out of memory setting up the integrator");
  ida_destroy(c);
  return NULL;
}

/* fmb_set_input's restart: IDA from the new consistent state with no step history (IDAReInit:
   order 1, its first step estimated anew), the work integrals from 0, while the vectors, the
   matrix and the linear solver with its KLU symbolic analysis stay (destroying and creating them
   again at every setting of a 1 kHz controller cost more than the steps between). IDAReInit
   zeroes IDA's counters: they are kept in before_reinit, as the fallback does. */
static int ida_reinit(void* self, double t0, const double* y0, const double* yp0, fmbDiag* diag) {
  IdaRun* c = self;
  const fmbModel* m = c->m;
  add_counters(c->ida, &c->before_reinit);
  memcpy(N_VGetArrayPointer(c->y), y0, sizeof(double) * (size_t)m->ny);
  memcpy(N_VGetArrayPointer(c->yp), yp0, sizeof(double) * (size_t)m->ny);
  if (c->work) N_VConst(0.0, c->work);
  if (IDAReInit(c->ida, t0, c->y, c->yp) != IDA_SUCCESS || (c->work && IDAQuadReInit(c->ida, c->work) != IDA_SUCCESS)) {
    fmb_diag_set(diag, FMB_EXIT_SOLVER, m->path, 0, 0, "could not restart IDA: %s", c->ida_msg);
    return -1;
  }
  c->fresh = 0; /* the first Jacobian evaluates the bodies' blocks anew, as a new backend did */
  return 0;
}

/* The default solver (schur.c) is a modified Newton iteration: it drops the O(|mu|) part of the
   position rows. If IDA gives up while using it, the cause may be that approximation rather than
   the model, so the interval is retried once from the last good step with KLU on the whole matrix
   (solver.linear_solver: klu_full), and the run says so; a failure after that is the model's and
   is reported as such. Regular runs never come here: their steps are unchanged. */
static int reduced_solve_failed(const IdaRun* c, int flag) {
  return c->m->solver.linear_solver == FMB_LS_KLU && !c->fell_back &&
         (flag == IDA_CONV_FAIL || flag == IDA_LSETUP_FAIL || flag == IDA_LSOLVE_FAIL || flag == IDA_ERR_FAIL);
}

static void add_counters(void* ida, fmbStats* acc);

static int fall_back_to_full(IdaRun* c, double t_good, double tout, double* tret) {
  c->fell_back = 1;
  SUNLinearSolver full = SUNLinSol_KLU(c->y, c->A, c->sun);
  double tq = t_good;
  if (c->work) IDAGetQuad(c->ida, &tq, c->work);
  add_counters(c->ida, &c->before_reinit);
  if (!full || IDASetLinearSolver(c->ida, full, c->A) != IDA_SUCCESS ||
      IDASetJacFn(c->ida, jacobian_fn) != IDA_SUCCESS || IDAReInit(c->ida, t_good, c->y, c->yp) != IDA_SUCCESS ||
      (c->work && IDAQuadReInit(c->ida, c->work) != IDA_SUCCESS)) {
    if (full) SUNLinSolFree(full);
    return IDA_LINIT_FAIL;
  }
  SUNLinSolFree(c->LS);
  c->LS = full;
  c->fresh = 0; /* the next Jacobian recomputes the bodies' blocks */
  fmb_warn(c->w,
           "note: t = %.6g: IDA failed with the reduced Newton solve (solver.linear_solver: klu); continuing "
           "from the last good step with klu_full (the whole matrix)",
           t_good);
  *tret = t_good;
  return IDASolve(c->ida, tout, tret, c->y, c->yp, IDA_NORMAL);
}

static int ida_advance(void* self, double tout, double* t_reached, double* y, double* yp, double* h, char* why,
                       size_t why_len) {
  IdaRun* c = self;
  const fmbModel* m = c->m;
  double tret = *t_reached;
  double ymax = 0.0; /* the state's magnitude, from the last good row on (fmax skips NaN) */
  for (int i = 0; i < m->ny; ++i) ymax = fmax(ymax, fmax(fabs(y[i]), fabs(yp[i])));
  int flag = IDASolve(c->ida, tout, &tret, c->y, c->yp, IDA_NORMAL);
  if (flag < 0 && !stop_requested(c) && reduced_solve_failed(c, flag)) flag = fall_back_to_full(c, tret, tout, &tret);
  *t_reached = tret;
  memcpy(y, N_VGetArrayPointer(c->y), sizeof(double) * (size_t)m->ny);
  memcpy(yp, N_VGetArrayPointer(c->yp), sizeof(double) * (size_t)m->ny);
  double hcur = 0.0;
  IDAGetCurrentStep(c->ida, &hcur);
  *h = hcur;
  if (flag >= 0) return FMB_ADVANCE_OK;
  if (stop_requested(c)) return FMB_ADVANCE_INTERRUPTED;
  for (int i = 0; i < m->ny; ++i) ymax = fmax(ymax, fmax(fabs(y[i]), fabs(yp[i])));
  char advice[600], floor_note[200] = "";
  failure_advice(m, flag, ymax, advice, sizeof advice);
  /* a stop at the step floor names the key that sets it and where its value came from */
  if (fabs(hcur) <= 1.5 * m->solver.min_step)
    snprintf(floor_note, sizeof floor_note, "; the step reached solver.min_step = %.3g (%s)", m->solver.min_step,
             m->solver.min_step_given ? "as given" : "the default, 1e-12 x (t_end - t0)");
  char* flag_name = IDAGetReturnFlagName(flag); /* allocated by SUNDIALS */
  snprintf(why, why_len, "%s%s [IDA %s: %s]", advice, floor_note, flag_name ? flag_name : "?", c->ida_msg);
  free(flag_name);
  return FMB_ADVANCE_FAILED;
}

static void ida_work(void* self, double* work) {
  IdaRun* c = self;
  double tq = 0.0;
  IDAGetQuad(c->ida, &tq, c->work);
  memcpy(work, N_VGetArrayPointer(c->work), sizeof(double) * (size_t)c->m->njoint);
}

static void ida_stats(const void* self, fmbStats* st) {
  const IdaRun* c = self;
  fmbStats acc = c->before_reinit; /* zero unless the run fell back to klu_full or was restarted */
  add_counters(c->ida, &acc);
  st->steps = acc.steps;
  st->residuals = acc.residuals;
  st->jacobians = acc.jacobians;
  st->newton_iters = acc.newton_iters;
  st->error_test_fails = acc.error_test_fails;
  st->conv_fails = acc.conv_fails;
  st->jacobians_reused = c->reused;
  st->integrator = fmb_integrator_ida.name;
}

static void ida_after_row(void* self, double t) {
  IdaRun* c = self;
  watch_step_rate(c->m, c->w, c->ida, c->before_reinit.steps, c->watch_ele, c->ewt, t, &c->watch);
}

const fmbIntegratorOps fmb_integrator_ida = {
    .name = "ida",
    .projected = 0,
    .check = NULL,
    .create = ida_create,
    .reinit = ida_reinit,
    .advance = ida_advance,
    .work = ida_work,
    .stats = ida_stats,
    .after_row = ida_after_row,
    .destroy = ida_destroy,
};
