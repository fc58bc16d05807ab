/*
 * beam.c — planar flexible beam in a floating frame: the complete geometric nonlinear model of
 * Liu, Hong & Liu (2009), with the FOAC and ZOAC approximations beside it.
 *
 * Coordinates q = [x, y, theta, p], p = [u_i, v_i, v'_i] for nodes i = 1..ne (node 0, the root,
 * is clamped to the frame). Axial w1 linear, transverse w2 cubic Hermite per element. The
 * coupling deformation w_c(x) = -1/2 int_0^x (w2')^2 enters the axial displacement.
 *
 * The residual R = M(q) a - Q(q, v) is evaluated as virtual work per quadrature point without
 * forming M (docs/beam.md, formulation note §4-5). Per point, in the body frame, the velocity is
 * J q' with J = J_R + J_D + J_C (rigid, linear deformation, coupling); the three models differ
 * only in which products of the parts they keep, so each point contributes
 *     J_R^T F_R + J_D^T F_D + J_C^T F_C
 * with three force vectors (per model, see point_forces). J_C's p-columns are -e1 h^T with the
 * dense h(x) = H(x) p; its products are accumulated with prefix sums (scalars h^T(.)) and tail
 * sums (the vector sum over points of c h), so a residual costs O(ne). Every integrand is a
 * polynomial in the element coordinate, so the residual integrates each element exactly from
 * coefficient vectors and moments (element_terms); the Jacobian differentiates the same sums at
 * the Gauss points (point_terms, element_derivs), exact for the same degrees.
 *
 * Those sums couple every element to all others, so the Jacobian of `residual` is dense. The
 * banded assembly (`assembly: banded`, the default from 64 elements) carries them as auxiliary
 * unknowns z with one recursion per element (beam_residual_aux, beam_pattern): the engine then
 * differentiates and factorizes a banded system, O(ne) per step in time and memory.
 */
#include <math.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>

#include "beam_section.h"
#include "flexmbd_plugin.h"

enum { BEAM_ZOAC = 0, BEAM_FOAC = 1, BEAM_COMPLETE = 2 };
enum { MAX_ELEMENTS = 4096 };

typedef struct Beam {
  /* parameters */
  double L, rho, A, Izz, Emod, beta;
  int ne, ng, model;
  int banded; /* the coupling's long-range sums carried as auxiliary unknowns (beam_residual_aux) */
  double pos0[2], angle0, vel0[2], omega0;
  /* derived */
  double le, r; /* element length, cross-section point offset sqrt(I/A) */
  int n;        /* 3 * ne deformation coordinates */
  /* quadrature points along an element; shape and slope functions there */
  double xg[FMB_GAUSS_MAX], wg[FMB_GAUSS_MAX];
  double ns_out[FMB_GAUSS_MAX][4], nd_out[FMB_GAUSS_MAX][4];
  /* The coupling integrals int_0^x of slope products, in closed form (see slope_poly): the
     weights of xi^k over [0, xi_g] (pw_out) and over a whole element (pw_full), and the weights
     G[j][i] that give h_j = int N2j' w2' from the slope coefficients */
  double nslope[4][3];
  double pw_out[FMB_GAUSS_MAX][5], pw_full[5];
  double G_full[4][3];
  /* for the Jacobian: G at each point (h_j = G[j].c there) and the slope-product matrices
     H[j][l] = int_0^x N2j' N2l' (dh_j/dd_l) at each point and over a whole element */
  double G_out[FMB_GAUSS_MAX][4][3], H_out[FMB_GAUSS_MAX][4][4], H_full[4][4];
  double kb[4][4], ka; /* element bending stiffness, axial stiffness EA/le */
  /* for the residual's exact integration (element_terms): the coefficients of xi^0..3 in the
     shape functions N2j (ncubic) and the moments mu_k = int_0^1 xi^k (k = 0..11) */
  double ncubic[4][4], mu[12];
} Beam;

/* a kernel inlined into one copy per model (element_terms, element_derivs), where the model is a
   constant */
#if defined(__GNUC__)
#define FMB_BEAM_SPECIALIZED __attribute__((always_inline))
#else
#define FMB_BEAM_SPECIALIZED
#endif

/* f(b, MODEL, ...) with b's model a constant: one inlined copy of f per model */
#define PER_MODEL(f, b, ...)                               \
  switch ((b)->model) {                                    \
    case BEAM_ZOAC: f((b), BEAM_ZOAC, __VA_ARGS__); break; \
    case BEAM_FOAC: f((b), BEAM_FOAC, __VA_ARGS__); break; \
    default: f((b), BEAM_COMPLETE, __VA_ARGS__); break;    \
  }

/* ---------------------------------------------------------------------------------------------
 * Shape functions on one element, xi in [0, 1], element length le.
 * ------------------------------------------------------------------------------------------- */
/* the element's shape functions, poly_mul and int_weights are beam_section.h's (shared with beam_modal.c) */
#define hermite fmb_beam_hermite
#define poly_mul fmb_beam_poly_mul
#define int_weights fmb_beam_int_weights

/* element dofs of a deformation vector p: axial ends a[2], transverse d[4] (root node = 0) */
static void gather(const double* p, int e, double a[2], double d[4]) {
  if (e == 0) {
    a[0] = d[0] = d[1] = 0.0;
  } else {
    const double* nl = p + 3 * (e - 1);
    a[0] = nl[0];
    d[0] = nl[1];
    d[1] = nl[2];
  }
  const double* nr = p + 3 * e;
  a[1] = nr[0];
  d[2] = nr[1];
  d[3] = nr[2];
}

/* index in p of the transverse element dof j (0..3) of element e, or -1 at the clamped root */
static int tdof(int e, int j) {
  int node = e + (j >= 2);
  if (node == 0) return -1;
  return 3 * (node - 1) + 1 + (j & 1);
}

static int adof(int e, int j) {
  int node = e + j;
  return node == 0 ? -1 : 3 * (node - 1);
}

static double dot4(const double* a, const double* b) { return a[0] * b[0] + a[1] * b[1] + a[2] * b[2] + a[3] * b[3]; }
static double dot2(const double* a, const double* b) { return a[0] * b[0] + a[1] * b[1]; }
static double dot3(const double* a, const double* b) { return a[0] * b[0] + a[1] * b[1] + a[2] * b[2]; }
static double dot5(const double* a, const double* b) {
  return a[0] * b[0] + a[1] * b[1] + a[2] * b[2] + a[3] * b[3] + a[4] * b[4];
}

/* ---------------------------------------------------------------------------------------------
 * The coupling deformation's integrals in closed form. On an element the slope w2' = N2' d is a
 * quadratic in xi, w2'(xi) = c0 + c1 xi + c2 xi^2 (c = slope_poly(d)), so a product of two slopes
 * is a quartic (poly_mul) and its integral over [0, xi] in x is the dot product of its five
 * coefficients with pw_k = le xi^(k+1) / (k+1) (int_weights): exact, no nested quadrature. The
 * same holds for h_j = int_0^x N2j' w2', whose weights G[j][i] (h_weights) act on c.
 * ------------------------------------------------------------------------------------------- */
static void slope_poly(const Beam* b, const double d[4], double c[3]) {
  for (int i = 0; i < 3; ++i)
    c[i] = b->nslope[0][i] * d[0] + b->nslope[1][i] * d[1] + b->nslope[2][i] * d[2] + b->nslope[3][i] * d[3];
}

static void h_weights(const Beam* b, const double pw[5], double G[4][3]) {
  for (int j = 0; j < 4; ++j)
    for (int i = 0; i < 3; ++i)
      G[j][i] = b->nslope[j][0] * pw[i] + b->nslope[j][1] * pw[i + 1] + b->nslope[j][2] * pw[i + 2];
}

/* an element's slope polynomials of p and pd (cp, cv) and the quartics w2'^2 (pp) and w2' w2d'
   (pv), whose integrals give w_c = -1/2 int w2'^2 and its rate -int w2' w2d' */
static void slope_products(const Beam* b, const double d[4], const double dd[4], double cp[3], double cv[3],
                           double pp[5], double pv[5]) {
  slope_poly(b, d, cp);
  slope_poly(b, dd, cv);
  poly_mul(cp, cp, pp);
  poly_mul(cp, cv, pv);
}

/* ---------------------------------------------------------------------------------------------
 * Parse.
 * ------------------------------------------------------------------------------------------- */
static const char* const model_names[] = {"zoac", "foac", "complete", NULL};
static const char* const assembly_names[] = {"auto", "dense", "banded", NULL};
static const char* const integration_names[] = {"reduced", "full", NULL};      /* model: exact's */
static const char* const axial_form_names[] = {"mixed", "displacement", NULL}; /* model: exact's */
static const char* const kinematics_names[] = {"cable", "intrinsic", NULL};    /* model: exact's */
enum { ASSEMBLY_AUTO, ASSEMBLY_DENSE, ASSEMBLY_BANDED };
/* `assembly: auto` is banded from this many elements on: below it the dense blocks are small
   and the fewer unknowns win (docs/performance.md, "Scaling") */
enum { BANDED_FROM_ELEMENTS = 64 };

static void beam_setup(Beam* b) {
  b->le = b->L / b->ne;
  b->r = sqrt(b->Izz / b->A);
  b->n = 3 * b->ne;
  fmb_gauss_legendre01(b->ng, b->xg, b->wg);
  for (int g = 0; g < b->ng; ++g) hermite(b->xg[g], b->le, b->ns_out[g], b->nd_out[g]);
  double le = b->le;
  fmb_beam_slope_coefficients(le, b->nslope);
  for (int g = 0; g < b->ng; ++g) int_weights(le, b->xg[g], b->pw_out[g]);
  int_weights(le, 1.0, b->pw_full);
  h_weights(b, b->pw_full, b->G_full);
  for (int g = 0; g < b->ng; ++g) h_weights(b, b->pw_out[g], b->G_out[g]);
  for (int j = 0; j < 4; ++j)
    for (int l = 0; l < 4; ++l) {
      b->H_full[j][l] = dot3(b->G_full[j], b->nslope[l]);
      for (int g = 0; g < b->ng; ++g) b->H_out[g][j][l] = dot3(b->G_out[g][j], b->nslope[l]);
    }
  double ei = b->Emod * b->Izz / (le * le * le);
  double kb[4][4] = {{12.0, 6.0 * le, -12.0, 6.0 * le},
                     {6.0 * le, 4.0 * le * le, -6.0 * le, 2.0 * le * le},
                     {-12.0, -6.0 * le, 12.0, -6.0 * le},
                     {6.0 * le, 2.0 * le * le, -6.0 * le, 4.0 * le * le}};
  for (int i = 0; i < 4; ++i)
    for (int j = 0; j < 4; ++j) b->kb[i][j] = ei * kb[i][j];
  b->ka = b->Emod * b->A / le;
  /* N2 = [1 - 3 xi^2 + 2 xi^3, le (xi - 2 xi^2 + xi^3), 3 xi^2 - 2 xi^3, le (xi^3 - xi^2)] (hermite) */
  const double nc[4][4] = {{1.0, 0.0, -3.0, 2.0}, {0.0, le, -2.0 * le, le}, {0.0, 0.0, 3.0, -2.0}, {0.0, 0.0, -le, le}};
  memcpy(b->ncubic, nc, sizeof nc);
  for (int k = 0; k < 12; ++k) b->mu[k] = 1.0 / (k + 1);
}

/* default Gauss points per element (the Jacobian's; the residual integrates exactly): the
   highest polynomial degree in xi of the model's integrands is 10 for complete (h h^T, h of
   degree 5), 6 for FOAC and ZOAC */
static int default_points(int model) { return model == BEAM_COMPLETE ? 6 : 4; }

static int beam_parse(fmbParser* p, fmbNode item, void** self) {
  Beam* b = calloc(1, sizeof *b);
  if (!b) return fmb_parse_error(p, item, "out of memory");
  int err = 0;
  err |= fmb_get_double(p, item, "length", FMB_REQUIRED | FMB_POSITIVE, &b->L);
  err |= fmb_get_int(p, item, "elements", FMB_REQUIRED, 1, MAX_ELEMENTS, &b->ne);
  err |= fmb_get_double(p, item, "density", FMB_REQUIRED | FMB_POSITIVE, &b->rho);
  err |= fmb_get_double(p, item, "area", FMB_REQUIRED | FMB_POSITIVE, &b->A);
  err |= fmb_get_double(p, item, "second_moment", FMB_REQUIRED | FMB_POSITIVE, &b->Izz);
  err |= fmb_get_double(p, item, "youngs_modulus", FMB_REQUIRED | FMB_POSITIVE, &b->Emod);
  b->model = BEAM_COMPLETE;
  err |= fmb_get_choice(p, item, "model", FMB_OPTIONAL, model_names, &b->model);
  err |= fmb_get_vec2(p, item, "position", FMB_OPTIONAL, b->pos0);
  err |= fmb_get_angle(p, item, "angle", FMB_POSE, &b->angle0);
  err |= fmb_get_vec2(p, item, "velocity", FMB_OPTIONAL, b->vel0);
  err |= fmb_get_double(p, item, "angular_velocity", FMB_OPTIONAL, &b->omega0);
  err |= fmb_get_double(p, item, "damping", FMB_OPTIONAL | FMB_NONNEGATIVE, &b->beta);
  int assembly = ASSEMBLY_AUTO;
  err |= fmb_get_choice(p, item, "assembly", FMB_OPTIONAL, assembly_names, &assembly);
  /* `integration` chooses the exact model's quadrature (bodies/beam_exact.c); these three models
     have theirs in quadrature_points, so they check the word and ignore it: a scene written for
     `model: exact` then runs under every model (`run --models`, docs/models.md) */
  int integration = 0, axial_form = 0;
  err |= fmb_get_choice(p, item, "integration", FMB_OPTIONAL, integration_names, &integration);
  err |= fmb_get_choice(p, item, "axial_form", FMB_OPTIONAL, axial_form_names, &axial_form);
  if (!err) {
    b->banded = assembly == ASSEMBLY_BANDED || (assembly == ASSEMBLY_AUTO && b->ne >= BANDED_FROM_ELEMENTS);
    b->ng = default_points(b->model);
    err |= fmb_get_int(p, item, "quadrature_points", FMB_OPTIONAL, 1, FMB_GAUSS_MAX, &b->ng);
  }
  /* fewer points integrate the mass and coupling terms inexactly (1 point put the tip deflection
     52 % off): refused, with the minimum */
  if (!err && b->ng < default_points(b->model))
    err = fmb_parse_error(p, fmb_find_key(p, item, "quadrature_points"),
                          "expected at least %d for 'quadrature_points' (the default), got %d: fewer Gauss points "
                          "under-integrate the %s beam, whose integrands reach degree %d in x",
                          default_points(b->model), b->ng, model_names[b->model], b->model == BEAM_COMPLETE ? 10 : 6);
  if (err) {
    free(b);
    return err;
  }
  beam_setup(b);
  /* parameters that are each positive and finite can still combine into an element whose mass or
     stiffness is not a usable double (length 1e-300: EI/le^3 overflows), which the solver would
     report later as a false cause */
  const double me = b->rho * b->A * b->le, k_bend = b->kb[0][0], k_axial = b->ka;
  const double w2 = fmax(k_bend, k_axial) / me; /* an element's highest frequency squared */
  if (!isnormal(me) || !isnormal(k_bend) || !isnormal(k_axial) || !isfinite(w2) || !isfinite(b->kb[1][1])) {
    fmb_beam_refuse_degenerate(p, item, b->L, b->ne, b->rho, b->A, b->Izz, b->Emod, me, k_bend, k_axial);
    free(b);
    return -1;
  }
  *self = b;
  return 0;
}

