/* test_linear_solvers.c — the engine's own pieces under IDA, each against an independent one:
 *   vector.c's N_Vector arithmetic against SUNDIALS' serial implementation, operation by
 *     operation, including an output that aliases its input;
 *   schur.c's reduced KLU solve against a dense LU of the whole assembled iteration matrix: exact
 *     (backward error at roundoff) when mu = 0, where the position block is exactly diagonal, and
 *     a perturbation of order |mu| otherwise (the modified Newton it stands for);
 *   radau's three reduced systems on one shared pattern (fmb_schur_new_like), the real one and two
 *     complex ones with other shifts, all factorized before any solve: each solves its own matrix
 *     (backward error at roundoff against the dense J_y + cj J_y'), with the dense LU of S and KLU;
 *   whole runs: the reduced solver's error against a 1e4 times tighter reference is that of the
 *     full KLU and dense solvers. */
#include <complex.h>
#include <nvector/nvector_serial.h>
#include <stdlib.h>
#include <string.h>
#include <sundials/sundials_context.h>
#include <sundials/sundials_linearsolver.h>
#include <sunmatrix/sunmatrix_sparse.h>

#include "internal.h"
#include "schur.h"
#include "testlib.h"

static double urand(unsigned* s) {
  *s = *s * 1103515245u + 12345u;
  return ((*s >> 8) & 0xffff) / 65535.0 - 0.5;
}

static double max_rel_diff(N_Vector a, N_Vector b) {
  double d = 0.0;
  for (sunindextype i = 0; i < NV_LENGTH_S(a); ++i)
    d = fmax(d, fabs(NV_Ith_S(a, i) - NV_Ith_S(b, i)) / (1.0 + fabs(NV_Ith_S(b, i))));
  return d;
}

