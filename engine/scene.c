/* scene.c — build an fmbModel from a YAML scene: solver settings, gravity, bodies and joints
 * (through the registry the program hands in), outputs, and the fixed sparsity pattern.
 * The keys are documented in docs/scenes.md. */
#include <math.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>
#include <sys/resource.h>
#include <unistd.h>

#include "integrator.h"
#include "internal.h"
#include "pattern.h"

#define FMB_MAX_ROWS 100000000L /* output rows: beyond this a scene is a typo, not a plan */
#define FMB_RTOL_MIN 1e-13      /* ~500 machine epsilons: below, IDA reports "too much accuracy requested" */
#define FMB_RTOL_MAX 0.1
#define FMB_ATOL_MIN 1e-16
#define FMB_ATOL_MAX 1e-3 /* 1 mm, 1 mrad: looser hides errors as large as a small mechanism */

static const char* const reserved_names[] = {"ground", "energy", "constraint", "t", NULL};

static int name_taken(const fmbModel* m, const char* name) {
  for (int b = 0; b < m->nbody; ++b)
    if (strcmp(m->body[b].name, name) == 0) return 1;
  for (int j = 0; j < m->njoint; ++j)
    if (strcmp(m->joint[j].name, name) == 0) return 1;
  for (int i = 0; reserved_names[i]; ++i)
    if (strcmp(reserved_names[i], name) == 0) return 1;
  return 0;
}

/* solver.atol: a number, or `auto` (as if absent: derived from rtol, engine/tolerance.c), which
   lets `--set solver.atol=auto` compare a scene's own atol with the derived one */
static int get_atol(fmbParser* p, fmbNode node, double* atol, int* is_auto) {
  const fmbNode key = fmb_find_key(p, node, "atol");
  const char* text = fmbp_scalar(p, key);
  *is_auto = text && strcmp(text, "auto") == 0;
  if (*is_auto) return 0;
  char* end = NULL;
  if (text && (strtod(text, &end), end == text || *end != '\0'))
    return fmb_parse_error(p, key, "expected a number or auto for 'atol', got '%s'", text);
  return fmb_get_double(p, node, "atol", FMB_POSITIVE, atol);
}

/* the keys of `solver:`, in the order parse_solver reads them: the one list for its messages */
static const char* const solver_keys[] = {
    "t_end",       "rtol",          "atol",          "output_step",   "max_step",
    "min_step",    "linear_solver", "error_control", "max_steps",     "max_order",
    "formulation", "integrator",    "schur_lu",      "singular_scan", "fault_reduced_setup",
    NULL};

