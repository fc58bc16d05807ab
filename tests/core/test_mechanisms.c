/* test_mechanisms.c — rigid mechanisms against independent values.
 *  - double pendulum (chaotic, conservative): total energy constant to a level consistent with
 *    rtol over 10 s, and tighter rtol gives a smaller drift; constraints stay at tolerance level;
 *  - Grashof crank-rocker four-bar driven at constant crank speed: rocker angle vs the closed-form
 *    position solution (intersection of the coupler and rocker circles, open branch);
 *  - spin-up drive (Eq. 41 of Liu, Hong & Liu 2009): the bar's angle and speed follow the analytic
 *    profile, computed here independently; after Tn the speed is exactly omega0 (steady state);
 *  - constant-speed drive: theta = speed t, omega = speed. */
#include <stdlib.h>
#include <string.h>

#include "testlib.h"

static int double_pendulum(double rtol, double* drift, double* cmax) {
  char o[2][64];
  snprintf(o[0], sizeof o[0], "solver.rtol=%g", rtol);
  snprintf(o[1], sizeof o[1], "solver.atol=%g", rtol * 1e-2);
  const char* ov[2] = {o[0], o[1]};
  fmbtCsv c;
  fmbStats st;
  char name[64];
  snprintf(name, sizeof name, "double_pendulum_%g.csv", rtol);
  int rc = fmbt_run_read("scenes/double_pendulum.yaml", ov, 2, name, &c, &st);
  const double *e = fmbt_col(&c, "energy.total"), *ke = fmbt_col(&c, "energy.kinetic"),
               *cp = fmbt_col(&c, "constraint.position");
  *drift = *cmax = 0.0;
  double kmax = 0.0;
  if (e && cp && ke)
    for (int i = 0; i < c.nrow; ++i) {
      *drift = fmax(*drift, fabs(e[i] - e[0]));
      *cmax = fmax(*cmax, cp[i]);
      kmax = fmax(kmax, ke[i]);
    }
  *drift /= kmax; /* relative to the energy scale of the motion (E(0) = 0 here) */
  fmbt_csv_free(&c);
  return rc;
}

static double rocker_closed_form(double th2) {
  const double a = 1.0, b = 3.5, c = 3.0, d = 4.0;
  const double Ax = a * cos(th2), Ay = a * sin(th2);
  const double Dx = d - Ax, Dy = -Ay, dist = hypot(Dx, Dy);
  const double aa = (b * b - c * c + dist * dist) / (2 * dist), h = sqrt(b * b - aa * aa);
  const double ux = Dx / dist, uy = Dy / dist;
  const double Bx = Ax + aa * ux - h * uy, By = Ay + aa * uy + h * ux;
  return atan2(By, Bx - d);
}

static void spinup(double t, double w0, double Tn, double* f, double* fd) {
  if (t <= Tn) {
    *f = w0 / Tn * (t * t / 2 + pow(Tn / (2 * M_PI), 2) * (cos(2 * M_PI * t / Tn) - 1));
    *fd = w0 / Tn * (t - Tn / (2 * M_PI) * sin(2 * M_PI * t / Tn));
  } else {
    *f = w0 * (t - Tn / 2);
    *fd = w0;
  }
}

int main(void) {
  fmbtCsv c;
  fmbStats st;

  double d6, c6, d9, c9;
  ENSURE(double_pendulum(1e-6, &d6, &c6) == 0);
  ENSURE(double_pendulum(1e-9, &d9, &c9) == 0);
  printf("double pendulum: relative energy drift %.2e (rtol 1e-6), %.2e (rtol 1e-9); constraint max %.2e, %.2e\n", d6,
         c6, d9, c9);
  ENSURE(d6 < 1e-3);
  ENSURE(d9 < 1e-6);
  ENSURE(d9 < d6);
  ENSURE(c6 < 2e-6 && c9 < 2e-9); /* position tolerance ~ rtol |q| */

  ENSURE(fmbt_run_read("scenes/fourbar.yaml", NULL, 0, "fourbar.csv", &c, &st) == 0);
  const double *t = fmbt_col(&c, "t"), *th2 = fmbt_col(&c, "crank.theta"), *th4 = fmbt_col(&c, "rocker.theta");
  double err4 = 0.0, err2 = 0.0;
  if (t && th2 && th4)
    for (int i = 0; i < c.nrow; ++i) {
      err2 = fmax(err2, fabs(th2[i] - 2.0 * t[i]));
      double ref = rocker_closed_form(2.0 * t[i]);
      double dth = remainder(th4[i] - ref, 2 * M_PI);
      err4 = fmax(err4, fabs(dth));
    }
  printf("four-bar: crank angle error %.2e, rocker angle error vs closed form %.2e rad over %d rows\n", err2, err4,
         c.nrow);
  ENSURE(c.nrow == 501);
  ENSURE(err2 < 1e-8);
  ENSURE(err4 < 1e-7);
  fmbt_csv_free(&c);

  ENSURE(fmbt_run_read("scenes/spinup_bar.yaml", NULL, 0, "spinup_bar.csv", &c, &st) == 0);
  t = fmbt_col(&c, "t");
  const double *th = fmbt_col(&c, "bar.theta"), *om = fmbt_col(&c, "bar.omega");
  double eth = 0.0, eom = 0.0, esteady = 0.0;
  if (t && th && om)
    for (int i = 0; i < c.nrow; ++i) {
      double f, fd;
      spinup(t[i], 4.0, 15.0, &f, &fd);
      eth = fmax(eth, fabs(th[i] - f));
      eom = fmax(eom, fabs(om[i] - fd));
      if (t[i] > 15.0) esteady = fmax(esteady, fabs(om[i] - 4.0));
    }
  printf("spin-up drive: angle error %.2e rad, speed error %.2e rad/s, steady-state speed error %.2e\n", eth, eom,
         esteady);
  ENSURE(eth < 1e-8);
  ENSURE(eom < 1e-7);
  ENSURE(esteady < 1e-7);
  fmbt_csv_free(&c);

  const char* ov[] = {"joints.spin.profile=constant", "joints.spin.speed=3.0", "solver.t_end=5"};
  /* omega0/ramp_time are not keys of a constant profile: drop them by overriding the type's keys */
  fmbDiag d;
  int rc = fmbt_run("scenes/spinup_bar.yaml", ov, 3, "constant_bar.csv", &st, &d);
  ENSURE(rc == FMB_EXIT_BAD_INPUT); /* unknown keys omega0, ramp_time for a constant profile */
  ENSURE(strstr(d.msg, "omega0") != NULL);
  ENSURE(fmbt_run_read("tests/core/scenes/constant_bar.yaml", NULL, 0, "constant_bar.csv", &c, &st) == 0);
  t = fmbt_col(&c, "t");
  th = fmbt_col(&c, "bar.theta");
  om = fmbt_col(&c, "bar.omega");
  eth = eom = 0.0;
  if (t && th && om)
    for (int i = 0; i < c.nrow; ++i) {
      eth = fmax(eth, fabs(th[i] - 3.0 * t[i]));
      eom = fmax(eom, fabs(om[i] - 3.0));
    }
  printf("constant-speed drive: angle error %.2e, speed error %.2e\n", eth, eom);
  ENSURE(eth < 1e-8 && eom < 1e-7);
  fmbt_csv_free(&c);
  return fmbt_finish("test_mechanisms");
}
