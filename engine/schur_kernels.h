/* schur_kernels.h — the numeric half of schur.c for one scalar type. schur.c includes it twice:
 * with SCHUR_T = double (IDA's iteration matrix, radau5's real system) and SCHUR_T = double
 * complex (radau5's complex system, Hairer & Wanner IV.8 (8.17)), so the elimination is written
 * once. Complex values are interleaved (re, im) pairs, which is both C11's layout of double
 * complex (6.2.5) and what KLU's klu_zl_* routines take. Not a header for anyone else.
 *
 * Expects: SCHUR_T, SCHUR_FINITE(x), SCHUR_FN(name) (the name with the type's suffix) and
 * SCHUR_KLU(name) (klu_l_name or klu_zl_name). */

/* S = J_RR - J_Rq D^-1 J_qR, column by column through a dense scratch column (schur.c's head
   comment); also the compact J_Rq D^-1 and D^-1 J_qR copies the solves use. 0, or 1 when D has a
   zero or non-finite entry. */
static int SCHUR_FN(schur_form)(fmbSchur* s, const double* Jd) {
  const fmbModel* m = s->m;
  const int nq = s->nq;
  const SCHUR_T* J = (const SCHUR_T*)Jd;
  SCHUR_T* dinv = (SCHUR_T*)s->dinv;
  SCHUR_T* acc = (SCHUR_T*)s->acc;
  SCHUR_T* data = (SCHUR_T*)s->data;
  for (int i = 0; i < nq; ++i) {
    const SCHUR_T d = J[s->diag_pos[i]];
    if (d == 0.0 || !SCHUR_FINITE(d)) return 1;
    dinv[i] = 1.0 / d;
  }
  for (int i = 0; i < nq; ++i) {
    SCHUR_T* val = (SCHUR_T*)s->rq_val + s->rq_ptr[i];
    for (long k = s->first_kept[i]; k < m->colptr[i + 1]; ++k) *val++ = J[k] * dinv[i];
  }
  for (int c = 0; c < s->nr; ++c) {
    SCHUR_T* val = (SCHUR_T*)s->qr_val + s->qr_ptr[c];
    for (long k = m->colptr[nq + c]; k < s->first_kept[nq + c]; ++k) *val++ = J[k] * dinv[m->rowind[k]];
  }
  for (int c = 0; c < s->nr; ++c) {
    const int jc = nq + c;
    for (long k = m->colptr[jc]; k < m->colptr[jc + 1]; ++k) {
      const long i = m->rowind[k];
      if (i >= nq) {
        acc[i - nq] += J[k];
        continue;
      }
      const SCHUR_T coef = J[k] * dinv[i]; /* (D^-1 J_qR)_ic */
      for (long kk = s->first_kept[i]; kk < m->colptr[i + 1]; ++kk) acc[m->rowind[kk] - nq] -= J[kk] * coef;
    }
    for (SuiteSparse_long k = s->colptr[c]; k < s->colptr[c + 1]; ++k) {
      data[k] = acc[s->rowind[k]];
      acc[s->rowind[k]] = 0.0;
    }
  }
  return 0;
}

/* S formed from J and factorized: a refactorization with the old pivot order, from scratch when a
   cheap estimate, then the accurate one, say the condition has degraded (as SUNDIALS' KLU module
   does). 0 ok, 1 recoverable (D or S singular), -1 KLU could not factorize at all. */
static int SCHUR_FN(schur_factor)(fmbSchur* s, const double* J) {
  if (SCHUR_FN(schur_form)(s, J)) return 1;
  if (!s->numeric) {
    s->numeric = SCHUR_KLU(factor)(s->colptr, s->rowind, s->data, s->symbolic, &s->common);
    return s->numeric ? 0 : -1;
  }
  if (!SCHUR_KLU(refactor)(s->colptr, s->rowind, s->data, s->symbolic, s->numeric, &s->common) ||
      !SCHUR_KLU(rcond)(s->symbolic, s->numeric, &s->common))
    return 1;
  const double tiny = pow(2.220446049250313e-16, 2.0 / 3.0);
  if (s->common.rcond < tiny) {
    if (!SCHUR_KLU(condest)(s->colptr, s->data, s->symbolic, s->numeric, &s->common)) return 1;
    if (s->common.condest > 1.0 / tiny) {
      SCHUR_KLU(free_numeric)(&s->numeric, &s->common);
      s->numeric = SCHUR_KLU(factor)(s->colptr, s->rowind, s->data, s->symbolic, &s->common);
      if (!s->numeric) return -1;
    }
  }
  return 0;
}

/* x = J^-1 x in place with the last factorization: dR from S dR = b_R - J_Rq D^-1 b_q, then
   dq = D^-1 (b_q - J_qR dR) (schur.c's head comment). 0 ok, 1 when KLU's solve failed. */
static int SCHUR_FN(schur_solve)(fmbSchur* s, double* xd) {
  const int nq = s->nq, nr = s->nr;
  SCHUR_T* x = (SCHUR_T*)xd;
  SCHUR_T* rhs = (SCHUR_T*)s->acc;
  SCHUR_T* dq = (SCHUR_T*)s->dq;
  const SCHUR_T* dinv = (const SCHUR_T*)s->dinv;
  /* b_R - J_Rq D^-1 b_q */
  memcpy(rhs, x + nq, sizeof(SCHUR_T) * (size_t)nr);
  for (int i = 0; i < nq; ++i) {
    const SCHUR_T bi = x[i];
    dq[i] = bi * dinv[i];
    const SCHUR_T* val = (const SCHUR_T*)s->rq_val + s->rq_ptr[i];
    for (int r = s->rq_run_ptr[i]; r < s->rq_run_ptr[i + 1]; ++r) {
      SCHUR_T* restrict dst = rhs + s->run_row[r];
      const int len = s->run_len[r];
      for (int j = 0; j < len; ++j) dst[j] -= val[j] * bi;
      val += len;
    }
  }
  if (!SCHUR_KLU(solve)(s->symbolic, s->numeric, nr, 1, (double*)rhs, &s->common)) {
    memset(rhs, 0, sizeof(SCHUR_T) * (size_t)nr);
    return 1;
  }
  /* dq = D^-1 (b_q - J_qR dR) */
  const int *qr_ptr = s->qr_ptr, *qr_row = s->qr_row;
  const SCHUR_T* qr_val = (const SCHUR_T*)s->qr_val;
  for (int c = 0; c < nr; ++c) {
    const SCHUR_T dr = rhs[c];
    for (int k = qr_ptr[c]; k < qr_ptr[c + 1]; ++k) dq[qr_row[k]] -= qr_val[k] * dr;
    x[nq + c] = dr;
  }
  memcpy(x, dq, sizeof(SCHUR_T) * (size_t)nq);
  memset(rhs, 0, sizeof(SCHUR_T) * (size_t)nr); /* the scratch column is kept zero between uses */
  return 0;
}
