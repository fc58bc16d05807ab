/* plot_figure.c — the figure of `flexmbd plot` (options: tools/cmd_plot.c, tools/plot.h).
 * Any run's columns against t (or --x COLUMN) through gnuplot; several CSVs are overlaid (model
 * or mesh comparisons); --diff REF.csv draws each column minus REF's (interpolated linearly in t
 * at the CSV's rows), with --abs --logy an error plot; --shape BEAM --at t1,t2 draws the beam's
 * centreline (BEAM.shape columns) at the rows nearest those times. The columns are checked
 * against the CSVs first (read by the one CSV reader, tools/csv_table.c), so a typo is a message
 * (exit 2), not an empty figure. The curves are computed here and handed to gnuplot as a data
 * file (never CSV names as gnuplot code); past 8 curves the dash pattern changes with the colour;
 * the axes carry the units the library knows (fmb_output_unit). */
#include <ctype.h>
#include <errno.h>
#include <math.h>
#include <signal.h>
#include <stddef.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>
#include <strings.h>
#include <sys/stat.h>
#include <sys/wait.h>
#include <unistd.h>

#include "cli.h"
#include "csv_table.h"
#include "plot.h"

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

/* the gnuplot terminal for the output's extension */
static const char* terminal_for(const char* out) {
  if (ends_with(out, ".png")) return "pngcairo size 900,560 font \"sans,11\"";
  if (ends_with(out, ".svg")) return "svg size 900,560 font \"sans,11\"";
  if (ends_with(out, ".pdf")) return "pdfcairo size 9in,5.6in font \"sans,11\"";
  return NULL;
}

/* one curve of the figure: computed here, handed to gnuplot as a data block */
typedef struct {
  char title[800];
  long n;
  double *x, *y;
} Curve;

static Curve* add_curve(Curve** curves, int* n, long rows) {
  Curve* grown = realloc(*curves, (size_t)(*n + 1) * sizeof *grown);
  if (!grown) return NULL;
  *curves = grown;
  Curve* c = &grown[*n];
  memset(c, 0, sizeof *c);
  c->x = malloc((size_t)(rows > 0 ? rows : 1) * sizeof(double));
  c->y = malloc((size_t)(rows > 0 ? rows : 1) * sizeof(double));
  if (!c->x || !c->y) {
    free(c->x);
    free(c->y);
    return NULL;
  }
  ++*n;
  return c;
}

/* "name [unit]" when the library knows the column's unit */
static void with_unit(char* out, size_t len, const char* what, const char* column) {
  const char* unit = fmb_output_unit_in(fmb_cli_registry(), column);
  if (unit)
    snprintf(out, len, "%s [%s]", what, unit);
  else
    snprintf(out, len, "%s", what);
}

/* the rows nearest each time of "t1,t2,...": the curves of BEAM's centreline */
static int shape_curves(const PlotArgs* a, const fmbTable* table, Curve** curves, int* ncurve) {
  for (int i = 0; i < a->ncsv; ++i) {
    const fmbTable* tb = &table[i];
    char name[300];
    int nst = 0;
    for (;; ++nst) {
      snprintf(name, sizeof name, "%s.shape%d_x", a->shape, nst);
      if (fmb_table_col(tb, name) < 1) break;
    }
    if (nst < 2) {
      fprintf(stderr,
              "flexmbd plot: '%s' has no centreline of '%s' (columns %s.shape0_x ...): run with "
              "--set 'outputs=[..., %s.shape]'\n",
              a->csv[i], a->shape, a->shape, a->shape);
      return FMB_EXIT_BAD_INPUT;
    }
    for (const char* s = a->at; *s;) {
      char* end;
      const double t = strtod(s, &end);
      if (end == s || (*end && *end != ',') || !isfinite(t)) {
        fprintf(stderr, "flexmbd plot: --at expects times t1,t2,... (numbers), got '%s'\n", a->at);
        return FMB_EXIT_BAD_INPUT;
      }
      s = *end ? end + 1 : end;
      long row = 0;
      for (long r = 1; r < tb->nrow; ++r)
        if (fabs(fmb_table_at(tb, r, 0) - t) < fabs(fmb_table_at(tb, row, 0) - t)) row = r;
      Curve* c = tb->nrow ? add_curve(curves, ncurve, nst) : NULL;
      if (!c) continue;
      for (int k = 0; k < nst; ++k) {
        snprintf(name, sizeof name, "%s.shape%d_x", a->shape, k);
        c->x[k] = fmb_table_at(tb, row, fmb_table_col(tb, name));
        snprintf(name, sizeof name, "%s.shape%d_y", a->shape, k);
        c->y[k] = fmb_table_at(tb, row, fmb_table_col(tb, name));
      }
      c->n = nst;
      char label[256];
      legend_item(a, i, label, sizeof label);
      if (a->ncsv == 1)
        snprintf(c->title, sizeof c->title, "t = %.6g s", fmb_table_at(tb, row, 0));
      else
        snprintf(c->title, sizeof c->title, "%s: t = %.6g s", label, fmb_table_at(tb, row, 0));
    }
  }
  return 0;
}

