/* test_loads3d.c — the spatial force elements against closed forms and balances (docs/spatial.md):
 *  - spring (dimension 3): a bob hanging at its centre on a spring, k = 200 N/m, m = 2 kg: along the
 *    spring it oscillates at sqrt(k/m) = 10 rad/s, across it it swings as a pendulum of the hanging
 *    length L = l0 + m g / k at sqrt(g / L); with a damper c the axial motion decays at
 *    sigma = c / (2 m) and rings at sqrt(k/m - sigma^2), and the energy lost equals the damper's work
 *    int c l'^2 dt (l' from the columns: tension = k (l - l0) + c l');
 *  - force3d: a constant global force at a free body's centre and a global torque: the centre moves
 *    as x0 + v0 t + F t^2 / (2 m), the angular momentum about it as L0 + T t, and the loads' work is
 *    the kinetic energy gained; a torque about a body axis given in the body frame spins a body at rest
 *    about that axis, fixed in space, at omega = T t / I3;
 *  - torsion3d beside a revolute3d on a skew hinge: the twist at sqrt(k / I_n), the total energy with
 *    the spring's held;
 *  - force3d with `law: input`, set through the stepping API (fmb_set_input): the centre follows
 *    the closed form of the load switched on at t = 1 s;
 *  - prismatic3d with a profile: the slide follows offset + a sin(w t). */
#include <math.h>
#include <stdio.h>
#include <string.h>

#include "testlib.h"

static double sq(double x) { return x * x; }

/* decay rate of the maxima of x after t0 (each refined by the parabola through its neighbours) */
static double decay_rate(const fmbtCsv* c, const char* col, double t0, int* npeaks) {
  const double *t = fmbt_col(c, "t"), *x = fmbt_col(c, col);
  double t1 = NAN, x1 = NAN, tn = NAN, xn = NAN;
  *npeaks = 0;
  for (int i = 1; t && x && i + 1 < c->nrow; ++i) {
    if (t[i] < t0 || !(x[i] > x[i - 1] && x[i] >= x[i + 1])) continue;
    const double a = 0.5 * (x[i + 1] + x[i - 1]) - x[i], b = 0.5 * (x[i + 1] - x[i - 1]);
    const double s = -b / (2.0 * a), h = t[i + 1] - t[i];
    const double tp = t[i] + s * h, xp = x[i] + b * s + a * s * s;
    if (*npeaks == 0) t1 = tp, x1 = xp;
    tn = tp, xn = xp;
    ++*npeaks;
  }
  return *npeaks >= 2 ? log(x1 / xn) / (tn - t1) : NAN;
}

