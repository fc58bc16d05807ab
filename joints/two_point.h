/* two_point.h — what revolute, fixed and spring joints share: two bodies, a point on each. */
#ifndef FLEXMBD_TWO_POINT_H
#define FLEXMBD_TWO_POINT_H
#include "flexmbd_plugin.h"

typedef struct {
  int body[2];
  double point[2][3]; /* in each body's reference frame; [x, y] (z unused) in a planar scene */
  int spatial;        /* parsed in a `dimension: 3` scene: the points are [x, y, z] (fmb_marker3) */
} fmbTwoPoint;

/* keys body1, body2 (required), point1, point2 (default [0, 0]; [x, y, z], default [0, 0, 0], in a
   `dimension: 3` scene); their declarations, for a type's params list */
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
/* the keys of a rotational spring-damper (torsion, torsion3d): stiffness, damping, angle0 */
#define FMBJ_ROTATIONAL_SPRING_PARAMS                                          \
  {.key = "stiffness",                                                         \
   .kind = FMB_PARAM_NUMBER,                                                   \
   .flags = FMB_REQUIRED | FMB_NONNEGATIVE,                                    \
   .unit = "N m/rad",                                                          \
   .doc = "rate k"},                                                           \
      {.key = "damping",                                                       \
       .kind = FMB_PARAM_NUMBER,                                               \
       .flags = FMB_NONNEGATIVE,                                               \
       .unit = "N m s/rad",                                                    \
       .fallback = "0",                                                        \
       .doc = "rate c"},                                                       \
  {                                                                            \
    .key = "angle0", .kind = FMB_PARAM_NUMBER, .unit = "rad", .fallback = "0", \
    .doc = "relative angle where it is relaxed (set point)"                    \
  }
int fmbj_parse_two_points(fmbParser* p, fmbNode item, fmbTwoPoint* tp);
/* the `bodies` and `attachment` ops of a joint whose state begins with its fmbTwoPoint */
void fmbj_two_point_bodies(const void* self, int body[2]);
int fmbj_two_point_attachment(const void* self, int k, int* body, double local[2]);
/* its `attachment3` op (a type that works in both dimensions): -1 in a planar scene */
int fmbj_two_point_attachment3(const void* self, int k, int* body, double local[3]);
/* positions of both points; with ld > 0, rows r0 and r0+1 of phi_q receive d(p1 - p2)/dq */
int fmbj_point_gap(const fmbJointEval* ev, const fmbTwoPoint* tp, double gap[2], double* phi_q, int ld, double ang[2],
                   double* dang);
/* its spatial twin (fmb_marker3): gap = p1 - p2; with ld > 0, rows r0..r0+2 of phi_q receive
   d(p1 - p2)/dq */
int fmbj_point_gap3(const fmbJointEval* ev, const fmbTwoPoint* tp, double gap[3], double* phi_q, int ld);
#endif
