/* cmd_regress.c — `flexmbd regress [PATH...] [--bless] [--junit FILE] [-j N] [--set PATH=VALUE]...
 *                                  [--slow FACTOR] [--rows N]`
 * The scene regression suite (docs/regression.md). PATH is a scene file or a folder searched
 * recursively for scenes that have a reference (default: the current folder). A scene's reference is
 * the file beside it named SCENE.ref.csv (SCENE without .yaml): a thinned copy of the run's CSV rows
 * behind a '#' header that records how it was made (flexmbd version and commit, date, solver
 * settings, the --set overrides it was made with, status, CPU time) and one tolerance per column.
 *
 * Each scene runs in a child process (a crash fails that scene only; -j N runs N at once) with the
 * overrides its reference records; every column is compared at the reference's rows with
 * |run - ref| <= atol + rtol * range(ref column). One table row per scene on stdout.
 * Exit 0 all pass, 1 any fails, 2 bad input (a missing path or reference, a malformed reference, or
 * with --bless a scene that does not load). */
#include <dirent.h>
#include <errno.h>
#include <fcntl.h>
#include <math.h>
#include <stdarg.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>
#include <sys/stat.h>
#include <sys/types.h>
#include <sys/wait.h>
#include <time.h>
#include <unistd.h>

#include "cli.h"
#include "csv_table.h"

/* Default column tolerance (docs/regression.md): --bless also runs the scene at rtol x 0.97 and
   x 1.03. Those companions take other, equally valid step sequences, as another compiler or a fused
   multiply-add does; their largest difference from the run, per column, is the column's noise:
     atol_col = NOISE_FACTOR noise + SOLVER_FACTOR atol,   rtol_col = SOLVER_FACTOR rtol
   Measured on the shipped scenes (docs/regression.md): an FMA build differs from the plain one by
   at most 1.5x the noise; a 1e-3 relative change of a length, a modulus or a mass goes 4x to 6000x
   beyond the tolerance. */
#define NOISE_FACTOR 10.0
#define SOLVER_FACTOR 10.0
#define NCOMPANION 2
static const double companion_rtol[NCOMPANION] = {0.97, 1.03};
#define DEFAULT_ROWS 201
#define MAX_DEPTH 32

typedef struct {
  char name[160];
  double atol, rtol;
  int override; /* set by a person: --bless keeps it */
} ColumnTol;

typedef struct {
  int present;
  char** sets; /* the --set overrides the reference was made with */
  int nsets;
  ColumnTol* tol;
  int ntol;
  int status_ok;
  double t_reached, cpu_s;
  fmbTable data;
} Reference;

/* what a child process reports about its run */
typedef struct {
  int loaded;     /* 0: the scene did not load (msg says why) */
  int exit_code;  /* fmb_run's */
  int status_ok;
  double t_reached, cpu_s;
  long steps;
  fmbSolverInfo solver;
  char msg[1024];
} RunResult;

typedef struct {
  char* scene;
  char* ref_path;
  int companion; /* 0 the run itself; k > 0 runs at rtol x companion_rtol[k - 1] (--bless) */
  Reference ref;
  pid_t pid;
  int pipe_fd;
  char csv[600], err[600]; /* the child's CSV and stderr */
  RunResult run;
  /* verdict */
  int failed, bad_input, warn_slow;
  char worst[160];
  double worst_err, worst_tol, worst_t;
  char why[1200];
  const char* action; /* bless: "written", "unchanged" */
} Job;

typedef struct {
  const char** sets; /* command-line --set */
  int nsets;
  int bless, jobs, rows;
  double slow;
  const char* junit;
  char tmpdir[512];
} Options;

static void* xcalloc(size_t n, size_t s) {
  void* p = calloc(n ? n : 1, s);
  if (!p) {
    fprintf(stderr, "flexmbd regress: out of memory\n");
    exit(FMB_EXIT_BAD_INPUT);
  }
  return p;
}

static char* xstrdup(const char* s) {
  char* d = strdup(s);
  if (!d) {
    fprintf(stderr, "flexmbd regress: out of memory\n");
    exit(FMB_EXIT_BAD_INPUT);
  }
  return d;
}

static void say(char* buf, size_t len, const char* fmt, ...) {
  va_list ap;
  va_start(ap, fmt);
  vsnprintf(buf, len, fmt, ap);
  va_end(ap);
}

/* ------------------------------------------------------------------------------------------------
 * Finding scenes
 * ---------------------------------------------------------------------------------------------- */

static int has_suffix(const char* s, const char* suf) {
  size_t n = strlen(s), m = strlen(suf);
  return n >= m && strcmp(s + n - m, suf) == 0;
}

static int is_scene_name(const char* s) {
  return (has_suffix(s, ".yaml") || has_suffix(s, ".yml")) && s[0] != '.';
}

/* SCENE.ref.csv beside SCENE.yaml */
static char* reference_path(const char* scene) {
  size_t n = strlen(scene);
  size_t stem = has_suffix(scene, ".yaml") ? n - 5 : has_suffix(scene, ".yml") ? n - 4 : n;
  char* r = xcalloc(stem + 9, 1);
  memcpy(r, scene, stem);
  memcpy(r + stem, ".ref.csv", 9);
  return r;
}

static int file_exists(const char* p) {
  struct stat st;
  return stat(p, &st) == 0 && S_ISREG(st.st_mode);
}

typedef struct {
  char** v;
  int n, cap;
} List;

