/*
 * test_exact_element.c — the exact beam (`model: exact`, bodies/beam_exact.c) against values that
 * do not come from it.
 *
 * A. Analytic Jacobian K = dR/dq, C = dR/dv, M = dR/da vs Richardson-extrapolated central
 *    differences of the residual, column by column within 1e-9 of the column's largest entry
 *    (see column_error), inertial part (moving, under gravity) and elastic part (strained) apart,
 *    both integrations. The banded assembly (exact_pattern + exact_pattern_jacobian, pairs summed
 *    as the engine sums them) scattered into dense: equal to the dense Jacobian to 1e-12 of its
 *    largest entry (so the pattern covers every nonzero) and within 1e-9 of the differences.
 *    A1: the same at a state of the flexible pendulum (16 elements, sagged, swinging).
 * B. Rigid-motion invariance: a rotated and translated straight element has no elastic force;
 *    a deformed element and its rotated copy have the same energy and rotated forces; a beam whose
 *    frame is moved anywhere, undeformed, has R = 0.
 * C. Modes: free beam (frame free) straight and bent to a circle arc (kappa = 0.5 1/m): exactly
 *    three eigenvalues of K x = w^2 M x near zero (no hourglass mode, both integrations); the first
 *    free-free and the first three clamped frequencies vs Euler-Bernoulli (beta L = 4.73004,
 *    1.87510, 4.69409, 7.85476) within 1e-4.
 * D. Mass with a free frame: positive definite in a deformed, moving state, and 1/2 v^T M v equal
 *    to the kinetic energy that exact_energy integrates on its own path.
 * E. Elastica, cantilever under a dead tip load, alpha = P L^2/(EI) = 1, 2, 5: tip deflection vs
 *    Bisshopp & Drucker (inextensible) v/L = 0.30172077, 0.49345748, 0.71379152 and shortening
 *    (L - x)/L = 0.05643324, 0.16064172, 0.38762836; 16 elements, static Newton on the body's own
 *    residual. Full integration locks (its error is over 10x the reduced one at alpha = 1).
 * F. Rotating at a constant Omega = 15 rad/s: steady tip stretch vs rho Omega^2 L^3/(3E) (1e-4),
 *    and the first in-plane frequency of the linearization about the steady state (mass, Coriolis
 *    and stiffness from the analytic Jacobian) vs the rotating-cantilever value 6.33515 rad/s (1e-4).
 */
#include "exacttest.h"

/* ---- A ---------------------------------------------------------------------------------------- */
static void residual(const BeamExact* b, const fmbEnv* env, const double* q, const double* v, const double* a,
                     double* R) {
  exact_residual(b, env, q, v, a, R, NULL);
}

/* worst over columns of max_i |A_ij - B_ij| / max(max_i |A_ij|, 1e-3 max_ij |A_ij|): column-
   relative, except that columns a thousand times smaller than the matrix's largest entry are
   measured against that thousandth (their differences carry the round-off of the whole residual) */
static double column_error(int nc, const double* A, const double* B) {
  double worst = 0.0, all = 0.0;
  for (size_t k = 0; k < (size_t)nc * nc; ++k) all = fmax(all, fabs(A[k]));
  for (int j = 0; j < nc; ++j) {
    double amax = 1e-3 * all, dmax = 0.0;
    for (int i = 0; i < nc; ++i) {
      amax = fmax(amax, fabs(A[i + (size_t)j * nc]));
      dmax = fmax(dmax, fabs(A[i + (size_t)j * nc] - B[i + (size_t)j * nc]));
    }
    worst = fmax(worst, amax > 0.0 ? dmax / amax : dmax);
  }
  return worst;
}

/* derivative of R wrt x[j] (x one of q, v, a) by Richardson on central differences */
static void fd_column(const BeamExact* b, const fmbEnv* env, double* q, double* v, double* a, double* x, int j,
                      double h, double* col) {
  const int nc = et_nc(b);
  double* Rp = malloc(2 * sizeof(double) * (size_t)nc);
  double* Rm = Rp + nc;
  double x0 = x[j];
  double d[2][512];
  for (int k = 0; k < 2; ++k) {
    const double hk = k ? h / 2 : h;
    x[j] = x0 + hk;
    residual(b, env, q, v, a, Rp);
    x[j] = x0 - hk;
    residual(b, env, q, v, a, Rm);
    for (int i = 0; i < nc; ++i) d[k][i] = (Rp[i] - Rm[i]) / (2 * hk);
  }
  x[j] = x0;
  for (int i = 0; i < nc; ++i) col[i] = (4.0 * d[1][i] - d[0][i]) / 3.0;
  free(Rp);
}

