/* two_point.h — what revolute, fixed and spring joints share: two bodies, a point on each. */
#ifndef FLEXMBD_TWO_POINT_H
#define FLEXMBD_TWO_POINT_H
#include "flexmbd_plugin.h"

typedef struct {
  int body[2];
  double point[2][2]; /* in each body's reference frame */
} fmbTwoPoint;

/* keys body1, body2 (required), point1, point2 (default [0, 0]); their declarations, for a
   type's params list */
#define FMBJ_TWO_POINT_PARAMS                                                                                       \
  {.key = "body1", .kind = FMB_PARAM_BODY, .flags = FMB_REQUIRED, .doc = "first body (or ground)"},                 \
      {.key = "body2", .kind = FMB_PARAM_BODY, .flags = FMB_REQUIRED, .doc = "second body (or ground)"},            \
      {.key = "point1",                                                                                             \
       .kind = FMB_PARAM_VEC2,                                                                                      \
       .unit = "m",                                                                                                 \
       .fallback = "[0, 0]",                                                                                        \
       .doc = "point on body1, body frame"},                                                                        \
  {                                                                                                                 \
    .key = "point2", .kind = FMB_PARAM_VEC2, .unit = "m", .fallback = "[0, 0]", .doc = "point on body2, body frame" \
  }
int fmbj_parse_two_points(fmbParser* p, fmbNode item, fmbTwoPoint* tp);
/* the `bodies` and `attachment` ops of a joint whose state begins with its fmbTwoPoint */
void fmbj_two_point_bodies(const void* self, int body[2]);
int fmbj_two_point_attachment(const void* self, int k, int* body, double local[2]);
/* positions of both points; with ld > 0, rows r0 and r0+1 of phi_q receive d(p1 - p2)/dq */
int fmbj_point_gap(const fmbJointEval* ev, const fmbTwoPoint* tp, double gap[2], double* phi_q, int ld, double ang[2],
                   double* dang);
#endif
