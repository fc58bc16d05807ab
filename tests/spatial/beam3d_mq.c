/* beam3d_mq.c — the spatial beam's M and Q in the quasi-velocities of docs/formulation-3d.md
 * (nu = [R^T r0', omega (body frame), p'], Eqs. 3D.20-3D.24), read off the C residual alone, for
 * test_beam3d_mq.py to compare with tools/spatial_refs/beam3d_ref.py --mq.
 *
 *   beam3d_mq SCENE.yaml STATE.txt    (STATE: q then v = q' of the scene's one body, 2 (7 + n) numbers)
 *
 * The residual is linear in a = q'': for each unit quasi-acceleration nu' = E_k it chooses the a
 * that gives it (r0'' = R (v0' + omega x v0), e'' = 1/2 L^T (omega' + (2 e.e'/|e|^2) omega)
 * - (|e'|^2/|e|^2) e, which also zeroes the gauge e.e'' + e'.e'), maps the rows back to the
 * quasi-velocity equations (R^T on the r0 rows, 1/2 L(e) on the e rows) and prints
 * M[:, k] = (F(u E_k) - F(0)) / u (u = 1e6), then Q = -F(0): (6 + n) lines of M, one line of Q, then
 * "marker ERR_POS SCALE_POS ERR_ROT SCALE_ROT": marker3's derivatives against central differences. */
#include <math.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>

#include "builtin.h"
#include "internal.h"

/* the unit acceleration: large, so that M's columns stand far above the rounding of Q (K p is
   1e5 times M's entries at the test's state); the residual is linear in a, so this is exact */
#define UNIT 1e6

static void lmat(const double* e, double L[3][4]) {
  const double rows[3][4] = {{-e[1], e[0], e[3], -e[2]}, {-e[2], -e[3], e[0], e[1]}, {-e[3], e[2], -e[1], e[0]}};
  memcpy(L, rows, sizeof rows);
}

