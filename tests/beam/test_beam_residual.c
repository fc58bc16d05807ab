/*
 * test_beam_residual.c — the fast O(n) beam residual against slow, obviously correct forms.
 *
 * 1. Slow: at every quadrature point form J_R, J_D, J_C densely (2 x ncoord, body frame) with a
 *    dense H(x), then M = sum m J^T J, Q = -sum m J^T g + sum m J^T f (FOAC: the bilinear
 *    products of formulation §4), and R = M a - Q + K p + beta K pd with K assembled by
 *    quadrature of N1'^T N1' and N2''^T N2''. Own shape functions, own quadrature counts.
 * 2. ZOAC and FOAC against the seed's constant-matrix form (formulation §6, seed Eqs. 19-30).
 * 3. Quadrature: the residual (integrated exactly, by moments) does not change with the Gauss point
 *    count; the Jacobian (summed over the Gauss points) does when there are too few.
 * 4. The mass matrix extracted from the residual is symmetric.
 */
#include "beamtest.h"

/* dense shape rows over p (length n) at reference x: N1, N2, N2' and N2'' */
static void shape_rows(const Beam* b, double x, double* n1, double* n2, double* n2d, double* n2dd) {
  int n = b->n, ne = b->ne;
  double le = b->L / ne;
  memset(n1, 0, sizeof(double) * (size_t)n);
  memset(n2, 0, sizeof(double) * (size_t)n);
  memset(n2d, 0, sizeof(double) * (size_t)n);
  if (n2dd) memset(n2dd, 0, sizeof(double) * (size_t)n);
  int e = (int)(x / le);
  if (e >= ne) e = ne - 1;
  double s = (x - e * le) / le;
  /* node e (left) and e+1 (right); Hermite written in the local coordinate s */
  double val[4] = {1 - 3 * s * s + 2 * s * s * s, le * (s - 2 * s * s + s * s * s), 3 * s * s - 2 * s * s * s,
                   le * (s * s * s - s * s)};
  double dv[4] = {(6 * s * s - 6 * s) / le, 3 * s * s - 4 * s + 1, (6 * s - 6 * s * s) / le, 3 * s * s - 2 * s};
  double ddv[4] = {(12 * s - 6) / (le * le), (6 * s - 4) / le, (6 - 12 * s) / (le * le), (6 * s - 2) / le};
  double lin[2] = {1 - s, s};
  for (int side = 0; side < 2; ++side) {
    int node = e + side;
    if (node == 0) continue;
    int base = 3 * (node - 1);
    n1[base] = lin[side];
    n2[base + 1] = val[2 * side];
    n2[base + 2] = val[2 * side + 1];
    n2d[base + 1] = dv[2 * side];
    n2d[base + 2] = dv[2 * side + 1];
    if (n2dd) {
      n2dd[base + 1] = ddv[2 * side];
      n2dd[base + 2] = ddv[2 * side + 1];
    }
  }
}

static double dotn(const double* a, const double* b, int n) {
  double s = 0.0;
  for (int i = 0; i < n; ++i) s += a[i] * b[i];
  return s;
}

/* dense H(x) = int_0^x N2'^T N2' (5-point Gauss on every inboard element and on [e*le, x]) */
static void dense_H(const Beam* b, double x, double* H) {
  int n = b->n;
  double le = b->L / b->ne, gx[5], gw[5];
  double* n1 = malloc(sizeof(double) * (size_t)n * 3);
  double* n2 = n1 + n;
  double* n2d = n2 + n;
  fmb_gauss_legendre01(5, gx, gw);
  memset(H, 0, sizeof(double) * (size_t)n * (size_t)n);
  for (double x0 = 0.0; x0 < x - 1e-14 * le; x0 += le) {
    double x1 = fmin(x0 + le, x), span = x1 - x0;
    for (int g = 0; g < 5; ++g) {
      shape_rows(b, x0 + gx[g] * span, n1, n2, n2d, NULL);
      for (int j = 0; j < n; ++j)
        for (int i = 0; i < n; ++i) H[i + j * n] += gw[g] * span * n2d[i] * n2d[j];
    }
  }
  free(n1);
}

