/* cli.c — argument handling shared by the command files (tools/cli.h). */
#include "cli.h"

#include <errno.h>
#include <fcntl.h>
#include <pthread.h>
#include <signal.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>
#include <sys/stat.h>
#include <unistd.h>

static fmbRegistry* cli_registry; /* the built-ins, then every --plugin in command-line order */

/* freed at exit, so that memcheck sees no memory still reachable (valgrind_paper.sh counts it) */
static void free_cli_registry(void) {
  fmb_registry_free(cli_registry);
  cli_registry = NULL;
}

/* The files this command reads (its scene, samples, references, --plugin files, and the files of
   every model it loaded: fmb_cli_note_model): no output of the command may replace one. The
   command is the process, so its set may live for the process; the library keeps none (each
   model has its own, engine/safe_file.c). Made before main's threads start (fmb_cli_inputs is
   first called while the arguments are read) and locked inside, so workers may note into it. */
static fmbInputs* cli_inputs;
static void free_cli_inputs(void) {
  fmb_inputs_free(cli_inputs);
  cli_inputs = NULL;
}
static pthread_once_t cli_inputs_once = PTHREAD_ONCE_INIT;
static void make_cli_inputs(void) {
  cli_inputs = fmb_inputs_new();
  if (cli_inputs) atexit(free_cli_inputs);
}
fmbInputs* fmb_cli_inputs(void) {
  pthread_once(&cli_inputs_once, make_cli_inputs);
  return cli_inputs;
}
int fmb_cli_note_input(const char* path) { return fmb_inputs_note(fmb_cli_inputs(), path); }
void fmb_cli_note_model(const fmbModel* m) {
  if (m) fmb_inputs_add(fmb_cli_inputs(), fmb_model_inputs(m));
}
fmbSafeFile* fmb_cli_safe_open(const char* path, char* err, size_t errlen) {
  return fmb_safe_open_guarded(path, fmb_cli_inputs(), err, errlen);
}

fmbRegistry* fmb_cli_registry(void) {
  if (!cli_registry) {
    fmbDiag d;
    cli_registry = fmb_registry_new();
    if (cli_registry) atexit(free_cli_registry);
    if (cli_registry && fmb_registry_add(cli_registry, fmb_builtin_plugin(), "built-in", &d)) {
      fmb_cli_print_diag(&d);
      fmb_registry_free(cli_registry);
      cli_registry = NULL;
    }
  }
  return cli_registry;
}

void fmb_cli_format_diag(const fmbDiag* d, char* buf, size_t len) {
  if (d->line > 0)
    snprintf(buf, len, "%s:%d:%d: error: %s", d->file, d->line, d->col, d->msg);
  else if (d->file[0])
    snprintf(buf, len, "%s: error: %s", d->file, d->msg);
  else
    snprintf(buf, len, "error: %s", d->msg);
}

void fmb_cli_print_diag(const fmbDiag* d) {
  char text[sizeof d->file + sizeof d->msg + 64];
  fmb_cli_format_diag(d, text, sizeof text);
  fprintf(stderr, "%s\n", text);
}

int fmb_cli_check_set(const char* cmd, const char* ov, const char* next) {
  (void)cmd; /* the message has the library's form for a --set (engine/yaml_get.c): the option, then why */
  const char* eq = strchr(ov, '=');
  if (eq && eq > ov) return 0;
  if (!eq && next && next[0] != '-' && strchr(ov, '.') && !strchr(next, '='))
    /* `--set solver.rtol 1e-6`: the value became the next argument */
    fprintf(stderr, "--set: error: %s: expected PATH=VALUE in one argument, not '%s %s' (write --set %s=%s)\n", ov, ov,
            next, ov, next);
  else
    fprintf(stderr, "--set: error: %s: expected PATH=VALUE, e.g. solver.rtol=1e-8\n", ov);
  return FMB_EXIT_BAD_INPUT;
}

int fmb_opt_read_set(const fmbOptContext* ctx, void* at, const char* value) {
  fmbCliScene* s = at;
  if (fmb_cli_check_set(ctx->cmd, value, ctx->next)) return FMB_EXIT_BAD_INPUT;
  if (s->nover == FMB_CLI_MAX_OVERRIDES) {
    fprintf(stderr, "flexmbd %s: more than %d --set overrides\n", ctx->cmd, FMB_CLI_MAX_OVERRIDES);
    return FMB_EXIT_BAD_INPUT;
  }
  s->overrides[s->nover++] = value;
  return 0;
}

int fmb_opt_read_plugin(const fmbOptContext* ctx, void* at, const char* so) {
  (void)ctx;
  fmbCliScene* s = at;
  fmbDiag d;
  fmbRegistry* reg = fmb_cli_registry();
  if (!reg) return FMB_EXIT_BAD_INPUT;
  if (fmb_registry_load(reg, so, &d)) {
    fmb_cli_print_diag(&d);
    return FMB_EXIT_BAD_INPUT;
  }
  fmb_cli_note_input(so); /* its code runs in this process: no output may replace the file */
  if (s->nplugins < (int)(sizeof s->plugins / sizeof s->plugins[0])) s->plugins[s->nplugins++] = so;
  return 0;
}

