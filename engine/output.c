/* output.c — named outputs and the one CSV writer.
 * Columns are resolved once at load ("BODY.quantity", "JOINT.quantity", "energy.*",
 * "constraint.*"); a row computes only what its columns need (no energy pass unless an energy
 * column is asked for). A run that stops keeps the rows it wrote: into a temporary file they are
 * gathered and written before it is renamed, to stdout or a FIFO each at once (the writer below). */
#include <errno.h>
#include <fcntl.h>
#include <math.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>
#include <sys/stat.h>
#include <unistd.h>

#include "internal.h"

static const char* const frame_names[] = {"x", "y", "theta", "omega", "vx", "vy", NULL};

/* A body with a frame is one whose marker places its origin (local [0, 0]) with an angle: the frame
   outputs x, y, theta are that point and angle, omega, vx, vy their rates. A body with three or
   more coordinates has its frame first, as flexmbd.h's convention says (q = [x, y, theta, ...]:
   read straight from q and v); one with fewer (a point mass, q = [x, y]) has one when its marker
   answers at the origin in the pose the scene gives it, and the frame outputs then come from the
   marker and its derivatives. Only the ground has none (it does not move). */
static int body_has_frame(fmbParser* p, const fmbModel* m, int b) {
  static const double origin[2] = {0.0, 0.0};
  double pos[2], angle;
  if (m->dimension == 3) return 0; /* a spatial body's x, y, z, ... are its own outputs (docs/spatial.md) */
  return m->body[b].nq >= 3 || fmb_initial_marker(p, b, origin, pos, &angle) == 0;
}

/* frame output `id` (index into frame_names) of body b at (q, v) */
static double frame_value(const fmbModel* m, fmbWorkspace* w, int b, int id, const double* q, const double* v) {
  const fmbBodyInst* bi = &m->body[b];
  if (bi->nq >= 3) {
    static const int src[] = {0, 1, 2, 2, 0, 1}; /* x y theta | omega vx vy from v */
    return (id < 3 ? q : v)[bi->qadr + src[id]];
  }
  /* fewer than 3 coordinates: the marker at the origin, its rates by the chain rule (dpos/dq) v */
  static const double origin[2] = {0.0, 0.0};
  double pos[2], angle, dpos[4] = {0, 0, 0, 0}, dangle[2] = {0, 0};
  if (bi->type->marker(bi->self, q + bi->qadr, origin, pos, &angle, dpos, dangle,
                       fmb_workspace_plugin(w) + bi->workadr))
    return NAN;
  const double* vb = v + bi->qadr;
  double rate[3] = {0.0, 0.0, 0.0}; /* omega, vx, vy */
  for (int i = 0; i < bi->nq; ++i) {
    rate[0] += dangle[i] * vb[i];
    rate[1] += dpos[i] * vb[i];
    rate[2] += dpos[bi->nq + i] * vb[i];
  }
  const double value[6] = {pos[0], pos[1], angle, rate[0], rate[1], rate[2]};
  return value[id];
}
static const char* const energy_names[] = {"kinetic", "strain", "gravity", "spring", "total", "balance", NULL};
/* outputs the engine provides for joints: power and work for any joint that constrains or
   applies forces, the reaction for a constraining one */
static const char* const power_names[] = {"power", "work", NULL};
static const char* const reaction_names[] = {"reaction_x", "reaction_y", "reaction_torque", NULL};
/* in space (dimension 3): force and torque about the joint's point, global frame */
static const char* const reaction3_names[] = {
    "reaction_x", "reaction_y", "reaction_z", "reaction_torque_x", "reaction_torque_y", "reaction_torque_z", NULL};
static const char* const constraint_names[] = {"position", "velocity", NULL};
/* in space: the pose of a body's origin (its marker3 at [0, 0, 0]) and its frame as unit Euler
   parameters (w >= 0), for a spatial body whose type gives no such output of its own (rigid3d
   gives its own, from its coordinates); on request also the frame's Euler angles z-y-x, R = Rz(yaw)
   Ry(pitch) Rx(roll), rigid3d's convention. The default columns are the first POSE3_DEFAULT. */
static const char* const pose3_names[] = {"x", "y", "z", "qw", "qx", "qy", "qz", "roll", "pitch", "yaw", NULL};
enum { POSE3_DEFAULT = 7 };
/* the units of the quantities above, in their order (constraint norms mix m and rad: none) */
static const char* const frame_units[] = {"m", "m", "rad", "rad/s", "m/s", "m/s"};
static const char* const power_units[] = {"W", "J"};
static const char* const reaction_units[] = {"N", "N", "N m"};
static const char* const reaction3_units[] = {"N", "N", "N", "N m", "N m", "N m"};

