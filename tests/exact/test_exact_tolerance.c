/*
 * test_exact_tolerance.c — absolute tolerances in metres for the exact beam (fmbBodyType.
 * length_scale, engine/tolerance.c): geometric similarity.
 *
 * The paper's omega0 = 15 spin-up beam scaled by s (length x s, area x s^2, second moment x s^4,
 * density and modulus kept, so times scale by s: ramp time and run x s, omega0 / s) is the same
 * dimensionless problem: its tip deflection is s times the original's at s times the time. Run at
 * the same rtol and atol = rtol x s metres, an integrator that measures every coordinate in
 * metres makes the same relative tip error at every s. The exact beam's slopes, root stretch and
 * frame angle are dimensionless; without length_scale atol would hold them to an absolute value
 * that means L times more tip motion at s = 10 than at s = 1.
 *
 * For s = 0.1, 1, 10: the relative tip error max |tip_v(s t)/s - ref(t)| / max |ref| against a
 * reference at rtol 1e-10 (s = 1), rtol 1e-6, atol 1e-6 x s m. With the op the three errors agree
 * within 25 % (measured 5.0e-3, 4.6e-3, 4.8e-3 at s = 0.1, 1, 10, a spread of 1.08x: not exactly
 * equal, since the velocities, whose size in m/s does not change with s, take atol / scale too).
 * The same runs with a copy of the exact table without the op: 2.2e-3, 5.9e-3, 7.1e-3, a spread
 * of 3.2x, checked to be over 1.5x so that the test sees what the op changes. The runs name IDA,
 * on which the figures were measured: under radau5 (the beams' default then; radau9 now), rtol 1e-6 errs below the
 * 1e-4 this test needs to see the tolerance decide.
 */
#include <string.h>

#include "testlib.h"

extern const fmbBodyType fmb_body_beam_exact, fmb_body_ground;
extern const fmbJointType fmb_joint_revolute, fmb_joint_drive;

static void write_scene(double s, const char* path) {
  FILE* f = fopen(path, "w");
  ENSURE(f != NULL);
  if (!f) return;
  fprintf(f,
          "solver: {t_end: %.17g, rtol: 1.0e-6, atol: 1.0e-8, output_step: %.17g, error_control: positions, "
          "integrator: ida}\n"
          "bodies:\n"
          "  - {name: beam, type: beam, model: exact, elements: 16, length: %.17g, density: 2767.0, area: %.17g,\n"
          "     second_moment: %.17g, youngs_modulus: 68.95e9}\n"
          "joints:\n"
          "  - {name: pin, type: revolute, body1: ground, body2: beam, point1: [0, 0], point2: [0, 0]}\n"
          "  - {name: spin, type: drive, joint: pin, profile: spinup, omega0: %.17g, ramp_time: %.17g}\n"
          "outputs: [beam.tip_v]\n",
          20.0 * s, 0.01 * s, 1.8 * s, 2.5e-4 * s * s, 1.302e-10 * s * s * s * s, 15.0 / s, 15.0 * s);
  fclose(f);
}

/* run the scene for scale s with the registry reg at rtol and atol = atol_m x s; tip_v / s read
   back into c */
