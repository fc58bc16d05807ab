/* sweep_plan.c — grids, zipped lists, samples files and random designs (sweep_plan.h).
 *
 * Random designs are reproducible sample by sample: sample i of path k takes its uniform number
 * from (seed, i, stream) alone (fmb_plan_uniform), never from a sequential generator, so the plan
 * does not depend on how many ranks or children run it or how often it is resumed (docs/sweep.md,
 * "Reproducibility"). Latin hypercube (--design lhs): for path k the N samples are ranked by a
 * second stream; sample i lands in stratum rank(i) at u = (rank(i) + U(seed, i, 2k)) / N. */
#include "sweep_plan.h"

#include <errno.h>
#include <fcntl.h>
#include <math.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>
#include <sys/stat.h>
#include <unistd.h>

#include "csv_table.h"

uint64_t fmb_fnv1a(uint64_t h, const void* data, size_t n) {
  const unsigned char* b = data;
  for (size_t i = 0; i < n; ++i) {
    h ^= b[i];
    h *= 0x100000001b3ULL;
  }
  return h;
}

/* splitmix64's output function (Steele, Lea, Flood 2014): a bijection that scatters counters */
uint64_t fmb_mix64(uint64_t z) {
  z = (z ^ (z >> 30)) * 0xbf58476d1ce4e5b9ULL;
  z = (z ^ (z >> 27)) * 0x94d049bb133111ebULL;
  return z ^ (z >> 31);
}

double fmb_plan_uniform(uint64_t seed, uint64_t sample, uint64_t stream) {
  uint64_t z = fmb_mix64(seed) + 0x9e3779b97f4a7c15ULL * (sample + 1) + 0xd1b54a32d192ed03ULL * (stream + 1);
  z = fmb_mix64(z);
  return ((double)(z >> 11) + 0.5) * 0x1.0p-53; /* 53 bits, never 0 or 1 */
}

double fmb_plan_normal_quantile(double u) {
  double lo = -40.0, hi = 40.0;
  for (;;) {
    const double mid = 0.5 * (lo + hi);
    if (mid <= lo || mid >= hi) return mid;
    if (0.5 * erfc(-mid / sqrt(2.0)) < u)
      lo = mid;
    else
      hi = mid;
  }
}

static void say(char* err, size_t len, const char* what, const char* spec) {
  snprintf(err, len, "%s: '%s'", what, spec);
}

/* A value as the runs get it: a finite number printed %.17g, or a word (a model name, an
   integrator) of letters, digits and _ . + - / kept as written. Nothing else: a value reaches a
   run as `--set PATH=VALUE`, a runner's request and a CSV cell, and a tab, a line break, a quote,
   a comma or YAML's [ ] { } in it would be read as more than one value there (a second override,
   a second request, a second cell). A value longer than FMB_PLAN_VALUE_MAX is refused, not cut.
   0, or -1 with what is wrong in why. */
static int normalized(const char* text, size_t n, char* out, size_t len, char* why, size_t whylen) {
  while (n > 0 && *text == ' ') ++text, --n;
  while (n > 0 && text[n - 1] == ' ') --n;
  if (n > FMB_PLAN_VALUE_MAX) {
    snprintf(why, whylen, "a value of %zu characters (at most %d): '%.40s...'", n, FMB_PLAN_VALUE_MAX, text);
    return -1;
  }
  char item[FMB_PLAN_VALUE_MAX + 1];
  memcpy(item, text, n);
  item[n] = '\0';
  char* end;
  errno = 0;
  const double v = strtod(item, &end);
  if (n > 0 && end == item + n && isfinite(v) && errno != ERANGE) {
    snprintf(out, len, "%.17g", v);
    return 0;
  }
  for (size_t i = 0; i < n; ++i) {
    const unsigned char c = (unsigned char)item[i];
    if (!((c >= 'a' && c <= 'z') || (c >= 'A' && c <= 'Z') || (c >= '0' && c <= '9') || strchr("_.+-/", c))) {
      char shown[16];
      snprintf(shown, sizeof shown, c < 32 || c > 126 ? "byte 0x%02x" : "'%c'", c);
      snprintf(why, whylen, "a value is a number or a word of letters, digits and _ . + - /, not %s (in '%.*s')", shown,
               (int)(n < 60 ? n : 60), item);
      for (char* q = why; *q; ++q)
        if ((unsigned char)*q < 32) *q = '?';
      return -1;
    }
  }
  snprintf(out, len, "%s", item);
  return 0;
}

