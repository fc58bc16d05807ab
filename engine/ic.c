/* ic.c — consistent initial conditions for the GGL system.
 *
 * 1. positions: Gauss–Newton projection onto Phi(q, t0) = 0, the minimum-norm correction
 *    dq = -Phi_q^T (Phi_q Phi_q^T)^-1 Phi, until max |Phi_i| <= FMB_IC_PHI_TOL: absolute, in
 *    the constraint's own units (m, rad), whatever the coordinates' magnitude (a test relative
 *    to |q| let a pose 1e13 m out "converge" with a 1 m rod violated by 0.9 m). A body moved by
 *    more than FMB_ASSEMBLY_TOL is an error unless the scene says `initial: assemble`: the
 *    projection would otherwise change the mechanism silently;
 * 2. velocities: the minimum-norm correction onto Phi_q v + Phi_t = 0;
 * 3. accelerations and multipliers from the augmented system
 *        [M  Phi_q^T] [a     ]   [Q    ]
 *        [Phi_q   0 ] [lambda] = [gamma],   gamma = -(Phi_q v)_q v - Phi_tt,
 *    so IDA starts from F(t0, y0, y0') = 0. mu = 0. The sizes of the corrections are reported.
 * Setup-time code: it may allocate. */
#include <float.h>
#include <math.h>
#include <stdlib.h>
#include <string.h>
#include <klu.h>

#include "internal.h"

#define FMB_IC_PHI_TOL 1e-10   /* m or rad: joints hold to 0.1 nm, 0.1 nrad at t0 */
#define FMB_ASSEMBLY_TOL 1e-6  /* m or rad: a larger initial correction changes the mechanism */

static double max_abs(const double* x, int n) {
  double s = 0.0;
  for (int i = 0; i < n; ++i) s = fmax(s, fabs(x[i]));
  return s;
}

static double norm2(const double* x, int n) {
  double s = 0.0;
  for (int i = 0; i < n; ++i) s += x[i] * x[i];
  return sqrt(s);
}

/* G = Phi_q Phi_q^T (column-major nc x nc) from the row-major nc x nq Phi_q; LU in place */
static int gram_factor(int nc, int nq, const double* PhiQ, double* G, int* piv) {
  for (int i = 0; i < nc; ++i)
    for (int k = 0; k < nc; ++k) {
      double s = 0.0;
      for (int c = 0; c < nq; ++c) s += PhiQ[(size_t)i * nq + c] * PhiQ[(size_t)k * nq + c];
      G[(size_t)k * nc + i] = s;
    }
  return fmb_lu_factor(nc, G, piv);
}

/* gamma = -(Phi_q v)_q v - Phi_tt, the right side of Phi_q a = gamma; fills PhiQ (dense nc x nq).
   (Phi_q v)_q v by a central difference along v. */
static void acceleration_rhs(const fmbModel* m, fmbWorkspace* w, double t0, const double* q, const double* v,
                             double* PhiQ, double* PhiQ2, double* phi, double* phit, double* phitt, double* qs,
                             double* gamma) {
  const int nq = m->nq, nc = m->nc;
  fmb_constraints_all(m, w, t0, q, v, phi, PhiQ, phit, phitt);
  double vn = norm2(v, nq);
  double h = vn > 0 ? 1e-5 * (1.0 + norm2(q, nq)) / vn : 0.0;
  double* dpv = phit; /* reuse: holds (Phi_q v)_q v below */
  memset(dpv, 0, (size_t)nc * sizeof(double));
  if (h > 0) {
    for (int i = 0; i < nq; ++i) qs[i] = q[i] + h * v[i];
    fmb_constraints_all(m, w, t0, qs, v, NULL, PhiQ2, NULL, NULL);
    for (int r = 0; r < nc; ++r)
      for (int c = 0; c < nq; ++c) dpv[r] += PhiQ2[(size_t)r * nq + c] * v[c];
    for (int i = 0; i < nq; ++i) qs[i] = q[i] - h * v[i];
    fmb_constraints_all(m, w, t0, qs, v, NULL, PhiQ2, NULL, NULL);
    for (int r = 0; r < nc; ++r) {
      double s = 0.0;
      for (int c = 0; c < nq; ++c) s += PhiQ2[(size_t)r * nq + c] * v[c];
      dpv[r] = (dpv[r] - s) / (2.0 * h);
    }
  }
  for (int r = 0; r < nc; ++r) gamma[r] = -dpv[r] - phitt[r];
}

