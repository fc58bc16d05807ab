/* torsion.c — a rotational spring-damper between the angles of point1 on body1 and point2 on
 * body2 (either may be the ground; on a beam the angle at a point includes the local slope):
 *   phi = angle2 - angle1,   torque on body2  tau = -k (phi - angle0) - c phi',   on body1 -tau. angle0 is the set point: with body1 the ground it is the PD law
 * tau = -k (angle - angle0) - c omega of a motor controller (examples/embed/ checks one against the
 * other). Generalized force by virtual work, Q = tau dphi/dq with dphi/dq = [-dangle1/dq1,
 * dangle2/dq2]; phi' = dphi/dq . v; potential energy k (phi - angle0)^2 / 2. */
#include <math.h>
#include <stdio.h>
#include <stdlib.h>

#include "two_point.h"

typedef struct {
  fmbTwoPoint tp;
  double stiffness, damping, angle0;
} Torsion;

static int torsion_parse(fmbParser* p, fmbNode item, void** self) {
  Torsion* s = calloc(1, sizeof *s);
  if (!s) return fmb_parse_error(p, item, "out of memory");
  *self = s;
  return fmbj_parse_two_points(p, item, &s->tp) ||
                 fmb_get_double(p, item, "stiffness", FMB_REQUIRED | FMB_NONNEGATIVE, &s->stiffness) ||
                 fmb_get_double(p, item, "damping", FMB_NONNEGATIVE, &s->damping) ||
                 fmb_get_angle(p, item, "angle0", 0, &s->angle0)
             ? -1
             : 0;
}

static void torsion_destroy(void* self) { free(self); }

/* phi, phi' and dphi/dq (ld entries, into dphi) */
static int torsion_state(const Torsion* s, const fmbJointEval* ev, double* dphi, double* phi, double* rate) {
  const int ld = fmb_eval_ncoord(ev, 0) + fmb_eval_ncoord(ev, 1);
  double gap[2], ang[2];
  for (int i = 0; i < ld; ++i) dphi[i] = 0.0;
  int rc = fmbj_point_gap(ev, &s->tp, gap, NULL, 0, ang, dphi);
  if (rc) return rc;
  *phi = ang[1] - ang[0];
  double r = 0.0;
  for (int k = 0; k < 2; ++k) {
    const double* v = fmb_eval_v(ev, k);
    const int c0 = fmb_eval_col0(ev, k), n = fmb_eval_ncoord(ev, k);
    for (int i = 0; i < n; ++i) r += dphi[c0 + i] * v[i];
  }
  *rate = r;
  return 0;
}

static int torsion_force(const void* self, const fmbJointEval* ev, double* Q) {
  const Torsion* s = self;
  const int ld = fmb_eval_ncoord(ev, 0) + fmb_eval_ncoord(ev, 1);
  double* dphi = fmb_eval_scratch(ev);
  double phi, rate;
  int rc = torsion_state(s, ev, dphi, &phi, &rate);
  if (rc) return rc;
  const double tau = -s->stiffness * (phi - s->angle0) - s->damping * rate;
  for (int i = 0; i < ld; ++i) Q[i] += tau * dphi[i];
  return 0;
}

static double torsion_energy(const void* self, const fmbJointEval* ev) {
  const Torsion* s = self;
  double gap[2], ang[2];
  if (fmbj_point_gap(ev, &s->tp, gap, NULL, 0, ang, NULL)) return NAN;
  const double x = ang[1] - ang[0] - s->angle0;
  return 0.5 * s->stiffness * x * x;
}

static const char* const torsion_outputs[] = {"angle", "torque", NULL};
static const char* const torsion_output_units[] = {"rad", "N m", NULL};
/* angle: phi = angle2 - angle1; torque: tau, on body2 */
static int torsion_output(const void* self, int id, const fmbJointEval* ev, double* value) {
  const Torsion* s = self;
  double phi = 0.0, rate = 0.0;
  const int rc = torsion_state(s, ev, fmb_eval_scratch(ev), &phi, &rate);
  *value = id == 0 ? phi : -s->stiffness * (phi - s->angle0) - s->damping * rate;
  return rc;
}

static void torsion_describe(const void* self, FILE* out) {
  const Torsion* s = self;
  fprintf(out, "rotational spring-damper k = %g N m/rad, c = %g N m s/rad, set point %g rad\n", s->stiffness,
          s->damping, s->angle0);
}

static const fmbParam torsion_params[] = {
    FMBJ_TWO_POINT_PARAMS,
    FMBJ_ROTATIONAL_SPRING_PARAMS,
    {.key = NULL},
};

const fmbJointType fmb_joint_torsion = {
    .name = "torsion",
    .abi = FMB_ABI_VERSION,
    .parse = torsion_parse,
    .describe = torsion_describe,
    .destroy = torsion_destroy,
    .bodies = fmbj_two_point_bodies,
    .attachment = fmbj_two_point_attachment,
    .force = torsion_force,
    .energy = torsion_energy,
    .output_names = torsion_outputs,
    .output_units = torsion_output_units,
    .output = torsion_output,
    .params = torsion_params,
    .example = "body1: a\nbody2: b\npoint1: [0.5, 0]\npoint2: [-0.5, 0]\nstiffness: 3\nangle0: 0.2\n",
    .example_damped = "damping: 0.5\n",
};
