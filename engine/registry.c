/* registry.c — the types a loader knows: a growable list of body and joint type tables, each
 * with the file it came from. Every type enters through fmb_registry_add, the built-ins
 * included (builtin/builtin.c hands in a descriptor like any plugin): one door, one set of checks.
 * The registry holds pointers only; the tables live in the library or in a loaded plugin, which
 * is never unloaded (engine/plugin.c). */
#include <stddef.h>
#include <stdlib.h>
#include <string.h>

#include "internal.h"

fmbRegistry* fmb_registry_new(void) {
  fmbRegistry* reg = calloc(1, sizeof *reg);
  if (!reg) return NULL;
  reg->body_names = calloc(1, sizeof *reg->body_names);
  reg->joint_names = calloc(1, sizeof *reg->joint_names);
  if (!reg->body_names || !reg->joint_names) {
    fmb_registry_free(reg);
    return NULL;
  }
  return reg;
}

void fmb_registry_free(fmbRegistry* reg) {
  if (!reg) return;
  for (int i = 0; i < reg->nbodies; ++i) free(reg->body_origin[i]);
  for (int i = 0; i < reg->njoints; ++i) free(reg->joint_origin[i]);
  free(reg->bodies);
  free(reg->joints);
  free(reg->body_names);
  free(reg->joint_names);
  free(reg->body_origin);
  free(reg->joint_origin);
  free(reg);
}

/* a NULL registry has no types (issue 12: no public function crashes on NULL) */
int fmb_registry_nbodies(const fmbRegistry* reg) { return reg ? reg->nbodies : 0; }
int fmb_registry_njoints(const fmbRegistry* reg) { return reg ? reg->njoints : 0; }
const fmbBodyType* fmb_registry_body(const fmbRegistry* reg, int i) {
  return reg && i >= 0 && i < reg->nbodies ? reg->bodies[i] : NULL;
}
const fmbJointType* fmb_registry_joint(const fmbRegistry* reg, int i) {
  return reg && i >= 0 && i < reg->njoints ? reg->joints[i] : NULL;
}
const char* fmb_registry_body_origin(const fmbRegistry* reg, int i) {
  return reg && i >= 0 && i < reg->nbodies ? reg->body_origin[i] : NULL;
}
const char* fmb_registry_joint_origin(const fmbRegistry* reg, int i) {
  return reg && i >= 0 && i < reg->njoints ? reg->joint_origin[i] : NULL;
}

/* room for one more entry in the four parallel arrays of one kind (names has a NULL sentinel) */
static int grow(int n, int* cap, const void*** types, const char*** names, char*** origins) {
  if (n + 1 < *cap) return 0;
  const int nc = *cap ? 2 * *cap : 16;
  const void** t = realloc(*types, (size_t)nc * sizeof *t);
  if (t) *types = t;
  const char** nm = realloc(*names, (size_t)(nc + 1) * sizeof *nm);
  if (nm) *names = nm;
  char** o = realloc(*origins, (size_t)nc * sizeof *o);
  if (o) *origins = o;
  if (!t || !nm || !o) return -1;
  *cap = nc;
  return 0;
}

/* NULL when a type named `name` may be added (absent, or the very same table: *same = 1) */
static const char* taken_by(const fmbRegistry* reg, int joints, const char* name, const void* table, int* same) {
  const int n = joints ? reg->njoints : reg->nbodies;
  for (int i = 0; i < n; ++i) {
    const void* t = joints ? (const void*)reg->joints[i] : (const void*)reg->bodies[i];
    const char* nm = joints ? reg->joints[i]->name : reg->bodies[i]->name;
    if (strcmp(nm, name) != 0) continue;
    if (t == table) {
      *same = 1;
      return NULL;
    }
    return joints ? reg->joint_origin[i] : reg->body_origin[i];
  }
  return NULL;
}