static void list_push(List* l, char* s) {
  if (l->n == l->cap) {
    l->cap = l->cap ? 2 * l->cap : 16;
    char** nv = realloc(l->v, (size_t)l->cap * sizeof *nv);
    if (!nv) {
      fprintf(stderr, "flexmbd regress: out of memory\n");
      exit(FMB_EXIT_BAD_INPUT);
    }
    l->v = nv;
  }
  l->v[l->n++] = s;
}

static int by_name(const void* a, const void* b) { return strcmp(*(char* const*)a, *(char* const*)b); }

/* every scene below dir (symbolic links to folders are not followed: no loops); with `all`, every
   *.yaml, otherwise those with a reference */
static void walk(const char* dir, int depth, int all, List* out) {
  if (depth > MAX_DEPTH) return;
  DIR* d = opendir(dir);
  if (!d) return;
  List here = {0};
  struct dirent* e;
  while ((e = readdir(d)) != NULL) {
    if (e->d_name[0] == '.') continue; /* ., .., hidden folders such as .git */
    size_t len = strlen(dir) + strlen(e->d_name) + 2;
    char* p = xcalloc(len, 1);
    snprintf(p, len, "%s%s%s", dir, has_suffix(dir, "/") ? "" : "/", e->d_name);
    list_push(&here, p);
  }
  closedir(d);
  if (here.n > 1) qsort(here.v, (size_t)here.n, sizeof *here.v, by_name);
  for (int i = 0; i < here.n; ++i) {
    struct stat st;
    char* p = here.v[i];
    if (lstat(p, &st) != 0) {
      free(p);
      continue;
    }
    if (S_ISDIR(st.st_mode)) {
      walk(p, depth + 1, all, out);
      free(p);
    } else if (S_ISREG(st.st_mode) && is_scene_name(strrchr(p, '/') + 1)) {
      char* r = reference_path(p);
      int take = all || file_exists(r);
      free(r);
      if (take)
        list_push(out, p);
      else
        free(p);
    } else {
      free(p);
    }
  }
  free(here.v);
}

/* ------------------------------------------------------------------------------------------------
 * References
 * ---------------------------------------------------------------------------------------------- */

static void reference_free(Reference* r) {
  for (int i = 0; i < r->nsets; ++i) free(r->sets[i]);
  free(r->sets);
  free(r->tol);
  fmb_table_free(&r->data);
  memset(r, 0, sizeof *r);
}

static const ColumnTol* find_tol(const Reference* r, const char* col) {
  for (int i = 0; i < r->ntol; ++i)
    if (strcmp(r->tol[i].name, col) == 0) return &r->tol[i];
  return NULL;
}

/* "key: value" from a metadata line (leading blanks skipped); the value or NULL */
static const char* meta_value(const char* line, const char* key) {
  while (*line == ' ') ++line;
  size_t n = strlen(key);
  if (strncmp(line, key, n) != 0 || line[n] != ':') return NULL;
  line += n + 1;
  while (*line == ' ') ++line;
  return line;
}

/* 0, or -1 with why (a malformed reference is bad input) */
static int reference_load(const char* path, Reference* r, char* why, size_t len) {
  memset(r, 0, sizeof *r);
  if (fmb_table_load(path, &r->data, why, len)) return -1;
  r->present = 1;
  r->status_ok = 1;
  r->t_reached = fmb_table_t_end(&r->data);
  r->cpu_s = NAN;
  for (int i = 0; i < r->data.nmeta; ++i) {
    const char* m = r->data.meta[i];
    const char* v;
    if ((v = meta_value(m, "set"))) {
      char** ns = realloc(r->sets, (size_t)(r->nsets + 1) * sizeof *ns);
      if (!ns) return say(why, len, "%s: out of memory", path), -1;
      r->sets = ns;
      r->sets[r->nsets++] = xstrdup(v);
    } else if ((v = meta_value(m, "status"))) {
      r->status_ok = strcmp(v, "ok") == 0;
    } else if ((v = meta_value(m, "t_reached"))) {
      r->t_reached = strtod(v, NULL);
    } else if ((v = meta_value(m, "cpu_s"))) {
      r->cpu_s = strtod(v, NULL);
    } else if ((v = meta_value(m, "tolerance"))) {
      ColumnTol t = {{0}, NAN, NAN, 0};
      char flag[32] = "";
      int n = sscanf(v, "%159s atol=%lf rtol=%lf %31s", t.name, &t.atol, &t.rtol, flag);
      if (n < 3 || !(t.atol >= 0.0) || !(t.rtol >= 0.0) || !isfinite(t.atol) || !isfinite(t.rtol) ||
          (n == 4 && strcmp(flag, "override") != 0 && flag[0] != '(')) {
        say(why, len,
            "%s:%d: expected '# tolerance: COLUMN atol=A rtol=R [override]' with A, R >= 0, got '#%.200s'", path,
            i + 1, m);
        return -1;
      }
      t.override = n == 4 && strcmp(flag, "override") == 0;
      ColumnTol* nt = realloc(r->tol, (size_t)(r->ntol + 1) * sizeof *nt);
      if (!nt) return say(why, len, "%s: out of memory", path), -1;
      r->tol = nt;
      r->tol[r->ntol++] = t;
    }
  }
  for (int c = 1; c < r->data.ncol; ++c)
    if (!find_tol(r, r->data.name[c])) {
      say(why, len, "%s: no '# tolerance: %s atol=... rtol=...' line for column '%s'", path, r->data.name[c],
          r->data.name[c]);
      return -1;
    }
  return 0;
}

/* ------------------------------------------------------------------------------------------------
 * Running a scene in a child process
 * ---------------------------------------------------------------------------------------------- */

