/*
 * exacttest.h — helpers of the exact beam's white-box tests (tests/exact/). Each test includes the
 * plugin's source (bodies/beam_exact.c) to build a BeamExact from numbers and call its ops; the
 * linear algebra here (dense LU, Hermitian inertia counts) is independent of the plugin.
 */
#ifndef EXACTTEST_H
#define EXACTTEST_H

#include <complex.h>
#include <math.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>

#include "../../bodies/beam_exact.c"

#include "check.h"

/* the seed beam (Liu, Hong & Liu 2009, section 4.1) */
#define SEED_RHO 2767.0
#define SEED_L 1.8
#define SEED_I 1.302e-10
#define SEED_A 2.5e-4
#define SEED_E 68.95e9

static inline BeamExact* et_beam(int ne, int integration) {
  BeamExact* b = calloc(1, sizeof *b);
  b->L = SEED_L;
  b->rho = SEED_RHO;
  b->A = SEED_A;
  b->Izz = SEED_I;
  b->Emod = SEED_E;
  b->ne = ne;
  b->integration = integration;
  exact_setup(b);
  return b;
}

static inline int et_nc(const BeamExact* b) { return 3 + b->n; }

/* deterministic uniform random numbers in [-1, 1] */
static unsigned long long et_rng = 88172645463325252ULL;
static inline double et_rand(void) {
  et_rng ^= et_rng << 13;
  et_rng ^= et_rng >> 7;
  et_rng ^= et_rng << 17;
  return (double)(et_rng >> 11) / 9007199254740992.0 * 2.0 - 1.0;
}

/* the submatrix of rows/cols [k0, nc) of a column-major nc x nc matrix, into n x n */
static inline void et_sub(const double* F, int nc, int k0, double* P) {
  const int n = nc - k0;
  for (int j = 0; j < n; ++j)
    for (int i = 0; i < n; ++i) P[i + (size_t)j * n] = F[(k0 + i) + (size_t)(k0 + j) * nc];
}

/* solve A x = b (column-major n x n, destroyed) by LU with partial pivoting; 0 or -1 if singular */
static inline int et_solve(int n, double* A, double* x) {
  for (int k = 0; k < n; ++k) {
    int p = k;
    for (int i = k + 1; i < n; ++i)
      if (fabs(A[i + (size_t)k * n]) > fabs(A[p + (size_t)k * n])) p = i;
    if (A[p + (size_t)k * n] == 0.0) return -1;
    if (p != k) {
      for (int j = 0; j < n; ++j) {
        double t = A[k + (size_t)j * n];
        A[k + (size_t)j * n] = A[p + (size_t)j * n];
        A[p + (size_t)j * n] = t;
      }
      double t = x[k];
      x[k] = x[p];
      x[p] = t;
    }
    for (int i = k + 1; i < n; ++i) {
      double l = A[i + (size_t)k * n] / A[k + (size_t)k * n];
      if (l == 0.0) continue;
      for (int j = k + 1; j < n; ++j) A[i + (size_t)j * n] -= l * A[k + (size_t)j * n];
      x[i] -= l * x[k];
    }
  }
  for (int i = n - 1; i >= 0; --i) {
    double s = x[i];
    for (int j = i + 1; j < n; ++j) s -= A[i + (size_t)j * n] * x[j];
    x[i] = s / A[i + (size_t)i * n];
  }
  return 0;
}

/* Number of negative eigenvalues of the Hermitian matrix H (column-major n x n, destroyed) by
   Sylvester's law of inertia on H = L D L^H (no pivoting: used away from exact singularity). */
static inline int et_negative_count(int n, double complex* H) {
  int neg = 0;
  for (int k = 0; k < n; ++k) {
    const double d = creal(H[k + (size_t)k * n]);
    if (d < 0.0) ++neg;
    /* lower triangle: H_ij -= H_ik conj(H_jk) / d for i >= j > k */
    for (int j = k + 1; j < n; ++j) {
      const double complex cjk = conj(H[j + (size_t)k * n]) / d;
      for (int i = j; i < n; ++i) H[i + (size_t)j * n] -= H[i + (size_t)k * n] * cjk;
    }
  }
  return neg;
}

/* Count of eigenvalue frequencies below omega of the gyroscopic system M x'' + G x' + K x = 0
   (M, K symmetric, G skew; column-major n x n): the Hermitian K - omega^2 M + i omega G has one
   negative eigenvalue per natural frequency below omega (each crosses zero downwards). */
static inline int et_count_below(int n, const double* K, const double* G, const double* M, double omega) {
  double complex* H = malloc((size_t)n * n * sizeof *H);
  for (size_t k = 0; k < (size_t)n * n; ++k) H[k] = K[k] - omega * omega * M[k] + I * omega * (G ? G[k] : 0.0);
  int c = et_negative_count(n, H);
  free(H);
  return c;
}

/* the k-th (1-based) natural frequency in (lo, hi) by bisection on the inertia count */
static inline double et_frequency(int n, const double* K, const double* G, const double* M, int k, double lo,
                                  double hi) {
  for (int it = 0; it < 80 && hi - lo > 1e-12 * hi; ++it) {
    const double mid = 0.5 * (lo + hi);
    if (et_count_below(n, K, G, M, mid) >= k)
      hi = mid;
    else
      lo = mid;
  }
  return 0.5 * (lo + hi);
}

#endif
