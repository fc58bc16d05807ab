/* static.c — static equilibrium and steady rotation (relative equilibrium), docs/analysis.md.
 *
 * The unknowns are x = [q, lambda]; the equations are the GGL system's own rows (system.c)
 *     F_v = M(q) a - Q(q, v, t) + Phi_q^T lambda = 0,    F_lambda = Phi(q, t) = 0,
 * evaluated at a state that does not change in a frame turning with the drives:
 *   - static: v = 0, a = 0;
 *   - steady rotation at speed W about a center c: every body's frame turns rigidly, its own
 *     (deformation) coordinates stay fixed, so for a frame origin r0
 *         v_r0 = W I~ (r0 - c),  theta' = W,   a_r0 = -W^2 (r0 - c)          (I~ = [[0,-1],[1,0]])
 *     and centrifugal stiffening enters through the bodies' own residuals at that v.
 * W and c are read from the constraints at t: the velocity constraints Phi_q v + Phi_t = 0 must
 * hold for a rigid rotation, which is linear in (W, W c) (least squares; a residual left over
 * means the drives are not one rigid rotation, e.g. a drive between two moving bodies).
 *
 * Newton on x with the full Jacobian of the system (fmb_system_jacobian: the bodies' analytic or
 * difference blocks, the joints' curvature terms Phi_qq lambda). With v = v(q), a = a(q):
 *     dF_v/dq = K + W C E + W^2 M E^2                                             (S1)
 * with K = dR/dq, C = dR/dv, M = dR/da and E the generator of the rotation (I~ on every body's
 * frame-origin pair, 0 elsewhere). Large deflections: load stepping by the homotopy
 *     G(x, s) = F(x) - (1 - s) F(x0),   s = 0 -> 1                                (S2)
 * which applies the out-of-balance load of the starting point (gravity, loads, centrifugal
 * forces, a drive's offset) in increments, halving an increment whenever Newton fails on it.
 * A spatial scene (dimension 3, engine/rotation3.c): the rotation has an axis as well, fitted the
 * same way (G2), E is the generator (G3) of its rigid motion on every body's coordinates, and the
 * bodies' gauge directions d (the length of Euler parameters, which nothing physical sees) are
 * held by rows d^T dq = 0 with multipliers mu beside the constraint rows (G1): x = [q, lambda, mu],
 *     [dF_v/dq  Phi_q^T  D; Phi_q 0 0; D^T 0 0]                                        (S3)
 * is regular where the 2D one is. The body's own equation along d is identically 0 at rest and
 * in a steady rotation, so mu stays 0.
 * Setup-time code: it allocates. */
#include <math.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>

#include "internal.h"

int fmb_state_size(const fmbModel* m) { return m ? m->ny : 0; }

static int has_frame(const fmbBodyInst* b) { return b->type && b->nq >= 3; }

void fmb_rigid_rotation(const fmbModel* m, double speed, const double center[2], const double* q, double* v,
                        double* a) {
  memset(v, 0, (size_t)m->nq * sizeof(double));
  memset(a, 0, (size_t)m->nq * sizeof(double));
  if (speed == 0.0) return;
  for (int b = 1; b < m->nbody; ++b) {
    const fmbBodyInst* bi = &m->body[b];
    if (!has_frame(bi)) continue;
    const double rx = q[bi->qadr] - center[0], ry = q[bi->qadr + 1] - center[1];
    v[bi->qadr] = -speed * ry;
    v[bi->qadr + 1] = speed * rx;
    v[bi->qadr + 2] = speed;
    a[bi->qadr] = -speed * speed * rx;
    a[bi->qadr + 1] = -speed * speed * ry;
  }
}

/* K (column-major, leading dimension ld, nq x nq) += W C E + W^2 M E^2 (S1); and, when Cg is
   not NULL, Cg += 2 W M E: the rotating-frame terms of a linearization about a steady rotation
   (modes.c). (C E) e_x = C e_y, (C E) e_y = -C e_x, E^2 = -1 on the frame-origin pair. */
void fmb_rotation_terms(const fmbModel* m, double speed, const double* C, const double* M, int ld, double* K,
                        double* Cg) {
  if (speed == 0.0) return;
  const int nq = m->nq;
  for (int b = 1; b < m->nbody; ++b) {
    const fmbBodyInst* bi = &m->body[b];
    if (!has_frame(bi)) continue;
    const size_t cx = (size_t)bi->qadr * ld, cy = (size_t)(bi->qadr + 1) * ld;
    for (int i = 0; i < nq; ++i) {
      const double Cx = C[cx + i], Cy = C[cy + i], Mx = M[cx + i], My = M[cy + i];
      K[cx + i] += speed * Cy - speed * speed * Mx;
      K[cy + i] += -speed * Cx - speed * speed * My;
      if (Cg) {
        Cg[cx + i] += 2.0 * speed * My;
        Cg[cy + i] -= 2.0 * speed * Mx;
      }
    }
  }
}