/* The banded assembly's values (exact_pattern_jacobian over exact_pattern's pairs, duplicates
   summed as the engine sums them) scattered into dense nc x nc K, C, M: an entry the pattern
   misses stays 0 and shows as a difference from the dense Jacobian. */
static void banded_as_dense(const BeamExact* b, const fmbEnv* env, const double* q, const double* v, const double* a,
                            double* K, double* C, double* M) {
  BeamExact banded = *b;
  banded.banded = 1;
  banded.mixed = 0; /* the displacement form's pattern (the mixed one: test_mixed_jacobian) */
  const int nc = et_nc(b);
  const long np = exact_pattern(&banded, NULL, NULL);
  ENSURE(np == exact_npair(&banded));
  int* rows = malloc(2 * sizeof(int) * (size_t)np);
  int* cols = rows + np;
  double* val = malloc(3 * sizeof(double) * (size_t)np);
  ENSURE(exact_pattern(&banded, rows, cols) == np);
  ENSURE(exact_pattern_jacobian(&banded, env, q, v, a, NULL, val, val + np, val + 2 * np, NULL) == 0);
  memset(K, 0, 3 * sizeof(double) * (size_t)nc * nc);
  for (long k = 0; k < np; ++k) {
    ENSURE(rows[k] >= 0 && rows[k] < nc && cols[k] >= 0 && cols[k] < nc);
    const size_t at = (size_t)cols[k] * nc + (size_t)rows[k];
    K[at] += val[k];
    C[at] += val[np + k];
    M[at] += val[2 * np + k];
  }
  free(rows);
  free(val);
}

/* max |A - B| / max |A| over an nc x nc matrix */
static double matrix_difference(int nc, const double* A, const double* B) {
  double amax = 0.0, dmax = 0.0;
  for (size_t k = 0; k < (size_t)nc * nc; ++k) amax = fmax(amax, fabs(A[k])), dmax = fmax(dmax, fabs(A[k] - B[k]));
  return amax > 0.0 ? dmax / amax : dmax;
}

/* the differences' steps in q and v, relative to jacobian_errors' (A1 refines the elastic one) */
static double fd_step_scale = 1.0;

/* analytic K, C, M of b at (q, v, a) vs differences: worst column-relative errors in e[3]; the
   banded values vs differences in e[3..5] and vs the dense analytic Jacobian in e[6..8] */
static void jacobian_errors(const BeamExact* b, const fmbEnv* env, double* q, double* v, double* a, double e[9]) {
  const int nc = et_nc(b);
  const size_t nn = (size_t)nc * nc;
  double* K = calloc(9 * nn, sizeof(double));
  double *C = K + nn, *M = C + nn;
  double *Kf = M + nn, *Cf = Kf + nn, *Mf = Cf + nn;
  double *Kb = Mf + nn, *Cb = Kb + nn, *Mb = Cb + nn;
  ENSURE(exact_jacobian(b, env, q, v, a, K, C, M, NULL) == 0);
  banded_as_dense(b, env, q, v, a, Kb, Cb, Mb);
  for (int j = 0; j < nc; ++j) {
    fd_column(b, env, q, v, a, q, j, (j == 2 ? 1e-2 : 1e-3) * fd_step_scale, Kf + (size_t)j * nc);
    fd_column(b, env, q, v, a, v, j, 1e-2 * fd_step_scale, Cf + (size_t)j * nc);
    fd_column(b, env, q, v, a, a, j, 1.0, Mf + (size_t)j * nc);
  }
  e[0] = column_error(nc, K, Kf);
  e[1] = column_error(nc, C, Cf);
  e[2] = column_error(nc, M, Mf);
  e[3] = column_error(nc, Kb, Kf);
  e[4] = column_error(nc, Cb, Cf);
  e[5] = column_error(nc, Mb, Mf);
  e[6] = matrix_difference(nc, K, Kb);
  e[7] = matrix_difference(nc, C, Cb);
  e[8] = matrix_difference(nc, M, Mb);
  free(K);
}

