/* system.c — the DAE of a planar multibody system in the stabilized index-2 form of
 * Gear, Gupta & Leimkuhler (GGL), with unknowns y = [q, v, lambda, mu]:
 *
 *   F_q      = q' - v - Phi_q^T mu                 = 0   (mu -> 0: velocity-level stabilization)
 *   F_v      = M(q) v' - Q(q, v, t) + Phi_q^T lambda = 0
 *   F_lambda = Phi(q, t)                            = 0   (position constraints)
 *   F_mu     = Phi_q v + Phi_t                      = 0   (velocity constraints)
 *
 * lambda and mu are algebraic (excluded from IDA's error test). Bodies supply M v' - Q through
 * their `residual`, joints supply Phi, Phi_q, Phi_t, force elements supply Q. The iteration
 * matrix dF/dy + cj dF/dy' is assembled into the fixed CSC pattern of pattern.c; blocks a plugin
 * does not provide analytically are differentiated numerically over that plugin's own
 * coordinates. Nothing here allocates: all scratch lives in the workspace made at setup.
 *
 * Redundant constraint rows (rows of Phi_q that depend on the others on the whole motion, e.g.
 * two pins that say the same thing; found by ic.c) are taken out of the equations: their rows
 * become F_lambda = lambda_r, F_mu = mu_r, so the Newton matrix stays regular while the
 * independent rows still fix the same motion (docs/mechanisms.md). Their share of the reactions
 * is restored in the outputs by the minimum-norm rule (output.c, with augmented.c's minimum-norm solve). */
#include <math.h>
#include <stdatomic.h>
#include <stdint.h>
#include <stdlib.h>
#include <string.h>

#include "fd.h"
#include "internal.h"

struct fmbWorkspace {
  double* plugin; /* m->nwork: plugin scratch */
  /* joint scratch */
  double *phi, *phi_q, *phi_q2, *phi_t, *phi_tt, *jq, *jv, *jQ, *jQ2;
  int* cols;
  /* body scratch: dense blocks and FD */
  double *K, *C, *M, *fdcol, *fd, *mk, *js;
  double *qpert, *vpert;
  double* ewt_default;
  /* global scratch */
  double *Mg, *PhiQ, *Qg;
  int max_rows, max_nq;
  /* the bodies' K, C, M blocks of the last fresh Jacobian, kept so that a new cj (IDA asks
     whenever the step size changes enough) costs a re-assembly, not new differences; NULL when
     they would take more than FMB_BLOCK_CACHE_BYTES */
  double* cache;
  size_t* cache_adr;
  int cache_valid;
  int cache_held;           /* an analysis on a run's workspace: the cache is the run's (fmb_workspace_hold_cache) */
  double* work_done;        /* njoint: accumulated work of each joint (step.c fills it) */
  unsigned char* redundant; /* nc: 1 = a redundant row, out of the equations (ic.c decides) */
  int nredundant_cap;       /* nc */
  /* an object a layer above keeps with the workspace and frees with it (output.c: the augmented
     system of the multipliers the outputs show), so that this file calls nothing above it */
  void* attached;
  void (*attached_free)(void*);
  double spring_energy0;
  fmbInputSetting* input; /* m->ninput: the inputs' settings */
  fmbWarnSink warn;       /* where this run's messages go */
};

#define FMB_BLOCK_CACHE_BYTES ((size_t)256 << 20)

static size_t max_body_nq(const fmbModel* m) {
  int mx = 1;
  for (int b = 1; b < m->nbody; ++b)
    if (m->body[b].nq > mx) mx = m->body[b].nq;
  return (size_t)mx;
}

/* doubles of one of a body's K, C, M blocks: its pattern's nonzeros, or nq^2 when dense */
static size_t block_size(const fmbBodyInst* b) {
  return b->pnnz >= 0 ? (size_t)b->pnnz : (size_t)b->nq * (size_t)b->nq;
}

/* workspaces made so far in this process, for the test that an analysis given a data object
   makes none (tests/core/test_analysis_data.c); atomic: runs in threads each make theirs */
static atomic_long workspaces_made;
long fmb_workspace_count(void) { return atomic_load(&workspaces_made); }

fmbWorkspace* fmb_workspace_new(const fmbModel* m) {
  atomic_fetch_add(&workspaces_made, 1);
  fmbWorkspace* w = calloc(1, sizeof *w);
  if (!w) return NULL;
  int mr = 1;
  for (int j = 0; j < m->njoint; ++j)
    if (m->joint[j].nrows > mr) mr = m->joint[j].nrows;
  size_t mc = (size_t)(m->max_joint_cols > 0 ? m->max_joint_cols : 1);
  size_t nb = max_body_nq(m);
  size_t nq = (size_t)m->nq;
  /* fmb_check_mass takes a dense mass matrix of the body in w->M */
  size_t nblk = m->check_definiteness ? nb * nb : 1, nfd = 7 * nb;
  for (int b = 1; b < m->nbody; ++b) {
    if (block_size(&m->body[b]) > nblk) nblk = block_size(&m->body[b]);
    if (m->body[b].pnnz >= 0 && fmb_body_sparse_scratch(&m->body[b]) > nfd) nfd = fmb_body_sparse_scratch(&m->body[b]);
  }
  w->max_rows = mr;
  w->max_nq = (int)nb;
  w->plugin = calloc(m->nwork + 1, sizeof(double));
  w->phi = calloc((size_t)mr, sizeof(double));
  w->phi_t = calloc((size_t)mr, sizeof(double));
  w->phi_tt = calloc((size_t)mr, sizeof(double));
  w->phi_q = calloc((size_t)mr * mc, sizeof(double));
  w->phi_q2 = calloc((size_t)mr * mc, sizeof(double));
  w->jq = calloc(mc, sizeof(double));
  w->jv = calloc(mc, sizeof(double));
  w->jQ = calloc(mc, sizeof(double));
  w->jQ2 = calloc(mc * (mc + 1), sizeof(double));
  w->cols = calloc(mc, sizeof(int));
  w->K = calloc(nblk, sizeof(double));
  w->C = calloc(nblk, sizeof(double));
  w->M = calloc(nblk, sizeof(double));
  w->fdcol = calloc(nblk, sizeof(double));
  w->fd = calloc(nfd, sizeof(double));
  w->mk = calloc(3 * nb, sizeof(double));
  w->js = calloc(6 * mc, sizeof(double)); /* fmb_eval_scratch: 6 x the columns from ABI 3.3 */
  w->qpert = calloc(nq, sizeof(double));
  w->vpert = calloc(nq, sizeof(double));
  w->ewt_default = calloc(2 * nq, sizeof(double));
  w->Qg = calloc(nq, sizeof(double));
  w->work_done = calloc((size_t)m->njoint + 1, sizeof(double));
  w->redundant = calloc((size_t)m->nc + 1, 1);
  w->nredundant_cap = m->nc;
  w->input = calloc((size_t)m->ninput + 1, sizeof *w->input);
  if (w->input) fmb_workspace_inputs_reset(m, w);
  if (!w->redundant || !w->input) {
    fmb_workspace_free(w);
    return NULL;
  }
  if (!w->work_done || !w->plugin || !w->phi || !w->phi_t || !w->phi_tt || !w->phi_q || !w->phi_q2 || !w->jq ||
      !w->jv || !w->jQ || !w->jQ2 || !w->cols || !w->K || !w->C || !w->M || !w->fdcol || !w->fd || !w->mk || !w->js ||
      !w->qpert || !w->vpert || !w->ewt_default || !w->Qg) {
    fmb_workspace_free(w);
    return NULL;
  }
  size_t ncache = 0;
  for (int b = 1; b < m->nbody; ++b) ncache += 3 * block_size(&m->body[b]);
  if (ncache * sizeof(double) <= FMB_BLOCK_CACHE_BYTES) {
    w->cache = malloc((ncache + 1) * sizeof(double));
    w->cache_adr = calloc((size_t)m->nbody + 1, sizeof(size_t));
    if (!w->cache || !w->cache_adr) {
      fmb_workspace_free(w);
      return NULL;
    }
    size_t adr = 0;
    for (int b = 1; b < m->nbody; ++b) {
      w->cache_adr[b] = adr;
      adr += 3 * block_size(&m->body[b]);
    }
  }
  if (m->check_definiteness) {
    w->Mg = calloc(nq * nq, sizeof(double));
    w->PhiQ = calloc((size_t)(m->nc > 0 ? m->nc : 1) * nq, sizeof(double));
    if (!w->Mg || !w->PhiQ) {
      fmb_workspace_free(w);
      return NULL;
    }
  }
  return w;
}

