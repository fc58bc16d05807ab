/* test_radau.c — solver.integrator: radau5 (engine/integrator_radau.c) against independent values:
 *   the 170-degree pendulum's period against 4 sqrt(Leq/g) K(sin(phi0/2)) (elliptic integral, as
 *   tests/core/test_pendulum.c), and the omega0 = 15 spin-up (16 elements, complete model, 5 s)
 *   against IDA at rtol 1e-12 (its own tip error 3e-9 m against IDA at 1e-13; at rtol 1e-11 it
 *   was 1.1e-8 m, the size of radau5's error at 1e-8, which then measured IDA's error). At rtol
 *   1e-6 and 1e-8 (atol rtol/100) each error must be within the tolerance radau5 applies (RADAU5's
 *   map rtol' = 0.1 rtol^(2/3), integrator_radau.c) and fall at least 10x between the two: order 5
 *   under that map gives about 20x (measured 18x on the spin-up, 20x on the pendulum); a wrong
 *   stage, error estimate or dense output gives order 1-2 or no convergence at all.
 * The runs above use the default solver.linear_solver: klu, both Newton systems with the position
 * rows eliminated (schur.c), a modified Newton iteration (the O(|mu|) part of the q-block dropped).
 * At rtol 1e-6 the spin-up with klu_full (the whole matrices, exact simplified Newton) must agree
 * with it to the tolerance applied (measured 1e-12 m of 2e-6 m allowed over 5 s; 4e-8 m over 20 s)
 * and need no more Newton iterations per step, within 15 % (measured 1.93 both over 5 s; 2.40
 * reduced, 2.50 whole over 20 s): a wrong elimination in either system would stall Newton or
 * change the answer.
 * The work integrals: the rotor's energy balance falls with rtol. The klu_full fallback (a failed reduced factorization, by fault injection) keeps the run going
 * at the same accuracy. Also: radau5 with formulation: projected, or with linear_solver: dense, is refused at load.
 * Every check but the last runs for radau5 and radau9 (the same code with the 5-stage tableau,
 * order 9): radau9's errors fall faster with rtol (measured 28x on the spin-up, 130x on the
 * pendulum, between 1e-6 and 1e-8), and a wrong coefficient in its tableau shows as lost order. */
#include <stdlib.h>
#include <string.h>

#include "testlib.h"

static const double g = 9.81, L = 1.0, mass = 1.0, inertia = 1.0e-6;

static double elliptic_K(double k) {
  double a = 1.0, b = sqrt(1.0 - k * k);
  for (int i = 0; i < 40; ++i) {
    const double an = 0.5 * (a + b);
    b = sqrt(a * b);
    a = an;
  }
  return M_PI / (2.0 * a);
}

/* mean period from the downward zero crossings of x, by bisection on the cubic Hermite
   interpolant between rows (x and vx), far below the tolerances tested */
static double period(const fmbtCsv* c) {
  const double *t = fmbt_col(c, "t"), *x = fmbt_col(c, "bob.x"), *vx = fmbt_col(c, "bob.vx");
  if (!t || !x || !vx) return NAN;
  double first = NAN, last = NAN;
  int n = 0;
  for (int i = 0; i + 1 < c->nrow; ++i) {
    if (!(x[i] > 0 && x[i + 1] <= 0)) continue;
    const double h = t[i + 1] - t[i];
    double lo = 0.0, hi = 1.0;
    for (int it = 0; it < 80; ++it) {
      const double s = 0.5 * (lo + hi);
      const double p = (2 * s * s * s - 3 * s * s + 1) * x[i] + (s * s * s - 2 * s * s + s) * h * vx[i] +
                       (-2 * s * s * s + 3 * s * s) * x[i + 1] + (s * s * s - s * s) * h * vx[i + 1];
      if ((p < 0) == (x[i] < 0))
        lo = s;
      else
        hi = s;
    }
    const double tc = t[i] + 0.5 * (lo + hi) * h;
    if (n == 0) first = tc;
    last = tc;
    n++;
  }
  return n >= 2 ? (last - first) / (n - 1) : NAN;
}

