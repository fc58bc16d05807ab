/* cmd_static.c — `flexmbd static SCENE [-o OUT.csv] [--at T] [--set PATH=VALUE]... [--quiet]`
 * The static equilibrium (or, under a constant-speed drive, the steady rotation) of the scene
 * with its drives held at t0 or T: the scene's outputs as one CSV row; the last stderr line is
 * `stats: status=... t=... speed=... iterations=... load_steps=... residual=... cpu_s=...`. */
#include <stdio.h>
#include <stdlib.h>
#include <string.h>
#include <time.h>

#include "cli.h"

int fmb_cli_parse_time(const char* cmd, const char* text, double* t) {
  char* end;
  *t = strtod(text, &end);
  if (end == text || *end != '\0') {
    fprintf(stderr, "flexmbd %s: --at needs a time in seconds, got '%s'\n", cmd, text);
    return FMB_EXIT_BAD_INPUT;
  }
  return 0;
}

void fmb_cli_print_static(const fmbStaticResult* r, int ok, double cpu_s, FILE* f) {
  fprintf(f, "stats: status=%s t=%.10g speed=%.10g center=%.6g,%.6g iterations=%d load_steps=%d residual=%.3e "
             "residual_start=%.3e cpu_s=%.4f\n",
          ok ? "ok" : "failed", r->t, r->speed, r->center[0], r->center[1], r->iterations, r->load_steps, r->residual,
          r->residual_start, cpu_s);
}

int fmb_cmd_static(int argc, char** argv) {
  fmbCliScene s;
  memset(&s, 0, sizeof s);
  const char* out = NULL;
  fmbStaticOptions opt;
  memset(&opt, 0, sizeof opt);
  for (int i = 2; i < argc; ++i) {
    const char* a = argv[i];
    int r = fmb_cli_take_scene_arg("static", argc, argv, &i, &s);
    if (r == 1) continue;
    if (r) return r;
    if (strcmp(a, "-o") == 0 || strcmp(a, "--output") == 0) {
      if (!(out = fmb_cli_value("static", argc, argv, &i, "a file name"))) return FMB_EXIT_BAD_INPUT;
    } else if (strcmp(a, "--at") == 0) {
      const char* v = fmb_cli_value("static", argc, argv, &i, "a time");
      if (!v || fmb_cli_parse_time("static", v, &opt.t)) return FMB_EXIT_BAD_INPUT;
      opt.has_t = 1;
    } else if (strcmp(a, "--quiet") == 0 || strcmp(a, "-q") == 0) {
      opt.quiet = 1;
    } else {
      fprintf(stderr, "flexmbd static: unknown option '%s'\n", a);
      return FMB_EXIT_BAD_INPUT;
    }
  }
  if (!s.scene) {
    fprintf(stderr, "flexmbd static: no scene file given\n");
    return FMB_EXIT_BAD_INPUT;
  }
  fmbDiag diag;
  fmbStaticResult res;
  memset(&res, 0, sizeof res);
  const clock_t c0 = clock();
  fmbModel* m = fmb_load(s.scene, s.overrides, s.nover, fmb_cli_registry(), &diag);
  if (!m) {
    fmb_cli_print_diag(&diag);
    fmb_cli_print_static(&res, 0, 0.0, stderr);
    return diag.code ? diag.code : FMB_EXIT_BAD_INPUT;
  }
  const int ny = fmb_state_size(m);
  double* y = calloc((size_t)ny, sizeof(double));
  double* yp = calloc((size_t)ny, sizeof(double));
  int rc = y && yp ? fmb_static(m, &opt, y, yp, &res, &diag) : FMB_EXIT_SOLVER;
  if (!rc) rc = fmb_write_state_row(m, out, res.t, y, yp, &diag);
  if (rc) fmb_cli_print_diag(&diag);
  fmb_cli_print_static(&res, rc == 0, (double)(clock() - c0) / CLOCKS_PER_SEC, stderr);
  free(y);
  free(yp);
  fmb_free(m);
  return rc;
}