static double norm2(const double* x, int n) {
  double s = 0.0;
  for (int i = 0; i < n; ++i) s += x[i] * x[i];
  return sqrt(s);
}

/* The rigid rotation the constraints prescribe at t, from the least-squares fit of
   Phi_q v(W, W c) = -Phi_t (module comment). 0, or FMB_EXIT_BAD_INPUT with *diag. */
static int fit_rotation(const fmbModel* m, fmbWorkspace* w, double t, const double* q, double* speed, double center[2],
                        fmbDiag* diag) {
  const int nq = m->nq, nc = m->nc;
  *speed = 0.0;
  center[0] = center[1] = 0.0;
  if (nc == 0) return 0;
  double* PhiQ = calloc((size_t)nc * nq, sizeof(double));
  double* phit = calloc((size_t)nc, sizeof(double));
  double* phitt = calloc((size_t)nc, sizeof(double));
  double* phi = calloc((size_t)nc, sizeof(double));
  double* vz = calloc((size_t)nq * 3, sizeof(double)); /* v for W = 1, W cx = 1, W cy = 1 */
  double* A = calloc((size_t)nc * 3, sizeof(double));
  int rc = 0;
  if (!PhiQ || !phit || !phitt || !phi || !vz || !A) {
    fmb_diag_set(diag, FMB_EXIT_SOLVER, m->path, 0, 0, "out of memory");
    rc = FMB_EXIT_SOLVER;
    goto done;
  }
  double* zero = calloc((size_t)nq, sizeof(double));
  if (!zero || fmb_constraints_all(m, w, t, q, zero, phi, PhiQ, phit, phitt)) {
    free(zero);
    fmb_diag_set(diag, FMB_EXIT_BAD_INPUT, m->path, 0, 0, "the joints cannot be evaluated at t = %g", t);
    rc = FMB_EXIT_BAD_INPUT;
    goto done;
  }
  free(zero);
  const double bnorm = norm2(phit, nc);
  if (bnorm == 0.0) goto done; /* no drive moves: static */
  int frameless = 0;
  for (int b = 1; b < m->nbody; ++b) {
    const fmbBodyInst* bi = &m->body[b];
    if (!has_frame(bi)) {
      frameless = 1;
      continue;
    }
    const int k = bi->qadr;
    vz[k] = -q[k + 1]; /* W I~ r0 */
    vz[k + 1] = q[k];
    vz[k + 2] = 1.0;
    vz[nq + k + 1] = -1.0; /* -I~ (W c) */
    vz[2 * nq + k] = 1.0;
  }
  for (int r = 0; r < nc; ++r)
    for (int j = 0; j < 3; ++j) {
      double s = 0.0;
      for (int c = 0; c < nq; ++c) s += PhiQ[(size_t)r * nq + c] * vz[(size_t)j * nq + c];
      A[(size_t)j * nc + r] = s;
    }
  /* normal equations with a tiny regularization: directions the constraints leave free (a
     center no joint fixes) get 0 */
  double N[9], z[3] = {0, 0, 0};
  int piv[3];
  double tr = 0.0;
  for (int i = 0; i < 3; ++i)
    for (int j = 0; j < 3; ++j) {
      double s = 0.0;
      for (int r = 0; r < nc; ++r) s += A[(size_t)i * nc + r] * A[(size_t)j * nc + r];
      N[j * 3 + i] = s;
      if (i == j) tr += s;
    }
  for (int i = 0; i < 3; ++i) {
    N[i * 3 + i] += 1e-12 * tr + 1e-300;
    double s = 0.0;
    for (int r = 0; r < nc; ++r) s -= A[(size_t)i * nc + r] * phit[r];
    z[i] = s;
  }
  if (fmb_lu_factor(3, N, piv) == 0) fmb_lu_solve(3, N, piv, z);
  double res = 0.0;
  for (int r = 0; r < nc; ++r) {
    double s = phit[r];
    for (int j = 0; j < 3; ++j) s += A[(size_t)j * nc + r] * z[j];
    res += s * s;
  }
  res = sqrt(res);
  if (res > 1e-8 * bnorm || z[0] == 0.0) {
    rc = fmb_steady_refusal(m, FMB_STEADY_NOT_RIGID, t, res, diag);
    goto done;
  }
  if (frameless) {
    fmb_diag_set(diag, FMB_EXIT_BAD_INPUT, m->path, 0, 0,
                 "a steady rotation needs every body to have a frame (x, y, theta)");
    rc = FMB_EXIT_BAD_INPUT;
    goto done;
  }
  if (norm2(phitt, nc) > 1e-9 * bnorm * (1.0 + fabs(z[0]))) {
    rc = fmb_steady_refusal(m, FMB_STEADY_ACCELERATING, t, norm2(phitt, nc), diag);
    goto done;
  }
  if (m->env.has_gravity) {
    fmb_diag_set(diag, FMB_EXIT_BAD_INPUT, m->path, 0, 0,
                 "gravity turns with respect to a rotating system: a steady rotation at %g rad/s exists only without "
                 "gravity (set gravity: [0, 0])",
                 z[0]);
    rc = FMB_EXIT_BAD_INPUT;
    goto done;
  }
  *speed = z[0];
  center[0] = z[1] / z[0];
  center[1] = z[2] / z[0];
done:
  free(PhiQ);
  free(phit);
  free(phitt);
  free(phi);
  free(vz);
  free(A);
  return rc;
}

