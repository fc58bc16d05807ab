/*
 * tolerance.c — the absolute tolerance of every unknown IDA weighs its errors with.
 *
 * IDA's weight for unknown i is 1 / (rtol |y_i| + atol_i). A coordinate that passes near zero (an
 * elastic amplitude, a hub angle at the start) is held to atol_i alone there, so a fixed atol
 * floors the error whatever rtol is: the ω0 = 15 spin-up with atol 1e-8 gave tip errors of 1.7e-5,
 * 1.5e-5, 1.5e-5 m at rtol 1e-8, 1e-9, 1e-10 (issue 16). Derived from rtol, the floor falls with it.
 */
#include <math.h>
#include <stdlib.h>

#include "internal.h"

/* A body's own length: the arc length of its centreline (a beam: L), 1 m for a body without one (a
   rigid body gives no size; a metre is the scale the scenes' atol = rtol / 100 was chosen for).
   Called once per run before integrating, so it may allocate. */
static double body_length(const fmbBodyInst* bi) {
  if (!bi->type->centreline) return 1.0;
  const int n = bi->type->centreline(bi->self, 0, NULL);
  double* local = n >= 2 ? malloc(sizeof(double) * 2 * (size_t)n) : NULL;
  double len = 0.0;
  if (local && bi->type->centreline(bi->self, n, local) == n)
    for (int k = 1; k < n; ++k) len += hypot(local[2 * k] - local[2 * k - 2], local[2 * k + 1] - local[2 * k - 1]);
  free(local);
  return len > 0.0 && isfinite(len) ? len : 1.0;
}

/* q and v get solver.atol when the scene gives it, or atol in metres of motion for a body that
   gives its coordinates' length scales (fmbBodyType.length_scale): atol / scale for a coordinate
   and its velocity. That is today's rule, kept exactly: the scenes that set atol do not change.

   Without solver.atol each body gets a tolerance in metres, rtol FMB_ATOL_PER_RTOL L (L its
   length), divided by the coordinate's length scale as above: a 1 m body at rtol 1e-6 is held to
   1e-8 m and 1e-8 rad, a slope of the exact beam to 1e-8 m of motion at its tip. A velocity gets
   its coordinate's tolerance per output_step: an error that size moves the body by the position
   tolerance within one output interval, the time resolution the scene asks for. Per t_end - t0
   instead (2000x tighter on the 20 s spin-up) cost the beams, whose velocities are out of the
   error test, twice the Newton convergence failures and 30 % more CPU at rtol 1e-6 for no gain in
   accuracy (docs/performance.md, "Tolerance defaults").

   The multipliers of an index-2 system carry roundoff of order eps/h^2 (Hairer & Wanner VII.3),
   so weighing them like positions in the Newton test makes small steps fail: they get an absolute
   tolerance so large that only q and v decide convergence (they are out of the error test as
   algebraic unknowns). The bodies' auxiliary unknowns likewise. */
void fmb_absolute_tolerances(const fmbModel* m, double* atv) {
  const fmbSolverSettings* s = &m->solver;
  for (int i = 0; i < m->ny; ++i) atv[i] = i < 2 * m->nq ? s->atol : 1e30;
  for (int b = 1; b < m->nbody; ++b) {
    const fmbBodyInst* bi = &m->body[b];
    const double metres = s->atol_given ? s->atol : s->rtol * FMB_ATOL_PER_RTOL * body_length(bi);
    const double per_time = s->atol_given ? 1.0 : 1.0 / s->output_step;
    if (bi->type->length_scale)
      bi->type->length_scale(bi->self, atv + m->nq + bi->qadr); /* the velocity slot as scratch */
    else if (s->atol_given)
      continue; /* atol as given */
    for (int i = bi->qadr; i < bi->qadr + bi->nq; ++i) {
      const double scale = bi->type->length_scale && atv[m->nq + i] > 0.0 ? atv[m->nq + i] : 1.0;
      atv[i] = metres / scale;
      atv[m->nq + i] = atv[i] * per_time;
    }
  }
}
