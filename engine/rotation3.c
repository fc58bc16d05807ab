/* rotation3.c — what statics, steady states and modes need of a spatial scene (dimension 3,
 * docs/analysis.md "Spatial scenes"), type-agnostically, from each body's ops only:
 *
 *   - the gauge rows: the coordinate directions d no marker sees (fmbBodyType.gauge; rigid3d:
 *     d = [0, p], the length of its Euler parameters). Nothing physical holds them, so the static
 *     Newton matrix and the modal stiffness are singular along them; statics and modes add
 *     d^T dq = 0 beside the constraint rows (G1).
 *   - the rigid motions: a body moves rigidly with angular velocity Omega (global) and its frame
 *     origin r0 with velocity Omega x r0 - s when its coordinates move by the least-norm u with
 *         [dr0/dq; G; D^T] u = [Omega x r0 - s; Omega; 0]                                (G2)
 *     (marker3 at the body's origin: dr0/dq and the virtual rotation G; D its gauge rows). u is
 *     linear in z = [Omega; s]: u = V(q) z, V nq x 6. A rotation at speed W about the unit axis a
 *     through c is z = W [a; a x c].
 *   - a rigid body's u is affine in q (u = E q + b exactly, for Euler parameters of any length),
 *     so the acceleration of the steady rotation is a = (du/dq) v = u(q + v) - u(q) and the
 *     rotation's generator (modes.c (M1), static.c (S1)) is E e_j = u(q + e_j) - u(q)      (G3)
 *     for z of unit speed. A body whose origin marker leaves its elastic coordinates alone (a
 *     floating-frame beam) keeps them fixed (least norm). */
#include <math.h>
#include <stdlib.h>
#include <string.h>

#include "internal.h"

/* the refusals of a steady rotation, shared with the plane's fit (static.c; here so that the
   two files call in one direction) */
int fmb_steady_refusal(const fmbModel* m, int why, double t, double value, fmbDiag* diag) {
  if (why == FMB_STEADY_NOT_RIGID)
    fmb_diag_set(diag, FMB_EXIT_BAD_INPUT, m->path, 0, 0,
                 "at t = %g the drives do not turn the whole system as one rigid rotation (velocity constraints left "
                 "unsatisfied by %.3g): a steady state exists only for constant-speed rotation of everything about one "
                 "%s",
                 t, value,
                 m->dimension == 3 ? "axis (drive a hub on a revolute3d to the ground)"
                                   : "center (drive a hub pinned to the ground)");
  else
    fmb_diag_set(diag, FMB_EXIT_BAD_INPUT, m->path, 0, 0,
                 "at t = %g the drives are accelerating (Phi_tt = %.3g): no steady state; take a time after the ramp "
                 "(--at T) or a constant-speed drive",
                 t, value);
  return FMB_EXIT_BAD_INPUT;
}

/* gauge directions of one body (at most 8, a body's frame has one) */
#define GAUGE_MAX 8

int fmb_gauge_count(const fmbModel* m, const double* q) {
  int ng = 0;
  for (int b = 1; b < m->nbody; ++b) {
    const fmbBodyInst* bi = &m->body[b];
    if (bi->type && bi->gauge) ng += bi->gauge(bi->self, q + bi->qadr, NULL);
  }
  return ng;
}

int fmb_gauge_rows(const fmbModel* m, const double* q, double* D, int ld) {
  int ng = 0;
  for (int b = 1; b < m->nbody; ++b) {
    const fmbBodyInst* bi = &m->body[b];
    if (!bi->type || !bi->gauge) continue;
    const int k = bi->gauge(bi->self, q + bi->qadr, NULL);
    if (k <= 0) continue;
    double* dir = calloc((size_t)k * bi->nq + 1, sizeof(double));
    if (!dir || k > GAUGE_MAX) {
      free(dir);
      return -1;
    }
    bi->gauge(bi->self, q + bi->qadr, dir);
    for (int g = 0; g < k; ++g, ++ng) {
      double* col = D + (size_t)ng * ld;
      memset(col, 0, (size_t)m->nq * sizeof(double));
      memcpy(col + bi->qadr, dir + (size_t)g * bi->nq, (size_t)bi->nq * sizeof(double));
    }
    free(dir);
  }
  return ng;
}

