/* check_foundation.c — a program embedding flexmbd: it registers the built-in types and the
 * foundation plugin, loads foundation.yaml, runs it, reads the CSV back and compares it with the
 * analytic solution (foundation.c's header):
 *   heave    y(t) = y0 (1 - cos(w_y t)),  y0 = m g_y / (k L),  w_y^2 = k L / m     (exact: linear)
 *   rocking  phi = 2 theta obeys phi'' = -w_t^2 sin(phi), w_t^2 = k L^3 / (12 J): a pendulum,
 *            period T = 2 pi / (w_t AGM(1, cos(phi0 / 2)))                         (exact)
 *   energy   kept by the run.
 * usage: check_foundation SCENE.yaml OUT.csv      exit 0 when all agree */
#include <math.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>

#include <flexmbd.h>

static double agm(double a, double b) {
  for (int i = 0; i < 40; ++i) {
    const double an = 0.5 * (a + b);
    b = sqrt(a * b);
    a = an;
  }
  return a;
}

int main(int argc, char** argv) {
  if (argc != 3) {
    fprintf(stderr, "usage: %s SCENE.yaml OUT.csv\n", argv[0]);
    return 2;
  }
  /* the built-in types; the scene's plugins: list brings the foundation bar */
  fmbDiag d;
  fmbRegistry* reg = fmb_registry_new();
  if (!reg || fmb_registry_add(reg, fmb_builtin_plugin(), "built-in", &d)) {
    fprintf(stderr, "error: %s\n", d.msg);
    return 2;
  }
  fmbModel* m = fmb_load(argv[1], NULL, 0, reg, &d);
  if (!m) {
    fprintf(stderr, "%s:%d:%d: error: %s\n", d.file, d.line, d.col, d.msg);
    return 2;
  }
  fmbRunOptions opt = {.csv_path = argv[2], .quiet = 1};
  fmbStats st;
  if (fmb_run(m, &opt, &st, &d)) {
    fprintf(stderr, "run failed: %s\n", d.msg);
    return 3;
  }
  fmb_free(m);
  fmb_registry_free(reg);

  /* the scene's values (foundation.yaml) */
  const double mass = 2, J = 0.25, L = 1.2, k = 500, g = -9.81, theta0 = 0.3, pi = acos(-1.0);
  const double wy = sqrt(k * L / mass), y0 = mass * g / (k * L);
  const double wt = sqrt(k * L * L * L / (12 * J)), period = 2 * pi / (wt * agm(1.0, cos(theta0)));

  FILE* f = fopen(argv[2], "r");
  char line[1024];
  if (!f || !fgets(line, sizeof line, f) || strncmp(line, "t,bar.y,bar.theta,bar.reaction,energy.total", 43) != 0) {
    fprintf(stderr, "unexpected CSV header in %s\n", argv[2]);
    return 1;
  }
  double heave_err = 0.0, e0 = NAN, drift = 0.0, tp = NAN, th_prev = NAN, t_prev = NAN;
  double crossings[64];
  int nc = 0;
  double t, y, th, reaction, e;
  while (fscanf(f, "%lf,%lf,%lf,%lf,%lf", &t, &y, &th, &reaction, &e) == 5) {
    heave_err = fmax(heave_err, fabs(y - y0 * (1 - cos(wy * t))));
    if (isnan(e0)) e0 = e;
    drift = fmax(drift, fabs(e - e0));
    /* downward zero crossings of theta (it starts at +theta0), linearly interpolated */
    if (!isnan(th_prev) && th_prev > 0 && th <= 0 && nc < 64)
      crossings[nc++] = t_prev + (t - t_prev) * th_prev / (th_prev - th);
    th_prev = th, t_prev = t;
    (void)tp, (void)reaction;
  }
  fclose(f);
  const double measured = nc >= 2 ? (crossings[nc - 1] - crossings[0]) / (nc - 1) : NAN;
  const double small_angle = 2 * pi / wt;
  printf("heave: max |y - y_exact| = %.3g m (amplitude %.3g m)\n", heave_err, fabs(y0));
  printf("rocking: period %.8f s measured over %d cycles, exact %.8f s (small-angle %.8f s), error %.2g\n", measured,
         nc - 1, period, small_angle, fabs(measured - period) / period);
  const double rocking_energy = 0.5 * k * L * L * L / 12 * sin(theta0) * sin(theta0); /* U(theta0), J */
  printf("energy: max drift %.3g J (%.2g of the rocking energy)\n", drift, drift / rocking_energy);
  int ok = heave_err < 1e-6 * fabs(y0) && fabs(measured - period) < 1e-6 * period && drift < 1e-6 * rocking_energy;
  /* the nonlinear period must be told apart from the small-angle one */
  ok = ok && fabs(small_angle - period) > 100 * fabs(measured - period);
  printf("%s\n",
         ok ? "foundation: agrees with the analytic solution" : "foundation: DISAGREES with the analytic solution");
  return ok ? 0 : 1;
}
