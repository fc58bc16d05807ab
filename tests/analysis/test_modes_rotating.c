/*
 * test_modes_rotating.c — modes about the steady rotation of a cantilever on a hub of radius 0,
 * in-plane, against the continuum (formulation note §8): with lambda = Omega sqrt(rho A L^4/EI)
 * and mu = omega sqrt(rho A L^4/EI), the in-plane first frequency is mu_c^2 = mu_f1^2 - lambda^2
 * with the flapwise (Southwell-type) mu_f1(lambda) = 3.681646814, 4.137319573, 5.585001421,
 * 9.256837601, 13.17015049 at lambda = 1, 2, 4, 8, 12. Complete and FOAC within 0.05 % (16
 * elements; measured below 3.5e-5); ZOAC has no stiffening: omega^2 = omega1^2 - Omega^2 with its
 * own omega1 at rest, and above omega1 the mode diverges (reported as frequency -sqrt(Omega^2 -
 * omega1^2), damping ratio -1). Also the steady state itself: the axial tip stretch
 * rho Omega^2 L^3 / (3E) (1.755e-5 m at 15 rad/s), and the paper's spin-up scene read at t = 20 s.
 * A centrifugal pendulum (a point mass on a link l pinned to an arm at radius R, turning at Omega)
 * swings at Omega sqrt(R m l / (I + m l^2)) about its radial steady state: its frame origin moves
 * freely, so this checks the rotating-frame terms of the linearization (without them: 18 % off).
 */
#include "analysis.h"