/* each operation on vectors carrying our ops and on SUNDIALS' own, same inputs */
static void check_vector_ops(SUNContext sun, int n) {
  enum { NV = 4 };
  N_Vector ref[NV], fast[NV];
  unsigned seed = 11u + (unsigned)n;
  for (int k = 0; k < NV; ++k) {
    ref[k] = N_VNew_Serial(n, sun);
    fast[k] = N_VNew_Serial(n, sun);
    fmb_vector_use_fast_ops(fast[k]);
    for (int i = 0; i < n; ++i) NV_Ith_S(ref[k], i) = NV_Ith_S(fast[k], i) = 3.0 * urand(&seed) + (k == 2 ? 2.0 : 0.0);
  }
  /* ref[3]/fast[3]: a 0/1 mask */
  for (int i = 0; i < n; ++i) NV_Ith_S(ref[3], i) = NV_Ith_S(fast[3], i) = (i % 3) ? 1.0 : 0.0;
  N_Vector rz = N_VClone(ref[0]), fz = N_VClone(fast[0]);
  double worst = 0.0;
#define SAME_VEC(call_ref, call_fast)          \
  do {                                         \
    call_ref;                                  \
    call_fast;                                 \
    worst = fmax(worst, max_rel_diff(fz, rz)); \
  } while (0)
#define SAME_NUM(a, b) worst = fmax(worst, fabs((a) - (b)) / (1.0 + fabs(a)))
  SAME_VEC(N_VLinearSum(0.7, ref[0], -1.3, ref[1], rz), N_VLinearSum(0.7, fast[0], -1.3, fast[1], fz));
  SAME_VEC(N_VConst(2.5, rz), N_VConst(2.5, fz));
  SAME_VEC(N_VProd(ref[0], ref[1], rz), N_VProd(fast[0], fast[1], fz));
  SAME_VEC(N_VDiv(ref[0], ref[2], rz), N_VDiv(fast[0], fast[2], fz));
  SAME_VEC(N_VScale(-0.3, ref[1], rz), N_VScale(-0.3, fast[1], fz));
  SAME_VEC(N_VAbs(ref[1], rz), N_VAbs(fast[1], fz));
  SAME_VEC(N_VInv(ref[2], rz), N_VInv(fast[2], fz));
  SAME_VEC(N_VAddConst(ref[0], 4.0, rz), N_VAddConst(fast[0], 4.0, fz));
  SAME_NUM(N_VDotProd(ref[0], ref[1]), N_VDotProd(fast[0], fast[1]));
  SAME_NUM(N_VMaxNorm(ref[1]), N_VMaxNorm(fast[1]));
  SAME_NUM(N_VMin(ref[1]), N_VMin(fast[1]));
  SAME_NUM(N_VWrmsNorm(ref[0], ref[2]), N_VWrmsNorm(fast[0], fast[2]));
  SAME_NUM(N_VWrmsNormMask(ref[0], ref[2], ref[3]), N_VWrmsNormMask(fast[0], fast[2], fast[3]));
  SAME_NUM(N_VWSqrSumLocal(ref[0], ref[2]), N_VWSqrSumLocal(fast[0], fast[2]));
  SAME_NUM(N_VWSqrSumMaskLocal(ref[0], ref[2], ref[3]), N_VWSqrSumMaskLocal(fast[0], fast[2], fast[3]));
  double c[3] = {0.5, -2.0, 1.25};
  N_Vector rX[3] = {ref[0], ref[1], ref[2]}, fX[3] = {fast[0], fast[1], fast[2]};
  SAME_VEC(N_VLinearCombination(3, c, rX, rz), N_VLinearCombination(3, c, fX, fz));
  N_Vector rY[2] = {ref[1], ref[2]}, fY[2] = {fast[1], fast[2]};
  N_Vector rZ[2] = {rz, N_VClone(ref[0])}, fZ[2] = {fz, N_VClone(fast[0])};
  SAME_VEC(N_VScaleAddMulti(2, c, ref[0], rY, rZ), N_VScaleAddMulti(2, c, fast[0], fY, fZ));
  worst = fmax(worst, max_rel_diff(fZ[1], rZ[1]));
  /* the array forms fall back to the single-vector operations */
  SAME_VEC(N_VLinearSumVectorArray(2, 0.5, rY, -1.0, rY, rZ), N_VLinearSumVectorArray(2, 0.5, fY, -1.0, fY, fZ));
  /* aliasing: z = x, and z = X[0] in a linear combination (IDA does both) */
  N_VScale(1.0, ref[0], rz);
  N_VScale(1.0, fast[0], fz);
  SAME_VEC(N_VLinearSum(2.0, rz, 1.0, ref[1], rz), N_VLinearSum(2.0, fz, 1.0, fast[1], fz));
  N_Vector rA[2] = {rz, ref[1]}, fA[2] = {fz, fast[1]};
  SAME_VEC(N_VLinearCombination(2, c, rA, rz), N_VLinearCombination(2, c, fA, fz));
  printf("vector ops, n = %d: largest difference from SUNDIALS' serial vector %.3g\n", n, worst);
  ENSURE(worst < 1e-14);
  N_VDestroy(rZ[1]);
  N_VDestroy(fZ[1]);
  N_VDestroy(rz);
  N_VDestroy(fz);
  for (int k = 0; k < NV; ++k) {
    N_VDestroy(ref[k]);
    N_VDestroy(fast[k]);
  }
#undef SAME_VEC
#undef SAME_NUM
}

/* dense.c's LU (initial conditions, checks): the residual of random systems that need row swaps */
static void check_dense_lu(void) {
  unsigned seed = 3;
  double worst = 0.0;
  for (int n = 1; n <= 40; n += 3) {
    double* A = malloc(sizeof(double) * (size_t)(n * n));
    double* LU = malloc(sizeof(double) * (size_t)(n * n));
    double* b = malloc(sizeof(double) * (size_t)n);
    double* x = malloc(sizeof(double) * (size_t)n);
    int* piv = malloc(sizeof(int) * (size_t)n);
    for (int i = 0; i < n * n; ++i) A[i] = LU[i] = urand(&seed);
    for (int i = 0; i < n; ++i) b[i] = x[i] = urand(&seed);
    ENSURE(fmb_lu_factor(n, LU, piv) == 0);
    fmb_lu_solve(n, LU, piv, x);
    for (int r = 0; r < n; ++r) {
      double s = -b[r], scale = fabs(b[r]);
      for (int c = 0; c < n; ++c) {
        s += A[(size_t)c * n + r] * x[c];
        scale += fabs(A[(size_t)c * n + r] * x[c]);
      }
      worst = fmax(worst, fabs(s) / scale);
    }
    free(A), free(LU), free(b), free(x), free(piv);
  }
  printf("dense LU: largest componentwise backward error %.3g (n = 1..40)\n", worst);
  ENSURE(worst < 1e-12);
}