int main(int argc, char** argv) {
  if (argc != 3) return fprintf(stderr, "usage: beam3d_mq SCENE.yaml STATE.txt\n"), 2;
  fmbDiag d;
  fmbModel* m = fmb_load(argv[1], NULL, 0, fmb_builtin_registry(), &d);
  if (!m) return fprintf(stderr, "%s\n", d.msg), 2;
  const fmbBodyInst* b = &m->body[1];
  const int nc = b->nq, nq = nc - 1; /* quasi-velocities: 6 + n = nc - 1 */
  double *q = calloc(nc, sizeof *q), *v = calloc(nc, sizeof *v), *a = calloc(nc, sizeof *a);
  double *Res = calloc(nc, sizeof *Res), *F0 = calloc(nq, sizeof *F0), *F = calloc(nq, sizeof *F);
  double* work = calloc(b->nwork + 1, sizeof *work);
  FILE* f = fopen(argv[2], "r");
  if (!f || !q || !v || !a || !Res || !F0 || !F || !work) return fprintf(stderr, "cannot read %s\n", argv[2]), 2;
  for (int i = 0; i < 2 * nc; ++i)
    if (fscanf(f, "%lf", i < nc ? &q[i] : &v[i - nc]) != 1) return fprintf(stderr, "short state\n"), 2;
  fclose(f);
  const double* e = q + 3;
  const double* ed = v + 3;
  const double n2 = e[0] * e[0] + e[1] * e[1] + e[2] * e[2] + e[3] * e[3];
  double R[9], L[3][4], v0[3], w[3], wxv0[3];
  fmb_quat_matrix(e, R);
  lmat(e, L);
  double eed = 0.0, eded = 0.0;
  for (int k = 0; k < 4; ++k) eed += e[k] * ed[k], eded += ed[k] * ed[k];
  for (int i = 0; i < 3; ++i) {
    v0[i] = R[i] * v[0] + R[3 + i] * v[1] + R[6 + i] * v[2];
    w[i] = 2.0 / n2 * (L[i][0] * ed[0] + L[i][1] * ed[1] + L[i][2] * ed[2] + L[i][3] * ed[3]);
  }
  wxv0[0] = w[1] * v0[2] - w[2] * v0[1], wxv0[1] = w[2] * v0[0] - w[0] * v0[2], wxv0[2] = w[0] * v0[1] - w[1] * v0[0];
  for (int k = -1; k < nq; ++k) {
    double nud[6] = {0};
    memset(a, 0, nc * sizeof *a);
    if (k >= 0 && k < 6) nud[k] = UNIT;
    if (k >= 6) a[7 + k - 6] = UNIT;
    double t[3], wd[3];
    for (int i = 0; i < 3; ++i) t[i] = nud[i] + wxv0[i], wd[i] = nud[3 + i] + 2.0 * eed / n2 * w[i];
    for (int i = 0; i < 3; ++i) a[i] = R[3 * i] * t[0] + R[3 * i + 1] * t[1] + R[3 * i + 2] * t[2];
    for (int j = 0; j < 4; ++j)
      a[3 + j] = 0.5 * (L[0][j] * wd[0] + L[1][j] * wd[1] + L[2][j] * wd[2]) - eded / n2 * e[j];
    if (b->type->residual(b->self, &m->env, q, v, a, Res, work)) return fprintf(stderr, "residual failed\n"), 3;
    double* out = k < 0 ? F0 : F;
    for (int i = 0; i < 3; ++i) out[i] = R[i] * Res[0] + R[3 + i] * Res[1] + R[6 + i] * Res[2];
    for (int i = 0; i < 3; ++i)
      out[3 + i] = 0.5 * (L[i][0] * Res[3] + L[i][1] * Res[4] + L[i][2] * Res[5] + L[i][3] * Res[6]);
    for (int i = 7; i < nc; ++i) out[i - 1] = Res[i];
    if (k < 0) continue;
    for (int i = 0; i < nq; ++i) printf("%.17g%c", (F[i] - F0[i]) / UNIT, i + 1 < nq ? ' ' : '\n');
  }
  for (int i = 0; i < nq; ++i) printf("%.17g%c", -F0[i], i + 1 < nq ? ' ' : '\n');
  /* the marker at a section point off the axis inside an element: dpos/dq and the virtual rotation
     G (d(R u)/dq_k = G_k x R u) against central differences of marker3's position and R */
  {
    const double local[3] = {0.37 * 1.8, 0.004, -0.003};
    double* dp = calloc(3 * (size_t)nc, sizeof *dp);
    double* G = calloc(3 * (size_t)nc, sizeof *G);
    double pos[3], Rm[9], pp[3], pm[3], Rp[9], Rmm[9], err_p = 0.0, err_r = 0.0, scale_p = 0.0, scale_r = 0.0;
    if (!dp || !G || b->marker3(b->self, q, local, pos, Rm, dp, G, nc, work)) return fprintf(stderr, "marker3\n"), 3;
    for (int k = 0; k < nc; ++k) {
      const double h = 1e-6, qk = q[k];
      q[k] = qk + h;
      b->marker3(b->self, q, local, pp, Rp, NULL, NULL, nc, work);
      q[k] = qk - h;
      b->marker3(b->self, q, local, pm, Rmm, NULL, NULL, nc, work);
      q[k] = qk;
      for (int i = 0; i < 3; ++i) {
        const double fd = (pp[i] - pm[i]) / (2 * h);
        err_p = fmax(err_p, fabs(fd - dp[i * nc + k])), scale_p = fmax(scale_p, fabs(fd));
      }
      for (int c = 0; c < 3; ++c) { /* column c of R: dR/dq_k u = G_k x (R u) */
        const double g[3] = {G[k], G[nc + k], G[2 * nc + k]}, u[3] = {Rm[c], Rm[3 + c], Rm[6 + c]};
        const double gx[3] = {g[1] * u[2] - g[2] * u[1], g[2] * u[0] - g[0] * u[2], g[0] * u[1] - g[1] * u[0]};
        for (int i = 0; i < 3; ++i) {
          const double fd = (Rp[3 * i + c] - Rmm[3 * i + c]) / (2 * h);
          err_r = fmax(err_r, fabs(fd - gx[i])), scale_r = fmax(scale_r, fabs(fd));
        }
      }
    }
    printf("marker %.3e %.3e %.3e %.3e\n", err_p, scale_p, err_r, scale_r);
    free(dp), free(G);
  }
  free(q), free(v), free(a), free(Res), free(F0), free(F), free(work);
  fmb_free(m);
  return 0;
}
