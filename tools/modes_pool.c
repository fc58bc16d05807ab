/* modes_pool.c — the modes at many speeds as tasks of the farm (farm.h): child processes of this
 * process (`campbell -j K`) and, under mpirun/srun, of every rank (rank 0 hands the speeds out one
 * at a time to whichever slot asks). Each child is this program again, `flexmbd campbell ...
 * --speeds S --modes-out FILE` (cmd_campbell.c: steady state, then modes, at the one speed S),
 * which writes the modes to a file; the rank that ran it sends the file's bytes to rank 0, which
 * reads them back and keeps them by speed: following a mode from speed to speed needs the speed
 * before, so the diagram is made afterwards, in speed order. A child is executed, not forked
 * with the work in it: a rank that forks after MPI_Init may share registered memory with its
 * child (Open MPI's warning about fork()), an exec shares nothing. The numbers are those of the
 * same computation in one process, bit for bit (the same code, doubles copied as bytes, speeds as
 * %.17g; tests/sweep/test_campbell_jobs.sh and test_campbell_mpi.sh: byte for byte). */
#include <signal.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>
#include <unistd.h>

#include "cli.h"
#include "farm.h"

typedef struct {
  char** argv; /* the child's command line; argv[speed_slot] and argv[out_slot] are set per speed */
  int speed_slot, out_slot;
  char speed_text[40];
  const double* speeds;
  int n;
  char dir[600];    /* this rank's temporary folder: one file per speed computed here */
  char cannot[700]; /* why no child can start here (no folder, no command line), "" none */
  /* rank 0 */
  long next, fail_at; /* the next speed to hand out; the first that failed (n: none yet) */
  fmbModes** out;
  int* rc;
  fmbDiag* diag;
  int* have;
} Farm;

static void file_of(const Farm* f, long index, char* path, size_t len) { snprintf(path, len, "%s/%ld", f->dir, index); }

/* through the one safe writer (engine/safe_file.c): a temporary file beside PATH, renamed into place
   only when whole, so a reader never takes a half-written result and no file is overwritten early */
int fmb_cli_modes_save(const char* path, int rc, const fmbDiag* diag, const fmbModes* m) {
  fmbSafeFile* sf = fmb_cli_safe_open(path, NULL, 0);
  FILE* f = sf ? fmb_safe_stream(sf) : NULL;
  if (!f) {
    if (sf) fmb_safe_close(sf, 0);
    return -1;
  }
  int ok = fwrite(&rc, sizeof rc, 1, f) == 1 && fwrite(diag, sizeof *diag, 1, f) == 1;
  if (ok && rc == 0) {
    const size_t n = (size_t)m->count, nq = (size_t)m->nq;
    ok = fwrite(m, sizeof *m, 1, f) == 1 && fwrite(m->frequency, sizeof(double), n, f) == n &&
         fwrite(m->damping_ratio, sizeof(double), n, f) == n &&
         fwrite(m->shape_re, sizeof(double), n * nq, f) == n * nq &&
         fwrite(m->shape_im, sizeof(double), n * nq, f) == n * nq &&
         (!m->family || fwrite(m->family, sizeof(int), n, f) == n);
  }
  ok = fflush(f) == 0 && ok;
  return fmb_safe_close(sf, ok) == 0 && ok ? 0 : -1;
}

