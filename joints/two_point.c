/* two_point.c — shared pieces of joints that connect a point on one body to a point on another. */
#include <string.h>

#include "two_point.h"

int fmbj_parse_two_points(fmbParser* p, fmbNode item, fmbTwoPoint* tp) {
  memset(tp, 0, sizeof *tp);
  if (fmb_get_body(p, item, "body1", FMB_REQUIRED, &tp->body[0]) ||
      fmb_get_body(p, item, "body2", FMB_REQUIRED, &tp->body[1]))
    return -1;
  /* only a type declaring FMB_DIM_SPATIAL meets a spatial scene (the engine refuses the others at
     their `type:`), so the planar joints never take this branch */
  tp->spatial = fmb_scene_dimension(p) == 3;
  if (tp->spatial)
    return fmb_get_point3(p, item, "point1", 0, tp->body[0], tp->point[0]) ||
                   fmb_get_point3(p, item, "point2", 0, tp->body[1], tp->point[1])
               ? -1
               : 0;
  return (fmb_get_point(p, item, "point1", 0, tp->body[0], tp->point[0]) ||
          fmb_get_point(p, item, "point2", 0, tp->body[1], tp->point[1]))
             ? -1
             : 0;
}

/* gap = p1 - p2; phi_q rows 0..1 = [dp1/dq1, -dp2/dq2]; ang = marker angles, dang (ld entries)
   = [-dang1/dq1, dang2/dq2] so that d(ang2 - ang1)/dq = dang */
int fmbj_point_gap(const fmbJointEval* ev, const fmbTwoPoint* tp, double gap[2], double* phi_q, int ld, double ang[2],
                   double* dang) {
  double p[2][2];
  for (int k = 0; k < 2; ++k) {
    const int c0 = fmb_eval_col0(ev, k);
    int rc = fmb_marker(ev, k, tp->point[k], p[k], &ang[k], phi_q ? phi_q + c0 : NULL, ld, dang ? dang + c0 : NULL);
    if (rc) return rc;
    const int n = fmb_eval_ncoord(ev, k);
    if (k == 1 && phi_q)
      for (int i = 0; i < n; ++i) {
        phi_q[c0 + i] = -phi_q[c0 + i];
        phi_q[ld + c0 + i] = -phi_q[ld + c0 + i];
      }
    if (k == 0 && dang)
      for (int i = 0; i < n; ++i) dang[c0 + i] = -dang[c0 + i];
  }
  gap[0] = p[0][0] - p[1][0];
  gap[1] = p[0][1] - p[1][1];
  return 0;
}

int fmbj_point_gap3(const fmbJointEval* ev, const fmbTwoPoint* tp, double gap[3], double* phi_q, int ld) {
  double p[2][3], R[9];
  for (int k = 0; k < 2; ++k) {
    const int c0 = fmb_eval_col0(ev, k);
    const int rc = fmb_marker3(ev, k, tp->point[k], p[k], R, phi_q ? phi_q + c0 : NULL, NULL, ld);
    if (rc) return rc;
    const int n = fmb_eval_ncoord(ev, k);
    if (k == 1 && phi_q)
      for (int r = 0; r < 3; ++r)
        for (int i = 0; i < n; ++i) phi_q[(size_t)r * ld + c0 + i] = -phi_q[(size_t)r * ld + c0 + i];
  }
  for (int i = 0; i < 3; ++i) gap[i] = p[0][i] - p[1][i];
  return 0;
}

void fmbj_two_point_bodies(const void* self, int body[2]) {
  const fmbTwoPoint* tp = self;
  body[0] = tp->body[0];
  body[1] = tp->body[1];
}

int fmbj_two_point_attachment(const void* self, int k, int* body, double local[2]) {
  const fmbTwoPoint* tp = self;
  if (tp->spatial) return -1; /* a spatial scene's points are attachment3's */
  *body = tp->body[k];
  local[0] = tp->point[k][0];
  local[1] = tp->point[k][1];
  return 0;
}

int fmbj_two_point_attachment3(const void* self, int k, int* body, double local[3]) {
  const fmbTwoPoint* tp = self;
  if (!tp->spatial || (k != 0 && k != 1)) return -1;
  *body = tp->body[k];
  for (int i = 0; i < 3; ++i) local[i] = tp->point[k][i];
  return 0;
}
