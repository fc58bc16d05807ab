/* beam_section.h — what the two files of `type: beam` share: beam.c (ZOAC, FOAC, complete) and
 * beam_exact.c (exact). The section's keys as declared to users and `conform`, the refusal of a
 * section that gives unusable element numbers, and where a point of the reference line lies. */
#ifndef FLEXMBD_BEAM_SECTION_H
#define FLEXMBD_BEAM_SECTION_H
#include <math.h>
#include <stdlib.h>
#include <string.h>

#include "flexmbd_plugin.h"

/* the keys every beam model reads the same way, then the frame's initial state */
#define FMB_BEAM_SECTION_PARAMS(max_elements)                                                              \
  {.key = "length",                                                                                        \
   .kind = FMB_PARAM_NUMBER,                                                                               \
   .flags = FMB_REQUIRED | FMB_POSITIVE,                                                                   \
   .unit = "m",                                                                                            \
   .doc = "undeformed length"},                                                                            \
      {.key = "elements",                                                                                  \
       .kind = FMB_PARAM_INT,                                                                              \
       .flags = FMB_REQUIRED,                                                                              \
       .unit = "1",                                                                                        \
       .lo = 1,                                                                                            \
       .hi = (max_elements),                                                                               \
       .doc = "finite elements along the length"},                                                         \
      {.key = "density",                                                                                   \
       .kind = FMB_PARAM_NUMBER,                                                                           \
       .flags = FMB_REQUIRED | FMB_POSITIVE,                                                               \
       .unit = "kg/m^3",                                                                                   \
       .doc = "mass density"},                                                                             \
      {.key = "area",                                                                                      \
       .kind = FMB_PARAM_NUMBER,                                                                           \
       .flags = FMB_REQUIRED | FMB_POSITIVE,                                                               \
       .unit = "m^2",                                                                                      \
       .doc = "cross-section area"},                                                                       \
      {.key = "second_moment",                                                                             \
       .kind = FMB_PARAM_NUMBER,                                                                           \
       .flags = FMB_REQUIRED | FMB_POSITIVE,                                                               \
       .unit = "m^4",                                                                                      \
       .doc = "second moment of area of the cross-section"},                                               \
  {                                                                                                        \
    .key = "youngs_modulus", .kind = FMB_PARAM_NUMBER, .flags = FMB_REQUIRED | FMB_POSITIVE, .unit = "Pa", \
    .doc = "Young's modulus"                                                                               \
  }
#define FMB_BEAM_FRAME_PARAMS                                                                                         \
  {.key = "position",                                                                                                 \
   .kind = FMB_PARAM_VEC2,                                                                                            \
   .unit = "m",                                                                                                       \
   .fallback = "[0, 0]",                                                                                              \
   .doc = "initial root of the floating frame"},                                                                      \
      {.key = "angle", .kind = FMB_PARAM_NUMBER, .unit = "rad", .fallback = "0", .doc = "initial frame orientation"}, \
      {.key = "velocity",                                                                                             \
       .kind = FMB_PARAM_VEC2,                                                                                        \
       .unit = "m/s",                                                                                                 \
       .fallback = "[0, 0]",                                                                                          \
       .doc = "initial root velocity"},                                                                               \
  {                                                                                                                   \
    .key = "angular_velocity", .kind = FMB_PARAM_NUMBER, .unit = "rad/s", .fallback = "0",                            \
    .doc = "initial frame angular velocity"                                                                           \
  }

/* `reduction: {modes: k, stiffening_modes: r, axial_modes: m}` (bodies/beam_modal.c): declared by both tables */
#define FMB_BEAM_REDUCTION_PARAM                                                                                    \
  {                                                                                                                 \
    .key = "reduction", .kind = FMB_PARAM_MAP, .fallback = "none (the full mesh)",                                  \
    .doc = "{modes: k, stiffening_modes: r, axial_modes: m}: the beam in its k lowest clamped-free bending "        \
           "modes of its own elements, r <= k spin-stiffening vectors (default k) and m axial modes, the coupling " \
           "kept exactly (docs/models.md, reduced beam)"                                                            \
  }

/* the parse error for a section whose element mass or stiffness is not a usable double (length
   1e-300: EI/le^3 overflows) */