const char* const* fmb_engine_outputs(const char* group) {
  static const struct {
    const char* group;
    const char* const* names;
  } groups[] = {{"frame", frame_names},         {"power", power_names},   {"reaction", reaction_names},
                {"reaction3", reaction3_names}, {"energy", energy_names}, {"constraint", constraint_names}};
  for (size_t i = 0; group && i < sizeof groups / sizeof groups[0]; ++i)
    if (strcmp(group, groups[i].group) == 0) return groups[i].names;
  return NULL;
}

static int lookup(const char* const* names, const char* s) {
  for (int i = 0; names[i]; ++i)
    if (strcmp(names[i], s) == 0) return i;
  return -1;
}

void fmb_write_xml_text(FILE* f, const char* s) {
  if (!f || !s) return;
  for (; *s; ++s) {
    switch (*s) {
      case '&': fputs("&amp;", f); break;
      case '<': fputs("&lt;", f); break;
      case '>': fputs("&gt;", f); break;
      case '"': fputs("&quot;", f); break;
      case '\'': fputs("&apos;", f); break;
      default: /* XML 1.0 has no other control characters */
        if ((unsigned char)*s >= 0x20 || *s == '\n' || *s == '\t') fputc(*s, f);
    }
  }
}

const char* fmb_output_unit(const char* column) {
  if (!column) return NULL;
  if (strcmp(column, "t") == 0) return "s";
  const char* dot = strrchr(column, '.');
  if (!dot) return NULL;
  const char* q = dot + 1;
  const size_t prefix = (size_t)(dot - column);
  if (prefix == 6 && strncmp(column, "energy", 6) == 0) return lookup(energy_names, q) >= 0 ? "J" : NULL;
  if (prefix == 10 && strncmp(column, "constraint", 10) == 0) return NULL;
  int k;
  if ((k = lookup(frame_names, q)) >= 0) return frame_units[k];
  if ((k = lookup(power_names, q)) >= 0) return power_units[k];
  if ((k = lookup(reaction_names, q)) >= 0) return reaction_units[k];
  if ((k = lookup(reaction3_names, q)) >= 0) return reaction3_units[k];
  /* BODY.shapeK_x, BODY.shapeK_y (BODY.shapeK_z in space): a centreline station, global frame */
  if (strncmp(q, "shape", 5) == 0 && (strcmp(q + strlen(q) - 2, "_x") == 0 || strcmp(q + strlen(q) - 2, "_y") == 0 ||
                                      strcmp(q + strlen(q) - 2, "_z") == 0)) {
    const char* d = q + 5;
    while (*d >= '0' && *d <= '9') ++d;
    if (d > q + 5 && d == q + strlen(q) - 2) return "m";
  }
  return NULL; /* a type's own output: its unit is not declared */
}

/* `quantity` with every run of digits after its first letter written as K (node12_v -> nodeK_v):
   how numbered outputs are listed in output_names. 0, or -1 when it does not fit. */
static int numbered_as_k(const char* quantity, char* out, size_t len) {
  size_t o = 0;
  for (const char* c = quantity; *c; ++c) {
    if (o + 2 > len) return -1;
    if (c != quantity && *c >= '0' && *c <= '9') {
      out[o++] = 'K';
      while (c[1] >= '0' && c[1] <= '9') ++c;
    } else {
      out[o++] = *c;
    }
  }
  out[o] = '\0';
  return 0;
}

/* the unit `names`/`units` give `quantity` (or its numbered form), NULL when none; *conflict set
   when it differs from *found */
static void declared_unit(const char* const* names, const char* const* units, const char* quantity, const char* as_k,
                          const char** found, int* conflict) {
  if (!names || !units) return;
  for (int i = 0; names[i]; ++i) {
    if (strcmp(names[i], quantity) != 0 && strcmp(names[i], as_k) != 0) continue;
    if (!units[i]) continue;
    if (*found && strcmp(*found, units[i]) != 0) *conflict = 1;
    *found = units[i];
  }
}

const char* fmb_output_unit_in(const fmbRegistry* reg, const char* column) {
  const char* unit = fmb_output_unit(column);
  if (unit || !reg || !column) return unit;
  const char* dot = strrchr(column, '.');
  if (!dot || !dot[1]) return NULL;
  char as_k[128];
  if (numbered_as_k(dot + 1, as_k, sizeof as_k)) return NULL;
  const char* found = NULL;
  int conflict = 0;
  for (int i = 0; i < fmb_registry_nbodies(reg); ++i) {
    const fmbBodyType* b = fmb_registry_body(reg, i);
    declared_unit(b->output_names, b->output_units, dot + 1, as_k, &found, &conflict);
  }
  for (int i = 0; i < fmb_registry_njoints(reg); ++i) {
    const fmbJointType* j = fmb_registry_joint(reg, i);
    declared_unit(j->output_names, j->output_units, dot + 1, as_k, &found, &conflict);
  }
  return conflict ? NULL : found;
}

