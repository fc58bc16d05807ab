/* pd_rotor.c — a program that embeds flexmbd and closes a control loop around it (issue 24): a
 * PD controller turns a flexible rotor (rotor_motor.yaml: a hub with a beam blade) to a set point.
 * Every control step h it reads the hub's angle and rate (fmb_outputs), sets the motor torque
 *     tau = -kp (theta - set_point) - kd omega                                  (fmb_set_input)
 * and advances the rotor by h (fmb_advance); the torque is held over the step (a zero-order hold,
 * as a digital controller applies it).
 *
 * The check: the same law applied continuously is a rotational spring-damper (rotor_spring.yaml,
 * joint type torsion, with kp, kd and the set point put in by --set overrides). A held torque lags
 * the continuous one by about h/2, so the two runs differ by O(h), not by the integration
 * tolerance; what must hold is that this difference is the sampling's and nothing else:
 *   1. it halves when h halves (first order: ratio e(h) / e(h/2) between 1.7 and 2.3), and
 *   2. Richardson's extrapolation 2 x(h/2) - x(h), whose error is O(h^2), agrees with the
 *      continuous run ten times better than x(h/2) does.
 * A controller that read a stale angle, applied the torque a step late or not at all, or an
 * engine that lost the input at a restart fails one of them.
 *
 *   pd_rotor rotor_motor.yaml rotor_spring.yaml [h]        (h: control step in s, default 2e-3) */
#include <flexmbd.h>
#include <math.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>

static const double kp = 2.0, kd = 1.0, set_point = 1.0; /* N m/rad, N m s/rad, rad */

/* the hub's angle, its rate and the blade's tip deflection at every output time */
typedef struct {
  int n;
  double t[256], theta[256], omega[256], tip[256];
} Track;

static int column(const fmbModel* m, const char* name) {
  for (int i = 0; i < fmb_noutput(m); ++i)
    if (strcmp(fmb_output_name(m, i), name) == 0) return i;
  fprintf(stderr, "pd_rotor: the scene has no output %s\n", name);
  exit(2);
}

static void record(const fmbModel* m, fmbData* d, Track* tr) {
  double out[16];
  if (fmb_noutput(m) > 16 || fmb_outputs(m, d, out) || tr->n >= 256) {
    fprintf(stderr, "pd_rotor: outputs not available at t = %g\n", fmb_data_time(d));
    exit(3);
  }
  tr->t[tr->n] = fmb_data_time(d);
  tr->theta[tr->n] = out[column(m, "hub.theta")];
  tr->omega[tr->n] = out[column(m, "hub.omega")];
  tr->tip[tr->n] = out[column(m, "blade.tip_v")];
  tr->n++;
}

static void fail(const char* what, const fmbDiag* diag) {
  fprintf(stderr, "pd_rotor: %s: %s:%d:%d: %s\n", what, diag->file, diag->line, diag->col, diag->msg);
  exit(diag->code ? diag->code : 1);
}

/* run a model; with h > 0 under the sampled controller (motor input), else as it is */
static void simulate(const fmbModel* m, double h, Track* tr) {
  fmbDiag diag;
  fmbSolverInfo si;
  fmb_model_solver(m, &si);
  fmbData* d = fmb_data_new(m, &diag);
  if (!d || fmb_init(m, d, &diag)) fail("init", &diag);
  tr->n = 0;
  record(m, d, tr);
  const long nout = lround((si.t_end - si.t0) / si.output_step);
  const long per_output = h > 0.0 ? lround(si.output_step / h) : 1;
  for (long k = 1; k <= nout; ++k) {
    for (long j = 1; j <= per_output; ++j) {
      if (h > 0.0) {
        double out[16];
        if (fmb_outputs(m, d, out)) fail("outputs", &diag);
        const double tau = -kp * (out[column(m, "hub.theta")] - set_point) - kd * out[column(m, "hub.omega")];
        if (fmb_set_input(m, d, "motor", tau)) {
          fprintf(stderr, "pd_rotor: the scene has no input 'motor'\n");
          exit(2);
        }
      }
      /* sample times counted in steps, so that every output time is met exactly */
      const double t = si.t0 + ((double)(k - 1) + (double)j / (double)per_output) * si.output_step;
      if (fmb_advance(m, d, k == nout && j == per_output ? si.t_end : t, &diag)) fail("advance", &diag);
    }
    record(m, d, tr);
  }
  fmbStats st;
  fmb_data_stats(d, &st);
  printf("%s: %ld steps, %.2f s CPU\n", h > 0.0 ? "controller" : "spring-damper", st.steps, st.cpu_s);
  fmb_data_free(d);
}