void fmb_workspace_free(fmbWorkspace* w) {
  if (!w) return;
  free(w->cache_adr);
  free(w->work_done);
  free(w->redundant);
  free(w->input);
  if (w->attached_free) w->attached_free(w->attached);
  double* bufs[] = {w->cache, w->plugin, w->phi,   w->phi_t, w->phi_tt,      w->phi_q, w->phi_q2, w->jq,
                    w->jv,    w->jQ,     w->jQ2,   w->K,     w->C,           w->M,     w->fdcol,  w->fd,
                    w->mk,    w->js,     w->qpert, w->vpert, w->ewt_default, w->Mg,    w->PhiQ,   w->Qg};
  for (size_t i = 0; i < sizeof bufs / sizeof bufs[0]; ++i) free(bufs[i]);
  free(w->cols);
  free(w);
}

int fmb_model_has_sparse_body(const fmbModel* m) {
  for (int b = 1; b < m->nbody; ++b)
    if (m->body[b].pnnz >= 0) return 1;
  return 0;
}

double* fmb_workspace_plugin(fmbWorkspace* w) { return w->plugin; }
double* fmb_workspace_work(fmbWorkspace* w) { return w->work_done; }
fmbInputSetting* fmb_workspace_inputs(fmbWorkspace* w) { return w->input; }

void fmb_workspace_inputs_reset(const fmbModel* m, fmbWorkspace* w) {
  for (int i = 0; i < m->ninput; ++i) {
    const fmbInputSetting at_rest = {m->input_initial[i], 0.0, 0.0, m->solver.t0, 0, fabs(m->input_initial[i])};
    w->input[i] = at_rest;
  }
}

void fmb_input_at(const fmbInputSetting* s, double t, double* value, double* rate, double* accel) {
  const double tau = t - s->t_set;
  /* a held setting is its value exactly, wherever t is (no 0 * tau rounding) */
  *value = s->rate == 0.0 && s->accel == 0.0 ? s->value : s->value + tau * (s->rate + 0.5 * tau * s->accel);
  if (rate) *rate = s->rate + tau * s->accel;
  if (accel) *accel = s->accel;
}
fmbWarnSink* fmb_workspace_warn(fmbWorkspace* w) { return &w->warn; }
unsigned char* fmb_workspace_redundant(fmbWorkspace* w, int* count) {
  if (count) {
    *count = 0;
    for (int r = 0; w->redundant && r < w->nredundant_cap; ++r) *count += w->redundant[r];
  }
  return w->redundant;
}

double* fmb_workspace_spring_energy0(fmbWorkspace* w) { return &w->spring_energy0; }
void fmb_workspace_hold_cache(fmbWorkspace* w, int hold) { w->cache_held = hold; }
void** fmb_workspace_attached(fmbWorkspace* w, void (*free_fn)(void*)) {
  if (free_fn) w->attached_free = free_fn;
  return &w->attached;
}

/* ---------------------------------------------------------------------------------------------
 * joints' view of the bodies */

/* Plugins call these from their callbacks; a NULL context or a body index other than 0 or 1 is a
   plugin bug, answered with a neutral value (NaN, 0, NULL, -1) instead of a crash. */
static int eval_body(const fmbJointEval* ev, int k) { return (ev && (k == 0 || k == 1)) ? ev->j->body[k] : -1; }

double fmb_eval_time(const fmbJointEval* ev) { return ev ? ev->t : NAN; }

int fmb_eval_ncoord(const fmbJointEval* ev, int k) {
  int b = eval_body(ev, k);
  return b >= 0 ? ev->m->body[b].nq : 0;
}

const double* fmb_eval_q(const fmbJointEval* ev, int k) {
  int b = eval_body(ev, k);
  return b >= 0 ? ev->q + ev->m->body[b].qadr : NULL;
}

const double* fmb_eval_v(const fmbJointEval* ev, int k) {
  int b = eval_body(ev, k);
  return b >= 0 ? ev->v + ev->m->body[b].qadr : NULL;
}

double* fmb_eval_scratch(const fmbJointEval* ev) { return ev ? ev->js : NULL; }

int fmb_eval_col0(const fmbJointEval* ev, int k) {
  if (!ev || (k != 0 && k != 1)) return -1; /* 0 would send a plugin to body 0's columns */
  return k == 1 ? fmb_eval_ncoord(ev, 0) : 0;
}
double fmb_eval_input(const fmbJointEval* ev) {
  double value = NAN;
  if (ev && ev->j->input >= 0 && ev->input) fmb_input_at(&ev->input[ev->j->input], ev->t, &value, NULL, NULL);
  return value;
}

double fmb_eval_input_rate(const fmbJointEval* ev, double* accel) {
  double value, rate = NAN, a = NAN;
  if (ev && ev->j->input >= 0 && ev->input) fmb_input_at(&ev->input[ev->j->input], ev->t, &value, &rate, &a);
  if (accel) *accel = a;
  return rate;
}

