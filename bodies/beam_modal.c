/*
 * beam_modal.c — `type: beam` with `reduction: {modes: k, stiffening_modes: r, axial_modes: m}`: the
 * floating-frame beam of beam.c (complete / FOAC / ZOAC) in k + r + m modal coordinates, with the coupling
 * deformation kept exactly (docs/models.md, "The reduced beam", Eqs. R1-R12).
 *
 * The modes are the clamped-free eigenmodes of the beam's own finite-element model (its
 * `elements`, the root node clamped to the frame as in beam.c): the k lowest bending modes, by
 * default each followed by its spin-stiffening vector K^-1 K_g1 phi_i (Eq. R1a: the first-order
 * change of the mode under spin, for every speed), and the m lowest axial ones (the two decouple
 * in the straight beam's mass and stiffness); "k" below counts them all. With
 * p = Phi eta the deformation is w1 = a(x) eta, w2 = b(x) eta, w2' = c(x) eta and the coupling
 * deformation w_c = -1/2 eta^T S(x) eta, S(x) = int_0^x c^T c (Eq. R2): every displacement field
 * of the beam is then a linear combination of the "line functions"
 *     phi = [1, x, a_i, b_i, c_i, S_ij (i <= j)]          (nb = 2 + 3k + k(k+1)/2 of them)
 * with coefficients polynomial in eta, eta', eta'' (Eq. R4), and every integral the residual and
 * the energies need is a bilinear form of two such coefficient vectors with the constant Gram
 * matrix G = int rho A phi phi^T dx (Eq. R5), computed once at load (exactly: per element the
 * integrands are polynomials of degree <= 10, 6 Gauss points). One residual is four products
 * G alpha (O(nb^2) = O(k^4)) and a few sparse dot products: nothing in the number of elements.
 * The Jacobian is left to the engine's differences (3 + k coordinates).
 */
#include <math.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>

#include "beam_section.h"
#include "flexmbd_plugin.h"
#include "internal.h" /* fmbp_node: the `reduction` mapping's own keys */

extern void dsygv_(const int* itype, const char* jobz, const char* uplo, const int* n, double* a, const int* lda,
                   double* b, const int* ldb, double* w, double* work, const int* lwork, int* info);

enum { MODAL_ZOAC = 0, MODAL_FOAC = 1, MODAL_COMPLETE = 2 };
enum { MODAL_MAX_ELEMENTS = 4096, MODAL_MAX_MODES = 64 };
/* Gauss points per element for G: S_ij S_kl is of degree 10 in xi (S of degree 5) */
enum { MODAL_POINTS = 6 };

typedef struct Modal {
  double L, rho, A, Izz, Emod, beta;
  int ne, model, nbend, nstiff, naxial, k, nb; /* k = nbend + nstiff + naxial */
  int stiff_given;                             /* stiffening_modes written: all of them or an error */
  double pos0[2], angle0, vel0[2], omega0;
  double le, r2, mass;
  double* omega2;    /* k: the retained modes' omega^2 (bending first, then axial) */
  double next_bend;  /* the first dropped bending frequency (rad/s), 0 when none is dropped */
  double next_axial; /* the first (dropped) axial one, 0 when none */
  double* ea;        /* [e][i][2] mode i's axial end values on element e */
  double* ed;        /* [e][i][4] its transverse element dofs (Hermite) */
  double* ec;        /* [e][i][3] its slope w2' on e as a quadratic in xi */
  double* Snode;     /* [node][i][j] S at the nodes (Eq. R2) */
  double* G;         /* nb x nb Gram matrix (Eq. R5) */
  /* The fields' 0 parts (F0) only ever hold the line functions 1, x, a, b, S and their 1 parts
     (F1, the cross-section's y terms) only 1 and c: G restricted to each set (n0, n1 of them, the
     indices in i0, i1), so `gram` multiplies only what can be nonzero */
  int n0, n1, *i0, *i1;
  double *G0, *G1;
} Modal;

/* the line functions' indices (Eq. R4) */
enum { I_ONE = 0, I_X = 1 };
static int IA(const Modal* m, int i) { return 2 + i + 0 * m->k; }
static int IB(const Modal* m, int i) { return 2 + m->k + i; }
static int IC(const Modal* m, int i) { return 2 + 2 * m->k + i; }
static int IS(const Modal* m, int i, int j) {
  if (i > j) {
    const int t = i;
    i = j;
    j = t;
  }
  return 2 + 3 * m->k + i * m->k - i * (i - 1) / 2 + (j - i);
}

static const char* const modal_model_names[] = {"zoac", "foac", "complete", NULL};
static const char* const modal_assembly_names[] = {"auto", "dense", "banded", NULL};
static const char* const modal_integration_names[] = {"reduced", "full", NULL};

/* ---------------------------------------------------------------------------------------------
 * The modes: clamped-free eigenmodes of the beam's finite-element model at rest (Eq. R1).
 * ------------------------------------------------------------------------------------------- */

/* K phi = omega^2 M phi, eigenvalues ascending, phi^T M phi = 1 (LAPACK dsygv); 0 = ok */
static int generalized_eigen(int n, double* K, double* M, double* w) {
  const int itype = 1;
  int lwork = -1, info = 0;
  double q;
  dsygv_(&itype, "V", "U", &n, K, &n, M, &n, w, &q, &lwork, &info);
  if (info) return info;
  lwork = (int)q;
  double* work = malloc(sizeof(double) * (size_t)lwork);
  if (!work) return -1;
  dsygv_(&itype, "V", "U", &n, K, &n, M, &n, w, work, &lwork, &info);
  free(work);
  return info;
}

/* Cholesky solve K y = b for nrhs right-hand sides (LAPACK dpotrf/dpotrs, K overwritten) */
extern void dpotrf_(const char* uplo, const int* n, double* a, const int* lda, int* info);
extern void dpotrs_(const char* uplo, const int* n, const int* nrhs, const double* a, const int* lda, double* b,
                    const int* ldb, int* info);

/* Y = A X for A dense n x n (column-major), X n x c */
static void dense_apply(int n, int c, const double* A, const double* X, double* Y) {
  memset(Y, 0, sizeof(double) * (size_t)n * c);
  for (int col = 0; col < c; ++col)
    for (int j = 0; j < n; ++j) {
      const double xj = X[(size_t)col * n + j];
      if (xj == 0.0) continue;
      const double* a = A + (size_t)j * n;
      double* y = Y + (size_t)col * n;
      for (int i = 0; i < n; ++i) y[i] += a[i] * xj;
    }
}

static double dot(int n, const double* x, const double* y) {
  double s = 0.0;
  for (int i = 0; i < n; ++i) s += x[i] * y[i];
  return s;
}

/* The stiffening vectors (Eq. R1a): psi_i = K^-1 K_g1 phi_i, i < nstiff, with K_g1 the geometric
   stiffness of unit spin about the root, int rho A (L^2 - x^2)/2 N2'N2'^T dx (the tension of
   steady spin is Omega^2 times it). Each is M-orthogonalised against the nbend eigenmodes and the
   vectors before it (Gram-Schmidt, twice) and normalised; then one Rayleigh-Ritz over the whole
   basis [modes, vectors] makes Phi^T K Phi diagonal and Phi^T M Phi = 1 to rounding (the modes
   come back as themselves: a vector M-orthogonal to them has a Rayleigh quotient above
   omega_(nbend+1)^2). K, M: the clamped bending matrices (n = nt, untouched); Phi: the
   eigenvectors (column-major, n x n) whose first nbend + nstiff columns become the basis, w2 its
   Ritz values. A vector already in the span (what is left of it after the projection is below
   1e-10 of it: rounding would make its direction) is left out, and m->nstiff counts those kept;
   when the scene gave stiffening_modes it is an error instead. 0 = ok, -1 = out of memory or
   LAPACK, 1 = a vector asked for is in the span. */
