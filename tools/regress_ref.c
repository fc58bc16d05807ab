/* regress_ref.c — the reference side of `flexmbd regress` (docs/regression.md): finding scenes,
 * reading a reference SCENE.ref.csv (its '#' header: settings, status, tolerances) and writing one
 * (--bless). A reference is data: of its `# set:` lines only the keys that change the numbers are
 * replayed (never `plugins`, which would load a library, nor `vtk`, which would write files). */
#include <dirent.h>
#include <errno.h>
#include <math.h>
#include <stdarg.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>
#include <strings.h>
#include <sys/stat.h>
#include <time.h>

#include "flexmbd_commit.h" /* generated at build time: FLEXMBD_COMMIT */
#include "regress.h"

const double regress_companion_rtol[REGRESS_NCOMPANION] = {0.97, 1.03};

void regress_say(char* buf, size_t len, const char* fmt, ...) {
  va_list ap;
  va_start(ap, fmt);
  vsnprintf(buf, len, fmt, ap);
  va_end(ap);
}

int regress_list_push(RegressList* l, char* s) {
  if (l->n == l->cap) {
    int cap = l->cap ? 2 * l->cap : 16;
    char** nv = realloc(l->v, (size_t)cap * sizeof *nv);
    if (!nv) return -1;
    l->v = nv, l->cap = cap;
  }
  l->v[l->n++] = s;
  return 0;
}

/* a formatted line pushed (notes about what a walk or a reference passes over) */
static void note(RegressList* l, const char* fmt, ...) __attribute__((format(printf, 2, 3)));
static void note(RegressList* l, const char* fmt, ...) {
  if (!l) return;
  char buf[1400];
  va_list ap;
  va_start(ap, fmt);
  vsnprintf(buf, sizeof buf, fmt, ap);
  va_end(ap);
  char* d = strdup(buf);
  if (d && regress_list_push(l, d)) free(d);
}

/* ------------------------------------------------------------------------------------------------
 * Finding scenes
 * ---------------------------------------------------------------------------------------------- */

static int has_suffix(const char* s, const char* suf) {
  size_t n = strlen(s), m = strlen(suf);
  return n >= m && strcmp(s + n - m, suf) == 0;
}

static int is_scene_name(const char* s) { return (has_suffix(s, ".yaml") || has_suffix(s, ".yml")) && s[0] != '.'; }

char* regress_reference_path(const char* scene) {
  size_t n = strlen(scene);
  size_t stem = has_suffix(scene, ".yaml") ? n - 5 : has_suffix(scene, ".yml") ? n - 4 : n;
  char* r = malloc(stem + 9);
  if (!r) return NULL;
  memcpy(r, scene, stem);
  memcpy(r + stem, ".ref.csv", 9);
  return r;
}

char* regress_twin_scene(const char* scene) {
  const int yaml = has_suffix(scene, ".yaml");
  if (!yaml && !has_suffix(scene, ".yml")) return NULL;
  const size_t stem = strlen(scene) - (yaml ? 5 : 4);
  char* twin = malloc(stem + 6);
  if (!twin) return NULL;
  memcpy(twin, scene, stem);
  strcpy(twin + stem, yaml ? ".yml" : ".yaml");
  struct stat st;
  if (lstat(twin, &st) == 0) return twin; /* whatever it is (a link too): the names clash */
  free(twin);
  return NULL;
}

int regress_file_exists(const char* p) {
  struct stat st;
  return stat(p, &st) == 0 && S_ISREG(st.st_mode);
}

static int by_name(const void* a, const void* b) { return strcmp(*(char* const*)a, *(char* const*)b); }

/* the folders a walk has searched (device, inode): each once, so that a link to a folder above
   it (a loop) or two links to one folder cost nothing */
typedef struct {
  dev_t* dev;
  ino_t* ino;
  int n, cap;
} Visited;

