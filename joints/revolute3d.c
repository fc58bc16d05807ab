/* revolute3d.c — a hinge in space: the points coincide and the joint frames' z axes (the
 * `axis`, given in the global frame of the scene's pose) stay aligned:
 *   Phi = [p1 - p2; z1 . x2; z1 . y2]        (5 rows; frames as in spatial_pair.h)
 * Its output `angle` is the turn about the axis since the scene's pose, in (-pi, pi].
 * With a `profile` (the planar prismatic's convention: the same keys as a drive) the turn is
 * prescribed too, a sixth, rheonomic row:
 *   Phi_6 = turn - angle0 - f(t),  Phi_t = -f', Phi_tt = -f''
 * whose derivative is the relative virtual rotation about the axis: d turn = z1 . (dphi2 - dphi1),
 * dphi_k = G_k dq_k (spatial_pair.h). The turn is taken in (-pi, pi] and f(t) grows without
 * bound, so the row uses the turn continued to the branch nearest angle0 + f(t). */
#include <math.h>
#include <stdio.h>
#include <stdlib.h>

#include "spatial_pair.h"
#include "time_law.h"

typedef struct {
  fmbSpatialPair sp; /* first: the fmbj3_* helpers take the state as a pair */
  int driven;
  double angle0;
  fmbMotion motion;
} Revolute3d;

static int revolute3d_parse(fmbParser* p, fmbNode item, void** self) {
  Revolute3d* r = calloc(1, sizeof *r);
  *self = r;
  if (!r) return fmb_parse_error(p, item, "out of memory");
  if (fmbj3_parse(p, item, "axis", &r->sp) || fmb_get_angle(p, item, "angle0", FMB_POSE, &r->angle0)) return -1;
  r->driven = fmb_find_key(p, item, "profile") >= 0;
  return r->driven ? fmbj_motion_parse(p, item, 1, &r->motion) : 0;
}

static void revolute3d_destroy(void* self) {
  Revolute3d* r = self;
  if (r && r->driven) fmbj_law_free(&r->motion.law);
  free(r);
}

static const fmbj3Row revolute3d_rows[] = {
    {FMBJ3_GAP, 0, 0}, {FMBJ3_GAP, 1, 0}, {FMBJ3_GAP, 2, 0}, {FMBJ3_AXES, 2, 0}, {FMBJ3_AXES, 2, 1}};
enum { HINGE_ROWS = (int)(sizeof revolute3d_rows / sizeof revolute3d_rows[0]) };

static int revolute3d_nrows(const void* self) { return HINGE_ROWS + (((const Revolute3d*)self)->driven ? 1 : 0); }

static int revolute3d_constraint(const void* self, const fmbJointEval* ev, double* phi, double* phi_q, double* phi_t,
                                 double* phi_tt) {
  const Revolute3d* r = self;
  int rc = fmbj3_rows(ev, &r->sp, revolute3d_rows, HINGE_ROWS, phi, phi_q);
  if (rc || !r->driven) return rc;
  const int n0 = fmb_eval_ncoord(ev, 0), ld = n0 + fmb_eval_ncoord(ev, 1);
  fmbSpatialEval e;
  if ((rc = fmbj3_eval(ev, &r->sp, phi_q != NULL, ld, &e))) return rc;
  double f[3];
  fmbj_motion_eval(&r->motion, ev, f);
  const double target = r->angle0 + f[0], turn = fmbj3_turn(&e);
  phi[HINGE_ROWS] = turn - target - 2.0 * M_PI * round((turn - target) / (2.0 * M_PI));
  phi_t[HINGE_ROWS] = -f[1];
  phi_tt[HINGE_ROWS] = -f[2];
  if (phi_q && e.G) {
    const double z1[3] = {e.X[0][2], e.X[0][5], e.X[0][8]};
    double* row = phi_q + (size_t)HINGE_ROWS * ld;
    for (int c = 0; c < ld; ++c) {
      const double s = c < n0 ? -1.0 : 1.0; /* turn = body2's rotation less body1's */
      row[c] = s * (z1[0] * e.G[c] + z1[1] * e.G[ld + c] + z1[2] * e.G[2 * (size_t)ld + c]);
    }
  }
  return 0;
}

static int revolute3d_input(const void* self, double* initial) {
  const Revolute3d* r = self;
  return r->driven && fmbj_law_input(&r->motion.law, initial);
}

static void revolute3d_describe(const void* self, FILE* out) {
  const Revolute3d* r = self;
  if (r->driven)
    fprintf(out, "the points coincide, the bodies turn about one axis, the turn prescribed (%s profile; 6 rows)\n",
            fmbj_motion_name(&r->motion));
  else
    fprintf(out, "the points coincide, the bodies turn about one axis (5 rows)\n");
}

static const char* const revolute3d_outputs[] = {"angle", "speed", NULL};
static const char* const revolute3d_output_units[] = {"rad", "rad/s", NULL};
/* angle: the turn as the bodies are; speed: its rate, z1 . (omega2 - omega1), from the same
   relative virtual rotation as the driven row (on the constraint manifold of a driven hinge, f') */
static int revolute3d_output(const void* self, int id, const fmbJointEval* ev, double* value) {
  const Revolute3d* r = self;
  const int n0 = fmb_eval_ncoord(ev, 0), ld = n0 + fmb_eval_ncoord(ev, 1);
  fmbSpatialEval e;
  const int rc = fmbj3_eval(ev, &r->sp, id == 1, ld, &e);
  if (rc) return rc;
  if (id == 0) {
    *value = fmbj3_turn(&e);
    return 0;
  }
  const double z1[3] = {e.X[0][2], e.X[0][5], e.X[0][8]};
  const double *v0 = fmb_eval_v(ev, 0), *v1 = fmb_eval_v(ev, 1);
  double rate = 0.0;
  for (int c = 0; c < ld; ++c) {
    const double vc = c < n0 ? -v0[c] : v1[c - n0];
    rate += vc * (z1[0] * e.G[c] + z1[1] * e.G[ld + c] + z1[2] * e.G[2 * (size_t)ld + c]);
  }
  *value = rate;
  return 0;
}

static const fmbParam revolute3d_params[] = {FMBJ_SPATIAL_PAIR_PARAMS,
                                             FMBJ_SPATIAL_AXIS_PARAM("the joint axis"),
                                             {.key = "angle0",
                                              .kind = FMB_PARAM_NUMBER,
                                              .unit = "rad",
                                              .fallback = "0",
                                              .doc = "turn at f = 0 (with a profile)"},
                                             FMBJ_OPTIONAL_MOTION_PARAMS("rad", "turn"),
                                             {.key = NULL}};

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
    .input = revolute3d_input,
    .output_names = revolute3d_outputs,
    .output_units = revolute3d_output_units,
    .output = revolute3d_output,
    .params = revolute3d_params,
    .example = "body1: a\nbody2: b\npoint1: [0.5, 0, 0]\npoint2: [-0.5, 0, 0]\naxis: [0, 0, 1]\n",
    .dimensions = FMB_DIM_SPATIAL,
};