static int add_one(fmbRegistry* reg, int joints, const void* table, const char* name, const char* origin,
                   fmbDiag* diag) {
  const char* kind = joints ? "joint" : "body";
  int same = 0;
  const char* other = taken_by(reg, joints, name, table, &same);
  if (other) {
    fmb_diag_set(diag, FMB_EXIT_BAD_INPUT, origin, 0, 0, "%s type '%s' is already registered (from %s)", kind, name,
                 other);
    return -1;
  }
  if (same) return 0;
  int* n = joints ? &reg->njoints : &reg->nbodies;
  char* o = strdup(origin);
  if (!o || grow(*n, joints ? &reg->cap_joints : &reg->cap_bodies,
                 joints ? (const void***)&reg->joints : (const void***)&reg->bodies,
                 joints ? &reg->joint_names : &reg->body_names, joints ? &reg->joint_origin : &reg->body_origin)) {
    free(o);
    fmb_diag_set(diag, FMB_EXIT_BAD_INPUT, origin, 0, 0, "out of memory registering %s type '%s'", kind, name);
    return -1;
  }
  if (joints) {
    reg->joints[*n] = table;
    reg->joint_names[*n] = name;
    reg->joint_origin[*n] = o;
    reg->joint_names[*n + 1] = NULL;
  } else {
    reg->bodies[*n] = table;
    reg->body_names[*n] = name;
    reg->body_origin[*n] = o;
    reg->body_names[*n + 1] = NULL;
  }
  ++*n;
  return 0;
}

unsigned fmb_type_dimensions(int abi, unsigned dimensions) {
  /* a field of ABI 3.3: a table of an older minor ends before it and is planar */
  return abi >= FMB_PLUGIN_ABI_MAJOR * 1000 + 3 && dimensions ? dimensions : FMB_DIM_PLANAR;
}

/* the first required op a table lacks, or NULL */
static const char* missing_body_op(const fmbBodyType* t) {
  if (!t->parse) return "parse";
  if (!t->destroy) return "destroy";
  if (!t->ncoord) return "ncoord";
  if (!t->initial) return "initial";
  if (!t->residual) return "residual";
  /* a spatial-only type (ABI 3.3) answers marker3 instead of the planar marker */
  const unsigned dims = fmb_type_dimensions(t->abi, t->dimensions);
  if ((dims & FMB_DIM_SPATIAL) && !t->marker3) return "marker3 (the type declares FMB_DIM_SPATIAL)";
  if ((dims & FMB_DIM_PLANAR) && !t->marker) return "marker";
  if ((t->output_lookup || t->output_names) && !t->output) return "output (output_names or output_lookup is set)";
  return NULL;
}

static const char* missing_joint_op(const fmbJointType* t) {
  if (!t->parse) return "parse";
  if (!t->destroy) return "destroy";
  if (!t->bodies) return "bodies";
  if (t->nrows && !t->constraint) return "constraint (nrows is set)";
  if (!t->nrows && !t->force) return "force (a joint without nrows must be a force element)";
  if ((t->output_lookup || t->output_names) && !t->output) return "output (output_names or output_lookup is set)";
  return NULL;
}

/* output_units, when a table declares them, pair with output_names one for one (a shorter list
   would make fmb_output_unit_in read past its end) */
static int units_match_names(const char* const* names, const char* const* units) {
  if (!units) return 1;
  int n = 0, u = 0;
  while (names && names[n]) ++n;
  while (units[u]) ++u;
  return n == u;
}

/* a type name is a YAML word: letters, digits, '_' */
static int valid_name(const char* name) {
  if (!name || !name[0]) return 0;
  for (const char* c = name; *c; ++c)
    if (!((*c >= 'a' && *c <= 'z') || (*c >= 'A' && *c <= 'Z') || (*c >= '0' && *c <= '9') || *c == '_')) return 0;
  return 1;
}

