/* cmd_view.c — `flexmbd view RUN.csv SCENE.yaml [-o run.html] [--columns a,b] [--scale S] [--model M]
 *                [--set PATH=VALUE]... [--plugin x.so]...`
 * One self-contained HTML file that animates the run (tools/view_page.c makes it); this file
 * reads the options and checks the files. */
#include <math.h>
#include <stddef.h>
#include <stdio.h>
#include <string.h>

#include "view.h"

/* RUN.csv, then SCENE.yaml */
static int view_file(const fmbOptContext* ctx, const char* arg) {
  fmbViewArgs* a = ctx->self;
  if (!a->csv) {
    a->csv = arg;
    return 0;
  }
  return fmb_opt_scene_positional(ctx, arg);
}

static const fmbOpt view_options[] = {
    {"--output", "-o", FMB_OPT_STRING, "run.html", offsetof(fmbViewArgs, out), "the page (default: RUN.html)",
     "a file name (.html)", 0, 0, NULL, NULL, 0},
    {"--columns", NULL, FMB_OPT_STRING, "a,b,...", offsetof(fmbViewArgs, columns),
     "the columns plotted (default: the one that moves most)", "a comma-separated list of columns", 0, 0, NULL, NULL,
     0},
    {"--scale", NULL, FMB_OPT_DOUBLE, "S", offsetof(fmbViewArgs, scale),
     "the beams' deformation drawn S times (default 1)", "a number >= 0 (1 = as computed)", 0, HUGE_VAL, NULL, NULL, 0},
    {"--model", NULL, FMB_OPT_STRING, "M", offsetof(fmbViewArgs, model), "the run of model M in a `run --models` CSV",
     "a model name (the CSV's NAME@MODEL columns)", 0, 0, NULL, NULL, 0},
    FMB_OPT_SCENE_ENTRIES(fmbViewArgs, s),
};

const fmbCommandSpec fmb_view_command = {
    "view",
    "RUN.csv SCENE.yaml",
    "one self-contained HTML page animating the run (mechanism, beam shapes, traces, a plot)",
    view_options,
    FMB_OPT_COUNT(view_options),
    view_file,
    NULL};

int fmb_cmd_view(int argc, char** argv) {
  fmbViewArgs a;
  memset(&a, 0, sizeof a);
  a.scale = 1.0;
  int rc;
  if (fmb_opt_parse(&fmb_view_command, argc, argv, &a, &rc)) return rc;
  if (!a.csv || !a.s.scene) {
    fprintf(stderr, "flexmbd view: expected RUN.csv SCENE.yaml (usage: flexmbd view RUN.csv SCENE.yaml -o run.html)\n");
    return FMB_EXIT_BAD_INPUT;
  }
  char default_out[1024];
  if (!a.out) { /* RUN.csv -> RUN.html */
    snprintf(default_out, sizeof default_out, "%s", a.csv);
    char* dot = strrchr(default_out, '.');
    if (dot && !strchr(dot, '/')) *dot = '\0';
    strncat(default_out, ".html", sizeof default_out - strlen(default_out) - 1);
    a.out = default_out;
  }
  if (fmb_cli_check_input(a.csv, "run's CSV") || fmb_cli_check_input(a.s.scene, "scene")) return FMB_EXIT_BAD_INPUT;
  const char* inputs[2 + 16] = {a.csv, a.s.scene};
  for (int k = 0; k < a.s.nplugins; ++k) inputs[2 + k] = a.s.plugins[k];
  if (fmb_cli_check_output_not_input(a.out, inputs, 2 + a.s.nplugins)) return FMB_EXIT_BAD_INPUT;
  return fmb_view_page(&a);
}
