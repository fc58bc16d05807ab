/* sweep_h5.c — DIR/sweep.h5, written by rank 0 at the end from DIR/table.csv and DIR/plan.csv
 * (never the live record: runs.csv is; a crash while writing loses nothing, and the next run of
 * the sweep writes it again). Layout (h5dump -H DIR/sweep.h5):
 *   /            attributes scene, verb, flexmbd (version), runs
 *   /plan/COL    one dataset per plan.csv column (index, run_id, the swept paths)
 *   /runs/COL    one dataset per table.csv column, rows sorted by index: float64 when every
 *                value is a number (empty = NaN), else variable-length strings
 *   /series/N    with --keep series: run N's CSV as a float64 [rows x columns] dataset, its
 *                column names in the attribute `columns`
 * One dataset per column keeps the file readable by h5dump, h5py and pandas alike without a
 * compound type. The serial HDF5 API: one writer (docs/sweep-notes §4.8: parallel HDF5's
 * collective creation would tie the ranks the dynamic schedule keeps apart). */
#include <math.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>

#include "cli.h"
#include "sweep.h"

#ifdef FLEXMBD_HAVE_HDF5
#include <hdf5.h>

typedef struct {
  int ncol;
  long nrow;
  char** cell; /* nrow x ncol, row 0 = header */
} Text;

/* a CSV line split into fields ("..." quoted, "" inside a quote = one quote), in place */
static int split(char* line, char** out, int max) {
  int n = 0;
  char* s = line;
  for (;;) {
    if (n == max) return n;
    char *w = s, *start = s;
    if (*s == '"') {
      ++s;
      for (; *s; ++s) {
        if (*s == '"' && s[1] == '"')
          *w++ = '"', ++s;
        else if (*s == '"') {
          ++s;
          break;
        } else
          *w++ = *s;
      }
    } else {
      while (*s && *s != ',' && *s != '\n') *w++ = *s++;
    }
    const char end = *s;
    *w = '\0';
    out[n++] = start;
    if (end != ',') return n;
    s++;
  }
}

static int text_load(const char* path, Text* t) {
  memset(t, 0, sizeof *t);
  FILE* f = fopen(path, "r");
  if (!f) return -1;
  size_t cap = 1 << 16;
  char* line = NULL;
  long rcap = 0;
  while (getline(&line, &cap, f) > 0) {
    char* fields[4096];
    int n = split(line, fields, 4096);
    if (t->nrow == 0) t->ncol = n;
    if (n != t->ncol) continue;
    if (t->nrow == rcap) {
      rcap = rcap ? 2 * rcap : 1024;
      char** g = realloc(t->cell, (size_t)rcap * (size_t)t->ncol * sizeof *g);
      if (!g) break;
      t->cell = g;
    }
    for (int c = 0; c < n; ++c) t->cell[t->nrow * t->ncol + c] = strdup(fields[c]);
    ++t->nrow;
  }
  free(line);
  fclose(f);
  return t->nrow > 0 ? 0 : -1;
}
static void text_free(Text* t) {
  for (long i = 0; i < t->nrow * t->ncol; ++i) free(t->cell[i]);
  free(t->cell);
}

static void string_attribute(hid_t obj, const char* name, const char* value) {
  hid_t type = H5Tcopy(H5T_C_S1);
  H5Tset_size(type, strlen(value) + 1);
  hid_t space = H5Screate(H5S_SCALAR);
  hid_t a = H5Acreate2(obj, name, type, space, H5P_DEFAULT, H5P_DEFAULT);
  H5Awrite(a, type, value);
  H5Aclose(a), H5Sclose(space), H5Tclose(type);
}

