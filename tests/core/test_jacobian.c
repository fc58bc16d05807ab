/* test_jacobian.c — the assembled iteration matrix dF/dy + cj dF/dy' against central differences
 * of the system residual, for scenes exercising every built-in body, joint and force type, at a
 * perturbed state with nonzero velocities, accelerations and multipliers. Checks both the
 * analytic blocks (rigid, joints) and the engine's FD blocks (beam), that the CSC pattern holds
 * every nonzero (the dense and sparse assemblies must agree), and that reassembling cached body
 * blocks for a new cj equals a fresh evaluation. The beam also in its banded assembly (auxiliary
 * unknowns, its declared pattern differenced by column colours): a missing pattern entry shows
 * as a dense/sparse difference, a wrong difference as a Jacobian error. */
#include <stdlib.h>
#include <string.h>

#include "internal.h"
#include "testlib.h"

static double urand(unsigned* s) {
  *s = *s * 1103515245u + 12345u;
  return ((*s >> 8) & 0xffff) / 65535.0 - 0.5;
}

static int check_scene(const char* rel, const char* const* ov, int nov) {
  char path[1024];
  fmbDiag d;
  fmbModel* m = fmb_load(fmbt_path(rel, path, sizeof path), ov, nov, fmb_builtin_registry(), &d);
  ENSURE(m != NULL);
  if (!m) {
    fprintf(stderr, "%s\n", d.msg);
    return 1;
  }
  const int ny = m->ny;
  fmbWorkspace* w = fmb_workspace_new(m);
  double* y = calloc((size_t)ny, sizeof(double));
  double* yp = calloc((size_t)ny, sizeof(double));
  double* ewt = calloc((size_t)ny, sizeof(double));
  double* J = calloc((size_t)ny * ny, sizeof(double));
  double* csc = calloc((size_t)m->nnz, sizeof(double));
  double* Fp = calloc((size_t)ny, sizeof(double));
  double* Fm = calloc((size_t)ny, sizeof(double));
  fmbStats st;
  ENSURE(fmb_initial_conditions(m, w, y, yp, &st, &d) == 0);
  unsigned seed = 7;
  /* perturb: positions a little (off the constraint manifold is fine), velocities, multipliers */
  for (int i = 0; i < ny; ++i) {
    const double scale = (i < m->nq) ? 1e-3 : 0.3;
    y[i] += scale * urand(&seed);
    yp[i] += 0.3 * urand(&seed);
  }
  for (int i = 0; i < ny; ++i) ewt[i] = 1.0 / (1e-6 * fabs(y[i]) + 1e-8);
  const double cj = 37.0, t = 0.37;
  ENSURE(fmb_system_jacobian(m, w, t, cj, y, yp, ewt, 0, NULL, J) == 0);
  /* the sparse one reassembled from the cached body blocks: must be the same numbers */
  ENSURE(fmb_system_jacobian(m, w, t, cj, y, yp, ewt, 1, csc, NULL) == 0);
  /* a reassembly for another cj must equal a fresh evaluation at that cj */
  {
    double* J2 = calloc((size_t)ny * ny, sizeof(double));
    double* J3 = calloc((size_t)ny * ny, sizeof(double));
    ENSURE(fmb_system_jacobian(m, w, t, 3.0 * cj, y, yp, ewt, 1, NULL, J2) == 0);
    ENSURE(fmb_system_jacobian(m, w, t, 3.0 * cj, y, yp, ewt, 0, NULL, J3) == 0);
    double reuse_diff = 0.0;
    for (size_t k = 0; k < (size_t)ny * ny; ++k)
      reuse_diff = fmax(reuse_diff, fabs(J2[k] - J3[k]) / (1.0 + fabs(J3[k])));
    ENSURE(reuse_diff < 1e-12);
    free(J2);
    free(J3);
  }
  double worst = 0.0, jmax = 0.0;
  int wr = -1, wc = -1;
  for (int c = 0; c < ny; ++c) {
    const double h = 1e-6 * (1.0 + fabs(y[c]));
    const double y0 = y[c], yp0 = yp[c];
    /* d/dy + cj d/dyp along column c */
    y[c] = y0 + h;
    yp[c] = yp0 + cj * h;
    fmb_system_residual(m, w, t, y, yp, Fp);
    y[c] = y0 - h;
    yp[c] = yp0 - cj * h;
    fmb_system_residual(m, w, t, y, yp, Fm);
    y[c] = y0;
    yp[c] = yp0;
    double colmax = 1.0; /* errors are measured against the column's scale, as Newton sees them */
    for (int r = 0; r < ny; ++r) colmax = fmax(colmax, fabs(Fp[r] - Fm[r]) / (2 * h));
    for (int r = 0; r < ny; ++r) {
      const double fd = (Fp[r] - Fm[r]) / (2 * h);
      const double an = J[(size_t)c * ny + r];
      jmax = fmax(jmax, fabs(fd));
      const double err = fabs(fd - an) / colmax;
      if (err > worst) {
        worst = err;
        wr = r;
        wc = c;
      }
    }
  }
  /* the sparse assembly must hold the same numbers */
  double sparse_diff = 0.0;
  for (int c = 0; c < ny; ++c) {
    double colsum_dense = 0.0, colsum_sparse = 0.0;
    for (int r = 0; r < ny; ++r) colsum_dense += fabs(J[(size_t)c * ny + r]);
    for (long k = m->colptr[c]; k < m->colptr[c + 1]; ++k) {
      colsum_sparse += fabs(csc[k]);
      sparse_diff = fmax(sparse_diff, fabs(csc[k] - J[(size_t)c * ny + m->rowind[k]]));
    }
    sparse_diff = fmax(sparse_diff, fabs(colsum_dense - colsum_sparse));
  }
  printf("%s: ny=%d nnz=%ld worst Jacobian error (relative to column max) %.3g at (%d,%d), max entry %.3g, "
         "dense/sparse diff %.3g\n",
         rel, ny, m->nnz, worst, wr, wc, jmax, sparse_diff);
  ENSURE(worst < 1e-5);
  ENSURE(sparse_diff <= 1e-9 * (1.0 + jmax));
  free(y), free(yp), free(ewt), free(J), free(csc), free(Fp), free(Fm);
  fmb_workspace_free(w);
  fmb_free(m);
  return 0;
}

int main(void) {
  check_scene("scenes/pendulum.yaml", NULL, 0);
  check_scene("scenes/fourbar.yaml", NULL, 0);
  check_scene("tests/core/scenes/conformance_rigid.yaml", NULL, 0);
  /* dimension 3: rigid3d and every spatial joint (docs/spatial.md) */
  check_scene("tests/spatial/scenes/chain.yaml", NULL, 0);
  static const char* const models[][1] = {
      {"bodies.beam.model=complete"}, {"bodies.beam.model=foac"}, {"bodies.beam.model=zoac"}};
  for (int k = 0; k < 3; ++k) check_scene("tests/core/scenes/conformance_beam.yaml", models[k], 1);
  /* the banded assembly: auxiliary unknowns, a declared pattern differenced by colours */
  static const char* const banded[][2] = {{"bodies.beam.model=complete", "bodies.beam.assembly=banded"},
                                          {"bodies.beam.model=foac", "bodies.beam.assembly=banded"},
                                          {"bodies.beam.model=zoac", "bodies.beam.assembly=banded"}};
  for (int k = 0; k < 3; ++k) check_scene("tests/core/scenes/conformance_beam.yaml", banded[k], 2);
  return fmbt_finish("test_jacobian");
}
