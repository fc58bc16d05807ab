/* schur.c — the Newton systems of the GGL DAE solved with the position rows eliminated, KLU on
 * the rest: IDA's default linear solver (solver.linear_solver: klu) and radau5's two systems.
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
 * The same holds for any cj, real or complex: radau5 (integrator_radau.c) solves with
 * J_y + (gamma/h) J_y' and with the complex J_y + ((alpha + i beta)/h) J_y' (Hairer & Wanner
 * IV.8 (8.16)-(8.17)), whose q-blocks are (gamma/h) I and ((alpha + i beta)/h) I minus the same
 * O(|mu|) term. So the elimination is written once for a scalar type (schur_kernels.h) and
 * compiled for double and double complex; the pattern of S and the block indices depend on the
 * model's pattern only: built here once, and shared by the systems made from the first
 * (fmb_schur_new_like: radau's real and complex ones).
 *
 * S's pattern and KLU's symbolic analysis are made once, at fmb_schur_new; the numeric
 * factorization follows the one KLU policy (klu.c: a new pivot order only when the condition
 * estimate degrades), as SUNDIALS' own KLU module does. Factor and solve allocate nothing but
 * that new pivot order. */
#include <complex.h>
#include <math.h>
#include <stdlib.h>
#include <string.h>
#include <sundials/sundials_linearsolver.h>
#include <sunmatrix/sunmatrix_sparse.h>

#include "internal.h"
#include "klu_policy.h"
#include "schur.h"

struct fmbSchur {
  const fmbModel* m;
  int nq, nr;                        /* eliminated rows, rows kept */
  int nc;                            /* doubles per value: 1 real, 2 complex (interleaved, as KLU's klu_zl_*) */
  long* first_kept;                  /* per column of J: position of its first row >= nq (rows are sorted) */
  long* diag_pos;                    /* per q column: position of J's (i, i) */
  SuiteSparse_long *colptr, *rowind; /* S, CSC */
  /* the blocks the solves need, copied at factorization with D^-1 applied and kept-row indices
     made relative (a tight loop: the solves run once per Newton iteration, factorizations rarely) */
  int *rq_ptr, *rq_run_ptr, *run_row, *run_len; /* J_Rq by q column, in runs of consecutive */
  int *qr_ptr, *qr_row;                         /* rows (the inner loop vectorizes); D^-1 J_qR by kept column */
  /* J_Rq = dF_R/dq is real for every cj, complex included: F_R holds no q' (the only q' is in
     F_q), so J_Rq has no cj J_y' part. It is kept real (one double per value) and D^-1 is applied
     to the complex b_q or coefficient instead: a real times a complex is half a complex product.
     The real system keeps J_Rq D^-1 (schur_kernels.h) */
  double* rq_val;
  /* values, nc doubles each */
  double* dinv;   /* 1 / J_ii of the last factorization */
  double* data;   /* S */
  double* qr_val; /* D^-1 J_qR's nonzeros only, by kept column (qz_ptr, qz_row: made at each
                     factorization, since which entries are zero depends on the values) */
  int *qz_ptr, *qz_row;
  double* acc; /* dense column / vector scratch, nr, kept zero between uses */
  double* dq;
  fmbKlu* klu; /* S's LU (klu.c), complex when nc == 2 */
  /* small, dense S (schur_use_dense): a dense LU instead of KLU; lu is S column-major (nr x nr,
     nc doubles each), NULL when KLU is used */
  double* lu;
  int* ipiv;
  int factored; /* lu holds a factorization */
  /* fault injection for tests: FMB_TEST_FAIL_REDUCED_SETUP=N (read once, in fmb_schur_new) makes
     the N-th and later factorizations fail as unrecoverable: how the tests reach the backends'
     fallback to klu_full (integrator_ida.c, integrator_radau.c), which no shipped scene needs */
  long factorizations, fail_from;
  /* the index arrays above (first_kept to qr_row) depend on the model's pattern only: made once
     and shared by every fmbSchur made from the first one (fmb_schur_new_like), freed by the last */
  int* pattern_refs;
};

