/* augmented.c — the index-1 form of the equations of motion, on a sparse matrix:
 *
 *     [M      Phi_q^T] [a     ]   [Q    ]
 *     [Phi_q  -eps I ] [lambda] = [gamma],   gamma = -(Phi_q v)_q v - Phi_tt
 *
 * (eps = 0, or a Tikhonov shift that keeps the multipliers defined, minimum-norm, where Phi_q
 * loses rank: a redundant joint, a singular configuration). Used by the initial conditions
 * (ic.c), the reaction outputs (system.c's fmb_output_multipliers), the mass-orthogonal
 * projections onto the constraints (fmb_project_state, Bayo & Ledesma 1996) and the projected
 * formulation's right-hand side (integrator_cvode.c).
 *
 * The matrix is sparse: the bodies' mass blocks and, per joint, its rows times the columns of its
 * bodies (fmb_joint_cols). KLU factors it (partial pivoting: the matrix is a saddle point, not
 * definite); the pattern and KLU's ordering are built once in fmb_augmented_new, and an evaluation
 * refactorizes with the last pivot order (it allocates only when that order has to be renewed),
 * so it costs what the mechanism's sparsity costs (a chain of linkages grows
 * linearly, where the dense matrix of earlier versions grew with the cube). */
#include <klu.h>
#include <math.h>
#include <stdlib.h>
#include <string.h>

#include "internal.h"
#include "klu_policy.h"

struct fmbAugmented {
  int nq, nc, n;
  SuiteSparse_long *Ap, *Ai;
  double* Ax;
  /* per constraint row rr (of nc), entries k = rowptr[rr] .. rowptr[rr+1]-1: the q column col[k],
     the positions of Phi_q(rr, col) (column nq + rr) and of Phi_q^T (column col) in Ax */
  int *rowptr, *col;
  /* per constraint row rr, per column c of its joint's fmb_joint_cols list (from eoff[rr] on):
     the merged entry k that column adds to (two columns of one body pair may coincide) */
  int *eoff, *entry;
  long *pos_phi, *pos_phit, *pos_diag;
  double *phi, *phit, *phitt, *phiq_v, *rhs, *Mb;
  fmbKlu* klu;        /* klu.c: the one KLU policy */
  double mdiag, pmax; /* scales of the last assembly (for the Tikhonov shift) */
  int failed_body;
};

int fmb_augmented_failed_body(const fmbAugmented* g) { return g ? g->failed_body : 0; }

static long find_entry(const fmbAugmented* g, long row, long col) {
  SuiteSparse_long lo = g->Ap[col], hi = g->Ap[col + 1] - 1;
  while (lo <= hi) {
    const SuiteSparse_long mid = (lo + hi) / 2;
    if (g->Ai[mid] == row) return mid;
    if (g->Ai[mid] < row)
      lo = mid + 1;
    else
      hi = mid - 1;
  }
  return -1;
}

static int cmp_long(const void* a, const void* b) {
  const SuiteSparse_long x = *(const SuiteSparse_long*)a, y = *(const SuiteSparse_long*)b;
  return (x > y) - (x < y);
}