typedef struct Slow {
  double *M, *Q, *K; /* nc x nc, nc, nc x nc (K: stiffness, on the p block) */
  double *C, *D;     /* n x n: int rho H, int rho x H */
} Slow;

/* slow reference: M and Q (inertia and gravity) of the given model, K */
static void slow_build(const Beam* b, const fmbEnv* env, const double* q, const double* v, Slow* S) {
  int n = b->n, nc = 3 + n, model = b->model, ngs = 8;
  double le = b->L / b->ne, gx[8], gw[8];
  fmb_gauss_legendre01(ngs, gx, gw);
  const double *p = q + 3, *pd = v + 3;
  double c = cos(q[2]), s = sin(q[2]), om = v[2];
  double At[2][2] = {{c, s}, {-s, c}}; /* A^T */
  double f[2] = {0.0, 0.0};
  if (env->has_gravity) {
    f[0] = c * env->gravity[0] + s * env->gravity[1];
    f[1] = -s * env->gravity[0] + c * env->gravity[1];
  }
  double* n1 = malloc(sizeof(double) * (size_t)n * 4);
  double *n2 = n1 + n, *n2d = n2 + n, *n2dd = n2d + n;
  double* H = malloc(sizeof(double) * (size_t)n * (size_t)n);
  double* h = malloc(sizeof(double) * (size_t)n * 2);
  double* hd = h + n;
  double* J = malloc(sizeof(double) * 2 * (size_t)nc * 4); /* JR, JD, JC, JRD: [row][col] */
  double *JR = J, *JD = J + 2 * nc, *JC = J + 4 * nc, *JRD = J + 6 * nc;
  memset(S->M, 0, sizeof(double) * (size_t)nc * (size_t)nc);
  memset(S->Q, 0, sizeof(double) * (size_t)nc);
  memset(S->K, 0, sizeof(double) * (size_t)nc * (size_t)nc);
  memset(S->C, 0, sizeof(double) * (size_t)n * (size_t)n);
  memset(S->D, 0, sizeof(double) * (size_t)n * (size_t)n);
  double r = sqrt(b->Izz / b->A);
  for (int e = 0; e < b->ne; ++e)
    for (int g = 0; g < ngs; ++g) {
      double x = (e + gx[g]) * le;
      shape_rows(b, x, n1, n2, n2d, n2dd);
      dense_H(b, x, H);
      for (int i = 0; i < n; ++i) {
        h[i] = dotn(H + (size_t)i * n, p, n);
        hd[i] = dotn(H + (size_t)i * n, pd, n);
      }
      double wc = -0.5 * dotn(p, h, n), wcd = -dotn(pd, h, n), pHp = dotn(pd, hd, n);
      double w1 = dotn(n1, p, n), w2 = dotn(n2, p, n), w2s = dotn(n2d, p, n);
      double w1d = dotn(n1, pd, n), w2d = dotn(n2, pd, n), w2sd = dotn(n2d, pd, n);
      double wx = gw[g] * le;
      for (int i = 0; i < n; ++i)
        for (int j = 0; j < n; ++j) {
          S->C[i + j * n] += wx * b->rho * b->A * H[i + j * n];
          S->D[i + j * n] += wx * b->rho * b->A * x * H[i + j * n];
        }
      /* stiffness */
      for (int i = 0; i < n; ++i)
        for (int j = 0; j < n; ++j) S->K[(3 + i) + (size_t)(3 + j) * nc] += wx * b->Emod * b->Izz * n2dd[i] * n2dd[j];
      for (int iy = 0; iy < 2; ++iy) {
        double y = iy ? r : -r, m = wx * b->rho * b->A * 0.5;
        double uD[2] = {w1 - y * w2s, w2}, uDd[2] = {w1d - y * w2sd, w2d};
        memset(J, 0, sizeof(double) * 2 * (size_t)nc * 4);
        for (int k = 0; k < 2; ++k)
          for (int l = 0; l < 2; ++l) JR[k * nc + l] = At[k][l];
        JR[0 * nc + 2] = -y;
        JR[1 * nc + 2] = x;
        JD[0 * nc + 2] = -uD[1];
        JD[1 * nc + 2] = uD[0];
        JC[0 * nc + 2] = 0.0;
        JC[1 * nc + 2] = wc;
        for (int i = 0; i < n; ++i) {
          JD[0 * nc + 3 + i] = n1[i] - y * n2d[i];
          JD[1 * nc + 3 + i] = n2[i];
          JC[0 * nc + 3 + i] = -h[i];
        }
        for (int i = 0; i < 2 * nc; ++i) JRD[i] = JR[i] + JD[i];
        double gR[2] = {-x * om * om, -y * om * om};
        double gD[2] = {-uD[0] * om * om - 2.0 * uDd[1] * om, -uD[1] * om * om + 2.0 * uDd[0] * om};
        double gC[2] = {-wc * om * om - pHp, 2.0 * wcd * om};
        double gRD[2] = {gR[0] + gD[0], gR[1] + gD[1]};
        /* (A^T X) products: sum over the two rows */
        for (int i = 0; i < nc; ++i) {
          for (int k = 0; k < 2; ++k) {
            double jrd = JRD[k * nc + i], jr = JR[k * nc + i], jc = JC[k * nc + i];
            double jall = jrd + jc;
            switch (model) {
              case BEAM_ZOAC: S->Q[i] += -m * jrd * gRD[k] + m * jrd * f[k]; break;
              case BEAM_FOAC: S->Q[i] += -m * (jrd * gRD[k] + jr * gC[k] + jc * gR[k]) + m * jall * f[k]; break;
              default: S->Q[i] += -m * jall * (gRD[k] + gC[k]) + m * jall * f[k]; break;
            }
            for (int j = 0; j < nc; ++j) {
              double krd = JRD[k * nc + j], kr = JR[k * nc + j], kc = JC[k * nc + j];
              double v2;
              switch (model) {
                case BEAM_ZOAC: v2 = jrd * krd; break;
                case BEAM_FOAC: v2 = jrd * krd + jr * kc + jc * kr; break;
                default: v2 = jall * (krd + kc); break;
              }
              S->M[i + (size_t)j * nc] += m * v2;
            }
          }
        }
      }
    }
  /* axial stiffness: EA int N1'^T N1' (piecewise constant derivative, one point per element) */
  for (int e = 0; e < b->ne; ++e) {
    int ia = e == 0 ? -1 : 3 + 3 * (e - 1), ib = 3 + 3 * e;
    double k = b->Emod * b->A / le;
    S->K[ib + (size_t)ib * nc] += k;
    if (ia >= 0) {
      S->K[ia + (size_t)ia * nc] += k;
      S->K[ia + (size_t)ib * nc] -= k;
      S->K[ib + (size_t)ia * nc] -= k;
    }
  }
  free(n1);
  free(H);
  free(h);
  free(J);
}