int fmb_marker(const fmbJointEval* ev, int k, const double local[2], double pos[2], double* angle, double* dpos_dq,
               int ld, double* dangle_dq) {
  if (!ev || !local || !pos || (k != 0 && k != 1) || (dpos_dq && ld < 0)) return -1;
  int b = ev->j->body[k];
  const fmbBodyInst* bi = b >= 0 ? &ev->m->body[b] : NULL;
  if (!bi || !bi->type) { /* the world frame */
    pos[0] = local[0];
    pos[1] = local[1];
    if (angle) *angle = 0.0;
    return 0;
  }
  if (!bi->type->marker) return -1; /* a spatial-only body: refused in a planar scene at parse */
  const int n = bi->nq;
  double* dp = dpos_dq ? ev->mk : NULL;
  int rc = bi->type->marker(bi->self, ev->q + bi->qadr, local, pos, angle, dp, dangle_dq, ev->work + bi->workadr);
  if (rc || !dpos_dq) return rc;
  for (int i = 0; i < n; ++i) {
    dpos_dq[i] = dp[i];
    dpos_dq[ld + i] = dp[n + i];
  }
  return 0;
}

int fmb_joint_cols(const fmbModel* m, const fmbJointInst* j, int* cols) {
  int n = 0;
  for (int k = 0; k < 2; ++k) {
    if (j->body[k] < 0) continue;
    const fmbBodyInst* b = &m->body[j->body[k]];
    for (int i = 0; i < b->nq; ++i) cols[n++] = b->qadr + i;
  }
  return n;
}

static int joint_eval(const fmbModel* m, fmbWorkspace* w, int j, double t, const double* q, const double* v,
                      double* phi, double* phi_q, double* phi_t, double* phi_tt) {
  const fmbJointInst* ji = &m->joint[j];
  fmbJointEval ev = {m, ji, t, q, v, w->plugin, w->mk, w->js, w->input};
  memset(phi_q, 0, (size_t)ji->nrows * (size_t)ji->ncol * sizeof(double));
  for (int r = 0; r < ji->nrows; ++r) phi_t[r] = phi_tt[r] = 0.0;
  return ji->type->constraint(ji->self, &ev, phi, phi_q, phi_t, phi_tt);
}

int fmb_joint_constraint(const fmbModel* m, fmbWorkspace* w, int j, double t, const double* q, const double* v,
                         double* phi, double* phi_q, double* phi_t, double* phi_tt) {
  return joint_eval(m, w, j, t, q, v, phi, phi_q, phi_t, phi_tt);
}

static int joint_force(const fmbModel* m, fmbWorkspace* w, int j, double t, const double* q, const double* v,
                       double* Q) {
  const fmbJointInst* ji = &m->joint[j];
  fmbJointEval ev = {m, ji, t, q, v, w->plugin, w->mk, w->js, w->input};
  memset(Q, 0, (size_t)ji->ncol * sizeof(double));
  return ji->type->force(ji->self, &ev, Q);
}

/* The columns (of the joint's ncol) its equations can depend on: those where its Phi_q or its
   force Q is nonzero at either of two random states near the initial one (for a body with a
   sparse pattern; a dense body's columns are all kept). A structural nonzero
   vanishes at a random state with probability zero, so what vanishes at both is zero for the
   smooth functions joints are; a joint that cannot be evaluated there keeps every column. A pin
   at a beam's root then touches the frame's 3 columns instead of all 3 + 3 ne. Setup-time. */
int fmb_joint_support(const fmbModel* m, fmbWorkspace* w, int j, int* sup) {
  const fmbJointInst* ji = &m->joint[j];
  const int ncol = fmb_joint_cols(m, ji, w->cols), nq = m->nq;
  unsigned char* hit = calloc((size_t)ncol + 1, 1);
  double* q = calloc(4 * (size_t)nq, sizeof(double));
  int all = !hit || !q;
  if (!all) {
    double *v = q + nq, *q0 = v + nq, *v0 = q0 + nq;
    for (int b = 1; b < m->nbody; ++b)
      m->body[b].type->initial(m->body[b].self, q0 + m->body[b].qadr, v0 + m->body[b].qadr);
    unsigned long long seed = 0x9E3779B97F4A7C15ull + (unsigned long long)j;
    for (int probe = 0; probe < 2 && !all; ++probe) {
      for (int i = 0; i < 2 * nq; ++i) {
        seed = seed * 6364136223846793005ull + 1442695040888963407ull;
        const double u = (double)(seed >> 11) / 9007199254740992.0 - 0.5;
        const double x0 = i < nq ? q0[i] : v0[i - nq];
        (i < nq ? q : v)[i % nq] = x0 + 0.01 * (1.0 + fabs(x0)) * u;
      }
      if (ji->type->force) {
        if (joint_force(m, w, j, m->solver.t0, q, v, w->jQ)) all = 1;
        for (int c = 0; c < ncol && !all; ++c) hit[c] |= w->jQ[c] != 0.0;
      }
      if (ji->nrows > 0 && !all) {
        if (joint_eval(m, w, j, m->solver.t0, q, v, w->phi, w->phi_q, w->phi_t, w->phi_tt)) all = 1;
        for (int k = 0; k < ji->nrows * ncol && !all; ++k) hit[k % ncol] |= w->phi_q[k] != 0.0;
      }
    }
  }
  /* only a body that declared a sparse pattern (a large one) is narrowed: a dense body's columns
     stay whole, as its block is (the same pattern, hence the same KLU pivoting, as before) */
  for (int k = 0, c0 = 0; k < 2 && !all; ++k) {
    if (ji->body[k] < 0) continue;
    const fmbBodyInst* bk = &m->body[ji->body[k]];
    if (bk->pnnz < 0) memset(hit + c0, 1, (size_t)bk->nq);
    c0 += bk->nq;
  }
  int n = 0;
  for (int c = 0; c < ncol; ++c)
    if (all || hit[c]) sup[n++] = c;
  free(hit);
  free(q);
  return n;
}

/* ---------------------------------------------------------------------------------------------
 * adding into the Newton matrix's values on the model's CSC pattern (pattern.c built it) */

/* position of (r, c) in the data array; the entry must be in the pattern */
static long find_entry(const fmbModel* m, int r, int c) {
  long lo = m->colptr[c], hi = m->colptr[c + 1] - 1;
  while (lo <= hi) {
    long mid = (lo + hi) / 2;
    if (m->rowind[mid] < r)
      lo = mid + 1;
    else if (m->rowind[mid] > r)
      hi = mid - 1;
    else
      return mid;
  }
  return -1;
}

static void csc_add(const fmbModel* m, double* data, int r, int c, double v) {
  long k = find_entry(m, r, c);
  if (k >= 0) data[k] += v;
}

static void csc_add_block(const fmbModel* m, double* data, int r0, int nr, int c0, int nc, const double* vals, int ld,
                          double scale) {
  for (int j = 0; j < nc; ++j) {
    long k = find_entry(m, r0, c0 + j);
    if (k < 0) continue; /* not in the pattern: a programming error caught by the FD tests */
    const double* col = vals + (size_t)j * (size_t)ld;
    for (int i = 0; i < nr; ++i) data[k + i] += scale * col[i];
  }
}