static int visit(Visited* v, const struct stat* st) {
  for (int i = 0; i < v->n; ++i)
    if (v->dev[i] == st->st_dev && v->ino[i] == st->st_ino) return 0;
  if (v->n == v->cap) {
    const int cap = v->cap ? 2 * v->cap : 64;
    dev_t* nd = realloc(v->dev, (size_t)cap * sizeof *nd);
    if (nd) v->dev = nd;
    ino_t* ni = realloc(v->ino, (size_t)cap * sizeof *ni);
    if (ni) v->ino = ni;
    if (!nd || !ni) return 1; /* out of memory: searched again rather than skipped */
    v->cap = cap;
  }
  v->dev[v->n] = st->st_dev;
  v->ino[v->n++] = st->st_ino;
  return 1;
}

/* what one regress_walk carries through its folders */
typedef struct {
  int all;
  RegressList *out, *skipped;
  Visited seen;
  RegressList links; /* links to folders, searched after every real folder (a real name first) */
  RegressList link_depth;
  char* why;
  size_t len;
} Walk;

/* Symbolic links to scenes and folders are followed (a scene's reference lies beside the name it
   was found under); a folder is searched once, however many links lead to it, under its real name
   when the tree has one (links are searched last). Nothing below dir is passed over silently: a
   folder deeper than REGRESS_MAX_DEPTH is an error, what else is left out gets a note. */
static int walk(Walk* w, const char* dir, int depth) {
  if (depth > REGRESS_MAX_DEPTH) {
    regress_say(w->why, w->len, "%s: more than %d folders deep: not searched (name a folder further down)", dir,
                REGRESS_MAX_DEPTH);
    return -1;
  }
  DIR* d = opendir(dir);
  if (!d) {
    note(w->skipped, "%s: cannot be read: %s", dir, strerror(errno));
    return 0;
  }
  RegressList here = {0};
  struct dirent* e;
  while ((e = readdir(d)) != NULL) {
    if (e->d_name[0] == '.') continue; /* ., .., hidden folders such as .git */
    size_t plen = strlen(dir) + strlen(e->d_name) + 2;
    char* p = malloc(plen);
    if (!p) continue;
    snprintf(p, plen, "%s%s%s", dir, has_suffix(dir, "/") ? "" : "/", e->d_name);
    if (regress_list_push(&here, p)) free(p);
  }
  closedir(d);
  if (here.n > 1) qsort(here.v, (size_t)here.n, sizeof *here.v, by_name);
  int rc = 0;
  for (int i = 0; i < here.n; ++i) {
    struct stat st, lst;
    char* p = here.v[i];
    here.v[i] = NULL;
    const int scene_name = is_scene_name(strrchr(p, '/') + 1);
    if (lstat(p, &lst) != 0) {
      free(p);
      continue;
    }
    const int link = S_ISLNK(lst.st_mode);
    if (link && stat(p, &st) != 0) {
      if (scene_name) note(w->skipped, "%s: a symbolic link to nothing (%s)", p, strerror(errno));
      free(p);
      continue;
    }
    if (!link) st = lst;
    if (S_ISDIR(st.st_mode) && link) {
      char depth_text[16];
      snprintf(depth_text, sizeof depth_text, "%d", depth + 1);
      char* dt = strdup(depth_text);
      if (dt && regress_list_push(&w->links, p) == 0) {
        if (regress_list_push(&w->link_depth, dt) == 0) continue;
        --w->links.n;
      }
      free(dt);
      free(p);
    } else if (S_ISDIR(st.st_mode)) {
      if (visit(&w->seen, &st) && !rc) rc = walk(w, p, depth + 1);
      free(p);
    } else if (S_ISREG(st.st_mode) && scene_name) {
      char* r = regress_reference_path(p);
      int has_ref = r && regress_file_exists(r);
      if (!has_ref && !w->all) note(w->skipped, "%s: no reference (make it with: flexmbd regress --bless %s)", p, p);
      free(r);
      if ((w->all || has_ref) && regress_list_push(w->out, p) == 0) continue;
      free(p);
    } else {
      free(p);
    }
  }
  for (int i = 0; i < here.n; ++i) free(here.v[i]);
  free(here.v);
  return rc;
}

