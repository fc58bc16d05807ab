/* ball_spring.c — a spatial spring-damper of zero rest length between two material points (a ball
 * joint made elastic, a bushing with the same stiffness in every direction), built out of tree as
 * a plugin for `dimension: 3` scenes (docs/plugins.md, "A spatial type"). With d = p2 - p1 the gap
 * of point2 on body2 from point1 on body1 (either body may be the ground):
 *
 *     force on body2 F = -(k d + c d'),  and its opposite on body1,   potential k |d|^2 / 2
 *
 * as generalized forces Q = (dd/dq)^T F, where dd/dq is body2's dpos/dq minus body1's: fmb_marker3
 * gives each (3 rows of the joint's columns at stride ld), for any spatial body, so the same code
 * holds a rigid3d and a flexible body alike. The rate is d' = (dd/dq) v. The table says it works
 * in space only (`.dimensions = FMB_DIM_SPATIAL`, plugin ABI 3.3 or later): in a planar scene the
 * engine refuses it at its `type:`. */
#include <math.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>

#include <flexmbd_plugin.h>

typedef struct {
  int body[2];        /* body indices (0 = the ground), as fmb_get_body gives them */
  double point[2][3]; /* the points, each in its body's frame */
  double k, c;        /* N/m, N s/m */
} BallSpring;

static int ball_parse(fmbParser* p, fmbNode item, void** self) {
  BallSpring* s = calloc(1, sizeof *s);
  if (!s) return fmb_parse_error(p, item, "out of memory");
  *self = s; /* handed back at once: destroy frees it also when parsing fails */
  return fmb_get_body(p, item, "body1", FMB_REQUIRED, &s->body[0]) ||
                 fmb_get_body(p, item, "body2", FMB_REQUIRED, &s->body[1]) ||
                 fmb_get_point3(p, item, "point1", 0, s->body[0], s->point[0]) ||
                 fmb_get_point3(p, item, "point2", 0, s->body[1], s->point[1]) ||
                 fmb_get_double(p, item, "stiffness", FMB_REQUIRED | FMB_NONNEGATIVE, &s->k) ||
                 fmb_get_double(p, item, "damping", FMB_NONNEGATIVE, &s->c)
             ? -1
             : 0;
}

static void ball_destroy(void* self) { free(self); }

static void ball_bodies(const void* self, int body[2]) {
  const BallSpring* s = self;
  body[0] = s->body[0];
  body[1] = s->body[1];
}

/* the gap d = p2 - p1, its rate, and (D not NULL) dd/dq: 3 rows of ld = ncoord0 + ncoord1 */
static int gap(const BallSpring* s, const fmbJointEval* ev, double d[3], double rate[3], double* D) {
  const int n0 = fmb_eval_ncoord(ev, 0), ld = n0 + fmb_eval_ncoord(ev, 1);
  double pos[2][3];
  for (int k = 0; k < 2; ++k) {
    /* the ground answers the point itself and writes no derivative */
    const int rc = fmb_marker3(ev, k, s->point[k], pos[k], NULL, D ? D + fmb_eval_col0(ev, k) : NULL, NULL, ld);
    if (rc) return rc;
  }
  for (int i = 0; i < 3; ++i) d[i] = pos[1][i] - pos[0][i];
  if (!D) return 0;
  for (int i = 0; i < 3; ++i) /* body1's columns enter with a minus: d = p2 - p1 */
    for (int c = 0; c < n0; ++c) D[i * ld + c] = -D[i * ld + c];
  const double *v0 = fmb_eval_v(ev, 0), *v1 = fmb_eval_v(ev, 1);
  for (int i = 0; i < 3; ++i) {
    rate[i] = 0.0;
    for (int c = 0; c < ld; ++c) rate[i] += D[i * ld + c] * (c < n0 ? v0[c] : v1[c - n0]);
  }
  return 0;
}