/* The residual is inertial (mass, velocity, gravity: independent of E) plus elastic (independent
   of v, a, theta). Differences of the sum would drown the small inertial entries in the elastic
   forces' round-off, so each part is checked on its own: the inertial Jacobian on a copy with
   E = 0 in a moving state under gravity, the elastic Hessian at rest in a strained state. */
static void test_jacobian(int integration) {
  BeamExact* b = et_beam(6, integration);
  BeamExact inertial = *b;
  inertial.Emod = 0.0;
  exact_setup(&inertial);
  const int nc = et_nc(b);
  fmbEnv env = {.gravity = {0.3, -9.81}, .has_gravity = 1}, env0 = {.gravity = {0.0, 0.0}, .has_gravity = 0};
  double *q = calloc(4 * (size_t)nc, sizeof(double)), *v = q + nc, *a = v + nc, *z = a + nc;
  q[0] = 0.4, q[1] = -0.2, q[2] = 0.7;
  for (int i = 3; i < nc; ++i) q[i] = 0.05 * et_rand();
  for (int i = 0; i < nc; ++i) v[i] = et_rand(), a[i] = 3.0 * et_rand();
  double ei[9], ee[9];
  jacobian_errors(&inertial, &env, q, v, a, ei);
  jacobian_errors(b, &env0, q, z, z, ee);
  printf("A. Jacobian vs differences (%s integration, column-relative): inertial K %.2e, C %.2e, M %.2e; "
         "elastic K %.2e\n",
         integration ? "full" : "reduced", ei[0], ei[1], ei[2], ee[0]);
  printf("   banded pattern values vs differences: inertial K %.2e, C %.2e, M %.2e, elastic K %.2e; "
         "vs the dense analytic Jacobian: K %.1e, C %.1e, M %.1e, elastic K %.1e\n",
         ei[3], ei[4], ei[5], ee[3], ei[6], ei[7], ei[8], ee[6]);
  for (int k = 0; k < 6; ++k) ENSURE(ei[k] < 1e-9);
  ENSURE(ee[0] < 1e-9);
  ENSURE(ee[3] < 1e-9);
  for (int k = 6; k < 9; ++k) ENSURE(ei[k] < 1e-12 && ee[k] < 1e-12);
  free(q);
  free(b);
}

/* A1. The same at a state of the flexible pendulum (scenes/paper/pendulum.yaml with model: exact,
   16 elements), where the exact beam's Newton iteration is slow (docs/performance.md, "The exact
   beam's Newton"): frame swung to theta = -0.6 and turning at 3 rad/s with 20 rad/s^2, the beam
   sagged like a cantilever under its weight (tip 0.25 m, slopes to match) with fast bending
   velocities and accelerations on top, under the scene's gravity. Whether the analytic Jacobian at
   such a state is the residual's derivative is what rules it out as the slow contraction's cause. */
static void test_jacobian_pendulum(void) {
  BeamExact* b = et_beam(16, INTEGRATION_REDUCED);
  BeamExact inertial = *b;
  inertial.Emod = 0.0;
  exact_setup(&inertial);
  const int nc = et_nc(b);
  fmbEnv env = {.gravity = {0.0, -9.81}, .has_gravity = 1}, env0 = {.gravity = {0.0, 0.0}, .has_gravity = 0};
  double *q = calloc(4 * (size_t)nc, sizeof(double)), *v = q + nc, *a = v + nc, *z = a + nc;
  q[2] = -0.6, v[2] = 3.0, a[2] = 20.0;
  for (int i = 1; i <= b->ne; ++i) {
    /* the static cantilever's shape w(x) = tip (6 xi^2 - 4 xi^3 + xi^4) / 3, xi = x / L */
    const double xi = (double)i / b->ne, tip = -0.25;
    double* nd = q + 4 + 4 * (i - 1);
    nd[1] = tip * (6.0 * xi * xi - 4.0 * xi * xi * xi + xi * xi * xi * xi) / 3.0;
    nd[3] = tip * (12.0 * xi - 12.0 * xi * xi + 4.0 * xi * xi * xi) / (3.0 * b->L);
    nd[0] = -0.5 * nd[3] * nd[3] * xi * b->L / 3.0 + 1e-6 * et_rand(); /* shortening, and a stretch */
    nd[2] = 1e-6 * et_rand();
    for (int k = 0; k < 4; ++k) v[4 + 4 * (i - 1) + k] = 0.5 * et_rand(), a[4 + 4 * (i - 1) + k] = 1e3 * et_rand();
  }
  double ei[9], ee[9];
  jacobian_errors(&inertial, &env, q, v, a, ei);
  /* elements 6x shorter than A's: the elastic differences' truncation error (h^4 / le^4) needs a
     10x smaller step (measured 9e-8 at A's step, 7e-10 at 0.3x, 9e-12 at 0.1x: truncation) */
  fd_step_scale = 0.1;
  jacobian_errors(b, &env0, q, z, z, ee);
  fd_step_scale = 1.0;
  printf("A1. Jacobian vs differences at a pendulum state (16 elements, column-relative): inertial K %.2e, "
         "C %.2e, M %.2e; elastic K %.2e; banded inertial K %.2e, elastic K %.2e\n",
         ei[0], ei[1], ei[2], ee[0], ei[3], ee[3]);
  /* inertial C: round-off of the differences (1.7e-9, growing as the step shrinks); a missing or
     stale term shows as O(1) in its column */
  for (int k = 0; k < 6; ++k) ENSURE(ei[k] < 1e-8);
  ENSURE(ee[0] < 1e-9);
  ENSURE(ee[3] < 1e-9);
  free(q);
  free(b);
}