/* registers PATH (the text before '='), refusing a repeat; its index or -1 */
static int add_path(fmbSweepPlan* p, const char* spec, const char** rest, char* err, size_t len) {
  const char* eq = strchr(spec, '=');
  if (!eq || eq == spec) {
    say(err, len, "expected PATH=VALUES (e.g. solver.rtol=1e-6,1e-8)", spec);
    return -1;
  }
  const size_t n = (size_t)(eq - spec);
  if (n > 200) { /* PATH=VALUE must fit FMB_SWEEP_SET_LEN whole: never cut */
    say(err, len, "a PATH longer than 200 characters", spec);
    return -1;
  }
  for (size_t i = 0; i < n; ++i)
    if (spec[i] == ',' || spec[i] == ' ' || spec[i] == ':') {
      say(err, len, "a PATH has no ',', ':' or blanks", spec);
      return -1;
    }
  for (int k = 0; k < p->npath; ++k)
    if (strlen(p->path[k]) == n && strncmp(p->path[k], spec, n) == 0) {
      say(err, len, "this PATH is swept twice", spec);
      return -1;
    }
  if (p->npath == FMB_SWEEP_MAX_PATHS) {
    say(err, len, "too many swept paths (at most 64)", spec);
    return -1;
  }
  char* name = malloc(n + 1);
  if (!name) return -1;
  memcpy(name, spec, n);
  name[n] = '\0';
  p->path[p->npath] = name;
  *rest = eq + 1;
  return p->npath++;
}

static fmbSweepFactor* new_factor(fmbSweepPlan* p) {
  fmbSweepFactor* f = &p->factor[p->nfactor++];
  memset(f, 0, sizeof *f);
  return f;
}

/* splits "v1,v2,..." into normalized values; the count, or -1 with why (an empty item, a value
   that is neither a number nor a word) */
static long split_list(const char* text, char*** out, char* why, size_t whylen) {
  long n = 1;
  for (const char* c = text; *c; ++c) n += *c == ',';
  char** v = calloc((size_t)n, sizeof *v);
  if (!v) return snprintf(why, whylen, "out of memory"), -1;
  const char* s = text;
  for (long i = 0; i < n; ++i) {
    const char* e = strchr(s, ',');
    size_t len = e ? (size_t)(e - s) : strlen(s);
    char norm[FMB_PLAN_VALUE_MAX + 40];
    int bad = normalized(s, len, norm, sizeof norm, why, whylen);
    if (!bad && !norm[0]) bad = 1, snprintf(why, whylen, "an empty value in the list");
    if (bad || !(v[i] = strdup(norm))) {
      for (long k = 0; k < i; ++k) free(v[k]);
      free(v);
      return -1;
    }
    s = e ? e + 1 : s + len;
  }
  *out = v;
  return n;
}

/* N of a grid A:B:N: a whole number from 1 to 1e8, written as digits or as a number with an
   exponent whose value is whole (1e3); 2.5, 3abc, 0 or -4 are refused, never rounded or cut */
static int grid_count(const char* text, long* n) {
  char* end;
  errno = 0;
  const double c = strtod(text, &end);
  if (end == text || *end || errno == ERANGE || !(c >= 1) || c > 1e8 || c != floor(c)) return -1;
  *n = (long)c;
  return 0;
}