static int parse_solver(fmbParser* p, fmbModel* m, fmbNode node) {
  fmbSolverSettings* s = &m->solver;
  s->t0 = 0.0;
  s->t_end = 0.0;
  s->rtol = 1e-6;
  s->atol = 1e-8;
  s->output_step = 0.0;
  s->max_step = 0.0;
  s->min_step = 0.0;
  s->linear_solver = FMB_LS_KLU;
  s->max_steps_per_output = 100000;
  if (node < 0)
    return fmb_parse_error(p, fmbp_root(p), "missing required key 'solver' (a mapping with at least t_end)");
  if (!fmbp_is_map(p, node)) {
    char keys[400] = "";
    for (size_t i = 0, used = 0; solver_keys[i]; ++i)
      used += (size_t)snprintf(keys + used, sizeof keys - used, "%s%s", i ? ", " : "", solver_keys[i]);
    return fmb_parse_error(p, node, "expected a mapping for 'solver' (keys %s)", keys);
  }
  fmbp_begin_item(p);
  fmbp_expect(p, "solver", solver_keys, NULL, 1);
  static const char* const solvers[] = {"klu", "dense", "klu_full", NULL}; /* order of FMB_LS_* */
  static const char* const controls[] = {"full", "positions", NULL};
  static const char* const formulations[] = {"ggl", "projected", "auto", NULL}; /* order of FMB_FORM_* */
  static const char* const schur_lus[] = {"auto", "klu", "dense", NULL};        /* order of FMB_SCHUR_LU_* */
  static const char* const scans[] = {"off", "auto", NULL};
  /* the GGL backends' names, from the one table of integrators (integrator_select.c), and auto */
  const char* integrators[9];
  const fmbIntegratorOps* integrator_ops[8];
  const int nintegrators = fmb_integrator_choices(integrators, integrator_ops, 8);
  integrators[nintegrators] = "auto";
  integrators[nintegrators + 1] = NULL;
  int formulation = FMB_FORM_AUTO, integrator = nintegrators; /* auto */
  s->positions_only = -1;                                     /* unset: chosen from the bodies */
  int max_steps = 100000, linear_solver = FMB_LS_KLU;
  s->max_order = 0; /* 0 = chosen from the bodies after they are parsed */
  int atol_is_auto = 0, schur_lu = FMB_SCHUR_LU_AUTO, fault_reduced_setup = 0;
  s->singular_scan = 1;
  if (fmb_get_double(p, node, "t_end", FMB_REQUIRED | FMB_POSITIVE, &s->t_end) ||
      fmb_get_double(p, node, "rtol", FMB_POSITIVE, &s->rtol) || get_atol(p, node, &s->atol, &atol_is_auto) ||
      fmb_get_double(p, node, "output_step", FMB_POSITIVE, &s->output_step) ||
      fmb_get_double(p, node, "max_step", FMB_NONNEGATIVE, &s->max_step) ||
      fmb_get_double(p, node, "min_step", FMB_POSITIVE, &s->min_step) ||
      fmb_get_choice(p, node, "linear_solver", 0, solvers, &linear_solver) ||
      fmb_get_choice(p, node, "error_control", 0, controls, &s->positions_only) ||
      fmb_get_int(p, node, "max_steps", 0, 10, 100000000, &max_steps) ||
      fmb_get_int(p, node, "max_order", 0, 1, 5, &s->max_order) ||
      fmb_get_choice(p, node, "formulation", 0, formulations, &formulation) ||
      fmb_get_choice(p, node, "integrator", 0, integrators, &integrator) ||
      fmb_get_choice(p, node, "schur_lu", 0, schur_lus, &schur_lu) ||
      fmb_get_choice(p, node, "singular_scan", 0, scans, &s->singular_scan) ||
      fmb_get_int(p, node, "fault_reduced_setup", 0, 0, 1000000000, &fault_reduced_setup))
    return -1;
  s->schur_lu = schur_lu;
  s->fault_reduced_setup = fault_reduced_setup;
  s->formulation = formulation;
  s->integrator = integrator < nintegrators ? integrator_ops[integrator] : NULL; /* NULL: auto */
  if (fmbp_check_unknown(p, node, "solver")) return -1;
  s->atol_given = !atol_is_auto && fmb_find_key(p, node, "atol") >= 0;
  if (!s->atol_given) s->atol = FMB_ATOL_PER_RTOL * s->rtol; /* a metre of a 1 m body (tolerance.c) */
  s->max_steps_per_output = max_steps;
  s->linear_solver = linear_solver;
  /* Tolerances outside these bounds give a wrong answer with exit 0 (atol = 1 lets a 1 m
     pendulum's error test pass anything) or ask for more than double precision can hold (IDA
     weighs errors by 1/(rtol |y| + atol); 1e-200 makes every step fail). */
  if (s->rtol >= FMB_RTOL_MAX || s->rtol < FMB_RTOL_MIN)
    return fmb_parse_error(p, fmb_find_key(p, node, "rtol"),
                           "expected rtol from %g to below %g (a relative tolerance), got %g", FMB_RTOL_MIN,
                           FMB_RTOL_MAX, s->rtol);
  if (s->atol > FMB_ATOL_MAX || s->atol < FMB_ATOL_MIN)
    return fmb_parse_error(
        p, fmb_find_key(p, node, "atol"),
        "expected atol from %g to %g (an absolute tolerance in SI units: metres, radians, m/s), got %g", FMB_ATOL_MIN,
        FMB_ATOL_MAX, s->atol);
  s->min_step_given = s->min_step > 0.0;
  if (!s->min_step_given) s->min_step = FMB_MIN_STEP_FRACTION * (s->t_end - s->t0);
  if (s->min_step >= s->t_end - s->t0)
    return fmb_parse_error(p, fmb_find_key(p, node, "min_step"),
                           "min_step (%g) must be shorter than the run (t_end %g)", s->min_step, s->t_end);
  if (s->output_step == 0.0) s->output_step = s->t_end / 1000.0;
  if (s->output_step > s->t_end)
    return fmb_parse_error(p, fmb_find_key(p, node, "output_step"), "output_step (%g) is longer than t_end (%g)",
                           s->output_step, s->t_end);
  if (s->t_end / s->output_step > (double)FMB_MAX_ROWS)
    return fmb_parse_error(p, fmb_find_key(p, node, "output_step"),
                           "output_step %g with t_end %g asks for more than %ld rows", s->output_step, s->t_end,
                           FMB_MAX_ROWS);
  return 0;
}

/* `materials:` and `sections:`: mappings of named entries, each a mapping of keys that the
   items naming it (`material: steel`, `section: bar`) take unless they give the key themselves */
static const char* const library_keys[2] = {"materials", "sections"};
/* the keys every body and joint item takes besides its type's own: the list an item's keys are
   accepted from and "expected one of" prints (yaml_get.c), and conform's declared keys */
const char* const fmb_item_keys[] = {"name", "type", "material", "section", NULL};
static const char* const* const reference_keys = fmb_item_keys + 2; /* material, section */

