/* force.c — an applied load: force [fx, fy] at `point` on `body` and a torque, both scaled by a
 * time law s(t) (time_law.c: constant, ramp, harmonic, spinup, table, input). With `frame: global` the
 * force keeps its direction in the global frame; with `frame: body` it is given in the frame of
 * the material point and turns with it (a follower load: F = R(angle) F_local, angle = the
 * marker's angle, which on a beam includes the local slope).
 * Generalized force by virtual work: Q = (dp/dq)^T F + (dangle/dq)^T torque. */
#include <math.h>
#include <stdio.h>
#include <stdlib.h>

#include "time_law.h"

static const char* const load_frames[] = {"global", "body", NULL};

typedef struct {
  int body;
  double point[2], force[2], torque;
  int follower;
  fmbTimeLaw law;
} Load;

static int load_parse(fmbParser* p, fmbNode item, void** self) {
  Load* l = calloc(1, sizeof *l);
  if (!l) return fmb_parse_error(p, item, "out of memory");
  *self = l;
  if (fmb_get_body(p, item, "body", FMB_REQUIRED, &l->body) || fmb_get_point(p, item, "point", 0, l->body, l->point) ||
      fmb_get_vec2(p, item, "force", 0, l->force) || fmb_get_double(p, item, "torque", 0, &l->torque) ||
      fmb_get_choice(p, item, "frame", 0, load_frames, &l->follower) || fmbj_law_parse(p, item, &l->law))
    return -1;
  if (l->body == 0)
    return fmb_parse_error(p, fmb_find_key(p, item, "body"), "a load on the ground does nothing: name a moving body");
  return 0;
}

static void load_destroy(void* self) {
  Load* l = self;
  fmbj_law_free(&l->law);
  free(l);
}
static void load_bodies(const void* self, int body[2]) {
  const Load* l = self;
  body[0] = l->body;
  body[1] = -1;
}

static int load_force(const void* self, const fmbJointEval* ev, double* Q) {
  const Load* l = self;
  const int n = fmb_eval_ncoord(ev, 0);
  double* D = fmb_eval_scratch(ev); /* rows: dpx/dq, dpy/dq; then dangle/dq */
  double pos[2], ang;
  const double s = fmbj_law_at(&l->law, ev).s;
  int rc = fmb_marker(ev, 0, l->point, pos, &ang, D, n, NULL);
  if (rc) return rc;
  double F[2] = {s * l->force[0], s * l->force[1]};
  if (l->follower) {
    const double c = cos(ang), sn = sin(ang), fx = F[0];
    F[0] = c * fx - sn * F[1];
    F[1] = sn * fx + c * F[1];
  }
  for (int i = 0; i < n; ++i) Q[i] += D[i] * F[0] + D[n + i] * F[1];
  if (l->torque != 0.0) {
    rc = fmb_marker(ev, 0, l->point, pos, &ang, NULL, 0, D);
    for (int i = 0; i < n; ++i) Q[i] += D[i] * s * l->torque;
  }
  return rc;
}

static int load_input(const void* self, double* initial) { return fmbj_law_input(&((const Load*)self)->law, initial); }

static void load_describe(const void* self, FILE* out) {
  const Load* l = self;
  fprintf(out, "load (%g, %g) N%s and %g N m, times a %s law\n", l->force[0], l->force[1],
          l->follower ? " in the body's frame (follower)" : "", l->torque, fmbj_law_name(&l->law));
}

static const fmbParam load_params[] = {
    {.key = "body", .kind = FMB_PARAM_BODY, .flags = FMB_REQUIRED, .doc = "the loaded body (not ground)"},
    {.key = "point",
     .kind = FMB_PARAM_VEC2,
     .unit = "m",
     .fallback = "[0, 0]",
     .doc = "point of application, body frame"},
    {.key = "force", .kind = FMB_PARAM_VEC2, .unit = "N", .fallback = "[0, 0]", .doc = "force at s = 1, in `frame`"},
    {.key = "torque", .kind = FMB_PARAM_NUMBER, .unit = "N m", .fallback = "0", .doc = "torque at s = 1"},
    {.key = "frame",
     .kind = FMB_PARAM_CHOICE,
     .choices = load_frames,
     .fallback = "global",
     .doc = "global: fixed direction; body: turns with the point (a follower load)"},
    FMBJ_LAW_PARAMS,
    {.key = NULL},
};

const fmbJointType fmb_joint_force = {
    .name = "force",
    .abi = FMB_ABI_VERSION,
    .parse = load_parse,
    .describe = load_describe,
    .destroy = load_destroy,
    .bodies = load_bodies,
    .force = load_force,
    .input = load_input,
    .params = load_params,
    .example = "body: b\npoint: [0.5, 0]\nforce: [1, 2]\ntorque: 0.5\nlaw: harmonic\nfrequency: 3\nframe: body\n",
    .flags = FMB_TYPE_DOES_WORK,
};
