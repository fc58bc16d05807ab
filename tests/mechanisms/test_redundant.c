/* test_redundant.c — consistent redundant constraints run, with the motion of the non-redundant
 * model and reactions that satisfy every body's equations of motion.
 *  - a bar hanging from two identical pins moves exactly like the bar on one pin; by the minimum-
 *    norm rule each pin carries half of the single pin's reaction;
 *  - a parallelogram with a third, redundant crank follows the 1-DOF pendulum in the crank angle
 *    (integrated here with RK4); the coupler (which translates on a circle) and each crank (which
 *    turns about its pivot) obey Newton's and Euler's laws with the reported pin forces;
 *  - `flexmbd check`'s report (fmb_check_constraints): the degrees of freedom counted by hand, the
 *    redundant rows by joint name, and a parallelogram started flat reported as singular (and
 *    refused by the run, exit 2). */
#include <stdlib.h>
#include <string.h>

#include "testlib.h"

/* the check report of a scene, in buf */
static int check_report(const char* rel, const char* const* ov, int nov, char* buf, size_t len) {
  char path[1024];
  fmbDiag d;
  buf[0] = '\0';
  fmbModel* m = fmb_load(fmbt_path(rel, path, sizeof path), ov, nov, fmb_builtin_registry(), &d);
  if (!m) return -1;
  FILE* f = tmpfile();
  int rc = fmb_check_constraints(m, f, &d);
  rewind(f);
  size_t n = fread(buf, 1, len - 1, f);
  buf[n] = '\0';
  fclose(f);
  fmb_free(m);
  return rc;
}

static void check_command(void) {
  char r[2048];
  ENSURE(check_report("scenes/fourbar.yaml", NULL, 0, r, sizeof r) == 0);
  ENSURE(strstr(r, "degrees of freedom: 0 (9 coordinates, 9 constraint equations of rank 9)") != NULL); /* driven */
  ENSURE(strstr(r, "redundant equations: none") != NULL);
  ENSURE(check_report("tests/mechanisms/scenes/parallelogram3.yaml", NULL, 0, r, sizeof r) == 0);
  ENSURE(strstr(r, "degrees of freedom: 1 (12 coordinates, 12 constraint equations of rank 11)") != NULL);
  ENSURE(strstr(r, "redundant equations: joint 'o3' row 2") != NULL);
  ENSURE(check_report("tests/mechanisms/scenes/pendulum_two_pins.yaml", NULL, 0, r, sizeof r) == 0);
  ENSURE(strstr(r, "degrees of freedom: 1") != NULL && strstr(r, "joint 'pin2' row 1, joint 'pin2' row 2") != NULL);
  ENSURE(strstr(r, "singular configuration at t = 0: no") != NULL);
  const char* flat[] = {"bodies.crank1.angle=0", "bodies.crank2.angle=0", "bodies.crank1.position=[0.5,0]",
                        "bodies.crank2.position=[2.5,0]", "bodies.coupler.position=[2,0]"};
  ENSURE(check_report("scenes/parallelogram.yaml", flat, 5, r, sizeof r) == 0);
  ENSURE(strstr(r, "singular configuration at t = 0: yes") != NULL);
  printf("check on a parallelogram started flat:\n%s", r);
  fmbStats st;
  fmbDiag d;
  ENSURE(fmbt_run("scenes/parallelogram.yaml", flat, 5, "flat.csv", &st, &d) == FMB_EXIT_BAD_INPUT);
  ENSURE(strstr(d.msg, "singular configuration") != NULL);
  printf("run on it: %s:%d:%d: %s\n", d.file, d.line, d.col, d.msg);
  ENSURE(d.line > 0 && d.col > 0); /* at the joint named first */
}

static void two_pins(void) {
  fmbtCsv one, two;
  fmbStats st;
  ENSURE(fmbt_run_read("tests/mechanisms/scenes/pendulum_one_pin.yaml", NULL, 0, "one_pin.csv", &one, &st) == 0);
  ENSURE(fmbt_run_read("tests/mechanisms/scenes/pendulum_two_pins.yaml", NULL, 0, "two_pins.csv", &two, &st) == 0);
  const double *th1 = fmbt_col(&one, "bar.theta"), *th2 = fmbt_col(&two, "bar.theta"),
               *rx = fmbt_col(&one, "pin.reaction_x"), *ry = fmbt_col(&one, "pin.reaction_y"),
               *ax = fmbt_col(&two, "pin.reaction_x"), *ay = fmbt_col(&two, "pin.reaction_y"),
               *bx = fmbt_col(&two, "pin2.reaction_x"), *by = fmbt_col(&two, "pin2.reaction_y");
  if (!th1 || !th2 || !rx || !ry || !ax || !ay || !bx || !by || one.nrow != two.nrow) return;
  double dth = 0, dsplit = 0, dsum = 0, rmax = 0;
  for (int i = 0; i < one.nrow; ++i) {
    dth = fmax(dth, fabs(th1[i] - th2[i]));
    dsum = fmax(dsum, fmax(fabs(ax[i] + bx[i] - rx[i]), fabs(ay[i] + by[i] - ry[i])));
    dsplit = fmax(dsplit, fmax(fabs(ax[i] - bx[i]), fabs(ay[i] - by[i])));
    rmax = fmax(rmax, hypot(rx[i], ry[i]));
  }
  printf("two identical pins vs one: angle difference %.2e rad; pin forces sum to the single pin's within %.2e N, "
         "differ from each other by %.2e N (reaction up to %.3g N)\n",
         dth, dsum, dsplit, rmax);
  ENSURE(dth < 1e-6);                                 /* two runs at rtol 1e-8, different step sequences */
  ENSURE(dsum < 1e-5 * rmax && dsplit < 1e-5 * rmax); /* Tikhonov shift 1e-10: ~1e-6 relative */
  fmbt_csv_free(&one);
  fmbt_csv_free(&two);
}