/* A2. The mixed form (exact_naux: the axial strains at the axial points as unknowns z, N = EA z):
   exact_pattern_jacobian's values over exact_pattern's pairs, rows [R; Rz], columns [q; z],
   against Richardson differences of exact_residual_aux, in a strained state with z off eps
   (so that N's geometric stiffness and the z coupling both show); and at z = aux_initial's
   eps(q), Rz = 0 and R equal to the displacement form's exact_residual. */
static void test_mixed_jacobian(void) {
  BeamExact* b = et_beam(5, INTEGRATION_REDUCED);
  b->mixed = b->banded = 1;
  const int nc = et_nc(b), nz = exact_naux(b), nt = nc + nz;
  const fmbEnv env0 = {.gravity = {0.0, 0.0}, .has_gravity = 0};
  double* q = calloc(4 * (size_t)nt, sizeof(double));
  double *v = q + nt, *a = v + nt, *z = a + nt; /* v = a = 0: the elastic and z parts */
  for (int i = 3; i < nc; ++i) q[i] = 0.05 * et_rand();
  ENSURE(exact_aux_initial(b, &env0, q, v, a, z, NULL) == 0);
  double *R0 = calloc(3 * (size_t)nt, sizeof(double)), *Rz0 = R0 + nt, *Rd = Rz0 + nt;
  ENSURE(exact_residual_aux(b, &env0, q, v, a, z, R0, Rz0, NULL) == 0);
  exact_residual(b, &env0, q, v, a, Rd, NULL);
  double rz = 0.0, rd = 0.0, rscale = 0.0;
  for (int i = 0; i < nz; ++i) rz = fmax(rz, fabs(Rz0[i]));
  for (int i = 0; i < nc; ++i) rd = fmax(rd, fabs(R0[i] - Rd[i])), rscale = fmax(rscale, fabs(Rd[i]));
  for (int i = 0; i < nz; ++i) z[i] *= 1.0 + 0.3 * et_rand();
  /* analytic, scattered into a dense nt x nt K */
  const long np = exact_pattern(b, NULL, NULL);
  int* rows = malloc(2 * sizeof(int) * (size_t)np);
  int* cols = rows + np;
  double* val = malloc(3 * sizeof(double) * (size_t)np);
  ENSURE(exact_pattern(b, rows, cols) == np);
  ENSURE(exact_pattern_jacobian(b, &env0, q, v, a, z, val, val + np, val + 2 * np, NULL) == 0);
  double *K = calloc(2 * (size_t)nt * nt, sizeof(double)), *Kf = K + (size_t)nt * nt;
  for (long k = 0; k < np; ++k) {
    ENSURE(rows[k] >= 0 && rows[k] < nt && cols[k] >= 0 && cols[k] < nt);
    K[(size_t)cols[k] * nt + (size_t)rows[k]] += val[k];
  }
  /* differences of [R; Rz] over [q; z] */
  double* Rp = calloc(2 * (size_t)nt, sizeof(double));
  double* Rm = calloc(2 * (size_t)nt, sizeof(double));
  for (int j = 0; j < nt; ++j) {
    double* x = j < nc ? q + j : z + (j - nc);
    const double x0 = *x, h = j < nc ? (j == 2 ? 1e-2 : 1e-3) : 1e-3 * fmax(fabs(x0), 1e-6);
    double d[2][1024];
    for (int k = 0; k < 2; ++k) {
      const double hk = k ? h / 2 : h;
      *x = x0 + hk;
      exact_residual_aux(b, &env0, q, v, a, z, Rp, Rp + nc, NULL);
      *x = x0 - hk;
      exact_residual_aux(b, &env0, q, v, a, z, Rm, Rm + nc, NULL);
      for (int i = 0; i < nt; ++i) d[k][i] = (Rp[i] - Rm[i]) / (2 * hk);
    }
    *x = x0;
    for (int i = 0; i < nt; ++i) Kf[(size_t)j * nt + i] = (4.0 * d[1][i] - d[0][i]) / 3.0;
  }
  const double err = column_error(nt, K, Kf);
  printf("A2. mixed form: Jacobian over [q; z] vs differences %.2e (column-relative); at z = eps: |Rz| %.1e, "
         "R - displacement form's %.1e of %.1e\n",
         err, rz, rd, rscale);
  ENSURE(err < 1e-8);
  ENSURE(rz < 1e-12 && rd <= 1e-12 * rscale);
  free(Rp);
  free(Rm);
  free(K);
  free(val);
  free(rows);
  free(R0);
  free(q);
  free(b);
}