int fmb_plan_add_grid(fmbSweepPlan* p, const char* spec, char* err, size_t len) {
  const char* rest;
  const int k = add_path(p, spec, &rest, err, len);
  if (k < 0) return -1;
  if (p->nfactor == FMB_SWEEP_MAX_PATHS) return say(err, len, "too many factors", spec), -1;
  fmbSweepFactor* f = new_factor(p);
  f->npath = 1;
  f->path[0] = k;
  if (strchr(rest, ':')) { /* A:B:N[:log] */
    char part[4][64];
    int np = 0;
    for (const char* s = rest;; ++np) { /* A, B, N and maybe "log": at most four parts */
      const size_t l = strcspn(s, ":");
      if (np == 4 || l >= sizeof part[0]) {
        np = 5;
        break;
      }
      memcpy(part[np], s, l);
      part[np][l] = '\0';
      if (!s[l]) {
        ++np;
        break;
      }
      s += l + 1;
    }
    char *ea, *eb;
    const double a = np >= 3 && np <= 4 ? strtod(part[0], &ea) : 0, b = np >= 3 && np <= 4 ? strtod(part[1], &eb) : 0;
    long n = 0;
    if (np < 3 || np > 4 || (np == 4 && strcmp(part[3], "log") != 0) || ea == part[0] || *ea || eb == part[1] || *eb) {
      say(err, len, "--grid expects PATH=A:B:N or PATH=A:B:N:log (N values from A to B)", spec);
      return -1;
    }
    if (grid_count(part[2], &n) != 0) {
      snprintf(err, len, "--grid: N (the number of values) must be a whole number from 1 to 1e8, got '%s' in '%s'",
               part[2], spec);
      return -1;
    }
    if (!isfinite(a) || !isfinite(b)) {
      say(err, len, "--grid: A and B must be finite numbers", spec);
      return -1;
    }
    const int logscale = np == 4;
    if (logscale && (a <= 0 || b <= 0)) {
      say(err, len, "--grid ...:log needs A > 0 and B > 0", spec);
      return -1;
    }
    f->nrow = n;
    f->is_range = 1, f->logscale = logscale, f->a = a, f->b = b; /* laid out by fmb_plan_finish */
    return 0;
  }
  char why[300];
  f->nrow = split_list(rest, &f->value, why, sizeof why);
  if (f->nrow < 1) {
    f->nrow = 0;
    snprintf(err, len, "--grid: %s (expected PATH=v1,v2,...): '%s'", why, spec);
    return -1;
  }
  return 0;
}

/* a grid A:B:N's values, once the plan's size was accepted */
static int lay_out_range(fmbSweepFactor* f) {
  const long n = f->nrow;
  f->value = calloc((size_t)n, sizeof *f->value);
  if (!f->value) return -1;
  for (long i = 0; i < n; ++i) {
    double v;
    if (i == 0)
      v = f->a;
    else if (i == n - 1)
      v = f->b;
    else if (f->logscale)
      v = exp(log(f->a) + (log(f->b) - log(f->a)) * (double)i / (double)(n - 1));
    else
      v = f->a + (f->b - f->a) * (double)i / (double)(n - 1);
    char t[40];
    snprintf(t, sizeof t, "%.17g", v);
    if (!(f->value[i] = strdup(t))) return -1;
  }
  f->is_range = 0;
  return 0;
}

