/* time_law.h — the time laws that drives, prismatic drives and loads share (time_law.c).
 *
 * A law is a dimensionless shape s(t) with its rate, second rate and integral from 0:
 *   constant  s = 1
 *   ramp      s = min(t / ramp_time, 1)
 *   harmonic  s = sin(frequency t + phase)
 *   spinup    s = t/Tn - sin(2 pi t/Tn)/(2 pi) for t <= Tn, 1 after: the speed profile of
 *             Liu, Hong & Liu (2009), Eq. 41 (its integral is the paper's spin-up angle)
 *   table     s piecewise linear through [t, value] rows, held at the end values outside
 *             (a load's); a prescribed motion's table is smooth instead (see fmbMotion)
 *   input     s set by a program between steps (fmb_set_input; the joint's `input` op), constant
 *             between two settings, or moving with the rate the program gave (fmb_set_input_motion); `value:` is its value until then (issue 24, docs/api.md)
 * A load multiplies its force and torque by s(t); a prescribed motion (fmbMotion) is either a
 * magnitude times the integral of s (constant, ramp, spinup: laws of the speed) or a magnitude
 * times s itself (harmonic, table: laws of the position). */
#ifndef FLEXMBD_TIME_LAW_H
#define FLEXMBD_TIME_LAW_H
#include "flexmbd_plugin.h"

typedef enum {
  FMB_LAW_CONSTANT,
  FMB_LAW_RAMP,
  FMB_LAW_HARMONIC,
  FMB_LAW_SPINUP,
  FMB_LAW_TABLE,
  FMB_LAW_INPUT
} fmbLawKind;

typedef struct {
  fmbLawKind kind;
  double ramp_time, frequency, phase;
  int n;                    /* table rows */
  double *t, *s, *integral; /* table points; integral of s from t[0] to t[i] */
  double integral_at_zero;  /* of s from t[0] to 0 (tables may start before or after 0) */
  /* a position table (a prescribed motion): C1 cubic Hermite through the rows, continued along the
     end slopes, with the slope at each row (NULL for a load's piecewise-linear table) */
  double* slope;
  double value; /* input: the initial value (`value:`) */
} fmbTimeLaw;

/* s, ds/dt, d2s/dt2 and the integral of s from 0 to t */
typedef struct {
  double s, rate, accel, integral;
} fmbLawValue;

/* keys: `law` (default constant) and the law's own: ramp_time (ramp, spinup), frequency, phase
   (harmonic), table (table: [[t, s], ...] or a CSV file name), value (input) */
int fmbj_law_parse(fmbParser* p, fmbNode item, fmbTimeLaw* law);
/* s at time t; an input law has no value of its own (NaN): fmbj_law_at reads it from ev */
fmbLawValue fmbj_law_eval(const fmbTimeLaw* law, double t);
/* s at the evaluation's time, an input law's the value the program set */
fmbLawValue fmbj_law_at(const fmbTimeLaw* law, const fmbJointEval* ev);
/* a joint type's `input` op for its law: 1 with the initial value when the law is `input` */
int fmbj_law_input(const fmbTimeLaw* law, double* initial);
void fmbj_law_free(fmbTimeLaw* law);
const char* fmbj_law_name(const fmbTimeLaw* law);

/* A prescribed coordinate f(t) (a drive's relative angle, a prismatic drive's displacement).
   Keys: `profile` (required) and its keys, compatible with the drive's original profiles:
     constant (speed):              f = speed t
     ramp     (speed, ramp_time):   the speed ramps linearly to `speed` over ramp_time
     spinup   (omega0, ramp_time):  Eq. 41, the speed rises smoothly to omega0 over ramp_time
     harmonic (amplitude, frequency, phase):  f = amplitude sin(frequency t + phase)
     table    (table):              f through the [t, f] rows, cubic between them with the slope
                                    of the parabola through each row and its neighbours, and
                                    straight on along the end slopes outside: continuous speed,
                                    so a rigid drive can follow it (a piecewise-linear angle
                                    jumps in speed at every row: an impulse no solver steps over);
                                    exact for f quadratic in t
     input    (value):              f set by a program between steps, held between settings or
                                    moving with the rate it gave (fmb_set_input_motion) */
typedef struct {
  fmbTimeLaw law;
  double magnitude;
  int integrate; /* f = magnitude * integral of s (speed laws) or magnitude * s (position laws) */
} fmbMotion;

/* angular: f is an angle (a drive): amplitude may carry a unit (`10 deg`, fmb_get_angle) */
int fmbj_motion_parse(fmbParser* p, fmbNode item, int angular, fmbMotion* motion);
extern const char *const fmbj_law_names[], *const fmbj_motion_names[];

