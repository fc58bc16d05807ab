/* pattern.c — the fixed sparsity pattern of the iteration matrix J = dF/dy + cj dF/dy'.
 *
 * Unknowns y = [q | v | lambda | mu | z] and residual rows F = [F_q | F_v | F_lambda | F_mu | F_z]
 * of the stabilized index-2 (GGL) system (see system.c). The pattern is the union of the
 * couplings each body, joint or force element introduces: a body's own block (dense, or the
 * sparse pattern it declares over its coordinates and auxiliary unknowns z), and per joint the
 * columns its equations can depend on. It is built once at load, so KLU's symbolic analysis runs
 * once, and in time and memory proportional to its nonzeros: the couplings are collected as
 * runs of consecutive rows per column, bucketed by column, sorted and merged. Within a column
 * the rows of one run are consecutive, which lets the assembly write a block column with one
 * binary search. */
#include <math.h>
#include <stdlib.h>
#include <string.h>

#include "data.h"
#include "pattern.h"

typedef struct {
  int col, start, len;
} Run;

typedef struct {
  Run* run;
  long n, cap;
} Runs;

static int add_run(Runs* rs, int col, int start, int len) {
  if (len <= 0) return 0;
  if (rs->n == rs->cap) {
    long ncap = rs->cap ? 2 * rs->cap : 1024;
    Run* nr = realloc(rs->run, (size_t)ncap * sizeof *nr);
    if (!nr) return -1;
    rs->run = nr;
    rs->cap = ncap;
  }
  rs->run[rs->n++] = (Run){col, start, len};
  return 0;
}

/* a dense rectangle, or its diagonal (diag != 0, nr == nc) */
static int add_block(Runs* rs, int r0, int nr, int c0, int nc, int diag) {
  for (int j = 0; j < nc; ++j)
    if (add_run(rs, c0 + j, diag ? r0 + j : r0, diag ? 1 : nr)) return -1;
  return 0;
}

/* every row of `rows` (sorted global indices) in every column of `cols` */
static int add_cross(Runs* rs, const int* rows, int nr, const int* cols, int nc) {
  for (int j = 0; j < nc; ++j)
    for (int i = 0; i < nr; ++i) {
      int len = 1;
      while (i + len < nr && rows[i + len] == rows[i] + len) ++len;
      if (add_run(rs, cols[j], rows[i], len)) return -1;
      i += len - 1;
    }
  return 0;
}

static int cmp_run(const void* a, const void* b) {
  const Run* x = a;
  const Run* y = b;
  return (x->start > y->start) - (x->start < y->start);
}

static int cmp_long(const void* a, const void* b) {
  long x = *(const long*)a, y = *(const long*)b;
  return (x > y) - (x < y);
}

/* A body's declared pattern as CSC over its nq + nz rows and columns, and a greedy colouring of
   its columns such that no two columns of one colour share a row (Curtis, Powell & Reid 1974):
   one residual evaluation then differences every column of a colour. */
