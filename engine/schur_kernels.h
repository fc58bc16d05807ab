/* schur_kernels.h — the numeric half of schur.c for one scalar type. schur.c includes it twice:
 * with SCHUR_T = double (IDA's iteration matrix, radau5's real system) and SCHUR_T = double
 * complex (radau5's complex system, Hairer & Wanner IV.8 (8.17)), so the elimination is written
 * once. Complex values are interleaved (re, im) pairs, which is both C11's layout of double
 * complex (6.2.5) and what KLU's klu_zl_* routines take. Not a header for anyone else.
 *
 * Expects: SCHUR_T, SCHUR_FINITE(x), SCHUR_FN(name) (the name with the type's suffix),
 * SCHUR_ABS1(x) (|x|, |re| + |im| if complex) and
 * SCHUR_IS_COMPLEX (0 or 1); undefines them at its end. Uses schur.c's SchurSource. */

/* entry k of J from its source (SchurSource, schur.c) */
static inline SCHUR_T SCHUR_FN(jval)(const SchurSource* src, long k) {
  if (src->J) return ((const SCHUR_T*)src->J)[k];
#if SCHUR_IS_COMPLEX
  /* set by parts, C11's layout of a complex (6.2.5): CMPLX is not defined by glibc's complex.h
     under clang, and re + im * I is not the same value when re is -0 */
  SCHUR_T z;
  double* part = (double*)&z;
  part[0] = src->jy[k] + src->a * src->jyp[k];
  part[1] = src->b * src->jyp[k];
  return z;
#else
  return src->jy[k] + src->a * src->jyp[k];
#endif
}

/* S = J_RR - J_Rq D^-1 J_qR, column by column (schur.c's head comment); also the compact J_Rq
   (complex: real, D^-1 applied in the solve; real: J_Rq D^-1) and D^-1 J_qR copies the solves use.
   Column c of S is accumulated in place: in S's dense storage when S is dense, else in the zeroed
   scratch column acc, gathered into KLU's values after. Per entry the operations of the
   column-wise product in their order: for each q row i of J's column (ascending) S_rc -= (J_Rq)_ri
   (D^-1 J_qR)_ic, with (D^-1 J_qR)_ic the nonzero just stored (the same product J_ic / J_ii), then
   S_rc += (J_RR)_rc. J_Rq's columns are runs of consecutive rows (schur_blocks), so the update is
   a contiguous axpy that vectorizes; a zero (D^-1 J_qR)_ic is skipped: the beam's mu columns hold
   all of its q rows in the pattern (Phi_q^T, a joint's block), a few of them nonzero. Skipping
   leaves every value as it was: the column starts at +0, and subtracting a zero product from a
   value that is +0 or nonzero changes nothing (-0 never arises: x - x is +0 when rounding to
   nearest). 0, or 1 when D has a zero or non-finite entry. */