static void child_run(const Job* job, const Options* o, int fd) {
  RunResult res;
  memset(&res, 0, sizeof res);
  /* the child's stderr (info lines, messages) goes to a file the parent shows on failure */
  int efd = open(job->err, O_WRONLY | O_CREAT | O_TRUNC, 0600);
  if (efd >= 0) {
    dup2(efd, 2);
    close(efd);
  }
  const int nsets = (job->ref.present && !(o->bless && o->nsets) ? job->ref.nsets : 0) + o->nsets;
  const char** sets = xcalloc((size_t)nsets, sizeof *sets);
  int k = 0;
  if (job->ref.present && !(o->bless && o->nsets))
    for (int i = 0; i < job->ref.nsets; ++i) sets[k++] = job->ref.sets[i];
  for (int i = 0; i < o->nsets; ++i) sets[k++] = o->sets[i];
  fmbDiag diag;
  memset(&diag, 0, sizeof diag);
  fmbModel* m = fmb_load(job->scene, sets, nsets, fmb_cli_registry(), &diag);
  if (m && job->companion) { /* the same scene at a neighbouring rtol */
    fmbSolverInfo si;
    fmb_model_solver(m, &si);
    fmb_free(m);
    char set[64];
    snprintf(set, sizeof set, "solver.rtol=%.17g", si.rtol * companion_rtol[job->companion - 1]);
    const char** more = realloc(sets, (size_t)(nsets + 1) * sizeof *more);
    if (!more) _exit(1);
    sets = more;
    sets[nsets] = set;
    m = fmb_load(job->scene, sets, nsets + 1, fmb_cli_registry(), &diag);
  }
  if (!m) {
    if (diag.line > 0)
      say(res.msg, sizeof res.msg, "%s:%d:%d: %s", diag.file, diag.line, diag.col, diag.msg);
    else
      say(res.msg, sizeof res.msg, "%s", diag.msg);
  } else {
    res.loaded = 1;
    fmb_model_solver(m, &res.solver);
    fmbStats st;
    memset(&st, 0, sizeof st);
    fmbRunOptions ro = {.csv_path = job->csv, .quiet = 1};
    res.exit_code = fmb_run(m, &ro, &st, &diag);
    res.status_ok = st.status_ok && res.exit_code == 0;
    res.t_reached = st.t_reached;
    res.cpu_s = st.cpu_s;
    res.steps = st.steps;
    if (res.exit_code) say(res.msg, sizeof res.msg, "%s", diag.msg);
    fmb_free(m);
  }
  free(sets);
  ssize_t w = write(fd, &res, sizeof res); /* < PIPE_BUF: one atomic write, never blocks */
  _exit(w == (ssize_t)sizeof res ? 0 : 1);
}

static void start_job(Job* job, const Options* o, int index) {
  snprintf(job->csv, sizeof job->csv, "%s/%d.csv", o->tmpdir, index);
  snprintf(job->err, sizeof job->err, "%s/%d.err", o->tmpdir, index);
  int fds[2];
  if (pipe(fds) != 0) {
    say(job->why, sizeof job->why, "cannot create a pipe: %s", strerror(errno));
    job->failed = 1;
    return;
  }
  fflush(NULL);
  pid_t pid = fork();
  if (pid < 0) {
    say(job->why, sizeof job->why, "cannot start a process: %s", strerror(errno));
    job->failed = 1;
    close(fds[0]);
    close(fds[1]);
    return;
  }
  if (pid == 0) {
    close(fds[0]);
    child_run(job, o, fds[1]);
  }
  close(fds[1]);
  job->pid = pid;
  job->pipe_fd = fds[0];
}

/* collect a finished child: fills job->run or marks the job failed */
static void finish_job(Job* job, int wstatus) {
  ssize_t r = read(job->pipe_fd, &job->run, sizeof job->run);
  close(job->pipe_fd);
  job->pid = 0;
  if (WIFSIGNALED(wstatus)) {
    job->failed = 1;
    say(job->why, sizeof job->why, "the run crashed (signal %d); its stderr is in %s", WTERMSIG(wstatus), job->err);
  } else if (r != (ssize_t)sizeof job->run) {
    job->failed = 1;
    say(job->why, sizeof job->why, "the run ended without a result (exit %d)",
        WIFEXITED(wstatus) ? WEXITSTATUS(wstatus) : -1);
  }
}

static void run_all(Job* jobs, int n, const Options* o) {
  int next = 0, running = 0;
  while (next < n || running > 0) {
    while (running < o->jobs && next < n) {
      Job* j = &jobs[next];
      if (!j->failed && !j->bad_input) {
        start_job(j, o, next);
        if (j->pid > 0) ++running;
      }
      ++next;
    }
    if (running == 0) continue;
    int ws;
    pid_t pid = waitpid(-1, &ws, 0);
    if (pid < 0) {
      if (errno == EINTR) continue;
      break;
    }
    for (int i = 0; i < n; ++i)
      if (jobs[i].pid == pid) {
        finish_job(&jobs[i], ws);
        --running;
      }
  }
}

/* ------------------------------------------------------------------------------------------------
 * Checking a run against its reference
 * ---------------------------------------------------------------------------------------------- */