/* ---------------------------------------------------------------------------------------------
 * residual */

/* 1 when every x[i] is finite. A non-finite double has all eleven exponent bits set, so adding
   one at the exponent's lowest bit carries into the sign bit exactly then; or-ing that over the
   vector has no early exit and no branch per value, and vectorizes (integer lanes) where
   isfinite's test-and-return did not: three calls per residual */
static int all_finite(const double* x, int n) {
  const uint64_t exponent = 0x7ff0000000000000u, low = 0x0010000000000000u;
  uint64_t bad = 0;
  for (int i = 0; i < n; ++i) {
    uint64_t bits;
    memcpy(&bits, x + i, sizeof bits);
    bad |= (bits & exponent) + low;
  }
  return (bad >> 63) == 0;
}

static int system_residual(const fmbModel* m, fmbWorkspace* w, double t, const double* y, const double* yp, double* F,
                           int eliminate_aux) {
  const int nq = m->nq, nc = m->nc;
  const double *q = y, *v = y + nq, *lam = y + 2 * nq, *mu = y + 2 * nq + nc;
  const double *qp = yp, *vp = yp + nq;
  double *Fq = F, *Fv = F + nq, *Fl = F + 2 * nq, *Fm = F + 2 * nq + nc;
  if (!all_finite(y, m->ny) || !all_finite(yp, m->ny)) return 1; /* IDA retries with a smaller step */
  for (int i = 0; i < nq; ++i) Fq[i] = qp[i] - v[i];
  for (int b = 1; b < m->nbody; ++b) {
    const fmbBodyInst* bi = &m->body[b];
    const int eliminate = eliminate_aux && !bi->aux_iterated; /* a mixed form's fields are iterated */
    if (bi->nz > 0 && eliminate) memset(F + m->zoff + bi->zadr, 0, sizeof(double) * (size_t)bi->nz);
    int rc = bi->nz > 0 && !eliminate ? bi->type->residual_aux(bi->self, &m->env, q + bi->qadr, v + bi->qadr,
                                                               vp + bi->qadr, y + m->zoff + bi->zadr, Fv + bi->qadr,
                                                               F + m->zoff + bi->zadr, w->plugin + bi->workadr)
                                      : bi->type->residual(bi->self, &m->env, q + bi->qadr, v + bi->qadr, vp + bi->qadr,
                                                           Fv + bi->qadr, w->plugin + bi->workadr);
    if (rc) return rc;
  }
  for (int j = 0; j < m->njoint; ++j) {
    const fmbJointInst* ji = &m->joint[j];
    if (!ji->type->force && ji->nrows == 0) continue;
    int ncol = fmb_joint_cols(m, ji, w->cols);
    if (ji->type->force) {
      int rc = joint_force(m, w, j, t, q, v, w->jQ);
      if (rc) return rc;
      for (int c = 0; c < ncol; ++c) Fv[w->cols[c]] -= w->jQ[c];
    }
    if (ji->nrows == 0) continue;
    int rc = joint_eval(m, w, j, t, q, v, w->phi, w->phi_q, w->phi_t, w->phi_tt);
    if (rc) return rc;
    for (int r = 0; r < ji->nrows; ++r) {
      const double* row = w->phi_q + (size_t)r * (size_t)ncol;
      double pv = 0.0;
      const double l = lam[ji->rowadr + r], u = mu[ji->rowadr + r];
      if (w->redundant[ji->rowadr + r]) {
        Fl[ji->rowadr + r] = l;
        Fm[ji->rowadr + r] = u;
        continue;
      }
      for (int c = 0; c < ncol; ++c) {
        pv += row[c] * v[w->cols[c]];
        Fv[w->cols[c]] += row[c] * l;
        Fq[w->cols[c]] -= row[c] * u;
      }
      Fl[ji->rowadr + r] = w->phi[r];
      Fm[ji->rowadr + r] = pv + w->phi_t[r];
    }
  }
  return all_finite(F, m->ny) ? 0 : 1;
}

int fmb_system_residual(const fmbModel* m, fmbWorkspace* w, double t, const double* y, const double* yp, double* F) {
  return system_residual(m, w, t, y, yp, F, 0);
}

/* Why the integrators eliminate the auxiliary unknowns. Their simplified Newton iteration
   freezes the Newton matrix at the step's start. Carried as unknowns of their own, the z start
   from an extrapolation inconsistent with the stages' q, v and a, and the matrix's z columns
   (the beam's dR/dT_e = -F_e, the coupling forces, which carry the inertia of modes far faster
   than the step) are stale at the stages, so the z error contracted by only 2-4x per iteration
   where the coordinates' fell by 1e-5 (radau5, pendulum, 64 elements banded), and Newton failed
   to converge on most steps. Evaluating R with z eliminated (the body's `residual`) and Rz = 0
   makes z mere placeholders; the banded Newton matrix, evaluated where z is consistent
   (fmb_system_aux_eliminate), then gives through its q, v part the Schur complement of its z
   block, which is the dense assembly's Newton matrix: the iteration is the dense assembly's,
   at the banded factorization's cost (docs/performance.md, "Fine meshes"). A body whose z are a
   mixed form's fields (fmbBodyType.aux_iterated: the exact beam's axial forces) is iterated on as
   it is: eliminating them would give back the displacement form whose Newton matrix goes stale. */
int fmb_system_residual_eliminated(const fmbModel* m, fmbWorkspace* w, double t, const double* y, const double* yp,
                                   double* F) {
  return system_residual(m, w, t, y, yp, F, 1);
}

int fmb_system_aux_eliminate(const fmbModel* m, fmbWorkspace* w, double* y, const double* yp) {
  const int nq = m->nq;
  for (int b = 1; b < m->nbody; ++b) {
    const fmbBodyInst* bi = &m->body[b];
    if (bi->nz <= 0) continue;
    const int rc = bi->type->aux_initial(bi->self, &m->env, y + bi->qadr, y + nq + bi->qadr, yp + nq + bi->qadr,
                                         y + m->zoff + bi->zadr, w->plugin + bi->workadr);
    if (rc) return rc;
  }
  return 0;
}

/* ---------------------------------------------------------------------------------------------
 * iteration matrix */

typedef struct {
  const fmbModel* m;
  double* csc;
  double* dense;
} Sink;

static void sink_add(const Sink* s, int r, int c, double v) {
  if (s->dense)
    s->dense[(size_t)c * (size_t)s->m->ny + (size_t)r] += v;
  else
    csc_add(s->m, s->csc, r, c, v);
}

