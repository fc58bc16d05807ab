/* cmd_static.c — `flexmbd static SCENE [-o OUT.csv] [--at T] [--set PATH=VALUE]... [--quiet]`
 * The static equilibrium (or, under a constant-speed drive, the steady rotation) of the scene
 * with its drives held at t0 or T: the scene's outputs as one CSV row; the last stderr line is
 * `stats: status=... t=... speed=... iterations=... load_steps=... residual=... cpu_s=...`. */
#include <math.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>
#include <time.h>

#include "cli.h"

static int parse_time(const char* cmd, const char* text, double* t) {
  char* end;
  *t = strtod(text, &end);
  /* nan and inf parse as numbers; they are bad input, not a solver failure at t = nan */
  if (end == text || *end != '\0' || !isfinite(*t)) {
    fprintf(stderr, "flexmbd %s: --at needs a finite time in seconds, got '%s'\n", cmd, text);
    return FMB_EXIT_BAD_INPUT;
  }
  return 0;
}

int fmb_cli_take_analysis_arg(const char* cmd, int argc, char** argv, int* i, fmbCliAnalysis* a) {
  const char* arg = argv[*i];
  if (strcmp(arg, "--at") == 0) {
    const char* v = fmb_cli_value(cmd, argc, argv, i, "a time");
    if (!v || parse_time(cmd, v, &a->opt.t)) return FMB_EXIT_BAD_INPUT;
    a->opt.has_t = a->at_given = 1;
  } else if (strcmp(arg, "--quiet") == 0 || strcmp(arg, "-q") == 0) {
    a->quiet = 1;
  } else if (a->count_max > 0 && strcmp(arg, "--eigen") == 0) {
    static const char* const names[] = {"auto", "dense", "sparse"}; /* FMB_EIGEN_* order */
    const char* v = fmb_cli_value(cmd, argc, argv, i, "dense, sparse or auto");
    if (!v) return FMB_EXIT_BAD_INPUT;
    a->method = -1;
    for (int k = 0; k < 3; ++k)
      if (strcmp(v, names[k]) == 0) a->method = k;
    if (a->method < 0) {
      fprintf(stderr, "flexmbd %s: --eigen expects dense, sparse or auto, got '%s'\n", cmd, v);
      return FMB_EXIT_BAD_INPUT;
    }
  } else if (a->count_max > 0 && strcmp(arg, "--count") == 0) {
    const char* v = fmb_cli_value(cmd, argc, argv, i, "a number of modes");
    char* end;
    if (!v) return FMB_EXIT_BAD_INPUT;
    const long k = strtol(v, &end, 10);
    if (*end || end == v || k < 1 || k > a->count_max) {
      fprintf(stderr, "flexmbd %s: --count needs an integer from 1 to %d, got '%s'\n", cmd, a->count_max, v);
      return FMB_EXIT_BAD_INPUT;
    }
    a->count = (int)k;
  } else {
    return 0;
  }
  return 1;
}

int fmb_cli_steady_state(const fmbCliScene* s, int nover, const fmbStaticOptions* opt, fmbModel** m, double** y,
                         double** yp, fmbStaticResult* res, fmbDiag* diag) {
  const fmbSceneSource scene = {s->scene, s->overrides, nover, fmb_cli_registry()};
  const int rc = fmb_load_steady(&scene, NULL, opt, m, y, yp, res, diag);
  if (m && *m) fmb_cli_note_model(*m); /* its table files: inputs of the whole command */
  return rc;
}

void fmb_cli_print_static(const fmbStaticResult* r, int ok, double cpu_s, FILE* f) {
  fprintf(f,
          "stats: status=%s t=%.10g speed=%.10g center=%.6g,%.6g iterations=%d load_steps=%d residual=%.3e "
          "residual_start=%.3e cpu_s=%.4f\n",
          ok ? "ok" : "failed", r->t, r->speed, r->center[0], r->center[1], r->iterations, r->load_steps, r->residual,
          r->residual_start, cpu_s);
}

int fmb_cmd_static(int argc, char** argv) {
  fmbCliScene s;
  memset(&s, 0, sizeof s);
  fmbCliAnalysis an;
  memset(&an, 0, sizeof an);
  const char* out = NULL;
  for (int i = 2; i < argc; ++i) {
    const char* a = argv[i];
    int r = fmb_cli_take_scene_arg("static", argc, argv, &i, &s);
    if (!r) r = fmb_cli_take_analysis_arg("static", argc, argv, &i, &an);
    if (r == 1) continue;
    if (r) return r;
    if (strcmp(a, "-o") == 0 || strcmp(a, "--output") == 0) {
      if (!(out = fmb_cli_value("static", argc, argv, &i, "a file name"))) return FMB_EXIT_BAD_INPUT;
    } else {
      fprintf(stderr, "flexmbd static: unknown option '%s'\n", a);
      return FMB_EXIT_BAD_INPUT;
    }
  }
  if (!s.scene) {
    fprintf(stderr, "flexmbd static: no scene file given\n");
    return FMB_EXIT_BAD_INPUT;
  }
  if (fmb_cli_check_output_not_input(out, NULL, 0)) return FMB_EXIT_BAD_INPUT; /* the scene, plugins */
  an.opt.quiet = an.quiet;
  fmbDiag diag;
  fmbStaticResult res;
  fmbModel* m;
  double *y, *yp;
  const clock_t c0 = clock();
  int rc = fmb_cli_steady_state(&s, s.nover, &an.opt, &m, &y, &yp, &res, &diag);
  if (!rc) rc = fmb_write_state_row(m, out, res.t, y, yp, &diag);
  if (rc) fmb_cli_print_diag(&diag);
  /* bad input ran nothing: the error line is the last word, as for `run` */
  if (rc != FMB_EXIT_BAD_INPUT) fmb_cli_print_static(&res, rc == 0, (double)(clock() - c0) / CLOCKS_PER_SEC, stderr);
  free(y);
  free(yp);
  fmb_free(m);
  return rc;
}