static void beam_destroy(void* self) { free(self); }

static int beam_ncoord(const void* self) { return 3 + ((const Beam*)self)->n; }

/* residual_serial's F and csum (5 ne), one residual for beam_aux_initial (3 + 3 ne), the dense
   Jacobian's scratch (jacobian_nwork; also when banded: the engine may ask for the dense M), then
   the outputs' cache (output_cache) */
static size_t jacobian_nwork(const Beam* b);
static size_t output_cache_at(const Beam* b) { return (size_t)9 * (size_t)b->ne + 3 + jacobian_nwork(b); }
static size_t output_cache_nwork(const Beam* b);
static size_t beam_nwork(const void* self) {
  const Beam* b = self;
  return output_cache_at(b) + output_cache_nwork(b);
}

static void beam_initial(const void* self, double* q0, double* v0) {
  const Beam* b = self;
  int nc = 3 + b->n;
  memset(q0, 0, sizeof(double) * (size_t)nc);
  memset(v0, 0, sizeof(double) * (size_t)nc);
  q0[0] = b->pos0[0];
  q0[1] = b->pos0[1];
  q0[2] = b->angle0;
  v0[0] = b->vel0[0];
  v0[1] = b->vel0[1];
  v0[2] = b->omega0;
}

/* ---------------------------------------------------------------------------------------------
 * Residual.
 * ------------------------------------------------------------------------------------------- */

/* Force vectors per point (body frame, mass-weighted) that multiply J_R, J_D and J_C.
     a_RD: acceleration of the rigid + linear-deformation part, a_R: rigid part, a_C: coupling
     part, f: body force per unit mass (gravity in the body frame).
   ZOAC      J_RD^T (a_RD - f)
   FOAC      J_RD^T (a_RD - f) + J_R^T a_C + J_C^T (a_R - f)
   complete  J^T (a_RD + a_C - f)                                                            */
static inline void point_forces(int model, double m, const double aRD[2], const double aR[2], const double aC[2],
                                const double f[2], double FR[2], double FD[2], double FC[2]) {
  for (int i = 0; i < 2; ++i) {
    switch (model) {
      case BEAM_ZOAC:
        FR[i] = FD[i] = m * (aRD[i] - f[i]);
        FC[i] = 0.0;
        break;
      case BEAM_FOAC:
        FD[i] = m * (aRD[i] - f[i]);
        FR[i] = FD[i] + m * aC[i];
        FC[i] = m * (aR[i] - f[i]);
        break;
      default: FR[i] = FD[i] = FC[i] = m * (aRD[i] + aC[i] - f[i]); break;
    }
  }
}

/* The frame's motion as every point sees it: acceleration a0 and gravity f in the body frame,
   angular velocity om (om2 = om^2) and acceleration al; c, s = cos, sin theta */
typedef struct {
  double a0[2], f[2], om, om2, al, c, s;
} FrameMotion;

static void frame_motion(const fmbEnv* env, const double* q, const double* v, const double* a, FrameMotion* fm) {
  double c = cos(q[2]), s = sin(q[2]);
  fm->c = c;
  fm->s = s;
  fm->a0[0] = c * a[0] + s * a[1];
  fm->a0[1] = -s * a[0] + c * a[1];
  fm->f[0] = fm->f[1] = 0.0;
  if (env && env->has_gravity) {
    fm->f[0] = c * env->gravity[0] + s * env->gravity[1];
    fm->f[1] = -s * env->gravity[0] + c * env->gravity[1];
  }
  fm->om = v[2];
  fm->om2 = v[2] * v[2];
  fm->al = a[2];
}

/* What one element contributes to the residual, given the coupling integrals over the elements
   inboard of it (prefix: int w2'^2, int w2' w2d', int (w2' w2dd' + w2d'^2) from the root to its
   left node). Everything here is local to the element; the only long-range couplings of the
   beam are the prefix (inboard -> outboard) and the tail (outboard -> inboard: the sum of the
   coupling forces F_C[0] of every point outboard, which multiplies F) and the frame sums. */
typedef struct {
  double rp_a[2], rp_t[4]; /* its p rows, without the outboard part -F tail */
  double F[4];             /* int over the element of N2j' w2' (what the outboard tail multiplies) */
  double csum;             /* sum of its points' F_C[0]: what it adds to the tail of inboard elements */
  double dprefix[3];       /* its whole-element coupling integrals: what it adds to the prefix */
  double frame[3];         /* body-frame force sums F_R (x, y) and the theta row */
} ElementTerms;

/* An element's nodal values of p, pd, pdd (gather) and, for the coupled models, its slope
   polynomials cp, cv, ca and the quartics the coupling integrates: pp = w2'^2, pv = w2' w2d',
   ha = w2' w2dd' + w2d'^2 (what h^T pdd + pd^T H pd integrates) */
typedef struct {
  double ua[2], d[4], uda[2], dd[4], udda[2], ddd[4];
  double cp[3], cv[3], ca[3], pp[5], pv5[5], ha[5];
} ElementState;

static inline FMB_BEAM_SPECIALIZED void element_state(const Beam* b, const int model, int e, const double* p,
                                                      const double* pd, const double* pdd, ElementState* es) {
  gather(p, e, es->ua, es->d);
  gather(pd, e, es->uda, es->dd);
  gather(pdd, e, es->udda, es->ddd);
  slope_poly(b, es->d, es->cp);
  slope_poly(b, es->dd, es->cv);
  slope_poly(b, es->ddd, es->ca);
  if (model != BEAM_ZOAC) {
    double vv[5];
    poly_mul(es->cp, es->cp, es->pp);
    poly_mul(es->cp, es->cv, es->pv5);
    poly_mul(es->cp, es->ca, es->ha);
    poly_mul(es->cv, es->cv, vv);
    for (int k = 0; k < 5; ++k) es->ha[k] += vv[k];
  }
}

/* One quadrature point g of element e: its deformation, coupling and the force vectors of the
   cross-section pair (point_forces), F = F0 + y F1: what element_derivs differentiates, point
   by point (element_terms integrates the same quantities exactly, by moments). */
typedef struct {
  double x, n1[2], w1, w2, w2s, w1d, w2d, w2sd, wc, wcd, M2;
  double FR0[2], FD0[2], FC0[2], FR1[2], FD1[2], FC1[2];
} PointTerms;

static inline FMB_BEAM_SPECIALIZED void point_terms(const Beam* b, const int model, const FrameMotion* fm, int e, int g,
                                                    const ElementState* es, const double prefix[3], PointTerms* pt) {
  const double le = b->le, om = fm->om, om2 = fm->om2, al = fm->al;
  const double *a0 = fm->a0, *f = fm->f;
  const double* ns = b->ns_out[g];
  const double* nd = b->nd_out[g];
  double xi = b->xg[g], x = e * le + xi * le;
  double n1[2] = {1.0 - xi, xi};
  double w1 = n1[0] * es->ua[0] + n1[1] * es->ua[1], w2 = dot4(ns, es->d), w2s = dot4(nd, es->d);
  double w1d = n1[0] * es->uda[0] + n1[1] * es->uda[1], w2d = dot4(ns, es->dd), w2sd = dot4(nd, es->dd);
  double w1dd = n1[0] * es->udda[0] + n1[1] * es->udda[1], w2dd = dot4(ns, es->ddd), w2sdd = dot4(nd, es->ddd);
  double wc = 0.0, wcd = 0.0, hacc = 0.0;
  if (model != BEAM_ZOAC) {
    /* inboard integrals + this element's part over [0, xi], in closed form */
    const double* pw = b->pw_out[g];
    wc = -0.5 * (prefix[0] + dot5(es->pp, pw)); /* w_c = -1/2 p^T H p */
    wcd = -(prefix[1] + dot5(es->pv5, pw));     /* dw_c/dt = -p^T H pd */
    hacc = prefix[2] + dot5(es->ha, pw);        /* h^T pdd + pd^T H pd */
  }
  /* The cross-section's two points y = -r, +r (weights m each): every force below is affine
     in y, F = F0 + y F1, so the sums over the pair are exact in closed form,
     sum (A + yB)(C + yD) = 2 (AC + r^2 BD); with M2 = 2m folded into F0 and F1, one pass
     gives what the two points gave. The accelerations split the same way:
       a_RD = a_RD0 + y a_RD1,  a_R = a_R0 + y a_R1,  a_C and f do not depend on y. */
  const double M2 = 2.0 * (0.5 * b->rho * b->A * le) * b->wg[g];
  const double aRD0[2] = {a0[0] - w2 * al - (x + w1) * om2 - 2.0 * w2d * om + w1dd,
                          a0[1] + (x + w1) * al - w2 * om2 + 2.0 * w1d * om + w2dd};
  const double aRD1[2] = {-al + w2s * om2 - w2sdd, -w2s * al - om2 - 2.0 * w2sd * om};
  const double aR0[2] = {a0[0] - x * om2, a0[1] + x * al};
  const double aR1[2] = {-al, -om2};
  const double aC[2] = {-wc * om2 - hacc, wc * al + 2.0 * wcd * om};
  const double zero[2] = {0.0, 0.0};
  point_forces(model, M2, aRD0, aR0, aC, f, pt->FR0, pt->FD0, pt->FC0);
  point_forces(model, M2, aRD1, aR1, zero, zero, pt->FR1, pt->FD1, pt->FC1);
  pt->x = x;
  pt->n1[0] = n1[0];
  pt->n1[1] = n1[1];
  pt->w1 = w1, pt->w2 = w2, pt->w2s = w2s, pt->w1d = w1d, pt->w2d = w2d, pt->w2sd = w2sd;
  pt->wc = wc, pt->wcd = wcd, pt->M2 = M2;
}

/* The moments int_0^1 xi^k F(xi) for k = 0..nk-1 of a polynomial F with nc coefficients */
static inline void poly_moments(const double* mu, const double* F, int nc, int nk, double* m) {
  for (int k = 0; k < nk; ++k) {
    double s = 0.0;
    for (int i = 0; i < nc; ++i) s += F[i] * mu[i + k];
    m[k] = s;
  }
}

/* One element's contribution, integrated exactly. Every integrand is a polynomial in xi: with
   w1 linear, w2 cubic, the slopes quadratic and the coupling terms w_c, dw_c/dt and h^T pdd +
   pd^T H pd quintic (int_0^x of quartics), the accelerations of point_terms are quintics (the
   y-parts, a_RD1, quadratics), and the products element_terms sums reach degree 10 (w_c F_C in
   the theta row, the coupling tail's h F_C[0]). So instead of evaluating point_terms at the
   Gauss points, the accelerations are built once per element as coefficient vectors, the
   forces from them by point_forces (linear: coefficient by coefficient, f in the constant one),
   and each integral is a dot product of coefficients with moments mu_k = 1/(k+1): the same
   numbers as the Gauss sums (exact to degree 2 ng - 1 >= 10, test_beam_residual) at about half
   the flops (bench/beam_residual.c). */