static void sink_block(const Sink* s, int r0, int nr, int c0, int nc, const double* vals, int ld, double scale) {
  if (!s->dense) {
    csc_add_block(s->m, s->csc, r0, nr, c0, nc, vals, ld, scale);
    return;
  }
  for (int j = 0; j < nc; ++j)
    for (int i = 0; i < nr; ++i)
      s->dense[(size_t)(c0 + j) * (size_t)s->m->ny + (size_t)(r0 + i)] += scale * vals[(size_t)j * ld + i];
}

int fmb_body_blocks(const fmbModel* m, fmbWorkspace* w, int b, const double* q, const double* v, const double* a,
                    const double* ewt, double* K, double* C, double* M) {
  const fmbBodyInst* bi = &m->body[b];
  double* work = w->plugin + bi->workadr;
  if (bi->type->jacobian) return bi->type->jacobian(bi->self, &m->env, q, v, a, K, C, M, work);
  return fmb_fd_body_jacobian(bi, &m->env, q, v, a, ewt, ewt + m->nq, K, C, M, work, w->fd);
}

int fmb_system_jacobian(const fmbModel* m, fmbWorkspace* w, double t, double cj, const double* y, const double* yp,
                        const double* ewt, int reuse_blocks, double* csc_data, double* dense) {
  const int nq = m->nq, nc = m->nc;
  const int Fq = 0, Fv = nq, Fl = 2 * nq, Fm = 2 * nq + nc;
  const int Yq = 0, Yv = nq, Yl = 2 * nq, Ym = 2 * nq + nc;
  const double *q = y, *v = y + nq, *lam = y + 2 * nq, *mu = y + 2 * nq + nc, *vp = yp + nq;
  Sink s = {m, csc_data, dense};
  if (dense)
    memset(dense, 0, (size_t)m->ny * (size_t)m->ny * sizeof(double));
  else
    memset(csc_data, 0, (size_t)m->nnz * sizeof(double));

  for (int i = 0; i < nq; ++i) {
    sink_add(&s, Fq + i, Yq + i, cj);
    sink_add(&s, Fq + i, Yv + i, -1.0);
  }
  /* held (an analysis between a run's advances): the blocks are evaluated anew into the scratch
     and the cache keeps the run's last fresh ones, which its next Jacobian may reuse */
  double* cache = w->cache_held ? NULL : w->cache;
  const int reuse = reuse_blocks && cache && w->cache_valid;
  for (int b = 1; b < m->nbody; ++b) {
    const fmbBodyInst* bi = &m->body[b];
    const int n = bi->nq, a0 = bi->qadr;
    const size_t nn = block_size(bi);
    double *K = w->K, *C = w->C, *M = w->M;
    if (cache) {
      K = cache + w->cache_adr[b];
      C = K + nn;
      M = C + nn;
    }
    if (!reuse) {
      int rc = bi->pnnz >= 0 ? fmb_body_sparse_blocks(bi, &m->env, q + a0, v + a0, vp + a0, y + m->zoff + bi->zadr,
                                                      ewt + a0, ewt + nq + a0, K, C, M, w->plugin + bi->workadr, w->fd)
                             : fmb_body_blocks(m, w, b, q + a0, v + a0, vp + a0, ewt + a0, K, C, M);
      if (rc) {
        if (cache) w->cache_valid = 0;
        return rc;
      }
    }
    if (bi->pnnz >= 0) {
      /* the declared pattern: rows R then Rz, columns q/v/a then z */
      for (int c = 0; c < n + bi->nz; ++c)
        for (long k = bi->pcolptr[c]; k < bi->pcolptr[c + 1]; ++k) {
          const int r = bi->prowind[k];
          const int row = r < n ? Fv + a0 + r : m->zoff + bi->zadr + (r - n);
          if (c < n) {
            sink_add(&s, row, Yq + a0 + c, K[k]);
            sink_add(&s, row, Yv + a0 + c, C[k] + cj * M[k]);
          } else {
            sink_add(&s, row, m->zoff + bi->zadr + (c - n), K[k]);
          }
        }
      continue;
    }
    /* dR/dq under q, dR/dv + cj dR/da under v */
    for (size_t k = 0; k < nn; ++k) w->fdcol[k] = C[k] + cj * M[k];
    sink_block(&s, Fv + a0, n, Yq + a0, n, K, n, 1.0);
    sink_block(&s, Fv + a0, n, Yv + a0, n, w->fdcol, n, 1.0);
  }
  if (cache) w->cache_valid = 1;

  memcpy(w->qpert, q, (size_t)nq * sizeof(double));
  memcpy(w->vpert, v, (size_t)nq * sizeof(double));
  for (int j = 0; j < m->njoint; ++j) {
    const fmbJointInst* ji = &m->joint[j];
    if (!ji->type->force && ji->nrows == 0) continue;
    const int ncol = fmb_joint_cols(m, ji, w->cols), nr = ji->nrows;
    const int* cols = w->cols;
    if (ji->type->force) {
      /* -dQ/dq and -dQ/dv by forward differences over the two bodies' coordinates */
      int rc = joint_force(m, w, j, t, q, v, w->jQ);
      if (rc) return rc;
      for (int pass = 0; pass < 2; ++pass) {
        double* x = pass == 0 ? w->qpert : w->vpert;
        const double* ew = ewt + (pass == 0 ? 0 : nq);
        for (int si = 0; si < ji->nsup; ++si) {
          const int gc = cols[ji->sup[si]];
          const double x0 = x[gc];
          double h = fmb_fd_increment(x0, ew[gc]);
          x[gc] = x0 + h;
          h = x[gc] - x0;
          rc = joint_force(m, w, j, t, w->qpert, w->vpert, w->jQ2);
          x[gc] = x0;
          if (rc) return rc;
          for (int sr = 0; sr < ji->nsup; ++sr) {
            const int r = ji->sup[sr];
            sink_add(&s, Fv + cols[r], (pass == 0 ? Yq : Yv) + gc, -(w->jQ2[r] - w->jQ[r]) / h);
          }
        }
      }
    }
    if (nr == 0) continue;
    int rc = joint_eval(m, w, j, t, q, v, w->phi, w->phi_q, w->phi_t, w->phi_tt);
    if (rc) return rc;
    for (int r = 0; r < nr; ++r)
      if (w->redundant[ji->rowadr + r]) {
        sink_add(&s, Fl + ji->rowadr + r, Yl + ji->rowadr + r, 1.0);
        sink_add(&s, Fm + ji->rowadr + r, Ym + ji->rowadr + r, 1.0);
      }
    for (int r = 0; r < nr; ++r)
      for (int c = 0; c < ncol; ++c) {
        const double d = w->phi_q[(size_t)r * ncol + c];
        if (d == 0.0 || w->redundant[ji->rowadr + r]) continue;
        sink_add(&s, Fl + ji->rowadr + r, Yq + cols[c], d);
        sink_add(&s, Fm + ji->rowadr + r, Yv + cols[c], d);
        sink_add(&s, Fv + cols[c], Yl + ji->rowadr + r, d);
        sink_add(&s, Fq + cols[c], Ym + ji->rowadr + r, -d);
      }
    /* d(Phi_q v)/dq, d(Phi_q^T lambda)/dq and d(Phi_q^T mu)/dq by forward differences of Phi_q */
    for (int si = 0; si < ji->nsup; ++si) {
      const int gc = cols[ji->sup[si]];
      const double x0 = w->qpert[gc];
      double h = fmb_fd_increment(x0, ewt[gc]);
      w->qpert[gc] = x0 + h;
      h = w->qpert[gc] - x0;
      rc = joint_eval(m, w, j, t, w->qpert, v, w->jq, w->phi_q2, w->jv, w->jQ2);
      w->qpert[gc] = x0;
      if (rc) return rc;
      for (int r = 0; r < nr; ++r) {
        double dpv = 0.0;
        const double l = lam[ji->rowadr + r], u = mu[ji->rowadr + r];
        if (w->redundant[ji->rowadr + r]) continue;
        for (int sk = 0; sk < ji->nsup; ++sk) {
          const int k = ji->sup[sk];
          const double dphiq = (w->phi_q2[(size_t)r * ncol + k] - w->phi_q[(size_t)r * ncol + k]) / h;
          if (dphiq == 0.0) continue;
          dpv += dphiq * v[cols[k]];
          sink_add(&s, Fv + cols[k], Yq + gc, dphiq * l);
          sink_add(&s, Fq + cols[k], Yq + gc, -dphiq * u);
        }
        if (dpv != 0.0) sink_add(&s, Fm + ji->rowadr + r, Yq + gc, dpv);
      }
    }
  }
  return 0;
}

