/* prismatic.c — a slider: point2 on body2 moves along a line through point1 on body1, the line's
 * direction `axis` fixed in body1's frame at point1, and the relative angle stays `angle` (default: as drawn).
 * With the axis e = R(angle1) a/|a| and its normal n = R(angle1) Ĩ a/|a| (angle1: the marker angle
 * of point1, which on a beam includes the local slope) and d = p2 - p1:
 *   Phi_0 = n . d                         = 0   (stay on the line)
 *   Phi_1 = (angle2 - angle1) - angle     = 0   (no relative rotation)
 *   Phi_2 = e . d - offset - f(t)         = 0   (only with a `profile`: a prescribed slide)
 * Derivatives (dR/dangle = Ĩ R, so de/dangle1 = n, dn/dangle1 = -e):
 *   dPhi_0/dq = n^T dd/dq - (e . d) dangle1/dq,   ds/dq = e^T dd/dq + (n . d) dangle1/dq,  s = e . d.
 * An optional spring-damper acts along the axis: tension f = k (s - rest_displacement) + c ds/dt,
 * Q = -f ds/dq (virtual work of the potential k (s - s_r)^2 / 2 and of the damper). */
#include <math.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>

#include "time_law.h"
#include "two_point.h"

typedef struct {
  fmbTwoPoint tp;
  double axis[2]; /* unit, in body1's frame */
  double angle, offset;
  int driven;
  fmbMotion motion;
  double stiffness, damping, rest;
} Prismatic;

static int prismatic_parse(fmbParser* p, fmbNode item, void** self) {
  Prismatic* s = calloc(1, sizeof *s);
  if (!s) return fmb_parse_error(p, item, "out of memory");
  *self = s;
  s->axis[0] = 1.0;
  if (fmbj_parse_two_points(p, item, &s->tp)) return -1;
  double pos[2], ang[2];
  for (int k = 0; k < 2; ++k)
    if (fmb_initial_marker(p, s->tp.body[k], s->tp.point[k], pos, &ang[k]))
      return fmb_parse_error(p, item, "prismatic joint: cannot place point%d on its body", k + 1);
  s->angle = ang[1] - ang[0]; /* as drawn, like a weld's */
  if (fmb_get_vec2(p, item, "axis", 0, s->axis) || fmb_get_angle(p, item, "angle", FMB_POSE, &s->angle) ||
      fmb_get_double(p, item, "offset", 0, &s->offset) ||
      fmb_get_double(p, item, "stiffness", FMB_NONNEGATIVE, &s->stiffness) ||
      fmb_get_double(p, item, "damping", FMB_NONNEGATIVE, &s->damping) ||
      fmb_get_double(p, item, "rest_displacement", 0, &s->rest))
    return -1;
  const double len = hypot(s->axis[0], s->axis[1]);
  if (!(len > 0))
    return fmb_parse_error(p, fmb_find_key(p, item, "axis"), "expected a non-zero axis direction [ax, ay]");
  s->axis[0] /= len;
  s->axis[1] /= len;
  s->driven = fmb_find_key(p, item, "profile") >= 0;
  return s->driven ? fmbj_motion_parse(p, item, 0, &s->motion) : 0;
}

static void prismatic_destroy(void* self) {
  Prismatic* s = self;
  if (s->driven) fmbj_law_free(&s->motion.law);
  free(s);
}
static int prismatic_nrows(const void* self) { return ((const Prismatic*)self)->driven ? 3 : 2; }

typedef struct {
  double e[2], n[2]; /* axis and normal, global */
  double s, h;       /* e . d (slide), n . d (off the line) */
  double ang[2];     /* marker angles */
} Slide;

/* G (2 x ld) = d(p1 - p2)/dq; dang (ld, may be NULL) = d(angle2 - angle1)/dq */
static int slide_eval(const Prismatic* ps, const fmbJointEval* ev, double* G, int ld, double* dang, Slide* sl) {
  double gap[2];
  int rc = fmbj_point_gap(ev, &ps->tp, gap, G, ld, sl->ang, dang);
  if (rc) return rc;
  const double c = cos(sl->ang[0]), s = sin(sl->ang[0]);
  sl->e[0] = c * ps->axis[0] - s * ps->axis[1];
  sl->e[1] = s * ps->axis[0] + c * ps->axis[1];
  sl->n[0] = -sl->e[1];
  sl->n[1] = sl->e[0];
  sl->s = -(sl->e[0] * gap[0] + sl->e[1] * gap[1]);
  sl->h = -(sl->n[0] * gap[0] + sl->n[1] * gap[1]);
  return 0;
}