/* ---- B ---------------------------------------------------------------------------------------- */
static void rotate(double phi, const double in[2], double out[2]) {
  out[0] = cos(phi) * in[0] - sin(phi) * in[1];
  out[1] = sin(phi) * in[0] + cos(phi) * in[1];
}

/* nodal displacements of element 0's nodal vectors X from its straight reference */
static void to_displacement(double le, const double X[8], double D[8]) {
  const double ref[8] = {0.0, 0.0, 1.0, 0.0, le, 0.0, 1.0, 0.0};
  for (int l = 0; l < 8; ++l) D[l] = X[l] - ref[l];
}

static void test_invariance(void) {
  BeamExact* b = et_beam(8, INTEGRATION_REDUCED);
  const double le = b->le, phi = 2.1, shift[2] = {-3.0, 7.5};
  /* a straight element, rotated and translated */
  double X[8], f[8], fmax_rigid = 0.0;
  const double ref[4][2] = {{0.0, 0.0}, {1.0, 0.0}, {le, 0.0}, {1.0, 0.0}};
  for (int k = 0; k < 4; ++k) {
    rotate(phi, ref[k], X + 2 * k);
    if (!(k & 1)) X[2 * k] += shift[0], X[2 * k + 1] += shift[1];
  }
  double D[8];
  to_displacement(le, X, D);
  double U = element_elastic(b, D, NULL, f, NULL);
  for (int l = 0; l < 8; ++l) fmax_rigid = fmax(fmax_rigid, fabs(f[l]));
  /* a deformed element and its rotated copy */
  double Y[8], Yr[8], fy[8], fyr[8];
  for (int k = 0; k < 4; ++k) {
    Y[2 * k] = ref[k][0] + 0.01 * et_rand();
    Y[2 * k + 1] = ref[k][1] + 0.01 * et_rand();
    rotate(phi, Y + 2 * k, Yr + 2 * k);
    if (!(k & 1)) Yr[2 * k] += shift[0], Yr[2 * k + 1] += shift[1];
  }
  double DY[8], DYr[8];
  to_displacement(le, Y, DY);
  to_displacement(le, Yr, DYr);
  double Uy = element_elastic(b, DY, NULL, fy, NULL), Uyr = element_elastic(b, DYr, NULL, fyr, NULL), ferr = 0.0,
         fscale = 0.0;
  for (int k = 0; k < 4; ++k) {
    double fr[2];
    rotate(phi, fy + 2 * k, fr);
    ferr = fmax(ferr, fmax(fabs(fr[0] - fyr[2 * k]), fabs(fr[1] - fyr[2 * k + 1])));
    fscale = fmax(fscale, fmax(fabs(fy[2 * k]), fabs(fy[2 * k + 1])));
  }
  printf("B. rigid element: U = %.2e J, max force %.2e N (EA = %.2e N); deformed: U %.6e vs rotated %.6e, force "
         "mismatch %.2e of %.2e\n",
         U, fmax_rigid, b->EA, Uy, Uyr, ferr, fscale);
  ENSURE(fmax_rigid < 1e-8 * b->EA);
  ENSURE(U < 1e-20 * b->EA);
  ENSURE_REL(Uyr, Uy, 1e-11);
  ENSURE(ferr < 1e-11 * fscale);
  /* the whole beam: frame anywhere, undeformed, at rest, no gravity -> R = 0 */
  const int nc = et_nc(b);
  double* q = calloc(3 * (size_t)nc, sizeof(double));
  double *z = q + nc, *R = z + nc, rmax = 0.0;
  q[0] = 12.0, q[1] = -4.0, q[2] = -2.5;
  fmbEnv env0 = {.gravity = {0.0, 0.0}, .has_gravity = 0};
  exact_residual(b, &env0, q, z, z, R, NULL);
  for (int i = 0; i < nc; ++i) rmax = fmax(rmax, fabs(R[i]));
  printf("B. undeformed beam with its frame moved: max |R| = %.2e\n", rmax);
  ENSURE(rmax < 1e-14 * b->EA); /* round-off of EA eps at eps = 0 */
  free(q);
  free(b);
}