static int stiffening_vectors(Modal* m, int n, const double* K, const double* M, double* Phi, double* w2) {
  const int nb = m->nbend, ns = m->nstiff, ne = m->ne;
  int nv = nb + ns;
  const double le = m->le, rA = m->rho * m->A, L = m->L;
  double* Kg = calloc((size_t)n * n, sizeof(double));
  double* Kc = malloc(sizeof(double) * (size_t)n * n);
  double* V = malloc(sizeof(double) * (size_t)n * nv);  /* the basis [modes, vectors] */
  double* MV = malloc(sizeof(double) * (size_t)n * nv); /* M V, column by column as V is built */
  double* KV = malloc(sizeof(double) * (size_t)n * nv);
  double* Kr = calloc((size_t)nv * nv, sizeof(double));
  double* Mr = calloc((size_t)nv * nv, sizeof(double));
  double* wr = calloc((size_t)nv, sizeof(double));
  double* Psi = malloc(sizeof(double) * (size_t)n * ns); /* the candidates K^-1 K_g1 phi_i */
  int err = !Kg || !Kc || !V || !MV || !KV || !Kr || !Mr || !wr || !Psi ? -1 : 0;
  if (!err) {
    double xg[4], wg[4];
    fmb_gauss_legendre01(4, xg, wg); /* (L^2 - x^2) N'N': degree 6 */
    for (int e = 0; e < ne; ++e) {
      double kge[4][4] = {{0}};
      for (int g = 0; g < 4; ++g) {
        double ns4[4], nd[4];
        const double x = (e + xg[g]) * le;
        fmb_beam_hermite(xg[g], le, ns4, nd);
        for (int i = 0; i < 4; ++i)
          for (int j = 0; j < 4; ++j) kge[i][j] += wg[g] * le * rA * 0.5 * (L * L - x * x) * nd[i] * nd[j];
      }
      for (int i = 0; i < 4; ++i) {
        const int gi = 2 * (e + (i >= 2)) + (i & 1) - 2;
        if (gi < 0) continue;
        for (int j = 0; j < 4; ++j) {
          const int gj = 2 * (e + (j >= 2)) + (j & 1) - 2;
          if (gj >= 0) Kg[(size_t)gj * n + gi] += kge[i][j];
        }
      }
    }
    memcpy(V, Phi, sizeof(double) * (size_t)n * nb);
    dense_apply(n, nb, M, V, MV);
    dense_apply(n, ns, Kg, V, Psi); /* K_g1 phi_i, i < ns (ns <= nb) */
    memcpy(Kc, K, sizeof(double) * (size_t)n * n);
    int info = 0;
    dpotrf_("U", &n, Kc, &n, &info);
    if (!info) dpotrs_("U", &n, &ns, Kc, &n, Psi, &n, &info);
    if (info) err = -1;
  }
  int c = nb; /* the next column of V */
  for (int cand = 0; cand < ns && !err; ++cand) {
    double *y = V + (size_t)c * n, *My = MV + (size_t)c * n;
    memcpy(y, Psi + (size_t)cand * n, sizeof(double) * (size_t)n);
    dense_apply(n, 1, M, y, My);
    const double n0 = sqrt(dot(n, y, My));
    for (int pass = 0; pass < 2; ++pass)
      for (int j = 0; j < c; ++j) {
        const double h = dot(n, MV + (size_t)j * n, y);
        for (int i = 0; i < n; ++i) y[i] -= h * V[(size_t)j * n + i];
      }
    dense_apply(n, 1, M, y, My);
    const double n1 = sqrt(dot(n, y, My));
    if (!(n1 > 1e-10 * n0)) {
      if (m->stiff_given) err = 1;
      continue;
    }
    for (int i = 0; i < n; ++i) y[i] /= n1, My[i] /= n1;
    ++c;
  }
  if (!err) nv = c, m->nstiff = c - nb;
  if (!err) {
    dense_apply(n, nv, K, V, KV);
    for (int a = 0; a < nv; ++a)
      for (int b = 0; b < nv; ++b) {
        Kr[(size_t)b * nv + a] = dot(n, V + (size_t)a * n, KV + (size_t)b * n);
        Mr[(size_t)b * nv + a] = dot(n, V + (size_t)a * n, MV + (size_t)b * n);
      }
    if (generalized_eigen(nv, Kr, Mr, wr)) err = -1;
  }
  if (!err)
    for (int col = 0; col < nv; ++col) {
      double* out = Phi + (size_t)col * n;
      memset(out, 0, sizeof(double) * (size_t)n);
      for (int a = 0; a < nv; ++a)
        for (int i = 0; i < n; ++i) out[i] += V[(size_t)a * n + i] * Kr[(size_t)col * nv + a];
      w2[col] = wr[col];
    }
  free(Kg), free(Kc), free(V), free(MV), free(KV), free(Kr), free(Mr), free(wr), free(Psi);
  return err;
}

/* The bending modes (2 ne dofs [v, v'] per node 1..ne) and the axial ones (ne dofs): the straight
   beam's mass and stiffness do not couple them (the cross term int rho N1 (-y N2') vanishes with
   int y dA = 0), so each problem is solved alone. The nbend lowest bending eigenmodes are followed
   by the nstiff stiffening vectors (stiffening_vectors), then the axial modes. Fills ea, ed, ec and
   the frequencies (the vectors' Ritz values). 0 = ok, 1 = eigenproblem failed, 2 = a stiffening
   vector is already in the span of the modes. */
