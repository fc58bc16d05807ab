/* sweep_main.c — `flexmbd sweep` once its options are read (tools/cmd_sweep.c): the plan checked and
 * laid out, the run ids, the folder made and locked, the inputs snapshotted, --dry-run, then the
 * runs (sweep_exec.c, sweep_serve.c) and the files written at the end (docs/sweep.md). */
#define _GNU_SOURCE /* sched_getaffinity */
#include <dirent.h>
#include <errno.h>
#include <math.h>
#include <sched.h>
#include <signal.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>
#include <sys/stat.h>
#include <unistd.h>

#include "cli.h"
#include "flexmbd_commit.h" /* generated at build time: FLEXMBD_COMMIT */
#include "sweep.h"

#define YES_LIMIT 1e6 /* a larger plan needs --yes */
#define MAX_PLAN 1e9  /* a larger plan is refused */

static volatile sig_atomic_t stop_requested;
static void on_stop(int sig) {
  (void)sig;
  stop_requested = 1;
}

int fmb_sweep_bad(const char* fmt, const char* what) {
  fprintf(stderr, "flexmbd sweep: ");
  fprintf(stderr, fmt, what);
  fputc('\n', stderr);
  return FMB_EXIT_BAD_INPUT;
}
#define bad fmb_sweep_bad

/* the id of every run: FNV-1a 64 over the scene's bytes, the verb, the engine version, the plugins
   and the run's overrides (fixed and swept), sorted, numbers printed %.17g; identical runs share
   one id and run once */
static int by_text(const void* a, const void* b) { return strcmp(*(char* const*)a, *(char* const*)b); }
static uint64_t hash_file(uint64_t h, const char* path) { /* the plugins' files */
  FILE* f = fopen(path, "rb");
  if (!f) return h;
  char buf[1 << 15];
  size_t n;
  while ((n = fread(buf, 1, sizeof buf, f)) > 0) h = fmb_fnv1a(h, buf, n);
  fclose(f);
  return h;
}
typedef struct {
  uint64_t id;
  long i;
} IdIndex;
static int by_id(const void* a, const void* b) {
  const IdIndex *x = a, *y = b;
  return x->id < y->id ? -1 : x->id > y->id ? 1 : (x->i > y->i) - (x->i < y->i);
}
static int make_ids(fmbSweep* sw, const char* scene_text, size_t scene_len) {
  sw->id = malloc((size_t)sw->nrun * sizeof *sw->id);
  sw->first = malloc((size_t)sw->nrun * sizeof *sw->first);
  if (!sw->id || !sw->first) return -1;
  uint64_t base = fmb_fnv1a(FMB_FNV_OFFSET, "flexmbd sweep run 1", 20);
  base = fmb_fnv1a(base, scene_text, scene_len); /* the bytes of the snapshot the runs read */
  const char* version = FLEXMBD_VERSION " " FLEXMBD_COMMIT;
  base = fmb_fnv1a(base, sw->verb, strlen(sw->verb) + 1);
  base = fmb_fnv1a(base, version, strlen(version) + 1);
  for (int k = 0; k < sw->nplugins; ++k) base = hash_file(base, sw->plugins[k]);
  const int nset = sw->nfixed + sw->plan.npath;
  char** sets = malloc((size_t)nset * sizeof *sets);
  char* text = malloc((size_t)sw->plan.npath * 600);
  if (!sets || !text) return free(sets), free(text), -1;
  sw->digest = FMB_FNV_OFFSET;
  for (long i = 0; i < sw->nrun; ++i) {
    int n = 0;
    for (int k = 0; k < sw->nfixed; ++k) sets[n++] = (char*)sw->fixed[k];
    for (int k = 0; k < sw->plan.npath; ++k) {
      snprintf(text + 600 * k, 600, "%s=%s", sw->plan.path[k], fmb_plan_value(&sw->plan, i, k));
      sets[n++] = text + 600 * k;
    }
    qsort(sets, (size_t)n, sizeof *sets, by_text);
    uint64_t h = base;
    for (int k = 0; k < n; ++k) h = fmb_fnv1a(h, sets[k], strlen(sets[k]) + 1);
    sw->id[i] = fmb_mix64(h); /* FNV-1a alone leaves ids of runs that differ in a last digit alike */
    sw->digest = fmb_fnv1a(sw->digest, &h, sizeof h);
  }
  free(sets), free(text);
  /* identical runs: the first index of each id (a sorted copy keeps this O(n log n)) */
  IdIndex* p = malloc((size_t)sw->nrun * sizeof *p);
  if (!p) return -1;
  for (long i = 0; i < sw->nrun; ++i) p[i] = (IdIndex){sw->id[i], i};
  qsort(p, (size_t)sw->nrun, sizeof *p, by_id);
  for (long k = 0; k < sw->nrun; ++k)
    sw->first[p[k].i] = k > 0 && p[k].id == p[k - 1].id ? sw->first[p[k - 1].i] : p[k].i;
  free(p);
  return 0;
}

