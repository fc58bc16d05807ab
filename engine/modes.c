/* modes.c — modal analysis about a static or steady state (docs/analysis.md).
 *
 * Linearizing the GGL rows about (q*, v*, a*, lambda*) gives, for small motions dq,
 *     M dq'' + C dq' + K dq + Phi_q^T dlambda = 0,    Phi_q dq = 0,
 * with K = dF_v/dq (the bodies' stiffness at v*, i.e. with geometric and centrifugal terms, the
 * joints' curvature Phi_qq lambda*, the force elements), C = dF_v/dv (damping and gyroscopic
 * terms) and M = dF_v/da, all read from the system Jacobian (fmb_system_jacobian at cj = 0 and
 * cj = 1). About a steady rotation at speed W the frames' origins turn; writing their
 * perturbations in the turning frame, dq = T(t) z with T' = W E T, gives the time-invariant
 *     M z'' + (C + 2 W M E) z' + (K + W C E + W^2 M E^2) z + Phi_q^T dlambda = 0     (M1)
 * (E: rotation generator on each frame origin; static.c's fmb_rotation_terms). The constraints
 * are eliminated with an orthonormal null-space basis N of Phi_q (SVD), z = N r:
 *     Mr r'' + Cr r' + Kr r = 0,   Mr = N^T M N, ...                                  (M2)
 * Without velocity terms (Cr = 0, as at rest) this is the symmetric-definite problem
 * Kr x = w^2 Mr x (LAPACK dsygv); otherwise the first-order form
 *     [0 I; -Mr^-1 Kr  -Mr^-1 Cr] [r; r'] = s [r; r']                                 (M3)
 * (dgesv, dgeev); both are solved inverted when Kr is regular (the low modes then carry the
 * largest eigenvalues, which a dense solver gets to full precision). For a few modes of a large
 * system the sparse path (M4, below) skips N: Arnoldi on one KLU factorization of the
 * saddle-point matrix. A mode reports |s| as its frequency and -Re(s)/|s| as its damping ratio; a
 * real positive s (divergence: ZOAC spun above w1, where w^2 = w1^2 - W^2 < 0) is reported as
 * frequency -|s|, so a Campbell curve passes continuously through zero. Dense: O(n^3).
 * A spatial scene (engine/rotation3.c): E is the generator of the rigid rotation on every body's
 * coordinates (G3), the rotation is read from v* with its axis, and the bodies' gauge directions
 * D join Phi_q in the null-space basis, N spanning {Phi_q dq = 0, D^T dq = 0} (G1): no
 * zero-frequency mode of an Euler parameter's length. Its modes are then classified into
 * families by where they move relative to the spin axis (engine/mode_family.c). */
#include <math.h>
#include <pthread.h>
#include <stdlib.h>
#include <string.h>

#include "data.h"
#include "klu_policy.h"

#include <arpack/arpack.h>

/* coordinates from which `auto` takes the sparse path for a few modes: bench/modes.sh measured
   the crossover between 8 and 16 beam elements (27 and 51 coordinates) for 4 modes */
#define FMB_SPARSE_MIN_COORDS 48

/* LAPACK / BLAS (Debian's liblapack-dev, libblas-dev), Fortran calling convention */
extern void dgesvd_(const char* jobu, const char* jobvt, const int* m, const int* n, double* a, const int* lda,
                    double* s, double* u, const int* ldu, double* vt, const int* ldvt, double* work, const int* lwork,
                    int* info);
extern void dsygv_(const int* itype, const char* jobz, const char* uplo, const int* n, double* a, const int* lda,
                   double* b, const int* ldb, double* w, double* work, const int* lwork, int* info);
extern void dgeev_(const char* jobvl, const char* jobvr, const int* n, double* a, const int* lda, double* wr,
                   double* wi, double* vl, const int* ldvl, double* vr, const int* ldvr, double* work, const int* lwork,
                   int* info);
extern void dgesv_(const int* n, const int* nrhs, double* a, const int* lda, int* ipiv, double* b, const int* ldb,
                   int* info);
extern void dlarnv_(const int* idist, int* iseed, const int* n, double* x);
extern void dgemm_(const char* ta, const char* tb, const int* m, const int* n, const int* k, const double* alpha,
                   const double* a, const int* lda, const double* b, const int* ldb, const double* beta, double* c,
                   const int* ldc);

typedef struct {
  double freq, zeta;
  int col;      /* eigenvector column (dsygv: real; dgeev: re at col, im at col + 1 or none) */
  int complex_; /* 0 real vector, 1 complex, -1 complex conjugated */
} Root;

static int cmp_root(const void* a, const void* b) {
  const double x = fabs(((const Root*)a)->freq), y = fabs(((const Root*)b)->freq);
  return x < y ? -1 : x > y;
}

/* Rt = N^T X N for X nq x nq (leading dimension ldx), N nq x nr; tmp nq x nr */
static void reduce(int nq, int nr, const double* N, const double* X, int ldx, double* tmp, double* Rt) {
  const double one = 1.0, zero = 0.0;
  dgemm_("N", "N", &nq, &nr, &nq, &one, X, &ldx, N, &nq, &zero, tmp, &nq);
  dgemm_("T", "N", &nr, &nr, &nq, &one, N, &nq, tmp, &nq, &zero, Rt, &nr);
}

static double fro(const double* X, size_t n) {
  double s = 0.0;
  for (size_t i = 0; i < n; ++i) s += X[i] * X[i];
  return sqrt(s);
}

/* the speed of the rigid rotation v* describes (0 if v* is not one: then no rotating-frame terms) */
static double state_speed(const fmbModel* m, const double* q, const double* v) {
  double speed = NAN;
  for (int b = 1; b < m->nbody; ++b) {
    const fmbBodyInst* bi = &m->body[b];
    if (!bi->type || bi->nq < 3) continue;
    speed = v[bi->qadr + 2];
    break;
  }
  if (!isfinite(speed) || speed == 0.0) return 0.0;
  /* center from the first frame: v = W I~ (r - c) -> c = r - I~^T v / W */
  const fmbBodyInst* b0 = NULL;
  for (int b = 1; b < m->nbody && !b0; ++b)
    if (m->body[b].type && m->body[b].nq >= 3) b0 = &m->body[b];
  const double c[2] = {q[b0->qadr] - v[b0->qadr + 1] / speed, q[b0->qadr + 1] + v[b0->qadr] / speed};
  double* vr = malloc((size_t)m->nq * 2 * sizeof(double));
  if (!vr) return 0.0;
  fmb_rigid_rotation(m, speed, c, q, vr, vr + m->nq);
  double d = 0.0, s = 0.0;
  for (int i = 0; i < m->nq; ++i) {
    d = fmax(d, fabs(vr[i] - v[i]));
    s = fmax(s, fabs(v[i]));
  }
  free(vr);
  return d <= 1e-9 * s ? speed : 0.0;
}

/* the modes among eigenvalues s = wr + i wi of the first-order form (inverted: dgeev/ARPACK
   computed 1/s, already mapped back; a pair's vector is stored for the conjugate root): one
   root per oscillating pair (Im s > 0), per divergent +-a pair (frequency -a), per rigid motion
   (two zero roots), per overdamped decay. Returns their number, -1 out of memory. */