static int check_library(fmbParser* p, fmbNode lib, const char* what) {
  if (lib < 0) return 0;
  yaml_node_t* nd = fmbp_node(p, lib);
  if (!fmbp_is_map(p, lib))
    return fmb_parse_error(
        p, lib, "expected a mapping of named entries for '%s', e.g. {steel: {density: 7850, youngs_modulus: 2.1e11}}",
        what);
  for (yaml_node_pair_t* pr = nd->data.mapping.pairs.start; pr < nd->data.mapping.pairs.top; ++pr)
    if (!fmbp_is_map(p, pr->value))
      return fmb_parse_error(p, pr->value, "expected a mapping of keys for %s entry '%s'", what,
                             fmbp_scalar(p, pr->key));
  return 0;
}

/* the entries an item names: p->inherited[k] (or -1) */
static int resolve_references(fmbParser* p, fmbNode item) {
  fmbNode root = fmbp_root(p);
  for (int k = 0; k < 2; ++k) {
    p->inherited[k] = -1;
    /* looked up here, before the type's keys: kept out of `looked`, so that the type's keys come
       first in "expected one of" (material and section follow from fmb_item_keys) */
    const int looked = p->nlooked;
    fmbNode ref = fmb_find_key(p, item, reference_keys[k]);
    p->nlooked = looked;
    if (ref < 0) continue;
    const char* name = fmbp_scalar(p, ref);
    fmbNode lib = fmb_find_key(p, root, library_keys[k]);
    fmbNode entry = name && lib >= 0 ? fmb_find_key(p, lib, name) : -1;
    p->nlooked = looked;
    if (entry < 0) {
      char list[400] = "";
      size_t used = 0;
      yaml_node_t* nd = fmbp_node(p, lib);
      for (yaml_node_pair_t* pr = nd ? nd->data.mapping.pairs.start : NULL;
           nd && pr < nd->data.mapping.pairs.top && used + 70 < sizeof list; ++pr)
        used += (size_t)snprintf(list + used, sizeof list - used, "%s%s", used ? ", " : "", fmbp_scalar(p, pr->key));
      return fmb_parse_error(p, ref, "no %s named '%s' (defined under '%s' at the top level: %s)", reference_keys[k],
                             name ? name : "?", library_keys[k], used ? list : "none");
    }
    p->inherited[k] = entry;
  }
  return 0;
}

/* every key of a used material or section must have been read by some item that names it */
static int check_library_keys(fmbParser* p, fmbNode lib, const char* what) {
  yaml_node_t* nd = fmbp_node(p, lib);
  if (!nd) return 0;
  for (yaml_node_pair_t* e = nd->data.mapping.pairs.start; e < nd->data.mapping.pairs.top; ++e) {
    if (!(e->key <= p->nnodes_cap && p->known[e->key])) continue; /* never named: nothing to check */
    yaml_node_t* entry = fmbp_node(p, e->value);
    for (yaml_node_pair_t* pr = entry->data.mapping.pairs.start; pr < entry->data.mapping.pairs.top; ++pr)
      if (!(pr->key <= p->nnodes_cap && p->known[pr->key]))
        return fmb_parse_error(p, pr->key, "unknown key '%s' in %s '%s': no body or joint that names it reads that key",
                               fmbp_scalar(p, pr->key), what, fmbp_scalar(p, e->key));
  }
  return 0;
}

/* the FMB_DIM_* of registered type i */
static unsigned registered_dimensions(const fmbRegistry* reg, int joints, int i) {
  return joints ? fmb_type_dimensions(reg->joints[i]->abi, reg->joints[i]->dimensions)
                : fmb_type_dimensions(reg->bodies[i]->abi, reg->bodies[i]->dimensions);
}

/* an item's `type:`, one of the registered types that work in the scene's dimension (they are
   the choices a message lists); a type of the other dimension is refused as such. *t is the
   registry index. */
static int get_type(fmbParser* p, fmbNode item, int joints, const char* const* names, int* t) {
  const char* kind = joints ? "joint" : "body";
  const unsigned need = p->model->dimension == 3 ? FMB_DIM_SPATIAL : FMB_DIM_PLANAR;
  int n = 0;
  while (names[n]) ++n;
  const char** offered = calloc((size_t)n + 1, sizeof *offered);
  int* index = calloc((size_t)n + 1, sizeof *index);
  if (!offered || !index) {
    free(offered), free(index);
    return fmb_parse_error(p, item, "out of memory");
  }
  int k = 0;
  for (int i = 0; i < n; ++i)
    if (registered_dimensions(p->reg, joints, i) & need) offered[k] = names[i], index[k++] = i;
  const fmbNode node = fmb_find_key(p, item, "type");
  const char* given = fmbp_scalar(p, node);
  int other = -1; /* a registered type of the other dimension, named as given */
  for (int i = 0; given && i < n; ++i)
    if (strcmp(names[i], given) == 0 && !(registered_dimensions(p->reg, joints, i) & need)) other = i;
  int choice = 0, rc = 0;
  if (other >= 0)
    rc = fmb_parse_error(p, node,
                         "%s type '%s' is %s; this scene is %s (the top-level 'dimension: %d'%s): `flexmbd types` "
                         "lists the types of each dimension",
                         kind, given, need == FMB_DIM_SPATIAL ? "planar" : "spatial (dimension 3)",
                         need == FMB_DIM_SPATIAL ? "spatial" : "planar", p->model->dimension,
                         need == FMB_DIM_SPATIAL ? "" : ", the default");
  else
    rc = fmb_get_choice(p, item, "type", FMB_REQUIRED, offered, &choice);
  if (rc == 0) *t = index[choice];
  free(offered);
  free(index);
  return rc ? -1 : 0;
}

