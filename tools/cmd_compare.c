/* cmd_compare.c — `flexmbd compare OUT.csv REF.csv [--columns a,b,...]`: the error of one run
 * against a reference run, per column, one machine-readable line each.
 *
 * The reference is interpolated linearly in time at every row of OUT inside the reference's time
 * span (rows at the same time, as when both runs share solver.output_step, are compared exactly,
 * without interpolation). For each column:
 *
 *   compare: column=NAME rows=N t_last=T max_abs=E t_max=T max_rel=E end_abs=E end_rel=E ref_scale=S
 *
 * max_abs is max |out - ref| over the rows, t_max where it occurred, end_abs the error at the last
 * compared row (t_last), ref_scale = max |ref| over the reference's rows, and the _rel values are
 * the errors divided by ref_scale (or equal to the absolute ones when ref_scale is 0). A non-finite
 * value in OUT gives max_abs=nan. Default columns: every column of OUT other than t that REF also
 * has. Exit 0, or 2 for a missing file, a malformed CSV, an unknown column or no common time. */
#include <ctype.h>
#include <math.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>

#include "cli.h"

typedef struct {
  int ncol;
  char** name;
  long nrow, cap;
  double* v; /* row-major nrow x ncol, column 0 = t */
} Table;

static void table_free(Table* tb) {
  for (int i = 0; i < tb->ncol; ++i) free(tb->name[i]);
  free(tb->name);
  free(tb->v);
  memset(tb, 0, sizeof *tb);
}

/* read a whole line (any length) into *buf; returns its length or -1 at EOF */
static long read_line(FILE* f, char** buf, size_t* cap) {
  size_t n = 0;
  int c;
  while ((c = fgetc(f)) != EOF && c != '\n') {
    if (n + 2 > *cap) {
      size_t nc = *cap ? 2 * *cap : 256;
      char* nb = realloc(*buf, nc);
      if (!nb) return -1;
      *buf = nb;
      *cap = nc;
    }
    (*buf)[n++] = (char)c;
  }
  if (c == EOF && n == 0) return -1;
  if (!*buf) {
    *buf = malloc(1);
    if (!*buf) return -1;
    *cap = 1;
  }
  if (n > 0 && (*buf)[n - 1] == '\r') --n;
  (*buf)[n] = '\0';
  return (long)n;
}

static int load_csv(const char* path, Table* tb) {
  memset(tb, 0, sizeof *tb);
  FILE* f = fopen(path, "r");
  if (!f) {
    fprintf(stderr, "flexmbd compare: cannot open '%s'\n", path);
    return -1;
  }
  char* line = NULL;
  size_t cap = 0;
  int rc = -1;
  if (read_line(f, &line, &cap) < 0) {
    fprintf(stderr, "flexmbd compare: '%s' is empty (no header row)\n", path);
    goto out;
  }
  /* header */
  for (char *s = line, *tok; (tok = strsep(&s, ",")) != NULL;) {
    char** nn = realloc(tb->name, (size_t)(tb->ncol + 1) * sizeof *nn);
    if (!nn) goto out;
    tb->name = nn;
    while (isspace((unsigned char)*tok)) ++tok;
    size_t len = strlen(tok);
    while (len > 0 && isspace((unsigned char)tok[len - 1])) tok[--len] = '\0';
    tb->name[tb->ncol] = strdup(tok);
    if (!tb->name[tb->ncol]) goto out;
    tb->ncol++;
  }
  if (strcmp(tb->name[0], "t") != 0) {
    fprintf(stderr, "flexmbd compare: '%s': the first column must be 't' (a flexmbd CSV), got '%s'\n", path,
            tb->name[0]);
    goto out;
  }
  long lineno = 1;
  while (read_line(f, &line, &cap) >= 0) {
    ++lineno;
    if (line[0] == '\0') continue;
    if (tb->nrow == tb->cap) {
      long nc = tb->cap ? 2 * tb->cap : 1024;
      double* nv = realloc(tb->v, (size_t)nc * (size_t)tb->ncol * sizeof *nv);
      if (!nv) goto out;
      tb->v = nv;
      tb->cap = nc;
    }
    double* row = tb->v + (size_t)tb->nrow * (size_t)tb->ncol;
    char* s = line;
    for (int k = 0; k < tb->ncol; ++k) {
      char* end;
      row[k] = strtod(s, &end);
      if (end == s || (*end != ',' && *end != '\0') || (k < tb->ncol - 1 && *end != ',') ||
          (k == tb->ncol - 1 && *end != '\0')) {
        fprintf(stderr, "flexmbd compare: %s:%ld: expected %d comma-separated numbers\n", path, lineno, tb->ncol);
        goto out;
      }
      s = end + 1;
    }
    if (!isfinite(row[0]) || (tb->nrow > 0 && row[0] < row[-tb->ncol])) {
      fprintf(stderr, "flexmbd compare: %s:%ld: times must be finite and non-decreasing\n", path, lineno);
      goto out;
    }
    tb->nrow++;
  }
  if (tb->nrow == 0) {
    fprintf(stderr, "flexmbd compare: '%s' has no data rows\n", path);
    goto out;
  }
  rc = 0;
out:
  free(line);
  fclose(f);
  if (rc) table_free(tb);
  return rc;
}

static int find_col(const Table* tb, const char* name) {
  for (int i = 1; i < tb->ncol; ++i)
    if (strcmp(tb->name[i], name) == 0) return i;
  return -1;
}

static void usage(FILE* f) {
  fprintf(f, "usage: flexmbd compare OUT.csv REF.csv [--columns a,b,...]\n");
}

