/* spring.c — a linear spring–damper between point1 on body1 and point2 on body2:
 * tension f = k (l - l0) + c dl/dt along the line of the points, Q = (dp/dq)^T (force on each
 * point); potential energy k (l - l0)^2 / 2. The same in a planar scene (points [x, y], fmb_marker)
 * and in a `dimension: 3` one (points [x, y, z], fmb_marker3's dpos/dq): D = d(p1 - p2)/dq has 2 or
 * 3 rows, e the unit vector from point1 to point2, dl/dt = -e . (D v), Q = D^T (f e). */
#include <math.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>

#include "two_point.h"

typedef struct {
  fmbTwoPoint tp;
  double stiffness, damping, rest_length;
} Spring;

static int spring_parse(fmbParser* p, fmbNode item, void** self) {
  Spring* s = calloc(1, sizeof *s);
  if (!s) return fmb_parse_error(p, item, "out of memory");
  *self = s;
  return fmbj_parse_two_points(p, item, &s->tp) ||
                 fmb_get_double(p, item, "stiffness", FMB_REQUIRED | FMB_NONNEGATIVE, &s->stiffness) ||
                 fmb_get_double(p, item, "damping", FMB_NONNEGATIVE, &s->damping) ||
                 fmb_get_double(p, item, "rest_length", FMB_REQUIRED | FMB_NONNEGATIVE, &s->rest_length)
             ? -1
             : 0;
}

static void spring_destroy(void* self) { free(self); }

/* the gap p1 - p2 (2 or 3 components: returns how many, or -1) and, with D, its derivative */
static int spring_gap(const Spring* s, const fmbJointEval* ev, double gap[3], double* D, int ld) {
  if (s->tp.spatial) return fmbj_point_gap3(ev, &s->tp, gap, D, ld) ? -1 : 3;
  double ang[2];
  gap[2] = 0.0;
  return fmbj_point_gap(ev, &s->tp, gap, D, ld, ang, NULL) ? -1 : 2;
}

/* the length of a gap of nd components (the planar one by hypot, as it always was) */
static double gap_length(const double gap[3], int nd) {
  return nd == 2 ? hypot(gap[0], gap[1]) : sqrt(gap[0] * gap[0] + gap[1] * gap[1] + gap[2] * gap[2]);
}

/* length, its rate, unit vector from point1 to point2 (e[2] = 0 in the plane); D (nd x ld) =
   d(p1 - p2)/dq; returns nd (2 or 3) or -1 */
static int spring_geometry(const Spring* s, const fmbJointEval* ev, double* D, int ld, double* len, double* rate,
                           double e[3]) {
  double gap[3];
  const int nd = s->tp.spatial ? 3 : 2;
  memset(D, 0, (size_t)nd * ld * sizeof(double));
  if (spring_gap(s, ev, gap, D, ld) < 0) return -1;
  const double l = gap_length(gap, nd);
  *len = l;
  double gdot[3] = {0.0, 0.0, 0.0};
  for (int r = 0; r < 3; ++r) e[r] = l > 0 && r < nd ? -gap[r] / l : 0.0; /* p2 - p1 direction */
  for (int k = 0; k < 2; ++k) {
    const double* v = fmb_eval_v(ev, k);
    const int c0 = fmb_eval_col0(ev, k), n = fmb_eval_ncoord(ev, k);
    for (int i = 0; i < n; ++i)
      for (int r = 0; r < nd; ++r) gdot[r] += D[(size_t)r * ld + c0 + i] * v[i];
  }
  *rate = nd == 2 ? -(e[0] * gdot[0] + e[1] * gdot[1]) : -(e[0] * gdot[0] + e[1] * gdot[1] + e[2] * gdot[2]);
  return nd;
}

static int spring_force(const void* self, const fmbJointEval* ev, double* Q) {
  const Spring* s = self;
  const int ld = fmb_eval_ncoord(ev, 0) + fmb_eval_ncoord(ev, 1);
  double* D = fmb_eval_scratch(ev);
  double l, ldot, e[3];
  const int nd = spring_geometry(s, ev, D, ld, &l, &ldot, e);
  if (nd < 0) return -1;
  const double f = s->stiffness * (l - s->rest_length) + s->damping * ldot;
  /* force on point1 = +f e, on point2 = -f e: Q = D^T (f e), D = d(p1 - p2)/dq */
  if (nd == 2)
    for (int i = 0; i < ld; ++i) Q[i] += f * (D[i] * e[0] + D[ld + i] * e[1]);
  else
    for (int i = 0; i < ld; ++i) Q[i] += f * (D[i] * e[0] + D[ld + i] * e[1] + D[2 * (size_t)ld + i] * e[2]);
  return 0;
}

static double spring_energy(const void* self, const fmbJointEval* ev) {
  const Spring* s = self;
  double gap[3];
  const int nd = spring_gap(s, ev, gap, NULL, 0);
  if (nd < 0) return NAN;
  const double x = gap_length(gap, nd) - s->rest_length;
  return 0.5 * s->stiffness * x * x;
}

static const char* const spring_outputs[] = {"length", "tension", NULL};
static const char* const spring_output_units[] = {"m", "N", NULL};
static int spring_output(const void* self, int id, const fmbJointEval* ev, double* value) {
  const Spring* s = self;
  const int ld = fmb_eval_ncoord(ev, 0) + fmb_eval_ncoord(ev, 1);
  double *D = fmb_eval_scratch(ev), l = NAN, ldot = NAN, e[3];
  const int nd = spring_geometry(s, ev, D, ld, &l, &ldot, e);
  *value = id == 0 ? l : s->stiffness * (l - s->rest_length) + s->damping * ldot;
  return nd < 0 ? -1 : 0;
}

static void spring_describe(const void* self, FILE* out) {
  const Spring* s = self;
  fprintf(out, "spring-damper k = %g N/m, c = %g N s/m, rest length %g m\n", s->stiffness, s->damping, s->rest_length);
}

static const fmbParam spring_params[] = {
    FMBJ_TWO_POINT_PARAMS,
    {.key = "stiffness",
     .kind = FMB_PARAM_NUMBER,
     .flags = FMB_REQUIRED | FMB_NONNEGATIVE,
     .unit = "N/m",
     .doc = "spring rate k"},
    {.key = "damping",
     .kind = FMB_PARAM_NUMBER,
     .flags = FMB_NONNEGATIVE,
     .unit = "N s/m",
     .fallback = "0",
     .doc = "damper rate c"},
    {.key = "rest_length",
     .kind = FMB_PARAM_NUMBER,
     .flags = FMB_REQUIRED | FMB_NONNEGATIVE,
     .unit = "m",
     .doc = "unstretched length l0"},
    {.key = NULL},
};

const fmbJointType fmb_joint_spring = {
    .name = "spring",
    .abi = FMB_ABI_VERSION,
    .parse = spring_parse,
    .describe = spring_describe,
    .destroy = spring_destroy,
    .bodies = fmbj_two_point_bodies,
    .attachment = fmbj_two_point_attachment,
    .attachment3 = fmbj_two_point_attachment3,
    .force = spring_force,
    .energy = spring_energy,
    .output_names = spring_outputs,
    .output_units = spring_output_units,
    .output = spring_output,
    .params = spring_params,
    .example = "body1: a\nbody2: b\npoint1: [0.5, 0]\npoint2: [-0.5, 0.1]\nstiffness: 50\nrest_length: 0.3\n",
    .example_damped = "damping: 2\n",
    .dimensions = FMB_DIM_PLANAR | FMB_DIM_SPATIAL,
};