/* ||J x - b||_inf / (||J||_inf ||x||_inf + ||b||_inf) of the reduced solve, J assembled at a
   perturbed state with multipliers mu scaled by mu_scale */
static double schur_backward_error(SUNContext sun, const fmbModel* m, double mu_scale, double* dense_diff) {
  const int ny = m->ny, nq = m->nq, nc = m->nc;
  fmbWorkspace* w = fmb_workspace_new(m);
  double* y = calloc((size_t)ny, sizeof(double));
  double* yp = calloc((size_t)ny, sizeof(double));
  double* ewt = calloc((size_t)ny, sizeof(double));
  double* Jd = calloc((size_t)ny * ny, sizeof(double));
  int* piv = calloc((size_t)ny, sizeof(int));
  fmbStats st;
  fmbDiag d;
  ENSURE(fmb_initial_conditions(m, w, y, yp, &st, &d) == 0);
  unsigned seed = 5;
  for (int i = 0; i < ny; ++i) {
    y[i] += (i < nq ? 1e-3 : 0.3) * urand(&seed);
    yp[i] += 0.3 * urand(&seed);
  }
  for (int i = 2 * nq + nc; i < ny; ++i) y[i] = mu_scale * urand(&seed); /* mu */
  for (int i = 0; i < ny; ++i) ewt[i] = 1.0 / (1e-6 * fabs(y[i]) + 1e-8);
  const double cj = 250.0;
  SUNMatrix A = SUNSparseMatrix(ny, ny, m->nnz, CSC_MAT, sun);
  fmb_sparse_pattern_into(m, A);
  ENSURE(fmb_system_jacobian(m, w, 0.3, cj, y, yp, ewt, 0, SUNSparseMatrix_Data(A), NULL) == 0);
  ENSURE(fmb_system_jacobian(m, w, 0.3, cj, y, yp, ewt, 0, NULL, Jd) == 0);
  N_Vector b = N_VNew_Serial(ny, sun), x = N_VNew_Serial(ny, sun);
  for (int i = 0; i < ny; ++i) NV_Ith_S(b, i) = urand(&seed);
  SUNLinearSolver S = fmb_schur_klu_new(m, sun);
  ENSURE(S != NULL);
  double err = INFINITY;
  if (S && SUNLinSolInitialize(S) == 0 && SUNLinSolSetup(S, A) == 0 && SUNLinSolSolve(S, A, x, b, 0.0) == 0) {
    /* componentwise (Oettli-Prager): max_r |J x - b|_r / (|J| |x| + |b|)_r */
    err = 0.0;
    for (int r = 0; r < ny; ++r) {
      double s = -NV_Ith_S(b, r), scale = fabs(NV_Ith_S(b, r));
      for (int c = 0; c < ny; ++c) {
        s += Jd[(size_t)c * ny + r] * NV_Ith_S(x, c);
        scale += fabs(Jd[(size_t)c * ny + r] * NV_Ith_S(x, c));
      }
      err = fmax(err, fabs(s) / scale);
    }
    /* and the solution itself against a dense LU of the whole matrix */
    double* xd = malloc(sizeof(double) * (size_t)ny);
    for (int i = 0; i < ny; ++i) xd[i] = NV_Ith_S(b, i);
    ENSURE(fmb_lu_factor(ny, Jd, piv) == 0);
    fmb_lu_solve(ny, Jd, piv, xd);
    double diff = 0.0;
    for (int i = 0; i < ny; ++i) diff = fmax(diff, fabs(xd[i] - NV_Ith_S(x, i)) / (1e-300 + fabs(xd[i])));
    *dense_diff = diff;
    free(xd);
  }
  if (S) SUNLinSolFree(S);
  SUNMatDestroy(A);
  N_VDestroy(b);
  N_VDestroy(x);
  free(y), free(yp), free(ewt), free(Jd), free(piv);
  fmb_workspace_free(w);
  return err;
}

/* componentwise backward error max_r |E x - b|_r / (|E| |x| + |b|)_r of a complex solve, E = Jy +
   cj Jyp (dense, column-major), x and b interleaved (re, im) */