static void run(const fmbRegistry* reg, double s, double rtol, double atol_m, const char* tag, fmbtCsv* c) {
  char scene[1024], out[1024], name[64], set[2][64];
  snprintf(name, sizeof name, "exact_similar_%g.yaml", s);
  fmbt_out_path(name, scene, sizeof scene);
  write_scene(s, scene);
  snprintf(name, sizeof name, "exact_similar_%g_%s.csv", s, tag);
  fmbt_out_path(name, out, sizeof out);
  snprintf(set[0], sizeof set[0], "solver.rtol=%.17g", rtol);
  snprintf(set[1], sizeof set[1], "solver.atol=%.17g", atol_m * s);
  const char* ov[] = {set[0], set[1]};
  fmbDiag diag;
  fmbStats st;
  fmbModel* m = fmb_load(scene, ov, 2, reg, &diag);
  ENSURE(m != NULL);
  if (!m) {
    fprintf(stderr, "%s:%d:%d: %s\n", diag.file, diag.line, diag.col, diag.msg);
    memset(c, 0, sizeof *c);
    return;
  }
  fmbRunOptions opt = {.csv_path = out, .quiet = 1};
  ENSURE(fmb_run(m, &opt, &st, &diag) == 0);
  fmb_free(m);
  ENSURE(fmbt_csv_read(out, c) == 0);
  double* tv = (double*)fmbt_col(c, "beam.tip_v");
  for (int i = 0; tv && i < c->nrow; ++i) tv[i] /= s;
  printf("  s = %-4g %-9s rtol %.0e atol %.1e m: %ld steps\n", s, tag, rtol, atol_m * s, st.steps);
}

static double relative_error(const fmbtCsv* c, const fmbtCsv* ref) {
  const double *x = fmbt_col(c, "beam.tip_v"), *r = fmbt_col(ref, "beam.tip_v");
  if (!x || !r || c->nrow != ref->nrow) return INFINITY;
  double e = 0.0, peak = 0.0;
  for (int i = 0; i < c->nrow; ++i) e = fmax(e, fabs(x[i] - r[i])), peak = fmax(peak, fabs(r[i]));
  return e / peak;
}

int main(void) {
  /* the exact table as type beam, once as shipped and once without length_scale */
  fmbBodyType unscaled = fmb_body_beam_exact;
  unscaled.length_scale = NULL;
  const fmbJointType* joints[] = {&fmb_joint_revolute, &fmb_joint_drive, NULL};
  const fmbBodyType* with_op[] = {&fmb_body_ground, &fmb_body_beam_exact, NULL};
  const fmbBodyType* without_op[] = {&fmb_body_ground, &unscaled, NULL};
  const fmbPlugin plugin[2] = {
      {.abi = FMB_ABI_VERSION, .name = "exact-scaled", .version = "1", .bodies = with_op, .joints = joints},
      {.abi = FMB_ABI_VERSION, .name = "exact-unscaled", .version = "1", .bodies = without_op, .joints = joints}};
  fmbRegistry* reg[2] = {fmb_registry_new(), fmb_registry_new()};
  fmbDiag diag;
  for (int k = 0; k < 2; ++k) ENSURE(reg[k] && fmb_registry_add(reg[k], &plugin[k], "test", &diag) == 0);

  fmbtCsv ref;
  run(reg[0], 1.0, 1e-10, 1e-12, "reference", &ref);
  const double scale[3] = {0.1, 1.0, 10.0};
  double err[2][3];
  for (int k = 0; k < 2; ++k)
    for (int i = 0; i < 3; ++i) {
      fmbtCsv c;
      run(reg[k], scale[i], 1e-6, 1e-6, k ? "no op" : "with op", &c);
      err[k][i] = relative_error(&c, &ref);
      fmbt_csv_free(&c);
    }
  double spread[2];
  for (int k = 0; k < 2; ++k) {
    const double lo = fmin(err[k][0], fmin(err[k][1], err[k][2])), hi = fmax(err[k][0], fmax(err[k][1], err[k][2]));
    spread[k] = hi / lo;
    printf("relative tip error %s length_scale at s = 0.1, 1, 10: %.3e %.3e %.3e (spread %.2fx)\n",
           k ? "without" : "with", err[k][0], err[k][1], err[k][2], spread[k]);
  }
  for (int i = 0; i < 3; ++i) ENSURE(err[0][i] > 1e-4 && err[0][i] < 2e-2); /* the tolerance is what decides */
  ENSURE(spread[0] < 1.25);
  ENSURE(spread[1] > 1.5);
  fmbt_csv_free(&ref);
  fmb_registry_free(reg[0]);
  fmb_registry_free(reg[1]);
  return fmbt_finish("test_exact_tolerance");
}
