/* sweep_exec.c — one run of a sweep as a child process, its journal row, and the local loop.
 *
 * A run is `flexmbd VERB SCENE -o DIR/series/ID.csv --quiet --set ...` (the same program), so
 * its numbers are those of the same command typed by hand, bit for bit (tests/sweep). What the
 * row keeps comes from the child's exit (child_pool.c), its stats line (the last stderr line,
 * docs/robustness.md) and, for --metric and --reference, its CSV, read back with the one CSV
 * reader (csv_table.c). */
#include <errno.h>
#include <inttypes.h>
#include <math.h>
#include <stdarg.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>
#include <sys/resource.h>
#include <sys/statvfs.h>
#include <unistd.h>

#include "cli.h"
#include "sweep.h"

static void run_file(const fmbSweep* sw, long index, const char* sub, const char* ext, char* out, size_t len) {
  snprintf(out, len, "%s/%s/%016" PRIx64 "%s", sw->dir, sub, sw->id[index], ext);
}

int fmb_sweep_argv(const fmbSweep* sw, long index, const char* verb, const char* out, char** argv,
                   char (*sets)[FMB_SWEEP_SET_LEN]) {
  int n = 0;
  argv[n++] = (char*)sw->exe;
  argv[n++] = (char*)verb;
  argv[n++] = (char*)sw->scene;
  if (out) argv[n++] = "-o", argv[n++] = (char*)out, argv[n++] = "--quiet";
  for (int k = 0; k < sw->nfixed; ++k) argv[n++] = "--set", argv[n++] = (char*)sw->fixed[k];
  for (int k = 0; k < sw->plan.npath; ++k) {
    snprintf(sets[k], FMB_SWEEP_SET_LEN, "%s=%s", sw->plan.path[k], fmb_plan_value(&sw->plan, index, k));
    argv[n++] = "--set", argv[n++] = sets[k];
  }
  for (int k = 0; k < sw->nplugins; ++k) argv[n++] = "--plugin", argv[n++] = (char*)sw->plugins[k];
  argv[n] = NULL;
  return n;
}

int fmb_sweep_start(fmbSweep* sw, fmbPool* pool, long index, double timeout_s) {
  char series[4300], err[4300];
  run_file(sw, index, "series", ".csv", series, sizeof series);
  run_file(sw, index, "logs", ".err", err, sizeof err);
  char* argv[FMB_SWEEP_MAX_ARGS];
  char sets[FMB_SWEEP_MAX_PATHS][FMB_SWEEP_SET_LEN];
  fmb_sweep_argv(sw, index, sw->verb, series, argv, sets);
  fmbChildSpec spec = {.argv = argv,
                       .stdout_path = NULL,
                       .stderr_path = err,
                       .timeout_s = timeout_s,
                       .mem_limit_mb = sw->mem_limit_mb,
                       .tag = index};
  return fmb_pool_start(pool, &spec);
}

double fmb_sweep_timeout(fmbSweep* sw) {
  if (sw->timeout_factor > 0 && sw->nok >= 5) {
    if (sw->nok >= sw->median_at) { /* re-taken as the count doubles: O(n log n) overall */
      double* w = malloc((size_t)sw->nok * sizeof *w);
      if (w) {
        memcpy(w, sw->ok_wall, (size_t)sw->nok * sizeof *w);
        for (long i = 1; i < sw->nok; ++i) /* insertion sort: small n, mostly sorted */
          for (long j = i; j > 0 && w[j - 1] > w[j]; --j) {
            double t = w[j];
            w[j] = w[j - 1], w[j - 1] = t;
          }
        sw->median_wall = sw->nok % 2 ? w[sw->nok / 2] : 0.5 * (w[sw->nok / 2 - 1] + w[sw->nok / 2]);
        free(w);
      }
      sw->median_at = sw->nok < 1000 ? sw->nok + 1 : 2 * sw->nok;
    }
    /* never below 1 s: a wall time of a few ms is the scheduler's (on a loaded machine a 0.3 ms
       median made 5x a 1.5 ms limit, and ok runs were killed); a hang still costs only 1 s */
    const double t = sw->timeout_factor * sw->median_wall;
    return t > 1.0 ? t : 1.0;
  }
  return sw->timeout_s;
}

