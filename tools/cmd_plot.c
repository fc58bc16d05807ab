/* cmd_plot.c — `flexmbd plot OUT.csv [MORE.csv]... [COLUMN]... [-o FIG.png|.svg|.pdf] [options]`
 * Any run's columns against t (or --x COLUMN) through gnuplot; several CSVs are overlaid (model
 * or mesh comparisons), --logy/--logx and --abs draw error plots. The columns are checked
 * against the CSVs first (read by the one CSV reader, tools/csv_table.c), so a typo is a message
 * (exit 2), not an empty figure. */
#include <ctype.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>
#include <strings.h>
#include <signal.h>
#include <sys/stat.h>
#include <sys/wait.h>

#include "cli.h"
#include "csv_table.h"

#define PLOT_MAX 64

typedef struct {
  const char* csv[PLOT_MAX];
  int ncsv;
  const char* column[PLOT_MAX];
  int ncolumn;
  const char* out;
  const char* x;
  const char *title, *xlabel, *ylabel, *xrange, *yrange, *legend;
  int logx, logy, absval;
} PlotArgs;

static int ends_with(const char* s, const char* suffix) {
  size_t n = strlen(s), k = strlen(suffix);
  return n >= k && strcasecmp(s + n - k, suffix) == 0;
}

static int is_file(const char* s) {
  struct stat st;
  return stat(s, &st) == 0 && S_ISREG(st.st_mode);
}

/* column `name` of a CSV as `flexmbd run` writes it (t is column 0) */
static int has_column(const fmbTable* tb, const char* name) {
  return fmb_table_col(tb, name) >= 0 || (tb->ncol > 0 && strcmp(tb->name[0], name) == 0);
}

/* "t, beam.tip_v, ..." for messages */
static void column_list(const fmbTable* tb, char* out, size_t len) {
  size_t used = 0;
  out[0] = '\0';
  for (int i = 0; i < tb->ncol && used + 80 < len; ++i)
    used += (size_t)snprintf(out + used, len - used, "%s%s", i ? ", " : "", tb->name[i]);
}

/* every string reaches gnuplot through fmb_cli_gnuplot_string (single quotes: a column named
   `touch PWNED` is a name, never a command); a name it refuses (a control character) is refused */
static int bad_string;
static void quoted(FILE* g, const char* s) {
  if (fmb_cli_gnuplot_string(g, s) != 0) {
    bad_string = 1;
    fputs("''", g);
  }
}

/* the legend label of CSV i: the i-th item of --legend a,b,c, else the file name */
static void legend_item(const PlotArgs* a, int i, char* out, size_t len) {
  const char* base = strrchr(a->csv[i], '/');
  snprintf(out, len, "%s", base ? base + 1 : a->csv[i]);
  if (!a->legend) return;
  const char* s = a->legend;
  for (int k = 0; k < i && s; ++k) {
    s = strchr(s, ',');
    if (s) ++s;
  }
  if (!s) return;
  size_t n = strcspn(s, ",");
  snprintf(out, len, "%.*s", (int)n, s);
}

