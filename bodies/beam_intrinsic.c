/*
 * beam_intrinsic.c — `type: beam`, `model: exact`, `kinematics: intrinsic`: the same continuum as
 * bodies/beam_exact.c (the planar extensible elastica without shear, in the floating frame) in
 * intrinsic coordinates: the axial strain and the tangent's angle along the beam instead of
 * nodal positions and slopes (docs/models.md, "Intrinsic kinematics").
 *
 * Why: with rho'(s) = (1 + eps(s)) e(phi(s)), e(phi) = (cos phi, sin phi), one has exactly
 *     |rho'| - 1 = eps,   rho' x rho'' / |rho'|^2 = phi',
 * so U = 1/2 int (EA eps^2 + EI phi'^2) ds is QUADRATIC in the coordinates and the stiffness is
 * constant, as in the complete model. In the cable's coordinates EA's stiff direction turns with
 * the slope, and a frozen Newton matrix is wrong by ~EA dphi (issue 32 item 4, the hypothesis
 * this file tests). All the nonlinearity moves into the inertia (positions are integrals).
 *
 * Coordinates q = [x, y, theta, eps_0, kappa_0, (eps_i, phi_i, kappa_i) for nodes i = 1..ne]:
 * eps linear between nodes (C0; its energy has no derivative of eps), phi cubic Hermite from the
 * nodal (phi_i, kappa_i = phi'_i) (C1: the curvature is continuous, as the cable's). The root is
 * clamped to the frame: phi_0 = 0, with the root stretch eps_0 and root curvature kappa_0 free (as
 * beam_exact.c's free root stretch a). So x, y, theta are the root's position and tangent, as in
 * every beam model, and joints, drives and outputs see the same frame.
 *
 * Kinematics in the frame: rho(s) = int_0^s rho'(s') ds', its rates from
 *     rho'_t  = epsdot e + (1 + eps) phidot e_perp,
 *     rho'_tt = epsddot e + 2 epsdot phidot e_perp + (1 + eps)(phiddot e_perp - phidot^2 e),
 * and a_b = A^T r0'' + theta'' I~rho - theta'^2 rho + 2 theta' I~rho_t + rho_tt (beam_exact.c's).
 * The integrals sample rho' (and its rates) at nq = 6 Gauss points of each element only (6
 * sin/cos per element): the element's increment rho(s_e+1) - rho(s_e) is their Gauss sum (exact to
 * degree 11 in xi), and a mass point's position at s_e + x_g le integrates over [s_e, s_e + x_g le]
 * the degree-5 polynomial through the 6 samples (weights W[g][m] = int_0^x_g l_m, a collocation
 * rule as Radau's stage matrix). Checked against 10 points and against 4-point Gauss on every
 * sub-interval (20 samples per element, the first version): the pendulum's first 0.5 s at rtol
 * 1e-10 differs by 1.3e-8 and 1.0e-8 m (its time error's size), the w15 spin-up (16 el., rtol
 * 1e-9) by 1.0e-9 and 1.8e-9 m; 4 points instead of 6 would be 4.5e-8 m on the pendulum.
 * The discrete positions rho_g(q) ARE the model: the residual is the exact virtual work of
 * T = 1/2 sum_g w_g mu |v_g|^2 with these positions, so energy is conserved as for any
 * Lagrangian discretization (its drift falls with the tolerance: 1.9e-7, 1.0e-7, 9e-10 J at rtol
 * 3e-7, 1e-8, 1e-10 on the pendulum's first 0.2 s).
 *
 * Residual: R_j = sum_g w_g mu (d rho_g/d q_j) . F_g + dU/dq_j, F = a_b - f_b. Swapping the sums
 * (d rho_g/dq_j is a sum of d rho'/dq_j over the samples), R_j = le sum_m (d rho'/dq_j)(s_m) . G_m
 * with G_m = w_m S + sum_g W[g][m] w_g mu F_g, S the sum of w_g mu F_g over the elements beyond
 * (their positions contain this element's increment). O(ne) per residual: one forward pass
 * (positions, F) and one backward (suffix sums).
 * Mass points: 4 Gauss per element (as beam_exact.c); the strain energy is a quartic in xi, exact
 * at those 4 points. The Jacobian is the engine's differences (engine/fd.c), dense.
 */
#include <math.h>
#include <stdlib.h>
#include <string.h>

#include "beam_section.h"
#include "flexmbd_plugin.h"

enum { INTRINSIC_MAX_ELEMENTS = 4096, INTRINSIC_MAX_POINTS = 10 };
#ifndef INTRINSIC_NESTED_POINTS
#define INTRINSIC_NESTED_POINTS 6
#endif