static int body_pattern(fmbBodyInst* b) {
  b->pnnz = -1;
  if (!b->type->pattern) return 0;
  long npair = b->type->pattern(b->self, NULL, NULL);
  if (npair < 0) return 0;
  const int n = b->nq + b->nz;
  int* rows = malloc(sizeof(int) * (size_t)(npair + 1));
  int* cols = malloc(sizeof(int) * (size_t)(npair + 1));
  long* key = malloc(sizeof(long) * (size_t)(npair + 1));
  b->pcolptr = calloc((size_t)n + 1, sizeof(long));
  if (!rows || !cols || !key || !b->pcolptr || b->type->pattern(b->self, rows, cols) != npair) goto fail;
  for (long k = 0; k < npair; ++k) {
    if (rows[k] < 0 || rows[k] >= n || cols[k] < 0 || cols[k] >= n) goto fail; /* a plugin bug */
    key[k] = (long)cols[k] * n + rows[k];
  }
  qsort(key, (size_t)npair, sizeof *key, cmp_long);
  long nnz = 0;
  for (long k = 0; k < npair; ++k)
    if (k == 0 || key[k] != key[k - 1]) key[nnz++] = key[k];
  b->prowind = malloc(sizeof(int) * (size_t)(nnz + 1));
  if (!b->prowind) goto fail;
  for (long k = 0; k < nnz; ++k) {
    b->pcolptr[key[k] / n + 1]++;
    b->prowind[k] = (int)(key[k] % n);
  }
  for (int c = 0; c < n; ++c) b->pcolptr[c + 1] += b->pcolptr[c];
  b->pnnz = nnz;
  /* an analytic pattern_jacobian returns values in pair order: where each pair lands */
  if (b->type->pattern_jacobian) {
    b->npair = npair;
    b->ppos = malloc(sizeof(long) * (size_t)(npair + 1));
    if (!b->ppos) goto fail;
    for (long k = 0; k < npair; ++k) {
      long lo = b->pcolptr[cols[k]], hi = b->pcolptr[cols[k] + 1] - 1;
      while (lo < hi) { /* rows are sorted within a column */
        const long mid = (lo + hi) / 2;
        if (b->prowind[mid] < rows[k])
          lo = mid + 1;
        else
          hi = mid;
      }
      b->ppos[k] = lo;
    }
  }
  free(rows);
  free(cols);
  free(key);
  /* colours, through the transposed pattern (the columns of each row) */
  long* rptr = calloc((size_t)n + 1, sizeof(long));
  int* rcol = malloc(sizeof(int) * (size_t)(nnz + 1));
  int* color = malloc(sizeof(int) * (size_t)n);
  int* mark = malloc(sizeof(int) * (size_t)(n + 1));
  b->color_ptr = calloc((size_t)n + 2, sizeof(int));
  b->color_col = malloc(sizeof(int) * (size_t)n);
  if (!rptr || !rcol || !color || !mark || !b->color_ptr || !b->color_col) {
    free(rptr), free(rcol), free(color), free(mark);
    return -1;
  }
  for (long k = 0; k < nnz; ++k) rptr[b->prowind[k] + 1]++;
  for (int r = 0; r < n; ++r) rptr[r + 1] += rptr[r];
  for (int c = 0; c < n; ++c)
    for (long k = b->pcolptr[c]; k < b->pcolptr[c + 1]; ++k) rcol[rptr[b->prowind[k]]++] = c;
  for (int r = n; r > 0; --r) rptr[r] = rptr[r - 1];
  rptr[0] = 0;
  for (int k = 0; k <= n; ++k) mark[k] = -1;
  b->ncolor = 0;
  for (int c = 0; c < n; ++c) {
    for (long k = b->pcolptr[c]; k < b->pcolptr[c + 1]; ++k) {
      const int r = b->prowind[k];
      for (long kk = rptr[r]; kk < rptr[r + 1]; ++kk)
        if (rcol[kk] < c) mark[color[rcol[kk]]] = c;
    }
    int k = 0;
    while (mark[k] == c) ++k;
    color[c] = k;
    if (k + 1 > b->ncolor) b->ncolor = k + 1;
  }
  for (int c = 0; c < n; ++c) b->color_ptr[color[c] + 1]++;
  for (int k = 0; k < b->ncolor; ++k) b->color_ptr[k + 1] += b->color_ptr[k];
  for (int k = 0; k <= n; ++k) mark[k] = b->color_ptr[k <= b->ncolor ? k : b->ncolor];
  for (int c = 0; c < n; ++c) b->color_col[mark[color[c]]++] = c;
  free(rptr), free(rcol), free(color), free(mark);
  return 0;
fail:
  free(rows), free(cols), free(key);
  return -1;
}

void fmb_pattern_free(fmbModel* m) {
  for (int b = 0; m->body && b < m->nbody; ++b) {
    free(m->body[b].ppos);
    free(m->body[b].pcolptr);
    free(m->body[b].prowind);
    free(m->body[b].color_ptr);
    free(m->body[b].color_col);
  }
  for (int j = 0; m->joint && j < m->njoint; ++j) free(m->joint[j].sup);
  free(m->colptr);
  free(m->rowind);
  m->colptr = NULL;
  m->rowind = NULL;
}