static int parse_args(int argc, char** argv, PlotArgs* a) {
  for (int i = 2; i < argc; ++i) {
    const char* s = argv[i];
    const char** opt = NULL;
    if (strcmp(s, "-o") == 0 || strcmp(s, "--output") == 0) opt = &a->out;
    else if (strcmp(s, "--x") == 0) opt = &a->x;
    else if (strcmp(s, "--title") == 0) opt = &a->title;
    else if (strcmp(s, "--xlabel") == 0) opt = &a->xlabel;
    else if (strcmp(s, "--ylabel") == 0) opt = &a->ylabel;
    else if (strcmp(s, "--xrange") == 0) opt = &a->xrange;
    else if (strcmp(s, "--yrange") == 0) opt = &a->yrange;
    else if (strcmp(s, "--legend") == 0) opt = &a->legend;
    if (opt) {
      if (!(*opt = fmb_cli_value("plot", argc, argv, &i, "a value"))) return FMB_EXIT_BAD_INPUT;
    } else if (strcmp(s, "--logx") == 0) {
      a->logx = 1;
    } else if (strcmp(s, "--logy") == 0) {
      a->logy = 1;
    } else if (strcmp(s, "--abs") == 0) {
      a->absval = 1;
    } else if (s[0] == '-' && s[1] != '\0') {
      fprintf(stderr, "flexmbd plot: unknown option '%s'\n", s);
      return FMB_EXIT_BAD_INPUT;
    } else if (ends_with(s, ".csv") || is_file(s)) {
      if (a->ncsv == PLOT_MAX) return fprintf(stderr, "flexmbd plot: at most %d CSV files\n", PLOT_MAX), FMB_EXIT_BAD_INPUT;
      a->csv[a->ncsv++] = s;
    } else {
      if (a->ncolumn == PLOT_MAX) return fprintf(stderr, "flexmbd plot: at most %d columns\n", PLOT_MAX), FMB_EXIT_BAD_INPUT;
      a->column[a->ncolumn++] = s;
    }
  }
  if (a->ncsv == 0) {
    fprintf(stderr, "flexmbd plot: no CSV file given (usage: flexmbd plot OUT.csv [MORE.csv]... [COLUMN]... [-o FIG.png])\n");
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

/* the gnuplot terminal for the output's extension */
static const char* terminal_for(const char* out) {
  if (ends_with(out, ".png")) return "pngcairo size 900,560 font \"sans,11\"";
  if (ends_with(out, ".svg")) return "svg size 900,560 font \"sans,11\"";
  if (ends_with(out, ".pdf")) return "pdfcairo size 9in,5.6in font \"sans,11\"";
  return NULL;
}

int fmb_cmd_plot(int argc, char** argv) {
  PlotArgs a;
  memset(&a, 0, sizeof a);
  int rc = parse_args(argc, argv, &a);
  if (rc) return rc;
  static fmbTable table[PLOT_MAX];
  char default_out[1024], err[1024], list[4096];
  int loaded = 0;
  for (int i = 0; i < a.ncsv && !rc; ++i, ++loaded)
    if (fmb_table_load(a.csv[i], &table[i], err, sizeof err)) {
      fprintf(stderr, "flexmbd plot: %s\n", err);
      rc = FMB_EXIT_BAD_INPUT;
    }
  /* the CSVs are inputs: the figure may not replace one (engine/safe_file.c) */
  if (!rc && fmb_cli_check_output_not_input(a.out, a.csv, a.ncsv)) rc = FMB_EXIT_BAD_INPUT;
  /* the x column: --x, else the first column (t) */
  const char* xcol = rc ? NULL : a.x ? a.x : table[0].name[0];
  for (int i = 0; i < a.ncsv && !rc; ++i)
    if (!has_column(&table[i], xcol)) {
      column_list(&table[i], list, sizeof list);
      fprintf(stderr, "flexmbd plot: '%s' has no column '%s' for the x axis (its columns: %s)\n", a.csv[i], xcol, list);
      rc = FMB_EXIT_BAD_INPUT;
    }
  /* no columns named: every column of the first CSV but x */
  const int every_column = a.ncolumn == 0;
  for (int c = 0; !rc && every_column && c < table[0].ncol && a.ncolumn < PLOT_MAX; ++c)
    if (strcmp(table[0].name[c], xcol) != 0) a.column[a.ncolumn++] = table[0].name[c];
  if (!rc && a.ncolumn == 0) {
    fprintf(stderr, "flexmbd plot: '%s' has no column to plot besides '%s'\n", a.csv[0], xcol);
    rc = FMB_EXIT_BAD_INPUT;
  }
  for (int c = 0; c < a.ncolumn && !rc; ++c) {
    int found = 0;
    for (int i = 0; i < a.ncsv; ++i) found |= has_column(&table[i], a.column[c]);
    if (!found) {
      column_list(&table[0], list, sizeof list);
      fprintf(stderr, "flexmbd plot: no CSV has a column '%s' (%s has: %s)\n", a.column[c], a.csv[0], list);
      rc = FMB_EXIT_BAD_INPUT;
    }
  }
  if (!rc && !a.out) { /* OUT.csv -> OUT.png */
    snprintf(default_out, sizeof default_out, "%s", a.csv[0]);
    char* dot = strrchr(default_out, '.');
    if (dot && !strchr(dot, '/')) *dot = '\0';
    strncat(default_out, ".png", sizeof default_out - strlen(default_out) - 1);
    a.out = default_out;
  }
  const char* term = rc ? NULL : terminal_for(a.out);
  if (!rc && !term) {
    fprintf(stderr, "flexmbd plot: the figure's name must end in .png, .svg or .pdf (got '%s')\n", a.out);
    rc = FMB_EXIT_BAD_INPUT;
  }
  FILE* g = NULL;
  /* gnuplot writes a temporary file beside the figure, which replaces it only if gnuplot made one */
  fmbSafeFile* fig = NULL;
  const char* fig_path = NULL;
  if (!rc) {
    char ferr[300] = "";
    fig = fmb_safe_open(a.out, ferr, sizeof ferr);
    fig_path = fmb_safe_write_path(fig);
    if (!fig_path) {
      fprintf(stderr, "flexmbd plot: cannot write '%s': %s\n", a.out, ferr[0] ? ferr : "not a file");
      rc = FMB_EXIT_BAD_INPUT;
    }
  }
  if (!rc) {
    /* gnuplot reads the script from its stdin; its own messages go to our stderr. A gnuplot that
       is missing or ends early must not kill us with SIGPIPE: writes then fail, and its exit
       status says why. */
    signal(SIGPIPE, SIG_IGN);
    g = popen("gnuplot", "w");
    if (!g) {
      fprintf(stderr, "flexmbd plot: cannot start gnuplot (Debian: apt-get install gnuplot-nox)\n");
      rc = FMB_EXIT_BAD_INPUT;
    }
  }
  if (!rc) {
    fprintf(g, "set terminal %s\nset output ", term);
    quoted(g, fig_path);
    fprintf(g, "\nset termoption noenhanced\nset datafile separator \",\"\nset key top right\nset grid\n");
    fprintf(g, "set xlabel ");
    quoted(g, a.xlabel ? a.xlabel : xcol);
    fprintf(g, "\n");
    if (a.ylabel || a.ncolumn == 1) { /* one column names the axis itself */
      fprintf(g, "set ylabel ");
      quoted(g, a.ylabel ? a.ylabel : a.column[0]);
      fprintf(g, "\n");
    }
    if (a.title) {
      fprintf(g, "set title ");
      quoted(g, a.title);
      fprintf(g, "\n");
    }
    if (a.xrange) fprintf(g, "set xrange [%s]\n", a.xrange);
    if (a.yrange) fprintf(g, "set yrange [%s]\n", a.yrange);
    if (a.logx) fprintf(g, "set logscale x\n");
    if (a.logy) fprintf(g, "set logscale y\nset format y \"%%.0e\"\n");
    fprintf(g, "plot ");
    int first = 1;
    for (int i = 0; i < a.ncsv; ++i) {
      char label[256];
      legend_item(&a, i, label, sizeof label);
      for (int c = 0; c < a.ncolumn; ++c) {
        if (!has_column(&table[i], a.column[c])) continue;
        fprintf(g, "%s", first ? "" : ", \\\n     ");
        first = 0;
        quoted(g, a.csv[i]);
        fprintf(g, " using (column(");
        quoted(g, xcol);
        fprintf(g, ")):(%s(column(", a.absval ? "abs" : "");
        quoted(g, a.column[c]);
        fprintf(g, "))) with lines lw 2 title ");
        char title[600];
        if (a.ncsv == 1) snprintf(title, sizeof title, "%s", a.column[c]);
        else if (a.ncolumn == 1) snprintf(title, sizeof title, "%s", label);
        else snprintf(title, sizeof title, "%s: %s", label, a.column[c]);
        quoted(g, title);
      }
    }
    fprintf(g, "\n");
    if (bad_string) fprintf(g, "\nexit status 1\n"); /* nothing drawn with a name it could not take */
    int status = pclose(g);
    struct stat st;
    /* success is judged by the file gnuplot leaves */
    const int made = status == 0 && stat(fig_path, &st) == 0 && st.st_size > 0;
    if (fmb_safe_close(fig, made) != 0 || !made) {
      if (bad_string)
        fprintf(stderr, "flexmbd plot: a column or file name holds a control character (a line break): not plotted\n");
      else if (status != -1 && WIFEXITED(status) && WEXITSTATUS(status) == 127)
        fprintf(stderr, "flexmbd plot: gnuplot is not installed (Debian: apt-get install gnuplot-nox)\n");
      else
        fprintf(stderr, "flexmbd plot: gnuplot did not write '%s' (exit status %d; its messages are above)\n", a.out, status);
      rc = FMB_EXIT_BAD_INPUT;
    } else {
      fprintf(stderr, "flexmbd plot: wrote %s\n", a.out);
    }
    fig = NULL;
  }
  fmb_safe_close(fig, 0);
  for (int i = 0; i < loaded; ++i) fmb_table_free(&table[i]);
  return rc;
}