typedef struct BeamIntrinsic {
  double L, rho, A, Izz, Emod;
  int ne;
  double pos0[2], angle0, vel0[2], omega0;
  /* derived */
  double le, mu, EA, EI;
  int n;                                                     /* deformation coordinates 2 + 3 ne */
  int nq, nm;                                                /* nested rule, mass rule (points per element) */
  double xq[INTRINSIC_MAX_POINTS], wq[INTRINSIC_MAX_POINTS]; /* nested rule on [0, 1] */
  double xm[INTRINSIC_MAX_POINTS], wm[INTRINSIC_MAX_POINTS]; /* mass points on [0, 1] */
  /* the shape weights (shape6) at the nested points and at the mass points (with their
     s-derivatives), the same in every element; and the mass points' integration weights W[g][m]
     = int_0^x_g l_m (l_m: the Lagrange polynomial of nested point m) */
  double sh_nest[INTRINSIC_MAX_POINTS][6], sh_mass[4][6], dsh_mass[4][6], W[4][INTRINSIC_MAX_POINTS];
} BeamIntrinsic;

static void shape6(double xi, double le, double w[6], double dw[6]);

/* W[m] = int_0^span l_m(xi) dxi over the Lagrange basis of the nq nested points (nq-point Gauss
   on [0, span] is exact for the degree nq - 1 polynomial); at span = 1 these are the Gauss weights */
static void span_weights(const BeamIntrinsic* b, double span, double W[INTRINSIC_MAX_POINTS]) {
  for (int m = 0; m < b->nq; ++m) {
    W[m] = 0.0;
    for (int k = 0; k < b->nq; ++k) {
      const double xi = span * b->xq[k];
      double l = 1.0;
      for (int j = 0; j < b->nq; ++j)
        if (j != m) l *= (xi - b->xq[j]) / (b->xq[m] - b->xq[j]);
      W[m] += span * b->wq[k] * l;
    }
  }
}

static void intrinsic_setup(BeamIntrinsic* b, int nested_points) {
  b->le = b->L / b->ne;
  b->mu = b->rho * b->A;
  b->EA = b->Emod * b->A;
  b->EI = b->Emod * b->Izz;
  b->n = 2 + 3 * b->ne;
  b->nq = nested_points;
  b->nm = 4;
  fmb_gauss_legendre01(b->nq, b->xq, b->wq);
  fmb_gauss_legendre01(b->nm, b->xm, b->wm);
  for (int m = 0; m < b->nq; ++m) shape6(b->xq[m], b->le, b->sh_nest[m], NULL);
  for (int g = 0; g < b->nm; ++g) {
    shape6(b->xm[g], b->le, b->sh_mass[g], b->dsh_mass[g]);
    span_weights(b, b->xm[g], b->W[g]);
  }
}

/* Element dofs: local l = 3 k + f (k: node e or e+1; f: 0 eps, 1 phi, 2 kappa). Index in q, or -1
   for the clamped root angle phi_0. */
static int idof(int e, int l) {
  const int node = e + (l >= 3), f = l % 3;
  if (node == 0) return f == 0 ? 3 : f == 2 ? 4 : -1;
  return 5 + 3 * (node - 1) + f;
}

/* weights of the element's six dofs at xi in their field (eps: linear; phi: Hermite with the
   slope weights carrying le) and, for phi, their s-derivatives (phi' = kappa) */
static void shape6(double xi, double le, double w[6], double dw[6]) {
  double ns[4], nd[4];
  fmb_beam_hermite(xi, le, ns, nd);
  w[0] = 1.0 - xi, w[1] = ns[0], w[2] = ns[1], w[3] = xi, w[4] = ns[2], w[5] = ns[3];
  if (dw) dw[0] = -1.0 / le, dw[1] = nd[0], dw[2] = nd[1], dw[3] = 1.0 / le, dw[4] = nd[2], dw[5] = nd[3];
}

static void element_dofs(const double* x, int e, double X[6]) {
  for (int l = 0; l < 6; ++l) {
    const int i = idof(e, l);
    X[l] = i >= 0 ? x[i] : 0.0;
  }
}

/* eps and phi (and phi' when asked) from the element's dof values X at weights w (dw) */
static void fields(const double w[6], const double* dw, const double X[6], double* eps, double* phi, double* dphi) {
  *eps = w[0] * X[0] + w[3] * X[3];
  *phi = w[1] * X[1] + w[2] * X[2] + w[4] * X[4] + w[5] * X[5];
  if (dphi) *dphi = dw[1] * X[1] + dw[2] * X[2] + dw[4] * X[4] + dw[5] * X[5];
}