static double complex_backward_error(int ny, const double* Jy, const double* Jyp, double complex cj, const double* x,
                                     const double* b) {
  double worst = 0.0;
  for (int r = 0; r < ny; ++r) {
    double complex s = -(b[2 * r] + I * b[2 * r + 1]);
    double scale = cabs(s);
    for (int c = 0; c < ny; ++c) {
      const double complex e = Jy[(size_t)c * ny + r] + cj * Jyp[(size_t)c * ny + r];
      const double complex t = e * (x[2 * c] + I * x[2 * c + 1]);
      s += t;
      scale += cabs(t);
    }
    worst = fmax(worst, scale > 0.0 ? cabs(s) / scale : 0.0);
  }
  return worst;
}

/* radau's real system and two complex ones made on one pattern (the second and third share the
   first's, fmb_schur_new_like), factorized one after the other and then solved: each keeps its own
   values and factors. schur_lu: the scene's rule, or "dense" / "klu" forced. */
static void check_shared_pattern(const char* rel, const char* schur_lu) {
  char path[1024], ov[64];
  snprintf(ov, sizeof ov, "solver.schur_lu=%s", schur_lu);
  const char* ovs[1] = {ov};
  fmbDiag d;
  fmbModel* m = fmb_load(fmbt_path(rel, path, sizeof path), ovs, 1, fmb_builtin_registry(), &d);
  ENSURE(m != NULL);
  if (!m) return;
  const int ny = m->ny;
  const long nnz = m->nnz;
  fmbWorkspace* w = fmb_workspace_new(m);
  double* y = calloc((size_t)ny, sizeof(double));
  double* yp = calloc((size_t)ny, sizeof(double));
  double* ewt = calloc((size_t)ny, sizeof(double));
  double *Jy = calloc((size_t)ny * ny, sizeof(double)), *Jyp = calloc((size_t)ny * ny, sizeof(double));
  double *jy = calloc((size_t)nnz, sizeof(double)), *jyp = calloc((size_t)nnz, sizeof(double));
  fmbStats st;
  ENSURE(fmb_initial_conditions(m, w, y, yp, &st, &d) == 0);
  unsigned seed = 7;
  for (int i = 0; i < ny; ++i) {
    y[i] += (i < m->nq ? 1e-3 : 0.3) * urand(&seed);
    yp[i] += 0.3 * urand(&seed);
  }
  for (int i = 2 * m->nq + m->nc; i < ny; ++i) y[i] = 0.0; /* mu = 0: the reduced solve is exact */
  for (int i = 0; i < ny; ++i) ewt[i] = 1.0 / (1e-6 * fabs(y[i]) + 1e-8);
  /* J_y and J_y' on the pattern and dense, as radau's evaluate_jacobian takes them */
  ENSURE(fmb_system_jacobian(m, w, 0.3, 0.0, y, yp, ewt, 0, jy, NULL) == 0);
  ENSURE(fmb_system_jacobian(m, w, 0.3, 0.0, y, yp, ewt, 0, NULL, Jy) == 0);
  ENSURE(fmb_system_jacobian(m, w, 0.3, 1.0, y, yp, ewt, 0, jyp, NULL) == 0);
  ENSURE(fmb_system_jacobian(m, w, 0.3, 1.0, y, yp, ewt, 0, NULL, Jyp) == 0);
  for (long k = 0; k < nnz; ++k) jyp[k] -= jy[k];
  for (size_t k = 0; k < (size_t)ny * ny; ++k) Jyp[k] -= Jy[k];
  enum { NSYS = 3 };
  const double complex cj[NSYS] = {250.0, 180.0 + 140.0 * I, 420.0 - 75.0 * I};
  fmbSchur *sys[NSYS], *alone[NSYS]; /* alone: each made by itself, its own pattern */
  sys[0] = fmb_schur_new(m, 0);
  for (int k = 1; k < NSYS; ++k) sys[k] = fmb_schur_new_like(sys[0], 1);
  for (int k = 0; k < NSYS; ++k) alone[k] = fmb_schur_new(m, k > 0);
  double* e = calloc(2 * (size_t)nnz, sizeof(double));
  for (int k = 0; k < NSYS; ++k) {
    ENSURE(sys[k] != NULL && alone[k] != NULL);
    if (!sys[k] || !alone[k]) continue;
    /* one value buffer for all: each system must have copied what it needs */
    for (long j = 0; j < nnz; ++j) {
      if (k == 0) {
        e[j] = jy[j] + creal(cj[0]) * jyp[j];
      } else {
        e[2 * j] = jy[j] + creal(cj[k]) * jyp[j];
        e[2 * j + 1] = cimag(cj[k]) * jyp[j];
      }
    }
    ENSURE(fmb_schur_factor(sys[k], e) == 0);
    ENSURE(fmb_schur_factor(alone[k], e) == 0);
  }
  double* b = calloc(2 * (size_t)ny, sizeof(double));
  double* x = calloc(2 * (size_t)ny, sizeof(double));
  double* xa = calloc(2 * (size_t)ny, sizeof(double));
  double worst = 0.0;
  for (int k = NSYS - 1; k >= 0; --k) { /* the last factorized first */
    if (!sys[k] || !alone[k]) continue;
    const int nc = k == 0 ? 1 : 2;
    for (int i = 0; i < ny; ++i) {
      b[2 * i] = urand(&seed);
      b[2 * i + 1] = nc == 2 ? urand(&seed) : 0.0;
    }
    if (nc == 1)
      for (int i = 0; i < ny; ++i) x[i] = b[2 * i];
    else
      memcpy(x, b, sizeof(double) * 2 * (size_t)ny);
    memcpy(xa, x, sizeof(double) * 2 * (size_t)ny);
    ENSURE(fmb_schur_solve(sys[k], x) == 0);
    ENSURE(fmb_schur_solve(alone[k], xa) == 0);
    /* the shared pattern is the same pattern: bit for bit the solution of a system made alone */
    ENSURE(memcmp(x, xa, sizeof(double) * (size_t)nc * (size_t)ny) == 0);
    if (nc == 1) /* as complex, imaginary parts 0 */
      for (int i = ny - 1; i >= 0; --i) {
        x[2 * i] = x[i];
        x[2 * i + 1] = 0.0;
      }
    const double err = complex_backward_error(ny, Jy, Jyp, cj[k], x, b);
    worst = fmax(worst, err);
    printf("%s schur_lu %s: system %d (cj = %g%+gi, shared pattern): backward error %.3g\n", rel, schur_lu, k,
           creal(cj[k]), cimag(cj[k]), err);
  }
  /* roundoff: 1e-13 on the beam; the rigid slider-crank's perturbed matrix is less well
     conditioned (1e-11 to 1.5e-9, the same for systems made alone); another system's matrix
     would give O(0.1) */
  ENSURE(worst < 1e-8);
  fmb_schur_free(sys[0]); /* the pattern's first owner first: the others keep it */
  if (sys[1]) {
    for (int i = 0; i < 2 * ny; ++i) x[i] = b[i];
    ENSURE(fmb_schur_solve(sys[1], x) == 0);
  }
  for (int k = 1; k < NSYS; ++k) fmb_schur_free(sys[k]);
  for (int k = 0; k < NSYS; ++k) fmb_schur_free(alone[k]);
  free(e), free(b), free(x), free(xa), free(y), free(yp), free(ewt), free(Jy), free(Jyp), free(jy), free(jyp);
  fmb_workspace_free(w);
  fmb_free(m);
}

