/* cylindrical.c — a cylindrical joint: body2 turns about and slides along the `axis`
 * through point1 (global direction in the scene's pose):
 *   Phi = [z1 . x2; z1 . y2; (p1 - p2) . x1; (p1 - p2) . y1]      (4 rows)
 * Outputs `angle` (as revolute3d's) and `displacement` ((p2 - p1) . z1). */
#include <math.h>
#include <stdio.h>

#include "spatial_pair.h"

static int cylindrical_parse(fmbParser* p, fmbNode item, void** self) {
  fmbSpatialPair* sp = NULL;
  if (fmbj3_new(p, item, self, &sp)) return -1;
  return fmbj3_parse(p, item, "axis", sp);
}

static const fmbj3Row cylindrical_rows[] = {
    {FMBJ3_AXES, 2, 0}, {FMBJ3_AXES, 2, 1}, {FMBJ3_GAP_ALONG, 0, 0}, {FMBJ3_GAP_ALONG, 1, 0}};

static int cylindrical_nrows(const void* self) {
  (void)self;
  return (int)(sizeof cylindrical_rows / sizeof cylindrical_rows[0]);
}

static int cylindrical_constraint(const void* self, const fmbJointEval* ev, double* phi, double* phi_q, double* phi_t,
                                  double* phi_tt) {
  (void)phi_t, (void)phi_tt; /* scleronomic */
  return fmbj3_rows(ev, self, cylindrical_rows, cylindrical_nrows(self), phi, phi_q);
}

static void cylindrical_describe(const void* self, FILE* out) {
  (void)self;
  fprintf(out, "body2 turns about and slides along the axis (4 rows)\n");
}

static const char* const cylindrical_outputs[] = {"angle", "displacement", NULL};
static const char* const cylindrical_output_units[] = {"rad", "m", NULL};
static int cylindrical_output(const void* self, int id, const fmbJointEval* ev, double* value) {
  fmbSpatialEval e;
  const int rc = fmbj3_eval(ev, self, 0, 0, &e);
  if (rc) return rc;
  *value = id == 0 ? fmbj3_turn(&e) : fmbj3_slide(&e);
  return 0;
}

static const fmbParam cylindrical_params[] = {
    FMBJ_SPATIAL_PAIR_PARAMS, FMBJ_SPATIAL_AXIS_PARAM("the joint axis"), {.key = NULL}};

const fmbJointType fmb_joint_cylindrical = {
    .name = "cylindrical",
    .abi = FMB_ABI_VERSION,
    .parse = cylindrical_parse,
    .describe = cylindrical_describe,
    .destroy = fmbj3_destroy,
    .bodies = fmbj3_bodies,
    .attachment3 = fmbj3_attachment,
    .nrows = cylindrical_nrows,
    .constraint = cylindrical_constraint,
    .output_names = cylindrical_outputs,
    .output_units = cylindrical_output_units,
    .output = cylindrical_output,
    .params = cylindrical_params,
    .example = "body1: a\nbody2: b\npoint1: [0.5, 0, 0]\npoint2: [-0.5, 0, 0]\naxis: [1, 0, 0]\n",
    .dimensions = FMB_DIM_SPATIAL,
};
