/* sweep_mpi.c — a sweep over MPI ranks: rank 0 plans, keeps the journal, and hands out one run
 * at a time to whichever rank asks (dynamic scheduling: run costs are heavy-tailed, a static
 * split leaves ranks idle, docs/sweep-notes §3.3); every rank, rank 0 too, runs -j K children.
 *
 * Messages (all small, point to point):
 *   worker -> 0  HELLO {slots}          once
 *   worker -> 0  ASK                    once per slot at the start
 *   worker -> 0  ROW "text"             a finished run's journal row; also asks for the next run
 *   0 -> worker  RUN {index, attempt, timeout}   or index -1: no more work for that slot
 * Every rank builds the same plan from the same command line (cheap, deterministic), so only
 * indices travel. Rank 0 polls with MPI_Iprobe between waits on its own children, backing off
 * from 0.2 ms to 20 ms while nothing happens. Built only with MPI (FLEXMBD_HAVE_MPI); without it,
 * or when not started by mpirun/srun, the sweep is the local pool alone (no MPI_Init: a
 * singleton start costs 0.3 s). */
#include <stdio.h>
#include <stdlib.h>
#include <string.h>
#include <time.h>

#include "cli.h"
#include "sweep.h"

#ifdef FLEXMBD_HAVE_MPI
#include <mpi.h>

enum { TAG_HELLO = 1, TAG_ASK, TAG_ROW, TAG_RUN };
static int mpi_up;

int fmb_sweep_mpi_init(fmbSweep* sw) {
  if (MPI_Init(NULL, NULL) != MPI_SUCCESS) {
    fprintf(stderr, "flexmbd sweep: MPI_Init failed\n");
    return -1;
  }
  mpi_up = 1;
  MPI_Comm_rank(MPI_COMM_WORLD, &sw->rank);
  MPI_Comm_size(MPI_COMM_WORLD, &sw->nranks);
  return 0;
}

void fmb_sweep_mpi_finalize(int rc) {
  if (!mpi_up) return;
  mpi_up = 0;
  if (rc == FMB_EXIT_INTERRUPTED) /* the other ranks may be waiting on us: end the job */
    MPI_Abort(MPI_COMM_WORLD, rc);
  MPI_Finalize();
}

/* a finished child into *r (1), or 0 after waiting up to *wait; the wait backs off from 0.2 ms to
   20 ms while nothing happens (`active`: something did this round) */
static int wait_child(fmbPool* pool, double* wait, int active, fmbChildResult* r) {
  int got = 0;
  if (fmb_pool_running(pool)) {
    got = fmb_pool_wait(pool, *wait, r) == 1;
  } else if (!active) {
    struct timespec ts = {0, (long)(*wait * 1e9)};
    nanosleep(&ts, NULL);
  }
  *wait = active || got ? 2e-4 : (*wait * 2 < 0.02 ? *wait * 2 : 0.02);
  return got;
}