/* What every body and joint item shares: a mapping with a fresh name and a registered type, read
   by its plugin with no key left unread. On success *self belongs to the caller; on error
   nothing is left allocated. */
static int parse_item(fmbParser* p, const fmbModel* m, fmbNode item, int joints, const char* const* names,
                      char name[FMB_NAME_MAX], int* t, const fmbBodyType** body_type, void** self) {
  const char* kind = joints ? "joint" : "body";
  *self = NULL;
  if (!fmbp_is_map(p, item)) return fmb_parse_error(p, item, "expected a mapping for a %s (with name and type)", kind);
  fmbp_begin_item(p);
  const char* const* item_keys = fmb_item_keys;
  fmbp_expect(p, kind, item_keys, NULL, 0); /* its type's keys are known once `type` is read */
  if (fmbp_get_name(p, item, "name", name)) return -1;
  if (name_taken(m, name))
    return fmb_parse_error(p, fmb_find_key(p, item, "name"),
                           "duplicate or reserved name '%s': every body and joint needs its own name", name);
  if (get_type(p, item, joints, names, t)) return -1;
  if (resolve_references(p, item)) return -1;
  p->item = item;
  /* a type with implementations behind one name picks this item's (fmbBodyType.variant) */
  const fmbBodyType* bt = joints ? NULL : p->reg->bodies[*t];
  if (bt && bt->variant && !(bt = bt->variant(p, item))) {
    p->item = p->inherited[0] = p->inherited[1] = -1;
    return -1;
  }
  if (body_type) *body_type = bt;
  const char* type_name = joints ? p->reg->joints[*t]->name : bt->name;

  int (*parse)(fmbParser*, fmbNode, void**) = joints ? p->reg->joints[*t]->parse : bt->parse;
  void (*destroy)(void*) = joints ? p->reg->joints[*t]->destroy : bt->destroy;
  char what[FMB_NAME_MAX + 40];
  snprintf(what, sizeof what, "%s '%s' (type %s)", kind, name, type_name);
  const fmbParam* params = joints ? p->reg->joints[*t]->params : bt->params;
  fmbp_expect(p, what, item_keys, params, params != NULL);
  const int failed = parse(p, item, self) || fmbp_check_unknown(p, item, what);
  p->item = p->inherited[0] = p->inherited[1] = -1;
  fmbp_expect(p, NULL, NULL, NULL, 0); /* `what` ends with this function */
  if (failed) {
    if (*self) destroy(*self); /* also a parse that failed after setting *self */
    *self = NULL;
    if (!p->diag->code) fmb_parse_error(p, item, "%s could not be set up", what);
    return -1;
  }
  return 0;
}

