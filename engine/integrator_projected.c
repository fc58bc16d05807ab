/* integrator_projected.c — solver.formulation: projected (docs/mechanisms.md). IDA integrates the
 * index-1 equations q' = v, v' = a(q, v, t), with a and the multipliers from the augmented system
 * [M Phi_q^T; Phi_q -eps I] (ic.c): with eps a Tikhonov shift the multipliers are the
 * minimum-norm ones and stay defined where Phi_q loses rank, so the motion passes singular
 * configurations. Drift off the constraints is removed by projecting at every output row
 * (fmb_project_state), after which IDA restarts. Small dense systems: IDA's difference-quotient
 * Jacobian over the 2 nq unknowns. */
#include <idas/idas.h>
#include <math.h>
#include <nvector/nvector_serial.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>
#include <sundials/sundials_context.h>
#include <sunlinsol/sunlinsol_dense.h>
#include <sunmatrix/sunmatrix_dense.h>

#include "integrator.h"

typedef struct {
  const fmbModel* m;
  fmbWorkspace* w;
  const volatile sig_atomic_t* stop;
  SUNContext sun;
  void* ida;
  N_Vector y, yp, id, atol, work, workatol; /* [q, v] and its rates */
  SUNMatrix A;
  SUNLinearSolver LS;
  fmbAugmented* aug;
  double *accel, *lambda; /* nq, nc */
  fmbStats before_reinit; /* IDA's counters up to the last IDAReInit (which zeroes them) */
  char ida_msg[512];
} ProjRun;