/* the stats line's value of each field (text as printed, so rows equal `flexmbd run`'s line) */
static void parse_stats(const char* line, char stats[FMB_SWEEP_NSTATS][40]) {
  for (int k = 0; k < FMB_SWEEP_NSTATS; ++k) {
    char key[40];
    snprintf(key, sizeof key, " %s=", fmb_sweep_stat_names[k]);
    const char* v = strstr(line, key);
    if (v) {
      v += strlen(key);
      snprintf(stats[k], 40, "%.*s", (int)strcspn(v, " \t"), v);
    }
  }
}

/* the stats and the first error line from a child's stderr file */
static void read_stderr(const char* path, char stats[FMB_SWEEP_NSTATS][40], char* msg, size_t msglen) {
  for (int k = 0; k < FMB_SWEEP_NSTATS; ++k) stats[k][0] = '\0';
  msg[0] = '\0';
  FILE* f = fopen(path, "r");
  if (!f) return;
  char line[2048], first[2048] = "";
  while (fgets(line, sizeof line, f)) {
    line[strcspn(line, "\n")] = '\0';
    if (strncmp(line, "stats:", 6) == 0) {
      parse_stats(line, stats);
    } else if (!msg[0] && strstr(line, "error")) {
      snprintf(msg, msglen, "%s", line);
    } else if (!first[0] && line[0]) {
      snprintf(first, sizeof first, "%s", line);
    }
  }
  fclose(f);
  if (!msg[0]) snprintf(msg, msglen, "%s", first);
}

static double metric_of(const fmbTable* t, int col, int kind) {
  if (t->nrow == 0) return NAN;
  if (kind == 2) return fmb_table_at(t, t->nrow - 1, col);
  double acc = kind == 3 ? 0.0 : fmb_table_at(t, 0, col);
  for (long r = 0; r < t->nrow; ++r) {
    const double v = fmb_table_at(t, r, col);
    if (kind == 0 && v > acc) acc = v;
    if (kind == 1 && v < acc) acc = v;
    if (kind == 3) acc += v * v;
  }
  return kind == 3 ? sqrt(acc / (double)t->nrow) : acc;
}

typedef struct {
  char* s;
  size_t n, cap;
} Buf;
static void put(Buf* b, const char* fmt, ...) {
  for (;;) {
    va_list ap;
    va_start(ap, fmt);
    int k = vsnprintf(b->s ? b->s + b->n : NULL, b->s ? b->cap - b->n : 0, fmt, ap);
    va_end(ap);
    if (k < 0) return;
    if (b->s && b->n + (size_t)k < b->cap) {
      b->n += (size_t)k;
      return;
    }
    size_t cap = b->cap ? 2 * b->cap : 1024;
    while (cap < b->n + (size_t)k + 1) cap *= 2;
    char* g = realloc(b->s, cap);
    if (!g) return;
    b->s = g, b->cap = cap;
  }
}
static void put_double(Buf* b, double v) {
  if (isfinite(v))
    put(b, ",%.17g", v);
  else
    put(b, ",%s", isnan(v) ? "nan" : v > 0 ? "inf" : "-inf");
}
/* a message as one CSV field: quoted, inner quotes doubled, control characters (a line break
   would end the row) as blanks, at most 200 characters */
static void put_message(Buf* b, const char* msg) {
  put(b, ",\"");
  for (int i = 0; msg[i] && i < 200; ++i) {
    if (msg[i] == '"')
      put(b, "\"\"");
    else
      put(b, "%c", (unsigned char)msg[i] < 32 ? ' ' : msg[i]);
  }
  put(b, "\"\n");
}

