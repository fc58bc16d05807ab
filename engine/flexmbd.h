/*
 * flexmbd.h — the public header for programs: load a scene, run it or step it, analyse it
 * (statics, modes, Campbell diagrams, several models), and write its outputs.
 *
 * Body and joint authors include flexmbd_plugin.h instead (it includes this one): the type tables,
 * the YAML accessors of a parse, the evaluation helpers and the plugin descriptor. A program
 * sees those tables only as opaque types (fmbBodyType, fmbJointType, fmbPlugin) that it hands on.
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

/* The program ABI: the shared library's SOVERSION (libflexmbd.so.FMB_SOVERSION). It changes when
   a function of this header is removed or changes its signature, or a struct a program allocates
   (fmbDiag, fmbStats, fmbRunOptions, ...) changes its layout. The plugin ABI is a number of its own
   (FMB_PLUGIN_ABI_MAJOR/MINOR, flexmbd_plugin.h): a new analysis or run option does not break
   plugins. */
#define FMB_SOVERSION 3

/* what the shared library exports (it is built with hidden visibility, docs/plugins.md) */
#if defined(__GNUC__)
#define FMB_API __attribute__((visibility("default")))
#else
#define FMB_API
#endif

/* the library's release, "MAJOR.MINOR.PATCH" (what `flexmbd --version` prints first), at run time */
FMB_API const char* fmb_version(void);
/* the plugin ABI the library implements, as FMB_PLUGIN_ABI encodes it (flexmbd_plugin.h):
   major * 1000 + minor */
FMB_API int fmb_plugin_abi(void);

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
 * The registry: the body and joint types a load knows. A plugin is a set of types behind one
 * descriptor (flexmbd_plugin.h); the built-in types are one too (fmb_builtin_plugin), and every
 * type enters a registry through fmb_registry_add, which checks the plugin ABI and the required
 * ops. The engine names no type; the program hands fmb_load a registry.
 * ------------------------------------------------------------------------------------------- */
typedef struct fmbBodyType fmbBodyType;   /* a body type's table (flexmbd_plugin.h) */
typedef struct fmbJointType fmbJointType; /* a joint or force type's table */
typedef struct fmbPlugin fmbPlugin;       /* a plugin's descriptor */

typedef struct fmbRegistry fmbRegistry;           /* growable, any number of types */
FMB_API fmbRegistry* fmb_registry_new(void);      /* empty; NULL when out of memory */
FMB_API void fmb_registry_free(fmbRegistry* reg); /* types and loaded code stay valid */
/* register every type of `plugin` (origin: "built-in" or the file, for messages). Refuses, with
   *diag filled (exit code 2), another plugin ABI (flexmbd_plugin.h's rule), a type without a name or a required op, and a name
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
  /* messages of the run that were warnings (text starting "warning"), through its warn handler;
     notes and progress lines are not counted. The stats line ends with warnings=N. */
  long warnings;
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
/* the scene's `dimension:`: 2 (planar) or 3 (spatial, docs/spatial.md); 0 for NULL */
FMB_API int fmb_model_dimension(const fmbModel* m);
FMB_API int fmb_model_body(const fmbModel* m, int i, const char** name, const char** type);
/* the scene's joints: their count, and joint i's name and `type:` (0 <= i < count; 0, or -1) */
FMB_API int fmb_model_njoint(const fmbModel* m);
FMB_API int fmb_model_joint(const fmbModel* m, int i, const char** name, const char** type);
/* What a mechanism looks like (engine/drawing.c), fixed at load: the points and cells that the
   ParaView animation (--vtk) and `flexmbd view` draw, from the types' ops alone: a body with a
   `centreline` is a polyline through its stations; any other body with a frame (ncoord >= 3) is the
   outline through the points its joints attach to (closed from three points) and its frame's x and
   y axes; a joint with constraint rows is a vertex at its first point; a force element with two
   points (a spring) is the line between them.
   In a spatial scene (dimension 3, docs/spatial.md) the drawing is the same from the spatial ops:
   points are material points of a body's marker3 (local3, 3 per point; fmbDrawPoint.local holds
   their x, y); a centreline's stations [x, y] are the body's [x, y, 0]; any other spatial body is
   the line or polygon through its joints' attachment3 points (in the joints' order) and its
   frame's x, y and z axes; a joint is a vertex at its first attachment3 point. */
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
  /* appended (issue 34): the scene's dimension, 2 or 3, and for 3 the points' body-frame
     coordinates [x, y, z] (3 per point, point i at 3 i; NULL in a planar drawing) */
  int dimension;
  double* local3;
} fmbDrawing;
/* the SI unit of a CSV column the engine itself defines ("t": s; BODY.x: m; BODY.omega: rad/s;
   JOINT.power: W; JOINT.work and energy.*: J; JOINT.reaction_x: N; reaction_torque: N m;
   BODY.shapeK_x: m), or NULL (a type's own output, whose unit is not declared; unknown names) */
