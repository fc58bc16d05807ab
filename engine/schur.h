/* schur.h — schur.c: KLU on the GGL Newton systems with the position rows eliminated, for the
 * integrator backends (integrator.h includes it) and their tests; out of internal.h, which every
 * engine file includes, because only the backends use it. */
#ifndef FMB_SCHUR_H
#define FMB_SCHUR_H

#include "internal.h"

/* One Newton matrix on the model's pattern, real or complex (values interleaved (re, im)), solved
   through the Schur complement of its position rows. Factor: 0 ok, 1 recoverable (singular),
   -1 KLU failed outright; solve in place: 0 ok, 1 failed. Allocates in new only (and when KLU
   picks a new pivot order). */
typedef struct fmbSchur fmbSchur;
fmbSchur* fmb_schur_new(const fmbModel* m, int complex_values);
/* another matrix on like's pattern (its own values and factorization), sharing like's index arrays
   and S's pattern: kept until the last of them is freed */
fmbSchur* fmb_schur_new_like(const fmbSchur* like, int complex_values);
int fmb_schur_factor(fmbSchur* s, const double* J);
/* the same for J = jy + (a + i b) jyp (real: jy + a jyp, b unused) on the model's pattern, its
   entries computed as read: jy[k] + a jyp[k] and b jyp[k], bit for bit the values of the stored
   matrix (radau's iteration matrices) */
int fmb_schur_factor_pencil(fmbSchur* s, const double* jy, const double* jyp, double a, double b);
int fmb_schur_solve(fmbSchur* s, double* x);
void fmb_schur_forget(fmbSchur* s); /* drop the factorization: the next one chooses pivots afresh */
void fmb_schur_free(fmbSchur* s);
/* the real one as IDA's SUNLinearSolver */
struct _generic_SUNLinearSolver;
struct _SUNContext;
struct _generic_SUNLinearSolver* fmb_schur_klu_new(const fmbModel* m, struct _SUNContext* sun);

#endif
