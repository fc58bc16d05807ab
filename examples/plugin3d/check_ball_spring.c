/* check_ball_spring.c — a program embedding flexmbd runs ball_spring.yaml (the scene's plugins:
 * line loads ball_spring.so) and compares it with the damped oscillator of each coordinate
 * (ball_spring.yaml's header):
 *   bob.x, bob.y, bob.z   x_s + exp(-zeta wn t) [(x0 - x_s) cos(wd t) + (v0 + zeta wn (x0 - x_s)) / wd sin(wd t)]
 *   mount.stretch         |x - a|
 *   energy.balance        constant: the damper's work is the energy lost
 * usage: check_ball_spring SCENE.yaml OUT.csv      exit 0 when all agree to 1e-7 */
#include <math.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>

#include <flexmbd.h>

int main(int argc, char** argv) {
  if (argc != 3) {
    fprintf(stderr, "usage: %s SCENE.yaml OUT.csv\n", argv[0]);
    return 2;
  }
  fmbDiag d;
  fmbRegistry* reg = fmb_registry_new();
  if (!reg || fmb_registry_add(reg, fmb_builtin_plugin(), "built-in", &d)) return 2;
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

  /* ball_spring.yaml */
  const double mass = 0.5, k = 20, c = 0.3, g[3] = {0, 0, -9.81}, a[3] = {0, 0, 1};
  const double x0[3] = {0.1, 0, 1}, v0[3] = {0, 0.3, 0.2};
  const double wn = sqrt(k / mass), zeta = c / (2 * sqrt(k * mass)), wd = wn * sqrt(1 - zeta * zeta);
  FILE* f = fopen(argv[2], "r");
  char line[1024];
  const char* header = "t,bob.x,bob.y,bob.z,mount.stretch,mount.force,mount.work,energy.total,energy.balance";
  if (!f || !fgets(line, sizeof line, f) || strncmp(line, header, strlen(header)) != 0) {
    fprintf(stderr, "unexpected CSV header in %s\n", argv[2]);
    if (f) fclose(f);
    return 1;
  }
  double worst = 0, worst_stretch = 0, balance0 = NAN, drift = 0, lost = 0, total0 = NAN;
  double t, x[3], stretch, force, work, total, balance;
  long rows = 0;
  while (fscanf(f, "%lf,%lf,%lf,%lf,%lf,%lf,%lf,%lf,%lf", &t, &x[0], &x[1], &x[2], &stretch, &force, &work, &total,
                &balance) == 9) {
    double s2 = 0;
    for (int i = 0; i < 3; ++i) {
      const double xs = a[i] + mass * g[i] / k, u0 = x0[i] - xs;
      const double exact = xs + exp(-zeta * wn * t) * (u0 * cos(wd * t) + (v0[i] + zeta * wn * u0) / wd * sin(wd * t));
      worst = fmax(worst, fabs(x[i] - exact));
      s2 += (x[i] - a[i]) * (x[i] - a[i]);
    }
    worst_stretch = fmax(worst_stretch, fabs(stretch - sqrt(s2)));
    if (isnan(balance0)) balance0 = balance, total0 = total;
    drift = fmax(drift, fabs(balance - balance0));
    lost = total0 - total;
    ++rows;
  }
  fclose(f);
  printf("%ld rows: |x - exact| <= %.2e m, |stretch - |x - a|| <= %.2e m, energy lost %.4f J, balance drift %.2e J\n",
         rows, worst, worst_stretch, lost, drift);
  if (rows < 500 || !(worst < 1e-7) || !(worst_stretch < 1e-10) || !(lost > 0.1) || !(drift < 1e-6)) {
    printf("FAIL: the run does not agree with the damped oscillator\n");
    return 1;
  }
  printf("check_ball_spring: agrees with the analytic solution\n");
  return 0;
}
