/* integrator_select.c — which integrator backend a model runs on, and the stats line that names
 * what a run did. One place for the choice (docs/style.md: "a choice made in one place"), apart
 * from the run driver (run.c), so that the backends' table and the rule that picks one can
 * grow without touching the driver. */
#include <stdio.h>

#include "integrator.h"

/* The one list of backends; solver.integrator names a GGL one or auto (the default, the rule below). */
const fmbIntegratorOps* const fmb_integrators[] = {&fmb_integrator_ida, &fmb_integrator_radau5, &fmb_integrator_radau9,
                                                   &fmb_integrator_projected, NULL};

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

/* solver.integrator: auto (the default). The rule, from the matrix of every shipped scene x
   integrator x rtol (bench/auto.sh, docs/performance.md "Integrator auto"):
   - a model with a body that caps the BDF order below 5 (fmbBodyType.max_bdf_order: undamped
     structural modes, i.e. every beam model) runs radau9, Radau IIA with 5 stages (order 9).
     BDF is held at order 2 there and buys accuracy at the second-order rate, while Radau IIA is
     L-stable at any order: radau5 was 15-1600x more accurate than IDA at each beam scene's
     former settings (the ω0 = 15 spin-up at rtol 1e-6: 6.2e-7 against 1.8e-4 m). radau9 against
     radau5 at each beam scene's own settings (error against converged runs; docs/performance.md
     "radau9 as auto's beam backend"): spin-ups ω0 = 1/4/15 9.0e-8/2.7e-7/6.2e-7 m against
     2.2e-7/2.5e-7/6.2e-7 m in a third of the steps, the exact spin-up 1.6e-7 against 1.7e-7 m
     (343 against 827 steps), the slider-crank 1.2e-4 against 3.5e-4 m/s, the flexible pendulum
     1.2e-7 against 1.2e-6 m, the rotor 4.1e-8 against 3.7e-8 m: as accurate or more for about
     the same CPU, and ahead at tighter tolerances (issue 23, "Where it is hardest").
   - a model of rigid bodies runs IDA: BDF up to order 5 has no such cap, and on the four-bar it
     reaches 8e-11 rad at rtol 1e-10 where radau5 stays at 4e-8 (its output rows between large
     steps come from the order-3 collocation polynomial).
   - linear_solver: dense is IDA's only (radau's complex systems), so it keeps IDA. */
static const fmbIntegratorOps* auto_integrator(const fmbModel* m, const char** why) {
  if (m->solver.linear_solver == FMB_LS_DENSE) {
    *why = "integrator auto: linear_solver dense is IDA's only";
    return &fmb_integrator_ida;
  }
  if (m->bdf_order_cap < 5) {
    *why = "integrator auto: a body caps the BDF order below 5 (undamped structural modes); Radau IIA is L-stable "
           "at order 9";
    return &fmb_integrator_radau9;
  }
  *why = "integrator auto: rigid bodies, BDF up to order 5";
  return &fmb_integrator_ida;
}

/* the backend a run starts on, and in words why (fmb_describe_solver: `flexmbd check`) */
static const fmbIntegratorOps* choose(const fmbModel* m, const char** why) {
  if (m->solver.formulation == FMB_FORM_PROJECTED) {
    *why = "formulation: projected";
    return projected_backend();
  }
  if (m->solver.formulation == FMB_FORM_AUTO && fmb_needs_singular_method(m)) {
    *why = "formulation auto: the walk along the constraint manifold finds a singular position; runs at rtol/300";
    return projected_backend();
  }
  /* ggl and auto start on a GGL backend; auto leaves it at a singular configuration (fmb_run) */
  if (m->solver.integrator) {
    *why = "solver.integrator names it";
    return m->solver.integrator;
  }
  return auto_integrator(m, why);
}

const fmbIntegratorOps* fmb_integrator_for(const fmbModel* m) {
  const char* why;
  return choose(m, &why);
}

void fmb_describe_solver(const fmbModel* m, FILE* f) {
  if (!m || !f) return;
  const char* why;
  const fmbIntegratorOps* ops = choose(m, &why);
  fprintf(f, "solver: %s%s (%s)%s\n", ops->name, ops->projected ? " formulation, CVODE with projections" : "", why,
          !ops->projected && m->solver.formulation == FMB_FORM_AUTO && m->nc > 0
              ? "; formulation auto: GGL, the projected one from where a singular position stops it"
              : "");
}

/* solver.integrator: auto checks nothing here: it never picks radau5 or radau9 with linear_solver: dense,
   and formulation: projected runs the projected backend whatever the integrator */
int fmb_integrator_check(const fmbModel* m, fmbParser* p, fmbNode solver) {
  const fmbIntegratorOps* ggl = m->solver.integrator;
  if (ggl && ggl->check && ggl->check(m, p, solver)) return -1;
  const fmbIntegratorOps* proj = projected_backend();
  if (m->solver.formulation == FMB_FORM_PROJECTED && proj && proj->check && proj->check(m, p, solver)) return -1;
  return 0;
}

void fmb_print_stats(const fmbStats* s, FILE* f) {
  if (!s || !f) return;
  fprintf(
      f,
      "stats: status=%s t_reached=%.10g steps=%ld residuals=%ld jacobians=%ld newton_iters=%ld error_test_fails=%ld "
      "conv_fails=%ld jacobians_reused=%ld integrator=%s cpu_s=%.4f warnings=%ld\n",
      s->status_ok     ? "ok"
      : s->interrupted ? "interrupted"
                       : "failed",
      s->t_reached, s->steps, s->residuals, s->jacobians, s->newton_iters, s->error_test_fails, s->conv_fails,
      s->jacobians_reused, s->integrator ? s->integrator : "none", s->cpu_s, s->warnings);
}