/* A body whose auxiliary unknowns are a mixed form's own fields (fmbBodyType.aux_iterated: the
   exact beam's axial forces) enters the analyses, which work on the coordinates alone, in its
   displacement form: z consistent with q (its aux_initial), and z folded out of the dense
   Jacobian J (ny x ny, column-major) by the Schur complement J_xx - J_xz J_zz^-1 J_zx, which is
   the displacement form's tangent (the exact beam: EA t t^T back in its q block). Only the
   columns and rows the body's z couple to are touched. */
int fmb_aux_iterated_consistent(const fmbModel* m, fmbWorkspace* w, double* y, const double* yp) {
  const int nq = m->nq;
  for (int b = 1; b < m->nbody; ++b) {
    const fmbBodyInst* bi = &m->body[b];
    if (!bi->aux_iterated) continue;
    const int rc = bi->type->aux_initial(bi->self, &m->env, y + bi->qadr, y + nq + bi->qadr, yp + nq + bi->qadr,
                                         y + m->zoff + bi->zadr, fmb_workspace_plugin(w) + bi->workadr);
    if (rc) return rc;
  }
  return 0;
}

int fmb_aux_iterated_fold(const fmbModel* m, double* J) {
  const size_t ny = (size_t)m->ny;
  for (int b = 1; b < m->nbody; ++b) {
    const fmbBodyInst* bi = &m->body[b];
    if (!bi->aux_iterated) continue;
    const int nz = bi->nz;
    const size_t z0 = (size_t)(m->zoff + bi->zadr);
    double* A = malloc(sizeof(double) * ((size_t)nz * nz + nz));
    int* piv = malloc(sizeof(int) * (size_t)nz);
    if (!A || !piv) {
      free(A);
      free(piv);
      return -1;
    }
    double* x = A + (size_t)nz * nz;
    for (int j = 0; j < nz; ++j)
      for (int i = 0; i < nz; ++i) A[(size_t)j * nz + i] = J[(z0 + j) * ny + z0 + i];
    int rc = fmb_lu_factor(nz, A, piv);
    for (size_t c = 0; !rc && c < ny; ++c) {
      if (c >= z0 && c < z0 + (size_t)nz) continue;
      int any = 0;
      for (int i = 0; i < nz; ++i) any |= (x[i] = J[c * ny + z0 + i]) != 0.0;
      if (!any) continue;
      fmb_lu_solve(nz, A, piv, x);
      for (int k = 0; k < nz; ++k) {
        const double* Jz = J + (z0 + k) * ny;
        if (x[k] == 0.0) continue;
        for (size_t r = 0; r < ny; ++r)
          if ((r < z0 || r >= z0 + (size_t)nz) && Jz[r] != 0.0) J[c * ny + r] -= Jz[r] * x[k];
      }
    }
    free(A);
    free(piv);
    if (rc) return -1;
  }
  return 0;
}

typedef struct {
  const fmbModel* m;
  fmbWorkspace* w;
  double t, speed, center[2];
  int n;               /* nq + nc + ng */
  int ng;              /* gauge rows (S3); spatial scenes only */
  fmbRotation3 rot;    /* a spatial scene's rotation (speed == rot.speed) */
  double *D, *E;       /* gauge directions (nq x ng), the rotation's generator (nq x nq) */
  double *U, *VT, *sv; /* spatial: the SVD of A (S4) */
  double load;         /* the out-of-balance load at the start (S4's test) */
  double *y, *yp, *F, *ewt, *J0, *J1, *A;
  int* piv;
} Newton;

/* y, yp of the steady state at x = [q, lambda] */
static void make_state(Newton* s, const double* x) {
  const fmbModel* m = s->m;
  const int nq = m->nq, nc = m->nc;
  memset(s->y, 0, (size_t)m->ny * sizeof(double));
  memset(s->yp, 0, (size_t)m->ny * sizeof(double));
  memcpy(s->y, x, (size_t)nq * sizeof(double));
  memcpy(s->y + 2 * nq, x + nq, (size_t)nc * sizeof(double));
  if (m->dimension == 3)
    fmb_rigid_rotation3(m, s->w, &s->rot, x, s->y + nq, s->yp + nq);
  else
    fmb_rigid_rotation(m, s->speed, s->center, x, s->y + nq, s->yp + nq);
  memcpy(s->yp, s->y + nq, (size_t)nq * sizeof(double));
  fmb_aux_iterated_consistent(m, s->w, s->y, s->yp); /* the mixed forms' z: their displacement form */
}

