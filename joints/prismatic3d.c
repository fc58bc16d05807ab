/* prismatic3d.c — a slider in space: the bodies keep their relative orientation and point2
 * moves along the `axis` through point1 (global direction in the scene's pose):
 *   Phi = [x1 . y2; y1 . z2; z1 . x2; (p1 - p2) . x1; (p1 - p2) . y1]      (5 rows)
 * Output `displacement`: (p2 - p1) . z1. */
#include <math.h>
#include <stdio.h>

#include "spatial_pair.h"

static int prismatic3d_parse(fmbParser* p, fmbNode item, void** self) {
  fmbSpatialPair* sp = NULL;
  if (fmbj3_new(p, item, self, &sp)) return -1;
  return fmbj3_parse(p, item, "axis", sp);
}

static const fmbj3Row prismatic3d_rows[] = {
    {FMBJ3_AXES, 0, 1}, {FMBJ3_AXES, 1, 2}, {FMBJ3_AXES, 2, 0}, {FMBJ3_GAP_ALONG, 0, 0}, {FMBJ3_GAP_ALONG, 1, 0}};

static int prismatic3d_nrows(const void* self) {
  (void)self;
  return (int)(sizeof prismatic3d_rows / sizeof prismatic3d_rows[0]);
}

static int prismatic3d_constraint(const void* self, const fmbJointEval* ev, double* phi, double* phi_q, double* phi_t,
                                  double* phi_tt) {
  (void)phi_t, (void)phi_tt; /* scleronomic */
  return fmbj3_rows(ev, self, prismatic3d_rows, prismatic3d_nrows(self), phi, phi_q);
}

static void prismatic3d_describe(const void* self, FILE* out) {
  (void)self;
  fprintf(out, "relative orientation held, point2 slides along the axis (5 rows)\n");
}

static const char* const prismatic3d_outputs[] = {"displacement", NULL};
static const char* const prismatic3d_output_units[] = {"m", NULL};
static int prismatic3d_output(const void* self, int id, const fmbJointEval* ev, double* value) {
  fmbSpatialEval e;
  const int rc = fmbj3_eval(ev, self, 0, 0, &e);
  if (rc) return rc;
  (void)id;
  *value = fmbj3_slide(&e);
  return 0;
}

static const fmbParam prismatic3d_params[] = {
    FMBJ_SPATIAL_PAIR_PARAMS, FMBJ_SPATIAL_AXIS_PARAM("the joint axis"), {.key = NULL}};

const fmbJointType fmb_joint_prismatic3d = {
    .name = "prismatic3d",
    .abi = FMB_ABI_VERSION,
    .parse = prismatic3d_parse,
    .describe = prismatic3d_describe,
    .destroy = fmbj3_destroy,
    .bodies = fmbj3_bodies,
    .attachment3 = fmbj3_attachment,
    .nrows = prismatic3d_nrows,
    .constraint = prismatic3d_constraint,
    .output_names = prismatic3d_outputs,
    .output_units = prismatic3d_output_units,
    .output = prismatic3d_output,
    .params = prismatic3d_params,
    .example = "body1: ground\nbody2: a\npoint2: [0, 0, 0.5]\naxis: [0, 0, 1]\n",
    .dimensions = FMB_DIM_SPATIAL,
};