static void put_lead(const fmbSweep* sw, Buf* b, long index, int attempt, const char* status, int exit_code, int sig,
                     double wall_s) {
  put(b, "%ld,%016" PRIx64 ",%d,%s,%d,%d,%.3f,%d", index, sw->id[index], attempt, status, exit_code, sig, wall_s,
      sw->rank);
  for (int k = 0; k < sw->plan.npath; ++k) put(b, ",%s", fmb_plan_value(&sw->plan, index, k));
}

/* A run that did not end ok because the disk was full is no result of the run: its CSV (or its
   messages) could not be written. Told by the engine's own message for a refused CSV write, or by
   a folder left without free space (the run's stderr may then be cut too). */
static int cut_by_disk(const fmbSweep* sw, const fmbChildResult* r, const char* msg) {
  if (r->status == FMB_CHILD_OK || r->status == FMB_CHILD_BAD_INPUT || r->status == FMB_CHILD_INTERRUPTED) return 0;
  if (strstr(msg, "writing the output failed")) return 1;
  struct statvfs v;
  return statvfs(sw->dir, &v) == 0 && (double)v.f_bavail * (double)v.f_frsize < 65536.0;
}

/* the row from what the run's end told: status, its stats fields, its message */
static char* build_row(fmbSweep* sw, const fmbChildResult* r, int attempt, char stats[FMB_SWEEP_NSTATS][40],
                       char* msg) {
  enum { msglen = 2048 };
  const long index = r->tag;
  char series[4300];
  run_file(sw, index, "series", ".csv", series, sizeof series);
  if (cut_by_disk(sw, r, msg)) { /* the journal takes no row for it (fmb_journal_append) */
    Buf b = {0};
    put_lead(sw, &b, index, attempt, FMB_SWEEP_CUT, r->exit_code, r->signal, r->wall_s);
    put(&b, "\n");
    unlink(series);
    return b.s;
  }
  if (r->status == FMB_CHILD_CRASHED && r->signal) {
    char m[msglen];
    snprintf(m, sizeof m, "killed by signal %d (%s)%s%.1800s", r->signal, strsignal(r->signal), msg[0] ? ": " : "",
             msg);
    memcpy(msg, m, msglen);
  } else if (r->status == FMB_CHILD_CRASHED && !msg[0]) {
    snprintf(msg, msglen, "exit code %d (flexmbd ends with 0, 2, 3 or 4)%s", r->exit_code,
             r->exit_code == 127 ? ": the program could not be started" : "");
  } else if (r->status == FMB_CHILD_TIMEOUT) {
    char m[msglen];
    snprintf(m, sizeof m, "no result within the time limit (--timeout): killed after %.3g s%s%.1800s", r->wall_s,
             msg[0] ? ": " : "", msg);
    memcpy(msg, m, msglen);
  } else if (r->status == FMB_CHILD_OK) {
    msg[0] = '\0';
  }
  Buf b = {0};
  put_lead(sw, &b, index, attempt, fmb_child_status_name(r->status), r->exit_code, r->signal, r->wall_s);
  for (int k = 0; k < FMB_SWEEP_NSTATS; ++k) put(&b, ",%s", stats[k]);
  fmbTable t;
  memset(&t, 0, sizeof t);
  const int usable =
      (r->status == FMB_CHILD_OK || r->status == FMB_CHILD_SOLVER_STOPPED) && (sw->nmetric + sw->nrefcol) > 0;
  char why[600] = "";
  /* run and static write t first, modes writes mode first: any first column for the metrics */
  const int have = usable && fmb_table_load_keyed(series, &t, NULL, why, sizeof why) == 0;
  for (int k = 0; k < sw->nmetric; ++k) {
    const int c = have ? fmb_table_col(&t, sw->metric[k].column) : -1;
    if (c < 0 && have && !msg[0]) snprintf(msg, msglen, "no column '%s' in the run's CSV", sw->metric[k].column);
    if (c < 0)
      put(&b, ",");
    else
      put_double(&b, metric_of(&t, c, sw->metric[k].kind));
  }
  for (int k = 0; k < sw->nrefcol; ++k) {
    const int c = have ? fmb_table_col(&t, sw->ref.name[sw->refcol[k]]) : -1;
    fmbColumnError e;
    if (c >= 0) fmb_table_column_error(&t, c, &sw->ref, sw->refcol[k], &e);
    if (c < 0 || e.rows == 0) {
      put(&b, ",,");
    } else {
      put_double(&b, e.max_abs);
      put_double(&b, e.end_abs);
    }
  }
  if (usable && !have && !msg[0]) snprintf(msg, msglen, "%s", why);
  if (have) fmb_table_free(&t);
  put_message(&b, msg);
  if (!sw->keep_series) unlink(series);
  return b.s;
}

