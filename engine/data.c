/* data.c — making and releasing a data object (fmbData, data.h): the one place a run's scratch
 * (the system workspace, system.c) is made. Beside step.c, not in it, because the checks below
 * step.c in the call graph take their scratch from a data object too (ic.c's start analysis,
 * pattern.c's joint supports, singular.c's walk) and step.c calls them: from step.c that would be
 * a circle (tools/callgraph.py). The quarantine of freed objects and everything a run does stay
 * in step.c. */
#include <math.h>
#include <stdlib.h>
#include <string.h>

#include "data.h"

void fmb_data_release(fmbData* d) {
  if (d->integ) d->ops->destroy(d->integ);
  d->integ = NULL;
  double* bufs[] = {d->y,       d->yp,       d->atol,      d->row, d->work_before, d->redundant_phi,
                    d->start.y, d->start.yp, d->start.work};
  for (size_t i = 0; i < sizeof bufs / sizeof bufs[0]; ++i) free(bufs[i]);
  free(d->range_warned);
  fmb_workspace_free(d->w);
  d->w = NULL;
}

fmbData* fmb_data_new(const fmbModel* m, fmbDiag* diag) {
  fmbDiag local;
  if (!diag) diag = &local;
  memset(diag, 0, sizeof *diag);
  if (!m) {
    fmb_diag_set(diag, FMB_EXIT_BAD_INPUT, "", 0, 0, "fmb_data_new: no model (NULL)");
    return NULL;
  }
  fmbData* d = calloc(1, sizeof *d);
  if (!d) {
    fmb_diag_set(diag, FMB_EXIT_SOLVER, m->path, 0, 0, "out of memory setting up a run");
    return NULL;
  }
  const size_t ny = (size_t)m->ny + 1;
  d->m = m;
  d->w = fmb_workspace_new(m);
  d->y = calloc(ny, sizeof(double));
  d->yp = calloc(ny, sizeof(double));
  d->atol = calloc(ny, sizeof(double));
  d->row = calloc((size_t)m->noutput + 1, sizeof(double));
  d->work_before = calloc((size_t)m->njoint + 1, sizeof(double));
  d->redundant_phi = calloc((size_t)m->nc + 1, sizeof(double));
  d->range_warned = calloc((size_t)m->nbody + 1, 1);
  d->may_switch = m->solver.formulation == FMB_FORM_AUTO && m->nc > 0 && m->nz == 0;
  d->start.y = calloc(ny, sizeof(double));
  d->start.yp = calloc(ny, sizeof(double));
  d->start.work = calloc((size_t)m->njoint + 1, sizeof(double));
  if (!d->w || !d->y || !d->yp || !d->atol || !d->row || !d->work_before || !d->redundant_phi || !d->range_warned ||
      !d->start.y || !d->start.yp || !d->start.work) {
    fmb_data_release(d);
    free(d);
    fmb_diag_set(diag, FMB_EXIT_SOLVER, m->path, 0, 0, "out of memory setting up the integrator");
    return NULL;
  }
  fmb_absolute_tolerances(m, d->atol);
  d->stop = &d->cancel;
  d->t = NAN;
  d->magic = FMB_DATA_LIVE;
  return d;
}

void fmb_data_destroy(fmbData* d) {
  if (!d || d->magic != FMB_DATA_LIVE) return;
  fmb_data_release(d);
  d->magic = 0;
  free(d);
}