static int compute_modes(Modal* m) {
  const int ne = m->ne, nt = 2 * ne;
  const double le = m->le, rA = m->rho * m->A, rI = m->rho * m->Izz;
  double* Kt = calloc((size_t)nt * nt, sizeof(double));
  double* Mt = calloc((size_t)nt * nt, sizeof(double));
  double* K0 = malloc(sizeof(double) * (size_t)nt * nt);
  double* M0 = malloc(sizeof(double) * (size_t)nt * nt);
  double* Ka = calloc((size_t)ne * ne, sizeof(double));
  double* Ma = calloc((size_t)ne * ne, sizeof(double));
  double* wt = calloc((size_t)nt, sizeof(double));
  double* wa = calloc((size_t)ne, sizeof(double));
  int err = !Kt || !Mt || !K0 || !M0 || !Ka || !Ma || !wt || !wa;
  if (!err) {
    double xg[4], wg[4], me[4][4] = {{0}};
    fmb_gauss_legendre01(4, xg, wg); /* N N^T and N' N'^T: degree 6 */
    for (int g = 0; g < 4; ++g) {
      double ns[4], nd[4];
      fmb_beam_hermite(xg[g], le, ns, nd);
      for (int i = 0; i < 4; ++i)
        for (int j = 0; j < 4; ++j) me[i][j] += wg[g] * le * (rA * ns[i] * ns[j] + rI * nd[i] * nd[j]);
    }
    const double ei = m->Emod * m->Izz / (le * le * le);
    const double kb[4][4] = {{12.0, 6.0 * le, -12.0, 6.0 * le},
                             {6.0 * le, 4.0 * le * le, -6.0 * le, 2.0 * le * le},
                             {-12.0, -6.0 * le, 12.0, -6.0 * le},
                             {6.0 * le, 2.0 * le * le, -6.0 * le, 4.0 * le * le}};
    const double ka = m->Emod * m->A / le, ma = rA * le / 6.0;
    for (int e = 0; e < ne; ++e) {
      for (int i = 0; i < 4; ++i) {
        const int gi = 2 * (e + (i >= 2)) + (i & 1) - 2; /* node e + (i >= 2), dof i & 1; node 0 clamped */
        if (gi < 0) continue;
        for (int j = 0; j < 4; ++j) {
          const int gj = 2 * (e + (j >= 2)) + (j & 1) - 2;
          if (gj < 0) continue;
          Kt[(size_t)gj * nt + gi] += ei * kb[i][j];
          Mt[(size_t)gj * nt + gi] += me[i][j];
        }
      }
      for (int i = 0; i < 2; ++i) {
        const int gi = e + i - 1;
        if (gi < 0) continue;
        for (int j = 0; j < 2; ++j) {
          const int gj = e + j - 1;
          if (gj < 0) continue;
          Ka[(size_t)gj * ne + gi] += i == j ? ka : -ka;
          Ma[(size_t)gj * ne + gi] += i == j ? 2.0 * ma : ma;
        }
      }
    }
    memcpy(K0, Kt, sizeof(double) * (size_t)nt * nt);
    memcpy(M0, Mt, sizeof(double) * (size_t)nt * nt);
    err = generalized_eigen(nt, Kt, Mt, wt) || generalized_eigen(ne, Ka, Ma, wa);
  }
  if (!err) {
    m->next_bend = m->nbend < nt ? sqrt(fmax(wt[m->nbend], 0.0)) : 0.0;
    m->next_axial = m->naxial < ne ? sqrt(fmax(wa[m->naxial], 0.0)) : 0.0;
    const int st = m->nstiff > 0 ? stiffening_vectors(m, nt, K0, M0, Kt, wt) : 0;
    if (st) err = st > 0 ? 2 : 1;
  }
  const int nbend = m->nbend + m->nstiff, k = m->k = nbend + m->naxial; /* the vectors kept */
  if (!err) {
    for (int i = 0; i < k; ++i) {
      const int axial = i >= nbend, col = axial ? i - nbend : i;
      const double* phi = axial ? Ka + (size_t)col * ne : Kt + (size_t)col * nt;
      m->omega2[i] = axial ? wa[col] : wt[col];
      /* sign: the tip moves positively (deterministic modes, whatever LAPACK returns) */
      const double tip = axial ? phi[ne - 1] : (fabs(phi[nt - 2]) > 0.0 ? phi[nt - 2] : phi[nt - 1]);
      const double sg = tip < 0.0 ? -1.0 : 1.0;
      for (int e = 0; e < ne; ++e) {
        double* a = m->ea + ((size_t)e * k + i) * 2;
        double* d = m->ed + ((size_t)e * k + i) * 4;
        memset(a, 0, 2 * sizeof(double));
        memset(d, 0, 4 * sizeof(double));
        if (axial) {
          a[0] = e > 0 ? sg * phi[e - 1] : 0.0;
          a[1] = sg * phi[e];
        } else {
          if (e > 0) d[0] = sg * phi[2 * e - 2], d[1] = sg * phi[2 * e - 1];
          d[2] = sg * phi[2 * e], d[3] = sg * phi[2 * e + 1];
        }
      }
    }
  }
  free(Kt), free(Mt), free(K0), free(M0), free(Ka), free(Ma), free(wt), free(wa);
  return err;
}

/* ---------------------------------------------------------------------------------------------
 * The line functions at a point and the Gram matrix (Eqs. R2-R5).
 * ------------------------------------------------------------------------------------------- */

/* mode i's slope quadratic and S at (e, xi): S(x) = S(node e) + the element's part over [0, xi] */
static void line_functions(const Modal* m, int e, double xi, double* phi) {
  const int k = m->k;
  double ns[4], nd[4], pw[5];
  fmb_beam_hermite(xi, m->le, ns, nd);
  fmb_beam_int_weights(m->le, xi, pw);
  phi[I_ONE] = 1.0;
  phi[I_X] = (e + xi) * m->le;
  for (int i = 0; i < k; ++i) {
    const double* a = m->ea + ((size_t)e * k + i) * 2;
    const double* d = m->ed + ((size_t)e * k + i) * 4;
    phi[IA(m, i)] = (1.0 - xi) * a[0] + xi * a[1];
    phi[IB(m, i)] = ns[0] * d[0] + ns[1] * d[1] + ns[2] * d[2] + ns[3] * d[3];
    phi[IC(m, i)] = nd[0] * d[0] + nd[1] * d[1] + nd[2] * d[2] + nd[3] * d[3];
  }
  const double* S0 = m->Snode + (size_t)e * k * k;
  for (int i = 0; i < k; ++i)
    for (int j = i; j < k; ++j) {
      double q5[5];
      fmb_beam_poly_mul(m->ec + ((size_t)e * k + i) * 3, m->ec + ((size_t)e * k + j) * 3, q5);
      phi[IS(m, i, j)] = S0[i * k + j] + q5[0] * pw[0] + q5[1] * pw[1] + q5[2] * pw[2] + q5[3] * pw[3] + q5[4] * pw[4];
    }
}

static int build_tensors(Modal* m) {
  const int ne = m->ne, k = m->k, nb = m->nb;
  double nslope[4][3];
  fmb_beam_slope_coefficients(m->le, nslope);
  for (size_t t = 0; t < (size_t)ne * k; ++t)
    for (int c = 0; c < 3; ++c) {
      const double* d = m->ed + t * 4;
      m->ec[t * 3 + c] = nslope[0][c] * d[0] + nslope[1][c] * d[1] + nslope[2][c] * d[2] + nslope[3][c] * d[3];
    }
  /* S at the nodes: S(node e+1) = S(node e) + int over element e of c_i c_j */
  double pwf[5];
  fmb_beam_int_weights(m->le, 1.0, pwf);
  memset(m->Snode, 0, sizeof(double) * (size_t)k * k);
  for (int e = 0; e < ne; ++e)
    for (int i = 0; i < k; ++i)
      for (int j = 0; j < k; ++j) {
        double q5[5];
        fmb_beam_poly_mul(m->ec + ((size_t)e * k + i) * 3, m->ec + ((size_t)e * k + j) * 3, q5);
        m->Snode[((size_t)e + 1) * k * k + i * k + j] = m->Snode[(size_t)e * k * k + i * k + j] + q5[0] * pwf[0] +
                                                        q5[1] * pwf[1] + q5[2] * pwf[2] + q5[3] * pwf[3] +
                                                        q5[4] * pwf[4];
      }
  double xg[MODAL_POINTS], wg[MODAL_POINTS];
  fmb_gauss_legendre01(MODAL_POINTS, xg, wg);
  double* phi = malloc(sizeof(double) * (size_t)nb);
  if (!phi) return -1;
  memset(m->G, 0, sizeof(double) * (size_t)nb * nb);
  for (int e = 0; e < ne; ++e)
    for (int g = 0; g < MODAL_POINTS; ++g) {
      line_functions(m, e, xg[g], phi);
      const double w = wg[g] * m->le * m->rho * m->A;
      for (int i = 0; i < nb; ++i) {
        const double wi = w * phi[i];
        if (wi == 0.0) continue;
        double* row = m->G + (size_t)i * nb;
        for (int j = i; j < nb; ++j) row[j] += wi * phi[j];
      }
    }
  for (int i = 0; i < nb; ++i)
    for (int j = 0; j < i; ++j) m->G[(size_t)i * nb + j] = m->G[(size_t)j * nb + i];
  free(phi);
  m->i0 = malloc(sizeof(int) * (size_t)nb);
  m->i1 = malloc(sizeof(int) * (size_t)nb);
  if (!m->i0 || !m->i1) return -1;
  m->n0 = m->n1 = 0;
  for (int i = 0; i < nb; ++i) {
    const int is_c = i >= IC(m, 0) && i < IC(m, 0) + k;
    if (!is_c) m->i0[m->n0++] = i;
    if (is_c || i == I_ONE) m->i1[m->n1++] = i;
  }
  m->G0 = malloc(sizeof(double) * (size_t)m->n0 * m->n0);
  m->G1 = malloc(sizeof(double) * (size_t)m->n1 * m->n1);
  if (!m->G0 || !m->G1) return -1;
  for (int i = 0; i < m->n0; ++i)
    for (int j = 0; j < m->n0; ++j) m->G0[(size_t)i * m->n0 + j] = m->G[(size_t)m->i0[i] * nb + m->i0[j]];
  for (int i = 0; i < m->n1; ++i)
    for (int j = 0; j < m->n1; ++j) m->G1[(size_t)i * m->n1 + j] = m->G[(size_t)m->i1[i] * nb + m->i1[j]];
  return 0;
}