static inline FMB_BEAM_SPECIALIZED void element_terms_of(const Beam* b, const int model, const FrameMotion* fm, int e,
                                                         const double* p, const double* pd, const double* pdd,
                                                         const double prefix[3], ElementTerms* out) {
  const int coupled = model != BEAM_ZOAC;
  const double le = b->le, r2 = b->r * b->r, om = fm->om, om2 = fm->om2, al = fm->al;
  const double* mu = b->mu;
  const double me = b->rho * b->A * le; /* the element's mass: int rho A dx = me int_0^1 dxi */
  ElementState es;
  element_state(b, model, e, p, pd, pdd, &es);
  /* the fields as coefficients of xi^k: x, w1 (and rates) linear, w2 (and rates) cubic, the
     slopes w2' = cp, cv, ca quadratic (element_state), the coupling terms quintic */
  const double x[2] = {e * le, le};
  const double w1[2] = {es.ua[0], es.ua[1] - es.ua[0]}, w1d[2] = {es.uda[0], es.uda[1] - es.uda[0]},
               w1dd[2] = {es.udda[0], es.udda[1] - es.udda[0]};
  double w2[4], w2d[4], w2dd[4];
  for (int k = 0; k < 4; ++k) {
    w2[k] = w2d[k] = w2dd[k] = 0.0;
    for (int j = 0; j < 4; ++j) {
      w2[k] += b->ncubic[j][k] * es.d[j];
      w2d[k] += b->ncubic[j][k] * es.dd[j];
      w2dd[k] += b->ncubic[j][k] * es.ddd[j];
    }
  }
  double wc[6] = {0.0}, wcd[6] = {0.0}, hacc[6] = {0.0};
  if (coupled) {
    /* w_c = -1/2 (P0 + int_0^xi pp), dw_c/dt = -(P1 + int pv), hacc = P2 + int ha (point_terms) */
    wc[0] = -0.5 * prefix[0];
    wcd[0] = -prefix[1];
    hacc[0] = prefix[2];
    for (int k = 0; k < 5; ++k) {
      const double w = le * mu[k];
      wc[k + 1] = -0.5 * w * es.pp[k];
      wcd[k + 1] = -w * es.pv5[k];
      hacc[k + 1] = w * es.ha[k];
    }
  }
  /* point_terms' accelerations, F = F0 + y F1, as coefficient vectors */
  double aRD0[2][6] = {{0.0}}, aC[2][6] = {{0.0}}, aRD1[2][3], aR0[2][6] = {{0.0}};
  for (int k = 0; k < 4; ++k) {
    aRD0[0][k] += -al * w2[k] - 2.0 * om * w2d[k];
    aRD0[1][k] += -om2 * w2[k] + w2dd[k];
  }
  for (int k = 0; k < 2; ++k) {
    aRD0[0][k] += -om2 * (x[k] + w1[k]) + w1dd[k];
    aRD0[1][k] += al * (x[k] + w1[k]) + 2.0 * om * w1d[k];
    aR0[0][k] = -om2 * x[k];
    aR0[1][k] = al * x[k];
  }
  for (int i = 0; i < 2; ++i) {
    aRD0[i][0] += fm->a0[i];
    aR0[i][0] += fm->a0[i];
  }
  for (int k = 0; k < 3; ++k) {
    aRD1[0][k] = om2 * es.cp[k] - es.ca[k];
    aRD1[1][k] = -al * es.cp[k] - 2.0 * om * es.cv[k];
  }
  aRD1[0][0] -= al;
  aRD1[1][0] -= om2;
  if (coupled)
    for (int k = 0; k < 6; ++k) {
      aC[0][k] = -om2 * wc[k] - hacc[k];
      aC[1][k] = al * wc[k] + 2.0 * om * wcd[k];
    }
  /* the forces per unit mass, coefficient by coefficient; then their moments */
  double FR0[2][6], FD0[2][6], FC0[2][6], FR1[2][3],
      FD1[2][3]; /* F_C1 enters no row (theta: w_c F_C0[1]; p: F_C0[0]) */
  const double zero[2] = {0.0, 0.0}, aR1[2] = {-al, -om2};
  for (int k = 0; k < 6; ++k) {
    double r[2], d[2], c[2];
    const double aRDk[2] = {aRD0[0][k], aRD0[1][k]}, aRk[2] = {aR0[0][k], aR0[1][k]}, aCk[2] = {aC[0][k], aC[1][k]};
    point_forces(model, 1.0, aRDk, aRk, aCk, k == 0 ? fm->f : zero, r, d, c);
    for (int i = 0; i < 2; ++i) FR0[i][k] = r[i], FD0[i][k] = d[i], FC0[i][k] = c[i];
  }
  for (int k = 0; k < 3; ++k) {
    double r[2], d[2], c[2];
    const double aRDk[2] = {aRD1[0][k], aRD1[1][k]};
    point_forces(model, 1.0, aRDk, k == 0 ? aR1 : zero, zero, zero, r, d, c);
    for (int i = 0; i < 2; ++i) FR1[i][k] = r[i], FD1[i][k] = d[i];
  }
  double mFR0x, mFR0y[2], mFR1x, mFD0x[6], mFD0y[6], mFD1x[3], mFD1y[3], mFC0x[6] = {0.0}, mFC0y[6] = {0.0};
  poly_moments(mu, FR1[0], 3, 1, &mFR1x);
  poly_moments(mu, FD1[0], 3, 3, mFD1x);
  poly_moments(mu, FD1[1], 3, 3, mFD1y);
  if (model == BEAM_COMPLETE) { /* F_R = F_D = F_C (point_forces): one set of moments */
    poly_moments(mu, FD0[0], 6, 6, mFD0x);
    poly_moments(mu, FD0[1], 6, 6, mFD0y);
    memcpy(mFC0x, mFD0x, sizeof mFC0x);
    memcpy(mFC0y, mFD0y, sizeof mFC0y);
    mFR0x = mFD0x[0], mFR0y[0] = mFD0y[0], mFR0y[1] = mFD0y[1];
  } else {
    poly_moments(mu, FR0[0], 6, 1, &mFR0x);
    poly_moments(mu, FR0[1], 6, 2, mFR0y);
    poly_moments(mu, FD0[0], 6, 4, mFD0x);
    poly_moments(mu, FD0[1], 6, 4, mFD0y);
    if (coupled) {
      poly_moments(mu, FC0[0], 6, 6, mFC0x);
      poly_moments(mu, FC0[1], 6, 6, mFC0y);
    }
  }
  out->frame[0] = me * mFR0x;
  out->frame[1] = me * mFR0y[0];
  /* theta row: rho0 x F_R + u_D x F_D + (e1 w_c) x F_C, u_D = [w1 - y w2', w2] */
  out->frame[2] = me * (dot2(x, mFR0y) - r2 * mFR1x + dot2(w1, mFD0y) - r2 * dot3(es.cp, mFD1y) - dot4(w2, mFD0x) +
                        dot3(wc, mFC0y) + dot3(wc + 3, mFC0y + 3));
  /* p rows: S_D^T F_D (local), S_D = [N1 - y N2'; N2] */
  out->rp_a[0] = me * (mFD0x[0] - mFD0x[1]);
  out->rp_a[1] = me * mFD0x[1];
  for (int j = 0; j < 4; ++j) out->rp_t[j] = me * (dot4(b->ncubic[j], mFD0y) - r2 * dot3(b->nslope[j], mFD1x));
  if (coupled) {
    /* p rows: -h F_C[0]; h's own element part through the F_C-weighted moments of the partial-
       integral weights pw_k(xi) = le xi^(k+1) / (k+1), the inboard part by the tail */
    double fc_moment[5], Gm[4][3]; /* int F_C[0] pw_k, and int F_C[0] G(xi) */
    for (int k = 0; k < 5; ++k) fc_moment[k] = me * le * mu[k] * mFC0x[k + 1];
    h_weights(b, fc_moment, Gm);
    for (int j = 0; j < 4; ++j) {
      out->F[j] = dot3(b->G_full[j], es.cp);
      out->rp_t[j] -= dot3(Gm[j], es.cp);
    }
    out->csum = me * mFC0x[0];
    out->dprefix[0] = dot5(es.pp, b->pw_full);
    out->dprefix[1] = dot5(es.pv5, b->pw_full);
    out->dprefix[2] = dot5(es.ha, b->pw_full);
  } else {
    for (int j = 0; j < 4; ++j) out->F[j] = 0.0;
    out->csum = out->dprefix[0] = out->dprefix[1] = out->dprefix[2] = 0.0;
  }
}

/* element_terms_of per model: the model a constant in each copy, so the coefficient loops lose
   point_forces' switch and the compiler can vectorize them; the same operations in the same order
   (no contraction under -std=c11), so the same numbers as one copy reading b->model */
FMB_VECTOR_CLONES static void element_terms(const Beam* b, const FrameMotion* fm, int e, const double* p,
                                            const double* pd, const double* pdd, const double prefix[3],
                                            ElementTerms* out) {
  PER_MODEL(element_terms_of, b, fm, e, p, pd, pdd, prefix, out);
}

/* ---------------------------------------------------------------------------------------------
 * Derivatives of element_terms. An element's terms depend on few inputs (its "local inputs",
 * the columns below): its six dofs in q, v and a, theta (through A^T a and A^T g), theta',
 * x'', y'', theta'' and the three prefix integrals. element_derivs differentiates exactly what
 * point_terms and element_terms compute, by the chain rule (docs/beam.md, "Jacobian"): each point
 * scalar s gets its gradient ds over the local inputs, and as point_forces is linear in the
 * accelerations, the force gradients are point_forces of the acceleration gradients. The
 * coupling scalars' gradients are the h of §1: dw_c/dd_j = -h_j, h_j = G[j].cp, and the like.
 * ------------------------------------------------------------------------------------------- */
enum {
  LQ = 0,   /* its dofs in q: ua[0], ua[1], d[0..3] (gather's order) */
  LTH = 6,  /* theta */
  LV = 7,   /* its dofs in v */
  LOM = 13, /* theta' */
  LA = 14,  /* its dofs in a */
  LAX = 20, /* x'' */
  LAY = 21, /* y'' */
  LAL = 22, /* theta'' */
  LP = 23,  /* the prefix integrals P_e (3) */
  NL = 26
};

/* the gradients over the local inputs of element_terms' outputs, and the values F (what the
   outboard tail multiplies) */
typedef struct {
  double rp[6][NL]; /* rp_a[0..1] then rp_t[0..3]: the rows of the local dofs, gather's order */
  double F[4][NL], csum[NL], dprefix[3][NL], frame[3][NL];
  double Fv[4];
} ElementDerivs;

static inline FMB_BEAM_SPECIALIZED void element_derivs_of(const Beam* b, const int model, const FrameMotion* fm, int e,
                                                          const double* p, const double* pd, const double* pdd,
                                                          const double prefix[3], ElementDerivs* D) {
  const int coupled = model != BEAM_ZOAC;
  const double r2 = b->r * b->r, om = fm->om, om2 = fm->om2, al = fm->al;
  ElementState es;
  element_state(b, model, e, p, pd, pdd, &es);
  memset(D, 0, sizeof *D);
  /* the frame scalars' gradients, the same at every point: d(A^T a)/dtheta = (a0_y, -a0_x) */
  double ga0[2][NL] = {{0.0}}, gf[2][NL] = {{0.0}}, gom[NL] = {0.0}, gom2[NL] = {0.0}, gal[NL] = {0.0};
  ga0[0][LTH] = fm->a0[1], ga0[1][LTH] = -fm->a0[0];
  ga0[0][LAX] = fm->c, ga0[1][LAX] = -fm->s;
  ga0[0][LAY] = fm->s, ga0[1][LAY] = fm->c;
  gf[0][LTH] = fm->f[1], gf[1][LTH] = -fm->f[0];
  gom[LOM] = 1.0, gom2[LOM] = 2.0 * om, gal[LAL] = 1.0;
  const double zero[2] = {0.0, 0.0};
  for (int g = 0; g < b->ng; ++g) {
    const double* ns = b->ns_out[g];
    const double* nd = b->nd_out[g];
    PointTerms pt;
    point_terms(b, model, fm, e, g, &es, prefix, &pt);
    const double x = pt.x, w1 = pt.w1, w2 = pt.w2, w2s = pt.w2s, wc = pt.wc;
    /* the deformation scalars are linear in the element's dofs: their gradients are the shape
       functions; the coupling's are h (of p, pd, pdd) at the point */
    double gw1[NL] = {0.0}, gw2[NL] = {0.0}, gw2s[NL] = {0.0}, gw1d[NL] = {0.0}, gw2d[NL] = {0.0}, gw2sd[NL] = {0.0};
    double gw1dd[NL] = {0.0}, gw2dd[NL] = {0.0}, gw2sdd[NL] = {0.0}, gwc[NL] = {0.0}, gwcd[NL] = {0.0},
           ghacc[NL] = {0.0};
    for (int k = 0; k < 2; ++k) gw1[LQ + k] = gw1d[LV + k] = gw1dd[LA + k] = pt.n1[k];
    for (int j = 0; j < 4; ++j) {
      gw2[LQ + 2 + j] = gw2d[LV + 2 + j] = gw2dd[LA + 2 + j] = ns[j];
      gw2s[LQ + 2 + j] = gw2sd[LV + 2 + j] = gw2sdd[LA + 2 + j] = nd[j];
    }
    double h[4] = {0.0, 0.0, 0.0, 0.0};
    if (coupled) {
      /* w_c = -1/2 (P0 + pp.pw), w_c' = -(P1 + pv.pw), hacc = P2 + ha.pw (point_terms) */
      for (int j = 0; j < 4; ++j) {
        const double* G = b->G_out[g][j];
        const double hp = dot3(G, es.cp), hv = dot3(G, es.cv), ha = dot3(G, es.ca);
        h[j] = hp;
        gwc[LQ + 2 + j] = -hp;
        gwcd[LQ + 2 + j] = -hv;
        gwcd[LV + 2 + j] = -hp;
        ghacc[LQ + 2 + j] = ha;
        ghacc[LV + 2 + j] = 2.0 * hv;
        ghacc[LA + 2 + j] = hp;
      }
      gwc[LP] = -0.5;
      gwcd[LP + 1] = -1.0;
      ghacc[LP + 2] = 1.0;
    }
    for (int l = 0; l < NL; ++l) {
      /* gradients of point_terms' accelerations, then of the forces */
      const double tRD0[2] = {ga0[0][l] - al * gw2[l] - w2 * gal[l] - om2 * gw1[l] - (x + w1) * gom2[l] -
                                  2.0 * om * gw2d[l] - 2.0 * pt.w2d * gom[l] + gw1dd[l],
                              ga0[1][l] + al * gw1[l] + (x + w1) * gal[l] - om2 * gw2[l] - w2 * gom2[l] +
                                  2.0 * om * gw1d[l] + 2.0 * pt.w1d * gom[l] + gw2dd[l]};
      const double tRD1[2] = {-gal[l] + om2 * gw2s[l] + w2s * gom2[l] - gw2sdd[l],
                              -al * gw2s[l] - w2s * gal[l] - gom2[l] - 2.0 * om * gw2sd[l] - 2.0 * pt.w2sd * gom[l]};
      const double tR0[2] = {ga0[0][l] - x * gom2[l], ga0[1][l] + x * gal[l]};
      const double tR1[2] = {-gal[l], -gom2[l]};
      const double tC[2] = {-om2 * gwc[l] - wc * gom2[l] - ghacc[l],
                            al * gwc[l] + wc * gal[l] + 2.0 * om * gwcd[l] + 2.0 * pt.wcd * gom[l]};
      const double tf[2] = {gf[0][l], gf[1][l]};
      double FR0[2], FD0[2], FC0[2], FR1[2], FD1[2], FC1[2];
      point_forces(model, pt.M2, tRD0, tR0, tC, tf, FR0, FD0, FC0);
      point_forces(model, pt.M2, tRD1, tR1, zero, zero, FR1, FD1, FC1);
      /* element_terms' sums, by the product rule */
      D->frame[0][l] += FR0[0];
      D->frame[1][l] += FR0[1];
      D->frame[2][l] += x * FR0[1] - r2 * FR1[0] + w1 * FD0[1] + pt.FD0[1] * gw1[l] -
                        r2 * (w2s * FD1[1] + pt.FD1[1] * gw2s[l]) - (w2 * FD0[0] + pt.FD0[0] * gw2[l]) + wc * FC0[1] +
                        pt.FC0[1] * gwc[l];
      D->rp[0][l] += pt.n1[0] * FD0[0];
      D->rp[1][l] += pt.n1[1] * FD0[0];
      for (int j = 0; j < 4; ++j) D->rp[2 + j][l] += ns[j] * FD0[1] - r2 * nd[j] * FD1[0] - h[j] * FC0[0];
      D->csum[l] += FC0[0];
    }
    /* -F_C[0] h_j(xi_g): h_j = G[j].cp depends on the dofs through H[j][m] = dh_j/dd_m */
    if (coupled)
      for (int j = 0; j < 4; ++j)
        for (int m = 0; m < 4; ++m) D->rp[2 + j][LQ + 2 + m] -= pt.FC0[0] * b->H_out[g][j][m];
  }
  if (coupled)
    for (int j = 0; j < 4; ++j) {
      /* F_j = G_full[j].cp; dprefix = (pp, pv, ha).pw_full, whose d/dd_m are the h over the
         whole element of p, pd, pdd as for w_c above */
      const double hp = dot3(b->G_full[j], es.cp), hv = dot3(b->G_full[j], es.cv), ha = dot3(b->G_full[j], es.ca);
      D->Fv[j] = hp;
      for (int m = 0; m < 4; ++m) D->F[j][LQ + 2 + m] = b->H_full[j][m];
      D->dprefix[0][LQ + 2 + j] = 2.0 * hp;
      D->dprefix[1][LQ + 2 + j] = hv;
      D->dprefix[1][LV + 2 + j] = hp;
      D->dprefix[2][LQ + 2 + j] = ha;
      D->dprefix[2][LV + 2 + j] = 2.0 * hv;
      D->dprefix[2][LA + 2 + j] = hp;
    }
}

