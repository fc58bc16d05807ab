/* farm.c — tasks as child processes over this process and the other ranks (farm.h). Rank 0
 * polls for messages between waits on its own children, backing off from 0.2 ms to 20 ms while
 * nothing happens; alone (no transport) it sleeps in the pool's wait. */
#include "farm.h"

#include <stdlib.h>
#include <string.h>
#include <time.h>

#include "cli.h"

/* the attempt of each local child, by tag (a handful of slots: a linear search) */
typedef struct {
  long* tag;
  int* attempt;
  int n;
} Attempts;
static void remember(Attempts* a, long tag, int attempt, int jobs) {
  for (int k = 0; k < a->n; ++k)
    if (a->tag[k] == tag) {
      a->attempt[k] = attempt;
      return;
    }
  if (a->n < jobs) a->tag[a->n] = tag, a->attempt[a->n++] = attempt;
}
static int recall(Attempts* a, long tag) {
  for (int k = 0; k < a->n; ++k)
    if (a->tag[k] == tag) {
      const int at = a->attempt[k];
      a->tag[k] = a->tag[--a->n], a->attempt[k] = a->attempt[a->n];
      return at;
    }
  return 0;
}

/* a finished child into *r (1), or 0 after waiting up to *wait; with messages to watch the wait
   backs off from 0.2 ms to 20 ms while nothing happens (`active`: something did this round) */
