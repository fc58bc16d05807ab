/* time_law.c — the laws of time of drives and loads (time_law.h): one implementation for all. */
#include <math.h>
#include <stdlib.h>
#include <string.h>

#include "time_law.h"

const char* const fmbj_law_names[] = {"constant", "ramp", "harmonic", "spinup", "table", "input", NULL};

/* The slope at each row of a position table: the derivative of the parabola through the row and
   its two neighbours (at the ends, the parabola through the first or last three rows), exact
   when f is quadratic in t, whatever the spacing; with two rows, the line's slope. */
static void table_slopes(const double* t, const double* s, int n, double* d) {
  if (n == 2) {
    d[0] = d[1] = (s[1] - s[0]) / (t[1] - t[0]);
    return;
  }
  for (int i = 0; i < n; ++i) {
    const int k = i == 0 ? 1 : i == n - 1 ? n - 2 : i; /* the middle row of the three */
    const double h0 = t[k] - t[k - 1], h1 = t[k + 1] - t[k];
    const double d0 = (s[k] - s[k - 1]) / h0, d1 = (s[k + 1] - s[k]) / h1, c = (d1 - d0) / (h0 + h1);
    /* the parabola s[k] + b (x - t[k]) + c (x - t[k])^2, b from the two secants */
    const double b = (h1 * d0 + h0 * d1) / (h0 + h1);
    const double x = t[i] - t[k];
    d[i] = b + 2.0 * c * x;
  }
}

static int table_setup(fmbParser* p, fmbNode item, fmbTimeLaw* law, int smooth) {
  if (fmb_get_table(p, item, "table", FMB_REQUIRED, &law->t, &law->s, &law->n)) return -1;
  if (smooth) {
    law->slope = calloc((size_t)law->n, sizeof(double));
    if (!law->slope) return fmb_parse_error(p, item, "out of memory");
    table_slopes(law->t, law->s, law->n, law->slope);
  }
  law->integral = calloc((size_t)law->n, sizeof(double));
  if (!law->integral) return fmb_parse_error(p, item, "out of memory");
  for (int i = 1; i < law->n; ++i) /* trapezoid rule: exact for a piecewise-linear s */
    law->integral[i] = law->integral[i - 1] + 0.5 * (law->s[i] + law->s[i - 1]) * (law->t[i] - law->t[i - 1]);
  law->integral_at_zero = 0.0;
  law->integral_at_zero = fmbj_law_eval(law, 0.0).integral; /* evaluated with a zero offset */
  return 0;
}

/* the law's own keys; smooth: a position table (a prescribed motion); angular: an angle (a drive) */
static int parse_kind(fmbParser* p, fmbNode item, fmbTimeLaw* law, int smooth, int angular) {
  switch (law->kind) {
    case FMB_LAW_INPUT:
      return angular ? fmb_get_angle(p, item, "value", 0, &law->value)
                     : fmb_get_double(p, item, "value", 0, &law->value);
    case FMB_LAW_RAMP:
    case FMB_LAW_SPINUP: return fmb_get_double(p, item, "ramp_time", FMB_REQUIRED | FMB_POSITIVE, &law->ramp_time);
    case FMB_LAW_HARMONIC:
      return fmb_get_double(p, item, "frequency", FMB_REQUIRED | FMB_POSITIVE, &law->frequency) ||
                     fmb_get_angle(p, item, "phase", 0, &law->phase)
                 ? -1
                 : 0;
    case FMB_LAW_TABLE: return table_setup(p, item, law, smooth);
    default: return 0;
  }
}

int fmbj_law_parse(fmbParser* p, fmbNode item, fmbTimeLaw* law) {
  memset(law, 0, sizeof *law);
  int kind = FMB_LAW_CONSTANT;
  if (fmb_get_choice(p, item, "law", 0, fmbj_law_names, &kind)) return -1;
  law->kind = (fmbLawKind)kind;
  return parse_kind(p, item, law, 0, 0);
}

