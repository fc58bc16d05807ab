/* integrator_projected.c — solver.formulation: projected (docs/mechanisms.md). CVODE (BDF,
 * variable order and step) integrates the index-1 equations
 *
 *     q' = v,   v' = a(q, v, t),   [M Phi_q^T; Phi_q -eps I] [a; lambda] = [Q; gamma]
 *
 * with a and the multipliers from the sparse augmented system (augmented.c): with eps a Tikhonov
 * shift the multipliers are the minimum-norm ones and stay defined where Phi_q loses rank, so the
 * motion passes singular configurations. After every step CVODE calls our projection
 * (CVodeSetProjFn): positions onto Phi = 0 and velocities onto Phi_q v + Phi_t = 0 by
 * mass-orthogonal corrections (Bayo & Ledesma 1996), and the local error estimate onto the
 * constraints' tangent space, so the error test measures the error along the manifold
 * (Eich 1993; the coordinate projection of Hairer & Wanner VII.2). Projecting every step keeps
 * the history of the multistep method on the manifold: no restarts, the order stays up (the
 * earlier version projected only at output rows and restarted IDA at order 1 there).
 *
 * Newton's linear systems: CVODE's dense difference-quotient Jacobian over the 2 nq unknowns for
 * small models; for larger ones GMRES without a matrix (Jacobian-vector products by differences,
 * one right-hand side each), which keeps the cost per step linear in the model's size but is
 * less robust at flat positions (PROJ_DENSE_MAX).
 * The work integrals of m->need_work ride along as extra unknowns (their powers come from the
 * same solve), untouched by the projection. */
#include <cvode/cvode.h>
#include <cvode/cvode_proj.h>
#include <math.h>
#include <nvector/nvector_serial.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>
#include <sundials/sundials_context.h>
#include <sunlinsol/sunlinsol_dense.h>
#include <sunlinsol/sunlinsol_spgmr.h>
#include <sunmatrix/sunmatrix_dense.h>

#include "integrator.h"

/* CVODE runs at this fraction of solver.rtol (the absolute tolerances at PROJ_ATOL_FACTOR), so
   that an rtol means at least the accuracy it means with the default formulation (IDA on the GGL
   system), also when `auto` switches mid-run. Measured on regular motions both formulations can integrate, error
   against an independent reference at rtol r (GGL) and r x factor (projected):
     rotating crank, 10 s, r = 1e-8:        GGL 6.7e-6 rad | x1 3.9e-5  x1/3 2.4e-5  x1/10 8.7e-6
     rotating crank, 10 s, r = 1e-6:        GGL 1.4e-3     | x1 3.2e-3  x1/3 9.5e-4  x1/10 6.6e-5
     swinging parallelogram, 10 s, 1e-8:    GGL 1.4e-6     | x1 3.3e-6  x1/3 1.3e-6  x1/10 5.6e-7
     swinging parallelogram, 10 s, 1e-10:   GGL 1.1e-8     | x1 8.2e-8  x1/3 7.2e-8  x1/10 1.2e-8
     double pendulum, 2 s, 1e-6:            GGL 7.2e-6     | x1 4.0e-5  x1/3 1.6e-5  x1/10 4.6e-6
     double pendulum, 2 s, 1e-8:            GGL 2.7e-7     | x1 7.2e-7  x1/3 1.6e-7  x1/10 1.4e-7
   CVODE's error test on the projected (tangential) error estimate is 2-7x looser than IDA's on the
   GGL system at the same rtol. The rows of parallelogram linkages that `auto` runs here from the
   start (issue 23: within 1e-5/3 rad of the exact motion at rtol 1e-8) need more: the crank angle
   error over 10 s, rows of 1, 2, 5 linkages at rtol 1e-8, 1.1e-8, 1.25e-8, 9e-9 (12 runs each,
   default tolerances; test_parallelogram):
     x1/10:  worst 1.5e-5 rad, 7 of 12 above 3.3e-6;  ~2750 steps
     x1/100: worst 4.1e-6, 2 of 12 above 3.3e-6;     ~3300 steps
     x1/300: worst 2.5e-6, none above;                ~3400 steps (+25 % CPU against x1/10)
   The error there falls slowly with the factor (it is not the local error test alone that sets
   it), so 1/300 buys the margin, not a proportional gain. CVODE's own rtol is kept at or above
   PROJ_RTOL_MIN: at 1e-12 a row of 20 linkages stopped at a flat position with the error test
   failing at the minimum step (t = 9.95 s). */
#define PROJ_TOL_FACTOR (1.0 / 300.0)
/* the absolute tolerances at 1/10 (the calibration above): scaled with rtol to 1/300 as well, the
   rows took 45 % more steps and the row of 20 stopped at a flat position at rtol 1e-9 (t = 5.11 s) */
