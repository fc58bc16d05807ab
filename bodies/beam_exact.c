/*
 * beam_exact.c — `type: beam` with `model: exact`: the geometrically exact planar beam (absolute-
 * nodal cable kinematics of Berzeri & Shabana / Gerstmayr & Irschik) written in the beam's
 * floating frame, beside the complete, FOAC and ZOAC models of bodies/beam.c (docs/models.md).
 *
 * Coordinates q = [x, y, theta, a, (ux_i, uy_i, sx_i, sy_i) for nodes i = 1..ne]. In the frame the
 * centreline at reference arc length s is rho(s), cubic Hermite between nodes, with nodal values
 *     rho_i = (s_i + ux_i, uy_i),   rho'_i = (1 + sx_i, sy_i),
 * and the root node clamped to the frame: rho_0 = 0, rho'_0 = (1 + a, 0) (a: the root's free
 * stretch). So the frame is a tangent frame as in beam.c and every joint, drive and output sees
 * the same x, y, theta.
 *
 * Strains (exact, no small-deformation assumption):
 *     eps = |rho'| - 1 = (2 dx + dx^2 + dy^2) / (1 + |rho'|),  rho' = (1 + dx, dy)   (no cancellation)
 *     kappa = (rho' x rho'') / |rho'|^2,    N = EA eps,  M = EI kappa,
 *     U = 1/2 int (EA eps^2 + EI kappa^2) ds.
 * Membrane locking: `integration: reduced` (default) samples the axial term at the 3 Lobatto
 * points of each element and the bending term at 2 Gauss points; `full` uses 5 and 3 Gauss
 * points (../shared/docs/exact-beam-notes.md: at L/r ~ 2500 full integration locks).
 *
 * Inertia: a material point of the centreline is at r = r0 + A(theta) rho(s), so in the body
 * frame its velocity is A^T r0' + theta' I~rho + rho' and its acceleration
 *     a_b = A^T r0'' + theta'' I~rho - theta'^2 rho + 2 theta' I~rho_t + rho_tt      (I~ = +90 deg)
 * The residual is virtual work, R_j = int mu J_j . (a_b - f_b) ds + dU/dq_j with J_j = d(a_b)/d(q_j'')
 * (A^T e_x, A^T e_y, I~rho, the shape functions), mu = rho A; 4 Gauss points per element
 * integrate it exactly (degree 6). The cross-section's rotary inertia (r^2/L^2 ~ 2e-7 here) is
 * not modelled: a cable has no cross-section.
 */
#include <math.h>
#include <stdlib.h>
#include <string.h>

#include "beam_section.h"
#include "flexmbd_plugin.h"

enum { EXACT_MAX_ELEMENTS = 4096 };
enum { INTEGRATION_REDUCED = 0, INTEGRATION_FULL = 1 };
enum { MASS_POINTS = 4, MAX_POINTS = 5 };

/* Hermite weights of the element's nodal vectors [rho_e, rho'_e, rho_e+1, rho'_e+1] at one
   point (the slope weights carry the element length), and their first and second s-derivatives */
typedef struct Shape {
  double n[4], d1[4], d2[4];
} Shape;

typedef struct Rule {
  int np;
  double w[MAX_POINTS];
  Shape sh[MAX_POINTS];
} Rule;

typedef struct BeamExact {
  double L, rho, A, Izz, Emod;
  int ne, integration;
  int banded; /* `assembly`: K, C, M over the banded pattern (exact_pattern) instead of dense */
  int mixed;  /* the axial strains at the axial points are unknowns of their own (exact_naux) */
  double pos0[2], angle0, vel0[2], omega0;
  /* derived */
  double le, mu, EA, EI;
  int n; /* deformation coordinates 1 + 4 ne */
  Rule mass, axial, bending;
} BeamExact;

static void hermite_shape(double xi, double le, Shape* sh) {
  const double x2 = xi * xi, x3 = x2 * xi;
  const double n[4] = {1.0 - 3.0 * x2 + 2.0 * x3, le * (xi - 2.0 * x2 + x3), 3.0 * x2 - 2.0 * x3, le * (x3 - x2)};
  const double d1[4] = {(6.0 * x2 - 6.0 * xi) / le, 1.0 - 4.0 * xi + 3.0 * x2, (6.0 * xi - 6.0 * x2) / le,
                        3.0 * x2 - 2.0 * xi};
  const double d2[4] = {(12.0 * xi - 6.0) / (le * le), (6.0 * xi - 4.0) / le, (6.0 - 12.0 * xi) / (le * le),
                        (6.0 * xi - 2.0) / le};
  memcpy(sh->n, n, sizeof n);
  memcpy(sh->d1, d1, sizeof d1);
  memcpy(sh->d2, d2, sizeof d2);
}

static void rule_setup(Rule* r, int np, int lobatto, double le) {
  double x[MAX_POINTS];
  r->np = np;
  if (lobatto)
    fmb_gauss_lobatto01(np, x, r->w);
  else
    fmb_gauss_legendre01(np, x, r->w);
  for (int g = 0; g < np; ++g) hermite_shape(x[g], le, &r->sh[g]);
}

static void exact_setup(BeamExact* b) {
  b->le = b->L / b->ne;
  b->mu = b->rho * b->A;
  b->EA = b->Emod * b->A;
  b->EI = b->Emod * b->Izz;
  b->n = 1 + 4 * b->ne;
  rule_setup(&b->mass, MASS_POINTS, 0, b->le);
  if (b->integration == INTEGRATION_FULL) {
    rule_setup(&b->axial, 5, 0, b->le);
    rule_setup(&b->bending, 3, 0, b->le);
  } else {
    rule_setup(&b->axial, 3, 1, b->le);
    rule_setup(&b->bending, 2, 0, b->le);
  }
}