static int classify(const double* wr, const double* wi, int n2, int inverted, Root* roots) {
  double smax = 0.0;
  for (int k = 0; k < n2; ++k)
    if (isfinite(wr[k])) smax = fmax(smax, hypot(wr[k], wi[k]));
  const double tiny = 1e-8 * smax;
  unsigned char* used = calloc((size_t)n2, 1);
  if (!used) return -1;
  int nroot = 0;
  for (int k = 0; k < n2; ++k) {
    if (!isfinite(wr[k])) continue;
    /* an oscillating pair: keep the root with Im s > 0. Its vector: columns k, k+1 of V as
       dgeev stores them for the first of the pair (Im > 0 direct, Im < 0 after inversion) */
    const int first = inverted ? (k + 1 < n2 && wi[k] < -tiny && wi[k + 1] > tiny) : (wi[k] > tiny);
    if (first) {
      const int kk = inverted ? k + 1 : k;
      const double mg = hypot(wr[kk], wi[kk]);
      /* |Re s| below 1e-10 |s| is the eigen-solver's rounding on an undamped gyroscopic
         system (measured: 1e-14 .. 1e-11), not damping */
      const double zeta = fabs(wr[kk]) <= 1e-10 * mg ? 0.0 : -wr[kk] / mg;
      roots[nroot++] = (Root){mg, zeta, k, inverted ? -1 : 1};
    } else if (fabs(wi[k]) <= tiny && !used[k]) {
      used[k] = 1;
      /* real: a divergent +a pairs with -a; zero roots come in pairs (one rigid motion) */
      int partner = -1;
      double best = 1e-6 * smax + 10.0 * tiny;
      for (int l = 0; l < n2; ++l)
        if (!used[l] && isfinite(wr[l]) && fabs(wi[l]) <= tiny && fabs(wr[l] + wr[k]) < best) {
          best = fabs(wr[l] + wr[k]);
          partner = l;
        }
      if (partner >= 0) used[partner] = 1;
      const int kk = partner >= 0 && wr[partner] > wr[k] ? partner : k;
      const double sr = wr[kk];
      if (fabs(sr) <= tiny)
        roots[nroot++] = (Root){0.0, 0.0, kk, 0};
      else if (sr > 0.0)
        roots[nroot++] = (Root){-sr, -1.0, kk, 0};
      else
        roots[nroot++] = (Root){-sr, 1.0, kk, 0}; /* overdamped: decay rate, damping ratio 1 */
    }
  }
  free(used);
  return nroot;
}

/* ---------------------------------------------------------------------------------------------
 * The sparse path: shift-invert (shift 0) Arnoldi on the first-order form without eliminating
 * the constraints. The operator is the inverse of (M3) in saddle-point form,
 *     [a; b] -> [a'; a],   [K  Phi_q^T; Phi_q  0] [a'; lambda] = [-(C a + M b); 0]           (M4)
 * whose largest eigenvalues mu = 1/s are the slowest modes; the constraint directions give mu = 0.
 * One KLU factorization of the saddle-point matrix, then one solve per Arnoldi step (ARPACK
 * dnaupd/dneupd, Debian's libarpack2-dev). */

typedef struct {
  int n, nnz;
  SuiteSparse_long *p, *i; /* KLU's index type: the saddle-point matrix goes to klu.c */
  double* x;
} Csc;

static void csc_free(Csc* a) {
  free(a->p);
  free(a->i);
  free(a->x);
}

/* the nonzeros of column-major blocks: rows [0, nr) of `top` (ld ldt) for columns [0, nt), the
   saddle-point coupling `P` (nc x nt from the Jacobian J0's rows) below them, and P^T as
   columns [nt, nt + nc); P = NULL gives a plain nt x nt matrix */
static int csc_build(Csc* a, int nt, const double* top, int ldt, int nc, const double* J0, int ny, int prow) {
  const int n = nt + nc;
  long nnz = 0;
  for (int j = 0; j < nt; ++j) {
    for (int i = 0; i < nt; ++i) nnz += top[(size_t)j * ldt + i] != 0.0;
    for (int r = 0; r < nc; ++r) nnz += 2 * (J0[(size_t)j * ny + prow + r] != 0.0);
  }
  a->n = n;
  a->p = malloc((size_t)(n + 1) * sizeof(SuiteSparse_long));
  a->i = malloc((size_t)(nnz + 1) * sizeof(SuiteSparse_long));
  a->x = malloc((size_t)(nnz + 1) * sizeof(double));
  if (!a->p || !a->i || !a->x) return -1;
  int k = 0;
  for (int j = 0; j < nt; ++j) {
    a->p[j] = k;
    for (int i = 0; i < nt; ++i)
      if (top[(size_t)j * ldt + i] != 0.0) {
        a->i[k] = i;
        a->x[k++] = top[(size_t)j * ldt + i];
      }
    for (int r = 0; r < nc; ++r)
      if (J0[(size_t)j * ny + prow + r] != 0.0) {
        a->i[k] = nt + r;
        a->x[k++] = J0[(size_t)j * ny + prow + r];
      }
  }
  for (int r = 0; r < nc; ++r) {
    a->p[nt + r] = k;
    for (int j = 0; j < nt; ++j)
      if (J0[(size_t)j * ny + prow + r] != 0.0) {
        a->i[k] = j;
        a->x[k++] = J0[(size_t)j * ny + prow + r];
      }
  }
  a->p[n] = k;
  a->nnz = k;
  return 0;
}

/* y += A x (A square CSC) */
static void csc_matvec_add(const Csc* a, const double* x, double* y) {
  for (int j = 0; j < a->n; ++j) {
    const double xj = x[j];
    if (xj == 0.0) continue;
    for (SuiteSparse_long k = a->p[j]; k < a->p[j + 1]; ++k) y[a->i[k]] += a->x[k] * xj;
  }
}

/* ARPACK's reverse-communication routines (dnaupd, dnaup2, dnaitr, dgetv0, dneupd) keep their
   state between the calls of one computation in Fortran SAVE variables, and its timing and debug
   common blocks are global: two computations in two threads at once would run on each other's
   state. So one computation at a time in the process, from the first dnaupd to the dneupd. The
   mutex is initialised statically and holds no data: it is the one piece of process-wide state
   here, and it is immutable synchronisation, not state a run could see (issue 35 item 3). */
static pthread_mutex_t arpack_lock = PTHREAD_MUTEX_INITIALIZER;

/* The Arnoldi start vector, given to dnaupd (info = 1) rather than drawn by ARPACK: dgetv0 draws it
   with dlarnv from a seed it SAVEs and advances, so a second computation in the same process (the
   speeds of a Campbell diagram, fmb_modes called twice) started elsewhere and agreed only to
   roundoff, and threads shared the seed. This is the vector dgetv0 draws on its first call in a
   process (dlarnv, uniform on (-1, 1), seed 1, 3, 5, 7: dgetv0.f), drawn from a fresh seed every
   time: every computation repeats the first one's bytes, so results of a process that computed
   sparse modes once (every `flexmbd modes` run) are unchanged. A pseudo-random vector has a part
   along every mode almost surely; a regular one (all ones, say) could be orthogonal to a
   symmetric structure's antisymmetric modes. */
static void arpack_start_vector(int n, double* resid) {
  int seed[4] = {1, 3, 5, 7}, uniform_pm1 = 2;
  dlarnv_(&uniform_pm1, seed, &n, resid);
}

/* 0 with the converged Ritz values mapped to s = 1/mu (*wr_out, *wi_out, *nconv) and vectors
   (*V_out, 2 nq rows); 1 when the path does not apply (a singular saddle-point matrix: rigid
   motions; no convergence); -1 out of memory */