static void check_job(Job* job) {
  const Reference* ref = &job->ref;
  const RunResult* run = &job->run;
  if (!run->loaded) {
    job->failed = 1;
    say(job->why, sizeof job->why, "the scene no longer loads: %s", run->msg);
    return;
  }
  fmbTable out;
  char err[600];
  if (fmb_table_load(job->csv, &out, err, sizeof err)) {
    job->failed = 1;
    say(job->why, sizeof job->why, "the run wrote no usable CSV (%s)%s%s", err, run->msg[0] ? ": " : "", run->msg);
    return;
  }
  char* w = job->why;
  size_t left = sizeof job->why;
#define WHY(...)                                                   \
  do {                                                             \
    int k_ = snprintf(w, left, __VA_ARGS__);                       \
    if (k_ > 0 && (size_t)k_ < left) w += k_, left -= (size_t)k_;  \
  } while (0)
  /* the run must get as far as the reference did, and stop only where the reference stopped */
  const double t_ref = ref->t_reached, t_run = run->t_reached;
  const double eps_t = 1e-9 * fmax(1.0, fabs(t_ref));
  if (t_run < t_ref - eps_t || (ref->status_ok && !run->status_ok)) {
    job->failed = 1;
    WHY("the run stopped early at t = %.10g (the reference reaches t = %.10g%s)%s%s; ", t_run, t_ref,
        ref->status_ok ? "" : " and stopped there too", run->msg[0] ? ": " : "", run->msg);
  } else if (!ref->status_ok && run->status_ok) {
    job->failed = 1;
    WHY("the run now completes (t = %.10g) where the reference stopped at t = %.10g; ", t_run, t_ref);
  }
  /* columns: missing (in the reference, not in the run), extra (in the run only) */
  int missing = 0, extra = 0;
  for (int c = 1; c < ref->data.ncol; ++c)
    if (fmb_table_col(&out, ref->data.name[c]) < 0) ++missing;
  for (int c = 1; c < out.ncol; ++c)
    if (fmb_table_col(&ref->data, out.name[c]) < 0) ++extra;
  if (missing && extra) {
    job->failed = 1;
    WHY("columns renamed? missing from the run:");
    for (int c = 1; c < ref->data.ncol; ++c)
      if (fmb_table_col(&out, ref->data.name[c]) < 0) WHY(" %s", ref->data.name[c]);
    WHY("; not in the reference:");
    for (int c = 1; c < out.ncol; ++c)
      if (fmb_table_col(&ref->data, out.name[c]) < 0) WHY(" %s", out.name[c]);
    WHY("; ");
  } else if (missing) {
    job->failed = 1;
    WHY("missing column%s (in the reference, not written by the run):", missing > 1 ? "s" : "");
    for (int c = 1; c < ref->data.ncol; ++c)
      if (fmb_table_col(&out, ref->data.name[c]) < 0) WHY(" %s", ref->data.name[c]);
    WHY("; ");
  } else if (extra) {
    job->failed = 1;
    WHY("extra column%s (written by the run, not in the reference; re-bless if intended):", extra > 1 ? "s" : "");
    for (int c = 1; c < out.ncol; ++c)
      if (fmb_table_col(&ref->data, out.name[c]) < 0) WHY(" %s", out.name[c]);
    WHY("; ");
  }
  /* values, at the reference's rows: the worst column is the one nearest to (or furthest beyond)
     its tolerance */
  double worst_ratio = -1.0;
  int nbeyond = 0;
  for (int c = 1; c < ref->data.ncol; ++c) {
    const int oc = fmb_table_col(&out, ref->data.name[c]);
    if (oc < 0) continue;
    fmbColumnError e;
    fmb_table_column_error(&ref->data, c, &out, oc, &e);
    if (e.rows == 0) continue;
    double range, absmax;
    fmb_table_column_scale(&ref->data, c, &range, &absmax);
    const ColumnTol* t = find_tol(ref, ref->data.name[c]);
    const double tol = t->atol + t->rtol * range;
    const double ratio = isnan(e.max_abs) ? INFINITY : tol > 0.0 ? e.max_abs / tol : (e.max_abs > 0.0 ? INFINITY : 0.0);
    if (ratio > worst_ratio) {
      worst_ratio = ratio;
      snprintf(job->worst, sizeof job->worst, "%s", ref->data.name[c]);
      job->worst_err = e.max_abs;
      job->worst_tol = tol;
      job->worst_t = e.t_max;
    }
    if (!(e.max_abs <= tol)) {
      if (nbeyond++ == 0) WHY("beyond tolerance:");
      WHY(" %s (max error %.3g > %.3g at t = %.6g)", ref->data.name[c], e.max_abs, tol, e.t_max);
      job->failed = 1;
    }
  }
  if (nbeyond) WHY("; ");
#undef WHY
  if (w > job->why && w[-2] == ';') w[-2] = '\0';
  fmb_table_free(&out);
}

/* ------------------------------------------------------------------------------------------------
 * Blessing: writing a reference
 * ---------------------------------------------------------------------------------------------- */

/* the whole text of a small file (NULL if unreadable) */
static char* slurp(const char* path, size_t* len) {
  FILE* f = fopen(path, "rb");
  if (!f) return NULL;
  size_t cap = 4096, n = 0;
  char* buf = xcalloc(cap, 1);
  size_t k;
  while ((k = fread(buf + n, 1, cap - n - 1, f)) > 0) {
    n += k;
    if (n + 1 == cap) {
      char* nb = realloc(buf, cap *= 2);
      if (!nb) {
        free(buf);
        fclose(f);
        return NULL;
      }
      buf = nb;
    }
  }
  fclose(f);
  buf[n] = '\0';
  *len = n;
  return buf;
}

