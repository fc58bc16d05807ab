/* cmd_run.c — `flexmbd run SCENE.yaml [-o OUT.csv] [--set PATH=VALUE]... [--quiet] [--progress]
 *                [--vtk DIR] [--reference REF.csv [--columns a,b]]
 *                [--models zoac,foac,complete,exact]`
 * Integrates the scene, writing the CSV as it goes; the last stderr line is the stats line. */
#include <stdio.h>
#include <stdlib.h>
#include <string.h>
#include <unistd.h>

#include "cli.h"

int fmb_cmd_run(int argc, char** argv) {
  fmbCliScene s;
  memset(&s, 0, sizeof s);
  const char* out = NULL;
  const char* reference = NULL; /* --reference REF.csv: error against REF and the run's cost */
  const char* columns = NULL;
  int quiet = 0, progress = 0;
  const char* vtk = NULL;    /* --vtk DIR: a ParaView animation there */
  int vtk_every = 1;         /* --vtk-every N: of every Nth row */
  const char* models = NULL; /* --models zoac,foac,complete,exact: tools/run_models.c */
  int serve = 0;             /* --serve: runs on demand for `sweep --runner serve` (tools/run_serve.c) */
  for (int i = 2; i < argc; ++i) {
    const char* a = argv[i];
    int r = fmb_cli_take_scene_arg("run", argc, argv, &i, &s);
    if (r == 1) continue;
    if (r) return r;
    if (strcmp(a, "-o") == 0 || strcmp(a, "--output") == 0) {
      if (!(out = fmb_cli_value("run", argc, argv, &i, "a file name"))) return FMB_EXIT_BAD_INPUT;
    } else if (strcmp(a, "--reference") == 0) {
      if (!(reference = fmb_cli_value("run", argc, argv, &i, "a CSV file"))) return FMB_EXIT_BAD_INPUT;
    } else if (strcmp(a, "--columns") == 0) {
      if (!(columns = fmb_cli_value("run", argc, argv, &i, "a comma-separated list"))) return FMB_EXIT_BAD_INPUT;
    } else if (strcmp(a, "--models") == 0) {
      if (!(models = fmb_cli_value("run", argc, argv, &i, "a comma-separated list of beam models")))
        return FMB_EXIT_BAD_INPUT;
    } else if (strcmp(a, "--quiet") == 0 || strcmp(a, "-q") == 0) {
      quiet = 1;
    } else if (strcmp(a, "--serve") == 0) {
      serve = 1;
    } else if (strcmp(a, "--progress") == 0) {
      progress = 1;
    } else if (strcmp(a, "--vtk") == 0) {
      if (!(vtk = fmb_cli_value("run", argc, argv, &i, "a directory"))) return FMB_EXIT_BAD_INPUT;
    } else if (strcmp(a, "--vtk-every") == 0) {
      const char* v = fmb_cli_value("run", argc, argv, &i, "a whole number N >= 1");
      char* end = NULL;
      const long n = v ? strtol(v, &end, 10) : 0;
      if (!v || end == v || *end || n < 1 || n > 1000000000L) {
        if (v) fprintf(stderr, "flexmbd run: --vtk-every expects a whole number N >= 1 (every Nth row), got '%s'\n", v);
        return FMB_EXIT_BAD_INPUT;
      }
      vtk_every = (int)n;
    } else {
      fprintf(stderr, "flexmbd run: unknown option '%s'\n", a);
      return FMB_EXIT_BAD_INPUT;
    }
  }
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
  int rc = fmb_run(m, &opt, &stats, &diag);
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