static double worst(int n, const double* a, const double* b) {
  double w = 0.0;
  for (int i = 0; i < n; ++i) w = fmax(w, fabs(a[i] - b[i]));
  return w;
}

int main(int argc, char** argv) {
  if (argc < 3) {
    fprintf(stderr, "usage: pd_rotor rotor_motor.yaml rotor_spring.yaml [control_step]\n");
    return 2;
  }
  const double h = argc > 3 ? atof(argv[3]) : 2e-3;
  fmbRegistry* reg = fmb_registry_new();
  fmbDiag diag;
  if (!reg || fmb_registry_add(reg, fmb_builtin_plugin(), "built-in", &diag)) fail("registry", &diag);
  char kp_set[64], kd_set[64], sp_set[64];
  snprintf(kp_set, sizeof kp_set, "joints.pd.stiffness=%.17g", kp);
  snprintf(kd_set, sizeof kd_set, "joints.pd.damping=%.17g", kd);
  snprintf(sp_set, sizeof sp_set, "joints.pd.angle0=%.17g", set_point);
  const char* sets[] = {kp_set, kd_set, sp_set};
  fmbModel* motor = fmb_load(argv[1], NULL, 0, reg, &diag);
  if (!motor) fail(argv[1], &diag);
  fmbModel* spring = fmb_load(argv[2], sets, 3, reg, &diag);
  if (!spring) fail(argv[2], &diag);

  static Track cont, coarse, fine;
  simulate(spring, 0.0, &cont);
  simulate(motor, h, &coarse);
  simulate(motor, 0.5 * h, &fine);
  if (cont.n != coarse.n || cont.n != fine.n) return 3;

  /* hub angle and blade tip: the sampled runs against the continuous one */
  static double rich_theta[256], rich_tip[256];
  for (int i = 0; i < cont.n; ++i) {
    rich_theta[i] = 2.0 * fine.theta[i] - coarse.theta[i];
    rich_tip[i] = 2.0 * fine.tip[i] - coarse.tip[i];
  }
  const double e1 = worst(cont.n, coarse.theta, cont.theta), e2 = worst(cont.n, fine.theta, cont.theta);
  const double er = worst(cont.n, rich_theta, cont.theta);
  const double t1 = worst(cont.n, coarse.tip, cont.tip), t2 = worst(cont.n, fine.tip, cont.tip);
  const double tr = worst(cont.n, rich_tip, cont.tip);
  printf("hub angle:  h = %g: %.3g rad, h/2: %.3g rad (ratio %.2f), extrapolated: %.3g rad\n", h, e1, e2, e1 / e2, er);
  printf("blade tip:  h = %g: %.3g m,   h/2: %.3g m   (ratio %.2f), extrapolated: %.3g m\n", h, t1, t2, t1 / t2, tr);
  printf("final angle %.6f rad (set point %g), continuous %.6f rad\n", fine.theta[fine.n - 1], set_point,
         cont.theta[cont.n - 1]);
  const int first_order = e1 / e2 > 1.7 && e1 / e2 < 2.3 && t1 / t2 > 1.7 && t1 / t2 < 2.3;
  const int extrapolates = er < 0.1 * e2 && tr < 0.1 * t2;
  if (first_order && extrapolates) {
    printf("the controller agrees with the spring-damper: the difference is the sampling's (first order in h)\n");
  } else {
    printf("FAIL: %s\n", !first_order ? "the difference does not halve with h" : "the extrapolation does not converge");
  }
  fmb_free(motor);
  fmb_free(spring);
  fmb_registry_free(reg);
  return first_order && extrapolates ? 0 : 1;
}