/* ---------------------------------------------------------------------------------------------
 * Parse.
 * ------------------------------------------------------------------------------------------- */
static void modal_destroy(void* self) {
  Modal* m = self;
  if (!m) return;
  free(m->omega2), free(m->ea), free(m->ed), free(m->ec), free(m->Snode), free(m->G);
  free(m->i0), free(m->i1), free(m->G0), free(m->G1);
  free(m);
}

static int modal_parse(fmbParser* p, fmbNode item, void** self) {
  Modal* m = calloc(1, sizeof *m);
  if (!m) return fmb_parse_error(p, item, "out of memory");
  *self = m;
  int err = 0;
  err |= fmb_get_double(p, item, "length", FMB_REQUIRED | FMB_POSITIVE, &m->L);
  err |= fmb_get_int(p, item, "elements", FMB_REQUIRED, 1, MODAL_MAX_ELEMENTS, &m->ne);
  err |= fmb_get_double(p, item, "density", FMB_REQUIRED | FMB_POSITIVE, &m->rho);
  err |= fmb_get_double(p, item, "area", FMB_REQUIRED | FMB_POSITIVE, &m->A);
  err |= fmb_get_double(p, item, "second_moment", FMB_REQUIRED | FMB_POSITIVE, &m->Izz);
  err |= fmb_get_double(p, item, "youngs_modulus", FMB_REQUIRED | FMB_POSITIVE, &m->Emod);
  m->model = MODAL_COMPLETE;
  err |= fmb_get_choice(p, item, "model", FMB_OPTIONAL, modal_model_names, &m->model);
  err |= fmb_get_vec2(p, item, "position", FMB_OPTIONAL, m->pos0);
  err |= fmb_get_angle(p, item, "angle", FMB_POSE, &m->angle0);
  err |= fmb_get_vec2(p, item, "velocity", FMB_OPTIONAL, m->vel0);
  err |= fmb_get_double(p, item, "angular_velocity", FMB_OPTIONAL, &m->omega0);
  err |= fmb_get_double(p, item, "damping", FMB_OPTIONAL | FMB_NONNEGATIVE, &m->beta);
  /* the full mesh's keys that mean nothing in modal coordinates are read and checked, so a scene
     keeps them when it switches the reduction on and off: the quadrature of the tensors is
     always exact (MODAL_POINTS), there is no assembly choice (the beam's block is 3 + k dense) */
  int assembly = 0, integration = 0, ng = 6;
  err |= fmb_get_choice(p, item, "assembly", FMB_OPTIONAL, modal_assembly_names, &assembly);
  err |= fmb_get_choice(p, item, "integration", FMB_OPTIONAL, modal_integration_names, &integration);
  err |= fmb_get_int(p, item, "quadrature_points", FMB_OPTIONAL, 4, FMB_GAUSS_MAX, &ng);
  if (err) return -1;
  if (assembly == 2)
    return fmb_parse_error(p, fmb_find_key(p, item, "assembly"),
                           "'assembly: banded' does not apply with 'reduction': the reduced beam's block is its 3 + k "
                           "coordinates, dense (use auto or dense, or remove 'reduction')");
  const fmbNode red = fmb_find_key(p, item, "reduction");
  const yaml_node_t* rn = fmbp_node(p, red);
  if (!rn || rn->type != YAML_MAPPING_NODE)
    return fmb_parse_error(p, red,
                           "expected a mapping for 'reduction', e.g. {modes: 4} (or {modes: 4, axial_modes: 1})");
  err |= fmb_get_int(p, red, "modes", FMB_REQUIRED, 0, 2 * (long)m->ne, &m->nbend);
  err |= fmb_get_int(p, red, "axial_modes", FMB_OPTIONAL, 0, m->ne, &m->naxial);
  if (err) return -1;
  /* default: one stiffening vector per bending mode, as many as the mesh has room for and the
     tensors allow (MODAL_MAX_MODES), those already in the span left out (stiffening_vectors) */
  const int room = m->nbend < 2 * m->ne - m->nbend ? m->nbend : 2 * m->ne - m->nbend;
  const int left = MODAL_MAX_MODES - m->nbend - m->naxial;
  m->nstiff = room < left ? room : left > 0 ? left : 0;
  m->stiff_given = fmb_find_key(p, red, "stiffening_modes") >= 0;
  err |= fmb_get_int(p, red, "stiffening_modes", FMB_OPTIONAL, 0, room, &m->nstiff);
  if (err) return -1;
  /* its own keys only (the unknown-key check of the item would list every key of the beam) */
  for (yaml_node_pair_t* pr = rn->data.mapping.pairs.start; pr < rn->data.mapping.pairs.top; ++pr) {
    const yaml_node_t* key = fmbp_node(p, pr->key);
    const char* k = key && key->type == YAML_SCALAR_NODE ? (const char*)key->data.scalar.value : "";
    if (strcmp(k, "modes") != 0 && strcmp(k, "axial_modes") != 0 && strcmp(k, "stiffening_modes") != 0)
      return fmb_parse_error(p, pr->key,
                             "unknown key '%s' in 'reduction' (expected modes, stiffening_modes, axial_modes)", k);
  }
  m->k = m->nbend + m->nstiff + m->naxial;
  if (m->k < 1)
    return fmb_parse_error(p, fmb_find_key(p, red, "modes"),
                           "expected at least one mode in 'reduction' (modes + axial_modes >= 1), got 0");
  if (m->k > MODAL_MAX_MODES)
    return fmb_parse_error(p, red,
                           "expected at most %d modes in 'reduction' (modes + stiffening_modes + axial_modes), got "
                           "%d: the tensors grow "
                           "like k^4; above that the full mesh (`assembly: banded`) is cheaper",
                           MODAL_MAX_MODES, m->k);
  m->le = m->L / m->ne;
  m->r2 = m->Izz / m->A;
  m->mass = m->rho * m->A * m->L;
  const double me = m->rho * m->A * m->le, kbend = 12.0 * m->Emod * m->Izz / (m->le * m->le * m->le),
               kaxial = m->Emod * m->A / m->le;
  if (!isnormal(me) || !isnormal(kbend) || !isnormal(kaxial) || !isfinite(fmax(kbend, kaxial) / me)) {
    fmb_beam_refuse_degenerate(p, item, m->L, m->ne, m->rho, m->A, m->Izz, m->Emod, me, kbend, kaxial);
    return -1;
  }
  const int k = m->k; /* at most: compute_modes may leave stiffening vectors out */
  m->omega2 = calloc((size_t)k, sizeof(double));
  m->ea = calloc((size_t)m->ne * k * 2, sizeof(double));
  m->ed = calloc((size_t)m->ne * k * 4, sizeof(double));
  m->ec = calloc((size_t)m->ne * k * 3, sizeof(double));
  m->Snode = calloc(((size_t)m->ne + 1) * k * k, sizeof(double));
  if (!m->omega2 || !m->ea || !m->ed || !m->ec || !m->Snode) return fmb_parse_error(p, item, "out of memory");
  const int modes_err = compute_modes(m);
  if (modes_err == 2)
    return fmb_parse_error(
        p, fmb_find_key(p, red, "stiffening_modes") >= 0 ? fmb_find_key(p, red, "stiffening_modes") : red,
        "the beam's stiffening vectors K^-1 K_g phi_i are already in the span of its %d modes "
        "(nothing left to add): give fewer 'stiffening_modes' or set it to 0",
        m->nbend);
  if (modes_err)
    return fmb_parse_error(p, red,
                           "the beam's clamped-free eigenproblem failed (LAPACK dsygv): its mass or stiffness "
                           "is not usable");
  m->nb = 2 + 3 * m->k + m->k * (m->k + 1) / 2;
  m->G = calloc((size_t)m->nb * m->nb, sizeof(double));
  if (!m->G || build_tensors(m)) return fmb_parse_error(p, item, "out of memory");
  return 0;
}