/* a file of our own in DIR/logs (mkstemp: created new, never a link or someone's file), closed */
static int own_temp(const fmbSweep* sw, const char* stem, char* path, size_t len) {
  snprintf(path, len, "%s/logs/%s.XXXXXX", sw->dir, stem);
  const int fd = mkstemp(path);
  if (fd < 0) return -1;
  close(fd);
  return 0;
}

/* `flexmbd check` of run `index` in a child: its exit code (its messages on stderr when it fails);
   with --verb run, every --metric column is checked against the outputs it lists (2 when one is
   missing: refused before any run) */
static int check_run(fmbSweep* sw, long index, int verbose) {
  char err[4300], out[4300];
  if (own_temp(sw, "check-err", err, sizeof err) || own_temp(sw, "check-out", out, sizeof out)) {
    fprintf(stderr, "flexmbd sweep: cannot create a file in %s/logs: %s\n", sw->dir, strerror(errno));
    unlink(err);
    return 3;
  }
  char* argv[FMB_SWEEP_MAX_ARGS];
  char sets[FMB_SWEEP_MAX_PATHS][FMB_SWEEP_SET_LEN];
  fmb_sweep_argv(sw, index, "check", NULL, argv, sets);
  fmbPool* pool = fmb_pool_new(1);
  /* a check that crashes or hangs is left to the runs to record; only refused input stops the sweep */
  fmbChildSpec spec = {.argv = argv,
                       .stdout_path = out,
                       .stderr_path = err,
                       .timeout_s = sw->timeout_s < 10 ? sw->timeout_s : 10.0,
                       .mem_limit_mb = sw->mem_limit_mb};
  fmbChildResult r = {.status = FMB_CHILD_CRASHED};
  if (pool && fmb_pool_start(pool, &spec) == 0)
    while (fmb_pool_wait(pool, 1.0, &r) == 0) {
    }
  fmb_pool_free(pool);
  int rc = r.status == FMB_CHILD_OK ? 0 : r.status == FMB_CHILD_BAD_INPUT ? 2 : 3;
  if (verbose || rc) {
    fprintf(stderr, "check of run %ld:", index);
    for (int k = 0; k < sw->plan.npath; ++k) fprintf(stderr, " %s", sets[k]);
    fprintf(stderr, ": %s\n", rc == 0 ? "loads" : fmb_child_status_name(r.status));
    FILE* f = rc ? fopen(err, "r") : NULL;
    char line[2048];
    while (f && fgets(line, sizeof line, f))
      if (strncmp(line, "stats:", 6) != 0) fprintf(stderr, "  %s", line);
    if (f) fclose(f);
  }
  if (rc == 0 && strcmp(sw->verb, "run") == 0 && sw->nmetric > 0) { /* "outputs: t a b ..." */
    FILE* f = fopen(out, "r");
    size_t cap = 0;
    char* line = NULL;
    while (f && getline(&line, &cap, f) > 0 && strncmp(line, "outputs: ", 9) != 0) {
    }
    for (int k = 0; f && line && strncmp(line, "outputs: ", 9) == 0 && k < sw->nmetric; ++k) {
      const char* c = sw->metric[k].column;
      const size_t n = strlen(c);
      int found = 0;
      for (const char* p = line + 8; p && !found; p = strchr(p + 1, ' '))
        found = strncmp(p + 1, c, n) == 0 && (p[1 + n] == ' ' || p[1 + n] == '\n' || !p[1 + n]);
      if (!found) {
        line[strcspn(line, "\n")] = '\0';
        fprintf(stderr, "flexmbd sweep: --metric %s: the runs have no column '%s' (%s)\n", c, c, line);
        rc = 2;
        break;
      }
    }
    free(line);
    if (f) fclose(f);
  }
  unlink(err);
  unlink(out);
  return rc;
}