#define PROJ_ATOL_FACTOR 0.1
#define PROJ_RTOL_MIN 3e-12

/* up to this many unknowns (2 nq + work integrals) the Newton matrix is dense; beyond, matrix-free
   GMRES. Measured on rows of N parallelograms passing flat positions (bench/mechanisms.sh): the
   dense path costs N^2 per step (0.68 s for 2 s of N = 20); GMRES is linear (0.64 s for N = 50)
   but stopped at flat positions at tighter tolerances than dense did (N = 10, 20, 50 at rtol
   1e-9 before the rtol/10 calibration, not helped by tighter GMRES tolerances), so dense goes as
   far as N = 20 linkages (246 unknowns) */
#define PROJ_DENSE_MAX 256

typedef struct {
  const fmbModel* m;
  fmbWorkspace* w;
  const volatile sig_atomic_t* stop;
  SUNContext sun;
  void* cvode;
  N_Vector y, atol; /* [q, v, work] */
  SUNMatrix A;
  SUNLinearSolver LS;
  fmbAugmented* aug;
  double* lambda; /* nc */
  int nwork;      /* work integrals carried (njoint or 0) */
  char msg[512];
  fmbStats before_reinit; /* CVODE's counters up to the last CVodeReInit (proj_reinit: it zeroes them) */
} ProjRun;

/* the powers of the joints (their work's rates) at (q, v) with the multipliers lambda */
static int joint_powers(ProjRun* c, double t, const double* q, const double* v, double* p) {
  for (int j = 0; j < c->nwork; ++j) {
    p[j] = fmb_joint_power(c->m, c->w, j, t, q, v, c->lambda);
    if (!isfinite(p[j])) return 1;
  }
  return 0;
}

static int proj_rhs(sunrealtype t, N_Vector Y, N_Vector Yd, void* ud) {
  ProjRun* c = ud;
  if (fmb_stop_requested(c->stop)) return -1;
  const int nq = c->m->nq;
  const double *q = N_VGetArrayPointer(Y), *v = q + nq;
  double* f = N_VGetArrayPointer(Yd);
  for (int i = 0; i < 2 * nq; ++i)
    if (!isfinite(q[i])) return 1;
  if (fmb_augmented_solve(c->m, c->w, c->aug, t, q, v, NULL, FMB_MIN_NORM_SHIFT, f + nq, c->lambda)) return 1;
  memcpy(f, v, sizeof(double) * (size_t)nq);
  return joint_powers(c, t, q, v, f + 2 * nq);
}

/* CVProjFn: ycur onto the constraints in place, corr = the change; err (may be NULL) onto the
   tangent space of the projected state (positions' and velocities' parts alike: both
   constraints have Phi_q as their Jacobian in the unknowns they constrain) */
static int proj_project(sunrealtype t, N_Vector ycur, N_Vector corr, sunrealtype eps, N_Vector err, void* ud) {
  (void)eps;
  ProjRun* c = ud;
  const int nq = c->m->nq;
  double *y = N_VGetArrayPointer(ycur), *dy = N_VGetArrayPointer(corr);
  memcpy(dy, y, sizeof(double) * 2 * (size_t)nq);
  if (fmb_project_state(c->m, c->w, c->aug, t, y, y + nq)) return 1; /* recoverable: a smaller step */
  for (int i = 0; i < 2 * nq; ++i) dy[i] = y[i] - dy[i];
  for (int i = 2 * nq; i < 2 * nq + c->nwork; ++i) dy[i] = 0.0;
  if (err) {
    double* e = N_VGetArrayPointer(err);
    if (fmb_project_tangent(c->w, c->aug, e) || fmb_project_tangent(c->w, c->aug, e + nq)) return 1;
  }
  return 0;
}

static void proj_error_handler(int code, const char* module, const char* function, char* msg, void* ud) {
  (void)code;
  (void)module;
  ProjRun* c = ud;
  snprintf(c->msg, sizeof c->msg, "%s: %s", function, msg);
}

static void proj_destroy(void* self) {
  ProjRun* c = self;
  if (!c) return;
  if (c->cvode) CVodeFree(&c->cvode);
  if (c->LS) SUNLinSolFree(c->LS);
  if (c->A) SUNMatDestroy(c->A);
  if (c->y) N_VDestroy(c->y);
  if (c->atol) N_VDestroy(c->atol);
  fmb_augmented_free(c->aug);
  free(c->lambda);
  if (c->sun) SUNContext_Free(&c->sun);
  free(c);
}