int fmb_type_output_id(int (*output_lookup)(const void*, const char*), const void* self, const char* const* names,
                       const char* quantity) {
  if (output_lookup) return output_lookup(self, quantity);
  return names ? lookup(names, quantity) : -1;
}

static void list_names(char* buf, size_t len, const char* const* names) {
  size_t used = strlen(buf);
  for (int i = 0; names && names[i] && used + 30 < len; ++i)
    used += (size_t)snprintf(buf + used, len - used, "%s%s", used ? ", " : "", names[i]);
}

static int resolve_one(fmbParser* p, fmbModel* m, fmbNode node, const char* text, fmbOutput* o) {
  snprintf(o->name, sizeof o->name, "%s", text);
  const char* dot = strchr(text, '.');
  if (!dot || dot == text || !dot[1])
    return fmb_parse_error(p, node, "expected an output name NAME.quantity (e.g. beam.tip_v, energy.total), got '%s'",
                           text);
  char owner[FMB_NAME_MAX];
  size_t len = (size_t)(dot - text);
  if (len >= sizeof owner) return fmb_parse_error(p, node, "no body or joint named '%.*s...'", 20, text);
  memcpy(owner, text, len);
  owner[len] = '\0';
  const char* qty = dot + 1;
  char avail[700] = "";
  const char* none = "none";
  if (strcmp(owner, "energy") == 0) {
    o->kind = FMB_OUT_ENERGY;
    o->id = lookup(energy_names, qty);
    m->need_energy = 1;
    if (o->id == 5) m->need_work = 1; /* balance = energy minus the work done on the system */
    list_names(avail, sizeof avail, energy_names);
  } else if (strcmp(owner, "constraint") == 0) {
    o->kind = FMB_OUT_CONSTRAINT;
    o->id = lookup(constraint_names, qty);
    m->need_constraint = 1;
    list_names(avail, sizeof avail, constraint_names);
  } else {
    int b = -1, j = -1;
    for (int i = 1; i < m->nbody; ++i)
      if (strcmp(m->body[i].name, owner) == 0) b = i;
    for (int i = 0; i < m->njoint; ++i)
      if (strcmp(m->joint[i].name, owner) == 0) j = i;
    if (b < 0 && j < 0)
      return fmb_parse_error(
          p, node, "output '%s': no body or joint named '%s' (outputs are NAME.quantity, energy.*, constraint.*)", text,
          owner);
    o->id = -1;
    if (b >= 0) {
      const fmbBodyInst* bi = &m->body[b];
      o->owner = b;
      const int framed = body_has_frame(p, m, b);
      if (framed && (o->id = lookup(frame_names, qty)) >= 0) {
        o->kind = FMB_OUT_FRAME;
      } else if ((o->id = fmb_type_output_id(bi->type->output_lookup, bi->self, bi->type->output_names, qty)) >= 0) {
        o->kind = FMB_OUT_BODY;
      } else if (m->dimension == 3 && bi->marker3 && (o->id = lookup(pose3_names, qty)) >= 0) {
        o->kind = FMB_OUT_POSE3;
      }
      if (framed) list_names(avail, sizeof avail, frame_names);
      if (m->dimension == 3 && bi->marker3) list_names(avail, sizeof avail, pose3_names);
      none = "none: no frame (its marker cannot place the point [0, 0]) and no outputs of its own";
      list_names(avail, sizeof avail, bi->type->output_names);
    } else {
      const fmbJointInst* ji = &m->joint[j];
      o->owner = j;
      const int has_power = ji->nrows > 0 || ji->type->force;
      if (has_power && (o->id = lookup(power_names, qty)) >= 0) {
        o->kind = o->id == 0 ? FMB_OUT_JOINT_POWER : FMB_OUT_JOINT_WORK;
        if (o->id == 1) m->need_work = 1;
        if (o->id == 0 && ji->nrows > 0) m->need_multipliers = 1;
      } else if (ji->nrows > 0 && (o->id = lookup(m->dimension == 3 ? reaction3_names : reaction_names, qty)) >= 0) {
        o->kind = FMB_OUT_JOINT_REACTION;
        m->need_multipliers = 1;
      } else if ((o->id = fmb_type_output_id(ji->type->output_lookup, ji->self, ji->type->output_names, qty)) >= 0) {
        o->kind = FMB_OUT_JOINT;
      }
      if (has_power) list_names(avail, sizeof avail, power_names);
      if (ji->nrows > 0) list_names(avail, sizeof avail, m->dimension == 3 ? reaction3_names : reaction_names);
      list_names(avail, sizeof avail, ji->type->output_names);
    }
  }
  if (o->id < 0)
    return fmb_parse_error(p, node, "output '%s': unknown quantity '%s' (available: %s)", text, qty,
                           avail[0] ? avail : none);
  return 0;
}