static int sparse_modes(int nq, int nc, int ny, const double* J0, const double* K, const double* Cg, const double* M,
                        int count, double** wr_out, double** wi_out, double** V_out, int* nconv) {
  const int n2 = 2 * nq, ns = nq + nc;
  int nev = 2 * count + 1; /* two Ritz values per oscillating mode, one more to keep pairs whole */
  if (nev > n2 - 3) nev = n2 - 3;
  int ncv = 2 * nev + 20;
  if (ncv > n2) ncv = n2;
  const int lworkl = 3 * ncv * ncv + 6 * ncv;
  Csc S = {0, 0, NULL, NULL, NULL}, Cs = S, Ms = S;
  fmbKlu* lu = NULL;
  double *resid = calloc((size_t)n2, sizeof(double)), *V = calloc((size_t)n2 * ncv, sizeof(double));
  double *workd = calloc((size_t)3 * n2, sizeof(double)), *workl = calloc((size_t)lworkl, sizeof(double));
  double *rhs = calloc((size_t)ns, sizeof(double)), *dr = calloc((size_t)nev + 1, sizeof(double));
  double *di = calloc((size_t)nev + 1, sizeof(double)), *Z = calloc((size_t)n2 * (nev + 1), sizeof(double));
  double* workev = calloc((size_t)3 * ncv, sizeof(double));
  int* select = calloc((size_t)ncv, sizeof(int));
  int rc = -1;
  if (!resid || !V || !workd || !workl || !rhs || !dr || !di || !Z || !workev || !select) goto done;
  if (csc_build(&S, nq, K, nq, nc, J0, ny, 2 * nq) || csc_build(&Cs, nq, Cg, nq, 0, J0, ny, 0) ||
      csc_build(&Ms, nq, M, nq, 0, J0, ny, 0))
    goto done;
  rc = 1;
  lu = fmb_klu_new(ns, S.p, S.i, 0);
  if (!lu || fmb_klu_factor(lu, S.x) != FMB_KLU_OK) goto done;
  int iparam[11] = {0}, ipntr[14] = {0}, ido = 0, info = 1; /* info = 1: resid is the start vector */
  iparam[0] = 1;                                            /* exact shifts */
  iparam[2] = 3000;                                         /* restarts */
  iparam[6] = 1;                                            /* regular mode on the operator (M4) */
  arpack_start_vector(n2, resid);
  pthread_mutex_lock(&arpack_lock);
  do {
    dnaupd_c(&ido, "I", n2, "LM", nev, 0.0, resid, ncv, V, n2, iparam, ipntr, workd, workl, lworkl, &info);
    if (ido != 1 && ido != -1) break;
    const double* x = workd + ipntr[0] - 1;
    double* yv = workd + ipntr[1] - 1;
    memset(rhs, 0, (size_t)ns * sizeof(double));
    csc_matvec_add(&Cs, x, rhs);
    csc_matvec_add(&Ms, x + nq, rhs);
    for (int i = 0; i < nq; ++i) rhs[i] = -rhs[i];
    fmb_klu_solve(lu, rhs);
    memcpy(yv, rhs, (size_t)nq * sizeof(double));
    memcpy(yv + nq, x, (size_t)nq * sizeof(double));
  } while (1);
  if (info >= 0 && iparam[4] >= 1)
    dneupd_c(1, "A", select, dr, di, Z, n2, 0.0, 0.0, workev, "I", n2, "LM", nev, 0.0, resid, ncv, V, n2, iparam, ipntr,
             workd, workl, lworkl, &info);
  else if (info >= 0)
    info = -1; /* no Ritz value converged */
  pthread_mutex_unlock(&arpack_lock);
  if (info != 0 || iparam[4] < 1) goto done;
  *nconv = iparam[4] < nev + 1 ? iparam[4] : nev + 1;
  for (int k = 0; k < *nconv; ++k) { /* s = 1/mu */
    const double d = dr[k] * dr[k] + di[k] * di[k];
    if (d > 0.0) {
      dr[k] /= d;
      di[k] = -di[k] / d;
    } else {
      dr[k] = INFINITY;
      di[k] = 0.0;
    }
  }
  *wr_out = dr;
  *wi_out = di;
  *V_out = Z;
  dr = di = Z = NULL;
  rc = 0;
done:
  fmb_klu_free(lu);
  csc_free(&S);
  csc_free(&Cs);
  csc_free(&Ms);
  free(resid);
  free(V);
  free(workd);
  free(workl);
  free(rhs);
  free(dr);
  free(di);
  free(Z);
  free(workev);
  free(select);
  return rc;
}

void fmb_modes_free(fmbModes* md) {
  if (!md) return;
  free(md->frequency);
  free(md->damping_ratio);
  free(md->shape_re);
  free(md->shape_im);
  free(md->family);
  free(md);
}

/* ---------------------------------------------------------------------------------------------
 * fmb_modes in stages, each owning what it allocates and freeing it on one path: assemble the
 * linearization (M1), solve it sparse (M4) or reduce it to the free motions (M2) and solve that
 * dense (symmetric, else M3), then pack the modes. */

static int out_of_memory(const fmbModel* m, fmbDiag* diag) {
  fmb_diag_set(diag, FMB_EXIT_SOLVER, m->path, 0, 0, "out of memory for the modal analysis (%d coordinates)", m->nq);
  return FMB_EXIT_SOLVER;
}

/* (M1) about the state: nq x nq column-major blocks, and J0 (ny x ny) for the constraint rows */
typedef struct {
  double speed;            /* the rigid rotation the state has */
  fmbRotation3 rot;        /* with its axis (spatial scenes) */
  double *J0, *K, *Cg, *M; /* dF/dy at cj = 0; stiffness, damping + gyroscopic, mass (rotating frame) */
} Linearized;

static void linearized_free(Linearized* L) {
  free(L->J0);
  free(L->K);
  free(L->Cg);
  free(L->M);
  memset(L, 0, sizeof *L);
}