/* rho', rho'_t, rho'_tt at one point (any may be NULL but rp) */
static void tangent_terms(const double w[6], const double X[6], const double* Xd, const double* Xdd, double rp[2],
                          double* rpt, double* rptt, double* cache) {
  double eps, phi, ed = 0.0, pd = 0.0, edd = 0.0, pdd = 0.0;
  fields(w, NULL, X, &eps, &phi, NULL);
  if (Xd) fields(w, NULL, Xd, &ed, &pd, NULL);
  if (Xdd) fields(w, NULL, Xdd, &edd, &pdd, NULL);
  const double c = cos(phi), s = sin(phi), st = 1.0 + eps;
  if (cache) cache[0] = c, cache[1] = s, cache[2] = st;
  rp[0] = st * c, rp[1] = st * s;
  if (rpt) rpt[0] = ed * c - st * pd * s, rpt[1] = ed * s + st * pd * c;
  if (rptt) {
    const double along = edd - st * pd * pd, across = 2.0 * ed * pd + st * pdd;
    rptt[0] = along * c - across * s;
    rptt[1] = along * s + across * c;
  }
}

/* rho', rho'_t, rho'_tt (rpt, rptt may be NULL) at the element's nq nested points; cache: NULL or
   3 nq doubles for cos phi, sin phi, 1 + eps there (add_tangent_work reuses them) */
static void element_tangents(const BeamIntrinsic* b, const double X[6], const double* Xd, const double* Xdd,
                             double (*rp)[2], double (*rpt)[2], double (*rptt)[2], double* cache) {
  for (int m = 0; m < b->nq; ++m)
    tangent_terms(b->sh_nest[m], X, Xd, Xdd, rp[m], rpt ? rpt[m] : NULL, rptt ? rptt[m] : NULL,
                  cache ? cache + 3 * m : NULL);
}

/* le sum_m W[m] f[m]: the integral over [0, span] of the field f sampled at the nested points */
static void integrate_points(const BeamIntrinsic* b, const double* W, const double (*f)[2], double d[2]) {
  d[0] = d[1] = 0.0;
  for (int m = 0; m < b->nq; ++m) d[0] += W[m] * f[m][0], d[1] += W[m] * f[m][1];
  d[0] *= b->le, d[1] *= b->le;
}

/* R_j += wl (d rho'/d q_j) . G over the element's dofs at a point of shape weights w, where
   cs = (cos phi, sin phi, 1 + eps): d rho'/d eps-dof = N e, d rho'/d phi-dof = (1 + eps) H e_perp */
static void add_tangent_work(int e, const double w[6], const double cs[3], double wl, const double G[2], double* R) {
  const double c = cs[0], s = cs[1];
  const double along = wl * (c * G[0] + s * G[1]), across = wl * cs[2] * (-s * G[0] + c * G[1]);
  for (int l = 0; l < 6; ++l) {
    const int i = idof(e, l);
    if (i >= 0) R[i] += w[l] * (l % 3 == 0 ? along : across);
  }
}

/* ---------------------------------------------------------------------------------------------
 * Parse (the keys of beam_exact.c's cable that apply; `kinematics: intrinsic` brought us here).
 * ------------------------------------------------------------------------------------------- */
static const char* const intrinsic_models[] = {"zoac", "foac", "complete", "exact", NULL}; /* as beam.c's */
static const char* const intrinsic_kinematics[] = {"cable", "intrinsic", NULL};            /* as beam.c's */

/* the cable's choices (beam.c's), declared here only to be refused by name */
static const char* const refused_integrations[] = {"reduced", "full", NULL};
static const char* const refused_assemblies[] = {"auto", "dense", "banded", NULL};
static const char* const refused_axial_forms[] = {"mixed", "displacement", NULL};
/* keys of type beam this form refuses, with the reason. One list each: the params table below
   declares them (so `types` and conform look them up) and intrinsic_parse refuses each of them.
   The exact beam has neither of the first two in either kinematics ... */
#define INTRINSIC_REFUSED_PARAMS                                                                                     \
  {.key = "damping", .kind = FMB_PARAM_NUMBER, .flags = FMB_NONNEGATIVE, .unit = "s", .doc = "refused: undamped"}, { \
    .key = "quadrature_points", .kind = FMB_PARAM_INT, .unit = "1", .lo = 1, .hi = FMB_GAUSS_MAX,                    \
    .doc = "refused: its rules are fixed (the cable's are chosen by `integration`)"                                  \
  }
/* ... and these three are the cable's (bodies/beam_exact.c) */
#define INTRINSIC_CABLE_PARAMS                                                                                      \
  {.key = "integration", .kind = FMB_PARAM_CHOICE, .choices = refused_integrations, .doc = "refused: the cable's"}, \
      {.key = "assembly", .kind = FMB_PARAM_CHOICE, .choices = refused_assemblies, .doc = "refused: dense"}, {      \
    .key = "axial_form", .kind = FMB_PARAM_CHOICE, .choices = refused_axial_forms, .doc = "refused: the cable's"    \
  }
