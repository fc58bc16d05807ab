/* frame3.c — spatial rigid-frame kinematics (docs/spatial.md), the 3D twin of frame.c, and the
 * joints' spatial view of the bodies (fmb_marker3).
 *
 * A frame is [r; p]: the origin r (3) and Euler parameters p = [e0, e1, e2, e3] of ANY nonzero
 * length. The rotation is that of the unit quaternion p / |p|:
 *   R(p) = ((e0^2 - e.e) I + 2 e e^T + 2 e0 [e]x) / |p|^2,          e = [e1, e2, e3]
 * so R does not depend on |p| (the body fixes |p| by a gauge of its own, not a constraint row).
 * With E(p) = [-e, e0 I + [e]x] (3 x 4, E(p) p = 0) the virtual rotation, global frame, is
 *   delta theta = G delta p,   G = 2 E(p) / |p|^2          (the radial part of delta p turns nothing)
 * and every body-fixed vector R u moves by d(R u) = (G delta p) x (R u). */
#include <math.h>
#include <string.h>

#include "internal.h"

int fmb_quat_matrix(const double p[4], double R[9]) {
  const double n2 = p[0] * p[0] + p[1] * p[1] + p[2] * p[2] + p[3] * p[3];
  if (!(n2 > 0.0) || !isfinite(n2)) return -1;
  const double w = p[0], x = p[1], y = p[2], z = p[3], s = 1.0 / n2;
  R[0] = (w * w + x * x - y * y - z * z) * s;
  R[1] = 2.0 * (x * y - w * z) * s;
  R[2] = 2.0 * (x * z + w * y) * s;
  R[3] = 2.0 * (x * y + w * z) * s;
  R[4] = (w * w - x * x + y * y - z * z) * s;
  R[5] = 2.0 * (y * z - w * x) * s;
  R[6] = 2.0 * (x * z - w * y) * s;
  R[7] = 2.0 * (y * z + w * x) * s;
  R[8] = (w * w - x * x - y * y + z * z) * s;
  return 0;
}

/* Shepperd's method: the largest of 4 w^2, 4 x^2, 4 y^2, 4 z^2 is taken from the trace, the others
   from off-diagonal sums over it (no cancellation near any of the four) */
void fmb_matrix_quat(const double R[9], double p[4]) {
  const double tr = R[0] + R[4] + R[8];
  const double d[4] = {tr, 2.0 * R[0] - tr, 2.0 * R[4] - tr, 2.0 * R[8] - tr};
  int k = 0;
  for (int i = 1; i < 4; ++i)
    if (d[i] > d[k]) k = i;
  const double s = 2.0 * sqrt(fmax(1.0 + d[k], 0.0)); /* = 4 |p_k| */
  double q[4];
  switch (k) {
    case 0: q[0] = 0.25 * s, q[1] = (R[7] - R[5]) / s, q[2] = (R[2] - R[6]) / s, q[3] = (R[3] - R[1]) / s; break;
    case 1: q[1] = 0.25 * s, q[0] = (R[7] - R[5]) / s, q[2] = (R[1] + R[3]) / s, q[3] = (R[2] + R[6]) / s; break;
    case 2: q[2] = 0.25 * s, q[0] = (R[2] - R[6]) / s, q[1] = (R[1] + R[3]) / s, q[3] = (R[5] + R[7]) / s; break;
    default: q[3] = 0.25 * s, q[0] = (R[3] - R[1]) / s, q[1] = (R[2] + R[6]) / s, q[2] = (R[5] + R[7]) / s; break;
  }
  const double sign = q[0] < 0.0 ? -1.0 : 1.0, n = sqrt(q[0] * q[0] + q[1] * q[1] + q[2] * q[2] + q[3] * q[3]);
  for (int i = 0; i < 4; ++i) p[i] = sign * q[i] / n;
}

int fmb_frame3_point(const double frame[7], const double local[3], double pos[3], double R[9], double* dpos_dframe,
                     double* rot_dframe, int ld) {
  if (!frame || !local || !pos) return -1;
  const double* p = frame + 3;
  double A[9];
  if (fmb_quat_matrix(p, A)) return -1;
  double u[3]; /* R local */
  for (int i = 0; i < 3; ++i) {
    u[i] = A[3 * i] * local[0] + A[3 * i + 1] * local[1] + A[3 * i + 2] * local[2];
    pos[i] = frame[i] + u[i];
  }
  if (R) memcpy(R, A, sizeof A);
  if (!dpos_dframe && !rot_dframe) return 0;
  const double n2 = p[0] * p[0] + p[1] * p[1] + p[2] * p[2] + p[3] * p[3], s = 2.0 / n2;
  /* G = 2 E(p) / |p|^2, E = [-e, e0 I + [e]x] */
  const double G[3][4] = {{-p[1] * s, p[0] * s, -p[3] * s, p[2] * s},
                          {-p[2] * s, p[3] * s, p[0] * s, -p[1] * s},
                          {-p[3] * s, -p[2] * s, p[1] * s, p[0] * s}};
  for (int i = 0; i < 3; ++i) {
    if (dpos_dframe)
      for (int c = 0; c < 3; ++c) dpos_dframe[(size_t)i * ld + c] = i == c ? 1.0 : 0.0;
    if (rot_dframe)
      for (int c = 0; c < 3; ++c) rot_dframe[(size_t)i * ld + c] = 0.0;
  }
  for (int k = 0; k < 4; ++k) {
    const double g[3] = {G[0][k], G[1][k], G[2][k]};
    const double gxu[3] = {g[1] * u[2] - g[2] * u[1], g[2] * u[0] - g[0] * u[2], g[0] * u[1] - g[1] * u[0]};
    for (int i = 0; i < 3; ++i) {
      if (dpos_dframe) dpos_dframe[(size_t)i * ld + 3 + k] = gxu[i];
      if (rot_dframe) rot_dframe[(size_t)i * ld + 3 + k] = g[i];
    }
  }
  return 0;
}

int fmb_marker3(const fmbJointEval* ev, int k, const double local[3], double pos[3], double R[9], double* dpos_dq,
                double* rot_dq, int ld) {
  if (!ev || !local || !pos || (k != 0 && k != 1) || ((dpos_dq || rot_dq) && ld < 0)) return -1;
  const int b = ev->j->body[k];
  const fmbBodyInst* bi = b >= 0 ? &ev->m->body[b] : NULL;
  if (!bi || !bi->type) { /* the world frame */
    for (int i = 0; i < 3; ++i) pos[i] = local[i];
    if (R)
      for (int i = 0; i < 9; ++i) R[i] = i % 4 == 0 ? 1.0 : 0.0;
    return 0;
  }
  if (!bi->marker3) return -1; /* a planar body: refused at parse, a plugin bug here */
  return bi->marker3(bi->self, ev->q + bi->qadr, local, pos, R, dpos_dq, rot_dq, ld, ev->work + bi->workadr);
}
