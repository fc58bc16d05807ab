/* cmd_check.c — `flexmbd check SCENE.yaml [--set PATH=VALUE]...`: load, validate, describe, and
 * report the constraints at t0 (degrees of freedom, redundant equations, singular start). */
#include <stdio.h>
#include <string.h>

#include "cli.h"

int fmb_cmd_check(int argc, char** argv) {
  fmbCliScene s;
  memset(&s, 0, sizeof s);
  for (int i = 2; i < argc; ++i) {
    int r = fmb_cli_take_scene_arg("check", argc, argv, &i, &s);
    if (r == 1) continue;
    if (r) return r;
    fprintf(stderr, "flexmbd check: unknown option '%s'\n", argv[i]);
    return FMB_EXIT_BAD_INPUT;
  }
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
  int rc = fmb_check_constraints(m, stdout, &diag);
  if (!rc) fmb_describe_solver(m, stdout);
  if (rc) fmb_cli_print_diag(&diag);
  fmb_free(m);
  return rc;
}