/* ---- C ---------------------------------------------------------------------------------------- */
static double eb_frequency(double betaL) {
  return betaL * betaL * sqrt(SEED_E * SEED_I / (SEED_RHO * SEED_A * pow(SEED_L, 4)));
}

/* the beam bent to an arc of curvature kappa (nodal values exact on the arc) */
static void arc_state(const BeamExact* b, double kappa, double* q) {
  for (int i = 1; i <= b->ne; ++i) {
    const double s = i * b->le;
    double* nd = q + 4 + 4 * (i - 1);
    nd[0] = sin(kappa * s) / kappa - s;
    nd[1] = (1.0 - cos(kappa * s)) / kappa;
    nd[2] = cos(kappa * s) - 1.0;
    nd[3] = sin(kappa * s);
  }
}

static void test_modes(int integration) {
  BeamExact* b = et_beam(16, integration);
  const int nc = et_nc(b), n = b->n;
  double* q = calloc(2 * (size_t)nc, sizeof(double));
  double* z = q + nc;
  double* K = calloc(4 * (size_t)nc * nc, sizeof(double));
  double *C = K + (size_t)nc * nc, *M = C + (size_t)nc * nc, *S = M + (size_t)nc * nc;
  fmbEnv env0 = {.gravity = {0.0, 0.0}, .has_gravity = 0};
  for (int curved = 0; curved < 2; ++curved) {
    if (curved) arc_state(b, 0.5, q);
    exact_jacobian(b, &env0, q, z, z, K, C, M, NULL);
    /* eigenvalues w^2 within (-1, 1) (rad/s)^2: the first elastic one is above 15 (clamped) */
    const int near_zero = et_count_below(nc, K, NULL, M, 1.0); /* w^2 < 1 */
    /* and w^2 < -1: the negative eigenvalues of K + M */
    for (size_t k = 0; k < (size_t)nc * nc; ++k) S[k] = K[k] + M[k];
    double complex* H = malloc((size_t)nc * nc * sizeof *H);
    for (size_t k = 0; k < (size_t)nc * nc; ++k) H[k] = S[k];
    const int below_minus = et_negative_count(nc, H);
    free(H);
    printf("C. free beam, %s, %s integration: %d eigenvalues w^2 in (-1, 1), %d below -1\n",
           curved ? "bent to kappa = 0.5 1/m" : "straight", integration ? "full" : "reduced", near_zero - below_minus,
           below_minus);
    ENSURE(near_zero - below_minus == 3);
    if (!curved) {
      ENSURE(below_minus == 0);
      const double w_ff = et_frequency(nc, K, NULL, M, 4, 1.0, 100.0), ref = eb_frequency(4.730040744862704);
      printf("C. first free-free frequency %.6f rad/s (Euler-Bernoulli %.6f)\n", w_ff, ref);
      ENSURE_REL(w_ff, ref, 1e-4);
      /* clamped: frame fixed, the p block */
      double *Kp = malloc(2 * sizeof(double) * (size_t)n * n), *Mp = Kp + (size_t)n * n;
      et_sub(K, nc, 3, Kp);
      et_sub(M, nc, 3, Mp);
      const double betaL[3] = {1.875104068711961, 4.694091132974175, 7.854757438237613};
      for (int k = 0; k < 3; ++k) {
        const double w = et_frequency(n, Kp, NULL, Mp, k + 1, 0.1, 200.0), r = eb_frequency(betaL[k]);
        printf("C. clamped frequency %d: %.6f rad/s (Euler-Bernoulli %.6f)\n", k + 1, w, r);
        ENSURE_REL(w, r, 1e-4);
      }
      free(Kp);
    }
  }
  free(K);
  free(q);
  free(b);
}

