/* plot.h — `flexmbd plot`: its options (tools/cmd_plot.c) and the figure made from them
 * (tools/plot_figure.c). */
#ifndef FLEXMBD_PLOT_H
#define FLEXMBD_PLOT_H

#define PLOT_MAX 64

typedef struct {
  const char* csv[PLOT_MAX];
  int ncsv;
  const char* column[PLOT_MAX];
  int ncolumn;
  const char* out;
  const char* x;
  const char *title, *xlabel, *ylabel, *xrange, *yrange, *legend;
  const char *diff, *shape, *at; /* --diff REF.csv, --shape BEAM --at t1,t2,... */
  int logx, logy, absval;
} PlotArgs;

/* an argument that names a CSV (ends in .csv, or is a file), not a column */
int fmb_plot_is_csv(const char* s);
/* the figure of the parsed arguments (the columns checked against the CSVs first): 0, or
   FMB_EXIT_BAD_INPUT after saying why */
int fmb_plot_figure(PlotArgs* a);
#endif