/* each CSV's columns against x; with a reference, minus the reference's at the same time */
static int column_curves(const PlotArgs* a, const fmbTable* table, const fmbTable* ref, const char* xcol,
                         Curve** curves, int* ncurve) {
  for (int i = 0; i < a->ncsv; ++i) {
    const fmbTable* tb = &table[i];
    char label[256];
    legend_item(a, i, label, sizeof label);
    const int cx = fmb_table_col(tb, xcol) >= 1 ? fmb_table_col(tb, xcol) : 0;
    for (int c = 0; c < a->ncolumn; ++c) {
      if (!has_column(tb, a->column[c])) continue;
      const int cy = fmb_table_col(tb, a->column[c]);
      const int cr = ref ? fmb_table_col(ref, a->column[c]) : 0;
      if (ref && cr < 1) {
        fprintf(stderr, "flexmbd plot: the reference '%s' has no column '%s' to take the difference with\n", a->diff,
                a->column[c]);
        return FMB_EXIT_BAD_INPUT;
      }
      Curve* cv = add_curve(curves, ncurve, tb->nrow);
      if (!cv) return FMB_EXIT_BAD_INPUT;
      long hint = 0;
      for (long r = 0; r < tb->nrow; ++r) {
        double v = fmb_table_at(tb, r, cy), rv = 0.0;
        if (ref && fmb_table_at_time(ref, cr, fmb_table_at(tb, r, 0), &hint, &rv)) continue; /* outside REF's span */
        v -= rv;
        cv->x[cv->n] = fmb_table_at(tb, r, cx);
        cv->y[cv->n++] = a->absval ? fabs(v) : v;
      }
      char what[400];
      snprintf(what, sizeof what, "%s%s%s", a->column[c], ref ? " - " : "", ref ? "reference" : "");
      if (a->ncsv == 1)
        snprintf(cv->title, sizeof cv->title, "%s", what);
      else if (a->ncolumn == 1 && !ref)
        snprintf(cv->title, sizeof cv->title, "%s", label);
      else
        snprintf(cv->title, sizeof cv->title, "%s: %s", label, what);
    }
  }
  return 0;
}

int fmb_plot_is_csv(const char* s) { return ends_with(s, ".csv") || is_file(s); }

/* the CSVs (and --diff's) loaded into table[0..*loaded) and ref, the x column and the columns
   checked against them, the default figure name (OUT.png, in default_out) and its terminal */
