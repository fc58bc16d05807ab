/* cli.h — what the command files of the `flexmbd` program share (tools/cmd_*.c).
 * One command is one file exporting `int fmb_cmd_NAME(int argc, char** argv)` (argv[1] is the
 * command's name), listed once in the table of tools/flexmbd.c. */
#ifndef FLEXMBD_CLI_H
#define FLEXMBD_CLI_H
#include <signal.h>
#include <stdio.h>

#include "flexmbd_cli.h"
#include "flexmbd_plugin.h"
#include "options.h"

#define FMB_CLI_MAX_OVERRIDES 256

/* what a result records as the build that made it (CMakeLists.txt defines the version for the
   files that write it: regression references, sweep run ids, sweep.h5, `flexmbd --version`; the
   commit comes from the header written at every build, generated/flexmbd_commit.h, which those
   that need it include) */
#ifndef FLEXMBD_VERSION
#define FLEXMBD_VERSION "unknown"
#endif

/* a scene and its --set overrides, as `run`, `check` and the analysis commands take them */
typedef struct fmbCliScene {
  const char* scene;
  const char* overrides[FMB_CLI_MAX_OVERRIDES];
  int nover;
  const char* plugins[16]; /* the --plugin files (the first 16): inputs an output may not replace */
  int nplugins;
} fmbCliScene;

/* a --set value `ov` has the form PATH=VALUE: 0, else FMB_EXIT_BAD_INPUT after saying so in the
   option's terms (`next`, the argument after it or NULL, shows `--set PATH VALUE`, a space for =) */
int fmb_cli_check_set(const char* cmd, const char* ov, const char* next);
/* file:line:col: error: msg (or the shorter forms when no location is known), on stderr or in buf */
void fmb_cli_print_diag(const fmbDiag* d);
void fmb_cli_format_diag(const fmbDiag* d, char* buf, size_t len);
/* `run SCENE --serve`: runs on demand for `sweep --runner serve` (tools/run_serve.c) */
int fmb_run_serve(const fmbCliScene* s);
/* an input file (what: "scene", "reference", ...) exists, is a regular file and can be read;
   else prints "PATH: error: cannot open the WHAT: why" and returns FMB_EXIT_BAD_INPUT */
int fmb_cli_check_input(const char* path, const char* what);
/* Notes the n inputs for the whole command (fmb_cli_inputs: no later write through
   fmb_cli_safe_open may replace one; each model guards its own files, engine/safe_file.c), then
   FMB_EXIT_BAD_INPUT after saying so when `out` is one of the noted inputs (device and inode,
   whatever the names), else 0. "-", non-regular files and files that do not exist are never inputs. */
int fmb_cli_check_output_not_input(const char* out, const char* const* inputs, int n);
/* catch SIGINT/SIGTERM: the flag they set (work stops after the step in progress, keeps what
   it has and exits FMB_EXIT_INTERRUPTED) */
volatile sig_atomic_t* fmb_cli_catch_stop_signals(void);
/* "$TMPDIR/flexmbd-STEM-XXXXXX" (/tmp without TMPDIR) into buf: the template of a temporary file
   (mkstemp) or folder of the command's own */
void fmb_cli_tmp_template(const char* stem, char* buf, size_t len);
/* a new private folder (mkdtemp: 0700, no link followed into it) from that template into dir;
   0, or -1 after saying why ("flexmbd STEM: cannot make a temporary folder ...") */
int fmb_cli_private_folder(const char* stem, char* dir, size_t len);
/* `s` as a gnuplot string that gnuplot never expands (single-quoted; no command substitution);
   -1 and nothing written when s holds a control character (a line break would end the command) */
int fmb_cli_gnuplot_string(FILE* g, const char* s);
/* The library's messages on stderr as the program always printed them (fmb_set_warn, installed by
   main): one line each, except the progress line on a terminal, rewritten in place; a message
   while it is shown clears it first. fmb_cli_warn_end ends a progress line left open, so that the
   stats line comes last on a line of its own. */
void fmb_cli_warn(void* user, const char* message);
void fmb_cli_warn_end(void);
/* the registry every command loads scenes with: the built-ins and the --plugin files */
fmbRegistry* fmb_cli_registry(void);
/* the files this command reads, for the whole process (tools/cli.c): note one (the command's
   scene and --plugin files are noted by fmb_cli_take_scene_arg), every file a loaded model read, and
   open an output through the safe path refusing any of them */
fmbInputs* fmb_cli_inputs(void);
int fmb_cli_note_input(const char* path);
void fmb_cli_note_model(const fmbModel* m);
fmbSafeFile* fmb_cli_safe_open(const char* path, char* err, size_t errlen);

/* `run --models a,b,...`: the scene once per beam model, outputs side by side (tools/run_models.c
   over the library's fmb_run_models), with vtk (or NULL) each model's animation in vtk/MODEL; *stop (SIGINT) ends it after the model in progress, whose
   rows and those of the models before it are written */
int fmb_cli_run_models(const fmbCliScene* s, const char* models, const char* out, int quiet, const char* vtk,
                       int vtk_every, volatile sig_atomic_t* stop);

/* `compare`'s work on parsed options (tools/cmd_compare.c), also `run --reference`'s: one line per
   column on stdout; returns compare's exit code */
typedef struct fmbCliCompare {
  const char *out, *ref; /* the run's CSV and the reference's */
  const char* columns;   /* "a,b,..." or NULL: every column (both files must have the same) */
  const char* tag;       /* appended to every line (run --reference: the run's cost), or NULL */
  double rtol, atol;
  int check;  /* apply rtol/atol: status=ok|beyond, exit 1 beyond */
  int common; /* the columns both files have; a missing or extra one is no failure */
} fmbCliCompare;
int fmb_cli_compare(const fmbCliCompare* c);