static int linearize(const fmbModel* m, fmbWorkspace* w, double t, const double* y, const double* yp, Linearized* L,
                     fmbDiag* diag) {
  const int nq = m->nq, ny = m->ny;
  memset(L, 0, sizeof *L);
  L->rot = (fmbRotation3){0.0, {0.0, 0.0, 1.0}, {0.0, 0.0, 0.0}, 0.0};
  if (m->dimension == 3) {
    if (w) fmb_state_rotation3(m, w, y, y + nq, &L->rot);
    L->speed = L->rot.speed;
  } else {
    L->speed = state_speed(m, y, y + nq);
  }
  double* J1 = calloc((size_t)ny * ny, sizeof(double));
  double* ewt = calloc((size_t)ny, sizeof(double));
  double* C = calloc((size_t)nq * nq, sizeof(double));
  L->J0 = calloc((size_t)ny * ny, sizeof(double));
  L->K = calloc((size_t)nq * nq, sizeof(double));
  L->M = calloc((size_t)nq * nq, sizeof(double));
  L->Cg = calloc((size_t)nq * nq, sizeof(double));
  int rc = 0;
  if (!w || !J1 || !ewt || !C || !L->J0 || !L->K || !L->M || !L->Cg) {
    rc = out_of_memory(m, diag);
  } else {
    for (int i = 0; i < ny; ++i) ewt[i] = 1.0 / (1e-8 * (1.0 + fabs(y[i])));
    /* a mixed form's body in its displacement form (static.c): z consistent, then folded out */
    double* yc = m->nz > 0 ? malloc(sizeof(double) * (size_t)ny) : NULL;
    if (yc) memcpy(yc, y, sizeof(double) * (size_t)ny);
    const double* ys = yc && !fmb_aux_iterated_consistent(m, w, yc, yp) ? yc : y;
    if (fmb_system_jacobian(m, w, t, 0.0, ys, yp, ewt, 0, NULL, L->J0) ||
        fmb_system_jacobian(m, w, t, 1.0, ys, yp, ewt, 1, NULL, J1) || fmb_aux_iterated_fold(m, L->J0)) {
      fmb_diag_set(diag, FMB_EXIT_SOLVER, m->path, 0, 0, "the equations cannot be differentiated at t = %g", t);
      rc = FMB_EXIT_SOLVER;
    }
    free(yc);
  }
  if (!rc) {
    for (int j = 0; j < nq; ++j)
      for (int i = 0; i < nq; ++i) {
        const size_t k = (size_t)j * nq + i;
        L->K[k] = L->J0[(size_t)j * ny + nq + i];
        C[k] = L->J0[(size_t)(nq + j) * ny + nq + i];
        L->M[k] = J1[(size_t)(nq + j) * ny + nq + i] - C[k];
        L->Cg[k] = C[k];
      }
    if (m->dimension != 3) {
      fmb_rotation_terms(m, L->speed, C, L->M, nq, L->K, L->Cg); /* (M1) */
    } else if (L->speed != 0.0) {
      double* E = calloc((size_t)nq * nq, sizeof(double));
      if (!E || fmb_rotation3_generator(m, w, &L->rot, y, E, nq)) {
        fmb_diag_set(diag, FMB_EXIT_SOLVER, m->path, 0, 0, "the rigid rotation of the bodies cannot be formed");
        rc = FMB_EXIT_SOLVER;
      } else {
        fmb_rotation3_terms(nq, L->speed, E, C, L->M, nq, L->K, L->Cg); /* (M1) */
      }
      free(E);
    }
  }
  free(J1);
  free(ewt);
  free(C);
  if (rc) linearized_free(L);
  return rc;
}

/* the roots found and their eigenvectors (columns of V, nvec rows each) */
typedef struct {
  Root* roots;
  int nroot;
  double* V;
  int nvec;
  int sparse; /* from the sparse path: the vectors are over the coordinates (no N) */
} Eigen;

static void eigen_free(Eigen* E) {
  free(E->roots);
  free(E->V);
  memset(E, 0, sizeof *E);
}

/* (M4): 0 with E filled, 1 when the path does not apply (E empty), or an exit code */
static int solve_sparse(const fmbModel* m, const Linearized* L, int count, Eigen* E, fmbDiag* diag) {
  const int nq = m->nq;
  double *wr = NULL, *wi = NULL;
  int nconv = 0;
  memset(E, 0, sizeof *E);
  const int sp = sparse_modes(nq, m->nc, m->ny, L->J0, L->K, L->Cg, L->M, count, &wr, &wi, &E->V, &nconv);
  int rc = sp < 0 ? out_of_memory(m, diag) : sp;
  if (!rc) {
    /* nconv converged Ritz values; the vectors' rows are [dq; dq'] over all coordinates */
    E->roots = calloc((size_t)nconv + 1, sizeof(Root));
    if (!E->roots || (E->nroot = classify(wr, wi, nconv, 1, E->roots)) < 0) rc = out_of_memory(m, diag);
    E->nvec = 2 * nq;
    E->sparse = 1;
  }
  free(wr);
  free(wi);
  if (rc) eigen_free(E);
  return rc;
}

/* (M2): N, an orthonormal basis of the null space of Phi_q (nq x nr), and the reduced blocks */
typedef struct {
  int nr;
  double *N, *Mr, *Cr, *Kr;
} Reduced;

static void reduced_free(Reduced* R) {
  free(R->N);
  free(R->Mr);
  free(R->Cr);
  free(R->Kr);
  memset(R, 0, sizeof *R);
}

/* the right singular vectors of [Phi_q; D^T] (nc + ng rows, from J0's rows and the gauge
   directions D, nq x ng) into VT, its rank into *rank */
static int constraint_svd(const fmbModel* m, const double* J0, const double* D, int ng, double* VT, int* rank,
                          fmbDiag* diag) {
  const int nq = m->nq, nc = m->nc + ng, ny = m->ny;
  *rank = 0;
  if (nc == 0) return 0;
  double* P = calloc((size_t)nc * nq, sizeof(double));
  double* sv = calloc((size_t)nq + 1, sizeof(double));
  double* work = NULL;
  int info = 0, rc = 0;
  if (!P || !sv) {
    rc = out_of_memory(m, diag);
  } else {
    for (int j = 0; j < nq; ++j)
      for (int r = 0; r < nc; ++r)
        P[(size_t)j * nc + r] = r < m->nc ? J0[(size_t)j * ny + 2 * nq + r] : D[(size_t)(r - m->nc) * nq + j];
    int lwork = -1, one = 1;
    double q1 = 0.0, u1 = 0.0;
    dgesvd_("N", "A", &nc, &nq, P, &nc, sv, &u1, &one, VT, &nq, &q1, &lwork, &info);
    lwork = (int)q1 + 1;
    work = malloc((size_t)lwork * sizeof(double));
    if (!work)
      rc = out_of_memory(m, diag);
    else
      dgesvd_("N", "A", &nc, &nq, P, &nc, sv, &u1, &one, VT, &nq, work, &lwork, &info);
  }
  if (!rc && info) {
    fmb_diag_set(diag, FMB_EXIT_SOLVER, m->path, 0, 0, "the SVD of the constraint Jacobian failed (LAPACK info %d)",
                 info);
    rc = FMB_EXIT_SOLVER;
  }
  for (int i = 0; !rc && i < (nc < nq ? nc : nq); ++i)
    if (sv[i] > 1e-10 * sv[0]) ++*rank;
  free(P);
  free(sv);
  free(work);
  return rc;
}

static int reduce_constraints(const fmbModel* m, const double* y, const Linearized* L, Reduced* R, fmbDiag* diag) {
  const int nq = m->nq, ng = m->dimension == 3 ? fmb_gauge_count(m, y) : 0, nc = m->nc + ng;
  memset(R, 0, sizeof *R);
  double* VT = calloc((size_t)nq * nq, sizeof(double));
  double* D = calloc((size_t)nq * ng + 1, sizeof(double));
  double* tmp = NULL;
  int rank = 0;
  int rc = VT && D ? 0 : out_of_memory(m, diag);
  if (!rc && ng > 0 && fmb_gauge_rows(m, y, D, nq) != ng) {
    fmb_diag_set(diag, FMB_EXIT_SOLVER, m->path, 0, 0, "a body's gauge directions cannot be formed");
    rc = FMB_EXIT_SOLVER;
  }
  if (!rc) rc = constraint_svd(m, L->J0, D, ng, VT, &rank, diag);
  free(D);
  const int nr = nq - rank;
  if (!rc && nr == 0) {
    fmb_diag_set(diag, FMB_EXIT_BAD_INPUT, m->path, 0, 0, "the joints leave no motion: there are no modes");
    rc = FMB_EXIT_BAD_INPUT;
  }
  if (!rc) {
    R->nr = nr;
    R->N = malloc((size_t)nq * nr * sizeof(double));
    tmp = malloc((size_t)nq * nr * sizeof(double));
    R->Mr = malloc((size_t)nr * nr * sizeof(double));
    R->Cr = malloc((size_t)nr * nr * sizeof(double));
    R->Kr = malloc((size_t)nr * nr * sizeof(double));
    if (!R->N || !tmp || !R->Mr || !R->Cr || !R->Kr) rc = out_of_memory(m, diag);
  }
  if (!rc) {
    for (int k = 0; k < nr; ++k)
      for (int i = 0; i < nq; ++i) R->N[(size_t)k * nq + i] = nc > 0 ? VT[(size_t)i * nq + rank + k] : (i == k);
    reduce(nq, nr, R->N, L->M, nq, tmp, R->Mr); /* (M2) */
    reduce(nq, nr, R->N, L->Cg, nq, tmp, R->Cr);
    reduce(nq, nr, R->N, L->K, nq, tmp, R->Kr);
  }
  free(VT);
  free(tmp);
  if (rc) reduced_free(R);
  return rc;
}