/* (k m l^2/3 + mc l^2) theta'' = -g (k m l/2 + mc l) cos(theta), k = 3 cranks */
static const double m = 1.0, mc = 2.0, l = 1.0, g = 9.81;
static double accel(double th) { return -g * (3 * m * l / 2 + mc * l) * cos(th) / (m * l * l + mc * l * l); }

static void three_cranks(void) {
  fmbtCsv c;
  fmbStats st;
  ENSURE(fmbt_run_read("tests/mechanisms/scenes/parallelogram3.yaml", NULL, 0, "parallelogram3.csv", &c, &st) == 0);
  const double *t = fmbt_col(&c, "t"), *th = fmbt_col(&c, "crank1.theta"), *om = fmbt_col(&c, "crank1.omega");
  const double* R[3][4];
  const char* names[3][4] = {{"o1.reaction_x", "o1.reaction_y", "a1.reaction_x", "a1.reaction_y"},
                             {"o2.reaction_x", "o2.reaction_y", "a2.reaction_x", "a2.reaction_y"},
                             {"o3.reaction_x", "o3.reaction_y", "a3.reaction_x", "a3.reaction_y"}};
  for (int k = 0; k < 3; ++k)
    for (int i = 0; i < 4; ++i)
      if (!(R[k][i] = fmbt_col(&c, names[k][i]))) return;
  if (!t || !th || !om) return;
  /* the exact motion: RK4 on the 1-DOF equation, 1e-4 s steps, sampled at the rows */
  double y = th[0], yd = 0.0, tt = 0.0, err = 0.0;
  const double h = 1e-4;
  double coupler = 0.0, crank = 0.0, fmax_ = 0.0;
  for (int i = 0; i < c.nrow; ++i) {
    while (tt < t[i] - 1e-12) {
      const double k1 = yd, l1 = accel(y), k2 = yd + 0.5 * h * l1, l2 = accel(y + 0.5 * h * k1), k3 = yd + 0.5 * h * l2,
                   l3 = accel(y + 0.5 * h * k2), k4 = yd + h * l3, l4 = accel(y + h * k3);
      y += h / 6 * (k1 + 2 * k2 + 2 * k3 + k4);
      yd += h / 6 * (l1 + 2 * l2 + 2 * l3 + l4);
      tt += h;
    }
    err = fmax(err, fabs(th[i] - y));
    /* coupler: translates on a circle of radius l; the a_k pins' forces act on it */
    const double a = accel(th[i]), w = om[i], s = sin(th[i]), co = cos(th[i]);
    const double acx = l * (-s * a - co * w * w), acy = l * (co * a - s * w * w);
    double fx = 0, fy = -mc * g;
    for (int k = 0; k < 3; ++k) fx += R[k][2][i], fy += R[k][3][i];
    coupler = fmax(coupler, hypot(fx - mc * acx, fy - mc * acy));
    /* each crank about its pivot: J theta'' = tip x (-(a_k force)) + centre x (m g) */
    for (int k = 0; k < 3; ++k) {
      const double tipx = l * co, tipy = l * s;
      const double torque = tipx * (-R[k][3][i]) - tipy * (-R[k][2][i]) + 0.5 * l * co * (-m * g);
      crank = fmax(crank, fabs(m * l * l / 3 * a - torque));
      fmax_ = fmax(fmax_, hypot(R[k][0][i], R[k][1][i]));
    }
  }
  printf("three-crank parallelogram (one redundant equation): crank angle vs the 1-DOF pendulum %.2e rad; coupler "
         "Newton residual %.2e N, crank Euler residual %.2e N m (pin forces up to %.3g N)\n",
         err, coupler, crank, fmax_);
  ENSURE(err < 1e-6);
  ENSURE(coupler < 1e-6 * fmax_ && crank < 1e-6 * fmax_);
  fmbt_csv_free(&c);
}

int main(void) {
  two_pins();
  three_cranks();
  check_command();
  return fmbt_finish("test_redundant");
}