/* DIR (and its parents), DIR/series, DIR/logs, DIR/inputs: made, or folders already (never links: a link planted
   there would send the runs' files elsewhere) */
static int make_dirs(const char* dir) {
  char p[4300];
  const char* sub[4] = {"", "/series", "/logs", "/inputs"};
  snprintf(p, sizeof p, "%s", dir); /* its parents too (-o out/study in a fresh checkout) */
  for (char* c = strchr(p + 1, '/'); c; c = strchr(c + 1, '/')) {
    *c = '\0';
    if (mkdir(p, 0755) != 0 && errno != EEXIST) break; /* said below, at DIR itself */
    *c = '/';
  }
  for (int k = 0; k < 4; ++k) {
    snprintf(p, sizeof p, "%s%s", dir, sub[k]);
    struct stat st;
    if (mkdir(p, 0755) != 0 && errno != EEXIST) {
      fprintf(stderr, "flexmbd sweep: cannot create %s: %s\n", p, strerror(errno));
      return FMB_EXIT_BAD_INPUT;
    }
    if ((k ? lstat(p, &st) : stat(p, &st)) != 0 || !S_ISDIR(st.st_mode)) {
      fprintf(stderr, "flexmbd sweep: %s is not a folder of its own (a file or a link): give another -o DIR\n", p);
      return FMB_EXIT_BAD_INPUT;
    }
    /* no link in series/ or logs/: a run's CSV or log written through one would land elsewhere */
    DIR* d = k == 1 || k == 2 ? opendir(p) : NULL;
    struct dirent* e;
    while (d && (e = readdir(d))) {
      char q[4600];
      snprintf(q, sizeof q, "%s/%s", p, e->d_name);
      if (lstat(q, &st) == 0 && S_ISLNK(st.st_mode)) {
        fprintf(stderr, "flexmbd sweep: %s is a symbolic link: the sweep writes only files of its own there\n", q);
        closedir(d);
        return FMB_EXIT_BAD_INPUT;
      }
    }
    if (d) closedir(d);
  }
  return 0;
}

/* bytes into DIR/inputs/SUB/name through the safe path, unless a file with these bytes is there */
static int snapshot_file(fmbSweep* sw, const char* sub, const char* name, const char* text, size_t n, char* path,
                         size_t len) {
  char rel[600];
  snprintf(rel, sizeof rel, "inputs/%s/%s", sub, name);
  snprintf(path, len, "%s/%s", sw->dir, rel);
  char* old = NULL;
  size_t oldn = 0;
  char why[600];
  struct stat st;
  if (lstat(path, &st) == 0 && S_ISREG(st.st_mode) &&
      fmb_sweep_read_input(path, n, &old, &oldn, why, sizeof why) == 0 && oldn == n && memcmp(old, text, n) == 0) {
    free(old);
    return 0;
  }
  free(old);
  fmbSafeFile* f = fmb_sweep_file_open(sw, rel);
  const int ok = f && (n == 0 || write(fmb_safe_fd(f), text, n) == (ssize_t)n);
  if (f && !ok) fmb_sweep_disk_full(sw, path, errno);
  return fmb_sweep_file_close(sw, rel, f, ok) == 0 && ok ? 0 : -1;
}

/* the snapshot's folder name: a hash of the scene's bytes and of its folder (the links beside the
   copy lead into that folder: the same bytes elsewhere are another snapshot) */
static void snapshot_name(const char* scene, const char* text, size_t n, char sub[17]) {
  const char* slash = strrchr(scene, '/');
  char from[4300];
  snprintf(from, sizeof from, "%.*s", slash ? (int)(slash - scene) : 1, slash ? scene : ".");
  char* real = realpath(from[0] ? from : "/", NULL);
  uint64_t h = fmb_fnv1a(FMB_FNV_OFFSET, text, n);
  if (real) h = fmb_fnv1a(h, real, strlen(real) + 1);
  free(real);
  snprintf(sub, 17, "%016llx", (unsigned long long)fmb_mix64(h));
}