static int prismatic_constraint(const void* self, const fmbJointEval* ev, double* phi, double* phi_q, double* phi_t,
                                double* phi_tt) {
  const Prismatic* ps = self;
  const int ld = fmb_eval_ncoord(ev, 0) + fmb_eval_ncoord(ev, 1), n0 = fmb_eval_ncoord(ev, 0);
  double* G = fmb_eval_scratch(ev);
  double* dang = phi_q + ld; /* row 1 is d(angle2 - angle1)/dq itself */
  Slide sl;
  int rc = slide_eval(ps, ev, G, ld, dang, &sl);
  if (rc) return rc;
  phi[0] = sl.h;
  phi[1] = (sl.ang[1] - sl.ang[0]) - ps->angle;
  for (int c = 0; c < ld; ++c) {
    const double dangle1 = c < n0 ? -dang[c] : 0.0; /* dang holds -dangle1/dq on body1's columns */
    const double ne = -(sl.n[0] * G[c] + sl.n[1] * G[ld + c]), ee = -(sl.e[0] * G[c] + sl.e[1] * G[ld + c]);
    phi_q[c] = ne - sl.s * dangle1;
    if (ps->driven) phi_q[2 * ld + c] = ee + sl.h * dangle1;
  }
  if (ps->driven) {
    double f[3];
    fmbj_motion_eval(&ps->motion, ev, f);
    phi[2] = sl.s - ps->offset - f[0];
    phi_t[2] = -f[1];
    phi_tt[2] = -f[2];
  }
  return 0;
}

/* slide s, its rate, and (with Q) Q += -f ds/dq for the tension f of the spring-damper */
static int slide_state(const Prismatic* ps, const fmbJointEval* ev, double* Q, double* s_out, double* rate_out) {
  const int ld = fmb_eval_ncoord(ev, 0) + fmb_eval_ncoord(ev, 1), n0 = fmb_eval_ncoord(ev, 0);
  double* D = fmb_eval_scratch(ev);
  const double* v0 = fmb_eval_v(ev, 0);
  double pos[2], ang, w1 = 0.0;
  /* angular rate of marker 1 first (the scratch is then reused for the point derivatives) */
  int rc = fmb_marker(ev, 0, ps->tp.point[0], pos, &ang, NULL, 0, D);
  if (rc) return rc;
  for (int i = 0; i < n0; ++i) w1 += D[i] * v0[i];
  Slide sl;
  rc = slide_eval(ps, ev, D, ld, NULL, &sl);
  if (rc) return rc;
  double gdot[2] = {0.0, 0.0};
  for (int k = 0; k < 2; ++k) {
    const double* v = fmb_eval_v(ev, k);
    const int c0 = fmb_eval_col0(ev, k), n = fmb_eval_ncoord(ev, k);
    for (int i = 0; i < n; ++i) {
      gdot[0] += D[c0 + i] * v[i];
      gdot[1] += D[ld + c0 + i] * v[i];
    }
  }
  const double rate = -(sl.e[0] * gdot[0] + sl.e[1] * gdot[1]) + sl.h * w1;
  *s_out = sl.s;
  *rate_out = rate;
  if (!Q) return 0;
  const double f = ps->stiffness * (sl.s - ps->rest) + ps->damping * rate;
  for (int c = 0; c < ld; ++c) Q[c] += f * (sl.e[0] * D[c] + sl.e[1] * D[ld + c]);
  rc = fmb_marker(ev, 0, ps->tp.point[0], pos, &ang, NULL, 0, D);
  for (int i = 0; i < n0; ++i) Q[i] -= f * sl.h * D[i];
  return rc;
}