static void slow_alloc(Slow* S, int n) {
  int nc = 3 + n;
  S->M = malloc(sizeof(double) * (size_t)nc * (size_t)nc);
  S->K = malloc(sizeof(double) * (size_t)nc * (size_t)nc);
  S->Q = malloc(sizeof(double) * (size_t)nc);
  S->C = malloc(sizeof(double) * (size_t)n * (size_t)n);
  S->D = malloc(sizeof(double) * (size_t)n * (size_t)n);
}

static void slow_free(Slow* S) {
  free(S->M);
  free(S->K);
  free(S->Q);
  free(S->C);
  free(S->D);
}

/* compare R_fast with R = M a - Q + K (p + beta pd), per row against the row's own scale */
static double compare(const Beam* b, const Slow* S, const double* q, const double* v, const double* a, const double* Rf,
                      const char* what) {
  int nc = 3 + b->n;
  double worst = 0.0;
  for (int i = 0; i < nc; ++i) {
    double r = -S->Q[i], scale = fabs(S->Q[i]);
    for (int j = 0; j < nc; ++j) {
      double t = S->M[i + (size_t)j * nc] * a[j];
      double k = S->K[i + (size_t)j * nc] * (q[j] + b->beta * v[j]);
      if (j < 3) k = 0.0;
      r += t + k;
      scale += fabs(t) + fabs(k);
    }
    double rel = fabs(Rf[i] - r) / (scale > 0.0 ? scale : 1.0);
    if (rel > worst) worst = rel;
  }
  printf("  %-44s worst row error / row scale = %.2e\n", what, worst);
  return worst;
}