/* Symmetric-definite (Cr = 0, Kr symmetric), symmetrized against difference noise. Solved
   inverted when Kr is positive definite, Mr x = (1/w^2) Kr x: the error of a dense eigen-solver
   is eps times the largest eigenvalue, so the form whose largest eigenvalues are the low modes
   gives them to full precision (the direct form lost 1e-6 of w1 at 64 elements, where
   (w_max/w1)^2 ~ 1e10). 0 with E filled, 1 when neither Kr nor Mr is definite, or an exit code. */
static int solve_symmetric(const fmbModel* m, const Reduced* R, Eigen* E, fmbDiag* diag) {
  const int nr = R->nr;
  const size_t nn = (size_t)nr * nr;
  memset(E, 0, sizeof *E);
  double* S = malloc(nn * sizeof(double));
  double* B = malloc(nn * sizeof(double));
  double* wr = malloc((size_t)nr * sizeof(double));
  double* work = NULL;
  E->roots = calloc((size_t)2 * nr, sizeof(Root));
  int rc = S && B && wr && E->roots ? 1 : out_of_memory(m, diag);
  for (int pass = 0; pass < 2 && rc == 1; ++pass) {
    const double* A_ = pass == 0 ? R->Mr : R->Kr;
    const double* B_ = pass == 0 ? R->Kr : R->Mr;
    for (int j = 0; j < nr; ++j)
      for (int i = 0; i < nr; ++i) {
        S[(size_t)j * nr + i] = 0.5 * (A_[(size_t)j * nr + i] + A_[(size_t)i * nr + j]);
        B[(size_t)j * nr + i] = 0.5 * (B_[(size_t)j * nr + i] + B_[(size_t)i * nr + j]);
      }
    int itype = 1, lwork = -1, info = 0;
    double q1 = 0.0;
    dsygv_(&itype, "V", "U", &nr, S, &nr, B, &nr, wr, &q1, &lwork, &info);
    lwork = (int)q1 + 1;
    free(work);
    work = malloc((size_t)lwork * sizeof(double));
    if (!work) {
      rc = out_of_memory(m, diag);
      break;
    }
    dsygv_(&itype, "V", "U", &nr, S, &nr, B, &nr, wr, work, &lwork, &info);
    if (info) continue; /* B not definite: Kr (unstable, rigid motions) or Mr (FOAC) */
    rc = 0;
    E->V = S;
    S = NULL;
    E->nvec = nr;
    for (int k = 0; k < nr; ++k) {
      const double l = pass == 0 ? (wr[k] != 0.0 ? 1.0 / wr[k] : INFINITY) : wr[k]; /* w^2 */
      E->roots[E->nroot++] = (Root){l >= 0 ? sqrt(l) : -sqrt(-l), l >= 0 ? 0.0 : -1.0, k, 0};
    }
  }
  free(S);
  free(B);
  free(wr);
  free(work);
  if (rc) eigen_free(E);
  return rc;
}

/* (M3), inverted when Kr is regular (as above: the low modes become the largest):
     B = [-Kr^-1 Cr  -Kr^-1 Mr; I 0],  B [r; r'] = (1/s) [r; r']
   else direct with X = Mr^-1 [Kr Cr]. 0 with E filled, or an exit code. */
static int solve_first_order(const fmbModel* m, double t, const Reduced* R, Eigen* E, fmbDiag* diag) {
  const int nr = R->nr, n2 = 2 * nr, nrhs = 2 * nr;
  const size_t nn = (size_t)nr * nr;
  memset(E, 0, sizeof *E);
  double* X = malloc((size_t)nr * n2 * sizeof(double));
  double* F = malloc(nn * sizeof(double));
  double* S = calloc((size_t)n2 * n2, sizeof(double));
  double* wr = malloc((size_t)n2 * sizeof(double));
  double* wi = malloc((size_t)n2 * sizeof(double));
  int* ipiv = calloc((size_t)2 * nr, sizeof(int));
  double* work = NULL;
  E->V = malloc((size_t)n2 * n2 * sizeof(double));
  E->roots = calloc((size_t)2 * nr, sizeof(Root));
  int rc = X && F && S && wr && wi && ipiv && E->V && E->roots ? 0 : out_of_memory(m, diag);
  int info = 0, inverted = 0;
  if (!rc) {
    memcpy(F, R->Kr, nn * sizeof(double));
    memcpy(X, R->Cr, nn * sizeof(double));
    memcpy(X + nn, R->Mr, nn * sizeof(double));
    dgesv_(&nr, &nrhs, F, &nr, ipiv, X, &nr, &info);
    inverted = info == 0;
    if (!inverted) {
      memcpy(F, R->Mr, nn * sizeof(double));
      memcpy(X, R->Kr, nn * sizeof(double));
      memcpy(X + nn, R->Cr, nn * sizeof(double));
      dgesv_(&nr, &nrhs, F, &nr, ipiv, X, &nr, &info);
    }
    if (info) {
      fmb_diag_set(diag, FMB_EXIT_SOLVER, m->path, 0, 0,
                   "the mass matrix on the free motions is singular at t = %g: no modes (a massless degree of freedom, "
                   "or a FOAC beam whose mass matrix lost definiteness)",
                   t);
      rc = FMB_EXIT_SOLVER;
    }
  }
  if (!rc) {
    /* inverted: top rows [-X_C  -X_M], bottom [I 0]; direct: top [0 I], bottom [-X_K  -X_C] */
    for (int j = 0; j < nr; ++j)
      for (int i = 0; i < nr; ++i) {
        if (inverted) {
          S[(size_t)j * n2 + i] = -X[(size_t)j * nr + i];
          S[(size_t)(nr + j) * n2 + i] = -X[nn + (size_t)j * nr + i];
        } else {
          S[(size_t)j * n2 + nr + i] = -X[(size_t)j * nr + i];
          S[(size_t)(nr + j) * n2 + nr + i] = -X[nn + (size_t)j * nr + i];
        }
      }
    for (int j = 0; j < nr; ++j) {
      if (inverted)
        S[(size_t)j * n2 + nr + j] = 1.0;
      else
        S[(size_t)(nr + j) * n2 + j] = 1.0;
    }
    int lwork = -1, one = 1;
    double q1 = 0.0, vl = 0.0;
    dgeev_("N", "V", &n2, S, &n2, wr, wi, &vl, &one, E->V, &n2, &q1, &lwork, &info);
    lwork = (int)q1 + 1;
    work = malloc((size_t)lwork * sizeof(double));
    if (!work)
      rc = out_of_memory(m, diag);
    else
      dgeev_("N", "V", &n2, S, &n2, wr, wi, &vl, &one, E->V, &n2, work, &lwork, &info);
    if (!rc && info) {
      fmb_diag_set(diag, FMB_EXIT_SOLVER, m->path, 0, 0,
                   "the eigenvalue solver did not converge (LAPACK dgeev info %d)", info);
      rc = FMB_EXIT_SOLVER;
    }
  }
  if (!rc) {
    E->nvec = n2;
    /* back to s = 1/mu; the conjugate pair swaps the sign of Im, the stored vector (re at k, im
       at k + 1) then belongs to Im s < 0: its conjugate is the Im s > 0 root's (sign below) */
    if (inverted)
      for (int k = 0; k < n2; ++k) {
        const double d = wr[k] * wr[k] + wi[k] * wi[k];
        if (d > 0.0) {
          wr[k] = wr[k] / d;
          wi[k] = -wi[k] / d;
        } else {
          wr[k] = INFINITY;
          wi[k] = 0.0;
        }
      }
    if ((E->nroot = classify(wr, wi, n2, inverted, E->roots)) < 0) rc = out_of_memory(m, diag);
  }
  free(X);
  free(F);
  free(S);
  free(wr);
  free(wi);
  free(ipiv);
  free(work);
  if (rc) eigen_free(E);
  return rc;
}

