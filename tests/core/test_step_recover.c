/* test_step_recover.c — the stepping API after a failure, and inputs a scene would refuse
 * (issue 36: "after a non-finite solver failure the stepping API's state is NaN, not the last good
 * one that flexmbd.h and docs/api.md promise; later advances cannot recover without fmb_init";
 * "fmb_set_input accepts a drive angle of 1e300 that a scene refuses").
 *
 * 1. tests/core/scenes/input_load.yaml (a free block, m = 2 kg, pushed by s [1 N, 0]): s = 0.5 to
 *    t = 0.5, then s = 1e300 (a scene accepts such a load: it is finite), whose advance fails on
 *    values that are not finite. The state must then be the last good one: finite, the outputs
 *    finite (fmb_outputs 0), at t = 0.5 with the very values it had there. With s set back to 0.5
 *    the next advance must go on to t = 1 and meet the closed form x = s F t^2 / (2 m) = 0.125 m,
 *    vx = 0.25 m/s, and energy.balance = 0 (the load's work integrals survived the failure), to
 *    the run's tolerance. With IDA (the default, which left NaN behind) and radau5.
 * 2. tests/core/scenes/input_drive.yaml (a pendulum whose pin angle a drive prescribes): the angles
 *    1e300, -1e300 and 1e6 rad are refused (FMB_EXIT_BAD_INPUT, the reason said, the input keeping
 *    its value), as the same scene with `value:` 1e6 is refused at init; 0.3 rad is taken; the run
 *    after the refusals has the bytes of a run never offered them. */
#include <string.h>

#include "testlib.h"

static int output_index(const fmbModel* m, const char* name) {
  for (int i = 0; i < fmb_noutput(m); ++i)
    if (strcmp(fmb_output_name(m, i), name) == 0) return i;
  return -1;
}

static int all_finite(const double* v, int n) {
  for (int i = 0; i < n; ++i)
    if (!isfinite(v[i])) return 0;
  return 1;
}

typedef struct {
  int count;
  char last[700];
} Heard;

static void hear(void* user, const char* message) {
  Heard* h = user;
  h->count++;
  snprintf(h->last, sizeof h->last, "%s", message);
}

static void recover(const char* integrator) {
  char path[1024], set[64];
  snprintf(set, sizeof set, "solver.integrator=%s", integrator);
  const char* sets[] = {set};
  fmbDiag diag;
  fmbModel* m = fmb_load(fmbt_path("tests/core/scenes/input_load.yaml", path, sizeof path), sets, 1,
                         fmb_builtin_registry(), &diag);
  ENSURE(m != NULL);
  if (!m) return;
  fmbData* d = fmb_data_new(m, &diag);
  Heard heard = {0, ""};
  fmb_data_set_warn(d, hear, &heard);
  const int n = fmb_noutput(m), ix = output_index(m, "block.x"), ivx = output_index(m, "block.vx"),
            ib = output_index(m, "energy.balance");
  ENSURE(n <= 16 && ix >= 0 && ivx >= 0 && ib >= 0);
  double y_good[64], y[64], yp[64], out_good[16], out[16];
  ENSURE(fmb_init(m, d, &diag) == 0);
  ENSURE(fmb_set_input(m, d, "push", 0.5) == 0);
  ENSURE(fmb_advance(m, d, 0.5, &diag) == 0);
  ENSURE(fmb_data_state(d, y_good, NULL) == 0 && fmb_outputs(m, d, out_good) == 0);

  ENSURE(fmb_set_input(m, d, "push", 1e300) == 0); /* finite: a scene takes it too */
  const int rc = fmb_advance(m, d, 1.0, &diag);
  ENSURE(rc == FMB_EXIT_SOLVER);
  const double t_failed = fmb_data_time(d);
  ENSURE(fmb_data_state(d, y, yp) == 0);
  const int orc = fmb_outputs(m, d, out);
  ENSURE(isfinite(t_failed) && t_failed >= 0.5 && t_failed <= 1.0);
  ENSURE(all_finite(y, 9) && all_finite(yp, 9)); /* q, v of the block (3 each) and more: all finite */
  ENSURE(orc == 0 && all_finite(out, n));
  if (t_failed == 0.5)
    ENSURE(memcmp(y, y_good, sizeof(double) * 6) == 0 && memcmp(out, out_good, sizeof(double) * (size_t)n) == 0);
  printf("%-7s s = 1e300: exit %d at t = %g (%s); state after: t = %g, x = %.12g, outputs %s\n", integrator, rc,
         t_failed, strncmp(diag.msg, "solver failed", 13) == 0 ? "solver failed" : diag.msg, fmb_data_time(d), out[ix],
         orc == 0 ? "finite" : "NOT finite");

  ENSURE(fmb_set_input(m, d, "push", 0.5) == 0);
  const int rc2 = fmb_advance(m, d, 1.0, &diag);
  ENSURE(rc2 == 0);
  ENSURE(fmb_outputs(m, d, out) == 0);
  /* x'' = s F / m = 0.25 m/s^2 from rest: x(1) = 0.125 m, vx(1) = 0.25 m/s; rtol 1e-9 */
  ENSURE_NEAR(out[ix], 0.125, 1e-7);
  ENSURE_NEAR(out[ivx], 0.25, 1e-7);
  ENSURE_NEAR(out[ib], 0.0, 1e-7);
  fmbStats st;
  ENSURE(fmb_data_stats(d, &st) == 0 && st.status_ok);
  printf("%-7s after s set back: exit %d, t = %g, x = %.12g (0.125), vx = %.12g (0.25), energy.balance = %.3g\n",
         integrator, rc2, fmb_data_time(d), out[ix], out[ivx], out[ib]);
  fmb_data_free(d);
  fmb_free(m);
}