static void random_state(const Beam* b, double amp, double* q, double* v, double* a) {
  int nc = 3 + b->n;
  for (int i = 0; i < nc; ++i) {
    double sc = i < 3 ? 1.0 : amp;
    q[i] = sc * bt_rand();
    v[i] = 3.0 * sc * bt_rand();
    a[i] = 10.0 * sc * bt_rand();
  }
  /* make slopes comparable to displacement/length */
  for (int i = 3; i < nc; i += 3) q[i] *= 0.1; /* axial smaller than transverse */
}

/* the seed's constant-matrix form (formulation §6) for ZOAC and FOAC: R = M a - Q + K p */
static void seed_form(const Beam* b, const fmbEnv* env, const Slow* S, const double* q, const double* v,
                      const double* a, double* R) {
  int n = b->n, nc = 3 + n, foac = b->model == BEAM_FOAC, ngs = 8;
  double le = b->L / b->ne, gx[8], gw[8];
  fmb_gauss_legendre01(ngs, gx, gw);
  const double *p = q + 3, *pd = v + 3, *pdd = a + 3;
  double rho = b->rho, Ar = b->A, I = b->Izz, L = b->L;
  double m = rho * Ar * L, E1 = rho * Ar * L * L / 2.0, J11 = rho * Ar * L * L * L / 3.0, J22 = rho * L * I;
  /* vectors Y1, Y2, Ybar2, Z11, Z12 and matrices W11, W12, W21, W22, Wbar22 */
  double* buf = calloc((size_t)(5 * n + 5 * n * n + 4 * n), sizeof(double));
  double *Y1 = buf, *Y2 = Y1 + n, *Yb2 = Y2 + n, *Z11 = Yb2 + n, *Z12 = Z11 + n;
  double *W11 = Z12 + n, *W12 = W11 + n * n, *W21 = W12 + n * n, *W22 = W21 + n * n, *Wb22 = W22 + n * n;
  double *n1 = Wb22 + n * n, *n2 = n1 + n, *n2d = n2 + n, *n2dd = n2d + n;
  for (int e = 0; e < b->ne; ++e)
    for (int g = 0; g < ngs; ++g) {
      double x = (e + gx[g]) * le, w = gw[g] * le * rho;
      shape_rows(b, x, n1, n2, n2d, n2dd);
      for (int i = 0; i < n; ++i) {
        Y1[i] += w * Ar * n1[i];
        Y2[i] += w * Ar * n2[i];
        Yb2[i] += w * I * n2d[i];
        Z11[i] += w * Ar * x * n1[i];
        Z12[i] += w * Ar * x * n2[i];
        for (int j = 0; j < n; ++j) {
          W11[i + j * n] += w * Ar * n1[i] * n1[j];
          W12[i + j * n] += w * Ar * n1[i] * n2[j];
          W21[i + j * n] += w * Ar * n2[i] * n1[j];
          W22[i + j * n] += w * Ar * n2[i] * n2[j];
          Wb22[i + j * n] += w * I * n2d[i] * n2d[j];
        }
      }
    }
  double th = q[2], om = v[2], c = cos(th), s = sin(th);
  double Y1p = dotn(Y1, p, n), Y2p = dotn(Y2, p, n), Y1pd = dotn(Y1, pd, n), Y2pd = dotn(Y2, pd, n);
  double Z11p = dotn(Z11, p, n), Z11pd = dotn(Z11, pd, n);
  double *Cp = calloc(6 * (size_t)n, sizeof(double)), *Cpd = Cp + n, *Dp = Cpd + n, *Dpd = Dp + n;
  double *Wp = Dpd + n, *Wpd = Wp + n; /* (W11+W22+Wb22) p, and W12^T - W21^T ... below */
  for (int i = 0; i < n; ++i)
    for (int j = 0; j < n; ++j) {
      Cp[i] += S->C[i + j * n] * p[j];
      Cpd[i] += S->C[i + j * n] * pd[j];
      Dp[i] += S->D[i + j * n] * p[j];
      Dpd[i] += S->D[i + j * n] * pd[j];
      double wsum = W11[i + j * n] + W22[i + j * n] + Wb22[i + j * n];
      Wp[i] += wsum * p[j];
      Wpd[i] += wsum * pd[j];
    }
  double pCp = dotn(p, Cp, n), pCpd = dotn(p, Cpd, n), pdCpd = dotn(pd, Cpd, n), pDp = dotn(p, Dp, n);
  double pDpd = dotn(p, Dpd, n);
  double F = foac ? 1.0 : 0.0;
  /* M12 = A [-Y2 p ; E1 + Y1 p - F p^T C p / 2], M13 = A [Y1 - F p^T C ; Y2] */
  double b12[2] = {-Y2p, E1 + Y1p - F * pCp / 2.0};
  double M12[2] = {c * b12[0] - s * b12[1], s * b12[0] + c * b12[1]};
  double M22 = J11 + J22 + 2.0 * Z11p - F * pDp + dotn(p, Wp, n);
  /* Q1 = A [F pd^T C pd ; 0] - 2 A om [-Y2 pd ; Y1 pd - F p^T C pd] + A om^2 [E1 + Y1 p - F pCp/2 ; Y2 p] */
  double q1b[2] = {F * pdCpd + 2.0 * om * Y2pd + om * om * (E1 + Y1p - F * pCp / 2.0),
                   -2.0 * om * (Y1pd - F * pCpd) + om * om * Y2p};
  double Q1[2] = {c * q1b[0] - s * q1b[1], s * q1b[0] + c * q1b[1]};
  double Q2 = -2.0 * om * (Z11pd - F * pDpd + dotn(p, Wpd, n));
  /* body force f' (per unit mass, body frame): fr = m g, f_theta, f_p (seed Eqs. 28-30) */
  double f[2] = {0.0, 0.0};
  if (env->has_gravity) {
    f[0] = c * env->gravity[0] + s * env->gravity[1];
    f[1] = -s * env->gravity[0] + c * env->gravity[1];
  }
  double fth = -f[0] * Y2p + f[1] * (E1 + Y1p - F * pCp / 2.0);
  /* rows r0 */
  double M13a[2];
  for (int k = 0; k < 2; ++k) {
    R[k] = m * a[k] + M12[k] * a[2] - Q1[k] - m * (env->has_gravity ? env->gravity[k] : 0.0);
  }
  for (int i = 0; i < n; ++i) {
    double b13[2] = {Y1[i] - F * Cp[i], Y2[i]};
    M13a[0] = c * b13[0] - s * b13[1];
    M13a[1] = s * b13[0] + c * b13[1];
    R[0] += M13a[0] * pdd[i];
    R[1] += M13a[1] * pdd[i];
  }
  /* row theta: M21 r0dd + M22 thdd + M23 pdd - Q2 - f_theta; M23 = Z12 + Ybar2 + p^T (W12 - W21) */
  R[2] = M12[0] * a[0] + M12[1] * a[1] + M22 * a[2] - Q2 - fth;
  for (int i = 0; i < n; ++i) {
    double m23 = Z12[i] + Yb2[i];
    for (int j = 0; j < n; ++j) m23 += p[j] * (W12[j + i * n] - W21[j + i * n]);
    R[2] += m23 * pdd[i];
  }
  /* rows p: M31 r0dd + M32 thdd + M33 pdd - Q3 - f_p + K p, with M33 = W11 + W22 + Wb22 and
     Q3 = om^2 (Z11 - F D p) + om^2 (W11 + W22 + Wb22) p + 2 (W12 - W21) om pd */
  for (int i = 0; i < n; ++i) {
    double b13[2] = {Y1[i] - F * Cp[i], Y2[i]};
    double m31[2] = {c * b13[0] - s * b13[1], s * b13[0] + c * b13[1]};
    double m23 = Z12[i] + Yb2[i];
    for (int j = 0; j < n; ++j) m23 += p[j] * (W12[j + i * n] - W21[j + i * n]);
    double r = m31[0] * a[0] + m31[1] * a[1] + m23 * a[2];
    double q3 = om * om * (Z11[i] - F * Dp[i]) + om * om * Wp[i];
    for (int j = 0; j < n; ++j) {
      r += (W11[i + j * n] + W22[i + j * n] + Wb22[i + j * n]) * pdd[j];
      q3 += 2.0 * om * (W12[i + j * n] - W21[i + j * n]) * pd[j];
      r += S->K[(3 + i) + (size_t)(3 + j) * nc] * p[j];
    }
    double fp = f[0] * Y1[i] + f[1] * Y2[i] - F * f[0] * Cp[i];
    R[3 + i] = r - q3 - fp;
  }
  free(buf);
  free(Cp);
}