static int ball_force(const void* self, const fmbJointEval* ev, double* Q) {
  const BallSpring* s = self;
  const int ld = fmb_eval_ncoord(ev, 0) + fmb_eval_ncoord(ev, 1);
  double* D = fmb_eval_scratch(ev); /* 6 ld doubles: room for dd/dq */
  double d[3], rate[3];
  const int rc = gap(s, ev, d, rate, D);
  if (rc) return rc;
  for (int i = 0; i < 3; ++i) {
    const double F = -(s->k * d[i] + s->c * rate[i]); /* on body2 */
    for (int c = 0; c < ld; ++c) Q[c] += D[i * ld + c] * F;
  }
  return 0;
}

static double ball_energy(const void* self, const fmbJointEval* ev) {
  const BallSpring* s = self;
  double d[3];
  if (gap(s, ev, d, NULL, NULL)) return NAN;
  return 0.5 * s->k * (d[0] * d[0] + d[1] * d[1] + d[2] * d[2]);
}

static const char* const ball_outputs[] = {"stretch", "force", NULL};
static const char* const ball_units[] = {"m", "N", NULL};
/* stretch: |d|; force: |k d + c d'|, the magnitude of the force on each body */
static int ball_output(const void* self, int id, const fmbJointEval* ev, double* value) {
  const BallSpring* s = self;
  double d[3], rate[3];
  const int rc = gap(s, ev, d, rate, fmb_eval_scratch(ev));
  if (rc) return rc;
  double f[3];
  for (int i = 0; i < 3; ++i) f[i] = id == 0 ? d[i] : s->k * d[i] + s->c * rate[i];
  *value = sqrt(f[0] * f[0] + f[1] * f[1] + f[2] * f[2]);
  return 0;
}

static void ball_describe(const void* self, FILE* out) {
  const BallSpring* s = self;
  fprintf(out, "ball spring-damper k = %g N/m, c = %g N s/m, zero rest length\n", s->k, s->c);
}

static const fmbParam ball_params[] = {
    {.key = "body1", .kind = FMB_PARAM_BODY, .flags = FMB_REQUIRED, .doc = "first body (or ground)"},
    {.key = "body2", .kind = FMB_PARAM_BODY, .flags = FMB_REQUIRED, .doc = "second body (or ground)"},
    {.key = "point1", .kind = FMB_PARAM_VEC3, .unit = "m", .fallback = "[0, 0, 0]", .doc = "point on body1"},
    {.key = "point2", .kind = FMB_PARAM_VEC3, .unit = "m", .fallback = "[0, 0, 0]", .doc = "point on body2"},
    {.key = "stiffness",
     .kind = FMB_PARAM_NUMBER,
     .flags = FMB_REQUIRED | FMB_NONNEGATIVE,
     .unit = "N/m",
     .doc = "spring rate k, every direction"},
    {.key = "damping",
     .kind = FMB_PARAM_NUMBER,
     .flags = FMB_NONNEGATIVE,
     .unit = "N s/m",
     .fallback = "0",
     .doc = "damper rate c, every direction"},
    {.key = NULL},
};

static const fmbJointType ball_type = {
    .name = "ball_spring",
    .abi = FMB_ABI_VERSION,
    .parse = ball_parse,
    .destroy = ball_destroy,
    .bodies = ball_bodies,
    .force = ball_force,
    .energy = ball_energy,
    .output_names = ball_outputs,
    .output_units = ball_units,
    .output = ball_output,
    .describe = ball_describe,
    .params = ball_params,
    /* conform's spatial fixture: rigid3d bodies a (on a ball joint at the ground) and b, centres
       [0.5, 0, 0] and [1.5, 0, 0] */
    .example = "body1: a\nbody2: b\npoint1: [0.5, 0, 0]\npoint2: [-0.5, 0.1, 0]\nstiffness: 5\n",
    .example_damped = "damping: 0.5\n",
    .dimensions = FMB_DIM_SPATIAL,
};

static const fmbJointType* const joints[] = {&ball_type, NULL};
static const fmbPlugin plugin = {.abi = FMB_ABI_VERSION, .name = "ball_spring", .version = "1.0", .joints = joints};

FMB_PLUGIN_EXPORT const fmbPlugin* fmb_plugin_descriptor(void) { return &plugin; }
