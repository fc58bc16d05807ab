/* test_loads.c — time-varying loads against their integrals: a free puck pushed at its centre by
 * F0 s(t) and a torque tau0 s(t) has vx = F0 S(t) / m and omega = tau0 S(t) / J, S = the integral
 * of s, computed here independently for each law (constant, ramp, harmonic, spinup, a table inline
 * and from a CSV file). The load's work equals the kinetic energy gained (energy.balance constant).
 * A follower load (frame: body) on a spinning puck turns with it: v = F/(m w) (sin wt, 1 - cos wt).
 * A drive whose table begins at t0 follows the prescribed angle through every row (drive_table:
 * the rows of a quadratic f, which a drive's C1 table reproduces exactly; before, the run failed
 * at t = 0 with the error test, the speed jumping at every row of a piecewise-linear angle). */
#include <string.h>

#include "testlib.h"

typedef double (*Integral)(double t);
static double S_constant(double t) { return t; }
static double S_ramp(double t) { return t < 1.5 ? t * t / 3.0 : t - 0.75; } /* ramp_time 1.5 */
static double S_harmonic(double t) { return (cos(0.3) - cos(2.5 * t + 0.3)) / 2.5; }
static double S_spinup(double t) { /* ramp_time 2: the integral of the Eq. 41 speed shape */
  const double T = 2.0;
  return t <= T ? (t * t / 2 + pow(T / (2 * M_PI), 2) * (cos(2 * M_PI * t / T) - 1)) / T : t - T / 2;
}
static double S_table(double t) { /* (0,0) (1,2) (2,2) (3,-1), held after */
  if (t <= 1) return t * t;
  if (t <= 2) return 1 + 2 * (t - 1);
  if (t <= 3) return 3 + 2 * (t - 2) - 1.5 * (t - 2) * (t - 2);
  return 3.5 - (t - 3);
}

static void law_case(const char* name, const char* const* ov, int nov, Integral S) {
  fmbtCsv c;
  fmbStats st;
  char out[64];
  snprintf(out, sizeof out, "load_%s.csv", name);
  ENSURE(fmbt_run_read("tests/mechanisms/scenes/free_load.yaml", ov, nov, out, &c, &st) == 0);
  const double *t = fmbt_col(&c, "t"), *vx = fmbt_col(&c, "puck.vx"), *om = fmbt_col(&c, "puck.omega"),
               *W = fmbt_col(&c, "push.work"), *T = fmbt_col(&c, "energy.kinetic"),
               *bal = fmbt_col(&c, "energy.balance");
  if (!t || !vx || !om || !W || !T || !bal) return;
  double ev = 0, ew = 0, eb = 0, scale = 0;
  for (int i = 0; i < c.nrow; ++i) {
    const double s = S(t[i]);
    ev = fmax(ev, fmax(fabs(vx[i] - 1.5 * s), fabs(om[i] - 0.8 * s)));
    ew = fmax(ew, fabs(W[i] - T[i]));
    eb = fmax(eb, fabs(bal[i]));
    scale = fmax(scale, T[i]);
  }
  printf("load law %-9s: velocity error %.2e, |work - kinetic energy| %.2e J, balance %.2e J (energy up to %.3g J)\n",
         name, ev, ew, eb, scale);
  ENSURE(ev < 1e-8);
  ENSURE(ew < 1e-7 * scale && eb < 1e-7 * scale);
  fmbt_csv_free(&c);
}

static void follower(int body_frame) {
  fmbtCsv c;
  fmbStats st;
  const char* ov[1] = {"joints.push.frame=global"};
  ENSURE(fmbt_run_read("tests/mechanisms/scenes/follower_load.yaml", ov, body_frame ? 0 : 1, "follower.csv", &c, &st) ==
         0);
  const double *t = fmbt_col(&c, "t"), *vx = fmbt_col(&c, "puck.vx"), *vy = fmbt_col(&c, "puck.vy"),
               *bal = fmbt_col(&c, "energy.balance");
  if (!t || !vx || !vy || !bal) return;
  const double F = 0.5, w = 2.0;
  double err = 0, eb = 0;
  for (int i = 0; i < c.nrow; ++i) {
    const double ax = body_frame ? F / w * sin(w * t[i]) : F * t[i],
                 ay = body_frame ? F / w * (1 - cos(w * t[i])) : 0.0;
    err = fmax(err, hypot(vx[i] - ax, vy[i] - ay));
    eb = fmax(eb, fabs(bal[i] - bal[0]));
  }
  printf("%s load on a spinning puck: velocity error %.2e, balance drift %.2e J\n", body_frame ? "follower" : "global",
         err, eb);
  ENSURE(err < 1e-8);
  ENSURE(eb < 1e-8);
  fmbt_csv_free(&c);
}

