#include "testlib.h"

#include <stdlib.h>
#include <string.h>
#include <sys/stat.h>
#include <unistd.h>

const char* fmbt_path(const char* rel, char* buf, size_t len) {
  snprintf(buf, len, "%s/%s", FLEXMBD_SOURCE_DIR, rel);
  return buf;
}

/* one file per process: concurrent ctest runs on the same build never share an output file */
const char* fmbt_out_path(const char* name, char* buf, size_t len) {
  mkdir(FLEXMBD_TEST_OUT, 0755);
  snprintf(buf, len, "%s/%ld-%s", FLEXMBD_TEST_OUT, (long)getpid(), name);
  return buf;
}

int fmbt_run(const char* scene_rel, const char* const* overrides, int noverrides, const char* out_name, fmbStats* st,
             fmbDiag* diag) {
  char scene[1024], out[1024];
  fmbt_path(scene_rel, scene, sizeof scene);
  fmbt_out_path(out_name, out, sizeof out);
  memset(st, 0, sizeof *st);
  fmbModel* m = fmb_load(scene, overrides, noverrides, fmb_builtin_registry(), diag);
  if (!m) {
    fprintf(stderr, "%s:%d:%d: error: %s\n", diag->file, diag->line, diag->col, diag->msg);
    return diag->code;
  }
  fmbRunOptions opt = {.csv_path = out, .quiet = 1};
  int rc = fmb_run(m, &opt, st, diag);
  if (rc) fprintf(stderr, "run %s stopped: %s\n", scene_rel, diag->msg);
  fmb_print_stats(st, stderr);
  fmb_free(m);
  return rc;
}

int fmbt_run_read(const char* scene_rel, const char* const* overrides, int noverrides, const char* out_name, fmbtCsv* c,
                  fmbStats* st) {
  fmbDiag d;
  memset(c, 0, sizeof *c);
  int rc = fmbt_run(scene_rel, overrides, noverrides, out_name, st, &d);
  if (rc == FMB_EXIT_BAD_INPUT) return rc;
  char out[1024];
  if (fmbt_csv_read(fmbt_out_path(out_name, out, sizeof out), c)) ++fmbt_failures;
  return rc;
}

int fmbt_csv_read(const char* path, fmbtCsv* c) {
  memset(c, 0, sizeof *c);
  FILE* f = fopen(path, "r");
  if (!f) {
    fprintf(stderr, "cannot read %s\n", path);
    return -1;
  }
  size_t cap = 1 << 16, len = 0;
  char* text = malloc(cap);
  size_t got;
  while ((got = fread(text + len, 1, cap - len - 1, f)) > 0) {
    len += got;
    if (cap - len < 2) text = realloc(text, cap *= 2);
  }
  fclose(f);
  text[len] = '\0';
  /* header */
  char* line = text;
  char* nl = strchr(line, '\n');
  if (!nl) {
    free(text);
    return -1;
  }
  *nl = '\0';
  c->ncol = 1;
  for (char* p = line; *p; ++p) c->ncol += *p == ',';
  c->names = calloc((size_t)c->ncol, sizeof(char*));
  char* save = NULL;
  int k = 0;
  for (char* tok = strtok_r(line, ",", &save); tok && k < c->ncol; tok = strtok_r(NULL, ",", &save))
    c->names[k++] = strdup(tok);
  /* rows */
  int rows = 0;
  for (char* p = nl + 1; *p; ++p) rows += *p == '\n';
  double* rowmajor = calloc((size_t)rows * c->ncol + 1, sizeof(double));
  char* p = nl + 1;
  int r = 0;
  while (r < rows && *p) {
    for (int j = 0; j < c->ncol; ++j) {
      char* end;
      rowmajor[(size_t)r * c->ncol + j] = strtod(p, &end);
      p = end;
      if (*p == ',') ++p;
    }
    while (*p && *p != '\n') ++p;
    if (*p == '\n') ++p;
    ++r;
  }
  c->nrow = r;
  c->data = calloc((size_t)r * c->ncol + 1, sizeof(double));
  for (int i = 0; i < r; ++i)
    for (int j = 0; j < c->ncol; ++j) c->data[(size_t)j * r + i] = rowmajor[(size_t)i * c->ncol + j];
  free(rowmajor);
  free(text);
  return 0;
}

const double* fmbt_col(const fmbtCsv* c, const char* name) {
  for (int j = 0; j < c->ncol; ++j)
    if (strcmp(c->names[j], name) == 0) return c->data + (size_t)j * c->nrow;
  fprintf(stderr, "no column '%s' in the CSV\n", name);
  ++fmbt_failures;
  return NULL;
}

void fmbt_csv_free(fmbtCsv* c) {
  for (int j = 0; j < c->ncol; ++j) free(c->names[j]);
  free(c->names);
  free(c->data);
  memset(c, 0, sizeof *c);
}

double fmbt_crossing_frequency(const fmbtCsv* c, const char* col, double t0, int* ncross) {
  const double* t = fmbt_col(c, "t");
  const double* x = fmbt_col(c, col);
  *ncross = 0;
  if (!t || !x) return NAN;
  double first = NAN, last = NAN;
  for (int i = 1; i < c->nrow; ++i) {
    if (t[i - 1] < t0 || (x[i - 1] < 0.0) == (x[i] < 0.0)) continue;
    const double tc = t[i - 1] - x[i - 1] * (t[i] - t[i - 1]) / (x[i] - x[i - 1]);
    if (*ncross == 0) first = tc;
    last = tc;
    ++*ncross;
  }
  return *ncross >= 2 ? M_PI * (*ncross - 1) / (last - first) : NAN;
}

double fmbt_energy_balance(const fmbtCsv* c, const char* body) {
  char omega[96], momentum[96];
  snprintf(omega, sizeof omega, "%s.omega", body);
  snprintf(momentum, sizeof momentum, "%s.ang_momentum", body);
  const double* e = fmbt_col(c, "energy.total");
  const double* om = fmbt_col(c, omega);
  const double* lz = fmbt_col(c, momentum);
  if (!e || !om || !lz) return INFINITY;
  double w = 0.0, worst = 0.0, emax = 0.0;
  for (int i = 1; i < c->nrow; ++i) {
    w += 0.5 * (om[i] + om[i - 1]) * (lz[i] - lz[i - 1]);
    worst = fmax(worst, fabs(e[i] - e[0] - w));
    emax = fmax(emax, fabs(e[i]));
  }
  return worst / emax;
}

char* fmbt_slurp(const char* path, size_t* len) {
  FILE* f = fopen(path, "rb");
  *len = 0;
  if (!f) return NULL;
  size_t cap = 1 << 16, n = 0, got;
  char* buf = malloc(cap);
  while (buf && (got = fread(buf + n, 1, cap - n - 1, f)) > 0) {
    n += got;
    if (cap - n < 2) {
      char* grown = realloc(buf, cap *= 2);
      if (!grown) free(buf);
      buf = grown;
    }
  }
  fclose(f);
  if (buf) buf[n] = '\0';
  *len = buf ? n : 0;
  return buf;
}
