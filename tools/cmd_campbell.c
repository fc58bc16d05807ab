/* cmd_campbell.c — `flexmbd campbell SCENE --speed PATH --speeds A:B:N|S1,S2,... [--count K] [-j J]
 *                    [--at T] [-o campbell.csv] [--plot campbell.png] [--eigen dense|sparse|auto]
 *                    [--set PATH=VALUE]...`
 * For each hub speed (PATH: the scene key that sets it, e.g. joints.spin.speed): the steady state,
 * then its modes. CSV columns: speed, mode1 ... modeK (rad/s; negative = divergent), the modes
 * followed from speed to speed by shape (greatest modal assurance criterion, MAC), not by order.
 * With -o FILE.csv a PNG is drawn beside it (FILE.png, or --plot) with gnuplot. On a failure the
 * speeds done so far are written, the message names the speed that failed, and the exit code is
 * run's (2 bad input, 3 solver: also a crash). -j J: the speeds in J child processes; under
 * mpirun/srun on every rank too (farm.c: rank 0 hands them out, gathers the modes and alone
 * follows them and writes); each child is this command again with one speed and `--modes-out
 * FILE` (internal: the modes of that speed into FILE, tools/modes_pool.c). The diagram itself is
 * the library's (fmb_campbell, engine/campbell.c); this file reads the options, tools/campbell_table.c
 * does the work. */
#include <stddef.h>
#include <stdio.h>
#include <string.h>

#include "cli.h"

typedef fmbCliCampbell CampbellArgs;
#define CAMPBELL_STRING(name, alias, meta, field, help, needs) \
  { name, alias, FMB_OPT_STRING, meta, offsetof(CampbellArgs, field), help, needs, 0, 0, NULL, NULL, 0 }
static const fmbOpt campbell_options[] = {
    CAMPBELL_STRING("--speed", NULL, "PATH", path, "the scene key that sets the hub speed (joints.spin.speed)",
                    "the scene key that sets the speed"),
    CAMPBELL_STRING("--speeds", NULL, "A:B:N|S1,S2,...", speeds_text, "N speeds from A to B, or a list",
                    "A:B:N or S1,S2,..."),
    FMB_CLI_EIGEN_ENTRIES(CampbellArgs, an, FMB_CAMPBELL_MAX_MODES, "an integer from 1 to 64"),
    {"--jobs", "-j", FMB_OPT_INT, "K", offsetof(CampbellArgs, jobs), "the speeds in K child processes",
     "1 to 1024 processes", 1, 1024, NULL, NULL, 0},
    CAMPBELL_STRING("--output", "-o", "campbell.csv", out, "speed, mode1 ... modeK (rad/s) (default: stdout)",
                    "a file name"),
    CAMPBELL_STRING("--plot", NULL, "campbell.png", png, "the figure (default: beside -o, .png)", "a PNG file name"),
    FMB_CLI_ANALYSIS_ENTRIES(CampbellArgs, an),
    FMB_OPT_SCENE_ENTRIES(CampbellArgs, s),
    CAMPBELL_STRING("--modes-out", NULL, "FILE", modes_out, "internal: a child's modes at its one speed into FILE",
                    "a file name"),
};

const fmbCommandSpec fmb_campbell_command = {
    "campbell",
    "SCENE.yaml --speed PATH --speeds A:B:N|S1,S2,...",
    "modes against the hub speed, followed by shape (MAC); under mpirun/srun the ranks share the speeds",
    campbell_options,
    FMB_OPT_COUNT(campbell_options),
    fmb_opt_scene_positional,
    NULL};

int fmb_cmd_campbell(int argc, char** argv) {
  CampbellArgs o;
  memset(&o, 0, sizeof o);
  o.an.count = 4;
  o.an.opt.quiet = 1;
  o.jobs = 1; /* -j J: the speeds' modes computed in J child processes (per rank, tools/modes_pool.c) */
  int rc;
  if (fmb_opt_parse(&fmb_campbell_command, argc, argv, &o, &rc)) return rc;
  if (!o.s.scene || !o.path || !o.speeds_text) {
    fprintf(stderr,
            "flexmbd campbell: needs SCENE, --speed PATH (e.g. joints.spin.speed) and --speeds A:B:N|S1,S2,...\n");
    return FMB_EXIT_BAD_INPUT;
  }
  /* outputs are never inputs (the scene, plugins: noted; table files: refused when written) */
  if (fmb_cli_check_output_not_input(o.out, NULL, 0) || fmb_cli_check_output_not_input(o.png, NULL, 0))
    return FMB_EXIT_BAD_INPUT;
  if (o.s.nover >= FMB_CLI_MAX_OVERRIDES) { /* the speed takes one more (fmb_campbell_modes_at) */
    fprintf(stderr, "flexmbd campbell: too many --set overrides\n");
    return FMB_EXIT_BAD_INPUT;
  }
  return fmb_cli_campbell(&o, argc, argv);
}
