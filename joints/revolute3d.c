/* revolute3d.c — a hinge in space: the points coincide and the joint frames' z axes (the
 * `axis`, given in the global frame of the scene's pose) stay aligned:
 *   Phi = [p1 - p2; z1 . x2; z1 . y2]        (5 rows; frames as in spatial_pair.h)
 * Its output `angle` is the turn about the axis since the scene's pose, in (-pi, pi]. */
#include <math.h>
#include <stdio.h>
#include <stdlib.h>

#include "spatial_pair.h"

static int revolute3d_parse(fmbParser* p, fmbNode item, void** self) {
  fmbSpatialPair* sp = calloc(1, sizeof *sp);
  if (!sp) return fmb_parse_error(p, item, "out of memory");
  *self = sp;
  return fmbj3_parse(p, item, "axis", sp);
}

static void revolute3d_destroy(void* self) { free(self); }
static int revolute3d_nrows(const void* self) {
  (void)self;
  return 5;
}

static int revolute3d_constraint(const void* self, const fmbJointEval* ev, double* phi, double* phi_q, double* phi_t,
                                 double* phi_tt) {
  (void)phi_t, (void)phi_tt; /* scleronomic */
  const int n0 = fmb_eval_ncoord(ev, 0), ld = n0 + fmb_eval_ncoord(ev, 1);
  fmbSpatialEval e;
  const int rc = fmbj3_eval(ev, self, phi_q, ld, &e);
  if (rc) return rc;
#define ROW(r) (phi_q ? phi_q + (size_t)(r)*ld : NULL)
  for (int i = 0; i < 3; ++i) phi[i] = e.gap[i];
  phi[3] = fmbj3_axes_row(&e, 2, 0, ROW(3), n0, ld);
  phi[4] = fmbj3_axes_row(&e, 2, 1, ROW(4), n0, ld);
#undef ROW
  return 0;
}

static void revolute3d_describe(const void* self, FILE* out) {
  (void)self;
  fprintf(out, "the points coincide, the bodies turn about one axis (5 rows)\n");
}

static const char* const revolute3d_outputs[] = {"angle", NULL};
static const char* const revolute3d_output_units[] = {"rad", NULL};
static int revolute3d_output(const void* self, int id, const fmbJointEval* ev, double* value) {
  fmbSpatialEval e;
  const int rc = fmbj3_eval(ev, self, NULL, 0, &e);
  if (rc) return rc;
  /* the turn of body2's frame x axis from body1's, about body1's z axis: (-pi, pi] */
  double c[3];
  const double* X1 = e.X[0];
  const double* X2 = e.X[1];
  c[0] = X1[3] * X2[6] - X1[6] * X2[3];
  c[1] = X1[6] * X2[0] - X1[0] * X2[6];
  c[2] = X1[0] * X2[3] - X1[3] * X2[0];
  const double angle = atan2(c[0] * X1[2] + c[1] * X1[5] + c[2] * X1[8], X1[0] * X2[0] + X1[3] * X2[3] + X1[6] * X2[6]);
  (void)id;
  *value = angle;
  return 0;
}

static const fmbParam revolute3d_params[] = {
    FMBJ_SPATIAL_PAIR_PARAMS, FMBJ_SPATIAL_AXIS_PARAM("the joint axis"), {.key = NULL}};

const fmbJointType fmb_joint_revolute3d = {
    .name = "revolute3d",
    .abi = FMB_ABI_VERSION,
    .parse = revolute3d_parse,
    .describe = revolute3d_describe,
    .destroy = revolute3d_destroy,
    .bodies = fmbj3_bodies,
    .attachment3 = fmbj3_attachment,
    .nrows = revolute3d_nrows,
    .constraint = revolute3d_constraint,
    .output_names = revolute3d_outputs,
    .output_units = revolute3d_output_units,
    .output = revolute3d_output,
    .params = revolute3d_params,
    .example = "body1: ground\nbody2: a\npoint2: [0, 0, 0.5]\naxis: [1, 0, 0]\n",
    .dimensions = FMB_DIM_SPATIAL,
};