static const fmbParam intrinsic_refused[] = {INTRINSIC_REFUSED_PARAMS, {.key = NULL}};
static const fmbParam intrinsic_cable_only[] = {INTRINSIC_CABLE_PARAMS, {.key = NULL}};
static const fmbParam intrinsic_params[] = {
    FMB_BEAM_SECTION_PARAMS(INTRINSIC_MAX_ELEMENTS),
    {.key = "model", .kind = FMB_PARAM_CHOICE, .fallback = "exact", .choices = intrinsic_models, .doc = "exact here"},
    {.key = "kinematics",
     .kind = FMB_PARAM_CHOICE,
     .fallback = "intrinsic",
     .choices = intrinsic_kinematics,
     .doc = "intrinsic here (model: exact's default): axial strain and tangent angle along the beam (constant "
            "stiffness)"},
    FMB_BEAM_FRAME_PARAMS,
    INTRINSIC_REFUSED_PARAMS,
    INTRINSIC_CABLE_PARAMS,
    {.key = NULL},
};

static int intrinsic_parse(fmbParser* p, fmbNode item, void** self) {
  BeamIntrinsic* b = calloc(1, sizeof *b);
  if (!b) return fmb_parse_error(p, item, "out of memory");
  int model = 3, kinematics = 1, err = 0;
  err |= fmb_beam_read_section(p, item, INTRINSIC_MAX_ELEMENTS, &b->L, &b->ne, &b->rho, &b->A, &b->Izz, &b->Emod);
  err |= fmb_get_choice(p, item, "model", FMB_OPTIONAL, intrinsic_models, &model);
  err |= fmb_get_choice(p, item, "kinematics", FMB_OPTIONAL, intrinsic_kinematics, &kinematics);
  err |= fmb_beam_read_frame(p, item, b->pos0, &b->angle0, b->vel0, &b->omega0);
  for (const fmbParam* k = intrinsic_refused; k->key && !err; ++k)
    if (fmb_find_key(p, item, k->key) >= 0)
      err = fmb_parse_error(p, fmb_find_key(p, item, k->key),
                            "'%s' is not available with model: exact (%s); remove the key", k->key, k->doc);
  /* the cable's keys: refused by name, whether `kinematics: intrinsic` was written or is the default
     (so a scene written for the cable does not silently change physics: it says how to keep it) */
  const int written = fmb_find_key(p, item, "kinematics") >= 0;
  for (const fmbParam* k = intrinsic_cable_only; k->key && !err; ++k)
    if (fmb_find_key(p, item, k->key) >= 0)
      err = fmb_parse_error(
          p, fmb_find_key(p, item, k->key),
          "'%s' is only with kinematics: cable, %s (its quadrature is fixed, its Jacobian dense by "
          "differences: docs/models.md); %s",
          k->key, written ? "not intrinsic" : "and model: exact is kinematics: intrinsic by default",
          written ? "remove the key" : "write `kinematics: cable` to keep the cable, or remove the key");
  if (err) {
    free(b);
    return err;
  }
  intrinsic_setup(b, INTRINSIC_NESTED_POINTS);
  if (fmb_beam_degenerate(p, item, b->L, b->ne, b->rho, b->A, b->Izz, b->Emod)) {
    free(b);
    return -1;
  }
  *self = b;
  return 0;
}

static void intrinsic_destroy(void* self) { free(self); }

static int intrinsic_ncoord(const void* self) { return 3 + ((const BeamIntrinsic*)self)->n; }

static void intrinsic_initial(const void* self, double* q0, double* v0) {
  const BeamIntrinsic* b = self;
  fmb_beam_frame_initial(3 + b->n, b->pos0, b->angle0, b->vel0, b->omega0, q0, v0);
}

/* work: per element its mass points' weighted F (2 nm), their sum (2) and cos phi, sin phi,
   1 + eps at its nested points (3 nq) for the residual; 2 per coordinate for the marker's
   body-frame columns */
static int residual_stride(const BeamIntrinsic* b) { return 2 * b->nm + 2 + 3 * b->nq; }
/* after both: the outputs' cache (sweep_state) */
static size_t cache_at(const BeamIntrinsic* b) {
  const size_t residual = (size_t)b->ne * (size_t)residual_stride(b), marker = 2 * (size_t)(3 + b->n);
  return residual > marker ? residual : marker;
}
static size_t intrinsic_nwork(const void* self) {
  const BeamIntrinsic* b = self;
  return cache_at(b) + 1 + 2 * (size_t)(3 + b->n) + 4 * (size_t)(b->ne + 1) + 5;
}