static int modal_ncoord(const void* self) { return 3 + ((const Modal*)self)->k; }

/* scratch: 17 coefficient fields of 4 nb (a gram output is followed by its compressed input), plus 2 k */
enum { NFIELDS = 17, CACHE_HEAD = 7 };
static size_t scratch_size(const Modal* m) { return (size_t)NFIELDS * 4 * (size_t)m->nb + 2 * (size_t)m->k; }
/* then the energies' cache (integrals_cached): a head and the state (q, v) they belong to */
static size_t modal_nwork(const void* self) {
  const Modal* m = self;
  return scratch_size(m) + CACHE_HEAD + 2 * (3 + (size_t)m->k);
}

static void modal_initial(const void* self, double* q0, double* v0) {
  const Modal* m = self;
  const int nc = 3 + m->k;
  memset(q0, 0, sizeof(double) * (size_t)nc);
  memset(v0, 0, sizeof(double) * (size_t)nc);
  q0[0] = m->pos0[0], q0[1] = m->pos0[1], q0[2] = m->angle0;
  v0[0] = m->vel0[0], v0[1] = m->vel0[1], v0[2] = m->omega0;
}

/* ---------------------------------------------------------------------------------------------
 * Coefficient fields (Eq. R4): a vector field over the beam, F(x, y) = F0(x) + y F1(x), as four
 * coefficient vectors over the line functions: F0x, F0y, F1x, F1y (4 nb doubles). The integral
 * int rho F.H dV = int rho A (F0.H0 + r^2 F1.H1) dx (the cross-section pair, int y dA = 0) is
 * F^T G H component by component (Eq. R5).
 * ------------------------------------------------------------------------------------------- */
static void field_zero(const Modal* m, double* F) { memset(F, 0, sizeof(double) * 4 * (size_t)m->nb); }

/* adds s * sum_ij S_ij u_i w_j to F0x (the symmetric S basis holds i <= j once) */
static void add_quadratic(const Modal* m, double* F, const double* u, const double* w, double s) {
  for (int i = 0; i < m->k; ++i)
    for (int j = i; j < m->k; ++j) F[IS(m, i, j)] += s * (i == j ? u[i] * w[i] : u[i] * w[j] + u[j] * w[i]);
}

/* u_D's part of the deformation's field at rates eta (s = sRD: with rho0 when rigid is set) */
static void field_deformation(const Modal* m, double* F, const double* eta, int rigid) {
  const int nb = m->nb;
  field_zero(m, F);
  for (int i = 0; i < m->k; ++i) {
    F[IA(m, i)] = eta[i];
    F[nb + IB(m, i)] = eta[i];
    F[2 * nb + IC(m, i)] = -eta[i]; /* u1 = w1 - y w2' */
  }
  if (rigid) {
    F[I_X] = 1.0; /* rho0 = [x, y] */
    F[3 * nb + I_ONE] = 1.0;
  }
}

/* a = g0 + al I~ s - om^2 s + 2 om I~ sd + sdd (the body-frame acceleration, Eq. R6), with
   I~ [u, v] = [-v, u] on each of the 0 and 1 parts */
static void field_accel(const Modal* m, double* a, const double* s, const double* sd, const double* sdd,
                        const double g0[2], double om, double al) {
  const int nb = m->nb;
  for (int part = 0; part < 2; ++part) {
    const int x = 2 * part * nb, y = x + nb;
    for (int i = 0; i < nb; ++i) {
      a[x + i] = -al * s[y + i] - om * om * s[x + i] - 2.0 * om * (sd ? sd[y + i] : 0.0) + (sdd ? sdd[x + i] : 0.0);
      a[y + i] = al * s[x + i] - om * om * s[y + i] + 2.0 * om * (sd ? sd[x + i] : 0.0) + (sdd ? sdd[y + i] : 0.0);
    }
  }
  if (g0) a[I_ONE] += g0[0], a[nb + I_ONE] += g0[1];
}

/* GF = G F, component by component, over the line functions each part can hold (Modal.i0, i1):
   the entries outside them stay zero in F and are not needed of GF (ip, ip_rot read them only
   against zeros) */
static void gram(const Modal* m, const double* F, double* GF) {
  const int nb = m->nb;
  double* fc = GF + 4 * (size_t)nb; /* the compressed input: every GF has a field's room after it */
  memset(GF, 0, sizeof(double) * 4 * (size_t)nb);
  for (int c = 0; c < 4; ++c) {
    const int n = c < 2 ? m->n0 : m->n1;
    const int* idx = c < 2 ? m->i0 : m->i1;
    const double* Gs = c < 2 ? m->G0 : m->G1;
    const double* f = F + (size_t)c * nb;
    double* out = GF + (size_t)c * nb;
    for (int j = 0; j < n; ++j) fc[j] = f[idx[j]];
    for (int i = 0; i < n; ++i) {
      const double* row = Gs + (size_t)i * n;
      double s0 = 0.0, s1 = 0.0, s2 = 0.0, s3 = 0.0; /* four sums: independent, so they pipeline */
      int j = 0;
      for (; j + 4 <= n; j += 4) {
        s0 += row[j] * fc[j];
        s1 += row[j + 1] * fc[j + 1];
        s2 += row[j + 2] * fc[j + 2];
        s3 += row[j + 3] * fc[j + 3];
      }
      for (; j < n; ++j) s0 += row[j] * fc[j];
      out[idx[i]] = (s0 + s1) + (s2 + s3);
    }
  }
}

/* int rho F.H dV with GH = G H */
static double ip(const Modal* m, const double* F, const double* GH) {
  const int nb = m->nb;
  double s0 = 0.0, s1 = 0.0;
  for (int i = 0; i < 2 * nb; ++i) s0 += F[i] * GH[i];
  for (int i = 2 * nb; i < 4 * nb; ++i) s1 += F[i] * GH[i];
  return s0 + m->r2 * s1;
}

/* int rho A F dx of one component's coefficients (G's first row: the line functions' integrals) */
static double ip_one(const Modal* m, const double* F) {
  double s = 0.0;
  for (int i = 0; i < m->nb; ++i) s += m->G[i] * F[i];
  return s;
}

/* int rho (I~ F).H dV */
static double ip_rot(const Modal* m, const double* F, const double* GH) {
  const int nb = m->nb;
  double s0 = 0.0, s1 = 0.0;
  for (int i = 0; i < nb; ++i) {
    s0 += -F[nb + i] * GH[i] + F[i] * GH[nb + i];
    s1 += -F[3 * nb + i] * GH[2 * nb + i] + F[2 * nb + i] * GH[3 * nb + i];
  }
  return s0 + m->r2 * s1;
}

/* The state's fields: sRD (rho0 + u_D), sC = [w_c, 0] and their rates (Eq. R4) */
typedef struct {
  double *sRD, *sC, *sdD, *sdC, *sddD, *sddC, *rho0;
} Fields;

static void state_fields(const Modal* m, const double* eta, const double* etad, const double* etadd, double* work,
                         Fields* f) {
  const size_t fs = 4 * (size_t)m->nb;
  f->sRD = work, f->sC = work + fs, f->sdD = work + 2 * fs, f->sdC = work + 3 * fs;
  f->sddD = work + 4 * fs, f->sddC = work + 5 * fs, f->rho0 = work + 6 * fs;
  field_deformation(m, f->sRD, eta, 1);
  field_deformation(m, f->sdD, etad, 0);
  field_zero(m, f->rho0); /* rho0 = [x, y] alone */
  f->rho0[I_X] = 1.0;
  f->rho0[3 * m->nb + I_ONE] = 1.0;
  if (etadd) field_deformation(m, f->sddD, etadd, 0);
  field_zero(m, f->sC), field_zero(m, f->sdC), field_zero(m, f->sddC);
  if (m->model == MODAL_ZOAC) return;
  add_quadratic(m, f->sC, eta, eta, -0.5);   /* w_c = -1/2 eta^T S eta */
  add_quadratic(m, f->sdC, eta, etad, -1.0); /* w_c' = -eta^T S eta' */
  if (etadd) {
    add_quadratic(m, f->sddC, eta, etadd, -1.0); /* w_c'' = -eta^T S eta'' - eta'^T S eta' */
    add_quadratic(m, f->sddC, etad, etad, -1.0);
  }
}