fmbAugmented* fmb_augmented_new(const fmbModel* m) {
  fmbAugmented* g = calloc(1, sizeof *g);
  if (!g) return NULL;
  const int nq = m->nq, nc = m->nc, n = nq + nc;
  g->nq = nq;
  g->nc = nc;
  g->n = n;
  int mb = 1, mc = 1;
  for (int b = 1; b < m->nbody; ++b)
    if (m->body[b].nq > mb) mb = m->body[b].nq;
  for (int j = 0; j < m->njoint; ++j) {
    int c = 0;
    for (int k = 0; k < 2; ++k)
      if (m->joint[j].body[k] >= 0) c += m->body[m->joint[j].body[k]].nq;
    if (c > mc) mc = c;
  }
  int* cols = calloc((size_t)mc, sizeof(int));
  /* row structure of Phi_q: the columns of each joint's bodies, sorted, duplicates merged */
  g->rowptr = calloc((size_t)nc + 1, sizeof(int));
  long nphi = 0;
  for (int j = 0; j < m->njoint; ++j) nphi += (long)m->joint[j].nrows * mc;
  g->col = calloc((size_t)nphi + 1, sizeof(int));
  g->eoff = calloc((size_t)nc + 1, sizeof(int));
  g->entry = calloc((size_t)nphi + 1, sizeof(int));
  if (!cols || !g->rowptr || !g->col || !g->eoff || !g->entry) goto fail;
  {
    int k = 0, e = 0;
    for (int j = 0; j < m->njoint; ++j) {
      const fmbJointInst* ji = &m->joint[j];
      if (ji->nrows == 0) continue;
      const int ncol = fmb_joint_cols(m, ji, cols);
      for (int r = 0; r < ji->nrows; ++r) {
        const int rr = ji->rowadr + r;
        g->rowptr[rr] = k;
        g->eoff[rr] = e;
        for (int c = 0; c < ncol; ++c) {
          int at = g->rowptr[rr];
          while (at < k && g->col[at] != cols[c]) ++at;
          if (at == k) g->col[k++] = cols[c];
          g->entry[e++] = at;
        }
      }
    }
    g->rowptr[nc] = k; /* rows are numbered joint by joint */
    g->eoff[nc] = e;
  }
  const long nnz_phi = g->rowptr[nc];
  /* CSC pattern: mass blocks, Phi_q^T (rows < nq in the multiplier columns), Phi_q, diagonal */
  long nnz = 2 * nnz_phi + nc;
  for (int b = 1; b < m->nbody; ++b) nnz += (long)m->body[b].nq * m->body[b].nq;
  g->Ap = calloc((size_t)n + 1, sizeof(SuiteSparse_long));
  g->Ai = calloc((size_t)nnz + 1, sizeof(SuiteSparse_long));
  g->Ax = calloc((size_t)nnz + 1, sizeof(double));
  g->pos_phi = calloc((size_t)nnz_phi + 1, sizeof(long));
  g->pos_phit = calloc((size_t)nnz_phi + 1, sizeof(long));
  g->pos_diag = calloc((size_t)nc + 1, sizeof(long));
  g->phi = calloc((size_t)nc + 1, sizeof(double));
  g->phit = calloc((size_t)nc + 1, sizeof(double));
  g->phitt = calloc((size_t)nc + 1, sizeof(double));
  g->phiq_v = calloc((size_t)nc + 1, sizeof(double));
  g->rhs = calloc((size_t)n + 1, sizeof(double));
  g->Mb = calloc((size_t)mb * mb, sizeof(double));
  if (!g->Ap || !g->Ai || !g->Ax || !g->pos_phi || !g->pos_phit || !g->pos_diag || !g->phi || !g->phit || !g->phitt ||
      !g->phiq_v || !g->rhs || !g->Mb)
    goto fail;
  /* count per column, then fill, then sort each column */
  for (int b = 1; b < m->nbody; ++b)
    for (int c = 0; c < m->body[b].nq; ++c) g->Ap[m->body[b].qadr + c + 1] += m->body[b].nq;
  for (int rr = 0; rr < nc; ++rr) {
    for (int k = g->rowptr[rr]; k < g->rowptr[rr + 1]; ++k) g->Ap[g->col[k] + 1]++;
    g->Ap[nq + rr + 1] += g->rowptr[rr + 1] - g->rowptr[rr] + 1;
  }
  for (int c = 0; c < n; ++c) g->Ap[c + 1] += g->Ap[c];
  {
    SuiteSparse_long* fill = calloc((size_t)n + 1, sizeof(SuiteSparse_long));
    if (!fill) goto fail;
    memcpy(fill, g->Ap, sizeof(SuiteSparse_long) * (size_t)n);
    for (int b = 1; b < m->nbody; ++b) {
      const fmbBodyInst* bi = &m->body[b];
      for (int c = 0; c < bi->nq; ++c)
        for (int r = 0; r < bi->nq; ++r) g->Ai[fill[bi->qadr + c]++] = bi->qadr + r;
    }
    for (int rr = 0; rr < nc; ++rr) {
      for (int k = g->rowptr[rr]; k < g->rowptr[rr + 1]; ++k) {
        g->Ai[fill[g->col[k]]++] = nq + rr;
        g->Ai[fill[nq + rr]++] = g->col[k];
      }
      g->Ai[fill[nq + rr]++] = nq + rr;
    }
    free(fill);
  }
  for (int c = 0; c < n; ++c)
    qsort(g->Ai + g->Ap[c], (size_t)(g->Ap[c + 1] - g->Ap[c]), sizeof(SuiteSparse_long), cmp_long);
  for (int rr = 0; rr < nc; ++rr) {
    for (int k = g->rowptr[rr]; k < g->rowptr[rr + 1]; ++k) {
      g->pos_phi[k] = find_entry(g, nq + rr, g->col[k]);
      g->pos_phit[k] = find_entry(g, g->col[k], nq + rr);
    }
    g->pos_diag[rr] = find_entry(g, nq + rr, nq + rr);
  }
  /* plain partial pivoting (KLU's default 1e-3 prefers a diagonal pivot 1000x smaller than the
     column's largest: a small inertia beside unit constraint rows is then a poor pivot) */
  g->klu = fmb_klu_new(n, g->Ap, g->Ai, FMB_KLU_PARTIAL_PIVOTING);
  if (!g->klu) goto fail;
  free(cols);
  return g;
fail:
  free(cols);
  fmb_augmented_free(g);
  return NULL;
}

