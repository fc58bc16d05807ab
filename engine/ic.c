/* ic.c — consistent initial conditions for the GGL system.
 *
 * 1. positions: Gauss–Newton projection onto Phi(q, t0) = 0, the minimum-norm correction
 *    dq = -Phi_q^T (Phi_q Phi_q^T)^-1 Phi, until max |Phi_i| <= FMB_IC_PHI_TOL: absolute, in
 *    the constraint's own units (m, rad), whatever the coordinates' magnitude (a test relative
 *    to |q| let a pose 1e13 m out "converge" with a 1 m rod violated by 0.9 m). A body moved by
 *    more than FMB_ASSEMBLY_TOL is an error unless the scene says `initial: assemble`: the
 *    projection would otherwise change the mechanism silently;
 * 2. velocities: the minimum-norm correction onto Phi_q v + Phi_t = 0;
 * 3. accelerations and multipliers from the augmented system (augmented.c)
 *        [M  Phi_q^T] [a     ]   [Q    ]
 *        [Phi_q   0 ] [lambda] = [gamma],   gamma = -(Phi_q v)_q v - Phi_tt,
 *    so IDA starts from F(t0, y0, y0') = 0. mu = 0. The sizes of the corrections are reported.
 * Setup-time code: it may allocate. */
#include <float.h>
#include <klu.h>
#include <math.h>
#include <stdlib.h>
#include <string.h>

#include "data.h"
#include "fd.h"
#include "klu_policy.h"

#define FMB_ASSEMBLY_TOL 1e-6 /* m or rad: a larger initial correction changes the mechanism */

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

/* G = Phi_q Phi_q^T (column-major nc x nc) from the row-major nc x nq Phi_q; LU in place. A
   redundant row (drop[r]) gets an identity row and column: its correction is zero. */
static int gram_factor(int nc, int nq, const double* PhiQ, const unsigned char* drop, double* G, int* piv) {
  for (int i = 0; i < nc; ++i)
    for (int k = 0; k < nc; ++k) {
      double s = 0.0;
      if (drop[i] || drop[k])
        s = i == k;
      else
        for (int c = 0; c < nq; ++c) s += PhiQ[(size_t)i * nq + c] * PhiQ[(size_t)k * nq + c];
      G[(size_t)k * nc + i] = s;
    }
  return fmb_lu_factor(nc, G, piv);
}

/* x -= Phi_q^T G^-1 r: the minimum-norm correction that removes the constraint residual r (nc,
   overwritten) to first order, with G = Phi_q Phi_q^T as gram_factor left it */
static void subtract_min_norm(int nc, int nq, const double* PhiQ, const double* G, const int* piv, double* r,
                              double* x) {
  fmb_lu_solve(nc, G, piv, r);
  for (int c = 0; c < nq; ++c) {
    double s = 0.0;
    for (int k = 0; k < nc; ++k) s += PhiQ[(size_t)k * nq + c] * r[k];
    x[c] -= s;
  }
}

/* Rows of Phi_q that depend on the others (relative tolerance FMB_RANK_TOL): marked in drop[].
   Returns the rank, or -1 out of memory. */
#define FMB_RANK_TOL 1e-9
static int mark_dependent_rows(int nc, int nq, const double* PhiQ, unsigned char* drop) {
  int* order = malloc(sizeof(int) * (size_t)nc);
  double* work = malloc(sizeof(double) * ((size_t)nc * nq + nc));
  if (!order || !work) {
    free(order);
    free(work);
    return -1;
  }
  const int rank = fmb_independent_rows(nc, nq, PhiQ, FMB_RANK_TOL, order, work);
  memset(drop, 0, (size_t)nc);
  for (int k = rank; k < nc; ++k) drop[order[k]] = 1;
  free(order);
  free(work);
  return rank;
}

/* Gauss-Newton projection of q onto Phi(q, t) = 0 with the independent rows, the minimum-norm
   correction dq = -Phi_q^T (Phi_q Phi_q^T)^-1 Phi each step; the redundant rows are re-found
   when the Gram matrix turns singular. Returns 0 converged, 1 not (res: the last residual). */
static int project_positions(const fmbModel* m, fmbWorkspace* w, double t, double* q, const double* v, double* PhiQ,
                             double* phi, double* phit, double* phitt, double* G, int* piv, double* rhs,
                             unsigned char* drop, double* res, int* iters) {
  const int nq = m->nq, nc = m->nc;
  for (int it = 0; it < 50; ++it) {
    *iters = it;
    if (fmb_constraints_all(m, w, t, q, v, phi, PhiQ, phit, phitt)) return 1;
    *res = max_abs(phi, nc); /* every row: redundant ones must hold too */
    if (*res <= FMB_IC_PHI_TOL) return 0;
    if (gram_factor(nc, nq, PhiQ, drop, G, piv)) {
      if (mark_dependent_rows(nc, nq, PhiQ, drop) < 0 || gram_factor(nc, nq, PhiQ, drop, G, piv)) return 1;
    }
    for (int r = 0; r < nc; ++r) rhs[r] = drop[r] ? 0.0 : phi[r];
    subtract_min_norm(nc, nq, PhiQ, G, piv, rhs, q);
  }
  return 1;
}

