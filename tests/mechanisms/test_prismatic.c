/* test_prismatic.c — the prismatic joint against analytic motions.
 *  - a block on a tilted slider with the joint's spring, under gravity: s(t) = s_eq + (s0 - s_eq)
 *    cos(sqrt(k/m) t); the normal reaction balances gravity's normal part (m g cos 30) with no
 *    torque; energy.total constant; with damping, energy.total falls but energy.balance stays;
 *  - a block sliding freely on an arm driven at constant w: r = r0 cosh(w t); the arm pushes it
 *    sideways with the Coriolis force 2 m w r'; the drive's work is the kinetic energy gained. */
#include "testlib.h"

static void slider_spring(double damping) {
  char ov[64];
  snprintf(ov, sizeof ov, "joints.slide.damping=%g", damping);
  const char* ovs[1] = {ov};
  fmbtCsv c;
  fmbStats st;
  ENSURE(fmbt_run_read("tests/mechanisms/scenes/slider_spring.yaml", ovs, 1, "slider_spring.csv", &c, &st) == 0);
  const double *t = fmbt_col(&c, "t"), *s = fmbt_col(&c, "slide.displacement"), *rx = fmbt_col(&c, "slide.reaction_x"),
               *ry = fmbt_col(&c, "slide.reaction_y"), *rt = fmbt_col(&c, "slide.reaction_torque"),
               *e = fmbt_col(&c, "energy.total"), *bal = fmbt_col(&c, "energy.balance"),
               *th = fmbt_col(&c, "block.theta");
  if (!t || !s || !rx || !ry || !rt || !e || !bal || !th) return;
  const double m = 2.0, k = 50.0, g = 9.81, w = sqrt(k / m), seq = -m * g * 0.5 / k, s0 = 0.3;
  const double nx = -0.5, ny = 0.866025403784439; /* normal of the axis */
  double err_s = 0, err_n = 0, err_t = 0, err_th = 0, drift_e = 0, drift_b = 0, along = 0;
  for (int i = 0; i < c.nrow; ++i) {
    if (damping == 0) err_s = fmax(err_s, fabs(s[i] - (seq + (s0 - seq) * cos(w * t[i]))));
    err_n = fmax(err_n, fabs(rx[i] * nx + ry[i] * ny - m * g * 0.866025403784439));
    along = fmax(along, fabs(rx[i] * ny - ry[i] * nx)); /* a slider transmits no force along its axis */
    err_t = fmax(err_t, fabs(rt[i]));
    err_th = fmax(err_th, fabs(th[i] - 0.523598775598299));
    drift_e = fmax(drift_e, fabs(e[i] - e[0]));
    drift_b = fmax(drift_b, fabs(bal[i] - bal[0]));
  }
  printf(
      "slider spring (damping %g): |s - analytic| %.2e, normal reaction error %.2e N, along %.2e N, torque %.2e N m, "
      "angle %.2e; energy drift %.3g J, balance drift %.2e J\n",
      damping, err_s, err_n, along, err_t, err_th, drift_e, drift_b);
  if (damping == 0) {
    ENSURE(err_s < 1e-7);         /* amplitude 0.5 m, rtol 1e-9 */
    ENSURE(drift_e < 1e-6 * 5.2); /* E = 5.19 J */
  } else {
    ENSURE(drift_e > 1.0); /* the damper takes energy out ... */
  }
  ENSURE(err_n < 1e-6 * 17.0 && along < 1e-6 * 17.0 && err_t < 1e-6);
  ENSURE(err_th < 1e-9);
  ENSURE(drift_b < 1e-6 * 5.2); /* ... and energy.balance accounts for it */
  fmbt_csv_free(&c);
}

static void slider_on_arm(void) {
  fmbtCsv c;
  fmbStats st;
  ENSURE(fmbt_run_read("tests/mechanisms/scenes/slider_on_arm.yaml", NULL, 0, "slider_on_arm.csv", &c, &st) == 0);
  const double *t = fmbt_col(&c, "t"), *r = fmbt_col(&c, "slide.displacement"), *rd = fmbt_col(&c, "slide.velocity"),
               *rx = fmbt_col(&c, "slide.reaction_x"), *ry = fmbt_col(&c, "slide.reaction_y"),
               *th = fmbt_col(&c, "arm.theta"), *W = fmbt_col(&c, "motor.work"), *T = fmbt_col(&c, "energy.kinetic"),
               *bal = fmbt_col(&c, "energy.balance");
  if (!t || !r || !rd || !rx || !ry || !th || !W || !T || !bal) return;
  const double m = 0.5, w = 2.0, r0 = 0.5;
  double err_r = 0, err_rd = 0, err_cor = 0, err_radial = 0, err_w = 0, cor_max = 0;
  for (int i = 0; i < c.nrow; ++i) {
    err_r = fmax(err_r, fabs(r[i] - r0 * cosh(w * t[i])));
    err_rd = fmax(err_rd, fabs(rd[i] - r0 * w * sinh(w * t[i])));
    const double ex = cos(th[i]), ey = sin(th[i]);
    const double normal = -ey * rx[i] + ex * ry[i], radial = ex * rx[i] + ey * ry[i];
    const double coriolis = 2.0 * m * w * r0 * w * sinh(w * t[i]); /* 2 m w r', with the analytic r' */
    err_cor = fmax(err_cor, fabs(normal - coriolis));
    cor_max = fmax(cor_max, coriolis);
    err_radial = fmax(err_radial, fabs(radial));
    err_w = fmax(err_w, fabs(W[i] - (T[i] - T[0])));
  }
  printf("slider on arm: |r - r0 cosh| %.2e, |r' - analytic| %.2e, Coriolis force error %.2e N (peak %.3g N), radial "
         "force %.2e N, |drive work - kinetic energy gained| %.2e J\n",
         err_r, err_rd, err_cor, cor_max, err_radial, err_w);
  ENSURE(err_r < 1e-7 && err_rd < 1e-6);
  ENSURE(err_cor < 1e-5 * cor_max);
  ENSURE(err_radial < 1e-6);
  ENSURE(err_w < 1e-6 * T[c.nrow - 1]);
  fmbt_csv_free(&c);
}

int main(void) {
  slider_spring(0.0);
  slider_spring(2.0);
  slider_on_arm();
  return fmbt_finish("test_prismatic");
}