/* ---------------------------------------------------------------------------------------------
 * Residual (Eqs. R7-R9): R = J_R^T F_R + J_D^T F_D + J_C^T F_C as in beam.c's point_forces,
 * integrated over the beam with G:
 *   complete  F_R = F_D = F_C = a(sRD + sC) - f
 *   FOAC      F_D = a_RD - f, F_R = F_D + a_C, F_C = a_R - f
 *   ZOAC      F_R = F_D = a_RD - f (no w_c)
 * ------------------------------------------------------------------------------------------- */
static int modal_residual(const void* self, const fmbEnv* env, const double* q, const double* v, const double* a,
                          double* R, double* work) {
  const Modal* m = self;
  const int k = m->k, nb = m->nb;
  const size_t fs = 4 * (size_t)nb;
  const double *eta = q + 3, *etad = v + 3, *etadd = a + 3;
  Fields f;
  state_fields(m, eta, etad, etadd, work, &f);
  double *FR = work + 7 * fs, *FD = work + 8 * fs, *FC = work + 9 * fs, *tmp = work + 10 * fs;
  double *GR = work + 11 * fs, *GD = work + 13 * fs, *GC = work + 15 * fs; /* each with room for gram after it */
  const double c = cos(q[2]), s = sin(q[2]), om = v[2], al = a[2];
  double g0[2] = {c * a[0] + s * a[1], -s * a[0] + c * a[1]}; /* A^T r0'' - f */
  if (env && env->has_gravity) {
    g0[0] -= c * env->gravity[0] + s * env->gravity[1];
    g0[1] -= -s * env->gravity[0] + c * env->gravity[1];
  }
  if (m->model == MODAL_ZOAC) {
    field_accel(m, FD, f.sRD, f.sdD, f.sddD, g0, om, al);
    gram(m, FD, GD);
    GR = GD;
  } else if (m->model == MODAL_COMPLETE) {
    for (size_t i = 0; i < fs; ++i) tmp[i] = f.sRD[i] + f.sC[i];
    for (size_t i = 0; i < fs; ++i) FC[i] = f.sdD[i] + f.sdC[i];
    for (size_t i = 0; i < fs; ++i) FR[i] = f.sddD[i] + f.sddC[i];
    field_accel(m, FD, tmp, FC, FR, g0, om, al);
    gram(m, FD, GD);
    GR = GC = GD;
  } else {
    field_accel(m, FD, f.sRD, f.sdD, f.sddD, g0, om, al);   /* a_RD - f */
    field_accel(m, tmp, f.sC, f.sdC, f.sddC, NULL, om, al); /* a_C */
    for (size_t i = 0; i < fs; ++i) FR[i] = FD[i] + tmp[i];
    field_accel(m, FC, f.rho0, NULL, NULL, g0, om, al); /* a_R - f */
    gram(m, FD, GD), gram(m, FR, GR), gram(m, FC, GC);
  }
  /* frame rows: A(theta) int F_R, and int (I~ rho0).F_R + (I~ u_D).F_D + (I~ [w_c, 0]).F_C */
  R[0] = c * GR[I_ONE] - s * GR[nb + I_ONE];
  R[1] = s * GR[I_ONE] + c * GR[nb + I_ONE];
  /* u_D = sRD - rho0: (I~ u_D).F_D = (I~ sRD).F_D - (I~ rho0).F_D */
  R[2] = ip_rot(m, f.rho0, GR) + ip_rot(m, f.sRD, GD) - ip_rot(m, f.rho0, GD);
  if (m->model != MODAL_ZOAC) R[2] += ip_rot(m, f.sC, GC);
  /* modal rows: (du_D/deta)^T F_D + (dw_c/deta) F_C,x + omega^2 (eta + beta eta') */
  for (int i = 0; i < k; ++i) {
    double r = GD[IA(m, i)] + GD[nb + IB(m, i)] - m->r2 * GD[2 * nb + IC(m, i)];
    if (m->model != MODAL_ZOAC)
      for (int j = 0; j < k; ++j) r -= eta[j] * GC[IS(m, i, j)];
    R[3 + i] = r + m->omega2[i] * (eta[i] + m->beta * etad[i]);
  }
  for (int i = 0; i < 3 + k; ++i)
    if (!isfinite(R[i])) return 1;
  return 0;
}

/* ---------------------------------------------------------------------------------------------
 * Kinematics of a point, markers.
 * ------------------------------------------------------------------------------------------- */

/* body-frame displacement u at reference (x, y) (with w_c in the coupled models), its rate, the
   slope w2', and du/deta (2 x k, row-major) when dueta != NULL */
static void point_kinematics(const Modal* m, const double* eta, const double* etad, double x, double y, double u[2],
                             double ud[2], double* slope, double* dueta) {
  const int k = m->k;
  int e;
  double xi;
  fmb_beam_locate(m->le, m->ne, x, &e, &xi);
  double ns[4], nd[4], pw[5];
  fmb_beam_hermite(xi, m->le, ns, nd);
  fmb_beam_int_weights(m->le, xi, pw);
  u[0] = u[1] = *slope = 0.0;
  if (ud) ud[0] = ud[1] = 0.0;
  const double* S0 = m->Snode + (size_t)e * k * k;
  for (int i = 0; i < k; ++i) {
    const double* a = m->ea + ((size_t)e * k + i) * 2;
    const double* d = m->ed + ((size_t)e * k + i) * 4;
    const double ai = (1.0 - xi) * a[0] + xi * a[1];
    const double bi = ns[0] * d[0] + ns[1] * d[1] + ns[2] * d[2] + ns[3] * d[3];
    const double ci = nd[0] * d[0] + nd[1] * d[1] + nd[2] * d[2] + nd[3] * d[3];
    double Seta = 0.0, Setad = 0.0;
    if (m->model != MODAL_ZOAC)
      for (int j = 0; j < k; ++j) {
        double q5[5];
        fmb_beam_poly_mul(m->ec + ((size_t)e * k + i) * 3, m->ec + ((size_t)e * k + j) * 3, q5);
        const double Sij =
            S0[i * k + j] + q5[0] * pw[0] + q5[1] * pw[1] + q5[2] * pw[2] + q5[3] * pw[3] + q5[4] * pw[4];
        Seta += Sij * eta[j];
        if (etad) Setad += Sij * etad[j];
      }
    u[0] += (ai - y * ci - 0.5 * Seta) * eta[i];
    u[1] += bi * eta[i];
    *slope += ci * eta[i];
    if (ud) {
      ud[0] += (ai - y * ci) * etad[i] - Setad * eta[i]; /* w_c' = -eta^T S eta' */
      ud[1] += bi * etad[i];
    }
    if (dueta) dueta[i] = ai - y * ci - Seta, dueta[k + i] = bi;
  }
}