/* ---------------------------------------------------------------------------------------------
 * Element dofs: local l = 2 k + c (k: rho_e, rho'_e, rho_e+1, rho'_e+1; c: x, y). Index in the
 * body's q, or -1 where the root is clamped (only its slope's x component, the stretch a, is free).
 * ------------------------------------------------------------------------------------------- */
static int edof(int e, int l) {
  const int k = l >> 1, c = l & 1, node = e + (k >= 2), slope = k & 1;
  if (node == 0) return (slope && c == 0) ? 3 : -1;
  return 4 + 4 * (node - 1) + 2 * slope + c;
}

/* nodal vectors of element e: with the straight reference added (positions) or without (rates) */
static void element_values(const BeamExact* b, const double* q, int e, int with_reference, double X[8]) {
  for (int l = 0; l < 8; ++l) {
    const int i = edof(e, l);
    X[l] = i >= 0 ? q[i] : 0.0;
  }
  if (with_reference) {
    X[0] += e * b->le;       /* rho_e.x */
    X[2] += 1.0;             /* rho'_e.x */
    X[4] += (e + 1) * b->le; /* rho_e+1.x */
    X[6] += 1.0;
  }
}

static void interp(const double w[4], const double X[8], double out[2]) {
  out[0] = w[0] * X[0] + w[1] * X[2] + w[2] * X[4] + w[3] * X[6];
  out[1] = w[0] * X[1] + w[1] * X[3] + w[2] * X[5] + w[3] * X[7];
}

/* ---------------------------------------------------------------------------------------------
 * Elastic energy of one element, its gradient f = dU/dD and (optionally) Hessian K (8 x 8, column-
 * major), from the nodal displacements D = X - X_ref (X_ref: the straight element, rho = (s, 0),
 * rho' = (1, 0)). The Hermite interpolation reproduces the reference exactly, so rho' = (1, 0) +
 * sum d1_k D_k and rho'' = sum d2_k D_k: the strain comes from displacements, without the round-
 * off of positions near s ~ L. U depends on X only through eps and kappa: a rigid motion of X
 * leaves it unchanged.
 * ------------------------------------------------------------------------------------------- */
static double element_elastic(const BeamExact* b, const double D[8], const double* Naxial, double f[8], double* K) {
  double U = 0.0;
  memset(f, 0, 8 * sizeof(double));
  if (K) memset(K, 0, 64 * sizeof(double));
  /* axial: dU = EA eps t . d(rho'), t = rho'/|rho'|; d2 eps/d rho'^2 = (I - t t^T)/|rho'| */
  for (int g = 0; g < b->axial.np; ++g) {
    const Shape* sh = &b->axial.sh[g];
    double dr[2];
    interp(sh->d1, D, dr);
    const double dx = dr[0], dy = dr[1], a[2] = {1.0 + dx, dy};
    const double len = sqrt(a[0] * a[0] + a[1] * a[1]);
    const double eps = (2.0 * dx + dx * dx + dy * dy) / (1.0 + len);
    const double wl = b->axial.w[g] * b->le, wq = wl * b->EA;
    const double t[2] = {a[0] / len, a[1] / len};
    /* N = EA eps, or the unknown axial force of the mixed form (then K holds N's geometric part
       only: its eps-gradient column is the z coupling, exact_fill) */
    const double N = Naxial ? Naxial[g] : b->EA * eps;
    U += 0.5 * wq * eps * eps;
    for (int l = 0; l < 8; ++l) f[l] += wl * N * t[l & 1] * sh->d1[l >> 1];
    if (K) {
      double H[2][2];
      for (int i = 0; i < 2; ++i)
        for (int j = 0; j < 2; ++j) H[i][j] = (Naxial ? 0.0 : t[i] * t[j]) + N / b->EA * ((i == j) - t[i] * t[j]) / len;
      for (int l2 = 0; l2 < 8; ++l2)
        for (int l1 = 0; l1 < 8; ++l1) K[l2 * 8 + l1] += wq * sh->d1[l1 >> 1] * sh->d1[l2 >> 1] * H[l1 & 1][l2 & 1];
    }
  }
  /* bending: kappa = c/g, c = a x bb = a_x bb_y - a_y bb_x, g = |a|^2 (a = rho', bb = rho'') */
  for (int g = 0; g < b->bending.np; ++g) {
    const Shape* sh = &b->bending.sh[g];
    double a[2], bb[2];
    interp(sh->d1, D, a);
    a[0] += 1.0;
    interp(sh->d2, D, bb);
    const double gg = a[0] * a[0] + a[1] * a[1];
    const double c = a[0] * bb[1] - a[1] * bb[0];
    const double kap = c / gg;
    const double ca[2] = {bb[1], -bb[0]}, cb[2] = {-a[1], a[0]}; /* dc/da, dc/dbb */
    const double ka[2] = {ca[0] / gg - 2.0 * c * a[0] / (gg * gg), ca[1] / gg - 2.0 * c * a[1] / (gg * gg)};
    const double kb[2] = {cb[0] / gg, cb[1] / gg};
    const double wq = b->bending.w[g] * b->le * b->EI;
    double grad[8];
    for (int l = 0; l < 8; ++l) grad[l] = ka[l & 1] * sh->d1[l >> 1] + kb[l & 1] * sh->d2[l >> 1];
    U += 0.5 * wq * kap * kap;
    for (int l = 0; l < 8; ++l) f[l] += wq * kap * grad[l];
    if (K) {
      /* second derivatives of kappa: kaa = -2(ca a^T + a ca^T)/g^2 - 2c I/g^2 + 8c a a^T/g^3,
         kab = [[0, 1], [-1, 0]]/g - 2 a cb^T/g^2, kbb = 0 */
      double kaa[2][2], kab[2][2];
      const double Cab[2][2] = {{0.0, 1.0}, {-1.0, 0.0}};
      const double g2 = gg * gg, g3 = g2 * gg;
      for (int i = 0; i < 2; ++i)
        for (int j = 0; j < 2; ++j) {
          kaa[i][j] = -2.0 * (ca[i] * a[j] + a[i] * ca[j]) / g2 - 2.0 * c * (i == j) / g2 + 8.0 * c * a[i] * a[j] / g3;
          kab[i][j] = Cab[i][j] / gg - 2.0 * a[i] * cb[j] / g2;
        }
      for (int l2 = 0; l2 < 8; ++l2)
        for (int l1 = 0; l1 < 8; ++l1) {
          const int i = l1 & 1, j = l2 & 1, k1 = l1 >> 1, k2 = l2 >> 1;
          const double hess = sh->d1[k1] * sh->d1[k2] * kaa[i][j] + sh->d1[k1] * sh->d2[k2] * kab[i][j] +
                              sh->d2[k1] * sh->d1[k2] * kab[j][i];
          K[l2 * 8 + l1] += wq * (grad[l1] * grad[l2] + kap * hess);
        }
    }
  }
  return U;
}

