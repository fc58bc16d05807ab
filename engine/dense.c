/* dense.c — small dense linear algebra for setup-time work (consistent initial conditions, the
 * mass-definiteness check). Column-major, n x n. Not used on the residual/Jacobian path. */
#include <math.h>

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