static int intrinsic_residual(const void* self, const fmbEnv* env, const double* q, const double* v, const double* a,
                              double* R, double* work) {
  const BeamIntrinsic* b = self;
  const int nm = b->nm, nq = b->nq, stride = residual_stride(b);
  double c, s, G0[2];
  fmb_beam_frame_load(env, q, a, &c, &s, G0);
  const double om = v[2], al = a[2];
  memset(R, 0, sizeof(double) * (size_t)(3 + b->n));
  /* forward: positions and rates at the nodes and mass points, the mass points' F */
  double rho[2] = {0.0, 0.0}, rt[2] = {0.0, 0.0}, rtt[2] = {0.0, 0.0};
  for (int e = 0; e < b->ne; ++e) {
    double X[6], Xd[6], Xdd[6];
    element_dofs(q, e, X), element_dofs(v, e, Xd), element_dofs(a, e, Xdd);
    double* Fw = work + (size_t)e * (size_t)stride;
    double* Te = Fw + 2 * nm;
    double* cache = Te + 2; /* its nested points' cos phi, sin phi, 1 + eps */
    double rp[INTRINSIC_MAX_POINTS][2], rpt[INTRINSIC_MAX_POINTS][2], rptt[INTRINSIC_MAX_POINTS][2];
    element_tangents(b, X, Xd, Xdd, rp, rpt, rptt, cache);
    Te[0] = Te[1] = 0.0;
    for (int g = 0; g < nm; ++g) {
      double d[2], dt[2], dtt[2];
      integrate_points(b, b->W[g], (const double(*)[2])rp, d);
      integrate_points(b, b->W[g], (const double(*)[2])rpt, dt);
      integrate_points(b, b->W[g], (const double(*)[2])rptt, dtt);
      const double r[2] = {rho[0] + d[0], rho[1] + d[1]}, r_t[2] = {rt[0] + dt[0], rt[1] + dt[1]};
      const double r_tt[2] = {rtt[0] + dtt[0], rtt[1] + dtt[1]};
      const double F[2] = {G0[0] - al * r[1] - om * om * r[0] - 2.0 * om * r_t[1] + r_tt[0],
                           G0[1] + al * r[0] - om * om * r[1] + 2.0 * om * r_t[0] + r_tt[1]};
      const double w = b->mu * b->wm[g] * b->le;
      Fw[2 * g] = w * F[0], Fw[2 * g + 1] = w * F[1];
      Te[0] += Fw[2 * g], Te[1] += Fw[2 * g + 1];
      R[0] += Fw[2 * g] * c - Fw[2 * g + 1] * s;        /* J = A^T e_x */
      R[1] += Fw[2 * g] * s + Fw[2 * g + 1] * c;        /* J = A^T e_y */
      R[2] += -r[1] * Fw[2 * g] + r[0] * Fw[2 * g + 1]; /* J = I~rho */
    }
    double d[2], dt[2], dtt[2];
    integrate_points(b, b->wq, (const double(*)[2])rp, d);
    integrate_points(b, b->wq, (const double(*)[2])rpt, dt);
    integrate_points(b, b->wq, (const double(*)[2])rptt, dtt);
    for (int k = 0; k < 2; ++k) rho[k] += d[k], rt[k] += dt[k], rtt[k] += dtt[k];
  }
  /* backward: the suffix sum S of F beyond each element; the deformation rows */
  double S[2] = {0.0, 0.0};
  for (int e = b->ne - 1; e >= 0; --e) {
    double X[6];
    element_dofs(q, e, X);
    const double* Fw = work + (size_t)e * (size_t)stride;
    const double* cache = Fw + 2 * nm + 2;
    for (int m = 0; m < nq; ++m) { /* G_m: the elements beyond, and each mass point through W[g][m] */
      double G[2] = {b->wq[m] * S[0], b->wq[m] * S[1]};
      for (int g = 0; g < nm; ++g) G[0] += b->W[g][m] * Fw[2 * g], G[1] += b->W[g][m] * Fw[2 * g + 1];
      add_tangent_work(e, b->sh_nest[m], cache + 3 * m, b->le, G, R);
    }
    /* strain energy: dU = int EA eps N + EI phi' H' (a quartic in xi: exact at the 4 mass points) */
    for (int g = 0; g < nm; ++g) {
      const double *w = b->sh_mass[g], *dw = b->dsh_mass[g];
      double eps, phi, dphi;
      fields(w, dw, X, &eps, &phi, &dphi);
      const double wl = b->wm[g] * b->le;
      for (int l = 0; l < 6; ++l) {
        const int i = idof(e, l);
        if (i >= 0) R[i] += l % 3 == 0 ? wl * b->EA * eps * w[l] : wl * b->EI * dphi * dw[l];
      }
    }
    S[0] += Fw[2 * nm], S[1] += Fw[2 * nm + 1];
  }
  return 0;
}

/* ---------------------------------------------------------------------------------------------
 * Where things are: rho at node k (the elements' increments up to it), the marker.
 * ------------------------------------------------------------------------------------------- */
static void node_position(const BeamIntrinsic* b, const double* q, int k, double rho[2]) {
  rho[0] = rho[1] = 0.0;
  for (int e = 0; e < k; ++e) {
    double X[6], d[2], rp[INTRINSIC_MAX_POINTS][2];
    element_dofs(q, e, X);
    element_tangents(b, X, NULL, NULL, rp, NULL, NULL, NULL);
    integrate_points(b, b->wq, (const double(*)[2])rp, d);
    rho[0] += d[0], rho[1] += d[1];
  }
}