/* element_derivs_of per model, as element_terms */
FMB_VECTOR_CLONES static void element_derivs(const Beam* b, const FrameMotion* fm, int e, const double* p,
                                             const double* pd, const double* pdd, const double prefix[3],
                                             ElementDerivs* D) {
  PER_MODEL(element_derivs_of, b, fm, e, p, pd, pdd, prefix, D);
}

/* index in p of an element's local dof l (0..5, gather's order), or -1 at the clamped root */
static int ldof(int e, int l) { return l < 2 ? adof(e, l) : tdof(e, l - 2); }

/* the elastic force's (add_elastic) derivative over an element's local dofs: K_e, and beta K_e
   for the velocities */
static void elastic_block(const Beam* b, double Ke[6][6]) {
  memset(Ke, 0, sizeof(double) * 36);
  Ke[0][0] = Ke[1][1] = b->ka;
  Ke[0][1] = Ke[1][0] = -b->ka;
  for (int j = 0; j < 4; ++j)
    for (int m = 0; m < 4; ++m) Ke[2 + j][2 + m] = b->kb[j][m];
}

static void add_element_rows(int e, const ElementTerms* t, double* Rp) {
  for (int j = 0; j < 2; ++j) {
    int i = adof(e, j);
    if (i >= 0) Rp[i] += t->rp_a[j];
  }
  for (int j = 0; j < 4; ++j) {
    int i = tdof(e, j);
    if (i >= 0) Rp[i] += t->rp_t[j];
  }
}

/* elastic and damping forces: K (p + beta pd), element by element */
FMB_VECTOR_CLONES static void add_elastic(const Beam* b, const double* p, const double* pd, double* Rp) {
  for (int e = 0; e < b->ne; ++e) {
    double ua[2], d[4], uda[2], dd[4];
    gather(p, e, ua, d);
    gather(pd, e, uda, dd);
    if (b->beta > 0.0) {
      for (int j = 0; j < 2; ++j) ua[j] += b->beta * uda[j];
      for (int j = 0; j < 4; ++j) d[j] += b->beta * dd[j];
    }
    double fa = b->ka * (ua[1] - ua[0]);
    int i0 = adof(e, 0), i1 = adof(e, 1);
    if (i0 >= 0) Rp[i0] -= fa;
    Rp[i1] += fa;
    for (int j = 0; j < 4; ++j) {
      int i = tdof(e, j);
      if (i >= 0) Rp[i] += dot4(b->kb[j], d);
    }
  }
}

/* frame rows from the body-frame force sums: R_xy = A(theta) F_R, R_theta */
static void frame_rows(const double* q, const double sums[3], double* R) {
  double c = cos(q[2]), s = sin(q[2]);
  R[0] = c * sums[0] - s * sums[1];
  R[1] = s * sums[0] + c * sums[1];
  R[2] = sums[2];
}

static int all_finite(const double* x, int n) {
  for (int i = 0; i < n; ++i)
    if (!isfinite(x[i])) return 0;
  return 1;
}

/* ---------------------------------------------------------------------------------------------
 * The auxiliary unknowns of the banded assembly (beam_residual_aux). Per element e, at its
 * left node: the prefix P_e (3: the coupling integrals from the root), the tail T_e (1: sum of
 * F_C[0] over the points outboard of e) and the frame sums S_e (3: over elements e..ne-1).
 * ZOAC has no coupling: S_e only.
 * ------------------------------------------------------------------------------------------- */
static int aux_per_element(const Beam* b) { return b->model == BEAM_ZOAC ? 3 : 7; }
static int zP(const Beam* b, int e) { return aux_per_element(b) * e; }
static int zT(const Beam* b, int e) { return aux_per_element(b) * e + 3; }
static int zS(const Beam* b, int e) { return aux_per_element(b) * e + (b->model == BEAM_ZOAC ? 0 : 4); }

/* The residual with the long-range sums accumulated serially (O(ne)): inboard to outboard for
   the prefix, then outboard to inboard for the tail. When z != NULL it also records the
   auxiliary unknowns these sums are (the consistent z of the banded assembly). */
static int residual_serial(const Beam* b, const fmbEnv* env, const double* q, const double* v, const double* a,
                           double* R, double* work, double* z) {
  const int ne = b->ne, coupled = b->model != BEAM_ZOAC;
  double* Rp = R + 3;
  FrameMotion fm;
  frame_motion(env, q, v, a, &fm);
  double* Fe = work; /* per element F[4] */
  double* csum = work + 4 * ne;
  memset(R, 0, sizeof(double) * (size_t)(3 + b->n));
  double prefix[3] = {0.0, 0.0, 0.0}, sums[3] = {0.0, 0.0, 0.0};
  for (int e = 0; e < ne; ++e) {
    ElementTerms t;
    if (z && coupled) memcpy(z + zP(b, e), prefix, sizeof prefix);
    element_terms(b, &fm, e, q + 3, v + 3, a + 3, prefix, &t);
    add_element_rows(e, &t, Rp);
    memcpy(Fe + 4 * e, t.F, sizeof t.F);
    csum[e] = t.csum;
    for (int k = 0; k < 3; ++k) {
      prefix[k] += t.dprefix[k];
      sums[k] += t.frame[k];
    }
    if (z) memcpy(z + zS(b, e), t.frame, sizeof t.frame);
  }
  /* tail: the coupling forces of every point outboard of e act on e's dofs through F_e */
  double tail = 0.0;
  for (int e = ne - 1; e >= 0; --e) {
    if (coupled) {
      for (int j = 0; j < 4; ++j) {
        int i = tdof(e, j);
        if (i >= 0) Rp[i] -= Fe[4 * e + j] * tail;
      }
      if (z) z[zT(b, e)] = tail;
      tail += csum[e];
    }
    if (z && e < ne - 1)
      for (int k = 0; k < 3; ++k) z[zS(b, e) + k] += z[zS(b, e + 1) + k];
  }
  frame_rows(q, sums, R);
  add_elastic(b, q + 3, v + 3, Rp);
  return all_finite(R, 3 + b->n) ? 0 : 1;
}

static int beam_residual(const void* self, const fmbEnv* env, const double* q, const double* v, const double* a,
                         double* R, double* work) {
  return residual_serial(self, env, q, v, a, R, work, NULL);
}

/* The same residual with the prefix, tail and frame sums as unknowns z and one recursion per
   element among them (Rz = 0): every equation then touches one element, its neighbours' sums
   and the frame, so the Jacobian is banded (plus the frame's rows and columns) and its cost,
   its factorization and memory grow linearly with ne. On Rz = 0, R is residual_serial's. */
static int beam_residual_aux(const void* self, const fmbEnv* env, const double* q, const double* v, const double* a,
                             const double* z, double* R, double* Rz, double* work) {
  (void)work;
  const Beam* b = self;
  const int ne = b->ne, coupled = b->model != BEAM_ZOAC;
  double* Rp = R + 3;
  FrameMotion fm;
  frame_motion(env, q, v, a, &fm);
  memset(R, 0, sizeof(double) * (size_t)(3 + b->n));
  /* the recursions: P_e = P_(e-1) + dP(e-1), P_0 = 0; T_e = T_(e+1) + csum(e+1), T_last = 0;
     S_e = S_(e+1) + s(e), S_ne = 0; the element terms are subtracted below */
  for (int e = 0; e < ne; ++e) {
    for (int k = 0; k < 3; ++k) Rz[zS(b, e) + k] = z[zS(b, e) + k] - (e + 1 < ne ? z[zS(b, e + 1) + k] : 0.0);
    if (!coupled) continue;
    for (int k = 0; k < 3; ++k) Rz[zP(b, e) + k] = z[zP(b, e) + k] - (e > 0 ? z[zP(b, e - 1) + k] : 0.0);
    Rz[zT(b, e)] = z[zT(b, e)] - (e + 1 < ne ? z[zT(b, e + 1)] : 0.0);
  }
  const double zero[3] = {0.0, 0.0, 0.0};
  for (int e = 0; e < ne; ++e) {
    ElementTerms t;
    element_terms(b, &fm, e, q + 3, v + 3, a + 3, coupled ? z + zP(b, e) : zero, &t);
    add_element_rows(e, &t, Rp);
    for (int k = 0; k < 3; ++k) Rz[zS(b, e) + k] -= t.frame[k];
    if (!coupled) continue;
    for (int j = 0; j < 4; ++j) {
      int i = tdof(e, j);
      if (i >= 0) Rp[i] -= t.F[j] * z[zT(b, e)];
    }
    if (e + 1 < ne)
      for (int k = 0; k < 3; ++k) Rz[zP(b, e + 1) + k] -= t.dprefix[k];
    if (e > 0) Rz[zT(b, e - 1)] -= t.csum;
  }
  frame_rows(q, z + zS(b, 0), R);
  add_elastic(b, q + 3, v + 3, Rp);
  return all_finite(R, 3 + b->n) && all_finite(Rz, aux_per_element(b) * ne) ? 0 : 1;
}

static int beam_naux(const void* self) {
  const Beam* b = self;
  return b->banded ? aux_per_element(b) * b->ne : 0;
}

static int beam_aux_initial(const void* self, const fmbEnv* env, const double* q, const double* v, const double* a,
                            double* z, double* work) {
  const Beam* b = self;
  double* R = work + 5 * (size_t)b->ne; /* beam_nwork leaves room for one residual */
  return residual_serial(b, env, q, v, a, R, work, z);
}

/* Element e's block of the banded assembly over [coordinates | aux]: its equations (its dof rows
   and the recursions it feeds: S_e, P_(e+1), T_(e-1)) by the columns they read (the frame, its
   dofs, and the sums at its own and its neighbours' nodes), with where each one sits (-1: absent
   at the root or an end) for beam_pattern_jacobian. */
typedef struct {
  int nr, nc, rows[16], cols[32];
  int r_dof[6], c_dof[6];                                /* local dofs, gather's order */
  int r_S[3], c_S[3], c_S1[3], c_P[3], r_P1[3], c_P1[3]; /* S_e, S_(e+1), P_e, P_(e+1) */
  int c_T, r_T0, c_T0;                                   /* T_e, T_(e-1) */
} ElementBlock;

static void element_block(const Beam* b, int e, ElementBlock* k) {
  const int ne = b->ne, nq = 3 + b->n, coupled = b->model != BEAM_ZOAC;
  int nr = 0, nc = 0;
  for (int i = 0; i < 6; ++i) k->r_dof[i] = k->c_dof[i] = -1;
  for (int i = 0; i < 3; ++i) k->r_S[i] = k->c_S[i] = k->c_S1[i] = k->c_P[i] = k->r_P1[i] = k->c_P1[i] = -1;
  k->c_T = k->r_T0 = k->c_T0 = -1;
  for (int i = 0; i < 3; ++i) k->cols[nc++] = i;
  for (int l = 0; l < 6; ++l)
    if (ldof(e, l) >= 0) {
      k->r_dof[l] = nr;
      k->c_dof[l] = nc;
      k->rows[nr++] = k->cols[nc++] = 3 + ldof(e, l);
    }
  for (int i = 0; i < 3; ++i) {
    k->r_S[i] = nr;
    k->c_S[i] = nc;
    k->rows[nr++] = k->cols[nc++] = nq + zS(b, e) + i;
    if (e + 1 < ne) k->c_S1[i] = nc, k->cols[nc++] = nq + zS(b, e + 1) + i;
    if (!coupled) continue;
    k->c_P[i] = nc;
    k->cols[nc++] = nq + zP(b, e) + i;
    if (e + 1 < ne) {
      k->r_P1[i] = nr;
      k->c_P1[i] = nc;
      k->rows[nr++] = k->cols[nc++] = nq + zP(b, e + 1) + i;
    }
  }
  if (coupled) {
    k->c_T = nc;
    k->cols[nc++] = nq + zT(b, e);
    if (e > 0) {
      k->r_T0 = nr;
      k->c_T0 = nc;
      k->rows[nr++] = k->cols[nc++] = nq + zT(b, e - 1);
    }
  }
  k->nr = nr;
  k->nc = nc;
}

/* The banded assembly's pattern: the element blocks (element_block), row-major each; then the
   frame rows, which read the frame and S_0; then P_0 = 0 and T_(ne-1) = 0. */