char* fmb_sweep_row(fmbSweep* sw, const fmbChildResult* r, int attempt) {
  char err[4300], stats[FMB_SWEEP_NSTATS][40], msg[2048];
  run_file(sw, r->tag, "logs", ".err", err, sizeof err);
  read_stderr(err, stats, msg, sizeof msg);
  char* row = build_row(sw, r, attempt, stats, msg);
  if (r->status == FMB_CHILD_OK) unlink(err); /* kept for the runs that need a look */
  return row;
}

char* fmb_sweep_row_served(fmbSweep* sw, const fmbChildResult* r, int attempt, const char* stats_line,
                           const char* message) {
  char stats[FMB_SWEEP_NSTATS][40], msg[2048];
  for (int k = 0; k < FMB_SWEEP_NSTATS; ++k) stats[k][0] = '\0';
  parse_stats(stats_line, stats);
  snprintf(msg, sizeof msg, "%s", message);
  return build_row(sw, r, attempt, stats, msg);
}

char* fmb_sweep_row_lost(fmbSweep* sw, long index, int attempt) {
  Buf b = {0};
  put_lead(sw, &b, index, attempt, "lost", -1, 0, 0.0);
  for (int k = 0; k < FMB_SWEEP_NSTATS; ++k) put(&b, ",");
  for (int k = 0; k < sw->nmetric; ++k) put(&b, ",");
  for (int k = 0; k < sw->nrefcol; ++k) put(&b, ",,");
  char msg[200];
  snprintf(msg, sizeof msg, "in flight at %d stops of the sweep: not run again", attempt);
  put_message(&b, msg);
  return b.s;
}

void fmb_sweep_account(fmbSweep* sw, int status, double wall_s) {
  if (status >= 0 && status < FMB_CHILD_NSTATUS) ++sw->count[status];
  ++sw->done;
  if (status != FMB_CHILD_OK) ++sw->failed;
  if (status == FMB_CHILD_OK) {
    if (sw->nok == sw->okcap) {
      long cap = sw->okcap ? 2 * sw->okcap : 256;
      double* g = realloc(sw->ok_wall, (size_t)cap * sizeof *g);
      if (!g) return;
      sw->ok_wall = g, sw->okcap = cap;
    }
    sw->ok_wall[sw->nok++] = wall_s;
  }
}

void fmb_sweep_progress(fmbSweep* sw, int final) {
  const double now = fmb_pool_now();
  if (sw->progress && (final || now - sw->last_progress >= 0.5)) {
    sw->last_progress = now;
    const double el = now - sw->t_start, rate = el > 0 ? (double)sw->done / el : 0.0;
    const double eta = rate > 0 ? (double)(sw->total_todo - sw->done) / rate : 0.0;
    fprintf(stderr, "\rsweep: %ld/%ld done, %ld not ok, %ld running, %.1f runs/s, ETA %.0f s   %s", sw->done,
            sw->total_todo, sw->failed, sw->running, rate, eta, final ? "\n" : "");
  }
  if (final) {
    fprintf(stderr, "sweep: %ld runs in %.2f s:", sw->done, now - sw->t_start);
    for (int s = 0; s < FMB_CHILD_NSTATUS; ++s)
      if (sw->count[s]) fprintf(stderr, " %s %ld", fmb_child_status_name((fmbChildStatus)s), sw->count[s]);
    /* the sweep's own CPU (plan, dispatch, journal, rows; its children not counted): what one
       manager spends per run, the serial part of a sweep over many ranks (docs/performance.md) */
    struct rusage ru;
    if (sw->done > 0 && getrusage(RUSAGE_SELF, &ru) == 0) {
      const double cpu = (double)ru.ru_utime.tv_sec + 1e-6 * (double)ru.ru_utime.tv_usec + (double)ru.ru_stime.tv_sec +
                         1e-6 * (double)ru.ru_stime.tv_usec;
      fprintf(stderr, " (this process: %.3f ms of CPU per run)", 1e3 * cpu / (double)sw->done);
    }
    fprintf(stderr, "\n");
  }
}