/* the drive's angle run through `angles` (refused ones skipped by the data), outputs at 0.2 s */
static int drive_run(const fmbModel* m, const double* angles, int n, int* refused, double* out, Heard* heard) {
  fmbDiag diag;
  fmbData* d = fmb_data_new(m, &diag);
  fmb_data_set_warn(d, hear, heard);
  int rc = fmb_init(m, d, &diag);
  *refused = 0;
  for (int k = 0; !rc && k < n; ++k) {
    double before = NAN, after = NAN;
    fmb_get_input(m, d, "servo", &before);
    const int s = fmb_set_input(m, d, "servo", angles[k]);
    fmb_get_input(m, d, "servo", &after);
    if (s) {
      ENSURE(s == FMB_EXIT_BAD_INPUT && after == before); /* refused: the input keeps its value */
      ++*refused;
    }
  }
  if (!rc) rc = fmb_advance(m, d, 0.2, &diag);
  if (!rc) rc = fmb_outputs(m, d, out);
  fmb_data_free(d);
  return rc;
}

static void drive_values(void) {
  char path[1024];
  fmbDiag diag;
  fmbt_path("tests/core/scenes/input_drive.yaml", path, sizeof path);
  fmbModel* m = fmb_load(path, NULL, 0, fmb_builtin_registry(), &diag);
  ENSURE(m != NULL);
  if (!m) return;
  const double offered[] = {1e300, 0.3, -1e300, 1e6};
  const double taken[] = {0.3};
  double a[16], b[16];
  int refused_a = 0, refused_b = 0;
  Heard heard = {0, ""};
  ENSURE(drive_run(m, offered, 4, &refused_a, a, &heard) == 0);
  ENSURE(refused_a == 3 && strstr(heard.last, "refused") && strstr(heard.last, "servo"));
  printf("drive angle 1e300, -1e300, 1e6 rad: %d of 3 refused (%s)\n", refused_a, heard.last);
  Heard quiet = {0, ""};
  ENSURE(drive_run(m, taken, 1, &refused_b, b, &quiet) == 0 && refused_b == 0);
  ENSURE(memcmp(a, b, sizeof(double) * (size_t)fmb_noutput(m)) == 0);
  const int itheta = output_index(m, "bar.theta");
  ENSURE(itheta >= 0 && fabs(a[itheta] - 0.3) < 1e-8);
  printf("after the refusals: the bytes of a run given 0.3 rad alone (bar.theta = %.12g)\n",
         itheta >= 0 ? a[itheta] : NAN);
  fmb_free(m);
  /* the scene's own rule: `value: 1e6` for the same drive is refused where the run starts */
  const char* big[] = {"joints.servo.value=1e6"};
  m = fmb_load(path, big, 1, fmb_builtin_registry(), &diag);
  int rc = m ? FMB_EXIT_SOLVER : diag.code;
  if (m) {
    fmbData* d = fmb_data_new(m, &diag);
    rc = fmb_init(m, d, &diag);
    fmb_data_free(d);
  }
  ENSURE(rc == FMB_EXIT_BAD_INPUT);
  printf("the scene with value: 1e6: exit %d: %s\n", rc, diag.msg);
  fmb_free(m);
}

int main(void) {
  fmb_set_warn(NULL, NULL);
  recover("ida");
  recover("radau5");
  drive_values();
  return fmbt_finish("test_step_recover");
}