static long beam_pattern(const void* self, int* rows, int* cols) {
  const Beam* b = self;
  if (!b->banded) return -1;
  const int ne = b->ne, nq = 3 + b->n, coupled = b->model != BEAM_ZOAC;
  long n = 0;
#define PAIR(r, c)   \
  do {               \
    if (rows) {      \
      rows[n] = (r); \
      cols[n] = (c); \
    }                \
    ++n;             \
  } while (0)
  for (int e = 0; e < ne; ++e) {
    ElementBlock k;
    element_block(b, e, &k);
    for (int i = 0; i < k.nr; ++i)
      for (int j = 0; j < k.nc; ++j) PAIR(k.rows[i], k.cols[j]);
  }
  for (int i = 0; i < 3; ++i)
    for (int k = 0; k < 3; ++k) {
      PAIR(i, k);
      PAIR(i, nq + zS(b, 0) + k);
    }
  if (coupled) {
    for (int k = 0; k < 3; ++k) PAIR(nq + zP(b, 0) + k, nq + zP(b, 0) + k);
    PAIR(nq + zT(b, ne - 1), nq + zT(b, ne - 1));
  }
#undef PAIR
  return n;
}

/* ---------------------------------------------------------------------------------------------
 * The analytic Jacobians, from element_derivs.
 * ------------------------------------------------------------------------------------------- */

/* Adds s * (a local gradient T of element e, its prefix part excluded) to one row of K, C, M:
   rq, rv, ra point at the row's entry in column 0 of each, st is the distance between columns. */
static void add_local_row(int e, const double* T, double s, double* rq, double* rv, double* ra, size_t st) {
  for (int l = 0; l < 6; ++l) {
    const int i = ldof(e, l);
    if (i < 0) continue;
    const size_t c = (size_t)(3 + i) * st;
    rq[c] += s * T[LQ + l];
    rv[c] += s * T[LV + l];
    ra[c] += s * T[LA + l];
  }
  rq[2 * st] += s * T[LTH];
  rv[2 * st] += s * T[LOM];
  ra[0] += s * T[LAX];
  ra[st] += s * T[LAY];
  ra[2 * st] += s * T[LAL];
}

/* Adds s * g (a gradient over all of q, v, a: g, g + nq, g + 2 nq) to one row of K, C, M, over the
   columns c0..c1-1 of each (those where g may be nonzero: the rest would add exact zeros) */
static void add_global_row(const double* g, double s, int nq, int c0, int c1, double* rq, double* rv, double* ra,
                           size_t st) {
  if (s == 0.0) return;
  for (int c = c0; c < c1; ++c) {
    rq[(size_t)c * st] += s * g[c];
    rv[(size_t)c * st] += s * g[nq + c];
    ra[(size_t)c * st] += s * g[2 * nq + c];
  }
}

/* beam_nwork's part for the dense Jacobian beyond the residual's: the z of residual_serial
   (7 ne), element_derivs' results per element (the coupled models need them twice: the prefix
   gradients first, then the outboard-to-inboard sweep) and the gradients of the prefix (3) and
   the tail (1) over q, v, a (12 nq) */
enum { DERIVS_DOUBLES = (sizeof(ElementDerivs) + sizeof(double) - 1) / sizeof(double) };
static size_t jacobian_nwork(const Beam* b) {
  return (size_t)b->ne * (7 + DERIVS_DOUBLES) + (size_t)12 * (size_t)(3 + b->n);
}

/* Dense K, C, M (column-major nq x nq; NULL blocks are skipped only all together) of the residual
   with the sums eliminated (residual_serial). Element e's rows read the prefix P_e (the sums of
   dprefix over the elements inboard) and the tail T_e (the sums of csum outboard), so by the
   chain rule
     dR_e = (local) + sum_k dR_e/dP_k dP_e[k] - F_e dT_e,   dT_e = sum_(k>e) (local + dcsum_k/dP dP_k),
   and the frame rows A(theta) S with S = sum_e frame_e. One sweep outboard to inboard carries
   dT_e; dP_e (nonzero on the dofs of the nodes up to e only) is rebuilt from the stored dprefix
   gradients, without cancellation, as the sweep moves inboard. */
FMB_VECTOR_CLONES static int beam_jacobian(const void* self, const fmbEnv* env, const double* q, const double* v,
                                           const double* a, double* K, double* C, double* M, double* work) {
  const Beam* b = self;
  if (!K || !C || !M) return -1;
  const int ne = b->ne, nq = 3 + b->n, coupled = b->model != BEAM_ZOAC;
  const size_t st = (size_t)nq;
  double* R = work + 5 * (size_t)ne; /* residual_serial's scratch, then R, z, element_derivs per element, dP, dT */
  double* z = R + nq;
  ElementDerivs* Dall = (ElementDerivs*)(z + 7 * (size_t)ne);
  double* dP = z + (7 + DERIVS_DOUBLES) * (size_t)ne;
  double* dT = dP + 9 * st;
  if (residual_serial(b, env, q, v, a, R, work, z)) return 1;
  memset(K, 0, sizeof(double) * st * st);
  memset(C, 0, sizeof(double) * st * st);
  memset(M, 0, sizeof(double) * st * st);
  memset(dP, 0, sizeof(double) * 12 * st);
  FrameMotion fm;
  frame_motion(env, q, v, a, &fm);
  const double zero[3] = {0.0, 0.0, 0.0};
  /* the frame rows R_xy = A(theta) S: theta turns them (d/dtheta = (-R_y, R_x)), S_k moves them */
  K[2 * st + 0] += -R[1];
  K[2 * st + 1] += R[0];
  const double W[3][3] = {{fm.c, -fm.s, 0.0}, {fm.s, fm.c, 0.0}, {0.0, 0.0, 1.0}};
  if (coupled) {
    /* dP_(ne-1): the dprefix gradients of every element but the last */
    for (int e = 0; e < ne; ++e) {
      element_derivs(b, &fm, e, q + 3, v + 3, a + 3, z + zP(b, e), &Dall[e]);
      if (e < ne - 1)
        for (int k = 0; k < 3; ++k)
          add_local_row(e, Dall[e].dprefix[k], 1.0, dP + 3 * st * k, dP + 3 * st * k + st, dP + 3 * st * k + 2 * st, 1);
    }
  }
  for (int e = ne - 1; e >= 0; --e) {
    ElementDerivs Dz;
    if (!coupled) element_derivs(b, &fm, e, q + 3, v + 3, a + 3, zero, &Dz);
    const ElementDerivs* D = coupled ? &Dall[e] : &Dz;
    /* dP_e is nonzero on the p dofs of the nodes 1..e only (the elements inboard of e): the
       columns 3..pend-1 of each of its q, v, a parts */
    const int pend = 3 + 3 * e;
    /* the rows of its dofs: local, through P_e, and the tail -F_e T_e */
    for (int l = 0; l < 6; ++l) {
      const int i = ldof(e, l);
      if (i < 0) continue;
      double *rq = K + 3 + i, *rv = C + 3 + i, *ra = M + 3 + i;
      add_local_row(e, D->rp[l], 1.0, rq, rv, ra, st);
      if (!coupled) continue;
      for (int k = 0; k < 3; ++k) add_global_row(dP + 3 * st * k, D->rp[l][LP + k], nq, 3, pend, rq, rv, ra, st);
      if (l < 2) continue; /* the tail acts on the transverse dofs (h) */
      add_local_row(e, D->F[l - 2], -z[zT(b, e)], rq, rv, ra, st);
      add_global_row(dT, -D->Fv[l - 2], nq, 0, nq, rq, rv, ra, st);
    }
    /* the frame rows: S_k gathers frame_k of every element */
    for (int i = 0; i < 3; ++i)
      for (int k = 0; k < 3; ++k) {
        if (W[i][k] == 0.0) continue;
        add_local_row(e, D->frame[k], W[i][k], K + i, C + i, M + i, st);
        if (coupled)
          for (int m = 0; m < 3; ++m)
            add_global_row(dP + 3 * st * m, W[i][k] * D->frame[k][LP + m], nq, 3, pend, K + i, C + i, M + i, st);
      }
    if (!coupled) continue;
    /* dT_(e-1) = dT_e + dcsum_e */
    add_local_row(e, D->csum, 1.0, dT, dT + st, dT + 2 * st, 1);
    for (int m = 0; m < 3; ++m)
      for (size_t part = 0; part < 3; ++part) /* q, v, a */
        for (size_t c = part * st + 3; c < part * st + (size_t)pend; ++c) dT[c] += D->csum[LP + m] * dP[3 * st * m + c];
    /* dP_(e-1): element e-1's dofs drop out; its left node keeps element e-2's part */
    if (e == 0) break;
    for (int k = 0; k < 3; ++k) {
      double* g = dP + 3 * st * k;
      for (int l = 0; l < 6; ++l) {
        const int i = ldof(e - 1, l);
        if (i >= 0) g[3 + i] = g[st + 3 + i] = g[2 * st + 3 + i] = 0.0;
      }
      if (e >= 2) {
        const double* T = Dall[e - 2].dprefix[k];
        for (int l = 1; l < 6; l += (l == 1 ? 3 : 1)) { /* e-2's right node: ua[1], d[2], d[3] */
          const int i = ldof(e - 2, l);
          g[3 + i] += T[LQ + l];
          g[st + 3 + i] += T[LV + l];
          g[2 * st + 3 + i] += T[LA + l];
        }
      }
    }
  }
  /* elastic and damping forces K (p + beta pd) */
  double Ke[6][6];
  elastic_block(b, Ke);
  for (int e = 0; e < ne; ++e)
    for (int lj = 0; lj < 6; ++lj) {
      const int j = ldof(e, lj);
      if (j < 0) continue;
      for (int li = 0; li < 6; ++li) {
        const int i = ldof(e, li);
        if (i < 0) continue;
        K[(size_t)(3 + j) * st + 3 + i] += Ke[li][lj];
        C[(size_t)(3 + j) * st + 3 + i] += b->beta * Ke[li][lj];
      }
    }
  return 0;
}

/* The banded assembly's K = d[R; Rz]/d[q; z], C, M, one value per pair of beam_pattern: each
   element's block from element_derivs (its rows read P_e and T_e as unknowns, so no chain
   through other elements), the recursions' unit entries, the frame rows A(theta) S_0. */
static int beam_pattern_jacobian(const void* self, const fmbEnv* env, const double* q, const double* v, const double* a,
                                 const double* z, double* K, double* C, double* M, double* work) {
  (void)work;
  const Beam* b = self;
  if (!b->banded || !z) return -1;
  const int ne = b->ne, coupled = b->model != BEAM_ZOAC;
  FrameMotion fm;
  frame_motion(env, q, v, a, &fm);
  const double zero[3] = {0.0, 0.0, 0.0};
  double Ke[6][6];
  elastic_block(b, Ke);
  size_t base = 0;
  for (int e = 0; e < ne; ++e) {
    ElementBlock k;
    ElementDerivs D;
    element_block(b, e, &k);
    element_derivs(b, &fm, e, q + 3, v + 3, a + 3, coupled ? z + zP(b, e) : zero, &D);
    const size_t nv = (size_t)k.nr * (size_t)k.nc;
    double *Kb = K + base, *Cb = C + base, *Mb = M + base;
    memset(Kb, 0, sizeof(double) * nv);
    memset(Cb, 0, sizeof(double) * nv);
    memset(Mb, 0, sizeof(double) * nv);
    /* s * T into row ri: its local columns, and the prefix columns P_e */
#define ROW(ri, T, s)                                                           \
  do {                                                                          \
    const size_t ro_ = (size_t)(ri) * (size_t)k.nc;                             \
    for (int l_ = 0; l_ < 6; ++l_)                                              \
      if (k.c_dof[l_] >= 0) {                                                   \
        Kb[ro_ + k.c_dof[l_]] += (s) * (T)[LQ + l_];                            \
        Cb[ro_ + k.c_dof[l_]] += (s) * (T)[LV + l_];                            \
        Mb[ro_ + k.c_dof[l_]] += (s) * (T)[LA + l_];                            \
      }                                                                         \
    Kb[ro_ + 2] += (s) * (T)[LTH];                                              \
    Cb[ro_ + 2] += (s) * (T)[LOM];                                              \
    Mb[ro_ + 0] += (s) * (T)[LAX];                                              \
    Mb[ro_ + 1] += (s) * (T)[LAY];                                              \
    Mb[ro_ + 2] += (s) * (T)[LAL];                                              \
    if (coupled)                                                                \
      for (int m_ = 0; m_ < 3; ++m_) Kb[ro_ + k.c_P[m_]] += (s) * (T)[LP + m_]; \
  } while (0)
    for (int l = 0; l < 6; ++l) {
      const int ri = k.r_dof[l];
      if (ri < 0) continue;
      ROW(ri, D.rp[l], 1.0);
      for (int m = 0; m < 6; ++m)
        if (k.c_dof[m] >= 0) {
          Kb[(size_t)ri * k.nc + k.c_dof[m]] += Ke[l][m];
          Cb[(size_t)ri * k.nc + k.c_dof[m]] += b->beta * Ke[l][m];
        }
      if (coupled && l >= 2) { /* -F_j T_e */
        ROW(ri, D.F[l - 2], -z[zT(b, e)]);
        Kb[(size_t)ri * k.nc + k.c_T] -= D.Fv[l - 2];
      }
    }
    for (int i = 0; i < 3; ++i) {
      /* S_e - S_(e+1) - frame_e */
      const size_t r0 = (size_t)k.r_S[i] * k.nc;
      Kb[r0 + k.c_S[i]] += 1.0;
      if (k.c_S1[i] >= 0) Kb[r0 + k.c_S1[i]] -= 1.0;
      ROW(k.r_S[i], D.frame[i], -1.0);
      if (!coupled || k.r_P1[i] < 0) continue;
      /* P_(e+1) - P_e - dprefix_e */
      const size_t r1 = (size_t)k.r_P1[i] * k.nc;
      Kb[r1 + k.c_P1[i]] += 1.0;
      Kb[r1 + k.c_P[i]] -= 1.0;
      ROW(k.r_P1[i], D.dprefix[i], -1.0);
    }
    if (coupled && k.r_T0 >= 0) {
      /* T_(e-1) - T_e - csum_e */
      const size_t r0 = (size_t)k.r_T0 * k.nc;
      Kb[r0 + k.c_T0] += 1.0;
      Kb[r0 + k.c_T] -= 1.0;
      ROW(k.r_T0, D.csum, -1.0);
    }
#undef ROW
    base += nv;
  }
  /* the frame rows R_xy = A(theta) S_0, R_theta = S_0[2]: pairs (i, k) and (i, S_0 + k) */
  const double* S = z + zS(b, 0);
  const double W[3][3] = {{fm.c, -fm.s, 0.0}, {fm.s, fm.c, 0.0}, {0.0, 0.0, 1.0}};
  const double Rx = fm.c * S[0] - fm.s * S[1], Ry = fm.s * S[0] + fm.c * S[1];
  for (int i = 0; i < 3; ++i)
    for (int k = 0; k < 3; ++k) {
      const size_t at = base + 2 * (size_t)(3 * i + k);
      K[at] = k == 2 ? (i == 0 ? -Ry : i == 1 ? Rx : 0.0) : 0.0;
      K[at + 1] = W[i][k];
      C[at] = C[at + 1] = M[at] = M[at + 1] = 0.0;
    }
  base += 18;
  if (coupled) /* P_0 = 0, T_(ne-1) = 0 */
    for (int k = 0; k < 4; ++k) {
      K[base + k] = 1.0;
      C[base + k] = M[base + k] = 0.0;
    }
  return 0;
}

