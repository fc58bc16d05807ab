/* cmd_sweep.c — `flexmbd sweep SCENE.yaml -o DIR [--grid PATH=A:B:N[:log] | --grid PATH=v1,v2,...]...
 *                 [--zip PATH=v1,v2,...]... [--samples FILE.csv] [--random PATH=uniform(a,b)|normal(m,s)|
 *                 lognormal(m,s)]... [--count N] [--seed S] [--design mc|lhs] [--set PATH=VALUE]...
 *                 [--verb run|static|modes] [--metric COL:max,min,end,rms]... [--reference REF.csv
 *                 [--columns a,b]] [-j K] [--timeout SEC|Nx] [--retry STATUS,...] [--keep summary|series]
 *                 [--runner auto|spawn|serve] [--mem-limit MB] [--dry-run] [--resume|--fresh] [--yes] [--quiet] [--plugin x.so]...`
 *               `flexmbd sweep --status DIR`
 * This file reads the options (one table, tools/options.h); tools/sweep_main.c goes from them to
 * the plan and the engine (docs/sweep.md). Every run is a child process (child_pool.c), its row
 * appended to DIR/runs.csv as it ends (sweep_journal.c); at the end DIR/table.csv (sorted by
 * index) and, when built with HDF5, DIR/sweep.h5. Under mpirun/srun the ranks share the runs
 * (farm.c, sweep_mpi.c). Exit: 0 every planned run has a row (whatever its status), 2 bad spec (or
 * the folder is another sweep's, or holds files the sweep did not make), 3 a write failed (a full
 * disk) or no runner could be started, 4 interrupted (SIGINT/SIGTERM: every child killed, the
 * journal flushed); 3 and 4 resume when run again. */
#include <math.h>
#include <stddef.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>

#include "cli.h"
#include "sweep.h"

#define bad fmb_sweep_bad

/* COL:max,min,end,rms -> one metric per statistic */
static int add_metrics(fmbSweep* sw, const char* spec) {
  static const char* const kinds[4] = {"max", "min", "end", "rms"};
  const char* colon = strrchr(spec, ':');
  if (!colon || colon == spec || !colon[1])
    return bad("--metric expects COLUMN:max|min|end|rms (several: max,rms), got '%s'", spec);
  const char* s = colon + 1;
  while (*s) {
    size_t n = strcspn(s, ",");
    int kind = -1;
    for (int k = 0; k < 4; ++k)
      if (strlen(kinds[k]) == n && strncmp(s, kinds[k], n) == 0) kind = k;
    if (kind < 0 || sw->nmetric == FMB_SWEEP_MAX_METRICS)
      return bad("--metric expects COLUMN:max|min|end|rms (several: max,rms), got '%s'", spec);
    fmbSweepMetric* m = &sw->metric[sw->nmetric++];
    snprintf(m->column, sizeof m->column, "%.*s", (int)(colon - spec), spec);
    m->kind = kind;
    s += n + (s[n] == ',');
  }
  return 0;
}

static int read_metric(const fmbOptContext* ctx, void* at, const char* v) {
  (void)ctx;
  return add_metrics(at, v) ? FMB_EXIT_BAD_INPUT : 0;
}

/* --grid, --zip, --random: a factor of the plan */
static int read_factor(const fmbOptContext* ctx, void* at, const char* v) {
  fmbSweepPlan* plan = at;
  char err[1200];
  const int r = ctx->option[2] == 'g'   ? fmb_plan_add_grid(plan, v, err, sizeof err)
                : ctx->option[2] == 'z' ? fmb_plan_add_zip(plan, v, err, sizeof err)
                                        : fmb_plan_add_random(plan, v, err, sizeof err);
  return r ? bad("%s", err) : 0;
}

/* --samples F.csv, read once (its copy goes to DIR/inputs) */
static int read_samples(const fmbOptContext* ctx, void* at, const char* v) {
  fmbSweepArgs* a = ctx->self;
  fmbSweep* sw = at;
  char err[1200];
  if (sw->samples_text) return bad("one --samples file at a time%s", "");
  if (fmb_sweep_read_input(v, 1u << 30, &sw->samples_text, &sw->samples_len, err, sizeof err) ||
      fmb_plan_add_samples(&sw->plan, v, sw->samples_text, sw->samples_len, err, sizeof err))
    return bad("--samples %s", err);
  a->samples_name = v;
  return 0;
}

static int read_seed(const fmbOptContext* ctx, void* at, const char* v) {
  char* end;
  *(uint64_t*)at = strtoull(v, &end, 10);
  if (*end || !*v || v[0] == '-') return bad("--seed needs a whole number >= 0, got '%s'", v);
  ((fmbSweepArgs*)ctx->self)->seed_given = 1;
  return 0;
}

/* --set PATH=VALUE: numbers as every run gets them, %.17g (so the run id does not depend on how
   they were typed) */
