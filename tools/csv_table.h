/* csv_table.h — flexmbd CSV files read back: a table of numbers with named columns, column 0 = t.
 * One reader for `compare`, `regress` and the fuzz target. Lines starting with '#' before the
 * header are kept as metadata (regression references carry their settings and tolerances there). */
#ifndef FLEXMBD_CSV_TABLE_H
#define FLEXMBD_CSV_TABLE_H
#include <stddef.h>

/* a line longer than this is refused (a CSV of 10 000 columns of %.12g numbers fits) */
#define FMB_CSV_MAX_LINE (1u << 20)

typedef struct fmbTable {
  int ncol;
  char** name;
  long nrow, cap;
  double* v; /* row-major nrow x ncol */
  int nmeta;
  char** meta; /* the '#' lines before the header, without the '#' and the newline */
  int* index;  /* open-addressing hash of the column names (nindex slots, -1 empty): a name is
                  found in O(1), so 60 000 columns are not 60 000^2 string compares */
  int nindex;
} fmbTable;

/* 0, or -1 with a message "PATH:LINE: what was expected" in err. Refuses non-regular files. */
int fmb_table_load(const char* path, fmbTable* tb, char* err, size_t errlen);
/* the same with another first column (`modes -o` writes `mode` first), or any when first is NULL */
int fmb_table_load_keyed(const char* path, fmbTable* tb, const char* first, char* err, size_t errlen);
void fmb_table_free(fmbTable* tb);
/* column index (>= 1) or -1 */
int fmb_table_col(const fmbTable* tb, const char* name);
static inline double fmb_table_at(const fmbTable* tb, long row, int col) {
  return tb->v[(size_t)row * (size_t)tb->ncol + (size_t)col];
}
double fmb_table_t_end(const fmbTable* tb);

/* column cb of b at time t, linear in t between b's rows (a row at t, to 1e-9 relative, exactly):
   0, or -1 when t lies outside b's time span. *j: b's row to start the search from (0 at first;
   the search moves forward, so calls with rising t cost one pass over b) */
int fmb_table_at_time(const fmbTable* b, int cb, double t, long* j, double* value);
/* The error of column ca of `a` against column cb of `b`, evaluated at the rows of `a` that lie in
   b's time span; b is interpolated linearly in time between its rows (rows at the same time, as
   when both come from the same output grid, are taken exactly). */
typedef struct fmbColumnError {
  long rows;      /* rows of a compared (0: no common time) */
  double max_abs; /* max |a - b| (NaN when a value is not finite) */
  double t_max;   /* where it occurred */
  double end_abs; /* at the last compared row */
  double t_last;
} fmbColumnError;
void fmb_table_column_error(const fmbTable* a, int ca, const fmbTable* b, int cb, fmbColumnError* e);
/* range (max - min) and max |value| of a column */
void fmb_table_column_scale(const fmbTable* tb, int col, double* range, double* absmax);
#endif
