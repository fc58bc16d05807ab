/*
 * flexmbd_plugin.h — the public header for body and joint authors: the type tables (fmbBodyType,
 * fmbJointType), the YAML accessors a type's parse calls, the evaluation helpers, the shared
 * numerics and the plugin descriptor (fmbPlugin) a shared object exports.
 *
 * It includes flexmbd.h, the programs' header: a plugin is built, loaded and tested by a program
 * (its check program embeds the engine: fmb_registry_load, fmb_load, fmb_run), and the two share
 * FMB_API, fmbDiag and the exit codes, so one include serves a plugin and its tests. The reverse
 * does not hold: a program sees the tables only as opaque types.
 */
#ifndef FLEXMBD_PLUGIN_H
#define FLEXMBD_PLUGIN_H

#include "flexmbd.h"

#ifdef __cplusplus
extern "C" {
#endif

/* The plugin ABI: the layout of fmbPlugin, fmbBodyType, fmbJointType, fmbParam and the signatures
   of every function of this header. Its own number, apart from the library's FMB_SOVERSION.
   Rule (engine/registry.c): a plugin built for the same major and an older or equal minor loads;
   a minor only appends fields at the end of a table, and a field a plugin's minor does not have
   reads as NULL / 0 (the descriptor's `size` says how much of it the plugin has). Another major,
   or a newer minor than the library's, is refused with both numbers named.
   History: 1, 2: earlier single numbers (another major: refused). 3.0 (flexmbd 0.1, where it was
   "ABI 3" and also the SOVERSION): the stepping API, the warn callback, inputs (the joints'
   optional `input` op, fmb_eval_input), output_units. 3.1: the descriptor's `size`, in what was
   padding after `abi` on LP64, so that a 3.0 descriptor (and one whose source leaves `size` out)
   reads as size 0: the fields 3.0 had. 3.2: fmbBodyType.aux_iterated, appended; the engine reads
   it only from a table whose `abi` says 3.2 or later (a table of an older minor ends before it).
   3.3: space (docs/spatial.md): fmbBodyType.dimensions and .marker3, fmbJointType.dimensions,
   fmbJointType.attachment3, fmbEnv.gravity3, FMB_PARAM_VEC3/QUAT, appended; fmb_marker3, fmb_get_vec3, fmb_get_quat, fmb_get_point3, fmb_initial_marker3,
   fmb_scene_dimension, fmb_frame3_point. A table of an older minor is planar.
   3.4: fmbBodyType.gauge (the coordinate directions no marker sees: a spatial body's Euler-parameter
   length), appended; read only from a table whose abi says 3.4 or later. */
#define FMB_PLUGIN_ABI_MAJOR 3
#define FMB_PLUGIN_ABI_MINOR 4
/* what a table's and a descriptor's `abi` field holds: major * 1000 + minor (a 3.0 plugin wrote 3:
   a value below 1000 is a major alone, minor 0) */
#define FMB_PLUGIN_ABI (FMB_PLUGIN_ABI_MAJOR * 1000 + FMB_PLUGIN_ABI_MINOR)
/* the name plugins of flexmbd 0.1 write in their tables (`.abi = FMB_ABI_VERSION`): kept so that
   they compile unchanged */
#define FMB_ABI_VERSION FMB_PLUGIN_ABI

/* what a plugin exports: its one entry point, fmb_plugin_descriptor */
#ifdef __cplusplus
#define FMB_PLUGIN_EXPORT extern "C" FMB_API
#else
#define FMB_PLUGIN_EXPORT FMB_API
#endif

/* ---------------------------------------------------------------------------------------------
 * Scene parsing API for plugins (the one YAML accessor layer, engine/yaml_get.c). A NULL parser,
 * key or output pointer makes an accessor return -1 without touching anything.
 * A node is an index into the loaded document. Every accessor records the key as "known" for
 * the unknown-key check, applies the default already in *out when the key is absent and not
 * required, and on error records file:line:column plus what was expected, returning non-zero.
 * ------------------------------------------------------------------------------------------- */
typedef struct fmbParser fmbParser;
typedef int fmbNode;

enum {
  FMB_OPTIONAL = 0,
  FMB_REQUIRED = 1 << 0,
  FMB_POSITIVE = 1 << 1,    /* > 0 */
  FMB_NONNEGATIVE = 1 << 2, /* >= 0 */
  FMB_POSE = 1 << 3         /* fmb_get_angle: an orientation, where |angle| > 2 pi is suspicious */
};

FMB_API int fmb_get_double(fmbParser* p, fmbNode map, const char* key, unsigned flags, double* out);
FMB_API int fmb_get_int(fmbParser* p, fmbNode map, const char* key, unsigned flags, long lo, long hi, int* out);
FMB_API int fmb_get_vec2(fmbParser* p, fmbNode map, const char* key, unsigned flags, double out[2]);
/* ABI 3.3: a list of three numbers [x, y, z] */
FMB_API int fmb_get_vec3(fmbParser* p, fmbNode map, const char* key, unsigned flags, double out[3]);
/* an angle in radians: a bare number is radians, `120 deg` / `2.1 rad` say their unit. With
   FMB_POSE a bare number beyond 2*pi in magnitude draws a warning (degrees written as radians?) */
FMB_API int fmb_get_angle(fmbParser* p, fmbNode map, const char* key, unsigned flags, double* out);
/* a piecewise-linear table: an inline list of [t, value] pairs or the name of a CSV file of
   "t,value" rows (one header line allowed; relative to the scene's folder). t strictly
   increasing, at least two rows. *x and *y are malloc'ed (the caller frees them, also on error). */
FMB_API int fmb_get_table(fmbParser* p, fmbNode map, const char* key, unsigned flags, double** x, double** y, int* n);
/* one of a NULL-terminated list of words; *out is the index */
FMB_API int fmb_get_choice(fmbParser* p, fmbNode map, const char* key, unsigned flags, const char* const* choices,
                           int* out);
/* a point of body `body` in the body's reference frame, [x, y] (default: *out as given); a point
   the body cannot place (its `marker` fails in the pose the scene gives, e.g. beyond a beam's
   length) is refused here, at the point, instead of failing the run later with a false cause */
FMB_API int fmb_get_point(fmbParser* p, fmbNode map, const char* key, unsigned flags, int body, double out[2]);
/* ABI 3.3: Euler parameters [w, x, y, z] (an orientation), normalized; a zero list is refused */
FMB_API int fmb_get_quat(fmbParser* p, fmbNode map, const char* key, unsigned flags, double out[4]);
/* ABI 3.3: fmb_get_point's spatial twin, [x, y, z] in the body's frame, checked with marker3 */
FMB_API int fmb_get_point3(fmbParser* p, fmbNode map, const char* key, unsigned flags, int body, double out[3]);
/* ABI 3.3: the scene's `dimension:` (2, the default, or 3) */
FMB_API int fmb_scene_dimension(const fmbParser* p);
/* a body by name ("ground" is always defined); *out is the body index */
FMB_API int fmb_get_body(fmbParser* p, fmbNode map, const char* key, unsigned flags, int* out);
/* a joint defined earlier in the file, by name; *out is the joint index */
FMB_API int fmb_get_joint(fmbParser* p, fmbNode map, const char* key, unsigned flags, int* out);
/* body index and local point of attachment k (0 or 1) of an already parsed joint with
   constraint rows (a pivot, a weld; not a spring's ends) */
FMB_API int fmb_joint_attachment(fmbParser* p, int joint, int k, int* body, double local[2]);
/* position and angle of material point `local` of body `body` in the pose the scene gives it
   (before any assembly), e.g. for a joint whose default is the configuration as assembled.
   Returns 0, or -1 (bad arguments, or the body cannot place the point). */
FMB_API int fmb_initial_marker(fmbParser* p, int body, const double local[2], double pos[2], double* angle);
/* ABI 3.3: its spatial twin: position and rotation matrix R (3 x 3 row-major, the body frame's
   axes at the point as columns) of material point `local` in the scene's pose (ground: local, I) */
FMB_API int fmb_initial_marker3(fmbParser* p, int body, const double local[3], double pos[3], double R[9]);
/* a plugin-level check failed at `node` (a value node or the item's mapping) */
FMB_API int fmb_parse_error(fmbParser* p, fmbNode node, const char* fmt, ...)
#if defined(__GNUC__)
    __attribute__((format(printf, 3, 4)))
#endif
    ;
/* the value node of `key` in `map`, or -1 if absent (marks the key known) */
FMB_API fmbNode fmb_find_key(fmbParser* p, fmbNode map, const char* key);

/* ---------------------------------------------------------------------------------------------
 * Evaluation environment shared by all plugins.
 * ------------------------------------------------------------------------------------------- */
typedef struct fmbEnv {
  double gravity[2]; /* m/s^2, global frame */
  int has_gravity;   /* 0 when the scene has g = 0: plugins skip gravity terms entirely */
  /* ABI 3.3: gravity in space, global frame; a planar scene's is [gravity[0], gravity[1], 0] */
  double gravity3[3];
} fmbEnv;

typedef struct fmbEnergy {
  double kinetic, strain, gravity, spring;
} fmbEnergy;

/* ---------------------------------------------------------------------------------------------
 * Parameter declarations. A type lists the keys its parse reads, with units, defaults and ranges:
 * `flexmbd types` prints them and `flexmbd conform` generates a bad scene from every range
 * (a value outside it must be refused at its file:line:column naming the key), so a new type
 * never edits the engine's test lists. The list ends with an entry whose key is NULL.
 * ------------------------------------------------------------------------------------------- */
typedef enum {
  FMB_PARAM_NUMBER, /* fmb_get_double; range from flags FMB_POSITIVE / FMB_NONNEGATIVE */
  FMB_PARAM_INT,    /* fmb_get_int; range [lo, hi] */
  FMB_PARAM_VEC2,   /* fmb_get_vec2 */
  FMB_PARAM_CHOICE, /* fmb_get_choice; the words in `choices` */
  FMB_PARAM_BODY,   /* fmb_get_body */
  FMB_PARAM_JOINT,  /* fmb_get_joint */
  FMB_PARAM_TABLE,  /* fmb_get_table: [[t, value], ...] or a CSV file name */
  FMB_PARAM_MAP,    /* a mapping of sub-keys, which `doc` names (beam's `reduction: {modes: k}`) */
  FMB_PARAM_VEC3,   /* ABI 3.3: fmb_get_vec3 */
  FMB_PARAM_QUAT    /* ABI 3.3: fmb_get_quat */
} fmbParamKind;

typedef struct fmbParam {
  const char* key;
  fmbParamKind kind;
  unsigned flags;             /* FMB_REQUIRED, FMB_POSITIVE, FMB_NONNEGATIVE as the parse passes them */
  const char* unit;           /* SI unit, "1" for a pure number or count, NULL for words and names */
  const char* fallback;       /* the default as a scene would write it; NULL when required or none */
  long lo, hi;                /* FMB_PARAM_INT: the accepted range */
  const char* const* choices; /* FMB_PARAM_CHOICE: NULL-terminated */
  const char* doc;            /* one line */
} fmbParam;

/* type flags (fmbBodyType.flags, fmbJointType.flags) */
enum {
  FMB_TYPE_DOES_WORK = 1 << 0, /* feeds energy in (a prescribed motion, an applied load): conform
                                  skips the energy-conservation run */
  /* conform's fixture (fmb_conform) is made of the first registered body type and joint type
     with this flag, so that the engine names no type: the body must take mass, inertia,
     position, velocity and angular_velocity (a rigid body with a frame), the joint body1, body2
     and point2 (a pin joining two bodies' points). A spatial-only probe gets the first flagged
     types that work in space (FMB_DIM_SPATIAL: rigid3d and spherical), a planar one the first
     that work in the plane */
  FMB_TYPE_CONFORM_FIXTURE = 1 << 1
};

/* ABI 3.3: the scene dimensions a type works in (fmbBodyType.dimensions, fmbJointType.dimensions);
   0 (and every table of an older minor) = FMB_DIM_PLANAR. An item of a type that does not work in
   the scene's `dimension:` is refused at its `type:`. */
enum { FMB_DIM_PLANAR = 1 << 0, FMB_DIM_SPATIAL = 1 << 1 };
/* the FMB_DIM_* of a table: its `dimensions` when its abi is 3.3 or later and it set them, else
   FMB_DIM_PLANAR (engine/registry.c) */
FMB_API unsigned fmb_type_dimensions(int abi, unsigned dimensions);

/* ---------------------------------------------------------------------------------------------
 * Body plugins. A body owns `ncoord` generalized coordinates q (frame x, y, theta first when the
 * body has a frame) and the same number of velocities v; its equations of motion are the rows
 *     R(q, v, a) = M(q) a - Q(q, v) = 0     (a = dv/dt, Q includes elastic, velocity and gravity)
 * The engine adds constraint forces and force elements. All arrays are the body's own slice.
 * ------------------------------------------------------------------------------------------- */
typedef struct fmbBodyType {
  const char* name; /* YAML `type:` */
  int abi;          /* FMB_ABI_VERSION */
  /* required */
  int (*parse)(fmbParser* p, fmbNode item, void** self);
  void (*destroy)(void* self);
  int (*ncoord)(const void* self);
  void (*initial)(const void* self, double* q0, double* v0);
  int (*residual)(const void* self, const fmbEnv* env, const double* q, const double* v, const double* a, double* R,
                  double* work);
  /* position and angle of a material point given in the body's reference configuration
     (`local`, body frame), with their derivatives wrt q (dpos_dq: 2 x ncoord row-major, may be
     NULL; dangle_dq: ncoord, may be NULL). Joints and force elements see bodies only this way. */
  int (*marker)(const void* self, const double* q, const double local[2], double pos[2], double* angle, double* dpos_dq,
                double* dangle_dq, double* work);
  /* optional */
  size_t (*nwork)(const void* self); /* scratch doubles the engine allocates once; NULL = 0 */
  /* dense ncoord x ncoord column-major blocks K = dR/dq, C = dR/dv, M = dR/da; NULL = the engine
     differentiates `residual` numerically (engine/fd.c) */
  int (*jacobian)(const void* self, const fmbEnv* env, const double* q, const double* v, const double* a, double* K,
                  double* C, double* M, double* work);
  void (*energy)(const void* self, const fmbEnv* env, const double* q, const double* v, fmbEnergy* e, double* work);
  /* named outputs beyond the frame's x, y, theta, omega, vx, vy (which the engine provides for
     every body with a frame: ncoord >= 3, or a marker that places the origin [0, 0]): lookup returns an id >= 0 or -1 (NULL: the id is the name's
     index in output_names); output evaluates one id. */
  const char* const* output_names; /* NULL-terminated, for listings */
  int (*output_lookup)(const void* self, const char* quantity);
  int (*output)(const void* self, int id, const double* q, const double* v, double* value, double* work);
  void (*describe)(
      const void* self,
      FILE*
          f); /* rest of one line after "body 'NAME' (TYPE, N coordinates): ": active terms, variant; ends with a newline */
  /* a body whose model can lose mass definiteness (FOAC) returns a hint saying why and what to
     do; the engine then checks the mass matrix reduced to the constraint manifold at every
     output time and stops the run with that hint when it is no longer positive definite.
     NULL op or NULL return = always definite, no check. */
  const char* (*indefinite_mass)(const void* self);
  /* the highest BDF order this body's dynamics tolerate. A body with many undamped stiff
     oscillatory modes (a finite-element beam) returns 2: BDF2 is A-stable, orders 3-5 amplify
     modes inside their instability wedge and the error test then forces tiny steps. NULL = 5.
     The engine uses the minimum over bodies unless the scene sets solver.max_order. */
  int (*max_bdf_order)(const void* self);
  /* 0 when this body's velocities should stay out of the error test unless the scene says
     otherwise (solver.error_control): after any sudden load a finite-element body carries every
     undamped mode, whose velocity amplitude falls only like 1/omega (its displacement like
     1/omega^2), so a velocity error test makes the steps resolve modes at 1e5 rad/s that the
     positions do not notice. NULL = 1 (positions and velocities tested). */
  int (*velocity_error_test)(const void* self);
  /* NULL when the state is within the model's validity; otherwise why not and what to do (a
     beam whose deformation exceeds its length is diverging). Checked at every output time:
     the run stops there with exit 3 instead of integrating a runaway solution. */
  const char* (*invalid_state)(const void* self, const double* q, const double* v);
  /* declarations (ABI 2): the keys parse reads; a valid instance as YAML lines `key: value`
     (without name and type) that conform runs free under gravity; extra lines that make it
     dissipate energy (NULL when it cannot); FMB_TYPE_* flags */
  const fmbParam* params;
  const char* example;
  const char* example_damped;
  unsigned flags;
  /* A body with a deformable centreline (a beam) names points along it for drawing and for the
     `BODY.shape` output: the reference points (body frame, as `marker` takes them) of n stations
     from root to tip into local[2n]. With local == NULL it only returns the station count it
     draws with by default (a beam: its nodes). The engine asks `marker` where they are now.
     NULL = a body without a centreline (drawn from its frame and joint points). */
  int (*centreline)(const void* self, int n, double* local);
  /* a type whose items choose between implementations behind one `type:` name (beam: `model:
     exact` is bodies/beam_exact.c) returns the ops table for this item, or NULL after recording
     a parse error; the engine then parses and runs the item with that table. NULL op = this one. */
  const struct fmbBodyType* (*variant)(fmbParser* p, fmbNode item);
  /* 0 when this body's K, C, M must be evaluated afresh whenever IDA asks for a new iteration
     matrix. The engine otherwise reassembles them from their last evaluation when only cj has
     changed (engine/integrator_ida.c), which suits bodies whose tangent changes slowly; a
     geometrically exact beam's axial stiffness EA t t^T turns with its tangent, and stale blocks
     cost Newton failures (spin-up at 15 rad/s, 20 elements: 454 against 123, 1.7x the CPU).
     NULL = 1 (reuse allowed). */
  int (*reuse_blocks)(const void* self);
  /* Auxiliary algebraic unknowns, for a body whose equations couple far-apart coordinates
     through sums (the beam's coupling deformation accumulates every inboard slope): carrying
     the sums as `naux` unknowns z with one equation each keeps every equation local, so the
     Jacobian is sparse. With naux > 0 the engine integrates R(q, v, a, z) = 0 (ncoord rows, R
     as `residual` returns it once Rz = 0) and Rz(q, v, a, z) = 0 (naux rows) from residual_aux;
     aux_initial gives the z that satisfies Rz = 0. `residual` (z eliminated) stays required:
     initial conditions and checks use it. NULL naux or 0 = none. */
  int (*naux)(const void* self);
  int (*residual_aux)(const void* self, const fmbEnv* env, const double* q, const double* v, const double* a,
                      const double* z, double* R, double* Rz, double* work);
  int (*aux_initial)(const void* self, const fmbEnv* env, const double* q, const double* v, const double* a, double* z,
                     double* work);
  /* The nonzeros of d[R; Rz]/d[x; z], x = q, v or a (their union), as (row, column) pairs over
     the ncoord + naux rows and columns (duplicates allowed): with rows/cols NULL it returns the
     count, else fills them. -1 (or a NULL op) = one dense block. The engine then differentiates
     the body over that pattern, grouping columns that share no row (engine/fd.c). */
  long (*pattern)(const void* self, int* rows, int* cols);
  /* The analytic K = d[R; Rz]/d[q; z], C = dR/dv, M = dR/da over the declared pattern: one value
     per (row, column) pair, in the order `pattern` lists the pairs (the engine sums duplicates,
     so a body may list each element's block and add into it as it assembles); C and M are 0 in
     the z columns. z is NULL when naux = 0. Nonzero = not evaluable (IDA cuts the step). The
     engine uses it instead of differencing over the pattern; NULL = differences (engine/fd.c). */
  int (*pattern_jacobian)(const void* self, const fmbEnv* env, const double* q, const double* v, const double* a,
                          const double* z, double* K, double* C, double* M, double* work);
  /* Each coordinate's length scale into metres_per_unit[ncoord]: the metres a point of the body
     moves per unit of the coordinate (1 for a displacement; the length L for a slope, a stretch
     or an angle that swings the body). The engine divides the scene's atol by it for that
     coordinate and its velocity (engine/tolerance.c), so one atol in metres controls slopes and
     displacements alike at any size of the body. NULL = atol as given for every coordinate. */
  void (*length_scale)(const void* self, double* metres_per_unit);
  /* The range where the body's model is accurate (ABI 2, added before any release of it): NULL
     while the state (q, v) is inside it; otherwise the body writes into msg[len] what left the
     range, by how much, and what to use instead, and returns msg. The run warns once per body,
     at the first output time it happens, with the time (beam: the tip deflection beyond the
     model's measured limit, "use model: exact"). NULL op = no range stated. */
  const char* (*model_range)(const void* self, const double* q, const double* v, char* msg, size_t len);
  /* ABI 3, optional: the SI unit of each name in output_names (same order; "1" for a pure number),
     for the axes of plots and of `view` (fmb_output_unit_in). NULL = not declared. */
  const char* const* output_units;
  /* ABI 3.2, optional (read only from a table whose abi is 3.2 or later): 1 when the auxiliary
     unknowns are a mixed form's own fields, which Newton iterates on with the coordinates rather
     than eliminating them (engine/system.c, fmb_system_residual_eliminated). The exact beam's axial
     strains at its axial points: iterated, its Newton matrix keeps EA out of the coupling that
     turns with the centreline, and Newton converges as for the complete model (docs/models.md,
     "Newton"). NULL or 0 = eliminated (the complete beam's coupling sums). */
  int (*aux_iterated)(const void* self);
  /* ABI 3.3, read only from a table whose abi is 3.3 or later: FMB_DIM_* the type works in
     (0 = planar). A spatial-only type may leave `marker` NULL and must give marker3. */
  unsigned dimensions;
  /* ABI 3.3: the spatial marker (docs/spatial.md). Position pos[3] of the material point `local`
     (body frame) and the rotation matrix R[9] (row-major; its columns are the body frame's axes at
     the point, global frame) with, when not NULL, dpos_dq (3 rows of ncoord at dpos_dq,
     dpos_dq + ld, dpos_dq + 2 ld) and rot_dq (3 rows likewise): the virtual rotation G, global
     frame, so that d(R u)/dq_k = G[:, k] x (R u) for every vector u of the body frame. R and
     either derivative may be NULL. Joints see spatial bodies only this way (fmb_marker3). */
  int (*marker3)(const void* self, const double* q, const double local[3], double pos[3], double R[9], double* dpos_dq,
                 double* rot_dq, int ld, double* work);
  /* ABI 3.4, optional, read only from a table whose abi is 3.4 or later: the gauge directions of
     the coordinates at q, directions d (ncoord each) along which nothing physical changes (no
     marker, no energy, no output): a spatial frame's Euler parameters p of any length, R = R(p/|p|),
     have one, d = [0, p, 0]. With dir == NULL it returns their count; else it writes them to
     dir[k * ncoord .. (k + 1) * ncoord) and returns the count. Integration needs no gauge (the body's
     own equations fix it); statics and modes do: they hold d^T dq = 0 as extra rows, so that the
     static Newton matrix is regular and no zero-frequency gauge mode appears. NULL = none. */
  int (*gauge)(const void* self, const double* q, double* dir);
} fmbBodyType;

/* ---------------------------------------------------------------------------------------------
 * Joint and force plugins. A joint touches at most two bodies; it contributes `nrows`
 * constraint rows Phi(q, t) = 0 and/or generalized forces. Its view of the bodies is an
 * fmbJointEval: the two bodies' coordinates and velocities, and fmb_marker() to ask a body where
 * a point is. Columns of phi_q (row-major, nrows x ncol) and entries of Q run over body 0's coordinates then
 * body 1's.
 * Rheonomic constraints must be of the form Phi(q) - f(t) (Phi_qt = 0).
 * ------------------------------------------------------------------------------------------- */
typedef struct fmbJointEval fmbJointEval;

typedef struct fmbJointType {
  const char* name;
  int abi;
  /* required */
  int (*parse)(fmbParser* p, fmbNode item, void** self);
  void (*destroy)(void* self);
  void (*bodies)(const void* self, int body[2]); /* body indices; body[1] may equal -1 */
  /* optional */
  int (*nrows)(const void* self); /* NULL = 0 (a pure force element) */
  int (*attachment)(const void* self, int k, int* body, double local[2]);
  int (*constraint)(const void* self, const fmbJointEval* ev, double* phi, double* phi_q, double* phi_t,
                    double* phi_tt);
  int (*force)(const void* self, const fmbJointEval* ev, double* Q); /* adds to Q */
  double (*energy)(const void* self, const fmbJointEval* ev);        /* spring potential */
  const char* const* output_names; /* as for bodies: NULL output_lookup = the index in this list */
  int (*output_lookup)(const void* self, const char* quantity);
  int (*output)(const void* self, int id, const fmbJointEval* ev, double* value);
  void (*describe)(const void* self, FILE* f);
  /* declarations (ABI 2), as for bodies. conform's fixture has two rigid bodies `a` (centre at
     [0.5, 0], pinned to ground at its end [-0.5, 0]) and `b` (centre at [1.5, 0]), 1 m long each,
     and a revolute joint `pin` (ground to a): the example refers to them by these names. A
     spatial-only type's example is placed in the spatial fixture: the same bodies in space (centres
     [0.5, 0, 0] and [1.5, 0, 0]) and `pin` a ball joint at a's end [-0.5, 0, 0]. */
  const fmbParam* params;
  const char* example;
  const char* example_damped;
  unsigned flags;
  /* ABI 3, optional: 1 when this instance takes its value from an input that a program sets
     between steps (fmb_set_input; a drive or load with `profile: input` / `law: input`), with the
     scene's initial `value:` in *initial; 0 otherwise. The input's name is the joint's. */
  int (*input)(const void* self, double* initial);
  /* ABI 3, optional: output_names' units, as for bodies */
  const char* const* output_units;
  /* ABI 3.3, read only from a table whose abi is 3.3 or later: FMB_DIM_* (0 = planar) */
  unsigned dimensions;
  /* ABI 3.3, optional: attachment's spatial twin, body and local point [x, y, z] of attachment k
     of a spatial joint with constraint rows: where the engine reports its reaction torque */
  int (*attachment3)(const void* self, int k, int* body, double local[3]);
} fmbJointType;

/* what a joint may ask of the evaluation context (a NULL context or k other than 0, 1 gives NaN,
   0, NULL or -1: a plugin bug, reported instead of crashing) */
FMB_API double fmb_eval_time(const fmbJointEval* ev);
FMB_API int fmb_eval_ncoord(const fmbJointEval* ev, int k); /* coordinates of body k (0 for ground) */
FMB_API const double* fmb_eval_q(const fmbJointEval* ev, int k);
FMB_API const double* fmb_eval_v(const fmbJointEval* ev, int k);
/* position and angle of body k's material point `local`; derivatives wrt body k's coordinates
   go to dpos_dq (row 0 at dpos_dq[0..nk), row 1 at dpos_dq[ld..ld+nk)) and dangle_dq[0..nk);
   either may be NULL. Use ld = the joint's column count to write straight into phi_q rows. */
FMB_API int fmb_marker(const fmbJointEval* ev, int k, const double local[2], double pos[2], double* angle,
                       double* dpos_dq, int ld, double* dangle_dq);
/* ABI 3.3: fmb_marker's spatial twin (fmbBodyType.marker3): position, rotation matrix (row-major,
   may be NULL) and, when not NULL, the rows of dpos/dq and of the virtual rotation G wrt body k's
   coordinates at stride ld (use the joint's column count and fmb_eval_col0 to write into phi_q).
   The ground answers local and the identity; a planar body answers -1. */
FMB_API int fmb_marker3(const fmbJointEval* ev, int k, const double local[3], double pos[3], double R[9],
                        double* dpos_dq, double* rot_dq, int ld);
/* scratch for the joint: at least 6 x (ncoord(body 0) + ncoord(body 1)) doubles (2 x before ABI 3.3):
   a spatial joint keeps both bodies' virtual rotations there (3 rows of its columns, fmb_marker3) */
FMB_API double* fmb_eval_scratch(const fmbJointEval* ev);
/* first column of body k in phi_q / Q (0 for body 0, ncoord(body 0) for body 1); -1 for a NULL
   context or another k (0 would be body 0's column: a wrong place, silently) */
FMB_API int fmb_eval_col0(const fmbJointEval* ev, int k);
/* the current value of this joint's input (its `input` op said 1): the scene's `value:` until a
   program sets it with fmb_set_input; NaN for a joint without an input */
FMB_API double fmb_eval_input(const fmbJointEval* ev);
/* its rate d/dt at the evaluation's time and (accel not NULL) its second rate: what the program
   gave with fmb_set_input_motion, 0 for a value held (fmb_set_input); NaN without an input. A
   prescribed motion reads them for its f' and f'' (a drive whose rate is 0 throws the motion
   between settings away) */
FMB_API double fmb_eval_input_rate(const fmbJointEval* ev, double* accel);

/* ---------------------------------------------------------------------------------------------
 * Numerics shared by plugins (one quadrature for the whole project, engine/quad.c).
 * ------------------------------------------------------------------------------------------- */
/* A hot vector kernel in two versions, picked once at load time by the CPU (GCC's target_clones,
   an ifunc): SSE2, x86-64's baseline the build targets, and AVX2, whose vectors hold twice the
   values. Only for element-wise loops (axpys, scalings): the wider vectors then do the same
   operations on each value in the same order, so results are bit for bit the same (no FMA: "avx2"
   does not enable it, and -std=c11 keeps contraction off). GCC on x86-64 Linux; one version
   elsewhere (clang, other targets). Public, so that a type's own hot loop can use it (the beam's
   energy pass). */
#if defined(__GNUC__) && !defined(__clang__) && defined(__x86_64__) && defined(__linux__)
#define FMB_VECTOR_CLONES __attribute__((target_clones("avx2", "default")))
#else
#define FMB_VECTOR_CLONES
#endif

#define FMB_GAUSS_MAX 10
/* n-point Gauss-Legendre rule on [0, 1] (1 <= n <= FMB_GAUSS_MAX); exact to degree 2n-1.
   Returns 0, or -1 for an unsupported n. */
FMB_API int fmb_gauss_legendre01(int n, double* x, double* w);
/* n-point Gauss-Lobatto rule on [0, 1] (2 <= n <= FMB_GAUSS_MAX): both ends and n - 2 interior
   points, exact to degree 2n-3. Returns 0, or -1 for an unsupported n. */
FMB_API int fmb_gauss_lobatto01(int n, double* x, double* w);

/* Rigid-frame kinematics (engine/frame.c): the global position and angle of the point `local` of
   a planar frame at frame = [x, y, theta] (p = r + A(theta) local, angle = theta), dp/dframe
   (2 x 3 row-major) and dangle/dframe (3); angle and the derivatives may be NULL. A rigid body
   (q = its frame) answers `marker` with exactly this call. */
FMB_API void fmb_frame_point(const double frame[3], const double local[2], double pos[2], double* angle,
                             double* dpos_dframe, double* dangle_dframe);
/* ABI 3.3, its spatial twin (engine/frame3.c): a frame [x, y, z, p0, p1, p2, p3] with Euler
   parameters p of any nonzero length (R = R(p / |p|), docs/spatial.md): position of `local`, R
   (row-major, may be NULL) and, when not NULL, dpos/dframe and the virtual rotation G/dframe, each
   3 rows of 7 at stride ld. Returns 0, or -1 for p = 0. */
FMB_API int fmb_frame3_point(const double frame[7], const double local[3], double pos[3], double R[9],
                             double* dpos_dframe, double* rot_dframe, int ld);
/* ABI 3.3: R(p / |p|) (row-major) of Euler parameters p = [w, x, y, z] of any nonzero length; -1 for p = 0 */
FMB_API int fmb_quat_matrix(const double p[4], double R[9]);
/* ABI 3.3: the Euler parameters (unit, w >= 0) of a rotation matrix (row-major) */
FMB_API void fmb_matrix_quat(const double R[9], double p[4]);

/* ---------------------------------------------------------------------------------------------
 * The plugin descriptor. A shared object exports it as
 *     FMB_PLUGIN_EXPORT const fmbPlugin* fmb_plugin_descriptor(void);
 * and a program adds it to a registry (fmb_registry_load, fmb_registry_add: flexmbd.h).
 * ------------------------------------------------------------------------------------------- */
struct fmbPlugin {
  int abi;          /* FMB_PLUGIN_ABI: first, never moves */
  unsigned size;    /* sizeof(fmbPlugin) as the plugin was compiled: second, never moves (0 = a 3.0
                    descriptor, which had padding here); FMB_PLUGIN_HEAD sets both */
  const char* name; /* for messages and `flexmbd types` */
  const char* version;
  const fmbBodyType* const* bodies; /* NULL-terminated; NULL = none */
  const fmbJointType* const* joints;
};
/* the first two fields of a descriptor: static const fmbPlugin p = {FMB_PLUGIN_HEAD, .name = ...} */
#define FMB_PLUGIN_HEAD .abi = FMB_PLUGIN_ABI, .size = sizeof(fmbPlugin)
#define FMB_PLUGIN_ENTRY "fmb_plugin_descriptor"
typedef const fmbPlugin* (*fmbPluginEntry)(void);

#ifdef __cplusplus
}
#endif
#endif