/* ---- D ---------------------------------------------------------------------------------------- */
static void test_mass(void) {
  BeamExact* b = et_beam(12, INTEGRATION_REDUCED);
  const int nc = et_nc(b);
  double* q = calloc(3 * (size_t)nc, sizeof(double));
  double *v = q + nc, *z = v + nc;
  arc_state(b, 1.2, q);
  q[0] = 0.3, q[1] = 0.1, q[2] = -0.8;
  for (int i = 0; i < nc; ++i) v[i] = et_rand();
  double* K = calloc(3 * (size_t)nc * nc, sizeof(double));
  double *C = K + (size_t)nc * nc, *M = C + (size_t)nc * nc;
  fmbEnv env0 = {.gravity = {0.0, 0.0}, .has_gravity = 0};
  exact_jacobian(b, &env0, q, v, z, K, C, M, NULL);
  double vMv = 0.0;
  for (int j = 0; j < nc; ++j)
    for (int i = 0; i < nc; ++i) vMv += v[i] * M[i + (size_t)j * nc] * v[j];
  fmbEnergy en;
  exact_energy(b, &env0, q, v, &en, NULL);
  double complex* H = malloc((size_t)nc * nc * sizeof *H);
  for (size_t k = 0; k < (size_t)nc * nc; ++k) H[k] = M[k];
  const int neg = et_negative_count(nc, H);
  printf("D. free-frame mass, bent and moving: %d negative pivots of %d; 1/2 v^T M v = %.12g, T = %.12g\n", neg, nc,
         0.5 * vMv, en.kinetic);
  ENSURE(neg == 0);
  ENSURE_REL(0.5 * vMv, en.kinetic, 1e-12);
  free(H);
  free(K);
  free(q);
  free(b);
}

/* ---- E, F: static solves with the frame fixed (Newton on the p rows) -------------------------- */
/* solve R_p(q, v, 0) - load = 0 for p (load on the p rows); returns Newton iterations or -1 */
static int static_solve(const BeamExact* b, double* q, const double* v, const double* load) {
  const int nc = et_nc(b), n = b->n;
  double* R = calloc((size_t)nc, sizeof(double));
  double* z = calloc((size_t)nc, sizeof(double));
  double* K = calloc(3 * (size_t)nc * nc, sizeof(double));
  double *C = K + (size_t)nc * nc, *M = C + (size_t)nc * nc;
  double* Kp = malloc(sizeof(double) * (size_t)n * n);
  double* dx = malloc(sizeof(double) * (size_t)n);
  fmbEnv env0 = {.gravity = {0.0, 0.0}, .has_gravity = 0};
  int it;
  for (it = 1; it <= 50; ++it) {
    exact_residual(b, &env0, q, v, z, R, NULL);
    double rn = 0.0;
    for (int i = 0; i < n; ++i) {
      dx[i] = -(R[3 + i] - (load ? load[i] : 0.0));
      rn = fmax(rn, fabs(dx[i]));
    }
    exact_jacobian(b, &env0, q, v, z, K, C, M, NULL);
    et_sub(K, nc, 3, Kp);
    if (et_solve(n, Kp, dx)) break;
    double dn = 0.0;
    for (int i = 0; i < n; ++i) {
      q[3 + i] += dx[i];
      dn = fmax(dn, fabs(dx[i]));
    }
    if (dn < 1e-14) break;
  }
  free(R);
  free(z);
  free(K);
  free(Kp);
  free(dx);
  return it > 50 ? -1 : it;
}

static double elastica_error(int integration, double alpha, double v_ref, double short_ref, double* short_err) {
  BeamExact* b = et_beam(16, integration);
  const int nc = et_nc(b), n = b->n, tip_y = 4 + 4 * (b->ne - 1) + 1;
  double* q = calloc(2 * (size_t)nc, sizeof(double));
  double* v = q + nc;
  double* load = calloc((size_t)n, sizeof(double));
  const int steps = 10;
  for (int k = 1; k <= steps; ++k) { /* load steps: Newton from the last equilibrium */
    load[tip_y - 3] = alpha * k / steps * b->EI / (b->L * b->L);
    ENSURE(static_solve(b, q, v, load) > 0);
  }
  const double vt = q[tip_y], ut = q[tip_y - 1];
  *short_err = fabs(-ut - short_ref * b->L);
  const double err = fabs(vt - v_ref * b->L);
  free(q);
  free(load);
  free(b);
  return err;
}

