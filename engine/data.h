/* data.h — the state of one run of one model (fmbData; made in data.c, run in step.c), private
 * to the engine: the stepping functions, the run loop (run.c) that writes files on top of them,
 * and the analyses and checks that take their scratch from a data object. Everything a run
 * changes lives here or in its workspace; the model is only read. */
#ifndef FMB_DATA_H
#define FMB_DATA_H

#include <pthread.h>
#include <signal.h>

#include "integrator.h"

#define FMB_DATA_LIVE 0x44424d46u  /* "FMBD" */
#define FMB_DATA_FREED 0x45455246u /* "FREE" */

struct fmbData {
  unsigned magic; /* FMB_DATA_LIVE while usable; FMB_DATA_FREED in quarantine (step.c) */
  const fmbModel* m;
  fmbWorkspace* w;
  int initialised; /* fmb_init succeeded (or got as far as a state at t0: ic_done) */
  int ic_done;     /* the initial conditions were found (fmb_run reports them even if init then fails) */
  double t;
  double *y, *yp; /* the whole state (q, v, multipliers, auxiliary unknowns), as the outputs read it */
  double* atol;   /* ny absolute tolerances (fmb_absolute_tolerances), fixed per model */
  double* row;    /* m->noutput: the outputs' values, t first (fmb_outputs) */
  /* the integrator backend: created at the first advance from (t, y, yp); NULL again after an
     input changed or an advance was interrupted or failed, when `restart` also asks for a
     consistent state at t first */
  const fmbIntegratorOps* ops;
  void* integ;
  int restart;
  int reinit_pending;    /* an input changed: integ starts again (its reinit op) at the next advance */
  fmbStats before;       /* counters of the backends retired so far */
  double* work_before;   /* njoint: work done before the current backend started */
  double* redundant_phi; /* nc: the redundant rows' residuals, checked after every advance */
  /* the state at the start of the advance in progress (the last good one): a switch to the
     projected formulation (formulation: auto) starts from it, and a failure that left values that
     are not finite puts it back (flexmbd.h: "the state is the last good one"); work: the joints'
     work there (njoint). Between advances, fmb_set_input's scratch for its trial projection. */
  int may_switch;
  struct {
    double t, *y, *yp, *work;
  } start;
  struct {
    double t, h;
    char why[1200];
  } switched;
  volatile sig_atomic_t cancel;      /* fmb_data_cancel */
  const volatile sig_atomic_t* stop; /* what the backends watch: &cancel, or fmb_run's flag */
  int quiet;                         /* fmb_run --quiet: no notes (warnings still go out) */
  fmbStats ic;                       /* the initial projection's corrections */
  unsigned char* range_warned;       /* nbody: the body's model_range warning was given (once per run) */
  int interrupted;
  /* the state is fmb_static_data's, not a run's: fmb_advance needs fmb_init */
  int analysis_state;
  int failed; /* the last init or advance failed (fmb_data_stats' status) */
  /* the time spent in init and advance (fmb_data_stats bounds it by cpu_at_init, step.c) */
  double cpu_s;
  int untimed; /* fmb_run's: it times the whole run itself, so init and advance read no clock */
  /* the calling thread's CPU clock at fmb_init and that thread; one_thread: every timed call since
     ran in it (the bound of fmb_data_stats holds only then) */
  double cpu_at_init;
  pthread_t init_thread;
  int one_thread;
};

/* the misuse every call on (m, d) refuses (NULL, freed, another model's): FMB_EXIT_BAD_INPUT with
   *diag naming fn; 0 when usable */
int fmb_data_misused(const fmbModel* m, const fmbData* d, const char* fn, fmbDiag* diag);
/* CPU seconds of the calling thread (fmbData.cpu_s) */
double fmb_thread_cpu_seconds(void);
/* fmb_run's SIGINT flag instead of the data's own cancel flag (NULL: the data's) */
void fmb_data_watch(fmbData* d, const volatile sig_atomic_t* stop);
/* everything fmb_data_new allocated in d, not d itself (data.c; fmb_data_free quarantines d) */
void fmb_data_release(fmbData* d);
/* free a data object that never left the engine (fmb_run's, an analysis wrapper's) at once,
   without the quarantine; NULL or not live: nothing */
void fmb_data_destroy(fmbData* d);
/* an analysis's state (fmb_static_data: the equilibrium at t) becomes d's: readable by
   fmb_data_state, fmb_outputs and fmb_modes_data; the run's integrator is dropped and
   fmb_advance asks for fmb_init (a run starts from the scene's initial conditions) */
void fmb_data_hold_analysis_state(fmbData* d, double t, const double* y, const double* yp);

#endif