static int run(const char* scene, const char* integrator, double rtol, double t_end, const char* out, fmbtCsv* c,
               fmbStats* st, const char* extra0, const char* extra1) {
  char o[6][96];
  snprintf(o[0], sizeof o[0], "solver.integrator=%s", integrator);
  snprintf(o[1], sizeof o[1], "solver.rtol=%g", rtol);
  snprintf(o[2], sizeof o[2], "solver.atol=%g", rtol / 100);
  if (rtol < 1e-11) snprintf(o[2], sizeof o[2], "solver.max_step=0"); /* the reference: atol derived */
  snprintf(o[3], sizeof o[3], "solver.t_end=%g", t_end);
  snprintf(o[4], sizeof o[4], "%s", extra0 ? extra0 : "solver.max_step=0");
  snprintf(o[5], sizeof o[5], "%s", extra1 ? extra1 : "solver.max_step=0");
  const char* ov[6] = {o[0], o[1], o[2], o[3], o[4], o[5]};
  return fmbt_run_read(scene, ov, 6, out, c, st);
}

/* max |a - b| of a column over the rows both runs share (same output grid) */
static double max_diff(const fmbtCsv* a, const fmbtCsv* b, const char* col) {
  const double *x = fmbt_col(a, col), *y = fmbt_col(b, col);
  if (!x || !y || a->nrow != b->nrow) return INFINITY;
  double e = 0.0;
  for (int i = 0; i < a->nrow; ++i) e = fmax(e, fabs(x[i] - y[i]));
  return e;
}

static void pendulum(const char* integ) {
  const double phi0 = 170.0 * M_PI / 180.0, Leq = L + inertia / (mass * L);
  const double T_exact = 4.0 * sqrt(Leq / g) * elliptic_K(sin(0.5 * phi0));
  double err[2];
  long fails[2], steps[2];
  const double rtols[2] = {1e-6, 1e-8};
  for (int k = 0; k < 2; ++k) {
    fmbtCsv c;
    fmbStats st;
    char out[64];
    snprintf(out, sizeof out, "%s_pendulum_%d.csv", integ, k);
    const int rc = run("scenes/pendulum.yaml", integ, rtols[k], 10.0, out, &c, &st, "solver.output_step=0.002", NULL);
    ENSURE(rc == 0);
    const double T = period(&c);
    err[k] = fabs(T / T_exact - 1.0);
    printf("pendulum 170 deg, %s rtol %g: T = %.12f, exact %.12f, relative error %.2e (%ld steps, %ld Newton "
           "convergence failures)\n",
           integ, rtols[k], T, T_exact, err[k], st.steps, st.conv_fails);
    fails[k] = st.conv_fails;
    steps[k] = st.steps;
    fmbt_csv_free(&c);
  }
  /* near the separatrix the period magnifies the energy error (test_pendulum: ~100 rtol) */
  ENSURE(err[0] < 2e-5);
  ENSURE(err[1] < 1e-6);
  ENSURE(err[1] * 10.0 < err[0]);
  /* The bob's tiny inertia, 1e-6, makes the Newton iteration contract slowly. With RADAU5's 7
     iterations radau9 failed to converge 331 and 427 times in 10 s (rtol 1e-6, 1e-8), took 889 and
     708 steps, and its period error at 1e-6 moved between 2.3e-5 and 1.4e-4 with roundoff-level
     changes to the code; with RADAU's 12 for 5 stages (integrator_radau.c, FMB_RADAU_NIT) 49 and 5
     failures, 134 and 174 steps, 8.0e-6 and 3.7e-9. radau5 (7 iterations, the same as before):
     10 and 15 failures in 340 and 732 steps. 100 failures in the 10 s is well above both and well
     below the old behaviour. */
  for (int k = 0; k < 2; ++k) ENSURE(fails[k] < 100 && steps[k] < 1000);
}