static int model_has_sparse_body(const fmbModel* m) {
  for (int b = 1; b < m->nbody; ++b)
    if (m->body[b].pnnz >= 0) return 1;
  return 0;
}

typedef struct {
  long n, cap;
  SuiteSparse_long* row;
  SuiteSparse_long* col;
  double* val;
} Triplets;

static int trip_add(Triplets* t, long r, long c, double v) {
  if (t->n == t->cap) {
    long ncap = t->cap ? 2 * t->cap : 4096;
    SuiteSparse_long* nr = realloc(t->row, sizeof(SuiteSparse_long) * (size_t)ncap);
    if (nr) t->row = nr;
    SuiteSparse_long* nc = realloc(t->col, sizeof(SuiteSparse_long) * (size_t)ncap);
    if (nc) t->col = nc;
    double* nv = realloc(t->val, sizeof(double) * (size_t)ncap);
    if (nv) t->val = nv;
    if (!nr || !nc || !nv) return -1;
    t->cap = ncap;
  }
  t->row[t->n] = r;
  t->col[t->n] = c;
  t->val[t->n++] = v;
  return 0;
}

/* Initial accelerations a, multipliers lambda and auxiliary unknowns z when a body declared a
 * sparse pattern (a banded beam), where the dense augmented system below would take
 * (nq + nc)^2 memory and cubic time. Solve instead, for x = [a, z, lambda],
 *     G_v = R(q, v, a, z) + Phi_q^T lambda - Q_joints = 0,   G_z = Rz(q, v, a, z) = 0,
 *     G_c = Phi_q a - gamma = 0
 * by Newton with KLU on the sparse G_x (the bodies' own blocks by differences over their
 * patterns: exact, since G is linear in a and lambda and at most quadratic in z; a dense body
 * enters with its mass matrix). Returns 0 or an exit code with diag set. */
