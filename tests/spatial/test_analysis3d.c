/* test_analysis3d.c — statics, modes, steady rotation and Campbell of spatial scenes against closed
 * forms (docs/analysis.md "Spatial scenes"):
 *  - statics: a rigid body on a ball joint (tests/spatial/scenes/hanging.yaml, started 60 degrees
 *    off about a skew axis), on a Cardan joint (hanging_cardan.yaml, tilted about both pins) and on
 *    a skew hinge (hinge.yaml turned 0.5 rad about its axis) hangs with its centre of mass straight
 *    below the pivot and its body z axis vertical;
 *  - modes about those states: the ball joint's two equal pendulum frequencies
 *    sqrt(m g l / (I + m l^2)), its free spin about the vertical at 0 and nothing else (3 degrees
 *    of freedom: no mode of the Euler parameters' length); the Cardan joint's two, one per pin;
 *    the hinge's sqrt(m g d / I_n), I_n the inertia about the skew hinge line;
 *  - a rigid blade on a Cardan hinge at radius e of a hub driven about z (rigid_blade.yaml): the
 *    steady rotation's modes per rev against nu_flap^2 = 1 + (m e d - Ia) / I and
 *    nu_lag^2 = m e d / I (d = Lb / 2, I = It + m d^2 about the hinge; thin rod: 1 + 3e / (2 Lb)
 *    and 3e / (2 Lb)), labelled flap and lag by fmb_modes_classify, and the Campbell diagram's
 *    two curves (fmb_campbell) each against its family's closed form;
 *  - gravity across the spin axis has no steady state (bad input), along it one exists. */
#include "../analysis/analysis.h"

static const double g = 9.81;

/* the body z axis of unit Euler parameters [w, x, y, z] (global): R e_z */
static void body_z(double w, double x, double y, double z, double out[3]) {
  out[0] = 2.0 * (x * z + w * y);
  out[1] = 2.0 * (y * z - w * x);
  out[2] = w * w - x * x - y * y + z * z;
}

/* the state's centre of mass and body z axis off hanging straight below the origin by l */
static double hang_error(const Analysis* a, double l) {
  const double x = state_output(a, "bob.x"), y = state_output(a, "bob.y"), z = state_output(a, "bob.z");
  double ez[3];
  body_z(state_output(a, "bob.qw"), state_output(a, "bob.qx"), state_output(a, "bob.qy"), state_output(a, "bob.qz"),
         ez);
  const double e = fmax(fmax(fabs(x), fabs(y)), fabs(z + l));
  return fmax(e, fmax(fmax(fabs(ez[0]), fabs(ez[1])), fabs(ez[2] - 1.0)));
}

