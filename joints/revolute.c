/* revolute.c — a pin: point1 on body1 and point2 on body2 coincide, Phi = p1 - p2 (2 rows). */
#include <stdio.h>
#include <stdlib.h>
#include <string.h>

#include "two_point.h"

static int revolute_parse(fmbParser* p, fmbNode item, void** self) {
  fmbTwoPoint* tp = calloc(1, sizeof *tp);
  if (!tp) return fmb_parse_error(p, item, "out of memory");
  *self = tp;
  return fmbj_parse_two_points(p, item, tp);
}

static void revolute_destroy(void* self) { free(self); }
static int revolute_nrows(const void* self) {
  (void)self;
  return 2;
}

static int revolute_constraint(const void* self, const fmbJointEval* ev, double* phi, double* phi_q, double* phi_t,
                               double* phi_tt) {
  (void)phi_t, (void)phi_tt; /* scleronomic */
  const int ld = fmb_eval_ncoord(ev, 0) + fmb_eval_ncoord(ev, 1);
  double ang[2];
  return fmbj_point_gap(ev, self, phi, phi_q, ld, ang, NULL);
}

static const char* const revolute_outputs[] = {"angle", NULL};
/* relative angle body2 - body1 at the pin */
static int revolute_output(const void* self, int id, const fmbJointEval* ev, double* value) {
  (void)id;
  double gap[2], ang[2];
  int rc = fmbj_point_gap(ev, self, gap, NULL, 0, ang, NULL);
  *value = ang[1] - ang[0];
  return rc;
}

static void revolute_describe(const void* self, FILE* out) {
  (void)self;
  fprintf(out, "the two points coincide\n");
}

static const fmbParam revolute_params[] = {FMBJ_TWO_POINT_PARAMS, {.key = NULL}};

const fmbJointType fmb_joint_revolute = {
    .name = "revolute",
    .abi = FMB_ABI_VERSION,
    .parse = revolute_parse,
    .describe = revolute_describe,
    .destroy = revolute_destroy,
    .bodies = fmbj_two_point_bodies,
    .nrows = revolute_nrows,
    .attachment = fmbj_two_point_attachment,
    .constraint = revolute_constraint,
    .output_names = revolute_outputs,
    .output = revolute_output,
    .params = revolute_params,
    .example = "body1: a\nbody2: b\npoint1: [0.5, 0]\npoint2: [-0.5, 0]\n",
    .flags = FMB_TYPE_CONFORM_FIXTURE, /* conform's pin of body a to ground */
};
