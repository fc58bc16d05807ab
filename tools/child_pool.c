/* child_pool.c — child processes with deadlines, own process groups and statuses (child_pool.h).
 *
 * Why vfork + exec and not posix_spawn: the child must set its process group, PR_SET_PDEATHSIG
 * and RLIMIT_AS before exec, which posix_spawn cannot do (only the group). vfork, as posix_spawn
 * itself does, shares the parent's memory until exec instead of copying its page tables (fork
 * of a process with many libraries mapped costs a good part of a millisecond per run); until
 * exec the child makes system calls only (no allocation, no stdio), which also makes it safe
 * from a process with threads (an MPI rank). A child that runs a function (spec->fn) is forked. Waiting: SIGCHLD stays blocked in the caller and is taken by sigtimedwait,
 * which wakes at once when a child ends (no polling delay) and returns early on a handled signal
 * (SIGINT/SIGTERM of the caller), so the caller's stop flag is seen at once. */
#include "child_pool.h"

#include <errno.h>
#include <fcntl.h>
#include <signal.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>
#include <sys/prctl.h>
#include <sys/resource.h>
#include <sys/wait.h>
#include <time.h>
#include <unistd.h>

#define KILL_GRACE_S 2.0 /* TERM, then KILL this much later (flexmbd run stops after its step) */

static const char* const status_names[FMB_CHILD_NSTATUS] = {"ok",      "solver_stopped", "bad_input",  "timeout",
                                                            "crashed", "lost",           "interrupted"};
const char* fmb_child_status_name(fmbChildStatus s) {
  return s >= 0 && s < FMB_CHILD_NSTATUS ? status_names[s] : "unknown";
}
int fmb_child_status_of(const char* name) {
  for (int s = 0; s < FMB_CHILD_NSTATUS; ++s)
    if (strcmp(name, status_names[s]) == 0) return s;
  return -1;
}

typedef struct {
  pid_t pid; /* 0: free */
  long tag;
  double start, deadline, kill_at; /* deadline/kill_at 0: none */
  int timed_out, killed;
} Slot;

struct fmbPool {
  int nslot, running;
  Slot* slot;
};

double fmb_pool_now(void) {
  struct timespec ts;
  clock_gettime(CLOCK_MONOTONIC, &ts);
  return (double)ts.tv_sec + 1e-9 * (double)ts.tv_nsec;
}

fmbPool* fmb_pool_new(int slots) {
  if (slots < 1) slots = 1;
  fmbPool* p = calloc(1, sizeof *p);
  if (!p) return NULL;
  p->slot = calloc((size_t)slots, sizeof *p->slot);
  if (!p->slot) {
    free(p);
    return NULL;
  }
  p->nslot = slots;
  sigset_t set;
  sigemptyset(&set);
  sigaddset(&set, SIGCHLD);
  sigprocmask(SIG_BLOCK, &set, NULL);
  return p;
}

void fmb_pool_free(fmbPool* p) {
  if (!p) return;
  fmb_pool_kill_all(p, KILL_GRACE_S);
  free(p->slot);
  free(p);
}

int fmb_pool_running(const fmbPool* p) { return p->running; }
int fmb_pool_free_slots(const fmbPool* p) { return p->nslot - p->running; }
void fmb_pool_kill(fmbPool* p, long tag) {
  for (int i = 0; i < p->nslot; ++i)
    if (p->slot[i].pid && p->slot[i].tag == tag) kill(-p->slot[i].pid, SIGKILL);
}

int fmb_pool_tags(const fmbPool* p, long* tags) {
  int n = 0;
  for (int i = 0; i < p->nslot; ++i)
    if (p->slot[i].pid) tags[n++] = p->slot[i].tag;
  return n;
}