/* (G2) for body bi at q: V's rows of the body (column-major, leading dimension nq) */
static int body_basis(const fmbModel* m, fmbWorkspace* w, const fmbBodyInst* bi, const double* q, double* V) {
  const int nb = bi->nq, nrow = 6 + GAUGE_MAX;
  const double* qb = q + bi->qadr;
  const double origin[3] = {0.0, 0.0, 0.0};
  double pos[3], R[9];
  double* A = calloc((size_t)nrow * nb, sizeof(double)); /* row-major nrow x nb */
  double AAt[(6 + GAUGE_MAX) * (6 + GAUGE_MAX)], rhs[6 + GAUGE_MAX];
  double dir[GAUGE_MAX * 64];
  int piv[6 + GAUGE_MAX];
  if (!A) return -1;
  int rc = bi->marker3(bi->self, qb, origin, pos, R, A, A + 3 * (size_t)nb, nb, fmb_workspace_plugin(w) + bi->workadr);
  int ng = bi->gauge ? bi->gauge(bi->self, qb, NULL) : 0;
  if (!rc && (ng < 0 || ng > GAUGE_MAX || (ng > 0 && (size_t)ng * nb > sizeof dir / sizeof *dir))) rc = -1;
  if (!rc && ng > 0) {
    bi->gauge(bi->self, qb, dir);
    memcpy(A + 6 * (size_t)nb, dir, (size_t)ng * nb * sizeof(double));
  }
  const int n = 6 + ng;
  if (!rc) {
    for (int i = 0; i < n; ++i)
      for (int j = 0; j < n; ++j) {
        double s = 0.0;
        for (int c = 0; c < nb; ++c) s += A[(size_t)i * nb + c] * A[(size_t)j * nb + c];
        AAt[j * n + i] = s;
      }
    rc = fmb_lu_factor(n, AAt, piv);
  }
  for (int col = 0; !rc && col < 6; ++col) {
    memset(rhs, 0, sizeof rhs);
    if (col < 3) { /* Omega = e_col: origin Omega x r0, rotation Omega */
      const double e[3] = {col == 0, col == 1, col == 2};
      rhs[0] = e[1] * pos[2] - e[2] * pos[1];
      rhs[1] = e[2] * pos[0] - e[0] * pos[2];
      rhs[2] = e[0] * pos[1] - e[1] * pos[0];
      rhs[3 + col] = 1.0;
    } else { /* s = e: origin -e */
      rhs[col - 3] = -1.0;
    }
    fmb_lu_solve(n, AAt, piv, rhs);
    double* out = V + (size_t)col * m->nq + bi->qadr;
    for (int c = 0; c < nb; ++c) {
      double s = 0.0;
      for (int i = 0; i < n; ++i) s += A[(size_t)i * nb + c] * rhs[i];
      out[c] = s;
    }
  }
  free(A);
  return rc ? -1 : 0;
}

int fmb_rotation3_basis(const fmbModel* m, fmbWorkspace* w, const double* q, double* V) {
  memset(V, 0, (size_t)m->nq * 6 * sizeof(double));
  for (int b = 1; b < m->nbody; ++b) {
    const fmbBodyInst* bi = &m->body[b];
    if (!bi->type || bi->nq == 0) continue;
    if (!bi->marker3 || body_basis(m, w, bi, q, V)) return -1;
  }
  return 0;
}

/* z = W [a; a x c] */
static void rotation_z(double speed, const double axis[3], const double center[3], double z[6]) {
  z[0] = speed * axis[0];
  z[1] = speed * axis[1];
  z[2] = speed * axis[2];
  z[3] = speed * (axis[1] * center[2] - axis[2] * center[1]);
  z[4] = speed * (axis[2] * center[0] - axis[0] * center[2]);
  z[5] = speed * (axis[0] * center[1] - axis[1] * center[0]);
}

/* u = V(q) z over all coordinates; V scratch nq x 6 */
static int velocity(const fmbModel* m, fmbWorkspace* w, const double* q, const double z[6], double* V, double* u) {
  if (fmb_rotation3_basis(m, w, q, V)) return -1;
  for (int i = 0; i < m->nq; ++i) {
    double s = 0.0;
    for (int j = 0; j < 6; ++j) s += V[(size_t)j * m->nq + i] * z[j];
    u[i] = s;
  }
  return 0;
}