/* The scene as the runs read it: its bytes, read once, hashed into the run ids and written to
   DIR/inputs/HASH/NAME, which every run loads. An edit of the scene during the sweep changes
   nothing (the ids and the runs are of the snapshot; the next start of the sweep sees a new
   plan). The files the scene names by relative paths (tables, plugins) are found beside it as
   before: DIR/inputs/HASH/ holds a link to every other entry of the scene's folder. */
static int snapshot_scene(fmbSweep* sw, const char* sub, const char* text, size_t n, char* path, size_t len) {
  char dir[4300];
  snprintf(dir, sizeof dir, "%s/inputs/%s", sw->dir, sub);
  struct stat st;
  if (mkdir(dir, 0755) != 0 && (errno != EEXIST || lstat(dir, &st) != 0 || !S_ISDIR(st.st_mode))) {
    fprintf(stderr, "flexmbd sweep: cannot create the folder %s of its own\n", dir);
    return -1;
  }
  const char* slash = strrchr(sw->scene_given, '/');
  const char* base = slash ? slash + 1 : sw->scene_given;
  if (snapshot_file(sw, sub, base, text, n, path, len)) return -1;
  char from[4300];
  snprintf(from, sizeof from, "%.*s", slash ? (int)(slash - sw->scene_given) : 1, slash ? sw->scene_given : ".");
  char* real = realpath(from[0] ? from : "/", NULL);
  DIR* d = real ? opendir(real) : NULL;
  struct dirent* e;
  int count = 0;
  while (d && (e = readdir(d)) && count < 100000) {
    if (strcmp(e->d_name, ".") == 0 || strcmp(e->d_name, "..") == 0 || strcmp(e->d_name, base) == 0) continue;
    char link[4600], target[8400];
    snprintf(link, sizeof link, "%s/%s", dir, e->d_name);
    snprintf(target, sizeof target, "%s/%s", strcmp(real, "/") ? real : "", e->d_name);
    if (symlink(target, link) == 0) ++count;
  }
  if (d) closedir(d);
  free(real);
  return 0;
}

/* the checks that need every option, and the plan laid out: -1 to go on, else the exit code */
static int plan_checks(fmbSweepArgs* a) {
  fmbSweep* sw = &a->sw;
  char err[1200];
  if (!sw->scene) return bad("no scene file given (flexmbd sweep --help)%s", "");
  if (!sw->dir) return bad("no output folder given (-o DIR)%s", "");
  if (a->resume && a->fresh) return bad("--resume and --fresh exclude each other%s", "");
  if (fmb_sweep_read_input(sw->scene, 1u << 28, &sw->scene_text, &sw->scene_len, err, sizeof err))
    return fprintf(stderr, "%s (the scene)\n", err), FMB_EXIT_BAD_INPUT;
  if (sw->serve == 1 && strcmp(sw->verb, "run") != 0) return bad("--runner serve goes with --verb run%s", "");
  if (a->design_lhs >= 0 && !sw->plan.nrandom) return bad("--design goes with --random%s", "");
  if (a->seed_given && !sw->plan.nrandom) return bad("--seed goes with --random%s", "");
  sw->plan.count = a->count;
  sw->plan.lhs = a->design_lhs == 1;
  /* the size from the factors' counts alone, before a value is laid out or a random sample drawn:
     a refused plan costs nothing (a plan of 1e7 runs was built in full, 8.6 s and 395 MB, first) */
  const double size = fmb_plan_size(&sw->plan);
  if (size > MAX_PLAN)
    return fprintf(stderr, "flexmbd sweep: a plan of %.4g runs is beyond the limit of 1e9\n", size), FMB_EXIT_BAD_INPUT;
  if (size > YES_LIMIT && !a->yes && !a->dry)
    return fprintf(stderr,
                   "flexmbd sweep: the plan has %.4g runs (more than 1e6): check it with --dry-run, then add --yes\n",
                   size),
           FMB_EXIT_BAD_INPUT;
  if (size > YES_LIMIT && !a->yes) { /* --dry-run of a huge plan: its size, nothing built or written */
    printf("sweep plan: %.0f runs of %s %s (more than 1e6): add --yes to lay it out (plan.csv) and check it\n", size,
           sw->verb, sw->scene);
    return 0;
  }
  if (fmb_plan_finish(&sw->plan, err, sizeof err)) return bad("%s", err);
  sw->nrun = (long)size;
  for (int k = 0; k < sw->nfixed; ++k)
    for (int p = 0; p < sw->plan.npath; ++p)
      if (strncmp(sw->fixed[k], sw->plan.path[p], strlen(sw->plan.path[p])) == 0 &&
          sw->fixed[k][strlen(sw->plan.path[p])] == '=')
        return bad("'%s' is both swept and fixed by --set", sw->plan.path[p]);
  return -1;
}

