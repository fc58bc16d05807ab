/* klu_policy.h — the one KLU policy (engine/klu.c), for every sparse LU the engine factors:
 * the reduced Newton systems (schur.c, real and complex), radau5's whole matrices
 * (integrator_radau.c, klu_full), the projected formulation's augmented matrix (augmented.c),
 * the initial accelerations (ic.c) and the shift-invert eigen-solver (modes.c).
 * Named klu_policy.h, not klu.h, so that it never shadows SuiteSparse's <klu.h>. */
#ifndef FMB_KLU_POLICY_H
#define FMB_KLU_POLICY_H

#include <klu.h>

/* KLU refactorizations keep their pivot order while the cheap estimate 1/rcond, then condest,
   stay below eps^(-2/3) = 1 / FMB_KLU_RCOND_TINY (as SUNDIALS' sunlinsol_klu.c) */
#define FMB_KLU_RCOND_TINY 3.666852862501036e-11

/* fmb_klu_factor's results */
enum { FMB_KLU_OK = 0, FMB_KLU_SINGULAR = 1, FMB_KLU_FAILED = -1 };

typedef struct fmbKlu fmbKlu;

/* fmb_klu_new's flags */
enum {
  FMB_KLU_COMPLEX = 1, /* values interleaved (re, im), as klu_zl_* */
  /* plain partial pivoting (KLU's default tolerance 1e-3 prefers a diagonal pivot 1000x smaller
     than the column's largest: poor for a saddle point such as augmented.c's) */
  FMB_KLU_PARTIAL_PIVOTING = 2
};

/* KLU for an n x n pattern (CSC, rows sorted, kept by the caller for the life of the object),
   analyzed once here. NULL when KLU cannot analyze the pattern or memory runs out. */
fmbKlu* fmb_klu_new(long n, const SuiteSparse_long* colptr, const SuiteSparse_long* rowind, unsigned flags);
void fmb_klu_free(fmbKlu* k);
/* Factor the values (in the pattern given at fmb_klu_new): a refactorization with the last
   pivot order; from scratch (new pivots) when there is none yet, when the refactorization fails,
   or when its condition estimates degrade past FMB_KLU_RCOND_TINY. FMB_KLU_OK, FMB_KLU_SINGULAR
   (no usable factorization: the matrix is singular), FMB_KLU_FAILED (out of memory, bad input). */
int fmb_klu_factor(fmbKlu* k, const double* values);
/* 1 when the last fmb_klu_factor started from scratch (new pivot order) */
int fmb_klu_was_full(const fmbKlu* k);
/* b = A^-1 b in place (n values, complex interleaved when is_complex) with the last
   factorization; 0 ok, 1 no factorization or KLU's solve failed */
int fmb_klu_solve(fmbKlu* k, double* b);
/* drop the factorization (the next fmb_klu_factor starts from scratch); the analysis is kept */
void fmb_klu_forget(fmbKlu* k);

#endif