/* dense on the free motions: symmetric-definite when there are no velocity terms, else (M3) */
static int solve_dense(const fmbModel* m, double t, const Reduced* R, Eigen* E, fmbDiag* diag) {
  const int nr = R->nr;
  const size_t nn = (size_t)nr * nr;
  const double kn = fro(R->Kr, nn), mn = fro(R->Mr, nn), cn = fro(R->Cr, nn);
  double asym = 0.0;
  for (int j = 0; j < nr; ++j)
    for (int i = 0; i < j; ++i) asym = fmax(asym, fabs(R->Kr[(size_t)j * nr + i] - R->Kr[(size_t)i * nr + j]));
  if (cn <= 1e-9 * sqrt(kn * mn) && asym <= 1e-6 * kn) {
    const int rc = solve_symmetric(m, R, E, diag);
    if (rc != 1) return rc;
  }
  return solve_first_order(m, t, R, E, diag);
}

/* the first `count` roots by |frequency| as fmbModes, shapes back over the coordinates (N x, or
   the vector itself on the sparse path) and scaled so the largest component is 1 */
static int pack_modes(const fmbModel* m, Eigen* E, const Reduced* R, double speed, int count, fmbModes** out,
                      fmbDiag* diag) {
  const int nq = m->nq, nr = E->sparse ? nq - m->nc : R->nr, nvec = E->nvec;
  const double* N = E->sparse ? NULL : R->N;
  qsort(E->roots, (size_t)E->nroot, sizeof(Root), cmp_root);
  if (count <= 0 || count > E->nroot) count = E->nroot;
  fmbModes* md = calloc(1, sizeof *md);
  if (!md) return out_of_memory(m, diag);
  md->count = count;
  md->nq = nq;
  md->nreduced = nr;
  md->sparse = E->sparse;
  md->speed = speed;
  md->frequency = calloc((size_t)count + 1, sizeof(double));
  md->damping_ratio = calloc((size_t)count + 1, sizeof(double));
  md->shape_re = calloc((size_t)count * nq + 1, sizeof(double));
  md->shape_im = calloc((size_t)count * nq + 1, sizeof(double));
  if (!md->frequency || !md->damping_ratio || !md->shape_re || !md->shape_im) {
    fmb_modes_free(md);
    return out_of_memory(m, diag);
  }
  for (int k = 0; k < count; ++k) {
    const Root* r = &E->roots[k];
    md->frequency[k] = r->freq;
    md->damping_ratio[k] = r->zeta;
    /* displacement part of the eigenvector (first nr rows), back to q: N x */
    const double* xr = E->V + (size_t)r->col * nvec;
    const double* xi = r->complex_ ? E->V + (size_t)(r->col + 1) * nvec : NULL;
    const double isign = r->complex_ < 0 ? -1.0 : 1.0; /* the conjugate (inverted form) */
    double* pr = md->shape_re + (size_t)k * nq;
    double* pi = md->shape_im + (size_t)k * nq;
    for (int i = 0; i < nq; ++i) {
      double a = 0.0, b = 0.0;
      if (!N) { /* sparse path: the vectors are over the coordinates themselves */
        a = xr[i];
        b = xi ? isign * xi[i] : 0.0;
      }
      for (int j = 0; N && j < nr; ++j) {
        a += N[(size_t)j * nq + i] * xr[j];
        if (xi) b += isign * N[(size_t)j * nq + i] * xi[j];
      }
      pr[i] = a;
      pi[i] = b;
    }
    /* scale by 1/phi_i at the largest component: it becomes 1, real */
    int at = 0;
    double big = -1.0;
    for (int i = 0; i < nq; ++i)
      if (hypot(pr[i], pi[i]) > big) {
        big = hypot(pr[i], pi[i]);
        at = i;
      }
    if (big > 0.0) {
      const double dr = pr[at] / (big * big), di = -pi[at] / (big * big); /* 1 / phi_at */
      for (int i = 0; i < nq; ++i) {
        const double a = pr[i] * dr - pi[i] * di, b = pr[i] * di + pi[i] * dr;
        pr[i] = a;
        pi[i] = b;
      }
    }
  }
  *out = md;
  return 0;
}

/* LAPACK reports a bad argument through xerbla, whose reference version prints a line and STOPs:
   the calling program would end with exit status 0. The library never ends its caller, so this
   definition (found before liblapack's, which the library links) only returns: the routine then
   returns with info < 0, which every call here checks. */
FMB_API void xerbla_(const char* name, const int* info, int len);
void xerbla_(const char* name, const int* info, int len) {
  (void)name;
  (void)info;
  (void)len;
}