/* /group/COL per column of a text table (rows 1..): numbers as float64, else strings */
static int write_columns(hid_t file, const char* group, const Text* t) {
  hid_t g = H5Gcreate2(file, group, H5P_DEFAULT, H5P_DEFAULT, H5P_DEFAULT);
  if (g < 0) return -1;
  const hsize_t n = (hsize_t)(t->nrow - 1);
  hid_t space = H5Screate_simple(1, &n, NULL);
  double* num = malloc((n ? n : 1) * sizeof *num);
  const char** str = malloc((n ? n : 1) * sizeof *str);
  int rc = num && str ? 0 : -1;
  for (int c = 0; c < t->ncol && !rc; ++c) {
    /* ids are hex (an all-digit one would parse), statuses and messages words even when empty */
    const char* name = t->cell[c];
    int numeric = strcmp(name, "run_id") && strcmp(name, "status") && strcmp(name, "message");
    for (hsize_t r = 0; r < n; ++r) { /* every row: a word in the last row makes it a string column */
      const char* v = t->cell[(r + 1) * (hsize_t)t->ncol + (hsize_t)c];
      char* end;
      num[r] = *v ? strtod(v, &end) : NAN;
      if (*v && *end) numeric = 0;
      str[r] = v;
    }
    hid_t type = numeric ? H5Tcopy(H5T_NATIVE_DOUBLE) : H5Tcopy(H5T_C_S1);
    if (!numeric) H5Tset_size(type, H5T_VARIABLE);
    hid_t d = H5Dcreate2(g, name, type, space, H5P_DEFAULT, H5P_DEFAULT, H5P_DEFAULT);
    if (d < 0 ||
        (n && H5Dwrite(d, type, H5S_ALL, H5S_ALL, H5P_DEFAULT, numeric ? (const void*)num : (const void*)str) < 0))
      rc = -1;
    if (d >= 0) H5Dclose(d);
    H5Tclose(type);
  }
  free(num), free(str);
  H5Sclose(space);
  H5Gclose(g);
  return rc;
}

static int write_series(hid_t file, const fmbSweep* sw, const Text* table) {
  hid_t g = H5Gcreate2(file, "series", H5P_DEFAULT, H5P_DEFAULT, H5P_DEFAULT);
  if (g < 0) return -1;
  int rc = 0;
  for (long r = 1; r < table->nrow && !rc; ++r) {
    const char* index = table->cell[r * table->ncol];
    const char* id = table->cell[r * table->ncol + 1];
    char path[4300], err[600];
    snprintf(path, sizeof path, "%s/series/%s.csv", sw->dir, id);
    fmbTable t;
    if (fmb_table_load(path, &t, err, sizeof err) != 0) continue; /* a run that wrote nothing */
    hsize_t dims[2] = {(hsize_t)t.nrow, (hsize_t)t.ncol};
    hid_t space = H5Screate_simple(2, dims, NULL);
    hid_t d = H5Dcreate2(g, index, H5T_NATIVE_DOUBLE, space, H5P_DEFAULT, H5P_DEFAULT, H5P_DEFAULT);
    if (d < 0 || (t.nrow && H5Dwrite(d, H5T_NATIVE_DOUBLE, H5S_ALL, H5S_ALL, H5P_DEFAULT, t.v) < 0)) rc = -1;
    if (d >= 0) {
      size_t len = 1;
      for (int c = 0; c < t.ncol; ++c) len += strlen(t.name[c]) + 1;
      char* names = calloc(len, 1);
      for (int c = 0; names && c < t.ncol; ++c) strcat(strcat(names, c ? "," : ""), t.name[c]);
      if (names) string_attribute(d, "columns", names);
      free(names);
      H5Dclose(d);
    }
    H5Sclose(space);
    fmb_table_free(&t);
  }
  H5Gclose(g);
  return rc;
}

int fmb_sweep_write_h5(const fmbSweep* sw, const char* out) {
  char path[4300];
  Text plan, table;
  snprintf(path, sizeof path, "%s/plan.csv", sw->dir);
  if (text_load(path, &plan)) return -1;
  snprintf(path, sizeof path, "%s/table.csv", sw->dir);
  if (text_load(path, &table)) {
    text_free(&plan);
    return -1;
  }
  H5Eset_auto2(H5E_DEFAULT, NULL, NULL); /* our message, not HDF5's stack dump */
  hid_t f = H5Fcreate(out, H5F_ACC_TRUNC, H5P_DEFAULT, H5P_DEFAULT);
  int rc = f < 0 ? -1 : 0;
  if (!rc) {
    string_attribute(f, "scene", sw->scene_given ? sw->scene_given : sw->scene);
    string_attribute(f, "verb", sw->verb);
    string_attribute(f, "flexmbd", FLEXMBD_VERSION);
    char runs[32];
    snprintf(runs, sizeof runs, "%ld", sw->nrun);
    string_attribute(f, "runs", runs);
    rc = write_columns(f, "plan", &plan) || write_columns(f, "runs", &table) ||
         (sw->keep_series && write_series(f, sw, &table));
    if (H5Fclose(f) < 0) rc = -1; /* a full disk may tell only here */
  }
  text_free(&plan), text_free(&table);
  return rc;
}
#endif
