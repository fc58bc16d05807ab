/* drive.c — prescribes the relative angle of a revolute joint:
 *   Phi = (angle2 - angle1) - angle0 - f(t)          (1 row, rheonomic: Phi_t = -f', Phi_tt = -f'')
 * with the angles of the joint's two markers. The profiles f(t) (constant speed, speed ramp, the
 * spin-up law of Liu, Hong & Liu 2009, Eq. 41, harmonic, table) are the shared time laws of
 * time_law.c. The power the drive feeds in is the engine's JOINT.power output. */
#include <math.h>
#include <stdlib.h>
#include <string.h>

#include "time_law.h"

typedef struct {
  int body[2];
  double point[2][2];
  double angle0;
  fmbMotion motion;
} Drive;

static int drive_parse(fmbParser* p, fmbNode item, void** self) {
  Drive* d = calloc(1, sizeof *d);
  if (!d) return fmb_parse_error(p, item, "out of memory");
  *self = d;
  int joint = -1;
  if (fmb_get_joint(p, item, "joint", FMB_REQUIRED, &joint)) return -1;
  for (int k = 0; k < 2; ++k)
    if (fmb_joint_attachment(p, joint, k, &d->body[k], d->point[k]))
      return fmb_parse_error(p, fmb_find_key(p, item, "joint"),
                             "a drive needs a revolute joint to drive (one with two attachment points)");
  return fmbj_motion_parse(p, item, 1, &d->motion) || fmb_get_angle(p, item, "angle0", FMB_POSE, &d->angle0) ? -1 : 0;
}

static void drive_destroy(void* self) {
  Drive* d = self;
  fmbj_law_free(&d->motion.law);
  free(d);
}
static int drive_nrows(const void* self) {
  (void)self;
  return 1;
}
static void drive_bodies(const void* self, int body[2]) {
  const Drive* d = self;
  body[0] = d->body[0];
  body[1] = d->body[1];
}

static int drive_constraint(const void* self, const fmbJointEval* ev, double* phi, double* phi_q, double* phi_t,
                            double* phi_tt) {
  const Drive* d = self;
  double pos[2], ang[2], f[3];
  for (int k = 0; k < 2; ++k) {
    const int c0 = fmb_eval_col0(ev, k), n = fmb_eval_ncoord(ev, k);
    int rc = fmb_marker(ev, k, d->point[k], pos, &ang[k], NULL, 0, phi_q + c0);
    if (rc) return rc;
    if (k == 0)
      for (int i = 0; i < n; ++i) phi_q[c0 + i] = -phi_q[c0 + i];
  }
  fmbj_motion_eval(&d->motion, ev, f);
  phi[0] = (ang[1] - ang[0]) - d->angle0 - f[0];
  phi_t[0] = -f[1];
  phi_tt[0] = -f[2];
  return 0;
}

static const char* const drive_outputs[] = {"angle", "speed", NULL};
static const char* const drive_output_units[] = {"rad", "rad/s", NULL};
/* angle: the joint's relative angle (angle2 - angle1) as the bodies are, which on the
   constraint manifold is angle0 + f(t); speed: the prescribed relative speed f'(t) */
static int drive_output(const void* self, int id, const fmbJointEval* ev, double* value) {
  const Drive* d = self;
  if (id == 0) {
    double pos[2], ang[2];
    for (int k = 0; k < 2; ++k) {
      const int rc = fmb_marker(ev, k, d->point[k], pos, &ang[k], NULL, 0, NULL);
      if (rc) return rc;
    }
    *value = ang[1] - ang[0];
    return 0;
  }
  double f[3];
  fmbj_motion_eval(&d->motion, ev, f);
  *value = f[1];
  return 0;
}

static int drive_input(const void* self, double* initial) {
  return fmbj_law_input(&((const Drive*)self)->motion.law, initial);
}

static void drive_describe(const void* self, FILE* f) {
  const Drive* d = self;
  fprintf(f, "%s profile\n", fmbj_motion_name(&d->motion));
}

static const fmbParam drive_params[] = {
    {.key = "joint",
     .kind = FMB_PARAM_JOINT,
     .flags = FMB_REQUIRED,
     .doc = "the revolute joint whose angle is prescribed"},
    {.key = "angle0", .kind = FMB_PARAM_NUMBER, .unit = "rad", .fallback = "0", .doc = "relative angle at f = 0"},
    FMBJ_MOTION_PARAMS("rad"),
    {.key = NULL},
};

const fmbJointType fmb_joint_drive = {
    .name = "drive",
    .abi = FMB_ABI_VERSION,
    .parse = drive_parse,
    .destroy = drive_destroy,
    .bodies = drive_bodies,
    .nrows = drive_nrows,
    .constraint = drive_constraint,
    .output_names = drive_outputs,
    .output_units = drive_output_units,
    .output = drive_output,
    .describe = drive_describe,
    .input = drive_input,
    .params = drive_params,
    .example = "joint: pin\nprofile: harmonic\namplitude: 0.2\nfrequency: 3\n",
    .flags = FMB_TYPE_DOES_WORK,
};