void fmb_augmented_free(fmbAugmented* g) {
  if (!g) return;
  fmb_klu_free(g->klu);
  free(g->Ap);
  free(g->Ai);
  free(g->Ax);
  free(g->rowptr);
  free(g->col);
  free(g->eoff);
  free(g->entry);
  free(g->pos_phi);
  free(g->pos_phit);
  free(g->pos_diag);
  double* bufs[] = {g->phi, g->phit, g->phitt, g->phiq_v, g->rhs, g->Mb};
  for (size_t i = 0; i < sizeof bufs / sizeof bufs[0]; ++i) free(bufs[i]);
  free(g);
}

/* Fill and factor the matrix at (q, v, t): masses, Phi_q, -eps on the multipliers' diagonal with
   eps = tikhonov |Phi_q|max^2 / |M|max (relative to Phi_q M^-1 Phi_q^T's scale). Rows marked in
   drop are out of the equations (lambda_r = 0). Also keeps phi, phi_t, phi_tt and Phi_q v. */
static int assemble(const fmbModel* m, fmbWorkspace* w, fmbAugmented* g, double t, const double* q, const double* v,
                    const unsigned char* drop, double tikhonov) {
  memset(g->Ax, 0, sizeof(double) * (size_t)g->Ap[g->n]);
  double mdiag = 0.0, pmax = 0.0;
  for (int b = 1; b < m->nbody; ++b) {
    const fmbBodyInst* bi = &m->body[b];
    if (fmb_body_mass(m, w, b, q + bi->qadr, v + bi->qadr, g->Mb)) {
      g->failed_body = b;
      return FMB_AUG_MASS_FAILED;
    }
    for (int c = 0; c < bi->nq; ++c) {
      double* colx = g->Ax + g->Ap[bi->qadr + c]; /* the block's rows come first in its columns */
      for (int r = 0; r < bi->nq; ++r) colx[r] = g->Mb[(size_t)c * bi->nq + r];
      mdiag = fmax(mdiag, fabs(g->Mb[(size_t)c * bi->nq + c]));
    }
  }
  int* cols = fmb_workspace_cols(w);
  double *jphi = fmb_workspace_joint_scratch(w, 0), *jphiq = fmb_workspace_joint_scratch(w, 1),
         *jphit = fmb_workspace_joint_scratch(w, 2), *jphitt = fmb_workspace_joint_scratch(w, 3);
  for (int j = 0; j < m->njoint; ++j) {
    const fmbJointInst* ji = &m->joint[j];
    if (ji->nrows == 0) continue;
    const int ncol = fmb_joint_cols(m, ji, cols);
    if (fmb_joint_constraint(m, w, j, t, q, v, jphi, jphiq, jphit, jphitt)) return FMB_AUG_NOT_FINITE;
    for (int r = 0; r < ji->nrows; ++r) {
      const int rr = ji->rowadr + r;
      g->phi[rr] = jphi[r];
      g->phit[rr] = jphit[r];
      g->phitt[rr] = jphitt[r];
      double pv = 0.0;
      for (int c = 0; c < ncol; ++c) {
        const double d = jphiq[(size_t)r * ncol + c];
        pv += d * v[cols[c]];
        pmax = fmax(pmax, fabs(d));
        if (drop && drop[rr]) continue;
        const int k = g->entry[g->eoff[rr] + c];
        g->Ax[g->pos_phi[k]] += d;
        g->Ax[g->pos_phit[k]] += d;
      }
      g->phiq_v[rr] = pv;
    }
  }
  g->mdiag = mdiag;
  g->pmax = pmax;
  const double eps = tikhonov * pmax * pmax / fmax(mdiag, 1e-300);
  for (int rr = 0; rr < g->nc; ++rr) g->Ax[g->pos_diag[rr]] = (drop && drop[rr]) ? 1.0 : -eps;
  /* the pivot order of the last factorization, refreshed (KLU allocates then) only when the
     condition estimates say it has degraded (klu.c's policy): near a singular configuration the
     order of the last one can become a bad one */
  if (fmb_klu_factor(g->klu, g->Ax) != FMB_KLU_OK) return FMB_AUG_SINGULAR;
  return 0;
}