int main(void) {
  const char* names[] = {"zoac", "foac", "complete"};
  fmbEnv env = {.gravity = {0.3, -9.81}, .has_gravity = 1};
  /* 1. fast vs slow, all three models, with and without gravity and damping */
  for (int model = 0; model < 3; ++model) {
    for (int trial = 0; trial < 3; ++trial) {
      int ne = 3 + 2 * trial;
      Beam* b = bt_seed_beam(model, ne);
      b->beta = trial == 1 ? 1e-3 : 0.0;
      int nc = 3 + b->n;
      double *q = malloc(sizeof(double) * 4 * (size_t)nc), *v = q + nc, *a = v + nc, *Rf = a + nc;
      random_state(b, 0.05 * (trial + 1), q, v, a);
      fmbEnv* e = trial == 2 ? &(fmbEnv){.gravity = {0.0, 0.0}, .has_gravity = 0} : &env;
      bt_residual(b, e, q, v, a, Rf);
      Slow S;
      slow_alloc(&S, b->n);
      slow_build(b, e, q, v, &S);
      char what[128];
      snprintf(what, sizeof what, "%s, %d elements, fast vs slow", names[model], ne);
      ENSURE(compare(b, &S, q, v, a, Rf, what) < 1e-12);
      /* the extracted mass matrix is symmetric */
      double* M = malloc(sizeof(double) * (size_t)nc * (size_t)nc);
      bt_mass(b, q, v, M);
      double asym = 0.0, mx = 0.0;
      for (int i = 0; i < nc; ++i)
        for (int j = 0; j < nc; ++j) {
          asym = fmax(asym, fabs(M[i + j * nc] - M[j + i * nc]));
          mx = fmax(mx, fabs(M[i + j * nc]));
        }
      ENSURE(asym <= 1e-12 * mx);
      /* 2. seed constant-matrix form (ZOAC, FOAC) */
      if (model != BEAM_COMPLETE && b->beta == 0.0) {
        double* Rs = malloc(sizeof(double) * (size_t)nc);
        seed_form(b, e, &S, q, v, a, Rs);
        snprintf(what, sizeof what, "%s, %d elements, fast vs seed matrices", names[model], ne);
        double worst = 0.0;
        for (int i = 0; i < nc; ++i) {
          double sc = 0.0;
          for (int j = 0; j < nc; ++j)
            sc += fabs(S.M[i + (size_t)j * nc] * a[j]) + fabs(S.K[i + (size_t)j * nc] * q[j]);
          sc += fabs(S.Q[i]);
          worst = fmax(worst, fabs(Rs[i] - Rf[i]) / sc);
        }
        printf("  %-44s worst row error / row scale = %.2e\n", what, worst);
        ENSURE(worst < 1e-12);
        free(Rs);
      }
      /* 3. quadrature: more Gauss points, same residual */
      Beam* b10 = bt_beam(model, ne, FMB_GAUSS_MAX, SEED_L, SEED_RHO, SEED_A, SEED_I, SEED_E);
      b10->beta = b->beta;
      double* R10 = malloc(sizeof(double) * (size_t)nc);
      bt_residual(b10, e, q, v, a, R10);
      snprintf(what, sizeof what, "%s, %d elements, %d vs %d Gauss points", names[model], ne, b->ng, FMB_GAUSS_MAX);
      ENSURE(compare(b10, &S, q, v, a, R10, what) < 1e-12);
      free(R10);
      free(b10);
      free(M);
      slow_free(&S);
      free(q);
      free(b);
    }
  }
  /* The residual integrates its polynomials exactly (element_terms: moments, no Gauss points), so
     3 points change nothing there; the Jacobian still sums element_derivs over the Gauss points,
     and 3 are too few for the complete model's degree-10 terms: its M must move visibly (the
     check that can fail, and why quadrature_points may not go below the default) */
  {
    Beam* b = bt_seed_beam(BEAM_COMPLETE, 4);
    Beam* b3 = bt_beam(BEAM_COMPLETE, 4, 3, SEED_L, SEED_RHO, SEED_A, SEED_I, SEED_E);
    int nc = 3 + b->n;
    double *q = malloc(sizeof(double) * 5 * (size_t)nc), *v = q + nc, *a = v + nc, *R6 = a + nc, *R3 = R6 + nc;
    random_state(b, 0.3, q, v, a);
    bt_residual(b, &env, q, v, a, R6);
    bt_residual(b3, &env, q, v, a, R3);
    double d = 0.0, sc = 0.0;
    for (int i = 0; i < nc; ++i) {
      d = fmax(d, fabs(R6[i] - R3[i]));
      sc = fmax(sc, fabs(R6[i]));
    }
    printf("  complete, residual with 3 vs 6 Gauss points: relative change %.2e (exact integration: none)\n", d / sc);
    ENSURE(d / sc < 1e-14);
    const size_t nn = (size_t)nc * (size_t)nc;
    double* KCM = malloc(sizeof(double) * 6 * nn);
    double *w6 = bt_work(b), *w3 = bt_work(b3);
    ENSURE(beam_jacobian(b, &env, q, v, a, KCM, KCM + nn, KCM + 2 * nn, w6) == 0);
    ENSURE(beam_jacobian(b3, &env, q, v, a, KCM + 3 * nn, KCM + 4 * nn, KCM + 5 * nn, w3) == 0);
    d = sc = 0.0;
    for (size_t i = 2 * nn; i < 3 * nn; ++i) { /* M: K is dominated by the exact elastic part */
      d = fmax(d, fabs(KCM[i] - KCM[3 * nn + i]));
      sc = fmax(sc, fabs(KCM[i]));
    }
    printf("  complete, Jacobian's M with 3 Gauss points (too few): relative change %.2e (must be visible)\n", d / sc);
    ENSURE(d / sc > 1e-10);
    free(KCM);
    free(w6);
    free(w3);
    free(q);
    free(b);
    free(b3);
  }
  return fmbt_finish("test_beam_residual");
}
