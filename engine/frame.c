/* frame.c — planar rigid-frame kinematics, for every body whose coordinates start with its
 * frame [x, y, theta]:  p = r + A(theta) u,  A = [c -s; s c],
 * dp/dx = e_x, dp/dy = e_y, dp/dtheta = A' u = [-s u_x - c u_y; c u_x - s u_y];
 * the point's angle is theta, d angle/dframe = [0, 0, 1]. */
#include <math.h>

#include "flexmbd_plugin.h"

void fmb_frame_point(const double frame[3], const double local[2], double pos[2], double* angle, double* dpos_dframe,
                     double* dangle_dframe) {
  if (!frame || !local || !pos) return;
  const double c = cos(frame[2]), s = sin(frame[2]);
  pos[0] = frame[0] + c * local[0] - s * local[1];
  pos[1] = frame[1] + s * local[0] + c * local[1];
  if (angle) *angle = frame[2];
  if (dpos_dframe) {
    dpos_dframe[0] = 1.0;
    dpos_dframe[1] = 0.0;
    dpos_dframe[2] = -s * local[0] - c * local[1];
    dpos_dframe[3] = 0.0;
    dpos_dframe[4] = 1.0;
    dpos_dframe[5] = c * local[0] - s * local[1];
  }
  if (dangle_dframe) {
    dangle_dframe[0] = dangle_dframe[1] = 0.0;
    dangle_dframe[2] = 1.0;
  }
}
