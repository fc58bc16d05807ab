/* cmd_static.c — `flexmbd static SCENE [-o OUT.csv] [--at T] [--set PATH=VALUE]... [--quiet]`
 * The static equilibrium (or, under a constant-speed drive, the steady rotation) of the scene
 * with its drives held at t0 or T: the scene's outputs as one CSV row; the last stderr line is
 * `stats: status=... t=... speed=... iterations=... load_steps=... residual=... cpu_s=...`. */
#include <math.h>
#include <stddef.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>
#include <time.h>

#include "cli.h"

int fmb_cli_read_at(const fmbOptContext* ctx, void* at, const char* text) {
  fmbCliAnalysis* a = at;
  char* end;
  a->opt.t = strtod(text, &end);
  /* nan and inf parse as numbers; they are bad input, not a solver failure at t = nan */
  if (end == text || *end != '\0' || !isfinite(a->opt.t)) {
    fprintf(stderr, "flexmbd %s: --at needs a finite time in seconds, got '%s'\n", ctx->cmd, text);
    return FMB_EXIT_BAD_INPUT;
  }
  a->opt.has_t = a->at_given = 1;
  return 0;
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

typedef struct {
  fmbCliScene s; /* first: fmb_opt_scene_positional */
  fmbCliAnalysis an;
  const char* out;
} StaticArgs;

static const fmbOpt static_options[] = {
    {"--output", "-o", FMB_OPT_STRING, "OUT.csv", offsetof(StaticArgs, out),
     "the state as one CSV row (default: stdout)", "a file name", 0, 0, NULL, NULL, 0},
    FMB_CLI_ANALYSIS_ENTRIES(StaticArgs, an),
    FMB_OPT_SCENE_ENTRIES(StaticArgs, s),
};

const fmbCommandSpec fmb_static_command = {"static",
                                           "SCENE.yaml",
                                           "equilibrium, or steady rotation under a constant-speed drive",
                                           static_options,
                                           FMB_OPT_COUNT(static_options),
                                           fmb_opt_scene_positional,
                                           NULL};

int fmb_cmd_static(int argc, char** argv) {
  StaticArgs o;
  memset(&o, 0, sizeof o);
  int rc;
  if (fmb_opt_parse(&fmb_static_command, argc, argv, &o, &rc)) return rc;
  const fmbCliScene s = o.s;
  fmbCliAnalysis an = o.an;
  const char* out = o.out;
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
  rc = fmb_cli_steady_state(&s, s.nover, &an.opt, &m, &y, &yp, &res, &diag);
  if (!rc) rc = fmb_write_state_row(m, out, res.t, y, yp, &diag);
  if (rc) fmb_cli_print_diag(&diag);
  /* bad input ran nothing: the error line is the last word, as for `run` */
  if (rc != FMB_EXIT_BAD_INPUT) fmb_cli_print_static(&res, rc == 0, (double)(clock() - c0) / CLOCKS_PER_SEC, stderr);
  free(y);
  free(yp);
  fmb_free(m);
  return rc;
}