/* Where the factorization reads J (schur_kernels.h's jval): J itself, interleaved (re, im) when
   complex, or, when J is NULL, the pencil J_y + (a + i b) J_y' entry by entry (b = 0 for the
   real one) with the operations radau's iteration matrices were formed with, so that the values
   are the same bit for bit and radau stores no matrix the factorization reads once */
typedef struct {
  const double *J, *jy, *jyp;
  double a, b;
} SchurSource;

/* the solves and the dense LU (schur_kernels.h) as AVX2 clones too (internal.h) */
#define SCHUR_WIDE FMB_VECTOR_CLONES

#define SCHUR_CAT_(a, b) a##b
#define SCHUR_CAT(a, b) SCHUR_CAT_(a, b)

#define SCHUR_T double
#define SCHUR_FINITE(x) isfinite(x)
#define SCHUR_FN(name) SCHUR_CAT(name, _real)
#define SCHUR_ABS1(x) fabs(x)
#define SCHUR_IS_COMPLEX 0
#include "schur_kernels.h"

#define SCHUR_T double complex
#define SCHUR_FINITE(x) (isfinite(creal(x)) && isfinite(cimag(x)))
#define SCHUR_FN(name) SCHUR_CAT(name, _complex)
#define SCHUR_ABS1(x) (fabs(creal(x)) + fabs(cimag(x)))
#define SCHUR_IS_COMPLEX 1
#include "schur_kernels.h"

static int schur_factor_from(fmbSchur* s, const SchurSource* src) {
  if (s->fail_from && ++s->factorizations >= s->fail_from) return -1;
  return s->nc == 2 ? schur_factor_complex(s, src) : schur_factor_real(s, src);
}

int fmb_schur_factor(fmbSchur* s, const double* J) {
  const SchurSource src = {.J = J};
  return schur_factor_from(s, &src);
}

int fmb_schur_factor_pencil(fmbSchur* s, const double* jy, const double* jyp, double a, double b) {
  const SchurSource src = {.jy = jy, .jyp = jyp, .a = a, .b = s->nc == 2 ? b : 0.0};
  return schur_factor_from(s, &src);
}

int fmb_schur_solve(fmbSchur* s, double* x) { return s->nc == 2 ? schur_solve_complex(s, x) : schur_solve_real(s, x); }

void fmb_schur_forget(fmbSchur* s) {
  s->factored = 0;
  fmb_klu_forget(s->klu);
}

void fmb_schur_free(fmbSchur* s) {
  if (!s) return;
  fmb_schur_forget(s);
  fmb_klu_free(s->klu); /* before the pattern it points into */
  if (!s->pattern_refs || --*s->pattern_refs <= 0) {
    free(s->pattern_refs);
    free(s->first_kept);
    free(s->diag_pos);
    free(s->colptr);
    free(s->rowind);
    free(s->rq_ptr);
    free(s->rq_run_ptr);
    free(s->run_row);
    free(s->run_len);
    free(s->qr_ptr);
    free(s->qr_row);
  }
  free(s->dinv);
  free(s->data);
  free(s->rq_val);
  free(s->qr_val);
  free(s->qz_ptr);
  free(s->qz_row);
  free(s->acc);
  free(s->dq);
  free(s->lu);
  free(s->ipiv);
  free(s);
}

static int schur_use_dense(const fmbSchur* s);

/* S's column c: the kept rows of J's column nq + c and, for each eliminated row i in it, the kept
   rows of J's column i, each row once (mark[r] == c once seen): counted per row (row_count), or
   c appended to each row's list (row_col at row_ptr[r], advanced). Returns how many. */
static long schur_column(const fmbSchur* s, int c, int* mark, long* row_count, SuiteSparse_long* row_ptr,
                         int* row_col) {
  const fmbModel* m = s->m;
  const int nq = s->nq, jc = nq + c;
  long n = 0;
  for (long k = m->colptr[jc]; k < m->colptr[jc + 1]; ++k) {
    const long i = m->rowind[k];
    const long from = i >= nq ? k : s->first_kept[i], to = i >= nq ? k + 1 : m->colptr[i + 1];
    for (long kk = from; kk < to; ++kk) {
      const long r = m->rowind[kk] - nq;
      if (mark[r] == c) continue;
      mark[r] = c;
      ++n;
      if (row_count) row_count[r]++;
      if (row_col) row_col[row_ptr[r]++] = c;
    }
  }
  return n;
}

