/* spatial_pair.h — what the spatial joints share (docs/spatial.md): two bodies, a point on each,
 * and a joint frame on each that coincide in the scene's pose. Rows are built from two kinds of
 * scalar, each with its derivative through the bodies' markers (fmb_marker3):
 *   s = A . B, A = R1 a on body1, B = R2 b on body2:   ds/dq1 = G1^T (A x B),  ds/dq2 = G2^T (B x A)
 *   s = d . A, d = p1 - p2 the points' gap:             ds/dq = (dd/dq)^T A + [G1^T (A x d) on body1]
 * with G the virtual rotation (d(R u)/dq_k = G[:, k] x R u). */
#ifndef FLEXMBD_SPATIAL_PAIR_H
#define FLEXMBD_SPATIAL_PAIR_H
#include "flexmbd_plugin.h"

typedef struct {
  int body[2];
  double point[2][3]; /* in each body's frame */
  double frame[2][9]; /* the joint frame's axes (columns) in each body's frame, row-major */
} fmbSpatialPair;

/* one joint evaluation: the gap's rows (phi_q rows 0..2 when phi_q is given), both joint frames'
   axes in the global frame (X[k][3 * i + c]: component i of axis c), and both bodies' virtual
   rotations, 3 rows of the joint's columns in fmb_eval_scratch */
typedef struct {
  double gap[3];
  double X[2][9];
  const double* G;     /* 3 rows of ld, or NULL when no derivatives were asked for */
  const double* gap_q; /* d(p1 - p2)/dq, 3 rows of ld after G in the scratch, or NULL */
  int ld;
} fmbSpatialEval;

/* one constraint row: the gap's component a; axis a of frame 1 . axis b of frame 2; the gap along
   axis a of frame 1 */
enum { FMBJ3_GAP, FMBJ3_AXES, FMBJ3_GAP_ALONG };
typedef struct {
  int kind, a, b;
} fmbj3Row;

#define FMBJ_SPATIAL_PAIR_PARAMS                                                                                       \
  {.key = "body1", .kind = FMB_PARAM_BODY, .flags = FMB_REQUIRED, .doc = "first body (or ground)"},                    \
      {.key = "body2", .kind = FMB_PARAM_BODY, .flags = FMB_REQUIRED, .doc = "second body (or ground)"},               \
      {.key = "point1",                                                                                                \
       .kind = FMB_PARAM_VEC3,                                                                                         \
       .unit = "m",                                                                                                    \
       .fallback = "[0, 0, 0]",                                                                                        \
       .doc = "point on body1, body frame"},                                                                           \
  {                                                                                                                    \
    .key = "point2", .kind = FMB_PARAM_VEC3, .unit = "m", .fallback = "[0, 0, 0]", .doc = "point on body2, body frame" \
  }
#define FMBJ_SPATIAL_AXIS_PARAM(what) \
  { .key = "axis", .kind = FMB_PARAM_VEC3, .fallback = "[0, 0, 1]", .doc = what " (global frame, in the scene's pose)" }

/* body1, body2, point1, point2; with `axis_key` (or NULL: the global axes) the joint frame's z
   axis, a global direction in the scene's pose, carried into both bodies' frames */
int fmbj3_parse(fmbParser* p, fmbNode item, const char* axis_key, fmbSpatialPair* sp);
/* its parts: body1, body2, point1, point2; a unit direction from `key` (default: *dir as given);
   an orthonormal frame F (axes as columns, row-major) with z = the unit vector z; the joint frame
   F (global, in the scene's pose) into both bodies' frames */
int fmbj3_parse_points(fmbParser* p, fmbNode item, fmbSpatialPair* sp);
int fmbj3_direction(fmbParser* p, fmbNode item, const char* key, double dir[3]);
void fmbj3_frame_about(const double z[3], double F[9]);
int fmbj3_set_frame(fmbParser* p, fmbNode item, const double F[9], fmbSpatialPair* sp);
/* the `bodies` op of a joint whose state begins with its fmbSpatialPair */
void fmbj3_bodies(const void* self, int body[2]);
/* its `attachment3` op: body and point of attachment k */
int fmbj3_attachment(const void* self, int k, int* body, double local[3]);
/* the gap, the frames and (derivatives) the gap's and the bodies' virtual rotations' rows over the
   joint's ld columns, in fmb_eval_scratch */
int fmbj3_eval(const fmbJointEval* ev, const fmbSpatialPair* sp, int derivatives, int ld, fmbSpatialEval* e);
/* a joint's constraint op from its list of rows: phi and (not NULL) phi_q */
int fmbj3_rows(const fmbJointEval* ev, const fmbSpatialPair* sp, const fmbj3Row* rows, int nrows, double* phi,
               double* phi_q);
/* the turn of frame 2's x axis from frame 1's about frame 1's z axis, in (-pi, pi]; the slide
   (p2 - p1) . z1 */
double fmbj3_turn(const fmbSpatialEval* e);
/* the same turn, atan2(y1 . x2, x1 . x2), and (row not NULL, e from fmbj3_eval with derivatives)
   its exact gradient over the joint's columns, off the hinge's manifold too (so that a potential of
   the turn and its generalized force agree everywhere):
   dturn = (c ds - s dc) / (s^2 + c^2), s = y1 . x2, c = x1 . x2, each an axes row */
double fmbj3_turn_row(const fmbSpatialEval* e, double* row, int ncol0);
double fmbj3_slide(const fmbSpatialEval* e);
/* a joint's state (an fmbSpatialPair) allocated into *self; its destroy op */
int fmbj3_new(fmbParser* p, fmbNode item, void** self, fmbSpatialPair** sp);
void fmbj3_destroy(void* self);
#endif