static int load_tables(PlotArgs* a, fmbTable* table, int* loaded, fmbTable* ref, const char** xcolp, char* default_out,
                       size_t len, const char** termp) {
  int rc = 0;
  char err[1024], list[4096];
  /* with --x the first column need not be t: `campbell -o` writes speed first (docs/models.md, the
     reduced beam's Campbell diagram against the full mesh and ZOAC) */
  for (int i = 0; i < a->ncsv && !rc; ++i, ++*loaded)
    if (fmb_table_load_keyed(a->csv[i], &table[i], a->x ? NULL : "t", err, sizeof err)) {
      fprintf(stderr, "flexmbd plot: %s\n", err);
      rc = FMB_EXIT_BAD_INPUT;
    }
  if (!rc && a->diff && fmb_table_load(a->diff, ref, err, sizeof err)) {
    fprintf(stderr, "flexmbd plot: --diff: %s\n", err);
    rc = FMB_EXIT_BAD_INPUT;
  }
  /* the CSVs are inputs: the figure may not replace one (engine/safe_file.c) */
  const char* diff_input[1] = {a->diff};
  if (!rc && (fmb_cli_check_output_not_input(a->out, a->csv, a->ncsv) ||
              fmb_cli_check_output_not_input(a->out, diff_input, 1)))
    rc = FMB_EXIT_BAD_INPUT;
  /* the x column: --x, else the first column (t) */
  const char* xcol = rc ? NULL : a->x ? a->x : table[0].name[0];
  for (int i = 0; i < a->ncsv && !rc && !a->shape; ++i)
    if (!has_column(&table[i], xcol)) {
      column_list(&table[i], list, sizeof list);
      fprintf(stderr, "flexmbd plot: '%s' has no column '%s' for the x axis (its columns: %s)\n", a->csv[i], xcol,
              list);
      rc = FMB_EXIT_BAD_INPUT;
    }
  /* no columns named: every column of the first CSV but x */
  const int every_column = a->ncolumn == 0;
  for (int c = 0; !rc && every_column && !a->shape && c < table[0].ncol && a->ncolumn < PLOT_MAX; ++c)
    if (strcmp(table[0].name[c], xcol) != 0) a->column[a->ncolumn++] = table[0].name[c];
  if (!rc && a->ncolumn == 0 && !a->shape) {
    fprintf(stderr, "flexmbd plot: '%s' has no column to plot besides '%s'\n", a->csv[0], xcol);
    rc = FMB_EXIT_BAD_INPUT;
  }
  for (int c = 0; c < a->ncolumn && !rc; ++c) {
    int found = 0;
    for (int i = 0; i < a->ncsv; ++i) found |= has_column(&table[i], a->column[c]);
    if (!found) {
      column_list(&table[0], list, sizeof list);
      fprintf(stderr, "flexmbd plot: no CSV has a column '%s' (%s has: %s)\n", a->column[c], a->csv[0], list);
      rc = FMB_EXIT_BAD_INPUT;
    }
  }
  if (!rc && !a->out) { /* OUT.csv -> OUT.png */
    snprintf(default_out, len, "%s", a->csv[0]);
    char* dot = strrchr(default_out, '.');
    if (dot && !strchr(dot, '/')) *dot = '\0';
    strncat(default_out, ".png", len - strlen(default_out) - 1);
    a->out = default_out;
  }
  const char* term = rc ? NULL : terminal_for(a->out);
  if (!rc && !term) {
    fprintf(stderr, "flexmbd plot: the figure's name must end in .png, .svg or .pdf (got '%s')\n", a->out);
    rc = FMB_EXIT_BAD_INPUT;
  }
  *xcolp = xcol;
  *termp = term;
  return rc;
}

/* the curves as gnuplot's data file of our own (blocks `index k`; never gnuplot code) at data_path */
static int write_data(const Curve* curves, int ncurve, char* data_path, size_t len) {
  int rc = 0;
  {
    fmb_cli_tmp_template("plot", data_path, len);
    const int fd = mkstemp(data_path);
    FILE* df = fd >= 0 ? fdopen(fd, "w") : NULL;
    for (int k = 0; df && k < ncurve; ++k) {
      for (long r = 0; r < curves[k].n; ++r) fprintf(df, "%.12g %.12g\n", curves[k].x[r], curves[k].y[r]);
      fprintf(df, "\n\n");
    }
    if (!df || fclose(df) != 0) {
      fprintf(stderr, "flexmbd plot: cannot write the plot data %s: %s\n", data_path, strerror(errno));
      if (!df && fd >= 0) close(fd);
      rc = FMB_EXIT_BAD_INPUT;
    }
  }
  return rc;
}

/* the axes, the title, the ranges */
static void axes(FILE* g, const PlotArgs* a, const char* xcol) {
  /* the axes: the user's labels, else the column and its unit */
  char label[600];
  if (a->shape)
    with_unit(label, sizeof label, "x", "beam.x");
  else
    with_unit(label, sizeof label, xcol, xcol);
  fprintf(g, "set xlabel ");
  quoted(g, a->xlabel ? a->xlabel : label);
  fprintf(g, "\n");
  const char* yunit = a->shape ? "m" : fmb_output_unit_in(fmb_cli_registry(), a->column[0]);
  for (int c = 1; c < a->ncolumn && yunit; ++c)
    if (!fmb_output_unit_in(fmb_cli_registry(), a->column[c]) ||
        strcmp(fmb_output_unit_in(fmb_cli_registry(), a->column[c]), yunit) != 0)
      yunit = NULL;
  const char* what = a->shape ? "y" : a->ncolumn == 1 ? a->column[0] : a->diff ? "difference" : NULL;
  if (a->diff && a->ncolumn == 1) {
    snprintf(label, sizeof label, "%s%s - reference%s", a->absval ? "|" : "", a->column[0], a->absval ? "|" : "");
  } else {
    snprintf(label, sizeof label, "%s", what ? what : "");
  }
  if (yunit) snprintf(label + strlen(label), sizeof label - strlen(label), "%s[%s]", label[0] ? " " : "", yunit);
  if (a->ylabel || label[0]) {
    fprintf(g, "set ylabel ");
    quoted(g, a->ylabel ? a->ylabel : label);
    fprintf(g, "\n");
  }
  if (a->title) {
    fprintf(g, "set title ");
    quoted(g, a->title);
    fprintf(g, "\n");
  }
  if (a->shape) fprintf(g, "set size ratio -1\n"); /* a shape in true proportions */
  if (a->xrange) fprintf(g, "set xrange [%s]\n", a->xrange);
  if (a->yrange) fprintf(g, "set yrange [%s]\n", a->yrange);
  if (a->logx) fprintf(g, "set logscale x\n");
  if (a->logy) fprintf(g, "set logscale y\nset format y \"%%.0e\"\n");
}