/* The plugin ABI rule (flexmbd_plugin.h): `abi` is major * 1000 + minor, or a bare major below
   1000 (what a 3.0 plugin wrote). Same major and a minor up to ours loads; anything else is refused
   with both numbers. A table's fields are not read before this passes: another layout may not have
   them where this one does. */
static void split_abi(int abi, int* major, int* minor) {
  *major = abi >= 1000 ? abi / 1000 : abi;
  *minor = abi >= 1000 ? abi % 1000 : 0;
}

static int check_abi(const char* origin, const char* what, const char* name, int abi, fmbDiag* diag) {
  int major, minor;
  split_abi(abi, &major, &minor);
  if (major == FMB_PLUGIN_ABI_MAJOR && minor >= 0 && minor <= FMB_PLUGIN_ABI_MINOR) return 0;
  const char* why = major != FMB_PLUGIN_ABI_MAJOR
                        ? "rebuild it against this version's headers"
                        : "it needs a newer flexmbd (or rebuild it against this version's headers)";
  fmb_diag_set(diag, FMB_EXIT_BAD_INPUT, origin, 0, 0,
               "%s%s%s%s was built for flexmbd plugin ABI %d.%d; this flexmbd %s has plugin ABI %d.%d: %s", what,
               name ? " '" : "", name ? name : "", name ? "'" : "", major, minor, fmb_version(), FMB_PLUGIN_ABI_MAJOR,
               FMB_PLUGIN_ABI_MINOR, why);
  return -1;
}

/* the descriptor as this library lays it out: the plugin's `size` bytes of it (a 3.0 descriptor,
   size 0, has every field up to `joints`), the fields a plugin's minor does not have left 0 (NULL:
   absent). 0, or -1 with *diag for a size that cannot be a descriptor of the plugin's minor. */
static int read_descriptor(const fmbPlugin* plugin, const char* origin, fmbPlugin* out, fmbDiag* diag) {
  /* what ABI 3.0 had: int abi, then name at the next pointer boundary (padding where 3.1 has size) */
  struct plugin30 {
    int abi;
    const char* name;
    const char* version;
    const void* bodies;
    const void* joints;
  };
  const size_t size30 = sizeof(struct plugin30);
  size_t size = plugin->size;
  if (size == 0) {
    /* 3.1 put `size` in 3.0's padding; where there was none (ILP32) a 3.0 descriptor has a
       different layout and cannot be read as this one */
    if (offsetof(fmbPlugin, name) != offsetof(struct plugin30, name)) {
      fmb_diag_set(diag, FMB_EXIT_BAD_INPUT, origin, 0, 0,
                   "plugin was built for flexmbd plugin ABI 3.0, whose descriptor this platform cannot read: "
                   "rebuild it against this version's headers");
      return -1;
    }
    size = size30;
  }
  if (size < size30 || size > sizeof(fmbPlugin)) {
    fmb_diag_set(diag, FMB_EXIT_BAD_INPUT, origin, 0, 0,
                 "plugin descriptor says it is %zu bytes; plugin ABI %d.%d's is %zu to %zu: a corrupt descriptor, or "
                 "one built with other headers",
                 size, FMB_PLUGIN_ABI_MAJOR, FMB_PLUGIN_ABI_MINOR, size30, sizeof(fmbPlugin));
    return -1;
  }
  memset(out, 0, sizeof *out);
  memcpy(out, plugin, size);
  out->size = (unsigned)size;
  return 0;
}

