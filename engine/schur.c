/* schur.c — the Newton systems of the GGL DAE solved with the position rows eliminated, KLU on
 * the rest (solver.linear_solver: klu, the default).
 *
 * With y = [q, v, lambda, mu] (system.c) the iteration matrix J = dF/dy + cj dF/dy' has position
 * rows F_q = q' - v - Phi_q^T mu whose q-block is cj I - d(Phi_q^T mu)/dq. mu vanishes on the exact
 * solution (it only absorbs the drift, GGL), so that block is its diagonal D up to O(|mu|), and
 * the position unknowns follow from the rest in closed form:
 *
 *   J_qq dq + J_qR dR = b_q    ->   dq = D^-1 (b_q - J_qR dR),       R = [v, lambda, mu]
 *   (J_RR - J_Rq D^-1 J_qR) dR = b_R - J_Rq D^-1 b_q                 (the Schur complement S)
 *
 * S has nq fewer rows than J (half of the differential unknowns). On a beam its velocity block
 * K/cj + C + cj M is as dense as J's, so KLU's triangular solves, the largest single cost of a
 * run, shrink about fourfold (docs/performance.md). Dropping the O(|mu|) off-diagonal part of J_qq
 * makes this a modified Newton iteration whose rate changes by O(|mu| / cj): nothing measurable.
 *
 * S's pattern and KLU's symbolic analysis are made once, at setup; the numeric factorization is
 * refreshed with klu_l_refactor (a new pivot order only when the condition estimate degrades),
 * as SUNDIALS' own KLU module does. Setup and solve allocate nothing. */
#include <math.h>
#include <stdlib.h>
#include <string.h>
#include <klu.h>
#include <sundials/sundials_linearsolver.h>
#include <sunmatrix/sunmatrix_sparse.h>

#include "internal.h"

typedef struct {
  const fmbModel* m;
  int nq, nr;          /* eliminated rows, rows kept */
  long* first_kept;    /* per column of J: position of its first row >= nq (rows are sorted) */
  long* diag_pos;      /* per q column: position of J's (i, i) */
  double* dinv;        /* 1 / J_ii of the last setup */
  SuiteSparse_long *colptr, *rowind; /* S, CSC */
  double* data;
  /* the blocks the solves need, copied at setup with D^-1 applied and kept-row indices made
     relative (a tight loop: the solves run once per Newton iteration, setups rarely) */
  int *rq_ptr, *rq_run_ptr, *run_row, *run_len; /* J_Rq D^-1 by q column, in runs of consecutive */
  double* rq_val;                                 /* rows (the inner loop vectorizes) */
  int *qr_ptr, *qr_row;                           /* D^-1 J_qR by kept column */
  double* qr_val;
  double* acc;         /* dense column / vector scratch, nr */
  double* dq;
  klu_l_common common;
  klu_l_symbolic* symbolic;
  klu_l_numeric* numeric;
  long last_flag;
  long setups, fail_from; /* fault injection for tests: setups from fail_from on fail (0: never) */
} Schur;

#define SCHUR(S) ((Schur*)(S)->content)

static SUNLinearSolver_Type schur_type(SUNLinearSolver S) {
  (void)S;
  return SUNLINEARSOLVER_DIRECT;
}

static SUNLinearSolver_ID schur_id(SUNLinearSolver S) {
  (void)S;
  return SUNLINEARSOLVER_CUSTOM;
}

static int schur_initialize(SUNLinearSolver S) {
  Schur* s = SCHUR(S);
  if (s->numeric) klu_l_free_numeric(&s->numeric, &s->common);
  s->last_flag = SUNLS_SUCCESS;
  return SUNLS_SUCCESS;
}

