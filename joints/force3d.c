/* force3d.c — an applied load in space, the spatial `force`: a force [fx, fy, fz] at `point` on
 * `body` and a torque [tx, ty, tz], both scaled by a time law s(t) (time_law.c: constant, ramp,
 * harmonic, spinup, table, input). With `frame: global` they keep their directions in the global
 * frame; with `frame: body` they are given in the frame of the material point and turn with it
 * (follower loads: F = R F_local, tau = R tau_local, R from fmb_marker3).
 * Generalized force by virtual work (docs/spatial.md): Q = (dp/dq)^T F + G^T tau, G the body's
 * virtual rotation at the point (fmb_marker3). The engine's `power` and `work` outputs are
 * Q . v and its integral. */
#include <math.h>
#include <stdio.h>
#include <stdlib.h>

#include "time_law.h"

static const char* const load3d_frames[] = {"global", "body", NULL};

typedef struct {
  int body;
  double point[3], force[3], torque[3];
  int follower;
  fmbTimeLaw law;
} Load3d;

static int load3d_parse(fmbParser* p, fmbNode item, void** self) {
  Load3d* l = calloc(1, sizeof *l);
  if (!l) return fmb_parse_error(p, item, "out of memory");
  *self = l;
  if (fmb_get_body(p, item, "body", FMB_REQUIRED, &l->body) || fmb_get_point3(p, item, "point", 0, l->body, l->point) ||
      fmb_get_vec3(p, item, "force", 0, l->force) || fmb_get_vec3(p, item, "torque", 0, l->torque) ||
      fmb_get_choice(p, item, "frame", 0, load3d_frames, &l->follower) || fmbj_law_parse(p, item, &l->law))
    return -1;
  if (l->body == 0)
    return fmb_parse_error(p, fmb_find_key(p, item, "body"), "a load on the ground does nothing: name a moving body");
  return 0;
}

static void load3d_destroy(void* self) {
  Load3d* l = self;
  fmbj_law_free(&l->law);
  free(l);
}

static void load3d_bodies(const void* self, int body[2]) {
  const Load3d* l = self;
  body[0] = l->body;
  body[1] = -1;
}

/* the force and torque now, global frame */
static int load3d_wrench(const Load3d* l, const fmbJointEval* ev, double* dpos, double* G, double F[3], double T[3]) {
  const int n = fmb_eval_ncoord(ev, 0);
  double pos[3], R[9];
  const double s = fmbj_law_at(&l->law, ev).s;
  const int rc = fmb_marker3(ev, 0, l->point, pos, R, dpos, G, n);
  if (rc) return rc;
  for (int i = 0; i < 3; ++i) {
    F[i] = l->follower ? s * (R[3 * i] * l->force[0] + R[3 * i + 1] * l->force[1] + R[3 * i + 2] * l->force[2])
                       : s * l->force[i];
    T[i] = l->follower ? s * (R[3 * i] * l->torque[0] + R[3 * i + 1] * l->torque[1] + R[3 * i + 2] * l->torque[2])
                       : s * l->torque[i];
  }
  return 0;
}

static int load3d_force(const void* self, const fmbJointEval* ev, double* Q) {
  const Load3d* l = self;
  const int n = fmb_eval_ncoord(ev, 0);
  double* dpos = fmb_eval_scratch(ev); /* 3 rows dp/dq, then 3 rows G */
  double* G = dpos + 3 * (size_t)n;
  double F[3], T[3];
  const int rc = load3d_wrench(l, ev, dpos, G, F, T);
  if (rc) return rc;
  for (int i = 0; i < n; ++i)
    for (int r = 0; r < 3; ++r) Q[i] += dpos[(size_t)r * n + i] * F[r] + G[(size_t)r * n + i] * T[r];
  return 0;
}

static const char* const load3d_outputs[] = {"force_x", "force_y", "force_z", "torque_x", "torque_y", "torque_z", NULL};
static const char* const load3d_output_units[] = {"N", "N", "N", "N m", "N m", "N m", NULL};
/* the load applied now, global frame */
static int load3d_output(const void* self, int id, const fmbJointEval* ev, double* value) {
  double F[3], T[3];
  const int rc = load3d_wrench(self, ev, NULL, NULL, F, T);
  *value = rc ? NAN : id < 3 ? F[id] : T[id - 3];
  return rc;
}

static int load3d_input(const void* self, double* initial) {
  return fmbj_law_input(&((const Load3d*)self)->law, initial);
}

static void load3d_describe(const void* self, FILE* out) {
  const Load3d* l = self;
  fprintf(out, "load (%g, %g, %g) N and (%g, %g, %g) N m%s, times a %s law\n", l->force[0], l->force[1], l->force[2],
          l->torque[0], l->torque[1], l->torque[2], l->follower ? " in the body's frame (follower)" : "",
          fmbj_law_name(&l->law));
}

static const fmbParam load3d_params[] = {
    {.key = "body", .kind = FMB_PARAM_BODY, .flags = FMB_REQUIRED, .doc = "the loaded body (not ground)"},
    {.key = "point",
     .kind = FMB_PARAM_VEC3,
     .unit = "m",
     .fallback = "[0, 0, 0]",
     .doc = "point of application, body frame"},
    {.key = "force", .kind = FMB_PARAM_VEC3, .unit = "N", .fallback = "[0, 0, 0]", .doc = "force at s = 1, in `frame`"},
    {.key = "torque",
     .kind = FMB_PARAM_VEC3,
     .unit = "N m",
     .fallback = "[0, 0, 0]",
     .doc = "torque at s = 1, in `frame`"},
    {.key = "frame",
     .kind = FMB_PARAM_CHOICE,
     .choices = load3d_frames,
     .fallback = "global",
     .doc = "global: fixed directions; body: they turn with the point (follower loads)"},
    FMBJ_LAW_PARAMS,
    {.key = NULL},
};

const fmbJointType fmb_joint_force3d = {
    .name = "force3d",
    .abi = FMB_ABI_VERSION,
    .parse = load3d_parse,
    .describe = load3d_describe,
    .destroy = load3d_destroy,
    .bodies = load3d_bodies,
    .force = load3d_force,
    .input = load3d_input,
    .output_names = load3d_outputs,
    .output_units = load3d_output_units,
    .output = load3d_output,
    .params = load3d_params,
    .example = "body: b\npoint: [0.5, 0, 0]\nforce: [1, 2, 0.5]\ntorque: [0.1, 0, 0.5]\nlaw: harmonic\nfrequency: "
               "3\nframe: body\n",
    .flags = FMB_TYPE_DOES_WORK,
    .dimensions = FMB_DIM_SPATIAL,
};
