/* regress_jobs.c — each scene of `flexmbd regress` run in a child process and compared with its
 * reference (docs/regression.md). The children come from the pool `sweep` uses (child_pool.c):
 * a crash or a hang costs that scene only (a per-scene time limit, --timeout), and SIGINT or
 * SIGTERM kill every child before regress leaves. The child loads and runs the scene in the
 * forked process (no exec: the scene's overrides travel as memory) and sends what the parent
 * needs through a pipe, one write smaller than PIPE_BUF. */
#include <errno.h>
#include <fcntl.h>
#include <math.h>
#include <signal.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>
#include <unistd.h>

#include "child_pool.h"
#include "regress.h"

typedef struct {
  const RegressJob* job;
  const RegressOptions* o;
  int fd;
} ChildArg;

/* in the child: load (with the reference's and the command line's overrides), run, report */
static void child_run(void* argp) {
  const ChildArg* a = argp;
  const RegressJob* job = a->job;
  const RegressOptions* o = a->o;
  RegressRun res;
  memset(&res, 0, sizeof res);
  const int use_ref = job->ref.present && !(o->bless && o->nsets);
  const int nsets = (use_ref ? job->ref.nsets : 0) + o->nsets;
  const char** sets = calloc((size_t)nsets + 2, sizeof *sets);
  if (!sets) _exit(1);
  int k = 0;
  for (int i = 0; use_ref && i < job->ref.nsets; ++i) sets[k++] = job->ref.sets[i];
  for (int i = 0; i < o->nsets; ++i) sets[k++] = o->sets[i];
  fmbDiag diag;
  memset(&diag, 0, sizeof diag);
  fmbModel* m = fmb_load(job->scene, sets, nsets, fmb_cli_registry(), &diag);
  if (m && job->companion) { /* the same scene at a neighbouring rtol */
    fmbSolverInfo si;
    fmb_model_solver(m, &si);
    fmb_free(m);
    char set[64];
    snprintf(set, sizeof set, "solver.rtol=%.17g", si.rtol * regress_companion_rtol[job->companion - 1]);
    sets[nsets] = set;
    m = fmb_load(job->scene, sets, nsets + 1, fmb_cli_registry(), &diag);
  }
  fmb_cli_note_model(m); /* no reference or report may replace a file it read */
  if (!m) {
    /* an override's message starts with the override itself: the command line's own is the
       caller's mistake (exit 2), a reference's `# set:` one is the scene's (it no longer loads) */
    for (int i = 0; strcmp(diag.file, "--set") == 0 && i < o->nsets; ++i) {
      const size_t n = strlen(o->sets[i]);
      if (strncmp(diag.msg, o->sets[i], n) == 0 && diag.msg[n] == ':') res.bad_set = 1;
    }
    if (diag.line > 0)
      regress_say(res.msg, sizeof res.msg, "%s:%d:%d: %s", diag.file, diag.line, diag.col, diag.msg);
    else
      regress_say(res.msg, sizeof res.msg, "%s", diag.msg);
  } else {
    res.loaded = 1;
    fmb_model_solver(m, &res.solver);
    fmbStats st;
    memset(&st, 0, sizeof st);
    fmbRunOptions ro = {.csv_path = job->csv, .quiet = 1};
    res.exit_code = fmb_run(m, &ro, &st, &diag);
    res.status_ok = st.status_ok && res.exit_code == 0;
    res.t_reached = st.t_reached;
    res.cpu_s = st.cpu_s;
    res.steps = st.steps;
    if (res.exit_code) regress_say(res.msg, sizeof res.msg, "%s", diag.msg);
    fmb_free(m);
  }
  ssize_t w = write(a->fd, &res, sizeof res); /* < PIPE_BUF: one atomic write, never blocks */
  _exit(w == (ssize_t)sizeof res ? 0 : 1);
}

/* the last non-empty line of a child's stderr (the file goes with the temporary folder) */
static void last_line(const char* path, char* out, size_t len) {
  out[0] = '\0';
  FILE* f = fopen(path, "r");
  char line[1024];
  while (f && fgets(line, sizeof line, f)) {
    line[strcspn(line, "\n")] = '\0';
    if (line[0]) snprintf(out, len, "%.400s", line);
  }
  if (f) fclose(f);
}

