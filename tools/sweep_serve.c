/* sweep_serve.c — `flexmbd sweep --runner serve`: one persistent `flexmbd run SCENE --serve` per
 * slot (tools/run_serve.c) instead of a process per run. A run costs what it computes plus a line
 * each way through a pipe, not a process start (exec and linking, ~3 ms of CPU: as much as a
 * four-bar run). Isolation is per runner: a crash or a hang (killed at the run's deadline) ends
 * the runner, the run in flight gets its row (`crashed`, `timeout`), and a fresh runner takes the
 * slot. The rows are those of the spawned runs, bit for bit (the same fmb_load and fmb_run; tested).
 * Runners are children of the pool (child_pool.c: process group, PDEATHSIG, RLIMIT_AS), talked to
 * through pipes; the wait is poll(2) on their answers, which SIGINT/SIGTERM interrupt. */
#define _GNU_SOURCE /* pipe2 */
#include <errno.h>
#include <fcntl.h>
#include <poll.h>
#include <signal.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>
#include <unistd.h>

#include "cli.h"
#include "serve_protocol.h"
#include "sweep.h"

typedef struct {
  int alive;
  int in, out;  /* the runner's requests (its fd 3, we write) and answers (its fd 4, we read) */
  long index;   /* the run in flight, -1 none */
  uint64_t seq; /* the number of its request, repeated by the answer */
  int attempt;
  double start, deadline;
  int timed_out;
  int reaped; /* its process ended and was collected (res) */
  fmbChildResult res;
  char buf[FMB_SERVE_MAX_ANSWER + 128]; /* its answer so far */
  size_t n;
  const char* broken; /* why its answers are not taken any more (it is being killed) */
} Runner;

static uint64_t next_seq; /* numbers the requests of this sweep */

static int start_runner(fmbSweep* sw, fmbPool* pool, Runner* r, int slot) {
  int to[2], from[2];
  if (pipe2(to, O_CLOEXEC) != 0) return -1;
  if (pipe2(from, O_CLOEXEC) != 0) {
    close(to[0]), close(to[1]);
    return -1;
  }
  char err[4300];
  snprintf(err, sizeof err, "%s/logs/runner-%d.err", sw->dir, slot);
  char* argv[FMB_SWEEP_MAX_ARGS];
  char sets[FMB_SWEEP_MAX_PATHS][FMB_SWEEP_SET_LEN];
  const int npath = sw->plan.npath;
  sw->plan.npath = 0; /* the fixed --set and plugins only: the swept values come per run */
  int n = fmb_sweep_argv(sw, 0, "run", NULL, argv, sets);
  sw->plan.npath = npath;
  memmove(argv + 4, argv + 3, (size_t)(n - 2) * sizeof *argv); /* ... SCENE --serve --set ... */
  argv[3] = "--serve";
  fmbChildSpec spec = {.argv = argv,
                       .stderr_path = err,
                       .use_fds = 1,
                       .request_fd = to[0],
                       .answer_fd = from[1],
                       .mem_limit_mb = sw->mem_limit_mb,
                       .tag = slot};
  const int rc = fmb_pool_start(pool, &spec);
  close(to[0]), close(from[1]);
  if (rc != 0) {
    close(to[1]), close(from[0]);
    return -1;
  }
  *r = (Runner){.alive = 1, .in = to[1], .out = from[0], .index = -1};
  fcntl(r->out, F_SETFL, O_NONBLOCK); /* read whatever each runner has, never wait on one */
  return 0;
}