int regress_walk(const char* dir, int all, RegressList* out, RegressList* skipped, char* why, size_t len) {
  Walk w = {.all = all, .out = out, .skipped = skipped, .why = why, .len = len};
  struct stat st;
  if (stat(dir, &st) == 0) visit(&w.seen, &st);
  int rc = walk(&w, dir, 0);
  /* the links to folders, in the order found (a link's own folder may add more) */
  for (int i = 0; i < w.links.n; ++i) {
    const char* p = w.links.v[i];
    if (!rc && stat(p, &st) == 0) {
      if (visit(&w.seen, &st))
        rc = walk(&w, p, atoi(w.link_depth.v[i]));
      else
        note(skipped, "%s: a symbolic link to a folder searched already", p);
    }
  }
  for (int i = 0; i < w.links.n; ++i) free(w.links.v[i]), free(w.link_depth.v[i]);
  free(w.links.v);
  free(w.link_depth.v);
  free(w.seen.dev);
  free(w.seen.ino);
  return rc;
}

/* ------------------------------------------------------------------------------------------------
 * References
 * ---------------------------------------------------------------------------------------------- */

void regress_reference_free(RegressRef* r) {
  for (int i = 0; i < r->nsets; ++i) free(r->sets[i]);
  free(r->sets);
  free(r->tol);
  fmb_table_free(&r->data);
  memset(r, 0, sizeof *r);
}

