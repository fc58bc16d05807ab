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
#include <stddef.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>
#include <sys/stat.h>
#include <time.h>

#include "cli.h"

/* a spatial scene's modes classified about a spin axis (fmb_modes_classify) get the columns flap,
   lag, axial, torsion: 1 in the mode's family, 0 in the others */
static int modes_csv(const fmbModes* md, const char* path, fmbDiag* diag) {
  static const char* const names[] = {"mode", "frequency", "frequency_hz", "damping_ratio",
                                      "flap", "lag",       "axial",        "torsion"};
  const int nc = md->family ? 8 : 4;
  double* rows = malloc((size_t)md->count * nc * sizeof(double) + 1);
  if (!rows) return FMB_EXIT_SOLVER;
  for (int k = 0; k < md->count; ++k) {
    double* r = rows + (size_t)nc * k;
    r[0] = k + 1;
    r[1] = md->frequency[k];
    r[2] = md->frequency[k] / (2.0 * M_PI);
    r[3] = md->damping_ratio[k];
    for (int f = FMB_FAMILY_FLAP; nc > 4 && f <= FMB_FAMILY_TORSION; ++f) r[3 + f] = md->family[k] == f;
  }
  int rc = fmb_write_table(path, nc, names, md->count, rows, diag);
  free(rows);
  return rc;
}

typedef struct {
  fmbCliScene s; /* first: fmb_opt_scene_positional */
  fmbCliAnalysis an;
  const char *out, *shapes, *animate;
  double amplitude;
  int static_given;
} ModesArgs;

static const fmbOpt modes_options[] = {
    {"--output", "-o", FMB_OPT_STRING, "modes.csv", offsetof(ModesArgs, out),
     "one row per mode: frequency (rad/s, Hz), damping ratio (default: stdout)", "a file name", 0, 0, NULL, NULL, 0},
    FMB_CLI_EIGEN_ENTRIES(ModesArgs, an, 1000000, "an integer from 1 to 1000000"),
    FMB_CLI_ANALYSIS_ENTRIES(ModesArgs, an),
    {"--static", NULL, FMB_OPT_FLAG, NULL, offsetof(ModesArgs, static_given), "about the state at the scene's t0", NULL,
     0, 0, NULL, NULL, 0},
    {"--shapes", NULL, FMB_OPT_STRING, "shapes.csv", offsetof(ModesArgs, shapes), "the mode shapes as a CSV",
     "a file name", 0, 0, NULL, NULL, 0},
    {"--animate", NULL, FMB_OPT_STRING, "DIR", offsetof(ModesArgs, animate),
     "each mode as a ParaView animation DIR/modeK/", "a directory", 0, 0, NULL, NULL, 0},
    {"--amplitude", NULL, FMB_OPT_DOUBLE, "A", offsetof(ModesArgs, amplitude),
     "the largest coordinate of an animated mode (default 0.1)", "a positive number (m or rad)", 0, HUGE_VAL, NULL,
     NULL, FMB_OPT_ABOVE_MIN},
    FMB_OPT_SCENE_ENTRIES(ModesArgs, s),
};

const fmbCommandSpec fmb_modes_command = {
    "modes",
    "SCENE.yaml",
    "frequencies, damping ratios and shapes of small motions about the static or steady state",
    modes_options,
    FMB_OPT_COUNT(modes_options),
    fmb_opt_scene_positional,
    NULL};

int fmb_cmd_modes(int argc, char** argv) {
  ModesArgs o;
  memset(&o, 0, sizeof o);
  o.an.count = 10;
  o.an.opt.quiet = 1;
  o.amplitude = 0.1;
  int rc;
  if (fmb_opt_parse(&fmb_modes_command, argc, argv, &o, &rc)) return rc;
  const fmbCliScene s = o.s;
  const fmbCliAnalysis an = o.an;
  const char *out = o.out, *shapes = o.shapes, *animate = o.animate;
  const double amplitude = o.amplitude;
  const int static_given = o.static_given;
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
  rc = fmb_cli_steady_state(&s, s.nover, &an.opt, &m, &y, &yp, &res, &diag);
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
    if (res.speed != 0.0 && !md->family)
      fprintf(stderr, "  speed %.8g rad/s about (%g, %g)\n", res.speed, res.center[0], res.center[1]);
    if (md->family) /* a spatial scene's steady rotation: its axis, the families about it */
      fprintf(stderr, "  speed %.8g rad/s about the axis [%g, %g, %g] through (%g, %g, %g)\n", res.speed, md->axis[0],
              md->axis[1], md->axis[2], md->center[0], md->center[1], md->center[2]);
    fprintf(stderr, "  %4s %16s %14s %14s%s\n", "mode", "frequency rad/s", "Hz", "damping ratio",
            md->family ? "  family" : "");
    for (int k = 0; k < md->count; ++k)
      fprintf(stderr, "  %4d %16.8g %14.8g %14.6g%s%s%s\n", k + 1, md->frequency[k], md->frequency[k] / (2.0 * M_PI),
              md->damping_ratio[k], md->family ? "  " : "", md->family ? fmb_family_name(md->family[k]) : "",
              md->frequency[k] < 0 ? "   divergent (unstable)" : "");
  }
  if (rc != FMB_EXIT_BAD_INPUT) fmb_cli_print_static(&res, rc == 0, (double)(clock() - c0) / CLOCKS_PER_SEC, stderr);
  fmb_modes_free(md);
  free(y);
  free(yp);
  fmb_free(m);
  return rc;
}