static void* proj_create(const fmbIntegratorSetup* s, double t0, const double* y0, const double* yp0, fmbDiag* diag) {
  (void)yp0;
  const fmbModel* m = s->m;
  ProjRun* c = calloc(1, sizeof *c);
  if (!c || SUNContext_Create(NULL, &c->sun) != 0) goto oom;
  c->m = m;
  c->w = s->w;
  c->stop = s->stop;
  c->nwork = m->need_work ? m->njoint : 0;
  const int nq = m->nq, n = 2 * nq + c->nwork;
  c->y = N_VNew_Serial(n, c->sun);
  c->atol = N_VNew_Serial(n, c->sun);
  c->aug = fmb_augmented_new(m);
  c->lambda = calloc((size_t)m->nc + 1, sizeof(double));
  if (!c->y || !c->atol || !c->aug || !c->lambda) goto oom;
  fmb_vector_use_fast_ops(c->y);
  double *y = N_VGetArrayPointer(c->y), *at = N_VGetArrayPointer(c->atol);
  memcpy(y, y0, sizeof(double) * 2 * (size_t)nq);
  const double rtol = fmax(PROJ_TOL_FACTOR * m->solver.rtol, fmin(PROJ_RTOL_MIN, m->solver.rtol));
  const double factor = PROJ_ATOL_FACTOR;
  for (int i = 0; i < 2 * nq; ++i) at[i] = factor * s->atol[i];
  /* velocities in the error test unless the scene keeps only positions (a huge atol) */
  if (m->solver.positions_only)
    for (int i = nq; i < 2 * nq; ++i) at[i] = 1e30;
  for (int j = 0; j < c->nwork; ++j) { /* as the IDA backend: a constraint's work is not controlled */
    y[2 * nq + j] = 0.0;
    at[2 * nq + j] = m->joint[j].nrows > 0 ? 1e30 : factor * m->solver.atol;
  }
  c->cvode = CVodeCreate(CV_BDF, c->sun);
  if (!c->cvode || CVodeInit(c->cvode, proj_rhs, t0, c->y) != CV_SUCCESS ||
      CVodeSVtolerances(c->cvode, rtol, c->atol) != CV_SUCCESS || CVodeSetUserData(c->cvode, c) != CV_SUCCESS ||
      CVodeSetErrHandlerFn(c->cvode, proj_error_handler, c) != CV_SUCCESS ||
      CVodeSetMaxOrd(c->cvode, m->solver.max_order) != CV_SUCCESS ||
      CVodeSetMaxNumSteps(c->cvode, m->solver.max_steps_per_output) != CV_SUCCESS ||
      (m->solver.max_step > 0 && CVodeSetMaxStep(c->cvode, m->solver.max_step) != CV_SUCCESS) ||
      CVodeSetMinStep(c->cvode, m->solver.min_step) != CV_SUCCESS) {
    fmb_diag_set(diag, FMB_EXIT_SOLVER, m->path, 0, 0, "could not set up CVODE: %s", c->msg);
    proj_destroy(c);
    return NULL;
  }
  if (n <= PROJ_DENSE_MAX) {
    c->A = SUNDenseMatrix(n, n, c->sun);
    c->LS = c->A ? SUNLinSol_Dense(c->y, c->A, c->sun) : NULL;
  } else {
    c->LS = SUNLinSol_SPGMR(c->y, SUN_PREC_NONE, 10, c->sun);
  }
  if (!c->LS || CVodeSetLinearSolver(c->cvode, c->LS, c->A) != CV_SUCCESS ||
      (m->nc > 0 && CVodeSetProjFn(c->cvode, proj_project) != CV_SUCCESS)) {
    fmb_diag_set(diag, FMB_EXIT_SOLVER, m->path, 0, 0, "could not set up the projected integrator: %s", c->msg);
    proj_destroy(c);
    return NULL;
  }
  return c;
oom:
  fmb_diag_set(diag, FMB_EXIT_SOLVER, m->path, 0, 0, "out of memory setting up the integrator");
  proj_destroy(c);
  return NULL;
}

static void proj_stats(const void* self, fmbStats* st);

/* fmb_set_input's restart (integrator.h): CVODE from (q, v) at t0 with no step history, the work
   integrals from 0; the vectors, the matrix or GMRES and the projection stay */
static int proj_reinit(void* self, double t0, const double* y0, const double* yp0, fmbDiag* diag) {
  (void)yp0;
  ProjRun* c = self;
  const int nq = c->m->nq;
  proj_stats(c, &c->before_reinit);
  double* y = N_VGetArrayPointer(c->y);
  memcpy(y, y0, sizeof(double) * 2 * (size_t)nq);
  for (int j = 0; j < c->nwork; ++j) y[2 * nq + j] = 0.0;
  if (CVodeReInit(c->cvode, t0, c->y) != CV_SUCCESS) {
    fmb_diag_set(diag, FMB_EXIT_SOLVER, c->m->path, 0, 0, "could not restart CVODE: %s", c->msg);
    return -1;
  }
  return 0;
}

