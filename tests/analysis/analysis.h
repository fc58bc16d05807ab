/* analysis.h — what the analysis tests share: a scene's static/steady state and its modes. */
#ifndef FLEXMBD_TEST_ANALYSIS_H
#define FLEXMBD_TEST_ANALYSIS_H
#include <stdlib.h>
#include <string.h>

#include "testlib.h"

/* the seed beam: EI / (rho A L^4), the scale of every frequency (omega = mu sqrt(EI / rho A L^4)) */
#define SEED_L 1.8
#define SEED_EI (68.95e9 * 1.302e-10)
#define SEED_RHOA (2767.0 * 2.5e-4)
static inline double seed_omega_scale(void) { return sqrt(SEED_EI / (SEED_RHOA * pow(SEED_L, 4))); }

typedef struct {
  fmbModel* m;
  double *y, *yp;
  fmbStaticResult st;
  fmbModes* modes;
} Analysis;

/* load scene (source-relative) with overrides, solve the static state (at t if has_t), then
   `count` modes if count > 0; returns the first failing code (reported) */
static inline int analyse(Analysis* a, const char* scene_rel, const char* const* ov, int nov, int has_t, double t,
                          int count) {
  char path[1024];
  fmbDiag d;
  memset(a, 0, sizeof *a);
  a->m = fmb_load(fmbt_path(scene_rel, path, sizeof path), ov, nov, fmb_builtin_registry(), &d);
  if (!a->m) {
    fprintf(stderr, "load %s: %s\n", scene_rel, d.msg);
    return d.code;
  }
  const int ny = fmb_state_size(a->m);
  a->y = calloc((size_t)ny, sizeof(double));
  a->yp = calloc((size_t)ny, sizeof(double));
  fmbStaticOptions o;
  memset(&o, 0, sizeof o);
  o.has_t = has_t;
  o.t = t;
  o.quiet = 1;
  int rc = fmb_static(a->m, &o, a->y, a->yp, &a->st, &d);
  if (!rc && count > 0) rc = fmb_modes(a->m, a->st.t, a->y, a->yp, count, FMB_EIGEN_AUTO, &a->modes, &d);
  if (rc) fprintf(stderr, "analysis of %s failed: %s\n", scene_rel, d.msg);
  return rc;
}

static inline void analysis_free(Analysis* a) {
  fmb_modes_free(a->modes);
  free(a->y);
  free(a->yp);
  fmb_free(a->m);
}

/* the dense and the sparse eigen-solver agree on the first `count` modes about a's state:
   frequencies to 1e-9, shapes to MAC 1 - 1e-9 */
static inline void ensure_solvers_agree(const Analysis* a, int count) {
  fmbModes *dense = NULL, *sparse = NULL;
  fmbDiag d;
  ENSURE(fmb_modes(a->m, a->st.t, a->y, a->yp, count, FMB_EIGEN_DENSE, &dense, &d) == 0);
  ENSURE(fmb_modes(a->m, a->st.t, a->y, a->yp, count, FMB_EIGEN_SPARSE, &sparse, &d) == 0);
  if (dense && sparse) {
    ENSURE(!dense->sparse && sparse->sparse);
    for (int n = 0; n < count; ++n) {
      ENSURE_REL(sparse->frequency[n], dense->frequency[n], 1e-9);
      ENSURE_NEAR(fmb_modes_mac(sparse, n, dense, n), 1.0, 1e-9);
      ENSURE(sparse->damping_ratio[n] == dense->damping_ratio[n]);
    }
  }
  fmb_modes_free(dense);
  fmb_modes_free(sparse);
}

/* one of the scene's outputs at the state (written through fmb_write_state_row, read back) */
static inline double state_output(const Analysis* a, const char* column) {
  char out[1024];
  fmbDiag d;
  fmbt_out_path("state.csv", out, sizeof out);
  if (fmb_write_state_row(a->m, out, a->st.t, a->y, a->yp, &d)) return NAN;
  fmbtCsv c;
  if (fmbt_csv_read(out, &c)) return NAN;
  const double* x = fmbt_col(&c, column);
  const double v = x && c.nrow == 1 ? x[0] : NAN;
  fmbt_csv_free(&c);
  return v;
}
#endif