long* fmb_sweep_todo(fmbSweep* sw, long* n, long* n_inflight) {
  /* FMB_TEST_SWEEP_NO_MEMORY: this allocation fails (test_mpi: the other ranks must not wait on rank 0) */
  long* todo = getenv("FMB_TEST_SWEEP_NO_MEMORY") ? NULL : malloc((size_t)(sw->nrun + 1) * sizeof *todo);
  long k = 0;
  if (!todo) return NULL;
  for (int pass = 0; pass < 2; ++pass)
    for (long i = 0; i < sw->nrun; ++i) {
      if (sw->first[i] != i) continue;
      const int st = sw->status[i];
      const int inflight = st < 0 && sw->starts[i] > 0;
      const int want = st < 0 || (sw->retry_mask >> st & 1u);
      if (!want || (pass == 0) != inflight) continue;
      if (inflight && sw->starts[i] >= FMB_SWEEP_MAX_RETRIES) { /* in flight at three stops: lost */
        char* row = fmb_sweep_row_lost(sw, i, sw->starts[i]);
        if (row && fmb_journal_append(sw, i, row) == 0) fmb_sweep_account(sw, FMB_CHILD_LOST, 0.0);
        free(row);
        continue;
      }
      todo[k++] = i;
      if (pass == 0) ++*n_inflight;
    }
  *n = k;
  return todo;
}

/* records the row of a finished child */
static void finish(fmbSweep* sw, const fmbChildResult* r) {
  char* row = fmb_sweep_row(sw, r, sw->starts[sw->first[r->tag]]);
  if (!row) fmb_sweep_disk_full(sw, "a row", ENOMEM);
  if (row && fmb_journal_append(sw, r->tag, row) == 0) fmb_sweep_account(sw, (int)r->status, r->wall_s);
  free(row);
}

void fmb_sweep_cancel(fmbSweep* sw, fmbPool* pool) {
  long tags[1024];
  const int n = fmb_pool_running(pool) <= 1024 ? fmb_pool_tags(pool, tags) : 0;
  fmb_pool_kill_all(pool, 2.0);
  for (int k = 0; k < n; ++k) fmb_journal_cancelled(sw, tags[k]);
}

int fmb_sweep_rerun_inflight(fmbSweep* sw, const long* todo, long n) {
  if (n == 0) return 0;
  fmbPool* pool = fmb_pool_new(1);
  if (!pool) return FMB_EXIT_BAD_INPUT;
  for (long k = 0; k < n && !*sw->stop && !sw->disk_full; ++k) {
    fmb_journal_started(sw, todo[k]);
    if (fmb_sweep_start(sw, pool, todo[k], fmb_sweep_timeout(sw)) != 0) continue;
    sw->running = 1;
    fmbChildResult r;
    int got = 0;
    while (!*sw->stop && (got = fmb_pool_wait(pool, 0.5, &r)) == 0) fmb_sweep_progress(sw, 0);
    sw->running = 0;
    if (got == 1) finish(sw, &r);
  }
  if (*sw->stop) fmb_sweep_cancel(sw, pool);
  fmb_pool_free(pool);
  return *sw->stop ? FMB_EXIT_INTERRUPTED : 0;
}

