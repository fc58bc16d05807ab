/*
 * test_exact_convergence.c — mesh and tolerance convergence of the exact beam's cable kinematics
 * (`kinematics: cable`, bodies/beam_exact.c: cubic Hermite elements) on the paper's spin-up at
 * omega0 = 4 and 15 rad/s (label long: about 20 s CPU). The intrinsic kinematics (model: exact's
 * default) converges so fast with the mesh that at 16 elements its error is already below IDA's
 * time error at rtol 1e-10 (4e-7 m: no order to observe here); its mesh convergence is
 * tests/exact/test_exact_intrinsic.sh's.
 *
 * Reference: 64 elements at rtol 1e-10, atol 1e-12 (positions-only error control). At 16, 20, 24
 * and 32 elements with the same tolerances the error max |tip_v - reference| must fall
 * monotonically with an observed order log2(e16/e32) of at least 3 (cubic Hermite elements:
 * about 4 is measured). Tolerance convergence at 32 elements: the distance of the rtol 1e-9 run
 * from the rtol 1e-10 run must be under 0.3 times that of the rtol 1e-8 run (the time error falls
 * with rtol), and under 2e-6 m. At
 * omega0 = 15 the exact beam reaches 1e-5 m at 20 elements, and the complete model's deviation
 * from the reference (its linear curvature) is over 100 times the exact model's 16-element error.
 * The runs name IDA, on which these factors were calibrated: radau5 (the beams' default then), maps rtol
 * to 0.1 rtol^(2/3) and its time error falls ~3x per decade (rtol 1e-9 against 1e-8 at 32
 * elements, ω0 = 4: 0.30, at the bound), and its 64-element reference costs 6.5 s at ω0 = 15.
 */
#include <string.h>

#include "testlib.h"

static int run(int omega0, const char* model, int elements, const char* rtol, const char* atol, fmbtCsv* c) {
  char scene[64], set_model[64], set_el[64], set_rtol[64], set_atol[64], out[96];
  snprintf(scene, sizeof scene, "scenes/paper/spinup_w%d.yaml", omega0);
  snprintf(set_model, sizeof set_model, "bodies.beam.model=%s", model);
  snprintf(set_el, sizeof set_el, "bodies.beam.elements=%d", elements);
  snprintf(set_rtol, sizeof set_rtol, "solver.rtol=%s", rtol);
  snprintf(set_atol, sizeof set_atol, "solver.atol=%s", atol);
  snprintf(out, sizeof out, "exact_conv_w%d_%s_%d_%s.csv", omega0, model, elements, rtol);
  const int exact = strcmp(model, "exact") == 0;
  const char* ov[] = {set_model,
                      set_el,
                      set_rtol,
                      set_atol,
                      "solver.error_control=positions",
                      "solver.integrator=ida",
                      "bodies.beam.kinematics=cable"};
  fmbStats st;
  int rc = fmbt_run_read(scene, ov, exact ? 7 : 6, out, c, &st);
  printf("omega0 = %2d %-8s %2d elements rtol %s: exit %d, %ld steps, %.2f s CPU\n", omega0, model, elements, rtol, rc,
         st.steps, st.cpu_s);
  return rc;
}

static double max_abs_diff(const fmbtCsv* a, const fmbtCsv* b) {
  const double* x = fmbt_col(a, "beam.tip_v");
  const double* y = fmbt_col(b, "beam.tip_v");
  if (!x || !y || a->nrow != b->nrow) return INFINITY;
  double m = 0.0;
  for (int i = 0; i < a->nrow; ++i) m = fmax(m, fabs(x[i] - y[i]));
  return m;
}

static void convergence(int omega0) {
  static const int mesh[4] = {16, 20, 24, 32};
  fmbtCsv ref, c[4], loose[2];
  ENSURE(run(omega0, "exact", 64, "1e-10", "1e-12", &ref) == 0);
  double e[4];
  for (int k = 0; k < 4; ++k) {
    ENSURE(run(omega0, "exact", mesh[k], "1e-10", "1e-12", &c[k]) == 0);
    e[k] = max_abs_diff(&c[k], &ref);
  }
  ENSURE(run(omega0, "exact", 32, "1e-8", "1e-10", &loose[0]) == 0);
  ENSURE(run(omega0, "exact", 32, "1e-9", "1e-11", &loose[1]) == 0);
  const double dt8 = max_abs_diff(&loose[0], &c[3]), dt = max_abs_diff(&loose[1], &c[3]);
  const double order = log(e[0] / e[3]) / log(2.0);
  printf("omega0 = %d: tip error vs 64 elements: %.3e (16), %.3e (20), %.3e (24), %.3e (32) m; observed order %.2f; "
         "32 elements at rtol 1e-8 and 1e-9 differ from rtol 1e-10 by %.2e and %.2e m\n",
         omega0, e[0], e[1], e[2], e[3], order, dt8, dt);
  for (int k = 1; k < 4; ++k) ENSURE(e[k] < e[k - 1]);
  ENSURE(order > 3.0);
  ENSURE(dt < 0.3 * dt8);
  ENSURE(dt < 2e-6);
  if (omega0 == 15) {
    ENSURE(e[1] < 1e-5);
    fmbtCsv comp;
    ENSURE(run(15, "complete", 16, "1e-8", "1e-10", &comp) == 0);
    const double dc = max_abs_diff(&comp, &ref);
    printf(
        "omega0 = 15: complete (16 elements, rtol 1e-8) deviates from the exact reference by %.3e m (%.0fx the exact "
        "model's 16-element error)\n",
        dc, dc / e[0]);
    ENSURE(dc > 100.0 * e[0]);
    fmbt_csv_free(&comp);
  }
  fmbt_csv_free(&ref);
  fmbt_csv_free(&loose[0]);
  fmbt_csv_free(&loose[1]);
  for (int k = 0; k < 4; ++k) fmbt_csv_free(&c[k]);
}

int main(void) {
  convergence(4);
  convergence(15);
  return fmbt_finish("test_exact_convergence");
}