int fmb_plan_add_zip(fmbSweepPlan* p, const char* spec, char* err, size_t len) {
  /* every --zip joins the one zip factor; its lists must have the same length */
  const char* rest;
  const int k = add_path(p, spec, &rest, err, len);
  if (k < 0) return -1;
  char** v;
  char why[300];
  long n = split_list(rest, &v, why, sizeof why);
  if (n < 1) {
    snprintf(err, len, "--zip: %s (expected PATH=v1,v2,...): '%s'", why, spec);
    return -1;
  }
  /* the zip factor is the one marked zip (value laid out row-major over its paths) */
  for (int i = 0; i < p->nfactor; ++i) {
    fmbSweepFactor* z = &p->factor[i];
    if (z->nrow >= 0 && z->npath > 0 && z->value && z->path[FMB_SWEEP_MAX_PATHS - 1] == -2) {
      if (n != z->nrow) {
        for (long r = 0; r < n; ++r) free(v[r]);
        free(v);
        snprintf(err, len, "--zip lists must have the same length: '%s' has %ld values, the first --zip %ld", spec, n,
                 z->nrow);
        return -1;
      }
      if (z->npath == FMB_SWEEP_MAX_PATHS - 1) return say(err, len, "too many --zip paths", spec), -1;
      char** grown = calloc((size_t)(n * (z->npath + 1)), sizeof *grown);
      if (!grown) return -1;
      for (long r = 0; r < n; ++r) {
        for (int c = 0; c < z->npath; ++c) grown[r * (z->npath + 1) + c] = z->value[r * z->npath + c];
        grown[r * (z->npath + 1) + z->npath] = v[r];
      }
      free(z->value);
      free(v);
      z->value = grown;
      z->path[z->npath++] = k;
      return 0;
    }
  }
  fmbSweepFactor* z = new_factor(p);
  z->npath = 1;
  z->path[0] = k;
  z->path[FMB_SWEEP_MAX_PATHS - 1] = -2; /* marks the zip factor */
  z->nrow = n;
  z->value = v;
  return 0;
}

int fmb_sweep_read_input(const char* path, size_t max, char** text, size_t* n, char* err, size_t errlen) {
  *text = NULL, *n = 0;
  const int fd = open(path, O_RDONLY | O_NONBLOCK | O_NOCTTY | O_CLOEXEC);
  struct stat st;
  if (fd < 0 || fstat(fd, &st) != 0) {
    snprintf(err, errlen, "%s: cannot open it: %s", path, strerror(errno));
    if (fd >= 0) close(fd);
    return -1;
  }
  const char* why = S_ISDIR(st.st_mode)        ? "it is a folder, expected a file"
                    : !S_ISREG(st.st_mode)     ? "it is not a regular file (a FIFO, device or socket would be read "
                                                 "without end)"
                    : (size_t)st.st_size > max ? "it is too large"
                                               : NULL;
  char* buf = why ? NULL : malloc((size_t)st.st_size + 1);
  size_t got = 0;
  if (!why && !buf) why = "out of memory";
  while (!why && got < (size_t)st.st_size) { /* a regular file never blocks: O_NONBLOCK is harmless */
    const ssize_t r = read(fd, buf + got, (size_t)st.st_size - got);
    if (r < 0 && errno == EINTR) continue;
    if (r < 0) why = strerror(errno);
    if (r <= 0) break;
    got += (size_t)r;
  }
  close(fd);
  if (why) {
    free(buf);
    snprintf(err, errlen, "%s: %s", path, why);
    return -1;
  }
  buf[got] = '\0';
  *text = buf, *n = got;
  return 0;
}