static int modal_marker(const void* self, const double* q, const double local[2], double pos[2], double* angle,
                        double* dpos_dq, double* dangle_dq, double* work) {
  const Modal* m = self;
  const int k = m->k, nc = 3 + k;
  const double x = local[0], y = local[1];
  if (x > m->L * (1.0 + 1e-12)) return -1;
  double* dueta = work; /* 2 k */
  double u[2] = {0.0, 0.0}, slope = 0.0;
  const int onbeam = x > 0.0; /* the root is clamped: points at x <= 0 move with the frame */
  if (onbeam) point_kinematics(m, q + 3, NULL, x, y, u, NULL, &slope, dueta);
  const double c = cos(q[2]), s = sin(q[2]), rb[2] = {x + u[0], y + u[1]};
  pos[0] = q[0] + c * rb[0] - s * rb[1];
  pos[1] = q[1] + s * rb[0] + c * rb[1];
  if (angle) *angle = q[2] + slope;
  if (dangle_dq) {
    memset(dangle_dq, 0, sizeof(double) * (size_t)nc);
    dangle_dq[2] = 1.0;
    if (onbeam) {
      double ns[4], nd[4], xi;
      int e;
      fmb_beam_locate(m->le, m->ne, x, &e, &xi);
      fmb_beam_hermite(xi, m->le, ns, nd);
      for (int i = 0; i < k; ++i) {
        const double* d = m->ed + ((size_t)e * k + i) * 4;
        dangle_dq[3 + i] = nd[0] * d[0] + nd[1] * d[1] + nd[2] * d[2] + nd[3] * d[3];
      }
    }
  }
  if (dpos_dq) {
    memset(dpos_dq, 0, sizeof(double) * 2 * (size_t)nc);
    double *r0 = dpos_dq, *r1 = dpos_dq + nc;
    r0[0] = r1[1] = 1.0;
    r0[2] = -s * rb[0] - c * rb[1];
    r1[2] = c * rb[0] - s * rb[1];
    if (onbeam)
      for (int i = 0; i < k; ++i) {
        r0[3 + i] = c * dueta[i] - s * dueta[k + i];
        r1[3 + i] = s * dueta[i] + c * dueta[k + i];
      }
  }
  return 0;
}

/* ---------------------------------------------------------------------------------------------
 * Energies (Eq. R10): each model's own T, U_e = 1/2 sum omega_i^2 eta_i^2, U_g = -int rho g.r;
 * and p_theta = dT/dtheta'.
 * ------------------------------------------------------------------------------------------- */
static void modal_integrals(const Modal* m, const fmbEnv* env, const double* q, const double* v, fmbEnergy* en,
                            double* ptheta, double* work) {
  const int k = m->k, nb = m->nb;
  const size_t fs = 4 * (size_t)nb;
  Fields f;
  state_fields(m, q + 3, v + 3, NULL, work, &f);
  double *vRD = work + 7 * fs, *vC = work + 8 * fs, *vR = work + 9 * fs, *Gv = work + 10 * fs, *Gw = work + 12 * fs;
  double *tmp = work + 14 * fs, *Gt = work + 15 * fs;
  const double c = cos(q[2]), s = sin(q[2]), om = v[2];
  const double v0[2] = {c * v[0] + s * v[1], -s * v[0] + c * v[1]};
  /* v = v0 + om I~ s + sd, part by part */
  for (int part = 0; part < 2; ++part) {
    const int x = 2 * part * nb, y = x + nb;
    for (int i = 0; i < nb; ++i) {
      vRD[x + i] = -om * f.sRD[y + i] + f.sdD[x + i];
      vRD[y + i] = om * f.sRD[x + i] + f.sdD[y + i];
      vC[x + i] = -om * f.sC[y + i] + f.sdC[x + i];
      vC[y + i] = om * f.sC[x + i] + f.sdC[y + i];
      vR[x + i] = -om * f.rho0[y + i];
      vR[y + i] = om * f.rho0[x + i];
    }
  }
  vRD[I_ONE] += v0[0], vRD[nb + I_ONE] += v0[1], vR[I_ONE] += v0[0], vR[nb + I_ONE] += v0[1];
  double T, pth;
  if (m->model == MODAL_COMPLETE) {
    for (size_t i = 0; i < fs; ++i) tmp[i] = vRD[i] + vC[i];
    gram(m, tmp, Gt);
    T = 0.5 * ip(m, tmp, Gt);
    for (size_t i = 0; i < fs; ++i) tmp[i] = f.sRD[i] + f.sC[i];
    pth = ip_rot(m, tmp, Gt);
  } else {
    gram(m, vRD, Gv);
    T = 0.5 * ip(m, vRD, Gv);
    pth = ip_rot(m, f.sRD, Gv);
    if (m->model == MODAL_FOAC) {
      gram(m, vC, Gw);
      gram(m, vR, Gt);
      T += ip(m, vR, Gw);
      pth += ip_rot(m, f.rho0, Gw) + ip_rot(m, f.sC, Gt);
    }
  }
  double Ue = 0.0;
  for (int i = 0; i < k; ++i) Ue += 0.5 * m->omega2[i] * q[3 + i] * q[3 + i];
  double Ug = 0.0;
  if (env && env->has_gravity) {
    const double fb[2] = {c * env->gravity[0] + s * env->gravity[1], -s * env->gravity[0] + c * env->gravity[1]};
    /* -int rho f.s over the beam (ZOAC: s without w_c), then the frame origin's share */
    for (size_t i = 0; i < fs; ++i) tmp[i] = f.sRD[i] + f.sC[i];
    Ug = -(fb[0] * ip_one(m, tmp) + fb[1] * ip_one(m, tmp + nb));
    Ug -= m->mass * (env->gravity[0] * q[0] + env->gravity[1] * q[1]);
  }
  if (en) en->kinetic = T, en->strain = Ue, en->gravity = Ug, en->spring = 0.0;
  if (ptheta) *ptheta = pth;
}

/* A row asks energy.kinetic, .strain, .total and beam.ang_momentum of one state: one pass of
   modal_integrals serves them all. The values are kept after the scratch, keyed by the state's
   bytes and the gravity they were computed with (the work is calloc'ed: head 0 = empty). */
static void integrals_cached(const Modal* m, const fmbEnv* env, const double* q, const double* v, fmbEnergy* en,
                             double* ptheta, double* work) {
  double* c = work + scratch_size(m);
  const size_t bytes = sizeof(double) * (3 + (size_t)m->k);
  const int grav = env && env->has_gravity;
  const double g0 = grav ? env->gravity[0] : 0.0, g1 = grav ? env->gravity[1] : 0.0;
  const int hit = c[0] == 1.0 && memcmp(c + CACHE_HEAD, q, bytes) == 0 &&
                  memcmp(c + CACHE_HEAD + 3 + m->k, v, bytes) == 0 && (!en || (c[1] == g0 && c[2] == g1));
  if (!hit) {
    fmbEnergy e;
    double pth;
    modal_integrals(m, env, q, v, &e, &pth, work);
    c[0] = 1.0, c[1] = g0, c[2] = g1, c[3] = e.kinetic, c[4] = e.strain, c[5] = e.gravity, c[6] = pth;
    memcpy(c + CACHE_HEAD, q, bytes);
    memcpy(c + CACHE_HEAD + 3 + m->k, v, bytes);
  }
  if (en) en->kinetic = c[3], en->strain = c[4], en->gravity = c[5], en->spring = 0.0;
  if (ptheta) *ptheta = c[6];
}

static void modal_energy(const void* self, const fmbEnv* env, const double* q, const double* v, fmbEnergy* en,
                         double* work) {
  integrals_cached(self, env, q, v, en, NULL, work);
}

/* ---------------------------------------------------------------------------------------------
 * Outputs: the full beam's names and meanings (beam_section.h).
 * ------------------------------------------------------------------------------------------- */
static int modal_output_lookup(const void* self, const char* quantity) {
  return fmb_beam_output_lookup(((const Modal*)self)->ne, quantity);
}

