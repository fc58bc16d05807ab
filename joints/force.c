/* force.c — a constant applied load: force [fx, fy] (global frame) at `point` on `body`, and a
 * torque. Generalized force Q = (dp/dq)^T F + (dangle/dq)^T torque. */
#include <stdio.h>
#include <stdlib.h>

#include "flexmbd.h"

typedef struct {
  int body;
  double point[2], force[2], torque;
} Load;

static int load_parse(fmbParser* p, fmbNode item, void** self) {
  Load* l = calloc(1, sizeof *l);
  if (!l) return fmb_parse_error(p, item, "out of memory");
  *self = l;
  if (fmb_get_body(p, item, "body", FMB_REQUIRED, &l->body) || fmb_get_point(p, item, "point", 0, l->body, l->point) ||
      fmb_get_vec2(p, item, "force", 0, l->force) || fmb_get_double(p, item, "torque", 0, &l->torque))
    return -1;
  if (l->body == 0) return fmb_parse_error(p, fmb_find_key(p, item, "body"), "a load on the ground does nothing: name a moving body");
  return 0;
}

static void load_destroy(void* self) { free(self); }
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
  int rc = fmb_marker(ev, 0, l->point, pos, &ang, D, n, NULL);
  if (rc) return rc;
  for (int i = 0; i < n; ++i) Q[i] += D[i] * l->force[0] + D[n + i] * l->force[1];
  if (l->torque != 0.0) {
    rc = fmb_marker(ev, 0, l->point, pos, &ang, NULL, 0, D);
    for (int i = 0; i < n; ++i) Q[i] += D[i] * l->torque;
  }
  return rc;
}

static void load_describe(const void* self, FILE* out) {
  const Load* l = self;
  fprintf(out, "constant load (%g, %g) N and %g N m\n", l->force[0], l->force[1], l->torque);
}

static const fmbParam load_params[] = {
    {.key = "body", .kind = FMB_PARAM_BODY, .flags = FMB_REQUIRED, .doc = "the loaded body (not ground)"},
    {.key = "point", .kind = FMB_PARAM_VEC2, .unit = "m", .fallback = "[0, 0]", .doc = "point of application, body frame"},
    {.key = "force", .kind = FMB_PARAM_VEC2, .unit = "N", .fallback = "[0, 0]", .doc = "constant force, global frame"},
    {.key = "torque", .kind = FMB_PARAM_NUMBER, .unit = "N m", .fallback = "0", .doc = "constant torque"},
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
    .params = load_params,
    .example = "body: b\npoint: [0.5, 0]\nforce: [1, 2]\ntorque: 0.5\n",
    .flags = FMB_TYPE_DOES_WORK,
};
