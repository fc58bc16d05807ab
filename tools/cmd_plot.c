/* cmd_plot.c — `flexmbd plot OUT.csv [MORE.csv]... [COLUMN]... [-o FIG.png|.svg|.pdf] [options]`
 * Any run's columns against t (or --x COLUMN) through gnuplot; several CSVs are overlaid (model
 * or mesh comparisons); --diff REF.csv draws each column minus REF's (interpolated linearly in t
 * at the CSV's rows), with --abs --logy an error plot; --shape BEAM --at t1,t2 draws the beam's
 * centreline (BEAM.shape columns) at the rows nearest those times. The columns are checked
 * against the CSVs first (read by the one CSV reader, tools/csv_table.c), so a typo is a message
 * (exit 2), not an empty figure. This file reads the options; the figure is tools/plot_figure.c's. */
#include <ctype.h>
#include <stddef.h>
#include <stdio.h>
#include <string.h>

#include "cli.h"
#include "plot.h"

/* a CSV (a name ending .csv, or a file) or a column */
static int plot_positional(const fmbOptContext* ctx, const char* s) {
  PlotArgs* a = ctx->self;
  if (fmb_plot_is_csv(s)) {
    if (a->ncsv == PLOT_MAX)
      return fprintf(stderr, "flexmbd plot: at most %d CSV files\n", PLOT_MAX), FMB_EXIT_BAD_INPUT;
    a->csv[a->ncsv++] = s;
  } else {
    if (a->ncolumn == PLOT_MAX)
      return fprintf(stderr, "flexmbd plot: at most %d columns\n", PLOT_MAX), FMB_EXIT_BAD_INPUT;
    a->column[a->ncolumn++] = s;
  }
  return 0;
}

#define PLOT_STRING(name, alias, meta, field, help) \
  { name, alias, FMB_OPT_STRING, meta, offsetof(PlotArgs, field), help, "a value", 0, 0, NULL, NULL, 0 }
#define PLOT_FLAG(name, field, help) \
  { name, NULL, FMB_OPT_FLAG, NULL, offsetof(PlotArgs, field), help, NULL, 0, 0, NULL, NULL, 0 }
static const fmbOpt plot_options[] = {
    PLOT_STRING("--output", "-o", "FIG.png|.svg|.pdf", out, "the figure (default: OUT.png)"),
    PLOT_STRING("--x", NULL, "COLUMN", x, "the abscissa (default: t)"),
    PLOT_FLAG("--logx", logx, "a logarithmic x axis"),
    PLOT_FLAG("--logy", logy, "a logarithmic y axis"),
    PLOT_FLAG("--abs", absval, "the absolute values"),
    PLOT_STRING("--title", NULL, "T", title, "the title"),
    PLOT_STRING("--xlabel", NULL, "L", xlabel, "the x axis' label"),
    PLOT_STRING("--ylabel", NULL, "L", ylabel, "the y axis' label"),
    PLOT_STRING("--xrange", NULL, "LO:HI", xrange, "the x range (numbers or *)"),
    PLOT_STRING("--yrange", NULL, "LO:HI", yrange, "the y range (numbers or *)"),
    PLOT_STRING("--legend", NULL, "a,b,...", legend, "the curves' names"),
    PLOT_STRING("--diff", NULL, "REF.csv", diff, "each column minus REF's (with --abs --logy: an error plot)"),
    PLOT_STRING("--shape", NULL, "BEAM", shape, "the beam's centreline (BEAM.shape columns), with --at"),
    PLOT_STRING("--at", NULL, "t1,t2,...", at, "the times of --shape"),
};

const fmbCommandSpec fmb_plot_command = {
    "plot",
    "OUT.csv [MORE.csv]... [COLUMN]...",
    "columns against t through gnuplot; several CSVs overlaid (default: every column, OUT.png)",
    plot_options,
    FMB_OPT_COUNT(plot_options),
    plot_positional,
    NULL};

static int parse_args(int argc, char** argv, PlotArgs* a) {
  int rc;
  if (fmb_opt_parse(&fmb_plot_command, argc, argv, a, &rc)) return rc ? rc : -1; /* -1: --help shown */
  if (!a->shape != !a->at) {
    fprintf(stderr, "flexmbd plot: --shape BEAM and --at t1,t2,... go together\n");
    return FMB_EXIT_BAD_INPUT;
  }
  if (a->shape && a->diff) {
    fprintf(stderr, "flexmbd plot: --shape and --diff do not combine\n");
    return FMB_EXIT_BAD_INPUT;
  }
  if (a->ncsv == 0) {
    fprintf(stderr,
            "flexmbd plot: no CSV file given (usage: flexmbd plot OUT.csv [MORE.csv]... [COLUMN]... [-o FIG.png])\n");
    return FMB_EXIT_BAD_INPUT;
  }
  for (const char* const* r = (const char* const[]){a->xrange, a->yrange, NULL}; *r; ++r)
    for (const char* c = *r; *c; ++c)
      if (!(isdigit((unsigned char)*c) || strchr("+-.eE:*", *c))) {
        fprintf(stderr, "flexmbd plot: expected a range LO:HI (numbers or *), got '%s'\n", *r);
        return FMB_EXIT_BAD_INPUT;
      }
  return 0;
}

int fmb_cmd_plot(int argc, char** argv) {
  PlotArgs a;
  memset(&a, 0, sizeof a);
  int rc = parse_args(argc, argv, &a);
  if (rc) return rc < 0 ? 0 : rc;
  return fmb_plot_figure(&a);
}