static int settle_positions(const fmbModel* m, fmbWorkspace* w, double t, double* q, const double* v, double* PhiQ,
                            double* phi, double* phit, double* phitt, double* G, int* piv, double* rhs,
                            unsigned char* drop, int* rank, double* res, int* it);

/* A row that depends on the others at q may do so on the whole motion (redundant: two pins that
   say the same thing) or only at q (a singular configuration, e.g. a linkage started flat). Move
   a little along the constraint manifold (a tangent step of 1e-3 of the coordinates' scale,
   projected back) and look again: returns 1 when fewer rows depend there (singular at q). */
int fmb_rank_deficient_at(const fmbModel* m, fmbWorkspace* w, double t, const double* q, const double* v, double tol) {
  const int nq = m->nq, nc = m->nc;
  if (nc == 0) return 0;
  double* PhiQ = calloc((size_t)nc * nq, sizeof(double));
  double* work = calloc((size_t)nc * nq + nc, sizeof(double));
  int* order = calloc((size_t)nc, sizeof(int));
  int nred = 0, deficient = 0;
  fmb_workspace_redundant(w, &nred);
  if (PhiQ && work && order && !fmb_constraints_all(m, w, t, q, v, NULL, PhiQ, NULL, NULL))
    deficient = fmb_independent_rows(nc, nq, PhiQ, tol, order, work) < nc - nred;
  free(PhiQ);
  free(work);
  free(order);
  return deficient;
}

static int singular_here(const fmbModel* m, fmbWorkspace* w, double t, const double* q, const double* v,
                         const unsigned char* drop, int rank) {
  const int nq = m->nq, nc = m->nc;
  double* qs = malloc(sizeof(double) * (size_t)nq);
  double* PhiQ = calloc((size_t)nc * nq, sizeof(double));
  double* phi = calloc((size_t)nc, sizeof(double));
  double* phit = calloc((size_t)nc, sizeof(double));
  double* phitt = calloc((size_t)nc, sizeof(double));
  double* G = calloc((size_t)nc * nc, sizeof(double));
  double* rhs = calloc((size_t)nc, sizeof(double));
  int* piv = calloc((size_t)nc, sizeof(int));
  unsigned char* d2 = malloc((size_t)nc);
  int singular = 0;
  if (qs && PhiQ && phi && phit && phitt && G && rhs && piv && d2) {
    /* a fixed, generic direction with its Phi_q component removed: a tangent */
    for (int i = 0; i < nq; ++i) qs[i] = sin(1.7 * i + 0.3);
    memcpy(d2, drop, (size_t)nc);
    fmb_constraints_all(m, w, t, q, v, phi, PhiQ, phit, phitt);
    if (!gram_factor(nc, nq, PhiQ, d2, G, piv)) {
      for (int r = 0; r < nc; ++r) {
        double s = 0.0;
        for (int c = 0; c < nq; ++c) s += PhiQ[(size_t)r * nq + c] * qs[c];
        rhs[r] = d2[r] ? 0.0 : s;
      }
      fmb_lu_solve(nc, G, piv, rhs);
      const double h = 1e-3 * (1.0 + norm2(q, nq)) / fmax(norm2(qs, nq), 1e-300);
      for (int c = 0; c < nq; ++c) {
        double s = 0.0;
        for (int r = 0; r < nc; ++r) s += PhiQ[(size_t)r * nq + c] * rhs[r];
        qs[c] = q[c] + h * (qs[c] - s);
      }
      double res = 0.0;
      int iters = 0, rank2 = 0;
      if (settle_positions(m, w, t, qs, v, PhiQ, phi, phit, phitt, G, piv, rhs, d2, &rank2, &res, &iters) &&
          rank2 > rank)
        singular = 1;
    }
  }
  free(qs);
  free(PhiQ);
  free(phi);
  free(phit);
  free(phitt);
  free(G);
  free(rhs);
  free(piv);
  free(d2);
  return singular;
}

/* Project q onto the constraints with the rows independent at q, then again with those
   independent at the result, until the set settles: 1 when converged (drop[] marks the dependent
   rows, *rank their complement's size), 0 when the joints cannot be satisfied. */