/* a finished child: job->run filled from its pipe, or the job marked failed with why */
static void finish_job(RegressJob* job, const fmbChildResult* r, const RegressOptions* o) {
  ssize_t got = read(job->pipe_fd, &job->run, sizeof job->run);
  close(job->pipe_fd);
  job->pipe_fd = -1;
  char tail[420];
  last_line(job->err, tail, sizeof tail);
  if (r->status == FMB_CHILD_TIMEOUT) {
    job->failed = 1;
    regress_say(job->why, sizeof job->why, "no result within --timeout %g s: the run was killed", o->timeout_s);
  } else if (r->signal) {
    job->failed = 1;
    regress_say(job->why, sizeof job->why, "the run crashed (signal %d, %s)%s%s", r->signal, strsignal(r->signal),
                tail[0] ? "; its last message: " : "", tail);
  } else if (got != (ssize_t)sizeof job->run) {
    job->failed = 1;
    regress_say(job->why, sizeof job->why, "the run ended without a result (exit %d)%s%s", r->exit_code,
                tail[0] ? "; its last message: " : "", tail);
  }
}

static volatile sig_atomic_t stop_requested;
static void on_stop(int sig) {
  (void)sig;
  stop_requested = 1;
}

int regress_run_all(RegressJob* jobs, int n, const RegressOptions* o) {
  struct sigaction sa, old_int, old_term;
  memset(&sa, 0, sizeof sa);
  sa.sa_handler = on_stop; /* no SA_RESTART: the pool's wait returns at once */
  sigemptyset(&sa.sa_mask);
  sigaction(SIGINT, &sa, &old_int);
  sigaction(SIGTERM, &sa, &old_term);
  fmbPool* pool = fmb_pool_new(o->jobs);
  int next = 0;
  while (pool && !stop_requested && (next < n || fmb_pool_running(pool))) {
    while (fmb_pool_free_slots(pool) > 0 && next < n && !stop_requested) {
      RegressJob* j = &jobs[next];
      const int index = next++;
      if (j->failed || j->bad_input) continue;
      snprintf(j->csv, sizeof j->csv, "%s/%d.csv", o->tmpdir, index);
      snprintf(j->err, sizeof j->err, "%s/%d.err", o->tmpdir, index);
      int fds[2];
      if (pipe(fds) != 0) {
        regress_say(j->why, sizeof j->why, "cannot create a pipe: %s", strerror(errno));
        j->failed = 1;
        continue;
      }
      fcntl(fds[0], F_SETFL, O_NONBLOCK); /* other children hold copies of the write end */
      fcntl(fds[0], F_SETFD, FD_CLOEXEC);
      ChildArg arg = {j, o, fds[1]};
      fmbChildSpec spec = {
          .fn = child_run, .arg = &arg, .stderr_path = j->err, .timeout_s = o->timeout_s, .tag = index};
      if (fmb_pool_start(pool, &spec) != 0) {
        regress_say(j->why, sizeof j->why, "cannot start a process: %s", strerror(errno));
        j->failed = 1;
        close(fds[0]);
      } else {
        j->pipe_fd = fds[0];
      }
      close(fds[1]);
    }
    fmbChildResult r;
    if (fmb_pool_running(pool) && fmb_pool_wait(pool, 1.0, &r) == 1) finish_job(&jobs[r.tag], &r, o);
  }
  fmb_pool_free(pool); /* kills what still runs (an interrupt) */
  for (int i = 0; i < n; ++i)
    if (jobs[i].pipe_fd > 0) close(jobs[i].pipe_fd), jobs[i].pipe_fd = -1;
  sigaction(SIGINT, &old_int, NULL);
  sigaction(SIGTERM, &old_term, NULL);
  return stop_requested ? FMB_EXIT_INTERRUPTED : 0;
}

/* ------------------------------------------------------------------------------------------------
 * Checking a run against its reference
 * ---------------------------------------------------------------------------------------------- */

