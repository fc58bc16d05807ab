/* dense.c — small dense linear algebra for setup-time work (consistent initial conditions, the
 * mass-definiteness check). Column-major, n x n. Not used on the residual/Jacobian path. */
#include <math.h>
#include <string.h>

#include "internal.h"

int fmb_lu_factor(int n, double* A, int* piv) {
  for (int k = 0; k < n; ++k) {
    int p = k;
    double best = fabs(A[(size_t)k * n + k]);
    for (int i = k + 1; i < n; ++i)
      if (fabs(A[(size_t)k * n + i]) > best) {
        best = fabs(A[(size_t)k * n + i]);
        p = i;
      }
    piv[k] = p;
    if (best == 0.0 || !isfinite(best)) return k + 1;
    if (p != k)
      for (int j = 0; j < n; ++j) {
        double t = A[(size_t)j * n + k];
        A[(size_t)j * n + k] = A[(size_t)j * n + p];
        A[(size_t)j * n + p] = t;
      }
    const double d = A[(size_t)k * n + k];
    for (int i = k + 1; i < n; ++i) A[(size_t)k * n + i] /= d;
    for (int j = k + 1; j < n; ++j) {
      const double f = A[(size_t)j * n + k];
      if (f == 0.0) continue;
      for (int i = k + 1; i < n; ++i) A[(size_t)j * n + i] -= f * A[(size_t)k * n + i];
    }
  }
  return 0;
}

/* fmb_lu_factor swaps whole rows, the multipliers of earlier columns included (P A = L U), so all
   the swaps apply to b before the forward substitution; interleaving them with it (LINPACK's
   order, where only the trailing columns are swapped) pairs rows with the wrong multipliers */
void fmb_lu_solve(int n, const double* LU, const int* piv, double* b) {
  for (int k = 0; k < n; ++k) {
    const int p = piv[k];
    if (p != k) {
      const double t = b[k];
      b[k] = b[p];
      b[p] = t;
    }
  }
  for (int k = 0; k < n; ++k)
    for (int i = k + 1; i < n; ++i) b[i] -= LU[(size_t)k * n + i] * b[k];
  for (int k = n - 1; k >= 0; --k) {
    b[k] /= LU[(size_t)k * n + k];
    for (int i = 0; i < k; ++i) b[i] -= LU[(size_t)k * n + i] * b[k];
  }
}

int fmb_cholesky(int n, double* A) {
  for (int j = 0; j < n; ++j) {
    double d = A[(size_t)j * n + j];
    for (int k = 0; k < j; ++k) d -= A[(size_t)k * n + j] * A[(size_t)k * n + j];
    if (!(d > 0.0)) return j + 1;
    d = sqrt(d);
    A[(size_t)j * n + j] = d;
    for (int i = j + 1; i < n; ++i) {
      double s = A[(size_t)j * n + i];
      for (int k = 0; k < j; ++k) s -= A[(size_t)k * n + i] * A[(size_t)k * n + j];
      A[(size_t)j * n + i] = s / d;
    }
  }
  return 0;
}

/* Independent rows of the row-major nr x nc matrix A by Gram-Schmidt with pivoting (the row of
   largest remaining norm first, orthogonalized twice: Bjorck's "twice is enough"). order[0..rank)
   are independent rows, order[rank..nr) depend on them to a relative tolerance tol of the largest
   row norm. work: nr * nc + nr doubles. Returns the rank. */
int fmb_independent_rows(int nr, int nc, const double* A, double tol, int* order, double* work) {
  double* W = work;
  double* norm2 = work + (size_t)nr * nc;
  memcpy(W, A, sizeof(double) * (size_t)nr * nc);
  double top = 0.0;
  for (int i = 0; i < nr; ++i) {
    order[i] = i;
    double s = 0.0;
    for (int c = 0; c < nc; ++c) s += W[(size_t)i * nc + c] * W[(size_t)i * nc + c];
    norm2[i] = s;
    top = fmax(top, s);
  }
  int rank = 0;
  for (int k = 0; k < nr; ++k) {
    int p = k;
    for (int i = k + 1; i < nr; ++i)
      if (norm2[i] > norm2[p]) p = i;
    if (!(norm2[p] > tol * tol * top) || top == 0.0) break;
    if (p != k) { /* swap rows k and p of W, their norms and their order */
      for (int c = 0; c < nc; ++c) {
        const double t = W[(size_t)k * nc + c];
        W[(size_t)k * nc + c] = W[(size_t)p * nc + c];
        W[(size_t)p * nc + c] = t;
      }
      const double tn = norm2[k];
      norm2[k] = norm2[p];
      norm2[p] = tn;
      const int to = order[k];
      order[k] = order[p];
      order[p] = to;
    }
    double* wk = W + (size_t)k * nc;
    const double inv = 1.0 / sqrt(norm2[k]);
    for (int c = 0; c < nc; ++c) wk[c] *= inv;
    for (int i = k + 1; i < nr; ++i) {
      double* wi = W + (size_t)i * nc;
      for (int pass = 0; pass < 2; ++pass) {
        double d = 0.0;
        for (int c = 0; c < nc; ++c) d += wi[c] * wk[c];
        for (int c = 0; c < nc; ++c) wi[c] -= d * wk[c];
      }
      double s = 0.0;
      for (int c = 0; c < nc; ++c) s += wi[c] * wi[c];
      norm2[i] = s;
    }
    rank = k + 1;
  }
  return rank;
}