static int settle_positions(const fmbModel* m, fmbWorkspace* w, double t, double* q, const double* v, double* PhiQ,
                            double* phi, double* phit, double* phitt, double* G, int* piv, double* rhs,
                            unsigned char* drop, int* rank, double* res, int* it) {
  const int nq = m->nq, nc = m->nc;
  unsigned char* before = malloc((size_t)nc);
  int converged = 0;
  for (int round = 0; before && round < 3 && !converged; ++round) {
    if (fmb_constraints_all(m, w, t, q, v, phi, PhiQ, phit, phitt) ||
        (*rank = mark_dependent_rows(nc, nq, PhiQ, drop)) < 0)
      break;
    if (project_positions(m, w, t, q, v, PhiQ, phi, phit, phitt, G, piv, rhs, drop, res, it)) break;
    memcpy(before, drop, (size_t)nc);
    *rank = mark_dependent_rows(nc, nq, PhiQ, drop);
    converged = memcmp(before, drop, (size_t)nc) == 0;
  }
  free(before);
  return converged;
}

/* The joint whose equations are furthest from holding at (t, q): the largest |Phi| over its
   rows, into *residual; -1 when none can be evaluated. The buffers are the caller's (nc and
   nc x nq doubles). Names the joint an initial-pose error is about. */
static int worst_joint(const fmbModel* m, fmbWorkspace* w, double t, const double* q, const double* v, double* phi,
                       double* PhiQ, double* phit, double* phitt, double* residual) {
  int worst = -1;
  *residual = 0.0;
  if (fmb_constraints_all(m, w, t, q, v, phi, PhiQ, phit, phitt)) return -1;
  for (int j = 0; j < m->njoint; ++j)
    for (int r = 0; r < m->joint[j].nrows; ++r) {
      const double a = fabs(phi[m->joint[j].rowadr + r]);
      if (a > *residual || worst < 0) *residual = a, worst = j;
    }
  return worst;
}

/* an initial-pose error at joint j's item in the scene (file:line:column and its name), or at the
   scene when there is no such joint */
static void joint_error(const fmbModel* m, int j, fmbDiag* diag, const char* what, const char* rest) {
  if (j >= 0)
    fmb_diag_set(diag, FMB_EXIT_BAD_INPUT, m->path, m->joint[j].line, m->joint[j].col, "joint '%s' %s%s",
                 m->joint[j].name, what, rest);
  else
    fmb_diag_set(diag, FMB_EXIT_BAD_INPUT, m->path, 0, 0, "the joints %s%s", what, rest);
}

/* joints that the projection could not satisfy (run and check say the same): named at the one
   furthest from holding where the projection stopped */
static void unsatisfiable_error(const fmbModel* m, fmbWorkspace* w, double t0, const double* q, const double* v,
                                double* phi, double* PhiQ, double* phit, double* phitt, double res, int it,
                                fmbDiag* diag) {
  /* far from the origin double precision cannot resolve FMB_IC_PHI_TOL: say so */
  const double qmax = max_abs(q, m->nq);
  char far[160] = "";
  if (qmax * 1e-15 > 0.1 * FMB_IC_PHI_TOL)
    snprintf(far, sizeof far, "; coordinates reach %.3g, too far out for double precision to hold joints to %g", qmax,
             FMB_IC_PHI_TOL);
  double rj = 0.0;
  const int j = worst_joint(m, w, t0, q, v, phi, PhiQ, phit, phitt, &rj);
  char rest[500];
  snprintf(rest, sizeof rest,
           " at t = %g (its residual %.3g; constraint residual %.3g, tolerance %g, after %d projection steps): check "
           "the joints' points and the bodies' initial poses; joints that repeat each other must agree%s",
           t0, rj, res, FMB_IC_PHI_TOL, it, far);
  joint_error(m, j, diag, j >= 0 ? "cannot be satisfied together with the other joints" : "cannot all be satisfied",
              rest);
}

/* The projection's change dq of the poses given: beyond FMB_ASSEMBLY_TOL on some body, and
   unless the scene says `initial: assemble`, the poses do not satisfy the joints: named at the
   joint furthest from holding in them (pose_joint, its residual). 1 with *diag filled, or 0. */
static int pose_moved_error(const fmbModel* m, const double* dq, int pose_joint, double pose_residual, fmbDiag* diag) {
  int worst = 0;
  double moved = 0.0;
  for (int b = 1; b < m->nbody; ++b) {
    const double d = max_abs(dq + m->body[b].qadr, m->body[b].nq);
    if (d > moved) {
      moved = d;
      worst = b;
    }
  }
  if (!(moved > FMB_ASSEMBLY_TOL) || m->assemble) return 0;
  char rest[500];
  snprintf(rest, sizeof rest,
           " (off by %.3g m or rad): the joints move body '%s' by %.3g (the largest change of one of its coordinates, "
           "m or rad; tolerance %g). Give poses that satisfy the joints, or write `initial: assemble` at the top level "
           "to let flexmbd move the bodies onto them",
           pose_residual, m->body[worst].name, moved, FMB_ASSEMBLY_TOL);
  joint_error(m, pose_joint, diag, "is not satisfied by the poses given", rest);
  return 1;
}