/* ---------------------------------------------------------------------------------------------
 * pieces for initial conditions, outputs and checks (not on the integration path) */

int fmb_body_mass(const fmbModel* m, fmbWorkspace* w, int b, const double* q, const double* v, double* M) {
  const fmbBodyInst* bi = &m->body[b];
  double* a = w->fd + 6 * (size_t)w->max_nq; /* zero acceleration */
  memset(a, 0, (size_t)bi->nq * sizeof(double));
  double* ew = w->ewt_default;
  for (int i = 0; i < bi->nq; ++i) ew[i] = ew[m->nq + i] = 1.0 / (m->solver.atol + m->solver.rtol * fabs(q[i]));
  if (bi->type->jacobian) return bi->type->jacobian(bi->self, &m->env, q, v, a, w->K, w->C, M, w->plugin + bi->workadr);
  return fmb_fd_body_jacobian(bi, &m->env, q, v, a, ew, ew + m->nq, NULL, NULL, M, w->plugin + bi->workadr, w->fd);
}

int fmb_generalized_forces(const fmbModel* m, fmbWorkspace* w, double t, const double* q, const double* v,
                           double* Qtot) {
  memset(Qtot, 0, (size_t)m->nq * sizeof(double));
  double* zero = w->fd + 6 * (size_t)w->max_nq;
  for (int b = 1; b < m->nbody; ++b) {
    const fmbBodyInst* bi = &m->body[b];
    memset(zero, 0, (size_t)bi->nq * sizeof(double));
    int rc = bi->type->residual(bi->self, &m->env, q + bi->qadr, v + bi->qadr, zero, Qtot + bi->qadr,
                                w->plugin + bi->workadr);
    if (rc) return rc;
    for (int i = 0; i < bi->nq; ++i) Qtot[bi->qadr + i] = -Qtot[bi->qadr + i];
  }
  for (int j = 0; j < m->njoint; ++j) {
    const fmbJointInst* ji = &m->joint[j];
    if (!ji->type->force) continue;
    int ncol = fmb_joint_cols(m, ji, w->cols);
    int rc = joint_force(m, w, j, t, q, v, w->jQ);
    if (rc) return rc;
    for (int c = 0; c < ncol; ++c) Qtot[w->cols[c]] += w->jQ[c];
  }
  return 0;
}

/* gamma = -(Phi_q v)_q v - Phi_tt, the right side of Phi_q a = gamma (the constraints
   differentiated twice in time), joint by joint. (Phi_q v)_q v = d/ds [Phi_q(q + s v) v] at s = 0
   by the five-point stencil [8 (g(h) - g(-h)) - (g(2h) - g(-2h))] / (12 h), with h moving no
   coordinate by more than 1e-3 (an angle by 1e-3 rad): truncation ~ h^4 / 30 ~ 3e-14 and roundoff
   ~ 1e-13 of the term. The central difference used before (step 1e-5 (1 + |q|) / |v|) erred by
   ~4e-9 of the term once a crank had turned a few times, and near a singular configuration that
   error is divided by the vanishing singular value of Phi_q: the accelerations of a parallelogram
   4e-4 rad from flat were ~1e-3 off, and the integrator failed its error test there at tight
   tolerances. Uses w->qpert. */
int fmb_constraints_gamma(const fmbModel* m, fmbWorkspace* w, double t, const double* q, const double* v,
                          double* gamma) {
  const int nq = m->nq;
  double vmax = 0.0;
  for (int i = 0; i < nq; ++i) vmax = fmax(vmax, fabs(v[i]));
  const double h = vmax > 0 ? 1e-3 / vmax : 0.0;
  static const double shift[4] = {1.0, -1.0, 2.0, -2.0}, weight[4] = {8.0, -8.0, -1.0, 1.0};
  double* qs = w->qpert;
  for (int r = 0; r < m->nc; ++r) gamma[r] = 0.0;
  for (int pass = 0; pass < 5; ++pass) { /* the four shifted states, then Phi_tt at q */
    if (pass < 4 && h == 0.0) continue;
    if (pass < 4)
      for (int i = 0; i < nq; ++i) qs[i] = q[i] + shift[pass] * h * v[i];
    for (int j = 0; j < m->njoint; ++j) {
      const fmbJointInst* ji = &m->joint[j];
      if (ji->nrows == 0) continue;
      const int ncol = fmb_joint_cols(m, ji, w->cols);
      const int rc = joint_eval(m, w, j, t, pass < 4 ? qs : q, v, w->phi, w->phi_q, w->phi_t, w->phi_tt);
      if (rc) return rc;
      for (int r = 0; r < ji->nrows; ++r) {
        const int row = ji->rowadr + r;
        if (pass == 4) {
          gamma[row] = (h > 0 ? -gamma[row] / (12.0 * h) : 0.0) - w->phi_tt[r];
          continue;
        }
        double g = 0.0;
        for (int c = 0; c < ncol; ++c) g += w->phi_q[(size_t)r * ncol + c] * v[w->cols[c]];
        gamma[row] += weight[pass] * g;
      }
    }
  }
  return 0;
}

int* fmb_workspace_cols(fmbWorkspace* w) { return w->cols; }
double* fmb_workspace_joint_scratch(fmbWorkspace* w, int which) {
  double* const bufs[] = {w->phi, w->phi_q, w->phi_t, w->phi_tt};
  return bufs[which];
}
double* fmb_workspace_qscratch(fmbWorkspace* w) { return w->vpert; }