/* S's pattern, built once per model (fmb_schur_new_like shares it). colptr from a counting pass
   (its count decides a dense S: schur_use_dense); where KLU factorizes S, rowind with each
   column's rows ascending, as KLU's analysis was made with: the pattern by rows first (a second
   pass, columns visited in ascending order, so each row's columns come out ascending), then back
   to columns by visiting the rows in ascending order (a counting sort both ways: O(nnz), where a
   sort per column took 3.2 M instructions for the three systems of the w15 spin-up's radau9).
   A dense S needs neither rowind nor KLU's values (schur_kernels.h writes it into lu). 0, or -1
   when out of memory. */
static int schur_pattern(fmbSchur* s) {
  const int nr = s->nr;
  s->colptr = malloc(sizeof(SuiteSparse_long) * (size_t)(nr + 1));
  int* mark = malloc(sizeof(int) * (size_t)(nr + 1));
  long* row_count = calloc((size_t)nr + 1, sizeof(long));
  int rc = -1;
  if (!s->colptr || !mark || !row_count) goto done;
  SuiteSparse_long nnz = 0;
  for (int r = 0; r < nr; ++r) mark[r] = -1;
  for (int c = 0; c < nr; ++c) {
    s->colptr[c] = nnz;
    nnz += schur_column(s, c, mark, row_count, NULL, NULL);
  }
  s->colptr[nr] = nnz;
  rc = 0;
  if (schur_use_dense(s)) goto done;
  rc = -1;
  SuiteSparse_long* row_end = malloc(sizeof(SuiteSparse_long) * (size_t)(nr + 1));
  SuiteSparse_long* col_next = malloc(sizeof(SuiteSparse_long) * (size_t)(nr + 1));
  int* row_col = malloc(sizeof(int) * (size_t)(nnz + 1));
  s->rowind = malloc(sizeof(SuiteSparse_long) * (size_t)(nnz + 1));
  if (row_end && col_next && row_col && s->rowind) {
    SuiteSparse_long at = 0;
    for (int r = 0; r < nr; ++r) { /* row r's start, advanced to its end as its columns come */
      row_end[r] = at;
      at += row_count[r];
    }
    for (int r = 0; r < nr; ++r) mark[r] = -1;
    for (int c = 0; c < nr; ++c) schur_column(s, c, mark, NULL, row_end, row_col);
    for (int c = 0; c < nr; ++c) col_next[c] = s->colptr[c];
    for (int r = 0; r < nr; ++r)
      for (SuiteSparse_long k = row_end[r] - row_count[r]; k < row_end[r]; ++k) s->rowind[col_next[row_col[k]]++] = r;
    rc = 0;
  }
  free(row_end);
  free(col_next);
  free(row_col);
done:
  free(mark);
  free(row_count);
  return rc;
}

/* index arrays of the compact J_Rq and J_qR copies (shared like S's pattern); 0 or -1 when out of
   memory */
static int schur_blocks(fmbSchur* s) {
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
  s->rq_run_ptr = malloc(sizeof(int) * (size_t)(nq + 1));
  s->run_row = malloc(sizeof(int) * (size_t)(n + 1));
  s->run_len = malloc(sizeof(int) * (size_t)(n + 1));
  if (!s->rq_run_ptr || !s->run_row || !s->run_len) return -1;
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
  if (!s->qr_row) return -1;
  for (int c = 0; c < nr; ++c)
    for (long k = m->colptr[nq + c]; k < s->first_kept[nq + c]; ++k)
      s->qr_row[s->qr_ptr[c] + (k - m->colptr[nq + c])] = (int)m->rowind[k];
  return 0;
}