FMB_API const char* fmb_output_unit(const char* column);
/* the same, and for a type's own output (BODY.tip_v, JOINT.torque) the unit the registry's types
   declare for that quantity (output_units; a numbered name such as node12_v matches nodeK_v), when
   every type that declares the quantity agrees on it; NULL otherwise. reg may be NULL. */
FMB_API const char* fmb_output_unit_in(const fmbRegistry* reg, const char* column);
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
/* set the state (issue 34): time() = t (t0 <= t <= t_end) and y (and y', NULL = zeros) as
   fmb_data_state gives them, e.g. one saved earlier, of another data object of the same model, or
   changed by the program. No step history crosses the jump: the next advance first makes the state
   consistent at t, as after an input's jump (q onto the constraints, v onto their rates, then the
   accelerations and multipliers), so the y' and multipliers given are only a start. A spatial
   body's coordinates are [r, p] with Euler parameters p of any nonzero length (docs/spatial.md):
   a p scaled by any factor is the same pose. The joints' work integrals go on from their values.
   0, or FMB_EXIT_BAD_INPUT (misuse, before fmb_init, y NULL, a value not finite, t outside
   [t0, t_end]: nothing changed, *diag says why). */
FMB_API int fmb_data_set_state(const fmbModel* m, fmbData* d, double t, const double* y, const double* yp,
                               fmbDiag* diag);
/* the scene's outputs: their number (the CSV's columns after t), the name of output i (e.g.
   "beam.tip_v"; NULL out of range) and their values at time() into out[fmb_noutput(m)], the very
   numbers the CSV row at that time holds. fmb_outputs: 0, FMB_EXIT_SOLVER when a value is not
   finite (out still filled), FMB_EXIT_BAD_INPUT for misuse */
FMB_API int fmb_noutput(const fmbModel* m);
FMB_API const char* fmb_output_name(const fmbModel* m, int i);
FMB_API int fmb_outputs(const fmbModel* m, fmbData* d, double* out);
/* The output grid fmb_run writes, one row at each time: row k (0 <= k < fmb_row_count(m)) is at
   t0 + k output_step, the last one at t_end (the scene's solver settings). fmb_row_count: 0 for
   NULL; fmb_row_time: NaN for NULL or k out of range. Every loop over the rows (fmb_run, the
   Python package, bench/) takes the times from here. */
FMB_API long fmb_row_count(const fmbModel* m);
FMB_API double fmb_row_time(const fmbModel* m, long k);
/* One output row for fmb_run_rows: its time and the fmb_noutput(m) values of fmb_outputs (valid
   during the call only). Return 0 to go on; non-zero stops the run after this row. */
typedef int (*fmbRowFn)(void* user, double t, const double* values, int nvalues);
/* A whole run through the library's one loop (the loop fmb_run writes its CSV from): fmb_init,
   then row(t, values) at t0 and after fmb_advance to every later time of the grid (fmb_row_time).
   Returns 0; FMB_EXIT_INTERRUPTED when row returned non-zero (before t_end) or the run was cancelled
   (fmb_data_cancel); FMB_EXIT_SOLVER with *diag when an advance failed or an output is not finite
   (that row is not delivered); FMB_EXIT_BAD_INPUT for misuse. The rows delivered before stay
   delivered; fmb_data_stats tells where the run got to. */
FMB_API int fmb_run_rows(const fmbModel* m, fmbData* d, fmbRowFn row, void* user, fmbDiag* diag);
/* the integrator's counters so far (all backends of this run), t_reached = time(), the time
   spent in fmb_init and fmb_advance (cpu_s: each call timed on the monotonic clock, the sum
   bounded by the calling thread's CPU time since fmb_init, read here: the thread's CPU time in
   those calls while it keeps its core; docs/api.md), the warnings given since fmb_init: 0, or
   FMB_EXIT_BAD_INPUT */