int fmb_constraints_all(const fmbModel* m, fmbWorkspace* w, double t, const double* q, const double* v, double* phi,
                        double* phi_q_dense, double* phi_t, double* phi_tt) {
  if (phi_q_dense) memset(phi_q_dense, 0, (size_t)m->nc * (size_t)m->nq * sizeof(double));
  for (int j = 0; j < m->njoint; ++j) {
    const fmbJointInst* ji = &m->joint[j];
    if (ji->nrows == 0) continue;
    int ncol = fmb_joint_cols(m, ji, w->cols);
    int rc = joint_eval(m, w, j, t, q, v, w->phi, w->phi_q, w->phi_t, w->phi_tt);
    if (rc) return rc;
    for (int r = 0; r < ji->nrows; ++r) {
      const int row = ji->rowadr + r;
      if (phi) phi[row] = w->phi[r];
      if (phi_t) phi_t[row] = w->phi_t[r];
      if (phi_tt) phi_tt[row] = w->phi_tt[r];
      if (phi_q_dense)
        for (int c = 0; c < ncol; ++c) phi_q_dense[(size_t)row * m->nq + w->cols[c]] += w->phi_q[(size_t)r * ncol + c];
    }
  }
  return 0;
}

void fmb_energy(const fmbModel* m, fmbWorkspace* w, double t, const double* q, const double* v, fmbEnergy* e) {
  memset(e, 0, sizeof *e);
  for (int b = 1; b < m->nbody; ++b) {
    const fmbBodyInst* bi = &m->body[b];
    if (!bi->type->energy) continue;
    fmbEnergy eb = {0, 0, 0, 0};
    bi->type->energy(bi->self, &m->env, q + bi->qadr, v + bi->qadr, &eb, w->plugin + bi->workadr);
    e->kinetic += eb.kinetic;
    e->strain += eb.strain;
    e->gravity += eb.gravity;
    e->spring += eb.spring;
  }
  for (int j = 0; j < m->njoint; ++j) {
    const fmbJointInst* ji = &m->joint[j];
    if (!ji->type->energy) continue;
    fmbJointEval ev = {m, ji, t, q, v, w->plugin, w->mk, w->js, w->input};
    e->spring += ji->type->energy(ji->self, &ev);
  }
}

/* Mass matrix positive definite on the constraint manifold? By Finsler's lemma M is positive
 * definite on null(Phi_q) iff M + r Phi_q^T Phi_q is positive definite for r large enough; a
 * Cholesky factorization with r = 1e8 (relative to M's diagonal) tells. Runs only when a body
 * declares its model can lose definiteness (FOAC). */
int fmb_check_mass(const fmbModel* m, fmbWorkspace* w, double t, const double* q, const double* v,
                   double singular_tol) {
  if (!m->check_definiteness) return 0;
  const int nq = m->nq;
  memset(w->Mg, 0, (size_t)nq * nq * sizeof(double));
  for (int b = 1; b < m->nbody; ++b) {
    const fmbBodyInst* bi = &m->body[b];
    if (fmb_body_mass(m, w, b, q + bi->qadr, v + bi->qadr, w->M)) return b + 1;
    for (int c = 0; c < bi->nq; ++c)
      for (int r = 0; r < bi->nq; ++r) w->Mg[(size_t)(bi->qadr + c) * nq + bi->qadr + r] = w->M[(size_t)c * bi->nq + r];
  }
  double dmax = 0.0;
  for (int i = 0; i < nq; ++i) dmax = fmax(dmax, fabs(w->Mg[(size_t)i * nq + i]));
  if (m->nc > 0) {
    fmb_constraints_all(m, w, t, q, v, NULL, w->PhiQ, NULL, NULL);
    double pmax = 0.0;
    for (size_t k = 0; k < (size_t)m->nc * nq; ++k) pmax = fmax(pmax, fabs(w->PhiQ[k]));
    const double r = 1e8 * dmax / fmax(pmax * pmax, 1e-300);
    for (int i = 0; i < nq; ++i)
      for (int k = 0; k < nq; ++k) {
        double s = 0.0;
        for (int c = 0; c < m->nc; ++c) s += w->PhiQ[(size_t)c * nq + i] * w->PhiQ[(size_t)c * nq + k];
        w->Mg[(size_t)k * nq + i] += r * s;
      }
  }
  for (int i = 0; i < nq; ++i) w->Qg[i] = w->Mg[(size_t)i * nq + i]; /* diagonal before factoring */
  int bad = fmb_cholesky(nq, w->Mg);
  if (!bad && singular_tol > 0.0) {
    /* squared pivot over its diagonal entry: 1 for a diagonal matrix, -> 0 as M becomes singular */
    for (int i = 0; i < nq && !bad; ++i) {
      const double d = w->Mg[(size_t)i * nq + i];
      if (w->Qg[i] > 0.0 && d * d < singular_tol * w->Qg[i]) bad = i + 1;
    }
  }
  if (!bad) return 0;
  /* name the body whose model can lose definiteness and whose coordinates hold the failing pivot */
  for (int b = 1; b < m->nbody; ++b) {
    const fmbBodyInst* bi = &m->body[b];
    if (bad - 1 >= bi->qadr && bad - 1 < bi->qadr + bi->nq) return b + 1;
  }
  for (int b = 1; b < m->nbody; ++b)
    if (m->body[b].type->indefinite_mass && m->body[b].type->indefinite_mass(m->body[b].self)) return b + 1;
  return 1;
}

/* norms of the position and velocity constraint residuals */
void fmb_constraint_norms(const fmbModel* m, fmbWorkspace* w, double t, const double* q, const double* v, double* pos,
                          double* vel) {
  double sp = 0.0, sv = 0.0;
  for (int j = 0; j < m->njoint; ++j) {
    const fmbJointInst* ji = &m->joint[j];
    if (ji->nrows == 0) continue;
    int ncol = fmb_joint_cols(m, ji, w->cols);
    if (joint_eval(m, w, j, t, q, v, w->phi, w->phi_q, w->phi_t, w->phi_tt)) continue;
    for (int r = 0; r < ji->nrows; ++r) {
      double pv = w->phi_t[r];
      for (int c = 0; c < ncol; ++c) pv += w->phi_q[(size_t)r * ncol + c] * v[w->cols[c]];
      sp += w->phi[r] * w->phi[r];
      sv += pv * pv;
    }
  }
  *pos = sqrt(sp);
  *vel = sqrt(sv);
}

/* power joint j feeds into the system: of its constraint forces -Phi_q^T lambda, that is
   -lambda^T Phi_q v = lambda^T Phi_t (zero for a scleronomic joint), plus that of its applied
   forces, Q . v (a spring's includes the rate of its potential, a damper's is <= 0) */