/* ---------------------------------------------------------------------------------------------
 * Parse.
 * ------------------------------------------------------------------------------------------- */
static const char* const exact_models[] = {"zoac", "foac", "complete", "exact", NULL}; /* as beam.c's */
static const char* const exact_integrations[] = {"reduced", "full", NULL};
static const char* const exact_assemblies[] = {"auto", "dense", "banded", NULL}; /* as beam.c's */
static const char* const exact_axial_forms[] = {"mixed", "displacement", NULL};  /* as beam.c's */
static const char* const exact_kinematics[] = {"cable", "intrinsic", NULL};      /* as beam.c's */
enum { ASSEMBLY_AUTO, ASSEMBLY_DENSE, ASSEMBLY_BANDED };
/* `assembly: auto` is banded from this many elements on. Unlike beam.c's (whose banded form adds
   auxiliary unknowns), this pattern adds nothing: measured (bench/exact_banded.sh, the omega0 = 15
   spin-up 20 s) banded is 1.2x faster at 8 elements, 1.6x at 16, 1.9x at 24, and even at 4 */
enum { BANDED_FROM_ELEMENTS = 8 };

static int exact_parse(fmbParser* p, fmbNode item, void** self) {
  BeamExact* b = calloc(1, sizeof *b);
  if (!b) return fmb_parse_error(p, item, "out of memory");
  int model = 3, err = 0;
  err |= fmb_beam_read_section(p, item, EXACT_MAX_ELEMENTS, &b->L, &b->ne, &b->rho, &b->A, &b->Izz, &b->Emod);
  err |= fmb_get_choice(p, item, "model", FMB_OPTIONAL, exact_models, &model); /* "exact": beam.c chose this table */
  err |= fmb_get_choice(p, item, "integration", FMB_OPTIONAL, exact_integrations, &b->integration);
  int kinematics =
      0; /* "intrinsic" (the default) is bodies/beam_intrinsic.c's (beam.c's variant chose): "cable" here */
  err |= fmb_get_choice(p, item, "kinematics", FMB_OPTIONAL, exact_kinematics, &kinematics);
  int assembly = ASSEMBLY_AUTO;
  err |= fmb_get_choice(p, item, "assembly", FMB_OPTIONAL, exact_assemblies, &assembly);
  b->banded = assembly == ASSEMBLY_BANDED || (assembly == ASSEMBLY_AUTO && b->ne >= BANDED_FROM_ELEMENTS);
  /* the mixed form (exact_naux) with reduced integration, whose axial points are the nodes and
     midpoints; it needs the pattern (its unknowns' rows and columns), so it is banded */
  int displacement_form = 0; /* axial_form: displacement keeps the form before the mixed one, to compare */
  err |= fmb_get_choice(p, item, "axial_form", FMB_OPTIONAL, exact_axial_forms, &displacement_form);
  b->mixed = !displacement_form && b->integration == INTEGRATION_REDUCED && assembly != ASSEMBLY_DENSE;
  if (b->mixed) b->banded = 1;
  err |= fmb_beam_read_frame(p, item, b->pos0, &b->angle0, b->vel0, &b->omega0);
  if (!err && fmb_find_key(p, item, "damping") >= 0)
    err = fmb_parse_error(p, fmb_find_key(p, item, "damping"),
                          "'damping' is not available with model: exact "
                          "(the exact beam is undamped); remove the key");
  if (!err && fmb_find_key(p, item, "quadrature_points") >= 0)
    err = fmb_parse_error(p, fmb_find_key(p, item, "quadrature_points"),
                          "model: exact sets its points with `integration: reduced | full`, not 'quadrature_points'");
  if (err) {
    free(b);
    return err;
  }
  exact_setup(b);
  /* as for the other models (beam.c): parameters that are each valid can still combine into an
     element whose mass or stiffness is not a usable double (length 1e-300: EI/le^3 overflows) */
  if (fmb_beam_degenerate(p, item, b->L, b->ne, b->rho, b->A, b->Izz, b->Emod)) {
    free(b);
    return -1;
  }
  *self = b;
  return 0;
}

static void exact_destroy(void* self) { free(self); }

static int exact_ncoord(const void* self) { return 3 + ((const BeamExact*)self)->n; }

static void exact_initial(const void* self, double* q0, double* v0) {
  const BeamExact* b = self;
  fmb_beam_frame_initial(3 + b->n, b->pos0, b->angle0, b->vel0, b->omega0, q0, v0);
}

/* ---------------------------------------------------------------------------------------------
 * Residual and Jacobian. At each mass point the coordinates that move it are the frame's x, y,
 * theta and the element's (up to 8) dofs; J_j is the body-frame vector d(a_b)/d(q_j'').
 * ------------------------------------------------------------------------------------------- */
/* The banded layout (exact_pattern's pair order): frame columns j < 3 over all nc rows; frame rows
   i < 3 over the nc - 3 deformation columns; then element blocks, element 0 over its 5 free dofs
   (the root stretch and node 1), each later element over its 8, column-major in the element's dof
   order (li, lj: the position of i, j among the element's free dofs). */