int fmb_rigid_rotation3(const fmbModel* m, fmbWorkspace* w, const fmbRotation3* rot, const double* q, double* v,
                        double* a) {
  const int nq = m->nq;
  memset(v, 0, (size_t)nq * sizeof(double));
  memset(a, 0, (size_t)nq * sizeof(double));
  if (rot->speed == 0.0) return 0;
  double z[6];
  rotation_z(rot->speed, rot->axis, rot->center, z);
  double* V = malloc((size_t)nq * 6 * sizeof(double));
  double* qv = malloc((size_t)nq * sizeof(double));
  int rc = V && qv ? velocity(m, w, q, z, V, v) : -1;
  if (!rc) { /* (G3): a = u(q + h v) - u(q), over h (exact for any h: u is affine) */
    double vmax = 0.0, qmax = 0.0;
    for (int i = 0; i < nq; ++i) {
      vmax = fmax(vmax, fabs(v[i]));
      qmax = fmax(qmax, fabs(q[i]));
    }
    const double h = vmax > 0.0 ? (1.0 + qmax) / vmax : 1.0;
    for (int i = 0; i < nq; ++i) qv[i] = q[i] + h * v[i];
    rc = velocity(m, w, qv, z, V, a);
    for (int i = 0; !rc && i < nq; ++i) a[i] = (a[i] - v[i]) / h;
  }
  free(V);
  free(qv);
  return rc;
}

int fmb_rotation3_generator(const fmbModel* m, fmbWorkspace* w, const fmbRotation3* rot, const double* q, double* E,
                            int ld) {
  const int nq = m->nq;
  double z[6];
  rotation_z(1.0, rot->axis, rot->center, z);
  double* V = malloc((size_t)nq * 6 * sizeof(double));
  double* u0 = malloc((size_t)nq * sizeof(double));
  double* qj = malloc((size_t)nq * sizeof(double));
  int rc = V && u0 && qj ? velocity(m, w, q, z, V, u0) : -1;
  for (int j = 0; !rc && j < nq; ++j) { /* (G3), a unit step (u is affine) */
    memcpy(qj, q, (size_t)nq * sizeof(double));
    qj[j] += 1.0;
    double* col = E + (size_t)j * ld;
    rc = velocity(m, w, qj, z, V, col);
    for (int i = 0; !rc && i < nq; ++i) col[i] -= u0[i];
  }
  free(V);
  free(u0);
  free(qj);
  return rc;
}

void fmb_rotation3_terms(int nq, double speed, const double* E, const double* C, const double* M, int ld, double* K,
                         double* Cg) {
  if (speed == 0.0) return;
  /* CE = C E, ME = M E, ME2 = (M E) E; all nq x nq column-major */
  double* CE = calloc((size_t)nq * nq * 3, sizeof(double));
  if (!CE) return;
  double *ME = CE + (size_t)nq * nq, *ME2 = ME + (size_t)nq * nq;
  for (int j = 0; j < nq; ++j)
    for (int k = 0; k < nq; ++k) {
      const double e = E[(size_t)j * nq + k];
      if (e == 0.0) continue;
      for (int i = 0; i < nq; ++i) {
        CE[(size_t)j * nq + i] += C[(size_t)k * ld + i] * e;
        ME[(size_t)j * nq + i] += M[(size_t)k * ld + i] * e;
      }
    }
  for (int j = 0; j < nq; ++j)
    for (int k = 0; k < nq; ++k) {
      const double e = E[(size_t)j * nq + k];
      if (e == 0.0) continue;
      for (int i = 0; i < nq; ++i) ME2[(size_t)j * nq + i] += ME[(size_t)k * nq + i] * e;
    }
  for (int j = 0; j < nq; ++j)
    for (int i = 0; i < nq; ++i) {
      const size_t at = (size_t)j * nq + i;
      K[(size_t)j * ld + i] += speed * CE[at] + speed * speed * ME2[at];
      if (Cg) Cg[(size_t)j * ld + i] += 2.0 * speed * ME[at];
    }
  free(CE);
}

/* least squares A z = b (A nr x 6 column-major) with a tiny regularization (directions nothing
   fixes get 0); returns the residual's 2-norm */
static double fit6(int nr, const double* A, const double* b, double z[6]) {
  double N[36], tr = 0.0;
  int piv[6];
  for (int i = 0; i < 6; ++i) {
    for (int j = 0; j < 6; ++j) {
      double s = 0.0;
      for (int r = 0; r < nr; ++r) s += A[(size_t)i * nr + r] * A[(size_t)j * nr + r];
      N[j * 6 + i] = s;
    }
    tr += N[i * 6 + i];
  }
  for (int i = 0; i < 6; ++i) {
    N[i * 6 + i] += 1e-12 * tr + 1e-300;
    double s = 0.0;
    for (int r = 0; r < nr; ++r) s += A[(size_t)i * nr + r] * b[r];
    z[i] = s;
  }
  if (fmb_lu_factor(6, N, piv) == 0) {
    fmb_lu_solve(6, N, piv, z);
    /* the regularization biases z by about 1e-12 of itself: two steps of refinement on the
       unregularized normal equations take it out (a fitted speed exact to rounding) */
    for (int pass = 0; pass < 2; ++pass) {
      double dz[6];
      for (int i = 0; i < 6; ++i) {
        double s = 0.0;
        for (int r = 0; r < nr; ++r) {
          double res = b[r];
          for (int j = 0; j < 6; ++j) res -= A[(size_t)j * nr + r] * z[j];
          s += A[(size_t)i * nr + r] * res;
        }
        dz[i] = s;
      }
      fmb_lu_solve(6, N, piv, dz);
      for (int i = 0; i < 6; ++i) z[i] += dz[i];
    }
  } else {
    memset(z, 0, 6 * sizeof(double));
  }
  double res = 0.0;
  for (int r = 0; r < nr; ++r) {
    double s = -b[r];
    for (int j = 0; j < 6; ++j) s += A[(size_t)j * nr + r] * z[j];
    res += s * s;
  }
  return sqrt(res);
}