/* the part of a reference that bless decides from: the data rows (header row on) and the set lines */
static int same_results(const char* old_text, const char* new_text) {
  const char* a = strstr(old_text, "\nt,");
  const char* b = strstr(new_text, "\nt,");
  if (!a || !b || strcmp(a, b) != 0) return 0;
  /* the --set lines must match too (they change what the rows mean) */
  for (const char *p = old_text, *q = new_text;;) {
    p = strstr(p, "# set: ");
    q = strstr(q, "# set: ");
    if (!p || !q || p > a || q > b) return (!p || p > a) && (!q || q > b);
    size_t lp = strcspn(p, "\n"), lq = strcspn(q, "\n");
    if (lp != lq || strncmp(p, q, lp) != 0) return 0;
    p += lp;
    q += lq;
  }
}

static void format_date(char* buf, size_t len) {
  time_t now = time(NULL);
  struct tm tmv;
  gmtime_r(&now, &tmv);
  strftime(buf, len, "%Y-%m-%d", &tmv);
}

/* the largest difference per column between the run (its CSV `out`) and its companions */
static void column_noise(const Job* companions, const fmbTable* out, double* noise) {
  for (int c = 1; c < out->ncol; ++c) noise[c] = 0.0;
  for (int k = 0; k < NCOMPANION; ++k) {
    fmbTable other;
    char err[600];
    if (!companions[k].run.loaded || fmb_table_load(companions[k].csv, &other, err, sizeof err)) continue;
    for (int c = 1; c < out->ncol; ++c) {
      const int oc = fmb_table_col(&other, out->name[c]);
      if (oc < 0) continue;
      fmbColumnError e;
      fmb_table_column_error(out, c, &other, oc, &e);
      if (e.rows > 0 && isfinite(e.max_abs)) noise[c] = fmax(noise[c], e.max_abs);
    }
    fmb_table_free(&other);
  }
}

/* write (or keep) the reference of a finished run (its companions follow it in the job list);
   0, or -1 with why */
static int bless_job(Job* job, const Options* o) {
  const RunResult* run = &job->run;
  if (!run->loaded) {
    job->bad_input = 1;
    say(job->why, sizeof job->why, "the scene does not load: %s", run->msg);
    return -1;
  }
  fmbTable out;
  char err[600];
  if (fmb_table_load(job->csv, &out, err, sizeof err)) {
    job->failed = 1;
    say(job->why, sizeof job->why, "the run wrote no usable CSV (%s)%s%s", err, run->msg[0] ? ": " : "", run->msg);
    return -1;
  }
  size_t csv_len = 0;
  char* csv = slurp(job->csv, &csv_len);
  if (!csv) {
    fmb_table_free(&out);
    say(job->why, sizeof job->why, "cannot read back %s", job->csv);
    job->failed = 1;
    return -1;
  }
  /* the rows to keep: every stride-th and the last, copied as the engine printed them */
  const long nrow = out.nrow;
  const long stride = nrow <= o->rows ? 1 : (nrow - 1 + (o->rows - 2)) / (o->rows - 1);
  size_t cap = csv_len + 8192 + (size_t)out.ncol * 256;
  char* text = xcalloc(cap, 1);
  size_t n = 0;
#define PUT(...) n += (size_t)snprintf(text + n, cap - n, __VA_ARGS__)
  const char* base = strrchr(job->scene, '/');
  base = base ? base + 1 : job->scene;
  char date[32];
  format_date(date, sizeof date);
  PUT("# flexmbd regression reference for %s, written by `flexmbd regress --bless` (docs/regression.md).\n", base);
  PUT("# A column passes when max |run - reference| <= atol + rtol * (its range here). Edit a tolerance\n");
  PUT("# line and end it with 'override' to keep it through --bless; everything else is rewritten.\n");
  PUT("# flexmbd: %s\n# commit: %s\n# date: %s\n", FLEXMBD_VERSION, FLEXMBD_COMMIT, date);
  PUT("# solver: t0=%.10g t_end=%.10g rtol=%.6g atol=%.6g output_step=%.10g\n", run->solver.t0, run->solver.t_end,
      run->solver.rtol, run->solver.atol, run->solver.output_step);
  const int keep_sets = job->ref.present && o->nsets == 0;
  for (int i = 0; keep_sets && i < job->ref.nsets; ++i) PUT("# set: %s\n", job->ref.sets[i]);
  for (int i = 0; !keep_sets && i < o->nsets; ++i) PUT("# set: %s\n", o->sets[i]);
  PUT("# status: %s\n# t_reached: %.10g\n# steps: %ld\n# cpu_s: %.4f\n", run->status_ok ? "ok" : "stopped",
      run->t_reached, run->steps, run->cpu_s);
  PUT("# rows: every %ld%s of %ld output rows and the last\n", stride,
      stride == 1 ? "st" : stride == 2 ? "nd" : stride == 3 ? "rd" : "th", nrow);
  const double rtol = run->solver.rtol, atol = run->solver.atol;
  double* noise = xcalloc((size_t)out.ncol, sizeof *noise);
  column_noise(job + 1, &out, noise);
  PUT("# noise: the largest difference from runs at rtol x %g and x %g; atol = %g x noise + %g x solver atol, "
      "rtol = %g x solver rtol\n", companion_rtol[0], companion_rtol[1], NOISE_FACTOR, SOLVER_FACTOR, SOLVER_FACTOR);
  for (int c = 1; c < out.ncol; ++c) {
    const ColumnTol* keep = job->ref.present ? find_tol(&job->ref, out.name[c]) : NULL;
    if (keep && keep->override)
      PUT("# tolerance: %s atol=%.3g rtol=%.3g override\n", out.name[c], keep->atol, keep->rtol);
    else
      PUT("# tolerance: %s atol=%.3g rtol=%.3g (noise %.3g)\n", out.name[c],
          NOISE_FACTOR * noise[c] + SOLVER_FACTOR * atol, SOLVER_FACTOR * rtol, noise[c]);
  }
  free(noise);
#undef PUT
  /* the header row and the kept data rows, verbatim */
  const char* line = csv;
  long row = -1; /* -1: the header */
  while (*line) {
    const char* end = strchr(line, '\n');
    size_t len = end ? (size_t)(end - line) + 1 : strlen(line);
    if (len > 1 && (row < 0 || row % stride == 0 || row == nrow - 1)) {
      memcpy(text + n, line, len);
      n += len;
      if (!end) text[n++] = '\n';
    }
    if (len > 1) ++row;
    line += len;
  }
  text[n] = '\0';
  free(csv);
  fmb_table_free(&out);
  /* an unchanged result keeps the file as it is (no churn of date and CPU time) */
  size_t old_len = 0;
  char* old = slurp(job->ref_path, &old_len);
  int same = old && same_results(old, text);
  free(old);
  if (same) {
    job->action = "unchanged";
    free(text);
    return 0;
  }
  /* beside it and renamed into place: never a half-written reference */
  char werr[300] = "";
  fmbSafeFile* sf = fmb_safe_open(job->ref_path, werr, sizeof werr);
  FILE* f = fmb_safe_stream(sf);
  const int wrote = f && fwrite(text, 1, n, f) == n;
  if (sf && !werr[0] && !wrote) snprintf(werr, sizeof werr, "%s", strerror(errno));
  if (fmb_safe_close(sf, wrote) != 0 && !werr[0]) snprintf(werr, sizeof werr, "%s", strerror(errno));
  free(text);
  if (!wrote || werr[0]) {
    say(job->why, sizeof job->why, "cannot write %s: %s", job->ref_path, werr[0] ? werr : "write failed");
    job->bad_input = 1;
    return -1;
  }
  job->action = "written";
  return 0;
}