static long exact_npair(const BeamExact* b) {
  const long nc = 3 + b->n;
  return 3 * nc + 3 * (nc - 3) + 25 + 64L * (b->ne - 1);
}

/* the mixed form's pairs after exact_npair's, per element e and axial point g: the point's Rz row
   over the element's nd free dofs, the dofs' rows over its z column, and its diagonal */
static size_t mixed_at(const BeamExact* b, int e, int g) {
  const size_t per_e0 = 3 * (2 * 5 + 1), per_e = 3 * (2 * 8 + 1);
  const int nd = e == 0 ? 5 : 8;
  return (size_t)exact_npair(b) + (e == 0 ? 0 : per_e0 + per_e * (size_t)(e - 1)) + (size_t)g * (size_t)(2 * nd + 1);
}

static long exact_npair_all(const BeamExact* b) { return b->mixed ? (long)mixed_at(b, b->ne, 0) : exact_npair(b); }

static size_t jac_at(const BeamExact* b, int banded, int e, int i, int li, int j, int lj) {
  const size_t nc = (size_t)(3 + b->n);
  if (!banded) return (size_t)j * nc + (size_t)i;
  if (j < 3) return (size_t)j * nc + (size_t)i;
  if (i < 3) return 3 * nc + (size_t)i * (nc - 3) + (size_t)(j - 3);
  const size_t base = 3 * nc + 3 * (nc - 3) + (e == 0 ? 0 : 25 + 64 * (size_t)(e - 1));
  const int nd = e == 0 ? 5 : 8;
  return base + (size_t)lj * (size_t)nd + (size_t)li;
}

typedef struct PointFrame {
  int ncol, col[11];
  double J[11][2];
  double rho[2], rho_t[2], F[2]; /* position, rate, F = a_b - f_b */
} PointFrame;

static void point_frame(const Shape* sh, int e, const double X[8], const double Xd[8], const double Xdd[8], double c,
                        double s, const double G0[2], double om, double al, PointFrame* pf) {
  double rho[2], rt[2], rtt[2];
  interp(sh->n, X, rho);
  interp(sh->n, Xd, rt);
  interp(sh->n, Xdd, rtt);
  memcpy(pf->rho, rho, sizeof rho);
  memcpy(pf->rho_t, rt, sizeof rt);
  /* a_b - f_b = G0 + theta'' I~rho - theta'^2 rho + 2 theta' I~rho_t + rho_tt, G0 = A^T(r0'' - g) */
  pf->F[0] = G0[0] - al * rho[1] - om * om * rho[0] - 2.0 * om * rt[1] + rtt[0];
  pf->F[1] = G0[1] + al * rho[0] - om * om * rho[1] + 2.0 * om * rt[0] + rtt[1];
  pf->col[0] = 0, pf->J[0][0] = c, pf->J[0][1] = -s; /* A^T e_x */
  pf->col[1] = 1, pf->J[1][0] = s, pf->J[1][1] = c;  /* A^T e_y */
  pf->col[2] = 2, pf->J[2][0] = -rho[1], pf->J[2][1] = rho[0];
  int nc = 3;
  for (int l = 0; l < 8; ++l) {
    const int i = edof(e, l);
    if (i < 0) continue;
    pf->col[nc] = i;
    pf->J[nc][l & 1] = sh->n[l >> 1];
    pf->J[nc][1 - (l & 1)] = 0.0;
    ++nc;
  }
  pf->ncol = nc;
}

/* element e's nodal displacements D, positions X, rates Xd and accelerations Xdd */
static void element_state(const BeamExact* b, const double* q, const double* v, const double* a, int e, double D[8],
                          double X[8], double Xd[8], double Xdd[8]) {
  element_values(b, q, e, 0, D);
  element_values(b, q, e, 1, X);
  element_values(b, v, e, 0, Xd);
  element_values(b, a, e, 0, Xdd);
}

/* the axial point g of element e's aux unknown in the mixed form: the nodes' forces first (the
   Lobatto end points, shared by the two elements at a node), then each element's midpoint */
static int axial_aux(const BeamExact* b, int e, int g) { return g == 0 ? e : g == 2 ? e + 1 : b->ne + 1 + e; }

/* eps at axial point g of an element with displacements D, and d eps / dD (the Hermite slope
   weights along t = rho'/|rho'|) */
static double axial_strain(const BeamExact* b, int g, const double D[8], double deps[8]) {
  const Shape* sh = &b->axial.sh[g];
  double dr[2];
  interp(sh->d1, D, dr);
  const double dx = dr[0], dy = dr[1], a[2] = {1.0 + dx, dy};
  const double len = sqrt(a[0] * a[0] + a[1] * a[1]);
  if (deps)
    for (int l = 0; l < 8; ++l) deps[l] = a[l & 1] / len * sh->d1[l >> 1];
  return (2.0 * dx + dx * dx + dy * dy) / (1.0 + len);
}

/* R (and, with z, the mixed form's Rz: per axial point, its weight times eps(q) - z, z the axial
   point's strain as an unknown of its own, N = EA z; exact_naux) */