static void test_elastica(void) {
  const double alpha[3] = {1.0, 2.0, 5.0};
  const double vref[3] = {0.3017207738, 0.4934574804, 0.7137915236};
  const double sref[3] = {0.05643323628, 0.1606417208, 0.3876283607};
  const double tol[3] = {5e-7, 2.5e-6, 1.2e-5}; /* the prototype's 2.1e-7, 1.2e-6, 6.2e-6 m, x2 */
  double reduced1 = 0.0;
  for (int k = 0; k < 3; ++k) {
    double se;
    const double e = elastica_error(INTEGRATION_REDUCED, alpha[k], vref[k], sref[k], &se);
    printf("E. elastica alpha = %g, 16 elements, reduced: tip deflection error %.2e m, shortening error %.2e m\n",
           alpha[k], e, se);
    ENSURE(e < tol[k]);
    ENSURE(se < tol[k]);
    if (k == 0) reduced1 = e;
  }
  double se;
  const double full1 = elastica_error(INTEGRATION_FULL, 1.0, vref[0], sref[0], &se);
  printf("E. elastica alpha = 1, 16 elements, full integration: %.2e m (%.0fx the reduced error: membrane locking)\n",
         full1, full1 / reduced1);
  ENSURE(full1 > 10.0 * reduced1);
}

static void test_rotating(int ne, int integration, double freq_tol) {
  const double Omega = 15.0;
  BeamExact* b = et_beam(ne, integration);
  const int nc = et_nc(b), n = b->n, tip_x = 4 + 4 * (b->ne - 1);
  double* q = calloc(3 * (size_t)nc, sizeof(double));
  double *v = q + nc, *z = v + nc;
  v[2] = Omega;
  ENSURE(static_solve(b, q, v, NULL) > 0);
  const double stretch = SEED_RHO * Omega * Omega * pow(SEED_L, 3) / (3.0 * SEED_E);
  printf("F. steady spin at %g rad/s: tip stretch %.6e m, rho Omega^2 L^3/(3E) = %.6e m\n", Omega, q[tip_x], stretch);
  ENSURE_REL(q[tip_x], stretch, 1e-4);
  /* linearization about the steady state under prescribed rotation: the p block of K, C, M */
  double* K = calloc(3 * (size_t)nc * nc, sizeof(double));
  double *C = K + (size_t)nc * nc, *M = C + (size_t)nc * nc;
  double* P = malloc(3 * sizeof(double) * (size_t)n * n);
  double *G = P + (size_t)n * n, *Mp = G + (size_t)n * n;
  fmbEnv env0 = {.gravity = {0.0, 0.0}, .has_gravity = 0};
  exact_jacobian(b, &env0, q, v, z, K, C, M, NULL);
  et_sub(K, nc, 3, P);
  et_sub(C, nc, 3, G);
  et_sub(M, nc, 3, Mp);
  const double w1 = et_frequency(n, P, G, Mp, 1, 0.5, 50.0);
  printf("F. %d elements, %s: first in-plane frequency at %g rad/s: %.7f rad/s (rotating cantilever 6.33515)\n", ne,
         integration ? "full" : "reduced", Omega, w1);
  ENSURE_REL(w1, 6.33515, freq_tol);
  free(P);
  free(K);
  free(q);
  free(b);
}

int main(void) {
  test_jacobian(INTEGRATION_REDUCED);
  test_jacobian(INTEGRATION_FULL);
  test_jacobian_pendulum();
  test_mixed_jacobian();
  test_invariance();
  test_modes(INTEGRATION_REDUCED);
  test_modes(INTEGRATION_FULL);
  test_mass();
  test_elastica();
  test_rotating(16, INTEGRATION_REDUCED, 2e-4);
  test_rotating(32, INTEGRATION_REDUCED, 1e-4);
  test_rotating(32, INTEGRATION_FULL, 1e-4);
  return fmbt_finish("test_exact_element");
}
