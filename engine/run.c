/* run.c — fmb_run: a whole run into files, as a loop over the stepping API (step.c): fmb_init,
 * then for every output time fmb_advance and the row (the CSV through the one writer, output.c;
 * the animation's frame, vtk.c), the progress line and the stop flag of a signal handler. What a
 * step does (the backends, the checks, the `formulation: auto` switch) is step.c's; a program that
 * steps by itself and writes the rows through fmb_write_table gets the same bytes (the test
 * tests/core/test_step.c). On any failure every row so far is already on disk and the message
 * says when, why, and what to try. */
#include <errno.h>
#include <math.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>
#include <time.h>
#include <unistd.h>

#include "data.h"

/* a CSV row that could not be written (wr < 0) or held a non-finite value (wr > 0). The latter names
   the first column that is not finite, and tells a solution that blew up (the state itself is not
   finite) from a type's output op that returned NaN or Inf from a finite state (a plugin bug or a
   quantity undefined there), where advice about the run's tolerances would mislead. */
static int row_failed(const fmbModel* m, fmbData* d, int wr, fmbDiag* diag) {
  const double t = d->t;
  if (wr < 0)
    fmb_diag_set(diag, FMB_EXIT_SOLVER, m->path, 0, 0, "writing the output failed at t = %.6g (disk full?)", t);
  else if (wr > 0) {
    fmb_outputs_eval(m, d->w, t, d->y, d->yp, d->row);
    int col = 1;
    while (col < m->noutput && isfinite(d->row[col])) ++col;
    const char* name = col < m->noutput ? m->output[col].name : "?";
    int state_finite = 1;
    for (int i = 0; i < m->ny && state_finite; ++i) state_finite = isfinite(d->y[i]) && isfinite(d->yp[i]);
    const fmbOutKind kind = col < m->noutput ? m->output[col].kind : FMB_OUT_BODY;
    if (state_finite && (kind == FMB_OUT_BODY || kind == FMB_OUT_JOINT))
      fmb_diag_set(diag, FMB_EXIT_SOLVER, m->path, 0, 0,
                   "stopped at t = %.6g: output '%s' is not finite (%g) while the state is: its type's output op "
                   "returned it (a bug in the type, or a quantity undefined in this state); the rows before are kept",
                   t, name, col < m->noutput ? d->row[col] : NAN);
    else
      fmb_diag_set(diag, FMB_EXIT_SOLVER, m->path, 0, 0,
                   "stopped at t = %.6g: output '%s' is not finite (the solution blew up): check the initial values "
                   "and parameters for an extreme value (e.g. a zero-length spring), try a tighter rtol or a smaller "
                   "solver.max_step, and check the model for instability",
                   t, name);
  }
  return wr != 0;
}

/* the CSV row, then the animation's frame (if any): what row_failed reads */
static int write_outputs(fmbCsv* csv, fmbVtk* vtk, const fmbModel* m, fmbData* d) {
  int wr = fmb_csv_row(csv, m, d->w, d->t, d->y, d->yp);
  if (wr == 0 && vtk && fmb_vtk_step(vtk, m, d->w, d->t, d->y)) wr = -1;
  return wr;
}

/* The progress line, a message like any other (fmb_warn): silent for the first `after` seconds
   of wall time (short runs print nothing), then at most 5 updates a second when stderr is a
   terminal (where the command line's handler rewrites the line in place, tools/cli.c) and one a
   second elsewhere (--progress into a file or pipe: one line each). */
typedef struct {
  int on, tty;
  double after, start, last;
} Progress;

static double wall_seconds(void) {
  struct timespec ts;
  clock_gettime(CLOCK_MONOTONIC, &ts);
  return (double)ts.tv_sec + 1e-9 * (double)ts.tv_nsec;
}

static void progress_update(Progress* pr, const fmbModel* m, fmbData* d) {
  if (!pr->on) return;
  const double now = wall_seconds(), elapsed = now - pr->start;
  if (elapsed < pr->after || now - pr->last < (pr->tty ? 0.2 : 1.0)) return;
  fmbStats sofar;
  fmb_data_stats(d, &sofar);
  const double done = (d->t - m->solver.t0) / (m->solver.t_end - m->solver.t0);
  char remaining[32] = "?";
  if (done > 0.0) snprintf(remaining, sizeof remaining, "%.1f s", elapsed * (1.0 - done) / done);
  fmb_warn(d->w, "progress: t = %.6g of %g (%.0f %%), %ld steps, %.1f s elapsed, ~%s remaining", d->t, m->solver.t_end,
           100.0 * done, sofar.steps, elapsed, remaining);
  pr->last = now;
}