static int sparse_accelerations(const fmbModel* m, fmbWorkspace* w, double t0, double* y, double* yp,
                                const double* PhiQ, const double* gamma, fmbDiag* diag) {
  const int nq = m->nq, nz = m->nz, nc = m->nc, N = nq + nz + nc;
  const double *q = y, *v = y + nq;
  double* x = calloc((size_t)N + 1, sizeof(double));
  double* G = calloc((size_t)N + 1, sizeof(double));
  double* Qj = calloc((size_t)nq + 1, sizeof(double));
  double* ewt = calloc(2 * (size_t)nq + 1, sizeof(double));
  double* blk = NULL;
  size_t nblk = 1;
  for (int b = 1; b < m->nbody; ++b) {
    const fmbBodyInst* bi = &m->body[b];
    size_t k = bi->pnnz >= 0 ? 3 * (size_t)bi->pnnz : (size_t)bi->nq * (size_t)bi->nq;
    if (k > nblk) nblk = k;
  }
  blk = calloc(nblk, sizeof(double));
  size_t nrb = 1, nscr = 1;
  for (int b = 1; b < m->nbody; ++b) {
    const fmbBodyInst* bi = &m->body[b];
    if ((size_t)(bi->nq + bi->nz) > nrb) nrb = (size_t)(bi->nq + bi->nz);
    if (bi->pnnz >= 0 && fmb_fd_sparse_scratch(bi) > nscr) nscr = fmb_fd_sparse_scratch(bi);
  }
  double* Rb = calloc(nrb, sizeof(double));
  double* scratch = calloc(nscr, sizeof(double));
  Triplets t = {0, 0, NULL, NULL, NULL};
  SuiteSparse_long *Ap = calloc((size_t)N + 1, sizeof(SuiteSparse_long)), *Ai = NULL;
  double* Ax = NULL;
  klu_l_common common;
  klu_l_defaults(&common);
  klu_l_symbolic* sym = NULL;
  klu_l_numeric* num = NULL;
  int rc = (!x || !G || !Qj || !ewt || !blk || !Ap || !Rb || !scratch) ? FMB_EXIT_SOLVER : 0;
  const char* why = "out of memory computing initial accelerations";
  /* the joints' forces: all forces less the bodies' own (-R at a = 0) */
  if (!rc && fmb_generalized_forces(m, w, t0, q, v, Qj)) rc = FMB_EXIT_SOLVER, why = "the generalized forces are not finite";
  for (int b = 1; b < m->nbody && !rc; ++b) {
    const fmbBodyInst* bi = &m->body[b];
    if (bi->type->residual(bi->self, &m->env, q + bi->qadr, v + bi->qadr, x, G, fmb_workspace_plugin(w) + bi->workadr))
      rc = FMB_EXIT_SOLVER, why = "the generalized forces are not finite";
    for (int i = 0; i < bi->nq && !rc; ++i) Qj[bi->qadr + i] += G[i];
  }
  for (int i = 0; i < nq; ++i) ewt[i] = ewt[nq + i] = 1.0 / (m->solver.atol + m->solver.rtol * fabs(y[i]));
  double* a = x;
  double* z = x + nq;
  double* lam = x + nq + nz;
  for (int b = 1; b < m->nbody && !rc; ++b) {
    const fmbBodyInst* bi = &m->body[b];
    if (bi->nz > 0 && bi->type->aux_initial(bi->self, &m->env, q + bi->qadr, v + bi->qadr, a + bi->qadr, z + bi->zadr,
                                            fmb_workspace_plugin(w) + bi->workadr))
      rc = FMB_EXIT_SOLVER, why = "the auxiliary unknowns are not finite";
  }
  int converged = 0;
  for (int it = 0; it < 20 && !rc && !converged; ++it) {
    /* G(x) */
    for (int b = 1; b < m->nbody && !rc; ++b) {
      const fmbBodyInst* bi = &m->body[b];
      double* R = Rb; /* R then Rz */
      if (fmb_body_eval(bi, &m->env, q + bi->qadr, v + bi->qadr, a + bi->qadr, z + bi->zadr, R,
                        fmb_workspace_plugin(w) + bi->workadr))
        rc = FMB_EXIT_SOLVER, why = "the equations of motion are not finite";
      for (int i = 0; i < bi->nq; ++i) G[bi->qadr + i] = R[i] - Qj[bi->qadr + i];
      for (int i = 0; i < bi->nz; ++i) G[nq + bi->zadr + i] = R[bi->nq + i];
    }
    for (int r = 0; r < nc; ++r) {
      double s = -gamma[r];
      for (int c = 0; c < nq; ++c) {
        const double d = PhiQ[(size_t)r * nq + c];
        s += d * a[c];
        G[c] += d * lam[r];
      }
      G[nq + nz + r] = s;
    }
    /* G_x as triplets, then CSC */
    t.n = 0;
    for (int b = 1; b < m->nbody && !rc; ++b) {
      const fmbBodyInst* bi = &m->body[b];
      const int nb = bi->nq;
      if (bi->pnnz >= 0) {
        double *K = blk, *C = K + bi->pnnz, *M = C + bi->pnnz;
        if (fmb_fd_body_sparse(bi, &m->env, q + bi->qadr, v + bi->qadr, a + bi->qadr, z + bi->zadr, ewt + bi->qadr,
                               ewt + nq + bi->qadr, K, C, M, fmb_workspace_plugin(w) + bi->workadr, scratch))
          rc = FMB_EXIT_SOLVER, why = "the equations of motion are not finite";
        for (int c = 0; c < nb + bi->nz && !rc; ++c)
          for (long k = bi->pcolptr[c]; k < bi->pcolptr[c + 1] && !rc; ++k) {
            const int r = bi->prowind[k];
            const long row = r < nb ? bi->qadr + r : nq + bi->zadr + (r - nb);
            const long col = c < nb ? bi->qadr + c : nq + bi->zadr + (c - nb);
            const double val = c < nb ? M[k] : K[k];
            if (trip_add(&t, row, col, val)) rc = FMB_EXIT_SOLVER;
          }
      } else {
        if (fmb_body_mass(m, w, b, q + bi->qadr, v + bi->qadr, blk)) rc = FMB_EXIT_SOLVER, why = "the mass matrix could not be evaluated";
        for (int c = 0; c < nb && !rc; ++c)
          for (int r = 0; r < nb && !rc; ++r)
            if (trip_add(&t, bi->qadr + r, bi->qadr + c, blk[(size_t)c * nb + r])) rc = FMB_EXIT_SOLVER;
      }
    }
    for (int r = 0; r < nc && !rc; ++r)
      for (int c = 0; c < nq && !rc; ++c) {
        const double d = PhiQ[(size_t)r * nq + c];
        if (d != 0.0 && (trip_add(&t, nq + nz + r, c, d) || trip_add(&t, c, nq + nz + r, d))) rc = FMB_EXIT_SOLVER;
      }
    if (rc) break;
    if (!Ai) {
      Ai = malloc(sizeof(SuiteSparse_long) * (size_t)(t.n + 1));
      Ax = malloc(sizeof(double) * (size_t)(t.n + 1));
      if (!Ai || !Ax) {
        rc = FMB_EXIT_SOLVER;
        break;
      }
    }
    /* counting sort by column; within a column the rows come in increasing order from each
       block, and blocks do not overlap, but KLU wants them sorted: sort each column */
    memset(Ap, 0, sizeof(SuiteSparse_long) * ((size_t)N + 1));
    for (long k = 0; k < t.n; ++k) Ap[t.col[k] + 1]++;
    for (int c = 0; c < N; ++c) Ap[c + 1] += Ap[c];
    for (long k = 0; k < t.n; ++k) {
      const long pos = Ap[t.col[k]]++;
      Ai[pos] = t.row[k];
      Ax[pos] = t.val[k];
    }
    for (int c = N; c > 0; --c) Ap[c] = Ap[c - 1];
    Ap[0] = 0;
    for (int c = 0; c < N; ++c) /* insertion sort: columns are short */
      for (SuiteSparse_long k = Ap[c] + 1; k < Ap[c + 1]; ++k) {
        SuiteSparse_long r = Ai[k];
        double vv = Ax[k];
        SuiteSparse_long j = k - 1;
        while (j >= Ap[c] && Ai[j] > r) {
          Ai[j + 1] = Ai[j];
          Ax[j + 1] = Ax[j];
          --j;
        }
        Ai[j + 1] = r;
        Ax[j + 1] = vv;
      }
    if (!sym) sym = klu_l_analyze(N, Ap, Ai, &common);
    if (num) klu_l_free_numeric(&num, &common);
    num = sym ? klu_l_factor(Ap, Ai, Ax, sym, &common) : NULL;
    if (!num) {
      rc = FMB_EXIT_BAD_INPUT;
      why = "the initial mass matrix is singular on the free motions (a body without mass or inertia, or a mechanism "
            "with redundant joints): cannot compute initial accelerations";
      break;
    }
    if (!klu_l_solve(sym, num, N, 1, G, &common)) {
      rc = FMB_EXIT_SOLVER;
      break;
    }
    double dmax = 0.0, xmax = 0.0;
    for (int i = 0; i < N; ++i) {
      x[i] -= G[i];
      dmax = fmax(dmax, fabs(G[i]));
      xmax = fmax(xmax, fabs(x[i]));
    }
    if (!isfinite(dmax)) {
      rc = FMB_EXIT_SOLVER;
      why = "initial accelerations are not finite";
    }
    converged = dmax <= 1e-13 * (1.0 + xmax);
  }
  if (!rc && !converged) rc = FMB_EXIT_SOLVER, why = "Newton's method did not converge on the initial accelerations";
  if (rc) {
    fmb_diag_set(diag, rc, m->path, 0, 0, "%s at t = %g", why, t0);
  } else {
    memcpy(yp, v, (size_t)nq * sizeof(double));
    memcpy(yp + nq, a, (size_t)nq * sizeof(double));
    memcpy(y + 2 * nq, lam, (size_t)nc * sizeof(double));
    memcpy(y + m->zoff, z, (size_t)nz * sizeof(double));
  }
  if (num) klu_l_free_numeric(&num, &common);
  if (sym) klu_l_free_symbolic(&sym, &common);
  free(x), free(G), free(Qj), free(ewt), free(blk), free(Rb), free(scratch), free(Ap), free(Ai), free(Ax);
  free(t.row), free(t.col), free(t.val);
  return rc;
}