/* in the child, before exec: async-signal-safe calls only */
static void child_setup(const fmbChildSpec* s, pid_t parent) {
  setpgid(0, 0);
  prctl(PR_SET_PDEATHSIG, SIGKILL);
  if (getppid() != parent) _exit(127); /* the parent died before prctl took effect */
  if (s->mem_limit_mb > 0) {
    struct rlimit rl;
    rl.rlim_cur = rl.rlim_max = (rlim_t)(s->mem_limit_mb * 1048576.0);
    setrlimit(RLIMIT_AS, &rl);
  }
  if (s->use_fds) { /* via copies above 10: a pipe may already sit at 3 or 4 */
    const int req = fcntl(s->request_fd, F_DUPFD_CLOEXEC, 10), ans = fcntl(s->answer_fd, F_DUPFD_CLOEXEC, 10);
    if (req < 0 || ans < 0 || dup2(req, 3) < 0 || dup2(ans, 4) < 0) _exit(127);
  }
  int in = open("/dev/null", O_RDONLY | O_CLOEXEC);
  if (in >= 0) dup2(in, 0);
  const char* paths[2] = {s->stdout_path, s->stderr_path};
  for (int k = 0; k < 2; ++k) {
    /* O_NOFOLLOW: a link planted in a shared output folder does not redirect the write */
    int fd = open(paths[k] ? paths[k] : "/dev/null",
                  O_WRONLY | O_CREAT | O_TRUNC | O_CLOEXEC | (paths[k] ? O_NOFOLLOW : 0), 0644);
    if (fd >= 0) dup2(fd, k + 1);
  }
  struct sigaction dfl;
  memset(&dfl, 0, sizeof dfl);
  dfl.sa_handler = SIG_DFL;
  sigaction(SIGINT, &dfl, NULL);
  sigaction(SIGTERM, &dfl, NULL);
  sigaction(SIGPIPE, &dfl, NULL);
  sigset_t none;
  sigemptyset(&none);
  sigprocmask(SIG_SETMASK, &none, NULL);
}

int fmb_pool_start(fmbPool* p, const fmbChildSpec* spec) {
  /* volatile: with vfork the child runs on this frame until it execs, and a local kept in a
     register or a reused slot might not survive its return (gcc's -Wclobbered) */
  Slot* volatile sl = NULL;
  for (int i = 0; i < p->nslot && !sl; ++i)
    if (!p->slot[i].pid) sl = &p->slot[i];
  if (!sl) {
    errno = EBUSY;
    return -1;
  }
  const pid_t parent = getpid();
  if (spec->fn) fflush(NULL); /* the function's child shares stdio buffers: empty them first */
  pid_t pid = spec->fn ? fork() : vfork();
  if (pid < 0) return -1;
  if (pid == 0) {
    child_setup(spec, parent);
    if (spec->fn) {
      spec->fn(spec->arg);
      _exit(0);
    }
    execv(spec->argv[0], spec->argv);
    _exit(127);
  }
  setpgid(pid, pid); /* also here: no race with a kill before the child ran setpgid */
  memset(sl, 0, sizeof *sl);
  sl->pid = pid;
  sl->tag = spec->tag;
  sl->start = fmb_pool_now();
  sl->deadline = spec->timeout_s > 0 ? sl->start + spec->timeout_s : 0.0;
  ++p->running;
  return 0;
}

static void classify(const Slot* sl, int ws, fmbChildResult* r) {
  r->tag = sl->tag;
  r->wall_s = fmb_pool_now() - sl->start;
  r->exit_code = WIFEXITED(ws) ? WEXITSTATUS(ws) : -1;
  r->signal = WIFSIGNALED(ws) ? WTERMSIG(ws) : 0;
  /* a child that ended by itself with one of its own results (0, 2, 3) as the deadline passed
     finished its work: the TERM came too late to matter, and the row says what it did */
  const int own_end = WIFEXITED(ws) && (r->exit_code == 0 || r->exit_code == 2 || r->exit_code == 3);
  if (sl->timed_out && !own_end)
    r->status = FMB_CHILD_TIMEOUT;
  else if (sl->killed)
    r->status = FMB_CHILD_INTERRUPTED;
  else if (r->signal)
    r->status = FMB_CHILD_CRASHED;
  else if (r->exit_code == 0)
    r->status = FMB_CHILD_OK;
  else if (r->exit_code == 2)
    r->status = FMB_CHILD_BAD_INPUT;
  else if (r->exit_code == 3)
    r->status = FMB_CHILD_SOLVER_STOPPED;
  else if (r->exit_code == 4)
    r->status = FMB_CHILD_INTERRUPTED; /* a signal sent by someone else to the child */
  else
    r->status = FMB_CHILD_CRASHED; /* 127: could not execute; anything else the program never returns */
}

