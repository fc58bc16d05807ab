/* fd.c — difference derivatives of a body's residual over its own coordinates, used when a
 * plugin provides no analytic `jacobian`. R = M a - Q is linear in a, so the M columns are exact
 * differences with a unit step; K uses forward differences with IDA's own increment rule
 * inc = max(sqrt(eps) |q|, 1/ewt); C uses central differences (exact for R quadratic in v),
 * and the same pair of evaluations carries the unit acceleration step for M.
 * Three residuals per column: a plugin whose residual is O(n) gets an O(n^2) Jacobian. */
#include <math.h>
#include <string.h>

#include "fd.h"
#include "internal.h"

/* a body's rows [R; Rz] at (q, v, a, z): residual_aux when it has auxiliary unknowns (the only
   evaluation the differences below need; ic.c calls it too) */
int fmb_body_eval(const fmbBodyInst* b, const fmbEnv* env, const double* q, const double* v, const double* a,
                  const double* z, double* R, double* work) {
  if (b->nz > 0) return b->type->residual_aux(b->self, env, q, v, a, z, R, R + b->nq, work);
  return b->type->residual(b->self, env, q, v, a, R, work);
}

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

/* ---------------------------------------------------------------------------------------------
 * Over a body's sparse pattern: the columns of one colour share no row, so one perturbed
 * evaluation differences all of them at once (Curtis, Powell & Reid 1974). Per colour:
 *   q and z columns together: R(q + h, z + hz) and R(z - hz): K_q forward (as above), K_z central
 *     (a body's rows are at most quadratic in its sums z, for which central differences are
 *     exact up to roundoff; hz = 1e-5 max(|z|, 1e-3 max|z|) keeps roundoff small);
 *   v and a columns: R(v +- h, a + 1): C central and M from the mean, as above.
 * Four residuals per colour, and the number of colours does not grow with a banded body's size:
 * an O(n) residual gives an O(n) Jacobian.
 * ------------------------------------------------------------------------------------------- */
static size_t fd_sparse_scratch(const fmbBodyInst* b) {
  const size_t nq = (size_t)b->nq, n = nq + (size_t)b->nz;
  return 3 * nq + (size_t)b->nz + 4 * n; /* q, v, a, z copies (3 nq + nz); R0, R1, Rm, steps (n each) */
}

/* the same over a body's sparse pattern (b->pcolptr/prowind), one residual pair per colour:
   K = d[R; Rz]/dq (and d/dz in the z columns), C = d/dv, M = d/da, each in pattern order
   (pnnz). z: the body's auxiliary unknowns (NULL when nz = 0). scratch: fd_sparse_scratch. */
