/*
 * test_beam_jacobian.c — the beam's analytic Jacobians (beam_jacobian, beam_pattern_jacobian)
 * against central differences of the residuals they differentiate, for all three models and both
 * assemblies (docs/beam.md, "Jacobian").
 *
 * At three random states (deflections of a few percent of L, slopes ~0.1, random rates and
 * accelerations, gravity on, damping on) of a soft 5-element beam:
 *   dense:  K, C, M of beam_jacobian against differences of beam_residual;
 *   banded: the pattern values summed into dense blocks over [R; Rz] x [q; z], v, a against
 *           differences of beam_residual_aux, with z off its consistent value (Rz != 0), and
 *           every difference outside the declared pairs zero.
 * Each block must agree to 1e-6 of its largest entry. R is linear in a (a unit step is exact)
 * and quadratic in v (a central difference of any step is exact up to round-off), so only the
 * q columns carry a truncation error (step 1e-5: ~1e-10 of the block). A wrong or missing term
 * of the coupling (relative size w2'^2 ~ 1e-2 here) or a dropped chain through the prefix or
 * tail sums is 1e4 times the tolerance.
 */
#include "beamtest.h"

enum { NE = 5 };

/* max |A - B| / max |B| over n entries */
static double block_err(const double* A, const double* B, size_t n) {
  double d = 0.0, s = 1e-300;
  for (size_t i = 0; i < n; ++i) {
    d = fmax(d, fabs(A[i] - B[i]));
    s = fmax(s, fabs(B[i]));
  }
  return d / s;
}

/* a random state: q (small deformation, any angle), v, a */
static void random_state(const Beam* b, double* q, double* v, double* a) {
  const int nq = 3 + b->n;
  for (int i = 0; i < nq; ++i) {
    q[i] = i < 3 ? bt_rand() : 0.05 * b->L * bt_rand();
    v[i] = bt_rand();
    a[i] = bt_rand();
  }
  q[2] *= 3.0;
  v[2] = 3.0 + bt_rand(); /* a spinning frame */
}

static Beam* test_beam(int model, int banded) {
  /* conform's example beam (soft: elastic forces do not swamp the inertial ones) */
  Beam* b = bt_beam(model, NE, 0, 1.0, 1000.0, 1e-3, 1e-7, 1e6);
  b->beta = 0.05;
  b->banded = banded;
  return b;
}

static const fmbEnv grav = {.gravity = {0.3, -9.81}, .has_gravity = 1};

static void check_dense(int model) {
  Beam* b = test_beam(model, 0);
  const int n = 3 + b->n;
  const size_t nn = (size_t)n * n;
  double* buf = calloc(6 * nn + 6 * (size_t)n, sizeof(double));
  double *K = buf, *C = K + nn, *M = C + nn, *Kd = M + nn, *Cd = Kd + nn, *Md = Cd + nn;
  double *q = Md + nn, *v = q + n, *a = v + n, *R1 = a + n, *R2 = R1 + n;
  double* work = bt_work(b);
  for (int trial = 0; trial < 3; ++trial) {
    random_state(b, q, v, a);
    ENSURE(beam_jacobian(b, &grav, q, v, a, K, C, M, work) == 0);
    double* xs[3] = {q, v, a};
    double* fd[3] = {Kd, Cd, Md};
    for (int k = 0; k < 3; ++k)
      for (int j = 0; j < n; ++j) {
        const double x0 = xs[k][j], h = k == 0 ? 1e-5 : 1.0;
        xs[k][j] = x0 + h;
        beam_residual(b, &grav, q, v, a, R1, work);
        xs[k][j] = x0 - h;
        beam_residual(b, &grav, q, v, a, R2, work);
        xs[k][j] = x0;
        for (int i = 0; i < n; ++i) fd[k][(size_t)j * n + i] = (R1[i] - R2[i]) / (2.0 * h);
      }
    const double eK = block_err(K, Kd, nn), eC = block_err(C, Cd, nn), eM = block_err(M, Md, nn);
    printf("%-8s dense  state %d: K %.1e  C %.1e  M %.1e\n", model_names[model], trial, eK, eC, eM);
    ENSURE(eK < 1e-6);
    ENSURE(eC < 1e-6);
    ENSURE(eM < 1e-6);
  }
  free(work);
  free(buf);
  free(b);
}