/* the keys the two parsers read, for the types' fmbParam tables (UNIT: of f, "rad" or "m") */
#define FMBJ_LAW_KEYS(what)                                                                                  \
  {.key = "ramp_time",                                                                                       \
   .kind = FMB_PARAM_NUMBER,                                                                                 \
   .flags = FMB_POSITIVE,                                                                                    \
   .unit = "s",                                                                                              \
   .doc = what "ramp, spinup: rise time (required)"},                                                        \
      {.key = "frequency",                                                                                   \
       .kind = FMB_PARAM_NUMBER,                                                                             \
       .flags = FMB_POSITIVE,                                                                                \
       .unit = "rad/s",                                                                                      \
       .doc = what "harmonic (required)"},                                                                   \
      {.key = "phase", .kind = FMB_PARAM_NUMBER, .unit = "rad", .fallback = "0", .doc = what "harmonic"}, {  \
    .key = "table", .kind = FMB_PARAM_TABLE, .doc = what "table: [[t, value], ...] or a CSV file (required)" \
  }
/* the keys of an optional prescribed motion on a joint that also stands alone (a prismatic's slide, a
   spatial hinge's turn: `profile` present = driven), UNIT of f ("m" or "rad"), WHAT it prescribes */
#define FMBJ_OPTIONAL_MOTION_PARAMS(UNIT, WHAT)                                                                      \
  {.key = "profile",                                                                                                 \
   .kind = FMB_PARAM_CHOICE,                                                                                         \
   .choices = fmbj_motion_names,                                                                                     \
   .doc = "optional: prescribed " WHAT " f(t), as a drive's"},                                                       \
      {.key = "speed", .kind = FMB_PARAM_NUMBER, .unit = UNIT "/s", .doc = "profile constant, ramp: (final) speed"}, \
      {.key = "omega0", .kind = FMB_PARAM_NUMBER, .unit = UNIT "/s", .doc = "profile spinup: final speed"},          \
      {.key = "amplitude", .kind = FMB_PARAM_NUMBER, .unit = UNIT, .doc = "profile harmonic"},                       \
      {.key = "value",                                                                                               \
       .kind = FMB_PARAM_NUMBER,                                                                                     \
       .unit = UNIT,                                                                                                 \
       .fallback = "0",                                                                                              \
       .doc = "profile input: f until a program sets it"},                                                           \
      FMBJ_LAW_KEYS("profile ")
#define FMBJ_LAW_PARAMS                                                     \
  {.key = "law",                                                            \
   .kind = FMB_PARAM_CHOICE,                                                \
   .choices = fmbj_law_names,                                               \
   .fallback = "constant",                                                  \
   .doc = "time law s(t) scaling force and torque"},                        \
      FMBJ_LAW_KEYS(""), {                                                  \
    .key = "value", .kind = FMB_PARAM_NUMBER, .unit = "1", .fallback = "0", \
    .doc = "input: s until a program sets it (fmb_set_input)"               \
  }
#define FMBJ_MOTION_PARAMS(UNIT)                                                                               \
  {.key = "profile",                                                                                           \
   .kind = FMB_PARAM_CHOICE,                                                                                   \
   .flags = FMB_REQUIRED,                                                                                      \
   .choices = fmbj_motion_names,                                                                               \
   .doc = "f(t), docs/scenes.md"},                                                                             \
      {.key = "speed",                                                                                         \
       .kind = FMB_PARAM_NUMBER,                                                                               \
       .unit = UNIT "/s",                                                                                      \
       .doc = "constant, ramp: (final) speed (required)"},                                                     \
      {.key = "omega0", .kind = FMB_PARAM_NUMBER, .unit = UNIT "/s", .doc = "spinup: final speed (required)"}, \
      {.key = "amplitude",                                                                                     \
       .kind = FMB_PARAM_NUMBER,                                                                               \
       .unit = UNIT,                                                                                           \
       .doc = "harmonic: f = amplitude sin(frequency t + phase) (required)"},                                  \
      {.key = "value",                                                                                         \
       .kind = FMB_PARAM_NUMBER,                                                                               \
       .unit = UNIT,                                                                                           \
       .fallback = "0",                                                                                        \
       .doc = "input: f until a program sets it (fmb_set_input)"},                                             \
      FMBJ_LAW_KEYS("")
/* f, f', f'' at the evaluation's time (an input: the value set, f' = f'' = 0) */
void fmbj_motion_eval(const fmbMotion* motion, const fmbJointEval* ev, double f[3]);
const char* fmbj_motion_name(const fmbMotion* motion);
#endif