int main(void) {
  const double g = 9.81, m = 2.0, k = 200.0, l0 = 0.5, L = l0 + m * g / k;
  { /* along and across the spring */
    const char* along[1] = {"bodies.bob.velocity=[0, 0, 0.01]"};
    const char* across[1] = {"bodies.bob.velocity=[0.001, 0, 0]"};
    fmbtCsv c;
    fmbStats st;
    int n1 = 0, n2 = 0;
    ENSURE(fmbt_run_read("tests/spatial/scenes/spring3d.yaml", along, 1, "spring3d_along.csv", &c, &st) == 0);
    const double fa = fmbt_crossing_frequency(&c, "bob.vz", 0.5, &n1);
    fmbt_csv_free(&c);
    ENSURE(fmbt_run_read("tests/spatial/scenes/spring3d.yaml", across, 1, "spring3d_across.csv", &c, &st) == 0);
    const double fs = fmbt_crossing_frequency(&c, "bob.vx", 0.5, &n2);
    fmbt_csv_free(&c);
    const double wa = sqrt(k / m), ws = sqrt(g / L);
    printf("spring along: %.9f rad/s over %d crossings (sqrt(k/m) %.9f, relative error %.2e); across: %.9f rad/s over "
           "%d crossings (sqrt(g/L) %.9f, relative error %.2e)\n",
           fa, n1, wa, fabs(fa - wa) / wa, fs, n2, ws, fabs(fs - ws) / ws);
    ENSURE_REL(fa, wa, 1e-6);
    ENSURE_REL(fs, ws, 1e-6); /* amplitude 2.5e-4 rad: the swing's own shift is ~4e-9 */
  }
  { /* the damper */
    const double cdamp = 0.4, sigma = cdamp / (2.0 * m), wd = sqrt(k / m - sigma * sigma);
    const char* ovs[2] = {"bodies.bob.velocity=[0, 0, 0.01]", "joints.coil.damping=0.4"};
    fmbtCsv c;
    fmbStats st;
    ENSURE(fmbt_run_read("tests/spatial/scenes/spring3d.yaml", ovs, 2, "spring3d_damped.csv", &c, &st) == 0);
    int np = 0, nc = 0;
    const double s = decay_rate(&c, "bob.vz", 0.5, &np), w = fmbt_crossing_frequency(&c, "bob.vz", 0.5, &nc);
    const double *t = fmbt_col(&c, "t"), *E = fmbt_col(&c, "energy.total"), *l = fmbt_col(&c, "coil.length"),
                 *f = fmbt_col(&c, "coil.tension"), *W = fmbt_col(&c, "coil.work"), *V = fmbt_col(&c, "energy.spring");
    double D = 0.0, worst = 0.0, worst_work = 0.0, prev = 0.0;
    for (int i = 0; t && E && l && f && W && V && i < c.nrow; ++i) {
      const double rate = (f[i] - k * (l[i] - l0)) / cdamp, p = cdamp * rate * rate; /* damper's loss rate */
      if (i > 0) D += 0.5 * (p + prev) * (t[i] - t[i - 1]);
      prev = p;
      worst = fmax(worst, fabs(E[i] - E[0] + D));
      worst_work = fmax(worst_work, fabs(W[i] + (V[i] - V[0]) + D)); /* the element's work: -dV - D */
    }
    printf("damper: decay %.9f 1/s over %d peaks (c/2m %.9f, relative error %.2e), ringing %.9f rad/s (%.9f, "
           "%.2e); energy lost %.6e J, E + D held to %.2e J, its work -dV - D to %.2e J\n",
           s, np, sigma, fabs(s - sigma) / sigma, w, wd, fabs(w - wd) / wd, D, worst, worst_work);
    ENSURE_REL(s, sigma, 1e-5);
    ENSURE_REL(w, wd, 1e-6);
    ENSURE(D > 0.5 * 0.5 * m * sq(0.01)); /* most of the initial kinetic energy is gone (e^-2 left) */
    ENSURE(worst < 1e-4 * D && worst_work < 1e-4 * D);
    fmbt_csv_free(&c);
  }
  { /* applied force and torque */
    const double mf = 2.0, F[3] = {1.0, -2.0, 0.5}, T[3] = {0.3, 0.1, -0.2}, x0[3] = {0.1, 0.2, 0.3},
                 v0[3] = {0.5, -0.2, 0.1};
    fmbtCsv c;
    fmbStats st;
    ENSURE(fmbt_run_read("tests/spatial/scenes/loads3d.yaml", NULL, 0, "loads3d.csv", &c, &st) == 0);
    const char* xs[3] = {"free.x", "free.y", "free.z"};
    const char* Ls[3] = {"free.Lx", "free.Ly", "free.Lz"};
    const char* ws[3] = {"spun.wx", "spun.wy", "spun.wz"};
    const double* t = fmbt_col(&c, "t");
    const double *K = fmbt_col(&c, "energy.kinetic"), *W1 = fmbt_col(&c, "push.work"), *W2 = fmbt_col(&c, "motor.work");
    double ex = 0.0, eL = 0.0, ew = 0.0, eW = 0.0, Kmax = 0.0;
    /* spun: tilted 45 degrees about x, its third axis is [0, -sin 45, cos 45] */
    const double axis[3] = {0.0, -M_SQRT1_2, M_SQRT1_2}, T3 = 0.4, I3 = 0.08;
    for (int r = 0; r < 3; ++r) {
      const double *x = fmbt_col(&c, xs[r]), *Lr = fmbt_col(&c, Ls[r]), *w = fmbt_col(&c, ws[r]);
      for (int i = 0; t && x && Lr && w && i < c.nrow; ++i) {
        ex = fmax(ex, fabs(x[i] - (x0[r] + v0[r] * t[i] + F[r] * t[i] * t[i] / (2.0 * mf))));
        eL = fmax(eL, fabs(Lr[i] - (Lr[0] + T[r] * t[i])));
        ew = fmax(ew, fabs(w[i] - T3 * t[i] / I3 * axis[r]));
      }
    }
    for (int i = 0; t && K && W1 && W2 && i < c.nrow; ++i) {
      eW = fmax(eW, fabs(K[i] - K[0] - W1[i] - W2[i]));
      Kmax = fmax(Kmax, K[i]);
    }
    printf("loads: centre off x0 + v0 t + F t^2/2m by %.2e m, angular momentum off L0 + T t by %.2e N m s, follower "
           "torque's spin off T t / I3 by %.2e rad/s (%.3g rad/s at the end), work - kinetic energy gained %.2e J "
           "(kinetic up to %.3g J)\n",
           ex, eL, ew, T3 * (t ? t[c.nrow - 1] : NAN) / I3, eW, Kmax);
    ENSURE(ex < 1e-9 && eL < 1e-6 && ew < 1e-6 && eW < 1e-6 * Kmax);
    fmbt_csv_free(&c);
  }
  { /* law: input through the stepping API: the push is off (value 0) for 1 s, then on at s = 2 for
       1 s; the centre then moves as x0 + v0 t + 2 F (t - 1)^2 / (2 m), the momentum jumps by 2 F */
    const double mf = 2.0, F[3] = {1.0, -2.0, 0.5}, x0[3] = {0.1, 0.2, 0.3}, v0[3] = {0.5, -0.2, 0.1};
    char path[1024];
    const char* ovs[1] = {"joints.push.law=input"};
    fmbDiag dg;
    fmbModel* mod = fmb_load(fmbt_path("tests/spatial/scenes/loads3d.yaml", path, sizeof path), ovs, 1,
                             fmb_builtin_registry(), &dg);
    fmbData* d = mod ? fmb_data_new(mod, &dg) : NULL;
    ENSURE(d && fmb_init(mod, d, &dg) == 0);
    ENSURE(d && fmb_advance(mod, d, 1.0, &dg) == 0);
    ENSURE(d && fmb_set_input(mod, d, "push", 2.0) == 0);
    ENSURE(d && fmb_advance(mod, d, 2.0, &dg) == 0);
    double err = 0.0;
    const int no = mod ? fmb_noutput(mod) : 0;
    double out[64];
    if (d && no <= 64 && fmb_outputs(mod, d, out) == 0) {
      const char* xs[3] = {"free.x", "free.y", "free.z"};
      for (int i = 0; i < no; ++i)
        for (int r = 0; r < 3; ++r)
          if (strcmp(fmb_output_name(mod, i), xs[r]) == 0)
            err = fmax(err, fabs(out[i] - (x0[r] + v0[r] * 2.0 + 2.0 * F[r] / (2.0 * mf))));
    } else
      err = INFINITY;
    printf("force3d law: input: off for 1 s, then s = 2 for 1 s: centre off the closed form by %.2e m\n", err);
    ENSURE(err < 1e-9);
    fmb_data_free(d);
    fmb_free(mod);
  }
  { /* the rotational spring on a skew hinge */
    const double n[3] = {M_SQRT1_2, M_SQRT1_2, 0.0}, J[3] = {0.02, 0.03, 0.015}, d = 0.1, kt = 3.0, w0 = 0.01;
    const double In = n[0] * n[0] * J[0] + n[1] * n[1] * J[1] + n[2] * n[2] * J[2] + m * d * d, wt = sqrt(kt / In);
    char ov[2][160];
    snprintf(ov[0], sizeof ov[0], "bodies.rotor.angular_velocity=[%.17g, %.17g, 0]", w0 * n[0], w0 * n[1]);
    /* the centre d below the pivot on the hinge line: v = omega x (0, 0, -d) */
    snprintf(ov[1], sizeof ov[1], "bodies.rotor.velocity=[%.17g, %.17g, 0]", -d * w0 * n[1], d * w0 * n[0]);
    const char* ovs[2] = {ov[0], ov[1]};
    fmbtCsv c;
    fmbStats st;
    ENSURE(fmbt_run_read("tests/spatial/scenes/torsion3d.yaml", ovs, 2, "torsion3d.csv", &c, &st) == 0);
    int nc = 0;
    const double w = fmbt_crossing_frequency(&c, "twist.speed", 0.5, &nc);
    const double *E = fmbt_col(&c, "energy.total"), *V = fmbt_col(&c, "energy.spring"),
                 *a1 = fmbt_col(&c, "twist.angle"), *a2 = fmbt_col(&c, "hinge.angle");
    double dE = 0.0, Vmax = 0.0, da = 0.0;
    for (int i = 0; E && V && a1 && a2 && i < c.nrow; ++i) {
      dE = fmax(dE, fabs(E[i] - E[0]));
      Vmax = fmax(Vmax, V[i]);
      da = fmax(da, fabs(a1[i] - a2[i]));
    }
    printf("torsion3d: %.9f rad/s over %d crossings (sqrt(k/I_n) %.9f, relative error %.2e); spring energy up to "
           "%.3e J (0.5 I w0^2 = %.3e), total held to %.2e J; its angle the hinge's to %.1e rad\n",
           w, nc, wt, fabs(w - wt) / wt, Vmax, 0.5 * In * w0 * w0, dE, da);
    ENSURE_REL(w, wt, 1e-6);
    ENSURE_REL(Vmax, 0.5 * In * w0 * w0, 1e-4);
    ENSURE(dE < 1e-4 * Vmax && da < 1e-12);
    fmbt_csv_free(&c);
  }
  { /* the driven slider */
    fmbtCsv c;
    fmbStats st;
    ENSURE(fmbt_run_read("tests/spatial/scenes/slider3d.yaml", NULL, 0, "slider3d.csv", &c, &st) == 0);
    const double *t = fmbt_col(&c, "t"), *s = fmbt_col(&c, "rail.displacement");
    double e = 0.0;
    for (int i = 0; t && s && i < c.nrow; ++i) e = fmax(e, fabs(s[i] - (0.05 + 0.1 * sin(2.0 * t[i]))));
    printf("prismatic3d profile: slide off 0.05 + 0.1 sin(2 t) by %.2e m\n", e);
    ENSURE(e < 1e-8);
    fmbt_csv_free(&c);
  }
  return fmbt_finish("test_loads3d");
}
