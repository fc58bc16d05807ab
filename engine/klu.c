/* klu.c — the one KLU policy (klu_policy.h). Written once because three copies of it had drifted
 * apart (schur_kernels.h asked condest after rcond, integrator_radau.c did not, augmented.c
 * factored afresh where schur gave up), and ic.c and modes.c called KLU directly.
 *
 * The rule is SUNDIALS' (sunlinsol_klu.c): the symbolic analysis (ordering) is made once per
 * pattern; each factorization is a refactorization with the pivot order of the last one, which
 * costs no allocation and no pivot search, unless the cheap reciprocal condition estimate rcond
 * falls below eps^(2/3) and the accurate 1-norm estimate condest then exceeds eps^(-2/3): the old
 * order has become a bad one (near a singular configuration it can) and a factorization from
 * scratch picks new pivots. A refactorization that fails outright (a zero pivot in the old order)
 * is also retried from scratch: fresh partial pivoting may pass where the old order cannot.
 * The rule's blind spot, kept on purpose: condest measures the matrix, not the factorization, so
 * a bad old pivot in a well-conditioned matrix (rcond 1e-28, condest 4: tests/core/test_klu.c)
 * keeps the old order. Factoring afresh on rcond alone would close it, but schur.c's S meets
 * rcond < eps^(2/3) with condest 1e7..1e8 in shipped scenes (pendulum, parallelogram), whose
 * numbers would then change; the Newton iterations that use S absorb a slightly worse solve. */
#include <stdlib.h>

#include "klu_policy.h"

struct fmbKlu {
  long n;
  int is_complex;
  int was_full; /* the last factorization started from scratch */
  const SuiteSparse_long *colptr, *rowind;
  klu_l_common common;
  klu_l_symbolic* symbolic;
  klu_l_numeric* numeric;
};

fmbKlu* fmb_klu_new(long n, const SuiteSparse_long* colptr, const SuiteSparse_long* rowind, unsigned flags) {
  if (n < 0 || !colptr || !rowind) return NULL;
  fmbKlu* k = calloc(1, sizeof *k);
  if (!k) return NULL;
  k->n = n;
  k->is_complex = (flags & FMB_KLU_COMPLEX) != 0;
  k->colptr = colptr;
  k->rowind = rowind;
  klu_l_defaults(&k->common);
  if (flags & FMB_KLU_PARTIAL_PIVOTING) k->common.tol = 1.0;
  k->symbolic = klu_l_analyze(n, (SuiteSparse_long*)colptr, (SuiteSparse_long*)rowind, &k->common);
  if (!k->symbolic) {
    free(k);
    return NULL;
  }
  return k;
}

void fmb_klu_forget(fmbKlu* k) {
  if (!k || !k->numeric) return;
  if (k->is_complex)
    klu_zl_free_numeric(&k->numeric, &k->common);
  else
    klu_l_free_numeric(&k->numeric, &k->common);
}

void fmb_klu_free(fmbKlu* k) {
  if (!k) return;
  fmb_klu_forget(k);
  if (k->symbolic) klu_l_free_symbolic(&k->symbolic, &k->common);
  free(k);
}

/* the refactorization with the old pivot order is still good: it succeeded and its condition
   estimates stay within eps^(-2/3) */
static int refactor_good(fmbKlu* k, double* x) {
  SuiteSparse_long *Ap = (SuiteSparse_long*)k->colptr, *Ai = (SuiteSparse_long*)k->rowind;
  if (k->is_complex) {
    if (!klu_zl_refactor(Ap, Ai, x, k->symbolic, k->numeric, &k->common) ||
        !klu_zl_rcond(k->symbolic, k->numeric, &k->common))
      return 0;
    if (k->common.rcond >= FMB_KLU_RCOND_TINY) return 1;
    return klu_zl_condest(Ap, x, k->symbolic, k->numeric, &k->common) && k->common.condest <= 1.0 / FMB_KLU_RCOND_TINY;
  }
  if (!klu_l_refactor(Ap, Ai, x, k->symbolic, k->numeric, &k->common) ||
      !klu_l_rcond(k->symbolic, k->numeric, &k->common))
    return 0;
  if (k->common.rcond >= FMB_KLU_RCOND_TINY) return 1;
  return klu_l_condest(Ap, x, k->symbolic, k->numeric, &k->common) && k->common.condest <= 1.0 / FMB_KLU_RCOND_TINY;
}

int fmb_klu_factor(fmbKlu* k, const double* values) {
  if (!k || !values) return FMB_KLU_FAILED;
  double* x = (double*)values; /* KLU's prototypes are not const-qualified; it does not write them */
  k->was_full = 0;
  if (k->numeric) {
    if (refactor_good(k, x)) return FMB_KLU_OK;
    fmb_klu_forget(k);
  }
  k->was_full = 1;
  SuiteSparse_long *Ap = (SuiteSparse_long*)k->colptr, *Ai = (SuiteSparse_long*)k->rowind;
  k->numeric = k->is_complex ? klu_zl_factor(Ap, Ai, x, k->symbolic, &k->common)
                             : klu_l_factor(Ap, Ai, x, k->symbolic, &k->common);
  if (k->numeric && k->common.status == KLU_OK) return FMB_KLU_OK;
  const int singular = k->common.status == KLU_SINGULAR;
  fmb_klu_forget(k);
  return singular ? FMB_KLU_SINGULAR : FMB_KLU_FAILED;
}

int fmb_klu_was_full(const fmbKlu* k) { return k && k->was_full; }

int fmb_klu_solve(fmbKlu* k, double* b) {
  if (!k || !k->numeric || !b) return 1;
  const SuiteSparse_long ok = k->is_complex ? klu_zl_solve(k->symbolic, k->numeric, k->n, 1, b, &k->common)
                                            : klu_l_solve(k->symbolic, k->numeric, k->n, 1, b, &k->common);
  return ok ? 0 : 1;
}