/* `BODY.shape` (the body's own station count) or `BODY.shape_N` (N equally spaced stations): the
   deformed centreline in one output, expanded into the columns BODY.shapeK_x, BODY.shapeK_y,
   K = 0 (root) .. N-1 (tip), global frame. Returns 0 when `text` is not a shape output, 1 when
   expanded, -1 on error. */
#define FMB_SHAPE_STATIONS_MAX 10000
static int resolve_shape(fmbParser* p, fmbModel* m, fmbNode node, const char* text, int* cap) {
  const char* dot = strchr(text, '.');
  if (!dot || strncmp(dot + 1, "shape", 5) != 0 || (dot[6] != '\0' && dot[6] != '_')) return 0;
  int b = -1;
  for (int i = 1; i < m->nbody; ++i)
    if (strlen(m->body[i].name) == (size_t)(dot - text) && strncmp(m->body[i].name, text, (size_t)(dot - text)) == 0)
      b = i;
  if (b < 0) return 0; /* not a body: resolve_one says what is wrong */
  const fmbBodyInst* bi = &m->body[b];
  if (!bi->type->centreline)
    return fmb_parse_error(p, node, "output '%s': a %s body has no centreline (shape is a beam's output)", text,
                           bi->type->name);
  int n = bi->type->centreline(bi->self, 0, NULL);
  const int ncomp = m->dimension == 3 ? 3 : 2; /* x, y (, z in space) per station */
  if (dot[6] == '_') {
    char* end = NULL;
    long v = strtol(dot + 7, &end, 10);
    if (dot[7] < '0' || dot[7] > '9' || *end != '\0' || v < 2 || v > FMB_SHAPE_STATIONS_MAX)
      return fmb_parse_error(p, node, "output '%s': expected shape_N with N stations from 2 to %d (or plain 'shape')",
                             text, FMB_SHAPE_STATIONS_MAX);
    n = (int)v;
  }
  if (m->noutput + ncomp * n > *cap) {
    *cap = m->noutput + ncomp * n + 16;
    fmbOutput* grown = realloc(m->output, (size_t)*cap * sizeof *grown);
    if (!grown) return fmb_parse_error(p, node, "out of memory");
    m->output = grown;
  }
  char first[sizeof m->output[0].name];
  snprintf(first, sizeof first, "%s.shape0_x", bi->name);
  for (int k = 1; k < m->noutput; ++k)
    if (strcmp(m->output[k].name, first) == 0)
      return fmb_parse_error(p, node, "output '%s': %s's shape is listed twice", text, bi->name);
  double* local = malloc(2 * (size_t)n * sizeof *local);
  if (!local) return fmb_parse_error(p, node, "out of memory");
  bi->type->centreline(bi->self, n, local);
  for (int k = 0; k < ncomp * n; ++k) {
    fmbOutput* o = &m->output[m->noutput++];
    memset(o, 0, sizeof *o);
    o->kind = FMB_OUT_SHAPE;
    o->owner = b;
    o->id = k % ncomp;
    o->local[0] = local[2 * (k / ncomp)];
    o->local[1] = local[2 * (k / ncomp) + 1];
    snprintf(o->name, sizeof o->name, "%s.shape%d_%c", bi->name, k / ncomp, "xyz"[k % ncomp]);
  }
  free(local);
  return 1;
}

int fmb_body_point(const fmbModel* m, fmbWorkspace* w, int b, const double* q, const double local[2], double pos[2],
                   double* angle) {
  const fmbBodyInst* bi = &m->body[b];
  if (!bi->type->marker) return -1; /* a spatial-only body */
  return bi->type->marker(bi->self, q + bi->qadr, local, pos, angle, NULL, NULL, fmb_workspace_plugin(w) + bi->workadr);
}

