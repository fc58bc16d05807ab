/* cmd_types.c — `flexmbd types [--plugin x.so]...`: every registered body and joint type, where
 * it came from, its keys (unit, default, range) as the type declares them (fmbParam), and its
 * outputs. */
#include <stddef.h>
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
  if (p->kind == FMB_PARAM_MAP) printf(" {key: value, ...}");
}

static void print_params(const fmbParam* params) {
  if (!params) {
    printf("    keys: (not declared)\n");
    return;
  }
  for (const fmbParam* p = params; p->key; ++p) {
    printf("    %-18s", p->key);
    if (p->kind == FMB_PARAM_VEC2) printf(" [x, y]");
    if (p->kind == FMB_PARAM_VEC3) printf(" [x, y, z]");
    if (p->kind == FMB_PARAM_QUAT) printf(" [w, x, y, z]");
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

/* every output a scene may ask of an item of this type, as NAME.quantity: the engine's groups
   (fmb_engine_outputs, the lists the loader resolves against) that apply, then the type's own */
static void print_outputs(const char* const* const* groups, int ngroups, const char* extra, const char* const* own) {
  printf("    outputs:");
  for (int g = 0; g < ngroups; ++g)
    for (const char* const* n = groups[g]; n && *n; ++n) printf(" %s", *n);
  if (extra) printf(" %s", extra);
  for (; own && *own; ++own) printf(" %s", *own);
  printf("\n");
}

typedef struct {
  fmbCliScene s; /* the --plugin files */
} TypesArgs;

static const fmbOpt types_options[] = {FMB_OPT_PLUGIN(TypesArgs, s)};

const fmbCommandSpec fmb_types_command = {"types",
                                          "",
                                          "the registered body and joint types: keys, units, ranges, outputs",
                                          types_options,
                                          FMB_OPT_COUNT(types_options),
                                          NULL,
                                          NULL};

int fmb_cmd_types(int argc, char** argv) {
  TypesArgs o;
  memset(&o, 0, sizeof o);
  int rc;
  if (fmb_opt_parse(&fmb_types_command, argc, argv, &o, &rc)) return rc;
  const fmbRegistry* reg = fmb_cli_registry();
  if (!reg) return FMB_EXIT_BAD_INPUT;
  const char* const* frame[] = {fmb_engine_outputs("frame")};
  printf("bodies (x y theta omega vx vy: the frame, for every body whose marker places its origin; nodeK_*: "
         "K = 0 .. elements; shape_N: N stations):\n");
  for (int i = 0; i < fmb_registry_nbodies(reg); ++i) {
    const fmbBodyType* t = fmb_registry_body(reg, i);
    const int planar = (fmb_type_dimensions(t->abi, t->dimensions) & FMB_DIM_PLANAR) != 0;
    printf("  %s  (%s)%s\n", t->name, fmb_registry_body_origin(reg, i), planar ? "" : ", dimension 3");
    print_params(t->params);
    print_outputs(frame, planar, t->centreline ? "shape shape_N" : NULL, t->output_names);
  }
  printf("joints and forces (power and work: a joint with constraint rows or a force; reaction_*: with "
         "constraint rows; dimension 3: a type for `dimension: 3` scenes, docs/spatial.md):\n");
  for (int i = 0; i < fmb_registry_njoints(reg); ++i) {
    const fmbJointType* t = fmb_registry_joint(reg, i);
    const unsigned dims = fmb_type_dimensions(t->abi, t->dimensions);
    const int planar = (dims & FMB_DIM_PLANAR) != 0;
    printf("  %s  (%s)%s%s\n", t->name, fmb_registry_joint_origin(reg, i),
           t->flags & FMB_TYPE_DOES_WORK ? ", feeds energy in" : "",
           !planar                    ? ", dimension 3"
           : (dims & FMB_DIM_SPATIAL) ? ", dimensions 2 and 3"
                                      : "");
    print_params(t->params);
    const char* const* engine_given[2];
    int n = 0;
    if (t->nrows || t->force) engine_given[n++] = fmb_engine_outputs("power");
    if (t->nrows) engine_given[n++] = fmb_engine_outputs(planar ? "reaction" : "reaction3");
    print_outputs(engine_given, n, NULL, t->output_names);
  }
  printf("scene-wide:\n    outputs:");
  for (const char* const* n = fmb_engine_outputs("energy"); *n; ++n) printf(" energy.%s", *n);
  for (const char* const* n = fmb_engine_outputs("constraint"); *n; ++n) printf(" constraint.%s", *n);
  printf("\n");
  return 0;
}