static int parse_bodies(fmbParser* p, fmbModel* m, fmbNode list) {
  if (list < 0)
    return fmb_parse_error(p, fmbp_root(p),
                           "missing required key 'bodies' (a list of bodies, each with name and type)");
  if (!fmbp_is_seq(p, list))
    return fmb_parse_error(p, list, "expected a list for 'bodies' (each item a mapping with name and type)");
  int n = fmbp_seq_len(p, list);
  if (n == 0) return fmb_parse_error(p, list, "'bodies' is empty: a scene needs at least one body");
  m->body = calloc((size_t)n + 1, sizeof *m->body);
  if (!m->body) return fmb_parse_error(p, list, "out of memory");
  m->bdf_order_cap = 5;
  /* body 0: the fixed world frame */
  snprintf(m->body[0].name, FMB_NAME_MAX, "ground");
  m->nbody = 1;
  const char* const* names = p->reg->body_names;
  for (int i = 0; i < n; ++i) {
    fmbBodyInst* b = &m->body[m->nbody];
    int t = 0;
    b->node = fmbp_seq_item(p, list, i);
    if (parse_item(p, m, b->node, 0, names, b->name, &t, &b->type, &b->self)) return -1;
    m->nbody++; /* owns self from here on, freed by fmb_free */
    b->qadr = m->nq;
    b->nq = b->type->ncoord(b->self);
    m->nq += b->nq;
    b->workadr = m->nwork;
    b->nwork = b->type->nwork ? b->type->nwork(b->self) : 0;
    m->nwork += b->nwork;
    b->zadr = m->nz;
    b->nz = (b->type->naux && b->type->residual_aux && b->type->aux_initial) ? b->type->naux(b->self) : 0;
    m->nz += b->nz;
    /* a field of ABI 3.2: a table of an older minor ends before it (flexmbd_plugin.h) */
    const int has_aux_iterated = b->type->abi >= FMB_PLUGIN_ABI_MAJOR * 1000 + 2;
    b->aux_iterated = b->nz > 0 && has_aux_iterated && b->type->aux_iterated && b->type->aux_iterated(b->self);
    b->marker3 = b->type->abi >= FMB_PLUGIN_ABI_MAJOR * 1000 + 3 ? b->type->marker3 : NULL; /* ABI 3.3 */
    b->gauge = b->type->abi >= FMB_PLUGIN_ABI_MAJOR * 1000 + 4 ? b->type->gauge : NULL;     /* ABI 3.4 */
    if (b->type->indefinite_mass && b->type->indefinite_mass(b->self)) m->check_definiteness = 1;
    if (b->type->velocity_error_test && !b->type->velocity_error_test(b->self)) m->bodies_prefer_positions = 1;
    if (b->type->reuse_blocks && !b->type->reuse_blocks(b->self)) m->fresh_body_blocks = 1;
    if (b->type->max_bdf_order) {
      const int k = b->type->max_bdf_order(b->self);
      if (k >= 1 && k < m->bdf_order_cap) m->bdf_order_cap = k;
    }
  }
  return 0;
}

static int parse_joints(fmbParser* p, fmbModel* m, fmbNode list) {
  if (list < 0) return 0;
  if (!fmbp_is_seq(p, list))
    return fmb_parse_error(p, list, "expected a list for 'joints' (each item a mapping with name and type)");
  int n = fmbp_seq_len(p, list);
  m->joint = calloc((size_t)n + 1, sizeof *m->joint);
  m->input_joint = calloc((size_t)n + 1, sizeof *m->input_joint);
  m->input_initial = calloc((size_t)n + 1, sizeof *m->input_initial);
  if (!m->joint || !m->input_joint || !m->input_initial) return fmb_parse_error(p, list, "out of memory");
  const char* const* names = p->reg->joint_names;
  for (int i = 0; i < n; ++i) {
    fmbNode item = fmbp_seq_item(p, list, i);
    fmbJointInst* j = &m->joint[m->njoint];
    int t = 0;
    if (parse_item(p, m, item, 1, names, j->name, &t, NULL, &j->self)) return -1;
    j->type = p->reg->joints[t];
    const yaml_node_t* at = fmbp_node(p, item);
    j->line = (int)at->start_mark.line + 1;
    j->col = (int)at->start_mark.column + 1;
    m->njoint++;
    j->type->bodies(j->self, j->body);
    if (j->body[0] == j->body[1])
      return fmb_parse_error(p, item, "joint '%s' connects body '%s' to itself", j->name, m->body[j->body[0]].name);
    j->ncol = 0;
    for (int k = 0; k < 2; ++k)
      if (j->body[k] >= 0) j->ncol += m->body[j->body[k]].nq;
    j->rowadr = m->nc;
    j->nrows = j->type->nrows ? j->type->nrows(j->self) : 0;
    m->nc += j->nrows;
    if (j->ncol > m->max_joint_cols) m->max_joint_cols = j->ncol;
    /* a joint whose value a program sets between steps (fmb_set_input) */
    j->input = -1;
    double initial = 0.0;
    if (j->type->input && j->type->input(j->self, &initial)) {
      m->input_joint[m->ninput] = m->njoint - 1;
      m->input_initial[m->ninput] = initial;
      j->input = m->ninput++;
    }
  }
  return 0;
}

/* What a run of this model will take, estimated from its sizes and fixed pattern at load:
   - memory: the dense per-body blocks of the workspace (K, C, M, FD column: 4 nb^2 for the
     largest body, up to 3 sum nb^2 for the block cache), the initial conditions' dense
     augmented matrix (nq + nc)^2 and Phi_q copies, the mass check (nq^2), a dense Newton
     matrix if asked for (ny^2), and the sparse pattern with KLU's copy and fill (~5 nnz);
   - work per factorization of the Newton matrix: sum over columns of (column nnz)^2, the cost
     of sparse LU without fill: nb^3 for a dense body block, linear for a banded one.
   A model beyond either limit is refused at load with the estimate: the accepted beam of 4096
   elements needed 19.5 GB, and one of 1024 elements could not do one step in 20 s. The memory
   estimate is conservative (measured peak: 88 MB for 256 elements, estimated 182 MB). */