/* a body's own block: F_v (and F_z) rows against q, v (and z) columns */
static int body_block(const fmbModel* m, Runs* rs, const fmbBodyInst* bi) {
  const int Fv = m->nq, Yq = 0, Yv = m->nq;
  if (bi->pnnz < 0)
    return add_block(rs, Fv + bi->qadr, bi->nq, Yq + bi->qadr, bi->nq, 0) ||
           add_block(rs, Fv + bi->qadr, bi->nq, Yv + bi->qadr, bi->nq, 0);
  const int n = bi->nq + bi->nz;
  for (int c = 0; c < n; ++c)
    for (long k = bi->pcolptr[c]; k < bi->pcolptr[c + 1]; ++k) {
      const int r = bi->prowind[k];
      const int row = r < bi->nq ? Fv + bi->qadr + r : m->zoff + bi->zadr + (r - bi->nq);
      if (c < bi->nq) {
        if (add_run(rs, Yq + bi->qadr + c, row, 1) || add_run(rs, Yv + bi->qadr + c, row, 1)) return -1;
      } else if (add_run(rs, m->zoff + bi->zadr + (c - bi->nq), row, 1)) {
        return -1;
      }
    }
  return 0;
}

/* a joint's couplings over the coordinates it can depend on (S, global indices, sorted);
   shifted: 2 ns scratch */
static int joint_blocks(const fmbModel* m, Runs* rs, const fmbJointInst* ji, const int* S, int ns, int* shifted) {
  const int nq = m->nq, nc = m->nc;
  const int Fq = 0, Fv = nq, Fl = 2 * nq, Fm = 2 * nq + nc;
  const int Yq = 0, Yv = nq, Yl = 2 * nq, Ym = 2 * nq + nc;
  for (int i = 0; i < ns; ++i) shifted[i] = Yq + S[i];
  /* d(Phi_q^T lambda)/dq, or a force element's dQ/dq: F_v rows x q columns */
  int* rows = shifted + ns;
  for (int i = 0; i < ns; ++i) rows[i] = Fv + S[i];
  if (add_cross(rs, rows, ns, shifted, ns)) return -1;
  if (ji->type->force) {
    for (int i = 0; i < ns; ++i) shifted[i] = Yv + S[i];
    if (add_cross(rs, rows, ns, shifted, ns)) return -1; /* dQ/dv */
  }
  if (ji->nrows == 0) return 0;
  for (int i = 0; i < ns; ++i) {
    shifted[i] = Yq + S[i];
    rows[i] = Fq + S[i];
  }
  if (add_cross(rs, rows, ns, shifted, ns)) return -1; /* d(Phi_q^T mu)/dq */
  for (int i = 0; i < ns; ++i) {
    /* Phi_q and d(Phi_q v)/dq under q, Phi_q under v */
    if (add_run(rs, Yq + S[i], Fl + ji->rowadr, ji->nrows) || add_run(rs, Yq + S[i], Fm + ji->rowadr, ji->nrows) ||
        add_run(rs, Yv + S[i], Fm + ji->rowadr, ji->nrows))
      return -1;
  }
  for (int r = 0; r < ji->nrows; ++r) {
    for (int i = 0; i < ns; ++i) rows[i] = Fv + S[i];
    if (add_cross(rs, rows, ns, (int[]){Yl + ji->rowadr + r}, 1)) return -1; /* Phi_q^T */
    for (int i = 0; i < ns; ++i) rows[i] = Fq + S[i];
    if (add_cross(rs, rows, ns, (int[]){Ym + ji->rowadr + r}, 1)) return -1; /* -Phi_q^T */
  }
  return 0;
}

