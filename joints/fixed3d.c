/* fixed3d.c — a weld in space: the points coincide and the two bodies' frames keep the
 * relative orientation of the scene's pose:
 *   Phi = [p1 - p2; x1 . y2; y1 . z2; z1 . x2]      (6 rows; each dot product vanishes as
 * assembled, and to first order they hold the three small relative rotations about z, x and y). */
#include <math.h>
#include <stdio.h>
#include <stdlib.h>

#include "spatial_pair.h"

static int fixed3d_parse(fmbParser* p, fmbNode item, void** self) {
  fmbSpatialPair* sp = calloc(1, sizeof *sp);
  if (!sp) return fmb_parse_error(p, item, "out of memory");
  *self = sp;
  return fmbj3_parse(p, item, NULL, sp);
}

static void fixed3d_destroy(void* self) { free(self); }
static int fixed3d_nrows(const void* self) {
  (void)self;
  return 6;
}

static int fixed3d_constraint(const void* self, const fmbJointEval* ev, double* phi, double* phi_q, double* phi_t,
                              double* phi_tt) {
  (void)phi_t, (void)phi_tt; /* scleronomic */
  const int n0 = fmb_eval_ncoord(ev, 0), ld = n0 + fmb_eval_ncoord(ev, 1);
  fmbSpatialEval e;
  const int rc = fmbj3_eval(ev, self, phi_q, ld, &e);
  if (rc) return rc;
#define ROW(r) (phi_q ? phi_q + (size_t)(r)*ld : NULL)
  for (int i = 0; i < 3; ++i) phi[i] = e.gap[i];
  phi[3] = fmbj3_axes_row(&e, 0, 1, ROW(3), n0, ld);
  phi[4] = fmbj3_axes_row(&e, 1, 2, ROW(4), n0, ld);
  phi[5] = fmbj3_axes_row(&e, 2, 0, ROW(5), n0, ld);
#undef ROW
  return 0;
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
    .destroy = fixed3d_destroy,
    .bodies = fmbj3_bodies,
    .attachment3 = fmbj3_attachment,
    .nrows = fixed3d_nrows,
    .constraint = fixed3d_constraint,
    .params = fixed3d_params,
    .example = "body1: ground\nbody2: a\npoint2: [0, 0, 0.5]\n",
    .dimensions = FMB_DIM_SPATIAL,
};
