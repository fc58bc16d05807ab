/* test_step3d.c — the stepping API with a spatial state (issue 34, item 5): the heavy top of
 * docs/spatial.md (tests/spatial/scenes/top.yaml, spinning at 24 and 44 rad/s, released).
 *
 * 1. fmb_init, fmb_advance to each output time, fmb_outputs, written through fmb_write_table,
 *    give the very bytes of fmb_run's CSV (what `flexmbd run` writes) and the same counters.
 * 2. The state: fmb_state_size is the DAE's [q, v, lambda, mu] size (7 + 7 coordinates and
 *    velocities for one rigid3d body, 3 + 3 rows of the ball joint); fmb_data_state's q is [r, p],
 *    the position equal to the outputs top.x, y, z and p / |p| to top.qw..qz, and q' = v (1e-6).
 * 3. fmb_data_set_state: a second data object set to the first's state at t = 0.25 s and advanced
 *    to 0.5 s follows the first (which never stopped) to the integration tolerance (a restart
 *    has no step history: 1e-6 at rtol 1e-10), and it is reproducible bit for bit; with the Euler
 *    parameters (and their rates) scaled by 2, a gauge nothing physical sees (docs/spatial.md),
 *    the outputs at 0.25 s are unchanged (1e-14) and the motion to 0.5 s is the same (1e-6);
 *    energy is conserved across the set (1e-7 J of 0.85 J). Misuse is refused, nothing changed. */
#include <math.h>
#include <stdlib.h>
#include <string.h>

#include "testlib.h"

static const char* const overrides[] = {
    "bodies.top.angular_velocity=[0, -24.04, 43.86]", "solver.t_end=0.5", "solver.output_step=0.01",
    "outputs=[top.x, top.y, top.z, top.qw, top.qx, top.qy, top.qz, top.wx, top.wy, top.wz, top.roll, top.pitch, "
    "top.yaw, pivot.reaction_z, energy.total]"};
enum { NOVER = sizeof overrides / sizeof overrides[0] };

static int col(const fmbModel* m, const char* name) {
  for (int i = 0; i < fmb_noutput(m); ++i)
    if (strcmp(fmb_output_name(m, i), name) == 0) return i;
  ENSURE(!"output found");
  return 0;
}