static inline void fmb_beam_refuse_degenerate(fmbParser* p, fmbNode item, double L, int ne, double rho, double A,
                                              double Izz, double E, double me, double k_bend, double k_axial) {
  fmb_parse_error(p, item,
                  "degenerate beam: length %g in %d elements with density %g, area %g, second moment %g and "
                  "Young's modulus %g gives an element mass %g, bending stiffness %g and axial stiffness %g: "
                  "not all are usable (finite, non-zero) floating-point numbers",
                  L, ne, rho, A, Izz, E, me, k_bend, k_axial);
}

/* Shape functions on one element of the small-strain models, xi in [0, 1], element length le:
   cubic Hermite values ns (transverse w2 from [v_l, v'_l, v_r, v'_r]) and slopes nd = dns/dx.
   Shared by beam.c and beam_modal.c (its modes are nodal vectors of the same elements). */
static inline void fmb_beam_hermite(double xi, double le, double ns[4], double nd[4]) {
  double x2 = xi * xi, x3 = x2 * xi;
  if (ns) {
    ns[0] = 1.0 - 3.0 * x2 + 2.0 * x3;
    ns[1] = le * (xi - 2.0 * x2 + x3);
    ns[2] = 3.0 * x2 - 2.0 * x3;
    ns[3] = le * (-x2 + x3);
  }
  if (nd) {
    nd[0] = (-6.0 * xi + 6.0 * x2) / le;
    nd[1] = 1.0 - 4.0 * xi + 3.0 * x2;
    nd[2] = (6.0 * xi - 6.0 * x2) / le;
    nd[3] = -2.0 * xi + 3.0 * x2;
  }
}
/* coefficients of xi^0..2 in the slope functions d/dx [H1, le H2, H3, le H4] (the hermite nd) */
static inline void fmb_beam_slope_coefficients(double le, double nslope[4][3]) {
  const double c[4][3] = {{0.0, -6.0 / le, 6.0 / le}, {1.0, -4.0, 3.0}, {0.0, 6.0 / le, -6.0 / le}, {0.0, -2.0, 3.0}};
  memcpy(nslope, c, sizeof c);
}
/* the product of two quadratics in xi (two slopes): a quartic's five coefficients */
static inline void fmb_beam_poly_mul(const double a[3], const double c[3], double out[5]) {
  out[0] = a[0] * c[0];
  out[1] = a[0] * c[1] + a[1] * c[0];
  out[2] = a[0] * c[2] + a[1] * c[1] + a[2] * c[0];
  out[3] = a[1] * c[2] + a[2] * c[1];
  out[4] = a[2] * c[2];
}
/* pw_k = le xi^(k+1) / (k+1): the integral over [0, xi] in x of a quartic is its coefficients . pw */
static inline void fmb_beam_int_weights(double le, double xi, double pw[5]) {
  double xk = xi;
  for (int k = 0; k < 5; ++k) {
    pw[k] = le * xk / (k + 1);
    xk *= xi;
  }
}

/* element e (0-based, clamped to the mesh) and local coordinate xi in [0, 1] of arc length x */
static inline void fmb_beam_locate(double le, int ne, double x, int* e, double* xi) {
  int k = (int)floor(x / le);
  if (k < 0) k = 0;
  if (k > ne - 1) k = ne - 1;
  *e = k;
  *xi = x / le - k;
}
/* fmbBodyType.centreline of every beam model: n stations equally spaced on the reference line
   from the clamped root (x = 0) to the tip (x = L); by default one per node. Both files answer
   `marker` at (x, 0) with the deformed centreline point of arc length x, so `BODY.shape` and the
   VTK polyline draw each model's own deformed shape. */
static inline int fmb_beam_centreline(double L, int ne, int n, double* local) {
  if (!local) return ne + 1;
  for (int i = 0; i < n; ++i) {
    local[2 * i] = n > 1 ? L * (double)i / (double)(n - 1) : 0.0;
    local[2 * i + 1] = 0.0;
  }
  return n;
}

/* non-zero, after the parse error, when the section's element mass or stiffness (le = L/ne) is
   not a usable double: the check every model makes after reading the section */
static inline int fmb_beam_degenerate(fmbParser* p, fmbNode item, double L, int ne, double rho, double A, double Izz,
                                      double E) {
  const double le = L / ne, me = rho * A * le, k_axial = E * A / le, k_bend = 12.0 * E * Izz / (le * le * le);
  if (isnormal(me) && isnormal(k_axial) && isnormal(k_bend) && isfinite(fmax(k_axial, k_bend) / me)) return 0;
  fmb_beam_refuse_degenerate(p, item, L, ne, rho, A, Izz, E, me, k_bend, k_axial);
  return -1;
}

