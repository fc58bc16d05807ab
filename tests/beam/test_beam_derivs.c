/*
 * test_beam_derivs.c — derivatives of the beam plugin against central differences.
 *
 * - marker position and angle derivatives wrt q (root, interior, element boundary, tip,
 *   off-axis points), all three models;
 * - at v = 0 (no damping) the residual is the gradient of U_e + U_g from `energy`;
 * - the kinetic energy from `energy` is 1/2 v^T M(q) v with M taken from the residual;
 * - U_e = 1/2 p^T K p with K p = R(q, 0, 0) without gravity;
 * - outputs: tip_x/tip_y agree with the marker at (L, 0); tip rates are d/dt of tip_u/tip_v;
 *   nodeNE_u/v equal tip_u/v; node0 is the frame origin; ang_momentum = dT/dtheta';
 * - the plugin's jacobian op, if any, against central differences of the residual.
 */
#include "beamtest.h"

/* which = 0: strain energy, 1: gravity potential */
static double energy_pot(const Beam* b, const fmbEnv* env, const double* q, const double* v, int which) {
  fmbEnergy e;
  beam_energy(b, env, q, v, &e, NULL);
  return which ? e.gravity : e.strain;
}

static double out(const Beam* b, const char* name, const double* q, const double* v) {
  int id = beam_output_lookup(b, name);
  ENSURE(id >= 0);
  double val = NAN;
  ENSURE(beam_output(b, id, q, v, &val, NULL) == 0);
  return val;
}