/* --reference REF.csv and its --columns: the error of every run against it, per column */
static int load_reference(fmbSweepArgs* a) {
  fmbSweep* sw = &a->sw;
  char err[1200];
  if (sw->reference) { /* the error per run against a reference, per column */
    if (fmb_cli_check_input(sw->reference, "reference")) return FMB_EXIT_BAD_INPUT;
    if (fmb_table_load(sw->reference, &sw->ref, err, sizeof err)) return bad("%s", err);
    for (int c = 1; c < sw->ref.ncol && !a->columns && sw->nrefcol < FMB_SWEEP_MAX_METRICS; ++c)
      sw->refcol[sw->nrefcol++] = c;
    for (const char* s = a->columns; s && *s && sw->nrefcol < FMB_SWEEP_MAX_METRICS;) {
      char name[200];
      size_t n = strcspn(s, ",");
      snprintf(name, sizeof name, "%.*s", (int)(n < 199 ? n : 199), s);
      int c = fmb_table_col(&sw->ref, name);
      if (c < 0)
        return fprintf(stderr, "flexmbd sweep: --a->columns: no column '%s' in %s\n", name, sw->reference),
               FMB_EXIT_BAD_INPUT;
      sw->refcol[sw->nrefcol++] = c;
      s += n + (s[n] == ',');
    }
  } else if (a->columns) {
    return bad("--a->columns goes with --reference%s", "");
  }
  return 0;
}

/* this program's path (the runs' children run it), the number of children, the scene's
   snapshot name (snap_sub) and path (sw->scene), the run ids */
static int prepare(fmbSweep* sw, char snap_sub[17]) {
  ssize_t el = readlink("/proc/self/exe", sw->exe, sizeof sw->exe - 1);
  if (el <= 0) return bad("cannot find this program (/proc/self/exe)%s", "");
  sw->exe[el] = '\0';
  if (sw->jobs == 0) { /* the CPUs this process may use (a rank bound to cores gets its share) */
    long n = sysconf(_SC_NPROCESSORS_ONLN);
#ifdef __linux__
    cpu_set_t set;
    if (sched_getaffinity(0, sizeof set, &set) == 0) n = CPU_COUNT(&set);
#endif
    sw->jobs = n > 0 ? (int)n : 1;
  }
  /* every run loads the snapshot DIR/inputs/HASH/NAME (snapshot_scene, written by rank 0 below) */
  sw->scene_given = sw->scene;
  snapshot_name(sw->scene, sw->scene_text, sw->scene_len, snap_sub);
  {
    char* snap = malloc(strlen(sw->dir) + strlen(sw->scene) + 64);
    const char* slash = strrchr(sw->scene, '/');
    if (!snap) return bad("out of memory%s", "");
    sprintf(snap, "%s/inputs/%s/%s", sw->dir, snap_sub, slash ? slash + 1 : sw->scene);
    sw->scene = snap;
  }
  if (make_ids(sw, sw->scene_text, sw->scene_len)) return bad("out of memory for %s runs", "the");
  return 0;
}

/* rank 0: the folder is the sweep's own: made, locked, and the inputs noted (no file of the sweep
   may replace one) and snapshotted, before anything is written there */