/* hands run `index` to an idle runner: 0, or -1 (its pipe is gone: it died) */
static int dispatch(fmbSweep* sw, Runner* r, long index, int attempt, double timeout) {
  char out[4300];
  char sets[FMB_SWEEP_MAX_PATHS][FMB_SWEEP_SET_LEN];
  const char* fields[1 + FMB_SWEEP_MAX_PATHS];
  snprintf(out, sizeof out, "%s/series/%016llx.csv", sw->dir, (unsigned long long)sw->id[index]);
  fields[0] = out;
  for (int k = 0; k < sw->plan.npath; ++k) {
    snprintf(sets[k], sizeof sets[k], "%s=%s", sw->plan.path[k], fmb_plan_value(&sw->plan, index, k));
    fields[1 + k] = sets[k];
  }
  size_t n;
  char* line = fmb_serve_request(++next_seq, fields, 1 + sw->plan.npath, &n);
  if (!line) return -1;
  r->index = index;
  r->seq = next_seq;
  r->attempt = attempt;
  r->start = fmb_pool_now();
  r->deadline = timeout > 0 ? r->start + timeout : 0.0;
  r->timed_out = 0;
  r->n = 0;
  int rc = 0;
  for (const char* p = line; n > 0;) {
    ssize_t w = write(r->in, p, n);
    if (w < 0 && errno == EINTR) continue;
    if (w <= 0) {
      rc = -1;
      break;
    }
    p += w, n -= (size_t)w;
  }
  free(line);
  return rc;
}

static void record(fmbSweep* sw, const fmbRunFeed* feed, const Runner* r, const fmbChildResult* res, const char* stats,
                   const char* msg) {
  feed->done(feed->ctx, res, fmb_sweep_row_served(sw, res, r->attempt, stats, msg));
}

/* a runner's answer for its run in flight (serve_protocol.h) */
static void answered(fmbSweep* sw, const fmbRunFeed* feed, Runner* r, int rc, const char* stats, const char* msg) {
  fmbChildResult res = {.tag = r->index, .exit_code = rc, .wall_s = fmb_pool_now() - r->start};
  res.status = rc == 0   ? FMB_CHILD_OK
               : rc == 2 ? FMB_CHILD_BAD_INPUT
               : rc == 3 ? FMB_CHILD_SOLVER_STOPPED
                         : FMB_CHILD_CRASHED;
  record(sw, feed, r, &res, stats, msg);
  r->index = -1;
}

/* a runner ended (crash, kill at a deadline): reaped, its run in flight recorded */
static void ended(fmbSweep* sw, const fmbRunFeed* feed, fmbPool* pool, Runner* runners, int slot) {
  Runner* r = &runners[slot];
  close(r->in), close(r->out);
  r->alive = 0;
  fmbChildResult got_res;
  while (!r->reaped && fmb_pool_wait(pool, 5.0, &got_res) == 1) { /* another one may end first */
    runners[got_res.tag].reaped = 1;
    runners[got_res.tag].res = got_res;
  }
  const int got = r->reaped;
  const fmbChildResult res = r->res;
  if (r->index < 0) return;
  char tail[600] = "", err[4300], line[600];
  snprintf(err, sizeof err, "%s/logs/runner-%d.err", sw->dir, slot);
  FILE* f = fopen(err, "r");
  while (f && fgets(line, sizeof line, f))
    if (line[0] != '\n') snprintf(tail, sizeof tail, "%.*s", (int)strcspn(line, "\n"), line);
  if (f) fclose(f);
  fmbChildResult run = {.tag = r->index,
                        .exit_code = got == 1 ? res.exit_code : -1,
                        .signal = got == 1 ? res.signal : 0,
                        .wall_s = fmb_pool_now() - r->start};
  run.status = r->timed_out ? FMB_CHILD_TIMEOUT : FMB_CHILD_CRASHED;
  /* the row's message says what happened (fmb_sweep_row_served); the runner's last words follow */
  char why[800];
  snprintf(why, sizeof why, "%s%s%s", r->broken ? r->broken : "", r->broken && tail[0] ? ": " : "", tail);
  record(sw, feed, r, &run, "", r->timed_out ? "" : why);
  r->index = -1;
}