void regress_check_job(RegressJob* job) {
  const RegressRef* ref = &job->ref;
  const RegressRun* run = &job->run;
  if (!run->loaded && run->bad_set) {
    job->bad_input = 1;
    regress_say(job->why, sizeof job->why, "--set does not apply to this scene: %s", run->msg);
    return;
  }
  if (!run->loaded) {
    job->failed = 1;
    regress_say(job->why, sizeof job->why, "the scene no longer loads: %s", run->msg);
    return;
  }
  fmbTable out;
  if (regress_load_run_csv(job, &out)) return;
  char* w = job->why;
  size_t left = sizeof job->why;
#define WHY(...)                                                  \
  do {                                                            \
    int k_ = snprintf(w, left, __VA_ARGS__);                      \
    if (k_ > 0 && (size_t)k_ < left) w += k_, left -= (size_t)k_; \
  } while (0)
  /* the run must get as far as the reference did, and stop only where the reference stopped */
  const double t_ref = ref->t_reached, t_run = run->t_reached;
  const double eps_t = 1e-9 * fmax(1.0, fabs(t_ref));
  if (t_run < t_ref - eps_t || (ref->status_ok && !run->status_ok)) {
    job->failed = 1;
    WHY("the run stopped early at t = %.10g (the reference reaches t = %.10g%s)%s%s; ", t_run, t_ref,
        ref->status_ok ? "" : " and stopped there too", run->msg[0] ? ": " : "", run->msg);
  } else if (!ref->status_ok && run->status_ok) {
    job->failed = 1;
    WHY("the run now completes (t = %.10g) where the reference stopped at t = %.10g; ", t_run, t_ref);
  }
  /* reference rows outside the run's time span would not be compared at all (column errors are
     taken where both have data): a reference from another time span fails, not passes */
  if (!job->failed && out.nrow > 0 && ref->data.nrow > 0) {
    const double t0 = fmb_table_at(&out, 0, 0), t1 = fmb_table_t_end(&out);
    const double eps = 1e-9 * fmax(1.0, fmax(fabs(t0), fabs(t1)));
    long outside = 0;
    for (long r = 0; r < ref->data.nrow; ++r) {
      const double t = fmb_table_at(&ref->data, r, 0);
      outside += !(t >= t0 - eps && t <= t1 + eps);
    }
    if (outside) {
      job->failed = 1;
      WHY("%ld of the reference's %ld rows lie outside the run's time span [%.10g, %.10g] and cannot be compared; ",
          outside, ref->data.nrow, t0, t1);
    }
  }
  /* columns: missing (in the reference, not in the run), extra (in the run only) */
  int missing = 0, extra = 0;
  for (int c = 1; c < ref->data.ncol; ++c)
    if (fmb_table_col(&out, ref->data.name[c]) < 0) ++missing;
  for (int c = 1; c < out.ncol; ++c)
    if (fmb_table_col(&ref->data, out.name[c]) < 0) ++extra;
  if (missing && extra) {
    job->failed = 1;
    WHY("columns renamed? missing from the run:");
    for (int c = 1; c < ref->data.ncol; ++c)
      if (fmb_table_col(&out, ref->data.name[c]) < 0) WHY(" %s", ref->data.name[c]);
    WHY("; not in the reference:");
    for (int c = 1; c < out.ncol; ++c)
      if (fmb_table_col(&ref->data, out.name[c]) < 0) WHY(" %s", out.name[c]);
    WHY("; ");
  } else if (missing) {
    job->failed = 1;
    WHY("missing column%s (in the reference, not written by the run):", missing > 1 ? "s" : "");
    for (int c = 1; c < ref->data.ncol; ++c)
      if (fmb_table_col(&out, ref->data.name[c]) < 0) WHY(" %s", ref->data.name[c]);
    WHY("; ");
  } else if (extra) {
    job->failed = 1;
    WHY("extra column%s (written by the run, not in the reference; re-bless if intended):", extra > 1 ? "s" : "");
    for (int c = 1; c < out.ncol; ++c)
      if (fmb_table_col(&ref->data, out.name[c]) < 0) WHY(" %s", out.name[c]);
    WHY("; ");
  }
  /* values, at the reference's rows: the worst column is the one nearest to (or furthest beyond)
     its tolerance */
  double worst_ratio = -1.0;
  int nbeyond = 0;
  for (int c = 1; c < ref->data.ncol; ++c) {
    const int oc = fmb_table_col(&out, ref->data.name[c]);
    if (oc < 0) continue;
    fmbColumnError e;
    fmb_table_column_error(&ref->data, c, &out, oc, &e);
    if (e.rows == 0) continue;
    double range, absmax;
    fmb_table_column_scale(&ref->data, c, &range, &absmax);
    const RegressTol* t = regress_find_tol(ref, ref->data.name[c]);
    const double tol = t->atol + t->rtol * range;
    const double ratio = isnan(e.max_abs) ? INFINITY : tol > 0.0 ? e.max_abs / tol : (e.max_abs > 0.0 ? INFINITY : 0.0);
    if (ratio > worst_ratio) {
      worst_ratio = ratio;
      snprintf(job->worst, sizeof job->worst, "%s", ref->data.name[c]);
      job->worst_err = e.max_abs;
      job->worst_tol = tol;
      job->worst_t = e.t_max;
    }
    if (!(e.max_abs <= tol)) {
      if (nbeyond++ == 0) WHY("beyond tolerance:");
      WHY(" %s (max error %.3g > %.3g at t = %.6g)", ref->data.name[c], e.max_abs, tol, e.t_max);
      job->failed = 1;
    }
  }
  if (nbeyond) WHY("; ");
#undef WHY
  if (w > job->why && w[-2] == ';') w[-2] = '\0';
  fmb_table_free(&out);
}