static void spinup(const char* integ) {
  fmbtCsv ref, c[2], full;
  fmbStats st, st_red = {0}, st_full = {0};
  const double t_end = 5.0;
  int rc = run("scenes/paper/spinup_w15.yaml", "ida", 1e-12, t_end, "radau_spinup_ref.csv", &ref, &st, NULL, NULL);
  ENSURE(rc == 0);
  const double rtols[2] = {1e-6, 1e-8};
  double err[2], scale = 0.0;
  const double* v = fmbt_col(&ref, "beam.tip_v");
  for (int i = 0; v && i < ref.nrow; ++i) scale = fmax(scale, fabs(v[i]));
  for (int k = 0; k < 2; ++k) {
    char out[64];
    snprintf(out, sizeof out, "%s_spinup_%d.csv", integ, k);
    rc = run("scenes/paper/spinup_w15.yaml", integ, rtols[k], t_end, out, &c[k], &st, NULL, NULL);
    ENSURE(rc == 0);
    if (k == 0) st_red = st;
    err[k] = max_diff(&c[k], &ref, "beam.tip_v");
    const double eth = max_diff(&c[k], &ref, "beam.theta");
    printf("spin-up 5 s, %s rtol %g: tip_v error %.3e m (scale %.3g m), theta error %.3e rad, %ld steps\n", integ,
           rtols[k], err[k], scale, eth, st.steps);
    /* agreement with IDA to the tolerance radau5 applies (measured: 0.16 rtol' and 0.2 rtol' of the
       tip's excursion, theta 0.002 rtol') */
    const double rtol_applied = 0.1 * pow(rtols[k], 2.0 / 3.0);
    ENSURE(err[k] < rtol_applied * scale);
    ENSURE(eth < 0.1 * rtol_applied);
  }
  ENSURE(err[1] * 10.0 < err[0]);

  /* the whole matrices against the reduced ones (c[0], the default linear_solver: klu) */
  char out_full[64], out_fb[64];
  snprintf(out_full, sizeof out_full, "%s_spinup_full.csv", integ);
  snprintf(out_fb, sizeof out_fb, "%s_spinup_fallback.csv", integ);
  rc = run("scenes/paper/spinup_w15.yaml", integ, rtols[0], t_end, out_full, &full, &st_full,
           "solver.linear_solver=klu_full", NULL);
  ENSURE(rc == 0);
  const double dfull = max_diff(&c[0], &full, "beam.tip_v");
  const double it_red = (double)st_red.newton_iters / (double)st_red.steps;
  const double it_full = (double)st_full.newton_iters / (double)st_full.steps;
  printf("spin-up 5 s, %s rtol 1e-6: klu vs klu_full tip_v %.3e m; Newton iterations per step %.2f (klu, %ld "
         "steps), %.2f (klu_full, %ld steps)\n",
         integ, dfull, it_red, st_red.steps, it_full, st_full.steps);
  ENSURE(dfull < 0.1 * pow(rtols[0], 2.0 / 3.0) * scale);
  ENSURE(it_red <= 1.15 * it_full);
  ENSURE(st_red.integrator && strcmp(st_red.integrator, integ) == 0); /* the stats line's integrator= */

  /* the fallback to klu_full: the reduced factorizations made to fail from the 5th on (schur.c's
     solver.fault_reduced_setup; the 5 s run factorizes 12 times). The run must go on with the whole matrices from
     the last accepted step and still meet the tolerance against IDA's reference; that it took
     another path shows in a difference from the reduced run (measured 2.1e-7 m, switch at t =
     0.006 s), while without the fallback the run would stop there (exit 3). */
  fmbtCsv fb;
  fmbStats st_fb;
  rc = run("scenes/paper/spinup_w15.yaml", integ, rtols[0], t_end, out_fb, &fb, &st_fb, "solver.fault_reduced_setup=5",
           NULL);
  ENSURE(rc == 0);
  const double efb = max_diff(&fb, &ref, "beam.tip_v"), dfb = max_diff(&fb, &c[0], "beam.tip_v");
  printf("spin-up 5 s, %s rtol 1e-6, reduced solve failing from the 5th factorization: tip_v error %.3e m, %.3e m "
         "from the reduced run, %ld steps\n",
         integ, efb, dfb, st_fb.steps);
  ENSURE(efb < 0.1 * pow(rtols[0], 2.0 / 3.0) * scale);
  ENSURE(dfb > 0.0);
  fmbt_csv_free(&fb);
  fmbt_csv_free(&full);
  fmbt_csv_free(&ref);
  fmbt_csv_free(&c[0]);
  fmbt_csv_free(&c[1]);
}

