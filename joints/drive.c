/* drive.c — prescribes the relative angle of a revolute joint:
 *   Phi = (angle2 - angle1) - angle0 - f(t)          (1 row, rheonomic: Phi_t = -f', Phi_tt = -f'')
 * with the angles of the joint's two markers. Profiles:
 *   constant  f = speed t
 *   harmonic  f = amplitude sin(frequency t + phase)
 *   spinup    f = (w0/Tn) [t^2/2 + (Tn/2pi)^2 (cos(2 pi t/Tn) - 1)]  for t <= Tn,
 *             f = w0 (t - Tn/2) after                                 (Liu, Hong & Liu 2009, Eq. 41)
 * The power the drive feeds in is the engine's JOINT.power output. */
#include <math.h>
#include <stdlib.h>
#include <string.h>

#include "flexmbd.h"

enum { PROFILE_CONSTANT, PROFILE_HARMONIC, PROFILE_SPINUP };
static const char* const profiles[] = {"constant", "harmonic", "spinup", NULL}; /* order of PROFILE_* */

typedef struct {
  int body[2];
  double point[2][2];
  int profile;
  double angle0, speed, amplitude, frequency, phase, omega0, ramp_time;
} Drive;

static int drive_parse(fmbParser* p, fmbNode item, void** self) {
  Drive* d = calloc(1, sizeof *d);
  if (!d) return fmb_parse_error(p, item, "out of memory");
  *self = d;
  int joint = -1;
  if (fmb_get_joint(p, item, "joint", FMB_REQUIRED, &joint)) return -1;
  for (int k = 0; k < 2; ++k)
    if (fmb_joint_attachment(p, joint, k, &d->body[k], d->point[k]))
      return fmb_parse_error(p, fmb_find_key(p, item, "joint"), "a drive needs a revolute joint to drive (one with two attachment points)");
  if (fmb_get_choice(p, item, "profile", FMB_REQUIRED, profiles, &d->profile) ||
      fmb_get_angle(p, item, "angle0", FMB_POSE, &d->angle0))
    return -1;
  switch (d->profile) {
    case PROFILE_CONSTANT: return fmb_get_double(p, item, "speed", FMB_REQUIRED, &d->speed);
    case PROFILE_HARMONIC:
      return fmb_get_angle(p, item, "amplitude", FMB_REQUIRED, &d->amplitude) ||
                     fmb_get_double(p, item, "frequency", FMB_REQUIRED | FMB_POSITIVE, &d->frequency) ||
                     fmb_get_angle(p, item, "phase", 0, &d->phase)
                 ? -1
                 : 0;
    default:
      return fmb_get_double(p, item, "omega0", FMB_REQUIRED, &d->omega0) ||
                     fmb_get_double(p, item, "ramp_time", FMB_REQUIRED | FMB_POSITIVE, &d->ramp_time)
                 ? -1
                 : 0;
  }
}

static void drive_destroy(void* self) { free(self); }
static int drive_nrows(const void* self) {
  (void)self;
  return 1;
}
static void drive_bodies(const void* self, int body[2]) {
  const Drive* d = self;
  body[0] = d->body[0];
  body[1] = d->body[1];
}

/* f(t), f'(t), f''(t) */
static void drive_profile(const Drive* d, double t, double f[3]) {
  switch (d->profile) {
    case PROFILE_CONSTANT:
      f[0] = d->speed * t;
      f[1] = d->speed;
      f[2] = 0.0;
      break;
    case PROFILE_HARMONIC: {
      const double w = d->frequency, a = w * t + d->phase;
      f[0] = d->amplitude * sin(a);
      f[1] = d->amplitude * w * cos(a);
      f[2] = -d->amplitude * w * w * sin(a);
      break;
    }
    default: {
      const double Tn = d->ramp_time, w0 = d->omega0;
      if (t <= Tn) {
        const double k = 2.0 * M_PI / Tn, r = Tn / (2.0 * M_PI);
        f[0] = (w0 / Tn) * (0.5 * t * t + r * r * (cos(k * t) - 1.0));
        f[1] = (w0 / Tn) * (t - r * sin(k * t));
        f[2] = (w0 / Tn) * (1.0 - cos(k * t));
      } else {
        f[0] = w0 * (t - 0.5 * Tn);
        f[1] = w0;
        f[2] = 0.0;
      }
    }
  }
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
  drive_profile(d, fmb_eval_time(ev), f);
  phi[0] = (ang[1] - ang[0]) - d->angle0 - f[0];
  phi_t[0] = -f[1];
  phi_tt[0] = -f[2];
  return 0;
}

static const char* const drive_outputs[] = {"angle", "speed", NULL};
static int drive_lookup(const void* self, const char* q) {
  (void)self;
  for (int i = 0; drive_outputs[i]; ++i)
    if (strcmp(q, drive_outputs[i]) == 0) return i;
  return -1;
}
/* angle: the joint's relative angle (angle2 - angle1) as the bodies are, which on the
   constraint manifold is angle0 + f(t) (it once gave f(t) alone, off by angle0); speed: the
   prescribed relative speed f'(t) */
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
  drive_profile(d, fmb_eval_time(ev), f);
  *value = f[1];
  return 0;
}

static void drive_describe(const void* self, FILE* f) {
  const Drive* d = self;
  static const char* const names[] = {"constant speed", "harmonic", "spin-up (Eq. 41)"};
  fprintf(f, "%s profile\n", names[d->profile]);
}

static const fmbParam drive_params[] = {
    {.key = "joint", .kind = FMB_PARAM_JOINT, .flags = FMB_REQUIRED, .doc = "the revolute joint whose angle is prescribed"},
    {.key = "profile", .kind = FMB_PARAM_CHOICE, .flags = FMB_REQUIRED, .choices = profiles, .doc = "f(t), see below"},
    {.key = "angle0", .kind = FMB_PARAM_NUMBER, .unit = "rad", .fallback = "0", .doc = "relative angle at f = 0"},
    {.key = "speed", .kind = FMB_PARAM_NUMBER, .unit = "rad/s", .doc = "constant: f = speed t (required)"},
    {.key = "amplitude", .kind = FMB_PARAM_NUMBER, .unit = "rad", .doc = "harmonic: f = amplitude sin(frequency t + phase) (required)"},
    {.key = "frequency", .kind = FMB_PARAM_NUMBER, .flags = FMB_POSITIVE, .unit = "rad/s", .doc = "harmonic (required)"},
    {.key = "phase", .kind = FMB_PARAM_NUMBER, .unit = "rad", .fallback = "0", .doc = "harmonic"},
    {.key = "omega0", .kind = FMB_PARAM_NUMBER, .unit = "rad/s", .doc = "spinup: final speed (required)"},
    {.key = "ramp_time", .kind = FMB_PARAM_NUMBER, .flags = FMB_POSITIVE, .unit = "s", .doc = "spinup: time to reach omega0 (required)"},
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
    .output_lookup = drive_lookup,
    .output = drive_output,
    .describe = drive_describe,
    .params = drive_params,
    .example = "joint: pin\nprofile: harmonic\namplitude: 0.2\nfrequency: 3\n",
    .flags = FMB_TYPE_DOES_WORK,
};