static int read_set(const fmbOptContext* ctx, void* at, const char* v) {
  (void)ctx;
  fmbSweep* sw = at;
  if (!strchr(v, '=') || sw->nfixed == FMB_SWEEP_MAX_FIXED) return bad("--set needs PATH=VALUE, got '%s'", v);
  char* end;
  const char* val = strchr(v, '=') + 1;
  double x = strtod(val, &end);
  char* t = malloc(strlen(v) + 40);
  if (!t) return FMB_EXIT_BAD_INPUT;
  if (end != val && !*end && isfinite(x))
    sprintf(t, "%.*s=%.17g", (int)(val - 1 - v), v, x);
  else
    strcpy(t, v);
  sw->fixed[sw->nfixed++] = t;
  return 0;
}

/* --plugin x.so: its real path, hashed into the run ids and handed to every run */
static int read_plugin(const fmbOptContext* ctx, void* at, const char* v) {
  (void)ctx;
  fmbSweep* sw = at;
  if (sw->nplugins == 16) return bad("at most 16 --plugin files%s", "");
  char* real = realpath(v, NULL);
  if (!real) return bad("--plugin: cannot find '%s'", v);
  sw->plugins[sw->nplugins++] = real;
  return 0;
}

static int read_timeout(const fmbOptContext* ctx, void* at, const char* v) {
  (void)ctx;
  fmbSweep* sw = at;
  char* end;
  double t = strtod(v, &end);
  const int rel = *end == 'x' && !end[1];
  if (end == v || (*end && !rel) || !(t > 0) || !isfinite(t))
    return bad("--timeout needs SEC (> 0) or Nx (N times the median of ok runs), got '%s'", v);
  if (rel)
    sw->timeout_factor = t;
  else
    sw->timeout_s = t;
  return 0;
}

static int read_retry(const fmbOptContext* ctx, void* at, const char* v) {
  (void)ctx;
  for (const char* s = v; *s;) {
    char name[32];
    size_t n = strcspn(s, ",");
    snprintf(name, sizeof name, "%.*s", (int)(n < 31 ? n : 31), s);
    int st = fmb_child_status_of(name);
    if (st < 0 || st == FMB_CHILD_OK)
      return bad("--retry needs statuses among solver_stopped,bad_input,timeout,crashed,lost, got '%s'", v);
    *(unsigned*)at |= 1u << st;
    s += n + (s[n] == ',');
  }
  return 0;
}

static int sweep_scene(const fmbOptContext* ctx, const char* arg) {
  fmbSweepArgs* a = ctx->self;
  if (a->sw.scene) return bad("unknown option or extra argument '%s'", arg);
  a->sw.scene = arg;
  return 0;
}

#define AT(field) offsetof(fmbSweepArgs, field)
#define SWEEP_CALL(name, meta, at, help, needs, call, flags) \
  { name, NULL, FMB_OPT_CALL, meta, at, help, needs, 0, 0, NULL, call, flags }
#define SWEEP_FLAG(name, alias, field, help) \
  { name, alias, FMB_OPT_FLAG, NULL, AT(field), help, NULL, 0, 0, NULL, NULL, 0 }
