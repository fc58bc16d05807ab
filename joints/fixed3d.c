/* fixed3d.c — a weld in space: the points coincide and the two bodies' frames keep the
 * relative orientation of the scene's pose:
 *   Phi = [p1 - p2; x1 . y2; y1 . z2; z1 . x2]      (6 rows; each dot product vanishes as
 * assembled, and to first order they hold the three small relative rotations about z, x and y). */
#include <math.h>
#include <stdio.h>

#include "spatial_pair.h"

static int fixed3d_parse(fmbParser* p, fmbNode item, void** self) {
  fmbSpatialPair* sp = NULL;
  if (fmbj3_new(p, item, self, &sp)) return -1;
  return fmbj3_parse(p, item, NULL, sp);
}

static const fmbj3Row fixed3d_rows[] = {{FMBJ3_GAP, 0, 0},  {FMBJ3_GAP, 1, 0},  {FMBJ3_GAP, 2, 0},
                                        {FMBJ3_AXES, 0, 1}, {FMBJ3_AXES, 1, 2}, {FMBJ3_AXES, 2, 0}};

static int fixed3d_nrows(const void* self) {
  (void)self;
  return (int)(sizeof fixed3d_rows / sizeof fixed3d_rows[0]);
}

static int fixed3d_constraint(const void* self, const fmbJointEval* ev, double* phi, double* phi_q, double* phi_t,
                              double* phi_tt) {
  (void)phi_t, (void)phi_tt; /* scleronomic */
  return fmbj3_rows(ev, self, fixed3d_rows, fixed3d_nrows(self), phi, phi_q);
}

static void fixed3d_describe(const void* self, FILE* out) {
  (void)self;
  fprintf(out, "the points coincide and the relative orientation is held (6 rows)\n");
}

static const fmbParam fixed3d_params[] = {FMBJ_SPATIAL_PAIR_PARAMS, {.key = NULL}};

const fmbJointType fmb_joint_fixed3d = {
    .name = "fixed3d",
    .abi = FMB_ABI_VERSION,
    .parse = fixed3d_parse,
    .describe = fixed3d_describe,
    .destroy = fmbj3_destroy,
    .bodies = fmbj3_bodies,
    .attachment3 = fmbj3_attachment,
    .nrows = fixed3d_nrows,
    .constraint = fixed3d_constraint,
    .params = fixed3d_params,
    .example = "body1: a\nbody2: b\npoint1: [0.5, 0, 0]\npoint2: [-0.5, 0, 0]\n",
    .dimensions = FMB_DIM_SPATIAL,
};
