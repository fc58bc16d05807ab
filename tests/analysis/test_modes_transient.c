/*
 * test_modes_transient.c — modes against transient runs of the same scene:
 *   - a cantilever released undeformed under a small gravity vibrates about its static sag: the
 *     zero crossings of tip_v - sag over 10 s (6 periods, sampled every 5 ms) give its frequency,
 *     which must equal `modes` about the static state within 0.1 % (crossings are located to
 *     ~1e-4 of a period by linear interpolation);
 *   - the paper's spin-up to 4 rad/s leaves a free vibration after the ramp (t > 15 s): its
 *     frequency equals `modes --at 20` about the steady rotation, within 0.3 % (3 periods);
 *   - the same beam welded to a hub at radius 0.5 m (its root circles, stiffer: 5.005 rad/s), within
 *     0.3 % (the run's own error at rtol 1e-6 is 1e-3 here: checked at rtol 1e-8);
 *   - `initial: static`: a run started from the static state stays there (tip_v constant to
 *     1e-6 of the sag), and one started from the steady rotation keeps its stretch.
 */
#include "analysis.h"

/* angular frequency from the zero crossings of x - ref for t >= t0 */
static double crossing_frequency(const fmbtCsv* c, const char* col, double ref, double t0) {
  const double* t = fmbt_col(c, "t");
  const double* x = fmbt_col(c, col);
  if (!t || !x) return NAN;
  int n = 0;
  double first = NAN, last = NAN;
  for (int i = 1; i < c->nrow; ++i) {
    if (t[i - 1] < t0) continue;
    const double a = x[i - 1] - ref, b = x[i] - ref;
    if ((a < 0.0) != (b < 0.0)) {
      const double tc = t[i - 1] - a * (t[i] - t[i - 1]) / (b - a);
      if (n++ == 0) first = tc;
      last = tc;
    }
  }
  return n >= 2 ? M_PI * (n - 1) / (last - first) : NAN;
}

/* the frequency of the free vibration a spin-up (ramp over t < 15 s) leaves, from the zero
   crossings of tip_v about its mean over t >= 15 s, against `modes --at 20` (checked within 0.3 %);
   returns the modal one */
static double after_ramp(const char* scene, const char* const* ov, int nov, const char* what) {
  Analysis a;
  ENSURE(analyse(&a, scene, NULL, 0, 1, 20.0, 1) == 0);
  const double w_modes = a.modes ? a.modes->frequency[0] : NAN;
  ENSURE(a.st.iterations <= 5); /* turned to the drives' angle first, then Newton */
  analysis_free(&a);
  fmbtCsv c;
  fmbStats st;
  ENSURE(fmbt_run_read(scene, ov, nov, "ramp.csv", &c, &st) == 0);
  const double* tv = fmbt_col(&c, "beam.tip_v");
  const double* t = fmbt_col(&c, "t");
  double mean = 0.0;
  int nm = 0;
  for (int i = 0; tv && t && i < c.nrow; ++i)
    if (t[i] >= 15.0) {
      mean += tv[i];
      ++nm;
    }
  mean /= nm > 0 ? nm : 1;
  const double w_run = crossing_frequency(&c, "beam.tip_v", mean, 15.0);
  printf("%s, free vibration after the ramp: %.6f rad/s, modes --at 20: %.6f rad/s (%+.2e)\n", what, w_run, w_modes,
         w_run / w_modes - 1.0);
  ENSURE_REL(w_run, w_modes, 3e-3);
  fmbt_csv_free(&c);
  return w_modes;
}

int main(void) {
  const char* ov[] = {"gravity=[0, -0.01]", "solver.t_end=10", "solver.output_step=0.005", "solver.rtol=1e-8"};
  Analysis a;
  ENSURE(analyse(&a, "tests/analysis/scenes/cantilever.yaml", ov, 1, 0, 0.0, 1) == 0);
  const double sag = state_output(&a, "beam.tip_v");
  const double w_modes = a.modes ? a.modes->frequency[0] : NAN;
  analysis_free(&a);
  fmbtCsv c;
  fmbStats st;
  ENSURE(fmbt_run_read("tests/analysis/scenes/cantilever.yaml", ov, 4, "sag.csv", &c, &st) == 0);
  const double w_run = crossing_frequency(&c, "beam.tip_v", sag, 0.0);
  printf("cantilever about its sag %.4e m: transient %.6f rad/s, modes %.6f rad/s (%+.2e)\n", sag, w_run, w_modes,
         w_run / w_modes - 1.0);
  ENSURE_REL(w_run, w_modes, 1e-3);
  fmbt_csv_free(&c);

  const char* tight[] = {"solver.rtol=1e-8", "solver.atol=1e-10"};
  const double w_spin = after_ramp("scenes/paper/spinup_w4.yaml", NULL, 0, "spin-up to 4 rad/s");
  const double w_hub = after_ramp("tests/analysis/scenes/hub.yaml", tight, 2, "hub of radius 0.5 m at 4 rad/s");
  ENSURE(w_spin > 4.0 && w_hub > w_spin); /* stiffened, more so on the hub */

  /* initial: static */
  const char* ovs[] = {"gravity=[0, -0.01]", "solver.t_end=2", "solver.output_step=0.01", "initial=static"};
  ENSURE(fmbt_run_read("tests/analysis/scenes/cantilever.yaml", ovs, 4, "still.csv", &c, &st) == 0);
  const double* tv = fmbt_col(&c, "beam.tip_v");
  double dev = 0.0;
  for (int i = 0; tv && i < c.nrow; ++i) dev = fmax(dev, fabs(tv[i] - sag));
  printf("initial: static under gravity: tip_v stays within %.2e m of the sag %.4e m over 2 s\n", dev, sag);
  ENSURE(c.nrow > 100);
  ENSURE(dev < 1e-6 * fabs(sag));
  fmbt_csv_free(&c);
  const char* ovr[] = {"joints.spin.speed=15", "initial=static", "solver.output_step=0.01"};
  ENSURE(fmbt_run_read("tests/analysis/scenes/rotating.yaml", ovr, 3, "steady.csv", &c, &st) == 0);
  const double* tu = fmbt_col(&c, "beam.tip_u");
  const double stretch = 2767.0 * 225.0 * pow(SEED_L, 3) / (3.0 * 68.95e9);
  dev = 0.0;
  for (int i = 0; tu && i < c.nrow; ++i) dev = fmax(dev, fabs(tu[i] - stretch));
  printf("initial: static at 15 rad/s: tip_u stays within %.2e m of rho Omega^2 L^3/(3E) = %.4e m over 1 s\n", dev,
         stretch);
  ENSURE(dev < 1e-3 * stretch);
  fmbt_csv_free(&c);
  return fmbt_finish("test_modes_transient");
}