/* Fx = [F_v; F_lambda] at x; 0 or the residual's code */
static int eval_F(Newton* s, const double* x, double* Fx) {
  const fmbModel* m = s->m;
  make_state(s, x);
  int rc = fmb_system_residual(m, s->w, s->t, s->y, s->yp, s->F);
  if (rc) return rc;
  memcpy(Fx, s->F + m->nq, (size_t)(m->nq + m->nc) * sizeof(double));
  if (s->ng > 0) { /* (S3): + D mu in the force rows, 0 in the gauge rows */
    const int nq = m->nq, at = nq + m->nc;
    if (fmb_gauge_rows(m, x, s->D, nq) != s->ng) return -1;
    for (int g = 0; g < s->ng; ++g) {
      for (int i = 0; i < nq; ++i) Fx[i] += s->D[(size_t)g * nq + i] * x[at + g];
      Fx[at + g] = 0.0;
    }
  }
  return 0;
}

/* LAPACK (as modes.c): the SVD of a spatial scene's Newton matrix */
extern void dgesvd_(const char* jobu, const char* jobvt, const int* m, const int* n, double* a, const int* lda,
                    double* s, double* u, const int* ldu, double* vt, const int* ldvt, double* work, const int* lwork,
                    int* info);

/* Space has free motions that a load never meets: a body on a ball joint under gravity turns
   freely about the vertical through the pivot, at every pose, so the Newton matrix is singular
   along a motion that every equilibrium of the family shares. Its step is then the least-norm
   one, from the SVD A = U S V^T with singular values below 1e-12 of the largest dropped:
       dx = V S^+ U^T G                                                                   (S4)
   (the free motion stays where it started), and a residual outside the range of A beyond
   roundoff (a load that nothing holds: a free body under gravity) is a singular system as the
   planar LU's zero pivot is. 0, or 2 when the SVD fails. */
static int svd_factor(Newton* s) {
  const int n = s->n;
  int lwork = -1, info = 0;
  double q1 = 0.0;
  dgesvd_("A", "A", &n, &n, s->A, &n, s->sv, s->U, &n, s->VT, &n, &q1, &lwork, &info);
  lwork = (int)q1 + 1;
  double* work = malloc((size_t)lwork * sizeof(double));
  if (!work) return -1;
  dgesvd_("A", "A", &n, &n, s->A, &n, s->sv, s->U, &n, s->VT, &n, work, &lwork, &info);
  free(work);
  return info ? 2 : 0;
}

/* (S4) in place on g; 1 when g has a part outside the range of A beyond roundoff */
static int svd_solve(Newton* s, double* g) {
  const int n = s->n;
  double* c = calloc((size_t)n, sizeof(double));
  if (!c) return 1;
  double dropped = 0.0;
  for (int k = 0; k < n; ++k) {
    double d = 0.0;
    for (int i = 0; i < n; ++i) d += s->U[(size_t)k * n + i] * g[i];
    if (s->sv[k] > 1e-12 * s->sv[0])
      c[k] = d / s->sv[k];
    else
      dropped += d * d;
  }
  for (int i = 0; i < n; ++i) {
    double x = 0.0;
    for (int k = 0; k < n; ++k) x += s->VT[(size_t)i * n + k] * c[k];
    g[i] = x;
  }
  free(c);
  return sqrt(dropped) > 1e-9 * (1.0 + s->load);
}

/* dense [dF_v/dq (S1), Phi_q^T; Phi_q, 0] at x, LU-factored into s->A; 0, 2 when the LU meets an
   exactly zero pivot, else the Jacobian's own failure code */