/* the sweep as a farm (farm.h): runs handed out from the to-do list, rows into the journal */
typedef struct {
  fmbSweep* sw;
  const long* todo;
  long next, n;
} Feed;
static int feed_next(void* ctx, fmbFarmTask* task) {
  Feed* f = ctx;
  if (f->next >= f->n || f->sw->disk_full) return 0; /* a full disk: nothing more is started */
  const long i = f->todo[f->next++];
  fmb_journal_started(f->sw, i);
  task->index = i;
  task->attempt = f->sw->starts[f->sw->first[i]];
  task->timeout_s = fmb_sweep_timeout(f->sw);
  return 1;
}
static int feed_start(void* ctx, fmbPool* pool, const fmbFarmTask* task) {
  return fmb_sweep_start(((Feed*)ctx)->sw, pool, task->index, task->timeout_s);
}
static char* feed_result(void* ctx, const fmbChildResult* r, int attempt, int* len) {
  char* row = fmb_sweep_row(((Feed*)ctx)->sw, r, attempt);
  *len = row ? (int)strlen(row) : 0;
  return row;
}
/* the n-th field of a row (after n commas), or NULL */
static const char* row_field(const char* row, int n) {
  for (int k = 0; k < n && row; ++k) row = strchr(row, ',') ? strchr(row, ',') + 1 : NULL;
  return row;
}
/* a row into the journal; from another rank, its index, status and wall time are read from it */
static void feed_take(void* ctx, const fmbChildResult* local, char* row, int len) {
  fmbSweep* sw = ((Feed*)ctx)->sw;
  long index = local ? local->tag : -1;
  int status = local ? (int)local->status : -1;
  double wall_s = local ? local->wall_s : 0.0;
  if (!local && len > 0) { /* index,run_id,attempt,status,exit_code,signal,wall_s,... */
    index = strtol(row, NULL, 10);
    const char* st = row_field(row, 3);
    char name[32] = "";
    if (st) snprintf(name, sizeof name, "%.*s", (int)strcspn(st, ","), st);
    status = fmb_child_status_of(name);
    const char* wall = row_field(row, 6);
    wall_s = wall ? strtod(wall, NULL) : 0.0;
  }
  if (index >= 0 && index < sw->nrun && len > 0 && fmb_journal_append(sw, index, row) == 0)
    fmb_sweep_account(sw, status, wall_s);
  else if (!sw->disk_full)
    fprintf(stderr, "flexmbd sweep: a row that cannot be taken (run %ld): the run will be done again on resume\n",
            index);
  free(row);
}
static void feed_tick(void* ctx, long running) {
  fmbSweep* sw = ((Feed*)ctx)->sw;
  sw->running = running;
  fmb_sweep_progress(sw, 0);
}
static void feed_cancelled(void* ctx, long index) { fmb_journal_cancelled(((Feed*)ctx)->sw, index); }

int fmb_sweep_farm(fmbSweep* sw, const fmbFarmTransport* t) {
  long n = 0, ninf = 0;
  long* todo = NULL;
  int rc = 0;
  if (sw->rank == 0) {
    if (!(todo = fmb_sweep_todo(sw, &n, &ninf))) rc = FMB_EXIT_BAD_INPUT, n = ninf = 0;
    sw->total_todo = sw->done + n;
    if (!rc) rc = fmb_sweep_rerun_inflight(sw, todo, ninf); /* alone, before anything else runs */
  }
  Feed feed = {sw, todo, ninf, rc ? ninf : n};
  const fmbFarm farm = {.jobs = sw->jobs,
                        .stop = sw->stop,
                        .ctx = &feed,
                        .next = feed_next,
                        .start = feed_start,
                        .result = feed_result,
                        .take = feed_take,
                        .tick = feed_tick,
                        .cancelled = feed_cancelled};
  /* after a failure above, rank 0 still runs the farm under MPI, with nothing to hand out: the
     other ranks, waiting for their first task, are told to stop instead of waiting forever */
  const int farm_rc = !rc || (t && t->nranks > 1) ? fmb_farm_run(&farm, t) : 0;
  if (!rc) rc = farm_rc;
  free(todo);
  return rc == FMB_EXIT_SOLVER ? FMB_EXIT_BAD_INPUT : rc; /* out of memory: as before */
}