SCHUR_WIDE static int SCHUR_FN(schur_form)(fmbSchur* s, const SchurSource* src) {
  const fmbModel* m = s->m;
  const int nq = s->nq, nr = s->nr;
  SCHUR_T* dinv = (SCHUR_T*)s->dinv;
  SCHUR_T* acc = (SCHUR_T*)s->acc;
  SCHUR_T* data = (SCHUR_T*)s->data;
  for (int i = 0; i < nq; ++i) {
    const SCHUR_T d = SCHUR_FN(jval)(src, s->diag_pos[i]);
    if (d == 0.0 || !SCHUR_FINITE(d)) return 1;
    dinv[i] = 1.0 / d;
  }
  for (int i = 0; i < nq; ++i) {
    double* val = s->rq_val + s->rq_ptr[i];
#if SCHUR_IS_COMPLEX /* J_Rq's real part: its imaginary part is zero (fmbSchur) */
    for (long k = s->first_kept[i]; k < m->colptr[i + 1]; ++k) *val++ = creal(SCHUR_FN(jval)(src, k));
#else /* J_Rq D^-1, the product IDA's runs were made with: singular passages (the parallelogram's
         flat points, tests/failures' singular four-bar) are sensitive to its last bit */
    for (long k = s->first_kept[i]; k < m->colptr[i + 1]; ++k) *val++ = SCHUR_FN(jval)(src, k) * dinv[i];
#endif
  }
  /* D^-1 J_qR's nonzeros (qz_ptr, qz_row): the beam's mu columns hold all of its q rows in the
     pattern (Phi_q^T, a joint's block), a few of them nonzero, and both the products below and
     the solve's back substitution skip the zeros */
  SCHUR_T* qz_val = (SCHUR_T*)s->qr_val;
  int nz = 0;
  for (int c = 0; c < nr; ++c) {
    s->qz_ptr[c] = nz;
    for (long k = m->colptr[nq + c]; k < s->first_kept[nq + c]; ++k) {
      const SCHUR_T coef = SCHUR_FN(jval)(src, k) * dinv[m->rowind[k]];
      if (coef == 0.0) continue;
      qz_val[nz] = coef;
      s->qz_row[nz++] = (int)m->rowind[k];
    }
  }
  s->qz_ptr[nr] = nz;
  for (int c = 0; c < nr; ++c) {
    const int jc = nq + c;
    SCHUR_T* restrict col = acc;
    if (s->lu) { /* dense: the whole column, zeros included */
      col = (SCHUR_T*)s->lu + (size_t)c * (size_t)nr;
      memset(col, 0, sizeof(SCHUR_T) * (size_t)nr);
    }
    for (int t = s->qz_ptr[c]; t < s->qz_ptr[c + 1]; ++t) {
      const SCHUR_T coef = qz_val[t]; /* (D^-1 J_qR)_ic, nonzero */
      const int i = s->qz_row[t];
#if SCHUR_IS_COMPLEX
      const double* restrict rq = s->rq_val + s->rq_ptr[i]; /* J_Rq's column i, real */
      for (int r = s->rq_run_ptr[i]; r < s->rq_run_ptr[i + 1]; ++r) {
        SCHUR_T* restrict dst = col + s->run_row[r];
        const int len = s->run_len[r];
        for (int j = 0; j < len; ++j) dst[j] -= rq[j] * coef;
        rq += len;
      }
#else /* J_Rq itself (rq_val holds J_Rq D^-1): J's, or the pencil's entries as jval makes them */
      const long k0 = s->first_kept[i];
      const double* restrict rq = src->J ? src->J + k0 : src->jy + k0;
      const double* restrict rqp = src->J ? NULL : src->jyp + k0;
      const double a = src->a;
      for (int r = s->rq_run_ptr[i]; r < s->rq_run_ptr[i + 1]; ++r) {
        SCHUR_T* restrict dst = col + s->run_row[r];
        const int len = s->run_len[r];
        if (!rqp)
          for (int j = 0; j < len; ++j) dst[j] -= rq[j] * coef;
        else {
          for (int j = 0; j < len; ++j) dst[j] -= (rq[j] + a * rqp[j]) * coef;
          rqp += len;
        }
        rq += len;
      }
#endif
    }
    for (long k = s->first_kept[jc]; k < m->colptr[jc + 1]; ++k) col[m->rowind[k] - nq] += SCHUR_FN(jval)(src, k);
    if (s->lu) continue;
    for (SuiteSparse_long k = s->colptr[c]; k < s->colptr[c + 1]; ++k) {
      data[k] = acc[s->rowind[k]];
      acc[s->rowind[k]] = 0.0;
    }
  }
  return 0;
}

/* x[lo..hi) -= c_m[i] u_m for the members m < cnt (<= 4) of a group, in the members' order: per
   value the subtractions of one axpy per member, in the same order; four members in one pass keep
   the value in a register between them (a load and a store per four products instead of per one) */
static inline void SCHUR_FN(group_update)(SCHUR_T* restrict x, int lo, int hi, int cnt, const SCHUR_T* restrict c0,
                                          SCHUR_T u0, const SCHUR_T* restrict c1, SCHUR_T u1,
                                          const SCHUR_T* restrict c2, SCHUR_T u2, const SCHUR_T* restrict c3,
                                          SCHUR_T u3) {
  if (cnt == 4) {
    for (int i = lo; i < hi; ++i) {
      SCHUR_T t = x[i];
      t -= c0[i] * u0;
      t -= c1[i] * u1;
      t -= c2[i] * u2;
      t -= c3[i] * u3;
      x[i] = t;
    }
    return;
  }
  if (cnt > 0)
    for (int i = lo; i < hi; ++i) x[i] -= c0[i] * u0;
  if (cnt > 1)
    for (int i = lo; i < hi; ++i) x[i] -= c1[i] * u1;
  if (cnt > 2)
    for (int i = lo; i < hi; ++i) x[i] -= c2[i] * u2;
}