int fmb_body_point3(const fmbModel* m, fmbWorkspace* w, int b, const double* q, const double local[3], double pos[3],
                    double R[9]) {
  const fmbBodyInst* bi = &m->body[b];
  if (!bi->marker3) return -1; /* a planar body */
  return bi->marker3(bi->self, q + bi->qadr, local, pos, R, NULL, NULL, 0, fmb_workspace_plugin(w) + bi->workadr);
}

static double shape_value(const fmbModel* m, fmbWorkspace* w, const fmbOutput* o, const double* q) {
  double pos[3];
  if (m->dimension == 3) { /* the station [x, y] of the body is its point [x, y, 0] */
    const double local[3] = {o->local[0], o->local[1], 0.0};
    double R[9];
    return fmb_body_point3(m, w, o->owner, q, local, pos, R) ? NAN : pos[o->id];
  }
  if (fmb_body_point(m, w, o->owner, q, o->local, pos, NULL)) return NAN;
  return pos[o->id];
}

/* pose output `id` (pose3_names) of a spatial body: its marker3 at the origin */
static double pose3_value(const fmbModel* m, fmbWorkspace* w, int b, int id, const double* q) {
  static const double origin[3] = {0.0, 0.0, 0.0};
  double pos[3], R[9], p[4];
  if (fmb_body_point3(m, w, b, q, origin, pos, R)) return NAN;
  if (id < 3) return pos[id];
  if (id >= POSE3_DEFAULT) { /* roll, pitch, yaw (rigid3d's formula, R row-major) */
    const double euler[3] = {atan2(R[7], R[8]), asin(fmax(-1.0, fmin(1.0, -R[6]))), atan2(R[3], R[0])};
    return euler[id - POSE3_DEFAULT];
  }
  fmb_matrix_quat(R, p);
  return p[id - 3];
}

int fmb_outputs_resolve(fmbParser* p, fmbModel* m, fmbNode list) {
  if (!fmbp_is_seq(p, list))
    return fmb_parse_error(p, list, "expected a list of output names for 'outputs', e.g. [beam.tip_v, energy.total]");
  int n = fmbp_seq_len(p, list);
  int cap = n + 1;
  m->output = calloc((size_t)cap, sizeof *m->output);
  if (!m->output) return fmb_parse_error(p, list, "out of memory");
  m->output[0].kind = FMB_OUT_TIME;
  snprintf(m->output[0].name, sizeof m->output[0].name, "t");
  m->noutput = 1;
  for (int i = 0; i < n; ++i) {
    fmbNode item = fmbp_seq_item(p, list, i);
    const char* s = fmbp_scalar(p, item);
    if (!s) return fmb_parse_error(p, item, "expected an output name NAME.quantity in 'outputs'");
    for (int k = 1; k < m->noutput; ++k)
      if (strcmp(m->output[k].name, s) == 0) return fmb_parse_error(p, item, "output '%s' is listed twice", s);
    const int shape = resolve_shape(p, m, item, s, &cap);
    if (shape < 0) return -1;
    if (shape) continue;
    if (m->noutput == cap) { /* shape columns took the room of the items after them */
      fmbOutput* grown = realloc(m->output, (size_t)++cap * sizeof *grown);
      if (!grown) return fmb_parse_error(p, item, "out of memory");
      m->output = grown;
    }
    if (resolve_one(p, m, item, s, &m->output[m->noutput])) return -1;
    m->noutput++;
  }
  return 0;
}

/* a spatial scene's default columns: each body's position and Euler parameters BODY.x, y, z, qw,
   qx, qy, qz, its type's own where it answers them, else the engine's from marker3 (docs/spatial.md) */
static void outputs_default_spatial(fmbModel* m) {
  const char* const* pose = pose3_names;
  for (int b = 1; b < m->nbody; ++b) {
    const fmbBodyInst* bi = &m->body[b];
    for (int k = 0; k < POSE3_DEFAULT && bi->nq > 0; ++k) {
      const int id = fmb_type_output_id(bi->type->output_lookup, bi->self, bi->type->output_names, pose[k]);
      if (id < 0 && !bi->marker3) continue;
      fmbOutput* o = &m->output[m->noutput++];
      o->kind = id >= 0 ? FMB_OUT_BODY : FMB_OUT_POSE3; /* the type's own, else the engine's from marker3 */
      o->owner = b;
      o->id = id >= 0 ? id : k;
      snprintf(o->name, sizeof o->name, "%s.%s", bi->name, pose[k]);
    }
  }
}