static int exact_eval(const BeamExact* b, const fmbEnv* env, const double* q, const double* v, const double* a,
                      const double* z, double* R, double* Rz) {
  double c, s, G0[2];
  fmb_beam_frame_load(env, q, a, &c, &s, G0);
  memset(R, 0, sizeof(double) * (size_t)(3 + b->n));
  if (Rz) memset(Rz, 0, sizeof(double) * (size_t)(2 * b->ne + 1));
  for (int e = 0; e < b->ne; ++e) {
    double X[8], D[8], Xd[8], Xdd[8], f[8], Ne[3];
    element_state(b, q, v, a, e, D, X, Xd, Xdd);
    for (int g = 0; g < b->mass.np; ++g) {
      PointFrame pf;
      point_frame(&b->mass.sh[g], e, X, Xd, Xdd, c, s, G0, v[2], a[2], &pf);
      const double w = b->mu * b->mass.w[g] * b->le;
      for (int k = 0; k < pf.ncol; ++k) R[pf.col[k]] += w * (pf.J[k][0] * pf.F[0] + pf.J[k][1] * pf.F[1]);
    }
    if (z)
      for (int g = 0; g < 3; ++g) {
        Ne[g] = b->EA * z[axial_aux(b, e, g)];
        Rz[axial_aux(b, e, g)] += b->axial.w[g] * b->le * (axial_strain(b, g, D, NULL) - z[axial_aux(b, e, g)]);
      }
    element_elastic(b, D, z ? Ne : NULL, f, NULL);
    for (int l = 0; l < 8; ++l) {
      const int i = edof(e, l);
      if (i >= 0) R[i] += f[l];
    }
  }
  for (int i = 0; i < 3 + b->n; ++i)
    if (!isfinite(R[i])) return 1; /* a wild trial step (|rho'| -> 0): IDA cuts the step */
  return 0;
}

static int exact_residual(const void* self, const fmbEnv* env, const double* q, const double* v, const double* a,
                          double* R, double* work) {
  (void)work;
  return exact_eval(self, env, q, v, a, NULL, R, NULL);
}

static int exact_naux(const void* self) {
  const BeamExact* b = self;
  return b->mixed ? 2 * b->ne + 1 : 0;
}

static int exact_residual_aux(const void* self, const fmbEnv* env, const double* q, const double* v, const double* a,
                              const double* z, double* R, double* Rz, double* work) {
  (void)work;
  return exact_eval(self, env, q, v, a, z, R, Rz);
}

/* fmbBodyType.aux_iterated: the axial strains are the mixed form's own unknowns */
static int exact_aux_iterated(const void* self) {
  (void)self;
  return 1;
}

/* the strains z = eps(q) that make Rz = 0 */
static int exact_aux_initial(const void* self, const fmbEnv* env, const double* q, const double* v, const double* a,
                             double* z, double* work) {
  (void)env, (void)v, (void)a, (void)work;
  const BeamExact* b = self;
  for (int e = 0; e < b->ne; ++e) {
    double D[8];
    element_values(b, q, e, 0, D);
    for (int g = 0; g < 3; ++g) z[axial_aux(b, e, g)] = axial_strain(b, g, D, NULL);
  }
  return 0;
}

/* K = dR/dq, C = dR/dv, M = dR/da (dense, column-major). Per mass point, with F = a_b - f_b:
     M_ij = w J_i.J_j
     C_ij = w J_i.dF/dv_j,   dF/dtheta' = -2 theta' rho + 2 I~rho_t,   dF/dp_j' = 2 theta' I~J_j
     K_ij = w (dJ_i/dq_j . F + J_i . dF/dq_j),  dJ_{x,y}/dtheta = -I~J_{x,y},  dJ_theta/dp_j = I~J_j,
            dF/dtheta = -I~G0,  dF/dp_j = (theta'' I~ - theta'^2) J_j
   plus the elastic Hessian of each element in the p block.
   One assembly serves both layouts: entry (i, j) of element e's contribution goes to jac_at's
   slot, the dense column-major nc x nc block or the banded pattern's pair (exact_pattern). */
static int exact_fill(const BeamExact* b, int banded, const fmbEnv* env, const double* q, const double* v,
                      const double* a, const double* z, double* K, double* C, double* M) {
  const size_t nc = (size_t)(3 + b->n), nv = banded ? (size_t)exact_npair_all(b) : nc * nc;
  double c, s, G0[2];
  fmb_beam_frame_load(env, q, a, &c, &s, G0);
  const double om = v[2], al = a[2];
  if (K) memset(K, 0, sizeof(double) * nv);
  if (C) memset(C, 0, sizeof(double) * nv);
  if (M) memset(M, 0, sizeof(double) * nv);
  for (int e = 0; e < b->ne; ++e) {
    double X[8], D[8], Xd[8], Xdd[8], f[8], Ke[64];
    element_state(b, q, v, a, e, D, X, Xd, Xdd);
    for (int g = 0; g < b->mass.np; ++g) {
      PointFrame pf;
      point_frame(&b->mass.sh[g], e, X, Xd, Xdd, c, s, G0, om, al, &pf);
      const double w = b->mu * b->mass.w[g] * b->le;
      const double IG0[2] = {-G0[1], G0[0]};
      for (int jj = 0; jj < pf.ncol; ++jj) {
        const int j = pf.col[jj];
        const double* Jj = pf.J[jj];
        const double IJj[2] = {-Jj[1], Jj[0]};
        /* dF/dv_j and dF/dq_j */
        double dFv[2] = {0.0, 0.0}, dFq[2] = {0.0, 0.0};
        if (j == 2) {
          dFv[0] = -2.0 * om * pf.rho[0] - 2.0 * pf.rho_t[1];
          dFv[1] = -2.0 * om * pf.rho[1] + 2.0 * pf.rho_t[0];
          dFq[0] = -IG0[0];
          dFq[1] = -IG0[1];
        } else if (j >= 3) {
          dFv[0] = 2.0 * om * IJj[0];
          dFv[1] = 2.0 * om * IJj[1];
          dFq[0] = al * IJj[0] - om * om * Jj[0];
          dFq[1] = al * IJj[1] - om * om * Jj[1];
        }
        for (int ii = 0; ii < pf.ncol; ++ii) {
          const int i = pf.col[ii];
          const double* Ji = pf.J[ii];
          const size_t at = jac_at(b, banded, e, i, ii - 3, j, jj - 3);
          if (M) M[at] += w * (Ji[0] * Jj[0] + Ji[1] * Jj[1]);
          if (C) C[at] += w * (Ji[0] * dFv[0] + Ji[1] * dFv[1]);
          if (K) {
            double dJ[2] = {0.0, 0.0};
            if (i <= 1 && j == 2) dJ[0] = Ji[1], dJ[1] = -Ji[0]; /* -I~J_i */
            if (i == 2 && j >= 3) dJ[0] = IJj[0], dJ[1] = IJj[1];
            K[at] += w * (dJ[0] * pf.F[0] + dJ[1] * pf.F[1] + Ji[0] * dFq[0] + Ji[1] * dFq[1]);
          }
        }
      }
    }
    if (K) {
      double Ne[3];
      for (int g = 0; z && g < 3; ++g) Ne[g] = b->EA * z[axial_aux(b, e, g)];
      element_elastic(b, D, z ? Ne : NULL, f, Ke);
      /* the mixed form's z coupling: dR/dz = EA w le d eps/dq, dRz/dq = w le d eps/dq, dRz/dz = -w le */
      for (int g = 0; z && g < 3; ++g) {
        double deps[8];
        axial_strain(b, g, D, deps);
        const double wl = b->axial.w[g] * b->le;
        const size_t at = mixed_at(b, e, g);
        const int nd = e == 0 ? 5 : 8;
        for (int l = 0, li = 0; l < 8; ++l) {
          if (edof(e, l) < 0) continue;
          K[at + (size_t)li] += wl * deps[l];
          K[at + (size_t)(nd + li)] += wl * b->EA * deps[l];
          ++li;
        }
        K[at + (size_t)(2 * nd)] += -wl;
      }
      for (int l2 = 0, lj = 0; l2 < 8; ++l2) {
        const int j = edof(e, l2);
        if (j < 0) continue;
        for (int l1 = 0, li = 0; l1 < 8; ++l1) {
          const int i = edof(e, l1);
          if (i >= 0) K[jac_at(b, banded, e, i, li++, j, lj)] += Ke[l2 * 8 + l1];
        }
        ++lj;
      }
    }
  }
  return 0;
}