static int factor_jacobian(Newton* s, const double* x) {
  const fmbModel* m = s->m;
  const int nq = m->nq, nc = m->nc, ny = m->ny, n = s->n;
  make_state(s, x);
  for (int i = 0; i < ny; ++i) s->ewt[i] = 1.0 / (1e-8 * (1.0 + fabs(s->y[i])));
  int rc = fmb_system_jacobian(m, s->w, s->t, 0.0, s->y, s->yp, s->ewt, 0, NULL, s->J0);
  if (!rc && s->speed != 0.0) rc = fmb_system_jacobian(m, s->w, s->t, 1.0, s->y, s->yp, s->ewt, 1, NULL, s->J1);
  if (!rc) rc = fmb_aux_iterated_fold(m, s->J0);
  if (rc) return rc;
  memset(s->A, 0, (size_t)n * n * sizeof(double));
  for (int j = 0; j < nq; ++j)
    for (int i = 0; i < nq + nc; ++i) s->A[(size_t)j * n + i] = s->J0[(size_t)j * ny + nq + i];
  for (int k = 0; k < nc; ++k)
    for (int i = 0; i < nq; ++i) s->A[(size_t)(nq + k) * n + i] = s->J0[(size_t)(2 * nq + k) * ny + nq + i];
  if (s->ng > 0) { /* (S3) */
    if (fmb_gauge_rows(m, x, s->D, nq) != s->ng) return -1;
    for (int g = 0; g < s->ng; ++g)
      for (int i = 0; i < nq; ++i) {
        s->A[(size_t)(nq + nc + g) * n + i] = s->D[(size_t)g * nq + i];
        s->A[(size_t)i * n + nq + nc + g] = s->D[(size_t)g * nq + i];
      }
  }
  if (s->speed != 0.0) {
    /* C = J0's (F_v, v) block, M = J1's minus C; both nq x nq with leading dimension ny */
    for (int j = 0; j < nq; ++j)
      for (int i = 0; i < nq; ++i) {
        const size_t at = (size_t)(nq + j) * ny + nq + i;
        s->J1[at] -= s->J0[at];
      }
    /* the rotation terms go into A's q block (leading dimension n) */
    double* Ctmp = s->J0 + (size_t)nq * ny + nq;
    double* Mtmp = s->J1 + (size_t)nq * ny + nq;
    double* K = malloc((size_t)nq * nq * sizeof(double));
    double* Cc = calloc((size_t)nq * nq, sizeof(double)); /* calloc: -Wmaybe-uninitialized under LTO */
    double* Mc = calloc((size_t)nq * nq, sizeof(double));
    if (!K || !Cc || !Mc) {
      free(K);
      free(Cc);
      free(Mc);
      return -1;
    }
    for (int j = 0; j < nq; ++j)
      for (int i = 0; i < nq; ++i) {
        Cc[(size_t)j * nq + i] = Ctmp[(size_t)j * ny + i];
        Mc[(size_t)j * nq + i] = Mtmp[(size_t)j * ny + i];
        K[(size_t)j * nq + i] = 0.0;
      }
    if (m->dimension == 3) {
      if (fmb_rotation3_generator(m, s->w, &s->rot, x, s->E, nq)) {
        free(K);
        free(Cc);
        free(Mc);
        return -1;
      }
      fmb_rotation3_terms(nq, s->speed, s->E, Cc, Mc, nq, K, NULL);
    } else {
      fmb_rotation_terms(m, s->speed, Cc, Mc, nq, K, NULL);
    }
    for (int j = 0; j < nq; ++j)
      for (int i = 0; i < nq; ++i) s->A[(size_t)j * n + i] += K[(size_t)j * nq + i];
    free(K);
    free(Cc);
    free(Mc);
  }
  if (m->dimension == 3) return svd_factor(s);
  return fmb_lu_factor(n, s->A, s->piv) ? 2 : 0; /* 2: an exactly zero pivot */
}

/* A steady rotation read at T = 20 s after a spin-up finds the drives 50 rad ahead of the bodies'
   initial poses; Newton, limited to MAX_TURN per iteration, took 236 iterations to get there.
   The whole system turned rigidly about the center by the angle that best satisfies the
   constraints (least squares along the rigid rotation: drives are linear in it, the other joints
   turn with it) starts Newton where the drives are. */
static void turn_to_drives(Newton* s, double* x) {
  const fmbModel* m = s->m;
  const int nq = m->nq, nc = m->nc;
  double* phi = calloc((size_t)nc + 1, sizeof(double));
  double* PhiQ = calloc((size_t)nc * nq + 1, sizeof(double));
  double* zero = calloc((size_t)nq + 1, sizeof(double));
  for (int pass = 0; phi && PhiQ && zero && pass < 3; ++pass) {
    if (fmb_constraints_all(m, s->w, s->t, x, zero, phi, PhiQ, NULL, NULL)) break;
    double num = 0.0, den = 0.0;
    for (int r = 0; r < nc; ++r) {
      double d = 0.0; /* Phi_q times the rigid-rotation direction */
      for (int b = 1; b < m->nbody; ++b) {
        const fmbBodyInst* bi = &m->body[b];
        if (!has_frame(bi)) continue;
        const double* row = PhiQ + (size_t)r * nq + bi->qadr;
        d += -row[0] * (x[bi->qadr + 1] - s->center[1]) + row[1] * (x[bi->qadr] - s->center[0]) + row[2];
      }
      num += d * phi[r];
      den += d * d;
    }
    if (!(den > 0.0)) break;
    const double turn = -num / den;
    if (fabs(turn) < 1e-14) break;
    const double c = cos(turn), sn = sin(turn);
    for (int b = 1; b < m->nbody; ++b) {
      const fmbBodyInst* bi = &m->body[b];
      if (!has_frame(bi)) continue;
      const double rx = x[bi->qadr] - s->center[0], ry = x[bi->qadr + 1] - s->center[1];
      x[bi->qadr] = s->center[0] + c * rx - sn * ry;
      x[bi->qadr + 1] = s->center[1] + sn * rx + c * ry;
      x[bi->qadr + 2] += turn;
    }
  }
  free(phi);
  free(PhiQ);
  free(zero);
}