/* measured: a 512-element beam (1.8e10) factorizes in ~1 s, so 5e10 is a few seconds; one of
   1024 elements (1.5e11) could not do a step in 20 s */
#define FMB_WORK_FLOPS_MAX 5e10
static void estimate_resources(const fmbModel* m, double* bytes, double* flops) {
  /* a body with a declared sparse pattern (a banded beam) keeps its blocks in pattern order, and
     its initial conditions are a sparse solve (ic.c): no dense block or augmented matrix */
  double blkmax = 0.0, sum_blk = 0.0;
  int sparse = 0;
  for (int b = 1; b < m->nbody; ++b) {
    const double nb = m->body[b].nq, blk = m->body[b].pnnz >= 0 ? (double)m->body[b].pnnz : nb * nb;
    blkmax = fmax(blkmax, blk);
    sum_blk += blk;
    sparse |= m->body[b].pnnz >= 0;
  }
  const double nq = m->nq, nc = m->nc, ny = m->ny, n = nq + nc;
  double doubles = 4.0 * blkmax + fmin(3.0 * sum_blk, (double)(256 << 20) / 8.0) + (sparse ? 0.0 : n * n) +
                   3.0 * nc * nq + nc * nc + 20.0 * ny + (double)m->nwork;
  if (m->check_definiteness) doubles += nq * nq + nc * nq;
  if (m->solver.linear_solver == FMB_LS_DENSE) doubles += ny * ny;
  *bytes = 8.0 * doubles + 5.0 * 16.0 * (double)m->nnz;
  double w = 0.0;
  for (int j = 0; j < m->ny; ++j) {
    const double c = (double)(m->colptr[j + 1] - m->colptr[j]);
    w += c * c;
  }
  if (m->solver.linear_solver == FMB_LS_DENSE) w = ny * ny * ny / 3.0;
  *flops = w;
}

/* physical memory, or less if the address space is limited (ulimit -v) */
static double memory_available(void) {
  double bytes = (double)sysconf(_SC_PHYS_PAGES) * (double)sysconf(_SC_PAGESIZE);
  struct rlimit rl;
  if (getrlimit(RLIMIT_AS, &rl) == 0 && rl.rlim_cur != RLIM_INFINITY) bytes = fmin(bytes, (double)rl.rlim_cur);
  return bytes > 0 ? bytes : 1e300;
}

static int check_resources(fmbParser* p, fmbModel* m) {
  double bytes = 0.0, flops = 0.0;
  estimate_resources(m, &bytes, &flops);
  const double avail = memory_available();
  if (bytes > 0.8 * avail || flops > FMB_WORK_FLOPS_MAX) {
    /* named at the largest body: the one to make smaller */
    int big = 1;
    for (int b = 2; b < m->nbody; ++b)
      if (m->body[b].nq > m->body[big].nq) big = b;
    return fmb_parse_error(
        p, m->nbody > 1 ? m->body[big].node : fmbp_root(p),
        "the model is too large to run here (largest body '%s', %d coordinates): %d unknowns need an "
        "estimated %.3g GB of memory (this machine offers %.3g GB) and %.3g operations per Newton "
        "matrix factorization (limit %.3g, a few seconds each): use fewer elements or bodies",
        m->body[big].name, m->body[big].nq, m->ny, bytes / 1e9, avail / 1e9, flops, FMB_WORK_FLOPS_MAX);
  }
  return 0;
}

/* the top-level keys, in the order parse_scene reads them (solver and bodies, the required ones,
   first: yaml_get.c's messages rely on it) */
const char* const fmb_scene_keys[] = {"solver",  "bodies", "joints",    "outputs",  "plugins",   "gravity",
                                      "initial", "vtk",    "materials", "sections", "dimension", NULL};