static int exact_jacobian(const void* self, const fmbEnv* env, const double* q, const double* v, const double* a,
                          double* K, double* C, double* M, double* work) {
  (void)work;
  return exact_fill(self, 0, env, q, v, a, NULL, K, C, M);
}

/* fmbBodyType.pattern_jacobian: the same K, C, M, one value per pair of exact_pattern */
static int exact_pattern_jacobian(const void* self, const fmbEnv* env, const double* q, const double* v,
                                  const double* a, const double* z, double* K, double* C, double* M, double* work) {
  (void)work;
  const BeamExact* b = self;
  return exact_fill(b, 1, env, q, v, a, b->mixed ? z : NULL, K, C, M); /* the engine checks the values are finite */
}

/* fmbBodyType.pattern (banded assembly only): the frame's columns x, y, theta over every row, its
   rows over every other column (the frame couples to every point), then per element e the block
   of its own dofs (node 0's stretch a and node 1's four for e = 0, nodes e and e+1's eight
   otherwise: neighbouring blocks overlap at their shared node, which the engine sums). The
   order is jac_at's. Memory and work are O(ne), against O(ne^2) for the dense block. */
static long exact_pattern(const void* self, int* rows, int* cols) {
  const BeamExact* b = self;
  if (!b->banded) return -1;
  const int nc = 3 + b->n;
  long k = 0;
  if (!rows) return exact_npair_all(b);
  for (int j = 0; j < 3; ++j)
    for (int i = 0; i < nc; ++i) rows[k] = i, cols[k++] = j;
  for (int i = 0; i < 3; ++i)
    for (int j = 3; j < nc; ++j) rows[k] = i, cols[k++] = j;
  for (int e = 0; e < b->ne; ++e) {
    int dof[8], nd = 0;
    for (int l = 0; l < 8; ++l)
      if (edof(e, l) >= 0) dof[nd++] = edof(e, l);
    for (int lj = 0; lj < nd; ++lj)
      for (int li = 0; li < nd; ++li) rows[k] = dof[li], cols[k++] = dof[lj];
  }
  for (int e = 0; b->mixed && e < b->ne; ++e) { /* mixed_at's order */
    int dof[8], nd = 0;
    for (int l = 0; l < 8; ++l)
      if (edof(e, l) >= 0) dof[nd++] = edof(e, l);
    for (int g = 0; g < 3; ++g) {
      const int zi = nc + axial_aux(b, e, g);
      for (int li = 0; li < nd; ++li) rows[k] = zi, cols[k++] = dof[li];
      for (int li = 0; li < nd; ++li) rows[k] = dof[li], cols[k++] = zi;
      rows[k] = zi, cols[k++] = zi;
    }
  }
  return k;
}

/* ---------------------------------------------------------------------------------------------
 * Where a point of the reference configuration is: local (x, y) = arc length x along the
 * centreline, offset y along the deformed normal n = I~rho'/|rho'|.
 * ------------------------------------------------------------------------------------------- */
static void locate(const BeamExact* b, double x, int* e, double* xi) { fmb_beam_locate(b->le, b->ne, x, e, xi); }