int fmb_cmd_compare(int argc, char** argv) {
  const char* files[2] = {NULL, NULL};
  const char* cols = NULL;
  const char* tag = NULL; /* appended to every line: `flexmbd run --reference` adds the run's cost */
  int nf = 0;
  for (int i = 2; i < argc; ++i) {
    if (strcmp(argv[i], "--tag") == 0 && i + 1 < argc) {
      tag = argv[++i];
    } else if (strcmp(argv[i], "--columns") == 0 || strcmp(argv[i], "-c") == 0) {
      if (++i >= argc) {
        fprintf(stderr, "flexmbd compare: --columns needs a comma-separated list\n");
        return 2;
      }
      cols = argv[i];
    } else if (strncmp(argv[i], "--columns=", 10) == 0) {
      cols = argv[i] + 10;
    } else if (strcmp(argv[i], "--help") == 0 || strcmp(argv[i], "-h") == 0) {
      usage(stdout);
      return 0;
    } else if (argv[i][0] == '-' && argv[i][1] != '\0') {
      fprintf(stderr, "flexmbd compare: unknown option '%s'\n", argv[i]);
      usage(stderr);
      return 2;
    } else if (nf < 2) {
      files[nf++] = argv[i];
    } else {
      fprintf(stderr, "flexmbd compare: two CSV files, OUT and REF (got a third, '%s')\n", argv[i]);
      return 2;
    }
  }
  if (nf != 2) {
    usage(stderr);
    return 2;
  }
  Table out, ref;
  if (load_csv(files[0], &out)) return 2;
  if (load_csv(files[1], &ref)) {
    table_free(&out);
    return 2;
  }
  int rc = 0;
  /* column pairs */
  int npair = 0;
  int* po = malloc((size_t)out.ncol * sizeof *po);
  int* pr = malloc((size_t)out.ncol * sizeof *pr);
  char* list = cols ? strdup(cols) : NULL;
  if (!po || !pr || (cols && !list)) {
    fprintf(stderr, "flexmbd compare: out of memory\n");
    rc = 2;
    goto done;
  }
  if (list) {
    for (char *s = list, *tok; (tok = strsep(&s, ",")) != NULL;) {
      if (!*tok) continue;
      int a = find_col(&out, tok), b = find_col(&ref, tok);
      if (a < 0 || b < 0) {
        fprintf(stderr, "flexmbd compare: no column '%s' in '%s'\n", tok, a < 0 ? files[0] : files[1]);
        rc = 2;
        goto done;
      }
      if (npair == out.ncol) break;
      po[npair] = a;
      pr[npair++] = b;
    }
  } else {
    for (int a = 1; a < out.ncol; ++a) {
      int b = find_col(&ref, out.name[a]);
      if (b >= 0) {
        po[npair] = a;
        pr[npair++] = b;
      }
    }
  }
  if (npair == 0) {
    fprintf(stderr, "flexmbd compare: no column to compare\n");
    rc = 2;
    goto done;
  }
  const double t_lo = ref.v[0], t_hi = ref.v[(size_t)(ref.nrow - 1) * (size_t)ref.ncol];
  const double tol_t = 1e-9 * fmax(1.0, fmax(fabs(t_lo), fabs(t_hi)));
  for (int p = 0; p < npair; ++p) {
    const int a = po[p], b = pr[p];
    double scale = 0.0;
    for (long k = 0; k < ref.nrow; ++k) scale = fmax(scale, fabs(ref.v[(size_t)k * (size_t)ref.ncol + (size_t)b]));
    double emax = 0.0, tmax = 0.0, eend = 0.0, tlast = 0.0;
    int nonfinite = 0;
    long rows = 0, j = 0; /* j: reference interval start */
    for (long k = 0; k < out.nrow; ++k) {
      const double* row = out.v + (size_t)k * (size_t)out.ncol;
      const double t = row[0];
      if (t < t_lo - tol_t || t > t_hi + tol_t) continue;
      while (j + 1 < ref.nrow && ref.v[(size_t)(j + 1) * (size_t)ref.ncol] <= t + tol_t) ++j;
      const double* r0 = ref.v + (size_t)j * (size_t)ref.ncol;
      double rv;
      if (fabs(r0[0] - t) <= tol_t || j + 1 >= ref.nrow) {
        rv = r0[b];
      } else {
        const double* r1 = r0 + ref.ncol;
        const double s = (t - r0[0]) / (r1[0] - r0[0]);
        rv = (1.0 - s) * r0[b] + s * r1[b];
      }
      double e = fabs(row[a] - rv);
      if (!isfinite(e)) nonfinite = 1;
      if (e > emax || rows == 0) {
        emax = e;
        tmax = t;
      }
      eend = e;
      tlast = t;
      ++rows;
    }
    if (rows == 0) {
      fprintf(stderr, "flexmbd compare: no row of '%s' lies in the reference's time span [%g, %g]\n", files[0],
              t_lo, t_hi);
      rc = 2;
      goto done;
    }
    if (nonfinite) emax = NAN;
    const double sc = scale > 0.0 ? scale : 1.0;
    printf("compare: column=%s rows=%ld t_last=%.10g max_abs=%.6e t_max=%.10g max_rel=%.6e end_abs=%.6e end_rel=%.6e "
           "ref_scale=%.6e%s%s\n",
           out.name[a], rows, tlast, emax, tmax, emax / sc, eend, eend / sc, scale, tag ? " " : "", tag ? tag : "");
  }
done:
  free(list);
  free(po);
  free(pr);
  table_free(&out);
  table_free(&ref);
  return rc;
}