/* x's rows swapped as the LU's first kend pivots swapped them, in their order */
static inline void SCHUR_FN(apply_swaps)(const int* ipiv, int kend, SCHUR_T* x) {
  for (int k = 0; k < kend; ++k)
    if (ipiv[k] != k) {
      const SCHUR_T t = x[k];
      x[k] = x[ipiv[k]];
      x[ipiv[k]] = t;
    }
}

/* x = L^-1 x by L's first kend columns (unit lower, column-major a, n x n): for k < kend in turn,
   u = x[k] and, unless u is zero, x[i] -= L_ik u below k. The nonzero u's are taken in groups of
   four (group_update): a row k inside a group gets the group's earlier members when it is reached
   (it needs them for its own u), the rows below the group all four together when it is full */
static inline void SCHUR_FN(lower_eliminate)(const SCHUR_T* a, int n, int kend, SCHUR_T* restrict x) {
  const SCHUR_T *c0 = a, *c1 = a, *c2 = a;
  SCHUR_T u0 = 0.0, u1 = 0.0, u2 = 0.0;
  int cnt = 0;
  for (int k = 0; k < kend; ++k) {
    SCHUR_T xk = x[k];
    if (cnt > 0) {
      xk -= c0[k] * u0;
      if (cnt > 1) {
        xk -= c1[k] * u1;
        if (cnt > 2) xk -= c2[k] * u2;
      }
      x[k] = xk;
    }
    if (xk == 0.0) continue; /* S's zeros outside the beam core stay zero */
    const SCHUR_T* ck = a + (size_t)k * (size_t)n;
    switch (cnt) {
      case 0: c0 = ck, u0 = xk, cnt = 1; break;
      case 1: c1 = ck, u1 = xk, cnt = 2; break;
      case 2: c2 = ck, u2 = xk, cnt = 3; break;
      default:
        SCHUR_FN(group_update)(x, k + 1, n, 4, c0, u0, c1, u1, c2, u2, ck, xk);
        cnt = 0;
        break;
    }
  }
  SCHUR_FN(group_update)(x, kend, n, cnt, c0, u0, c1, u1, c2, u2, a, 0.0);
}

/* Dense LU with partial pivoting of the n x n column-major a, in place (L unit lower, U upper):
   LAPACK's getf2, the pivot the largest |re| + |im| (izamax's measure). Left-looking, column by
   column: column j gets the earlier row swaps, then L's updates (lower_eliminate), then its pivot.
   Each value gets the same operations in the same order as in the right-looking form (every
   update of column j by column k after the swaps up to k, k ascending, none where the multiplier
   u = a_kj is zero; a swap moves a row and its values alike, and the rows at k and above are
   fixed once swap k is done), so the factors and pivots are bit for bit those of the
   right-looking loop, while column j stays in cache and four updates go in one pass (reference
   BLAS' zgemm/ztrsm spend ~20 instructions per complex multiply-add: schur.c's schur_use_dense).
   0, or 1 when a pivot is zero or not finite (S singular). */
SCHUR_WIDE static int SCHUR_FN(dense_lu)(SCHUR_T* restrict a, int n, int* restrict ipiv) {
  for (int j = 0; j < n; ++j) {
    SCHUR_T* restrict aj = a + (size_t)j * (size_t)n;
    SCHUR_FN(apply_swaps)(ipiv, j, aj);
    SCHUR_FN(lower_eliminate)(a, n, j, aj);
    int p = j;
    double best = -1.0;
    for (int i = j; i < n; ++i) {
      const double v = SCHUR_ABS1(aj[i]);
      if (v > best) best = v, p = i;
    }
    ipiv[j] = p;
    if (best == 0.0 || !isfinite(best)) return 1;
    if (p != j)
      for (int c = 0; c <= j; ++c) {
        SCHUR_T* col = a + (size_t)c * (size_t)n;
        const SCHUR_T t = col[j];
        col[j] = col[p];
        col[p] = t;
      }
    const SCHUR_T r = 1.0 / aj[j];
    for (int i = j + 1; i < n; ++i) aj[i] *= r;
  }
  return 0;
}