/* fmb_modes on the scratch of a data object (w: its workspace, NULL when none could be made) */
static int modes_with(const fmbModel* m, fmbWorkspace* w, double t, const double* y, const double* yp, int count,
                      int method, fmbModes** out, fmbDiag* diag) {
  fmbDiag local;
  if (!diag) diag = &local;
  memset(diag, 0, sizeof *diag);
  if (!m || !y || !yp || !out) {
    fmb_diag_set(diag, FMB_EXIT_BAD_INPUT, "", 0, 0, "fmb_modes: NULL model, state or result");
    return FMB_EXIT_BAD_INPUT;
  }
  *out = NULL;
  /* an unknown method once ran the dense path silently; a time of nan linearized at nan */
  if (method != FMB_EIGEN_AUTO && method != FMB_EIGEN_DENSE && method != FMB_EIGEN_SPARSE) {
    fmb_diag_set(diag, FMB_EXIT_BAD_INPUT, m->path, 0, 0,
                 "fmb_modes: method %d is not FMB_EIGEN_AUTO, _DENSE or _SPARSE", method);
    return FMB_EXIT_BAD_INPUT;
  }
  if (!isfinite(t)) {
    fmb_diag_set(diag, FMB_EXIT_BAD_INPUT, m->path, 0, 0, "fmb_modes: the time %g is not finite", t);
    return FMB_EXIT_BAD_INPUT;
  }
  /* a state that is not finite is refused too: LAPACK would be handed NaN workspace sizes and its
     error handler (xerbla, above) would end the calling program */
  int bad = -1;
  for (int i = 0; i < m->ny && bad < 0; ++i)
    if (!isfinite(y[i]) || !isfinite(yp[i])) bad = i;
  if (bad >= 0) {
    fmb_diag_set(diag, FMB_EXIT_BAD_INPUT, m->path, 0, 0, "fmb_modes: the state is not finite (y or yp [%d])", bad);
    return FMB_EXIT_BAD_INPUT;
  }
  Linearized L;
  Reduced R;
  Eigen E;
  memset(&R, 0, sizeof R);
  memset(&E, 0, sizeof E);
  int rc = linearize(m, w, t, y, yp, &L, diag);
  if (rc) return rc;
  /* a few modes of a large system: shift-invert Arnoldi (bench/modes.sh: the crossover); when it
     does not apply (a singular saddle-point matrix: rigid motions; no convergence), dense */
  const int use_sparse = count > 0 && 4 * count < m->nq &&
                         (method == FMB_EIGEN_SPARSE || (method == FMB_EIGEN_AUTO && m->nq >= FMB_SPARSE_MIN_COORDS));
  /* the sparse path's saddle-point matrix has no gauge rows: spatial scenes are solved dense */
  rc = use_sparse && m->dimension != 3 ? solve_sparse(m, &L, count, &E, diag) : 1;
  if (rc == 1) {
    rc = reduce_constraints(m, y, &L, &R, diag);
    if (!rc) rc = solve_dense(m, t, &R, &E, diag);
  }
  if (!rc) rc = pack_modes(m, &E, &R, L.speed, count, out, diag);
  if (!rc && m->dimension == 3) { /* families about the spin axis (a static state: none, family 0) */
    memcpy((*out)->axis, L.rot.axis, sizeof L.rot.axis);
    memcpy((*out)->center, L.rot.center, sizeof L.rot.center);
    if (L.speed != 0.0) (void)fmb_modes_classify_with(m, w, t, y, *out, L.rot.axis, L.rot.center, NULL); /* else none */
  }
  linearized_free(&L);
  reduced_free(&R);
  eigen_free(&E);
  return rc;
}

double fmb_modes_mac(const fmbModes* a, int i, const fmbModes* b, int k) {
  if (!a || !b || a->nq != b->nq || i < 0 || k < 0 || i >= a->count || k >= b->count)
    return NAN; /* not 0: "orthogonal" */
  const double *ar = a->shape_re + (size_t)i * a->nq, *ai = a->shape_im + (size_t)i * a->nq;
  const double *br = b->shape_re + (size_t)k * b->nq, *bi = b->shape_im + (size_t)k * b->nq;
  double re = 0.0, im = 0.0, na = 0.0, nb = 0.0;
  for (int j = 0; j < a->nq; ++j) {
    re += ar[j] * br[j] + ai[j] * bi[j]; /* a^H b */
    im += ar[j] * bi[j] - ai[j] * br[j];
    na += ar[j] * ar[j] + ai[j] * ai[j];
    nb += br[j] * br[j] + bi[j] * bi[j];
  }
  return na > 0.0 && nb > 0.0 ? (re * re + im * im) / (na * nb) : 0.0;
}

/* ---------------------------------------------------------------------------------------------
 * tables through the one CSV writer (output.c) */

int fmb_write_table(const char* path, int ncol, const char* const* names, int nrow, const double* values,
                    fmbDiag* diag) {
  fmbDiag local;
  if (!diag) diag = &local;
  memset(diag, 0, sizeof *diag); /* this call's error, not an earlier one (the first error wins) */
  int named = names != NULL;
  for (int i = 0; named && i < ncol; ++i) named = names[i] != NULL;
  if (ncol <= 0 || !named || nrow < 0 || (nrow > 0 && !values)) {
    fmb_diag_set(diag, FMB_EXIT_BAD_INPUT, path ? path : "", 0, 0,
                 "fmb_write_table: no columns, a NULL name, no values or a negative row count");
    return FMB_EXIT_BAD_INPUT;
  }
  /* A name is written as it is (the CSV has no quoting: flexmbd's readers split the header at
     commas, csv_table.c, and take a first line starting with '#' as a comment): one that holds a
     comma, a quote or a control character (a line break), is empty, has blanks at its ends, or
     would turn the header into a comment, would misalign every later column or row; refused. */
  for (int i = 0; i < ncol; ++i) {
    const char* n = names[i];
    const size_t len = strlen(n);
    const char* why = len == 0                           ? "is empty"
                      : strpbrk(n, ",\"")                ? "holds a comma or a quote"
                      : n[0] == ' ' || n[len - 1] == ' ' ? "has blanks at its ends"
                      : i == 0 && n[0] == '#'            ? "starts the header with '#' (a comment line)"
                                                         : NULL;
    for (size_t k = 0; !why && k < len; ++k)
      if ((unsigned char)n[k] < 0x20 || n[k] == 0x7f) why = "holds a control character (a line break, a tab)";
    if (why) {
      fmb_diag_set(diag, FMB_EXIT_BAD_INPUT, path ? path : "", 0, 0,
                   "fmb_write_table: column %d's name %s: a CSV name may not (it has no quoting)", i + 1, why);
      return FMB_EXIT_BAD_INPUT;
    }
  }
  fmbCsv* c = fmb_csv_open(path, diag);
  if (!c) return FMB_EXIT_BAD_INPUT;
  fmb_csv_header_names(c, ncol, names);
  int rc = 0;
  for (int r = 0; r < nrow && !rc; ++r)
    if (fmb_csv_values(c, values + (size_t)r * ncol)) {
      fmb_diag_set(diag, FMB_EXIT_SOLVER, path, 0, 0, "writing the table failed (disk full?)");
      rc = FMB_EXIT_SOLVER;
    }
  fmb_csv_close(c);
  return rc;
}

int fmb_write_state_row(const fmbModel* m, const char* path, double t, const double* y, const double* yp,
                        fmbDiag* diag) {
  fmbDiag local;
  if (!diag) diag = &local;
  memset(diag, 0, sizeof *diag); /* this call's error, not an earlier one (the first error wins) */
  if (!m || !y || !yp) {
    fmb_diag_set(diag, FMB_EXIT_BAD_INPUT, "", 0, 0, "fmb_write_state_row: NULL model or state");
    return FMB_EXIT_BAD_INPUT;
  }
  fmbData* own = fmb_data_new(m, NULL);
  fmbWorkspace* w = own ? own->w : NULL;
  fmbCsv* c = w ? fmb_csv_open_guarded(path, m->inputs, diag) : NULL;
  int rc = 0;
  if (!c) {
    if (!w) fmb_diag_set(diag, FMB_EXIT_SOLVER, m->path, 0, 0, "out of memory");
    rc = w ? FMB_EXIT_BAD_INPUT : FMB_EXIT_SOLVER;
  } else {
    fmb_csv_header(c, m);
    const int wr = fmb_csv_row(c, m, w, t, y, yp);
    unsigned char* warned = wr > 0 ? NULL : calloc((size_t)m->nbody + 1, 1);
    if (warned) fmb_warn_model_range(m, w, t, y, warned); /* a state out of a body's model's range */
    free(warned);
    if (wr) {
      fmb_diag_set(diag, FMB_EXIT_SOLVER, m->path, 0, 0,
                   wr > 0 ? "an output is not finite" : "writing the output failed");
      rc = FMB_EXIT_SOLVER;
    }
  }
  fmb_csv_close(c);
  fmb_data_destroy(own);
  return rc;
}