int fmb_registry_add(fmbRegistry* reg, const fmbPlugin* plugin, const char* origin, fmbDiag* diag) {
  fmbDiag local_diag;
  if (!diag) diag = &local_diag;
  memset(diag, 0, sizeof *diag);
  if (!reg || !plugin) {
    fmb_diag_set(diag, FMB_EXIT_BAD_INPUT, origin ? origin : "", 0, 0, "fmb_registry_add: %s is NULL",
                 reg ? "the plugin" : "the registry");
    return -1;
  }
  if (!origin) origin = "?";
  /* the descriptor's abi is read before anything else of it (the field never moves), then its
     size, then the rest as far as the plugin has it */
  if (check_abi(origin, "plugin", NULL, plugin->abi, diag)) return -1;
  fmbPlugin desc;
  if (read_descriptor(plugin, origin, &desc, diag)) return -1;
  plugin = &desc;
  /* validate every table before registering any, so a refused plugin leaves the registry as it was */
  for (int k = 0; k < 2; ++k) {
    for (int i = 0; k ? (plugin->joints && plugin->joints[i]) : (plugin->bodies && plugin->bodies[i]); ++i) {
      const char* kind = k ? "joint type" : "body type";
      const int abi = k ? plugin->joints[i]->abi : plugin->bodies[i]->abi;
      const char* name = k ? plugin->joints[i]->name : plugin->bodies[i]->name;
      if (check_abi(origin, kind, NULL, abi, diag)) return -1;
      if (!valid_name(name)) {
        fmb_diag_set(diag, FMB_EXIT_BAD_INPUT, origin, 0, 0,
                     "%s %d of plugin '%s' has no valid name (letters, digits and '_')", kind, i + 1,
                     plugin->name ? plugin->name : "?");
        return -1;
      }
      const char* op = k ? missing_joint_op(plugin->joints[i]) : missing_body_op(plugin->bodies[i]);
      if (op) {
        fmb_diag_set(diag, FMB_EXIT_BAD_INPUT, origin, 0, 0, "%s '%s' has no %s op (required)", kind, name, op);
        return -1;
      }
      if (!(k ? units_match_names(plugin->joints[i]->output_names, plugin->joints[i]->output_units)
              : units_match_names(plugin->bodies[i]->output_names, plugin->bodies[i]->output_units))) {
        fmb_diag_set(diag, FMB_EXIT_BAD_INPUT, origin, 0, 0,
                     "%s '%s' declares output_units that do not pair one for one with its output_names", kind, name);
        return -1;
      }
      for (int e = 0; e < i; ++e)
        if (strcmp(name, k ? plugin->joints[e]->name : plugin->bodies[e]->name) == 0) {
          fmb_diag_set(diag, FMB_EXIT_BAD_INPUT, origin, 0, 0, "%s '%s' is listed twice in the plugin", kind, name);
          return -1;
        }
      int same = 0;
      const char* other =
          taken_by(reg, k, name, k ? (const void*)plugin->joints[i] : (const void*)plugin->bodies[i], &same);
      if (other) {
        fmb_diag_set(diag, FMB_EXIT_BAD_INPUT, origin, 0, 0, "%s '%s' is already registered (from %s)", kind, name,
                     other);
        return -1;
      }
    }
  }
  for (int i = 0; plugin->bodies && plugin->bodies[i]; ++i)
    if (add_one(reg, 0, plugin->bodies[i], plugin->bodies[i]->name, origin, diag)) return -1;
  for (int i = 0; plugin->joints && plugin->joints[i]; ++i)
    if (add_one(reg, 1, plugin->joints[i], plugin->joints[i]->name, origin, diag)) return -1;
  return 0;
}

fmbRegistry* fmb_registry_clone(const fmbRegistry* reg) {
  fmbRegistry* c = fmb_registry_new();
  fmbDiag d;
  for (int i = 0; c && i < reg->nbodies; ++i)
    if (add_one(c, 0, reg->bodies[i], reg->bodies[i]->name, reg->body_origin[i], &d)) {
      fmb_registry_free(c);
      c = NULL;
    }
  for (int i = 0; c && i < reg->njoints; ++i)
    if (add_one(c, 1, reg->joints[i], reg->joints[i]->name, reg->joint_origin[i], &d)) {
      fmb_registry_free(c);
      c = NULL;
    }
  return c;
}