static int wait_child(fmbPool* pool, const fmbFarmTransport* t, double* wait, int active, fmbChildResult* r) {
  if (!t) return fmb_pool_wait(pool, 0.5, r) == 1;
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

/* starts a task here; a start that fails (fork) is a crashed task with a result all the same */
static void start_here(const fmbFarm* f, fmbPool* pool, Attempts* a, const fmbFarmTask* task, char** failed,
                       int* failed_len) {
  *failed = NULL;
  if (f->start(f->ctx, pool, task) == 0) {
    remember(a, task->index, task->attempt, f->jobs);
    return;
  }
  const fmbChildResult r = {.tag = task->index, .status = FMB_CHILD_CRASHED, .exit_code = -1};
  *failed = f->result(f->ctx, &r, task->attempt, failed_len);
  if (!*failed) *failed_len = 0;
}

/* on an interrupt: every child killed, their tasks given back */
static void cancel(const fmbFarm* f, fmbPool* pool) {
  long tags[1024];
  const int n = fmb_pool_running(pool) <= 1024 ? fmb_pool_tags(pool, tags) : 0;
  fmb_pool_kill_all(pool, 2.0);
  for (int k = 0; f->cancelled && k < n; ++k) f->cancelled(f->ctx, tags[k]);
}

static int manager(const fmbFarm* f, const fmbFarmTransport* t) {
  const int nworkers = t ? t->nranks - 1 : 0;
  fmbPool* pool = fmb_pool_new(f->jobs);
  Attempts a = {calloc((size_t)f->jobs, sizeof(long)), calloc((size_t)f->jobs, sizeof(int)), 0};
  int rc = pool && a.tag && a.attempt ? 0 : FMB_EXIT_SOLVER;
  long outstanding = 0, worker_slots = 0, stops = 0;
  int more = 1, hellos = 0;
  double wait = 2e-4;
  fmbFarmTask task;
  while (!rc && !*f->stop) {
    int active = 0;
    while (more && fmb_pool_free_slots(pool) > 0 && !*f->stop && (more = f->next(f->ctx, &task)) != 0) {
      char* failed;
      int len;
      start_here(f, pool, &a, &task, &failed, &len);
      if (failed) {
        const fmbChildResult r = {.tag = task.index, .status = FMB_CHILD_CRASHED, .exit_code = -1};
        f->take(f->ctx, &r, failed, len);
      }
      active = 1;
    }
    int source, tag, len;
    char* msg;
    while (t && t->poll(&source, &tag, &msg, &len) == 1) {
      active = 1;
      if (tag == FMB_FARM_HELLO) {
        int slots = 0;
        if (len == (int)sizeof slots) memcpy(&slots, msg, sizeof slots);
        free(msg);
        worker_slots += slots;
        ++hellos;
        continue;
      }
      if (tag == FMB_FARM_RESULT) {
        f->take(f->ctx, NULL, msg, len);
        --outstanding;
      } else {
        free(msg); /* ASK */
      }
      double reply[3] = {-1, 0, 0}; /* index, attempt, timeout (N x the median is known here only) */
      if (more && (more = f->next(f->ctx, &task)) != 0) {
        reply[0] = (double)task.index, reply[1] = task.attempt, reply[2] = task.timeout_s;
        ++outstanding;
      } else {
        ++stops;
      }
      t->send(source, FMB_FARM_TASK, reply, (int)sizeof reply);
    }
    if (f->tick) f->tick(f->ctx, fmb_pool_running(pool) + outstanding);
    if (!more && fmb_pool_running(pool) == 0 && outstanding == 0 && hellos == nworkers && stops == worker_slots) break;
    fmbChildResult r;
    if (wait_child(pool, t, &wait, active, &r)) {
      int rlen = 0;
      char* bytes = f->result(f->ctx, &r, recall(&a, r.tag), &rlen);
      f->take(f->ctx, &r, bytes, bytes ? rlen : 0);
    }
  }
  if (pool && *f->stop) cancel(f, pool);
  fmb_pool_free(pool);
  free(a.tag), free(a.attempt);
  return rc ? rc : *f->stop ? FMB_EXIT_INTERRUPTED : 0;
}

struct fmbFarmInbox {
  const fmbFarmTransport* t;
  int slots;
  double* queue; /* [slots][3]: index, attempt, timeout; at most one request per slot is out */
  int head, count, stops;
};

fmbFarmInbox* fmb_farm_inbox_new(const fmbFarmTransport* t, int slots) {
  fmbFarmInbox* q = calloc(1, sizeof *q);
  if (q) q->queue = calloc((size_t)slots * 3, sizeof(double));
  if (!q || !q->queue) return fmb_farm_inbox_free(q), NULL;
  q->t = t, q->slots = slots;
  t->send(0, FMB_FARM_HELLO, &slots, (int)sizeof slots);
  for (int s = 0; s < slots; ++s) t->send(0, FMB_FARM_ASK, NULL, 0);
  return q;
}

void fmb_farm_inbox_free(fmbFarmInbox* q) {
  if (q) free(q->queue);
  free(q);
}

int fmb_farm_inbox_pump(fmbFarmInbox* q) {
  int source, tag, len, got = 0;
  char* msg;
  while (q->t->poll(&source, &tag, &msg, &len) == 1) {
    got = 1;
    double m[3] = {-1, 0, 0};
    if (tag == FMB_FARM_TASK && len == (int)sizeof m) memcpy(m, msg, sizeof m);
    free(msg);
    if (m[0] < 0)
      ++q->stops;
    else if (q->count < q->slots)
      memcpy(q->queue + 3 * ((q->head + q->count++) % q->slots), m, sizeof m);
  }
  return got;
}

int fmb_farm_inbox_next(fmbFarmInbox* q, fmbFarmTask* task) {
  if (!q->count) return q->stops >= q->slots ? -1 : 0;
  const double* m = q->queue + 3 * q->head;
  task->index = (long)m[0], task->attempt = (int)m[1], task->timeout_s = m[2];
  q->head = (q->head + 1) % q->slots;
  --q->count;
  return 1;
}

void fmb_farm_inbox_reply(fmbFarmInbox* q, const char* bytes, int len) {
  q->t->send(0, FMB_FARM_RESULT, bytes, bytes ? len : 0);
}

/* a worker rank: a child per task, its result to rank 0 */
static int worker(const fmbFarm* f, const fmbFarmTransport* t) {
  fmbPool* pool = fmb_pool_new(f->jobs);
  Attempts a = {calloc((size_t)f->jobs, sizeof(long)), calloc((size_t)f->jobs, sizeof(int)), 0};
  fmbFarmInbox* q = pool && a.tag && a.attempt ? fmb_farm_inbox_new(t, f->jobs) : NULL;
  const int rc = q ? 0 : FMB_EXIT_SOLVER;
  int more = 1;
  double wait = 2e-4;
  while (!rc && !*f->stop && (more || fmb_pool_running(pool))) {
    int active = fmb_farm_inbox_pump(q), got = 0;
    fmbFarmTask task;
    while (fmb_pool_free_slots(pool) > 0 && (got = fmb_farm_inbox_next(q, &task)) > 0) {
      active = 1;
      char* failed;
      int len;
      start_here(f, pool, &a, &task, &failed, &len);
      if (failed) fmb_farm_inbox_reply(q, failed, len);
      free(failed);
    }
    if (got < 0) more = 0;
    fmbChildResult r;
    if (wait_child(pool, t, &wait, active, &r)) {
      int len = 0;
      char* bytes = f->result(f->ctx, &r, recall(&a, r.tag), &len);
      fmb_farm_inbox_reply(q, bytes, len);
      free(bytes);
    }
  }
  fmb_pool_free(pool); /* kills what still runs (an interrupt) */
  fmb_farm_inbox_free(q);
  free(a.tag), free(a.attempt);
  return rc ? rc : *f->stop ? FMB_EXIT_INTERRUPTED : 0;
}

int fmb_farm_run(const fmbFarm* f, const fmbFarmTransport* t) {
  if (t && t->nranks < 2) t = NULL;
  return t && t->rank != 0 ? worker(f, t) : manager(f, t);
}
