/* torsion3d.c — a rotational spring-damper about an axis in space, the spatial `torsion`: put it
 * beside a revolute3d with the same bodies and `axis` and it is that hinge's spring. With the
 * joint frames of spatial_pair.h (z = `axis`, coincident in the scene's pose) the turn is
 *   phi = atan2(y1 . x2, x1 . x2)        (fmbj3_turn: 0 in the scene's pose)
 * and the torque on body2 about z1 is tau = -k (phi - angle0) - c phi', on body1 -tau.
 * Generalized force by virtual work, Q = tau dphi/dq with the exact gradient of phi
 * (fmbj3_turn_row, through both bodies' virtual rotations G of fmb_marker3), so that the force is
 * -dV/dq of the potential V = k (phi - angle0)^2 / 2 everywhere, on a hinge or not (off a hinge
 * the turn is that of x2 projected on frame 1's x-y plane); phi' = dphi/dq . v. phi - angle0 is
 * taken in (-pi, pi]: a spring of more than half a turn is out of its range. */
#include <math.h>
#include <stdio.h>
#include <stdlib.h>

#include "spatial_pair.h"
#include "two_point.h" /* FMBJ_ROTATIONAL_SPRING_PARAMS, the planar torsion's keys */

typedef struct {
  fmbSpatialPair sp; /* first: the fmbj3_* helpers take the state as a pair */
  double stiffness, damping, angle0;
} Torsion3d;

static int torsion3d_parse(fmbParser* p, fmbNode item, void** self) {
  Torsion3d* s = calloc(1, sizeof *s);
  *self = s;
  if (!s) return fmb_parse_error(p, item, "out of memory");
  return fmbj3_parse(p, item, "axis", &s->sp) ||
                 fmb_get_double(p, item, "stiffness", FMB_REQUIRED | FMB_NONNEGATIVE, &s->stiffness) ||
                 fmb_get_double(p, item, "damping", FMB_NONNEGATIVE, &s->damping) ||
                 fmb_get_angle(p, item, "angle0", 0, &s->angle0)
             ? -1
             : 0;
}

/* phi - angle0 in (-pi, pi] */
static double wrapped(double x) { return x - 2.0 * M_PI * round(x / (2.0 * M_PI)); }

/* the turn, its rate and (dphi not NULL) its gradient over the joint's columns */
static int torsion3d_state(const Torsion3d* s, const fmbJointEval* ev, double* dphi, double* phi, double* rate) {
  const int n0 = fmb_eval_ncoord(ev, 0), ld = n0 + fmb_eval_ncoord(ev, 1);
  fmbSpatialEval e;
  const int rc = fmbj3_eval(ev, &s->sp, 1, ld, &e);
  if (rc) return rc;
  *phi = fmbj3_turn_row(&e, dphi, n0);
  const double *v0 = fmb_eval_v(ev, 0), *v1 = fmb_eval_v(ev, 1);
  double r = 0.0;
  for (int c = 0; c < ld; ++c) r += dphi[c] * (c < n0 ? v0[c] : v1[c - n0]);
  *rate = r;
  return 0;
}

/* where the gradient row goes: the scratch (6 ld) holds G (3 ld) and then the gap's rows (3 ld),
   which the turn does not read (fmbj3_turn_row reads G and the frames only) */
static double* gradient_row(const fmbJointEval* ev) {
  const int ld = fmb_eval_ncoord(ev, 0) + fmb_eval_ncoord(ev, 1);
  return fmb_eval_scratch(ev) + 3 * (size_t)ld;
}

static int torsion3d_force(const void* self, const fmbJointEval* ev, double* Q) {
  const Torsion3d* s = self;
  const int ld = fmb_eval_ncoord(ev, 0) + fmb_eval_ncoord(ev, 1);
  double* dphi = gradient_row(ev);
  double phi, rate;
  const int rc = torsion3d_state(s, ev, dphi, &phi, &rate);
  if (rc) return rc;
  const double tau = -s->stiffness * wrapped(phi - s->angle0) - s->damping * rate;
  for (int i = 0; i < ld; ++i) Q[i] += tau * dphi[i];
  return 0;
}

static double torsion3d_energy(const void* self, const fmbJointEval* ev) {
  const Torsion3d* s = self;
  fmbSpatialEval e;
  if (fmbj3_eval(ev, &s->sp, 0, 0, &e)) return NAN;
  const double x = wrapped(fmbj3_turn(&e) - s->angle0);
  return 0.5 * s->stiffness * x * x;
}

static const char* const torsion3d_outputs[] = {"angle", "speed", "torque", NULL};
static const char* const torsion3d_output_units[] = {"rad", "rad/s", "N m", NULL};
/* angle: phi; speed: phi'; torque: tau, on body2 about the axis */
static int torsion3d_output(const void* self, int id, const fmbJointEval* ev, double* value) {
  const Torsion3d* s = self;
  double phi = NAN, rate = NAN;
  const int rc = torsion3d_state(s, ev, gradient_row(ev), &phi, &rate);
  *value = id == 0 ? phi : id == 1 ? rate : -s->stiffness * wrapped(phi - s->angle0) - s->damping * rate;
  return rc;
}

static void torsion3d_describe(const void* self, FILE* out) {
  const Torsion3d* s = self;
  fprintf(out, "rotational spring-damper about an axis, k = %g N m/rad, c = %g N m s/rad, set point %g rad\n",
          s->stiffness, s->damping, s->angle0);
}

static const fmbParam torsion3d_params[] = {
    FMBJ_SPATIAL_PAIR_PARAMS,
    FMBJ_SPATIAL_AXIS_PARAM("the axis of the turn"),
    FMBJ_ROTATIONAL_SPRING_PARAMS,
    {.key = NULL},
};

const fmbJointType fmb_joint_torsion3d = {
    .name = "torsion3d",
    .abi = FMB_ABI_VERSION,
    .parse = torsion3d_parse,
    .describe = torsion3d_describe,
    .destroy = fmbj3_destroy,
    .bodies = fmbj3_bodies,
    .force = torsion3d_force,
    .energy = torsion3d_energy,
    .output_names = torsion3d_outputs,
    .output_units = torsion3d_output_units,
    .output = torsion3d_output,
    .params = torsion3d_params,
    .example = "body1: a\nbody2: b\npoint1: [0.5, 0, 0]\npoint2: [-0.5, 0, 0]\naxis: [0, 0, 1]\nstiffness: 3\nangle0: "
               "0.2\n",
    .example_damped = "damping: 0.5\n",
    .dimensions = FMB_DIM_SPATIAL,
};