long fmb_row_count(const fmbModel* m) {
  if (!m) return 0;
  const fmbSolverSettings* so = &m->solver;
  return (long)ceil((so->t_end - so->t0) / so->output_step - 1e-9) + 1;
}

double fmb_row_time(const fmbModel* m, long k) {
  const long n = fmb_row_count(m);
  if (k < 0 || k >= n) return NAN;
  return k == n - 1 ? m->solver.t_end : m->solver.t0 + (double)k * m->solver.output_step;
}

/* what the loop does with a row at d's time: 0, or an exit code with *diag set (FMB_EXIT_INTERRUPTED
   without: the caller stops there) */
typedef int (*RowHook)(void* user, const fmbModel* m, fmbData* d, fmbDiag* diag);

/* The one loop over the output grid (fmb_run's file, fmb_run_rows' callback), from an initialised
   d: the row at t0, then fmb_advance to each later row time and its row, the progress line, a stop
   request after each row. *rows counts the rows the hook took. */
static int row_loop(const fmbModel* m, fmbData* d, RowHook hook, void* user, Progress* progress,
                    const volatile sig_atomic_t* stop, long* rows, fmbDiag* diag) {
  const long n = fmb_row_count(m);
  for (long k = 0; k < n; ++k) {
    int rc = k > 0 ? fmb_advance(m, d, fmb_row_time(m, k), diag) : 0;
    if (!rc) rc = hook(user, m, d, diag);
    if (rc) return rc;
    ++*rows;
    if (progress) progress_update(progress, m, d);
    if (k + 1 < n && fmb_stop_requested(stop)) return FMB_EXIT_INTERRUPTED;
  }
  return 0;
}

typedef struct {
  fmbRowFn fn;
  void* user;
} RowCallback;

/* fmb_run_rows' hook: the row's values (fmb_outputs) to the caller's function */
static int deliver_row(void* user, const fmbModel* m, fmbData* d, fmbDiag* diag) {
  const RowCallback* cb = user;
  if (fmb_outputs_eval(m, d->w, d->t, d->y, d->yp, d->row)) {
    row_failed(m, d, 1, diag);
    return FMB_EXIT_SOLVER;
  }
  return cb->fn(cb->user, d->t, d->row + 1, m->noutput - 1) ? FMB_EXIT_INTERRUPTED : 0;
}

int fmb_run_rows(const fmbModel* m, fmbData* d, fmbRowFn row, void* user, fmbDiag* diag) {
  fmbDiag local;
  if (!diag) diag = &local;
  memset(diag, 0, sizeof *diag);
  if (fmb_data_misused(m, d, "fmb_run_rows", diag)) return FMB_EXIT_BAD_INPUT;
  if (!row) {
    fmb_diag_set(diag, FMB_EXIT_BAD_INPUT, m->path, 0, 0, "fmb_run_rows: no row function (NULL)");
    return FMB_EXIT_BAD_INPUT;
  }
  /* timed once for the whole run, as fmb_run times itself: not twice a row (a system call each
     on a virtual machine: 1001 rows of scenes/pendulum.yaml cost 1.6x the CLI's CPU from Python) */
  const int untimed = d->untimed;
  const double c0 = untimed ? 0.0 : fmb_thread_cpu_seconds();
  d->untimed = 1;
  int rc = fmb_init(m, d, diag);
  RowCallback cb = {row, user};
  long rows = 0;
  if (!rc) rc = row_loop(m, d, deliver_row, &cb, NULL, d->stop, &rows, diag);
  d->untimed = untimed;
  if (!untimed) d->cpu_s += fmb_thread_cpu_seconds() - c0;
  if (rc && rc != FMB_EXIT_INTERRUPTED) return rc;
  if (rc == FMB_EXIT_INTERRUPTED && !diag->code) {
    d->interrupted = d->failed = 1; /* fmb_data_stats: status=interrupted */
    fmb_diag_set(diag, rc, m->path, 0, 0,
                 "interrupted at t = %.6g (by the row function): the %ld rows so far were delivered", d->t, rows);
  }
  return rc;
}

/* fmb_run's hook: the CSV row and the animation's frame (the header before the first row) */
typedef struct {
  fmbCsv* csv;
  fmbVtk* vtk;
  int header_done;
} FileRows;

static int write_row(void* user, const fmbModel* m, fmbData* d, fmbDiag* diag) {
  FileRows* f = user;
  if (!f->header_done++ && fmb_csv_header(f->csv, m)) {
    row_failed(m, d, -1, diag);
    return FMB_EXIT_SOLVER;
  }
  return row_failed(m, d, write_outputs(f->csv, f->vtk, m, d), diag) ? FMB_EXIT_SOLVER : 0;
}

