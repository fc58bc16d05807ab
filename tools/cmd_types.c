/* cmd_types.c — `flexmbd types [--plugin x.so]...`: every registered body and joint type, where
 * it came from, its keys (unit, default, range) as the type declares them (fmbParam), and its
 * outputs. */
#include <stdio.h>
#include <string.h>

#include "cli.h"

static void print_range(const fmbParam* p) {
  if (p->kind == FMB_PARAM_INT) printf(" %ld..%ld", p->lo, p->hi);
  if (p->flags & FMB_POSITIVE) printf(" > 0");
  if (p->flags & FMB_NONNEGATIVE) printf(" >= 0");
  if (p->kind == FMB_PARAM_CHOICE && p->choices) {
    printf(" one of");
    for (const char* const* c = p->choices; *c; ++c) printf("%s%s", c == p->choices ? " " : "|", *c);
  }
  if (p->kind == FMB_PARAM_BODY) printf(" a body name (or ground)");
  if (p->kind == FMB_PARAM_JOINT) printf(" a joint named earlier");
  if (p->kind == FMB_PARAM_TABLE) printf(" [[t, value], ...] or a CSV file");
}

static void print_params(const fmbParam* params) {
  if (!params) {
    printf("    keys: (not declared)\n");
    return;
  }
  for (const fmbParam* p = params; p->key; ++p) {
    printf("    %-18s", p->key);
    if (p->kind == FMB_PARAM_VEC2) printf(" [x, y]");
    if (p->unit) printf(" %s", strcmp(p->unit, "1") == 0 ? "(count)" : p->unit);
    print_range(p);
    if (p->flags & FMB_REQUIRED)
      printf(", required");
    else if (p->fallback)
      printf(", default %s", p->fallback);
    if (p->doc) printf(" -- %s", p->doc);
    printf("\n");
  }
}

static void print_outputs(const char* engine_given, const char* const* own) {
  printf("    outputs: %s", engine_given);
  for (; own && *own; ++own) printf(" %s", *own);
  printf("\n");
}

int fmb_cmd_types(int argc, char** argv) {
  fmbCliScene s;
  memset(&s, 0, sizeof s);
  for (int i = 2; i < argc; ++i) {
    int r = fmb_cli_take_scene_arg("types", argc, argv, &i, &s);
    if (r != 1 || s.scene || s.nover) {
      fprintf(stderr, "flexmbd types: unexpected argument '%s' (only --plugin x.so)\n", argv[i]);
      return FMB_EXIT_BAD_INPUT;
    }
  }
  const fmbRegistry* reg = fmb_cli_registry();
  if (!reg) return FMB_EXIT_BAD_INPUT;
  printf("bodies (the frame outputs come with every body that has coordinates):\n");
  for (int i = 0; i < fmb_registry_nbodies(reg); ++i) {
    const fmbBodyType* t = fmb_registry_body(reg, i);
    printf("  %s  (%s)\n", t->name, fmb_registry_body_origin(reg, i));
    print_params(t->params);
    print_outputs("[x y theta omega vx vy]", t->output_names);
  }
  printf("joints and forces (power comes with every joint that has constraint rows):\n");
  for (int i = 0; i < fmb_registry_njoints(reg); ++i) {
    const fmbJointType* t = fmb_registry_joint(reg, i);
    printf("  %s  (%s)%s\n", t->name, fmb_registry_joint_origin(reg, i),
           t->flags & FMB_TYPE_DOES_WORK ? ", feeds energy in" : "");
    print_params(t->params);
    print_outputs(t->nrows ? "[power]" : "", t->output_names);
  }
  return 0;
}