/* The work integrals (energy.balance = E(t) - E(0) - W(t), zero for the exact solution): the rotor,
   a hub driven by a torque table (kinks) with three beams, 8 s. radau5 integrates the motor's work
   with the state (try_work, in the error test as IDA's quadratures are); the balance must fall with
   rtol, >= 5x per 100x (measured 14x: 1.3e-4 J at 1e-5, 9.2e-6 J at 1e-7; before, with the stage
   powers taken at the step's end state, 0.21 and 0.069 J, and 0.027 J at 1e-9), and stay below
   1e-6 of the largest kinetic energy (24.8 J) at 1e-7. */
static void work_balance(const char* integ) {
  double bal[2], ekin = 0.0;
  const double rtols[2] = {1e-5, 1e-7};
  for (int k = 0; k < 2; ++k) {
    fmbtCsv c;
    fmbStats st;
    char out[64], r[48];
    char in[48];
    snprintf(out, sizeof out, "%s_rotor_%d.csv", integ, k);
    snprintf(r, sizeof r, "solver.rtol=%g", rtols[k]);
    snprintf(in, sizeof in, "solver.integrator=%s", integ);
    const char* ov[3] = {in, r, "solver.atol=auto"};
    ENSURE(fmbt_run_read("scenes/rotor.yaml", ov, 3, out, &c, &st) == 0);
    const double *b = fmbt_col(&c, "energy.balance"), *e = fmbt_col(&c, "energy.kinetic");
    bal[k] = 0.0;
    for (int i = 0; b && e && i < c.nrow; ++i) {
      bal[k] = fmax(bal[k], fabs(b[i]));
      ekin = fmax(ekin, fabs(e[i]));
    }
    printf("rotor, %s rtol %g: max |energy.balance| %.3e J (kinetic energy up to %.3g J), %ld steps\n", integ, rtols[k],
           bal[k], ekin, st.steps);
    fmbt_csv_free(&c);
  }
  ENSURE(bal[1] * 5.0 < bal[0]);
  /* radau9: 3.7e-4 and 7.5e-4 J at 1e-5, 3.5e-5 and 4.8e-5 J (1.9e-6 of the kinetic energy) at
     1e-7 (two roundoff-level variants of the code), in 700-800 steps against radau5's 1294 */
  ENSURE(bal[1] < (strcmp(integ, "radau9") == 0 ? 4e-6 : 1e-6) * ekin);
}

static void refused_with_projected(void) {
  fmbStats st;
  fmbDiag diag;
  const char* ov[2] = {"solver.integrator=radau5", "solver.formulation=projected"};
  const int rc = fmbt_run("scenes/pendulum.yaml", ov, 2, "radau_projected.csv", &st, &diag);
  ENSURE(rc == FMB_EXIT_BAD_INPUT);
  ENSURE(strstr(diag.msg, "radau5") != NULL);
  const char* dense[2] = {"solver.integrator=radau5", "solver.linear_solver=dense"};
  ENSURE(fmbt_run("scenes/pendulum.yaml", dense, 2, "radau_dense.csv", &st, &diag) == FMB_EXIT_BAD_INPUT);
  ENSURE(strstr(diag.msg, "klu_full") != NULL);
  const char* bad[1] = {"solver.integrator=radau3"};
  ENSURE(fmbt_run("scenes/pendulum.yaml", bad, 1, "radau_bad.csv", &st, &diag) == FMB_EXIT_BAD_INPUT);
}

int main(void) {
  const char* integ[2] = {"radau5", "radau9"};
  for (int k = 0; k < 2; ++k) {
    pendulum(integ[k]);
    spinup(integ[k]);
    work_balance(integ[k]);
  }
  refused_with_projected();
  return fmbt_finish("test_radau");
}