int fmb_run(const fmbModel* m, const fmbRunOptions* opt, fmbStats* st, fmbDiag* diag) {
  fmbStats local_stats;
  fmbDiag local_diag;
  if (!st) st = &local_stats;
  if (!diag) diag = &local_diag;
  if (!m) {
    memset(st, 0, sizeof *st);
    memset(diag, 0, sizeof *diag);
    fmb_diag_set(diag, FMB_EXIT_BAD_INPUT, "", 0, 0, "fmb_run: no model (NULL)");
    return FMB_EXIT_BAD_INPUT;
  }
  const clock_t c0 = clock();
  memset(st, 0, sizeof *st);
  memset(diag, 0, sizeof *diag);
  st->t_reached = m->solver.t0;
  const int quiet = opt && opt->quiet;
  const volatile sig_atomic_t* stop = opt ? opt->stop : NULL;
  fmbCsv* csv = fmb_csv_open_guarded(opt ? opt->csv_path : NULL, m->inputs, diag);
  if (!csv) return diag->code ? diag->code : FMB_EXIT_BAD_INPUT;
  const char* vtk_dir = (opt && opt->vtk_dir) ? opt->vtk_dir : (m->vtk_dir[0] ? m->vtk_dir : NULL);
  fmbVtk* vtk = NULL;
  if (vtk_dir && (vtk = fmb_vtk_open(m, vtk_dir, diag))) fmb_vtk_set_every(vtk, opt ? opt->vtk_every : 1);
  if (vtk_dir && !vtk) {
    fmb_csv_close(csv);
    return diag->code ? diag->code : FMB_EXIT_SOLVER;
  }
  fmbData* d = fmb_data_new(m, diag);
  if (!d) {
    fmb_vtk_close(vtk);
    fmb_csv_close(csv);
    return diag->code ? diag->code : FMB_EXIT_SOLVER;
  }
  d->quiet = quiet;
  d->untimed = 1; /* st->cpu_s is the whole run's, read here at the start and the end */
  fmb_data_watch(d, stop);
  Progress progress = {opt && opt->progress && !quiet, isatty(fileno(stderr)), opt ? opt->progress_after_s : 0.0,
                       wall_seconds(), 0.0};

  int rc = fmb_init(m, d, diag);
  if (d->ic_done && !quiet) {
    fmb_warn(d->w, "initial conditions: position correction %.3g, velocity correction %.3g",
             d->ic.ic_position_correction, d->ic.ic_velocity_correction);
    int nredundant = 0;
    const unsigned char* redundant = fmb_workspace_redundant(d->w, &nredundant);
    if (nredundant) {
      char rows[600];
      fmb_name_rows(m, redundant, rows, sizeof rows);
      fmb_warn(d->w,
               "redundant constraints: %s repeat%s the other joints' equations: left out of the equations, their "
               "share of the reactions by the minimum-norm rule",
               rows, nredundant == 1 ? "s" : "");
    }
  }
  if (rc || fmb_stop_requested(stop)) goto done;
  FileRows files = {csv, vtk, 0};
  rc = row_loop(m, d, write_row, &files, &progress, stop, &st->rows_written, diag);
  if (rc == FMB_EXIT_INTERRUPTED && !diag->code) rc = 0; /* a stop between rows: said below */

done:
  if (fmb_csv_flush(csv) && !rc) { /* the last rows gathered (output.c): a failure says so like any row's */
    row_failed(m, d, -1, diag);
    rc = FMB_EXIT_SOLVER;
  }
  if (rc == FMB_EXIT_INTERRUPTED || (fmb_stop_requested(stop) && !rc)) {
    rc = FMB_EXIT_INTERRUPTED;
    memset(diag, 0, sizeof *diag);
    fmb_diag_set(diag, rc, m->path, 0, 0,
                 "interrupted at t = %.6g (SIGINT or SIGTERM): the %ld rows written so far are kept", d->t,
                 st->rows_written);
  }
  const long rows = st->rows_written;
  fmb_data_stats(d, st);
  st->rows_written = rows;
  st->interrupted = rc == FMB_EXIT_INTERRUPTED;
  st->status_ok = rc == 0;
  fmb_data_destroy(d);
  fmb_vtk_close(vtk);
  if (fmb_csv_close(csv) && !rc) {
    fmb_diag_set(diag, FMB_EXIT_SOLVER, m->path, 0, 0, "could not put the output in place: %s", strerror(errno));
    rc = FMB_EXIT_SOLVER;
    st->status_ok = 0;
  }
  st->cpu_s = (double)(clock() - c0) / CLOCKS_PER_SEC;
  return rc;
}
