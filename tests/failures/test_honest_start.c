/* test_honest_start.c — no silently wrong start (issue 12), each against an exact value:
 *   1. a pose off the joints is an error naming the body and the size (0.5 m, exact: the pin
 *      is 0.5 m from the bob's marker), unless the scene says `initial: assemble`; then the
 *      minimum-norm correction is exactly that 0.5 m and the joint holds at t = 0;
 *   2. the projection's test is absolute: a pendulum drawn 10 km out is assembled onto its 1 m
 *      rod to 1e-10 m (distance of the bob's centre from the pivot = 1);
 *   3. a weld without `angle` holds the angle as drawn (0.7 rad), with no initial correction;
 *   4. a drive's `angle` output is the relative angle angle0 + f(t) = 0.3 + t (and equals the
 *      bar's angle, the drive being on a pin to the ground). */
#include <string.h>

#include "testlib.h"

static double max_abs_diff(const double* a, const double* b, double offset, int n) {
  double e = 0.0;
  for (int i = 0; i < n; ++i) e = fmax(e, fabs(a[i] - b[i] - offset));
  return e;
}

static void off_joint_pose(void) {
  fmbStats st;
  fmbDiag d;
  int rc = fmbt_run("tests/bad_scenes/107-pose-off-joints.yaml", NULL, 0, "honest_off.csv", &st, &d);
  ENSURE(rc == FMB_EXIT_BAD_INPUT);
  ENSURE(strstr(d.msg, "the joints move body 'bob' by 0.5 ") != NULL);
  ENSURE(strstr(d.msg, "joint 'pin' is not satisfied") == d.msg && d.line == 7 && d.col == 5); /* named, located */
  ENSURE(strstr(d.msg, "initial: assemble") != NULL);
  const char* ov[] = {"initial=assemble", "outputs=[bob.x, bob.y, constraint.position]"};
  fmbtCsv c;
  rc = fmbt_run_read("tests/bad_scenes/107-pose-off-joints.yaml", ov, 2, "honest_assembled.csv", &c, &st);
  ENSURE(rc == 0);
  ENSURE_NEAR(st.ic_position_correction, 0.5, 1e-12);
  const double *x = fmbt_col(&c, "bob.x"), *y = fmbt_col(&c, "bob.y"), *cp = fmbt_col(&c, "constraint.position");
  if (x && y && cp && c.nrow > 0) {
    ENSURE_NEAR(x[0], 1.0, 1e-12);
    ENSURE_NEAR(y[0], 0.0, 1e-12);
    ENSURE(cp[0] <= 1e-10);
  }
  fmbt_csv_free(&c);
}

static void far_off_pose(void) {
  fmbStats st;
  fmbtCsv c;
  int rc = fmbt_run_read("tests/failures/far_off_assembly.yaml", NULL, 0, "honest_far.csv", &c, &st);
  ENSURE(rc == 0);
  const double *x = fmbt_col(&c, "bob.x"), *y = fmbt_col(&c, "bob.y"), *th = fmbt_col(&c, "bob.theta"),
               *cp = fmbt_col(&c, "constraint.position");
  if (x && y && th && cp && c.nrow > 0) {
    printf("far-off pose: assembled by %.6g m, t = 0 residual %.3g, |centre| - 1 = %.3g\n", st.ic_position_correction,
           cp[0], hypot(x[0], y[0]) - 1.0);
    ENSURE(cp[0] <= 1e-10);
    /* the pin is the bob's point [-1, 0]: the centre sits 1 m from the pivot, along theta (theta
       is ~6300 rad after a minimum-norm projection, so the CSV's 12 digits give it to 1e-7) */
    ENSURE_NEAR(hypot(x[0], y[0]), 1.0, 1e-10);
    ENSURE_NEAR(x[0], cos(th[0]), 1e-6);
    ENSURE_NEAR(y[0], sin(th[0]), 1e-6);
  }
  fmbt_csv_free(&c);
}

static void weld_as_drawn(void) {
  fmbStats st;
  fmbtCsv c;
  int rc = fmbt_run_read("tests/failures/weld_as_drawn.yaml", NULL, 0, "honest_weld.csv", &c, &st);
  ENSURE(rc == 0);
  ENSURE(st.ic_position_correction <= 1e-12);
  const double *a = fmbt_col(&c, "a.theta"), *b = fmbt_col(&c, "b.theta");
  if (a && b) {
    const double e = max_abs_diff(b, a, 0.7, c.nrow);
    printf("weld as drawn: max |(b.theta - a.theta) - 0.7| = %.3g over %d rows, a.theta(1 s) = %.6g\n", e, c.nrow,
           a[c.nrow - 1]);
    ENSURE(e <= 1e-8);
    ENSURE(fabs(a[c.nrow - 1]) > 0.1); /* the mechanism did move: the weld held under load */
  }
  fmbt_csv_free(&c);
}

static void drive_angle(void) {
  fmbStats st;
  fmbtCsv c;
  int rc = fmbt_run_read("tests/failures/drive_angle0.yaml", NULL, 0, "honest_drive.csv", &c, &st);
  ENSURE(rc == 0);
  const double *t = fmbt_col(&c, "t"), *ang = fmbt_col(&c, "motor.angle"), *th = fmbt_col(&c, "bar.theta"),
               *sp = fmbt_col(&c, "motor.speed");
  if (t && ang && th && sp) {
    double e = 0.0, es = 0.0;
    for (int i = 0; i < c.nrow; ++i) {
      e = fmax(e, fabs(ang[i] - (0.3 + t[i])));
      es = fmax(es, fabs(sp[i] - 1.0));
    }
    printf("drive angle: max |angle - (0.3 + t)| = %.3g, |angle - bar.theta| = %.3g\n", e,
           max_abs_diff(ang, th, 0.0, c.nrow));
    ENSURE(e <= 1e-8);
    ENSURE(es <= 1e-12);
    ENSURE(max_abs_diff(ang, th, 0.0, c.nrow) <= 1e-12);
  }
  fmbt_csv_free(&c);
}

int main(void) {
  off_joint_pose();
  far_off_pose();
  weld_as_drawn();
  drive_angle();
  return fmbt_finish("honest_start");
}
