/* modes_pool.c — the modes at many speeds computed in child processes (`campbell -j K`), on the
 * pool the sweep and regress use (child_pool.c). Each child computes one speed's modes (the
 * front-end's function: steady state, then modes) and writes them to a file; the parent reads
 * them back in speed order, because following a mode from speed to speed needs the speed
 * before. The numbers are those of the same computation in one process, bit for bit (the same
 * code, doubles copied as bytes; tests/analysis: campbell -j 2 equals -j 1 byte for byte). */
#include <stdio.h>
#include <stdlib.h>
#include <string.h>
#include <unistd.h>

#include "child_pool.h"
#include "cli.h"

typedef struct {
  fmbCliModesAt at;
  void* ctx;
  double speed;
  const char* file;
} Job;

/* in the child: the modes at one speed into a file: rc, diag, then (rc 0) the modes */
static void child(void* arg) {
  const Job* j = arg;
  fmbModes* m = NULL;
  fmbDiag diag;
  memset(&diag, 0, sizeof diag);
  int rc = j->at(j->ctx, j->speed, &m, &diag);
  FILE* f = fopen(j->file, "wb");
  if (!f) _exit(1);
  int ok = fwrite(&rc, sizeof rc, 1, f) == 1 && fwrite(&diag, sizeof diag, 1, f) == 1;
  if (ok && rc == 0) {
    const size_t n = (size_t)m->count, nq = (size_t)m->nq;
    ok = fwrite(m, sizeof *m, 1, f) == 1 && fwrite(m->frequency, sizeof(double), n, f) == n &&
         fwrite(m->damping_ratio, sizeof(double), n, f) == n &&
         fwrite(m->shape_re, sizeof(double), n * nq, f) == n * nq &&
         fwrite(m->shape_im, sizeof(double), n * nq, f) == n * nq;
  }
  ok = fclose(f) == 0 && ok;
  _exit(ok ? 0 : 1);
}

/* the modes a child wrote (malloc'd as fmb_modes_free frees them), or NULL with *rc and *diag */
static fmbModes* read_back(const char* file, int* rc, fmbDiag* diag) {
  FILE* f = fopen(file, "rb");
  fmbModes* m = NULL;
  if (!f || fread(rc, sizeof *rc, 1, f) != 1 || fread(diag, sizeof *diag, 1, f) != 1) {
    *rc = FMB_EXIT_SOLVER;
    snprintf(diag->msg, sizeof diag->msg, "the computation at this speed ended without a result (a crash?)");
  } else if (*rc == 0) {
    m = calloc(1, sizeof *m);
    if (m && fread(m, sizeof *m, 1, f) == 1) {
      const size_t n = (size_t)m->count, nq = (size_t)m->nq;
      m->frequency = malloc(n * sizeof(double) + 1);
      m->damping_ratio = malloc(n * sizeof(double) + 1);
      m->shape_re = malloc(n * nq * sizeof(double) + 1);
      m->shape_im = malloc(n * nq * sizeof(double) + 1);
      if (!m->frequency || !m->damping_ratio || !m->shape_re || !m->shape_im ||
          fread(m->frequency, sizeof(double), n, f) != n || fread(m->damping_ratio, sizeof(double), n, f) != n ||
          fread(m->shape_re, sizeof(double), n * nq, f) != n * nq ||
          fread(m->shape_im, sizeof(double), n * nq, f) != n * nq) {
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
  if (f) fclose(f);
  return m;
}

int fmb_cli_modes_in_children(int jobs, const double* speeds, int n, fmbCliModesAt at, void* ctx, fmbModes** out,
                              int* done, fmbDiag* diag) {
  *done = 0;
  char dir[600];
  const char* tmp = getenv("TMPDIR");
  snprintf(dir, sizeof dir, "%s/flexmbd-modes-XXXXXX", tmp && *tmp ? tmp : "/tmp");
  fmbPool* pool = mkdtemp(dir) ? fmb_pool_new(jobs) : NULL;
  Job* job = calloc((size_t)n, sizeof *job);
  char* files = calloc((size_t)n, 640);
  if (!pool || !job || !files) {
    fmb_pool_free(pool), free(job), free(files);
    snprintf(diag->msg, sizeof diag->msg, "cannot start the children (a temporary folder in %s)", dir);
    return FMB_EXIT_SOLVER;
  }
  for (int next = 0; next < n || fmb_pool_running(pool);) {
    while (next < n && fmb_pool_free_slots(pool) > 0) {
      snprintf(files + 640 * (size_t)next, 640, "%s/%d", dir, next);
      job[next] = (Job){at, ctx, speeds[next], files + 640 * (size_t)next};
      fmbChildSpec spec = {.fn = child, .arg = &job[next], .tag = next};
      if (fmb_pool_start(pool, &spec) != 0) break;
      ++next;
    }
    fmbChildResult r;
    if (fmb_pool_wait(pool, 1.0, &r) < 0 && next < n) break; /* nothing runs and nothing starts */
  }
  fmb_pool_free(pool);
  int rc = 0;
  for (int i = 0; i < n && !rc; ++i) {
    memset(diag, 0, sizeof *diag);
    out[i] = read_back(files + 640 * (size_t)i, &rc, diag);
    if (!rc) *done = i + 1;
  }
  for (int i = 0; i < n; ++i) unlink(files + 640 * (size_t)i);
  rmdir(dir);
  free(job), free(files);
  return rc;
}