static int parse_scene(fmbParser* p, fmbModel* m) {
  fmbNode root = fmbp_root(p);
  fmbp_begin_item(p);
  fmbp_expect(p, "the scene's top level", fmb_scene_keys, NULL, 1);
  fmbNode solver = fmb_find_key(p, root, "solver");
  fmbNode bodies = fmb_find_key(p, root, "bodies");
  fmbNode joints = fmb_find_key(p, root, "joints");
  fmbNode outputs = fmb_find_key(p, root, "outputs");
  fmbNode plugins = fmb_find_key(p, root, "plugins");
  double g[3] = {0.0, 0.0, 0.0};
  /* initial: given (default) = the poses must satisfy the joints (to FMB_ASSEMBLY_TOL);
     assemble = the initial projection may move the bodies onto the joints (ic.c);
     static = runs start from the static or steady state (engine/static.c) */
  static const char* const initial_modes[] = {"given", "assemble", "static", NULL};
  int initial = 0;
  /* dimension: 2 (planar, the default) or 3 (spatial: docs/spatial.md); read first, since the
     gravity's length and every item's type depend on it */
  m->dimension = 2;
  if (fmb_get_int(p, root, "dimension", 0, 2, 3, &m->dimension)) return -1;
  if ((m->dimension == 3 ? fmb_get_vec3(p, root, "gravity", 0, g) : fmb_get_vec2(p, root, "gravity", 0, g)) ||
      fmb_get_choice(p, root, "initial", 0, initial_modes, &initial))
    return -1;
  m->assemble = initial == 1;
  m->initial_static = initial == 2;
  fmbNode vtk = fmb_find_key(p, root, "vtk"); /* a directory for the ParaView animation (engine/vtk.c) */
  fmbNode library[2] = {fmb_find_key(p, root, library_keys[0]), fmb_find_key(p, root, library_keys[1])};
  if (fmbp_check_unknown(p, root, "the scene's top level")) return -1;
  if (vtk >= 0) {
    const char* dir = fmbp_scalar(p, vtk);
    if (!dir || !*dir || strlen(dir) >= sizeof m->vtk_dir)
      return fmb_parse_error(p, vtk, "expected a directory name for 'vtk' (where the ParaView animation goes)");
    snprintf(m->vtk_dir, sizeof m->vtk_dir, "%s", dir);
  }
  if (m->initial_static && m->dimension == 3)
    return fmb_parse_error(p, fmb_find_key(p, root, "initial"),
                           "'initial: static' is planar for now: a run of a spatial scene (dimension: 3) does not "
                           "start from its static or steady state yet (`flexmbd static` computes it)");
  if (vtk >= 0 && m->dimension == 3)
    return fmb_parse_error(p, vtk,
                           "'vtk' is planar for now: a spatial scene (dimension: 3) has no ParaView output yet");
  if (m->dimension == 2) m->env.gravity[0] = g[0], m->env.gravity[1] = g[1];
  for (int i = 0; i < 3; ++i) m->env.gravity3[i] = g[i];
  m->env.has_gravity = (g[0] != 0.0 || g[1] != 0.0 || g[2] != 0.0);
  for (int k = 0; k < 2; ++k)
    if (check_library(p, library[k], library_keys[k])) return -1;
  if (fmb_scene_plugins(p, plugins) || parse_solver(p, m, solver) || parse_bodies(p, m, bodies) ||
      parse_joints(p, m, joints))
    return -1;
  for (int k = 0; k < 2; ++k)
    if (library[k] >= 0 && check_library_keys(p, library[k], reference_keys[k])) return -1;
  if (m->nq == 0) return fmb_parse_error(p, bodies, "the scene has no moving body (no generalized coordinates)");
  /* more constraint rows than coordinates: redundant (run, ic.c) or contradictory (refused there) */
  m->zoff = 2 * m->nq + 2 * m->nc;
  m->ny = m->zoff + m->nz;
  if (m->solver.max_order == 0) m->solver.max_order = m->bdf_order_cap;
  if (m->solver.positions_only < 0) m->solver.positions_only = m->bodies_prefer_positions;
  if (outputs >= 0) {
    if (fmb_outputs_resolve(p, m, outputs)) return -1;
  } else if (fmb_outputs_default(p, m)) {
    return fmb_parse_error(p, root, "out of memory");
  }
  /* a CSV of times alone says nothing: refused rather than written silently */
  if (m->noutput <= 1)
    return fmb_parse_error(p, outputs >= 0 ? outputs : root,
                           "the run would write only the time column t: %s; list what to write, e.g. "
                           "outputs: [energy.total] (`flexmbd types` lists each type's outputs)",
                           outputs >= 0 ? "'outputs' is empty" : "the scene has no 'outputs' and no body with a frame");
  /* each backend's cross-key rules (e.g. radau5 refuses formulation: projected) */
  if (fmb_integrator_check(m, p, solver)) return -1;
  m->nredundant = fmb_count_redundant(m);
  if (fmb_pattern_build(m)) return fmb_parse_error(p, root, "out of memory building the sparsity pattern");
  return check_resources(p, m);
}

