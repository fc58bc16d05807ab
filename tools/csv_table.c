/* csv_table.c — reading flexmbd CSV files back (tools/csv_table.h). */
#include "csv_table.h"

#include <ctype.h>
#include <errno.h>
#include <math.h>
#include <stdarg.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>
#include <sys/stat.h>

void fmb_table_free(fmbTable* tb) {
  for (int i = 0; i < tb->ncol; ++i) free(tb->name[i]);
  for (int i = 0; i < tb->nmeta; ++i) free(tb->meta[i]);
  free(tb->name);
  free(tb->meta);
  free(tb->index);
  free(tb->v);
  memset(tb, 0, sizeof *tb);
}

static void say(char* err, size_t errlen, const char* fmt, ...) {
  va_list ap;
  va_start(ap, fmt);
  vsnprintf(err, errlen, fmt, ap);
  va_end(ap);
}

/* one line (without '\n', '\r' stripped) into *buf: its length, -1 at EOF, -2 when longer than
   FMB_CSV_MAX_LINE, -3 out of memory */
static long read_line(FILE* f, char** buf, size_t* cap) {
  size_t n = 0;
  int c;
  while ((c = fgetc(f)) != EOF && c != '\n') {
    if (n >= FMB_CSV_MAX_LINE) return -2;
    if (n + 2 > *cap) {
      size_t nc = *cap ? 2 * *cap : 256;
      char* nb = realloc(*buf, nc);
      if (!nb) return -3;
      *buf = nb;
      *cap = nc;
    }
    (*buf)[n++] = (char)c;
  }
  if (c == EOF && n == 0) return -1;
  if (!*buf) {
    if (!(*buf = malloc(1))) return -3;
    *cap = 1;
  }
  if (n > 0 && (*buf)[n - 1] == '\r') --n;
  (*buf)[n] = '\0';
  return (long)n;
}

/* FNV-1a, for the column-name index */
static unsigned name_hash(const char* s) {
  unsigned h = 2166136261u;
  for (; *s; ++s) h = (h ^ (unsigned char)*s) * 16777619u;
  return h;
}

static int push_string(char*** list, int* n, const char* s) {
  if ((*n & (*n - 1)) == 0) { /* at 0, 1, 2, 4, ...: capacity doubles, appending stays linear */
    char** nl = realloc(*list, (size_t)(*n ? 2 * *n : 1) * sizeof *nl);
    if (!nl) return -1;
    *list = nl;
  }
  char** nl = *list;
  if (!(nl[*n] = strdup(s))) return -1;
  ++*n;
  return 0;
}

int fmb_table_load(const char* path, fmbTable* tb, char* err, size_t errlen) {
  return fmb_table_load_keyed(path, tb, "t", err, errlen);
}

int fmb_table_load_keyed(const char* path, fmbTable* tb, const char* first, char* err, size_t errlen) {
  memset(tb, 0, sizeof *tb);
  struct stat st;
  if (stat(path, &st) != 0) {
    say(err, errlen, "%s: cannot open: %s", path, strerror(errno));
    return -1;
  }
  if (!S_ISREG(st.st_mode)) {
    say(err, errlen, "%s: not a regular file (a CSV file was expected)", path);
    return -1;
  }
  FILE* f = fopen(path, "r");
  if (!f) {
    say(err, errlen, "%s: cannot open: %s", path, strerror(errno));
    return -1;
  }
  char* line = NULL;
  size_t cap = 0;
  int rc = -1;
  long lineno = 0, n;
  for (;;) {
    n = read_line(f, &line, &cap);
    ++lineno;
    /* a byte-order mark (a spreadsheet's "CSV UTF-8") is no part of the first name or comment */
    if (lineno == 1 && n >= 3 && memcmp(line, "\xEF\xBB\xBF", 3) == 0) memmove(line, line + 3, (size_t)(n -= 3) + 1);
    if (n < 0 || line[0] != '#') break;
    if (push_string(&tb->meta, &tb->nmeta, line + 1)) goto nomem;
  }
  if (n == -1) {
    say(err, errlen, "%s: empty (no header row)", path);
    goto out;
  }
  if (n == -2) goto toolong;
  if (n == -3) goto nomem;
  for (char *s = line, *tok; (tok = strsep(&s, ",")) != NULL;) {
    while (isspace((unsigned char)*tok)) ++tok;
    size_t len = strlen(tok);
    while (len > 0 && isspace((unsigned char)tok[len - 1])) tok[--len] = '\0';
    if (!*tok) {
      say(err, errlen, "%s:%ld: column %d of the header has no name", path, lineno, tb->ncol + 1);
      goto out;
    }
    if (push_string(&tb->name, &tb->ncol, tok)) goto nomem;
  }
  if (first && strcmp(tb->name[0], first) != 0) {
    say(err, errlen, "%s:%ld: the first column must be '%s' (a flexmbd CSV), got '%.40s'", path, lineno, first,
        tb->name[0]);
    goto out;
  }
  /* the name index: a duplicate is found as it is entered */
  tb->nindex = 2;
  while (tb->nindex < 2 * tb->ncol) tb->nindex *= 2;
  if (!(tb->index = malloc((size_t)tb->nindex * sizeof *tb->index))) goto nomem;
  for (int i = 0; i < tb->nindex; ++i) tb->index[i] = -1;
  for (int i = 0; i < tb->ncol; ++i) {
    unsigned h = name_hash(tb->name[i]) & (unsigned)(tb->nindex - 1);
    while (tb->index[h] >= 0 && strcmp(tb->name[tb->index[h]], tb->name[i]) != 0)
      h = (h + 1) & (unsigned)(tb->nindex - 1);
    if (tb->index[h] >= 0) {
      say(err, errlen, "%s:%ld: column '%.80s' appears twice in the header", path, lineno, tb->name[i]);
      goto out;
    }
    tb->index[h] = i;
  }
  while ((n = read_line(f, &line, &cap)) >= 0) {
    ++lineno;
    if (line[0] == '\0') continue;
    if (tb->nrow == tb->cap) {
      long nc = tb->cap ? 2 * tb->cap : 1024;
      double* nv = realloc(tb->v, (size_t)nc * (size_t)tb->ncol * sizeof *nv);
      if (!nv) goto nomem;
      tb->v = nv;
      tb->cap = nc;
    }
    double* row = tb->v + (size_t)tb->nrow * (size_t)tb->ncol;
    char* s = line;
    for (int k = 0; k < tb->ncol; ++k) {
      char* end;
      row[k] = strtod(s, &end); /* blanks before a number are skipped, */
      if (end != s)
        while (*end == ' ' || *end == '\t') ++end; /* and after it (a spreadsheet's padded cells) */
      const char want = k < tb->ncol - 1 ? ',' : '\0';
      if (end == s || *end != want) {
        say(err, errlen, "%s:%ld: expected %d comma-separated numbers (the header's columns)", path, lineno, tb->ncol);
        goto out;
      }
      s = end + 1;
    }
    if (!isfinite(row[0]) || (tb->nrow > 0 && row[0] < row[-tb->ncol])) {
      say(err, errlen, "%s:%ld: times must be finite and non-decreasing", path, lineno);
      goto out;
    }
    tb->nrow++;
  }
  if (n == -2) goto toolong;
  if (n == -3) goto nomem;
  if (tb->nrow == 0) {
    say(err, errlen, "%s: no data rows", path);
    goto out;
  }
  rc = 0;
  goto out;
toolong:
  say(err, errlen, "%s:%ld: line longer than %u bytes (not a flexmbd CSV?)", path, lineno, FMB_CSV_MAX_LINE);
  goto out;
nomem:
  say(err, errlen, "%s: out of memory", path);
out:
  free(line);
  fclose(f);
  if (rc) fmb_table_free(tb);
  return rc;
}

