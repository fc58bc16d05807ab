/* fd.c — difference derivatives of a body's residual over its own coordinates, used when a
 * plugin provides no analytic `jacobian`. R = M a - Q is linear in a, so the M columns are exact
 * differences with a unit step; K uses forward differences with IDA's own increment rule
 * inc = max(sqrt(eps) |q|, 1/ewt); C uses central differences (exact for R quadratic in v),
 * and the same pair of evaluations carries the unit acceleration step for M.
 * Three residuals per column: a plugin whose residual is O(n) gets an O(n^2) Jacobian. */
#include <math.h>
#include <string.h>

#include "internal.h"

/* IDA's difference increment: sqrt(eps) |y|, but never below the error tolerance 1/ewt */
double fmb_fd_increment(double y, double ewt) {
  const double srur = 1.4901161193847656e-08; /* sqrt(DBL_EPSILON) */
  double inc = srur * fabs(y);
  double floor_ = ewt > 0 ? 1.0 / ewt : srur;
  return inc > floor_ ? inc : floor_;
}

int fmb_fd_body_jacobian(const fmbBodyInst* b, const fmbEnv* env, const double* q, const double* v, const double* a,
                         const double* ewt_q, const double* ewt_v, double* K, double* C, double* M, double* work,
                         double* scratch) {
  const int n = b->nq;
  double* qq = scratch;
  double* vv = scratch + n;
  double* aa = scratch + 2 * n;
  double* R0 = scratch + 3 * n;
  double* R1 = scratch + 4 * n;
  double* Rm = scratch + 5 * n;
  double vmax = 1e-3;
  for (int j = 0; j < n; ++j) vmax = fmax(vmax, fabs(v[j]));
  memcpy(qq, q, (size_t)n * sizeof(double));
  memcpy(vv, v, (size_t)n * sizeof(double));
  memcpy(aa, a, (size_t)n * sizeof(double));
  int rc = b->type->residual(b->self, env, q, v, a, R0, work);
  if (rc) return rc;
  for (int j = 0; j < n; ++j) {
    if (K) {
      double h = fmb_fd_increment(q[j], ewt_q[j]);
      qq[j] = q[j] + h;
      h = qq[j] - q[j]; /* the step actually taken */
      rc = b->type->residual(b->self, env, qq, v, a, R1, work);
      qq[j] = q[j];
      if (rc) return rc;
      for (int i = 0; i < n; ++i) K[(size_t)j * n + i] = (R1[i] - R0[i]) / h;
    }
    if (M && !C) {
      /* mass matrix alone (initial conditions, definiteness checks): R is linear in a */
      aa[j] = a[j] + 1.0;
      rc = b->type->residual(b->self, env, q, v, aa, R1, work);
      aa[j] = a[j];
      if (rc) return rc;
      for (int i = 0; i < n; ++i) M[(size_t)j * n + i] = R1[i] - R0[i];
    } else if (C) {
      /* R = M(q) a + g(q, v) + f(q) with g quadratic in v: one pair of evaluations at
         (v +- h e_j, a + e_j) gives C_j exactly from their difference and M_j from their mean,
         (R+ + R-)/2 - R0 = M_j + h^2 g_vjvj / 2, an error of order 1e-11 relative. The step is
         large enough that roundoff from big elastic forces in R does not swamp the velocity
         terms. */
      const double h = 6.0e-6 * fmax(fmax(fabs(v[j]), vmax), 1.0 / ewt_v[j]);
      aa[j] = a[j] + 1.0;
      vv[j] = v[j] + h;
      rc = b->type->residual(b->self, env, q, vv, aa, R1, work);
      if (!rc) {
        vv[j] = v[j] - h;
        rc = b->type->residual(b->self, env, q, vv, aa, Rm, work);
      }
      vv[j] = v[j];
      aa[j] = a[j];
      if (rc) return rc;
      if (C)
        for (int i = 0; i < n; ++i) C[(size_t)j * n + i] = (R1[i] - Rm[i]) / (2.0 * h);
      if (M)
        for (int i = 0; i < n; ++i) M[(size_t)j * n + i] = 0.5 * (R1[i] + Rm[i]) - R0[i];
    }
  }
  return 0;
}