/* The section's keys (FMB_BEAM_SECTION_PARAMS) and the frame's initial state (FMB_BEAM_FRAME_PARAMS)
   as the exact beam's two forms read them (beam_exact.c, beam_intrinsic.c); non-zero on an error */
static inline int fmb_beam_read_section(fmbParser* p, fmbNode item, int max_elements, double* L, int* ne, double* rho,
                                        double* A, double* Izz, double* E) {
  int err = 0;
  err |= fmb_get_double(p, item, "length", FMB_REQUIRED | FMB_POSITIVE, L);
  err |= fmb_get_int(p, item, "elements", FMB_REQUIRED, 1, max_elements, ne);
  err |= fmb_get_double(p, item, "density", FMB_REQUIRED | FMB_POSITIVE, rho);
  err |= fmb_get_double(p, item, "area", FMB_REQUIRED | FMB_POSITIVE, A);
  err |= fmb_get_double(p, item, "second_moment", FMB_REQUIRED | FMB_POSITIVE, Izz);
  err |= fmb_get_double(p, item, "youngs_modulus", FMB_REQUIRED | FMB_POSITIVE, E);
  return err;
}
static inline int fmb_beam_read_frame(fmbParser* p, fmbNode item, double pos0[2], double* angle0, double vel0[2],
                                      double* omega0) {
  int err = 0;
  err |= fmb_get_vec2(p, item, "position", FMB_OPTIONAL, pos0);
  err |= fmb_get_angle(p, item, "angle", FMB_POSE, angle0);
  err |= fmb_get_vec2(p, item, "velocity", FMB_OPTIONAL, vel0);
  err |= fmb_get_double(p, item, "angular_velocity", FMB_OPTIONAL, omega0);
  return err;
}
/* q0, v0 of nc coordinates: the frame's initial state, the rest zero (the undeformed beam) */
static inline void fmb_beam_frame_initial(int nc, const double pos0[2], double angle0, const double vel0[2],
                                          double omega0, double* q0, double* v0) {
  memset(q0, 0, sizeof(double) * (size_t)nc);
  memset(v0, 0, sizeof(double) * (size_t)nc);
  q0[0] = pos0[0];
  q0[1] = pos0[1];
  q0[2] = angle0;
  v0[0] = vel0[0];
  v0[1] = vel0[1];
  v0[2] = omega0;
}
/* A marker at pb in the frame (q[0..2]; c, s: cos, sin of q[2]) turned phi from it: its position and
   angle, and their derivatives by the frame's coordinates, columns 0..2 of dpos_dq (2 rows of nc)
   and dangle_dq (already zeroed; the caller adds the beam's own columns) */
static inline void fmb_beam_frame_marker(int nc, const double* q, double c, double s, const double pb[2], double phi,
                                         double pos[2], double* angle, double* dpos_dq, double* dangle_dq) {
  pos[0] = q[0] + c * pb[0] - s * pb[1];
  pos[1] = q[1] + s * pb[0] + c * pb[1];
  if (angle) *angle = q[2] + phi;
  if (dangle_dq) dangle_dq[2] = 1.0;
  if (dpos_dq) {
    dpos_dq[0] = 1.0;
    dpos_dq[nc + 1] = 1.0;
    dpos_dq[2] = -s * pb[0] - c * pb[1];
    dpos_dq[nc + 2] = c * pb[0] - s * pb[1];
  }
}
/* cos, sin of the frame angle q[2] and G0 = A^T (r0'' - g): the frame's share of a_b - f_b */
static inline void fmb_beam_frame_load(const fmbEnv* env, const double* q, const double* a, double* c, double* s,
                                       double G0[2]) {
  *c = cos(q[2]);
  *s = sin(q[2]);
  double g[2] = {0.0, 0.0};
  if (env && env->has_gravity) g[0] = env->gravity[0], g[1] = env->gravity[1];
  const double d[2] = {a[0] - g[0], a[1] - g[1]};
  G0[0] = *c * d[0] + *s * d[1];
  G0[1] = -*s * d[0] + *c * d[1];
}
/* U_g = -int mu g . (r0 + A rho) of a beam of mass m whose first moment in the frame is mrho =
   int mu rho (c, s: cos, sin of q[2]); 0 without gravity */