int fmb_table_col(const fmbTable* tb, const char* name) {
  if (!tb->index) { /* a table built by hand */
    for (int i = 1; i < tb->ncol; ++i)
      if (strcmp(tb->name[i], name) == 0) return i;
    return -1;
  }
  for (unsigned h = name_hash(name) & (unsigned)(tb->nindex - 1);; h = (h + 1) & (unsigned)(tb->nindex - 1)) {
    const int i = tb->index[h];
    if (i < 0) return -1;
    if (strcmp(tb->name[i], name) == 0) return i >= 1 ? i : -1;
  }
}

double fmb_table_t_end(const fmbTable* tb) { return fmb_table_at(tb, tb->nrow - 1, 0); }

int fmb_table_at_time(const fmbTable* b, int cb, double t, long* j, double* value) {
  if (b->nrow == 0) return -1;
  const double t_lo = fmb_table_at(b, 0, 0), t_hi = fmb_table_t_end(b);
  const double tol_t = 1e-9 * fmax(1.0, fmax(fabs(t_lo), fabs(t_hi)));
  if (t < t_lo - tol_t || t > t_hi + tol_t) return -1;
  if (*j < 0 || *j >= b->nrow || fmb_table_at(b, *j, 0) > t + tol_t) *j = 0;
  while (*j + 1 < b->nrow && fmb_table_at(b, *j + 1, 0) <= t + tol_t) ++*j;
  const double t0 = fmb_table_at(b, *j, 0);
  if (fabs(t0 - t) <= tol_t || *j + 1 >= b->nrow) {
    *value = fmb_table_at(b, *j, cb);
  } else {
    const double s = (t - t0) / (fmb_table_at(b, *j + 1, 0) - t0);
    *value = (1.0 - s) * fmb_table_at(b, *j, cb) + s * fmb_table_at(b, *j + 1, cb);
  }
  return 0;
}

void fmb_table_column_error(const fmbTable* a, int ca, const fmbTable* b, int cb, fmbColumnError* e) {
  memset(e, 0, sizeof *e);
  int nonfinite = 0;
  long j = 0; /* b's interval start */
  for (long k = 0; k < a->nrow; ++k) {
    const double t = fmb_table_at(a, k, 0);
    double bv;
    if (fmb_table_at_time(b, cb, t, &j, &bv)) continue;
    const double err = fabs(fmb_table_at(a, k, ca) - bv);
    if (!isfinite(err)) nonfinite = 1;
    if (err > e->max_abs || e->rows == 0) {
      e->max_abs = err;
      e->t_max = t;
    }
    e->end_abs = err;
    e->t_last = t;
    e->rows++;
  }
  if (nonfinite) e->max_abs = NAN;
}

void fmb_table_column_scale(const fmbTable* tb, int col, double* range, double* absmax) {
  double lo = INFINITY, hi = -INFINITY, am = 0.0;
  for (long k = 0; k < tb->nrow; ++k) {
    const double x = fmb_table_at(tb, k, col);
    lo = fmin(lo, x);
    hi = fmax(hi, x);
    am = fmax(am, fabs(x));
  }
  *range = tb->nrow ? hi - lo : 0.0;
  *absmax = am;
}