/* z = [Omega; s] -> speed, unit axis (largest component positive: a reversed axis is a negative
   speed), center (the point of the axis nearest the origin: c = a x s / W) */
static void rotation_of(const double z[6], fmbRotation3* rot) {
  const double W = sqrt(z[0] * z[0] + z[1] * z[1] + z[2] * z[2]);
  memset(rot, 0, sizeof *rot);
  rot->axis[2] = 1.0;
  if (!(W > 0.0)) return;
  int big = 0;
  for (int i = 1; i < 3; ++i)
    if (fabs(z[i]) > fabs(z[big])) big = i;
  const double sg = z[big] < 0.0 ? -1.0 : 1.0;
  rot->speed = sg * W;
  for (int i = 0; i < 3; ++i) rot->axis[i] = sg * z[i] / W;
  const double* a = rot->axis;
  const double s[3] = {z[3] / rot->speed, z[4] / rot->speed, z[5] / rot->speed}; /* a x c */
  rot->center[0] = a[1] * s[2] - a[2] * s[1];                                    /* a x (a x c) = -c (c . a = 0) */
  rot->center[1] = a[2] * s[0] - a[0] * s[2];
  rot->center[2] = a[0] * s[1] - a[1] * s[0];
  for (int i = 0; i < 3; ++i) rot->center[i] = -rot->center[i];
  rot->screw = (a[0] * s[0] + a[1] * s[1] + a[2] * s[2]); /* a . (a x c) = 0 for a rotation */
}

int fmb_state_rotation3(const fmbModel* m, fmbWorkspace* w, const double* q, const double* v, fmbRotation3* rot) {
  const int nq = m->nq;
  memset(rot, 0, sizeof *rot);
  rot->axis[2] = 1.0;
  double* V = malloc((size_t)nq * 6 * sizeof(double));
  double z[6];
  int rc = V ? fmb_rotation3_basis(m, w, q, V) : -1;
  double vn = 0.0;
  for (int i = 0; i < nq; ++i) vn = fmax(vn, fabs(v[i]));
  if (!rc && vn > 0.0) {
    fit6(nq, V, v, z);
    rotation_of(z, rot);
    double d = 0.0; /* the fitted rotation reproduces v? */
    for (int i = 0; i < nq; ++i) {
      double s = -v[i];
      for (int j = 0; j < 6; ++j) s += V[(size_t)j * nq + i] * z[j];
      d = fmax(d, fabs(s));
    }
    if (!(d <= 1e-9 * vn) ||
        fabs(rot->screw) > 1e-9 * (1.0 + fabs(rot->center[0]) + fabs(rot->center[1]) + fabs(rot->center[2])))
      memset(rot, 0, sizeof *rot), rot->axis[2] = 1.0;
  }
  free(V);
  return rc;
}