int fmb_pattern_build(fmbModel* m) {
  const int nq = m->nq;
  for (int b = 1; b < m->nbody; ++b)
    if (body_pattern(&m->body[b])) return -1;
  /* which columns each joint can touch: by evaluating it (system.c), on a data object's scratch */
  fmbData* scratch = fmb_data_new(m, NULL);
  if (!scratch) return -1;
  for (int j = 0; j < m->njoint; ++j) {
    fmbJointInst* ji = &m->joint[j];
    ji->sup = malloc(sizeof(int) * (size_t)(ji->ncol + 1));
    if (!ji->sup) {
      fmb_data_destroy(scratch);
      return -1;
    }
    ji->nsup = fmb_joint_support(m, scratch->w, j, ji->sup);
  }
  fmb_data_destroy(scratch);

  Runs rs = {NULL, 0, 0};
  int* S = malloc(sizeof(int) * (size_t)(3 * (m->max_joint_cols + 1)));
  int* cols = malloc(sizeof(int) * (size_t)(m->max_joint_cols + 1));
  int err = !S || !cols;
  /* F_q = q' - v - Phi_q^T mu: the diagonals under q and v */
  err = err || add_block(&rs, 0, nq, 0, nq, 1) || add_block(&rs, 0, nq, nq, nq, 1);
  /* F_lambda, F_mu of a redundant row are lambda_r, mu_r themselves (system.c): the diagonals,
     only in models that have such rows (explicit zeros change KLU's pivoting, and with it the
     roundoff of every run: the 170-degree pendulum's period moved by 7e-6) */
  const int nc = m->nc;
  if (m->nredundant > 0)
    err = err || add_block(&rs, 2 * nq, nc, 2 * nq, nc, 1) || add_block(&rs, 2 * nq + nc, nc, 2 * nq + nc, nc, 1);
  for (int b = 1; b < m->nbody && !err; ++b) err = body_block(m, &rs, &m->body[b]);
  for (int j = 0; j < m->njoint && !err; ++j) {
    const fmbJointInst* ji = &m->joint[j];
    fmb_joint_cols(m, ji, cols);
    for (int i = 0; i < ji->nsup; ++i) S[i] = cols[ji->sup[i]]; /* increasing: sup is */
    err = joint_blocks(m, &rs, ji, S, ji->nsup, S + ji->nsup);
  }
  free(S);
  free(cols);
  const int ny = m->ny;
  /* bucket the runs by column, then per column sort and merge */
  long* cstart = calloc((size_t)ny + 2, sizeof(long));
  Run* byc = err ? NULL : malloc(sizeof(Run) * (size_t)(rs.n + 1));
  m->colptr = calloc((size_t)ny + 1, sizeof *m->colptr);
  if (err || !cstart || !byc || !m->colptr) {
    free(rs.run), free(cstart), free(byc);
    return -1;
  }
  for (long k = 0; k < rs.n; ++k) cstart[rs.run[k].col + 2]++;
  for (int c = 0; c < ny; ++c) cstart[c + 2] += cstart[c + 1];
  for (long k = 0; k < rs.n; ++k) byc[cstart[rs.run[k].col + 1]++] = rs.run[k];
  free(rs.run);
  for (int c = 0; c < ny; ++c) qsort(byc + cstart[c], (size_t)(cstart[c + 1] - cstart[c]), sizeof *byc, cmp_run);
  for (int pass = 0; pass < 2; ++pass) {
    long nnz = 0;
    for (int c = 0; c < ny; ++c) {
      m->colptr[c] = nnz;
      int last = -1; /* last row already emitted */
      for (long i = cstart[c]; i < cstart[c + 1]; ++i) {
        int s = byc[i].start, e = byc[i].start + byc[i].len;
        if (s <= last) s = last + 1;
        for (int r = s; r < e; ++r) {
          if (pass == 1) m->rowind[nnz] = r;
          ++nnz;
        }
        if (e - 1 > last) last = e - 1;
      }
    }
    m->colptr[ny] = nnz;
    if (pass == 0) {
      m->nnz = nnz;
      m->rowind = malloc((size_t)(nnz > 0 ? nnz : 1) * sizeof *m->rowind);
      if (!m->rowind) {
        free(cstart), free(byc);
        return -1;
      }
    }
  }
  free(cstart);
  free(byc);
  return 0;
}
