/* revolute3d.c — a hinge in space: the points coincide and the joint frames' z axes (the
 * `axis`, given in the global frame of the scene's pose) stay aligned:
 *   Phi = [p1 - p2; z1 . x2; z1 . y2]        (5 rows; frames as in spatial_pair.h)
 * Its output `angle` is the turn about the axis since the scene's pose, in (-pi, pi]. */
#include <math.h>
#include <stdio.h>

#include "spatial_pair.h"

static int revolute3d_parse(fmbParser* p, fmbNode item, void** self) {
  fmbSpatialPair* sp = NULL;
  if (fmbj3_new(p, item, self, &sp)) return -1;
  return fmbj3_parse(p, item, "axis", sp);
}

static const fmbj3Row revolute3d_rows[] = {
    {FMBJ3_GAP, 0, 0}, {FMBJ3_GAP, 1, 0}, {FMBJ3_GAP, 2, 0}, {FMBJ3_AXES, 2, 0}, {FMBJ3_AXES, 2, 1}};

static int revolute3d_nrows(const void* self) {
  (void)self;
  return (int)(sizeof revolute3d_rows / sizeof revolute3d_rows[0]);
}

static int revolute3d_constraint(const void* self, const fmbJointEval* ev, double* phi, double* phi_q, double* phi_t,
                                 double* phi_tt) {
  (void)phi_t, (void)phi_tt; /* scleronomic */
  return fmbj3_rows(ev, self, revolute3d_rows, revolute3d_nrows(self), phi, phi_q);
}

static void revolute3d_describe(const void* self, FILE* out) {
  (void)self;
  fprintf(out, "the points coincide, the bodies turn about one axis (5 rows)\n");
}

static const char* const revolute3d_outputs[] = {"angle", NULL};
static const char* const revolute3d_output_units[] = {"rad", NULL};
static int revolute3d_output(const void* self, int id, const fmbJointEval* ev, double* value) {
  fmbSpatialEval e;
  const int rc = fmbj3_eval(ev, self, 0, 0, &e);
  if (rc) return rc;
  (void)id;
  *value = fmbj3_turn(&e);
  return 0;
}

static const fmbParam revolute3d_params[] = {
    FMBJ_SPATIAL_PAIR_PARAMS, FMBJ_SPATIAL_AXIS_PARAM("the joint axis"), {.key = NULL}};

const fmbJointType fmb_joint_revolute3d = {
    .name = "revolute3d",
    .abi = FMB_ABI_VERSION,
    .parse = revolute3d_parse,
    .describe = revolute3d_describe,
    .destroy = fmbj3_destroy,
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