int fmb_plan_add_samples(fmbSweepPlan* p, const char* file, const char* text, size_t textlen, char* err, size_t len) {
  FILE* f = fmemopen((void*)text, textlen, "r");
  if (!f) {
    snprintf(err, len, "%s: cannot read the samples: %s", file, strerror(errno));
    return -1;
  }
  char* line = malloc(FMB_CSV_MAX_LINE);
  fmbSweepFactor* fa = NULL;
  long lineno = 0, cap = 0;
  int rc = -1;
  while (line && fgets(line, FMB_CSV_MAX_LINE, f)) {
    ++lineno;
    size_t n = strlen(line);
    if (n == FMB_CSV_MAX_LINE - 1 && line[n - 1] != '\n') {
      snprintf(err, len, "%s:%ld: line too long", file, lineno);
      goto done;
    }
    while (n && (line[n - 1] == '\n' || line[n - 1] == '\r')) line[--n] = '\0';
    if (!n || line[0] == '#') continue;
    if (!fa) { /* the header: one PATH per column */
      if (p->nfactor == FMB_SWEEP_MAX_PATHS) goto done;
      fa = new_factor(p);
      char* save = NULL;
      for (char* tok = strtok_r(line, ",", &save); tok; tok = strtok_r(NULL, ",", &save)) {
        while (*tok == ' ' || *tok == '"') ++tok;
        size_t tl = strlen(tok);
        while (tl && (tok[tl - 1] == ' ' || tok[tl - 1] == '"')) tok[--tl] = '\0';
        char spec[300];
        snprintf(spec, sizeof spec, "%s=", tok);
        const char* rest;
        int k = add_path(p, spec, &rest, err, len);
        if (k < 0) {
          char why[300];
          snprintf(why, sizeof why, "%s", err);
          snprintf(err, len, "%s:%ld: header: %s", file, lineno, why);
          goto done;
        }
        if (fa->npath == FMB_SWEEP_MAX_PATHS) goto done;
        fa->path[fa->npath++] = k;
      }
      continue;
    }
    if (fa->nrow == cap) {
      cap = cap ? 2 * cap : 256;
      char** grown = realloc(fa->value, (size_t)cap * (size_t)fa->npath * sizeof *grown);
      if (!grown) goto done;
      fa->value = grown;
    }
    int c = 0;
    const char* s = line;
    for (;;) {
      const char* e = strchr(s, ',');
      size_t l = e ? (size_t)(e - s) : strlen(s);
      char norm[FMB_PLAN_VALUE_MAX + 40], why[300];
      const int bad = normalized(s, l, norm, sizeof norm, why, sizeof why);
      if (bad || c == fa->npath || !norm[0]) {
        if (bad)
          snprintf(err, len, "%s:%ld:%ld: %s", file, lineno, (long)(s - line) + 1, why);
        else
          snprintf(err, len, "%s:%ld: expected %d values (one per header column), got %s", file, lineno, fa->npath,
                   c == fa->npath ? "more" : "an empty one");
        for (int k = 0; k < c; ++k) free(fa->value[fa->nrow * fa->npath + k]);
        goto done;
      }
      fa->value[fa->nrow * fa->npath + c++] = strdup(norm);
      if (!e) break;
      s = e + 1;
    }
    if (c != fa->npath) {
      snprintf(err, len, "%s:%ld: expected %d values (one per header column), got %d", file, lineno, fa->npath, c);
      for (int k = 0; k < c; ++k) free(fa->value[fa->nrow * fa->npath + k]);
      goto done;
    }
    ++fa->nrow;
  }
  if (!fa || fa->nrow == 0) {
    snprintf(err, len, "%s: no samples (expected a header of PATHs and at least one row)", file);
    goto done;
  }
  rc = 0;
done:
  free(line);
  fclose(f);
  return rc;
}

int fmb_plan_add_random(fmbSweepPlan* p, const char* spec, char* err, size_t len) {
  const char* rest;
  const int k = add_path(p, spec, &rest, err, len);
  if (k < 0) return -1;
  static const char* const kinds[3] = {"uniform", "normal", "lognormal"};
  char name[16];
  double a, b;
  int kind = -1, used = 0;
  if (sscanf(rest, "%15[a-z](%lf,%lf)%n", name, &a, &b, &used) == 3 && used > 0 && rest[used] == '\0')
    for (int i = 0; i < 3; ++i)
      if (strcmp(name, kinds[i]) == 0) kind = i;
  if (kind < 0 || !isfinite(a) || !isfinite(b)) {
    say(err, len, "--random expects PATH=uniform(a,b), PATH=normal(mean,sd) or PATH=lognormal(mu,sigma)", spec);
    return -1;
  }
  if ((kind == 0 && !(a < b)) || (kind > 0 && !(b > 0))) {
    say(err, len, kind == 0 ? "--random uniform(a,b) needs a < b" : "--random: the spread (second number) must be > 0",
        spec);
    return -1;
  }
  p->random_path[p->nrandom] = k;
  p->random_kind[p->nrandom] = kind;
  p->random_p[p->nrandom][0] = a;
  p->random_p[p->nrandom][1] = b;
  ++p->nrandom;
  return 0;
}

double fmb_plan_size(const fmbSweepPlan* p) {
  double n = 1.0;
  for (int i = 0; i < p->nfactor; ++i) n *= (double)p->factor[i].nrow;
  if (p->nrandom) n *= (double)p->count;
  return n;
}

