/* sweep_plan.c — grids, zipped lists, samples files and random designs (sweep_plan.h).
 *
 * Random designs are reproducible sample by sample: sample i of path k takes its uniform number
 * from (seed, i, stream) alone (fmb_plan_uniform), never from a sequential generator, so the plan
 * does not depend on how many ranks or children run it or how often it is resumed (docs/sweep.md,
 * "Reproducibility"). Latin hypercube (--design lhs): for path k the N samples are ranked by a
 * second stream; sample i lands in stratum rank(i) at u = (rank(i) + U(seed, i, 2k)) / N. */
#include "sweep_plan.h"

#include <errno.h>
#include <math.h>
#include <stdlib.h>
#include <string.h>

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

/* a value as the runs get it: a finite number printed %.17g, anything else as written */
static void normalized(const char* text, char* out, size_t len) {
  while (*text == ' ') ++text;
  char* end;
  errno = 0;
  const double v = strtod(text, &end);
  size_t n = strlen(text);
  while (n > 0 && text[n - 1] == ' ') --n;
  if (end != text && (size_t)(end - text) == n && isfinite(v) && errno != ERANGE)
    snprintf(out, len, "%.17g", v);
  else
    snprintf(out, len, "%.*s", (int)n, text);
}

/* registers PATH (the text before '='), refusing a repeat; its index or -1 */
static int add_path(fmbSweepPlan* p, const char* spec, const char** rest, char* err, size_t len) {
  const char* eq = strchr(spec, '=');
  if (!eq || eq == spec) {
    say(err, len, "expected PATH=VALUES (e.g. solver.rtol=1e-6,1e-8)", spec);
    return -1;
  }
  const size_t n = (size_t)(eq - spec);
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

/* splits "v1,v2,..." into normalized values; the count, or -1 (an empty item) */
static long split_list(const char* text, char*** out) {
  long n = 1;
  for (const char* c = text; *c; ++c) n += *c == ',';
  char** v = calloc((size_t)n, sizeof *v);
  if (!v) return -1;
  const char* s = text;
  for (long i = 0; i < n; ++i) {
    const char* e = strchr(s, ',');
    size_t len = e ? (size_t)(e - s) : strlen(s);
    char item[256];
    snprintf(item, sizeof item, "%.*s", (int)(len < 255 ? len : 255), s);
    char norm[256];
    normalized(item, norm, sizeof norm);
    if (!norm[0]) {
      for (long k = 0; k < i; ++k) free(v[k]);
      free(v);
      return -1;
    }
    v[i] = strdup(norm);
    s = e ? e + 1 : s + len;
  }
  *out = v;
  return n;
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
    double a, b;
    long n;
    char scale[8] = "", tail;
    int got = sscanf(rest, "%lf:%lf:%ld:%7[a-z]%c", &a, &b, &n, scale, &tail);
    if (!(got == 3 || (got == 4 && strcmp(scale, "log") == 0))) {
      say(err, len, "--grid expects PATH=A:B:N or PATH=A:B:N:log (N values from A to B)", spec);
      return -1;
    }
    if (n < 1 || n > 100000000L || !isfinite(a) || !isfinite(b)) {
      say(err, len, "--grid: N must be from 1 to 1e8 and A, B finite", spec);
      return -1;
    }
    const int logscale = got == 4;
    if (logscale && (a <= 0 || b <= 0)) {
      say(err, len, "--grid ...:log needs A > 0 and B > 0", spec);
      return -1;
    }
    f->nrow = n;
    f->value = calloc((size_t)n, sizeof *f->value);
    if (!f->value) return -1;
    for (long i = 0; i < n; ++i) {
      double v;
      if (i == 0)
        v = a;
      else if (i == n - 1)
        v = b;
      else if (logscale)
        v = exp(log(a) + (log(b) - log(a)) * (double)i / (double)(n - 1));
      else
        v = a + (b - a) * (double)i / (double)(n - 1);
      char t[40];
      snprintf(t, sizeof t, "%.17g", v);
      if (!(f->value[i] = strdup(t))) return -1;
    }
    return 0;
  }
  f->nrow = split_list(rest, &f->value);
  if (f->nrow < 1) {
    f->nrow = 0;
    say(err, len, "--grid: an empty value in the list (expected PATH=v1,v2,...)", spec);
    return -1;
  }
  return 0;
}

int fmb_plan_add_zip(fmbSweepPlan* p, const char* spec, char* err, size_t len) {
  /* every --zip joins the one zip factor; its lists must have the same length */
  const char* rest;
  const int k = add_path(p, spec, &rest, err, len);
  if (k < 0) return -1;
  char** v;
  long n = split_list(rest, &v);
  if (n < 1) {
    say(err, len, "--zip: an empty value in the list (expected PATH=v1,v2,...)", spec);
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

int fmb_plan_add_samples(fmbSweepPlan* p, const char* file, char* err, size_t len) {
  FILE* f = fopen(file, "r");
  if (!f) {
    snprintf(err, len, "%s: cannot open the samples file: %s", file, strerror(errno));
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
      char item[256], norm[256];
      snprintf(item, sizeof item, "%.*s", (int)(l < 255 ? l : 255), s);
      normalized(item, norm, sizeof norm);
      if (c == fa->npath || !norm[0]) {
        snprintf(err, len, "%s:%ld: expected %d values (one per header column), got %s", file, lineno, fa->npath,
                 c == fa->npath ? "more" : "an empty one");
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