FMB_API int fmb_data_stats(const fmbData* d, fmbStats* st);
/* on (the default): fmb_init and fmb_advance read the monotonic clock (no system call on Linux:
   vDSO) and fmb_run_rows the thread's CPU clock once at its start and end, for st.cpu_s; 0: they
   do not, and st.cpu_s stays as it was (a program that times itself; bench/inputs.sh measures
   both for a controller setting an input at 1 kHz, docs/api.md "Inputs"). NULL or a freed d:
   nothing. */
FMB_API void fmb_data_set_timing(fmbData* d, int on);
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
  /* spatial scenes (dimension 3; appended): each mode's FMB_FAMILY_* (count of them; NULL when not
     classified: a planar scene, a state without rotation unless fmb_modes_classify was called),
     and the spin axis and a point on it of the steady rotation (speed 0: axis [0, 0, 1]) */
  int* family;
  double axis[3], center[3];
} fmbModes;

/* a mode's family relative to a spin axis (fmb_modes_classify, docs/analysis.md): where the
   motion of the bodies' centreline stations (or frame origins) points — along the axis, out of
   the plane of rotation (flap, flapwise); in that plane across the radius (lag, lead-lag or
   chordwise); along the radius (axial); or a turn about the radius with the stations at rest
   (torsion) */
enum { FMB_FAMILY_NONE = 0, FMB_FAMILY_FLAP = 1, FMB_FAMILY_LAG = 2, FMB_FAMILY_AXIAL = 3, FMB_FAMILY_TORSION = 4 };
/* "flap", "lag", "axial", "torsion", or "mode" for FMB_FAMILY_NONE and anything else */
FMB_API const char* fmb_family_name(int family);

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
/* Classify the modes of a spatial scene's state y (those fmb_modes computed there) against the
   spin axis `axis` (unit) through `center`: fills modes->family (allocated here, freed by
   fmb_modes_free) and modes->axis, ->center. fmb_modes calls it itself about a steady rotation;
   a caller with a static state (a Campbell diagram's speed 0) gives the axis of the sweep.
   Returns 0, FMB_EXIT_BAD_INPUT (a planar scene, mismatched modes) or FMB_EXIT_SOLVER. */
FMB_API int fmb_modes_classify(const fmbModel* m, double t, const double* y, fmbModes* modes, const double axis[3],
                               const double center[3], fmbDiag* diag);

/* The same analyses on a data object (fmb_data_new): they take their scratch from it, so a program
   holding one runs statics and modes without the engine making a workspace per call (fmb_static
   and fmb_modes make a data object for the call). The model's inputs are as d holds them
   (fmb_set_input) and the bodies' blocks a run's next Jacobian may reuse are left alone: advancing
   after an analysis gives the bytes advancing without it gives.
   fmb_static_data: fmb_static's equilibrium (from the scene's poses, at opt->t); on success it
   becomes d's state at res->t (fmb_data_state, fmb_outputs, fmb_modes_data read it) and d's run
   ends there: fmb_advance asks for fmb_init (`initial: static` runs from the equilibrium). On
   failure d's state is unchanged.
   fmb_modes_data: fmb_modes about d's state (fmb_data_time, fmb_data_state: a run's between
   advances, or fmb_static_data's); d is only read. FMB_EXIT_BAD_INPUT with *diag for misuse (a
   NULL, freed or other model's d, no state yet) as the stepping calls. */
FMB_API int fmb_static_data(const fmbModel* m, fmbData* d, const fmbStaticOptions* opt, fmbStaticResult* res,
                            fmbDiag* diag);
FMB_API int fmb_modes_data(const fmbModel* m, fmbData* d, int count, int method, fmbModes** out, fmbDiag* diag);
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
  /* appended: nspeed x count, each followed mode's FMB_FAMILY_* at each speed (spatial scenes;
     FMB_FAMILY_NONE for planar ones) */
  int* family;
} fmbCampbell;
/* the family a followed mode k has at most of the speeds done (FMB_FAMILY_NONE: planar) */
FMB_API int fmb_campbell_family(const fmbCampbell* c, int k);

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

#ifdef __cplusplus
}
#endif
#endif
