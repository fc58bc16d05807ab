/* cli.c — argument handling shared by the command files (tools/cli.h). */
#include "cli.h"

#include <stdio.h>
#include <string.h>

fmbRegistry* fmb_cli_registry(void) {
  static fmbRegistry* reg; /* the built-ins, then every --plugin in command-line order */
  if (!reg) {
    fmbDiag d;
    reg = fmb_registry_new();
    if (reg && fmb_registry_add(reg, fmb_builtin_plugin(), "built-in", &d)) {
      fmb_cli_print_diag(&d);
      fmb_registry_free(reg);
      reg = NULL;
    }
  }
  return reg;
}

void fmb_cli_print_diag(const fmbDiag* d) {
  if (d->line > 0)
    fprintf(stderr, "%s:%d:%d: error: %s\n", d->file, d->line, d->col, d->msg);
  else if (d->file[0])
    fprintf(stderr, "%s: error: %s\n", d->file, d->msg);
  else
    fprintf(stderr, "error: %s\n", d->msg);
}

const char* fmb_cli_value(const char* cmd, int argc, char** argv, int* i, const char* what) {
  if (*i + 1 >= argc) {
    fprintf(stderr, "flexmbd %s: %s needs %s\n", cmd, argv[*i], what);
    return NULL;
  }
  return argv[++*i];
}

int fmb_cli_take_scene_arg(const char* cmd, int argc, char** argv, int* i, fmbCliScene* s) {
  const char* a = argv[*i];
  const char* ov = NULL;
  if (strcmp(a, "--plugin") == 0 || strncmp(a, "--plugin=", 9) == 0) {
    const char* so = a[8] == '=' ? a + 9 : fmb_cli_value(cmd, argc, argv, i, "a plugin file (x.so)");
    fmbDiag d;
    fmbRegistry* reg = fmb_cli_registry();
    if (!so || !reg) return FMB_EXIT_BAD_INPUT;
    if (fmb_registry_load(reg, so, &d)) {
      fmb_cli_print_diag(&d);
      return FMB_EXIT_BAD_INPUT;
    }
    return 1;
  }
  if (strcmp(a, "--set") == 0) {
    if (!(ov = fmb_cli_value(cmd, argc, argv, i, "PATH=VALUE"))) return FMB_EXIT_BAD_INPUT;
  } else if (strncmp(a, "--set=", 6) == 0) {
    ov = a + 6;
  } else if (a[0] == '-' && a[1] != '\0') {
    return 0; /* an option of the command's own */
  } else if (!s->scene) {
    s->scene = a;
    return 1;
  } else {
    fprintf(stderr, "flexmbd %s: one scene file at a time (got '%s' and '%s')\n", cmd, s->scene, a);
    return FMB_EXIT_BAD_INPUT;
  }
  if (s->nover == FMB_CLI_MAX_OVERRIDES) {
    fprintf(stderr, "flexmbd %s: more than %d --set overrides\n", cmd, FMB_CLI_MAX_OVERRIDES);
    return FMB_EXIT_BAD_INPUT;
  }
  s->overrides[s->nover++] = ov;
  return 1;
}