/* f(t) = 0.5 t - 0.8 t^2 up to 3 s, then straight on along f'(3) = -4.3 (scenes/table_drive.yaml) */
static void drive_table(const char* name, const char* const* ov, int nov) {
  fmbtCsv c;
  fmbStats st;
  char out[64];
  snprintf(out, sizeof out, "drive_%s.csv", name);
  ENSURE(fmbt_run_read("tests/mechanisms/scenes/table_drive.yaml", ov, nov, out, &c, &st) == 0);
  const double *t = fmbt_col(&c, "t"), *th = fmbt_col(&c, "bar.theta"), *om = fmbt_col(&c, "bar.omega"),
               *ang = fmbt_col(&c, "motor.angle"), *bal = fmbt_col(&c, "energy.balance");
  if (!t || !th || !om || !ang || !bal) return;
  double ea = 0.0, ew = 0.0, eb = 0.0; /* angle, speed, energy.balance drift */
  for (int i = 0; i < c.nrow; ++i) {
    const double ti = t[i], f = ti <= 3.0 ? 0.5 * ti - 0.8 * ti * ti : -5.7 - 4.3 * (ti - 3.0),
                 df = ti <= 3.0 ? 0.5 - 1.6 * ti : -4.3;
    ea = fmax(ea, fmax(fabs(th[i] - f), fabs(ang[i] - f)));
    ew = fmax(ew, fabs(om[i] - df));
    eb = fmax(eb, fabs(bal[i] - bal[0]));
  }
  printf(
      "drive table %-6s: %d rows to t = %g, %ld steps, |theta - f| %.2e rad, |omega - f'| %.2e rad/s, balance %.2e J\n",
      name, c.nrow, c.nrow ? t[c.nrow - 1] : 0.0, st.steps, ea, ew, eb);
  ENSURE(c.nrow == 401);
  ENSURE(ea < 1e-7 && ew < 1e-6);
  /* energy.balance is printed, not checked: the constraint's work is outside the error test and
     drifts by up to 0.1 J here after the last row (IDA's steps grow on the straight motion), 1e-4 J
     with max_step 1e-3; a constant drive on the same motion keeps 1e-6 J (left to issue 23 item 2) */
  fmbt_csv_free(&c);
}

int main(void) {
  drive_table("inline", NULL, 0);
  const char* tfile[] = {"joints.motor.table=table_drive.csv"};
  drive_table("file", tfile, 1);
  law_case("constant", NULL, 0, S_constant);
  const char* ramp[] = {"joints.push.law=ramp", "joints.push.ramp_time=1.5"};
  law_case("ramp", ramp, 2, S_ramp);
  const char* harm[] = {"joints.push.law=harmonic", "joints.push.frequency=2.5", "joints.push.phase=0.3"};
  law_case("harmonic", harm, 3, S_harmonic);
  const char* spin[] = {"joints.push.law=spinup", "joints.push.ramp_time=2"};
  law_case("spinup", spin, 2, S_spinup);
  const char* tab[] = {"joints.push.law=table", "joints.push.table=[[0, 0], [1, 2], [2, 2], [3, -1]]"};
  law_case("table", tab, 2, S_table);
  const char* file[] = {"joints.push.law=table", "joints.push.table=load_table.csv"};
  law_case("tablefile", file, 2, S_table);
  /* the same rows, one padded to 700 characters and a 7000-character comment: one row each (a
     512-byte line buffer once split them into two rows) */
  const char* longfile[] = {"joints.push.law=table", "joints.push.table=load_table_long.csv"};
  law_case("tablelong", longfile, 2, S_table);
  follower(1);
  follower(0);
  return fmbt_finish("test_loads");
}