/* d rho/d q of element e's integral with weights W (integrate_points') into body-frame columns
   du (2 per coordinate, nc of them), for the marker's derivatives */
static void add_position_columns(const BeamIntrinsic* b, int e, const double* W, const double X[6], double* du) {
  for (int m = 0; m < b->nq; ++m) {
    const double* w = b->sh_nest[m];
    double eps, phi;
    fields(w, NULL, X, &eps, &phi, NULL);
    const double wl = W[m] * b->le, c = cos(phi), s = sin(phi);
    for (int l = 0; l < 6; ++l) {
      const int i = idof(e, l);
      if (i < 0) continue;
      if (l % 3 == 0)
        du[2 * i] += wl * w[l] * c, du[2 * i + 1] += wl * w[l] * s;
      else
        du[2 * i] -= wl * w[l] * (1.0 + eps) * s, du[2 * i + 1] += wl * w[l] * (1.0 + eps) * c;
    }
  }
}

/* work: 2 nc doubles of body-frame columns (intrinsic_nwork) */
static int intrinsic_marker(const void* self, const double* q, const double local[2], double pos[2], double* angle,
                            double* dpos_dq, double* dangle_dq, double* work) {
  const BeamIntrinsic* b = self;
  const int nc = 3 + b->n;
  const double x = local[0], y = local[1];
  if (x > b->L * (1.0 + 1e-12)) return -1;
  const double c = cos(q[2]), s = sin(q[2]);
  if (dpos_dq) memset(dpos_dq, 0, sizeof(double) * 2 * (size_t)nc);
  if (dangle_dq) memset(dangle_dq, 0, sizeof(double) * (size_t)nc);
  double pb[2] = {x, y}, phi = 0.0;
  const int onbeam = x > 0.0; /* points at x <= 0 move rigidly with the frame (the root is clamped) */
  int e = 0;
  double xi = 0.0, X[6], w[6], Wx[INTRINSIC_MAX_POINTS];
  if (onbeam) {
    double rho[2], d[2], eps, rp[INTRINSIC_MAX_POINTS][2];
    fmb_beam_locate(b->le, b->ne, x, &e, &xi);
    node_position(b, q, e, rho);
    element_dofs(q, e, X);
    span_weights(b, xi, Wx);
    element_tangents(b, X, NULL, NULL, rp, NULL, NULL, NULL);
    integrate_points(b, Wx, (const double(*)[2])rp, d);
    shape6(xi, b->le, w, NULL);
    fields(w, NULL, X, &eps, &phi, NULL);
    pb[0] = rho[0] + d[0] - y * sin(phi);
    pb[1] = rho[1] + d[1] + y * cos(phi);
  }
  fmb_beam_frame_marker(nc, q, c, s, pb, phi, pos, angle, dpos_dq, dangle_dq);
  if (!onbeam) return 0;
  if (dangle_dq)
    for (int l = 0; l < 6; ++l)
      if (l % 3 && idof(e, l) >= 0) dangle_dq[idof(e, l)] += w[l];
  if (!dpos_dq) return 0;
  double* du = work; /* body-frame d pb / d q_i, 2 per coordinate */
  memset(du, 0, sizeof(double) * 2 * (size_t)nc);
  for (int k = 0; k < e; ++k) {
    double Xk[6];
    element_dofs(q, k, Xk);
    add_position_columns(b, k, b->wq, Xk, du);
  }
  add_position_columns(b, e, Wx, X, du);
  for (int l = 0; l < 6; ++l) { /* y n(phi): d n/d phi = -e(phi) */
    const int i = idof(e, l);
    if (i >= 0 && l % 3) du[2 * i] -= y * w[l] * cos(phi), du[2 * i + 1] -= y * w[l] * sin(phi);
  }
  for (int i = 3; i < nc; ++i) {
    dpos_dq[i] = c * du[2 * i] - s * du[2 * i + 1];
    dpos_dq[nc + i] = s * du[2 * i] + c * du[2 * i + 1];
  }
  return 0;
}

/* ---------------------------------------------------------------------------------------------
 * Energy and outputs.
 * ------------------------------------------------------------------------------------------- */
/* One sweep at (q, v) for every output and the energy: the nodes' rho and rho_t (2 (ne + 1)
   each), then, with need_sums, T, U_e, p_theta (angular momentum about the frame origin) and
   sum w mu rho_g (2). An output row asks for several outputs and the energy at one state: the
   sweep is kept in the scratch with the (q, v) it was made at and made again only when they
   differ (bitwise) or the sums are asked of a sweep made without them. The nodes alone (the tip
   outputs) skip the mass points' integrals, most of a row's cost when no energy is asked (the
   nodes' values are the same either way: the sums do not enter them). */