/* S = J_RR - J_Rq D^-1 J_qR, column by column through a dense scratch column */
static int schur_setup(SUNLinearSolver S, SUNMatrix A) {
  Schur* s = SCHUR(S);
  if (s->fail_from && ++s->setups >= s->fail_from) return s->last_flag = SUNLS_PACKAGE_FAIL_UNREC;
  const fmbModel* m = s->m;
  const int nq = s->nq;
  const double* J = SUNSparseMatrix_Data(A);
  for (int i = 0; i < nq; ++i) {
    const double d = J[s->diag_pos[i]];
    if (d == 0.0 || !isfinite(d)) return s->last_flag = SUNLS_PACKAGE_FAIL_REC;
    s->dinv[i] = 1.0 / d;
  }
  for (int i = 0; i < nq; ++i) {
    double* val = s->rq_val + s->rq_ptr[i];
    for (long k = s->first_kept[i]; k < m->colptr[i + 1]; ++k) *val++ = J[k] * s->dinv[i];
  }
  for (int c = 0; c < s->nr; ++c) {
    double* val = s->qr_val + s->qr_ptr[c];
    for (long k = m->colptr[nq + c]; k < s->first_kept[nq + c]; ++k) *val++ = J[k] * s->dinv[m->rowind[k]];
  }
  for (int c = 0; c < s->nr; ++c) {
    const int jc = nq + c;
    for (long k = m->colptr[jc]; k < m->colptr[jc + 1]; ++k) {
      const long i = m->rowind[k];
      if (i >= nq) {
        s->acc[i - nq] += J[k];
        continue;
      }
      const double coef = J[k] * s->dinv[i]; /* (D^-1 J_qR)_ic */
      for (long kk = s->first_kept[i]; kk < m->colptr[i + 1]; ++kk) s->acc[m->rowind[kk] - nq] -= J[kk] * coef;
    }
    for (SuiteSparse_long k = s->colptr[c]; k < s->colptr[c + 1]; ++k) {
      s->data[k] = s->acc[s->rowind[k]];
      s->acc[s->rowind[k]] = 0.0;
    }
  }
  if (!s->numeric) {
    s->numeric = klu_l_factor(s->colptr, s->rowind, s->data, s->symbolic, &s->common);
    return s->last_flag = s->numeric ? SUNLS_SUCCESS : SUNLS_PACKAGE_FAIL_UNREC;
  }
  if (!klu_l_refactor(s->colptr, s->rowind, s->data, s->symbolic, s->numeric, &s->common) ||
      !klu_l_rcond(s->symbolic, s->numeric, &s->common))
    return s->last_flag = SUNLS_PACKAGE_FAIL_REC;
  /* the pivot order of the first factorization may no longer suit: refactor from scratch when a
     cheap estimate, then the accurate one, say the condition has degraded (as SUNDIALS' KLU) */
  const double tiny = pow(2.220446049250313e-16, 2.0 / 3.0);
  if (s->common.rcond < tiny) {
    if (!klu_l_condest(s->colptr, s->data, s->symbolic, s->numeric, &s->common))
      return s->last_flag = SUNLS_PACKAGE_FAIL_REC;
    if (s->common.condest > 1.0 / tiny) {
      klu_l_free_numeric(&s->numeric, &s->common);
      s->numeric = klu_l_factor(s->colptr, s->rowind, s->data, s->symbolic, &s->common);
      if (!s->numeric) return s->last_flag = SUNLS_PACKAGE_FAIL_UNREC;
    }
  }
  return s->last_flag = SUNLS_SUCCESS;
}

static int schur_solve(SUNLinearSolver S, SUNMatrix A, N_Vector x, N_Vector b, sunrealtype tol) {
  (void)tol;
  Schur* s = SCHUR(S);
  (void)A; /* its blocks were copied at setup */
  const int nq = s->nq, nr = s->nr;
  const double* bv = N_VGetArrayPointer(b);
  double* xv = N_VGetArrayPointer(x);
  double* rhs = s->acc;
  /* b_R - J_Rq D^-1 b_q */
  memcpy(rhs, bv + nq, sizeof(double) * (size_t)nr);
  for (int i = 0; i < nq; ++i) {
    const double bi = bv[i];
    s->dq[i] = bi * s->dinv[i];
    const double* val = s->rq_val + s->rq_ptr[i];
    for (int r = s->rq_run_ptr[i]; r < s->rq_run_ptr[i + 1]; ++r) {
      double* restrict dst = rhs + s->run_row[r];
      const int len = s->run_len[r];
      for (int j = 0; j < len; ++j) dst[j] -= val[j] * bi;
      val += len;
    }
  }
  if (!klu_l_solve(s->symbolic, s->numeric, nr, 1, rhs, &s->common)) {
    memset(rhs, 0, sizeof(double) * (size_t)nr);
    return s->last_flag = SUNLS_PACKAGE_FAIL_REC;
  }
  /* dq = D^-1 (b_q - J_qR dR) */
  const int *qr_ptr = s->qr_ptr, *qr_row = s->qr_row;
  const double* qr_val = s->qr_val;
  for (int c = 0; c < nr; ++c) {
    const double dr = rhs[c];
    for (int k = qr_ptr[c]; k < qr_ptr[c + 1]; ++k) s->dq[qr_row[k]] -= qr_val[k] * dr;
    xv[nq + c] = dr;
  }
  memcpy(xv, s->dq, sizeof(double) * (size_t)nq);
  memset(rhs, 0, sizeof(double) * (size_t)nr); /* the scratch column is kept zero between uses */
  return s->last_flag = SUNLS_SUCCESS;
}

