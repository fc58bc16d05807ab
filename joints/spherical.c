/* spherical.c — a ball joint in space: point1 on body1 and point2 on body2 coincide,
 * Phi = p1 - p2 (3 rows). The bodies turn freely about the point. */
#include <math.h>
#include <stdio.h>
#include <stdlib.h>

#include "spatial_pair.h"

static int spherical_parse(fmbParser* p, fmbNode item, void** self) {
  fmbSpatialPair* sp = calloc(1, sizeof *sp);
  if (!sp) return fmb_parse_error(p, item, "out of memory");
  *self = sp;
  return fmbj3_parse(p, item, NULL, sp);
}

static void spherical_destroy(void* self) { free(self); }
static int spherical_nrows(const void* self) {
  (void)self;
  return 3;
}

static int spherical_constraint(const void* self, const fmbJointEval* ev, double* phi, double* phi_q, double* phi_t,
                                double* phi_tt) {
  (void)phi_t, (void)phi_tt; /* scleronomic */
  const int n0 = fmb_eval_ncoord(ev, 0), ld = n0 + fmb_eval_ncoord(ev, 1);
  fmbSpatialEval e;
  const int rc = fmbj3_eval(ev, self, phi_q, ld, &e);
  if (rc) return rc;
#define ROW(r) (phi_q ? phi_q + (size_t)(r)*ld : NULL)
  for (int i = 0; i < 3; ++i) phi[i] = e.gap[i];
#undef ROW
  return 0;
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
    .destroy = spherical_destroy,
    .bodies = fmbj3_bodies,
    .attachment3 = fmbj3_attachment,
    .nrows = spherical_nrows,
    .constraint = spherical_constraint,
    .params = spherical_params,
    .example = "body1: ground\nbody2: a\npoint2: [0, 0, 0.5]\n",
    .dimensions = FMB_DIM_SPATIAL,
};