int main(void) {
  char scene[1024], out_run[1024], out_step[1024];
  fmbt_path("tests/spatial/scenes/top.yaml", scene, sizeof scene);
  fmbDiag diag;
  fmbModel* m = fmb_load(scene, overrides, NOVER, fmb_builtin_registry(), &diag);
  ENSURE(m != NULL);
  if (!m) return fmbt_finish("test_step3d");
  ENSURE(fmb_model_dimension(m) == 3);

  /* 1. stepping = fmb_run, byte for byte */
  fmbStats run_stats, step_stats;
  fmbRunOptions opt = {.csv_path = fmbt_out_path("top_run.csv", out_run, sizeof out_run), .quiet = 1};
  ENSURE(fmb_run(m, &opt, &run_stats, &diag) == 0);
  const int nout = fmb_noutput(m), ncol = nout + 1;
  const long nrow = fmb_row_count(m);
  double* table = calloc((size_t)nrow * (size_t)ncol, sizeof *table);
  const char** names = calloc((size_t)ncol, sizeof *names);
  names[0] = "t";
  for (int i = 0; i < nout; ++i) names[i + 1] = fmb_output_name(m, i);
  fmbData* a = fmb_data_new(m, &diag);
  ENSURE(a && fmb_init(m, a, &diag) == 0);
  const int ny = fmb_state_size(m);
  double *y25 = calloc((size_t)ny, sizeof *y25), *yp25 = calloc((size_t)ny, sizeof *yp25);
  double *out25 = calloc((size_t)nout, sizeof *out25), *out50 = calloc((size_t)nout, sizeof *out50);
  for (long k = 0; k < nrow; ++k) {
    if (k > 0) ENSURE(fmb_advance(m, a, fmb_row_time(m, k), &diag) == 0);
    table[k * ncol] = fmb_data_time(a);
    ENSURE(fmb_outputs(m, a, table + k * ncol + 1) == 0);
    if (fabs(fmb_data_time(a) - 0.25) < 1e-12) { /* the state half way, for 2. and 3. */
      ENSURE(fmb_data_state(a, y25, yp25) == 0);
      memcpy(out25, table + k * ncol + 1, sizeof(double) * (size_t)nout);
    }
  }
  memcpy(out50, table + (nrow - 1) * ncol + 1, sizeof(double) * (size_t)nout);
  fmb_data_stats(a, &step_stats);
  ENSURE(fmb_write_table(fmbt_out_path("top_step.csv", out_step, sizeof out_step), ncol, names, (int)nrow, table,
                         &diag) == 0);
  size_t len_run = 0, len_step = 0;
  char *bytes_run = fmbt_slurp(out_run, &len_run), *bytes_step = fmbt_slurp(out_step, &len_step);
  ENSURE(bytes_run && bytes_step && len_run == len_step && memcmp(bytes_run, bytes_step, len_run) == 0);
  ENSURE(run_stats.steps == step_stats.steps && run_stats.residuals == step_stats.residuals);
  printf("stepping: %ld rows, %zu bytes, the same as fmb_run's (%ld steps)\n", nrow, len_run, run_stats.steps);
  free(bytes_run);
  free(bytes_step);

  /* 2. the state's layout: q = [r, p], v = q' */
  ENSURE(ny == 7 + 7 + 3 + 0 || ny == 7 + 7 + 3 + 3); /* [q, v, lambda] (+ mu of the GGL form) */
  const double n2 = sqrt(y25[3] * y25[3] + y25[4] * y25[4] + y25[5] * y25[5] + y25[6] * y25[6]);
  const char* pose[7] = {"top.x", "top.y", "top.z", "top.qw", "top.qx", "top.qy", "top.qz"};
  for (int i = 0; i < 7; ++i) ENSURE_NEAR(i < 3 ? y25[i] : y25[i] / n2, out25[col(m, pose[i])], 1e-15);
  /* q' = v holds to the error test's tolerance (IDA's y' is its polynomial's derivative): 1.7e-7 seen */
  for (int i = 0; i < 7; ++i) ENSURE_NEAR(yp25[i], y25[7 + i], 1e-6 * (1.0 + fabs(y25[7 + i])));
  printf("state: %d values, |p| = %.15f at t = 0.25\n", ny, n2);

  /* 3. set the state: a second object from the first's state at 0.25 s */
  fmbData* b = fmb_data_new(m, &diag);
  ENSURE(b && fmb_init(m, b, &diag) == 0);
  ENSURE(fmb_data_set_state(m, b, 0.25, y25, yp25, &diag) == 0);
  ENSURE(fmb_data_time(b) == 0.25);
  double* got = calloc((size_t)nout, sizeof *got);
  double* again = calloc((size_t)nout, sizeof *again);
  ENSURE(fmb_outputs(m, b, got) == 0);
  for (int i = 0; i < nout; ++i) ENSURE(got[i] == out25[i] || strstr(fmb_output_name(m, i), "reaction"));
  ENSURE(fmb_advance(m, b, 0.5, &diag) == 0);
  ENSURE(fmb_outputs(m, b, got) == 0);
  double worst = 0.0;
  for (int i = 0; i < nout; ++i)
    if (!strstr(fmb_output_name(m, i), "reaction")) worst = fmax(worst, fabs(got[i] - out50[i]));
  ENSURE(worst < 1e-6);
  ENSURE_NEAR(got[col(m, "energy.total")], out25[col(m, "energy.total")], 1e-7);
  printf("set state at 0.25, advanced to 0.5: largest difference from the run that went on %.3g\n", worst);
  /* reproducible: the same set and advance again */
  ENSURE(fmb_data_set_state(m, b, 0.25, y25, yp25, &diag) == 0 && fmb_advance(m, b, 0.5, &diag) == 0);
  ENSURE(fmb_outputs(m, b, again) == 0);
  ENSURE(memcmp(got, again, sizeof(double) * (size_t)nout) == 0);
  /* the gauge: p and p' scaled by 2 are the same pose and motion */
  double *ys = malloc(sizeof(double) * (size_t)ny), *yps = malloc(sizeof(double) * (size_t)ny);
  memcpy(ys, y25, sizeof(double) * (size_t)ny);
  memcpy(yps, yp25, sizeof(double) * (size_t)ny);
  for (int i = 3; i < 7; ++i) ys[i] *= 2.0, ys[7 + i] *= 2.0, yps[i] *= 2.0;
  ENSURE(fmb_data_set_state(m, b, 0.25, ys, yps, &diag) == 0);
  ENSURE(fmb_outputs(m, b, again) == 0);
  for (int i = 0; i < nout; ++i)
    if (!strstr(fmb_output_name(m, i), "reaction") && strcmp(fmb_output_name(m, i), "energy.total") != 0)
      ENSURE_NEAR(again[i], out25[i], 1e-14 * (1.0 + fabs(out25[i])));
  ENSURE_NEAR(again[col(m, "energy.total")], out25[col(m, "energy.total")], 1e-13);
  ENSURE(fmb_advance(m, b, 0.5, &diag) == 0 && fmb_outputs(m, b, again) == 0);
  double worst_gauge = 0.0;
  for (int i = 0; i < nout; ++i)
    if (!strstr(fmb_output_name(m, i), "reaction")) worst_gauge = fmax(worst_gauge, fabs(again[i] - out50[i]));
  ENSURE(worst_gauge < 1e-6);
  printf("Euler parameters scaled by 2: the same motion to %.3g\n", worst_gauge);
  /* misuse: refused, nothing changed */
  const double t_before = fmb_data_time(b);
  ys[2] = NAN;
  ENSURE(fmb_data_set_state(m, b, 0.25, ys, yps, &diag) == FMB_EXIT_BAD_INPUT && strstr(diag.msg, "not finite"));
  ENSURE(fmb_data_set_state(m, b, 0.75, y25, yp25, &diag) == FMB_EXIT_BAD_INPUT && strstr(diag.msg, "t_end"));
  ENSURE(fmb_data_set_state(m, b, 0.25, NULL, yp25, &diag) == FMB_EXIT_BAD_INPUT);
  ENSURE(fmb_data_set_state(m, NULL, 0.25, y25, yp25, &diag) == FMB_EXIT_BAD_INPUT);
  ENSURE(fmb_data_time(b) == t_before);
  fmbData* fresh = fmb_data_new(m, &diag);
  ENSURE(fmb_data_set_state(m, fresh, 0.25, y25, yp25, &diag) == FMB_EXIT_BAD_INPUT && strstr(diag.msg, "fmb_init"));
  fmb_data_free(fresh);

  fmb_data_free(a);
  fmb_data_free(b);
  free(table), free(names), free(y25), free(yp25), free(out25), free(out50), free(got), free(again), free(ys),
      free(yps);
  fmb_free(m);
  return fmbt_finish("test_step3d");
}