int fmb_outputs_default(fmbParser* p, fmbModel* m) {
  m->output = calloc(1 + 7 * (size_t)m->nbody, sizeof *m->output);
  if (!m->output) return -1;
  m->output[0].kind = FMB_OUT_TIME;
  snprintf(m->output[0].name, sizeof m->output[0].name, "t");
  m->noutput = 1;
  if (m->dimension == 3) {
    outputs_default_spatial(m);
    return 0;
  }
  for (int b = 1; b < m->nbody; ++b) {
    if (m->body[b].nq == 0 || !body_has_frame(p, m, b)) continue; /* a fixed frame's columns are constants */
    for (int k = 0; k < 4; ++k) {
      fmbOutput* o = &m->output[m->noutput++];
      o->kind = FMB_OUT_FRAME;
      o->owner = b;
      o->id = k;
      snprintf(o->name, sizeof o->name, "%s.%s", m->body[b].name, frame_names[k]);
    }
  }
  return 0;
}

/* ------------------------------------------------------------------------------------------ */

/* The writer never deletes, replaces or truncates a file this run did not create: it writes
 * through fmb_safe_open (engine/safe_file.c), and fmb_csv_close puts the rows in place once the
 * run has written its header: a run that stops on bad input before that leaves the target as it
 * was; one that stops later replaces it with the rows it has.
 * Whole rows only: rows are formatted in memory and written with one write loop; if that fails
 * (disk full) the temporary file is cut back to the last complete row. Signals only set a flag
 * (tools/cmd_run.c), so a row is never left half written by SIGINT or SIGTERM.
 * Into a temporary file the rows are gathered up to FMB_CSV_BUFFER bytes per write: nobody sees
 * that file before fmb_csv_close flushes and renames it, so when its bytes reach it changes
 * nothing, and one write() a row was 5 % of the ω0 = 15 spin-up's CPU (2,001 system calls, most
 * of it in the kernel). Written straight through (stdout, a FIFO, a terminal), every row goes out
 * at once as before: a reader may be following it. */
#define FMB_CSV_BUFFER 65536
struct fmbCsv {
  fmbSafeFile* file;
  int fd;
  off_t complete; /* bytes of whole lines written */
  int wrote_header;
  int buffered; /* gather rows (a temporary file) */
  double* row;
  int nrow;
  char* line;     /* formatted rows not yet written (one when not buffered) */
  size_t used;    /* bytes of them */
  size_t cap;     /* of line */
  size_t row_max; /* the most one row can take */
};

/* the bytes of buf written (all len, or fewer when a write failed: errno says why) */
static size_t write_all(int fd, const char* buf, size_t len) {
  size_t done = 0;
  while (done < len) {
    ssize_t k = write(fd, buf + done, len - done);
    if (k < 0 && errno == EINTR) continue;
    if (k <= 0) break;
    done += (size_t)k;
  }
  return done;
}

/* write whole lines, or (temporary file) as many of them as fit: a short write is cut back to
   the end of the last line it completed */
static int write_line(fmbCsv* c, const char* buf, size_t len) {
  const size_t done = write_all(c->fd, buf, len);
  if (done == len) {
    c->complete += (off_t)len;
    return 0;
  }
  const int err = errno;
  size_t whole = done;
  while (whole > 0 && buf[whole - 1] != '\n') --whole;
  c->complete += (off_t)whole;
  if (fmb_safe_is_temporary(c->file) && ftruncate(c->fd, c->complete) == 0) lseek(c->fd, c->complete, SEEK_SET);
  errno = err;
  return -1;
}

/* the gathered rows to the file: 0, or -1 when a write failed (the file then ends in a whole row,
   the rows that did not fit are gone) */
int fmb_csv_flush(fmbCsv* c) {
  if (!c->used) return 0;
  const int rc = write_line(c, c->line, c->used);
  c->used = 0;
  return rc;
}

/* a line formatted at line + used is complete: written now, or when the next one might not fit */
static int csv_line_done(fmbCsv* c, size_t len) {
  c->used += len;
  if (c->buffered && c->used + c->row_max <= c->cap) return 0;
  return fmb_csv_flush(c);
}

fmbCsv* fmb_csv_open(const char* path, fmbDiag* diag) { return fmb_csv_open_guarded(path, NULL, diag); }

fmbCsv* fmb_csv_open_guarded(const char* path, const fmbInputs* inputs, fmbDiag* diag) {
  fmbCsv* c = calloc(1, sizeof *c);
  char err[700];
  if (c) c->file = fmb_safe_open_guarded(path ? path : "-", inputs, err, sizeof err);
  if (!c || !c->file) {
    fmb_diag_set(diag, FMB_EXIT_BAD_INPUT, path, 0, 0, "cannot write the output file: %s", c ? err : "out of memory");
    free(c);
    return NULL;
  }
  c->fd = fmb_safe_fd(c->file);
  c->buffered = fmb_safe_is_temporary(c->file);
  return c;
}

