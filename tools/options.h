/* options.h — the command line of every command as data: one table of options per command
 * (name, short alias, value, type and range, help, where it is stored) read by one parser
 * (tools/options.c), which also writes the command's usage and --help from the table. The same
 * table therefore decides what a command accepts and what its --help lists
 * (tests/ux/test_cli_options.py checks both by calling every listed option).
 *
 * Messages, the same for every command (exit FMB_EXIT_BAD_INPUT):
 *   flexmbd CMD: unknown option '--x'; did you mean '--y'? (flexmbd CMD --help lists the options)
 *   flexmbd CMD: --opt needs WHAT                  (no value after it)
 *   flexmbd CMD: --opt needs WHAT, got 'V'         (a value of the wrong type or out of range) */
#ifndef FLEXMBD_OPTIONS_H
#define FLEXMBD_OPTIONS_H
#include <stddef.h>
#include <stdio.h>

typedef enum fmbOptType {
  FMB_OPT_FLAG,   /* no value: the int at `at` becomes 1 */
  FMB_OPT_STRING, /* const char*: the argument itself (argv outlives the command) */
  FMB_OPT_INT,    /* int, a whole number in [min, max] */
  FMB_OPT_DOUBLE, /* double, a finite number in [min, max] (FMB_OPT_ABOVE_MIN: > min) */
  FMB_OPT_CHOICE, /* int: the index of the value in `choices` ("a|b|c") */
  FMB_OPT_CALL    /* the command's own reading: call(ctx, at, value) */
} fmbOptType;

enum {
  FMB_OPT_REPEAT = 1,   /* may be given several times (usage shows `...`) */
  FMB_OPT_ABOVE_MIN = 2 /* FMB_OPT_DOUBLE: the value must exceed min */
};

/* what a FMB_OPT_CALL reader is told */
typedef struct fmbOptContext {
  const char* cmd;    /* the command's name, for messages: "flexmbd CMD: ..." */
  const char* option; /* the option's name as the table spells it ("--set") */
  const char* next;   /* the argument after the value, or NULL (for `--set a.b 1` hints) */
  void* self;         /* the command's options */
} fmbOptContext;

typedef struct fmbOpt {
  const char* name;    /* "--output" */
  const char* alias;   /* "-o", or NULL */
  fmbOptType type;     /* how the value is read */
  const char* meta;    /* the value as usage shows it ("OUT.csv"); NULL for a flag */
  size_t at;           /* where it is stored: offsetof(the command's options, field) */
  const char* help;    /* one line for --help */
  const char* needs;   /* what the value must be, for messages ("a finite time in seconds") */
  double min, max;     /* FMB_OPT_INT and FMB_OPT_DOUBLE: the range */
  const char* choices; /* FMB_OPT_CHOICE: "dense|sparse|auto" */
  int (*call)(const fmbOptContext* ctx, void* at, const char* value); /* 0, or an exit code after saying why */
  int flags;                                                          /* FMB_OPT_REPEAT, FMB_OPT_ABOVE_MIN */
} fmbOpt;

/* one command: its arguments, its options and what it does; one per tools/cmd_*.c */
typedef struct fmbCommandSpec {
  const char* name;    /* "run" */
  const char* args;    /* the positional arguments as usage shows them ("SCENE.yaml"), or "" */
  const char* summary; /* one line: what the command does */
  const fmbOpt* opts;
  int nopts;
  /* an argument that is no option (a scene, a file, a type name): 0, or an exit code after saying
     why; NULL: the command takes none */
  int (*positional)(const fmbOptContext* ctx, const char* arg);
  const char* more; /* further lines for --help (other forms, exit codes, the doc), or NULL */
} fmbCommandSpec;

#define FMB_OPT_COUNT(table) ((int)(sizeof(table) / sizeof((table)[0])))

/* Reads argv[2..argc) into self, in order (an option's reader runs when it is met: --plugin is
   loaded before the next argument is read, as before). Returns 1 when the command must return
   *rc at once: after --help/-h (the help on stdout, *rc 0) or a refused argument (the message
   on stderr, *rc FMB_EXIT_BAD_INPUT or the reader's code); 0 to go on. A value option takes the
   next argument (`--at -1` is a value), or the text after `=` (`--output=a.csv`); a short alias
   with a value may hold it (`-j4`). */
int fmb_opt_parse(const fmbCommandSpec* spec, int argc, char** argv, void* self, int* rc);
/* the usage line(s) "flexmbd NAME ARGS [options]" and, with full, the summary, every option with
   its help, and `more` */
void fmb_opt_usage(const fmbCommandSpec* spec, FILE* f, int full);
/* the option named `arg` ("--output", "-o") of spec, or NULL */
const fmbOpt* fmb_opt_find(const fmbCommandSpec* spec, const char* arg);

/* readers every command with a scene shares (tools/cli.c): `at` is the command's fmbCliScene */
int fmb_opt_read_set(const fmbOptContext* ctx, void* at, const char* value);    /* --set PATH=VALUE */
int fmb_opt_read_plugin(const fmbOptContext* ctx, void* at, const char* value); /* --plugin x.so */
/* the scene file of a command whose options begin with an fmbCliScene (one scene) */
int fmb_opt_scene_positional(const fmbOptContext* ctx, const char* arg);

/* --set PATH=VALUE and --plugin x.so of a command whose options hold an fmbCliScene `field` */
#define FMB_OPT_SET(Type, field)                                                                        \
  {                                                                                                     \
    "--set", NULL, FMB_OPT_CALL, "PATH=VALUE", offsetof(Type, field),                                   \
        "override a scene value (solver.rtol=1e-8, bodies.beam.elements=32)", "PATH=VALUE", 0, 0, NULL, \
        fmb_opt_read_set, FMB_OPT_REPEAT                                                                \
  }
#define FMB_OPT_PLUGIN(Type, field)                                                                          \
  {                                                                                                          \
    "--plugin", NULL, FMB_OPT_CALL, "x.so", offsetof(Type, field), "load body or joint types from a plugin", \
        "a plugin file (x.so)", 0, 0, NULL, fmb_opt_read_plugin, FMB_OPT_REPEAT                              \
  }
#define FMB_OPT_SCENE_ENTRIES(Type, field) FMB_OPT_SET(Type, field), FMB_OPT_PLUGIN(Type, field)
#endif
