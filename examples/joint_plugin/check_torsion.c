/* check_torsion.c — a program embedding flexmbd runs torsion.yaml (the scene's plugins: line loads
 * torsion.so) and compares it with the damped oscillator (torsion.yaml's header):
 *   wheel.theta, spring.angle   theta(t) = (w0 / wd) exp(-zeta wn t) sin(wd t)
 *   spring.torque               -(k theta + c theta')
 *   energy.balance              constant: the damper's work is the energy lost
 * usage: check_torsion SCENE.yaml OUT.csv      exit 0 when all agree to 1e-6 */
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

  const double I = 0.5, k = 2, c = 0.1, w0 = 1; /* torsion.yaml */
  const double wn = sqrt(k / I), zeta = c / (2 * sqrt(k * I)), wd = wn * sqrt(1 - zeta * zeta);
  FILE* f = fopen(argv[2], "r");
  char line[1024];
  const char* header = "t,wheel.theta,spring.angle,spring.torque,spring.work,energy.total,energy.balance";
  if (!f || !fgets(line, sizeof line, f) || strncmp(line, header, strlen(header)) != 0) {
    fprintf(stderr, "unexpected CSV header in %s\n", argv[2]);
    return 1;
  }
  double worst = 0, worst_torque = 0, balance0 = NAN, drift = 0, t, th, phi, tq, work, total, balance;
  long rows = 0;
  while (fscanf(f, "%lf,%lf,%lf,%lf,%lf,%lf,%lf", &t, &th, &phi, &tq, &work, &total, &balance) == 7) {
    const double e = exp(-zeta * wn * t), exact = w0 / wd * e * sin(wd * t);
    const double rate = w0 / wd * e * (wd * cos(wd * t) - zeta * wn * sin(wd * t));
    worst = fmax(worst, fmax(fabs(th - exact), fabs(phi - exact)));
    worst_torque = fmax(worst_torque, fabs(tq + k * exact + c * rate));
    if (isnan(balance0)) balance0 = balance;
    drift = fmax(drift, fabs(balance - balance0));
    ++rows;
  }
  fclose(f);
  printf("%ld rows: |theta - exact| <= %.2e rad, |torque - exact| <= %.2e N m, energy balance drift %.2e J\n", rows,
         worst, worst_torque, drift);
  if (rows < 500 || !(worst < 1e-6) || !(worst_torque < 1e-5) || !(drift < 1e-6)) {
    printf("FAIL: the run does not agree with the damped oscillator\n");
    return 1;
  }
  printf("check_torsion: agrees with the analytic solution\n");
  return 0;
}