/* b = (P L U)^-1 b with dense_lu's factors: the row swaps, then L and U by columns (axpy form,
   contiguous again; the nonzero b_k's four at a time, as in lower_eliminate) */
SCHUR_WIDE static void SCHUR_FN(dense_solve)(const SCHUR_T* restrict a, int n, const int* restrict ipiv,
                                             SCHUR_T* restrict b) {
  SCHUR_FN(apply_swaps)(ipiv, n, b);
  SCHUR_FN(lower_eliminate)(a, n, n, b);
  /* U from the last row up: b_k = (b_k - the group's pending products) / U_kk, then U's column k
     above k times b_k, four columns together */
  const SCHUR_T *c0 = a, *c1 = a, *c2 = a;
  SCHUR_T u0 = 0.0, u1 = 0.0, u2 = 0.0;
  int cnt = 0;
  for (int k = n - 1; k >= 0; --k) {
    const SCHUR_T* ak = a + (size_t)k * (size_t)n;
    SCHUR_T bk = b[k];
    if (cnt > 0) {
      bk -= c0[k] * u0;
      if (cnt > 1) {
        bk -= c1[k] * u1;
        if (cnt > 2) bk -= c2[k] * u2;
      }
    }
    bk = bk / ak[k];
    b[k] = bk;
    if (bk == 0.0) continue;
    switch (cnt) {
      case 0: c0 = ak, u0 = bk, cnt = 1; break;
      case 1: c1 = ak, u1 = bk, cnt = 2; break;
      case 2: c2 = ak, u2 = bk, cnt = 3; break;
      default:
        SCHUR_FN(group_update)(b, 0, k, 4, c0, u0, c1, u1, c2, u2, ak, bk);
        cnt = 0;
        break;
    }
  }
}

/* S formed from J and factorized (klu.c's policy: the old pivot order while the condition
   estimates allow). 0 ok, 1 recoverable (D singular, or a small dense S), -1 KLU could not
   factorize S, not even from scratch with new pivots. */
static int SCHUR_FN(schur_factor)(fmbSchur* s, const SchurSource* src) {
  if (SCHUR_FN(schur_form)(s, src)) return 1;
  if (s->lu) { /* partial pivoting afresh each time: a dense LU has no refactorization to reuse */
    s->factored = !SCHUR_FN(dense_lu)((SCHUR_T*)s->lu, s->nr, s->ipiv);
    return s->factored ? 0 : 1;
  }
  /* the one KLU policy (klu.c). No factorization at all, even from scratch, is a failure the step
     size cannot mend (as SUNDIALS' KLU module says of a failed klu_factor): the caller falls back
     to the whole matrix (klu_full) */
  return fmb_klu_factor(s->klu, s->data) == FMB_KLU_OK ? 0 : -1;
}

/* x = J^-1 x in place with the last factorization: dR from S dR = b_R - J_Rq D^-1 b_q, then
   dq = D^-1 (b_q - J_qR dR) (schur.c's head comment). 0 ok, 1 when the LU's solve failed. */