/* the modes a child wrote (malloc'd as fmb_modes_free frees them), or NULL with *rc and *diag */
static fmbModes* read_back(FILE* f, int* rc, fmbDiag* diag) {
  fmbModes* m = NULL;
  if (!f || fread(rc, sizeof *rc, 1, f) != 1 || fread(diag, sizeof *diag, 1, f) != 1) {
    *rc = FMB_EXIT_SOLVER;
    memset(diag, 0, sizeof *diag);
    snprintf(diag->msg, sizeof diag->msg, "the computation at this speed ended without a result");
  } else if (*rc == 0) {
    m = calloc(1, sizeof *m);
    if (m && fread(m, sizeof *m, 1, f) == 1) {
      const size_t n = (size_t)m->count, nq = (size_t)m->nq;
      const int classified = m->family != NULL; /* the writer's pointer: only whether it wrote them */
      m->family = classified ? malloc(n * sizeof(int) + 1) : NULL;
      m->frequency = malloc(n * sizeof(double) + 1);
      m->damping_ratio = malloc(n * sizeof(double) + 1);
      m->shape_re = malloc(n * nq * sizeof(double) + 1);
      m->shape_im = malloc(n * nq * sizeof(double) + 1);
      if (!m->frequency || !m->damping_ratio || !m->shape_re || !m->shape_im ||
          fread(m->frequency, sizeof(double), n, f) != n || fread(m->damping_ratio, sizeof(double), n, f) != n ||
          fread(m->shape_re, sizeof(double), n * nq, f) != n * nq ||
          fread(m->shape_im, sizeof(double), n * nq, f) != n * nq || (classified && !m->family) ||
          (classified && fread(m->family, sizeof(int), n, f) != n)) {
        fmb_modes_free(m);
        m = NULL;
      }
    } else {
      free(m);
      m = NULL;
    }
    if (!m) {
      *rc = FMB_EXIT_SOLVER;
      snprintf(diag->msg, sizeof diag->msg, "the modes at this speed could not be read back");
    }
  }
  return m;
}

/* rank 0: the speeds in order, none after one that failed (the diagram stops there) */
static int next_speed(void* ctx, fmbFarmTask* task) {
  Farm* f = ctx;
  if (f->next >= f->n || f->next > f->fail_at) return 0;
  *task = (fmbFarmTask){f->next++, 1, 0.0};
  return 1;
}

static int start_speed(void* ctx, fmbPool* pool, const fmbFarmTask* task) {
  Farm* f = ctx;
  if (f->cannot[0]) return -1; /* its result says why */
  char path[700];
  file_of(f, task->index, path, sizeof path);
  snprintf(f->speed_text, sizeof f->speed_text, "%.17g", f->speeds[task->index]);
  f->argv[f->speed_slot] = f->speed_text;
  f->argv[f->out_slot] = path; /* copied by the exec before fmb_pool_start returns */
  const fmbChildSpec spec = {.argv = f->argv, .tag = task->index};
  return fmb_pool_start(pool, &spec);
}

/* the speed's index, then the child's file as it is, or a failure that names how it ended */
static char* speed_result(void* ctx, const fmbChildResult* r, int attempt, int* len) {
  (void)attempt;
  Farm* f = ctx;
  char path[700];
  file_of(f, r->tag, path, sizeof path);
  FILE* in = r->status == FMB_CHILD_OK ? fopen(path, "rb") : NULL;
  long size = -1;
  if (in && fseek(in, 0, SEEK_END) == 0) size = ftell(in);
  if (in && size >= 0) rewind(in);
  const int ok = size >= (long)(sizeof(int) + sizeof(fmbDiag));
  const size_t total = sizeof(long) + (ok ? (size_t)size : sizeof(int) + sizeof(fmbDiag));
  char* bytes = malloc(total);
  if (bytes) {
    memcpy(bytes, &r->tag, sizeof(long));
    if (!ok || fread(bytes + sizeof(long), 1, (size_t)size, in) != (size_t)size) {
      int rc = FMB_EXIT_SOLVER;
      fmbDiag d;
      memset(&d, 0, sizeof d);
      if (f->cannot[0])
        snprintf(d.msg, sizeof d.msg, "%s", f->cannot);
      else if (r->signal)
        snprintf(d.msg, sizeof d.msg, "the computation crashed (killed by signal %d, %s)", r->signal,
                 strsignal(r->signal));
      else
        snprintf(d.msg, sizeof d.msg, "the computation ended without a result (exit code %d)", r->exit_code);
      memcpy(bytes + sizeof(long), &rc, sizeof rc);
      memcpy(bytes + sizeof(long) + sizeof rc, &d, sizeof d);
      *len = (int)(sizeof(long) + sizeof(int) + sizeof(fmbDiag));
    } else {
      *len = (int)total;
    }
  }
  if (in) fclose(in);
  unlink(path);
  return bytes;
}