static int proj_advance(void* self, double tout, double* t_reached, double* y, double* yp, double* h, char* why,
                        size_t why_len) {
  ProjRun* c = self;
  const fmbModel* m = c->m;
  const int nq = m->nq;
  double tret = *t_reached;
  const int flag = CVode(c->cvode, tout, c->y, &tret, CV_NORMAL);
  double hcur = 0.0;
  CVodeGetCurrentStep(c->cvode, &hcur);
  *h = hcur;
  *t_reached = tret;
  memcpy(y, N_VGetArrayPointer(c->y), sizeof(double) * 2 * (size_t)nq);
  /* the row: CVODE's interpolant between projected steps is on the constraints only to the
     tolerance; the copy written out is projected exactly (CVODE's own state is not touched) */
  int proj_failed = 0;
  if (fmb_project_state(m, c->w, c->aug, tret, y, y + nq) ||
      fmb_augmented_solve(m, c->w, c->aug, tret, y, y + nq, NULL, FMB_MIN_NORM_SHIFT, yp + nq, y + 2 * nq))
    proj_failed = 1;
  memcpy(yp, y + nq, sizeof(double) * (size_t)nq);
  if (flag >= 0 && !proj_failed) return FMB_ADVANCE_OK;
  if (fmb_stop_requested(c->stop)) return FMB_ADVANCE_INTERRUPTED;
  if (flag >= 0) {
    snprintf(why, why_len,
             "the projection onto the constraints did not converge (the mechanism may have left its "
             "assembled configurations); try a tighter rtol");
  } else {
    char* flag_name = CVodeGetReturnFlagName(flag);
    snprintf(why, why_len,
             "the integrator of the projected formulation stopped: try a tighter rtol or a smaller "
             "solver.max_step [CVODE %s: %s]",
             flag_name ? flag_name : "?", c->msg);
    free(flag_name);
  }
  return FMB_ADVANCE_FAILED;
}

static void proj_work(void* self, double* work) {
  ProjRun* c = self;
  memcpy(work, N_VGetArrayPointer(c->y) + 2 * c->m->nq, sizeof(double) * (size_t)c->nwork);
}

static void proj_stats(const void* self, fmbStats* st) {
  const ProjRun* c = self;
  long v = 0;
  void* cv = c->cvode;
  st->steps = c->before_reinit.steps;
  st->residuals = c->before_reinit.residuals;
  st->jacobians = c->before_reinit.jacobians;
  st->newton_iters = c->before_reinit.newton_iters;
  st->error_test_fails = c->before_reinit.error_test_fails;
  st->conv_fails = c->before_reinit.conv_fails;
  if (CVodeGetNumSteps(cv, &v) == CV_SUCCESS) st->steps += v;
  if (CVodeGetNumRhsEvals(cv, &v) == CV_SUCCESS) st->residuals += v;
  if (CVodeGetNumJacEvals(cv, &v) == CV_SUCCESS) st->jacobians += v;
  if (CVodeGetNumNonlinSolvIters(cv, &v) == CV_SUCCESS) st->newton_iters += v;
  if (CVodeGetNumErrTestFails(cv, &v) == CV_SUCCESS) st->error_test_fails += v;
  if (CVodeGetNumNonlinSolvConvFails(cv, &v) == CV_SUCCESS) st->conv_fails += v;
  st->jacobians_reused = 0;
  st->integrator = fmb_integrator_projected.name;
}

/* the projected formulation works on q and v alone, with the bodies' mass matrices */
static int proj_check(const fmbModel* m, fmbParser* p, fmbNode solver) {
  /* a body with a sparse pattern (a banded beam, with or without auxiliary unknowns: the exact
     beam's banded assembly has none) fills its mass into the pattern's layout, which the dense
     mass matrices here do not have: it wrote past the workspace before this was refused */
  int sparse = 0; /* asked of the types: the check runs before the pattern is built (pattern.c) */
  for (int b = 1; b < m->nbody && !sparse; ++b) {
    const fmbBodyType* type = m->body[b].type;
    sparse = type->pattern && type->pattern(m->body[b].self, NULL, NULL) >= 0;
  }
  if (m->nz > 0 || sparse)
    return fmb_parse_error(
        p, fmb_find_key(p, solver, "formulation"),
        "formulation: projected needs bodies assembled dense (a banded beam is not: set its assembly: "
        "dense, or use formulation: ggl)");
  return 0;
}

const fmbIntegratorOps fmb_integrator_projected = {
    .name = "projected",
    .projected = 1,
    .check = proj_check,
    .create = proj_create,
    .reinit = proj_reinit,
    .advance = proj_advance,
    .work = proj_work,
    .stats = proj_stats,
    .after_row = NULL,
    .destroy = proj_destroy,
};