void fmbj_law_free(fmbTimeLaw* law) {
  free(law->t);
  free(law->s);
  free(law->integral);
  free(law->slope);
  law->t = law->s = law->integral = law->slope = NULL;
}

const char* fmbj_law_name(const fmbTimeLaw* law) { return fmbj_law_names[law->kind]; }

/* the row lo with t[lo] <= t < t[lo + 1], for t[0] < t < t[n - 1] (bisection) */
static int table_segment(const fmbTimeLaw* law, double t) {
  int lo = 0, hi = law->n - 1;
  while (hi - lo > 1) {
    const int mid = (lo + hi) / 2;
    if (law->t[mid] <= t)
      lo = mid;
    else
      hi = mid;
  }
  return lo;
}

/* a position table: the cubic Hermite through the rows with their slopes, straight on along the
   end slopes outside (s, rate, accel; no integral: a position law is not integrated) */
static fmbLawValue smooth_table_eval(const fmbTimeLaw* law, double t) {
  fmbLawValue v = {0, 0, 0, 0};
  const int n = law->n;
  if (t <= law->t[0] || t >= law->t[n - 1]) {
    const int e = t <= law->t[0] ? 0 : n - 1;
    v.rate = law->slope[e];
    v.s = law->s[e] + v.rate * (t - law->t[e]);
    return v;
  }
  const int lo = table_segment(law, t), hi = lo + 1;
  const double h = law->t[hi] - law->t[lo], x = (t - law->t[lo]) / h;
  const double s0 = law->s[lo], s1 = law->s[hi], d0 = law->slope[lo] * h, d1 = law->slope[hi] * h;
  /* Hermite basis on x in [0, 1]; d/dt = (d/dx) / h */
  const double x2 = x * x, x3 = x2 * x;
  v.s = (2 * x3 - 3 * x2 + 1) * s0 + (x3 - 2 * x2 + x) * d0 + (-2 * x3 + 3 * x2) * s1 + (x3 - x2) * d1;
  v.rate = ((6 * x2 - 6 * x) * s0 + (3 * x2 - 4 * x + 1) * d0 + (-6 * x2 + 6 * x) * s1 + (3 * x2 - 2 * x) * d1) / h;
  v.accel = ((12 * x - 6) * s0 + (6 * x - 4) * d0 + (-12 * x + 6) * s1 + (6 * x - 2) * d1) / (h * h);
  return v;
}

/* piecewise-linear table: s, slope and the integral from t[0] (s held at the end values) */
static fmbLawValue table_eval(const fmbTimeLaw* law, double t) {
  if (law->slope) return smooth_table_eval(law, t);
  fmbLawValue v = {0, 0, 0, 0};
  const int n = law->n;
  if (t <= law->t[0]) {
    v.s = law->s[0];
    v.integral = law->s[0] * (t - law->t[0]);
  } else if (t >= law->t[n - 1]) {
    v.s = law->s[n - 1];
    v.integral = law->integral[n - 1] + law->s[n - 1] * (t - law->t[n - 1]);
  } else {
    const int lo = table_segment(law, t), hi = lo + 1;
    const double h = t - law->t[lo];
    v.rate = (law->s[hi] - law->s[lo]) / (law->t[hi] - law->t[lo]);
    v.s = law->s[lo] + v.rate * h;
    v.integral = law->integral[lo] + 0.5 * (law->s[lo] + v.s) * h;
  }
  v.integral -= law->integral_at_zero;
  return v;
}