static sunindextype schur_last_flag(SUNLinearSolver S) { return SCHUR(S)->last_flag; }

static void schur_content_free(Schur* s) {
  if (!s) return;
  if (s->numeric) klu_l_free_numeric(&s->numeric, &s->common);
  if (s->symbolic) klu_l_free_symbolic(&s->symbolic, &s->common);
  free(s->first_kept);
  free(s->diag_pos);
  free(s->dinv);
  free(s->colptr);
  free(s->rowind);
  free(s->data);
  free(s->rq_ptr);
  free(s->rq_run_ptr);
  free(s->run_row);
  free(s->run_len);
  free(s->rq_val);
  free(s->qr_ptr);
  free(s->qr_row);
  free(s->qr_val);
  free(s->acc);
  free(s->dq);
  free(s);
}

static int schur_free(SUNLinearSolver S) {
  if (!S) return SUNLS_SUCCESS;
  schur_content_free(S->content);
  S->content = NULL;
  SUNLinSolFreeEmpty(S);
  return SUNLS_SUCCESS;
}

static int cmp_sslong(const void* a, const void* b) {
  SuiteSparse_long x = *(const SuiteSparse_long*)a, y = *(const SuiteSparse_long*)b;
  return (x > y) - (x < y);
}

/* S's pattern: the kept rows of J's column, and for each eliminated row i in it, the kept rows
   of J's column i. Returns 0, or -1 when out of memory. */
static int schur_pattern(Schur* s) {
  const fmbModel* m = s->m;
  const int nq = s->nq, nr = s->nr;
  s->colptr = malloc(sizeof(SuiteSparse_long) * (size_t)(nr + 1));
  int* mark = malloc(sizeof(int) * (size_t)nr);
  SuiteSparse_long* list = malloc(sizeof(SuiteSparse_long) * (size_t)(nr + 1)); /* rows of one column */
  if (!s->colptr || !mark || !list) {
    free(mark);
    free(list);
    return -1;
  }
  for (int pass = 0; pass < 2; ++pass) {
    SuiteSparse_long nnz = 0;
    for (int r = 0; r < nr; ++r) mark[r] = -1;
    for (int c = 0; c < nr; ++c) {
      const int jc = nq + c;
      s->colptr[c] = nnz;
      long nl = 0; /* the column's rows, collected and sorted: O(nnz log) rather than O(nr) per column */
      for (long k = m->colptr[jc]; k < m->colptr[jc + 1]; ++k) {
        const long i = m->rowind[k];
        if (i >= nq) {
          if (mark[i - nq] != c) list[nl++] = i - nq;
          mark[i - nq] = c;
        } else {
          for (long kk = s->first_kept[i]; kk < m->colptr[i + 1]; ++kk) {
            const long r = m->rowind[kk] - nq;
            if (mark[r] != c) list[nl++] = r;
            mark[r] = c;
          }
        }
      }
      qsort(list, (size_t)nl, sizeof *list, cmp_sslong);
      for (long k = 0; k < nl; ++k) {
        if (pass) s->rowind[nnz] = list[k];
        ++nnz;
      }
    }
    s->colptr[nr] = nnz;
    if (!pass) {
      s->rowind = malloc(sizeof(SuiteSparse_long) * (size_t)(nnz + 1));
      s->data = calloc((size_t)nnz + 1, sizeof(double));
      if (!s->rowind || !s->data) {
        free(mark);
        free(list);
        return -1;
      }
    }
  }
  free(mark);
  free(list);
  return 0;
}

