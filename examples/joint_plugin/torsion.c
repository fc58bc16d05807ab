/* torsion.c — a torsional spring-damper between two bodies, built out of tree as a plugin
 * (docs/plugins.md, "A joint type"). It joins the material point `point1` of body1 and `point2`
 * of body2 (either may be the ground) and acts on their relative rotation
 *
 *     phi = angle2 - angle1          (the two points' orientations, from fmb_marker)
 *     torque on body2 = -(k (phi - angle0) + c dphi/dt),  and its opposite on body1,
 *
 * as generalized forces Q = -(k (phi - angle0) + c dphi/dt) dphi/dq, where dphi/dq is body2's
 * dangle/dq minus body1's (fmb_marker gives both, in their own columns of Q). The rate is
 * dphi/dt = dphi/dq . v, with v the two bodies' velocities (fmb_eval_v): a rigid body's angular
 * velocity is its third velocity, but asking the marker works for any body, a beam's cross-section
 * included. Potential energy k (phi - angle0)^2 / 2. No constraint rows: a force element, drawn by
 * `--vtk` and `flexmbd view` as the line between its two points (the `attachment` op).
 * flexmbd has the same element built in (`type: torsion`, joints/torsion.c); this one, registered
 * as `torsion_spring`, is the worked example of writing a joint outside the tree. */
#include <math.h>
#include <stdio.h>
#include <stdlib.h>

#include <flexmbd_plugin.h>

typedef struct {
  int body[2];         /* body indices (0 = the ground), as fmb_get_body gives them */
  double point[2][2];  /* the points, each in its body's frame */
  double k, c, angle0; /* N m/rad, N m s/rad, rad */
} Torsion;

static int torsion_parse(fmbParser* p, fmbNode item, void** self) {
  Torsion* s = calloc(1, sizeof *s);
  if (!s) return fmb_parse_error(p, item, "out of memory");
  *self = s; /* handed back at once: destroy frees it also when parsing fails */
  return fmb_get_body(p, item, "body1", FMB_REQUIRED, &s->body[0]) ||
                 fmb_get_body(p, item, "body2", FMB_REQUIRED, &s->body[1]) ||
                 fmb_get_point(p, item, "point1", 0, s->body[0], s->point[0]) ||
                 fmb_get_point(p, item, "point2", 0, s->body[1], s->point[1]) ||
                 fmb_get_double(p, item, "stiffness", FMB_REQUIRED | FMB_NONNEGATIVE, &s->k) ||
                 fmb_get_double(p, item, "damping", FMB_NONNEGATIVE, &s->c) ||
                 fmb_get_angle(p, item, "angle0", 0, &s->angle0)
             ? -1
             : 0;
}

static void torsion_destroy(void* self) { free(self); }

static void torsion_bodies(const void* self, int body[2]) {
  const Torsion* s = self;
  body[0] = s->body[0];
  body[1] = s->body[1];
}

/* where the element is drawn: point k on its body (k = 0, 1) */
static int torsion_attachment(const void* self, int k, int* body, double local[2]) {
  const Torsion* s = self;
  if (k != 0 && k != 1) return -1;
  *body = s->body[k];
  local[0] = s->point[k][0];
  local[1] = s->point[k][1];
  return 0;
}

/* phi, its rate and dphi/dq (into dphi[0 .. ncoord0 + ncoord1), body1's columns first) */
static int relative_angle(const Torsion* s, const fmbJointEval* ev, double* phi, double* rate, double* dphi) {
  double pos[2], angle[2];
  for (int k = 0; k < 2; ++k) {
    /* the ground has no coordinates: fmb_marker gives angle 0 and writes no derivative */
    const int rc = fmb_marker(ev, k, s->point[k], pos, &angle[k], NULL, 0, dphi + fmb_eval_col0(ev, k));
    if (rc) return rc;
  }
  const int n0 = fmb_eval_ncoord(ev, 0), n = n0 + fmb_eval_ncoord(ev, 1);
  for (int i = 0; i < n0; ++i) dphi[i] = -dphi[i]; /* phi = angle2 - angle1 */
  *phi = angle[1] - angle[0];
  *rate = 0.0;
  for (int k = 0; k < 2; ++k) {
    const double* v = fmb_eval_v(ev, k);
    const int c0 = fmb_eval_col0(ev, k), nk = fmb_eval_ncoord(ev, k);
    for (int i = 0; i < nk; ++i) *rate += dphi[c0 + i] * v[i];
  }
  (void)n;
  return 0;
}

