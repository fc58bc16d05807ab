/* options.c — the one parser of every command's options, and the usage and --help written from
 * the same tables (tools/options.h). */
#include "options.h"

#include <math.h>
#include <stdlib.h>
#include <string.h>

#include "cli.h"

const fmbOpt* fmb_opt_find(const fmbCommandSpec* spec, const char* arg) {
  for (int k = 0; k < spec->nopts; ++k) {
    const fmbOpt* o = &spec->opts[k];
    if (strcmp(arg, o->name) == 0 || (o->alias && strcmp(arg, o->alias) == 0)) return o;
  }
  return NULL;
}

/* the message of a value the option does not take */
static int bad_value(const char* cmd, const char* arg, const fmbOpt* o, const char* v) {
  fprintf(stderr, "flexmbd %s: %s needs %s, got '%s'\n", cmd, arg, o->needs ? o->needs : o->meta, v);
  return FMB_EXIT_BAD_INPUT;
}

/* the value v of option o (typed as `arg`) into self */
static int store(const fmbCommandSpec* spec, const fmbOpt* o, const char* arg, const char* v, const char* next,
                 void* self) {
  void* at = (char*)self + o->at;
  char* end = NULL;
  switch (o->type) {
    case FMB_OPT_FLAG: *(int*)at = 1; return 0;
    case FMB_OPT_STRING: *(const char**)at = v; return 0;
    case FMB_OPT_INT: {
      const double x = strtod(v, &end);
      if (end == v || *end || !(x >= o->min && x <= o->max) || x != floor(x)) return bad_value(spec->name, arg, o, v);
      *(int*)at = (int)x;
      return 0;
    }
    case FMB_OPT_DOUBLE: {
      const double x = strtod(v, &end);
      /* nan and inf parse as numbers: refused like any text that is not one */
      if (end == v || *end || !isfinite(x) || x < o->min || x > o->max ||
          ((o->flags & FMB_OPT_ABOVE_MIN) && x <= o->min))
        return bad_value(spec->name, arg, o, v);
      *(double*)at = x;
      return 0;
    }
    case FMB_OPT_CHOICE: {
      const size_t n = strlen(v);
      int index = 0;
      for (const char* c = o->choices; *c; ++index) {
        const size_t len = strcspn(c, "|");
        if (len == n && strncmp(c, v, n) == 0) {
          *(int*)at = index;
          return 0;
        }
        c += len + (c[len] == '|');
      }
      return bad_value(spec->name, arg, o, v);
    }
    case FMB_OPT_CALL: {
      const fmbOptContext ctx = {spec->name, o->name, next, self};
      return o->call(&ctx, at, v);
    }
  }
  return FMB_EXIT_BAD_INPUT;
}

static int unknown(const fmbCommandSpec* spec, const char* arg) {
  const char* names[256];
  int n = 0;
  for (int k = 0; k < spec->nopts && n < 256; ++k) names[n++] = spec->opts[k].name;
  char typed[128]; /* `--output=x`: the name typed */
  snprintf(typed, sizeof typed, "%.*s", (int)strcspn(arg, "="), arg);
  const char* near = strlen(typed) > 2 ? fmb_nearest_word(typed, names, n) : NULL;
  if (near)
    fprintf(stderr, "flexmbd %s: unknown option '%s'; did you mean '%s'? (flexmbd %s --help lists the options)\n",
            spec->name, arg, near, spec->name);
  else
    fprintf(stderr, "flexmbd %s: unknown option '%s' (flexmbd %s --help lists the options)\n", spec->name, arg,
            spec->name);
  return FMB_EXIT_BAD_INPUT;
}

int fmb_opt_parse(const fmbCommandSpec* spec, int argc, char** argv, void* self, int* rc) {
  *rc = 0;
  for (int i = 2; i < argc; ++i) {
    const char* a = argv[i];
    if (a[0] != '-' || a[1] == '\0') { /* "-" is a file name (stdout, stdin) */
      if (!spec->positional) {
        fprintf(stderr, "flexmbd %s: unexpected argument '%s' (flexmbd %s --help)\n", spec->name, a, spec->name);
        *rc = FMB_EXIT_BAD_INPUT;
        return 1;
      }
      const fmbOptContext ctx = {spec->name, NULL, i + 1 < argc ? argv[i + 1] : NULL, self};
      if ((*rc = spec->positional(&ctx, a)) != 0) return 1;
      continue;
    }
    if (strcmp(a, "--help") == 0 || strcmp(a, "-h") == 0) {
      fmb_opt_usage(spec, stdout, 1);
      return 1;
    }
    const fmbOpt* o = fmb_opt_find(spec, a);
    const char* v = NULL;
    char name[128];
    if (!o && a[1] == '-' && strchr(a, '=')) { /* --name=VALUE */
      snprintf(name, sizeof name, "%.*s", (int)(strchr(a, '=') - a), a);
      o = fmb_opt_find(spec, name);
      if (o && o->type == FMB_OPT_FLAG) {
        fprintf(stderr, "flexmbd %s: %s takes no value (got '%s')\n", spec->name, name, a);
        *rc = FMB_EXIT_BAD_INPUT;
        return 1;
      }
      if (o) v = strchr(a, '=') + 1;
    } else if (!o && a[1] != '-' && a[2]) { /* -j4: a short alias with its value */
      snprintf(name, sizeof name, "%.2s", a);
      o = fmb_opt_find(spec, name);
      if (o && o->type == FMB_OPT_FLAG) o = NULL;
      if (o) v = a + 2;
    }
    if (!o) {
      *rc = unknown(spec, a);
      return 1;
    }
    const char* typed = v ? name : a;
    if (!v && o->type != FMB_OPT_FLAG) {
      if (i + 1 >= argc) {
        fprintf(stderr, "flexmbd %s: %s needs %s\n", spec->name, typed, o->needs ? o->needs : o->meta);
        *rc = FMB_EXIT_BAD_INPUT;
        return 1;
      }
      v = argv[++i];
    }
    if ((*rc = store(spec, o, typed, v, i + 1 < argc ? argv[i + 1] : NULL, self)) != 0) return 1;
  }
  return 0;
}

void fmb_opt_usage(const fmbCommandSpec* spec, FILE* f, int full) {
  fprintf(f, "usage: flexmbd %s%s%s%s\n", spec->name, spec->args[0] ? " " : "", spec->args,
          spec->nopts ? " [options]" : "");
  if (!full) return;
  fprintf(f, "%s\n", spec->summary);
  if (spec->nopts) fprintf(f, "options:\n");
  for (int k = 0; k < spec->nopts; ++k) {
    const fmbOpt* o = &spec->opts[k];
    char left[160];
    snprintf(left, sizeof left, "%s%s%s%s%s%s", o->alias ? o->alias : "", o->alias ? ", " : "    ", o->name,
             o->meta ? " " : "", o->meta ? o->meta : "", o->flags & FMB_OPT_REPEAT ? " ..." : "");
    /* a long left column gets the help on a line of its own */
    if (strlen(left) <= 26)
      fprintf(f, "  %-26s  %s\n", left, o->help);
    else
      fprintf(f, "  %s\n  %-26s  %s\n", left, "", o->help);
  }
  if (spec->more) fprintf(f, "%s", spec->more);
}