/* ---------------------------------------------------------------------------------------------
 * Kinematics of one material point: element, shape and coupling at reference x.
 * ------------------------------------------------------------------------------------------- */

/* w_c(x), and optionally dw_c/dt, by the same closed-form integrals as the residual (element e
   at xi); model must be coupled */
static void coupling_at(const Beam* b, const double* p, const double* pd, int e, double xi, double* wc, double* wcd) {
  double Ipp = 0.0, Ipv = 0.0, pw_part[5];
  double ua[2], d[4], dd[4] = {0.0, 0.0, 0.0, 0.0};
  int_weights(b->le, xi, pw_part);
  for (int k = 0; k <= e; ++k) {
    gather(p, k, ua, d);
    if (pd) gather(pd, k, ua, dd);
    const double* pw = (k == e) ? pw_part : b->pw_full;
    double cp[3], cv[3], pp[5], pv[5];
    slope_products(b, d, dd, cp, cv, pp, pv); /* dd = 0 without pd */
    Ipp += dot5(pp, pw);
    Ipv += dot5(pv, pw);
  }
  *wc = -0.5 * Ipp;
  if (wcd) *wcd = -Ipv;
}

static void locate(const Beam* b, double x, int* e, double* xi) { fmb_beam_locate(b->le, b->ne, x, e, xi); }

static int beam_marker(const void* self, const double* q, const double local[2], double pos[2], double* angle,
                       double* dpos_dq, double* dangle_dq, double* work) {
  (void)work;
  const Beam* b = self;
  const int nc = 3 + b->n;
  const double* p = q + 3;
  double x = local[0], y = local[1];
  double c = cos(q[2]), s = sin(q[2]);
  if (x > b->L * (1.0 + 1e-12)) return -1;
  if (dpos_dq) memset(dpos_dq, 0, sizeof(double) * 2 * (size_t)nc);
  if (dangle_dq) memset(dangle_dq, 0, sizeof(double) * (size_t)nc);
  double u[2] = {0.0, 0.0}, slope = 0.0;
  int e = 0;
  double xi = 0.0, n1[2] = {0.0, 0.0}, ns[4] = {0.0, 0.0, 0.0, 0.0}, nd[4] = {0.0, 0.0, 0.0, 0.0};
  int onbeam = x > 0.0; /* points at x <= 0 move rigidly with the frame (the root is clamped) */
  if (onbeam) {
    double ua[2], d[4];
    locate(b, x, &e, &xi);
    gather(p, e, ua, d);
    hermite(xi, b->le, ns, nd);
    n1[0] = 1.0 - xi;
    n1[1] = xi;
    slope = dot4(nd, d);
    u[0] = n1[0] * ua[0] + n1[1] * ua[1] - y * slope;
    u[1] = dot4(ns, d);
    if (b->model != BEAM_ZOAC) {
      double wc;
      coupling_at(b, p, NULL, e, xi, &wc, NULL);
      u[0] += wc;
    }
  }
  double rb[2] = {x + u[0], y + u[1]};
  pos[0] = q[0] + c * rb[0] - s * rb[1];
  pos[1] = q[1] + s * rb[0] + c * rb[1];
  if (angle) *angle = q[2] + slope;
  if (dangle_dq) {
    dangle_dq[2] = 1.0;
    if (onbeam)
      for (int j = 0; j < 4; ++j) {
        int i = tdof(e, j);
        if (i >= 0) dangle_dq[3 + i] = nd[j];
      }
  }
  if (dpos_dq) {
    double* r0 = dpos_dq;
    double* r1 = dpos_dq + nc;
    r0[0] = 1.0;
    r1[1] = 1.0;
    r0[2] = -s * rb[0] - c * rb[1];
    r1[2] = c * rb[0] - s * rb[1];
    if (onbeam) {
      /* body-frame d u / d p = S_D - e1 h^T, then rotate by A */
      for (int j = 0; j < 2; ++j) {
        int i = adof(e, j);
        if (i >= 0) {
          r0[3 + i] += c * n1[j];
          r1[3 + i] += s * n1[j];
        }
      }
      for (int j = 0; j < 4; ++j) {
        int i = tdof(e, j);
        if (i < 0) continue;
        double du0 = -y * nd[j], du1 = ns[j];
        r0[3 + i] += c * du0 - s * du1;
        r1[3 + i] += s * du0 + c * du1;
      }
      if (b->model != BEAM_ZOAC) {
        /* -h(x): h_j = int_0^x N2j' w2' over the inboard elements and [0, xi] of e */
        double pw_part[5], G_part[4][3];
        int_weights(b->le, xi, pw_part);
        h_weights(b, pw_part, G_part);
        for (int k = 0; k <= e; ++k) {
          double ua[2], d[4], cp[3], h[4];
          gather(p, k, ua, d);
          slope_poly(b, d, cp);
          for (int j = 0; j < 4; ++j) h[j] = dot3(k == e ? G_part[j] : b->G_full[j], cp);
          for (int j = 0; j < 4; ++j) {
            int i = tdof(k, j);
            if (i < 0) continue;
            r0[3 + i] -= c * h[j];
            r1[3 + i] -= s * h[j];
          }
        }
      }
    }
  }
  return 0;
}

/* ---------------------------------------------------------------------------------------------
 * Energy: each model's own kinetic energy, strain energy 1/2 p^T K p, gravity -int rho g.r.
 * ------------------------------------------------------------------------------------------- */
/* four doubles, one element of the beam in each lane (GCC's and Clang's vector extension: two SSE2
   registers on a baseline x86-64, one in beam_integrals' AVX2 version, two NEON ones on arm64) */
typedef double dbl4 __attribute__((vector_size(4 * sizeof(double))));
/* macros, not functions: a function returning a 4-double vector has another ABI with and without
   AVX (GCC's -Wpsabi), and beam_integrals is compiled both ways */
#define splat(a) ((dbl4){(a), (a), (a), (a)})
/* m_k = int_0^1 a(xi) xi^k dxi (k < nk) of a polynomial given by its na coefficients: the Hankel
   product sum_i a_i mu_(i+k). Then int_0^1 a b = b . m for b of degree < nk */
/* sum_j m[j][i] x_j over a 4 x n table's column i, and sum_j r[j] x_j (dot4's order) */
#define COLUMN4(m, i, x) \
  (splat((m)[0][i]) * (x)[0] + splat((m)[1][i]) * (x)[1] + splat((m)[2][i]) * (x)[2] + splat((m)[3][i]) * (x)[3])
#define ROW4(r, x) (splat((r)[0]) * (x)[0] + splat((r)[1]) * (x)[1] + splat((r)[2]) * (x)[2] + splat((r)[3]) * (x)[3])
/* poly_mul's product of two quadratics in each lane, in its order */
#define POLY_MUL(a, c)                                                                                       \
  {                                                                                                          \
    (a)[0] * (c)[0], (a)[0] * (c)[1] + (a)[1] * (c)[0], (a)[0] * (c)[2] + (a)[1] * (c)[1] + (a)[2] * (c)[0], \
        (a)[1] * (c)[2] + (a)[2] * (c)[1], (a)[2] * (c)[2]                                                   \
  }
#define MOMENTS(mu, a, na, m, nk)                                                         \
  for (int k_ = 0; k_ < (nk); ++k_) {                                                     \
    (m)[k_] = (a)[0] * splat((mu)[k_]);                                                   \
    for (int i_ = 1; i_ < (na); ++i_) (m)[k_] = (m)[k_] + (a)[i_] * splat((mu)[i_ + k_]); \
  }

/* T (the model's own), U_e, U_g and the generalized momentum p_theta = dT/dtheta' (the angular
   momentum about the frame origin for the complete model) in one pass; with the coupling integrals
   over the whole beam (coupled models). Each element is integrated exactly by moments, as
   element_terms integrates the residual: every integrand is a product of two fields that are
   polynomials in xi, x and w1 linear, w2 cubic, the slopes quadratic and w_c and its rate quintic
   (the inboard integrals plus int_0^xi of quartics), so int_0^1 a b = sum_i a_i sum_k b_k
   mu_(i+k). Four elements at a time, one per lane of a vector (the lanes past the last element
   repeat it, and are then not summed); the sums over elements in their order. The Gauss
   quadrature this replaced (points in the lanes) was exact for the same degrees (<= 10): the same
   energies up to rounding, in about a third of the instructions. */
FMB_VECTOR_CLONES static void beam_integrals(const Beam* b, const fmbEnv* env, const double* q, const double* v,
                                             fmbEnergy* en, double* ptheta, double coupling_total[2]) {
  const int ne = b->ne, model = b->model, coupled = model != BEAM_ZOAC;
  const double le = b->le, r2 = b->r * b->r;
  const double* mu = b->mu;
  const double* p = q + 3;
  const double* pd = v + 3;
  const double c = cos(q[2]), s = sin(q[2]), om = v[2];
  const double v0[2] = {c * v[0] + s * v[1], -s * v[0] + c * v[1]};
  const int grav = env && env->has_gravity;
  double f[2] = {0.0, 0.0};
  if (grav) {
    f[0] = c * env->gravity[0] + s * env->gravity[1];
    f[1] = -s * env->gravity[0] + c * env->gravity[1];
  }
  double T = 0.0, Ug = 0.0, Ue = 0.0, pth = 0.0, Ipp = 0.0, Ipv = 0.0;
  /* the element's mass: a cross-section pair y = -r, +r of rho A dx / 2 each, whose velocities
     and lever arms are affine in y, X = X0 + y X1, so the pair sums in closed form as in the
     residual: sum m (A + yB).(C + yD) = rho A dx (A.C + r^2 B.D) */
  const double me = b->rho * b->A * le;
  const dbl4 omv = splat(om), zero = splat(0.0), lev = splat(le);
  for (int e0 = 0; e0 < ne; e0 += 4) {
    const int nlane = ne - e0 < 4 ? ne - e0 : 4;
    dbl4 ua[2] = {zero, zero}, d[4] = {zero, zero, zero, zero}, uda[2] = {zero, zero}, dd[4] = {zero, zero, zero, zero},
         x0 = zero;
    for (int l = 0; l < 4; ++l) {
      const int e = e0 + (l < nlane ? l : nlane - 1);
      double ua_l[2], d_l[4], uda_l[2], dd_l[4];
      gather(p, e, ua_l, d_l);
      gather(pd, e, uda_l, dd_l);
      for (int j = 0; j < 2; ++j) ua[j][l] = ua_l[j], uda[j][l] = uda_l[j];
      for (int j = 0; j < 4; ++j) d[j][l] = d_l[j], dd[j][l] = dd_l[j];
      x0[l] = e * le;
    }
    /* the fields as coefficients of xi^0..5 (element_terms' layout; slope_poly's cp, cv) */
    dbl4 cp[3], cv[3], w2[4], w2d[4];
    for (int i = 0; i < 3; ++i) {
      cp[i] = COLUMN4(b->nslope, i, d);
      cv[i] = COLUMN4(b->nslope, i, dd);
    }
    for (int k = 0; k < 4; ++k) {
      w2[k] = COLUMN4(b->ncubic, k, d);
      w2d[k] = COLUMN4(b->ncubic, k, dd);
    }
    /* x = x0 + le xi (lev) */
    const dbl4 w1[2] = {ua[0], ua[1] - ua[0]}, w1d[2] = {uda[0], uda[1] - uda[0]};
    dbl4 wc[6], wcd[6];
    for (int k = 0; k < 6; ++k) wc[k] = wcd[k] = zero;
    if (coupled) {
      /* w_c = -1/2 (P0 + int_0^xi w2'^2), its rate -(P1 + int_0^xi w2' w2d'), P the inboard
         elements' integrals: the quartics in poly_mul's order, whole-element integrals summed in
         the elements' order (the tip outputs read them: beam_output) */
      const dbl4 pp[5] = POLY_MUL(cp, cp), pv[5] = POLY_MUL(cp, cv);
      const double* pw = b->pw_full;
      const dbl4 dpp = pp[0] * splat(pw[0]) + pp[1] * splat(pw[1]) + pp[2] * splat(pw[2]) + pp[3] * splat(pw[3]) +
                       pp[4] * splat(pw[4]);
      const dbl4 dpv = pv[0] * splat(pw[0]) + pv[1] * splat(pw[1]) + pv[2] * splat(pw[2]) + pv[3] * splat(pw[3]) +
                       pv[4] * splat(pw[4]);
      dbl4 P0, P1;
      for (int l = 0; l < 4; ++l) {
        P0[l] = Ipp;
        P1[l] = Ipv;
        if (l < nlane) Ipp += dpp[l], Ipv += dpv[l];
      }
      wc[0] = splat(-0.5) * P0;
      wcd[0] = -P1;
      for (int k = 0; k < 5; ++k) {
        const double w = le * mu[k];
        wc[k + 1] = splat(-0.5 * w) * pp[k];
        wcd[k + 1] = splat(-w) * pv[k];
      }
    }
    /* body-frame velocities of the pair, V = V0 + y V1: the rigid and linear deformation parts
       vRD0 = vR0 + (w1d - om w2, om w1 + w2d), vR0 = (v0x, v0y + om x), vRD1 = (-om - w2d',
       -om w2') (B below); the coupling's vC = (w_c rate, om w_c); and dV/dtheta' of the parts,
       gRD0 = (-w2, x + w1), gRD1 = (-1, -w2'). The complete model's own velocity is vRD0 + vC
       (V below), its p_theta gRD0.V + w_c V_y; ZOAC and FOAC keep vRD0 (FOAC adding vR0.vC to T
       and x om w_c + w_c vR0y to p_theta) */
    dbl4 V[2][6], gy[6], B[2][3];
    for (int k = 0; k < 6; ++k) V[0][k] = V[1][k] = gy[k] = zero;
    for (int k = 0; k < 4; ++k) {
      V[0][k] = -omv * w2[k];
      V[1][k] = w2d[k];
    }
    gy[0] = x0 + w1[0];
    gy[1] = lev + w1[1];
    for (int k = 0; k < 2; ++k) {
      V[0][k] = V[0][k] + w1d[k];
      V[1][k] = V[1][k] + omv * gy[k];
    }
    V[0][0] = V[0][0] + splat(v0[0]);
    V[1][0] = V[1][0] + splat(v0[1]);
    if (model == BEAM_COMPLETE)
      for (int k = 0; k < 6; ++k) {
        V[0][k] = V[0][k] + wcd[k];
        V[1][k] = V[1][k] + omv * wc[k];
        gy[k] = gy[k] + wc[k];
      }
    for (int k = 0; k < 3; ++k) {
      B[0][k] = -cv[k];
      B[1][k] = -omv * cp[k];
    }
    B[0][0] = B[0][0] - omv;
    dbl4 mV[2][6], mB[2][3];
    MOMENTS(mu, V[0], 6, mV[0], 6);
    MOMENTS(mu, V[1], 6, mV[1], 6);
    MOMENTS(mu, B[0], 3, mB[0], 3);
    MOMENTS(mu, B[1], 3, mB[1], 3);
    dbl4 sqV = zero, sqB = zero, momV = zero;
    for (int k = 0; k < 6; ++k) {
      sqV = sqV + V[0][k] * mV[0][k] + V[1][k] * mV[1][k];
      momV = momV + gy[k] * mV[1][k];
    }
    for (int k = 0; k < 4; ++k) momV = momV - w2[k] * mV[0][k];
    dbl4 momB = -mB[0][0];
    for (int k = 0; k < 3; ++k) {
      sqB = sqB + B[0][k] * mB[0][k] + B[1][k] * mB[1][k];
      momB = momB - cp[k] * mB[1][k];
    }
    dbl4 dT = splat(0.5) * (sqV + splat(r2) * sqB), dp = momV + splat(r2) * momB;
    if (model == BEAM_FOAC) {
      dbl4 mwc[2], iwcd = zero;
      MOMENTS(mu, wc, 6, mwc, 2);
      for (int k = 0; k < 6; ++k) iwcd = iwcd + wcd[k] * splat(mu[k]);
      const dbl4 vR0y[2] = {splat(v0[1]) + omv * x0, omv * lev};
      const dbl4 vR0y_wc = vR0y[0] * mwc[0] + vR0y[1] * mwc[1];
      dT = dT + splat(v0[0]) * iwcd + omv * vR0y_wc;
      dp = dp + omv * (x0 * mwc[0] + lev * mwc[1]) + vR0y_wc;
    }
    /* gravity: -m f.(rho0 + u) in the body frame (the frame origin term is added below); the
       strain energy 1/2 ka (u2 - u1)^2 + 1/2 d.kb d */
    dbl4 dUg = zero;
    if (grav) {
      dbl4 ax = x0 * splat(mu[0]) + lev * splat(mu[1]) + w1[0] * splat(mu[0]) + w1[1] * splat(mu[1]), aw2 = zero;
      for (int k = 0; k < 6; ++k) ax = ax + wc[k] * splat(mu[k]);
      for (int k = 0; k < 4; ++k) aw2 = aw2 + w2[k] * splat(mu[k]);
      dUg = splat(f[0]) * ax + splat(f[1]) * aw2;
    }
    const dbl4 du = ua[1] - ua[0];
    dbl4 dUe = splat(0.5 * b->ka) * du * du;
    for (int j = 0; j < 4; ++j) dUe = dUe + splat(0.5) * d[j] * ROW4(b->kb[j], d);
    for (int l = 0; l < nlane; ++l) { /* in the order of the elements */
      T += me * dT[l];
      pth += me * dp[l];
      Ue += dUe[l];
      Ug -= me * dUg[l];
    }
  }
  if (grav) Ug -= me * ne * (env->gravity[0] * q[0] + env->gravity[1] * q[1]);
  en->kinetic = T;
  en->strain = Ue;
  en->gravity = Ug;
  en->spring = 0.0;
  if (ptheta) *ptheta = pth;
  coupling_total[0] = Ipp; /* int_0^L w2'^2 and int_0^L w2' w2d' (coupled models): the tip's w_c, rate */
  coupling_total[1] = Ipv;
}

