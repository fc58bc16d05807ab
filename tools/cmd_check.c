/* cmd_check.c — `flexmbd check SCENE.yaml [--set PATH=VALUE]...`: load, validate, describe, and
 * report the constraints at t0 (degrees of freedom, redundant equations, singular start). */
#include <stdio.h>
#include <string.h>

#include "cli.h"

typedef struct {
  fmbCliScene s;
} CheckArgs;

static const fmbOpt check_options[] = {FMB_OPT_SCENE_ENTRIES(CheckArgs, s)};

const fmbCommandSpec fmb_check_command = {"check",
                                          "SCENE.yaml",
                                          "load, validate and describe the scene and its constraints at t0; no run",
                                          check_options,
                                          FMB_OPT_COUNT(check_options),
                                          fmb_opt_scene_positional,
                                          NULL};

int fmb_cmd_check(int argc, char** argv) {
  CheckArgs o;
  memset(&o, 0, sizeof o);
  fmbCliScene s;
  int rc;
  if (fmb_opt_parse(&fmb_check_command, argc, argv, &o, &rc)) return rc;
  s = o.s;
  if (!s.scene) {
    fprintf(stderr, "flexmbd check: no scene file given\n");
    return FMB_EXIT_BAD_INPUT;
  }
  fmbDiag diag;
  fmbModel* m = fmb_load(s.scene, s.overrides, s.nover, fmb_cli_registry(), &diag);
  if (!m) {
    fmb_cli_print_diag(&diag);
    return diag.code ? diag.code : FMB_EXIT_BAD_INPUT;
  }
  fmb_describe(m, stdout);
  rc = fmb_check_constraints(m, stdout, &diag);
  if (!rc) fmb_describe_solver(m, stdout);
  if (rc) fmb_cli_print_diag(&diag);
  fmb_free(m);
  return rc;
}