/* offdiag_mu: the scene has a joint whose Phi_q depends on coordinates other than its bodies'
   angles (a joint at a beam's elastic point), so d(Phi_q^T mu)/dq is not diagonal. Revolute joints
   on rigid bodies and at a beam's clamped root give a diagonal block, which D holds exactly. */
static void check_schur(SUNContext sun, const char* rel, const char* const* ov, int nov, int offdiag_mu) {
  char path[1024];
  fmbDiag d;
  fmbModel* m = fmb_load(fmbt_path(rel, path, sizeof path), ov, nov, fmb_builtin_registry(), &d);
  ENSURE(m != NULL);
  if (!m) return;
  double diff0 = INFINITY, diff_small = INFINITY, diff_big = INFINITY;
  const double e0 = schur_backward_error(sun, m, 0.0, &diff0);
  const double e_small = schur_backward_error(sun, m, 1e-8, &diff_small);
  const double e_big = schur_backward_error(sun, m, 1e-2, &diff_big);
  printf("%s%s%s: reduced solve backward error %.3g at mu = 0 (vs dense LU %.3g); %.3g at |mu| ~ 1e-8, %.3g at 1e-2\n",
         rel, nov ? " " : "", nov ? ov[0] : "", e0, diff0, e_small, e_big);
  ENSURE(e0 < 1e-10);
  ENSURE(diff0 < 1e-8);
  /* mu = O(drift) in a run, ~1e-8 or less: the dropped block is invisible there */
  ENSURE(e_small < 1e-10);
  if (offdiag_mu) {
    /* the error is the dropped O(|mu|) block and nothing else: it shows at large mu, and stays
       of the order of |mu| times the block's weight against cj */
    ENSURE(e_big > 100.0 * e_small);
    ENSURE(e_big < 1e-2);
  } else {
    ENSURE(e_big < 1e-10);
  }
  fmb_free(m);
}