int main(void) {
  const double m = 2.0, l = 0.4;
  { /* ball joint */
    Analysis a;
    ENSURE(analyse(&a, "tests/spatial/scenes/hanging.yaml", NULL, 0, 0, 0.0, 10) == 0);
    if (a.modes) {
      const double w = sqrt(m * g * l / (0.02 + m * l * l)), err = hang_error(&a, l);
      printf("ball joint: hangs within %.2e m of below the pivot (%d Newton iterations); %d modes: %.10g %.10g %.10g "
             "rad/s (closed form 0 and twice %.10g)\n",
             err, a.st.iterations, a.modes->count, a.modes->frequency[0], a.modes->frequency[1],
             a.modes->count > 2 ? a.modes->frequency[2] : NAN, w);
      ENSURE(err < 1e-12);
      ENSURE(a.modes->nreduced == 3 && a.modes->count == 3); /* two swings and the spin: no gauge mode */
      ENSURE(fabs(a.modes->frequency[0]) < 1e-6 * w);
      ENSURE_REL(a.modes->frequency[1], w, 1e-10);
      ENSURE_REL(a.modes->frequency[2], w, 1e-10);
      ENSURE(a.modes->family == NULL); /* at rest: no spin axis */
    }
    analysis_free(&a);
  }
  { /* the ball joint started hanging: gravity balanced, the spin free; that start is the equilibrium */
    const char* ov[] = {"bodies.bob.orientation=[1, 0, 0, 0]", "bodies.bob.position=[0, 0, -0.4]"};
    Analysis a;
    ENSURE(analyse(&a, "tests/spatial/scenes/hanging.yaml", ov, 2, 0, 0.0, 10) == 0);
    if (a.modes) {
      const double w = sqrt(m * g * l / (0.02 + m * l * l));
      printf("ball joint started hanging: %d Newton iterations, modes %.3g %.10g %.10g rad/s\n", a.st.iterations,
             a.modes->frequency[0], a.modes->frequency[1], a.modes->count > 2 ? a.modes->frequency[2] : NAN);
      ENSURE(hang_error(&a, l) < 1e-15 && a.modes->count == 3);
      ENSURE(fabs(a.modes->frequency[0]) < 1e-6 * w);
      ENSURE_REL(a.modes->frequency[1], w, 1e-10);
      ENSURE_REL(a.modes->frequency[2], w, 1e-10);
    }
    analysis_free(&a);
  }
  { /* Cardan joint: one swing per pin, about x with I1 = 0.02, about y with I2 = 0.03 */
    Analysis a;
    ENSURE(analyse(&a, "tests/spatial/scenes/hanging_cardan.yaml", NULL, 0, 0, 0.0, 10) == 0);
    if (a.modes) {
      const double wy = sqrt(m * g * l / (0.03 + m * l * l)), wx = sqrt(m * g * l / (0.02 + m * l * l));
      const double err = hang_error(&a, l);
      printf("Cardan joint: hangs within %.2e m; modes %.10g %.10g rad/s (closed form %.10g %.10g)\n", err,
             a.modes->frequency[0], a.modes->count > 1 ? a.modes->frequency[1] : NAN, wy, wx);
      ENSURE(err < 1e-12);
      ENSURE(a.modes->nreduced == 2 && a.modes->count == 2);
      ENSURE_REL(a.modes->frequency[0], wy, 1e-10);
      ENSURE_REL(a.modes->frequency[1], wx, 1e-10);
    }
    analysis_free(&a);
  }
  { /* the skew hinge, started 0.5 rad about its axis [1, 1, 0] / sqrt 2 */
    const char* ov[] = {"bodies.bob.orientation=[0.968912421710645, 0.17494101728127348, 0.17494101728127348, 0]",
                        "bodies.bob.position=[-0.135602019768418, 0.135602019768418, -0.3510330247561493]"};
    Analysis a;
    ENSURE(analyse(&a, "tests/spatial/scenes/hinge.yaml", ov, 2, 0, 0.0, 10) == 0);
    if (a.modes) {
      const double In = 0.5 * (0.02 + 0.03) + m * l * l, w = sqrt(m * g * l / In);
      const double x = state_output(&a, "bob.x"), y = state_output(&a, "bob.y"), z = state_output(&a, "bob.z");
      const double ang = state_output(&a, "hinge.angle");
      printf("skew hinge: centre of mass (%.2e, %.2e, %.12f), turned back by %.12f rad; mode %.10g rad/s (closed "
             "form %.10g)\n",
             x, y, z, ang, a.modes->frequency[0], w);
      ENSURE(fabs(x) < 1e-12 && fabs(y) < 1e-12 && fabs(z + l) < 1e-12);
      ENSURE_NEAR(ang, -0.5, 1e-12);
      ENSURE(a.modes->nreduced == 1 && a.modes->count == 1);
      ENSURE_REL(a.modes->frequency[0], w, 1e-10);
    }
    analysis_free(&a);
  }
  /* the rigid blade: its closed forms per rev */
  const double mb = 3.0, Lb = 1.2, r = 0.01, e = 0.2, d = Lb / 2.0;
  const double Ia = mb * r * r / 2.0, It = mb * Lb * Lb / 12.0 + mb * r * r / 4.0, Ih = It + mb * d * d;
  const double nu_flap = sqrt(1.0 + (mb * e * d - Ia) / Ih), nu_lag = sqrt(mb * e * d / Ih);
  printf("rigid blade: nu_flap %.10f, nu_lag %.10f per rev (thin rod: %.10f, %.10f)\n", nu_flap, nu_lag,
         sqrt(1.0 + 1.5 * e / Lb), sqrt(1.5 * e / Lb));
  ENSURE(fabs(nu_flap - sqrt(1.0 + 1.5 * e / Lb)) < 1e-4 && fabs(nu_lag - sqrt(1.5 * e / Lb)) < 1e-4);
  const double speeds[] = {2.0, 7.0, 13.0, 25.0};
  for (int i = 0; i < 4; ++i) {
    char ov[80];
    snprintf(ov, sizeof ov, "joints.spin.speed=%.17g", speeds[i]);
    const char* o[] = {ov};
    Analysis a;
    ENSURE(analyse(&a, "tests/spatial/scenes/rigid_blade.yaml", o, 1, 0, 0.0, 10) == 0);
    if (a.modes) {
      const double W = speeds[i];
      printf("  at %g rad/s (fitted %.12g about [%.1e, %.1e, %.12f]): %s %.10g, %s %.10g rad/s (closed form lag "
             "%.10g, flap %.10g)\n",
             W, a.st.speed, a.modes->axis[0], a.modes->axis[1], a.modes->axis[2],
             a.modes->family ? fmb_family_name(a.modes->family[0]) : "?", a.modes->frequency[0],
             a.modes->family && a.modes->count > 1 ? fmb_family_name(a.modes->family[1]) : "?",
             a.modes->count > 1 ? a.modes->frequency[1] : NAN, nu_lag * W, nu_flap * W);
      ENSURE_REL(a.st.speed, W, 1e-12);
      ENSURE(a.modes->nreduced == 2 && a.modes->count == 2 && a.modes->family);
      ENSURE_NEAR(a.modes->axis[2], 1.0, 1e-12);
      ENSURE_REL(a.modes->frequency[0], nu_lag * W, 1e-9);
      ENSURE_REL(a.modes->frequency[1], nu_flap * W, 1e-9);
      if (a.modes->family) ENSURE(a.modes->family[0] == FMB_FAMILY_LAG && a.modes->family[1] == FMB_FAMILY_FLAP);
    }
    analysis_free(&a);
  }
  { /* the Campbell diagram: each curve against its family's line */
    char path[1024];
    const fmbSceneSource scene = {fmbt_path("tests/spatial/scenes/rigid_blade.yaml", path, sizeof path), NULL, 0,
                                  fmb_builtin_registry()};
    fmbCampbellOptions opt;
    memset(&opt, 0, sizeof opt);
    opt.speed_key = "joints.spin.speed";
    opt.count = 2;
    opt.method = FMB_EIGEN_AUTO;
    opt.steady.quiet = 1;
    const double sw[] = {1.0, 4.0, 8.0, 16.0, 32.0};
    fmbCampbell* c = NULL;
    fmbDiag diag;
    ENSURE(fmb_campbell(&scene, &opt, sw, 5, &c, &diag) == 0);
    double worst = 0.0;
    int flap = 0, lag = 0;
    for (int k = 0; c && k < 2; ++k) {
      const int f = fmb_campbell_family(c, k);
      flap += f == FMB_FAMILY_FLAP;
      lag += f == FMB_FAMILY_LAG;
      const double nu = f == FMB_FAMILY_FLAP ? nu_flap : f == FMB_FAMILY_LAG ? nu_lag : NAN;
      for (int i = 0; i < c->done; ++i) {
        ENSURE(c->family[(size_t)i * 2 + k] == f); /* the curve keeps its family at every speed */
        worst = fmax(worst, fabs(c->frequency[(size_t)i * 2 + k] - nu * sw[i]) / (nu * sw[i]));
      }
    }
    printf("Campbell over 1 .. 32 rad/s: one flap and one lag curve (%d, %d), each off its line nu Omega by at most "
           "%.2e relative\n",
           flap, lag, worst);
    ENSURE(c && c->done == 5 && flap == 1 && lag == 1 && worst < 1e-9);
    fmb_campbell_free(c);
  }
  { /* gravity across the spin axis: no steady state; along it: the blade droops and turns steadily */
    const char* across[] = {"gravity=[0, -9.81, 0]"};
    const char* along[] = {"gravity=[0, 0, -9.81]", "joints.spin.speed=20"};
    Analysis a;
    ENSURE(analyse(&a, "tests/spatial/scenes/rigid_blade.yaml", across, 1, 0, 0.0, 0) == FMB_EXIT_BAD_INPUT);
    analysis_free(&a);
    ENSURE(analyse(&a, "tests/spatial/scenes/rigid_blade.yaml", along, 2, 0, 0.0, 0) == 0);
    /* droop b about the flap hinge: the centrifugal moment of -W^2 I_zz(b) / 2, I_zz = It cos^2 b +
       Ia sin^2 b + m (e + d cos b)^2 about the spin axis, balances gravity's m g d cos b:
       tan b = m g d / (W^2 ((It - Ia) cos b + m d (e + d cos b))), by fixed point; z = -d sin b */
    const double W = 20.0;
    double b = 0.0;
    for (int it = 0; it < 200; ++it) b = atan(mb * g * d / (W * W * ((It - Ia) * cos(b) + mb * d * (e + d * cos(b)))));
    const double bz = state_output(&a, "blade.z"), by = state_output(&a, "blade.y");
    printf("gravity along the axis at 20 rad/s: the blade's centre of mass at z = %.12e m, y = %.1e m (closed form "
           "droop %.12e m)\n",
           bz, by, -d * sin(b));
    ENSURE_REL(bz, -d * sin(b), 1e-9);
    ENSURE(fabs(by) < 1e-12);
    analysis_free(&a);
  }
  return fmbt_finish("test_analysis3d");
}