/* rank 0: a speed's modes (or why there are none) kept by its index */
static void take_speed(void* ctx, const fmbChildResult* local, char* bytes, int len) {
  (void)local;
  Farm* f = ctx;
  long index = -1;
  if (bytes && len >= (int)sizeof index) memcpy(&index, bytes, sizeof index);
  if (f->have && index >= 0 && index < f->n && !f->have[index]) {
    FILE* in = fmemopen(bytes + sizeof index, (size_t)len - sizeof index, "rb");
    fmbModes* m = read_back(in, &f->rc[index], &f->diag[index]);
    if (f->out)
      f->out[index] = m;
    else
      fmb_modes_free(m); /* the caller could not keep them (out of memory): it fails anyway */
    if (in) fclose(in);
    f->have[index] = 1;
    if (f->rc[index] && index < f->fail_at) f->fail_at = index;
  }
  free(bytes);
}

int fmb_cli_modes_in_children(int jobs, char** argv, int speed_slot, int out_slot, const double* speeds, int n,
                              const fmbFarmTransport* t, volatile sig_atomic_t* stop, fmbModes** out, int* done,
                              fmbDiag* diag) {
  *done = 0;
  memset(diag, 0, sizeof *diag);
  Farm f = {
      .argv = argv, .speed_slot = speed_slot, .out_slot = out_slot, .speeds = speeds, .n = n, .fail_at = n, .out = out};
  const char* tmp = getenv("TMPDIR");
  snprintf(f.dir, sizeof f.dir, "%s/flexmbd-modes-XXXXXX", tmp && *tmp ? tmp : "/tmp");
  const int master = !t || t->rank == 0;
  if (master) {
    f.rc = calloc((size_t)n, sizeof *f.rc);
    f.diag = calloc((size_t)n, sizeof *f.diag);
    f.have = calloc((size_t)n, sizeof *f.have);
  }
  /* whatever fails here, every rank still goes through the farm (the others wait for its word):
     each speed it would compute then fails, saying why */
  if (!argv)
    snprintf(f.cannot, sizeof f.cannot, "cannot start the computation: out of memory");
  else if (!mkdtemp(f.dir))
    snprintf(f.cannot, sizeof f.cannot, "cannot start the computation: no temporary folder %s (TMPDIR)", f.dir);
  const int kept = !master || (f.rc && f.diag && f.have);
  if (!kept) free(f.rc), free(f.diag), free(f.have), f.rc = NULL, f.diag = NULL, f.have = NULL;
  const fmbFarm farm = {.jobs = jobs,
                        .stop = stop,
                        .ctx = &f,
                        .next = next_speed,
                        .start = start_speed,
                        .result = speed_result,
                        .take = take_speed};
  int rc = fmb_farm_run(&farm, t);
  if (!rc && !kept) rc = FMB_EXIT_SOLVER;
  if (rc && rc != FMB_EXIT_INTERRUPTED)
    snprintf(diag->msg, sizeof diag->msg, "cannot start the children (out of memory)");
  /* the speeds in order up to the first without modes: its code and message */
  for (int i = 0; master && !rc && i < n; ++i) {
    if (!f.have[i]) { /* not computed: an interrupt (rc), else a speed before it failed */
      rc = FMB_EXIT_SOLVER;
      snprintf(diag->msg, sizeof diag->msg, "no result");
    } else if (f.rc[i]) {
      rc = f.rc[i];
      *diag = f.diag[i];
    } else {
      *done = i + 1;
    }
  }
  if (master && kept && rc == FMB_EXIT_INTERRUPTED)
    while (*done < n && f.have[*done] && !f.rc[*done]) ++*done;
  for (int i = *done; master && out && i < n; ++i) { /* only the speeds in order are the caller's */
    fmb_modes_free(out[i]);
    out[i] = NULL;
  }
  if (!f.cannot[0]) rmdir(f.dir);
  free(f.rc), free(f.diag), free(f.have);
  return rc;
}