/* a header of named columns; rows of as many values follow (the scene's outputs, or tables
   that are not: modes, Campbell). 0 ok, -1 a write failed or no memory */
int fmb_csv_header_names(fmbCsv* c, int n, const char* const* names) {
  size_t need = 2;
  for (int i = 0; i < n; ++i) need += strlen(names[i]) + 1;
  /* a row: at most 24 characters per %.12g value plus its comma, and the 32 bytes
     fmb_format_g12 may be given for the last one */
  if (need < (size_t)n * 26 + 34) need = (size_t)n * 26 + 34;
  if (fmb_csv_flush(c)) return -1;
  free(c->line);
  free(c->row);
  c->cap = need + (c->buffered ? FMB_CSV_BUFFER : 0);
  c->row_max = need;
  c->line = malloc(c->cap);
  c->row = calloc((size_t)(n > 0 ? n : 1), sizeof(double));
  if (!c->line || !c->row) return -1;
  size_t used = 0;
  for (int i = 0; i < n; ++i) used += (size_t)snprintf(c->line + used, need - used, "%s%s", i ? "," : "", names[i]);
  c->line[used++] = '\n';
  c->nrow = n;
  c->wrote_header = 1;
  return csv_line_done(c, used);
}

int fmb_csv_header(fmbCsv* c, const fmbModel* m) {
  const char** names = malloc((size_t)(m->noutput > 0 ? m->noutput : 1) * sizeof *names);
  if (!names) return -1;
  for (int i = 0; i < m->noutput; ++i) names[i] = m->output[i].name;
  const int rc = fmb_csv_header_names(c, m->noutput, names);
  free(names);
  return rc;
}

/* one whole row of as many values as the header has columns; 0 ok, -1 a write failed */
int fmb_csv_values(fmbCsv* c, const double* values) {
  char* line = c->line + c->used;
  size_t used = 0;
  for (int i = 0; i < c->nrow; ++i) { /* %.12g's bytes (format_g12.c); the line holds 24 + 1 a value */
    if (i) line[used++] = ',';
    used += (size_t)fmb_format_g12(values[i], line + used);
  }
  line[used++] = '\n';
  return csv_line_done(c, used) ? -1 : 0;
}

/* The multipliers the reaction outputs show: consistent with (q, v) at t from the augmented
   system (augmented.c; IDA's own between steps are interpolated outside its error test), or y's
   when that system cannot be solved. Made at the first row that needs them and kept with the
   workspace, which frees it. */
typedef struct {
  fmbAugmented* aug; /* NULL with a body that declared a sparse pattern (a banded beam: the
                        augmented system takes (nq + nc)^2 memory there), where IDA's own are used */
  double* lambda;
} OutputMultipliers;

static void output_multipliers_free(void* p) {
  OutputMultipliers* om = p;
  if (!om) return;
  fmb_augmented_free(om->aug);
  free(om->lambda);
  free(om);
}

static const double* output_multipliers(const fmbModel* m, fmbWorkspace* w, double t, const double* y) {
  void** slot = fmb_workspace_attached(w, output_multipliers_free);
  OutputMultipliers* om = *slot;
  if (!om && (om = calloc(1, sizeof *om)) != NULL) {
    *slot = om;
    if (!fmb_model_has_sparse_body(m)) {
      om->aug = fmb_augmented_new(m);
      om->lambda = calloc((size_t)m->nc + 1, sizeof(double));
    }
  }
  if (!om || !om->aug || !om->lambda) return y + 2 * m->nq;
  int nred = 0;
  fmb_workspace_redundant(w, &nred);
  /* with redundant rows the multipliers are not unique: the minimum-norm ones, the limit of the
     Tikhonov-regularized system as its shift -> 0 */
  if (fmb_augmented_solve(m, w, om->aug, t, y, y + m->nq, NULL, nred ? FMB_MIN_NORM_SHIFT : 0.0, NULL, om->lambda))
    return y + 2 * m->nq;
  return om->lambda;
}

/* the scene's outputs at (t, y) into row[noutput] (every one, also after a value that is not
   finite: fmb_outputs hands them all over); 0 ok, 1 a value is not finite */
