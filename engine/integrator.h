/* integrator.h — integrators behind an ops table, as body and joint types are (docs/style.md).
 * The stepping API (step.c) owns what every run does: initial conditions, the checks after each
 * advance (mass definiteness, a body's own validity, redundant rows), interrupts, the failure
 * message's frame and the `formulation: auto` switch; the run loop (run.c) the CSV and VTK rows
 * and progress. A backend owns how the state advances from one time a caller asks for to the
 * next and what it needs for that (its own vectors, matrices, solver).
 *
 * Built-in backends (integrator_*.c), listed once in fmb_integrators[] (integrator_select.c) and
 * chosen by fmb_integrator_for():
 *   ida        IDA (BDF, variable order and step) on the GGL index-2 system of system.c, KLU
 *   radau5     Radau IIA of order 5 (3 stages, after Hairer & Wanner's RADAU5) on the same GGL
 *              system, KLU real and complex (solver.integrator: radau5)
 *   radau9     Radau IIA of order 9 (5 stages, RADAU's), the same code (solver.integrator: radau9)
 *   projected  the index-1 form with minimum-norm multipliers and projections onto the
 *              constraints (solver.formulation: projected; passes singular configurations)
 * A backend's name is its ops' .name: solver.integrator's words are the names of the GGL
 * backends in the table, and the messages take the name from there. */
#ifndef FMB_INTEGRATOR_H
#define FMB_INTEGRATOR_H

#include <signal.h>
#include <stddef.h>

#include "internal.h"
#include "schur.h"

typedef struct {
  const fmbModel* m;
  fmbWorkspace* w;
  const volatile sig_atomic_t* stop; /* may be NULL; non-zero: end after the step in progress */
  const double* atol;                /* ny absolute tolerances, one per unknown (tolerance.c) */
} fmbIntegratorSetup;

/* A stop request (fmbIntegratorSetup.stop; NULL: none): set by a signal handler in the same thread
   (fmb_run's SIGINT) or by another thread (fmb_data_cancel), so read and written atomically:
   a lock-free atomic int is what both may touch (C11 7.14.1.1, 7.17.5). */
static inline int fmb_stop_requested(const volatile sig_atomic_t* stop) {
#if defined(__GNUC__)
  return stop && __atomic_load_n(stop, __ATOMIC_RELAXED);
#else
  return stop && *stop;
#endif
}
static inline void fmb_stop_set(volatile sig_atomic_t* stop, int value) {
#if defined(__GNUC__)
  __atomic_store_n(stop, value, __ATOMIC_RELAXED);
#else
  *stop = value;
#endif
}

/* fmbIntegratorOps.advance's results */
enum { FMB_ADVANCE_OK = 0, FMB_ADVANCE_FAILED = -1, FMB_ADVANCE_INTERRUPTED = -2 };

typedef struct fmbIntegratorOps {
  const char* name; /* the word solver.integrator takes (GGL backends), and the one messages use */
  /* 1: integrates the projected formulation (solver.formulation: projected, or auto after a
     singular configuration); 0: a GGL backend, named by solver.integrator */
  int projected;
  /* optional: the backend's cross-key rules, checked at load once the bodies are parsed (e.g.
     radau5 refuses formulation: projected). 0 when the model suits the backend, else -1 with the
     error reported through fmb_parse_error at the offending key of the scene's `solver` node. */
  int (*check)(const fmbModel* m, fmbParser* p, fmbNode solver);
  /* Set up from the consistent initial state y, yp (all ny unknowns: q, v, multipliers, a body's
     auxiliary unknowns) at t0. NULL with *diag set on failure. When m->need_work, the joints'
     powers (fmb_joint_power) are integrated from t0 into m->njoint work integrals. */
  void* (*create)(const fmbIntegratorSetup* s, double t0, const double* y, const double* yp, fmbDiag* diag);
  /* Advance to tout. On return *t_reached is where the state is and y, yp hold it (all ny
     unknowns, the multipliers consistent with it: the outputs read them), also after a failure
     (the last good state). FMB_ADVANCE_FAILED fills why (what stopped, what to try), and *h the
     last step size tried. */
  int (*advance)(void* self, double tout, double* t_reached, double* y, double* yp, double* h, char* why,
                 size_t why_len);
  /* optional: start again from the consistent state y, yp at t0 as create would (no step
     history: first order or first step, the step size estimated anew; the work integrals from 0),
     keeping what does not depend on the state (vectors, matrices, the linear solver's symbolic
     analysis). Called by fmb_set_input's restart instead of destroy + create, so a controller
     that sets an input every millisecond does not pay the set-up each time. The counters (stats)
     go on from where they were. 0, or non-zero with *diag set (the caller then destroys the
     backend and creates a new one). NULL: destroy + create. */
  int (*reinit)(void* self, double t0, const double* y, const double* yp, fmbDiag* diag);
  /* the work integrals at the last t_reached (called only when m->need_work) */
  void (*work)(void* self, double* work);
  /* counters so far (steps, residuals, jacobians, newton_iters, error_test_fails, conv_fails,
     jacobians_reused); the driver fills the rest of fmbStats */
  void (*stats)(const void* self, fmbStats* st);
  /* optional: after each successful advance to t (fmb_run: each output row; e.g. a warning when
     the step rate explodes) */
  void (*after_row)(void* self, double t);
  void (*destroy)(void* self);
} fmbIntegratorOps;

extern const fmbIntegratorOps fmb_integrator_ida;
extern const fmbIntegratorOps fmb_integrator_projected;
extern const fmbIntegratorOps fmb_integrator_radau5;
extern const fmbIntegratorOps fmb_integrator_radau9;

/* every backend, NULL-terminated; the first GGL one is the default of solver.integrator */
extern const fmbIntegratorOps* const fmb_integrators[];

/* 1 when the model's constraint manifold holds a singular configuration near its motion (a
   scan along the manifold from the initial state, engine/singular.c): `formulation: auto` then
   starts on the projected formulation */
int fmb_needs_singular_method(const fmbModel* m);

/* the backend the model's solver settings ask for */
const fmbIntegratorOps* fmb_integrator_for(const fmbModel* m);

/* solver.integrator's words: the GGL backends' names, NULL-terminated, into names[cap] and their
   ops into ops[cap] (same order); returns how many */
int fmb_integrator_choices(const char** names, const fmbIntegratorOps** ops, int cap);

/* the cross-key rules of every backend the model may run on: 0, or -1 with the parse error set */
int fmb_integrator_check(const fmbModel* m, fmbParser* p, fmbNode solver);

#endif
