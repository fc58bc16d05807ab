/* universal.c — a Cardan joint: the points coincide and the pin of body1 (`axis1`) stays
 * perpendicular to the pin of body2 (`axis2`), both global directions in the scene's pose, which
 * must be perpendicular there. Joint frame: x = axis1, y = axis2, z = x × y;
 *   Phi = [p1 - p2; x1 . y2]        (4 rows). */
#include <math.h>
#include <stdio.h>

#include "spatial_pair.h"

static int universal_parse(fmbParser* p, fmbNode item, void** self) {
  fmbSpatialPair* sp = NULL;
  if (fmbj3_new(p, item, self, &sp)) return -1;
  double a1[3] = {1.0, 0.0, 0.0}, a2[3] = {0.0, 1.0, 0.0};
  if (fmbj3_parse_points(p, item, sp) || fmbj3_direction(p, item, "axis1", a1) || fmbj3_direction(p, item, "axis2", a2))
    return -1;
  if (fabs(a1[0] * a2[0] + a1[1] * a2[1] + a1[2] * a2[2]) > 1e-9)
    return fmb_parse_error(p, fmb_find_key(p, item, "axis2"),
                           "the pins of a universal joint must be perpendicular: axis1 . axis2 = %g",
                           a1[0] * a2[0] + a1[1] * a2[1] + a1[2] * a2[2]);
  const double F[9] = {a1[0], a2[0], a1[1] * a2[2] - a1[2] * a2[1], a1[1], a2[1], a1[2] * a2[0] - a1[0] * a2[2],
                       a1[2], a2[2], a1[0] * a2[1] - a1[1] * a2[0]};
  return fmbj3_set_frame(p, item, F, sp);
}

static const fmbj3Row universal_rows[] = {{FMBJ3_GAP, 0, 0}, {FMBJ3_GAP, 1, 0}, {FMBJ3_GAP, 2, 0}, {FMBJ3_AXES, 0, 1}};

static int universal_nrows(const void* self) {
  (void)self;
  return (int)(sizeof universal_rows / sizeof universal_rows[0]);
}

static int universal_constraint(const void* self, const fmbJointEval* ev, double* phi, double* phi_q, double* phi_t,
                                double* phi_tt) {
  (void)phi_t, (void)phi_tt; /* scleronomic */
  return fmbj3_rows(ev, self, universal_rows, universal_nrows(self), phi, phi_q);
}

static void universal_describe(const void* self, FILE* out) {
  (void)self;
  fprintf(out, "the points coincide, the two pins stay perpendicular (4 rows)\n");
}

static const fmbParam universal_params[] = {
    FMBJ_SPATIAL_PAIR_PARAMS,
    {.key = "axis1", .kind = FMB_PARAM_VEC3, .fallback = "[1, 0, 0]", .doc = "pin on body1 (global, scene pose)"},
    {.key = "axis2",
     .kind = FMB_PARAM_VEC3,
     .fallback = "[0, 1, 0]",
     .doc = "pin on body2 (global, scene pose), perpendicular to axis1"},
    {.key = NULL}};

const fmbJointType fmb_joint_universal = {
    .name = "universal",
    .abi = FMB_ABI_VERSION,
    .parse = universal_parse,
    .describe = universal_describe,
    .destroy = fmbj3_destroy,
    .bodies = fmbj3_bodies,
    .attachment3 = fmbj3_attachment,
    .nrows = universal_nrows,
    .constraint = universal_constraint,
    .params = universal_params,
    .example = "body1: a\nbody2: b\npoint1: [0.5, 0, 0]\npoint2: [-0.5, 0, 0]\n",
    .dimensions = FMB_DIM_SPATIAL,
};
