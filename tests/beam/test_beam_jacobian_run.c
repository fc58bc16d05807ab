/*
 * test_beam_jacobian_run.c — a whole run with the beam's analytic Jacobian against the same run
 * with the engine's finite differences (docs/beam.md, "Jacobian").
 *
 * The omega0 = 15 spin-up (scenes/paper/spinup_w15.yaml: 16 elements, complete, dense assembly)
 * to t = 5 s, and the same with `assembly: banded`. `jacobian: differences` (--set bodies.beam.jacobian=differences)
 * makes bodies/beam.c hand the engine its ops without `jacobian` and `pattern_jacobian` (read
 * when the scene is parsed, see beam_variant), which is how the code ran before them.
 * Both runs solve the same DAE to the scene's rtol 1e-6, so they may differ only by integration
 * error: the tip deflection of each is compared with a run at rtol 1e-10 (its error e_fd,
 * e_analytic), and the two must agree to within 2 (e_fd + e_analytic). A Jacobian that is not
 * the residual's costs Newton iterations before it costs accuracy, so the analytic run must also
 * need no more Newton iterations per step than the differenced one, with 25 % slack (these are
 * counts, deterministic on one build; times are in bench/beam_jacobian.sh).
 */
#include <stdio.h>
#include <stdlib.h>

#include "testlib.h"

/* max |a - b| over the tip_v column */
static double tip_diff(const fmbtCsv* a, const fmbtCsv* b) {
  const double* x = fmbt_col(a, "beam.tip_v");
  const double* y = fmbt_col(b, "beam.tip_v");
  ENSURE(a->nrow == b->nrow && a->nrow > 0);
  if (!x || !y || a->nrow != b->nrow) return INFINITY;
  double d = 0.0;
  for (int i = 0; i < a->nrow; ++i) d = fmax(d, fabs(x[i] - y[i]));
  return d;
}

static void compare(const char* assembly) {
  char as[64], name[3][64];
  snprintf(as, sizeof as, "bodies.beam.assembly=%s", assembly);
  const char* const list[] = {"solver.t_end=5", as, "solver.rtol=1e-10", "solver.atol=1e-12"};
  const char* const fd_list[] = {"solver.t_end=5", as, "bodies.beam.jacobian=differences"};
  fmbtCsv ana, fd, ref;
  fmbStats sa, sf, sr;
  snprintf(name[0], sizeof name[0], "jacobian_run_%s_analytic.csv", assembly);
  snprintf(name[1], sizeof name[1], "jacobian_run_%s_fd.csv", assembly);
  snprintf(name[2], sizeof name[2], "jacobian_run_%s_ref.csv", assembly);
  ENSURE(fmbt_run_read("scenes/paper/spinup_w15.yaml", list, 2, name[0], &ana, &sa) == 0);
  ENSURE(fmbt_run_read("scenes/paper/spinup_w15.yaml", list, 4, name[2], &ref, &sr) == 0);
  ENSURE(fmbt_run_read("scenes/paper/spinup_w15.yaml", fd_list, 3, name[1], &fd, &sf) == 0);
  const double d = tip_diff(&ana, &fd), ea = tip_diff(&ana, &ref), ef = tip_diff(&fd, &ref);
  const double* tip = fmbt_col(&ref, "beam.tip_v");
  double peak = 0.0;
  for (int i = 0; tip && i < ref.nrow; ++i) peak = fmax(peak, fabs(tip[i]));
  const double ia = (double)sa.newton_iters / (double)sa.steps, ifd = (double)sf.newton_iters / (double)sf.steps;
  printf("%-6s: tip_v analytic vs FD %.2e m (peak %.3f m); error vs rtol 1e-10: analytic %.2e, FD %.2e m\n", assembly,
         d, peak, ea, ef);
  printf("        steps %ld / %ld, Newton iterations per step %.3f / %.3f, Jacobians %ld / %ld (analytic / FD)\n",
         sa.steps, sf.steps, ia, ifd, sa.jacobians, sf.jacobians);
  ENSURE(peak > 0.01); /* the beam did deflect */
  ENSURE(d <= 2.0 * (ea + ef));
  ENSURE(ia <= 1.25 * ifd);
  fmbt_csv_free(&ana);
  fmbt_csv_free(&fd);
  fmbt_csv_free(&ref);
}

int main(void) {
  compare("dense");
  compare("banded");
  return fmbt_finish("test_beam_jacobian_run");
}
