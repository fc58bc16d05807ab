/* quad.c — Gauss–Legendre rules: the one quadrature of the project.
 * Nodes are the roots of P_n, found by Newton's method from Tricomi's initial guess; weights
 * w_i = 2 / ((1 - x_i^2) P_n'(x_i)^2). Mapped to [0, 1]. Computed once for every n, the first
 * time any is asked for (pthread_once: two threads loading two models at once must not fill the
 * table together). */
#include <math.h>
#include <pthread.h>

#include "flexmbd_plugin.h"

static double rule_x[FMB_GAUSS_MAX + 1][FMB_GAUSS_MAX];
static double rule_w[FMB_GAUSS_MAX + 1][FMB_GAUSS_MAX];
static pthread_once_t rules_once = PTHREAD_ONCE_INIT;

static void legendre(int n, double x, double* p, double* dp) {
  double p0 = 1.0, p1 = x;
  for (int k = 2; k <= n; ++k) {
    double pk = ((2.0 * k - 1.0) * x * p1 - (k - 1.0) * p0) / k;
    p0 = p1;
    p1 = pk;
  }
  *p = (n == 0) ? 1.0 : p1;
  *dp = n * (x * p1 - p0) / (x * x - 1.0);
}

static void build_rule(int n) {
  for (int i = 0; i < n; ++i) {
    double x = cos(M_PI * (i + 0.75) / (n + 0.5));
    for (int it = 0; it < 100; ++it) {
      double p, dp;
      legendre(n, x, &p, &dp);
      double dx = p / dp;
      x -= dx;
      if (fabs(dx) < 1e-16) break;
    }
    double p, dp;
    legendre(n, x, &p, &dp);
    double w = 2.0 / ((1.0 - x * x) * dp * dp);
    /* map [-1, 1] -> [0, 1], ascending */
    rule_x[n][n - 1 - i] = 0.5 * (x + 1.0);
    rule_w[n][n - 1 - i] = 0.5 * w;
  }
}

static void build_rules(void) {
  for (int n = 2; n <= FMB_GAUSS_MAX; ++n) build_rule(n);
}

int fmb_gauss_legendre01(int n, double* x, double* w) {
  if (n < 1 || n > FMB_GAUSS_MAX || !x || !w) return -1;
  if (n == 1) {
    x[0] = 0.5;
    w[0] = 1.0;
    return 0;
  }
  pthread_once(&rules_once, build_rules);
  for (int i = 0; i < n; ++i) {
    x[i] = rule_x[n][i];
    w[i] = rule_w[n][i];
  }
  return 0;
}

/* Gauss-Lobatto rules on [0, 1]: the two ends and the roots of P'_{n-1}, exact to degree 2n-3;
   weights 2 / (n (n-1) P_{n-1}(x_i)^2) on [-1, 1]. Used where an integrand must be sampled at
   the element ends (reduced integration against membrane locking). Newton on P'_{n-1} uses the
   Legendre equation (1 - x^2) P'' = 2x P' - k(k+1) P. */
int fmb_gauss_lobatto01(int n, double* x, double* w) {
  if (n < 2 || n > FMB_GAUSS_MAX || !x || !w) return -1;
  const int k = n - 1;
  for (int i = 0; i < n; ++i) {
    double t = -cos(M_PI * i / k); /* Chebyshev-Lobatto guess, ascending */
    if (i > 0 && i < k)
      for (int it = 0; it < 100; ++it) {
        double p, dp;
        legendre(k, t, &p, &dp);
        double d2p = (2.0 * t * dp - k * (k + 1.0) * p) / (1.0 - t * t);
        double dt = dp / d2p;
        t -= dt;
        if (fabs(dt) < 1e-16) break;
      }
    double p = (i == 0) ? (k % 2 ? -1.0 : 1.0) : (i == k ? 1.0 : 0.0), dp;
    if (i > 0 && i < k) legendre(k, t, &p, &dp);
    x[i] = 0.5 * (t + 1.0);
    w[i] = 0.5 * 2.0 / (n * (double)k * p * p);
  }
  return 0;
}
