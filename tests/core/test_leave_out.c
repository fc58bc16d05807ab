/* test_leave_out.c — the engine leaves out what a scene does not need:
 *  - no joints: no multiplier unknowns or constraint rows (ny = 2 nq);
 *  - g = 0: gravity is not evaluated (has_gravity off), so a body's residual at rest is zero;
 *  - outputs: an energy pass only when an energy column is asked for, constraint norms likewise;
 *  - the pattern of a jointless scene holds only the bodies' own blocks and the identity rows.
 * And, for contrast, the same scene with a joint and gravity gets them. */
#include <string.h>

#include "internal.h"
#include "testlib.h"

static fmbModel* load(const char* rel, const char* const* ov, int nov) {
  char path[1024];
  fmbDiag d;
  fmbModel* m = fmb_load(fmbt_path(rel, path, sizeof path), ov, nov, fmb_builtin_registry(), &d);
  if (!m) fprintf(stderr, "%s\n", d.msg);
  return m;
}

int main(void) {
  const char* free_ov[] = {"gravity=[0, 0]"};
  fmbModel* m = load("tests/core/scenes/free_bodies.yaml", free_ov, 1);
  ENSURE(m != NULL);
  if (m) {
    ENSURE(m->nc == 0);
    ENSURE(m->ny == 2 * m->nq);
    ENSURE(!m->env.has_gravity);
    ENSURE(!m->need_energy && !m->need_constraint);
    /* identity rows (2 nq entries) plus each body's two dense blocks */
    long expect = 2L * m->nq;
    for (int b = 1; b < m->nbody; ++b) expect += 2L * m->body[b].nq * m->body[b].nq;
    ENSURE(m->nnz == expect);
    /* with g = 0 the residual of a body at rest with zero acceleration is exactly zero */
    fmbWorkspace* w = fmb_workspace_new(m);
    double y[64] = {0}, yp[64] = {0}, F[64];
    fmbStats st;
    fmbDiag d;
    ENSURE(m->ny <= 64);
    ENSURE(fmb_initial_conditions(m, w, y, yp, &st, &d) == 0);
    for (int i = m->nq; i < 2 * m->nq; ++i) y[i] = 0.0; /* at rest */
    memset(yp, 0, sizeof yp);
    ENSURE(fmb_system_residual(m, w, 0.0, y, yp, F) == 0);
    double fmax_ = 0.0;
    for (int i = 0; i < m->ny; ++i) fmax_ = fmax(fmax_, fabs(F[i]));
    ENSURE(fmax_ == 0.0);
    fmb_workspace_free(w);
    fmb_free(m);
  }
  const char* on_ov[] = {"outputs=[a.x, energy.total, constraint.position]"};
  m = load("tests/core/scenes/free_bodies.yaml", on_ov, 1);
  ENSURE(m != NULL);
  if (m) {
    ENSURE(m->env.has_gravity);
    ENSURE(m->need_energy && m->need_constraint);
    fmb_free(m);
  }
  m = load("tests/core/scenes/conformance_rigid.yaml", NULL, 0);
  ENSURE(m != NULL);
  if (m) {
    ENSURE(m->nc == 10);
    ENSURE(m->ny == 2 * m->nq + 2 * m->nc);
    fmb_free(m);
  }
  return fmbt_finish("test_leave_out");
}