int fmb_outputs_eval(const fmbModel* m, fmbWorkspace* w, double t, const double* y, const double* yp, double* row) {
  const double *q = y, *v = y + m->nq;
  int not_finite = 0;
  (void)yp;
  fmbEnergy e = {0, 0, 0, 0};
  double cpos = 0.0, cvel = 0.0;
  if (m->need_energy) fmb_energy(m, w, t, q, v, &e);
  if (m->need_constraint) fmb_constraint_norms(m, w, t, q, v, &cpos, &cvel);
  const double* lam = m->need_multipliers ? output_multipliers(m, w, t, y) : y + 2 * m->nq;
  double* work = fmb_workspace_plugin(w);
  for (int i = 0; i < m->noutput; ++i) {
    const fmbOutput* o = &m->output[i];
    double val = 0.0;
    switch (o->kind) {
      case FMB_OUT_TIME: val = t; break;
      case FMB_OUT_FRAME: val = frame_value(m, w, o->owner, o->id, q, v); break;
      case FMB_OUT_BODY: {
        const fmbBodyInst* b = &m->body[o->owner];
        if (b->type->output(b->self, o->id, q + b->qadr, v + b->qadr, &val, work + b->workadr)) val = NAN;
        break;
      }
      case FMB_OUT_JOINT:
        if (fmb_joint_output(m, w, o->owner, o->id, t, q, v, &val)) val = NAN;
        break;
      case FMB_OUT_JOINT_POWER: val = fmb_joint_power(m, w, o->owner, t, q, v, lam); break;
      case FMB_OUT_JOINT_WORK: val = fmb_workspace_work(w)[o->owner]; break;
      case FMB_OUT_JOINT_REACTION: {
        double r[6];
        if (m->dimension == 3)
          val = fmb_joint_reaction3(m, w, o->owner, t, q, v, lam, r) ? NAN : r[o->id];
        else
          val = fmb_joint_reaction(m, w, o->owner, t, q, v, lam, r) ? NAN : r[o->id];
        break;
      }
      case FMB_OUT_ENERGY: {
        double balance = 0.0;
        if (o->id == 5) { /* T + U - W: the joints' work includes their springs', so their
                             potential enters only through its value at t0 */
          balance = e.kinetic + e.strain + e.gravity + *fmb_workspace_spring_energy0(w);
          for (int j = 0; j < m->njoint; ++j) balance -= fmb_workspace_work(w)[j];
        }
        const double parts[6] = {e.kinetic, e.strain, e.gravity, e.spring, e.kinetic + e.strain + e.gravity + e.spring,
                                 balance};
        val = parts[o->id];
        break;
      }
      case FMB_OUT_CONSTRAINT: val = o->id == 0 ? cpos : cvel; break;
      case FMB_OUT_SHAPE: val = shape_value(m, w, o, q); break;
      case FMB_OUT_POSE3: val = pose3_value(m, w, o->owner, o->id, q); break;
    }
    row[i] = val;
    not_finite |= !isfinite(val);
  }
  return not_finite;
}

/* A body whose state has left the range where its model is accurate (fmbBodyType.model_range)
   is named once per run (warned[b]), at the first time it is seen there: at t0 and after every
   advance (step.c; fmb_run: its output times), and in a state written as a row (modes.c, the
   static state) (issue 23: the complete beam 0.29 m off the exact one at 43 % of L, silently).
   The run goes on: it is the user's call. */
void fmb_warn_model_range(const fmbModel* m, fmbWorkspace* w, double t, const double* y, unsigned char* warned) {
  for (int b = 1; b < m->nbody; ++b) {
    const fmbBodyInst* bi = &m->body[b];
    if (!bi->type->model_range || warned[b]) continue;
    char msg[600];
    if (!bi->type->model_range(bi->self, y + bi->qadr, y + m->nq + bi->qadr, msg, sizeof msg)) continue;
    warned[b] = 1;
    fmb_warn(w, "warning: t = %.6g: body '%s' has left its model's range: %s", t, bi->name, msg);
  }
}

/* 0 ok; 1 a value is not finite (nothing written); -1 a write failed */
int fmb_csv_row(fmbCsv* c, const fmbModel* m, fmbWorkspace* w, double t, const double* y, const double* yp) {
  if (fmb_outputs_eval(m, w, t, y, yp, c->row)) return 1;
  return fmb_csv_values(c, c->row);
}

/* The rows are put in place if the header was written (the run got as far as its first row:
   keep what it has), else the target is left as it was. Returns 0, or -1 with errno when the
   rows could not be put in place. */
int fmb_csv_close(fmbCsv* c) {
  if (!c) return 0;
  const int flushed = fmb_csv_flush(c), err = errno;
  int rc = fmb_safe_close(c->file, c->wrote_header);
  if (flushed && !rc) { /* kept, ending in a whole row, but without the rows the last write lost */
    rc = -1;
    errno = err;
  }
  free(c->line);
  free(c->row);
  free(c);
  return rc;
}