/* ------------------------------------------------------------------------------------------------
 * Reporting
 * ---------------------------------------------------------------------------------------------- */

static int write_junit(const char* path, Job* const* jobs, int n) {
  char err[300] = "";
  fmbSafeFile* sf = fmb_safe_open(path, err, sizeof err);
  FILE* f = fmb_safe_stream(sf);
  if (!f) {
    fprintf(stderr, "flexmbd regress: cannot write %s: %s\n", path, err[0] ? err : strerror(errno));
    fmb_safe_close(sf, 0);
    return -1;
  }
  int nfail = 0, nerr = 0;
  double total = 0.0;
  for (int i = 0; i < n; ++i) {
    nfail += jobs[i]->failed && !jobs[i]->bad_input;
    nerr += jobs[i]->bad_input;
    total += jobs[i]->run.cpu_s;
  }
  fprintf(f, "<?xml version=\"1.0\" encoding=\"UTF-8\"?>\n");
  fprintf(f, "<testsuites>\n<testsuite name=\"flexmbd regress\" tests=\"%d\" failures=\"%d\" errors=\"%d\" time=\"%.4f\">\n",
          n, nfail, nerr, total);
  for (int i = 0; i < n; ++i) {
    const Job* j = jobs[i];
    fprintf(f, "  <testcase classname=\"regress\" name=\"");
    fmb_write_xml_text(f, j->scene);
    fprintf(f, "\" time=\"%.4f\"", j->run.cpu_s);
    if (!j->failed && !j->bad_input) {
      fprintf(f, "/>\n");
      continue;
    }
    fprintf(f, ">\n    <%s message=\"", j->bad_input ? "error" : "failure");
    fmb_write_xml_text(f, j->why);
    fprintf(f, "\">");
    if (j->worst[0]) {
      char detail[400];
      snprintf(detail, sizeof detail, "worst column %s: max error %.3g, tolerance %.3g, at t = %.6g", j->worst,
               j->worst_err, j->worst_tol, j->worst_t);
      fmb_write_xml_text(f, detail);
    }
    fprintf(f, "</%s>\n  </testcase>\n", j->bad_input ? "error" : "failure");
  }
  fprintf(f, "</testsuite>\n</testsuites>\n");
  if (fmb_safe_close(sf, 1) != 0) {
    fprintf(stderr, "flexmbd regress: cannot write %s: %s\n", path, strerror(errno));
    return -1;
  }
  return 0;
}

