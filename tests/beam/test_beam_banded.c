/*
 * test_beam_banded.c — the banded assembly (coupling sums as auxiliary unknowns, `assembly:
 * banded`) against the dense one it replaces, as the landed code (0a88803) computed it before the
 * change: its CSVs are stored in tests/beam/data/ (README there says how they were made).
 *
 * The omega0 = 15 spin-up's first 3 s (tip deflection 0.09 m), all three models, 16..128
 * elements, rtol 1e-8: tip_v, tip_u and the total energy agree to 5e-6 of their range. That is
 * the integration error of either run (each is 1e-6..4e-6 from a run at rtol 1e-11), and 200x
 * below what a change of physics moves (FOAC against complete: 1e-3..2e-3). At rtol 1e-11 the two
 * assemblies agree to 5e-8 (measured 1e-8): the same equations, integrated differently.
 */
#include <stdio.h>

#include "testlib.h"

/* max over the rows of |a - b| over max |b| */
static double rel_diff(const fmbtCsv* a, const fmbtCsv* b, const char* col) {
  const double* x = fmbt_col(a, col);
  const double* y = fmbt_col(b, col);
  ENSURE(a->nrow == b->nrow);
  if (!x || !y || a->nrow != b->nrow) return INFINITY;
  double d = 0.0, s = 0.0;
  for (int i = 0; i < a->nrow; ++i) {
    d = fmax(d, fabs(x[i] - y[i]));
    s = fmax(s, fabs(y[i]));
  }
  return d / s;
}

static void compare(const char* model, int n, const char* rtol, const char* atol, const char* ref, double tol) {
  char ov[6][64], name[128], path[1024];
  snprintf(ov[0], sizeof ov[0], "bodies.beam.model=%s", model);
  snprintf(ov[1], sizeof ov[1], "bodies.beam.elements=%d", n);
  snprintf(ov[2], sizeof ov[2], "solver.rtol=%s", rtol);
  snprintf(ov[3], sizeof ov[3], "solver.atol=%s", atol);
  snprintf(ov[4], sizeof ov[4], "solver.t_end=3");
  snprintf(ov[5], sizeof ov[5], "solver.output_step=0.05");
  /* the stored references were made with the scene's former full error control */
  const char* const list[] = {
      ov[0], ov[1], ov[2], ov[3], ov[4], ov[5], "bodies.beam.assembly=banded", "solver.error_control=full"};
  snprintf(name, sizeof name, "banded_%s_%d_%s.csv", model, n, rtol);
  fmbtCsv run, old;
  fmbStats st;
  ENSURE(fmbt_run_read("scenes/paper/spinup_w15.yaml", list, 8, name, &run, &st) == 0);
  ENSURE(fmbt_csv_read(fmbt_path(ref, path, sizeof path), &old) == 0);
  const char* cols[] = {"beam.tip_v", "beam.tip_u", "energy.total"};
  printf("%-8s %3d elements rtol %-5s:", model, n, rtol);
  for (int k = 0; k < 3; ++k) {
    const double d = rel_diff(&run, &old, cols[k]);
    printf(" %s %.2e", cols[k], d);
    ENSURE(d <= tol);
  }
  printf("  (%ld steps, %.3f s)\n", st.steps, st.cpu_s);
  fmbt_csv_free(&run);
  fmbt_csv_free(&old);
}

int main(void) {
  const char* models[] = {"complete", "foac", "zoac"};
  const int ns[] = {16, 32, 64, 128};
  char ref[128];
  for (int m = 0; m < 3; ++m)
    for (int k = 0; k < 4; ++k) {
      snprintf(ref, sizeof ref, "tests/beam/data/dense_%s_%d.csv", models[m], ns[k]);
      compare(models[m], ns[k], "1e-8", "1e-10", ref, 5e-6);
    }
  compare("complete", 16, "1e-11", "1e-13", "tests/beam/data/dense_complete_16_rtol1e-11.csv", 5e-8);
  return fmbt_finish("test_beam_banded");
}
