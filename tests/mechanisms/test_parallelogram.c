/* test_parallelogram.c — singular configurations: parallelogram linkages turning under gravity pass
 * the flat position (where the constraint Jacobian loses rank) about 20 times in 10 s, and follow
 * the exact motion: the linkage stays a parallelogram, so the crank angle obeys the 1-DOF pendulum
 *     (k J + c m_c l^2) theta'' = -g (k m l/2 + c m_c l) cos(theta)       (k cranks, c couplers)
 * integrated here with RK4 (1e-4 s steps; its own error is far below 1e-9 rad).
 * Linkages: scenes/parallelogram.yaml (k = 2, c = 1), scenes/parallelogram_chain.yaml (a row of
 * two, k = 3, c = 2) and tests/mechanisms/scenes/parallelogram_row5.yaml (a row of five, k = 6,
 * c = 5), all with `formulation: projected` (CVODE, projection every step):
 *  - at rtol 1e-8 (atol 1e-10): within 1e-5 rad (measured 6.8e-7, 2.4e-6, 8.1e-6);
 *  - at rtol 3e-9: within 5e-6 rad (4.1e-7, 1.9e-6, 3.1e-6): the error falls with rtol;
 *  - every crank alike and couplers never turning (no switch to the crossed branch); the row of
 *    two keeps its energy to 1e-5 (relative);
 *  - the default formulation (auto) switches from GGL to projected at the first flat position
 *    and passes them all (2.8e-6 rad at rtol 1e-8, 2.8e-6 with radau5, which switches at t = 4.5);
 *    `formulation: ggl` stops there. */
#include <string.h>

#include "testlib.h"

typedef struct {
  double err, spread, coupler_turn, energy, energy_drift;
  int flats, ok;
} Linkage;

static double K_, C_; /* cranks, couplers */
static double accel(double th) {
  const double m = 1.0, mc = 2.0, l = 1.0, g = 9.81, J = m * l * l / 3.0;
  return -g * (K_ * m * l / 2 + C_ * mc * l) * cos(th) / (K_ * J + C_ * mc * l * l);
}

static Linkage run(const char* scene, int cranks, int couplers, double rtol, const char* formulation,
                   const char* integrator, const char* out) {
  Linkage r = {0, 0, 0, 0, 0, 0, 0};
  K_ = cranks;
  C_ = couplers;
  fmbtCsv c;
  fmbStats st;
  char o[4][64];
  snprintf(o[0], sizeof o[0], "solver.rtol=%g", rtol);
  snprintf(o[1], sizeof o[1], "solver.atol=%g", rtol / 100);
  snprintf(o[2], sizeof o[2], "solver.formulation=%s", formulation);
  snprintf(o[3], sizeof o[3], "solver.integrator=%s", integrator);
  const char* ov[4] = {o[0], o[1], o[2], o[3]};
  r.ok = fmbt_run_read(scene, ov, 4, out, &c, &st) == 0;
  const double *t = fmbt_col(&c, "t"), *th = fmbt_col(&c, "crank1.theta"), *th2 = fmbt_col(&c, "crank2.theta");
  char last_coupler[32];
  snprintf(last_coupler, sizeof last_coupler, "coupler%d.theta", couplers);
  const double* cp = fmbt_col(&c, couplers == 1 ? "coupler.theta" : last_coupler);
  const double* e = fmbt_col(&c, "energy.total");
  if (!t || !th || !th2 || !cp || !e) return r;
  r.energy = fabs(e[0]);
  const double h = 1e-4;
  double y = M_PI / 2, yd = 5.0, prev = 1.0;
  long n = 0;
  for (int i = 0; i < c.nrow; ++i) {
    for (const long target = lround(t[i] / h); n < target; ++n) {
      const double k1 = yd, l1 = accel(y), k2 = yd + 0.5 * h * l1, l2 = accel(y + 0.5 * h * k1), k3 = yd + 0.5 * h * l2,
                   l3 = accel(y + 0.5 * h * k2), k4 = yd + h * l3, l4 = accel(y + h * k3);
      y += h / 6 * (k1 + 2 * k2 + 2 * k3 + k4);
      yd += h / 6 * (l1 + 2 * l2 + 2 * l3 + l4);
    }
    r.err = fmax(r.err, fabs(remainder(th[i] - y, 2 * M_PI)));
    r.spread = fmax(r.spread, fabs(th2[i] - th[i]));
    r.coupler_turn = fmax(r.coupler_turn, fabs(cp[i]));
    r.energy_drift = fmax(r.energy_drift, fabs(e[i] - e[0]));
    if ((sin(y) > 0) != (prev > 0)) r.flats++;
    prev = sin(y);
  }
  fmbt_csv_free(&c);
  return r;
}

/* one run, reported and checked: passes at least 10 flat positions, stays a parallelogram, and
   the crank angle is within `bound` of the 1-DOF pendulum */
static Linkage checked(const char* scene, int cranks, int couplers, double rtol, const char* formulation,
                       const char* integrator, double bound) {
  char out[128];
  snprintf(out, sizeof out, "parallelogram_%d_%g_%s_%s.csv", cranks, rtol, formulation, integrator);
  Linkage r = run(scene, cranks, couplers, rtol, formulation, integrator, out);
  printf("%d crank(s), rtol %g, %s/%s: %d flat passages, crank angle error %.2e rad, cranks differ by %.1e, coupler "
         "turns %.1e rad, energy drift %.2e of %.4g J\n", cranks, rtol, formulation, integrator, r.flats, r.err, r.spread,
         r.coupler_turn, r.energy_drift, r.energy);
  ENSURE(r.ok);
  ENSURE(r.flats >= 10);
  ENSURE(r.spread < 1e-8 && r.coupler_turn < 1e-8);
  ENSURE(r.err < bound);
  return r;
}

int main(void) {
  static const struct {
    const char* scene;
    int cranks, couplers;
  } cases[] = {
      {"scenes/parallelogram.yaml", 2, 1},
      {"scenes/parallelogram_chain.yaml", 3, 2},
      {"tests/mechanisms/scenes/parallelogram_row5.yaml", 6, 5},
  };
  for (size_t i = 0; i < sizeof cases / sizeof cases[0]; ++i) {
    const Linkage a = checked(cases[i].scene, cases[i].cranks, cases[i].couplers, 1e-8, "projected", "ida", 1e-5);
    const Linkage b = checked(cases[i].scene, cases[i].cranks, cases[i].couplers, 3e-9, "projected", "ida", 5e-6);
    if (i == 1) ENSURE(a.energy_drift < 1e-5 * a.energy && b.energy_drift < 1e-5 * b.energy);
  }
  /* the default formulation: GGL until the integrator fails at the first flat position, then
     projected; with IDA and with radau5 */
  checked("scenes/parallelogram.yaml", 2, 1, 1e-8, "auto", "ida", 1e-5);
  checked("scenes/parallelogram.yaml", 2, 1, 1e-8, "auto", "radau5", 1e-5);
  /* formulation: ggl cannot pass the first flat position (t = 0.28 s) */
  const char* ggl[] = {"solver.formulation=ggl"};
  fmbStats st;
  fmbDiag d;
  ENSURE(fmbt_run("scenes/parallelogram.yaml", ggl, 1, "parallelogram_ggl.csv", &st, &d) == FMB_EXIT_SOLVER);
  printf("formulation ggl stops at t = %.4g: %.80s...\n", st.t_reached, d.msg);
  ENSURE(st.t_reached > 0.2 && st.t_reached < 0.35);
  return fmbt_finish("test_parallelogram");
}