int fmb_pose_check(const fmbModel* m, fmbWorkspace* w, double t, double* q, fmbDiag* diag) {
  const int nq = m->nq, nc = m->nc;
  if (nc == 0) return 0;
  double* v = calloc((size_t)nq + 1, sizeof(double));
  double* dq = calloc((size_t)nq + 1, sizeof(double));
  double* PhiQ = calloc((size_t)nc * nq + 1, sizeof(double));
  double* phi = calloc((size_t)nc + 1, sizeof(double));
  double* phit = calloc((size_t)nc + 1, sizeof(double));
  double* phitt = calloc((size_t)nc + 1, sizeof(double));
  double* G = calloc((size_t)nc * nc + 1, sizeof(double));
  double* rhs = calloc((size_t)nq + nc + 1, sizeof(double));
  int* piv = calloc((size_t)nq + nc + 1, sizeof(int));
  unsigned char* drop = calloc((size_t)nc + 1, 1);
  int rc = 0;
  if (!v || !dq || !PhiQ || !phi || !phit || !phitt || !G || !rhs || !piv || !drop) {
    fmb_diag_set(diag, FMB_EXIT_SOLVER, m->path, 0, 0, "out of memory checking the initial poses");
    rc = FMB_EXIT_SOLVER;
  } else {
    double pose_residual = 0.0, res = 0.0;
    const int pose_joint = worst_joint(m, w, t, q, v, phi, PhiQ, phit, phitt, &pose_residual);
    int rank = nc, it = 0;
    memcpy(dq, q, (size_t)nq * sizeof(double));
    if (!settle_positions(m, w, t, q, v, PhiQ, phi, phit, phitt, G, piv, rhs, drop, &rank, &res, &it)) {
      unsatisfiable_error(m, w, t, q, v, phi, PhiQ, phit, phitt, res, it, diag);
      rc = FMB_EXIT_BAD_INPUT;
    } else {
      for (int i = 0; i < nq; ++i) dq[i] = q[i] - dq[i];
      if (pose_moved_error(m, dq, pose_joint, pose_residual, diag)) rc = FMB_EXIT_BAD_INPUT;
    }
  }
  free(v), free(dq), free(PhiQ), free(phi), free(phit), free(phitt), free(G), free(rhs), free(piv), free(drop);
  return rc;
}

/* The constraints at the scene's initial state, projected: what fmb_count_redundant and
   fmb_check_constraints both report. */
typedef struct {
  fmbData* data; /* the scratch (its workspace: w) */
  fmbWorkspace* w;
  double *q, *v, *PhiQ, *phi, *phit, *phitt, *G, *rhs;
  int* piv;
  int settled, rank, singular, iters;
  double res;
} Start;

/* 0, or -1 out of memory; s->settled = 0 when the joints cannot be satisfied */
static int analyze_start(const fmbModel* m, Start* s) {
  const int nq = m->nq, nc = m->nc;
  memset(s, 0, sizeof *s);
  s->data = fmb_data_new(m, NULL);
  s->w = s->data ? s->data->w : NULL;
  s->q = calloc((size_t)nq + 1, sizeof(double));
  s->v = calloc((size_t)nq + 1, sizeof(double));
  s->PhiQ = calloc((size_t)(nc ? nc : 1) * nq, sizeof(double));
  s->phi = calloc((size_t)nc + 1, sizeof(double));
  s->phit = calloc((size_t)nc + 1, sizeof(double));
  s->phitt = calloc((size_t)nc + 1, sizeof(double));
  s->G = calloc((size_t)nc * nc + 1, sizeof(double));
  s->rhs = calloc((size_t)nc + 1, sizeof(double));
  s->piv = calloc((size_t)nc + 1, sizeof(int));
  if (!s->w || !s->q || !s->v || !s->PhiQ || !s->phi || !s->phit || !s->phitt || !s->G || !s->rhs || !s->piv) return -1;
  for (int b = 1; b < m->nbody; ++b)
    m->body[b].type->initial(m->body[b].self, s->q + m->body[b].qadr, s->v + m->body[b].qadr);
  s->rank = nc;
  s->settled = 1;
  if (nc == 0) return 0;
  unsigned char* drop = fmb_workspace_redundant(s->w, NULL);
  s->settled = settle_positions(m, s->w, m->solver.t0, s->q, s->v, s->PhiQ, s->phi, s->phit, s->phitt, s->G, s->piv,
                                s->rhs, drop, &s->rank, &s->res, &s->iters);
  s->singular = s->settled && s->rank < nc && singular_here(m, s->w, m->solver.t0, s->q, s->v, drop, s->rank);
  return 0;
}

static void start_free(Start* s) {
  fmb_data_destroy(s->data);
  double* bufs[] = {s->q, s->v, s->PhiQ, s->phi, s->phit, s->phitt, s->G, s->rhs};
  for (size_t i = 0; i < sizeof bufs / sizeof bufs[0]; ++i) free(bufs[i]);
  free(s->piv);
}

int fmb_count_redundant(const fmbModel* m) {
  Start s;
  const int count = analyze_start(m, &s) == 0 && s.settled && !s.singular ? m->nc - s.rank : 0;
  start_free(&s);
  return count;
}