/* Dense LU (schur_kernels.h's dense_lu) or KLU for S. A beam's S is a dense core (its velocity
   block couples every element to all inboard ones): 57 x 57 with 3,231 nonzeros (99 %) for 16 elements.
   There KLU's left-looking sparse LU pays an indirect access per flop and a sparse triangular
   solve per column, while a dense LU runs the same flops as contiguous column updates that
   vectorize (instruction counts in docs/performance.md, "Integrators"; LAPACK's getrf/getrs on
   Debian's reference BLAS gained only 3 % over KLU, its zgemm/ztrsm being unvectorized Fortran
   loops, so the LU is written out). A dense LU costs nr^3/3 whatever the pattern, so it is
   used only where that is near KLU's own work: S small (nr <= 200, lu at most 640 kB complex)
   and at least 90 % full. Large or sparse S (banded beams, long chains, big mechanisms) keep
   KLU, and so do the rigid mechanisms (the slider-crank's S is 51 x 51, 71 % full): at 30 % the
   dense LU's fresh pivots changed where IDA gives up at singular passages (test_parallelogram,
   failure_singular_fourbar), whose tests pin KLU's behaviour. The scene's solver.schur_lu: klu or
   dense overrides the rule (to compare the two). */
static int schur_use_dense(const fmbSchur* s) {
  if (s->m->solver.schur_lu == FMB_SCHUR_LU_KLU) return 0;
  if (s->m->solver.schur_lu == FMB_SCHUR_LU_DENSE) return 1;
  const double nr = s->nr;
  return s->nr > 0 && s->nr <= 200 && (double)s->colptr[s->nr] >= 0.9 * nr * nr;
}

/* the pattern's index arrays (first_kept to qr_row): made for s, or like's shared */
static int schur_index(fmbSchur* s, const fmbSchur* like) {
  if (like) {
    s->pattern_refs = like->pattern_refs;
    ++*s->pattern_refs;
    s->first_kept = like->first_kept;
    s->diag_pos = like->diag_pos;
    s->colptr = like->colptr;
    s->rowind = like->rowind;
    s->rq_ptr = like->rq_ptr;
    s->rq_run_ptr = like->rq_run_ptr;
    s->run_row = like->run_row;
    s->run_len = like->run_len;
    s->qr_ptr = like->qr_ptr;
    s->qr_row = like->qr_row;
    return 0;
  }
  const fmbModel* m = s->m;
  s->pattern_refs = malloc(sizeof(int));
  s->first_kept = malloc(sizeof(long) * (size_t)m->ny);
  s->diag_pos = malloc(sizeof(long) * (size_t)(m->nq + 1));
  if (!s->pattern_refs || !s->first_kept || !s->diag_pos) return -1;
  *s->pattern_refs = 1;
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
    if (s->diag_pos[c] < 0) return -1; /* pattern.c always holds F_q's diagonal */
  return schur_pattern(s) || schur_blocks(s) ? -1 : 0;
}

static fmbSchur* schur_new(const fmbModel* m, int complex_values, const fmbSchur* like) {
  fmbSchur* s = calloc(1, sizeof *s);
  if (!s) return NULL;
  s->m = m;
  s->nq = m->nq;
  s->nr = m->ny - m->nq;
  s->nc = complex_values ? 2 : 1;
  const size_t nc = (size_t)s->nc;
  s->fail_from = m->solver.fault_reduced_setup;
  if (schur_index(s, like)) goto fail;
  s->dinv = calloc(nc * ((size_t)m->nq + 1), sizeof(double));
  s->acc = calloc(nc * ((size_t)s->nr + 1), sizeof(double));
  s->dq = calloc(nc * ((size_t)m->nq + 1), sizeof(double));
  s->rq_val = malloc(sizeof(double) * (size_t)(s->rq_ptr[s->nq] + 1)); /* real, see fmbSchur */
  s->qr_val = malloc(sizeof(double) * nc * (size_t)(s->qr_ptr[s->nr] + 1));
  s->qz_ptr = malloc(sizeof(int) * ((size_t)s->nr + 1));
  s->qz_row = malloc(sizeof(int) * (size_t)(s->qr_ptr[s->nr] + 1));
  if (!s->dinv || !s->acc || !s->dq || !s->rq_val || !s->qr_val || !s->qz_ptr || !s->qz_row) goto fail;
  if (schur_use_dense(s)) { /* S lives in lu: no KLU, no values on S's pattern (nor rowind) */
    s->lu = malloc(sizeof(double) * nc * (size_t)s->nr * (size_t)s->nr + sizeof(double));
    s->ipiv = malloc(sizeof(int) * ((size_t)s->nr + 1));
    if (!s->lu || !s->ipiv) goto fail;
    return s;
  }
  s->data = calloc(nc * ((size_t)s->colptr[s->nr] + 1), sizeof(double));
  if (!s->data) goto fail;
  s->klu = fmb_klu_new(s->nr, s->colptr, s->rowind, nc == 2 ? FMB_KLU_COMPLEX : 0);
  if (!s->klu) goto fail;
  return s;
fail:
  fmb_schur_free(s);
  return NULL;
}