int fmb_initial_conditions(const fmbModel* m, fmbWorkspace* w, double* y, double* yp, fmbStats* st, fmbDiag* diag) {
  const int nq = m->nq, nc = m->nc, n = nq + nc;
  const double t0 = m->solver.t0;
  double* q = y;
  double* v = y + nq;
  memset(y, 0, (size_t)m->ny * sizeof(double));
  memset(yp, 0, (size_t)m->ny * sizeof(double));
  for (int b = 1; b < m->nbody; ++b) {
    const fmbBodyInst* bi = &m->body[b];
    bi->type->initial(bi->self, q + bi->qadr, v + bi->qadr);
  }
  double* PhiQ = calloc((size_t)(nc ? nc : 1) * nq, sizeof(double));
  double* PhiQ2 = calloc((size_t)(nc ? nc : 1) * nq, sizeof(double));
  double* phi = calloc((size_t)nc + 1, sizeof(double));
  double* phit = calloc((size_t)nc + 1, sizeof(double));
  double* phitt = calloc((size_t)nc + 1, sizeof(double));
  double* G = calloc((size_t)nc * nc + 1, sizeof(double));
  int* piv = calloc((size_t)n + 1, sizeof(int));
  const int sparse = model_has_sparse_body(m);
  double* A = sparse ? NULL : calloc((size_t)n * n, sizeof(double));
  double* rhs = calloc((size_t)n + 1, sizeof(double));
  double* q0 = calloc((size_t)nq, sizeof(double));
  double* v0 = calloc((size_t)nq, sizeof(double));
  double* qs = calloc((size_t)nq, sizeof(double));
  int rc = 0;
  if (!PhiQ || !PhiQ2 || !phi || !phit || !phitt || !G || !piv || (!A && !sparse) || !rhs || !q0 || !v0 || !qs) {
    fmb_diag_set(diag, FMB_EXIT_SOLVER, m->path, 0, 0, "out of memory computing initial conditions");
    rc = FMB_EXIT_SOLVER;
    goto done;
  }
  if (m->initial_static) {
    /* `initial: static`: the static or steady state at t0 replaces the bodies' initial poses */
    fmbStaticOptions so = {t0, 1, 0, 0, 0.0, 1};
    fmbStaticResult sr;
    if ((rc = fmb_static_solve(m, w, &so, y, yp, &sr, diag))) goto done;
    memset(y + nq, 0, (size_t)(m->ny - nq) * sizeof(double));
    fmb_rigid_rotation(m, sr.speed, sr.center, q, v, yp + nq);
  }
  memcpy(q0, q, (size_t)nq * sizeof(double));
  memcpy(v0, v, (size_t)nq * sizeof(double));

  if (nc > 0) {
    double res = 0.0;
    int it, converged = 0;
    for (it = 0; it < 50; ++it) {
      if (fmb_constraints_all(m, w, t0, q, v, phi, PhiQ, phit, phitt)) break;
      res = max_abs(phi, nc);
      if (res <= FMB_IC_PHI_TOL) {
        converged = 1;
        break;
      }
      if (gram_factor(nc, nq, PhiQ, G, piv)) break;
      memcpy(rhs, phi, (size_t)nc * sizeof(double));
      fmb_lu_solve(nc, G, piv, rhs);
      for (int c = 0; c < nq; ++c) {
        double s = 0.0;
        for (int r = 0; r < nc; ++r) s += PhiQ[(size_t)r * nq + c] * rhs[r];
        q[c] -= s;
      }
    }
    if (!converged) {
      /* far from the origin double precision cannot resolve FMB_IC_PHI_TOL: say so */
      const double qmax = max_abs(q, nq);
      char far[160] = "";
      if (qmax * 1e-15 > 0.1 * FMB_IC_PHI_TOL)
        snprintf(far, sizeof far, "; coordinates reach %.3g, too far out for double precision to hold joints to %g",
                 qmax, FMB_IC_PHI_TOL);
      fmb_diag_set(diag, FMB_EXIT_BAD_INPUT, m->path, 0, 0,
                   "the joints cannot all be satisfied at t = %g (constraint residual %.3g, tolerance %g, after %d projection steps, "
                   "or redundant constraints): check the joints' points, the bodies' initial poses, and that no joint repeats another%s",
                   t0, res, FMB_IC_PHI_TOL, it, far);
      rc = FMB_EXIT_BAD_INPUT;
      goto done;
    }
    /* velocities */
    if (gram_factor(nc, nq, PhiQ, G, piv)) {
      fmb_diag_set(diag, FMB_EXIT_BAD_INPUT, m->path, 0, 0, "redundant constraints: the joints' equations are not independent");
      rc = FMB_EXIT_BAD_INPUT;
      goto done;
    }
    for (int r = 0; r < nc; ++r) {
      double s = phit[r];
      for (int c = 0; c < nq; ++c) s += PhiQ[(size_t)r * nq + c] * v[c];
      rhs[r] = s;
    }
    fmb_lu_solve(nc, G, piv, rhs);
    for (int c = 0; c < nq; ++c) {
      double s = 0.0;
      for (int r = 0; r < nc; ++r) s += PhiQ[(size_t)r * nq + c] * rhs[r];
      v[c] -= s;
    }
  }
  for (int i = 0; i < nq; ++i) {
    q0[i] = q[i] - q0[i];
    v0[i] = v[i] - v0[i];
  }
  /* coordinates so large that a double cannot resolve the joint tolerance: the run would hold
     its joints only to that resolution (a bob projected from 1e13 m got an angle of -3e12 rad,
     resolved to 5e-4 rad) */
  const double qmax = max_abs(q, nq);
  if (qmax * DBL_EPSILON > FMB_IC_PHI_TOL) {
    fmb_diag_set(diag, FMB_EXIT_BAD_INPUT, m->path, 0, 0,
                 "the initial coordinates reach %.3g (m or rad)%s: at that magnitude a double resolves only %.2g, coarser "
                 "than the joints' tolerance %g. Place the mechanism near the origin",
                 qmax, m->assemble ? " after assembly" : "", qmax * DBL_EPSILON, FMB_IC_PHI_TOL);
    rc = FMB_EXIT_BAD_INPUT;
    goto done;
  }
  /* the body the projection moved most: beyond FMB_ASSEMBLY_TOL only if the scene asks */
  int worst = 0;
  double moved = 0.0;
  for (int b = 1; b < m->nbody; ++b) {
    const double d = max_abs(q0 + m->body[b].qadr, m->body[b].nq);
    if (d > moved) {
      moved = d;
      worst = b;
    }
  }
  if (moved > FMB_ASSEMBLY_TOL && !m->assemble) {
    fmb_diag_set(diag, FMB_EXIT_BAD_INPUT, m->path, 0, 0,
                 "the joints are not satisfied by the poses given: they move body '%s' by %.3g (the largest change of "
                 "one of its coordinates, m or rad; tolerance %g). Give poses that satisfy the joints, or write "
                 "`initial: assemble` at the top level to let flexmbd move the bodies onto them",
                 m->body[worst].name, moved, FMB_ASSEMBLY_TOL);
    rc = FMB_EXIT_BAD_INPUT;
    goto done;
  }
  st->ic_position_correction = norm2(q0, nq);
  st->ic_velocity_correction = norm2(v0, nq);

  if (sparse) {
    acceleration_rhs(m, w, t0, q, v, PhiQ, PhiQ2, phi, phit, phitt, qs, rhs + nq);
    rc = sparse_accelerations(m, w, t0, y, yp, PhiQ, rhs + nq, diag);
    goto done;
  }
  /* augmented system for accelerations and multipliers */
  for (int b = 1; b < m->nbody; ++b) {
    const fmbBodyInst* bi = &m->body[b];
    double* Mb = calloc((size_t)bi->nq * bi->nq, sizeof(double));
    if (!Mb || fmb_body_mass(m, w, b, q + bi->qadr, v + bi->qadr, Mb)) {
      free(Mb);
      fmb_diag_set(diag, FMB_EXIT_SOLVER, m->path, 0, 0, "could not evaluate the mass matrix of body '%s' at t = %g", bi->name, t0);
      rc = FMB_EXIT_SOLVER;
      goto done;
    }
    for (int c = 0; c < bi->nq; ++c)
      for (int r = 0; r < bi->nq; ++r) A[(size_t)(bi->qadr + c) * n + bi->qadr + r] = Mb[(size_t)c * bi->nq + r];
    free(Mb);
  }
  if (fmb_generalized_forces(m, w, t0, q, v, rhs)) {
    fmb_diag_set(diag, FMB_EXIT_SOLVER, m->path, 0, 0, "the generalized forces are not finite at t = %g", t0);
    rc = FMB_EXIT_SOLVER;
    goto done;
  }
  if (nc > 0) {
    acceleration_rhs(m, w, t0, q, v, PhiQ, PhiQ2, phi, phit, phitt, qs, rhs + nq);
    for (int r = 0; r < nc; ++r)
      for (int c = 0; c < nq; ++c) {
        A[(size_t)c * n + nq + r] = PhiQ[(size_t)r * nq + c];
        A[(size_t)(nq + r) * n + c] = PhiQ[(size_t)r * nq + c];
      }
  }
  if (fmb_lu_factor(n, A, piv)) {
    fmb_diag_set(diag, FMB_EXIT_BAD_INPUT, m->path, 0, 0,
                 "the initial mass matrix is singular on the free motions (a body without mass or inertia, or a mechanism "
                 "with redundant joints): cannot compute initial accelerations");
    rc = FMB_EXIT_BAD_INPUT;
    goto done;
  }
  fmb_lu_solve(n, A, piv, rhs);
  memcpy(yp, v, (size_t)nq * sizeof(double));
  memcpy(yp + nq, rhs, (size_t)nq * sizeof(double));
  memcpy(y + 2 * nq, rhs + nq, (size_t)nc * sizeof(double));
  for (int i = 0; i < n; ++i)
    if (!isfinite(rhs[i])) {
      fmb_diag_set(diag, FMB_EXIT_SOLVER, m->path, 0, 0, "initial accelerations are not finite");
      rc = FMB_EXIT_SOLVER;
      break;
    }
  /* the bodies' auxiliary unknowns, consistent with (q, v, a) */
  for (int b = 1; b < m->nbody && !rc; ++b) {
    const fmbBodyInst* bi = &m->body[b];
    if (bi->nz > 0 && bi->type->aux_initial(bi->self, &m->env, q + bi->qadr, v + bi->qadr, yp + nq + bi->qadr,
                                            y + m->zoff + bi->zadr, fmb_workspace_plugin(w) + bi->workadr)) {
      fmb_diag_set(diag, FMB_EXIT_SOLVER, m->path, 0, 0, "the auxiliary unknowns of body '%s' are not finite at t = %g",
                   bi->name, t0);
      rc = FMB_EXIT_SOLVER;
    }
  }
done:
  free(PhiQ);
  free(PhiQ2);
  free(phi);
  free(phit);
  free(phitt);
  free(G);
  free(piv);
  free(A);
  free(rhs);
  free(q0);
  free(v0);
  free(qs);
  return rc;
}
