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
#endif
