/* cmd_compare.c — `flexmbd compare OUT.csv REF.csv [--columns a,b,...] [--rtol R] [--atol A] [--common]`:
 * the error of one run against a reference run, per column, one machine-readable line each:
 *
 *   compare: column=NAME rows=N t_last=T max_abs=E t_max=T max_rel=E end_abs=E end_rel=E ref_scale=S
 *            [range=D tol=E status=ok|beyond]
 *
 * REF is interpolated linearly in time at every row of OUT inside REF's time span (rows at the same
 * time, as when both runs share solver.output_step, are compared exactly). max_abs is max |OUT - REF|,
 * t_max where it occurred, end_abs the error at the last compared row t_last, ref_scale = max |REF|,
 * and the _rel values are the errors divided by ref_scale. A non-finite value gives max_abs=nan.
 *
 * With --rtol and/or --atol a column passes when max_abs <= atol + rtol * range, range = max - min of
 * REF's column (docs/regression.md), and OUT must reach REF's last time. Without --columns or
 * --common, both files must have the same columns: one missing or extra is a failure.
 * Exit 0 all within tolerance (or no tolerance asked), 1 a column beyond tolerance, a missing or
 * extra column, or OUT shorter than REF; 2 bad input (unreadable or malformed CSV, unknown option,
 * an unknown --columns name, no common time). */
#include <math.h>
#include <stddef.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>

#include "cli.h"
#include "csv_table.h"

/* --rtol R, --atol A: a non-negative finite number; either asks for the check */
static int tolerance_arg(const fmbOptContext* ctx, void* at, const char* v) {
  char* end;
  const double x = strtod(v, &end);
  if (end == v || *end || !isfinite(x) || x < 0.0) {
    fprintf(stderr, "flexmbd compare: %s needs a number >= 0, got '%s'\n", ctx->option, v);
    return FMB_EXIT_BAD_INPUT;
  }
  *(double*)at = x;
  ((fmbCliCompare*)ctx->self)->check = 1;
  return 0;
}

static int compare_file(const fmbOptContext* ctx, const char* arg) {
  fmbCliCompare* c = ctx->self;
  if (c->out && c->ref) {
    fprintf(stderr, "flexmbd compare: two CSV files, OUT and REF (got a third, '%s')\n", arg);
    return FMB_EXIT_BAD_INPUT;
  }
  *(c->out ? &c->ref : &c->out) = arg;
  return 0;
}

static const fmbOpt compare_options[] = {
    {"--columns", "-c", FMB_OPT_STRING, "a,b,...", offsetof(fmbCliCompare, columns), "compare only these columns",
     "a comma-separated list", 0, 0, NULL, NULL, 0},
    {"--rtol", NULL, FMB_OPT_CALL, "R", offsetof(fmbCliCompare, rtol),
     "fail (exit 1) when a column's max error exceeds A + R * (its range in REF)", "a number >= 0", 0, 0, NULL,
     tolerance_arg, 0},
    {"--atol", NULL, FMB_OPT_CALL, "A", offsetof(fmbCliCompare, atol), "the absolute part A of that tolerance",
     "a number >= 0", 0, 0, NULL, tolerance_arg, 0},
    {"--common", NULL, FMB_OPT_FLAG, NULL, offsetof(fmbCliCompare, common),
     "compare the columns both files have (a missing or extra one is no failure)", NULL, 0, 0, NULL, NULL, 0},
    {"--tag", NULL, FMB_OPT_STRING, "TEXT", offsetof(fmbCliCompare, tag), "append TEXT to every line", "a text", 0, 0,
     NULL, NULL, 0},
};

const fmbCommandSpec fmb_compare_command = {
    "compare",
    "OUT.csv REF.csv",
    "the error of OUT against REF per column, one line each; exit 1 beyond tolerance",
    compare_options,
    FMB_OPT_COUNT(compare_options),
    compare_file,
    "exit: 0 within tolerance (or none asked), 1 a column beyond it, a missing or extra column, or OUT shorter "
    "than REF, 2 bad input\n"};

/* are the column sets the same? prints each difference; returns the number of differences */
static int column_set_differences(const fmbTable* out, const fmbTable* ref, const char* fo, const char* fr) {
  int nd = 0;
  for (int a = 1; a < out->ncol; ++a)
    if (fmb_table_col(ref, out->name[a]) < 0) {
      fprintf(stderr, "flexmbd compare: column '%s' of %s is not in %s (an extra column)\n", out->name[a], fo, fr);
      ++nd;
    }
  for (int b = 1; b < ref->ncol; ++b)
    if (fmb_table_col(out, ref->name[b]) < 0) {
      fprintf(stderr, "flexmbd compare: column '%s' of %s is missing from %s\n", ref->name[b], fr, fo);
      ++nd;
    }
  return nd;
}