int fmb_sweep_serve_feed(fmbSweep* sw, const fmbRunFeed* feed) {
  fmbPool* pool = fmb_pool_new(sw->jobs);
  Runner* runners = calloc((size_t)sw->jobs, sizeof *runners);
  struct pollfd* pfd = calloc((size_t)sw->jobs, sizeof *pfd);
  signal(SIGPIPE, SIG_IGN); /* a runner that died: its pipe says so by EPIPE */
  int more = 1;             /* the feed may still hand out runs */
  int failed = 0;           /* no runner could be started */
  double wait = 2e-4;       /* with a pump (MPI): how long poll waits, backing off to 20 ms */
  while (pool && runners && pfd && !*sw->stop) {
    int busy = 0, active = feed->pump ? feed->pump(feed->ctx) : 0;
    for (int k = 0; k < sw->jobs; ++k) {
      Runner* r = &runners[k];
      if (!r->alive && more && start_runner(sw, pool, r, k) != 0) {
        int alive = 0;
        for (int j = 0; j < sw->jobs; ++j) alive += runners[j].alive;
        if (!alive) { /* no runner at all: the runs left stay without a row, for a resume */
          fprintf(stderr, "flexmbd sweep: cannot start a runner (%s): stopping; run the command again to resume\n",
                  strerror(errno));
          more = 0, failed = 1;
        }
        break;
      }
      if (r->alive && r->index < 0 && more) {
        long index;
        int attempt;
        double timeout;
        const int got = feed->next(feed->ctx, &index, &attempt, &timeout);
        if (got < 0) more = 0;
        if (got > 0) {
          active = 1;
          if (dispatch(sw, r, index, attempt, timeout) != 0) ended(sw, feed, pool, runners, k);
        }
      }
      busy += r->alive && r->index >= 0;
    }
    sw->running = busy;
    if (!busy && !more) break;
    /* wait for an answer, a deadline, or a signal */
    double now = fmb_pool_now(), wake = now + (feed->pump ? wait : 0.5);
    int np = 0;
    for (int k = 0; k < sw->jobs; ++k) {
      Runner* r = &runners[k];
      if (!r->alive) continue;
      pfd[np++] = (struct pollfd){.fd = r->out, .events = POLLIN};
      if (r->index >= 0 && r->deadline > 0 && r->deadline < wake) wake = r->deadline;
    }
    int ms = (int)((wake - now) * 1e3) + 1;
    const int ready = poll(pfd, (nfds_t)np, ms < 0 ? 0 : ms);
    if (ready < 0 && errno != EINTR) break;
    wait = active || ready > 0 ? 2e-4 : (wait * 2 < 0.02 ? wait * 2 : 0.02);
    now = fmb_pool_now();
    for (int k = 0; k < sw->jobs; ++k) {
      Runner* r = &runners[k];
      if (!r->alive) continue;
      /* the answer first, the deadline after: an answer that came while poll overslept the
         deadline (it wakes up to 1 ms late) is the run's result, and a runner is only ever
         killed with its run still in flight. Killing it and then taking the answer left a dead
         runner idle, and the next run handed to it got a false `crashed` row. */
      ssize_t got = read(r->out, r->buf + r->n, sizeof r->buf - 1 - r->n);
      if (got == 0 || (got < 0 && errno != EAGAIN && errno != EINTR)) {
        ended(sw, feed, pool, runners, k);
        continue;
      }
      if (got > 0 && !r->timed_out && !r->broken) { /* a killed runner's last words are not its run's result */
        r->n += (size_t)got;
        uint64_t seq;
        int rc;
        char stats[2100], msg[FMB_SERVE_MAX_ANSWER];
        const long used = fmb_serve_parse_answer(r->buf, r->n, &seq, &rc, stats, sizeof stats, msg, sizeof msg);
        if (used != 0 && (used < 0 || r->index < 0 || seq != r->seq || (size_t)used != r->n)) {
          /* not the answer to the request in flight (or more than it): this runner is out of step
             with us, whatever the cause; none of its words are taken, it is replaced */
          r->broken = used < 0 ? "the runner's answer was malformed" : "the runner answered out of turn";
          fmb_pool_kill(pool, k); /* its pipe closes: ended() on a later pass */
        } else if (used > 0) {
          answered(sw, feed, r, rc, stats, msg);
          r->n = 0;
        }
      }
      if (r->index >= 0 && r->deadline > 0 && now >= r->deadline && !r->timed_out) {
        r->timed_out = 1;
        fmb_pool_kill(pool, k); /* its pipe closes: ended() on a later pass */
      }
    }
    fmb_sweep_progress(sw, 0);
  }
  if (pool && *sw->stop) {
    for (int k = 0; k < sw->jobs; ++k)
      if (runners[k].alive && runners[k].index >= 0 && feed->cancelled) feed->cancelled(feed->ctx, runners[k].index);
    fmb_pool_kill_all(pool, 0.0);
  }
  for (int k = 0; runners && k < sw->jobs; ++k)
    if (runners[k].alive) close(runners[k].in), close(runners[k].out); /* EOF: the runner ends */
  fmb_pool_free(pool);
  free(runners), free(pfd);
  return *sw->stop ? FMB_EXIT_INTERRUPTED : failed ? FMB_EXIT_SOLVER : 0;
}

