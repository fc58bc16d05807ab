/*
 * flexmbd.h — the one public header of the flexmbd engine.
 *
 * Two audiences:
 *   - programs that load a scene and run it (fmb_load, fmb_run, fmb_free);
 *   - plugin authors who add a body or joint/force type (fmbBodyType, fmbJointType and the
 *     fmb_get_* accessors used inside a plugin's parse function).
 *
 * Conventions: SI units; functions are fmb_verbNoun, outputs after inputs unless noted;
 * evaluation callbacks return 0 on success, >0 for a recoverable failure (IDA cuts the step,
 * e.g. a non-finite value in a trial step) and <0 for a fatal one, exactly IDA's rule.
 */
#ifndef FLEXMBD_H
#define FLEXMBD_H

#include <signal.h>
#include <stddef.h>
#include <stdio.h>

#ifdef __cplusplus
extern "C" {
#endif

/* The plugin ABI: the layout of fmbPlugin, fmbBodyType, fmbJointType, fmbParam and the signatures
   of every function below. A plugin built for another number is refused when it is loaded
   (engine/plugin.c). 2: the type tables gained params, example, example_damped, flags, and bodies
   the optional centreline op and the optional naux, residual_aux, aux_initial, pattern,
   pattern_jacobian, length_scale and model_range ops (added to 2 before any release of it). 3: the
   stepping API (fmbData, fmb_init, fmb_advance, ...), the warn callback, and inputs: joints gained
   the optional `input` op and read an input's value with fmb_eval_input; bodies and joints the
   optional output_units (what plots and `view` put on their axes). */
#define FMB_ABI_VERSION 3

/* what the shared library exports (it is built with hidden visibility, docs/plugins.md) */
#if defined(__GNUC__)
#define FMB_API __attribute__((visibility("default")))
#else
#define FMB_API
#endif
/* what a plugin exports: its one entry point, fmb_plugin_descriptor */
#ifdef __cplusplus
#define FMB_PLUGIN_EXPORT extern "C" FMB_API
#else
#define FMB_PLUGIN_EXPORT FMB_API
#endif

/* ---------------------------------------------------------------------------------------------
 * Diagnostics: the first error wins; file/line/col are 1-based, 0 when not applicable.
 * ------------------------------------------------------------------------------------------- */
#define FMB_EXIT_OK 0
#define FMB_EXIT_BAD_INPUT 2
#define FMB_EXIT_SOLVER 3
#define FMB_EXIT_INTERRUPTED 4 /* SIGINT/SIGTERM: stopped at the next step, rows so far kept */

typedef struct fmbDiag {
  int code;       /* 0 none, FMB_EXIT_BAD_INPUT, FMB_EXIT_SOLVER or FMB_EXIT_INTERRUPTED */
  char file[512]; /* scene path, or "--set" for an override */
  int line, col;
  char msg[1024];
} fmbDiag;

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
  FMB_PARAM_MAP     /* a mapping of sub-keys, which `doc` names (beam's `reduction: {modes: k}`) */
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
     and point2 (a pin joining two bodies' points) */
  FMB_TYPE_CONFORM_FIXTURE = 1 << 1
};

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
  /* ABI 3, optional (added before any release of it): 1 when the auxiliary unknowns are a mixed
     form's own fields, which Newton iterates on with the coordinates rather than eliminating
     them (engine/system.c, fmb_system_residual_eliminated). The exact beam's axial forces at its
     axial points: iterated, its Newton matrix keeps EA out of the coupling that turns with the
     centreline, and Newton converges as for the complete model (docs/models.md, "Newton").
     NULL or 0 = eliminated (the complete beam's coupling sums). */
  int (*aux_iterated)(const void* self);
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
     and a revolute joint `pin` (ground to a): the example refers to them by these names. */
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
/* scratch for the joint: at least 2 x (ncoord(body 0) + ncoord(body 1)) doubles */
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

/* ---------------------------------------------------------------------------------------------
 * Plugins and the registry. A plugin is a set of types behind one descriptor; the built-in types
 * are one too (fmb_builtin_plugin), and every type enters a registry through fmb_registry_add,
 * which checks the ABI and the required ops. A shared object exports the descriptor as
 *     FMB_PLUGIN_EXPORT const fmbPlugin* fmb_plugin_descriptor(void);
 * The engine names no type; the program hands fmb_load a registry.
 * ------------------------------------------------------------------------------------------- */
typedef struct fmbPlugin {
  int abi;          /* FMB_ABI_VERSION: first, never moves */
  const char* name; /* for messages and `flexmbd types` */
  const char* version;
  const fmbBodyType* const* bodies; /* NULL-terminated; NULL = none */
  const fmbJointType* const* joints;
} fmbPlugin;
#define FMB_PLUGIN_ENTRY "fmb_plugin_descriptor"
typedef const fmbPlugin* (*fmbPluginEntry)(void);

typedef struct fmbRegistry fmbRegistry;           /* growable, any number of types */
FMB_API fmbRegistry* fmb_registry_new(void);      /* empty; NULL when out of memory */
FMB_API void fmb_registry_free(fmbRegistry* reg); /* types and loaded code stay valid */
/* register every type of `plugin` (origin: "built-in" or the file, for messages). Refuses, with
   *diag filled (exit code 2), another ABI, a type without a name or a required op, and a name
   already registered by another table; the same table twice is a no-op. */
FMB_API int fmb_registry_add(fmbRegistry* reg, const fmbPlugin* plugin, const char* origin, fmbDiag* diag);
/* dlopen a shared object (a path without '/' is taken in the current folder, never searched for),
   look up fmb_plugin_descriptor and add it. Loaded code is never unloaded. */
FMB_API int fmb_registry_load(fmbRegistry* reg, const char* path, fmbDiag* diag);
FMB_API int fmb_registry_nbodies(const fmbRegistry* reg);
FMB_API int fmb_registry_njoints(const fmbRegistry* reg);
FMB_API const fmbBodyType* fmb_registry_body(const fmbRegistry* reg, int i);
FMB_API const fmbJointType* fmb_registry_joint(const fmbRegistry* reg, int i);
/* where type i came from: "built-in" or the plugin's file */
FMB_API const char* fmb_registry_body_origin(const fmbRegistry* reg, int i);
FMB_API const char* fmb_registry_joint_origin(const fmbRegistry* reg, int i);
/* the types shipped with flexmbd (builtin/builtin.c), registered like any plugin */
FMB_API const fmbPlugin* fmb_builtin_plugin(void);

/* ---------------------------------------------------------------------------------------------
 * Loading and running.
 * ------------------------------------------------------------------------------------------- */
typedef struct fmbModel fmbModel;

typedef struct fmbStats {
  int status_ok;
  double t_reached;
  long steps, residuals, jacobians, newton_iters, error_test_fails;
  long conv_fails;       /* Newton convergence failures */
  long jacobians_reused; /* of `jacobians`: reassembled for a new cj from the last body blocks */
  double cpu_s;
  double ic_position_correction, ic_velocity_correction; /* norms of the initial projection */
  long rows_written;
  int interrupted; /* the run stopped because *fmbRunOptions.stop was set */
  /* the integrator backend that ran last ("ida", "radau5", "projected"; solver.integrator: auto
     picks one per model, formulation: auto may switch to projected mid-run); NULL if none ran */
  const char* integrator;
} fmbStats;

typedef struct fmbRunOptions {
  const char* csv_path; /* NULL or "-" = stdout */
  /* no progress line and no notes (initial conditions, redundant rows, a switch of formulation);
     warnings still go out. Messages go to the thread's warn handler (fmb_set_warn). */
  int quiet;
  /* a progress message "progress: t = ..." (t, % of t_end, steps, elapsed, remaining), from
     progress_after_s of wall time on, at most 5 a second when stderr is a terminal (where the
     flexmbd program rewrites the line in place), one a second otherwise */
  int progress;
  double progress_after_s;
  const char* vtk_dir; /* NULL = the scene's `vtk` key (if any); else a ParaView collection there */
  int vtk_every;       /* the animation takes every Nth output row, from the first (0, 1: each) */
  /* may be NULL; when *stop becomes non-zero (e.g. set by a SIGINT handler) the run ends after
     the step in progress, keeps its rows and returns FMB_EXIT_INTERRUPTED */
  const volatile sig_atomic_t* stop;
} fmbRunOptions;

/* Ownership and misuse (every function here checks its pointer arguments: a NULL required
 * argument is an error, never a crash):
 *   - fmb_load returns a model the caller owns and releases with fmb_free (NULL is fine). It
 *     reads `path` and the override strings only during the call; the registry and the type
 *     tables it points to must outlive the model (the model calls their ops). A plugin's `self`
 *     belongs to the model once its parse returned 0 (and to nobody if it failed: the engine
 *     calls destroy on whatever it set).
 *   - fmb_run only reads the model (one model may be run several times); it writes *stats and
 *     *diag, both optional (NULL = not wanted); opt may be NULL (stdout, progress lines on).
 *   - fmbDiag and fmbStats are plain values owned by the caller; nothing in them needs freeing.
 *   - Output files: fmb_run writes a regular file to a temporary file beside it and renames it
 *     into place once the header is written, so a run that fails before that leaves an existing
 *     file as it was; "-" and non-regular files are written through and never removed. */

/* Load `path`, applying "PATH=VALUE" overrides (e.g. "solver.rtol=1e-8",
   "bodies.beam.elements=32"). Returns NULL with *diag filled (diag may be NULL) on error,
   including a NULL path or registry, or NULL overrides with noverrides > 0. */
FMB_API fmbModel* fmb_load(const char* path, const char* const* overrides, int noverrides, const fmbRegistry* reg,
                           fmbDiag* diag);
/* Integrate from the scene's t0 to t_end, writing CSV rows as it goes. Returns 0 or an exit code
   (FMB_EXIT_SOLVER, FMB_EXIT_INTERRUPTED; FMB_EXIT_BAD_INPUT for a NULL model or an output that
   cannot be written) with *diag saying when and why it stopped. */
FMB_API int fmb_run(const fmbModel* m, const fmbRunOptions* opt, fmbStats* stats, fmbDiag* diag);
FMB_API void fmb_free(fmbModel* m);
/* the solver settings a loaded scene runs with (its values after --set overrides) */
typedef struct fmbSolverInfo {
  double t0, t_end, rtol, atol, output_step;
} fmbSolverInfo;
/* 0, or -1 when an argument is NULL */
FMB_API int fmb_model_solver(const fmbModel* m, fmbSolverInfo* out);
/* the scene's bodies (the fixed ground excluded): their count, and body i's name and `type:`
   (0 <= i < count; 0, or -1 when out of range). Lets a program address them with --set. */
FMB_API int fmb_model_nbody(const fmbModel* m);
FMB_API int fmb_model_body(const fmbModel* m, int i, const char** name, const char** type);
/* the scene's joints: their count, and joint i's name and `type:` (0 <= i < count; 0, or -1) */
FMB_API int fmb_model_njoint(const fmbModel* m);
FMB_API int fmb_model_joint(const fmbModel* m, int i, const char** name, const char** type);
/* What a mechanism looks like (engine/drawing.c), fixed at load: the points and cells that the
   ParaView animation (--vtk) and `flexmbd view` draw, from the types' ops alone: a body with a
   `centreline` is a polyline through its stations; any other body with a frame (ncoord >= 3) is the
   outline through the points its joints attach to (closed from three points) and its frame's x and
   y axes; a joint with constraint rows is a vertex at its first point; a force element with two
   points (a spring) is the line between them. */
enum {
  FMB_DRAW_CENTRELINE = 0,
  FMB_DRAW_OUTLINE = 1,
  FMB_DRAW_FRAME_AXIS = 2,
  FMB_DRAW_JOINT = 3,
  FMB_DRAW_FORCE_ELEMENT = 4
};
typedef struct fmbDrawPoint {
  int body;        /* 0 = the world frame (local is then global); k >= 1 = fmb_model_body(m, k - 1) */
  double local[2]; /* the material point in the body frame, as joints and `marker` take it */
  int station;     /* a centreline station: K of the columns BODY.shapeK_x, BODY.shapeK_y; else -1 */
} fmbDrawPoint;
typedef struct fmbDrawCell {
  int first, count; /* its points: conn[first .. first + count) */
  int part;         /* FMB_DRAW_* */
  int owner;        /* the body (numbered as fmbDrawPoint.body) or the joint (from 0) it draws */
} fmbDrawCell;
typedef struct fmbDrawing {
  int npoint, ncell, nconn;
  fmbDrawPoint* point;
  fmbDrawCell* cell;
  int* conn;
} fmbDrawing;
/* the SI unit of a CSV column the engine itself defines ("t": s; BODY.x: m; BODY.omega: rad/s;
   JOINT.power: W; JOINT.work and energy.*: J; JOINT.reaction_x: N; reaction_torque: N m;
   BODY.shapeK_x: m), or NULL (a type's own output, whose unit is not declared; unknown names) */
FMB_API const char* fmb_output_unit(const char* column);
/* the same, and for a type's own output (BODY.tip_v, JOINT.torque) the unit the registry's types
   declare for that quantity (output_units; a numbered name such as node12_v matches nodeK_v), when
   every type that declares the quantity agrees on it; NULL otherwise. reg may be NULL. */
FMB_API const char* fmb_output_unit_in(const fmbRegistry* reg, const char* column);
/* s as XML text or attribute value (& < > " ' escaped, control characters other than \n \t
   dropped): the VTK collection, JUnit reports */
FMB_API void fmb_write_xml_text(FILE* f, const char* s);
/* NULL when m is NULL or out of memory; free with fmb_drawing_free (NULL allowed) */
FMB_API fmbDrawing* fmb_drawing_new(const fmbModel* m);
FMB_API void fmb_drawing_free(fmbDrawing* d);
/* one line per body and joint: type and active terms (nothing when m or f is NULL) */
FMB_API void fmb_describe(const fmbModel* m, FILE* f);
/* the constraints at t0 after the initial projection: degrees of freedom, redundant equations by
   joint name and row, and whether the start is a singular configuration. 0, or an exit code with
   *diag filled (joints that cannot be satisfied). */
FMB_API int fmb_check_constraints(const fmbModel* m, FILE* f, fmbDiag* diag);
/* the backend a run of this model starts on and why, as one line "solver: ..." (what
   `integrator: auto` and `formulation: auto` pick, or what the scene names; `flexmbd check`). */
FMB_API void fmb_describe_solver(const fmbModel* m, FILE* f);
/* the outputs the engine itself gives, as NULL-terminated names (NULL for an unknown group):
   "frame" (BODY.x y theta omega vx vy, for every body with a frame: one whose marker places its
   origin), "power" (JOINT.power work, for a joint with constraint rows or a force), "reaction"
   (JOINT.reaction_x ..., for a joint with constraint rows), "energy" (energy.*), "constraint"
   (constraint.*). `flexmbd types` lists them from here, the loader resolves them from here. */
FMB_API const char* const* fmb_engine_outputs(const char* group);
/* the `stats: status=ok|failed|interrupted ...` line (nothing when s or f is NULL) */
FMB_API void fmb_print_stats(const fmbStats* s, FILE* f);

/* ---------------------------------------------------------------------------------------------
 * Stepping (engine/step.c; docs/api.md). A model is fixed after fmb_load and only read; the state
 * of one run of it lives in an fmbData (MuJoCo's mjModel / mjData split), so one model can be run
 * by several data objects, and two data objects (of one model or two) can be advanced in two
 * threads at once. fmb_run is a loop over these calls (engine/run.c) and writes the same bytes.
 *
 *   fmbData* d = fmb_data_new(m, &diag);            everything a run needs is allocated here
 *   fmb_init(m, d, &diag);                           consistent state at t0 (again: restart)
 *   while (fmb_data_time(d) < t_end) {
 *     fmb_set_input(m, d, "motor", torque);          optional: a load or drive between steps
 *     fmb_advance(m, d, t_next, &diag);              integrate to t_next
 *     fmb_outputs(m, d, values);                     the CSV row's values at time()
 *   }
 *   fmb_data_free(d);
 *
 * Return codes: 0; FMB_EXIT_SOLVER (the state is the last good one and diag says when and why:
 * the backend's last step, or, when it left values that are not finite, where the advance started;
 * a later advance restarts from it, e.g. once the input that caused it is set back);
 * FMB_EXIT_INTERRUPTED (fmb_data_cancel); FMB_EXIT_BAD_INPUT for misuse: a NULL argument, a data
 * object of another model or already freed, advance before init, t_out NaN, before time() or
 * beyond the scene's t_end. A misused call changes nothing.
 * ------------------------------------------------------------------------------------------- */
typedef struct fmbData fmbData; /* the state of one run of one model */
/* one message (no trailing newline): a warning, a note, a progress line; user as given */
typedef void (*fmbWarnFn)(void* user, const char* message);

/* allocates everything a run needs (state, scratch, outputs); NULL with *diag on failure */
FMB_API fmbData* fmb_data_new(const fmbModel* m, fmbDiag* diag);
/* NULL is fine; a second free of the same object is detected and ignored while it is among the
   last FMB_DATA_QUARANTINE freed ones (its memory is held back until then), as is any other call
   on it (FMB_EXIT_BAD_INPUT); beyond that, using a freed object is undefined */
FMB_API void fmb_data_free(fmbData* d);
#define FMB_DATA_QUARANTINE 64
/* the consistent state at the scene's t0 (initial conditions; inputs back to their `value:`);
   again = restart from t0. The integrator itself is set up by the first fmb_advance from the
   state then (after any fmb_set_input). 0 or an exit code with *diag */
FMB_API int fmb_init(const fmbModel* m, fmbData* d, fmbDiag* diag);
/* integrate from time() to t_out, time() <= t_out <= t_end (t_out == time(): nothing to do). A
   changed input (fmb_set_input) or a run interrupted or failed before restarts the integrator
   from a consistent state at time(): no step history is carried across the jump. */
FMB_API int fmb_advance(const fmbModel* m, fmbData* d, double t_out, fmbDiag* diag);
FMB_API double fmb_data_time(const fmbData* d); /* NaN for NULL (or before fmb_init) */
/* the DAE state y = [q, v, lambda, mu, z] and y' (fmb_state_size(m) doubles each; either may be
   NULL): 0, or FMB_EXIT_BAD_INPUT (NULL or freed d, before fmb_init) */
FMB_API int fmb_data_state(const fmbData* d, double* y, double* yp);
/* the scene's outputs: their number (the CSV's columns after t), the name of output i (e.g.
   "beam.tip_v"; NULL out of range) and their values at time() into out[fmb_noutput(m)], the very
   numbers the CSV row at that time holds. fmb_outputs: 0, FMB_EXIT_SOLVER when a value is not
   finite (out still filled), FMB_EXIT_BAD_INPUT for misuse */
FMB_API int fmb_noutput(const fmbModel* m);
FMB_API const char* fmb_output_name(const fmbModel* m, int i);
FMB_API int fmb_outputs(const fmbModel* m, fmbData* d, double* out);
/* the integrator's counters so far (all backends of this run), t_reached = time(), the CPU time
   spent in fmb_init and fmb_advance: 0, or FMB_EXIT_BAD_INPUT */
FMB_API int fmb_data_stats(const fmbData* d, fmbStats* st);
/* ask the advance in progress, or the next one, to stop: it returns FMB_EXIT_INTERRUPTED with the
   state at the last good step, and the request is used up (a later advance goes on from there).
   Only sets a flag: safe from another thread or a signal handler. */
FMB_API void fmb_data_cancel(fmbData* d);
/* where this run's messages go: fn(user, message); fn NULL = the thread's default (fmb_set_warn) */
FMB_API void fmb_data_set_warn(fmbData* d, fmbWarnFn fn, void* user);
/* the calling thread's default handler, for messages while loading and of runs without their own:
   fn(user, message); fn NULL = silent. Until a thread sets one, messages go to stderr, one line
   each. */
FMB_API void fmb_set_warn(fmbWarnFn fn, void* user);
/* inputs: values a program sets between steps (a drive's angle or position with `profile: input`,
   a load with `law: input`), named by their joint. fmb_set_input: 0, or FMB_EXIT_BAD_INPUT (an
   unknown name, NaN or infinity, misuse, or a value a scene's `value:` would be refused for: a drive
   angle or slide that puts the coordinates where a double cannot resolve the joints' tolerance, or
   that the joints cannot follow; why goes to the run's warn handler, and the input keeps its value);
   the value holds from time() on, as a step (piecewise constant, rate 0) that the next advance
   starts from. fmb_set_input_motion gives its rate and second rate too: from time() on the input is
   value + rate tau + accel tau^2 / 2 (tau = t - time()) until the next setting, so a drive fed a
   smooth motion moves with it (velocities and accelerations follow the rate) instead of coming to
   rest at every setting. A drive's setting that lands away from where its previous one led (a
   jump: always, when a moving drive is held by fmb_set_input) restarts the integrator from a
   state projected onto the new motion, and the first such jump of each input is warned about. */
FMB_API int fmb_ninput(const fmbModel* m);
FMB_API const char* fmb_input_name(const fmbModel* m, int i);
FMB_API int fmb_set_input(const fmbModel* m, fmbData* d, const char* name, double value);
FMB_API int fmb_set_input_motion(const fmbModel* m, fmbData* d, const char* name, double value, double rate,
                                 double accel);
/* the current value of input `name`: 0, or FMB_EXIT_BAD_INPUT */
FMB_API int fmb_get_input(const fmbModel* m, const fmbData* d, const char* name, double* value);

/* ---------------------------------------------------------------------------------------------
 * Conformance (engine/conform.c): the checks every registered type must pass, run on its
 * declared example: bad parameters refused with a located message, declared keys = keys read,
 * analytic Jacobian against finite differences, mass matrix symmetric positive definite, marker
 * and constraint derivatives, energy kept by a free run and lost by a damped one, outputs finite,
 * gravity left out when the scene has none. One line per check on `report`; returns the number
 * of failed checks (0 = conforming), or -1 when no type has that name.
 * ------------------------------------------------------------------------------------------- */
FMB_API int fmb_conform(fmbRegistry* reg, const char* type_name, const char* work_dir, FILE* report);

/* ---------------------------------------------------------------------------------------------
 * Analysis beyond time integration (engine/static.c, engine/modes.c; docs/analysis.md).
 * A state is the DAE's y = [q, v, lambda, mu] and y' = [v, a, 0, 0], fmb_state_size(m) doubles
 * each, in arrays the caller owns.
 * ------------------------------------------------------------------------------------------- */
FMB_API int fmb_state_size(const fmbModel* m); /* 0 for m == NULL */

typedef struct fmbStaticOptions {
  double t;         /* time at which drives and other rheonomic joints are held, */
  int has_t;        /* when has_t; otherwise the scene's t0 */
  int max_iter;     /* Newton iterations per load step; 0 = 30 */
  int max_halvings; /* how often a load step may be halved; 0 = 12 (down to 1/4096 of the load) */
  double tol;       /* Newton stops when max |dq_i| <= tol (1 + |q_i|); 0 = 1e-10 */
  int quiet;        /* no progress messages (to the warn handler) */
} fmbStaticOptions;

typedef struct fmbStaticResult {
  double t;
  /* the steady state is a rigid rotation of the whole system at `speed` (rad/s) about `center`
     (0 = static equilibrium), read from the drives' speeds at t */
  double speed, center[2];
  double residual;       /* 2-norm of the equations at the solution (forces and Phi) */
  double residual_start; /* the same at the starting point (the out-of-balance load) */
  int iterations, load_steps;
} fmbStaticResult;

/* Static equilibrium, or relative equilibrium under a constant-speed drive, at opt->t (NULL
   options = defaults at the scene's t0), by Newton on the full nonlinear equations with load
   stepping (homotopy F(x) - (1 - s) F(x0), s: 0 -> 1, steps halved when Newton fails). Starts
   from the bodies' initial poses. Fills y, yp (fmb_state_size doubles each). Returns 0,
   FMB_EXIT_BAD_INPUT (the scene has no steady state: gravity on a rotating system, drives that
   are not one rigid rotation) or FMB_EXIT_SOLVER (no convergence), with *diag saying why. */
FMB_API int fmb_static(const fmbModel* m, const fmbStaticOptions* opt, double* y, double* yp, fmbStaticResult* res,
                       fmbDiag* diag);

typedef struct fmbModes {
  int count;             /* modes held, sorted by |frequency| */
  int nq;                /* length of a shape */
  int nreduced;          /* degrees of freedom after the constraints were eliminated */
  int sparse;            /* 1 when the sparse (Arnoldi) path computed them */
  double speed;          /* the rigid rotation the state has (rad/s) */
  double* frequency;     /* rad/s, |s| of the eigenvalue s; negative -|s| for a divergent mode
                             (real s > 0, e.g. ZOAC spun above its first bending frequency) */
  double* damping_ratio; /* -Re(s)/|s|; -1 for a divergent mode */
  double* shape_re;      /* count x nq, mode k at k * nq: the generalized coordinates' motion, */
  double* shape_im;      /* scaled so the largest component is 1 (real) */
} fmbModes;

/* eigen-solvers: dense LAPACK on the constraint-reduced problem (all modes), or shift-invert
   Arnoldi (ARPACK) with KLU on the saddle-point system (a few modes of a large system; falls
   back to dense when the system has rigid motions); auto picks sparse from 48 coordinates */
enum { FMB_EIGEN_AUTO = 0, FMB_EIGEN_DENSE = 1, FMB_EIGEN_SPARSE = 2 };
/* Linearize the DAE about the state (y, yp) at time t (from fmb_static: the rotating-frame
   terms of a steady rotation are included), eliminate the constraints and solve the
   eigenproblem (`method`). Returns 0 with *out (the caller frees it with fmb_modes_free)
   holding at most `count` modes (count <= 0: all, dense), or an exit code with *diag
   (FMB_EXIT_BAD_INPUT for a `method` other than FMB_EIGEN_* or a time that is not finite). */
FMB_API int fmb_modes(const fmbModel* m, double t, const double* y, const double* yp, int count, int method,
                      fmbModes** out, fmbDiag* diag);
FMB_API void fmb_modes_free(fmbModes* modes);
/* modal assurance criterion |a^H b|^2 / (|a|^2 |b|^2) of mode i of a and mode k of b, in [0, 1];
   NaN for NULL sets, shapes of different lengths or i, k out of range (0 would read "orthogonal") */
FMB_API double fmb_modes_mac(const fmbModes* a, int i, const fmbModes* b, int k);
/* the scene's outputs at state (y, yp), one CSV row (header first) */
FMB_API int fmb_write_state_row(const fmbModel* m, const char* path, double t, const double* y, const double* yp,
                                fmbDiag* diag);
/* each mode's effect on the scene's outputs: d(output)/d(amplitude) along the real shape, one row
   per mode, columns `mode` then the outputs (put beam.nodeK_v in `outputs` for nodal shapes) */
FMB_API int fmb_write_mode_shapes(const fmbModel* m, double t, const double* y, const double* yp, const fmbModes* modes,
                                  const char* path, fmbDiag* diag);
/* mode k (0-based) as a ParaView animation in dir (created; DIR/SCENE.pvd and one .vtu per frame,
   the run's VTK writer): `frames` states over one period, the largest coordinate moving by
   `amplitude` (its units: m or rad; positive and finite, else FMB_EXIT_BAD_INPUT) */
FMB_API int fmb_write_mode_animation(const fmbModel* m, double t, const double* y, const fmbModes* modes, int k,
                                     double amplitude, int frames, const char* dir, fmbDiag* diag);
/* a table of named numeric columns (row-major values), through the one CSV writer; nrow >= 0
   (a negative count is FMB_EXIT_BAD_INPUT, not an empty table). The CSV has no quoting: a name
   that is empty, holds a comma, a quote or a control character (a line break), has blanks at its
   ends, or starts the header with '#' is FMB_EXIT_BAD_INPUT, nothing written. With the names "t" and
   fmb_output_name's and rows of [time, fmb_outputs], the very bytes fmb_run writes */
FMB_API int fmb_write_table(const char* path, int ncol, const char* const* names, int nrow, const double* values,
                            fmbDiag* diag);

/* A scene as fmb_load takes it, for the analyses that load it again with an override of their own
   (one per hub speed, one per beam model): path, the caller's overrides and the registry, read
   only during the call. */
typedef struct fmbSceneSource {
  const char* path;
  const char* const* overrides;
  int noverrides;
  const fmbRegistry* reg;
} fmbSceneSource;

/* Load the scene with `extra` (may be NULL) after its overrides, and solve its static or steady
   state (fmb_static): *m, *y, *yp are the caller's (fmb_free, free) also on failure (NULL when
   not made). Returns 0 or an exit code with *diag. */
FMB_API int fmb_load_steady(const fmbSceneSource* scene, const char* extra, const fmbStaticOptions* opt, fmbModel** m,
                            double** y, double** yp, fmbStaticResult* res, fmbDiag* diag);

/* ---------------------------------------------------------------------------------------------
 * Campbell diagram (engine/campbell.c; docs/analysis.md): for each hub speed the steady state
 * (fmb_load_steady with `speed_key=SPEED`), then its modes, each mode followed from speed to
 * speed by its shape (the largest modal assurance criterion with its shape at the speed before,
 * assigned greedily), not by its rank in frequency.
 * ------------------------------------------------------------------------------------------- */
#define FMB_CAMPBELL_MAX_MODES 64
typedef struct fmbCampbellOptions {
  const char* speed_key;   /* the scene key that sets the hub speed, e.g. joints.spin.speed */
  int count;               /* modes followed, 1 .. FMB_CAMPBELL_MAX_MODES (0 = 4) */
  int method;              /* FMB_EIGEN_* */
  fmbStaticOptions steady; /* for fmb_static at each speed */
} fmbCampbellOptions;

typedef struct fmbCampbell {
  int nspeed;        /* speeds asked for */
  int done;          /* speeds computed, from the first on (rows filled) */
  int count;         /* modes followed */
  double* speed;     /* nspeed, rad/s */
  double* frequency; /* nspeed x count, row i at i * count: mode k at speed i (rad/s; negative = divergent) */
  double* mac;       /* nspeed x count: MAC of mode k with its own shape at speed i - 1 (1 at the first
                        speed); below 0.5 the speeds are too far apart to follow it reliably */
  /* internal: the last speed's modes and which of them each followed mode is */
  fmbModes* last;
  int* track;
} fmbCampbell;

/* The diagram at speeds[0 .. nspeed). Returns 0, or an exit code with *diag (the scene, a speed
   whose steady state or modes fail, fewer modes than opt->count); *out (free it with
   fmb_campbell_free) holds the speeds done before a failure as well. */
FMB_API int fmb_campbell(const fmbSceneSource* scene, const fmbCampbellOptions* opt, const double* speeds, int nspeed,
                         fmbCampbell** out, fmbDiag* diag);
/* The same in steps, for a caller that computes the speeds' modes itself (in other processes):
   an empty diagram; the modes at one speed (at least opt->count + FMB_CAMPBELL_EXTRA_MODES of
   them when the system has that many, so that a mode crossing from above can be followed); and
   the modes at speeds[c->done] added in order (c takes `modes` over, also on failure). */
#define FMB_CAMPBELL_EXTRA_MODES 6
FMB_API fmbCampbell* fmb_campbell_new(const double* speeds, int nspeed, int count);
FMB_API int fmb_campbell_modes_at(const fmbSceneSource* scene, const fmbCampbellOptions* opt, double speed,
                                  fmbModes** modes, fmbDiag* diag);
FMB_API int fmb_campbell_add(fmbCampbell* c, fmbModes* modes, fmbDiag* diag);
FMB_API void fmb_campbell_free(fmbCampbell* c);

/* ---------------------------------------------------------------------------------------------
 * One scene, several models (engine/models.c; docs/models.md): the scene run once per model,
 * the named bodies' `model` key set to it (`bodies.NAME.model=M`, as --set would), the outputs
 * side by side in one CSV: t (from the longest run), then each model's columns as NAME@MODEL. A
 * model whose run stops keeps its rows; its later cells are `nan`.
 * ------------------------------------------------------------------------------------------- */
#define FMB_MODELS_MAX 8
typedef struct fmbModelsResult {
  int ran;                  /* models run, in order (their entries below are filled) */
  int code[FMB_MODELS_MAX]; /* fmb_run's result for each */
  fmbStats stats[FMB_MODELS_MAX];
  fmbDiag diag[FMB_MODELS_MAX]; /* why a model's run stopped (code 0: it did not) */
} fmbModelsResult;
/* opt->csv_path (required, a file: not "-") receives the merged table; each run takes quiet and
   stop from opt, and its animation goes to MODEL/ below opt->vtk_dir (else below the scene's `vtk`
   key; none without either), of every opt->vtk_every-th row. A model named twice is bad input. Every model is loaded before any runs (a misspelt model is bad input, not a late
   failure). Returns 0, or the largest exit code of the runs, or an exit code for the scene, the
   models or the merged file with *diag saying why; *res (may be NULL) says what each run did. */
FMB_API int fmb_run_models(const fmbSceneSource* scene, const char* const* bodies, int nbody, const char* const* models,
                           int nmodel, const fmbRunOptions* opt, fmbModelsResult* res, fmbDiag* diag);

/* ---------------------------------------------------------------------------------------------
 * Writing a file without losing one (engine/safe_file.c): the content goes to a temporary file
 * beside `path` that replaces it only on fmb_safe_close(f, 1); fmb_safe_close(f, 0) removes the
 * temporary file and leaves `path` as it was. "-" and non-regular paths (a FIFO, /dev/null) are
 * written straight through and never removed. The caller owns the handle until fmb_safe_close.
 * ------------------------------------------------------------------------------------------- */
typedef struct fmbSafeFile fmbSafeFile;
/* A set of input files that a writer must not replace (fmbInputs): whatever name or link leads to
   one (same device and inode), until the noted name no longer leads to that file (deleted or
   replaced since: its inode may be reused). There is no process-wide list: each model keeps the
   set of the files fmb_load read for it (the scene, its table files, the scene's plugins;
   fmb_model_inputs) and the writers of its runs check against it; a program that reads more
   (samples, references, plugins it loads itself) keeps a set of its own and opens its files with
   fmb_safe_open_guarded. A set has its own lock: it may be shared by threads.
   note: 0, or -1 (not a regular file, or out of memory); notes are counted, each undone by one
   forget. add: every file of `from` noted in `to` (0, or -1). at: 1 when `path` is one of the set's
   files, with the name it was noted under in name[namelen] (may be NULL), else 0. */
typedef struct fmbInputs fmbInputs;
FMB_API fmbInputs* fmb_inputs_new(void); /* NULL when out of memory */
FMB_API void fmb_inputs_free(fmbInputs* in);
FMB_API int fmb_inputs_note(fmbInputs* in, const char* path);
FMB_API void fmb_inputs_forget(fmbInputs* in, const char* path);
FMB_API int fmb_inputs_add(fmbInputs* to, const fmbInputs* from);
FMB_API int fmb_inputs_at(const fmbInputs* in, const char* path, char* name, size_t namelen);
FMB_API int fmb_inputs_count(const fmbInputs* in);
/* the files fmb_load read for m (valid while m is); NULL for a NULL model */
FMB_API const fmbInputs* fmb_model_inputs(const fmbModel* m);
/* NULL with the reason in err on failure, among them a target that is one of `inputs` (may be NULL:
   nothing refused on that ground; fmb_safe_open is fmb_safe_open_guarded with NULL) */
FMB_API fmbSafeFile* fmb_safe_open_guarded(const char* path, const fmbInputs* inputs, char* err, size_t errlen);
FMB_API fmbSafeFile* fmb_safe_open(const char* path, char* err, size_t errlen);
FMB_API FILE* fmb_safe_stream(fmbSafeFile* f); /* a stdio stream over it (closed by fmb_safe_close) */
FMB_API int fmb_safe_fd(const fmbSafeFile* f);
FMB_API int fmb_safe_is_temporary(const fmbSafeFile* f);
/* the file to write when another program writes it (gnuplot): the temporary file, or the target
   written through; NULL for stdout */
FMB_API const char* fmb_safe_write_path(const fmbSafeFile* f);
/* keep != 0: put the content in place (rename); 0: discard it. 0, or -1 with errno on failure */
FMB_API int fmb_safe_close(fmbSafeFile* f, int keep);

/* "did you mean": of words[0..n) (NULL entries skipped), the nearest to `typed` when `typed` is
   a typo of it (an edit distance, with adjacent transpositions, of 1 in a word of up to 4
   letters, 2 from 5 on), else NULL. The scene loader's unknown keys and the program's unknown
   commands are matched by this one rule. */
FMB_API const char* fmb_nearest_word(const char* typed, const char* const* words, int n);

#ifdef __cplusplus
}
#endif
#endif