/* the commands: each one's options and usage (its fmbCommandSpec, tools/options.h) and its main */
extern const fmbCommandSpec fmb_run_command, fmb_check_command, fmb_types_command, fmb_compare_command,
    fmb_regress_command, fmb_conform_command, fmb_plot_command, fmb_new_command, fmb_static_command, fmb_modes_command,
    fmb_campbell_command, fmb_view_command, fmb_sweep_command, fmb_refine_command;
int fmb_cmd_run(int argc, char** argv);
int fmb_cmd_check(int argc, char** argv);
int fmb_cmd_types(int argc, char** argv);
int fmb_cmd_compare(int argc, char** argv);
int fmb_cmd_regress(int argc, char** argv);
int fmb_cmd_conform(int argc, char** argv);
int fmb_cmd_plot(int argc, char** argv);
int fmb_cmd_new(int argc, char** argv);
int fmb_cmd_static(int argc, char** argv);
int fmb_cmd_modes(int argc, char** argv);
int fmb_cmd_campbell(int argc, char** argv);
int fmb_cmd_view(int argc, char** argv);
int fmb_cmd_sweep(int argc, char** argv);
int fmb_cmd_refine(int argc, char** argv);
/* what the analysis commands (static, modes, campbell) share, in cmd_static.c */
typedef struct fmbCliAnalysis {
  fmbStaticOptions opt; /* --at T, --quiet */
  int method;           /* --eigen dense|sparse|auto */
  int count;            /* --count K */
  int at_given, quiet;
} fmbCliAnalysis;
/* --at T (also sets opt.has_t and at_given) */
int fmb_cli_read_at(const fmbOptContext* ctx, void* at, const char* value);
/* --at T and --quiet/-q of a command whose options hold an fmbCliAnalysis `field` */
#define FMB_CLI_ANALYSIS_ENTRIES(Type, field)                                                                         \
  {"--at",                                                                                                            \
   NULL,                                                                                                              \
   FMB_OPT_CALL,                                                                                                      \
   "T",                                                                                                               \
   offsetof(Type, field),                                                                                             \
   "hold the drives at time T (default: the scene's t0)",                                                             \
   "a finite time in seconds",                                                                                        \
   0,                                                                                                                 \
   0,                                                                                                                 \
   NULL,                                                                                                              \
   fmb_cli_read_at,                                                                                                   \
   0},                                                                                                                \
  {                                                                                                                   \
    "--quiet", "-q", FMB_OPT_FLAG, NULL, offsetof(Type, field.quiet), "no progress messages", NULL, 0, 0, NULL, NULL, \
        0                                                                                                             \
  }
/* --eigen and --count K (1..count_max) of the commands that compute modes */
#define FMB_CLI_EIGEN_ENTRIES(Type, field, count_max, count_needs)                                                    \
  {"--eigen",                                                                                                         \
   NULL,                                                                                                              \
   FMB_OPT_CHOICE,                                                                                                    \
   "dense|sparse|auto",                                                                                               \
   offsetof(Type, field.method),                                                                                      \
   "the eigensolver (auto: sparse for large models)",                                                                 \
   "dense, sparse or auto",                                                                                           \
   0,                                                                                                                 \
   0,                                                                                                                 \
   "auto|dense|sparse",                                                                                               \
   NULL,                                                                                                              \
   0}, /* FMB_EIGEN_* order */                                                                                        \
  {                                                                                                                   \
    "--count", NULL, FMB_OPT_INT, "K", offsetof(Type, field.count), "the number of modes", count_needs, 1, count_max, \
        NULL, NULL, 0                                                                                                 \
  }
/* `campbell`'s options (tools/cmd_campbell.c) and its work on them (tools/campbell_table.c): argv is
   the command line, which -j children and ranks run again with one speed each */
typedef struct fmbCliCampbell {
  fmbCliScene s; /* first: fmb_opt_scene_positional */
  fmbCliAnalysis an;
  const char *out, *png, *path, *speeds_text;
  const char* modes_out; /* internal: a child of -j or of a rank (its -j is not used) */
  int jobs;
} fmbCliCampbell;
int fmb_cli_campbell(const fmbCliCampbell* a, int argc, char** argv);
/* load the scene (with overrides[0..nover)) and solve its static or steady state: *m, *y, *yp
   are the caller's to free (fmb_free, free) also on failure; returns 0 or an exit code */
int fmb_cli_steady_state(const fmbCliScene* s, int nover, const fmbStaticOptions* opt, fmbModel** m, double** y,
                         double** yp, fmbStaticResult* res, fmbDiag* diag);
void fmb_cli_print_static(const fmbStaticResult* r, int ok, double cpu_s, FILE* f);
/* the modes at many speeds in child processes, `jobs` at once on this process and, with t (farm.h:
   under mpirun/srun), on every rank (tools/modes_pool.c). A child is argv (this program's
   `campbell` command line) with argv[speed_slot] the speed (%.17g) and argv[out_slot] the file
   the modes go to (fmb_cli_modes_save). On rank 0: out[i] for i < *done (the speeds before the
   first that failed, whose code and *diag are returned; 4 when *stop ended it). On the other
   ranks: 0 when rank 0 had no more speeds, *done 0. */
struct fmbFarmTransport;
int fmb_cli_modes_in_children(int jobs, char** argv, int speed_slot, int out_slot, const double* speeds, int n,
                              const struct fmbFarmTransport* t, volatile sig_atomic_t* stop, fmbModes** out, int* done,
                              fmbDiag* diag);
/* a child's answer into path: rc, *diag, then (rc 0) the modes; 0 or -1 */
int fmb_cli_modes_save(const char* path, int rc, const fmbDiag* diag, const fmbModes* modes);
#endif