static int proj_residual_fn(sunrealtype t, N_Vector y, N_Vector yp, N_Vector F, void* ud) {
  ProjRun* c = ud;
  if (c->stop && *c->stop) return -1;
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

static int proj_power_fn(sunrealtype t, N_Vector y, N_Vector yp, N_Vector P, void* ud) {
  (void)yp;
  ProjRun* c = ud;
  double* p = N_VGetArrayPointer(P);
  const double* yv = N_VGetArrayPointer(y);
  if (fmb_augmented_solve(c->m, c->w, c->aug, t, yv, yv + c->m->nq, NULL, FMB_MIN_NORM_SHIFT, NULL, c->lambda)) return 1;
  for (int j = 0; j < c->m->njoint; ++j) {
    p[j] = fmb_joint_power(c->m, c->w, j, t, yv, yv + c->m->nq, c->lambda);
    if (!isfinite(p[j])) return 1;
  }
  return 0;
}

static void proj_error_handler(int code, const char* module, const char* function, char* msg, void* ud) {
  (void)code;
  (void)module;
  ProjRun* c = ud;
  snprintf(c->ida_msg, sizeof c->ida_msg, "%s: %s", function, msg);
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

static void proj_destroy(void* self) {
  ProjRun* c = self;
  if (!c) return;
  if (c->ida) IDAFree(&c->ida);
  if (c->LS) SUNLinSolFree(c->LS);
  if (c->A) SUNMatDestroy(c->A);
  N_Vector* vs[] = {&c->y, &c->yp, &c->id, &c->atol, &c->work, &c->workatol};
  for (size_t i = 0; i < sizeof vs / sizeof vs[0]; ++i)
    if (*vs[i]) N_VDestroy(*vs[i]);
  fmb_augmented_free(c->aug);
  free(c->accel);
  free(c->lambda);
  if (c->sun) SUNContext_Free(&c->sun);
  free(c);
}

static void* proj_create(const fmbIntegratorSetup* s, double t0, const double* y0, const double* yp0, fmbDiag* diag) {
  const fmbModel* m = s->m;
  const int n = 2 * m->nq;
  ProjRun* c = calloc(1, sizeof *c);
  if (!c || SUNContext_Create(NULL, &c->sun) != 0) goto oom;
  c->m = m;
  c->w = s->w;
  c->stop = s->stop;
  c->y = N_VNew_Serial(n, c->sun);
  c->yp = N_VNew_Serial(n, c->sun);
  c->id = N_VNew_Serial(n, c->sun);
  c->atol = N_VNew_Serial(n, c->sun);
  c->aug = fmb_augmented_new(m);
  c->accel = calloc((size_t)m->nq + 1, sizeof(double));
  c->lambda = calloc((size_t)m->nc + 1, sizeof(double));
  if (!c->y || !c->yp || !c->id || !c->atol || !c->aug || !c->accel || !c->lambda) goto oom;
  fmb_vector_use_fast_ops(c->y);
  memcpy(N_VGetArrayPointer(c->y), y0, sizeof(double) * (size_t)n);
  memcpy(N_VGetArrayPointer(c->yp), yp0, sizeof(double) * (size_t)n);
  memcpy(N_VGetArrayPointer(c->atol), s->atol, sizeof(double) * (size_t)n);
  const int ndiff = m->solver.positions_only ? m->nq : n;
  for (int i = 0; i < n; ++i) N_VGetArrayPointer(c->id)[i] = i < ndiff ? 1.0 : 0.0;
  c->ida = IDACreate(c->sun);
  if (!c->ida || IDAInit(c->ida, proj_residual_fn, t0, c->y, c->yp) != IDA_SUCCESS ||
      IDASVtolerances(c->ida, m->solver.rtol, c->atol) != IDA_SUCCESS || IDASetUserData(c->ida, c) != IDA_SUCCESS ||
      IDASetErrHandlerFn(c->ida, proj_error_handler, c) != IDA_SUCCESS || IDASetId(c->ida, c->id) != IDA_SUCCESS ||
      IDASetSuppressAlg(c->ida, SUNTRUE) != IDA_SUCCESS || IDASetMaxOrd(c->ida, m->solver.max_order) != IDA_SUCCESS ||
      IDASetMaxNumSteps(c->ida, m->solver.max_steps_per_output) != IDA_SUCCESS ||
      (m->solver.max_step > 0 && IDASetMaxStep(c->ida, m->solver.max_step) != IDA_SUCCESS) ||
      IDASetMinStep(c->ida, m->solver.min_step) != IDA_SUCCESS) {
    fmb_diag_set(diag, FMB_EXIT_SOLVER, m->path, 0, 0, "could not set up IDA: %s", c->ida_msg);
    proj_destroy(c);
    return NULL;
  }
  c->A = SUNDenseMatrix(n, n, c->sun);
  c->LS = c->A ? SUNLinSol_Dense(c->y, c->A, c->sun) : NULL;
  if (!c->A || !c->LS || IDASetLinearSolver(c->ida, c->LS, c->A) != IDA_SUCCESS) {
    fmb_diag_set(diag, FMB_EXIT_SOLVER, m->path, 0, 0, "could not set up the linear solver");
    proj_destroy(c);
    return NULL;
  }
  if (m->need_work && m->njoint > 0) { /* as in integrator_ida.c */
    c->work = N_VNew_Serial(m->njoint, c->sun);
    c->workatol = N_VNew_Serial(m->njoint, c->sun);
    if (!c->work || !c->workatol) goto oom;
    N_VConst(0.0, c->work);
    for (int j = 0; j < m->njoint; ++j) N_VGetArrayPointer(c->workatol)[j] = m->joint[j].nrows > 0 ? 1e30 : m->solver.atol;
    if (IDAQuadInit(c->ida, proj_power_fn, c->work) != IDA_SUCCESS || IDASetQuadErrCon(c->ida, SUNTRUE) != IDA_SUCCESS ||
        IDAQuadSVtolerances(c->ida, m->solver.rtol, c->workatol) != IDA_SUCCESS) {
      fmb_diag_set(diag, FMB_EXIT_SOLVER, m->path, 0, 0, "could not set up the work integrals: %s", c->ida_msg);
      proj_destroy(c);
      return NULL;
    }
  }
  return c;
oom:
  fmb_diag_set(diag, FMB_EXIT_SOLVER, m->path, 0, 0, "out of memory setting up the integrator");
  proj_destroy(c);
  return NULL;
}

static int proj_advance(void* self, double tout, double* t_reached, double* y, double* yp, double* h, char* why,
                        size_t why_len) {
  ProjRun* c = self;
  const fmbModel* m = c->m;
  const int n = 2 * m->nq;
  double tret = *t_reached;
  int flag = IDASolve(c->ida, tout, &tret, c->y, c->yp, IDA_NORMAL);
  double hcur = 0.0;
  IDAGetCurrentStep(c->ida, &hcur);
  *h = hcur;
  *t_reached = tret;
  memcpy(y, N_VGetArrayPointer(c->y), sizeof(double) * (size_t)n);
  int proj_failed = 0;
  if (flag >= 0) {
    /* back onto the constraints, with the multipliers for the outputs, at every row (measured on
       scenes/parallelogram.yaml: projecting only once the drift exceeds the tolerance, or
       Baumgarte's stabilization instead, let the linkage slip onto the crossed branch at a flat
       passage or made the error erratic in alpha; every row gives errors that fall with rtol:
       4.7e-5, 3.4e-6, 2.1e-7 rad at rtol 1e-8, 1e-9, 1e-10) */
    if (fmb_project_state(m, c->w, c->aug, tret, y, y + m->nq) ||
        fmb_augmented_solve(m, c->w, c->aug, tret, y, y + m->nq, NULL, FMB_MIN_NORM_SHIFT, yp + m->nq, y + 2 * m->nq))
      proj_failed = 1;
    memcpy(yp, y + m->nq, sizeof(double) * (size_t)m->nq);
    memcpy(N_VGetArrayPointer(c->y), y, sizeof(double) * (size_t)n);
    memcpy(N_VGetArrayPointer(c->yp), yp, sizeof(double) * (size_t)n);
    add_counters(c->ida, &c->before_reinit);
    if (c->work) {
      double tq = tret;
      IDAGetQuad(c->ida, &tq, c->work);
    }
    if (!proj_failed && IDAReInit(c->ida, tret, c->y, c->yp) != IDA_SUCCESS) proj_failed = 1;
    if (!proj_failed && c->work) IDAQuadReInit(c->ida, c->work); /* IDAReInit restarted the integration */
    if (!proj_failed) return FMB_ADVANCE_OK;
  }
  if (c->stop && *c->stop) return FMB_ADVANCE_INTERRUPTED;
  if (proj_failed) {
    snprintf(why, why_len, "the projection onto the constraints did not converge (the mechanism may have left its "
             "assembled configurations); try a tighter rtol or a smaller solver.output_step");
  } else {
    char* flag_name = IDAGetReturnFlagName(flag);
    snprintf(why, why_len, "the integrator of the projected formulation stopped: try a tighter rtol or a smaller "
             "solver.max_step [IDA %s: %s]", flag_name ? flag_name : "?", c->ida_msg);
    free(flag_name);
  }
  return FMB_ADVANCE_FAILED;
}

static void proj_work(void* self, double* work) {
  ProjRun* c = self;
  memcpy(work, N_VGetArrayPointer(c->work), sizeof(double) * (size_t)c->m->njoint);
}

static void proj_stats(const void* self, fmbStats* st) {
  const ProjRun* c = self;
  fmbStats acc = c->before_reinit;
  add_counters(c->ida, &acc);
  st->steps = acc.steps;
  st->residuals = acc.residuals;
  st->jacobians = acc.jacobians;
  st->newton_iters = acc.newton_iters;
  st->error_test_fails = acc.error_test_fails;
  st->conv_fails = acc.conv_fails;
  st->jacobians_reused = 0;
}

const fmbIntegratorOps fmb_integrator_projected = {
    .name = "projected",
    .create = proj_create,
    .advance = proj_advance,
    .work = proj_work,
    .stats = proj_stats,
    .after_row = NULL,
    .destroy = proj_destroy,
};