int fmb_cmd_compare(int argc, char** argv) {
  fmbCliCompare c;
  memset(&c, 0, sizeof c);
  int rc;
  if (fmb_opt_parse(&fmb_compare_command, argc, argv, &c, &rc)) return rc;
  if (!c.out || !c.ref) {
    fmb_opt_usage(&fmb_compare_command, stderr, 0);
    return FMB_EXIT_BAD_INPUT;
  }
  return fmb_cli_compare(&c);
}

int fmb_cli_compare(const fmbCliCompare* c) {
  const char* files[2] = {c->out, c->ref};
  const char* cols = c->columns;
  const char* tag = c->tag;
  const double rtol = c->rtol, atol = c->atol;
  const int check = c->check, common = c->common;
  fmbTable out, ref;
  char err[600];
  if (fmb_table_load(files[0], &out, err, sizeof err)) {
    fprintf(stderr, "flexmbd compare: %s\n", err);
    return FMB_EXIT_BAD_INPUT;
  }
  if (fmb_table_load(files[1], &ref, err, sizeof err)) {
    fprintf(stderr, "flexmbd compare: %s\n", err);
    fmb_table_free(&out);
    return FMB_EXIT_BAD_INPUT;
  }
  int rc = 0, beyond = 0;
  int npair = 0;
  int* po = malloc((size_t)out.ncol * sizeof *po);
  int* pr = malloc((size_t)out.ncol * sizeof *pr);
  char* list = cols ? strdup(cols) : NULL;
  if (!po || !pr || (cols && !list)) {
    fprintf(stderr, "flexmbd compare: out of memory\n");
    rc = FMB_EXIT_BAD_INPUT;
    goto done;
  }
  if (list) {
    for (char *s = list, *tok; (tok = strsep(&s, ",")) != NULL;) {
      if (!*tok) continue;
      int a = fmb_table_col(&out, tok), b = fmb_table_col(&ref, tok);
      if (a < 0 || b < 0) {
        fprintf(stderr, "flexmbd compare: no column '%s' in '%s'\n", tok, a < 0 ? files[0] : files[1]);
        rc = FMB_EXIT_BAD_INPUT;
        goto done;
      }
      if (npair == out.ncol) break;
      po[npair] = a;
      pr[npair++] = b;
    }
  } else {
    if (!common && column_set_differences(&out, &ref, files[0], files[1])) beyond = 1;
    for (int a = 1; a < out.ncol; ++a) {
      int b = fmb_table_col(&ref, out.name[a]);
      if (b >= 0) {
        po[npair] = a;
        pr[npair++] = b;
      }
    }
  }
  if (npair == 0) {
    fprintf(stderr, "flexmbd compare: no column to compare\n");
    rc = FMB_EXIT_BAD_INPUT;
    goto done;
  }
  for (int p = 0; p < npair; ++p) {
    fmbColumnError e;
    fmb_table_column_error(&out, po[p], &ref, pr[p], &e);
    if (e.rows == 0) {
      fprintf(stderr, "flexmbd compare: no row of '%s' lies in the time span [%g, %g] of '%s'\n", files[0],
              fmb_table_at(&ref, 0, 0), fmb_table_t_end(&ref), files[1]);
      rc = FMB_EXIT_BAD_INPUT;
      goto done;
    }
    double range, scale;
    fmb_table_column_scale(&ref, pr[p], &range, &scale);
    const double sc = scale > 0.0 ? scale : 1.0;
    printf("compare: column=%s rows=%ld t_last=%.10g max_abs=%.6e t_max=%.10g max_rel=%.6e end_abs=%.6e end_rel=%.6e "
           "ref_scale=%.6e",
           out.name[po[p]], e.rows, e.t_last, e.max_abs, e.t_max, e.max_abs / sc, e.end_abs, e.end_abs / sc, scale);
    if (check) {
      const double tol = atol + rtol * range;
      const int ok = e.max_abs <= tol; /* false for NaN */
      printf(" range=%.6e tol=%.6e status=%s", range, tol, ok ? "ok" : "beyond");
      if (!ok) beyond = 1;
    }
    printf("%s%s\n", tag ? " " : "", tag ? tag : "");
  }
  if (check) {
    const double t_out = fmb_table_t_end(&out), t_ref = fmb_table_t_end(&ref);
    if (t_out < t_ref - 1e-9 * fmax(1.0, fabs(t_ref))) {
      fprintf(stderr, "flexmbd compare: %s ends at t = %.10g, before %s (t = %.10g): a shorter run\n", files[0], t_out,
              files[1], t_ref);
      beyond = 1;
    }
  }
  if (beyond) rc = 1;
done:
  free(list);
  free(po);
  free(pr);
  fmb_table_free(&out);
  fmb_table_free(&ref);
  return rc;
}