static int own_folder(fmbSweepArgs* a, const char* snap_sub) {
  fmbSweep* sw = &a->sw;
  char err[1200];
  int rc = 0;
  fmb_cli_note_input(sw->scene_given);
  if (a->samples_name) fmb_cli_note_input(a->samples_name);
  if (sw->reference) fmb_cli_note_input(sw->reference);
  rc = make_dirs(sw->dir);
  if (!rc) rc = fmb_sweep_lock(sw);
  /* the files written at the end too, checked now: refused before the runs, not after them */
  const char* const ends[3] = {"plan.csv", "table.csv", "sweep.h5"};
  for (int k = 0; k < 3 && !rc; ++k)
    if (fmb_sweep_may_write(sw, ends[k])) rc = FMB_EXIT_BAD_INPUT;
  char path[4300];
  if (!rc && snapshot_scene(sw, snap_sub, sw->scene_text, sw->scene_len, path, sizeof path)) rc = FMB_EXIT_BAD_INPUT;
  if (!rc && strcmp(path, sw->scene) != 0) rc = bad("the scene's snapshot is not %s", sw->scene);
  const char* hash = snap_sub;
  if (!rc && a->samples_name &&
      snapshot_file(sw, hash, "samples.csv", sw->samples_text, sw->samples_len, path, sizeof path))
    rc = FMB_EXIT_BAD_INPUT;
  if (!rc && sw->reference) {
    char* ref = NULL;
    size_t nref = 0;
    if (fmb_sweep_read_input(sw->reference, 1u << 30, &ref, &nref, err, sizeof err))
      rc = (fprintf(stderr, "flexmbd sweep: --reference %s\n", err), FMB_EXIT_BAD_INPUT);
    else if (snapshot_file(sw, hash, "reference.csv", ref, nref, path, sizeof path))
      rc = FMB_EXIT_BAD_INPUT;
    free(ref);
  }
  if (!rc) fmb_cli_note_input(sw->scene);
  return rc;
}

/* --dry-run: the plan's size, plan.csv, and `flexmbd check` of its first, last and a random run */
static int dry_run(fmbSweep* sw) {
  int rc = 0;
  long distinct = 0;
  for (long i = 0; i < sw->nrun; ++i) distinct += sw->first[i] == i;
  printf("sweep plan: %ld runs (%ld distinct) of %s %s, %d swept paths:", sw->nrun, distinct, sw->verb, sw->scene_given,
         sw->plan.npath);
  for (int k = 0; k < sw->plan.npath; ++k) printf(" %s", sw->plan.path[k]);
  printf("\n");
  if (fmb_journal_write_plan(sw) == 0)
    printf("sweep plan: written to %s/plan.csv\n", sw->dir);
  else
    rc = FMB_EXIT_BAD_INPUT;
  fflush(stdout);
  long pick[3] = {0, sw->nrun - 1, (long)(fmb_plan_uniform(sw->plan.seed, 0, 1u << 20) * (double)sw->nrun)};
  for (int k = 0; k < 3 && !rc; ++k)
    if (k == 0 || (pick[k] != pick[0] && pick[k] != pick[1])) rc = check_run(sw, pick[k], 1);
  return rc ? FMB_EXIT_BAD_INPUT : 0;
}