static void check_banded(int model) {
  Beam* b = test_beam(model, 1);
  const int n = 3 + b->n, nz = beam_naux(b), N = n + nz;
  const long np = beam_pattern(b, NULL, NULL);
  ENSURE(np > 0);
  const size_t NN = (size_t)N * N, Nn = (size_t)N * n;
  double* buf = calloc(4 * NN + 2 * Nn + 3 * (size_t)np + 3 * (size_t)n + (size_t)nz + 2 * (size_t)N, sizeof(double));
  int* pr = calloc(2 * (size_t)np, sizeof(int));
  int* pc = pr + np;
  double *Ka = buf, *Kd = Ka + NN, *Ca = Kd + NN, *Cd = Ca + Nn, *Ma = Cd + Nn, *Md = Ma + NN;
  double *Kp = Md + NN, *Cp = Kp + np, *Mp = Cp + np;
  double *q = Mp + np, *v = q + n, *a = v + n, *z = a + n, *F1 = z + nz, *F2 = F1 + N;
  double* work = bt_work(b);
  beam_pattern(b, pr, pc);
  for (int trial = 0; trial < 3; ++trial) {
    random_state(b, q, v, a);
    ENSURE(beam_aux_initial(b, &grav, q, v, a, z, work) == 0);
    for (int i = 0; i < nz; ++i) z[i] = z[i] * (1.0 + 0.01 * bt_rand()) + 1e-3 * bt_rand();
    ENSURE(beam_pattern_jacobian(b, &grav, q, v, a, z, Kp, Cp, Mp, work) == 0);
    memset(Ka, 0, NN * sizeof(double));
    memset(Ca, 0, Nn * sizeof(double));
    memset(Ma, 0, NN * sizeof(double));
    for (long k = 0; k < np; ++k) {
      Ka[(size_t)pc[k] * N + pr[k]] += Kp[k];
      if (pc[k] < n) {
        Ca[(size_t)pc[k] * N + pr[k]] += Cp[k];
        Ma[(size_t)pc[k] * N + pr[k]] += Mp[k];
      }
      ENSURE(pc[k] < n || (Cp[k] == 0.0 && Mp[k] == 0.0)); /* C, M are 0 in the z columns */
    }
    double* xs[4] = {q, v, a, z};
    for (int k = 0; k < 4; ++k)
      for (int j = 0; j < (k == 3 ? nz : n); ++j) {
        const double x0 = xs[k][j], h = k == 0 || k == 3 ? 1e-5 * (1.0 + fabs(x0)) : 1.0;
        xs[k][j] = x0 + h;
        beam_residual_aux(b, &grav, q, v, a, z, F1, F1 + n, work);
        xs[k][j] = x0 - h;
        beam_residual_aux(b, &grav, q, v, a, z, F2, F2 + n, work);
        xs[k][j] = x0;
        double* col = k == 0   ? Kd + (size_t)j * N
                      : k == 1 ? Cd + (size_t)j * N
                      : k == 2 ? Md + (size_t)j * N
                               : Kd + (size_t)(n + j) * N;
        for (int i = 0; i < N; ++i) col[i] = (F1[i] - F2[i]) / (2.0 * h);
      }
    const double eK = block_err(Ka, Kd, NN), eC = block_err(Ca, Cd, Nn), eM = block_err(Ma, Md, Nn);
    /* a coupling the pattern leaves out would be missing from the Newton matrix */
    double outside = 0.0, scale = 1e-300;
    for (size_t i = 0; i < NN; ++i) scale = fmax(scale, fabs(Kd[i]));
    memset(Ka, 0, NN * sizeof(double));
    for (long k = 0; k < np; ++k) Ka[(size_t)pc[k] * N + pr[k]] = 1.0;
    for (size_t i = 0; i < NN; ++i)
      if (Ka[i] == 0.0) outside = fmax(outside, fabs(Kd[i]) + (i < Nn ? fabs(Cd[i]) + fabs(Md[i]) : 0.0));
    printf("%-8s banded state %d: K %.1e  C %.1e  M %.1e  outside the pattern %.1e\n", model_names[model], trial, eK,
           eC, eM, outside / scale);
    ENSURE(eK < 1e-6);
    ENSURE(eC < 1e-6);
    ENSURE(eM < 1e-6);
    ENSURE(outside < 1e-9 * scale);
  }
  free(work);
  free(pr);
  free(buf);
  free(b);
}

int main(void) {
  for (int model = BEAM_ZOAC; model <= BEAM_COMPLETE; ++model) {
    check_dense(model);
    check_banded(model);
  }
  return fmbt_finish("test_beam_jacobian");
}