typedef struct {
  double key;
  long i;
} Keyed;
static int by_key(const void* a, const void* b) {
  const Keyed *x = a, *y = b;
  return x->key < y->key ? -1 : x->key > y->key ? 1 : (x->i > y->i) - (x->i < y->i);
}

int fmb_plan_finish(fmbSweepPlan* p, char* err, size_t len) {
  if (p->nrandom && p->count < 1) return snprintf(err, len, "--random needs --count N (N >= 1)"), -1;
  if (!p->nrandom && p->count) return snprintf(err, len, "--count goes with --random"), -1;
  if (p->nfactor == 0 && !p->nrandom)
    return snprintf(err, len, "nothing to sweep: give --grid, --zip, --samples or --random"), -1;
  for (int i = 0; i < p->nfactor; ++i)
    if (p->factor[i].is_range && lay_out_range(&p->factor[i]) != 0)
      return snprintf(err, len, "out of memory for %ld grid values", p->factor[i].nrow), -1;
  if (!p->nrandom) return 0;
  if (p->nfactor == FMB_SWEEP_MAX_PATHS) return snprintf(err, len, "too many factors"), -1;
  const long n = p->count;
  fmbSweepFactor* f = new_factor(p);
  f->npath = p->nrandom;
  f->nrow = n;
  f->value = calloc((size_t)n * (size_t)p->nrandom, sizeof *f->value);
  long* rank = p->lhs ? malloc((size_t)n * sizeof *rank) : NULL;
  Keyed* keyed = p->lhs ? malloc((size_t)n * sizeof *keyed) : NULL;
  if (!f->value || (p->lhs && (!rank || !keyed))) {
    free(rank), free(keyed);
    return snprintf(err, len, "out of memory for %ld samples", n), -1;
  }
  for (int k = 0; k < p->nrandom; ++k) {
    f->path[k] = p->random_path[k];
    if (p->lhs) {
      for (long i = 0; i < n; ++i) keyed[i] = (Keyed){fmb_plan_uniform(p->seed, (uint64_t)i, 2u * (uint64_t)k + 1), i};
      qsort(keyed, (size_t)n, sizeof *keyed, by_key);
      for (long r = 0; r < n; ++r) rank[keyed[r].i] = r;
    }
    for (long i = 0; i < n; ++i) {
      double u = fmb_plan_uniform(p->seed, (uint64_t)i, 2u * (uint64_t)k);
      if (p->lhs) u = ((double)rank[i] + u) / (double)n;
      const double a = p->random_p[k][0], b = p->random_p[k][1];
      double v = p->random_kind[k] == 0 ? a + (b - a) * u : a + b * fmb_plan_normal_quantile(u);
      if (p->random_kind[k] == 2) v = exp(v);
      char t[40];
      snprintf(t, sizeof t, "%.17g", v);
      if (!(f->value[i * p->nrandom + k] = strdup(t))) {
        free(rank), free(keyed);
        return snprintf(err, len, "out of memory"), -1;
      }
    }
  }
  free(rank), free(keyed);
  return 0;
}

const char* fmb_plan_value(const fmbSweepPlan* p, long i, int k) {
  /* mixed radix, the first factor slowest */
  long stride = 1;
  for (int f = p->nfactor - 1; f >= 0; --f) {
    const fmbSweepFactor* fa = &p->factor[f];
    const long r = (i / stride) % fa->nrow;
    for (int c = 0; c < fa->npath; ++c)
      if (fa->path[c] == k) return fa->value[r * fa->npath + c];
    stride *= fa->nrow;
  }
  return "";
}

void fmb_plan_free(fmbSweepPlan* p) {
  for (int f = 0; f < p->nfactor; ++f) {
    fmbSweepFactor* fa = &p->factor[f];
    for (long r = 0; fa->value && r < fa->nrow * fa->npath; ++r) free(fa->value[r]);
    free(fa->value);
  }
  for (int k = 0; k < p->npath; ++k) free(p->path[k]);
  memset(p, 0, sizeof *p);
}