fmbModel* fmb_load(const char* path, const char* const* overrides, int noverrides, const fmbRegistry* reg,
                   fmbDiag* diag) {
  fmbDiag local_diag;
  if (!diag) diag = &local_diag;
  memset(diag, 0, sizeof *diag);
  /* the registry itself is whole: every type entered it through fmb_registry_add's checks */
  const char* misuse = !path ? "fmb_load: no scene path (NULL)"
                       : (noverrides < 0 || (noverrides > 0 && !overrides))
                           ? "fmb_load: overrides NULL or a negative count"
                       : !reg ? "fmb_load: no registry (NULL)"
                              : NULL;
  for (int i = 0; !misuse && i < noverrides; ++i)
    if (!overrides[i]) misuse = "fmb_load: an override is NULL";
  if (misuse) {
    fmb_diag_set(diag, FMB_EXIT_BAD_INPUT, path ? path : "", 0, 0, "%s", misuse);
    return NULL;
  }
  fmbModel* m = calloc(1, sizeof *m);
  if (!m) {
    fmb_diag_set(diag, FMB_EXIT_BAD_INPUT, path, 0, 0, "out of memory");
    return NULL;
  }
  snprintf(m->path, sizeof m->path, "%s", path);
  if (!(m->inputs = fmb_inputs_new())) {
    fmb_diag_set(diag, FMB_EXIT_BAD_INPUT, path, 0, 0, "out of memory");
    free(m);
    return NULL;
  }
  fmbParser p;
  memset(&p, 0, sizeof p);
  p.model = m;
  p.reg = reg;
  int rc = fmbp_open(&p, path, overrides, noverrides, diag);
  if (rc == 0) fmb_inputs_note(m->inputs, path); /* no output of this model's runs may replace it */
  if (rc == 0) rc = parse_scene(&p, m);
  fmbp_close(&p);
  fmb_registry_free(p.own_reg); /* the types stay: their code is never unloaded */
  if (rc) {
    if (!diag->code) fmb_diag_set(diag, FMB_EXIT_BAD_INPUT, path, 0, 0, "invalid scene");
    fmb_free(m);
    return NULL;
  }
  return m;
}

void fmb_free(fmbModel* m) {
  if (!m) return;

  for (int b = 0; b < m->nbody; ++b)
    if (m->body[b].type && m->body[b].self) m->body[b].type->destroy(m->body[b].self);
  for (int j = 0; j < m->njoint; ++j)
    if (m->joint[j].self) m->joint[j].type->destroy(m->joint[j].self);
  fmb_pattern_free(m);
  free(m->body);
  free(m->joint);
  free(m->input_joint);
  free(m->input_initial);
  free(m->output);
  fmb_inputs_free(m->inputs);
  free(m);
}

const fmbInputs* fmb_model_inputs(const fmbModel* m) { return m ? m->inputs : NULL; }

int fmb_model_solver(const fmbModel* m, fmbSolverInfo* out) {
  if (!m || !out) return -1;
  const fmbSolverSettings* s = &m->solver;
  *out = (fmbSolverInfo){s->t0, s->t_end, s->rtol, s->atol, s->output_step};
  return 0;
}

int fmb_scene_dimension(const fmbParser* p) { return p && p->model ? p->model->dimension : 2; }

int fmb_model_nbody(const fmbModel* m) { return m ? m->nbody - 1 : 0; }
int fmb_model_dimension(const fmbModel* m) { return m ? m->dimension : 0; }

int fmb_model_body(const fmbModel* m, int i, const char** name, const char** type) {
  if (!m || i < 0 || i >= m->nbody - 1) return -1;
  if (name) *name = m->body[i + 1].name;
  if (type) *type = m->body[i + 1].type->name;
  return 0;
}

int fmb_model_njoint(const fmbModel* m) { return m ? m->njoint : 0; }

int fmb_model_joint(const fmbModel* m, int i, const char** name, const char** type) {
  if (!m || i < 0 || i >= m->njoint) return -1;
  if (name) *name = m->joint[i].name;
  if (type) *type = m->joint[i].type->name;
  return 0;
}

void fmb_describe(const fmbModel* m, FILE* f) {
  if (!m || !f) return;
  fprintf(f, "scene %s: %d bodies, %d joints, %d coordinates, %d constraint rows, %d unknowns, %ld nonzeros\n", m->path,
          m->nbody - 1, m->njoint, m->nq, m->nc, m->ny, m->nnz);
  fprintf(f, "gravity: %s\n", m->env.has_gravity ? "on" : "off (no gravity terms evaluated)");
  double bytes = 0.0, flops = 0.0;
  estimate_resources(m, &bytes, &flops);
  fprintf(f, "resources: ~%.3g MB of memory, ~%.3g flops per Newton matrix factorization (estimates)\n", bytes / 1e6,
          flops);
  for (int b = 1; b < m->nbody; ++b) {
    const fmbBodyInst* bi = &m->body[b];
    fprintf(f, "body '%s' (%s, %d coordinates)%s", bi->name, bi->type->name, bi->nq, bi->type->describe ? ": " : "\n");
    if (bi->type->describe) bi->type->describe(bi->self, f);
  }
  for (int j = 0; j < m->njoint; ++j) {
    const fmbJointInst* ji = &m->joint[j];
    fprintf(f, "joint '%s' (%s, %d constraint rows)%s", ji->name, ji->type->name, ji->nrows,
            ji->type->describe ? ": " : "\n");
    if (ji->type->describe) ji->type->describe(ji->self, f);
  }
  fprintf(f, "outputs:");
  for (int i = 0; i < m->noutput; ++i) fprintf(f, " %s", m->output[i].name);
  fprintf(f, "\n");
}