/* gnuplot draws the curves into the figure (fig_path, the safe file's temporary) */
static int draw(const PlotArgs* a, const char* xcol, const char* term, const Curve* curves, int ncurve,
                const char* data_path, fmbSafeFile* fig) {
  const char* fig_path = fmb_safe_write_path(fig);
  /* gnuplot reads the script from its stdin; its own messages go to our stderr. A gnuplot that
     is missing or ends early must not kill us with SIGPIPE: writes then fail, and its exit
     status says why. */
  signal(SIGPIPE, SIG_IGN);
  FILE* g = popen("gnuplot", "w");
  if (!g) {
    fprintf(stderr, "flexmbd plot: cannot start gnuplot (Debian: apt-get install gnuplot-nox)\n");
    fmb_safe_close(fig, 0);
    return FMB_EXIT_BAD_INPUT;
  }
  int rc = 0;
  fprintf(g, "set terminal %s\nset output ", term);
  quoted(g, fig_path);
  fprintf(g, "\nset termoption noenhanced\nset key top right\nset grid\n");
  axes(g, a, xcol);
  fprintf(g, "plot ");
  for (int k = 0; k < ncurve; ++k) {
    fprintf(g, "%s", k ? ", \\\n     " : "");
    quoted(g, data_path);
    /* 8 colours, then the next dash pattern: 40 curves stay apart */
    fprintf(g, " index %d using 1:2 with lines lw 2 lt %d dt %d title ", k, k % 8 + 1, k / 8 % 5 + 1);
    quoted(g, curves[k].title);
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
      fprintf(stderr, "flexmbd plot: gnuplot did not write '%s' (exit status %d; its messages are above)\n", a->out,
              status);
    rc = FMB_EXIT_BAD_INPUT;
  } else {
    fprintf(stderr, "flexmbd plot: wrote %s\n", a->out);
  }
  return rc;
}

int fmb_plot_figure(PlotArgs* a) {
  static fmbTable table[PLOT_MAX];
  fmbTable ref;
  memset(&ref, 0, sizeof ref);
  char default_out[1024];
  int loaded = 0;
  const char *xcol = NULL, *term = NULL;
  int rc = load_tables(a, table, &loaded, &ref, &xcol, default_out, sizeof default_out, &term);
  /* the curves, computed before anything is written */
  Curve* curves = NULL;
  int ncurve = 0;
  if (!rc)
    rc = a->shape ? shape_curves(a, table, &curves, &ncurve)
                  : column_curves(a, table, a->diff ? &ref : NULL, xcol, &curves, &ncurve);
  if (!rc && ncurve == 0) {
    fprintf(stderr, "flexmbd plot: nothing to draw\n");
    rc = FMB_EXIT_BAD_INPUT;
  }
  char data_path[1100] = "";
  if (!rc) rc = write_data(curves, ncurve, data_path, sizeof data_path);
  /* gnuplot writes a temporary file beside the figure, which replaces it only if gnuplot made one */
  if (!rc) {
    char ferr[300] = "";
    fmbSafeFile* fig = fmb_cli_safe_open(a->out, ferr, sizeof ferr);
    if (!fmb_safe_write_path(fig)) {
      fprintf(stderr, "flexmbd plot: cannot write '%s': %s\n", a->out, ferr[0] ? ferr : "not a file");
      fmb_safe_close(fig, 0);
      rc = FMB_EXIT_BAD_INPUT;
    } else {
      rc = draw(a, xcol, term, curves, ncurve, data_path, fig);
    }
  }
  if (data_path[0] && !strstr(data_path, "XXXXXX")) unlink(data_path);
  for (int k = 0; k < ncurve; ++k) {
    free(curves[k].x);
    free(curves[k].y);
  }
  free(curves);
  for (int i = 0; i < loaded; ++i) fmb_table_free(&table[i]);
  fmb_table_free(&ref);
  return rc;
}
