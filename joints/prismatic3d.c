/* prismatic3d.c — a slider in space: the bodies keep their relative orientation and point2
 * moves along the `axis` through point1 (global direction in the scene's pose):
 *   Phi = [x1 . y2; y1 . z2; z1 . x2; (p1 - p2) . x1; (p1 - p2) . y1]      (5 rows)
 * Output `displacement`: (p2 - p1) . z1.
 * With a `profile` (the drive's keys, as revolute3d's and the planar prismatic's) the slide is
 * prescribed too, a sixth, rheonomic row:
 *   Phi_6 = (p2 - p1) . z1 - offset - f(t),  Phi_t = -f', Phi_tt = -f''
 * whose derivative is minus that of the gap along z1 (a FMBJ3_GAP_ALONG row). */
#include <math.h>
#include <stdio.h>
#include <stdlib.h>

#include "spatial_pair.h"
#include "time_law.h"

typedef struct {
  fmbSpatialPair sp; /* first: the fmbj3_* helpers take the state as a pair */
  int driven;
  double offset;
  fmbMotion motion;
} Prismatic3d;

static int prismatic3d_parse(fmbParser* p, fmbNode item, void** self) {
  Prismatic3d* s = calloc(1, sizeof *s);
  *self = s;
  if (!s) return fmb_parse_error(p, item, "out of memory");
  if (fmbj3_parse(p, item, "axis", &s->sp) || fmb_get_double(p, item, "offset", 0, &s->offset)) return -1;
  s->driven = fmb_find_key(p, item, "profile") >= 0;
  return s->driven ? fmbj_motion_parse(p, item, 0, &s->motion) : 0;
}

static void prismatic3d_destroy(void* self) {
  Prismatic3d* s = self;
  if (s && s->driven) fmbj_law_free(&s->motion.law);
  free(s);
}

/* the slider's five rows, then (driven) the gap along the axis, turned into the slide's row */
static const fmbj3Row prismatic3d_rows[] = {{FMBJ3_AXES, 0, 1},      {FMBJ3_AXES, 1, 2},      {FMBJ3_AXES, 2, 0},
                                            {FMBJ3_GAP_ALONG, 0, 0}, {FMBJ3_GAP_ALONG, 1, 0}, {FMBJ3_GAP_ALONG, 2, 0}};
enum { SLIDER_ROWS = 5 };

static int prismatic3d_nrows(const void* self) { return SLIDER_ROWS + (((const Prismatic3d*)self)->driven ? 1 : 0); }

static int prismatic3d_constraint(const void* self, const fmbJointEval* ev, double* phi, double* phi_q, double* phi_t,
                                  double* phi_tt) {
  const Prismatic3d* s = self;
  const int rc = fmbj3_rows(ev, &s->sp, prismatic3d_rows, prismatic3d_nrows(self), phi, phi_q);
  if (rc || !s->driven) return rc;
  double f[3];
  fmbj_motion_eval(&s->motion, ev, f);
  phi[SLIDER_ROWS] = -phi[SLIDER_ROWS] - s->offset - f[0]; /* slide = -(p1 - p2) . z1 */
  phi_t[SLIDER_ROWS] = -f[1];
  phi_tt[SLIDER_ROWS] = -f[2];
  if (phi_q) {
    const int ld = fmb_eval_ncoord(ev, 0) + fmb_eval_ncoord(ev, 1);
    double* row = phi_q + (size_t)SLIDER_ROWS * ld;
    for (int c = 0; c < ld; ++c) row[c] = -row[c];
  }
  return 0;
}

static int prismatic3d_input(const void* self, double* initial) {
  const Prismatic3d* s = self;
  return s->driven && fmbj_law_input(&s->motion.law, initial);
}

static void prismatic3d_describe(const void* self, FILE* out) {
  const Prismatic3d* s = self;
  if (s->driven)
    fprintf(out, "relative orientation held, point2 slides along the axis, the slide prescribed (%s profile; 6 rows)\n",
            fmbj_motion_name(&s->motion));
  else
    fprintf(out, "relative orientation held, point2 slides along the axis (5 rows)\n");
}

static const char* const prismatic3d_outputs[] = {"displacement", NULL};
static const char* const prismatic3d_output_units[] = {"m", NULL};
static int prismatic3d_output(const void* self, int id, const fmbJointEval* ev, double* value) {
  fmbSpatialEval e;
  const int rc = fmbj3_eval(ev, &((const Prismatic3d*)self)->sp, 0, 0, &e);
  if (rc) return rc;
  (void)id;
  *value = fmbj3_slide(&e);
  return 0;
}

static const fmbParam prismatic3d_params[] = {
    FMBJ_SPATIAL_PAIR_PARAMS,
    FMBJ_SPATIAL_AXIS_PARAM("the joint axis"),
    {.key = "offset", .kind = FMB_PARAM_NUMBER, .unit = "m", .fallback = "0", .doc = "slide at f = 0 (with a profile)"},
    FMBJ_OPTIONAL_MOTION_PARAMS("m", "slide"),
    {.key = NULL}};

const fmbJointType fmb_joint_prismatic3d = {
    .name = "prismatic3d",
    .abi = FMB_ABI_VERSION,
    .parse = prismatic3d_parse,
    .describe = prismatic3d_describe,
    .destroy = prismatic3d_destroy,
    .bodies = fmbj3_bodies,
    .attachment3 = fmbj3_attachment,
    .nrows = prismatic3d_nrows,
    .constraint = prismatic3d_constraint,
    .input = prismatic3d_input,
    .output_names = prismatic3d_outputs,
    .output_units = prismatic3d_output_units,
    .output = prismatic3d_output,
    .params = prismatic3d_params,
    .example = "body1: a\nbody2: b\npoint1: [0.5, 0, 0]\npoint2: [-0.5, 0, 0]\naxis: [1, 0, 0]\n",
    .dimensions = FMB_DIM_SPATIAL,
};
