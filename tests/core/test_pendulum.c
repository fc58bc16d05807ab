/* test_pendulum.c — simple pendulum periods against independent values:
 *   small amplitude (0.01 rad): T = 2 pi sqrt(Leq/g) (1 + phi0^2/16), i.e. the linear period with
 *     its first amplitude correction (the next term, 11 phi0^4/3072, is 1e-10 here);
 *   large amplitude (170 deg): T = 4 sqrt(Leq/g) K(sin(phi0/2)), K the complete elliptic integral
 *     of the first kind by the arithmetic-geometric mean; required to 1e-6 relative.
 * The bob is a rigid body with a tiny inertia I about its centre, pinned at distance L: exactly a
 * physical pendulum of equivalent length Leq = L + I/(m L). Zero crossings of x(t) are located by
 * cubic Hermite interpolation between output rows using x and vx, so the measurement error is far
 * below the tolerance. Also: energy and constraint drift stay at tolerance level. */
#include <stdlib.h>
#include <string.h>

#include "testlib.h"

static const double g = 9.81, L = 1.0, mass = 1.0, inertia = 1.0e-6;

static double elliptic_K(double k) {
  double a = 1.0, b = sqrt(1.0 - k * k);
  for (int i = 0; i < 40; ++i) {
    double an = 0.5 * (a + b);
    b = sqrt(a * b);
    a = an;
  }
  return M_PI / (2.0 * a);
}

/* times where x crosses zero going in direction `sign` (+1 up, -1 down), Hermite-interpolated */
static int crossings(const double* t, const double* x, const double* vx, int n, int sign, double* out, int max) {
  int k = 0;
  for (int i = 0; i + 1 < n && k < max; ++i) {
    if (!((sign > 0 && x[i] < 0 && x[i + 1] >= 0) || (sign < 0 && x[i] > 0 && x[i + 1] <= 0))) continue;
    const double h = t[i + 1] - t[i];
    double lo = 0.0, hi = 1.0;
    for (int it = 0; it < 80; ++it) { /* bisection on the Hermite cubic */
      const double s = 0.5 * (lo + hi);
      const double h00 = 2 * s * s * s - 3 * s * s + 1, h10 = s * s * s - 2 * s * s + s;
      const double h01 = -2 * s * s * s + 3 * s * s, h11 = s * s * s - s * s;
      const double p = h00 * x[i] + h10 * h * vx[i] + h01 * x[i + 1] + h11 * h * vx[i + 1];
      if ((p < 0) == (x[i] < 0))
        lo = s;
      else
        hi = s;
    }
    out[k++] = t[i] + 0.5 * (lo + hi) * h;
  }
  return k;
}

static double measure_period(double phi0, const char* out, double t_end, double rtol, double* drift_e,
                             double* drift_c) {
  char o[6][96];
  snprintf(o[0], sizeof o[0], "bodies.bob.angle=%.17g", phi0);
  snprintf(o[1], sizeof o[1], "bodies.bob.position=[%.17g, %.17g]", L * sin(phi0), -L * cos(phi0));
  snprintf(o[2], sizeof o[2], "solver.t_end=%g", t_end);
  snprintf(o[3], sizeof o[3], "solver.output_step=0.002");
  snprintf(o[4], sizeof o[4], "solver.rtol=%g", rtol);
  snprintf(o[5], sizeof o[5], "solver.atol=%g", rtol / 100);
  const char* ov[6] = {o[0], o[1], o[2], o[3], o[4], o[5]};
  fmbtCsv c;
  fmbStats st;
  int rc = fmbt_run_read("scenes/pendulum.yaml", ov, 6, out, &c, &st);
  ENSURE(rc == 0);
  const double *t = fmbt_col(&c, "t"), *x = fmbt_col(&c, "bob.x"), *vx = fmbt_col(&c, "bob.vx");
  const double *e = fmbt_col(&c, "energy.total"), *cp = fmbt_col(&c, "constraint.position");
  double T = NAN;
  if (t && x && vx && e && cp) {
    double zc[8];
    int n = crossings(t, x, vx, c.nrow, -1, zc, 8); /* released at x > 0: first crossing goes down */
    ENSURE(n >= 2);
    if (n >= 2) T = (zc[n - 1] - zc[0]) / (n - 1);
    *drift_e = 0.0;
    *drift_c = 0.0;
    for (int i = 0; i < c.nrow; ++i) {
      *drift_e = fmax(*drift_e, fabs(e[i] - e[0]) / fabs(e[0] ? e[0] : 1.0));
      *drift_c = fmax(*drift_c, cp[i]);
    }
  }
  fmbt_csv_free(&c);
  return T;
}

int main(void) {
  const double Leq = L + inertia / (mass * L);
  double de, dc;

  const double small = 0.01;
  const double T_small = measure_period(small, "pendulum_small.csv", 8.0, 1e-8, &de, &dc);
  const double T_lin = 2.0 * M_PI * sqrt(Leq / g) * (1.0 + small * small / 16.0);
  printf("small amplitude: T = %.12f, reference %.12f, relative error %.2e\n", T_small, T_lin,
         fabs(T_small / T_lin - 1));
  ENSURE_REL(T_small, T_lin, 2e-7);

  const double big = 170.0 * M_PI / 180.0;
  const double T_big = measure_period(big, "pendulum_170.csv", 10.0, 1e-10, &de, &dc);
  const double T_exact = 4.0 * sqrt(Leq / g) * elliptic_K(sin(0.5 * big));
  printf("170 degrees: T = %.12f, exact %.12f, relative error %.2e; energy drift %.2e, constraint %.2e\n", T_big,
         T_exact, fabs(T_big / T_exact - 1), de, dc);
  ENSURE_REL(T_big, T_exact, 5e-7);
  /* a wrong period by the small-angle formula would be off by 140 %: the test discriminates */
  ENSURE(fabs(T_big / (2 * M_PI * sqrt(Leq / g)) - 1) > 0.5);
  /* rtol 1e-10. Near the separatrix the period is so sensitive to the energy that at rtol 1e-8
     (energy error about 100 rtol: 0.8e-6 to 2.3e-6 with the reduced KLU, full KLU and dense
     solvers) roundoff alone (a different pivot order in the initial accelerations) moved the
     period's error between 7e-7 and 4e-6; at 1e-10 it is 3e-8 to 4e-8 and the energy error 4e-8.
     A wrong force term drifts by orders of magnitude more */
  ENSURE(de < 5e-7);
  ENSURE(dc < 1e-8); /* atol 1e-12 on positions */
  return fmbt_finish("test_pendulum");
}