int fmb_fit_rotation3(const fmbModel* m, fmbWorkspace* w, double t, const double* q, fmbRotation3* rot, fmbDiag* diag) {
  const int nq = m->nq, nc = m->nc;
  memset(rot, 0, sizeof *rot);
  rot->axis[2] = 1.0;
  if (nc == 0) return 0;
  double* PhiQ = calloc((size_t)nc * nq, sizeof(double));
  double* phit = calloc((size_t)nc, sizeof(double));
  double* phitt = calloc((size_t)nc, sizeof(double));
  double* phi = calloc((size_t)nc, sizeof(double));
  double* zero = calloc((size_t)nq, sizeof(double));
  double* V = calloc((size_t)nq * 6, sizeof(double));
  double* A = calloc((size_t)nc * 6, sizeof(double));
  int rc = 0;
  if (!PhiQ || !phit || !phitt || !phi || !zero || !V || !A) {
    fmb_diag_set(diag, FMB_EXIT_SOLVER, m->path, 0, 0, "out of memory");
    rc = FMB_EXIT_SOLVER;
    goto done;
  }
  if (fmb_constraints_all(m, w, t, q, zero, phi, PhiQ, phit, phitt)) {
    fmb_diag_set(diag, FMB_EXIT_BAD_INPUT, m->path, 0, 0, "the joints cannot be evaluated at t = %g", t);
    rc = FMB_EXIT_BAD_INPUT;
    goto done;
  }
  double bnorm = 0.0;
  for (int r = 0; r < nc; ++r) bnorm += phit[r] * phit[r];
  bnorm = sqrt(bnorm);
  if (bnorm == 0.0) goto done; /* no drive moves: static */
  if (fmb_rotation3_basis(m, w, q, V)) {
    fmb_diag_set(diag, FMB_EXIT_BAD_INPUT, m->path, 0, 0,
                 "a steady rotation needs every body's spatial marker (marker3) and a regular frame at its origin");
    rc = FMB_EXIT_BAD_INPUT;
    goto done;
  }
  for (int j = 0; j < 6; ++j)
    for (int r = 0; r < nc; ++r) {
      double s = 0.0;
      for (int c = 0; c < nq; ++c) s += PhiQ[(size_t)r * nq + c] * V[(size_t)j * nq + c];
      A[(size_t)j * nc + r] = s;
    }
  for (int r = 0; r < nc; ++r) phit[r] = -phit[r];
  double z[6];
  const double res = fit6(nc, A, phit, z);
  rotation_of(z, rot);
  if (res > 1e-8 * bnorm || rot->speed == 0.0 ||
      fabs(rot->screw) > 1e-8 * (1.0 + fabs(rot->center[0]) + fabs(rot->center[1]) + fabs(rot->center[2]))) {
    rc = fmb_steady_refusal(m, FMB_STEADY_NOT_RIGID, t, res, diag);
    goto done;
  }
  double tt = 0.0;
  for (int r = 0; r < nc; ++r) tt += phitt[r] * phitt[r];
  if (sqrt(tt) > 1e-9 * bnorm * (1.0 + fabs(rot->speed))) {
    rc = fmb_steady_refusal(m, FMB_STEADY_ACCELERATING, t, sqrt(tt), diag);
    goto done;
  }
  /* gravity along the spin axis turns with nothing; any other component turns against the system */
  const double* g = m->env.gravity3;
  const double ga = g[0] * rot->axis[0] + g[1] * rot->axis[1] + g[2] * rot->axis[2];
  const double gn = sqrt(g[0] * g[0] + g[1] * g[1] + g[2] * g[2]);
  if (m->env.has_gravity && sqrt(fmax(gn * gn - ga * ga, 0.0)) > 1e-12 * gn) {
    fmb_diag_set(
        diag, FMB_EXIT_BAD_INPUT, m->path, 0, 0,
        "gravity across the spin axis [%g, %g, %g] turns with respect to the rotating system: a steady rotation "
        "at %g rad/s exists only with gravity along the axis or none",
        rot->axis[0], rot->axis[1], rot->axis[2], rot->speed);
    rc = FMB_EXIT_BAD_INPUT;
    goto done;
  }
done:
  if (rc) memset(rot, 0, sizeof *rot), rot->axis[2] = 1.0;
  free(PhiQ);
  free(phit);
  free(phitt);
  free(phi);
  free(zero);
  free(V);
  free(A);
  return rc;
}

double fmb_turn3(const fmbModel* m, fmbWorkspace* w, const double* q, const double* dq) {
  double turn = 0.0;
  const double origin[3] = {0.0, 0.0, 0.0};
  for (int b = 1; b < m->nbody; ++b) {
    const fmbBodyInst* bi = &m->body[b];
    if (!bi->type || !bi->marker3 || bi->nq == 0) continue;
    double* G = calloc((size_t)3 * bi->nq, sizeof(double));
    double pos[3], R[9];
    if (G &&
        !bi->marker3(bi->self, q + bi->qadr, origin, pos, R, NULL, G, bi->nq, fmb_workspace_plugin(w) + bi->workadr)) {
      double th[3] = {0.0, 0.0, 0.0};
      for (int i = 0; i < 3; ++i)
        for (int c = 0; c < bi->nq; ++c) th[i] += G[(size_t)i * bi->nq + c] * dq[bi->qadr + c];
      turn = fmax(turn, sqrt(th[0] * th[0] + th[1] * th[1] + th[2] * th[2]));
    }
    free(G);
  }
  return turn;
}
