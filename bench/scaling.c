/* scaling.c — cost of one beam residual and one iteration-matrix (Jacobian) evaluation against
 * the element count, through the library (docs/performance.md, "Scaling").
 *
 *   scaling SCENE.yaml [N...]        (default N = 8 16 32 64 128 256; the scene's beam is `beam`)
 *
 * For each N the scene is loaded with bodies.beam.elements=N, the state is the scene's initial
 * state with a smooth deformation (tip deflection ~1 % of L) and random velocities, and it times
 *   - the beam body's own residual (fmbBodyType.residual, what one IDA residual costs per body),
 *   - the whole DAE residual (fmb_system_residual),
 *   - one iteration matrix J = dF/dy + cj dF/dy' into the sparse pattern (fmb_system_jacobian:
 *     the beam's analytic `jacobian` op if it has one, otherwise engine/fd.c's differences),
 *   - one factorization of the Newton matrix and one solve with it (the default solver: KLU on
 *     the Schur complement, engine/schur.c), what a Jacobian update and a Newton iteration add,
 * each as the median of 5 blocks of repeated calls (a block lasts >= 0.05 s), in CPU time.
 *
 *   scaling SCENE.yaml [-s PATH=VALUE]... [N...]     (-s: an override for every run, e.g.
 *                                                      -s bodies.beam.assembly=banded)
 * Prints one CSV line per N:
 *   n,ncoord,ny,nnz,residual_us,system_residual_us,jacobian_us,jac_per_res,lsetup_us,lsolve_us */
#include <math.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>
#include <time.h>

#include <nvector/nvector_serial.h>
#include <sundials/sundials_context.h>
#include <sundials/sundials_linearsolver.h>
#include <sunmatrix/sunmatrix_sparse.h>

#include "builtin.h"
#include "internal.h"

static double cpu_now(void) {
  struct timespec ts;
  clock_gettime(CLOCK_PROCESS_CPUTIME_ID, &ts);
  return (double)ts.tv_sec + 1e-9 * (double)ts.tv_nsec;
}

static int cmp_d(const void* a, const void* b) {
  double x = *(const double*)a, y = *(const double*)b;
  return (x > y) - (x < y);
}

typedef struct {
  const fmbModel* m;
  fmbWorkspace* w;
  const fmbBodyInst* b;
  double *y, *yp, *F, *R, *ewt, *csc;
  SUNMatrix A;
  SUNLinearSolver LS;
  N_Vector x, rhs;
  int what; /* 0 body residual, 1 system residual, 2 jacobian, 3 factorization, 4 solve */
} Ctx;

static volatile double sink;

static int once(Ctx* c) {
  const fmbModel* m = c->m;
  switch (c->what) {
    case 0: {
      const fmbBodyInst* b = c->b;
      int rc = b->type->residual(b->self, &m->env, c->y + b->qadr, c->y + m->nq + b->qadr, c->yp + m->nq + b->qadr,
                                 c->R, fmb_workspace_plugin(c->w) + b->workadr);
      sink += c->R[0];
      return rc;
    }
    case 1: {
      int rc = fmb_system_residual(m, c->w, 1.0, c->y, c->yp, c->F);
      sink += c->F[0];
      return rc;
    }
    case 2: {
      int rc = fmb_system_jacobian(m, c->w, 1.0, 1e3, c->y, c->yp, c->ewt, 0, c->csc, NULL); /* fresh blocks */
      sink += c->csc[0];
      return rc;
    }
    case 3: return SUNLinSolSetup(c->LS, c->A);
    default: {
      int rc = SUNLinSolSolve(c->LS, c->A, c->x, c->rhs, 0.0);
      sink += NV_Ith_S(c->x, 0);
      return rc;
    }
  }
}

/* median over 5 blocks of the CPU time per call, in microseconds */
static double time_per_call(Ctx* c) {
  double per[5];
  long reps = 1;
  for (;;) { /* calibrate */
    double t0 = cpu_now();
    for (long k = 0; k < reps; ++k)
      if (once(c)) return NAN;
    double dt = cpu_now() - t0;
    if (dt >= 0.05) break;
    reps = dt > 1e-4 ? (long)(reps * 0.06 / dt) + 1 : reps * 10;
  }
  for (int blk = 0; blk < 5; ++blk) {
    double t0 = cpu_now();
    for (long k = 0; k < reps; ++k) once(c);
    per[blk] = (cpu_now() - t0) / (double)reps * 1e6;
  }
  qsort(per, 5, sizeof per[0], cmp_d);
  return per[2];
}