static void print_table(Job* const* jobs, int n, const Options* o) {
  int w = 5;
  for (int i = 0; i < n; ++i) w = (int)fmax(w, (double)strlen(jobs[i]->scene));
  if (o->bless) {
    printf("%-*s  %-9s  %8s  %s\n", w, "scene", "reference", "cpu_s", "t_reached");
    for (int i = 0; i < n; ++i) {
      const Job* j = jobs[i];
      printf("%-*s  %-9s  %8.3f  %.6g\n", w, j->scene, j->failed || j->bad_input ? "FAILED" : j->action, j->run.cpu_s,
             j->run.t_reached);
    }
  } else {
    printf("%-*s  %-24s  %10s  %10s  %10s  %-6s  %8s  %8s\n", w, "scene", "worst column", "max error", "tolerance",
           "t(max)", "result", "cpu_s", "ref_cpu");
    for (int i = 0; i < n; ++i) {
      const Job* j = jobs[i];
      const char* res = j->bad_input ? "ERROR" : j->failed ? "FAIL" : "pass";
      if (j->worst[0])
        printf("%-*s  %-24s  %10.3g  %10.3g  %10.6g  %-6s  %8.3f  %8.3f%s\n", w, j->scene, j->worst, j->worst_err,
               j->worst_tol, j->worst_t, res, j->run.cpu_s, j->ref.cpu_s, j->warn_slow ? "  (slow)" : "");
      else
        printf("%-*s  %-24s  %10s  %10s  %10s  %-6s  %8.3f  %8.3f\n", w, j->scene, "-", "-", "-", "-", res,
               j->run.cpu_s, j->ref.cpu_s);
    }
  }
  for (int i = 0; i < n; ++i) {
    const Job* j = jobs[i];
    if (j->failed || j->bad_input) printf("%s: %s: %s\n", j->bad_input ? "error" : "FAIL", j->scene, j->why);
    if (j->warn_slow)
      printf("warning: %s: %.3f s of CPU, %.1fx the reference's %.3f s (beyond --slow %.3g)\n", j->scene, j->run.cpu_s,
             j->run.cpu_s / j->ref.cpu_s, j->ref.cpu_s, o->slow);
  }
}

/* ------------------------------------------------------------------------------------------------ */

static void usage(FILE* f) {
  fprintf(f,
          "usage: flexmbd regress [PATH...] [--bless] [--junit FILE] [-j N] [--set PATH=VALUE]... [--slow F] [--rows N]\n"
          "  PATH        a scene, or a folder searched for scenes with a reference SCENE.ref.csv (default: .)\n"
          "  --bless     write or update the references (a folder: every *.yaml in it); with --set, the\n"
          "              references record those overrides, otherwise the ones they had\n"
          "  --junit F   also write the results as JUnit XML\n"
          "  -j N        run N scenes at once\n"
          "  --slow F    warn when a scene takes more than F times its reference's CPU time (default 3)\n"
          "  --rows N    rows kept in a reference (default %d)\n"
          "exit: 0 all pass, 1 a scene fails, 2 bad input\n",
          DEFAULT_ROWS);
}

static int positive_int(const char* s, int lo, int hi, int* out) {
  char* end;
  long v = s ? strtol(s, &end, 10) : 0;
  if (!s || end == s || *end || v < lo || v > hi) return -1;
  *out = (int)v;
  return 0;
}

static void remove_tmpdir(const char* dir) {
  DIR* d = opendir(dir);
  if (d) {
    struct dirent* e;
    char p[1200];
    while ((e = readdir(d)) != NULL) {
      if (e->d_name[0] == '.') continue;
      snprintf(p, sizeof p, "%s/%s", dir, e->d_name);
      remove(p);
    }
    closedir(d);
  }
  rmdir(dir);
}

static int regress(const Options* op, const List* sc);

/* options and the scenes to run; returns -1 to go on, or an exit code (everything it allocates
   hangs off o, paths and scenes, which the caller frees) */
static int parse_arguments(int argc, char** argv, Options* op, List* pathsp, List* scenesp) {
  Options o = *op;
  List paths = {0}, scenes = {0};
  int rc = -1;
#define return_code(c) \
  do {                  \
    rc = (c);           \
    goto out;           \
  } while (0)
  for (int i = 2; i < argc; ++i) {
    const char* a = argv[i];
    const char* v;
    if (strcmp(a, "--bless") == 0) {
      o.bless = 1;
    } else if (strcmp(a, "--junit") == 0) {
      if (!(o.junit = fmb_cli_value("regress", argc, argv, &i, "a file name"))) return_code(FMB_EXIT_BAD_INPUT);
    } else if (strcmp(a, "-j") == 0 || strcmp(a, "--jobs") == 0) {
      if (!(v = fmb_cli_value("regress", argc, argv, &i, "a number")) || positive_int(v, 1, 256, &o.jobs)) {
        fprintf(stderr, "flexmbd regress: -j needs a whole number from 1 to 256\n");
        return_code(FMB_EXIT_BAD_INPUT);
      }
    } else if (strncmp(a, "-j", 2) == 0 && a[2]) {
      if (positive_int(a + 2, 1, 256, &o.jobs)) {
        fprintf(stderr, "flexmbd regress: -j needs a whole number from 1 to 256\n");
        return_code(FMB_EXIT_BAD_INPUT);
      }
    } else if (strcmp(a, "--rows") == 0) {
      if (!(v = fmb_cli_value("regress", argc, argv, &i, "a number")) || positive_int(v, 2, 100000, &o.rows)) {
        fprintf(stderr, "flexmbd regress: --rows needs a whole number from 2 to 100000\n");
        return_code(FMB_EXIT_BAD_INPUT);
      }
    } else if (strcmp(a, "--slow") == 0) {
      char* end;
      if (!(v = fmb_cli_value("regress", argc, argv, &i, "a factor")) || (o.slow = strtod(v, &end), *end) ||
          !(o.slow >= 1.0) || !isfinite(o.slow)) {
        fprintf(stderr, "flexmbd regress: --slow needs a factor >= 1\n");
        return_code(FMB_EXIT_BAD_INPUT);
      }
    } else if (strcmp(a, "--set") == 0) {
      if (!(v = fmb_cli_value("regress", argc, argv, &i, "PATH=VALUE"))) return_code(FMB_EXIT_BAD_INPUT);
      op->sets[o.nsets++] = v;
    } else if (strncmp(a, "--set=", 6) == 0) {
      op->sets[o.nsets++] = a + 6;
    } else if (strcmp(a, "--help") == 0 || strcmp(a, "-h") == 0) {
      usage(stdout);
      return_code(0);
    } else if (a[0] == '-' && a[1]) {
      fprintf(stderr, "flexmbd regress: unknown option '%s'\n", a);
      usage(stderr);
      return_code(FMB_EXIT_BAD_INPUT);
    } else {
      list_push(&paths, (char*)a);
    }
  }
  if (paths.n == 0) list_push(&paths, ".");
  /* the scenes */
  for (int i = 0; i < paths.n; ++i) {
    struct stat st;
    const char* p = paths.v[i];
    if (stat(p, &st) != 0) {
      fprintf(stderr, "flexmbd regress: %s: %s\n", p, strerror(errno));
      return_code(FMB_EXIT_BAD_INPUT);
    }
    if (S_ISDIR(st.st_mode)) {
      int before = scenes.n;
      walk(p, 0, o.bless, &scenes);
      if (scenes.n == before) {
        fprintf(stderr, "flexmbd regress: no scene %sunder %s%s\n", o.bless ? "" : "with a reference ", p,
                o.bless ? "" : " (make references with: flexmbd regress --bless PATH)");
        return_code(FMB_EXIT_BAD_INPUT);
      }
    } else if (S_ISREG(st.st_mode)) {
      list_push(&scenes, xstrdup(p));
    } else {
      fprintf(stderr, "flexmbd regress: %s: not a scene file or a folder\n", p);
      return_code(FMB_EXIT_BAD_INPUT);
    }
  }
out:
#undef return_code
  o.sets = op->sets;
  *op = o;
  *pathsp = paths;
  *scenesp = scenes;
  return rc;
}