SCHUR_WIDE static int SCHUR_FN(schur_solve)(fmbSchur* s, double* xd) {
  const int nq = s->nq, nr = s->nr;
  SCHUR_T* x = (SCHUR_T*)xd;
  SCHUR_T* rhs = (SCHUR_T*)s->acc;
  SCHUR_T* dq = (SCHUR_T*)s->dq;
  const SCHUR_T* dinv = (const SCHUR_T*)s->dinv;
  /* b_R - J_Rq D^-1 b_q, column i of J_Rq after column i - 1 for every value; columns whose rows
     are one and the same run (a beam's are all of S's rows) four per pass, each value kept in a
     register between them */
  memcpy(rhs, x + nq, sizeof(SCHUR_T) * (size_t)nr);
  SCHUR_T bq[4];
  for (int i = 0; i < nq;) {
    int g = 1; /* columns i.. in this pass */
    const int r0 = s->rq_run_ptr[i];
    if (s->rq_run_ptr[i + 1] == r0 + 1)
      while (g < 4 && i + g < nq && s->rq_run_ptr[i + g + 1] == r0 + g + 1 && s->run_row[r0 + g] == s->run_row[r0] &&
             s->run_len[r0 + g] == s->run_len[r0])
        ++g;
    for (int l = 0; l < g; ++l) {
#if SCHUR_IS_COMPLEX
      bq[l] = x[i + l] * dinv[i + l]; /* (D^-1 b_q)_i, then J_Rq (real) times it */
      dq[i + l] = bq[l];
#else
      bq[l] = x[i + l]; /* rq_val holds J_Rq D^-1 */
      dq[i + l] = bq[l] * dinv[i + l];
#endif
    }
    if (g == 4) {
      SCHUR_T* restrict dst = rhs + s->run_row[r0];
      const int len = s->run_len[r0];
      const double* restrict v0 = s->rq_val + s->rq_ptr[i], * restrict v1 = s->rq_val + s->rq_ptr[i + 1], * restrict v2 = s->rq_val + s->rq_ptr[i + 2], * restrict v3 = s->rq_val + s->rq_ptr[i + 3];
      const SCHUR_T b0 = bq[0], b1 = bq[1], b2 = bq[2], b3 = bq[3];
      for (int j = 0; j < len; ++j) {
        SCHUR_T t = dst[j];
        t -= v0[j] * b0;
        t -= v1[j] * b1;
        t -= v2[j] * b2;
        t -= v3[j] * b3;
        dst[j] = t;
      }
      i += 4;
      continue;
    }
    for (int l = 0; l < g; ++l) {
      const SCHUR_T bi = bq[l];
      const double* val = s->rq_val + s->rq_ptr[i + l];
      for (int r = s->rq_run_ptr[i + l]; r < s->rq_run_ptr[i + l + 1]; ++r) {
        SCHUR_T* restrict dst = rhs + s->run_row[r];
        const int len = s->run_len[r];
        for (int j = 0; j < len; ++j) dst[j] -= val[j] * bi;
        val += len;
      }
    }
    i += g;
  }
  int ok = 1;
  if (s->lu) {
    ok = s->factored;
    if (ok) SCHUR_FN(dense_solve)((const SCHUR_T*)s->lu, nr, s->ipiv, rhs);
  } else {
    ok = fmb_klu_solve(s->klu, (double*)rhs) == 0;
  }
  if (!ok) {
    memset(rhs, 0, sizeof(SCHUR_T) * (size_t)nr);
    return 1;
  }
  /* dq = D^-1 (b_q - J_qR dR), over D^-1 J_qR's nonzeros (schur_form): a zero product subtracted
     leaves dq as it was unless dq is -0 and the product -0 (then +0), which no shipped scene meets
     (their CSVs byte for byte as with the zeros in); the w15 spin-up's solves 19.2 -> 17.5 M
     instructions, the zeros being most of the mu columns' */
  const int *qz_ptr = s->qz_ptr, *qz_row = s->qz_row;
  const SCHUR_T* qz_val = (const SCHUR_T*)s->qr_val;
  for (int c = 0; c < nr; ++c) {
    const SCHUR_T dr = rhs[c];
    for (int k = qz_ptr[c]; k < qz_ptr[c + 1]; ++k) dq[qz_row[k]] -= qz_val[k] * dr;
    x[nq + c] = dr;
  }
  memcpy(x, dq, sizeof(SCHUR_T) * (size_t)nq);
  memset(rhs, 0, sizeof(SCHUR_T) * (size_t)nr); /* the scratch column is kept zero between uses */
  return 0;
}

/* the parameters are this instantiation's only: the next one defines its own */
#undef SCHUR_T
#undef SCHUR_FINITE
#undef SCHUR_FN
#undef SCHUR_ABS1
#undef SCHUR_IS_COMPLEX