/* index arrays of the compact J_Rq and J_qR copies; 0 or -1 when out of memory */
static int schur_blocks(Schur* s) {
  const fmbModel* m = s->m;
  const int nq = s->nq, nr = s->nr;
  s->rq_ptr = malloc(sizeof(int) * (size_t)(nq + 1));
  s->qr_ptr = malloc(sizeof(int) * (size_t)(nr + 1));
  if (!s->rq_ptr || !s->qr_ptr) return -1;
  long n = 0;
  for (int i = 0; i < nq; ++i) {
    s->rq_ptr[i] = (int)n;
    n += m->colptr[i + 1] - s->first_kept[i];
  }
  s->rq_ptr[nq] = (int)n;
  s->rq_val = malloc(sizeof(double) * (size_t)(n + 1));
  s->rq_run_ptr = malloc(sizeof(int) * (size_t)(nq + 1));
  s->run_row = malloc(sizeof(int) * (size_t)(n + 1));
  s->run_len = malloc(sizeof(int) * (size_t)(n + 1));
  if (!s->rq_val || !s->rq_run_ptr || !s->run_row || !s->run_len) return -1;
  int nrun = 0;
  for (int i = 0; i < nq; ++i) {
    s->rq_run_ptr[i] = nrun;
    for (long k = s->first_kept[i]; k < m->colptr[i + 1]; ++k) {
      const int row = (int)(m->rowind[k] - nq);
      if (k > s->first_kept[i] && row == s->run_row[nrun - 1] + s->run_len[nrun - 1]) {
        s->run_len[nrun - 1]++;
      } else {
        s->run_row[nrun] = row;
        s->run_len[nrun++] = 1;
      }
    }
  }
  s->rq_run_ptr[nq] = nrun;
  n = 0;
  for (int c = 0; c < nr; ++c) {
    s->qr_ptr[c] = (int)n;
    n += s->first_kept[nq + c] - m->colptr[nq + c];
  }
  s->qr_ptr[nr] = (int)n;
  s->qr_row = malloc(sizeof(int) * (size_t)(n + 1));
  s->qr_val = malloc(sizeof(double) * (size_t)(n + 1));
  if (!s->qr_row || !s->qr_val) return -1;
  for (int c = 0; c < nr; ++c)
    for (long k = m->colptr[nq + c]; k < s->first_kept[nq + c]; ++k) s->qr_row[s->qr_ptr[c] + (k - m->colptr[nq + c])] = (int)m->rowind[k];
  return 0;
}

SUNLinearSolver fmb_schur_klu_new(const fmbModel* m, SUNContext sun) {
  SUNLinearSolver S = SUNLinSolNewEmpty(sun);
  Schur* s = calloc(1, sizeof *s);
  if (!S || !s) goto fail;
  s->m = m;
  s->nq = m->nq;
  /* FMB_TEST_FAIL_REDUCED_SETUP=N makes the N-th and later setups fail: how the tests reach the
     fallback to klu_full (integrator_ida.c), which no shipped scene needs */
  const char* fault = getenv("FMB_TEST_FAIL_REDUCED_SETUP");
  s->fail_from = fault ? strtol(fault, NULL, 10) : 0;
  s->nr = m->ny - m->nq;
  s->first_kept = malloc(sizeof(long) * (size_t)m->ny);
  s->diag_pos = malloc(sizeof(long) * (size_t)(m->nq + 1));
  s->dinv = calloc((size_t)m->nq + 1, sizeof(double));
  s->acc = calloc((size_t)s->nr + 1, sizeof(double));
  s->dq = calloc((size_t)m->nq + 1, sizeof(double));
  if (!s->first_kept || !s->diag_pos || !s->dinv || !s->acc || !s->dq) goto fail;
  for (int c = 0; c < m->nq; ++c) s->diag_pos[c] = -1;
  for (int c = 0; c < m->ny; ++c) {
    long k = m->colptr[c];
    while (k < m->colptr[c + 1] && m->rowind[k] < m->nq) {
      if (m->rowind[k] == c) s->diag_pos[c] = k;
      ++k;
    }
    s->first_kept[c] = k;
  }
  for (int c = 0; c < m->nq; ++c)
    if (s->diag_pos[c] < 0) goto fail; /* pattern.c always holds F_q's diagonal */
  if (schur_pattern(s) || schur_blocks(s)) goto fail;
  klu_l_defaults(&s->common);
  s->symbolic = klu_l_analyze(s->nr, s->colptr, s->rowind, &s->common);
  if (!s->symbolic) goto fail;
  S->content = s;
  S->ops->gettype = schur_type;
  S->ops->getid = schur_id;
  S->ops->initialize = schur_initialize;
  S->ops->setup = schur_setup;
  S->ops->solve = schur_solve;
  S->ops->lastflag = schur_last_flag;
  S->ops->free = schur_free;
  return S;
fail:
  schur_content_free(s);
  if (S) SUNLinSolFreeEmpty(S);
  return NULL;
}
