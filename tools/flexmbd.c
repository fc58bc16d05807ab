/* flexmbd.c — the command line: a table of commands, one file each (tools/cmd_NAME.c).
 * Exit codes: 0 ok, 1 a comparison beyond tolerance (compare, regress), 2 bad input, 3 solver
 * failure, 4 interrupted by SIGINT/SIGTERM (run). The last stderr line of `run` is the stats line. */
#include <stdio.h>
#include <string.h>

#include "cli.h"
#include "flexmbd_commit.h" /* generated at build time: FLEXMBD_COMMIT */

typedef struct {
  const char* name;
  int (*main)(int argc, char** argv);
  const char* usage; /* one or more lines, each starting with the command's name */
  int own_help;      /* the command prints a longer --help itself */
} Command;

static const Command commands[] = {
    {"run", fmb_cmd_run,
     "run SCENE.yaml [-o OUT.csv] [--set PATH=VALUE]... [--plugin x.so]... [--quiet] [--progress] [--vtk DIR "
     "[--vtk-every N]]\n"
     "      [--reference REF.csv [--columns a,b,...]]   also print the error against REF and the cost\n"
     "      [--models zoac,foac,complete,exact]   once per beam model, columns NAME@MODEL, a stats line each",
     0},
    {"check", fmb_cmd_check, "check SCENE.yaml [--set PATH=VALUE]...   load, validate and describe; no run", 0},
    {"compare", fmb_cmd_compare,
     "compare OUT.csv REF.csv [--columns a,b,...] [--rtol R] [--atol A]   error per column; exit 1 beyond tolerance",
     1},
    {"regress", fmb_cmd_regress,
     "regress [PATH...] [--bless] [--junit FILE] [-j N] [--set PATH=VALUE]...   scenes against their stored references",
     1},
    {"types", fmb_cmd_types,
     "types [--plugin x.so]...   the registered body and joint types: keys, units, ranges, outputs", 0},
    {"conform", fmb_cmd_conform,
     "conform [--plugin x.so]... [--work DIR] [TYPE]...   conformance checks of every (or the named) type; exit 1 on a "
     "failure",
     0},
    {"plot", fmb_cmd_plot,
     "plot OUT.csv [MORE.csv]... [COLUMN]... [-o FIG.png|.svg|.pdf] [--x COLUMN] [--logx] [--logy] [--abs]\n"
     "      [--title T] [--xlabel L] [--ylabel L] [--xrange LO:HI] [--yrange LO:HI] [--legend a,b,...]\n"
     "      [--diff REF.csv]   each column minus REF's (with --abs --logy: an error plot)\n"
     "      [--shape BEAM --at t1,t2,...]   the beam's centreline at those times (BEAM.shape columns)\n"
     "      columns against t through gnuplot; several CSVs overlaid (default: every column, OUT.png)",
     0},
    {"view", fmb_cmd_view,
     "view RUN.csv SCENE.yaml [-o run.html] [--columns a,b,...] [--scale S] [--model M] [--set PATH=VALUE]... "
     "[--plugin x.so]...\n"
     "      one self-contained HTML page animating the run (mechanism, beam shapes, traces, a plot)",
     0},
    {"new", fmb_cmd_new, "new pendulum|beam|rotor|slider-crank > scene.yaml   a commented starter scene", 0},
    {"static", fmb_cmd_static,
     "static SCENE.yaml [-o OUT.csv] [--at T] [--set PATH=VALUE]...   equilibrium, or steady rotation under a "
     "constant-speed drive",
     0},
    {"modes", fmb_cmd_modes,
     "modes SCENE.yaml [--at T | --static] [--count K] [-o modes.csv] [--shapes shapes.csv] [--animate DIR]\n"
     "      [--eigen dense|sparse|auto] [--set PATH=VALUE]...   modes about the static or steady state",
     0},
    {"campbell", fmb_cmd_campbell,
     "campbell SCENE.yaml --speed PATH --speeds A:B:N|S1,S2,... [--count K] [-j K] [-o campbell.csv] [--plot "
     "campbell.png]\n"
     "      [--eigen dense|sparse|auto] [--set PATH=VALUE]...   modes against the hub speed, followed by shape (MAC);\n"
     "      under mpirun/srun the ranks share the speeds",
     0},
    {"refine", fmb_cmd_refine,
     "refine SCENE.yaml --elements N1,N2,... [--column COL] [--body NAME] [--time-factor F] [-o TABLE.csv] [--set "
     "PATH=VALUE]...\n"
     "      a mesh refinement study: per mesh the column's end value, the difference to the next finer mesh,\n"
     "      the time error (against rtol/F) and the CPU (docs/refine.md)",
     1},
    {"sweep", fmb_cmd_sweep,
     "sweep SCENE.yaml -o DIR [--grid PATH=A:B:N[:log]|PATH=v1,v2,...]... [--zip ...] [--samples F.csv] [--random "
     "...]\n"
     "      [-j K] [--metric COL:max] [--timeout SEC|Nx] ...   many runs, each a child process; resumable "
     "(docs/sweep.md)\n"
     "sweep --status DIR   what a sweep has done",
     1},
};
#define NCOMMANDS (int)(sizeof commands / sizeof commands[0])

static void usage(FILE* f) {
  for (int i = 0; i < NCOMMANDS; ++i) fprintf(f, "%s flexmbd %s\n", i ? "      " : "usage:", commands[i].usage);
  fprintf(f, "       flexmbd --version\n");
  fprintf(f, "PATH addresses any scene value, bodies and joints by name: solver.rtol=1e-8, bodies.beam.elements=32\n"
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
    printf("flexmbd %s (commit %s, plugin ABI %d)\n", FLEXMBD_VERSION, FLEXMBD_COMMIT, FMB_ABI_VERSION);
    return 0;
  }
  if (strcmp(cmd, "--help") == 0 || strcmp(cmd, "-h") == 0 || strcmp(cmd, "help") == 0) {
    for (int i = 0; argc == 3 && i < NCOMMANDS; ++i)
      if (strcmp(argv[2], commands[i].name) == 0) {
        printf("usage: flexmbd %s\n", commands[i].usage);
        return 0;
      }
    usage(stdout);
    return 0;
  }
  /* `flexmbd CMD --help` and `flexmbd help CMD`: that command's lines of the usage */
  const int help = argc == 3 && (strcmp(argv[2], "--help") == 0 || strcmp(argv[2], "-h") == 0);
  for (int i = 0; i < NCOMMANDS; ++i)
    if (strcmp(cmd, commands[i].name) == 0) {
      if (help && !commands[i].own_help) {
        printf("usage: flexmbd %s\n", commands[i].usage);
        return 0;
      }
      return commands[i].main(argc, argv);
    }
  const char* names[NCOMMANDS];
  for (int i = 0; i < NCOMMANDS; ++i) names[i] = commands[i].name;
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
