/* flexmbd.c — the command line: a table of commands, one file each (tools/cmd_NAME.c).
 * Exit codes: 0 ok, 1 a comparison beyond tolerance (compare, regress), 2 bad input, 3 solver
 * failure, 4 interrupted by SIGINT/SIGTERM (run). The last stderr line of `run` is the stats line. */
#include <stdio.h>
#include <string.h>

#include "cli.h"
#include "flexmbd_commit.h" /* generated at build time: FLEXMBD_COMMIT */

typedef struct {
  const fmbCommandSpec* spec; /* its name, arguments, options (tools/options.h) */
  int (*main)(int argc, char** argv);
} Command;

static const Command commands[] = {
    {&fmb_run_command, fmb_cmd_run},         {&fmb_check_command, fmb_cmd_check},
    {&fmb_compare_command, fmb_cmd_compare}, {&fmb_regress_command, fmb_cmd_regress},
    {&fmb_types_command, fmb_cmd_types},     {&fmb_conform_command, fmb_cmd_conform},
    {&fmb_plot_command, fmb_cmd_plot},       {&fmb_view_command, fmb_cmd_view},
    {&fmb_new_command, fmb_cmd_new},         {&fmb_static_command, fmb_cmd_static},
    {&fmb_modes_command, fmb_cmd_modes},     {&fmb_campbell_command, fmb_cmd_campbell},
    {&fmb_refine_command, fmb_cmd_refine},   {&fmb_sweep_command, fmb_cmd_sweep},
};
#define NCOMMANDS (int)(sizeof commands / sizeof commands[0])

/* one line per command, from its table: flexmbd NAME ARGS [options]   what it does */
static void usage(FILE* f) {
  for (int i = 0; i < NCOMMANDS; ++i) {
    const fmbCommandSpec* c = commands[i].spec;
    fprintf(f, "%s flexmbd %s%s%s%s\n        %s\n", i ? "      " : "usage:", c->name, c->args[0] ? " " : "", c->args,
            c->nopts ? " [options]" : "", c->summary);
  }
  fprintf(f, "       flexmbd --version\n");
  fprintf(f, "flexmbd CMD --help lists the options of CMD\n"
             "PATH addresses any scene value, bodies and joints by name: solver.rtol=1e-8, bodies.beam.elements=32\n"
             "exit codes: 0 ok, 1 beyond tolerance (compare, regress), 2 bad input, 3 solver failure, 4 interrupted\n");
}

int main(int argc, char** argv) {
  fmb_set_warn(fmb_cli_warn, NULL);
  if (argc < 2) {
    usage(stderr);
    return FMB_EXIT_BAD_INPUT;
  }
  const char* cmd = argv[1];
  if (strcmp(cmd, "--version") == 0 || strcmp(cmd, "version") == 0) {
    printf("flexmbd %s (commit %s, plugin ABI %d.%d)\n", FLEXMBD_VERSION, FLEXMBD_COMMIT, FMB_PLUGIN_ABI_MAJOR,
           FMB_PLUGIN_ABI_MINOR);
    return 0;
  }
  if (strcmp(cmd, "--help") == 0 || strcmp(cmd, "-h") == 0 || strcmp(cmd, "help") == 0) {
    for (int i = 0; argc == 3 && i < NCOMMANDS; ++i)
      if (strcmp(argv[2], commands[i].spec->name) == 0) { /* `flexmbd help CMD`: CMD --help */
        fmb_opt_usage(commands[i].spec, stdout, 1);
        return 0;
      }
    usage(stdout);
    return 0;
  }
  /* `flexmbd CMD --help`: the command's parser writes the help from its table */
  for (int i = 0; i < NCOMMANDS; ++i)
    if (strcmp(cmd, commands[i].spec->name) == 0) return commands[i].main(argc, argv);
  const char* names[NCOMMANDS];
  for (int i = 0; i < NCOMMANDS; ++i) names[i] = commands[i].spec->name;
  const char* nearest = fmb_nearest_word(cmd, names, NCOMMANDS);
  if (nearest) { /* a typo: the one command meant, not the whole usage */
    fprintf(stderr, "flexmbd: unknown command '%s'; did you mean '%s'? (flexmbd --help lists the commands)\n", cmd,
            nearest);
    return FMB_EXIT_BAD_INPUT;
  }
  fprintf(stderr, "flexmbd: unknown command '%s'\n", cmd);
  usage(stderr);
  return FMB_EXIT_BAD_INPUT;
}