/* one finished child reaped into *res: 1, or 0 */
static int reap_one(fmbPool* p, fmbChildResult* res) {
  for (int i = 0; i < p->nslot; ++i) {
    Slot* sl = &p->slot[i];
    if (!sl->pid) continue;
    int ws;
    pid_t r = waitpid(sl->pid, &ws, WNOHANG);
    if (r == sl->pid) {
      classify(sl, ws, res);
      kill(-sl->pid, SIGKILL); /* whatever the child left in its group */
      sl->pid = 0;
      --p->running;
      return 1;
    }
  }
  return 0;
}

/* deadlines: TERM at the deadline, KILL KILL_GRACE_S later; returns the next time to look */
static double enforce_deadlines(fmbPool* p, double now) {
  double next = 0.0;
  for (int i = 0; i < p->nslot; ++i) {
    Slot* sl = &p->slot[i];
    if (!sl->pid) continue;
    if (sl->deadline > 0 && !sl->timed_out && now >= sl->deadline) {
      sl->timed_out = 1;
      sl->kill_at = now + KILL_GRACE_S;
      kill(-sl->pid, SIGTERM);
    }
    if (sl->kill_at > 0 && now >= sl->kill_at) {
      kill(-sl->pid, SIGKILL);
      sl->kill_at = 0.0;
    }
    const double t = sl->kill_at > 0 ? sl->kill_at : (sl->deadline > 0 && !sl->timed_out ? sl->deadline : 0.0);
    if (t > 0 && (next == 0.0 || t < next)) next = t;
  }
  return next;
}

int fmb_pool_wait(fmbPool* p, double max_wait_s, fmbChildResult* res) {
  if (!p->running) return -1;
  const double until = fmb_pool_now() + (max_wait_s > 0 ? max_wait_s : 0.0);
  sigset_t chld;
  sigemptyset(&chld);
  sigaddset(&chld, SIGCHLD);
  for (;;) {
    if (reap_one(p, res)) return 1;
    double now = fmb_pool_now();
    double next = enforce_deadlines(p, now);
    if (now >= until) return 0;
    double wake = next > 0 && next < until ? next : until;
    double dt = wake - now;
    if (dt < 0) dt = 0;
    struct timespec ts = {(time_t)dt, (long)((dt - (double)(time_t)dt) * 1e9)};
    int r = sigtimedwait(&chld, NULL, &ts);
    if (r < 0 && errno == EINTR) return 0; /* a handled signal: let the caller look at its flags */
  }
}

void fmb_pool_kill_all(fmbPool* p, double grace_s) {
  if (!p->running) return;
  for (int i = 0; i < p->nslot; ++i)
    if (p->slot[i].pid) {
      p->slot[i].killed = 1;
      kill(-p->slot[i].pid, SIGTERM);
    }
  const double kill_at = fmb_pool_now() + grace_s;
  int killed = 0;
  fmbChildResult r;
  while (p->running) {
    if (reap_one(p, &r)) continue;
    double now = fmb_pool_now();
    if (!killed && now >= kill_at) {
      for (int i = 0; i < p->nslot; ++i)
        if (p->slot[i].pid) kill(-p->slot[i].pid, SIGKILL);
      killed = 1;
    }
    struct timespec ts = {0, 2000000}; /* 2 ms */
    nanosleep(&ts, NULL);
  }
}