/* a whole run with each solver, and a reference at a 1e4 times tighter tolerance: the reduced
   solver's error against the reference is that of the full KLU and dense solvers */
static void check_runs(const char* rel, const char* const* cols, int ncol, const char* ov_extra) {
  enum { NS = 4 };
  fmbtCsv c[NS];
  static const char* const solvers[NS] = {"klu", "klu_full", "dense", "klu_full"};
  for (int k = 0; k < NS; ++k) {
    char o[64], name[96];
    snprintf(o, sizeof o, "solver.linear_solver=%s", solvers[k]);
    snprintf(name, sizeof name, "linear_solvers_%d_%d.csv", k, (int)strlen(rel));
    const char* ov[4] = {o, k == 3 ? "solver.rtol=1e-10" : NULL, k == 3 ? "solver.atol=1e-12" : NULL, ov_extra};
    const char* list[4];
    int n = 0;
    for (int i = 0; i < 4; ++i)
      if (ov[i]) list[n++] = ov[i];
    fmbStats st;
    ENSURE(fmbt_run_read(rel, list, n, name, &c[k], &st) == 0);
  }
  for (int j = 0; j < ncol; ++j) {
    const double* ref = fmbt_col(&c[3], cols[j]);
    double err[3] = {0.0, 0.0, 0.0};
    int ok = ref != NULL;
    for (int k = 0; k < 3 && ok; ++k) {
      const double* a = fmbt_col(&c[k], cols[j]);
      if (!a || c[k].nrow != c[3].nrow) {
        ok = 0;
        break;
      }
      for (int i = 0; i < c[3].nrow; ++i) err[k] = fmax(err[k], fabs(a[i] - ref[i]));
    }
    ENSURE(ok);
    printf("%s %s: error against the reference: klu %.3g, klu_full %.3g, dense %.3g\n", rel, cols[j], err[0], err[1],
           err[2]);
    ENSURE(err[0] <= 3.0 * fmax(err[1], err[2]) + 1e-12);
  }
  for (int k = 0; k < NS; ++k) fmbt_csv_free(&c[k]);
}

int main(void) {
  SUNContext sun;
  ENSURE(SUNContext_Create(NULL, &sun) == 0);
  check_dense_lu();
  check_vector_ops(sun, 1);
  check_vector_ops(sun, 7);
  check_vector_ops(sun, 108);
  check_schur(sun, "scenes/pendulum.yaml", NULL, 0, 0);
  check_schur(sun, "scenes/fourbar.yaml", NULL, 0, 0);
  static const char* const complete[] = {"bodies.beam.model=complete"};
  check_schur(sun, "tests/core/scenes/conformance_beam.yaml", complete, 1, 0);
  check_schur(sun, "scenes/paper/spinup_w15.yaml", NULL, 0, 0);
  check_schur(sun, "tests/core/scenes/beam_tip_link.yaml", NULL, 0, 1);
  check_shared_pattern("scenes/paper/spinup_w15.yaml", "auto");
  check_shared_pattern("scenes/paper/spinup_w15.yaml", "klu");
  check_shared_pattern("scenes/slider_crank.yaml", "auto");
  check_shared_pattern("scenes/slider_crank.yaml", "dense");
  SUNContext_Free(&sun);
  static const char* const fourbar_cols[] = {"crank.theta", "rocker.theta"};
  check_runs("scenes/fourbar.yaml", fourbar_cols, 2, NULL);
  static const char* const beam_cols[] = {"beam.tip_v", "beam.tip_u"};
  check_runs("scenes/paper/spinup_w4.yaml", beam_cols, 2, "solver.t_end=5");
  static const char* const link_cols[] = {"beam.tip_v", "link.theta"};
  check_runs("tests/core/scenes/beam_tip_link.yaml", link_cols, 2, "solver.t_end=0.2");
  return fmbt_finish("test_linear_solvers");
}