fmbSchur* fmb_schur_new(const fmbModel* m, int complex_values) { return schur_new(m, complex_values, NULL); }

fmbSchur* fmb_schur_new_like(const fmbSchur* like, int complex_values) {
  return like ? schur_new(like->m, complex_values, like) : NULL;
}

/* ---- IDA's linear solver: the real fmbSchur as a SUNLinearSolver ---- */

typedef struct {
  fmbSchur* s;
  long last_flag;
} SchurLS;

#define SCHUR_LS(S) ((SchurLS*)(S)->content)

static SUNLinearSolver_Type schur_type(SUNLinearSolver S) {
  (void)S;
  return SUNLINEARSOLVER_DIRECT;
}

static SUNLinearSolver_ID schur_id(SUNLinearSolver S) {
  (void)S;
  return SUNLINEARSOLVER_CUSTOM;
}

static int schur_initialize(SUNLinearSolver S) {
  SchurLS* ls = SCHUR_LS(S);
  fmb_schur_forget(ls->s);
  ls->last_flag = SUNLS_SUCCESS;
  return SUNLS_SUCCESS;
}

static int schur_setup(SUNLinearSolver S, SUNMatrix A) {
  SchurLS* ls = SCHUR_LS(S);
  const int rc = fmb_schur_factor(ls->s, SUNSparseMatrix_Data(A));
  return ls->last_flag = rc == 0 ? SUNLS_SUCCESS : rc > 0 ? SUNLS_PACKAGE_FAIL_REC : SUNLS_PACKAGE_FAIL_UNREC;
}

static int schur_solve(SUNLinearSolver S, SUNMatrix A, N_Vector x, N_Vector b, sunrealtype tol) {
  (void)tol;
  (void)A; /* its blocks were copied at setup */
  SchurLS* ls = SCHUR_LS(S);
  double* xv = N_VGetArrayPointer(x);
  const double* bv = N_VGetArrayPointer(b);
  if (xv != bv) memcpy(xv, bv, sizeof(double) * (size_t)ls->s->m->ny);
  return ls->last_flag = fmb_schur_solve(ls->s, xv) ? SUNLS_PACKAGE_FAIL_REC : SUNLS_SUCCESS;
}

static sunindextype schur_last_flag(SUNLinearSolver S) { return SCHUR_LS(S)->last_flag; }

static int schur_free(SUNLinearSolver S) {
  if (!S) return SUNLS_SUCCESS;
  SchurLS* ls = S->content;
  if (ls) fmb_schur_free(ls->s);
  free(ls);
  S->content = NULL;
  SUNLinSolFreeEmpty(S);
  return SUNLS_SUCCESS;
}

SUNLinearSolver fmb_schur_klu_new(const fmbModel* m, SUNContext sun) {
  SUNLinearSolver S = SUNLinSolNewEmpty(sun);
  SchurLS* ls = calloc(1, sizeof *ls);
  if (!S || !ls || !(ls->s = fmb_schur_new(m, 0))) {
    free(ls);
    if (S) SUNLinSolFreeEmpty(S);
    return NULL;
  }
  S->content = ls;
  S->ops->gettype = schur_type;
  S->ops->getid = schur_id;
  S->ops->initialize = schur_initialize;
  S->ops->setup = schur_setup;
  S->ops->solve = schur_solve;
  S->ops->lastflag = schur_last_flag;
  S->ops->free = schur_free;
  return S;
}
