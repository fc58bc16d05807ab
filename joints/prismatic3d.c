/* prismatic3d.c — a slider in space: the bodies keep their relative orientation and point2
 * moves along the `axis` through point1 (global direction in the scene's pose):
 *   Phi = [x1 . y2; y1 . z2; z1 . x2; (p1 - p2) . x1; (p1 - p2) . y1]      (5 rows)
 * Output `displacement`: (p2 - p1) . z1. */
#include <math.h>
#include <stdio.h>
#include <stdlib.h>

#include "spatial_pair.h"

static int prismatic3d_parse(fmbParser* p, fmbNode item, void** self) {
  fmbSpatialPair* sp = calloc(1, sizeof *sp);
  if (!sp) return fmb_parse_error(p, item, "out of memory");
  *self = sp;
  return fmbj3_parse(p, item, "axis", sp);
}

static void prismatic3d_destroy(void* self) { free(self); }
static int prismatic3d_nrows(const void* self) {
  (void)self;
  return 5;
}

static int prismatic3d_constraint(const void* self, const fmbJointEval* ev, double* phi, double* phi_q, double* phi_t,
                                  double* phi_tt) {
  (void)phi_t, (void)phi_tt; /* scleronomic */
  const int n0 = fmb_eval_ncoord(ev, 0), ld = n0 + fmb_eval_ncoord(ev, 1);
  fmbSpatialEval e;
  const int rc = fmbj3_eval(ev, self, phi_q, ld, &e);
  if (rc) return rc;
#define ROW(r) (phi_q ? phi_q + (size_t)(r)*ld : NULL)
  /* the gap's derivative sits in rows 0..2 until the two gap rows are made from it */
  phi[3] = fmbj3_gap_row(&e, 0, phi_q, ROW(3), n0, ld);
  phi[4] = fmbj3_gap_row(&e, 1, phi_q, ROW(4), n0, ld);
  phi[0] = fmbj3_axes_row(&e, 0, 1, ROW(0), n0, ld);
  phi[1] = fmbj3_axes_row(&e, 1, 2, ROW(1), n0, ld);
  phi[2] = fmbj3_axes_row(&e, 2, 0, ROW(2), n0, ld);
#undef ROW
  return 0;
}

static void prismatic3d_describe(const void* self, FILE* out) {
  (void)self;
  fprintf(out, "relative orientation held, point2 slides along the axis (5 rows)\n");
}

static const char* const prismatic3d_outputs[] = {"displacement", NULL};
static const char* const prismatic3d_output_units[] = {"m", NULL};
static int prismatic3d_output(const void* self, int id, const fmbJointEval* ev, double* value) {
  fmbSpatialEval e;
  const int rc = fmbj3_eval(ev, self, NULL, 0, &e);
  if (rc) return rc;
  const double displacement =
      -(e.gap[0] * e.X[0][2] + e.gap[1] * e.X[0][5] + e.gap[2] * e.X[0][8]); /* (p2 - p1) . z1 */
  (void)id;
  *value = displacement;
  return 0;
}

static const fmbParam prismatic3d_params[] = {
    FMBJ_SPATIAL_PAIR_PARAMS, FMBJ_SPATIAL_AXIS_PARAM("the joint axis"), {.key = NULL}};

const fmbJointType fmb_joint_prismatic3d = {
    .name = "prismatic3d",
    .abi = FMB_ABI_VERSION,
    .parse = prismatic3d_parse,
    .describe = prismatic3d_describe,
    .destroy = prismatic3d_destroy,
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