int fmb_check_constraints(const fmbModel* m, FILE* f, fmbDiag* diag) {
  fmbDiag local;
  if (!diag) diag = &local;
  if (!m || !f) {
    memset(diag, 0, sizeof *diag);
    fmb_diag_set(diag, FMB_EXIT_BAD_INPUT, "", 0, 0, "fmb_check_constraints: NULL model or stream");
    return FMB_EXIT_BAD_INPUT;
  }
  const int nq = m->nq, nc = m->nc;
  const double t0 = m->solver.t0;
  memset(diag, 0, sizeof *diag);
  Start s;
  int rc = 0;
  if (analyze_start(m, &s)) {
    fmb_diag_set(diag, FMB_EXIT_SOLVER, m->path, 0, 0, "out of memory checking the constraints");
    rc = FMB_EXIT_SOLVER;
  } else if (!s.settled) {
    unsatisfiable_error(m, s.w, t0, s.q, s.v, s.phi, s.PhiQ, s.phit, s.phitt, s.res, s.iters, diag);
    rc = FMB_EXIT_BAD_INPUT;
  } else {
    char rows[600] = "";
    fmb_name_rows(m, fmb_workspace_redundant(s.w, NULL), rows, sizeof rows);
    fprintf(f, "degrees of freedom: %d (%d coordinates, %d constraint equations of rank %d)\n", nq - s.rank, nq, nc,
            s.rank);
    if (s.rank == nc)
      fprintf(f, "redundant equations: none\nsingular configuration at t = %g: no\n", t0);
    else if (s.singular)
      fprintf(f,
              "redundant equations: none found (see below)\nsingular configuration at t = %g: yes: %s depend%s on the "
              "others here but not nearby (the degrees of freedom above hold only at this instant); the run refuses to "
              "start here\n",
              t0, rows, s.rank == nc - 1 ? "s" : "");
    else
      fprintf(f,
              "redundant equations: %s (left out of the equations when run; reactions by the minimum-norm rule)\n"
              "singular configuration at t = %g: no\n",
              rows, t0);
  }
  start_free(&s);
  return rc;
}