static int torsion_force(const void* self, const fmbJointEval* ev, double* Q) {
  const Torsion* s = self;
  double* dphi = fmb_eval_scratch(ev); /* 2 (ncoord0 + ncoord1) doubles: room for dphi/dq */
  double phi, rate;
  const int rc = relative_angle(s, ev, &phi, &rate, dphi);
  if (rc) return rc;
  const double torque = -(s->k * (phi - s->angle0) + s->c * rate); /* on body2 */
  const int n = fmb_eval_ncoord(ev, 0) + fmb_eval_ncoord(ev, 1);
  for (int i = 0; i < n; ++i) Q[i] += torque * dphi[i]; /* adds: other elements share Q */
  return 0;
}

static double torsion_energy(const void* self, const fmbJointEval* ev) {
  const Torsion* s = self;
  double phi, rate;
  if (relative_angle(s, ev, &phi, &rate, fmb_eval_scratch(ev))) return NAN;
  return 0.5 * s->k * (phi - s->angle0) * (phi - s->angle0);
}

/* outputs JOINT.angle (phi, rad) and JOINT.torque (on body2, N m); the engine adds power, work */
static const char* const torsion_outputs[] = {"angle", "torque", NULL};
static int torsion_output(const void* self, int id, const fmbJointEval* ev, double* value) {
  const Torsion* s = self;
  double phi, rate;
  const int rc = relative_angle(s, ev, &phi, &rate, fmb_eval_scratch(ev));
  *value = id == 0 ? phi : -(s->k * (phi - s->angle0) + s->c * rate);
  return rc;
}

static void torsion_describe(const void* self, FILE* out) {
  const Torsion* s = self;
  fprintf(out, "torsional spring-damper k = %g N m/rad, c = %g N m s/rad, rest angle %g rad\n", s->k, s->c, s->angle0);
}

static const fmbParam torsion_params[] = {
    {.key = "body1", .kind = FMB_PARAM_BODY, .flags = FMB_REQUIRED, .doc = "first body (or ground)"},
    {.key = "body2", .kind = FMB_PARAM_BODY, .flags = FMB_REQUIRED, .doc = "second body (or ground)"},
    {.key = "point1", .kind = FMB_PARAM_VEC2, .unit = "m", .fallback = "[0, 0]", .doc = "point on body1, body frame"},
    {.key = "point2", .kind = FMB_PARAM_VEC2, .unit = "m", .fallback = "[0, 0]", .doc = "point on body2, body frame"},
    {.key = "stiffness",
     .kind = FMB_PARAM_NUMBER,
     .flags = FMB_REQUIRED | FMB_NONNEGATIVE,
     .unit = "N m/rad",
     .doc = "torsional rate k"},
    {.key = "damping",
     .kind = FMB_PARAM_NUMBER,
     .flags = FMB_NONNEGATIVE,
     .unit = "N m s/rad",
     .fallback = "0",
     .doc = "torsional damper rate c"},
    {.key = "angle0", .kind = FMB_PARAM_NUMBER, .unit = "rad", .fallback = "0", .doc = "relative angle at rest"},
    {.key = NULL},
};

static const fmbJointType torsion_type = {
    .name = "torsion_spring", /* not "torsion": that is a built-in type (joints/torsion.c) */
    .abi = FMB_ABI_VERSION,
    .parse = torsion_parse,
    .destroy = torsion_destroy,
    .bodies = torsion_bodies,
    .attachment = torsion_attachment,
    .force = torsion_force,
    .energy = torsion_energy,
    .output_names = torsion_outputs,
    .output = torsion_output,
    .describe = torsion_describe,
    .params = torsion_params,
    /* conform's fixture: rigid bodies a (pinned to ground) and b, 1 m long each */
    .example = "body1: a\nbody2: b\npoint1: [0.5, 0]\npoint2: [-0.5, 0]\nstiffness: 5\nangle0: 0.2\n",
    .example_damped = "damping: 0.5\n",
};

static const fmbJointType* const joints[] = {&torsion_type, NULL};
static const fmbPlugin plugin = {.abi = FMB_ABI_VERSION, .name = "torsion_spring", .version = "1.0", .joints = joints};

FMB_PLUGIN_EXPORT const fmbPlugin* fmb_plugin_descriptor(void) { return &plugin; }
