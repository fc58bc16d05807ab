/* cmd_run.c — `flexmbd run SCENE.yaml [-o OUT.csv] [--set PATH=VALUE]... [--quiet] [--progress]
 *                [--vtk DIR] [--reference REF.csv [--columns a,b]]
 *                [--models zoac,foac,complete,exact]`
 * Integrates the scene, writing the CSV as it goes; the last stderr line is the stats line. */
#include <stddef.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>
#include <unistd.h>

#include "cli.h"

typedef struct {
  fmbCliScene s; /* first: fmb_opt_scene_positional */
  const char* out;
  const char* reference; /* --reference REF.csv: error against REF and the run's cost */
  const char* columns;
  int quiet, progress;
  const char* vtk;    /* --vtk DIR: a ParaView animation there */
  int vtk_every;      /* --vtk-every N: of every Nth row */
  const char* models; /* --models zoac,foac,complete,exact: tools/run_models.c */
  int serve;          /* --serve: runs on demand for `sweep --runner serve` (tools/run_serve.c) */
} RunArgs;

#define RUN_STRING(name, alias, meta, field, help, needs) \
  { name, alias, FMB_OPT_STRING, meta, offsetof(RunArgs, field), help, needs, 0, 0, NULL, NULL, 0 }
#define RUN_FLAG(name, alias, field, help) \
  { name, alias, FMB_OPT_FLAG, NULL, offsetof(RunArgs, field), help, NULL, 0, 0, NULL, NULL, 0 }
static const fmbOpt run_options[] = {
    RUN_STRING("--output", "-o", "OUT.csv", out, "the CSV, written as the run goes (default: stdout)", "a file name"),
    FMB_OPT_SCENE_ENTRIES(RunArgs, s),
    RUN_FLAG("--quiet", "-q", quiet, "no progress line, no warnings but errors"),
    RUN_FLAG("--progress", NULL, progress, "the progress line from the start, also off a terminal"),
    RUN_STRING("--vtk", NULL, "DIR", vtk, "the run as a ParaView animation in DIR", "a directory"),
    {"--vtk-every", NULL, FMB_OPT_INT, "N", offsetof(RunArgs, vtk_every), "animate every Nth row (default 1)",
     "a whole number N >= 1 (every Nth row)", 1, 1000000000, NULL, NULL, 0},
    RUN_STRING("--reference", NULL, "REF.csv", reference, "also print the error against REF and the run's cost",
               "a CSV file"),
    RUN_STRING("--columns", NULL, "a,b,...", columns, "the columns compared with --reference",
               "a comma-separated list"),
    RUN_STRING("--models", NULL, "zoac,foac,complete,exact", models,
               "once per beam model, columns NAME@MODEL, a stats line each", "a comma-separated list of beam models"),
    RUN_FLAG("--serve", NULL, serve, "internal: runs on demand for `sweep --runner serve`"),
};

const fmbCommandSpec fmb_run_command = {"run",
                                        "SCENE.yaml",
                                        "integrate the scene, writing the CSV as it goes; the last stderr line is "
                                        "the stats line",
                                        run_options,
                                        FMB_OPT_COUNT(run_options),
                                        fmb_opt_scene_positional,
                                        NULL};

int fmb_cmd_run(int argc, char** argv) {
  RunArgs o;
  memset(&o, 0, sizeof o);
  o.vtk_every = 1;
  int rc;
  if (fmb_opt_parse(&fmb_run_command, argc, argv, &o, &rc)) return rc;
  const fmbCliScene s = o.s;
  const char *out = o.out, *reference = o.reference, *columns = o.columns, *vtk = o.vtk, *models = o.models;
  const int quiet = o.quiet, progress = o.progress, vtk_every = o.vtk_every, serve = o.serve;
  if (reference && (!out || strcmp(out, "-") == 0)) {
    fprintf(stderr, "flexmbd: --reference needs the run's CSV in a file (-o OUT.csv)\n");
    return FMB_EXIT_BAD_INPUT;
  }
  if (!s.scene) {
    fprintf(stderr, "flexmbd run: no scene file given\n");
    return FMB_EXIT_BAD_INPUT;
  }
  if (models && reference) {
    fprintf(stderr,
            "flexmbd run: --models and --reference do not combine (compare the merged CSV's columns instead)\n");
    return FMB_EXIT_BAD_INPUT;
  }
  if (serve) return fmb_run_serve(&s);
  fmbDiag diag;
  fmbStats stats;
  memset(&stats, 0, sizeof stats);
  /* every input is checked (the scene by fmb_load), and the output compared with them, before
     anything is run or written */
  const char* inputs[2 + sizeof s.plugins / sizeof s.plugins[0]] = {s.scene, reference};
  int ninputs = 2;
  for (int k = 0; k < s.nplugins; ++k) inputs[ninputs++] = s.plugins[k];
  int bad = reference ? fmb_cli_check_input(reference, "reference") : 0;
  if (!bad) bad = fmb_cli_check_output_not_input(out, inputs, ninputs);
  if (bad) return bad; /* nothing ran: no stats line */
  volatile sig_atomic_t* stop = fmb_cli_catch_stop_signals();
  if (models) return fmb_cli_run_models(&s, models, out, quiet, vtk, vtk_every, stop);
  fmbModel* m = fmb_load(s.scene, s.overrides, s.nover, fmb_cli_registry(), &diag);
  if (!m) {
    fmb_cli_print_diag(&diag);
    return diag.code ? diag.code : FMB_EXIT_BAD_INPUT;
  }
  fmb_cli_note_model(m); /* its table files and plugins: inputs of the whole command */
  /* the progress line: on a terminal once a run has taken 2 s; --progress asks for it anywhere
     and from the start; --quiet wins over both */
  fmbRunOptions opt = {.csv_path = out,
                       .quiet = quiet,
                       .progress = !quiet && (progress || isatty(STDERR_FILENO)),
                       .progress_after_s = progress ? 0.0 : 2.0,
                       .vtk_dir = vtk,
                       .vtk_every = vtk_every,
                       .stop = stop};
  rc = fmb_run(m, &opt, &stats, &diag);
  fmb_cli_warn_end();
  if (rc) fmb_cli_print_diag(&diag);
  if (reference) {
    /* one line per column on stdout: the error against the reference and what the run cost */
    char tag[160];
    snprintf(tag, sizeof tag, "status=%s cpu_s=%.4f steps=%ld", rc ? "failed" : "ok", stats.cpu_s, stats.steps);
    const fmbCliCompare c = {.out = out, .ref = reference, .columns = columns, .tag = tag, .common = 1};
    int crc = fmb_cli_compare(&c);
    if (crc && !rc) rc = crc;
  }
  /* the stats line tells what a run did; bad input (found in the initial pose, or an output that
     cannot be written) ran nothing, and the error line is the last word */
  if (rc != FMB_EXIT_BAD_INPUT) fmb_print_stats(&stats, stderr);
  fmb_free(m);
  return rc;
}