fmbLawValue fmbj_law_eval(const fmbTimeLaw* law, double t) {
  fmbLawValue v = {1.0, 0.0, 0.0, t};
  switch (law->kind) {
    case FMB_LAW_CONSTANT: break;
    case FMB_LAW_RAMP: {
      const double T = law->ramp_time;
      if (t < T) {
        v.s = t / T;
        v.rate = 1.0 / T;
        v.integral = 0.5 * t * t / T;
      } else {
        v.integral = t - 0.5 * T;
      }
      break;
    }
    case FMB_LAW_HARMONIC: {
      const double w = law->frequency, a = w * t + law->phase;
      v.s = sin(a);
      v.rate = w * cos(a);
      v.accel = -w * w * sin(a);
      v.integral = (cos(law->phase) - cos(a)) / w;
      break;
    }
    case FMB_LAW_SPINUP: { /* Liu, Hong & Liu (2009), Eq. 41, per unit omega0 */
      const double T = law->ramp_time, k = 2.0 * M_PI / T, r = T / (2.0 * M_PI);
      if (t <= T) {
        v.s = (t - r * sin(k * t)) / T;
        v.rate = (1.0 - cos(k * t)) / T;
        v.accel = k * sin(k * t) / T;
        v.integral = (0.5 * t * t + r * r * (cos(k * t) - 1.0)) / T;
      } else {
        v.integral = t - 0.5 * T;
      }
      break;
    }
    case FMB_LAW_TABLE: return table_eval(law, t);
    case FMB_LAW_INPUT: v.s = v.integral = NAN; break;
  }
  return v;
}

fmbLawValue fmbj_law_at(const fmbTimeLaw* law, const fmbJointEval* ev) {
  if (law->kind != FMB_LAW_INPUT) return fmbj_law_eval(law, fmb_eval_time(ev));
  /* as the program set it: held (rate 0, fmb_set_input) or moving (fmb_set_input_motion); the
     integral is not used (an input motion is a position law) */
  fmbLawValue v = {fmb_eval_input(ev), 0.0, 0.0, NAN};
  v.rate = fmb_eval_input_rate(ev, &v.accel);
  return v;
}

int fmbj_law_input(const fmbTimeLaw* law, double* initial) {
  if (law->kind != FMB_LAW_INPUT) return 0;
  *initial = law->value;
  return 1;
}

/* ------------------------------------------------------------------------------------------ */

const char* const fmbj_motion_names[] = {"constant", "ramp", "harmonic", "spinup", "table", "input", NULL};

int fmbj_motion_parse(fmbParser* p, fmbNode item, int angular, fmbMotion* mo) {
  memset(mo, 0, sizeof *mo);
  int kind = 0;
  if (fmb_get_choice(p, item, "profile", FMB_REQUIRED, fmbj_motion_names, &kind)) return -1;
  mo->law.kind = (fmbLawKind)kind; /* the same order as the laws */
  mo->integrate = kind == FMB_LAW_CONSTANT || kind == FMB_LAW_RAMP || kind == FMB_LAW_SPINUP;
  mo->magnitude = 1.0;
  int rc = 0;
  switch (mo->law.kind) {
    case FMB_LAW_CONSTANT:
    case FMB_LAW_RAMP: rc = fmb_get_double(p, item, "speed", FMB_REQUIRED, &mo->magnitude); break;
    case FMB_LAW_SPINUP: rc = fmb_get_double(p, item, "omega0", FMB_REQUIRED, &mo->magnitude); break;
    case FMB_LAW_HARMONIC:
      rc = angular ? fmb_get_angle(p, item, "amplitude", FMB_REQUIRED, &mo->magnitude)
                   : fmb_get_double(p, item, "amplitude", FMB_REQUIRED, &mo->magnitude);
      break;
    case FMB_LAW_TABLE:
    case FMB_LAW_INPUT: break;
  }
  return rc || parse_kind(p, item, &mo->law, 1, angular) ? -1 : 0;
}

void fmbj_motion_eval(const fmbMotion* mo, const fmbJointEval* ev, double f[3]) {
  const fmbLawValue v = fmbj_law_at(&mo->law, ev);
  const double a = mo->magnitude;
  if (mo->integrate) {
    f[0] = a * v.integral;
    f[1] = a * v.s;
    f[2] = a * v.rate;
  } else {
    f[0] = a * v.s;
    f[1] = a * v.rate;
    f[2] = a * v.accel;
  }
}

const char* fmbj_motion_name(const fmbMotion* mo) {
  static const char* const described[] = {"constant speed",   "speed ramp", "harmonic",
                                          "spin-up (Eq. 41)", "table",      "input"};
  return described[mo->law.kind];
}