static int exact_marker(const void* self, const double* q, const double local[2], double pos[2], double* angle,
                        double* dpos_dq, double* dangle_dq, double* work) {
  (void)work;
  const BeamExact* b = self;
  const int nc = 3 + b->n;
  const double x = local[0], y = local[1];
  if (x > b->L * (1.0 + 1e-12)) return -1;
  const double c = cos(q[2]), s = sin(q[2]);
  if (dpos_dq) memset(dpos_dq, 0, sizeof(double) * 2 * (size_t)nc);
  if (dangle_dq) memset(dangle_dq, 0, sizeof(double) * (size_t)nc);
  double pb[2] = {x, y}, phi = 0.0;
  int e = 0;
  Shape sh;
  double X[8], t[2] = {1.0, 0.0}, len = 1.0, rp[2] = {1.0, 0.0};
  const int onbeam = x > 0.0; /* points at x <= 0 move rigidly with the frame (the root is clamped) */
  if (onbeam) {
    double xi, rho[2];
    locate(b, x, &e, &xi);
    hermite_shape(xi, b->le, &sh);
    element_values(b, q, e, 1, X);
    interp(sh.n, X, rho);
    interp(sh.d1, X, rp);
    len = sqrt(rp[0] * rp[0] + rp[1] * rp[1]);
    t[0] = rp[0] / len;
    t[1] = rp[1] / len;
    pb[0] = rho[0] - y * t[1];
    pb[1] = rho[1] + y * t[0];
    phi = atan2(rp[1], rp[0]);
  }
  fmb_beam_frame_marker(nc, q, c, s, pb, phi, pos, angle, dpos_dq, dangle_dq);
  if (!onbeam) return 0;
  for (int l = 0; l < 8; ++l) {
    const int i = edof(e, l);
    if (i < 0) continue;
    const int k = l >> 1, comp = l & 1;
    /* d rho'/dq_i = d1_k e_comp; d n/d rho' = I~ (I - t t^T)/|rho'|; d phi/d rho' = I~rho'/|rho'|^2 */
    double da[2] = {0.0, 0.0};
    da[comp] = sh.d1[k];
    const double tda = t[0] * da[0] + t[1] * da[1];
    const double pdn[2] = {(da[0] - t[0] * tda) / len, (da[1] - t[1] * tda) / len}; /* (I - t t^T) da / |rho'| */
    double du[2] = {-y * pdn[1], y * pdn[0]};
    du[comp] += sh.n[k];
    if (dpos_dq) {
      dpos_dq[i] += c * du[0] - s * du[1];
      dpos_dq[nc + i] += s * du[0] + c * du[1];
    }
    if (dangle_dq) dangle_dq[i] += (-rp[1] * da[0] + rp[0] * da[1]) / (len * len);
  }
  return 0;
}

/* ---------------------------------------------------------------------------------------------
 * Energy and outputs.
 * ------------------------------------------------------------------------------------------- */
/* T, U_e, U_g and p_theta = dT/dtheta' (angular momentum about the frame origin) in one pass */
static void exact_integrals(const BeamExact* b, const fmbEnv* env, const double* q, const double* v, fmbEnergy* en,
                            double* ptheta) {
  const double c = cos(q[2]), s = sin(q[2]), om = v[2];
  const double v0[2] = {c * v[0] + s * v[1], -s * v[0] + c * v[1]};
  double T = 0.0, Ue = 0.0, pth = 0.0, mrho[2] = {0.0, 0.0};
  for (int e = 0; e < b->ne; ++e) {
    double X[8], D[8], Xd[8], f[8];
    element_values(b, q, e, 0, D);
    element_values(b, q, e, 1, X);
    element_values(b, v, e, 0, Xd);
    for (int g = 0; g < b->mass.np; ++g) {
      double rho[2], rt[2];
      interp(b->mass.sh[g].n, X, rho);
      interp(b->mass.sh[g].n, Xd, rt);
      const double w = b->mu * b->mass.w[g] * b->le;
      const double vb[2] = {v0[0] - om * rho[1] + rt[0], v0[1] + om * rho[0] + rt[1]};
      T += 0.5 * w * (vb[0] * vb[0] + vb[1] * vb[1]);
      pth += w * (-rho[1] * vb[0] + rho[0] * vb[1]);
      mrho[0] += w * rho[0];
      mrho[1] += w * rho[1];
    }
    Ue += element_elastic(b, D, NULL, f, NULL);
  }
  en->kinetic = T;
  en->strain = Ue;
  en->gravity = fmb_beam_gravity_potential(env, b->mu * b->L, q, c, s, mrho);
  en->spring = 0.0;
  if (ptheta) *ptheta = pth;
}

static void exact_energy(const void* self, const fmbEnv* env, const double* q, const double* v, fmbEnergy* en,
                         double* work) {
  (void)work;
  exact_integrals(self, env, q, v, en, NULL);
}

/* the same output names and meanings as bodies/beam.c: tip_u/tip_v = the tip's axial and
   transverse displacement in the frame (the complete model's u(L) and w2(L)); the ids are
   beam_section.h's FMB_BEAM_*, one list for all four models */
static int exact_output_lookup(const void* self, const char* quantity) {
  return fmb_beam_output_lookup(((const BeamExact*)self)->ne, quantity);
}

static int exact_output(const void* self, int id, const double* q, const double* v, double* value, double* work) {
  const BeamExact* b = self;
  if (id == FMB_BEAM_ANG_MOMENTUM) {
    fmbEnergy en;
    exact_integrals(b, NULL, q, v, &en, value);
    return 0;
  }
  if (id == FMB_BEAM_TIP_ANGLE) {
    const double tip[2] = {b->L, 0.0};
    double pos[2], angle;
    if (exact_marker(b, q, tip, pos, &angle, NULL, NULL, work)) return -1;
    *value = angle - q[2];
    return 0;
  }
  int node, comp;
  if (fmb_beam_output_node(b->ne, id, &node, &comp)) return -1;
  /* a node's displacement and rate are coordinates (the root node is fixed in the frame) */
  const int i = 4 + 4 * (node - 1);
  const double u[2] = {node ? q[i] : 0.0, node ? q[i + 1] : 0.0};
  const double ud[2] = {node ? v[i] : 0.0, node ? v[i + 1] : 0.0};
  const double rho[2] = {node * b->le + u[0], u[1]};
  *value = fmb_beam_node_value(comp, q, u, ud, rho);
  return 0;
}

static void exact_describe(const void* self, FILE* f) {
  const BeamExact* b = self;
  fprintf(
      f,
      "exact model (geometrically exact cable in the floating frame), %d elements, %s integration (%s), %s assembly; "
      "no range limit (its accuracy is the mesh's and the tolerance's, docs/models.md)\n",
      b->ne, b->integration == INTEGRATION_FULL ? "full" : "reduced",
      b->integration == INTEGRATION_FULL ? "axial at 5, bending at 3 Gauss points"
                                         : "axial at 3 Lobatto, bending at 2 Gauss points",
      b->banded ? "banded" : "dense");
}