int main(void) {
  const char* names[] = {"zoac", "foac", "complete"};
  fmbEnv env = {.gravity = {0.7, -9.81}, .has_gravity = 1};
  fmbEnv env0 = {.gravity = {0.0, 0.0}, .has_gravity = 0};
  for (int model = 0; model < 3; ++model) {
    Beam* b = bt_seed_beam(model, 6);
    int nc = 3 + b->n;
    double* q = calloc(6 * (size_t)nc, sizeof(double));
    double *v = q + nc, *qp = v + nc, *R = qp + nc, *vz = R + nc, *az = vz + nc;
    q[0] = 0.3;
    q[1] = -0.2;
    q[2] = 0.7;
    v[0] = 0.4;
    v[1] = -1.1;
    v[2] = 2.3;
    for (int i = 3; i < nc; ++i) {
      int kind = (i - 3) % 3; /* u, v, v' */
      double node = (i - 3) / 3 + 1.0;
      q[i] = kind == 0 ? 1e-3 * bt_rand() : kind == 1 ? 0.02 * node * node / 36.0 * 5.0 : 0.1 * node / 6.0;
      q[i] += 0.01 * bt_rand();
      v[i] = 0.5 * bt_rand();
    }
    printf("%s:\n", names[model]);

    /* marker derivatives */
    double pts[][2] = {{0.0, 0.0}, {0.37, 0.0}, {0.6, 0.0}, {1.1, 0.004}, {SEED_L, 0.0}, {SEED_L, -0.01}};
    double worst_pos = 0.0, worst_ang = 0.0;
    for (size_t k = 0; k < sizeof pts / sizeof pts[0]; ++k) {
      double pos[2], ang, dpos[2 * 64], dang[64];
      ENSURE(nc <= 64);
      ENSURE(beam_marker(b, q, pts[k], pos, &ang, dpos, dang, NULL) == 0);
      for (int j = 0; j < nc; ++j) {
        double h = 1e-6, pp[2], pm[2], ap, am;
        memcpy(qp, q, sizeof(double) * (size_t)nc);
        qp[j] += h;
        beam_marker(b, qp, pts[k], pp, &ap, NULL, NULL, NULL);
        qp[j] -= 2.0 * h;
        beam_marker(b, qp, pts[k], pm, &am, NULL, NULL, NULL);
        for (int r = 0; r < 2; ++r) worst_pos = fmax(worst_pos, fabs((pp[r] - pm[r]) / (2.0 * h) - dpos[r * nc + j]));
        worst_ang = fmax(worst_ang, fabs((ap - am) / (2.0 * h) - dang[j]));
      }
    }
    printf("  marker: worst |dpos/dq - FD| = %.2e, |dangle/dq - FD| = %.2e\n", worst_pos, worst_ang);
    ENSURE(worst_pos < 1e-8);
    ENSURE(worst_ang < 1e-8);

    /* R(q, 0, 0) = grad (U_e + U_g), each part on its own: the elastic part without gravity,
       the gravity part as the difference of residuals with and without it */
    for (int g = 0; g < 2; ++g) {
      const fmbEnv* e = g ? &env : &env0;
      bt_residual(b, e, q, vz, az, R);
      if (g) {
        double* R0 = malloc(sizeof(double) * (size_t)nc);
        bt_residual(b, &env0, q, vz, az, R0);
        for (int j = 0; j < nc; ++j) R[j] -= R0[j];
        free(R0);
      }
      double worst = 0.0, scale = 0.0;
      for (int j = 0; j < nc; ++j) {
        double h = j < 3 ? 1e-4 : 1e-6;
        memcpy(qp, q, sizeof(double) * (size_t)nc);
        qp[j] += h;
        double up = energy_pot(b, e, qp, vz, g);
        qp[j] -= 2.0 * h;
        double um = energy_pot(b, e, qp, vz, g);
        double fd = (up - um) / (2.0 * h);
        worst = fmax(worst, fabs(fd - R[j]));
        scale = fmax(scale, fabs(R[j]));
      }
      printf("  R(q,0,0) vs grad %s: worst %.2e of %.2e\n", g ? "U_g (gravity part)" : "U_e", worst, scale);
      ENSURE(worst < (g ? 1e-8 : 1e-6) * scale);
    }

    /* U_e = 1/2 p^T K p, K p = R(q, 0, 0) without gravity */
    {
      bt_residual(b, &env0, q, vz, az, R);
      double pkp = 0.0;
      for (int i = 3; i < nc; ++i) pkp += q[i] * R[i];
      fmbEnergy en;
      beam_energy(b, &env0, q, v, &en, NULL);
      ENSURE_NEAR(en.strain, 0.5 * pkp, 1e-12 * en.strain);
      ENSURE(R[0] == 0.0 && R[1] == 0.0);
    }

    /* T = 1/2 v^T M v */
    {
      double* M = malloc(sizeof(double) * (size_t)nc * (size_t)nc);
      bt_mass(b, q, v, M);
      double vMv = 0.0;
      for (int i = 0; i < nc; ++i)
        for (int j = 0; j < nc; ++j) vMv += v[i] * M[i + (size_t)j * nc] * v[j];
      fmbEnergy en;
      beam_energy(b, &env, q, v, &en, NULL);
      printf("  T = %.12g, 1/2 v^T M v = %.12g\n", en.kinetic, 0.5 * vMv);
      ENSURE_NEAR(en.kinetic, 0.5 * vMv, 1e-9 * en.kinetic);
      free(M);
    }

    /* outputs */
    {
      double tipl[2] = {SEED_L, 0.0}, pos[2], ang;
      beam_marker(b, q, tipl, pos, &ang, NULL, NULL, NULL);
      ENSURE_NEAR(out(b, "tip_x", q, v), pos[0], 1e-14);
      ENSURE_NEAR(out(b, "tip_y", q, v), pos[1], 1e-14);
      char nm[32];
      snprintf(nm, sizeof nm, "node%d_u", b->ne);
      ENSURE_NEAR(out(b, nm, q, v), out(b, "tip_u", q, v), 1e-15);
      snprintf(nm, sizeof nm, "node%d_v", b->ne);
      ENSURE_NEAR(out(b, nm, q, v), out(b, "tip_v", q, v), 1e-15);
      ENSURE_NEAR(out(b, "node0_x", q, v), q[0], 1e-15);
      ENSURE_NEAR(out(b, "node0_y", q, v), q[1], 1e-15);
      ENSURE_NEAR(out(b, "node2_v", q, v), q[3 + 3 * 1 + 1], 1e-15);
      double uL = q[3 + 3 * (b->ne - 1)], vL = q[3 + 3 * (b->ne - 1) + 1];
      if (model == BEAM_ZOAC)
        ENSURE_NEAR(out(b, "tip_u", q, v), uL, 1e-15);
      else
        ENSURE(out(b, "tip_u", q, v) < uL); /* w_c shortens */
      ENSURE_NEAR(out(b, "tip_v", q, v), vL, 1e-15);
      /* rates: d/dt along v */
      const char* pairs[2][2] = {{"tip_u", "tip_u_rate"}, {"tip_v", "tip_v_rate"}};
      for (int k = 0; k < 2; ++k) {
        double h = 1e-6;
        for (int i = 0; i < nc; ++i) qp[i] = q[i] + h * v[i];
        double fp = out(b, pairs[k][0], qp, v);
        for (int i = 0; i < nc; ++i) qp[i] = q[i] - h * v[i];
        double fm = out(b, pairs[k][0], qp, v);
        ENSURE_NEAR(out(b, pairs[k][1], q, v), (fp - fm) / (2.0 * h), 1e-8);
      }
      /* ang_momentum = dT/dtheta' */
      {
        double h = 1e-5, vp[64], tp, tm;
        memcpy(vp, v, sizeof(double) * (size_t)nc);
        fmbEnergy en;
        vp[2] = v[2] + h;
        beam_energy(b, &env0, q, vp, &en, NULL);
        tp = en.kinetic;
        vp[2] = v[2] - h;
        beam_energy(b, &env0, q, vp, &en, NULL);
        tm = en.kinetic;
        double pth = out(b, "ang_momentum", q, v);
        ENSURE_NEAR(pth, (tp - tm) / (2.0 * h), 1e-8 * fabs(pth));
      }
      ENSURE(beam_output_lookup(b, "node99_u") == -1);
      ENSURE(beam_output_lookup(b, "node1_") == -1);
      ENSURE(beam_output_lookup(b, "node1_q") == -1);
      ENSURE(beam_output_lookup(b, "nodex_u") == -1);
      ENSURE(beam_output_lookup(b, "tip") == -1);
    }

    /* the plugin's analytic jacobian, if it has one */
    if (fmb_body_beam.jacobian) {
      double* a = calloc((size_t)nc, sizeof(double));
      for (int i = 0; i < nc; ++i) a[i] = (i < 3 ? 1.0 : 0.05) * bt_rand();
      size_t nn = (size_t)nc * (size_t)nc;
      double* K = malloc(sizeof(double) * nn * 3);
      double *C = K + nn, *Mj = C + nn;
      double* w = bt_work(b);
      ENSURE(fmb_body_beam.jacobian(b, &env, q, v, a, K, C, Mj, w) == 0);
      double* Rp = malloc(sizeof(double) * (size_t)nc * 2);
      double* Rm = Rp + nc;
      const double* args[3] = {q, v, a};
      double* blocks[3] = {K, C, Mj};
      const char* bn[3] = {"K = dR/dq", "C = dR/dv", "M = dR/da"};
      for (int which = 0; which < 3; ++which) {
        double worst = 0.0, scale = 0.0;
        double* x = malloc(sizeof(double) * (size_t)nc);
        for (int j = 0; j < nc; ++j) {
          /* R is linear in a and quadratic in v, so a unit step is exact there (central) and
             keeps the round-off of the large elastic forces (|R| ~ 1e6, eps |R| / h) out of C, M */
          double h = which == 0 ? 1e-6 * fmax(1.0, fabs(args[which][j])) : 1.0;
          memcpy(x, args[which], sizeof(double) * (size_t)nc);
          x[j] += h;
          beam_residual(b, &env, which == 0 ? x : q, which == 1 ? x : v, which == 2 ? x : a, Rp, w);
          x[j] -= 2.0 * h;
          beam_residual(b, &env, which == 0 ? x : q, which == 1 ? x : v, which == 2 ? x : a, Rm, w);
          for (int i = 0; i < nc; ++i) {
            double fd = (Rp[i] - Rm[i]) / (2.0 * h);
            worst = fmax(worst, fabs(fd - blocks[which][i + (size_t)j * nc]));
            scale = fmax(scale, fabs(fd));
          }
        }
        printf("  jacobian %s: worst %.2e of %.2e\n", bn[which], worst, scale);
        ENSURE(worst < 1e-6 * scale);
        free(x);
      }
      free(w);
      free(Rp);
      free(K);
      free(a);
    }
    free(q);
    free(b);
  }
  return fmbt_finish("test_beam_derivs");
}
