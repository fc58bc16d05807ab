/* test_joints3d.c — the spatial joints against closed forms (docs/spatial.md):
 *  - revolute3d: a compound pendulum on a horizontal hinge skew to the body's principal axes
 *    swings at omega^2 = m g d / I_n, I_n = n . J n + m d^2 the inertia about the hinge line n
 *    (small amplitude: 1e-3 rad, whose frequency shift theta0^2 / 16 is 6e-8);
 *  - prismatic3d and cylindrical: bodies on an axis inclined at 45 degrees slide with
 *    s = g t^2 / (2 sqrt 2); the prismatic block does not turn, the cylindrical spool spins at its
 *    initial 1 rad/s (no torque about the axis reaches it);
 *  - the six-joint chain (tests/spatial/scenes/chain.yaml: every spatial joint) keeps its energy
 *    (ideal joints do no work) and its constraints. */
#include <math.h>
#include <stdio.h>

#include "testlib.h"

int main(void) {
  const double g = 9.81;
  { /* the hinge */
    const double m = 2.0, d = 0.4, n[3] = {M_SQRT1_2, M_SQRT1_2, 0.0}, J[3] = {0.02, 0.03, 0.015};
    const double In = n[0] * n[0] * J[0] + n[1] * n[1] * J[1] + n[2] * n[2] * J[2] + m * d * d;
    const double omega = sqrt(m * g * d / In), amp = 1e-3, w0 = amp * omega;
    char ov[2][160];
    snprintf(ov[0], sizeof ov[0], "bodies.bob.angular_velocity=[%.17g, %.17g, 0]", w0 * n[0], w0 * n[1]);
    snprintf(ov[1], sizeof ov[1], "bodies.bob.velocity=[%.17g, %.17g, 0]", -d * n[1] * w0, d * n[0] * w0);
    const char* ovs[2] = {ov[0], ov[1]};
    fmbtCsv c;
    fmbStats st;
    ENSURE(fmbt_run_read("tests/spatial/scenes/hinge.yaml", ovs, 2, "hinge3d.csv", &c, &st) == 0);
    int ncross = 0;
    const double f = fmbt_crossing_frequency(&c, "hinge.angle", 0.5, &ncross);
    const double* a = fmbt_col(&c, "hinge.angle");
    double amax = 0.0;
    for (int i = 0; a && i < c.nrow; ++i) amax = fmax(amax, fabs(a[i]));
    printf("hinge: %.9f rad/s over %d crossings (closed form %.9f, relative error %.2e), amplitude %.6e rad "
           "(%.6e)\n",
           f, ncross, omega, fabs(f - omega) / omega, amax, amp);
    ENSURE_REL(f, omega, 1e-6);
    ENSURE_REL(amax, amp, 1e-4);
    fmbt_csv_free(&c);
  }
  { /* the incline */
    fmbtCsv c;
    fmbStats st;
    ENSURE(fmbt_run_read("tests/spatial/scenes/incline.yaml", NULL, 0, "incline3d.csv", &c, &st) == 0);
    const double *t = fmbt_col(&c, "t"), *s1 = fmbt_col(&c, "slider.displacement"),
                 *s2 = fmbt_col(&c, "sleeve.displacement"), *ang = fmbt_col(&c, "sleeve.angle"),
                 *wx = fmbt_col(&c, "block.wx"), *wy = fmbt_col(&c, "block.wy"), *wz = fmbt_col(&c, "block.wz");
    double e1 = 0.0, e2 = 0.0, ea = 0.0, ew = 0.0;
    for (int i = 0; t && s1 && s2 && ang && wx && wy && wz && i < c.nrow; ++i) {
      const double s = g * t[i] * t[i] / (2.0 * M_SQRT2);
      e1 = fmax(e1, fabs(s1[i] - s));
      e2 = fmax(e2, fabs(s2[i] - s));
      ea = fmax(ea, fabs(ang[i] - t[i])); /* 1 rad/s, up to 2 rad: inside (-pi, pi] */
      ew = fmax(ew, sqrt(wx[i] * wx[i] + wy[i] * wy[i] + wz[i] * wz[i]));
    }
    printf("incline: prismatic off g t^2 / (2 sqrt 2) by %.2e m, cylindrical by %.2e m (%.3f m at %.1f s); spool "
           "angle off 1 rad/s by %.2e rad; block turns at up to %.2e rad/s\n",
           e1, e2, g * 4.0 / (2.0 * M_SQRT2), t ? t[c.nrow - 1] : NAN, ea, ew);
    ENSURE(e1 < 1e-7 && e2 < 1e-7 && ea < 1e-7 && ew < 1e-7);
    fmbt_csv_free(&c);
  }
  { /* the chain */
    const char* ovs[2] = {"solver.rtol=1e-10", "solver.t_end=0.5"};
    fmbtCsv c;
    fmbStats st;
    ENSURE(fmbt_run_read("tests/spatial/scenes/chain.yaml", ovs, 2, "chain3d.csv", &c, &st) == 0);
    const double *E = fmbt_col(&c, "energy.total"), *K = fmbt_col(&c, "energy.kinetic"),
                 *cp = fmbt_col(&c, "constraint.position");
    double dE = 0.0, kmax = 0.0, cmax = 0.0;
    for (int i = 0; E && K && cp && i < c.nrow; ++i) {
      dE = fmax(dE, fabs(E[i] - E[0]));
      kmax = fmax(kmax, K[i]);
      cmax = fmax(cmax, cp[i]);
    }
    printf("chain of six joints: energy drift %.2e J (kinetic up to %.3g J), constraints held to %.2e; %ld steps\n", dE,
           kmax, cmax, st.steps);
    ENSURE(kmax > 50.0); /* it moves */
    ENSURE(dE < 1e-7 * kmax);
    ENSURE(cmax < 1e-9);
    fmbt_csv_free(&c);
  }
  return fmbt_finish("test_joints3d");
}