/* an out-of-balance load below this (N, N m) is roundoff: nothing loads the system */
#define FMB_STATIC_NO_LOAD 1e-9

/* 1 when the equilibrium Jacobian at x is singular (a pivot of its LU at most 1e-12 of the
   largest, or exactly zero), 0 when not, -1 when it cannot be evaluated */
static int singular_stiffness(Newton* s, const double* x) {
  const int rc = factor_jacobian(s, x);
  if (rc == 2) return 1; /* an exactly zero pivot */
  if (rc) return -1;
  if (s->m->dimension == 3) return s->sv[s->n - 1] <= 1e-12 * s->sv[0] ? 1 : 0;
  double lo = INFINITY, hi = 0.0;
  for (int i = 0; i < s->n; ++i) {
    const double d = fabs(s->A[(size_t)i * s->n + i]);
    lo = fmin(lo, d);
    hi = fmax(hi, d);
  }
  return lo <= 1e-12 * hi ? 1 : 0;
}

/* rad: the largest turn of a frame in one Newton iteration */
#define MAX_TURN 0.5

/* lambda that balances the forces at the start as well as the constraints can (least squares,
   lambda = -(Phi_q Phi_q^T)^-1 Phi_q F_v(q, 0)): the stiffness a mechanism gets from its joints'
   curvature (Phi_qq lambda, a pendulum's restoring moment) is there from the first iteration */
static int initial_multipliers(Newton* s, double* x, fmbDiag* diag) {
  const fmbModel* m = s->m;
  const int nq = m->nq, nc = m->nc;
  if (nc == 0) return 0;
  double* Fx = malloc((size_t)s->n * sizeof(double));
  double* PhiQ = calloc((size_t)nc * nq, sizeof(double));
  double* G = calloc((size_t)nc * nc, sizeof(double));
  double* r = calloc((size_t)nc, sizeof(double));
  int* piv = calloc((size_t)nc, sizeof(int));
  int rc = 0;
  if (!Fx || !PhiQ || !G || !r || !piv) {
    fmb_diag_set(diag, FMB_EXIT_SOLVER, m->path, 0, 0, "out of memory");
    rc = FMB_EXIT_SOLVER;
  } else if (!eval_F(s, x, Fx) && !fmb_constraints_all(m, s->w, s->t, x, s->y + nq, NULL, PhiQ, NULL, NULL)) {
    for (int i = 0; i < nc; ++i) {
      for (int k = 0; k < nc; ++k) {
        double a = 0.0;
        for (int c = 0; c < nq; ++c) a += PhiQ[(size_t)i * nq + c] * PhiQ[(size_t)k * nq + c];
        G[(size_t)k * nc + i] = a;
      }
      double b = 0.0; /* F_v already holds Phi_q^T lambda for the current lambda */
      for (int c = 0; c < nq; ++c) b += PhiQ[(size_t)i * nq + c] * Fx[c];
      r[i] = -b;
    }
    if (fmb_lu_factor(nc, G, piv) == 0) {
      fmb_lu_solve(nc, G, piv, r);
      for (int i = 0; i < nc; ++i) x[nq + i] += r[i];
    }
  }
  free(Fx);
  free(PhiQ);
  free(G);
  free(r);
  free(piv);
  return rc;
}

