/* static_api.c — fmb_static, the public statics entry: the poses the scene gives are checked
 * against the joints as a run checks them (ic.c), then the equilibrium is solved (static.c). In
 * its own file because ic.c calls static.c (`initial: static`) and this calls both: statics once
 * moved bodies onto their joints silently, or failed with exit 3 "no equilibrium" on joints that
 * cannot all hold, where `run` refuses the same scene. */
#include <math.h>
#include <stdlib.h>
#include <string.h>

#include "data.h"

/* fmb_static on the scratch of a data object (w: its workspace, NULL when none could be made) */
static int static_with(const fmbModel* m, fmbWorkspace* w, const fmbStaticOptions* opt, double* y, double* yp,
                       fmbStaticResult* res, fmbDiag* diag) {
  fmbDiag local;
  if (!diag) diag = &local;
  memset(diag, 0, sizeof *diag);
  if (!m || !y || !yp || !res) {
    fmb_diag_set(diag, FMB_EXIT_BAD_INPUT, "", 0, 0, "fmb_static: NULL model, state or result");
    return FMB_EXIT_BAD_INPUT;
  }
  memset(res, 0, sizeof *res);
  if (opt && opt->has_t && !isfinite(opt->t)) {
    fmb_diag_set(diag, FMB_EXIT_BAD_INPUT, m->path, 0, 0, "fmb_static: the time (fmbStaticOptions.t) is %g, not finite",
                 opt->t);
    return FMB_EXIT_BAD_INPUT;
  }
  if (opt && (!(opt->tol >= 0.0) || opt->max_iter < 0 || opt->max_halvings < 0)) {
    fmb_diag_set(diag, FMB_EXIT_BAD_INPUT, m->path, 0, 0,
                 "fmb_static: options out of range (a negative or NaN tol, max_iter or max_halvings)");
    return FMB_EXIT_BAD_INPUT;
  }
  double* q = calloc((size_t)m->nq + 1, sizeof(double));
  double* v = calloc((size_t)m->nq + 1, sizeof(double));
  int rc = 0;
  if (!w || !q || !v) {
    fmb_diag_set(diag, FMB_EXIT_SOLVER, m->path, 0, 0, "out of memory");
    rc = FMB_EXIT_SOLVER;
  } else {
    /* the poses as given, at t0 (the drives may stand elsewhere at opt->t: Newton goes there) */
    for (int b = 1; b < m->nbody; ++b) {
      const fmbBodyInst* bi = &m->body[b];
      bi->type->initial(bi->self, q + bi->qadr, v + bi->qadr);
    }
    rc = fmb_pose_check(m, w, m->solver.t0, q, diag);
    if (!rc) rc = fmb_static_solve(m, w, opt, y, yp, res, diag);
  }
  free(q);
  free(v);
  return rc;
}

/* ---------------------------------------------------------------------------------------------
 * the public entries: on the caller's data object, or on one made for the call (docs/api.md
 * "Analyses on a data object") */

int fmb_static(const fmbModel* m, const fmbStaticOptions* opt, double* y, double* yp, fmbStaticResult* res,
               fmbDiag* diag) {
  fmbData* own = m ? fmb_data_new(m, NULL) : NULL;
  const int rc = static_with(m, own ? own->w : NULL, opt, y, yp, res, diag);
  fmb_data_destroy(own);
  return rc;
}

int fmb_static_data(const fmbModel* m, fmbData* d, const fmbStaticOptions* opt, fmbStaticResult* res, fmbDiag* diag) {
  fmbDiag local;
  if (!diag) diag = &local;
  memset(diag, 0, sizeof *diag);
  if (fmb_data_misused(m, d, "fmb_static_data", diag)) return FMB_EXIT_BAD_INPUT;
  /* solved into the data's scratch state (step.c: free between advances): d's state stays the
     run's when there is no equilibrium */
  fmb_workspace_hold_cache(d->w, 1);
  const int rc = static_with(m, d->w, opt, d->start.y, d->start.yp, res, diag);
  fmb_workspace_hold_cache(d->w, 0);
  if (!rc) fmb_data_hold_analysis_state(d, res->t, d->start.y, d->start.yp);
  return rc;
}
