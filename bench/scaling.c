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
 * each as the median of 5 blocks of repeated calls (a block lasts >= 0.05 s), in CPU time.
 * Prints one CSV line per N: n,ncoord,nnz,residual_us,system_residual_us,jacobian_us,jac_per_res. */
#include <math.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>
#include <time.h>

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
  int what; /* 0 body residual, 1 system residual, 2 jacobian */
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
    default: {
      int rc = fmb_system_jacobian(m, c->w, 1.0, 1e3, c->y, c->yp, c->ewt, 0, c->csc, NULL); /* fresh blocks */
      sink += c->csc[0];
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
  int ns[32], nn = 0;
  for (int i = 2; i < argc && nn < 32; ++i) ns[nn++] = atoi(argv[i]);
  if (nn == 0) {
    const int def[] = {8, 16, 32, 64, 128, 256};
    for (int i = 0; i < 6; ++i) ns[nn++] = def[i];
  }
  printf("n,ncoord,nnz,residual_us,system_residual_us,jacobian_us,jac_per_res\n");
  srand(12345);
  for (int i = 0; i < nn; ++i) {
    char set[64];
    snprintf(set, sizeof set, "bodies.beam.elements=%d", ns[i]);
    const char* ov[] = {set};
    fmbDiag diag;
    fmbModel* m = fmb_load(argv[1], ov, 1, fmb_builtin_registry(), &diag);
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
    for (size_t k = 0; k < ny; ++k) c.ewt[k] = 1.0 / (1e-6 * fabs(c.y[k]) + 1e-8);
    double tr, ts, tj;
    c.what = 0;
    tr = time_per_call(&c);
    c.what = 1;
    ts = time_per_call(&c);
    c.what = 2;
    tj = time_per_call(&c);
    printf("%d,%d,%ld,%.3f,%.3f,%.3f,%.1f\n", ne, beam->nq, m->nnz, tr, ts, tj, tj / tr);
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
  return sink == 12345.678 ? 1 : 0;
}
