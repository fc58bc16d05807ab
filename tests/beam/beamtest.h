/*
 * beamtest.h — shared helpers of the beam plugin's white-box tests.
 *
 * Each test program includes the plugin's source (bodies/beam.c) so it can build a Beam directly
 * from numbers (no scene parser) and call its static ops. The helpers here are independent of the
 * plugin's internals except for the Beam struct itself and beam_setup.
 */
#ifndef BEAMTEST_H
#define BEAMTEST_H

#include <math.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>

#include "../../bodies/beam.c"

#include "check.h"

/* the seed beam (Liu, Hong & Liu 2009, section 4.1) */
#define SEED_RHO 2767.0
#define SEED_L 1.8
#define SEED_I 1.302e-10
#define SEED_A 2.5e-4
#define SEED_E 68.95e9

/* a beam built from numbers, with the plugin's own defaults; ng <= 0 = the model's default */
static inline Beam* bt_beam(int model, int ne, int ng, double L, double rho, double A, double Izz, double Emod) {
  Beam* b = calloc(1, sizeof *b);
  b->model = model;
  b->ne = ne;
  b->ng = ng > 0 ? ng : default_points(model);
  b->L = L;
  b->rho = rho;
  b->A = A;
  b->Izz = Izz;
  b->Emod = Emod;
  beam_setup(b);
  return b;
}

static inline Beam* bt_seed_beam(int model, int ne) {
  return bt_beam(model, ne, 0, SEED_L, SEED_RHO, SEED_A, SEED_I, SEED_E);
}

/* deterministic uniform random numbers in [-1, 1] */
static unsigned long long bt_rng_state = 88172645463325252ULL;
static inline double bt_rand(void) {
  bt_rng_state ^= bt_rng_state << 13;
  bt_rng_state ^= bt_rng_state >> 7;
  bt_rng_state ^= bt_rng_state << 17;
  return (double)(bt_rng_state >> 11) / 9007199254740992.0 * 2.0 - 1.0;
}

static inline double* bt_work(const Beam* b) { return calloc(beam_nwork(b) + 1, sizeof(double)); }

/* the plugin's residual */
static inline void bt_residual(const Beam* b, const fmbEnv* env, const double* q, const double* v, const double* a,
                               double* R) {
  double* w = bt_work(b);
  beam_residual(b, env, q, v, a, R, w);
  free(w);
}

/* M (nc x nc, column-major, column j = (R(q, v, s e_j) - R(q, v, 0)) / s: R is linear in a) */
static inline void bt_mass(const Beam* b, const double* q, const double* v, double* M) {
  int nc = 3 + b->n;
  double* a = calloc((size_t)nc, sizeof(double));
  double* R0 = calloc((size_t)nc, sizeof(double));
  fmbEnv env0 = {.gravity = {0.0, 0.0}, .has_gravity = 0};
  bt_residual(b, &env0, q, v, a, R0);
  for (int j = 0; j < nc; ++j) {
    /* a large acceleration keeps the cancellation against R0 (elastic, velocity terms) small */
    const double big = 1e6;
    a[j] = big;
    bt_residual(b, &env0, q, v, a, M + (size_t)j * nc);
    for (int i = 0; i < nc; ++i) M[(size_t)j * nc + i] = (M[(size_t)j * nc + i] - R0[i]) / big;
    a[j] = 0.0;
  }
  free(a);
  free(R0);
}

/* ---------------------------------------------------------------------------------------------
 * Small dense linear algebra for the tests (column-major n x n).
 * ------------------------------------------------------------------------------------------- */

/* Cholesky A = L L^T in place (lower part); returns -1 if not positive definite */
static inline int bt_cholesky(double* A, int n) {
  for (int j = 0; j < n; ++j) {
    double d = A[j + j * n];
    for (int k = 0; k < j; ++k) d -= A[j + k * n] * A[j + k * n];
    if (!(d > 0.0)) return -1;
    d = sqrt(d);
    A[j + j * n] = d;
    for (int i = j + 1; i < n; ++i) {
      double s = A[i + j * n];
      for (int k = 0; k < j; ++k) s -= A[i + k * n] * A[j + k * n];
      A[i + j * n] = s / d;
    }
  }
  return 0;
}

/* cyclic Jacobi eigenvalues of a symmetric matrix (destroyed); eigenvalues sorted ascending */
static inline void bt_jacobi_eig(double* A, int n, double* lam) {
  for (int sweep = 0; sweep < 100; ++sweep) {
    double off = 0.0, tot = 0.0;
    for (int j = 0; j < n; ++j)
      for (int i = 0; i < n; ++i) {
        tot += A[i + j * n] * A[i + j * n];
        if (i != j) off += A[i + j * n] * A[i + j * n];
      }
    if (off <= 1e-30 * tot) break;
    for (int p = 0; p < n; ++p)
      for (int r = p + 1; r < n; ++r) {
        double apr = A[p + r * n];
        if (apr == 0.0) continue;
        double app = A[p + p * n], arr = A[r + r * n];
        double tau = (arr - app) / (2.0 * apr);
        double t = (tau >= 0.0 ? 1.0 : -1.0) / (fabs(tau) + sqrt(1.0 + tau * tau));
        double c = 1.0 / sqrt(1.0 + t * t), s = t * c;
        for (int k = 0; k < n; ++k) {
          double akp = A[k + p * n], akr = A[k + r * n];
          A[k + p * n] = c * akp - s * akr;
          A[k + r * n] = s * akp + c * akr;
        }
        for (int k = 0; k < n; ++k) {
          double apk = A[p + k * n], ark = A[r + k * n];
          A[p + k * n] = c * apk - s * ark;
          A[r + k * n] = s * apk + c * ark;
        }
      }
  }
  for (int i = 0; i < n; ++i) lam[i] = A[i + i * n];
  for (int i = 1; i < n; ++i)
    for (int j = i; j > 0 && lam[j] < lam[j - 1]; --j) {
      double t = lam[j];
      lam[j] = lam[j - 1];
      lam[j - 1] = t;
    }
}

/* generalized symmetric eigenproblem K x = lam M x (M positive definite): eigenvalues ascending.
   Returns -1 if M is not positive definite. K and M are destroyed. */
static inline int bt_gen_eig(double* K, double* M, int n, double* lam) {
  if (bt_cholesky(M, n)) return -1;
  /* C = L^-1 K L^-T: solve L Y = K (columns), then C = L^-1 Y^T */
  for (int pass = 0; pass < 2; ++pass) {
    for (int j = 0; j < n; ++j)
      for (int i = 0; i < n; ++i) {
        double s = K[i + j * n];
        for (int k = 0; k < i; ++k) s -= M[i + k * n] * K[k + j * n];
        K[i + j * n] = s / M[i + i * n];
      }
    for (int j = 0; j < n; ++j)
      for (int i = j + 1; i < n; ++i) {
        double t = K[i + j * n];
        K[i + j * n] = K[j + i * n];
        K[j + i * n] = t;
      }
  }
  bt_jacobi_eig(K, n, lam);
  return 0;
}

#endif
