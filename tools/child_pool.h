/* child_pool.h — a pool of child processes for `sweep` and `regress` (and whatever runs many
 * scenes at once): every run is a process of its own, so a segfault, an abort, a hang or a
 * runaway allocation costs that run, never the caller (docs/sweep.md, "Statuses").
 *
 * A child is either a program (argv, executed with execv) or a function run in the forked
 * process (fn(arg), which must end with _exit). Each child gets its own process group (a
 * timeout or an interrupt kills whatever it started too), PR_SET_PDEATHSIG = SIGKILL (it dies
 * with the caller, even after kill -9), optional RLIMIT_AS, and stdout/stderr in files.
 * The caller blocks SIGCHLD (fmb_pool_new does) and waits in fmb_pool_wait, which sleeps in
 * sigtimedwait until a child ends, a deadline passes or a handled signal arrives. */
#ifndef FLEXMBD_CHILD_POOL_H
#define FLEXMBD_CHILD_POOL_H
#include <sys/types.h>

/* what became of a child; the names are the sweep's status column */
typedef enum {
  FMB_CHILD_OK = 0,         /* exit 0 */
  FMB_CHILD_SOLVER_STOPPED, /* exit 3: the solver stopped, the rows so far are kept */
  FMB_CHILD_BAD_INPUT,      /* exit 2: the scene or an override was refused */
  FMB_CHILD_TIMEOUT,        /* killed at its wall deadline */
  FMB_CHILD_CRASHED,        /* a signal we did not send, or another exit code */
  FMB_CHILD_LOST,           /* in flight at three deaths of the caller (sweep resume) */
  FMB_CHILD_INTERRUPTED,    /* killed because the caller was interrupted */
  FMB_CHILD_NSTATUS
} fmbChildStatus;
const char* fmb_child_status_name(fmbChildStatus s);
/* the status of a name, or -1 */
int fmb_child_status_of(const char* name);

typedef struct fmbChildSpec {
  char* const* argv;     /* a program to execute (argv[0] is its path) ... */
  void (*fn)(void* arg); /* ... or a function run in the forked child; it must _exit */
  void* arg;
  const char *stdout_path, *stderr_path; /* NULL: /dev/null; opened without following a link */
  /* use_fds: two more descriptors, request_fd as the child's fd 3 and answer_fd as its fd 4 (a
     runner's pipes, tools/run_serve.c: a channel of their own, apart from stdin and stdout, so
     nothing the child prints can be taken for an answer) */
  int use_fds, request_fd, answer_fd;
  double timeout_s;    /* wall time allowed; <= 0: none */
  double mem_limit_mb; /* RLIMIT_AS of the child; <= 0: none */
  long tag;            /* the caller's name for the child, handed back */
} fmbChildSpec;

typedef struct fmbChildResult {
  long tag;
  fmbChildStatus status;
  int exit_code; /* -1 when killed by a signal */
  int signal;    /* 0 when it exited */
  double wall_s;
} fmbChildResult;

typedef struct fmbPool fmbPool;

/* a pool of `slots` children at most; NULL when out of memory */
fmbPool* fmb_pool_new(int slots);
/* kills what still runs (fmb_pool_kill_all) and frees */
void fmb_pool_free(fmbPool* p);
int fmb_pool_running(const fmbPool* p);
int fmb_pool_free_slots(const fmbPool* p);
/* SIGKILL to the process group of the running child tagged `tag` (its result: status as if it
   had died on its own, signal 9) */
void fmb_pool_kill(fmbPool* p, long tag);
/* the tags of the running children into tags[0..running); their number */
int fmb_pool_tags(const fmbPool* p, long* tags);
/* starts a child in a free slot: 0, or -1 (no free slot, or fork failed: errno) */
int fmb_pool_start(fmbPool* p, const fmbChildSpec* spec);
/* Waits until a child ends (1, *res filled), `max_wait_s` passes (0) or a handled signal
   arrives (0). Kills children past their deadline on the way (TERM, then KILL after 2 s).
   -1 when nothing runs. */
int fmb_pool_wait(fmbPool* p, double max_wait_s, fmbChildResult* res);
/* TERM to every child's process group, KILL after `grace_s`, all reaped; their results are
   dropped. Used on SIGINT/SIGTERM and at the end. */
void fmb_pool_kill_all(fmbPool* p, double grace_s);
/* seconds since an arbitrary start (CLOCK_MONOTONIC) */
double fmb_pool_now(void);
#endif