/* the local feed: the runs still to do, rows into the journal */
typedef struct {
  fmbSweep* sw;
  const long* todo;
  long next, n;
} Local;
static int local_next(void* ctx, long* index, int* attempt, double* timeout) {
  Local* l = ctx;
  if (l->next >= l->n || l->sw->disk_full) return -1; /* a full disk: nothing more is started */
  *index = l->todo[l->next++];
  fmb_journal_started(l->sw, *index);
  *attempt = l->sw->starts[l->sw->first[*index]];
  *timeout = fmb_sweep_timeout(l->sw);
  return 1;
}
static void local_done(void* ctx, const fmbChildResult* res, char* row) {
  Local* l = ctx;
  if (row && fmb_journal_append(l->sw, res->tag, row) == 0) fmb_sweep_account(l->sw, (int)res->status, res->wall_s);
  free(row);
}
static void local_cancelled(void* ctx, long index) { fmb_journal_cancelled(((Local*)ctx)->sw, index); }

/* a worker rank's feed: rank 0's tasks (farm.h), rows back to rank 0 */
static int remote_next(void* ctx, long* index, int* attempt, double* timeout) {
  fmbFarmTask task;
  const int got = fmb_farm_inbox_next(ctx, &task);
  if (got > 0) *index = task.index, *attempt = task.attempt, *timeout = task.timeout_s;
  return got;
}
static void remote_done(void* ctx, const fmbChildResult* res, char* row) {
  (void)res;
  fmb_farm_inbox_reply(ctx, row, row ? (int)strlen(row) : 0);
  free(row);
}
static int remote_pump(void* ctx) { return fmb_farm_inbox_pump(ctx); }

int fmb_sweep_serve(fmbSweep* sw, const fmbFarmTransport* t) {
  if (t && sw->rank == 0) return fmb_sweep_farm(sw, t); /* the journal's keeper: a process per run */
  if (t) {
    fmbFarmInbox* q = fmb_farm_inbox_new(t, sw->jobs);
    if (!q) return FMB_EXIT_BAD_INPUT;
    const fmbRunFeed feed = {remote_next, remote_done, remote_pump, NULL, q};
    const int rc = fmb_sweep_serve_feed(sw, &feed);
    fmb_farm_inbox_free(q);
    return rc;
  }
  long n = 0, ninf = 0;
  long* todo = fmb_sweep_todo(sw, &n, &ninf);
  if (!todo) return FMB_EXIT_BAD_INPUT;
  sw->total_todo = sw->done + n;
  int rc = fmb_sweep_rerun_inflight(sw, todo, ninf); /* alone, each in a fresh process */
  Local local = {sw, todo, ninf, n};
  const fmbRunFeed feed = {local_next, local_done, NULL, local_cancelled, &local};
  if (!rc) rc = fmb_sweep_serve_feed(sw, &feed);
  free(todo);
  return rc;
}