int fmb_static_solve(const fmbModel* m, fmbWorkspace* w, const fmbStaticOptions* opt_in, double* y, double* yp,
                     fmbStaticResult* res, fmbDiag* diag) {
  fmbStaticOptions opt = {0.0, 0, 30, 12, 1e-10, 1};
  if (opt_in) opt = *opt_in;
  if (!opt.has_t) opt.t = m->solver.t0;
  if (opt.max_iter <= 0) opt.max_iter = 30;
  if (opt.max_halvings <= 0) opt.max_halvings = 12;
  if (!(opt.tol > 0.0)) opt.tol = 1e-10;
  const int nq = m->nq, nc = m->nc, ny = m->ny;
  memset(res, 0, sizeof *res);
  res->t = opt.t;
  double* x = calloc((size_t)nq + nc + 1, sizeof(double));
  double* v0 = calloc((size_t)nq + 1, sizeof(double));
  if (x && v0)
    for (int b = 1; b < m->nbody; ++b) {
      const fmbBodyInst* bi = &m->body[b];
      bi->type->initial(bi->self, x + bi->qadr, v0 + bi->qadr);
    }
  const int ng = m->dimension == 3 && x ? fmb_gauge_count(m, x) : 0, n = nq + nc + ng;
  Newton s = {m,    w,    opt.t, 0.0,  {0.0, 0.0}, n,   ng,   {0.0, {0.0, 0.0, 1.0}, {0.0, 0.0, 0.0}, 0.0},
              NULL, NULL, NULL,  NULL, NULL,       0.0, NULL, NULL,
              NULL, NULL, NULL,  NULL, NULL,       NULL};
  if (x) x = realloc(x, (size_t)n * sizeof(double) + 1);
  if (x) memset(x + nq + nc, 0, (size_t)ng * sizeof(double));
  s.D = calloc((size_t)nq * ng + 1, sizeof(double));
  s.E = m->dimension == 3 ? calloc((size_t)nq * nq + 1, sizeof(double)) : NULL;
  if (m->dimension == 3) {
    s.U = calloc((size_t)n * n, sizeof(double));
    s.VT = calloc((size_t)n * n, sizeof(double));
    s.sv = calloc((size_t)n, sizeof(double));
  }
  s.y = calloc((size_t)ny, sizeof(double));
  s.yp = calloc((size_t)ny, sizeof(double));
  s.F = calloc((size_t)ny, sizeof(double));
  s.ewt = calloc((size_t)ny, sizeof(double));
  s.J0 = calloc((size_t)ny * ny, sizeof(double));
  s.J1 = calloc((size_t)ny * ny, sizeof(double));
  s.A = calloc((size_t)n * n, sizeof(double));
  s.piv = calloc((size_t)n, sizeof(int));
  double* xt = calloc((size_t)n, sizeof(double));
  double* F0 = calloc((size_t)n, sizeof(double));
  double* G = calloc((size_t)n, sizeof(double));
  int rc = 0;
  if (!s.y || !s.yp || !s.F || !s.ewt || !s.J0 || !s.J1 || !s.A || !s.piv || !x || !xt || !F0 || !G || !v0 || !s.D ||
      (m->dimension == 3 && (!s.E || !s.U || !s.VT || !s.sv))) {
    fmb_diag_set(diag, FMB_EXIT_SOLVER, m->path, 0, 0, "out of memory for the static solution (%d unknowns)", n);
    rc = FMB_EXIT_SOLVER;
    goto done;
  }
  if (m->dimension == 3) {
    if ((rc = fmb_fit_rotation3(m, w, opt.t, x, &s.rot, diag))) goto done;
    s.speed = s.rot.speed;
    s.center[0] = s.rot.center[0];
    s.center[1] = s.rot.center[1];
  } else if ((rc = fit_rotation(m, w, opt.t, x, &s.speed, s.center, diag))) {
    goto done;
  }
  res->speed = s.speed;
  res->center[0] = s.center[0];
  res->center[1] = s.center[1];
  if (s.speed != 0.0 && m->dimension != 3) turn_to_drives(&s, x);
  if ((rc = initial_multipliers(&s, x, diag))) goto done;
  if (eval_F(&s, x, F0)) {
    fmb_diag_set(diag, FMB_EXIT_SOLVER, m->path, 0, 0, "the equations are not finite at the starting point (t = %g)",
                 opt.t);
    rc = FMB_EXIT_SOLVER;
    goto done;
  }
  res->residual_start = norm2(F0, n);
  s.load = res->residual_start;
  /* No load (a mechanism without gravity, springs or applied forces: the out-of-balance load is
     roundoff, 2e-15 on a pendulum without gravity) and a singular stiffness: every pose along the
     free motion is an equilibrium. Newton then succeeded on a residual of exactly 0 and failed on
     one of 1e-16 ("no equilibrium found"), both answers wrong: say what holds. The test is on the
     pivots of the equilibrium Jacobian (smallest / largest below 1e-12: a roundoff-level pivot
     against the stiffest entry; a 1.8 m aluminium blade's softest pivot is 1e-8 of its stiffest). */
  /* In space gravity (the only load there yet) can balance at the start while a free motion it
     never meets remains (a body hanging on a ball joint spins freely about the vertical): that
     start is an equilibrium, its free motion left where it is as (S4) leaves it. */
  const int loaded_in_space = m->dimension == 3 && m->env.has_gravity;
  if (s.speed == 0.0 && res->residual_start <= FMB_STATIC_NO_LOAD && !loaded_in_space) {
    const int free_motions = singular_stiffness(&s, x);
    if (free_motions < 0) {
      fmb_diag_set(diag, FMB_EXIT_SOLVER, m->path, 0, 0, "the equilibrium equations cannot be evaluated (t = %g)",
                   opt.t);
      rc = FMB_EXIT_SOLVER;
      goto done;
    }
    if (free_motions > 0) {
      fmb_diag_set(
          diag, FMB_EXIT_BAD_INPUT, m->path, 0, 0,
          "no unique equilibrium: nothing loads the system (no gravity, spring or applied force; out-of-balance "
          "load %.3g) and its stiffness is singular, so every pose along its free motion (a mechanism's degree "
          "of freedom, a free body) is in equilibrium. Add the load or the spring that holds it, or fix that "
          "motion with a joint or a drive",
          res->residual_start);
      rc = FMB_EXIT_BAD_INPUT;
      goto done;
    }
  }
  /* already balanced (a structure at rest without loads, free bodies): nothing to solve, and
     nothing to factor where nothing holds a body */
  double done_s = norm2(F0, n) == 0.0 ? 1.0 : 0.0, ds = 1.0;
  int halvings = 0, singular = 0;
  while (done_s < 1.0) {
    const double st = ds >= 1.0 - done_s ? 1.0 : done_s + ds;
    memcpy(xt, x, (size_t)n * sizeof(double));
    int converged = 0, it;
    singular = 0;
    for (it = 0; it < opt.max_iter; ++it) {
      if (eval_F(&s, xt, G)) break;
      for (int i = 0; i < n; ++i) G[i] -= (1.0 - st) * F0[i]; /* (S2) */
      if (factor_jacobian(&s, xt)) {
        singular = 1;
        break;
      }
      if (m->dimension != 3) {
        fmb_lu_solve(n, s.A, s.piv, G);
      } else if (svd_solve(&s, G)) { /* (S4): a load that nothing holds */
        singular = 1;
        break;
      }
      /* a frame turns at most MAX_TURN per iteration: near a mechanism's dead point (a
         pendulum at the horizontal has no stiffness in its angle) the full step would spin it
         through many turns */
      double turn = 0.0;
      if (m->dimension == 3)
        turn = fmb_turn3(m, w, xt, G);
      else
        for (int b = 1; b < m->nbody; ++b)
          if (has_frame(&m->body[b])) turn = fmax(turn, fabs(G[m->body[b].qadr + 2]));
      const double scale = turn > MAX_TURN ? MAX_TURN / turn : 1.0;
      int finite = 1, small = scale == 1.0;
      for (int i = 0; i < n; ++i) {
        if (!isfinite(G[i])) finite = 0;
        if (i < nq && fabs(G[i]) > opt.tol * (1.0 + fabs(xt[i]))) small = 0;
        xt[i] -= scale * G[i];
      }
      res->iterations++;
      if (!finite) break;
      if (small) {
        converged = 1;
        break;
      }
    }
    if (converged) {
      memcpy(x, xt, (size_t)n * sizeof(double));
      done_s = st;
      res->load_steps++;
      if (!opt.quiet && st < 1.0) fmb_warn(w, "static: load %.4g reached in %d Newton iterations", st, it + 1);
      if (ds < 1.0) ds *= 2.0; /* a step that worked: try a longer one */
    } else {
      ds *= 0.5;
      if (++halvings > opt.max_halvings && singular) {
        fmb_diag_set(
            diag, FMB_EXIT_SOLVER, m->path, 0, 0,
            "no equilibrium found: the equilibrium equations are singular (%d Newton iterations): some motion "
            "is held by nothing (a body without supports under a load, a mechanism at a dead point, a pendulum "
            "started exactly horizontal). Support the body, or start it away from the dead point",
            res->iterations);
        rc = FMB_EXIT_SOLVER;
        goto done;
      }
      if (halvings > opt.max_halvings) {
        fmb_diag_set(diag, FMB_EXIT_SOLVER, m->path, 0, 0,
                     "no equilibrium found: Newton failed even on a load step of %.3g of the load, at %.4g of it "
                     "(%d iterations in all). The structure may buckle or snap here, or the load is beyond what the "
                     "model can carry (a beam bent beyond its length)",
                     2.0 * ds, done_s, res->iterations);
        rc = FMB_EXIT_SOLVER;
        goto done;
      }
      if (!opt.quiet) fmb_warn(w, "static: Newton failed at load %.4g; halving the load step to %.3g", st, ds);
    }
  }
  if (eval_F(&s, x, G)) {
    fmb_diag_set(diag, FMB_EXIT_SOLVER, m->path, 0, 0, "the equations are not finite at the solution");
    rc = FMB_EXIT_SOLVER;
    goto done;
  }
  res->residual = norm2(G, n);
  make_state(&s, x);
  memcpy(y, s.y, (size_t)ny * sizeof(double));
  memcpy(yp, s.yp, (size_t)ny * sizeof(double));
done:
  free(s.y);
  free(s.yp);
  free(s.F);
  free(s.ewt);
  free(s.J0);
  free(s.J1);
  free(s.A);
  free(s.piv);
  free(x);
  free(xt);
  free(F0);
  free(G);
  free(v0);
  free(s.D);
  free(s.E);
  free(s.U);
  free(s.VT);
  free(s.sv);
  return rc;
}