const RegressTol* regress_find_tol(const RegressRef* r, const char* col) {
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

/* the scene keys whose `# set:` a reference may replay: those that change the numbers. Not
   `plugins` (it would load a library named by a data file) nor `vtk` (it would write files). */
static int replayable(const char* set) {
  static const char* const never[] = {"plugins", "vtk"};
  const size_t n = strcspn(set, ".=[");
  for (size_t k = 0; k < sizeof never / sizeof never[0]; ++k)
    if (strlen(never[k]) == n && strncmp(set, never[k], n) == 0) return 0;
  return 1;
}

/* "# rows: every K-th of N output rows and the last": the rows a whole reference holds, or -1 */
static long rows_promised(const char* v) {
  long k, n;
  char suffix[8];
  if (sscanf(v, "every %ld%7[a-z] of %ld output rows", &k, suffix, &n) != 3 || k < 1 || n < 1) return -1;
  return (n - 1) / k + 1 + ((n - 1) % k != 0);
}

int regress_reference_load(const char* path, RegressRef* r, char* why, size_t len, RegressList* warn) {
  memset(r, 0, sizeof *r);
  if (fmb_table_load(path, &r->data, why, len)) return -1;
  r->present = 1;
  r->status_ok = 1;
  r->t_reached = fmb_table_t_end(&r->data);
  r->cpu_s = NAN;
  long promised = -1;
  int has_t_reached = 0;
  for (int i = 0; i < r->data.nmeta; ++i) {
    const char* m = r->data.meta[i];
    const char* v;
    if ((v = meta_value(m, "set"))) {
      if (!replayable(v)) {
        note(warn, "%s:%d: '# set: %.200s' is not replayed (regress replays only the keys that change the numbers)",
             path, i + 1, v);
        continue;
      }
      char** ns = realloc(r->sets, (size_t)(r->nsets + 1) * sizeof *ns);
      if (!ns || !(ns[r->nsets] = strdup(v))) {
        if (ns) r->sets = ns;
        return regress_say(why, len, "%s: out of memory", path), -1;
      }
      r->sets = ns;
      ++r->nsets;
    } else if ((v = meta_value(m, "status"))) {
      /* written as `ok` or `stopped`; an edited `OK ` is the same word, anything else is refused
         (it once counted as stopped, and a good run then failed for completing) */
      size_t n = strlen(v);
      while (n > 0 && (v[n - 1] == ' ' || v[n - 1] == '\t')) --n;
      if (n == 2 && strncasecmp(v, "ok", 2) == 0)
        r->status_ok = 1;
      else if (n == 7 && strncasecmp(v, "stopped", 7) == 0)
        r->status_ok = 0;
      else {
        regress_say(why, len, "%s:%d: expected '# status: ok' or '# status: stopped', got '#%.200s'", path, i + 1, m);
        return -1;
      }
    } else if ((v = meta_value(m, "t_reached"))) {
      r->t_reached = strtod(v, NULL);
      has_t_reached = 1;
    } else if ((v = meta_value(m, "cpu_s"))) {
      r->cpu_s = strtod(v, NULL);
    } else if ((v = meta_value(m, "rows"))) {
      promised = rows_promised(v);
    } else if ((v = meta_value(m, "tolerance"))) {
      RegressTol t = {{0}, NAN, NAN, 0, i + 1};
      char flag[32] = "";
      int n = sscanf(v, "%159s atol=%lf rtol=%lf %31s", t.name, &t.atol, &t.rtol, flag);
      if (n < 3 || !(t.atol >= 0.0) || !(t.rtol >= 0.0) || !isfinite(t.atol) || !isfinite(t.rtol) ||
          (n == 4 && strcmp(flag, "override") != 0 && flag[0] != '(')) {
        regress_say(why, len,
                    "%s:%d: expected '# tolerance: COLUMN atol=A rtol=R [override]' with A, R >= 0, got '#%.200s'",
                    path, i + 1, m);
        return -1;
      }
      const RegressTol* before = regress_find_tol(r, t.name);
      if (before) { /* which one would count? refused rather than guessed */
        regress_say(why, len, "%s:%d: a second tolerance line for column '%s' (the first is on line %d)", path, i + 1,
                    t.name, before->line);
        return -1;
      }
      t.override = n == 4 && strcmp(flag, "override") == 0;
      RegressTol* nt = realloc(r->tol, (size_t)(r->ntol + 1) * sizeof *nt);
      if (!nt) return regress_say(why, len, "%s: out of memory", path), -1;
      r->tol = nt;
      r->tol[r->ntol++] = t;
    }
  }
  for (int c = 1; c < r->data.ncol; ++c)
    if (!regress_find_tol(r, r->data.name[c])) {
      regress_say(why, len, "%s: no '# tolerance: %s atol=... rtol=...' line for column '%s'", path, r->data.name[c],
                  r->data.name[c]);
      return -1;
    }
  /* a reference cut short (a truncated copy, a merge gone wrong) would check only what is left */
  const double t_last = fmb_table_t_end(&r->data);
  if (promised >= 0 && r->data.nrow != promised) {
    regress_say(why, len, "%s: %ld data rows, but its '# rows:' line promises %ld: cut short or edited?", path,
                r->data.nrow, promised);
    return -1;
  }
  if (has_t_reached && r->status_ok && !(fabs(t_last - r->t_reached) <= 1e-9 * fmax(1.0, fabs(r->t_reached)))) {
    regress_say(why, len, "%s: its last row is at t = %.10g, but '# t_reached: %.10g': cut short or edited?", path,
                t_last, r->t_reached);
    return -1;
  }
  return 0;
}

/* ------------------------------------------------------------------------------------------------
 * Blessing: writing a reference
 * ---------------------------------------------------------------------------------------------- */

/* the whole text of a small file (NULL if unreadable) */
static char* slurp(const char* path, size_t* len) {
  FILE* f = fopen(path, "rb");
  if (!f) return NULL;
  size_t cap = 4096, n = 0;
  char* buf = malloc(cap);
  if (!buf) {
    fclose(f);
    return NULL;
  }
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
static void column_noise(const RegressJob* companions, const fmbTable* out, double* noise) {
  for (int c = 1; c < out->ncol; ++c) noise[c] = 0.0;
  for (int k = 0; k < REGRESS_NCOMPANION; ++k) {
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

int regress_load_run_csv(RegressJob* job, fmbTable* out) {
  char err[600];
  if (!fmb_table_load(job->csv, out, err, sizeof err)) return 0;
  job->failed = 1;
  regress_say(job->why, sizeof job->why, "the run wrote no usable CSV (%s)%s%s", err, job->run.msg[0] ? ": " : "",
              job->run.msg);
  return -1;
}

int regress_bless_job(RegressJob* job, const RegressOptions* o) {
  const RegressRun* run = &job->run;
  if (!run->loaded) {
    job->bad_input = 1;
    regress_say(job->why, sizeof job->why, "the scene does not load: %s", run->msg);
    return -1;
  }
  fmbTable out;
  if (regress_load_run_csv(job, &out)) return -1;
  size_t csv_len = 0;
  char* csv = slurp(job->csv, &csv_len);
  if (!csv) {
    fmb_table_free(&out);
    regress_say(job->why, sizeof job->why, "cannot read back %s", job->csv);
    job->failed = 1;
    return -1;
  }
  /* the rows to keep: every stride-th and the last, copied as the engine printed them */
  const long nrow = out.nrow;
  const long stride = nrow <= o->rows ? 1 : (nrow - 1 + (o->rows - 2)) / (o->rows - 1);
  size_t cap = csv_len + 8192 + (size_t)out.ncol * 256;
  char* text = malloc(cap);
  double* noise = calloc((size_t)out.ncol, sizeof *noise);
  if (!text || !noise) {
    free(text), free(noise), free(csv);
    fmb_table_free(&out);
    regress_say(job->why, sizeof job->why, "out of memory");
    job->failed = 1;
    return -1;
  }
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
      stride == 1   ? "st"
      : stride == 2 ? "nd"
      : stride == 3 ? "rd"
                    : "th",
      nrow);
  const double rtol = run->solver.rtol, atol = run->solver.atol;
  column_noise(job + 1, &out, noise);
  PUT("# noise: the largest difference from runs at rtol x %g and x %g; atol = %g x noise + %g x solver atol, "
      "rtol = %g x solver rtol\n",
      regress_companion_rtol[0], regress_companion_rtol[1], REGRESS_NOISE_FACTOR, REGRESS_SOLVER_FACTOR,
      REGRESS_SOLVER_FACTOR);
  for (int c = 1; c < out.ncol; ++c) {
    const RegressTol* keep = job->ref.present ? regress_find_tol(&job->ref, out.name[c]) : NULL;
    if (keep && keep->override)
      PUT("# tolerance: %s atol=%.3g rtol=%.3g override\n", out.name[c], keep->atol, keep->rtol);
    else
      PUT("# tolerance: %s atol=%.3g rtol=%.3g (noise %.3g)\n", out.name[c],
          REGRESS_NOISE_FACTOR * noise[c] + REGRESS_SOLVER_FACTOR * atol, REGRESS_SOLVER_FACTOR * rtol, noise[c]);
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
  fmbSafeFile* sf = fmb_cli_safe_open(job->ref_path, werr, sizeof werr);
  FILE* f = fmb_safe_stream(sf);
  const int wrote = f && fwrite(text, 1, n, f) == n;
  if (sf && !werr[0] && !wrote) snprintf(werr, sizeof werr, "%s", strerror(errno));
  if (fmb_safe_close(sf, wrote) != 0 && !werr[0]) snprintf(werr, sizeof werr, "%s", strerror(errno));
  free(text);
  if (!wrote || werr[0]) {
    regress_say(job->why, sizeof job->why, "cannot write %s: %s", job->ref_path, werr[0] ? werr : "write failed");
    job->bad_input = 1;
    return -1;
  }
  job->action = "written";
  return 0;
}