static int manager(fmbSweep* sw) {
  long n = 0, ninf = 0;
  long* todo = fmb_sweep_todo(sw, &n, &ninf);
  if (!todo) return FMB_EXIT_BAD_INPUT;
  sw->total_todo = sw->done + n;
  int rc = fmb_sweep_rerun_inflight(sw, todo, ninf); /* alone, before anything else runs */
  fmbPool* pool = rc ? NULL : fmb_pool_new(sw->jobs);
  long next = ninf, outstanding = 0, worker_slots = 0, stops = 0;
  int hellos = 0;
  double wait = 2e-4;
  char* buf = NULL;
  int bufcap = 0;
  while (pool && !*sw->stop) {
    int active = 0;
    while (fmb_pool_free_slots(pool) > 0 && next < n) {
      const long i = todo[next++];
      fmb_journal_started(sw, i);
      if (fmb_sweep_start(sw, pool, i, fmb_sweep_timeout(sw)) != 0) { /* fork failed: the row says so */
        fmbChildResult r = {.tag = i, .status = FMB_CHILD_CRASHED, .exit_code = -1};
        char* row = fmb_sweep_row(sw, &r, sw->starts[sw->first[i]]);
        if (row && fmb_journal_append(sw, i, row) == 0) fmb_sweep_account(sw, (int)r.status, 0.0);
        free(row);
      }
      active = 1;
    }
    int flag = 1;
    MPI_Status st;
    while (MPI_Iprobe(MPI_ANY_SOURCE, MPI_ANY_TAG, MPI_COMM_WORLD, &flag, &st) == MPI_SUCCESS && flag) {
      active = 1;
      int len;
      MPI_Get_count(&st, MPI_CHAR, &len);
      if (len + 1 > bufcap) {
        char* g = realloc(buf, (size_t)len + 1);
        if (!g) break;
        buf = g, bufcap = len + 1;
      }
      MPI_Recv(buf, len, MPI_CHAR, st.MPI_SOURCE, st.MPI_TAG, MPI_COMM_WORLD, MPI_STATUS_IGNORE);
      buf[len] = '\0';
      if (st.MPI_TAG == TAG_HELLO) {
        int slots;
        memcpy(&slots, buf, sizeof slots);
        worker_slots += slots;
        ++hellos;
        continue;
      }
      if (st.MPI_TAG == TAG_ROW) {
        long index = strtol(buf, NULL, 10);
        const char* stf = buf;
        for (int k = 0; k < 3 && stf; ++k) stf = strchr(stf, ',') ? strchr(stf, ',') + 1 : NULL;
        char sname[32] = "";
        if (stf) snprintf(sname, sizeof sname, "%.*s", (int)strcspn(stf, ","), stf);
        const char* wf = buf;
        for (int k = 0; k < 6 && wf; ++k) wf = strchr(wf, ',') ? strchr(wf, ',') + 1 : NULL;
        if (index >= 0 && index < sw->nrun && fmb_journal_append(sw, index, buf) == 0)
          fmb_sweep_account(sw, fmb_child_status_of(sname), wf ? strtod(wf, NULL) : 0.0);
        --outstanding;
      }
      double msg[3] = {-1, 0, 0}; /* index, attempt, timeout (N x the median is known here only) */
      if (next < n) {
        const long i = todo[next++];
        fmb_journal_started(sw, i);
        msg[0] = (double)i;
        msg[1] = sw->starts[sw->first[i]];
        msg[2] = fmb_sweep_timeout(sw);
        ++outstanding;
      } else {
        ++stops;
      }
      MPI_Send(msg, 3, MPI_DOUBLE, st.MPI_SOURCE, TAG_RUN, MPI_COMM_WORLD);
    }
    sw->running = fmb_pool_running(pool) + outstanding;
    if (next >= n && fmb_pool_running(pool) == 0 && outstanding == 0 && hellos == sw->nranks - 1 &&
        stops == worker_slots)
      break;
    fmbChildResult r;
    if (wait_child(pool, &wait, active, &r)) {
      char* row = fmb_sweep_row(sw, &r, sw->starts[sw->first[r.tag]]);
      if (row && fmb_journal_append(sw, r.tag, row) == 0) fmb_sweep_account(sw, (int)r.status, r.wall_s);
      free(row);
    }
    fmb_sweep_progress(sw, 0);
  }
  if (pool && *sw->stop) fmb_sweep_cancel(sw, pool);
  fmb_pool_free(pool);
  free(todo);
  free(buf);
  return rc ? rc : *sw->stop ? FMB_EXIT_INTERRUPTED : 0;
}

/* a worker starts: its slots, then one request per slot */
static void hello(fmbSweep* sw) {
  MPI_Send(&sw->jobs, (int)sizeof sw->jobs, MPI_CHAR, 0, TAG_HELLO, MPI_COMM_WORLD);
  for (int s = 0; s < sw->jobs; ++s) MPI_Send(NULL, 0, MPI_CHAR, 0, TAG_ASK, MPI_COMM_WORLD);
}