#undef splat
#undef COLUMN4
#undef ROW4
#undef POLY_MUL
#undef MOMENTS

/* ---------------------------------------------------------------------------------------------
 * The outputs' cache: a row asks several outputs of one state (q, v). The energies and
 * beam.ang_momentum come from one pass of beam_integrals, and the tip's u, x, y and u rate from
 * one coupling integral over every element (coupling_at); each was computed once per column
 * (the w15 spin-up's 2,001 rows: 84 M of its 405 M instructions in beam_integrals, half of them
 * the second pass for ang_momentum). Kept after the Jacobian's scratch in the body's work,
 * keyed by the state's bytes: a value comes from the cache only for the very (q, v) it was
 * computed from, so every output is bit for bit what its own pass gives. The work is calloc'ed
 * (system.c), so a new one holds no valid entry.
 * ------------------------------------------------------------------------------------------- */
enum {
  CACHE_INTEGRALS, /* 1 when T, Ue, p_theta are the key state's */
  CACHE_T,
  CACHE_UE,
  CACHE_PTHETA,
  CACHE_GRAVITY, /* 1 when Ug is the key state's, for the gravity in CACHE_G0, CACHE_G1 */
  CACHE_G0,
  CACHE_G1,
  CACHE_UG,
  CACHE_IPP, /* with CACHE_INTEGRALS: the coupling integrals over the whole beam (beam_integrals) */
  CACHE_IPV,
  CACHE_DEFORMATION, /* 1 when the axial u, ud at x = CACHE_X (coupling included) are the key state's */
  CACHE_X,
  CACHE_U0,
  CACHE_UD0,
  CACHE_KEY /* then q and v (3 + n each) */
};
static size_t output_cache_nwork(const Beam* b) { return CACHE_KEY + 2 * (size_t)(3 + b->n); }

/* the cache in work for the state (q, v): its entries dropped when the state is another one;
   NULL without work (beam_model_range's call) */
static double* output_cache(const Beam* b, const double* q, const double* v, double* work) {
  if (!work) return NULL;
  double* cache = work + output_cache_at(b);
  const size_t nc = (size_t)(3 + b->n), bytes = sizeof(double) * nc;
  double* key = cache + CACHE_KEY;
  if (memcmp(key, q, bytes) != 0 || memcmp(key + nc, v, bytes) != 0) {
    memcpy(key, q, bytes);
    memcpy(key + nc, v, bytes);
    cache[CACHE_INTEGRALS] = cache[CACHE_GRAVITY] = cache[CACHE_DEFORMATION] = 0.0;
  }
  return cache;
}

/* beam_integrals through the cache: T, Ue and p_theta do not depend on gravity, Ug does (env NULL:
   no gravity, Ug = 0) */
static void integrals_cached(const Beam* b, const fmbEnv* env, const double* q, const double* v, fmbEnergy* en,
                             double* ptheta, double* work) {
  double* cache = output_cache(b, q, v, work);
  const int grav = env && env->has_gravity;
  const double g0 = grav ? env->gravity[0] : 0.0, g1 = grav ? env->gravity[1] : 0.0;
  if (cache && cache[CACHE_INTEGRALS] == 1.0 &&
      (!en || (cache[CACHE_GRAVITY] == 1.0 && cache[CACHE_G0] == g0 && cache[CACHE_G1] == g1))) {
    if (en) {
      en->kinetic = cache[CACHE_T];
      en->strain = cache[CACHE_UE];
      en->gravity = cache[CACHE_UG];
      en->spring = 0.0;
    }
    if (ptheta) *ptheta = cache[CACHE_PTHETA];
    return;
  }
  fmbEnergy local;
  double pth, coupling_total[2];
  if (!en) en = &local;
  beam_integrals(b, grav ? env : NULL, q, v, en, &pth, coupling_total);
  if (ptheta) *ptheta = pth;
  if (!cache) return;
  cache[CACHE_INTEGRALS] = cache[CACHE_GRAVITY] = 1.0;
  cache[CACHE_T] = en->kinetic;
  cache[CACHE_UE] = en->strain;
  cache[CACHE_PTHETA] = pth;
  cache[CACHE_G0] = g0;
  cache[CACHE_G1] = g1;
  cache[CACHE_UG] = en->gravity;
  cache[CACHE_IPP] = coupling_total[0];
  cache[CACHE_IPV] = coupling_total[1];
}

static void beam_energy(const void* self, const fmbEnv* env, const double* q, const double* v, fmbEnergy* en,
                        double* work) {
  integrals_cached(self, env, q, v, en, NULL, work);
}

/* ---------------------------------------------------------------------------------------------
 * Outputs.
 * ------------------------------------------------------------------------------------------- */
enum {
  OUT_TIP_U = FMB_BEAM_TIP_U,
  OUT_TIP_V = FMB_BEAM_TIP_V,
  OUT_TIP_U_RATE = FMB_BEAM_TIP_U_RATE,
  OUT_TIP_V_RATE = FMB_BEAM_TIP_V_RATE,
  OUT_TIP_X = FMB_BEAM_TIP_X,
  OUT_TIP_Y = FMB_BEAM_TIP_Y,
  OUT_ANG_MOMENTUM = FMB_BEAM_ANG_MOMENTUM,
  OUT_TIP_ANGLE = FMB_BEAM_TIP_ANGLE,
  OUT_NTIP = FMB_BEAM_NTIP
};
enum { OUT_NODE_BASE = FMB_BEAM_NODE_BASE, OUT_NODE_STRIDE = FMB_BEAM_NODE_STRIDE };

static int beam_output_lookup(const void* self, const char* quantity) {
  return fmb_beam_output_lookup(((const Beam*)self)->ne, quantity);
}

/* axial (with w_c in coupled models, when `axial`) and transverse deformation at reference (x, 0),
   rates. The transverse ones need no coupling integral (beam.tip_v, and beam_model_range's check
   after every advance); the axial ones come through the cache (work, may be NULL). */
static void deformation_at(const Beam* b, const double* q, const double* v, double x, int axial, double u[2],
                           double ud[2], double* work) {
  const double *p = q + 3, *pd = v + 3;
  int e;
  double xi, ua[2], d[4], uda[2], dd[4], ns[4];
  locate(b, x, &e, &xi);
  gather(p, e, ua, d);
  gather(pd, e, uda, dd);
  hermite(xi, b->le, ns, NULL);
  u[0] = (1.0 - xi) * ua[0] + xi * ua[1];
  u[1] = dot4(ns, d);
  ud[0] = (1.0 - xi) * uda[0] + xi * uda[1];
  ud[1] = dot4(ns, dd);
  if (axial && b->model != BEAM_ZOAC && x > 0.0) {
    double* cache = output_cache(b, q, v, work);
    if (cache && cache[CACHE_DEFORMATION] == 1.0 && cache[CACHE_X] == x) {
      u[0] = cache[CACHE_U0];
      ud[0] = cache[CACHE_UD0];
      return;
    }
    double wc, wcd;
    if (cache && cache[CACHE_INTEGRALS] == 1.0 && e == b->ne - 1 && xi == 1.0) {
      /* the tip: coupling_at's sums over every element with the whole element's weights, which
         the energy pass of this state has made in the same order (bit for bit) */
      wc = -0.5 * cache[CACHE_IPP];
      wcd = -cache[CACHE_IPV];
    } else {
      coupling_at(b, p, pd, e, xi, &wc, &wcd);
    }
    u[0] += wc;
    ud[0] += wcd;
    if (cache) {
      cache[CACHE_DEFORMATION] = 1.0;
      cache[CACHE_X] = x;
      cache[CACHE_U0] = u[0];
      cache[CACHE_UD0] = ud[0];
    }
  }
}

static int beam_output(const void* self, int id, const double* q, const double* v, double* value, double* work) {
  const Beam* b = self;
  double x = b->L;
  int comp = id;
  if (id >= OUT_NODE_BASE) {
    int k = (id - OUT_NODE_BASE) / OUT_NODE_STRIDE;
    x = k * b->le;
    comp = (id - OUT_NODE_BASE) % OUT_NODE_STRIDE; /* u, v, x, y */
    comp = comp == 0 ? OUT_TIP_U : comp == 1 ? OUT_TIP_V : comp == 2 ? OUT_TIP_X : OUT_TIP_Y;
  } else if (id < 0 || id >= OUT_NTIP) {
    return -1;
  } else if (id == OUT_ANG_MOMENTUM) {
    integrals_cached(b, NULL, q, v, NULL, value, work);
    return 0;
  } else if (id == OUT_TIP_ANGLE) {
    const double tip[2] = {b->L, 0.0};
    double pos[2], angle;
    if (beam_marker(b, q, tip, pos, &angle, NULL, NULL, work)) return -1;
    *value = angle - q[2];
    return 0;
  }
  double u[2], ud[2];
  deformation_at(b, q, v, x, comp != OUT_TIP_V && comp != OUT_TIP_V_RATE, u, ud, work);
  switch (comp) {
    case OUT_TIP_U: *value = u[0]; break;
    case OUT_TIP_V: *value = u[1]; break;
    case OUT_TIP_U_RATE: *value = ud[0]; break;
    case OUT_TIP_V_RATE: *value = ud[1]; break;
    case OUT_TIP_X: *value = q[0] + cos(q[2]) * (x + u[0]) - sin(q[2]) * u[1]; break; /* the frame's angle only here */
    default: *value = q[1] + sin(q[2]) * (x + u[0]) + cos(q[2]) * u[1]; break;
  }
  return 0;
}