int main(int argc, char** argv) {
  if (argc < 2) {
    fprintf(stderr, "usage: scaling SCENE.yaml [N...]\n");
    return 2;
  }
  int ns[32], nn = 0, nset = 0;
  const char* sets[16];
  for (int i = 2; i < argc && nn < 32; ++i) {
    if (strcmp(argv[i], "-s") == 0 && i + 1 < argc && nset < 15)
      sets[nset++] = argv[++i];
    else
      ns[nn++] = atoi(argv[i]);
  }
  if (nn == 0) {
    const int def[] = {8, 16, 32, 64, 128, 256};
    for (int i = 0; i < 6; ++i) ns[nn++] = def[i];
  }
  printf("n,ncoord,ny,nnz,residual_us,system_residual_us,jacobian_us,jac_per_res,lsetup_us,lsolve_us\n");
  SUNContext sun = NULL;
  if (SUNContext_Create(NULL, &sun)) return 3;
  srand(12345);
  for (int i = 0; i < nn; ++i) {
    char set[64];
    snprintf(set, sizeof set, "bodies.beam.elements=%d", ns[i]);
    const char* ov[17] = {set};
    for (int k = 0; k < nset; ++k) ov[1 + k] = sets[k];
    fmbDiag diag;
    fmbModel* m = fmb_load(argv[1], ov, 1 + nset, fmb_builtin_registry(), &diag);
    if (!m) {
      fprintf(stderr, "scaling: %s: %s\n", argv[1], diag.msg);
      return 2;
    }
    const fmbBodyInst* beam = NULL;
    for (int b = 1; b < m->nbody; ++b)
      if (strcmp(m->body[b].name, "beam") == 0) beam = &m->body[b];
    if (!beam) {
      fprintf(stderr, "scaling: the scene has no body named 'beam'\n");
      return 2;
    }
    Ctx c = {.m = m, .b = beam};
    c.w = fmb_workspace_new(m);
    const size_t ny = (size_t)m->ny;
    c.y = calloc(ny, sizeof(double));
    c.yp = calloc(ny, sizeof(double));
    c.F = calloc(ny, sizeof(double));
    c.R = calloc((size_t)beam->nq, sizeof(double));
    c.ewt = calloc(ny, sizeof(double));
    c.csc = calloc((size_t)m->nnz, sizeof(double));
    if (!c.w || !c.y || !c.yp || !c.F || !c.R || !c.ewt || !c.csc) return 3;
    fmbStats st;
    if (fmb_initial_conditions(m, c.w, c.y, c.yp, &st, &diag)) {
      fprintf(stderr, "scaling: initial conditions: %s\n", diag.msg);
      return 3;
    }
    /* a smooth deformation: nodal transverse v = 0.01 L (x/L)^2, slope consistent, small axial,
       frame spinning at 2 rad/s, random deformation rates */
    const int ne = (beam->nq - 3) / 3;
    double* q = c.y + beam->qadr;
    double* v = c.y + m->nq + beam->qadr;
    double* a = c.yp + m->nq + beam->qadr;
    const double L = 1.8;
    v[2] = 2.0;
    for (int k = 1; k <= ne; ++k) {
      double x = L * k / ne;
      q[3 + 3 * (k - 1) + 0] = -1e-5 * x / L;
      q[3 + 3 * (k - 1) + 1] = 0.01 * L * (x / L) * (x / L);
      q[3 + 3 * (k - 1) + 2] = 0.02 * x / L;
      for (int j = 0; j < 3; ++j) {
        v[3 + 3 * (k - 1) + j] = 1e-3 * ((double)rand() / RAND_MAX - 0.5);
        a[3 + 3 * (k - 1) + j] = 1e-2 * ((double)rand() / RAND_MAX - 0.5);
      }
    }
    /* the auxiliary unknowns of a banded beam, consistent with that state */
    if (beam->nz > 0 && beam->type->aux_initial(beam->self, &m->env, q, v, a, c.y + m->zoff + beam->zadr,
                                                fmb_workspace_plugin(c.w) + beam->workadr))
      return 3;
    for (size_t k = 0; k < ny; ++k) c.ewt[k] = 1.0 / (1e-6 * fabs(c.y[k]) + 1e-8);
    /* the Newton matrix at that state, for the factorization and solve timings */
    c.A = SUNSparseMatrix((sunindextype)ny, (sunindextype)ny, m->nnz, CSC_MAT, sun);
    c.LS = fmb_schur_klu_new(m, sun);
    c.x = N_VNew_Serial((sunindextype)ny, sun);
    c.rhs = N_VNew_Serial((sunindextype)ny, sun);
    if (!c.A || !c.LS || !c.x || !c.rhs) return 3;
    fmb_sparse_pattern_into(m, c.A);
    if (fmb_system_jacobian(m, c.w, 1.0, 1e3, c.y, c.yp, c.ewt, 0, SUNSparseMatrix_Data(c.A), NULL) ||
        SUNLinSolInitialize(c.LS) || SUNLinSolSetup(c.LS, c.A))
      return 3;
    for (size_t k = 0; k < ny; ++k) NV_Ith_S(c.rhs, k) = (double)rand() / RAND_MAX - 0.5;
    double t[5];
    for (c.what = 0; c.what < 5; ++c.what) t[c.what] = time_per_call(&c);
    printf("%d,%d,%zu,%ld,%.3f,%.3f,%.3f,%.1f,%.3f,%.3f\n", ne, beam->nq, ny, m->nnz, t[0], t[1], t[2], t[2] / t[0],
           t[3], t[4]);
    SUNLinSolFree(c.LS);
    SUNMatDestroy(c.A);
    N_VDestroy(c.x);
    N_VDestroy(c.rhs);
    fflush(stdout);
    free(c.y);
    free(c.yp);
    free(c.F);
    free(c.R);
    free(c.ewt);
    free(c.csc);
    fmb_workspace_free(c.w);
    fmb_free(m);
  }
  SUNContext_Free(&sun);
  return sink == 12345.678 ? 1 : 0;
}
