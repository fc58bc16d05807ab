/* spherical.c — a ball joint in space: point1 on body1 and point2 on body2 coincide,
 * Phi = p1 - p2 (3 rows). The bodies turn freely about the point. */
#include <math.h>
#include <stdio.h>

#include "spatial_pair.h"

static int spherical_parse(fmbParser* p, fmbNode item, void** self) {
  fmbSpatialPair* sp = NULL;
  if (fmbj3_new(p, item, self, &sp)) return -1;
  return fmbj3_parse(p, item, NULL, sp);
}

static const fmbj3Row spherical_rows[] = {{FMBJ3_GAP, 0, 0}, {FMBJ3_GAP, 1, 0}, {FMBJ3_GAP, 2, 0}};

static int spherical_nrows(const void* self) {
  (void)self;
  return (int)(sizeof spherical_rows / sizeof spherical_rows[0]);
}

static int spherical_constraint(const void* self, const fmbJointEval* ev, double* phi, double* phi_q, double* phi_t,
                                double* phi_tt) {
  (void)phi_t, (void)phi_tt; /* scleronomic */
  return fmbj3_rows(ev, self, spherical_rows, spherical_nrows(self), phi, phi_q);
}

static void spherical_describe(const void* self, FILE* out) {
  (void)self;
  fprintf(out, "the two points coincide (3 rows)\n");
}

static const fmbParam spherical_params[] = {FMBJ_SPATIAL_PAIR_PARAMS, {.key = NULL}};

const fmbJointType fmb_joint_spherical = {
    .name = "spherical",
    .abi = FMB_ABI_VERSION,
    .parse = spherical_parse,
    .describe = spherical_describe,
    .destroy = fmbj3_destroy,
    .bodies = fmbj3_bodies,
    .attachment3 = fmbj3_attachment,
    .nrows = spherical_nrows,
    .constraint = spherical_constraint,
    .params = spherical_params,
    .example = "body1: a\nbody2: b\npoint1: [0.5, 0, 0]\npoint2: [-0.5, 0, 0]\n",
    .dimensions = FMB_DIM_SPATIAL,
    .flags = FMB_TYPE_CONFORM_FIXTURE, /* conform's ball joint of body a to ground in space */
};