static int modal_output(const void* self, int id, const double* q, const double* v, double* value, double* work) {
  const Modal* m = self;
  double x = m->L;
  int comp = id;
  if (id >= FMB_BEAM_NODE_BASE) {
    const int node = (id - FMB_BEAM_NODE_BASE) / FMB_BEAM_NODE_STRIDE;
    x = node * m->le;
    comp = (id - FMB_BEAM_NODE_BASE) % FMB_BEAM_NODE_STRIDE;
    comp = comp == 0 ? FMB_BEAM_TIP_U : comp == 1 ? FMB_BEAM_TIP_V : comp == 2 ? FMB_BEAM_TIP_X : FMB_BEAM_TIP_Y;
  } else if (id < 0 || id >= FMB_BEAM_NTIP) {
    return -1;
  } else if (id == FMB_BEAM_ANG_MOMENTUM) {
    integrals_cached(m, NULL, q, v, NULL, value, work);
    return 0;
  }
  double u[2] = {0.0, 0.0}, ud[2] = {0.0, 0.0}, slope = 0.0;
  if (x > 0.0) point_kinematics(m, q + 3, v + 3, x, 0.0, u, ud, &slope, NULL);
  switch (comp) {
    case FMB_BEAM_TIP_U: *value = u[0]; break;
    case FMB_BEAM_TIP_V: *value = u[1]; break;
    case FMB_BEAM_TIP_U_RATE: *value = ud[0]; break;
    case FMB_BEAM_TIP_V_RATE: *value = ud[1]; break;
    case FMB_BEAM_TIP_ANGLE: *value = slope; break;
    case FMB_BEAM_TIP_X: *value = q[0] + cos(q[2]) * (x + u[0]) - sin(q[2]) * u[1]; break;
    default: *value = q[1] + sin(q[2]) * (x + u[0]) + cos(q[2]) * u[1]; break;
  }
  return 0;
}

/* The complete model's range is the full mesh's (docs/models.md, "Each model's range": 18 % of L
   for complete and ZOAC, 40 % for FOAC); ZOAC also above 30 % of its first bending frequency.
   The reduced beam adds its truncation, measured in docs/models.md ("The reduced beam"). */
static const char* modal_model_range(const void* self, const double* q, const double* v, char* msg, size_t len) {
  const Modal* m = self;
  double tip = 0.0;
  modal_output(m, FMB_BEAM_TIP_V, q, v, &tip, NULL);
  const double limit = m->model == MODAL_FOAC ? 0.40 : 0.18, w1 = sqrt(m->omega2[0]);
  if (fabs(tip) > limit * m->L) {
    snprintf(msg, len,
             "its tip deflects %.3g m, %.1f %% of its length, beyond the %.0f %% up to which the %s model stays within "
             "about 5 %% of the geometrically exact beam (docs/models.md); use `model: exact`",
             fabs(tip), 100.0 * fabs(tip) / m->L, 100.0 * limit, modal_model_names[m->model]);
    return msg;
  }
  if (m->model == MODAL_ZOAC && m->nbend > 0 && fabs(v[2]) > 0.3 * w1) {
    snprintf(msg, len,
             "it turns at %.3g rad/s, %.0f %% of its first bending frequency %.3g rad/s: ZOAC has no centrifugal "
             "stiffening, is off by more than about 5 %% beyond 30 %% and diverges at 100 %% (docs/models.md); use "
             "`model: complete` or `model: exact`",
             fabs(v[2]), 100.0 * fabs(v[2]) / w1, w1);
    return msg;
  }
  return NULL;
}

/* one line for `flexmbd check`: the model, where it sits in the hierarchy, the retained
   frequencies and the first dropped ones */
static void modal_describe(const void* self, FILE* f) {
  const Modal* m = self;
  static const char* const terms[] = {"w_c dropped (linear modal: no dynamic stiffening)", "w_c to first order",
                                      "w_c exact (quadratic in the modal coordinates)"};
  fprintf(f,
          "%s model reduced to %d bending + %d stiffening + %d axial clamped-free modes of its %d elements, %s%s; "
          "retained (rad/s):",
          modal_model_names[m->model], m->nbend, m->nstiff, m->naxial, m->ne, terms[m->model],
          m->beta > 0.0 ? ", stiffness-proportional damping" : "");
  /* the stiffening vectors' Ritz values are not frequencies of the beam: marked s, after the modes */
  for (int i = 0; i < m->k; ++i)
    fprintf(f, " %.6g%s", sqrt(fmax(m->omega2[i], 0.0)), i >= m->nbend + m->nstiff ? "a" : i >= m->nbend ? "s" : "");
  fprintf(f, "; first dropped: ");
  if (m->next_bend > 0.0) fprintf(f, "bending %.6g", m->next_bend);
  if (m->next_bend > 0.0 && m->next_axial > 0.0) fprintf(f, ", ");
  if (m->next_axial > 0.0) fprintf(f, "axial %.6g%s", m->next_axial, m->naxial ? "" : " (the beam is axially rigid)");
  if (m->next_bend <= 0.0 && m->next_axial <= 0.0) fprintf(f, "none (every mode of the mesh is kept)");
  fprintf(f,
          "; hierarchy: exact > complete full mesh > %s; accurate while the tip deflects less than %.0f %% of the "
          "length\n",
          m->model == MODAL_COMPLETE ? "complete reduced (this) > FOAC > ZOAC"
          : m->model == MODAL_FOAC   ? "complete reduced > FOAC reduced (this) > ZOAC"
                                     : "complete reduced > FOAC > ZOAC reduced (this)",
          m->model == MODAL_FOAC ? 40.0 : 18.0);
}

static const char* modal_indefinite_mass(const void* self) {
  const Modal* m = self;
  if (m->model != MODAL_FOAC) return NULL;
  return "the FOAC beam's kinetic energy is not positive definite (in modal coordinates as on the full mesh): with "
         "its angle free its mass matrix loses definiteness at small deflections; use `model: complete` (FOAC is "
         "usable only under prescribed rotation)";
}

static int modal_max_bdf_order(const void* self) {
  (void)self;
  return 2;
}

static const char* modal_invalid_state(const void* self, const double* q, const double* v) {
  const Modal* m = self;
  double u[2], slope;
  point_kinematics(m, q + 3, NULL, m->L, 0.0, u, NULL, &slope, NULL);
  (void)v;
  if (fabs(u[0]) <= m->L && fabs(u[1]) <= m->L) return NULL;
  return m->model == MODAL_ZOAC
             ? "its deformation exceeds its length: the solution is diverging. ZOAC has no dynamic stiffening and "
               "is unstable when spun above its first bending frequency; use model: foac or complete"
             : "its deformation exceeds its length: the beam has left the range of this model (a floating frame "
               "with small strains), whether the loads are too large for it or the motion is unstable";
}

static int modal_velocity_error_test(const void* self) {
  (void)self;
  return 0;
}

static int modal_centreline(const void* self, int n, double* local) {
  const Modal* m = self;
  return fmb_beam_centreline(m->L, m->ne, n, local);
}

/* the keys are type beam's (beam.c): one declaration for `types`, `conform` and the unknown-key check */
extern const fmbParam fmb_beam_params[];

/* reached through beam.c's `variant` op when the item has `reduction:` */
const fmbBodyType fmb_body_beam_modal = {
    .name = "beam",
    .abi = FMB_ABI_VERSION,
    .parse = modal_parse,
    .destroy = modal_destroy,
    .ncoord = modal_ncoord,
    .initial = modal_initial,
    .residual = modal_residual,
    .marker = modal_marker,
    .nwork = modal_nwork,
    .energy = modal_energy,
    .output_names = fmb_beam_output_names,
    .output_units = fmb_beam_output_units,
    .output_lookup = modal_output_lookup,
    .output = modal_output,
    .describe = modal_describe,
    .indefinite_mass = modal_indefinite_mass,
    .max_bdf_order = modal_max_bdf_order,
    .invalid_state = modal_invalid_state,
    .velocity_error_test = modal_velocity_error_test,
    .params = fmb_beam_params,
    .example = "length: 1\nelements: 4\ndensity: 1000\narea: 1e-3\nsecond_moment: 1e-7\nyoungs_modulus: 1e6\n"
               "angular_velocity: 3\nvelocity: [0.2, 0.5]\nreduction: {modes: 3, axial_modes: 1}\n",
    .example_damped = "damping: 0.05\n",
    .centreline = modal_centreline,
    .model_range = modal_model_range,
};
