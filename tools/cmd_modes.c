/* cmd_modes.c — `flexmbd modes SCENE [--at T | --static] [--count K] [-o modes.csv]
 *                 [--shapes shapes.csv] [--animate DIR [--amplitude A]] [--eigen dense|sparse|auto]
 *                 [--set PATH=VALUE]... [--quiet]`
 * Frequencies, damping ratios and shapes of small motions about the static or steady state
 * (drives held at t0, or at T with --at). The CSV has one row per mode: mode, frequency (rad/s),
 * frequency_hz, damping_ratio; without -o it goes to stdout. --animate DIR: each mode as a
 * ParaView animation DIR/modeK/SCENE.pvd (24 frames over a period, largest coordinate A = 0.1). A table goes to stderr, then
 * the static solution's stats line. */
#include <errno.h>
#include <math.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>
#include <sys/stat.h>
#include <time.h>

#include "cli.h"

static int modes_csv(const fmbModes* md, const char* path, fmbDiag* diag) {
  static const char* const names[] = {"mode", "frequency", "frequency_hz", "damping_ratio"};
  double* rows = malloc((size_t)md->count * 4 * sizeof(double) + 1);
  if (!rows) return FMB_EXIT_SOLVER;
  for (int k = 0; k < md->count; ++k) {
    rows[4 * k] = k + 1;
    rows[4 * k + 1] = md->frequency[k];
    rows[4 * k + 2] = md->frequency[k] / (2.0 * M_PI);
    rows[4 * k + 3] = md->damping_ratio[k];
  }
  int rc = fmb_write_table(path, 4, names, md->count, rows, diag);
  free(rows);
  return rc;
}

int fmb_cmd_modes(int argc, char** argv) {
  fmbCliScene s;
  memset(&s, 0, sizeof s);
  fmbCliAnalysis an;
  memset(&an, 0, sizeof an);
  an.count = 10;
  an.count_max = 1000000;
  an.opt.quiet = 1;
  const char *out = NULL, *shapes = NULL, *animate = NULL;
  double amplitude = 0.1;
  int static_given = 0;
  for (int i = 2; i < argc; ++i) {
    const char* a = argv[i];
    int r = fmb_cli_take_scene_arg("modes", argc, argv, &i, &s);
    if (!r) r = fmb_cli_take_analysis_arg("modes", argc, argv, &i, &an);
    if (r == 1) continue;
    if (r) return r;
    if (strcmp(a, "-o") == 0 || strcmp(a, "--output") == 0) {
      if (!(out = fmb_cli_value("modes", argc, argv, &i, "a file name"))) return FMB_EXIT_BAD_INPUT;
    } else if (strcmp(a, "--shapes") == 0) {
      if (!(shapes = fmb_cli_value("modes", argc, argv, &i, "a file name"))) return FMB_EXIT_BAD_INPUT;
    } else if (strcmp(a, "--animate") == 0) {
      if (!(animate = fmb_cli_value("modes", argc, argv, &i, "a directory"))) return FMB_EXIT_BAD_INPUT;
    } else if (strcmp(a, "--amplitude") == 0) {
      const char* v = fmb_cli_value("modes", argc, argv, &i, "a number");
      char* end;
      if (!v) return FMB_EXIT_BAD_INPUT;
      amplitude = strtod(v, &end);
      if (*end || end == v || !(amplitude > 0.0)) {
        fprintf(stderr, "flexmbd modes: --amplitude needs a positive number (m or rad), got '%s'\n", v);
        return FMB_EXIT_BAD_INPUT;
      }
    } else if (strcmp(a, "--static") == 0) {
      static_given = 1;
    } else {
      fprintf(stderr, "flexmbd modes: unknown option '%s'\n", a);
      return FMB_EXIT_BAD_INPUT;
    }
  }
  if (!s.scene) {
    fprintf(stderr, "flexmbd modes: no scene file given\n");
    return FMB_EXIT_BAD_INPUT;
  }
  /* outputs are never inputs (the scene and plugins are noted; table files are refused when written) */
  if (fmb_cli_check_output_not_input(out, NULL, 0) || fmb_cli_check_output_not_input(shapes, NULL, 0))
    return FMB_EXIT_BAD_INPUT;
  if (an.at_given && static_given) {
    fprintf(stderr, "flexmbd modes: --at T and --static are alternatives (--static: the state at the scene's t0)\n");
    return FMB_EXIT_BAD_INPUT;
  }
  fmbDiag diag;
  fmbStaticResult res;
  fmbModel* m;
  double *y, *yp;
  fmbModes* md = NULL;
  const clock_t c0 = clock();
  int rc = fmb_cli_steady_state(&s, s.nover, &an.opt, &m, &y, &yp, &res, &diag);
  if (!rc) rc = fmb_modes(m, res.t, y, yp, an.count, an.method, &md, &diag);
  if (!rc) rc = modes_csv(md, out, &diag);
  if (!rc && shapes) rc = fmb_write_mode_shapes(m, res.t, y, yp, md, shapes, &diag);
  if (!rc && animate) {
    /* one ParaView collection per mode: DIR/mode1, DIR/mode2, ... */
    if (mkdir(animate, 0777) != 0 && errno != EEXIST) {
      fprintf(stderr, "%s: error: cannot create the directory: %s\n", animate, strerror(errno));
      rc = FMB_EXIT_BAD_INPUT;
    }
    char dir[1200];
    for (int k = 0; !rc && k < md->count; ++k) {
      snprintf(dir, sizeof dir, "%s/mode%d", animate, k + 1);
      rc = fmb_write_mode_animation(m, res.t, y, md, k, amplitude, 24, dir, &diag);
    }
  }
  if (rc) fmb_cli_print_diag(&diag);
  if (md && !an.quiet) {
    fprintf(stderr, "modes about the %s at t = %g (%d degrees of freedom after the constraints, %s eigen-solver):\n",
            res.speed != 0.0 ? "steady rotation" : "static equilibrium", res.t, md->nreduced,
            md->sparse ? "sparse shift-invert" : "dense");
    if (res.speed != 0.0)
      fprintf(stderr, "  speed %.8g rad/s about (%g, %g)\n", res.speed, res.center[0], res.center[1]);
    fprintf(stderr, "  %4s %16s %14s %14s\n", "mode", "frequency rad/s", "Hz", "damping ratio");
    for (int k = 0; k < md->count; ++k)
      fprintf(stderr, "  %4d %16.8g %14.8g %14.6g%s\n", k + 1, md->frequency[k], md->frequency[k] / (2.0 * M_PI),
              md->damping_ratio[k], md->frequency[k] < 0 ? "   divergent (unstable)" : "");
  }
  if (rc != FMB_EXIT_BAD_INPUT) fmb_cli_print_static(&res, rc == 0, (double)(clock() - c0) / CLOCKS_PER_SEC, stderr);
  fmb_modes_free(md);
  free(y);
  free(yp);
  fmb_free(m);
  return rc;
}