enum { SWEEP_T, SWEEP_UE, SWEEP_PTHETA, SWEEP_MRHO };
static const double* sweep_state(const BeamIntrinsic* b, const double* q, const double* v, int need_sums,
                                 double* work) {
  const size_t nc = (size_t)(3 + b->n);
  double* key = work + cache_at(b);
  double* out = key + 1 + 2 * nc;
  const double level = need_sums ? 2.0 : 1.0; /* key[0]: 0 nothing kept, 1 the nodes, 2 and the sums */
  if (key[0] >= level && !memcmp(key + 1, q, nc * sizeof(double)) && !memcmp(key + 1 + nc, v, nc * sizeof(double)))
    return out;
  double* rho_n = out;
  double* rt_n = out + 2 * (b->ne + 1);
  double* sums = rt_n + 2 * (b->ne + 1);
  const double om = v[2];
  const double c = cos(q[2]), s = sin(q[2]), v0[2] = {c * v[0] + s * v[1], -s * v[0] + c * v[1]};
  double T = 0.0, Ue = 0.0, pth = 0.0, mrho[2] = {0.0, 0.0}, rho[2] = {0.0, 0.0}, rt[2] = {0.0, 0.0};
  rho_n[0] = rho_n[1] = rt_n[0] = rt_n[1] = 0.0;
  for (int e = 0; e < b->ne; ++e) {
    double X[6], Xd[6], d[2], dt[2], rp[INTRINSIC_MAX_POINTS][2], rpt[INTRINSIC_MAX_POINTS][2];
    element_dofs(q, e, X), element_dofs(v, e, Xd);
    element_tangents(b, X, Xd, NULL, rp, rpt, NULL, NULL);
    for (int g = 0; need_sums && g < b->nm; ++g) {
      integrate_points(b, b->W[g], (const double(*)[2])rp, d);
      integrate_points(b, b->W[g], (const double(*)[2])rpt, dt);
      const double r[2] = {rho[0] + d[0], rho[1] + d[1]};
      const double w = b->mu * b->wm[g] * b->le;
      const double vb[2] = {v0[0] - om * r[1] + rt[0] + dt[0], v0[1] + om * r[0] + rt[1] + dt[1]};
      T += 0.5 * w * (vb[0] * vb[0] + vb[1] * vb[1]);
      pth += w * (-r[1] * vb[0] + r[0] * vb[1]);
      mrho[0] += w * r[0], mrho[1] += w * r[1];
      double eps, phi, dphi;
      fields(b->sh_mass[g], b->dsh_mass[g], X, &eps, &phi, &dphi);
      Ue += 0.5 * b->wm[g] * b->le * (b->EA * eps * eps + b->EI * dphi * dphi);
    }
    integrate_points(b, b->wq, (const double(*)[2])rp, d);
    integrate_points(b, b->wq, (const double(*)[2])rpt, dt);
    rho[0] += d[0], rho[1] += d[1], rt[0] += dt[0], rt[1] += dt[1];
    rho_n[2 * (e + 1)] = rho[0], rho_n[2 * (e + 1) + 1] = rho[1];
    rt_n[2 * (e + 1)] = rt[0], rt_n[2 * (e + 1) + 1] = rt[1];
  }
  sums[SWEEP_T] = T, sums[SWEEP_UE] = Ue, sums[SWEEP_PTHETA] = pth;
  sums[SWEEP_MRHO] = mrho[0], sums[SWEEP_MRHO + 1] = mrho[1];
  memcpy(key + 1, q, nc * sizeof(double));
  memcpy(key + 1 + nc, v, nc * sizeof(double));
  key[0] = level;
  return out;
}

/* the sweep's sums (after the nodes' rho and rho_t) */
static const double* sweep_sums(const BeamIntrinsic* b, const double* sweep) { return sweep + 4 * (b->ne + 1); }

static void intrinsic_energy(const void* self, const fmbEnv* env, const double* q, const double* v, fmbEnergy* en,
                             double* work) {
  const BeamIntrinsic* b = self;
  const double* sums = sweep_sums(b, sweep_state(b, q, v, 1, work));
  en->kinetic = sums[SWEEP_T];
  en->strain = sums[SWEEP_UE];
  en->gravity = fmb_beam_gravity_potential(env, b->mu * b->L, q, cos(q[2]), sin(q[2]), sums + SWEEP_MRHO);
  en->spring = 0.0;
}

static int intrinsic_output_lookup(const void* self, const char* quantity) {
  return fmb_beam_output_lookup(((const BeamIntrinsic*)self)->ne, quantity);
}