/* as for the other beam models: undamped axial modes near 5e5 rad/s */
static int exact_max_bdf_order(const void* self) {
  (void)self;
  return 2;
}

/* velocities in the error test cost 12x the steps in the prototype (exact-beam-notes.md) */
static int exact_velocity_error_test(const void* self) {
  (void)self;
  return 0;
}

/* its tangent stiffness turns with the centreline (fmbBodyType.reuse_blocks) */
static int exact_reuse_blocks(const void* self) {
  (void)self;
  return 0;
}

/* fmbBodyType.length_scale: a unit of the frame angle, the root stretch or a slope moves the
   centreline by up to L metres, a unit of x, y or a nodal displacement by one metre. So one atol
   in metres holds the tip to the same accuracy whatever L is (docs/models.md, "Tolerances"). */
static void exact_length_scale(const void* self, double* metres_per_unit) {
  const BeamExact* b = self;
  metres_per_unit[0] = metres_per_unit[1] = 1.0;
  metres_per_unit[2] = metres_per_unit[3] = b->L;
  for (int i = 0; i < b->ne; ++i) {
    double* nd = metres_per_unit + 4 + 4 * i;
    nd[0] = nd[1] = 1.0;
    nd[2] = nd[3] = b->L;
  }
}

static const char* exact_invalid_state(const void* self, const double* q, const double* v) {
  (void)v;
  const BeamExact* b = self;
  for (int i = 0; i < b->ne; ++i) {
    const double* nd = q + 4 + 4 * i;
    if (!(fabs(nd[0]) <= 2.0 * b->L && fabs(nd[1]) <= 2.0 * b->L && fabs(nd[2]) <= 10.0 && fabs(nd[3]) <= 10.0))
      return "a node moved more than twice the beam's length or its slope changed tenfold: the solution is diverging "
             "(check the loads and parameters)";
  }
  return NULL;
}

/* the deformed centreline for `BODY.shape` and the VTK polyline, as the other models draw it */
static int exact_centreline(const void* self, int n, double* local) {
  const BeamExact* b = self;
  return fmb_beam_centreline(b->L, b->ne, n, local);
}

/* what `flexmbd conform` needs to check this table on its own (tests/exact/test_exact_conform.c:
   beam.c's table, which the registry holds, declares the keys of type beam for users) */
static const fmbParam exact_params[] = {
    FMB_BEAM_SECTION_PARAMS(EXACT_MAX_ELEMENTS),
    {.key = "model", .kind = FMB_PARAM_CHOICE, .fallback = "exact", .choices = exact_models, .doc = "exact here"},
    {.key = "integration",
     .kind = FMB_PARAM_CHOICE,
     .fallback = "reduced",
     .choices = exact_integrations,
     .doc = "reduced: axial at 3 Lobatto, bending at 2 Gauss points; full: 5 and 3 Gauss points"},
    {.key = "assembly",
     .kind = FMB_PARAM_CHOICE,
     .fallback = "auto",
     .choices = exact_assemblies,
     .doc = "body Jacobian layout: banded (O(n); auto: with the mixed form's axial strains, docs/models.md) or "
            "dense (the displacement form)"},
    {.key = "axial_form",
     .kind = FMB_PARAM_CHOICE,
     .fallback = "mixed",
     .choices = exact_axial_forms,
     .doc = "mixed: the axial strains at the axial points are unknowns Newton iterates on (integration: reduced, "
            "assembly not dense); displacement: the form before it, to compare (docs/models.md, \"Newton\")"},
    {.key = "kinematics",
     .kind = FMB_PARAM_CHOICE,
     .fallback = "cable",
     .choices = exact_kinematics,
     .doc = "cable here, written out: nodal positions and slopes (model: exact's default is intrinsic, "
            "bodies/beam_intrinsic.c)"},
    FMB_BEAM_FRAME_PARAMS,
    /* keys of type beam that this model refuses, with the reason (so they are looked up) */
    {.key = "damping", .kind = FMB_PARAM_NUMBER, .flags = FMB_NONNEGATIVE, .unit = "s", .doc = "refused: undamped"},
    {.key = "quadrature_points",
     .kind = FMB_PARAM_INT,
     .unit = "1",
     .lo = 1,
     .hi = FMB_GAUSS_MAX,
     .doc = "refused: see integration"},
    {.key = NULL},
};

const fmbBodyType fmb_body_beam_exact = {
    .name = "beam",
    .abi = FMB_ABI_VERSION,
    .parse = exact_parse,
    .destroy = exact_destroy,
    .ncoord = exact_ncoord,
    .initial = exact_initial,
    .residual = exact_residual,
    .marker = exact_marker,
    .jacobian = exact_jacobian,
    .energy = exact_energy,
    .output_names = fmb_beam_output_names,
    .output_units = fmb_beam_output_units,
    .output_lookup = exact_output_lookup,
    .output = exact_output,
    .describe = exact_describe,
    .max_bdf_order = exact_max_bdf_order,
    .velocity_error_test = exact_velocity_error_test,
    .invalid_state = exact_invalid_state,
    .reuse_blocks = exact_reuse_blocks,
    .pattern = exact_pattern,
    .pattern_jacobian = exact_pattern_jacobian,
    .naux = exact_naux,
    .residual_aux = exact_residual_aux,
    .aux_initial = exact_aux_initial,
    .aux_iterated = exact_aux_iterated,
    .length_scale = exact_length_scale,
    .centreline = exact_centreline,
    .params = exact_params,
    .example = "length: 1\nelements: 2\ndensity: 1000\narea: 1e-3\nsecond_moment: 1e-7\nyoungs_modulus: 1e6\n"
               "model: exact\nkinematics: cable\nangular_velocity: 3\nvelocity: [0.2, 0.5]\n",
};
