/* pattern.c — the fixed sparsity pattern of the iteration matrix J = dF/dy + cj dF/dyp.
 *
 * Unknowns y = [q | v | lambda | mu] and residual rows F = [F_q | F_v | F_lambda | F_mu] of the
 * stabilized index-2 (GGL) system (see system.c). The pattern is the union of rectangles, one per
 * coupling a body, joint or force element introduces; it is built once at load, so KLU's symbolic
 * analysis runs once. Within a column the rows of one rectangle are consecutive, which lets the
 * assembly write a block column with one binary search. */
#include <stdlib.h>
#include <string.h>

#include "internal.h"

typedef struct {
  int start, len;
} Run;

static int add_block(fmbModel* m, int* cap, int r0, int nr, int c0, int nc, int diag) {
  if (nr <= 0 || nc <= 0) return 0;
  if (m->nblock == *cap) {
    int ncap = *cap ? 2 * *cap : 64;
    fmbBlock* nb = realloc(m->block, (size_t)ncap * sizeof *nb);
    if (!nb) return -1;
    m->block = nb;
    *cap = ncap;
  }
  m->block[m->nblock++] = (fmbBlock){r0, nr, c0, nc, diag};
  return 0;
}

static int cmp_run(const void* a, const void* b) {
  const Run* x = a;
  const Run* y = b;
  return (x->start > y->start) - (x->start < y->start);
}

int fmb_pattern_build(fmbModel* m) {
  const int nq = m->nq, nc = m->nc;
  const int Fq = 0, Fv = nq, Fl = 2 * nq, Fm = 2 * nq + nc; /* row offsets */
  const int Yq = 0, Yv = nq, Yl = 2 * nq, Ym = 2 * nq + nc;  /* column offsets */
  int cap = 0;
  m->nblock = 0;
  /* F_q = q' - v - Phi_q^T mu */
  if (add_block(m, &cap, Fq, nq, Yq, nq, 1) || add_block(m, &cap, Fq, nq, Yv, nq, 1)) return -1;
  /* F_lambda, F_mu of a redundant row are lambda_r, mu_r themselves (system.c): the diagonals,
     only in models that have such rows (explicit zeros change KLU's pivoting, and with it the
     roundoff of every run: the 170-degree pendulum's period moved by 7e-6) */
  if (m->nredundant > 0 && (add_block(m, &cap, Fl, nc, Yl, nc, 1) || add_block(m, &cap, Fm, nc, Ym, nc, 1))) return -1;
  /* F_v = M v' - Q: each body's own dense block */
  for (int b = 1; b < m->nbody; ++b) {
    const fmbBodyInst* bi = &m->body[b];
    if (add_block(m, &cap, Fv + bi->qadr, bi->nq, Yq + bi->qadr, bi->nq, 0) ||
        add_block(m, &cap, Fv + bi->qadr, bi->nq, Yv + bi->qadr, bi->nq, 0))
      return -1;
  }
  for (int j = 0; j < m->njoint; ++j) {
    const fmbJointInst* ji = &m->joint[j];
    for (int k = 0; k < 2; ++k) {
      if (ji->body[k] < 0) continue;
      const fmbBodyInst* bk = &m->body[ji->body[k]];
      if (bk->nq == 0) continue;
      for (int k2 = 0; k2 < 2; ++k2) {
        if (ji->body[k2] < 0) continue;
        const fmbBodyInst* b2 = &m->body[ji->body[k2]];
        if (b2->nq == 0) continue;
        /* d(Phi_q^T lambda)/dq, or a force element's dQ/dq and dQ/dv */
        if (add_block(m, &cap, Fv + bk->qadr, bk->nq, Yq + b2->qadr, b2->nq, 0)) return -1;
        /* d(Phi_q^T mu)/dq */
        if (ji->nrows > 0 && add_block(m, &cap, Fq + bk->qadr, bk->nq, Yq + b2->qadr, b2->nq, 0)) return -1;
        if (ji->type->force && add_block(m, &cap, Fv + bk->qadr, bk->nq, Yv + b2->qadr, b2->nq, 0)) return -1;
      }
      if (ji->nrows == 0) continue;
      if (add_block(m, &cap, Fl + ji->rowadr, ji->nrows, Yq + bk->qadr, bk->nq, 0) ||  /* Phi_q */
          add_block(m, &cap, Fm + ji->rowadr, ji->nrows, Yq + bk->qadr, bk->nq, 0) ||  /* d(Phi_q v)/dq */
          add_block(m, &cap, Fm + ji->rowadr, ji->nrows, Yv + bk->qadr, bk->nq, 0) ||  /* Phi_q */
          add_block(m, &cap, Fv + bk->qadr, bk->nq, Yl + ji->rowadr, ji->nrows, 0) ||  /* Phi_q^T */
          add_block(m, &cap, Fq + bk->qadr, bk->nq, Ym + ji->rowadr, ji->nrows, 0))    /* -Phi_q^T */
        return -1;
    }
  }

  /* columns: gather the row runs of every block covering the column, sort, merge */
  const int ny = m->ny;
  Run* runs = malloc((size_t)(m->nblock + 1) * sizeof *runs);
  m->colptr = calloc((size_t)ny + 1, sizeof *m->colptr);
  if (!runs || !m->colptr) {
    free(runs);
    return -1;
  }
  for (int pass = 0; pass < 2; ++pass) {
    long nnz = 0;
    for (int c = 0; c < ny; ++c) {
      int nr = 0;
      for (int i = 0; i < m->nblock; ++i) {
        const fmbBlock* bl = &m->block[i];
        if (c < bl->c0 || c >= bl->c0 + bl->nc) continue;
        runs[nr++] = bl->diag ? (Run){bl->r0 + (c - bl->c0), 1} : (Run){bl->r0, bl->nr};
      }
      qsort(runs, (size_t)nr, sizeof *runs, cmp_run);
      m->colptr[c] = nnz;
      int last = -1; /* last row already emitted */
      for (int i = 0; i < nr; ++i) {
        int s = runs[i].start, e = runs[i].start + runs[i].len;
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
        free(runs);
        return -1;
      }
    }
  }
  free(runs);
  return 0;
}

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

void fmb_csc_add(const fmbModel* m, double* data, int r, int c, double v) {
  long k = find_entry(m, r, c);
  if (k >= 0) data[k] += v;
}

void fmb_csc_add_block(const fmbModel* m, double* data, int r0, int nr, int c0, int nc, const double* vals, int ld,
                       double scale) {
  for (int j = 0; j < nc; ++j) {
    long k = find_entry(m, r0, c0 + j);
    if (k < 0) continue; /* not in the pattern: a programming error caught by the FD tests */
    const double* col = vals + (size_t)j * (size_t)ld;
    for (int i = 0; i < nr; ++i) data[k + i] += scale * col[i];
  }
}