static int fd_body_sparse(const fmbBodyInst* b, const fmbEnv* env, const double* q, const double* v, const double* a,
                          const double* z, const double* ewt_q, const double* ewt_v, double* K, double* C, double* M,
                          double* work, double* scratch) {
  const int nq = b->nq, nz = b->nz, n = nq + nz;
  double* qq = scratch;
  double* vv = qq + nq;
  double* aa = vv + nq;
  double* zz = aa + nq;
  double* R0 = zz + nz;
  double* R1 = R0 + n;
  double* Rm = R1 + n;
  double* step = Rm + n;
  memcpy(qq, q, (size_t)nq * sizeof(double));
  memcpy(vv, v, (size_t)nq * sizeof(double));
  memcpy(aa, a, (size_t)nq * sizeof(double));
  if (nz > 0) memcpy(zz, z, (size_t)nz * sizeof(double));
  double vmax = 1e-3, zmax = 0.0;
  for (int j = 0; j < nq; ++j) vmax = fmax(vmax, fabs(v[j]));
  for (int j = 0; j < nz; ++j) zmax = fmax(zmax, fabs(z[j]));
  int rc = fmb_body_eval(b, env, q, v, a, zz, R0, work);
  if (rc) return rc;
  for (int k = 0; k < b->ncolor; ++k) {
    const int* col = b->color_col + b->color_ptr[k];
    const int ncol = b->color_ptr[k + 1] - b->color_ptr[k];
    int has_x = 0, has_z = 0;
    /* q and z columns */
    for (int i = 0; i < ncol; ++i) {
      const int c = col[i];
      if (c < nq) {
        qq[c] = q[c] + fmb_fd_increment(q[c], ewt_q[c]);
        step[c] = qq[c] - q[c]; /* the step actually taken */
        has_x = 1;
      } else {
        const double x0 = z[c - nq];
        zz[c - nq] = x0 + 1e-5 * fmax(fmax(fabs(x0), 1e-3 * zmax), 1e-300);
        step[c] = zz[c - nq] - x0;
        has_z = 1;
      }
    }
    rc = fmb_body_eval(b, env, qq, v, a, zz, R1, work);
    for (int i = 0; i < ncol; ++i) {
      const int c = col[i];
      if (c < nq)
        qq[c] = q[c];
      else
        zz[c - nq] = z[c - nq] - step[c];
    }
    if (!rc && has_z) rc = fmb_body_eval(b, env, q, v, a, zz, Rm, work);
    for (int i = 0; i < ncol; ++i)
      if (col[i] >= nq) zz[col[i] - nq] = z[col[i] - nq];
    if (rc) return rc;
    for (int i = 0; i < ncol; ++i) {
      const int c = col[i];
      for (long e = b->pcolptr[c]; e < b->pcolptr[c + 1]; ++e) {
        const int r = b->prowind[e];
        if (c < nq) {
          K[e] = (R1[r] - R0[r]) / step[c];
        } else {
          K[e] = (R1[r] - Rm[r]) / (2.0 * step[c]);
          C[e] = M[e] = 0.0;
        }
      }
    }
    if (!has_x) continue;
    /* v and a columns: central in v with a unit acceleration step (see fmb_fd_body_jacobian) */
    for (int i = 0; i < ncol; ++i) {
      const int c = col[i];
      if (c >= nq) continue;
      step[c] = 6.0e-6 * fmax(fmax(fabs(v[c]), vmax), 1.0 / ewt_v[c]);
      vv[c] = v[c] + step[c];
      aa[c] = a[c] + 1.0;
    }
    rc = fmb_body_eval(b, env, q, vv, aa, z, R1, work);
    for (int i = 0; i < ncol; ++i)
      if (col[i] < nq) vv[col[i]] = v[col[i]] - step[col[i]];
    if (!rc) rc = fmb_body_eval(b, env, q, vv, aa, z, Rm, work);
    for (int i = 0; i < ncol; ++i)
      if (col[i] < nq) {
        vv[col[i]] = v[col[i]];
        aa[col[i]] = a[col[i]];
      }
    if (rc) return rc;
    for (int i = 0; i < ncol; ++i) {
      const int c = col[i];
      if (c >= nq) continue;
      for (long e = b->pcolptr[c]; e < b->pcolptr[c + 1]; ++e) {
        const int r = b->prowind[e];
        C[e] = (R1[r] - Rm[r]) / (2.0 * step[c]);
        M[e] = 0.5 * (R1[r] + Rm[r]) - R0[r];
      }
    }
  }
  return 0;
}

/* K, C, M of a sparse body (internal.h). The analytic op's pair-order values sit in scratch and are
   summed into their CSC entries: duplicate pairs (element blocks sharing a node) add up. */
size_t fmb_body_sparse_scratch(const fmbBodyInst* b) {
  const size_t fd = fd_sparse_scratch(b), exact = 3 * (size_t)b->npair;
  return b->type && b->type->pattern_jacobian && exact > fd ? exact : fd;
}

int fmb_body_sparse_blocks(const fmbBodyInst* b, const fmbEnv* env, const double* q, const double* v, const double* a,
                           const double* z, const double* ewt_q, const double* ewt_v, double* K, double* C, double* M,
                           double* work, double* scratch) {
  if (!b->type->pattern_jacobian) return fd_body_sparse(b, env, q, v, a, z, ewt_q, ewt_v, K, C, M, work, scratch);
  double *Kp = scratch, *Cp = Kp + b->npair, *Mp = Cp + b->npair;
  const int rc = b->type->pattern_jacobian(b->self, env, q, v, a, z, Kp, Cp, Mp, work);
  if (rc) return rc;
  memset(K, 0, sizeof(double) * (size_t)b->pnnz);
  memset(C, 0, sizeof(double) * (size_t)b->pnnz);
  memset(M, 0, sizeof(double) * (size_t)b->pnnz);
  for (long k = 0; k < b->npair; ++k) {
    K[b->ppos[k]] += Kp[k];
    C[b->ppos[k]] += Cp[k];
    M[b->ppos[k]] += Mp[k];
  }
  for (long k = 0; k < b->pnnz; ++k)
    if (!isfinite(K[k]) || !isfinite(C[k]) || !isfinite(M[k])) return 1; /* a wild trial step: IDA cuts it */
  return 0;
}