double fmb_joint_power(const fmbModel* m, fmbWorkspace* w, int j, double t, const double* q, const double* v,
                       const double* lam) {
  const fmbJointInst* ji = &m->joint[j];
  double p = 0.0;
  if (ji->type->force) {
    const int ncol = fmb_joint_cols(m, ji, w->cols);
    if (joint_force(m, w, j, t, q, v, w->jQ)) return NAN;
    for (int c = 0; c < ncol; ++c) p += w->jQ[c] * v[w->cols[c]];
  }
  if (ji->nrows == 0) return p;
  if (joint_eval(m, w, j, t, q, v, w->phi, w->phi_q, w->phi_t, w->phi_tt)) return NAN;
  for (int r = 0; r < ji->nrows; ++r) p += lam[ji->rowadr + r] * w->phi_t[r];
  return p;
}

/* The constraint force -Phi_q^T lambda restricted to a body's frame coordinates (x, y, theta) is
   the resultant F and its moment about the frame origin r; every material point p of a body with
   a frame has dp/dtheta = Ĩ (p - r) and dangle/dtheta = 1 (rigid body and beam alike), so the
   torque about the joint's point P is Q_theta - (P - r) x F. */
int fmb_joint_reaction(const fmbModel* m, fmbWorkspace* w, int j, double t, const double* q, const double* v,
                       const double* lam, double out[3]) {
  const fmbJointInst* ji = &m->joint[j];
  int k = 1;
  if (ji->body[1] < 0 || m->body[ji->body[1]].nq < 3) k = 0;
  if (ji->nrows == 0 || ji->body[k] < 0 || m->body[ji->body[k]].nq < 3) return -1;
  const fmbBodyInst* bi = &m->body[ji->body[k]];
  if (joint_eval(m, w, j, t, q, v, w->phi, w->phi_q, w->phi_t, w->phi_tt)) return -1;
  const int ncol = ji->ncol, c0 = k == 0 ? 0 : (ji->body[0] >= 0 ? m->body[ji->body[0]].nq : 0);
  double Q[3] = {0.0, 0.0, 0.0};
  for (int i = 0; i < 3; ++i)
    for (int r = 0; r < ji->nrows; ++r) Q[i] -= w->phi_q[(size_t)r * ncol + c0 + i] * lam[ji->rowadr + r];
  const double* qb = q + bi->qadr;
  double P[2] = {qb[0], qb[1]}, local[2], ang;
  int body = -1;
  if (ji->type->attachment && ji->type->attachment(ji->self, k, &body, local) == 0 && body == ji->body[k] &&
      bi->type->marker(bi->self, qb, local, P, &ang, NULL, NULL, w->plugin + bi->workadr))
    return -1;
  const double sign = k == 1 ? 1.0 : -1.0; /* Newton's third law: what body1 feels, reversed */
  out[0] = sign * Q[0];
  out[1] = sign * Q[1];
  out[2] = sign * (Q[2] - ((P[0] - qb[0]) * Q[1] - (P[1] - qb[1]) * Q[0]));
  return 0;
}

int fmb_joint_output(const fmbModel* m, fmbWorkspace* w, int j, int id, double t, const double* q, const double* v,
                     double* value) {
  const fmbJointInst* ji = &m->joint[j];
  fmbJointEval ev = {m, ji, t, q, v, w->plugin, w->mk, w->js, w->input};
  return ji->type->output(ji->self, id, &ev, value);
}

int fmb_joint_reaction3(const fmbModel* m, fmbWorkspace* w, int j, double t, const double* q, const double* v,
                        const double* lam, double out[6]) {
  const fmbJointInst* ji = &m->joint[j];
  const int k = ji->body[1] >= 0 && m->body[ji->body[1]].marker3 ? 1 : 0;
  if (ji->nrows == 0 || ji->body[k] < 0 || !m->body[ji->body[k]].marker3) return -1;
  const fmbBodyInst* bi = &m->body[ji->body[k]];
  if (joint_eval(m, w, j, t, q, v, w->phi, w->phi_q, w->phi_t, w->phi_tt)) return -1;
  const int n = bi->nq, c0 = k == 0 ? 0 : (ji->body[0] >= 0 ? m->body[ji->body[0]].nq : 0);
  double* Q = w->jQ; /* the constraint force -Phi_q^T lambda on the body's coordinates */
  for (int i = 0; i < n; ++i) {
    Q[i] = 0.0;
    for (int r = 0; r < ji->nrows; ++r) Q[i] -= w->phi_q[(size_t)r * ji->ncol + c0 + i] * lam[ji->rowadr + r];
  }
  /* the body's origin O: its dr/dq and G (6 rows of n, in the joint scratch) */
  static const double origin[3] = {0.0, 0.0, 0.0};
  double O[3], P[3], local[3];
  double* Jw = w->js;
  const double* qb = q + bi->qadr;
  if (bi->marker3(bi->self, qb, origin, O, NULL, Jw, Jw + 3 * (size_t)n, n, w->plugin + bi->workadr)) return -1;
  /* least squares J^T [F; tau] = Q: (J J^T) x = J Q, J 6 x n of full row rank for a body with a frame */
  double N[36], x[6];
  for (int a = 0; a < 6; ++a) {
    x[a] = 0.0;
    for (int i = 0; i < n; ++i) x[a] += Jw[(size_t)a * n + i] * Q[i];
    for (int b = 0; b < 6; ++b) {
      double s = 0.0;
      for (int i = 0; i < n; ++i) s += Jw[(size_t)a * n + i] * Jw[(size_t)b * n + i];
      N[b * 6 + a] = s;
    }
  }
  int piv[6];
  if (fmb_lu_factor(6, N, piv)) return -1;
  fmb_lu_solve(6, N, piv, x);
  /* the torque about the joint's point P = tau_O - (P - O) x F */
  int body = -1;
  for (int i = 0; i < 3; ++i) P[i] = O[i];
  if (ji->type->abi >= FMB_PLUGIN_ABI_MAJOR * 1000 + 3 && ji->type->attachment3 &&
      ji->type->attachment3(ji->self, k, &body, local) == 0 && body == ji->body[k] &&
      bi->marker3(bi->self, qb, local, P, NULL, NULL, NULL, 0, w->plugin + bi->workadr))
    return -1;
  const double d[3] = {P[0] - O[0], P[1] - O[1], P[2] - O[2]}, *F = x;
  const double dxF[3] = {d[1] * F[2] - d[2] * F[1], d[2] * F[0] - d[0] * F[2], d[0] * F[1] - d[1] * F[0]};
  const double sign = k == 1 ? 1.0 : -1.0; /* Newton's third law: what body1 feels, reversed */
  for (int i = 0; i < 3; ++i) {
    out[i] = sign * F[i];
    out[3 + i] = sign * (x[3 + i] - dxF[i]);
  }
  return 0;
}