int fmb_write_mode_shapes(const fmbModel* m, double t, const double* y, const double* yp, const fmbModes* md,
                          const char* path, fmbDiag* diag) {
  fmbDiag local;
  if (!diag) diag = &local;
  memset(diag, 0, sizeof *diag); /* this call's error, not an earlier one (the first error wins) */
  if (!m || !y || !yp || !md || md->nq != m->nq || md->count < 0 || (md->count > 0 && !md->shape_re)) {
    fmb_diag_set(diag, FMB_EXIT_BAD_INPUT, "", 0, 0, "fmb_write_mode_shapes: NULL or mismatched arguments");
    return FMB_EXIT_BAD_INPUT;
  }
  const int nout = m->noutput, nq = m->nq;
  fmbData* own = fmb_data_new(m, NULL);
  fmbWorkspace* w = own ? own->w : NULL;
  double* yy = malloc((size_t)m->ny * sizeof(double));
  double* plus = malloc((size_t)nout * sizeof(double));
  double* minus = malloc((size_t)nout * sizeof(double));
  double* rows = malloc((size_t)md->count * nout * sizeof(double) + 1);
  const char** names = malloc((size_t)nout * sizeof(char*));
  int rc = 0;
  if (!w || !yy || !plus || !minus || !rows || !names) {
    fmb_diag_set(diag, FMB_EXIT_SOLVER, m->path, 0, 0, "out of memory");
    rc = FMB_EXIT_SOLVER;
    goto done;
  }
  names[0] = "mode"; /* the time column's place */
  for (int i = 1; i < nout; ++i) names[i] = m->output[i].name;
  double qmax = 0.0;
  for (int i = 0; i < nq; ++i) qmax = fmax(qmax, fabs(y[i]));
  const double h = 1e-6 * (1.0 + qmax);
  for (int k = 0; k < md->count && !rc; ++k) {
    /* central difference of the outputs along the real shape: exact for outputs linear in q */
    const double* phi = md->shape_re + (size_t)k * nq;
    for (int sgn = 0; sgn < 2; ++sgn) {
      memcpy(yy, y, (size_t)m->ny * sizeof(double));
      for (int i = 0; i < nq; ++i) yy[i] += (sgn ? -h : h) * phi[i];
      if (fmb_outputs_eval(m, w, t, yy, yp, sgn ? minus : plus)) {
        fmb_diag_set(diag, FMB_EXIT_SOLVER, m->path, 0, 0, "an output is not finite along mode %d", k + 1);
        rc = FMB_EXIT_SOLVER;
      }
    }
    rows[(size_t)k * nout] = k + 1;
    for (int i = 1; i < nout; ++i) rows[(size_t)k * nout + i] = (plus[i] - minus[i]) / (2.0 * h);
  }
  if (!rc) rc = fmb_write_table(path, nout, names, md->count, rows, diag);
done:
  fmb_data_destroy(own);
  free(yy);
  free(plus);
  free(minus);
  free(rows);
  free(names);
  return rc;
}

/* The animation of mode k through the run's VTK writer (engine/vtk.c): `frames` states over one
   period, q = q* + amplitude Re(phi e^(i w tau)) = q* + amplitude (Re phi cos - Im phi sin), the
   time value tau (s; frame numbers for a mode of frequency 0 or a divergent one, whose motion is
   not periodic: there the shape is swept once, 0 -> amplitude -> -amplitude -> 0). */
int fmb_write_mode_animation(const fmbModel* m, double t, const double* y, const fmbModes* md, int k, double amplitude,
                             int frames, const char* dir, fmbDiag* diag) {
  fmbDiag local;
  if (!diag) diag = &local;
  memset(diag, 0, sizeof *diag); /* this call's error, not an earlier one (the first error wins) */
  if (!m || !y || !md || !dir || md->nq != m->nq || k < 0 || k >= md->count || !md->shape_re || !md->frequency ||
      frames < 2 || frames > 100000 || !(amplitude > 0.0) || !isfinite(amplitude) || !isfinite(t)) {
    /* an amplitude of 0, -1 or nan drew a still or inverted mode; 1 << 30 frames, as many files */
    fmb_diag_set(diag, FMB_EXIT_BAD_INPUT, "", 0, 0,
                 "fmb_write_mode_animation: NULL or mismatched arguments (frames 2..100000, amplitude > 0, t finite)");
    return FMB_EXIT_BAD_INPUT;
  }
  const int nq = m->nq;
  const double w = md->frequency[k];
  const int periodic = w > 0.0;
  fmbData* own = fmb_data_new(m, NULL);
  fmbWorkspace* ws = own ? own->w : NULL;
  double* yy = malloc((size_t)m->ny * sizeof(double));
  fmbVtk* v = ws && yy ? fmb_vtk_open(m, dir, diag) : NULL;
  int rc = 0;
  if (!v) {
    if (!diag->code) fmb_diag_set(diag, FMB_EXIT_SOLVER, m->path, 0, 0, "out of memory");
    rc = diag->code;
  }
  const double *re = md->shape_re + (size_t)k * nq, *im = md->shape_im + (size_t)k * nq;
  for (int j = 0; v && !rc && j < frames; ++j) {
    const double phase = 2.0 * M_PI * j / frames;
    const double c = cos(phase), sn = periodic ? sin(phase) : 0.0;
    memcpy(yy, y, (size_t)m->ny * sizeof(double));
    for (int i = 0; i < nq; ++i) yy[i] += amplitude * (re[i] * (periodic ? c : sin(phase)) - im[i] * sn);
    if (fmb_vtk_step(v, m, ws, periodic ? t + phase / w : t + j, yy)) {
      fmb_diag_set(diag, FMB_EXIT_SOLVER, dir, 0, 0, "writing the animation of mode %d failed (disk full?)", k + 1);
      rc = FMB_EXIT_SOLVER;
    }
  }
  fmb_vtk_close(v);
  fmb_data_destroy(own);
  free(yy);
  return rc;
}

/* ---------------------------------------------------------------------------------------------
 * the public modes entries: on the caller's data object, or on one made for the call (docs/api.md
 * "Analyses on a data object") */

int fmb_modes(const fmbModel* m, double t, const double* y, const double* yp, int count, int method, fmbModes** out,
              fmbDiag* diag) {
  fmbData* own = m ? fmb_data_new(m, NULL) : NULL;
  const int rc = modes_with(m, own ? own->w : NULL, t, y, yp, count, method, out, diag);
  fmb_data_destroy(own);
  return rc;
}

int fmb_modes_data(const fmbModel* m, fmbData* d, int count, int method, fmbModes** out, fmbDiag* diag) {
  fmbDiag local;
  if (!diag) diag = &local;
  memset(diag, 0, sizeof *diag);
  if (out) *out = NULL;
  if (fmb_data_misused(m, d, "fmb_modes_data", diag)) return FMB_EXIT_BAD_INPUT;
  if (!d->ic_done) {
    fmb_diag_set(diag, FMB_EXIT_BAD_INPUT, m->path, 0, 0,
                 "fmb_modes_data: the data object holds no state yet (fmb_init, or fmb_static_data, first)");
    return FMB_EXIT_BAD_INPUT;
  }
  fmb_workspace_hold_cache(d->w, 1); /* the run's next Jacobian may reuse its cached blocks */
  const int rc = modes_with(m, d->w, d->t, d->y, d->yp, count, method, out, diag);
  fmb_workspace_hold_cache(d->w, 0);
  return rc;
}