static inline double fmb_beam_gravity_potential(const fmbEnv* env, double m, const double* q, double c, double s,
                                                const double mrho[2]) {
  if (!(env && env->has_gravity)) return 0.0;
  const double gx = env->gravity[0], gy = env->gravity[1];
  return -m * (gx * q[0] + gy * q[1]) - (gx * (c * mrho[0] - s * mrho[1]) + gy * (s * mrho[0] + c * mrho[1]));
}

/* The outputs every beam model gives (the same ids, so `--models` compares like with like): the
   tip's deformation, its rates and position, the angular momentum, the tip cross-section's angle
   to the frame (the marker's angle at (L, 0) less theta: the slope w2'(L) of the small-strain
   models, atan2 of the tangent for the exact one), and nodeK_u/v/x/y at node K. */
enum {
  FMB_BEAM_TIP_U,
  FMB_BEAM_TIP_V,
  FMB_BEAM_TIP_U_RATE,
  FMB_BEAM_TIP_V_RATE,
  FMB_BEAM_TIP_X,
  FMB_BEAM_TIP_Y,
  FMB_BEAM_ANG_MOMENTUM,
  FMB_BEAM_TIP_ANGLE,
  FMB_BEAM_NTIP
};
enum { FMB_BEAM_NODE_BASE = 1000, FMB_BEAM_NODE_STRIDE = 4 }; /* node k: u, v, x, y */
static const char* const fmb_beam_output_names[] = {"tip_u",   "tip_v",        "tip_u_rate", "tip_v_rate", "tip_x",
                                                    "tip_y",   "ang_momentum", "tip_angle",  "nodeK_u",    "nodeK_v",
                                                    "nodeK_x", "nodeK_y",      NULL};
/* their units, in the same order (for plot axes) */
static const char* const fmb_beam_output_units[] = {"m",   "m", "m/s", "m/s", "m", "m", "kg m^2/s",
                                                    "rad", "m", "m",   "m",   "m", NULL};

/* the output id of `quantity` for a beam of ne elements, or -1 */
static inline int fmb_beam_output_lookup(int ne, const char* quantity) {
  for (int i = 0; i < FMB_BEAM_NTIP; ++i)
    if (strcmp(quantity, fmb_beam_output_names[i]) == 0) return i;
  if (strncmp(quantity, "node", 4) != 0 || quantity[4] < '0' || quantity[4] > '9') return -1;
  char* end;
  const long k = strtol(quantity + 4, &end, 10);
  if (k < 0 || k > ne || end[0] != '_' || end[1] == '\0' || end[2] != '\0') return -1;
  static const char comp[] = "uvxy";
  const char* at = strchr(comp, end[1]);
  return at ? FMB_BEAM_NODE_BASE + FMB_BEAM_NODE_STRIDE * (int)k + (int)(at - comp) : -1;
}
/* the node (ne for the tip quantities) and component (FMB_BEAM_TIP_U ... _Y) of output id, or -1
   when id is not a node's or the tip's position or displacement quantity */
static inline int fmb_beam_output_node(int ne, int id, int* node, int* comp) {
  *node = ne, *comp = id;
  if (id >= FMB_BEAM_NODE_BASE) {
    *node = (id - FMB_BEAM_NODE_BASE) / FMB_BEAM_NODE_STRIDE;
    const int k = (id - FMB_BEAM_NODE_BASE) % FMB_BEAM_NODE_STRIDE;
    *comp = k == 0 ? FMB_BEAM_TIP_U : k == 1 ? FMB_BEAM_TIP_V : k == 2 ? FMB_BEAM_TIP_X : FMB_BEAM_TIP_Y;
    return 0;
  }
  return id < 0 || id >= FMB_BEAM_NTIP ? -1 : 0;
}
/* component comp at a node of displacement u (its rate ud) and position rho in the frame of q */
static inline double fmb_beam_node_value(int comp, const double* q, const double u[2], const double ud[2],
                                         const double rho[2]) {
  const double c = cos(q[2]), s = sin(q[2]);
  switch (comp) {
    case FMB_BEAM_TIP_U: return u[0];
    case FMB_BEAM_TIP_V: return u[1];
    case FMB_BEAM_TIP_U_RATE: return ud[0];
    case FMB_BEAM_TIP_V_RATE: return ud[1];
    case FMB_BEAM_TIP_X: return q[0] + c * rho[0] - s * rho[1];
    default: return q[1] + s * rho[0] + c * rho[1];
  }
}
#endif
