/* farm.h — many tasks, each a child process, handed out one at a time to whichever slot asks:
 * the children of this process (child_pool.c) and, under mpirun/srun, those of the other ranks.
 * Rank 0 plans (next), hands out and also works; every rank runs `jobs` children; what a task
 * gives back (bytes: a sweep's journal row, a speed's modes) travels to rank 0, which alone keeps
 * it (take). Dynamic scheduling because task costs are heavy-tailed: a static split leaves ranks
 * idle (docs/sweep.md, docs/performance.md#sweeps). Used by `flexmbd sweep` (sweep_exec.c) and
 * `flexmbd campbell` (modes_pool.c); the MPI transport is in the sweep's module (sweep_mpi.c).
 *
 * Messages (all small, point to point; only task indices travel: every rank builds the same
 * tasks from the same command line):
 *   worker -> 0  HELLO {slots}          once
 *   worker -> 0  ASK                    once per slot at the start
 *   worker -> 0  RESULT bytes           a finished task's result; also asks for the next task
 *   0 -> worker  TASK {index, attempt, timeout}   or index -1: no more work for that slot */
#ifndef FLEXMBD_FARM_H
#define FLEXMBD_FARM_H
#include <signal.h>

#include "child_pool.h"

enum { FMB_FARM_HELLO = 1, FMB_FARM_ASK, FMB_FARM_RESULT, FMB_FARM_TASK };

/* the ranks and how messages pass between them (MPI, sweep_mpi.c) */
typedef struct fmbFarmTransport {
  int rank, nranks;
  /* a message waiting for this rank: 1 with its source, tag and bytes (malloc'd, '\0' after the
     len bytes; the caller frees), 0 none */
  int (*poll)(int* source, int* tag, char** bytes, int* len);
  void (*send)(int dest, int tag, const void* bytes, int len);
  /* rank 0's value on every rank */
  int (*bcast_int)(int value);
} fmbFarmTransport;

typedef struct fmbFarmTask {
  long index;
  int attempt;
  double timeout_s; /* the child's wall time limit, <= 0 none */
} fmbFarmTask;

typedef struct fmbFarm {
  int jobs; /* children at once on each rank */
  volatile sig_atomic_t* stop;
  void* ctx;
  /* rank 0: the next task (1, *task filled), or 0: none any more */
  int (*next)(void* ctx, fmbFarmTask* task);
  /* any rank: starts the task's child in the pool, tagged task->index; 0 or -1 */
  int (*start)(void* ctx, fmbPool* pool, const fmbFarmTask* task);
  /* the rank that ran it: the result of a finished child (or of a start that failed: status
     crashed, exit code -1), malloc'd, *len bytes; NULL when out of memory */
  char* (*result)(void* ctx, const fmbChildResult* r, int attempt, int* len);
  /* rank 0: a task's result (taken over; NULL when out of memory); `local`: the child's end when
     it ran here, NULL when it came from another rank */
  void (*take)(void* ctx, const fmbChildResult* local, char* bytes, int len);
  /* optional, rank 0, every round: tasks running (here and handed out) */
  void (*tick)(void* ctx, long running);
  /* optional, rank 0: a task whose child was killed because of an interrupt (*stop) */
  void (*cancelled)(void* ctx, long index);
} fmbFarm;

/* Runs the farm: rank 0 until every task has been taken (t NULL or one rank: this process
   alone), another rank until rank 0 has no more tasks. 0, FMB_EXIT_INTERRUPTED (*stop: every
   child killed), or FMB_EXIT_SOLVER (out of memory). */
int fmb_farm_run(const fmbFarm* f, const fmbFarmTransport* t);

/* a worker rank's tasks when it runs them its own way (sweep --runner serve) */
typedef struct fmbFarmInbox fmbFarmInbox;
/* says HELLO and asks for one task per slot; NULL when out of memory */
fmbFarmInbox* fmb_farm_inbox_new(const fmbFarmTransport* t, int slots);
void fmb_farm_inbox_free(fmbFarmInbox* q);
/* fetches the TASK messages that arrived; nonzero when some did */
int fmb_farm_inbox_pump(fmbFarmInbox* q);
/* 1 with the next task, 0 none now, -1 none any more (every slot was told to stop) */
int fmb_farm_inbox_next(fmbFarmInbox* q, fmbFarmTask* task);
/* a task's result to rank 0 (which takes it as a request for the next task too) */
void fmb_farm_inbox_reply(fmbFarmInbox* q, const char* bytes, int len);
#endif