/* beam_exact.c's names and meanings: tip_u/tip_v the tip's displacement in the frame */
static int intrinsic_output(const void* self, int id, const double* q, const double* v, double* value, double* work) {
  const BeamIntrinsic* b = self;
  if (id == FMB_BEAM_ANG_MOMENTUM) {
    *value = sweep_sums(b, sweep_state(b, q, v, 1, work))[SWEEP_PTHETA];
    return 0;
  }
  if (id == FMB_BEAM_TIP_ANGLE) {
    *value = q[5 + 3 * (b->ne - 1) + 1]; /* phi at the tip */
    return 0;
  }
  int node, comp;
  if (fmb_beam_output_node(b->ne, id, &node, &comp)) return -1;
  const double* sweep = sweep_state(b, q, v, 0, work);
  const double *rho = sweep + 2 * node, *rt = sweep + 2 * (b->ne + 1) + 2 * node;
  const double u[2] = {rho[0] - node * b->le, rho[1]};
  *value = fmb_beam_node_value(comp, q, u, rt, rho);
  return 0;
}

static void intrinsic_describe(const void* self, FILE* f) {
  const BeamIntrinsic* b = self;
  fprintf(f,
          "exact model in intrinsic kinematics (strain and angle along the beam, constant stiffness), %d elements, "
          "nested %d-point rule, dense Jacobian by differences; no range limit (its accuracy is the mesh's and the "
          "tolerance's, docs/models.md)\n",
          b->ne, b->nq);
}

/* as the cable's (beam_exact.c): undamped axial modes */
static int intrinsic_max_bdf_order(const void* self) {
  (void)self;
  return 2;
}

static int intrinsic_velocity_error_test(const void* self) {
  (void)self;
  return 0;
}

/* metres per unit (fmbBodyType.length_scale): the frame's x, y 1, theta L (it swings the beam).
   The deformation coordinates are LOCAL: a node's eps_i or phi_i changes rho' only on the node's
   two elements, so the beam beyond them translates by about le per unit (it does not turn: its
   own phi is unchanged): le; kappa_i changes phi by at most 4/27 le (the Hermite slope weight's
   peak) there: le 4 le / 27. Measured (pendulum, first 0.5 s, auto): with L instead of le for
   eps and phi 2,052 steps and 1.24e-6 m against its rtol 1e-10 run, with le 1,681 and 1.29e-6 m */
static void intrinsic_length_scale(const void* self, double* mpu) {
  const BeamIntrinsic* b = self;
  mpu[0] = mpu[1] = 1.0;
  mpu[2] = b->L;
  mpu[3] = b->le;
  mpu[4] = b->le * 4.0 * b->le / 27.0;
  for (int i = 0; i < b->ne; ++i) {
    double* nd = mpu + 5 + 3 * i;
    nd[0] = nd[1] = b->le;
    nd[2] = b->le * 4.0 * b->le / 27.0;
  }
}

static const char* intrinsic_invalid_state(const void* self, const double* q, const double* v) {
  (void)v;
  const BeamIntrinsic* b = self;
  for (int i = 0; i <= b->ne; ++i) {
    const double eps = q[i == 0 ? 3 : 5 + 3 * (i - 1)];
    const double phi = i == 0 ? 0.0 : q[5 + 3 * (i - 1) + 1];
    if (!(fabs(eps) <= 0.5 && fabs(phi) <= 100.0))
      return "a node's axial strain exceeds 50 % or its angle 100 rad: the solution is diverging "
             "(check the loads and parameters)";
  }
  return NULL;
}

static int intrinsic_centreline(const void* self, int n, double* local) {
  const BeamIntrinsic* b = self;
  return fmb_beam_centreline(b->L, b->ne, n, local);
}

const fmbBodyType fmb_body_beam_intrinsic = {
    .name = "beam",
    .abi = FMB_ABI_VERSION,
    .parse = intrinsic_parse,
    .destroy = intrinsic_destroy,
    .ncoord = intrinsic_ncoord,
    .initial = intrinsic_initial,
    .residual = intrinsic_residual,
    .marker = intrinsic_marker,
    .nwork = intrinsic_nwork,
    .energy = intrinsic_energy,
    .output_names = fmb_beam_output_names,
    .output_units = fmb_beam_output_units,
    .output_lookup = intrinsic_output_lookup,
    .output = intrinsic_output,
    .describe = intrinsic_describe,
    .max_bdf_order = intrinsic_max_bdf_order,
    .velocity_error_test = intrinsic_velocity_error_test,
    .invalid_state = intrinsic_invalid_state,
    .length_scale = intrinsic_length_scale,
    .centreline = intrinsic_centreline,
    .params = intrinsic_params,
    .example = "length: 1\nelements: 2\ndensity: 1000\narea: 1e-3\nsecond_moment: 1e-7\nyoungs_modulus: 1e6\n"
               "model: exact\nkinematics: intrinsic\nangular_velocity: 3\nvelocity: [0.2, 0.5]\n",
};
