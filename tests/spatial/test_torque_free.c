/* test_torque_free.c — a free asymmetric rigid body (tests/spatial/scenes/torque_free.yaml:
 * principal moments I = 1, 2, 3 kg m^2, spinning at 1 rad/s about the intermediate axis with a
 * 0.01 rad/s perturbation about the others), the Dzhanibekov flip:
 *  - kinetic energy and angular momentum (global frame) conserved to 1e-10 relative over 100 s;
 *  - the flip period against the closed form (Landau & Lifshitz, Mechanics, section 37): with
 *    2E = sum I_i w_i^2, L^2 = sum I_i^2 w_i^2 and L^2 > 2 E I2, w2 = c sn(tau, k) with
 *      tau = t sqrt((I3 - I2)(L^2 - 2 E I1) / (I1 I2 I3)),  k^2 = (I2 - I1)(2 E I3 - L^2) / ((I3 - I2)(L^2 - 2 E I1))
 *    so w2 changes sign every 2 K(k) / sqrt(...) seconds, K the complete elliptic integral of the
 *    first kind, computed here by the arithmetic-geometric mean: K = pi / (2 AGM(1, sqrt(1 - k^2))).
 *  - the Euler parameters' length, a gauge no physics sees (docs/spatial.md), stays near 1. */
#include <math.h>
#include <stdio.h>

#include "testlib.h"

static double agm(double a, double b) {
  for (int i = 0; i < 60 && fabs(a - b) > 1e-16 * a; ++i) {
    const double m = 0.5 * (a + b);
    b = sqrt(a * b);
    a = m;
  }
  return a;
}

int main(void) {
  fmbtCsv c;
  fmbStats st;
  const int rc = fmbt_run_read("tests/spatial/scenes/torque_free.yaml", NULL, 0, "torque_free.csv", &c, &st);
  ENSURE(rc == 0);
  const double *t = fmbt_col(&c, "t"), *w1 = fmbt_col(&c, "box.w1"), *w2 = fmbt_col(&c, "box.w2"),
               *w3 = fmbt_col(&c, "box.w3"), *T = fmbt_col(&c, "energy.kinetic");
  const double* L[3] = {fmbt_col(&c, "box.Lx"), fmbt_col(&c, "box.Ly"), fmbt_col(&c, "box.Lz")};
  const double* q[4] = {fmbt_col(&c, "box.qw"), fmbt_col(&c, "box.qx"), fmbt_col(&c, "box.qy"), fmbt_col(&c, "box.qz")};
  if (rc || !t || !w1 || !w2 || !w3 || !T || !L[0] || !L[1] || !L[2] || !q[0]) return fmbt_finish("test_torque_free");
  const double I1 = 1.0, I2 = 2.0, I3 = 3.0;
  /* the initial state the scene gives, from the CSV's first row (body frame = principal frame) */
  const double E2 = I1 * w1[0] * w1[0] + I2 * w2[0] * w2[0] + I3 * w3[0] * w3[0];
  const double L2 = I1 * I1 * w1[0] * w1[0] + I2 * I2 * w2[0] * w2[0] + I3 * I3 * w3[0] * w3[0];
  ENSURE_REL(2.0 * T[0], E2, 1e-12);
  ENSURE(L2 > E2 * I2); /* the case of the formulas above */
  double dE = 0.0, dL = 0.0, dq = 0.0;
  const double Lnorm = sqrt(L2);
  for (int i = 0; i < c.nrow; ++i) {
    dE = fmax(dE, fabs(T[i] - T[0]) / T[0]);
    dL = fmax(dL, sqrt(pow(L[0][i] - L[0][0], 2) + pow(L[1][i] - L[1][0], 2) + pow(L[2][i] - L[2][0], 2)) / Lnorm);
    /* the outputs' Euler parameters are normalized: |p| = 1 to round-off, by construction */
    dq = fmax(dq, fabs(q[0][i] * q[0][i] + q[1][i] * q[1][i] + q[2][i] * q[2][i] + q[3][i] * q[3][i] - 1.0));
  }
  const double rate = sqrt((I3 - I2) * (L2 - E2 * I1) / (I1 * I2 * I3));
  const double k2 = (I2 - I1) * (E2 * I3 - L2) / ((I3 - I2) * (L2 - E2 * I1));
  const double K = M_PI / (2.0 * agm(1.0, sqrt(1.0 - k2)));
  const double half_period = 2.0 * K / rate;
  /* the sign changes of w2, interpolated linearly (at a zero of sn the curvature vanishes too) */
  double first = NAN, last = NAN;
  int flips = 0;
  for (int i = 1; i < c.nrow; ++i)
    if ((w2[i - 1] > 0.0) != (w2[i] > 0.0)) {
      const double tc = t[i - 1] + (t[i] - t[i - 1]) * w2[i - 1] / (w2[i - 1] - w2[i]);
      if (flips == 0) first = tc;
      last = tc;
      ++flips;
    }
  const double measured = flips >= 2 ? (last - first) / (flips - 1) : NAN;
  printf(
      "torque-free body over %.0f s: %ld steps, %ld residuals; energy drift %.2e, angular momentum drift %.2e "
      "(relative); %d flips, half period %.9f s (closed form %.9f s, K(k) = %.9f, k^2 = %.9f), relative error %.2e\n",
      t[c.nrow - 1], st.steps, st.residuals, dE, dL, flips, measured, half_period, K, k2,
      fabs(measured - half_period) / half_period);
  ENSURE(dE < 1e-10);
  ENSURE(dL < 1e-10);
  ENSURE(dq < 1e-10);
  ENSURE(flips >= 4);
  ENSURE_REL(measured, half_period, 1e-6);
  fmbt_csv_free(&c);
  return fmbt_finish("test_torque_free");
}