/* "joint 'a' row 2, joint 'b' row 1" for the marked rows */
void fmb_name_rows(const fmbModel* m, const unsigned char* drop, char* buf, size_t len) {
  size_t used = 0;
  buf[0] = '\0';
  for (int j = 0; j < m->njoint && used + 80 < len; ++j)
    for (int r = 0; r < m->joint[j].nrows; ++r)
      if (drop[m->joint[j].rowadr + r])
        used +=
            (size_t)snprintf(buf + used, len - used, "%sjoint '%s' row %d", used ? ", " : "", m->joint[j].name, r + 1);
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
    if (bi->pnnz >= 0 && fmb_body_sparse_scratch(bi) > nscr) nscr = fmb_body_sparse_scratch(bi);
  }
  double* Rb = calloc(nrb, sizeof(double));
  double* scratch = calloc(nscr, sizeof(double));
  Triplets t = {0, 0, NULL, NULL, NULL};
  SuiteSparse_long *Ap = calloc((size_t)N + 1, sizeof(SuiteSparse_long)), *Ai = NULL;
  double* Ax = NULL;
  fmbKlu* lu = NULL; /* klu.c; G_x keeps its pattern from one iteration to the next */
  int rc = (!x || !G || !Qj || !ewt || !blk || !Ap || !Rb || !scratch) ? FMB_EXIT_SOLVER : 0;
  const char* why = "out of memory computing initial accelerations";
  /* the joints' forces: all forces less the bodies' own (-R at a = 0) */
  if (!rc && fmb_generalized_forces(m, w, t0, q, v, Qj))
    rc = FMB_EXIT_SOLVER, why = "the generalized forces are not finite";
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
  double dmax_prev = INFINITY;
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
        if (fmb_body_sparse_blocks(bi, &m->env, q + bi->qadr, v + bi->qadr, a + bi->qadr, z + bi->zadr, ewt + bi->qadr,
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
        if (fmb_body_mass(m, w, b, q + bi->qadr, v + bi->qadr, blk))
          rc = FMB_EXIT_SOLVER, why = "the mass matrix could not be evaluated";
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
    if (!lu) lu = fmb_klu_new(N, Ap, Ai, 0);
    if (!lu || fmb_klu_factor(lu, Ax) != FMB_KLU_OK) {
      rc = FMB_EXIT_BAD_INPUT;
      why = "the initial mass matrix is singular on the free motions (a body without mass or inertia, or a mechanism "
            "with redundant joints): cannot compute initial accelerations";
      break;
    }
    if (fmb_klu_solve(lu, G)) {
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
    /* G is linear in a, z and lambda, so one step solves it and the next ones only refine at the
       roundoff of G. That floor grows with the unknowns: a 200-element banded beam sits at
       1.3-2.8e-9 against xmax 1e4 (1.3-1.7e-13 relative), just above the 1e-13 asked, where
       whether an iteration lands below it is luck. So an iteration that no longer halves the
       correction, within 1e-10, has converged as far as the residual can tell. */
    converged = dmax <= 1e-13 * (1.0 + xmax) || (dmax <= 1e-10 * (1.0 + xmax) && dmax >= 0.5 * dmax_prev);
    dmax_prev = dmax;
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
  fmb_klu_free(lu);
  free(x), free(G), free(Qj), free(ewt), free(blk), free(Rb), free(scratch), free(Ap), free(Ai), free(Ax);
  free(t.row), free(t.col), free(t.val);
  return rc;
}

/* the dense scratch of steps 1-3: Phi_q (row-major nc x nq), phi, phi_t, phi_tt (nc), the Gram
   matrix (nc^2), pivots and a right-hand side (nq + nc each); 0, or -1 out of memory (all NULL) */
typedef struct {
  double *PhiQ, *phi, *phit, *phitt, *G, *rhs;
  int* piv;
} Scratch;

static void scratch_free(Scratch* s) {
  double* bufs[] = {s->PhiQ, s->phi, s->phit, s->phitt, s->G, s->rhs};
  for (size_t i = 0; i < sizeof bufs / sizeof bufs[0]; ++i) free(bufs[i]);
  free(s->piv);
  memset(s, 0, sizeof *s);
}

static int scratch_new(const fmbModel* m, Scratch* s) {
  const size_t nq = (size_t)m->nq, nc = (size_t)m->nc, n = nq + nc + 1;
  s->PhiQ = calloc((nc ? nc : 1) * nq, sizeof(double));
  s->phi = calloc(nc + 1, sizeof(double));
  s->phit = calloc(nc + 1, sizeof(double));
  s->phitt = calloc(nc + 1, sizeof(double));
  s->G = calloc(nc * nc + 1, sizeof(double));
  s->rhs = calloc(n, sizeof(double));
  s->piv = calloc(n, sizeof(int));
  if (s->PhiQ && s->phi && s->phit && s->phitt && s->G && s->rhs && s->piv) return 0;
  scratch_free(s);
  return -1;
}

/* The minimum-norm correction of v onto Phi_q v + Phi_t = 0 (the rows marked in drop left out),
   with Phi_q (row-major nc x nq) and Phi_t at the positions: 0, or 1 when the rows kept are not
   independent. G, piv, rhs: scratch of nc^2, nc, nc. */
static int project_velocities(int nc, int nq, const double* PhiQ, const double* phit, const unsigned char* drop,
                              double* G, int* piv, double* rhs, double* v) {
  if (gram_factor(nc, nq, PhiQ, drop, G, piv)) return 1;
  for (int r = 0; r < nc; ++r) {
    double s = phit[r];
    for (int c = 0; c < nq; ++c) s += PhiQ[(size_t)r * nq + c] * v[c];
    rhs[r] = drop[r] ? 0.0 : s;
  }
  subtract_min_norm(nc, nq, PhiQ, G, piv, rhs, v);
  return 0;
}

/* Step 3 at consistent q, v (y's) and time t: the accelerations (yp's v slice; yp's q slice = v),
   the multipliers and the bodies' auxiliary unknowns, mu = 0. Scratch: PhiQ (nc x nq), phi, phit,
   phitt (nc), rhs (nq + nc). 0 or an exit code with diag set. */
static int accelerations_at(const fmbModel* m, fmbWorkspace* w, double t, double* y, double* yp, double* PhiQ,
                            double* phi, double* phit, double* phitt, double* rhs, fmbDiag* diag) {
  const int nq = m->nq;
  double *q = y, *v = y + nq;
  int rc = 0;
  if (fmb_model_has_sparse_body(m)) {
    /* a body declared a sparse pattern (a banded beam): the dense augmented system would take
       (nq + nc)^2 memory and cubic time; sparse Newton for a, lambda and the auxiliary unknowns */
    int nred = 0;
    fmb_workspace_redundant(w, &nred);
    if (nred > 0) {
      fmb_diag_set(diag, FMB_EXIT_BAD_INPUT, m->path, 0, 0,
                   "redundant constraints with a body that declares a sparse pattern (a banded beam) are not "
                   "supported yet: remove the repeated joint, or set the beam's `assembly: dense`");
      return FMB_EXIT_BAD_INPUT;
    }
    if (fmb_constraints_all(m, w, t, q, v, phi, PhiQ, phit, phitt) || fmb_constraints_gamma(m, w, t, q, v, rhs + nq)) {
      fmb_diag_set(diag, FMB_EXIT_SOLVER, m->path, 0, 0, "the constraints are not finite at t = %g", t);
      rc = FMB_EXIT_SOLVER;
    } else {
      rc = sparse_accelerations(m, w, t, y, yp, PhiQ, rhs + nq, diag);
    }
    return rc;
  }
  /* augmented system for accelerations and multipliers */
  fmbAugmented* aug = fmb_augmented_new(m);
  if (!aug) {
    fmb_diag_set(diag, FMB_EXIT_SOLVER, m->path, 0, 0, "out of memory computing initial conditions");
    return FMB_EXIT_SOLVER;
  }
  int arc = fmb_augmented_solve(m, w, aug, t, q, v, fmb_workspace_redundant(w, NULL), 0.0, yp + nq, y + 2 * nq);
  memcpy(yp, v, (size_t)nq * sizeof(double));
  if (arc == FMB_AUG_MASS_FAILED) {
    fmb_diag_set(diag, FMB_EXIT_SOLVER, m->path, 0, 0, "could not evaluate the mass matrix of body '%s' at t = %g",
                 m->body[fmb_augmented_failed_body(aug)].name, t);
    rc = FMB_EXIT_SOLVER;
  } else if (arc == FMB_AUG_FORCES_FAILED) {
    fmb_diag_set(diag, FMB_EXIT_SOLVER, m->path, 0, 0, "the generalized forces are not finite at t = %g", t);
    rc = FMB_EXIT_SOLVER;
  } else if (arc == FMB_AUG_SINGULAR) {
    fmb_diag_set(
        diag, FMB_EXIT_BAD_INPUT, m->path, 0, 0,
        "the initial mass matrix is singular on the free motions (a body without mass or inertia, or a mechanism "
        "with redundant joints): cannot compute initial accelerations");
    rc = FMB_EXIT_BAD_INPUT;
  } else if (arc == FMB_AUG_NOT_FINITE) {
    fmb_diag_set(diag, FMB_EXIT_SOLVER, m->path, 0, 0, "initial accelerations are not finite");
    rc = FMB_EXIT_SOLVER;
  }
  /* the bodies' auxiliary unknowns, consistent with (q, v, a) */
  for (int b = 1; b < m->nbody && !rc; ++b) {
    const fmbBodyInst* bi = &m->body[b];
    if (bi->nz > 0 && bi->type->aux_initial(bi->self, &m->env, q + bi->qadr, v + bi->qadr, yp + nq + bi->qadr,
                                            y + m->zoff + bi->zadr, fmb_workspace_plugin(w) + bi->workadr)) {
      fmb_diag_set(diag, FMB_EXIT_SOLVER, m->path, 0, 0, "the auxiliary unknowns of body '%s' are not finite at t = %g",
                   bi->name, t);
      rc = FMB_EXIT_SOLVER;
    }
  }
  fmb_augmented_free(aug);
  return rc;
}

int fmb_initial_conditions(const fmbModel* m, fmbWorkspace* w, double* y, double* yp, fmbStats* st, fmbDiag* diag) {
  const int nq = m->nq, nc = m->nc;
  const double t0 = m->solver.t0;
  double* q = y;
  double* v = y + nq;
  memset(y, 0, (size_t)m->ny * sizeof(double));
  memset(yp, 0, (size_t)m->ny * sizeof(double));
  for (int b = 1; b < m->nbody; ++b) {
    const fmbBodyInst* bi = &m->body[b];
    bi->type->initial(bi->self, q + bi->qadr, v + bi->qadr);
  }
  Scratch sc;
  const int no_scratch = scratch_new(m, &sc);
  double *PhiQ = sc.PhiQ, *phi = sc.phi, *phit = sc.phit, *phitt = sc.phitt, *G = sc.G, *rhs = sc.rhs;
  int* piv = sc.piv;
  double* q0 = calloc((size_t)nq, sizeof(double));
  double* v0 = calloc((size_t)nq, sizeof(double));
  int rc = 0;
  if (no_scratch || !q0 || !v0) {
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

  unsigned char* drop = fmb_workspace_redundant(w, NULL);
  /* the joint furthest from holding in the poses given: the one a pose error names */
  double pose_residual = 0.0;
  const int pose_joint = nc > 0 ? worst_joint(m, w, t0, q, v, phi, PhiQ, phit, phitt, &pose_residual) : -1;
  if (nc > 0) {
    double res = 0.0;
    int it = 0, rank = nc;
    const int converged = settle_positions(m, w, t0, q, v, PhiQ, phi, phit, phitt, G, piv, rhs, drop, &rank, &res, &it);
    if (!converged) {
      unsatisfiable_error(m, w, t0, q, v, phi, PhiQ, phit, phitt, res, it, diag);
      rc = FMB_EXIT_BAD_INPUT;
      goto done;
    }
    if (rank < nc) {
      char rows[600];
      fmb_name_rows(m, drop, rows, sizeof rows);
      if (singular_here(m, w, t0, q, v, drop, rank)) {
        int first = -1; /* located at the first joint named */
        for (int j = 0; j < m->njoint && first < 0; ++j)
          for (int r = 0; r < m->joint[j].nrows; ++r)
            if (drop[m->joint[j].rowadr + r]) first = j;
        fmb_diag_set(diag, FMB_EXIT_BAD_INPUT, m->path, first >= 0 ? m->joint[first].line : 0,
                     first >= 0 ? m->joint[first].col : 0,
                     "the mechanism starts in a singular configuration at t = %g: %s depend%s on the other joints' "
                     "equations here but not nearby (a dead point or a flat linkage); start it away from that position",
                     t0, rows, rank == nc - 1 ? "s" : "");
        rc = FMB_EXIT_BAD_INPUT;
        goto done;
      }
      if (m->nredundant != nc - rank) {
        fmb_diag_set(diag, FMB_EXIT_SOLVER, m->path, 0, 0,
                     "internal: %d redundant constraint rows at t = %g (%s), %d found when the scene was loaded",
                     nc - rank, t0, rows, m->nredundant);
        rc = FMB_EXIT_SOLVER;
        goto done;
      }
    } else {
      memset(drop, 0, (size_t)nc);
    }
    if (project_velocities(nc, nq, PhiQ, phit, drop, G, piv, rhs, v)) {
      fmb_diag_set(diag, FMB_EXIT_BAD_INPUT, m->path, 0, 0, "the joints' equations are not independent at t = %g", t0);
      rc = FMB_EXIT_BAD_INPUT;
      goto done;
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
    fmb_diag_set(
        diag, FMB_EXIT_BAD_INPUT, m->path, 0, 0,
        "the initial coordinates reach %.3g (m or rad)%s: at that magnitude a double resolves only %.2g, coarser "
        "than the joints' tolerance %g. Place the mechanism near the origin",
        qmax, m->assemble ? " after assembly" : "", qmax * DBL_EPSILON, FMB_IC_PHI_TOL);
    rc = FMB_EXIT_BAD_INPUT;
    goto done;
  }
  if (pose_moved_error(m, q0, pose_joint, pose_residual, diag)) {
    rc = FMB_EXIT_BAD_INPUT;
    goto done;
  }
  st->ic_position_correction = norm2(q0, nq);
  st->ic_velocity_correction = norm2(v0, nq);

  rc = accelerations_at(m, w, t0, y, yp, PhiQ, phi, phit, phitt, rhs, diag);
done:
  scratch_free(&sc);
  free(q0);
  free(v0);
  return rc;
}

/* A consistent state at t from the q, v in y, for a run that goes on after something changed
   under it (an input set between steps, an interrupted or failed advance: step.c): q projected
   onto Phi(q, t) = 0 and v onto Phi_q v + Phi_t = 0 with the rows found redundant at t0 left out
   (steps 1 and 2, minimum-norm), then step 3 as at t0. A jump in a drive's prescribed angle thus
   moves the bodies onto the new constraint, and a jump in a load gives new accelerations and
   multipliers. 0 or an exit code with diag set. */
int fmb_consistent_state(const fmbModel* m, fmbWorkspace* w, double t, double* y, double* yp, fmbDiag* diag) {
  const int nq = m->nq, nc = m->nc;
  Scratch sc;
  int rc = 0;
  if (scratch_new(m, &sc)) {
    fmb_diag_set(diag, FMB_EXIT_SOLVER, m->path, 0, 0, "out of memory restarting the integrator at t = %.6g", t);
    rc = FMB_EXIT_SOLVER;
  } else if (nc > 0) {
    unsigned char* drop = fmb_workspace_redundant(w, NULL);
    double res = 0.0;
    int iters = 0;
    if (project_positions(m, w, t, y, y + nq, sc.PhiQ, sc.phi, sc.phit, sc.phitt, sc.G, sc.piv, sc.rhs, drop, &res,
                          &iters) ||
        fmb_constraints_all(m, w, t, y, y + nq, sc.phi, sc.PhiQ, sc.phit, sc.phitt) ||
        project_velocities(nc, nq, sc.PhiQ, sc.phit, drop, sc.G, sc.piv, sc.rhs, y + nq)) {
      fmb_diag_set(diag, FMB_EXIT_SOLVER, m->path, 0, 0,
                   "the joints cannot be satisfied at t = %.6g after the change (constraint residual %.3g after %d "
                   "projection steps): a prescribed motion set by fmb_set_input jumped further than the mechanism can "
                   "follow; change it in smaller steps",
                   t, res, iters);
      rc = FMB_EXIT_SOLVER;
    }
  }
  if (!rc) {
    /* the multipliers' and auxiliary unknowns' derivatives and mu are 0 in a consistent state */
    memset(y + 2 * nq + nc, 0, (size_t)nc * sizeof(double));
    memset(yp + 2 * nq, 0, (size_t)(m->ny - 2 * nq) * sizeof(double));
    rc = accelerations_at(m, w, t, y, yp, sc.PhiQ, sc.phi, sc.phit, sc.phitt, sc.rhs, diag);
  }
  scratch_free(&sc);
  return rc;
}