static int prismatic_force(const void* self, const fmbJointEval* ev, double* Q) {
  const Prismatic* ps = self;
  if (ps->stiffness == 0.0 && ps->damping == 0.0) return 0;
  double s, rate;
  return slide_state(ps, ev, Q, &s, &rate);
}

static double prismatic_energy(const void* self, const fmbJointEval* ev) {
  const Prismatic* ps = self;
  double s, rate;
  if (ps->stiffness == 0.0) return 0.0;
  if (slide_state(ps, ev, NULL, &s, &rate)) return NAN;
  return 0.5 * ps->stiffness * (s - ps->rest) * (s - ps->rest);
}

static const char* const prismatic_outputs[] = {"displacement", "velocity", "tension", NULL};
static const char* const prismatic_output_units[] = {"m", "m/s", "N", NULL};
/* slide along the axis, its rate, and the spring-damper's tension */
static int prismatic_output(const void* self, int id, const fmbJointEval* ev, double* value) {
  const Prismatic* ps = self;
  double s, rate;
  int rc = slide_state(ps, ev, NULL, &s, &rate);
  *value = id == 0 ? s : id == 1 ? rate : ps->stiffness * (s - ps->rest) + ps->damping * rate;
  return rc;
}

static int prismatic_input(const void* self, double* initial) {
  const Prismatic* ps = self;
  return ps->driven && fmbj_law_input(&ps->motion.law, initial);
}

static void prismatic_describe(const void* self, FILE* out) {
  const Prismatic* ps = self;
  fprintf(out, "slides along [%g, %g] of body1, relative angle held at %g rad", ps->axis[0], ps->axis[1], ps->angle);
  if (ps->driven) fprintf(out, ", slide prescribed (%s profile)", fmbj_motion_name(&ps->motion));
  if (ps->stiffness > 0 || ps->damping > 0)
    fprintf(out, ", spring-damper k = %g N/m, c = %g N s/m", ps->stiffness, ps->damping);
  fprintf(out, "\n");
}

static const fmbParam prismatic_params[] = {
    FMBJ_TWO_POINT_PARAMS,
    {.key = "axis",
     .kind = FMB_PARAM_VEC2,
     .fallback = "[1, 0]",
     .doc = "slide direction in body1's frame at point1 (non-zero)"},
    {.key = "angle",
     .kind = FMB_PARAM_NUMBER,
     .unit = "rad",
     .fallback = "0",
     .doc = "angle of body2 relative to body1"},
    {.key = "offset", .kind = FMB_PARAM_NUMBER, .unit = "m", .fallback = "0", .doc = "slide at f = 0 (with a profile)"},
    {.key = "stiffness",
     .kind = FMB_PARAM_NUMBER,
     .flags = FMB_NONNEGATIVE,
     .unit = "N/m",
     .fallback = "0",
     .doc = "spring along the axis"},
    {.key = "damping",
     .kind = FMB_PARAM_NUMBER,
     .flags = FMB_NONNEGATIVE,
     .unit = "N s/m",
     .fallback = "0",
     .doc = "damper along the axis"},
    {.key = "rest_displacement",
     .kind = FMB_PARAM_NUMBER,
     .unit = "m",
     .fallback = "0",
     .doc = "slide where the spring is relaxed"},
    FMBJ_OPTIONAL_MOTION_PARAMS("m", "slide"),
    {.key = NULL},
};

const fmbJointType fmb_joint_prismatic = {
    .name = "prismatic",
    .abi = FMB_ABI_VERSION,
    .parse = prismatic_parse,
    .describe = prismatic_describe,
    .input = prismatic_input,
    .destroy = prismatic_destroy,
    .bodies = fmbj_two_point_bodies,
    .nrows = prismatic_nrows,
    .attachment = fmbj_two_point_attachment,
    .constraint = prismatic_constraint,
    .force = prismatic_force,
    .energy = prismatic_energy,
    .output_names = prismatic_outputs,
    .output_units = prismatic_output_units,
    .output = prismatic_output,
    .params = prismatic_params,
    .example = "body1: a\nbody2: b\npoint1: [0.5, 0]\npoint2: [-0.5, 0]\nstiffness: 20\nrest_displacement: 0.1\n",
    .example_damped = "damping: 2\n",
};
