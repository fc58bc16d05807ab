/* cylindrical.c — a cylindrical joint: body2 turns about and slides along the `axis`
 * through point1 (global direction in the scene's pose):
 *   Phi = [z1 . x2; z1 . y2; (p1 - p2) . x1; (p1 - p2) . y1]      (4 rows)
 * Outputs `angle` (as revolute3d's) and `displacement` ((p2 - p1) . z1). */
#include <math.h>
#include <stdio.h>
#include <stdlib.h>

#include "spatial_pair.h"

static int cylindrical_parse(fmbParser* p, fmbNode item, void** self) {
  fmbSpatialPair* sp = calloc(1, sizeof *sp);
  if (!sp) return fmb_parse_error(p, item, "out of memory");
  *self = sp;
  return fmbj3_parse(p, item, "axis", sp);
}

static void cylindrical_destroy(void* self) { free(self); }
static int cylindrical_nrows(const void* self) {
  (void)self;
  return 4;
}

static int cylindrical_constraint(const void* self, const fmbJointEval* ev, double* phi, double* phi_q, double* phi_t,
                                  double* phi_tt) {
  (void)phi_t, (void)phi_tt; /* scleronomic */
  const int n0 = fmb_eval_ncoord(ev, 0), ld = n0 + fmb_eval_ncoord(ev, 1);
  fmbSpatialEval e;
  const int rc = fmbj3_eval(ev, self, phi_q, ld, &e);
  if (rc) return rc;
#define ROW(r) (phi_q ? phi_q + (size_t)(r)*ld : NULL)
  /* the gap's derivative sits in rows 0..2 until the two gap rows are made from it; the second
     waits in the scratch after the virtual rotations (3 rows of ld) */
  double* tmp = phi_q ? fmb_eval_scratch(ev) + 3 * (size_t)ld : NULL;
  phi[3] = fmbj3_gap_row(&e, 0, phi_q, ROW(3), n0, ld);
  const double gy = fmbj3_gap_row(&e, 1, phi_q, tmp, n0, ld);
  phi[0] = fmbj3_axes_row(&e, 2, 0, ROW(0), n0, ld);
  phi[1] = fmbj3_axes_row(&e, 2, 1, ROW(1), n0, ld);
  phi[2] = gy;
  for (int c = 0; tmp && c < ld; ++c) phi_q[2 * (size_t)ld + c] = tmp[c];
#undef ROW
  return 0;
}

static void cylindrical_describe(const void* self, FILE* out) {
  (void)self;
  fprintf(out, "body2 turns about and slides along the axis (4 rows)\n");
}

static const char* const cylindrical_outputs[] = {"angle", "displacement", NULL};
static const char* const cylindrical_output_units[] = {"rad", "m", NULL};
static int cylindrical_output(const void* self, int id, const fmbJointEval* ev, double* value) {
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
  const double displacement =
      -(e.gap[0] * e.X[0][2] + e.gap[1] * e.X[0][5] + e.gap[2] * e.X[0][8]); /* (p2 - p1) . z1 */
  *value = id == 0 ? angle : displacement;
  return 0;
}

static const fmbParam cylindrical_params[] = {
    FMBJ_SPATIAL_PAIR_PARAMS, FMBJ_SPATIAL_AXIS_PARAM("the joint axis"), {.key = NULL}};

const fmbJointType fmb_joint_cylindrical = {
    .name = "cylindrical",
    .abi = FMB_ABI_VERSION,
    .parse = cylindrical_parse,
    .describe = cylindrical_describe,
    .destroy = cylindrical_destroy,
    .bodies = fmbj3_bodies,
    .attachment3 = fmbj3_attachment,
    .nrows = cylindrical_nrows,
    .constraint = cylindrical_constraint,
    .output_names = cylindrical_outputs,
    .output_units = cylindrical_output_units,
    .output = cylindrical_output,
    .params = cylindrical_params,
    .example = "body1: ground\nbody2: a\npoint2: [0, 0, 0.5]\naxis: [0, 0, 1]\n",
    .dimensions = FMB_DIM_SPATIAL,
};