static int solve_rhs(fmbAugmented* g) {
  if (fmb_klu_solve(g->klu, g->rhs)) return FMB_AUG_SINGULAR;
  for (int i = 0; i < g->n; ++i)
    if (!isfinite(g->rhs[i])) return FMB_AUG_NOT_FINITE;
  return 0;
}

int fmb_augmented_solve(const fmbModel* m, fmbWorkspace* w, fmbAugmented* g, double t, const double* q, const double* v,
                        const unsigned char* drop, double tikhonov, double* a, double* lambda) {
  const int nq = g->nq, nc = g->nc;
  int rc = assemble(m, w, g, t, q, v, drop, tikhonov);
  if (rc) return rc;
  if (fmb_generalized_forces(m, w, t, q, v, g->rhs)) return FMB_AUG_FORCES_FAILED;
  if (nc > 0 && fmb_constraints_gamma(m, w, t, q, v, g->rhs + nq)) return FMB_AUG_NOT_FINITE;
  for (int r = 0; r < nc; ++r)
    if (drop && drop[r]) g->rhs[nq + r] = 0.0;
  if ((rc = solve_rhs(g))) return rc;
  if (a) memcpy(a, g->rhs, (size_t)nq * sizeof(double));
  if (lambda) memcpy(lambda, g->rhs + nq, (size_t)nc * sizeof(double));
  return 0;
}

/* dx = -M^-1 Phi_q^T (Phi_q M^-1 Phi_q^T + eps)^-1 r with the matrix as factored: the correction
   of least kinetic-energy norm that removes the constraint residual r to first order (the
   mass-orthogonal projection of Bayo & Ledesma 1996), from [M Phi_q^T; Phi_q -eps I][dx; mu] =
   [0; -r]. */
static int mass_projection(fmbAugmented* g, const double* r, double* dx) {
  memset(g->rhs, 0, sizeof(double) * (size_t)g->nq);
  for (int k = 0; k < g->nc; ++k) g->rhs[g->nq + k] = -r[k];
  int rc = solve_rhs(g);
  if (!rc) memcpy(dx, g->rhs, sizeof(double) * (size_t)g->nq);
  return rc;
}

static double norm2(const double* x, int n) {
  double s = 0.0;
  for (int i = 0; i < n; ++i) s += x[i] * x[i];
  return sqrt(s);
}

int fmb_project_state(const fmbModel* m, fmbWorkspace* w, fmbAugmented* g, double t, double* q, double* v) {
  const int nq = g->nq, nc = g->nc;
  if (nc == 0) return 0;
  const double scale = 1.0 + norm2(q, nq);
  double* dx = fmb_workspace_qscratch(w);
  int converged = 0;
  for (int it = 0; it < 8; ++it) { /* positions: Newton on Phi(q) = 0 with mass-orthogonal steps */
    if (assemble(m, w, g, t, q, v, NULL, FMB_MIN_NORM_SHIFT)) return 1;
    if (norm2(g->phi, nc) <= 1e-14 * scale) {
      converged = 1;
      break;
    }
    if (mass_projection(g, g->phi, dx)) return 1;
    for (int c = 0; c < nq; ++c) q[c] += dx[c];
  }
  /* velocities: one step, Phi_q v + Phi_t is linear in v (the matrix is the one at the final q) */
  for (int k = 0; k < nc; ++k) g->phit[k] += g->phiq_v[k];
  if (mass_projection(g, g->phit, dx)) return 1;
  for (int c = 0; c < nq; ++c) v[c] += dx[c];
  return converged ? 0 : 1;
}

/* Phi_q x with the Phi_q of the last assembly */
static void phiq_times(const fmbAugmented* g, const double* x, double* out) {
  for (int rr = 0; rr < g->nc; ++rr) {
    double s = 0.0;
    for (int k = g->rowptr[rr]; k < g->rowptr[rr + 1]; ++k) s += g->Ax[g->pos_phi[k]] * x[g->col[k]];
    out[rr] = s;
  }
}

int fmb_project_tangent(fmbWorkspace* w, fmbAugmented* g, double* x) {
  double* dx = fmb_workspace_qscratch(w);
  phiq_times(g, x, g->phiq_v);
  if (mass_projection(g, g->phiq_v, dx)) return 1;
  for (int c = 0; c < g->nq; ++c) x[c] += dx[c];
  return 0;
}
