/* test_tight.c — the default linear solver (KLU on the reduced Newton systems) at rtol = atol =
 * 1e-12 on rigid mechanisms, against closed forms and against klu_full (the whole matrix):
 *  - the driven four-bar: rocker angle vs the circle-intersection solution;
 *  - a stiff slider: the 2 kg block on a 1e6 N/m spring along the slider axis (707 rad/s), vs
 *    s(t) = s_eq + (s0 - s_eq) cos(w t);
 *  - the fallback: with the reduced solve made to fail (solver.fault_reduced_setup, schur.c) the
 *    four-bar at 1e-12 continues with klu_full from the last good step and still matches the
 *    closed form (integrator_ida.c);
 *  - the reduced system factorized by KLU and by the dense LU (solver.schur_lu): both match it. */
#define _POSIX_C_SOURCE 200809L
#include <stdlib.h>

#include "testlib.h"

static double rocker_closed_form(double th2) {
  const double a = 1.0, b = 3.5, c = 3.0, d = 4.0;
  const double Ax = a * cos(th2), Ay = a * sin(th2), Dx = d - Ax, Dy = -Ay, dist = hypot(Dx, Dy);
  const double aa = (b * b - c * c + dist * dist) / (2 * dist), h = sqrt(b * b - aa * aa);
  const double ux = Dx / dist, uy = Dy / dist;
  return atan2(Ay + aa * uy + h * ux, Ax + aa * ux - h * uy - d);
}

/* extra: one more override (a solver option), or NULL */
static double fourbar(const char* solver, const char* extra) {
  char ls[64];
  snprintf(ls, sizeof ls, "solver.linear_solver=%s", solver);
  const char* ov[] = {"solver.rtol=1e-12", "solver.atol=1e-12", ls, extra};
  fmbtCsv c;
  fmbStats st;
  ENSURE(fmbt_run_read("scenes/fourbar.yaml", ov, extra ? 4 : 3, "tight_fourbar.csv", &c, &st) == 0);
  const double *t = fmbt_col(&c, "t"), *th = fmbt_col(&c, "rocker.theta");
  double err = 0;
  if (t && th)
    for (int i = 0; i < c.nrow; ++i) err = fmax(err, fabs(remainder(th[i] - rocker_closed_form(2.0 * t[i]), 2 * M_PI)));
  fmbt_csv_free(&c);
  return err;
}

static double stiff_slider(const char* solver) {
  char ls[64];
  snprintf(ls, sizeof ls, "solver.linear_solver=%s", solver);
  const char* ov[] = {"solver.rtol=1e-12",          "solver.atol=1e-12", ls,
                      "joints.slide.stiffness=1e6", "solver.t_end=0.1",  "solver.output_step=1e-4"};
  fmbtCsv c;
  fmbStats st;
  ENSURE(fmbt_run_read("tests/mechanisms/scenes/slider_spring.yaml", ov, 6, "tight_slider.csv", &c, &st) == 0);
  const double *t = fmbt_col(&c, "t"), *s = fmbt_col(&c, "slide.displacement");
  const double k = 1e6, m = 2.0, w = sqrt(k / m), seq = -m * 9.81 * 0.5 / k;
  double err = 0;
  if (t && s)
    for (int i = 0; i < c.nrow; ++i) err = fmax(err, fabs(s[i] - (seq + (0.3 - seq) * cos(w * t[i]))));
  fmbt_csv_free(&c);
  return err;
}

int main(void) {
  const double fallback = fourbar("klu", "solver.fault_reduced_setup=20");
  printf("four-bar with the reduced solve failing from its 20th setup on: rocker error %.2e rad\n", fallback);
  ENSURE(fallback < 1e-10);
  /* the reduced system's two LUs, forced either way (solver.schur_lu): both meet the closed form */
  const double lu_klu = fourbar("klu", "solver.schur_lu=klu"), lu_dense = fourbar("klu", "solver.schur_lu=dense");
  printf("four-bar, reduced system by KLU: rocker error %.2e rad; by the dense LU: %.2e rad\n", lu_klu, lu_dense);
  ENSURE(lu_klu < 1e-10 && lu_dense < 1e-10);
  const double f = fourbar("klu", NULL), ff = fourbar("klu_full", NULL), s = stiff_slider("klu"),
               sf = stiff_slider("klu_full");
  printf("rtol = atol = 1e-12: four-bar rocker error %.2e rad (klu), %.2e (klu_full); stiff slider error %.2e m (klu), "
         "%.2e (klu_full)\n",
         f, ff, s, sf);
  ENSURE(f < 1e-10 && ff < 1e-10); /* the CSV's 12 significant digits limit what can be seen */
  ENSURE(s < 1e-9 && sf < 1e-9);   /* amplitude 0.3 m, 700 rad/s, 11 periods */
  return fmbt_finish("test_tight");
}