int fmb_opt_scene_positional(const fmbOptContext* ctx, const char* arg) {
  fmbCliScene* s = ctx->self; /* the command's options begin with their fmbCliScene */
  if (s->scene) {
    fprintf(stderr, "flexmbd %s: one scene file at a time (got '%s' and '%s')\n", ctx->cmd, s->scene, arg);
    return FMB_EXIT_BAD_INPUT;
  }
  s->scene = arg;
  fmb_cli_note_input(arg); /* no output of this command may replace it (fmb_cli_inputs) */
  return 0;
}

int fmb_cli_check_input(const char* path, const char* what) {
  /* O_NONBLOCK: opening a FIFO must not wait for a writer; the type is checked on the open file */
  int fd = open(path, O_RDONLY | O_NONBLOCK | O_NOCTTY | O_CLOEXEC);
  struct stat st;
  const char* why = NULL;
  if (fd < 0)
    why = strerror(errno);
  else if (fstat(fd, &st) != 0)
    why = strerror(errno);
  else if (S_ISDIR(st.st_mode))
    why = "it is a directory, expected a file";
  else if (!S_ISREG(st.st_mode))
    why = "it is not a regular file (a device, FIFO or socket would be read without end)";
  if (fd >= 0) close(fd);
  if (!why) return 0;
  fprintf(stderr, "%s: error: cannot open the %s: %s\n", path, what, why);
  return FMB_EXIT_BAD_INPUT;
}

int fmb_cli_check_output_not_input(const char* out, const char* const* inputs, int n) {
  /* the inputs are noted for the whole command, so every later write (fmb_cli_safe_open) is
     checked against them too, besides the scene, --plugin files and loaded models' files */
  for (int i = 0; i < n; ++i)
    if (inputs[i]) fmb_cli_note_input(inputs[i]);
  char input[512];
  if (!fmb_inputs_at(fmb_cli_inputs(), out, input, sizeof input)) return 0;
  fprintf(stderr, "%s: error: the output file is the input '%s': refusing to overwrite it\n", out, input);
  return FMB_EXIT_BAD_INPUT;
}

/* SIGINT/SIGTERM end the work after the step (or speed, or model) in progress: what is done so
   far is kept and the exit code is FMB_EXIT_INTERRUPTED. One-shot (SA_RESETHAND): a second signal
   ends the program at once. */
static volatile sig_atomic_t stop_requested;
static void on_stop_signal(int sig) {
  (void)sig;
  stop_requested = 1;
}
void fmb_cli_tmp_template(const char* stem, char* buf, size_t len) {
  const char* tmp = getenv("TMPDIR");
  snprintf(buf, len, "%s/flexmbd-%s-XXXXXX", tmp && *tmp ? tmp : "/tmp", stem);
}

int fmb_cli_private_folder(const char* stem, char* dir, size_t len) {
  fmb_cli_tmp_template(stem, dir, len);
  if (mkdtemp(dir)) return 0;
  fprintf(stderr, "flexmbd %s: cannot make a temporary folder %s: %s\n", stem, dir, strerror(errno));
  return -1;
}

volatile sig_atomic_t* fmb_cli_catch_stop_signals(void) {
  struct sigaction sa;
  memset(&sa, 0, sizeof sa);
  sa.sa_handler = on_stop_signal;
  sa.sa_flags = SA_RESETHAND | SA_RESTART;
  sigemptyset(&sa.sa_mask);
  sigaction(SIGINT, &sa, NULL);
  sigaction(SIGTERM, &sa, NULL);
  return &stop_requested;
}

int fmb_cli_gnuplot_string(FILE* g, const char* s) {
  /* single quotes: gnuplot expands `backquotes` (runs a shell command) inside double quotes and
     on the command line, never inside single quotes, where '' is a quote; a line break would end
     the command, so a string with a control character is refused instead */
  for (const char* c = s; *c; ++c)
    if ((unsigned char)*c < 0x20 || *c == 0x7f) return -1;
  fputc('\'', g);
  for (; *s; ++s) {
    if (*s == '\'') fputc('\'', g);
    fputc(*s, g);
  }
  fputc('\'', g);
  return 0;
}

/* 1 while a progress line is on a terminal without its newline */
static int progress_open;

void fmb_cli_warn(void* user, const char* message) {
  (void)user;
  const int tty = isatty(STDERR_FILENO);
  if (tty && strncmp(message, "progress: ", 10) == 0) {
    fprintf(stderr, "\r%s\033[K", message);
    progress_open = 1;
  } else {
    /* over the progress line (redrawn at its next update) */
    fprintf(stderr, "%s%s\n", tty && progress_open ? "\r\033[K" : "", message);
    progress_open = 0;
  }
  fflush(stderr);
}

void fmb_cli_warn_end(void) {
  if (progress_open) fputc('\n', stderr);
  progress_open = 0;
}
