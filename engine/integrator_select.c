/* integrator_select.c — which integrator backend a model runs on, and the stats line that names
 * what a run did. One place for the choice (docs/style.md: "a choice made in one place"), apart
 * from the run driver (integrate.c), so that the backends' table and the rule that picks one can
 * grow without touching the driver. */
#include <stdio.h>

#include "integrator.h"

/* The one list of backends; the first GGL backend is solver.integrator's default. */
const fmbIntegratorOps* const fmb_integrators[] = {&fmb_integrator_ida, &fmb_integrator_radau5, &fmb_integrator_projected,
                                                   NULL};

static const fmbIntegratorOps* projected_backend(void) {
  for (int i = 0; fmb_integrators[i]; ++i)
    if (fmb_integrators[i]->projected) return fmb_integrators[i];
  return NULL;
}

int fmb_integrator_choices(const char** names, const fmbIntegratorOps** ops, int cap) {
  int n = 0;
  for (int i = 0; fmb_integrators[i] && n + 1 < cap; ++i)
    if (!fmb_integrators[i]->projected) {
      if (ops) ops[n] = fmb_integrators[i];
      names[n++] = fmb_integrators[i]->name;
    }
  names[n] = NULL;
  return n;
}

const fmbIntegratorOps* fmb_integrator_for(const fmbModel* m) {
  if (m->solver.formulation == FMB_FORM_PROJECTED ||
      (m->solver.formulation == FMB_FORM_AUTO && fmb_needs_singular_method(m)))
    return projected_backend();
  /* ggl and auto start on a GGL backend; auto leaves it at a singular configuration (fmb_run) */
  return m->solver.integrator;
}

int fmb_integrator_check(const fmbModel* m, fmbParser* p, fmbNode solver) {
  const fmbIntegratorOps* ggl = m->solver.integrator;
  if (ggl && ggl->check && ggl->check(m, p, solver)) return -1;
  const fmbIntegratorOps* proj = projected_backend();
  if (m->solver.formulation == FMB_FORM_PROJECTED && proj && proj->check && proj->check(m, p, solver)) return -1;
  return 0;
}

void fmb_print_stats(const fmbStats* s, FILE* f) {
  if (!s || !f) return;
  fprintf(f,
          "stats: status=%s t_reached=%.10g steps=%ld residuals=%ld jacobians=%ld newton_iters=%ld error_test_fails=%ld "
          "conv_fails=%ld jacobians_reused=%ld cpu_s=%.4f\n",
          s->status_ok ? "ok" : s->interrupted ? "interrupted" : "failed", s->t_reached, s->steps, s->residuals, s->jacobians, s->newton_iters,
          s->error_test_fails, s->conv_fails, s->jacobians_reused, s->cpu_s);
}