int main(void) {
  const double scale = seed_omega_scale();
  const double lambda[5] = {1, 2, 4, 8, 12};
  const double mu_f[5] = {3.681646814, 4.137319573, 5.585001421, 9.256837601, 13.17015049};
  const char* models[2] = {"complete", "foac"};
  for (int k = 0; k < 2; ++k)
    for (int i = 0; i < 5; ++i) {
      char ov[2][64];
      snprintf(ov[0], sizeof ov[0], "bodies.beam.model=%s", models[k]);
      snprintf(ov[1], sizeof ov[1], "joints.spin.speed=%.17g", lambda[i] * scale);
      const char* o[] = {ov[0], ov[1]};
      Analysis a;
      ENSURE(analyse(&a, "tests/analysis/scenes/rotating.yaml", o, 2, 0, 0.0, 2) == 0);
      if (!a.modes) continue;
      const double exact = sqrt(mu_f[i] * mu_f[i] - lambda[i] * lambda[i]) * scale;
      printf("%-8s Omega = %8.5f rad/s: first in-plane frequency %.7f, continuum %.7f, error %.2e\n", models[k],
             a.st.speed, a.modes->frequency[0], exact, a.modes->frequency[0] / exact - 1.0);
      ENSURE_REL(a.st.speed, lambda[i] * scale, 1e-10);
      ENSURE_REL(a.modes->frequency[0], exact, 5e-4);
      ENSURE(a.modes->damping_ratio[0] == 0.0);
      analysis_free(&a);
    }
  /* the two eigen-solvers agree about a steady rotation, the divergent ZOAC mode included */
  {
    const char* o[] = {"bodies.beam.model=zoac", "joints.spin.speed=6"};
    Analysis a;
    ENSURE(analyse(&a, "tests/analysis/scenes/rotating.yaml", o, 2, 0, 0.0, 4) == 0);
    ensure_solvers_agree(&a, 4);
    /* `auto` took the sparse path (51 coordinates) and found the divergent mode */
    ENSURE(a.modes && a.modes->sparse && a.modes->frequency[0] < 0.0 && a.modes->damping_ratio[0] == -1.0);
    analysis_free(&a);
  }
  /* ZOAC */
  Analysis rest;
  const char* zo[] = {"bodies.beam.model=zoac", "joints.spin.speed=0"};
  ENSURE(analyse(&rest, "tests/analysis/scenes/rotating.yaml", zo, 2, 0, 0.0, 1) == 0);
  const double w1 = rest.modes ? rest.modes->frequency[0] : NAN;
  analysis_free(&rest);
  const double speeds[5] = {1.0, 2.0, 3.5, 4.0, 6.0};
  for (int i = 0; i < 5; ++i) {
    char ov[64];
    snprintf(ov, sizeof ov, "joints.spin.speed=%.17g", speeds[i]);
    const char* o[] = {"bodies.beam.model=zoac", ov};
    Analysis a;
    ENSURE(analyse(&a, "tests/analysis/scenes/rotating.yaml", o, 2, 0, 0.0, 1) == 0);
    if (!a.modes) continue;
    const double w2 = w1 * w1 - speeds[i] * speeds[i];
    const double expect = w2 >= 0 ? sqrt(w2) : -sqrt(-w2);
    printf("zoac     Omega = %8.5f rad/s: first frequency %.7f, omega1^2 - Omega^2 gives %.7f\n", speeds[i],
           a.modes->frequency[0], expect);
    ENSURE_NEAR(a.modes->frequency[0], expect, 2e-3 * w1);
    ENSURE(a.modes->damping_ratio[0] == (w2 >= 0 ? 0.0 : -1.0));
    analysis_free(&a);
  }
  /* the steady state: axial stretch of the tip at 15 rad/s */
  const char* so[] = {"joints.spin.speed=15"};
  Analysis a;
  ENSURE(analyse(&a, "tests/analysis/scenes/rotating.yaml", so, 1, 0, 0.0, 0) == 0);
  const double stretch = 2767.0 * 225.0 * pow(SEED_L, 3) / (3.0 * 68.95e9);
  const double tip_u = state_output(&a, "beam.tip_u");
  printf("steady tip stretch at 15 rad/s: %.6e m, rho Omega^2 L^3/(3E) = %.6e m; %d Newton iterations, residual %.2e\n",
         tip_u, stretch, a.st.iterations, a.st.residual);
  ENSURE_REL(tip_u, stretch, 1e-3);
  ENSURE_NEAR(state_output(&a, "beam.tip_v"), 0.0, 1e-12);
  ENSURE_REL(state_output(&a, "beam.omega"), 15.0, 1e-10);
  analysis_free(&a);
  /* the paper's spin-up scene at t = 20 s (after the ramp): 4.26118 rad/s (formulation note §8) */
  ENSURE(analyse(&a, "scenes/paper/spinup_w4.yaml", NULL, 0, 1, 20.0, 1) == 0);
  if (a.modes) ENSURE_REL(a.modes->frequency[0], 4.26118, 2e-5);
  ENSURE_REL(a.st.speed, 4.0, 1e-10);
  analysis_free(&a);
  /* centrifugal pendulum, R = 0.5, l = 0.2, m = 1, I = 1e-6, at 3 and 6 rad/s */
  for (int i = 0; i < 2; ++i) {
    const double W = 3.0 * (i + 1);
    char ov[64];
    snprintf(ov, sizeof ov, "joints.spin.speed=%g", W);
    const char* o[] = {ov};
    ENSURE(analyse(&a, "tests/analysis/scenes/centrifugal_pendulum.yaml", o, 1, 0, 0.0, 1) == 0);
    const double exact = W * sqrt(0.5 * 0.2 / (1e-6 + 0.04));
    if (a.modes) {
      printf("centrifugal pendulum at %g rad/s: %.12f rad/s, Omega sqrt(R m l/(I + m l^2)) = %.12f\n", W,
             a.modes->frequency[0], exact);
      ENSURE_REL(a.modes->frequency[0], exact, 1e-8);
      ENSURE(a.modes->count == 1);
    }
    ENSURE_NEAR(state_output(&a, "bob.theta"), 0.0, 1e-12); /* the link stays radial (the arm at angle 0) */
    analysis_free(&a);
  }
  /* during the ramp the drive accelerates: no steady state, a clear refusal */
  {
    char path[1024];
    fmbDiag d;
    fmbModel* m =
        fmb_load(fmbt_path("scenes/paper/spinup_w4.yaml", path, sizeof path), NULL, 0, fmb_builtin_registry(), &d);
    double* y = calloc((size_t)fmb_state_size(m), sizeof(double));
    double* yp = calloc((size_t)fmb_state_size(m), sizeof(double));
    fmbStaticOptions o = {5.0, 1, 0, 0, 0.0, 1};
    fmbStaticResult r;
    ENSURE(fmb_static(m, &o, y, yp, &r, &d) == FMB_EXIT_BAD_INPUT);
    ENSURE(strstr(d.msg, "accelerating") != NULL);
    ENSURE(fmb_static(NULL, &o, y, yp, &r, &d) == FMB_EXIT_BAD_INPUT);
    free(y);
    free(yp);
    fmb_free(m);
  }
  return fmbt_finish("test_modes_rotating");
}
