/* test_reactions.c — reactions and the energy balance.
 *  - pendulum: the pin pulls the bob toward the pivot with the rod tension
 *    T = m g cos(theta) + m L theta'^2 (radial equation of motion, exact for any rotary inertia);
 *  - the paper's driven spin-up (complete beam, omega0 = 4): energy.balance = T + U - W_drive stays
 *    constant to the tolerance's order, and a tighter rtol makes it tighter, while the drive's work
 *    is of the order of the energy itself;
 *  - scenes/rotor.yaml (a hub driven by a torque table, three flexible blades): the same balance
 *    with the work of an applied load, tightening with rtol. */
#include "testlib.h"

static void pendulum(void) {
  fmbtCsv c;
  fmbStats st;
  ENSURE(fmbt_run_read("tests/mechanisms/scenes/pendulum_reaction.yaml", NULL, 0, "pendulum_reaction.csv", &c, &st) ==
         0);
  const double *x = fmbt_col(&c, "bob.x"), *y = fmbt_col(&c, "bob.y"), *th = fmbt_col(&c, "bob.theta"),
               *om = fmbt_col(&c, "bob.omega"), *rx = fmbt_col(&c, "pin.reaction_x"),
               *ry = fmbt_col(&c, "pin.reaction_y"), *p = fmbt_col(&c, "pin.power");
  if (!x || !y || !th || !om || !rx || !ry || !p) return;
  const double m = 1.0, g = 9.81, L = 1.0;
  double err = 0, tmax = 0, pmax = 0;
  for (int i = 0; i < c.nrow; ++i) {
    const double ux = -x[i] / L, uy = -y[i] / L; /* bob -> pivot */
    const double tension = m * g * cos(th[i]) + m * L * om[i] * om[i];
    err = fmax(err, fabs(rx[i] * ux + ry[i] * uy - tension));
    tmax = fmax(tmax, fabs(tension));
    pmax = fmax(pmax, fabs(p[i]));
  }
  printf("pendulum: rod tension error %.2e N (tension up to %.3g N); pin power %.1e W\n", err, tmax, pmax);
  ENSURE(err < 1e-5 * tmax);
  ENSURE(pmax < 1e-9); /* a fixed pin does no work */
  fmbt_csv_free(&c);
}

/* largest drift of energy.balance and largest |work| of the column `work` of a scene at rtol */
static double balance_drift(const char* scene, double rtol, const char* outputs, const char* work_col, double* work) {
  char r[64], a[64], o[200];
  snprintf(r, sizeof r, "solver.rtol=%g", rtol);
  snprintf(a, sizeof a, "solver.atol=%g", rtol * 1e-2);
  snprintf(o, sizeof o, "outputs=%s", outputs ? outputs : "");
  /* full error control: the balance is a velocity quantity (kinetic energy, drive power), and the
     spin-up's default (positions) leaves velocity errors untested, so its drift would not tighten
     with rtol as this test asks (the scene used full before issue 16). The rotor (no outputs
     override) keeps its own settings: the count below leaves both out. */
  const char* ov[] = {r, a, o, "solver.error_control=full"};
  fmbtCsv c;
  fmbStats st;
  ENSURE(fmbt_run_read(scene, ov, outputs ? 4 : 2, "balance.csv", &c, &st) == 0);
  const double *b = fmbt_col(&c, "energy.balance"), *w = fmbt_col(&c, work_col);
  double drift = 0;
  *work = 0;
  if (b && w)
    for (int i = 0; i < c.nrow; ++i) {
      drift = fmax(drift, fabs(b[i] - b[0]));
      *work = fmax(*work, fabs(w[i]));
    }
  fmbt_csv_free(&c);
  return drift;
}

int main(void) {
  pendulum();
  double w6, w8;
  const char* spin_out = "[beam.tip_v, energy.total, energy.balance, spin.work]";
  const double d6 = balance_drift("scenes/paper/spinup_w4.yaml", 1e-6, spin_out, "spin.work", &w6),
               d8 = balance_drift("scenes/paper/spinup_w4.yaml", 1e-8, spin_out, "spin.work", &w8);
  printf("spin-up w0 = 4 (complete beam): drive work up to %.4g J; energy.balance drift %.2e J (rtol 1e-6), %.2e J "
         "(rtol 1e-8)\n",
         w6, d6, d8);
  ENSURE(w6 > 10.0);      /* the drive does real work ... */
  ENSURE(d6 < 1e-5 * w6); /* ... and the balance holds to the tolerance's order */
  ENSURE(d8 < 1e-7 * w8 && d8 < d6);
  const double r6 = balance_drift("scenes/rotor.yaml", 1e-6, NULL, "motor.work", &w6),
               r8 = balance_drift("scenes/rotor.yaml", 1e-8, NULL, "motor.work", &w8);
  printf("rotor (torque table, 3 complete blades): torque work %.4g J; energy.balance drift %.2e J (rtol 1e-6), %.2e J "
         "(rtol 1e-8)\n",
         w6, r6, r8);
  ENSURE(w6 > 20.0);
  ENSURE(r6 < 1e-3 * w6 && r8 < 2e-5 * w8 && r8 < r6 / 10);
  return fmbt_finish("test_reactions");
}