int fmb_cmd_regress(int argc, char** argv) {
  Options o;
  memset(&o, 0, sizeof o);
  o.jobs = 1;
  o.rows = DEFAULT_ROWS;
  o.slow = 3.0;
  o.sets = xcalloc((size_t)argc, sizeof *o.sets);
  List paths = {0}, scenes = {0};
  int rc = parse_arguments(argc, argv, &o, &paths, &scenes);
  if (rc < 0) rc = regress(&o, &scenes);
  for (int i = 0; i < scenes.n; ++i) free(scenes.v[i]);
  free(scenes.v);
  free(paths.v);
  free(o.sets);
  return rc;
}

/* run (or bless) every scene; the exit code */
static int regress(const Options* op, const List* sc) {
  Options o = *op;
  const List scenes = *sc;
  int rc = 0;
  /* with --bless each scene's job is followed by its companions (same scene, neighbouring rtol) */
  const int per = o.bless ? 1 + NCOMPANION : 1;
  Job* all = xcalloc((size_t)scenes.n * (size_t)per, sizeof *all);
  Job** jobs = xcalloc((size_t)scenes.n, sizeof *jobs);
  for (int i = 0; i < scenes.n; ++i) {
    Job* j = jobs[i] = &all[i * per];
    j->scene = scenes.v[i];
    j->ref_path = reference_path(j->scene);
    j->ref.cpu_s = NAN;
    char why[700];
    if (file_exists(j->ref_path)) {
      if (reference_load(j->ref_path, &j->ref, why, sizeof why)) {
        j->bad_input = 1;
        say(j->why, sizeof j->why, "%s", why);
      }
    } else if (!o.bless) {
      j->bad_input = 1;
      say(j->why, sizeof j->why, "no reference %s (make it with: flexmbd regress --bless %s)", j->ref_path, j->scene);
    }
    for (int k = 1; k < per; ++k) {
      Job* c = &all[i * per + k];
      c->scene = j->scene;
      c->ref = j->ref; /* shared, read-only; freed with the scene's own job */
      c->companion = k;
      c->bad_input = j->bad_input;
    }
  }
  const char* tmp = getenv("TMPDIR");
  snprintf(o.tmpdir, sizeof o.tmpdir, "%s/flexmbd-regress-XXXXXX", tmp && *tmp ? tmp : "/tmp");
  if (!mkdtemp(o.tmpdir)) {
    fprintf(stderr, "flexmbd regress: cannot make a temporary folder %s: %s\n", o.tmpdir, strerror(errno));
    rc = FMB_EXIT_BAD_INPUT;
    goto out;
  }
  run_all(all, scenes.n * per, &o);
  int nfail = 0, bad = 0;
  for (int i = 0; i < scenes.n; ++i) {
    Job* j = jobs[i];
    if (!j->failed && !j->bad_input) {
      if (o.bless)
        bless_job(j, &o);
      else
        check_job(j);
      if (!o.bless && !j->failed && isfinite(j->ref.cpu_s) && j->ref.cpu_s >= 0.05 &&
          j->run.cpu_s > o.slow * j->ref.cpu_s)
        j->warn_slow = 1;
    }
    bad += j->bad_input;
    nfail += j->failed || j->bad_input;
  }
  print_table(jobs, scenes.n, &o);
  printf("regress: %d passed, %d failed\n", scenes.n - nfail, nfail);
  rc = bad ? FMB_EXIT_BAD_INPUT : nfail ? 1 : 0;
  if (o.junit && write_junit(o.junit, jobs, scenes.n)) rc = FMB_EXIT_BAD_INPUT;
  remove_tmpdir(o.tmpdir);
out:
  for (int i = 0; i < scenes.n; ++i) {
    reference_free(&jobs[i]->ref);
    free(jobs[i]->ref_path);
  }
  free(jobs);
  free(all);
  return rc;
}