static const fmbOpt sweep_options[] = {
    {"--output", "-o", FMB_OPT_STRING, "DIR", AT(sw.dir), "the sweep's folder (runs.csv, table.csv, series/, logs/)",
     "a folder", 0, 0, NULL, NULL, 0},
    SWEEP_CALL("--grid", "PATH=A:B:N[:log]|PATH=v1,v2,...", AT(sw.plan),
               "a factor: every value, crossed with the others", "PATH=VALUES", read_factor, FMB_OPT_REPEAT),
    SWEEP_CALL("--zip", "PATH=v1,v2,...", AT(sw.plan), "factors that vary together (the same count of values)",
               "PATH=VALUES", read_factor, FMB_OPT_REPEAT),
    SWEEP_CALL("--samples", "F.csv", AT(sw), "one run per row of F.csv (a column per PATH)", "a CSV file", read_samples,
               0),
    SWEEP_CALL("--random", "PATH=uniform(a,b)|normal(m,s)|lognormal(m,s)", AT(sw.plan),
               "a random factor (with --count)", "PATH=VALUES", read_factor, FMB_OPT_REPEAT),
    {"--count", NULL, FMB_OPT_INT, "N", AT(count), "the number of random samples", "a whole number from 1 to 1e9", 1,
     1e9, NULL, NULL, 0},
    SWEEP_CALL("--seed", "S", AT(sw.plan.seed), "the random samples' seed", "a whole number >= 0", read_seed, 0),
    {"--design", NULL, FMB_OPT_CHOICE, "mc|lhs", AT(design_lhs), "random sampling or a Latin hypercube", "mc or lhs", 0,
     0, "mc|lhs", NULL, 0},
    SWEEP_CALL("--set", "PATH=VALUE", AT(sw), "a value every run gets", "PATH=VALUE", read_set, FMB_OPT_REPEAT),
    {"--verb", NULL, FMB_OPT_CHOICE, "run|static|modes", AT(verb), "what each run computes (default run)",
     "run, static or modes", 0, 0, "run|static|modes", NULL, 0},
    SWEEP_CALL("--metric", "COL:max,min,end,rms", AT(sw), "a summary of a column per run, in its row",
               "COLUMN:max|min|end|rms", read_metric, FMB_OPT_REPEAT),
    {"--reference", NULL, FMB_OPT_STRING, "REF.csv", AT(sw.reference), "the error of every run against REF",
     "a CSV file", 0, 0, NULL, NULL, 0},
    {"--columns", NULL, FMB_OPT_STRING, "a,b,...", AT(columns), "the columns compared with --reference",
     "a comma-separated list", 0, 0, NULL, NULL, 0},
    {"--jobs", "-j", FMB_OPT_INT, "K", AT(sw.jobs), "K runs at once (default: the CPUs this process may use)",
     "1 to 1024 children", 1, 1024, NULL, NULL, 0},
    SWEEP_CALL("--timeout", "SEC|Nx", AT(sw), "a run's wall time limit (Nx: N times the median of ok runs)",
               "SEC or Nx", read_timeout, 0),
    SWEEP_CALL("--retry", "STATUS,...", AT(sw.retry_mask), "run again the runs that ended so, on resume",
               "a list of statuses", read_retry, 0),
    {"--keep", NULL, FMB_OPT_CHOICE, "summary|series", AT(sw.keep_series), "keep each run's CSV (series) or not",
     "summary or series", 0, 0, "summary|series", NULL, 0},
    {"--runner", NULL, FMB_OPT_CHOICE, "auto|spawn|serve", AT(runner), "a process per run, or persistent runners",
     "auto, spawn or serve", 0, 0, "auto|spawn|serve", NULL, 0},
    {"--mem-limit", NULL, FMB_OPT_DOUBLE, "MB", AT(sw.mem_limit_mb), "a run's memory limit",
     "megabytes (>= 16) per run", 16, HUGE_VAL, NULL, NULL, 0},
    SWEEP_FLAG("--dry-run", NULL, dry, "lay out and check the plan (plan.csv), run nothing"),
    SWEEP_FLAG("--resume", NULL, resume, "go on with the folder's sweep (the default when it is this one)"),
    SWEEP_FLAG("--fresh", NULL, fresh, "start the folder's sweep again"),
    SWEEP_FLAG("--yes", NULL, yes, "run a plan of more than 1e6 runs"),
    SWEEP_FLAG("--quiet", "-q", sw.quiet, "no progress line"),
    SWEEP_CALL("--plugin", "x.so", AT(sw), "a plugin every run loads", "a plugin file", read_plugin, FMB_OPT_REPEAT),
    {"--status", NULL, FMB_OPT_STRING, "DIR", AT(status_dir), "what the sweep in DIR has done", "a sweep folder", 0, 0,
     NULL, NULL, 0},
};

const fmbCommandSpec fmb_sweep_command = {
    "sweep",
    "SCENE.yaml -o DIR",
    "many runs, each a child process; resumable (docs/sweep.md)",
    sweep_options,
    FMB_OPT_COUNT(sweep_options),
    sweep_scene,
    "also: flexmbd sweep --status DIR   what the sweep in DIR has done\n"
    "Runs the scene once per planned point, each run a child process; DIR/runs.csv gets one row per finished run\n"
    "(statuses ok, solver_stopped, bad_input, timeout, crashed, lost), DIR/table.csv the rows sorted by index.\n"
    "Run it again to resume. Under mpirun or srun the ranks share the runs. Exit: 0 every run has a row, 2 bad\n"
    "spec or a folder not the sweep's, 3 a write failed (disk full), 4 interrupted (3 and 4 resume). "
    "docs/sweep.md\n"};

int fmb_cmd_sweep(int argc, char** argv) {
  static fmbSweepArgs a0;
  fmbSweepArgs* a = &a0;
  memset(a, 0, sizeof *a);
  fmbSweep* sw = &a->sw;
  sw->verb = "run";
  sw->jobs = 0;
  sw->timeout_s = 600.0;
  sw->journal_fd = sw->inflight_fd = -1;
  a->design_lhs = -1;
  int rc;
  if (fmb_opt_parse(&fmb_sweep_command, argc, argv, a, &rc)) return rc;
  static const char* const verbs[] = {"run", "static", "modes"};
  sw->verb = verbs[a->verb];
  sw->serve = a->runner - 1; /* auto -1 (resolved once the verb is known), spawn 0, serve 1 */
  return fmb_sweep_main(a);
}