/* The range where each model is accurate, from its measured error against the exact beam
   (docs/models.md, "Each model's range"). Error = the largest |tip_v - exact| over a run relative
   to the exact peak deflection; d = the model's own peak |tip_v| / L (what the run sees):
     complete: 0.01 % at d = 1.0 % (paper spin-up w0 = 1), 0.14 % at 3.9 % (w0 = 4), 1.9 % at 10.9 %
               (w0 = 15), 4.3 % at 17.0 % (the rotor starter, w0 = 6 over 5 s), 46 % at 43 % (the
               same at w0 = 15): error ~ d^2.5;
     FOAC:     0.05 % at 3.9 %, 0.31 % at 10.9 %, 4.3 % at 36.6 % (starter at w0 = 15), 6.3 % at
               45.7 % (w0 = 20).
   The limit is the deflection where the error reaches 5 % of the deflection, interpolated between
   the two measured points around it: 18 % of L for complete (and ZOAC, whose kinematics are the
   same), 40 % for FOAC. The paper's cases (at most 10.9 %) and the starter (17.0 %) lie inside.
   ZOAC has no centrifugal stiffening: 4 % off at w0 = 1, a quarter of its first clamped bending
   frequency w1; with the stiffening it lacks growing like w^2 the error reaches ~5 % near 0.3 w1,
   and the beam diverges at w1. */
static double beam_first_frequency(const Beam* b) {
  return 1.8751040687119611 * 1.8751040687119611 * sqrt(b->Emod * b->Izz / (b->rho * b->A)) / (b->L * b->L);
}
static double beam_deflection_limit(const Beam* b) { return b->model == BEAM_FOAC ? 0.40 : 0.18; }
enum { ZOAC_SPIN_LIMIT_PERCENT = 30 };

static const char* beam_model_range(const void* self, const double* q, const double* v, char* msg, size_t len) {
  const Beam* b = self;
  double tip = 0.0;
  beam_output(b, OUT_TIP_V, q, v, &tip, NULL);
  const double limit = beam_deflection_limit(b), w1 = beam_first_frequency(b);
  if (fabs(tip) > limit * b->L) {
    snprintf(msg, len,
             "its tip deflects %.3g m, %.1f %% of its length, beyond the %.0f %% up to which the %s model stays within "
             "about 5 %% of the geometrically exact beam (docs/models.md); use `model: exact`",
             fabs(tip), 100.0 * fabs(tip) / b->L, 100.0 * limit, model_names[b->model]);
    return msg;
  }
  if (b->model == BEAM_ZOAC && fabs(v[2]) > 0.01 * ZOAC_SPIN_LIMIT_PERCENT * w1) {
    snprintf(msg, len,
             "it turns at %.3g rad/s, %.0f %% of its first bending frequency %.3g rad/s: ZOAC has no centrifugal "
             "stiffening, is off by more than about 5 %% beyond %d %% and diverges at 100 %% (docs/models.md); use "
             "`model: complete` or `model: exact`",
             fabs(v[2]), 100.0 * fabs(v[2]) / w1, w1, ZOAC_SPIN_LIMIT_PERCENT);
    return msg;
  }
  return NULL;
}

static void beam_describe(const void* self, FILE* f) {
  const Beam* b = self;
  static const char* const terms[] = {"w_c dropped (no coupling deformation)",
                                      "w_c to first order (rigid x coupling products only)",
                                      "w_c and all its high-order terms kept"};
  fprintf(f, "%s model, %d elements, %d Gauss points/element, %s%s, %s assembly", model_names[b->model], b->ne, b->ng,
          terms[b->model], b->beta > 0.0 ? ", stiffness-proportional damping" : "",
          b->banded ? "banded (coupling sums as auxiliary unknowns)" : "dense");
  /* its range (beam_model_range): the run warns when it is left */
  fprintf(f, "; accurate while the tip deflects less than %.0f %% of the length (%.3g m)",
          100.0 * beam_deflection_limit(b), beam_deflection_limit(b) * b->L);
  if (b->model == BEAM_ZOAC)
    fprintf(f, " and it turns slower than %d %% of its first bending frequency (%.3g rad/s)", ZOAC_SPIN_LIMIT_PERCENT,
            0.01 * ZOAC_SPIN_LIMIT_PERCENT * beam_first_frequency(b));
  if (b->model == BEAM_FOAC) fprintf(f, ", under prescribed rotation only");
  fputc('\n', f);
}

static const char* beam_indefinite_mass(const void* self) {
  const Beam* b = self;
  if (b->model != BEAM_FOAC) return NULL;
  return "the FOAC beam's kinetic energy is not positive definite: with its angle free (a pendulum, a free beam) "
         "its mass matrix loses definiteness once the deflection exceeds a few tenths of a percent of the length, "
         "less on finer meshes (it keeps -p^T D p in M22 without the high-order terms that balance it); use "
         "`model: complete` (FOAC is usable only under prescribed rotation)";
}

/* Undamped axial and bending modes up to ~1e5 rad/s: only A-stable BDF (order <= 2) steps over
   them without the error test chasing modes that orders 3-5 amplify. */
static int beam_max_bdf_order(const void* self) {
  (void)self;
  return 2;
}

/* A small-strain finite-element beam whose nodal displacement exceeds its own length is no longer
   a beam: the solution is running away (ZOAC above the first bending frequency). */
static const char* beam_invalid_state(const void* self, const double* q, const double* v) {
  (void)v;
  const Beam* b = self;
  for (int i = 0; i < b->ne; ++i)
    if (!(fabs(q[3 + 3 * i]) <= b->L && fabs(q[3 + 3 * i + 1]) <= b->L))
      return b->model == BEAM_ZOAC
                 ? "its deformation exceeds its length: the solution is diverging. ZOAC has no dynamic stiffening and "
                   "is unstable when spun above its first bending frequency; use model: foac or complete"
                 : "its deformation exceeds its length: the beam has left the range of this model (a floating frame "
                   "with small strains), whether the loads are too large for it or the motion is unstable. Check the "
                   "loads and parameters; a stiffer beam or gentler loading stays in range";
  return NULL;
}

/* Any sudden load rings every undamped mode up to ~1e5 rad/s; their velocities, not their
   displacements, would then set the step (the pendulum: 459k against 8.3k steps per simulated
   second). Smooth, prescribed motions may ask for `error_control: full` (docs/performance.md). */
static int beam_velocity_error_test(const void* self) {
  (void)self;
  return 0;
}

/* the `model:` words of type beam: this file's three, and `exact` (bodies/beam_exact.c) */
static const char* const all_models[] = {"zoac", "foac", "complete", "exact", NULL};
/* `jacobian:` the analytic K, C, M (default) or the engine's differences of the residual */
static const char* const jacobian_names[] = {"analytic", "differences", NULL};

/* the keys of type beam, whichever file reads them (beam_modal.c's table declares these too) */
const fmbParam fmb_beam_params[] = {
    FMB_BEAM_SECTION_PARAMS(MAX_ELEMENTS),
    {.key = "model",
     .kind = FMB_PARAM_CHOICE,
     .fallback = "complete",
     .choices = all_models,
     .doc = "coupling deformation kept in full, to first order, or left out (docs/beam.md); exact: the "
            "geometrically exact beam (docs/models.md)"},
    FMB_BEAM_FRAME_PARAMS,
    {.key = "damping",
     .kind = FMB_PARAM_NUMBER,
     .flags = FMB_NONNEGATIVE,
     .unit = "s",
     .fallback = "0",
     .doc = "stiffness-proportional (Kelvin-Voigt) damping time beta: forces K (p + beta dp/dt)"},
    {.key = "quadrature_points",
     .kind = FMB_PARAM_INT,
     .unit = "1",
     .fallback = "6 (complete), 4 (foac, zoac)",
     .lo = 4,
     .hi = FMB_GAUSS_MAX,
     .doc = "Gauss points per element, at least the default (fewer under-integrate the model)"},
    {.key = "integration",
     .kind = FMB_PARAM_CHOICE,
     .fallback = "reduced",
     .choices = integration_names,
     .doc = "model: exact, kinematics: cable: axial term at 3 Lobatto, bending at 2 Gauss points (reduced), or 5 "
            "and 3 (full); the other models ignore it"},
    {.key = "assembly",
     .kind = FMB_PARAM_CHOICE,
     .fallback = "auto",
     .choices = assembly_names,
     .doc = "dense, or banded: the coupling sums as auxiliary unknowns, O(n) per step (auto: banded from 64 elements)"},
    {.key = "axial_form",
     .kind = FMB_PARAM_CHOICE,
     .fallback = "mixed",
     .choices = axial_form_names,
     .doc = "model: exact, kinematics: cable: the axial strains as unknowns Newton iterates on (mixed), or the "
            "displacement form before it (to compare); the other models ignore it"},
    {.key = "kinematics",
     .kind = FMB_PARAM_CHOICE,
     .fallback = "intrinsic",
     .choices = kinematics_names,
     .doc = "model: exact: axial strain and tangent angle along the beam (intrinsic: constant stiffness, "
            "bodies/beam_intrinsic.c), or nodal positions and slopes (cable); the other models refuse it"},
    FMB_BEAM_REDUCTION_PARAM,
    {.key = "jacobian",
     .kind = FMB_PARAM_CHOICE,
     .fallback = "analytic",
     .choices = jacobian_names,
     .doc = "analytic K, C, M, or differences: the engine differences the residual (to compare the two; "
            "models complete, foac, zoac without reduction)"},
    {.key = NULL},
};

static int beam_centreline(const void* self, int n, double* local) {
  const Beam* b = self;
  return fmb_beam_centreline(b->L, b->ne, n, local);
}

/* `model: exact` (the geometrically exact beam) is its own implementation behind the same type
   name: bodies/beam_exact.c. The other three models are this file's.
   `jacobian: differences` hands the item the table without the analytic Jacobians (beam_fd), so
   the engine differences the residual as before them: for comparing the two
   (test_beam_jacobian_run, bench/beam_jacobian.sh). */
extern const fmbBodyType fmb_body_beam_exact;
static const fmbBodyType beam_fd;
static const fmbBodyType* beam_variant(fmbParser* p, fmbNode item) {
  extern const fmbBodyType fmb_body_beam;
  /* `dimension: 3`: the spatial beam (bodies/beam3d.c); exact and the modal reduction are planar */
  extern const fmbBodyType fmb_body_beam3d;
  if (fmb_scene_dimension(p) == 3) {
    const char* const planar_only[] = {"reduction", "jacobian"};
    int model = BEAM_COMPLETE;
    if (fmb_get_choice(p, item, "model", FMB_OPTIONAL, all_models, &model)) return NULL;
    if (model == 3) {
      fmb_parse_error(p, fmb_find_key(p, item, "model"),
                      "model: exact is planar only for now; a spatial beam (dimension: 3) is complete, foac or zoac");
      return NULL;
    }
    for (int k = 0; k < 2; ++k)
      if (fmb_find_key(p, item, planar_only[k]) >= 0) {
        fmb_parse_error(p, fmb_find_key(p, item, planar_only[k]),
                        "'%s' is planar only for now (a spatial beam, dimension: 3, is the full mesh with the "
                        "engine's differenced Jacobian)",
                        planar_only[k]);
        return NULL;
      }
    return &fmb_body_beam3d;
  }
  int model = BEAM_COMPLETE, differences = 0;
  if (fmb_get_choice(p, item, "model", FMB_OPTIONAL, all_models, &model) ||
      fmb_get_choice(p, item, "jacobian", FMB_OPTIONAL, jacobian_names, &differences))
    return NULL;
  /* `reduction: {modes: k}`: the same beam in k of its own clamped-free modes (bodies/beam_modal.c) */
  extern const fmbBodyType fmb_body_beam_modal;
  const int reduced = fmb_find_key(p, item, "reduction") >= 0;
  if (differences && (model == 3 || reduced)) {
    fmb_parse_error(p, fmb_find_key(p, item, "jacobian"),
                    "jacobian: differences is for the complete, foac and zoac models without reduction");
    return NULL;
  }
  /* `kinematics: intrinsic` (model: exact only): the same continuum in strain and angle
     coordinates, bodies/beam_intrinsic.c */
  extern const fmbBodyType fmb_body_beam_intrinsic;
  if (model == 3) {
    int intrinsic = 1; /* the default since issue 32 item 4: a healthy Newton iteration (docs/models.md) */
    if (fmb_get_choice(p, item, "kinematics", FMB_OPTIONAL, kinematics_names, &intrinsic)) return NULL;
    return intrinsic ? &fmb_body_beam_intrinsic : &fmb_body_beam_exact;
  }
  if (fmb_find_key(p, item, "kinematics") >= 0) { /* not read: the other models' key lists stay as they were */
    fmb_parse_error(p, fmb_find_key(p, item, "kinematics"), "'kinematics' is for model: exact (cable or intrinsic)");
    return NULL;
  }
  if (reduced) return &fmb_body_beam_modal;
  return differences ? &beam_fd : &fmb_body_beam;
}

/* a spatial item is always beam3d.c's (beam_variant), so the table's marker3 is its */
int fmb_beam3d_marker3(const void* self, const double* q, const double local[3], double pos[3], double R[9],
                       double* dpos, double* rot, int ld, double* work);
/* the ops of both tables below (fmb_body_beam and beam_fd) */
#define BEAM_OPS                                                                                                     \
  .name = "beam", .abi = FMB_ABI_VERSION, .parse = beam_parse, .destroy = beam_destroy, .ncoord = beam_ncoord,       \
  .initial = beam_initial, .residual = beam_residual, .marker = beam_marker, .nwork = beam_nwork,                    \
  .energy = beam_energy, .output_names = fmb_beam_output_names, .output_units = fmb_beam_output_units,               \
  .output_lookup = beam_output_lookup, .output = beam_output, .describe = beam_describe,                             \
  .indefinite_mass = beam_indefinite_mass, .max_bdf_order = beam_max_bdf_order, .invalid_state = beam_invalid_state, \
  .velocity_error_test = beam_velocity_error_test, .params = fmb_beam_params,                                        \
  .example = "length: 1\nelements: 2\ndensity: 1000\narea: 1e-3\nsecond_moment: 1e-7\nyoungs_modulus: 1e6\n"         \
             "angular_velocity: 3\nvelocity: [0.2, 0.5]\n",                                                          \
  .example_damped = "damping: 0.05\n", .centreline = beam_centreline, .variant = beam_variant, .naux = beam_naux,    \
  .residual_aux = beam_residual_aux, .aux_initial = beam_aux_initial, .pattern = beam_pattern,                       \
  .model_range = beam_model_range, .dimensions = FMB_DIM_PLANAR | FMB_DIM_SPATIAL, .marker3 = fmb_beam3d_marker3

const fmbBodyType fmb_body_beam = {BEAM_OPS, .jacobian = beam_jacobian, .pattern_jacobian = beam_pattern_jacobian};
static const fmbBodyType beam_fd = {BEAM_OPS};