/* the runs on every rank, then (rank 0) the table, sweep.h5 and the last word */
static int run_all(fmbSweep* sw, fmbFarmTransport* ranks, int rc) {
  struct sigaction sa;
  memset(&sa, 0, sizeof sa);
  sa.sa_handler = on_stop; /* no SA_RESTART: the pool's wait returns at once */
  sigemptyset(&sa.sa_mask);
  sigaction(SIGINT, &sa, NULL);
  sigaction(SIGTERM, &sa, NULL);
  sw->progress = !sw->quiet && isatty(STDERR_FILENO);
  sw->t_start = fmb_pool_now();
  if (sw->nranks > 1) /* rank 0's verdict on the spec and the journal: every rank stops on it */
    rc = ranks->bcast_int(rc);
  const fmbFarmTransport* t = sw->nranks > 1 ? ranks : NULL;
  if (!rc) rc = sw->serve ? fmb_sweep_serve(sw, t) : fmb_sweep_farm(sw, t);
  if (sw->rank == 0 && sw->journal_fd >= 0) {
    fmb_sweep_progress(sw, 1);
    if (fmb_journal_write_table(sw) && !sw->disk_full) fmb_sweep_disk_full(sw, "table.csv", EIO);
    const fmbSweepExtension* ext = fmb_sweep_extension_load(1);
    if (rc == 0 && !sw->disk_full && ext->has_hdf5) { /* through the safe path: a temporary beside it */
      fmbSafeFile* h5 = fmb_sweep_file_open(sw, "sweep.h5");
      const int ok = h5 && ext->write_h5(sw, fmb_safe_write_path(h5)) == 0;
      if (h5 && !ok) fprintf(stderr, "flexmbd sweep: cannot write %s/sweep.h5\n", sw->dir);
      if (fmb_sweep_file_close(sw, "sweep.h5", h5, ok) != 0 || !ok) fmb_sweep_disk_full(sw, "sweep.h5", EIO);
    }
    fmb_journal_close(sw);
    if (rc == FMB_EXIT_INTERRUPTED)
      fprintf(stderr,
              "sweep: interrupted; every child stopped, %s/runs.csv is complete: run the same command to resume\n",
              sw->dir);
    if (sw->disk_full && (rc == 0 || rc == FMB_EXIT_INTERRUPTED)) {
      long left = 0;
      for (long i = 0; i < sw->nrun; ++i) left += sw->first[i] == i && sw->status[i] < 0;
      fprintf(stderr,
              "flexmbd sweep: stopped: a write failed (%s; the disk is full?): %ld runs have no row; free space and "
              "run the same command to resume\n",
              sw->disk_why, left);
      rc = FMB_EXIT_SOLVER;
    }
  }
  return rc;
}

int fmb_sweep_main(fmbSweepArgs* a) {
  fmbSweep* sw = &a->sw;
  sw->stop = &stop_requested;
  if (a->status_dir) return fmb_journal_status(a->status_dir);
  int rc = plan_checks(a);
  if (rc >= 0) return rc;
  if ((rc = load_reference(a)) != 0) return rc;
  char snap_sub[17];
  if ((rc = prepare(sw, snap_sub)) != 0) return rc;
  /* the module (MPI, HDF5) is loaded now only under mpirun/srun: mapped into this process, its
     libraries make every fork of a child slower; otherwise only at the end, for sweep.h5 */
  fmbFarmTransport ranks;
  const int mpi = fmb_farm_mpi_start("sweep", &ranks);
  if (mpi < 0) return 0; /* built without MPI: rank 0 runs the sweep alone */
  sw->rank = ranks.rank, sw->nranks = ranks.nranks;
  const fmbSweepExtension* ext = fmb_sweep_extension_load(0);
  /* --runner auto (the default): alone, persistent runners for `--verb run`; a process per run otherwise. A runner
   * still runs each run in a child (a crash or a hang costs that run's row and a fresh runner takes the slot, tested)
   * and saves the ~3 ms exec and linking of every run: 1.28x -> 1.70x the serial loop on 400 four-bar runs on 2 cores
   * (bench/sweep.sh, docs/performance.md "Sweeps"). Across ranks it stays a process per run: with runners on the
   * workers, SIGTERM to Open MPI 4.1's mpirun left mpirun spinning after the ranks' MPI_Abort (seen in sweep_mpi). */
  if (sw->serve < 0) sw->serve = sw->nranks == 1 && strcmp(sw->verb, "run") == 0;

  if (sw->rank != 0 && a->dry) { /* rank 0 alone checks the plan */
    ext->mpi_finalize(0);
    return 0;
  }
  if (sw->rank == 0) {
    rc = own_folder(a, snap_sub);
    if (!rc && a->dry) {
      rc = dry_run(sw);
      ext->mpi_finalize(0);
      return rc;
    }
    if (!rc) rc = check_run(sw, 0, 0) == 2 ? FMB_EXIT_BAD_INPUT : 0; /* an unknown path: refused before anything runs */
    if (!rc) rc = fmb_journal_open(sw, a->resume, a->fresh);
    if (!rc) rc = fmb_journal_write_plan(sw) ? FMB_EXIT_BAD_INPUT : 0;
  }
  rc = run_all(sw, &ranks, rc);
  ext->mpi_finalize(rc);
  return rc;
}
