/* fd.h — fd.c: a body's equations and their derivatives over its own coordinates (analytic when
 * the type has them, else by differences), for the assemblies that need them (system.c, ic.c).
 * Out of internal.h, which every engine file includes. */
#ifndef FMB_FD_H
#define FMB_FD_H

#include "internal.h"

double fmb_fd_increment(double y, double ewt);
/* dense column-major derivative of a body's residual: K = dR/dq, C = dR/dv, M = dR/da */
int fmb_fd_body_jacobian(const fmbBodyInst* b, const fmbEnv* env, const double* q, const double* v, const double* a,
                         const double* ewt_q, const double* ewt_v, double* K, double* C, double* M, double* work,
                         double* scratch);
/* a sparse body's K, C, M in pattern order (pnnz each), from the body's analytic
   pattern_jacobian when it has one, else by differences over its pattern, one residual pair per
   colour; scratch doubles: fmb_body_sparse_scratch */
size_t fmb_body_sparse_scratch(const fmbBodyInst* b);
int fmb_body_sparse_blocks(const fmbBodyInst* b, const fmbEnv* env, const double* q, const double* v, const double* a,
                           const double* z, const double* ewt_q, const double* ewt_v, double* K, double* C, double* M,
                           double* work, double* scratch);
/* a body's rows [R; Rz] at (q, v, a, z): residual_aux when it has auxiliary unknowns */
int fmb_body_eval(const fmbBodyInst* b, const fmbEnv* env, const double* q, const double* v, const double* a,
                  const double* z, double* R, double* work);

#endif