/* a worker's runs: rank 0's RUN messages, queued (pump) and taken one by one (next) */
typedef struct {
  fmbSweep* sw;
  double* queue; /* [jobs][3]: index, attempt, timeout; at most one request per slot is out */
  int head, count, stops;
} Remote;
static int remote_pump(void* ctx) {
  Remote* q = ctx;
  int flag = 1, got = 0;
  while (MPI_Iprobe(0, TAG_RUN, MPI_COMM_WORLD, &flag, MPI_STATUS_IGNORE) == MPI_SUCCESS && flag) {
    double msg[3];
    MPI_Recv(msg, 3, MPI_DOUBLE, 0, TAG_RUN, MPI_COMM_WORLD, MPI_STATUS_IGNORE);
    got = 1;
    if (msg[0] < 0) {
      ++q->stops;
    } else if (q->count < q->sw->jobs) {
      memcpy(q->queue + 3 * ((q->head + q->count++) % q->sw->jobs), msg, sizeof msg);
    }
  }
  return got;
}
static int remote_next(void* ctx, long* index, int* attempt, double* timeout) {
  Remote* q = ctx;
  if (!q->count) return q->stops >= q->sw->jobs ? -1 : 0;
  const double* m = q->queue + 3 * q->head;
  *index = (long)m[0], *attempt = (int)m[1], *timeout = m[2];
  q->head = (q->head + 1) % q->sw->jobs;
  --q->count;
  return 1;
}
static void remote_done(void* ctx, const fmbChildResult* res, char* row) {
  (void)ctx, (void)res;
  MPI_Send(row, row ? (int)strlen(row) : 0, MPI_CHAR, 0, TAG_ROW, MPI_COMM_WORLD);
  free(row);
}
static int worker_serve(fmbSweep* sw) {
  Remote q = {sw, calloc((size_t)sw->jobs * 3, sizeof(double)), 0, 0, 0};
  if (!q.queue) return FMB_EXIT_BAD_INPUT;
  hello(sw);
  const fmbRunFeed feed = {remote_next, remote_done, remote_pump, NULL, &q};
  const int rc = fmb_sweep_serve_feed(sw, &feed);
  free(q.queue);
  return rc;
}

/* a finished run's row to rank 0 (which takes it as a request for the next run too) */
static void send_row(fmbSweep* sw, const fmbChildResult* r, int attempt) {
  char* row = fmb_sweep_row(sw, r, attempt);
  MPI_Send(row, row ? (int)strlen(row) : 0, MPI_CHAR, 0, TAG_ROW, MPI_COMM_WORLD);
  free(row);
}

/* a worker with a process per run */
static int worker(fmbSweep* sw) {
  fmbPool* pool = fmb_pool_new(sw->jobs);
  int* attempt = calloc((size_t)sw->nrun, sizeof *attempt);
  Remote q = {sw, calloc((size_t)sw->jobs * 3, sizeof(double)), 0, 0, 0};
  int rc = pool && attempt && q.queue ? 0 : FMB_EXIT_BAD_INPUT;
  if (!rc) hello(sw);
  int more = 1;
  double wait = 2e-4;
  while (!rc && !*sw->stop && (more || fmb_pool_running(pool))) {
    int active = remote_pump(&q), got = 0;
    long i;
    int att;
    double timeout;
    while (fmb_pool_free_slots(pool) > 0 && (got = remote_next(&q, &i, &att, &timeout)) > 0) {
      active = 1;
      attempt[i] = att;
      if (fmb_sweep_start(sw, pool, i, timeout) != 0) {
        fmbChildResult r = {.tag = i, .status = FMB_CHILD_CRASHED, .exit_code = -1};
        send_row(sw, &r, attempt[i]);
      }
    }
    if (got < 0) more = 0;
    fmbChildResult r;
    if (wait_child(pool, &wait, active, &r)) send_row(sw, &r, attempt[r.tag]);
  }
  fmb_pool_free(pool); /* kills what still runs (an interrupt) */
  free(attempt), free(q.queue);
  return rc ? rc : *sw->stop ? FMB_EXIT_INTERRUPTED : 0;
}

int fmb_sweep_mpi(fmbSweep* sw, int rc0) {
  MPI_Bcast(&rc0, 1, MPI_INT, 0, MPI_COMM_WORLD);
  if (rc0) return rc0;
  return sw->rank == 0 ? manager(sw) : sw->serve ? worker_serve(sw) : worker(sw);
}

#endif
