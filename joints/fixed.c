/* fixed.c — a weld: point1 and point2 coincide and the relative angle stays `angle`:
 * Phi = [p1 - p2; (angle2 - angle1) - angle] (3 rows). A beam on a hub is a fixed joint between
 * the hub and the beam's root. `angle` defaults to the relative angle of the two points in the
 * poses the scene gives (the weld holds the mechanism as drawn): a default of 0 silently turned
 * bodies drawn at an angle. */
#include <stdio.h>
#include <stdlib.h>

#include "two_point.h"

typedef struct {
  fmbTwoPoint tp;
  double angle;
} Fixed;

static int fixed_parse(fmbParser* p, fmbNode item, void** self) {
  Fixed* f = calloc(1, sizeof *f);
  if (!f) return fmb_parse_error(p, item, "out of memory");
  *self = f;
  if (fmbj_parse_two_points(p, item, &f->tp)) return -1;
  double pos[2], ang[2];
  for (int k = 0; k < 2; ++k)
    if (fmb_initial_marker(p, f->tp.body[k], f->tp.point[k], pos, &ang[k]))
      return fmb_parse_error(p, item, "fixed joint: cannot place point%d on its body", k + 1);
  f->angle = ang[1] - ang[0]; /* as assembled */
  return fmb_get_angle(p, item, "angle", FMB_POSE, &f->angle) ? -1 : 0;
}

static void fixed_destroy(void* self) { free(self); }
static int fixed_nrows(const void* self) {
  (void)self;
  return 3;
}

static int fixed_constraint(const void* self, const fmbJointEval* ev, double* phi, double* phi_q, double* phi_t,
                            double* phi_tt) {
  (void)phi_t, (void)phi_tt;
  const Fixed* f = self;
  const int ld = fmb_eval_ncoord(ev, 0) + fmb_eval_ncoord(ev, 1);
  double ang[2];
  int rc = fmbj_point_gap(ev, &f->tp, phi, phi_q, ld, ang, phi_q + 2 * ld);
  phi[2] = (ang[1] - ang[0]) - f->angle;
  return rc;
}

static void fixed_describe(const void* self, FILE* out) {
  const Fixed* f = self;
  fprintf(out, "points coincide, relative angle held at %g rad\n", f->angle);
}

static const fmbParam fixed_params[] = {
    FMBJ_TWO_POINT_PARAMS,
    {.key = "angle",
     .kind = FMB_PARAM_NUMBER,
     .unit = "rad",
     .fallback = "0",
     .doc = "angle of body2 relative to body1"},
    {.key = NULL},
};

const fmbJointType fmb_joint_fixed = {
    .name = "fixed",
    .abi = FMB_ABI_VERSION,
    .parse = fixed_parse,
    .describe = fixed_describe,
    .destroy = fixed_destroy,
    .bodies = fmbj_two_point_bodies,
    .nrows = fixed_nrows,
    .attachment = fmbj_two_point_attachment,
    .constraint = fixed_constraint,
    .params = fixed_params,
    .example = "body1: a\nbody2: b\npoint1: [0.5, 0]\npoint2: [-0.5, 0]\n",
};
