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

#include <stddef.h>
#include <stdio.h>

#ifdef __cplusplus
extern "C" {
#endif

#define FMB_ABI_VERSION 1

/* ---------------------------------------------------------------------------------------------
 * Diagnostics: the first error wins; file/line/col are 1-based, 0 when not applicable.
 * ------------------------------------------------------------------------------------------- */
#define FMB_EXIT_OK 0
#define FMB_EXIT_BAD_INPUT 2
#define FMB_EXIT_SOLVER 3

typedef struct fmbDiag {
  int code;        /* 0 none, FMB_EXIT_BAD_INPUT or FMB_EXIT_SOLVER */
  char file[512];  /* scene path, or "--set" for an override */
  int line, col;
  char msg[1024];
} fmbDiag;

/* ---------------------------------------------------------------------------------------------
 * Scene parsing API for plugins (the one YAML accessor layer, engine/yaml_get.c).
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
  FMB_NONNEGATIVE = 1 << 2  /* >= 0 */
};

int fmb_get_double(fmbParser* p, fmbNode map, const char* key, unsigned flags, double* out);
int fmb_get_int(fmbParser* p, fmbNode map, const char* key, unsigned flags, long lo, long hi, int* out);
int fmb_get_vec2(fmbParser* p, fmbNode map, const char* key, unsigned flags, double out[2]);
/* one of a NULL-terminated list of words; *out is the index */
int fmb_get_choice(fmbParser* p, fmbNode map, const char* key, unsigned flags, const char* const* choices,
                   int* out);
/* a body by name ("ground" is always defined); *out is the body index */
int fmb_get_body(fmbParser* p, fmbNode map, const char* key, unsigned flags, int* out);
/* a joint defined earlier in the file, by name; *out is the joint index */
int fmb_get_joint(fmbParser* p, fmbNode map, const char* key, unsigned flags, int* out);
/* body index and local point of attachment k (0 or 1) of an already parsed joint */
int fmb_joint_attachment(fmbParser* p, int joint, int k, int* body, double local[2]);
/* a plugin-level check failed at `node` (a value node or the item's mapping) */
int fmb_parse_error(fmbParser* p, fmbNode node, const char* fmt, ...)
#if defined(__GNUC__)
    __attribute__((format(printf, 3, 4)))
#endif
    ;
/* the value node of `key` in `map`, or -1 if absent (marks the key known) */
fmbNode fmb_find_key(fmbParser* p, fmbNode map, const char* key);

/* ---------------------------------------------------------------------------------------------
 * Evaluation environment shared by all plugins.
 * ------------------------------------------------------------------------------------------- */
typedef struct fmbEnv {
  double gravity[2];  /* m/s^2, global frame */
  int has_gravity;    /* 0 when the scene has g = 0: plugins skip gravity terms entirely */
} fmbEnv;

typedef struct fmbEnergy {
  double kinetic, strain, gravity, spring;
} fmbEnergy;

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
  int (*residual)(const void* self, const fmbEnv* env, const double* q, const double* v, const double* a,
                  double* R, double* work);
  /* position and angle of a material point given in the body's reference configuration
     (`local`, body frame), with their derivatives wrt q (dpos_dq: 2 x ncoord row-major, may be
     NULL; dangle_dq: ncoord, may be NULL). Joints and force elements see bodies only this way. */
  int (*marker)(const void* self, const double* q, const double local[2], double pos[2], double* angle,
                double* dpos_dq, double* dangle_dq, double* work);
  /* optional */
  size_t (*nwork)(const void* self); /* scratch doubles the engine allocates once; NULL = 0 */
  /* dense ncoord x ncoord column-major blocks K = dR/dq, C = dR/dv, M = dR/da; NULL = the engine
     differentiates `residual` numerically (engine/fd.c) */
  int (*jacobian)(const void* self, const fmbEnv* env, const double* q, const double* v, const double* a,
                  double* K, double* C, double* M, double* work);
  void (*energy)(const void* self, const fmbEnv* env, const double* q, const double* v, fmbEnergy* e,
                 double* work);
  /* named outputs beyond the frame's x, y, theta, omega, vx, vy (which the engine provides for
     every body with ncoord >= 3): lookup returns an id >= 0 or -1; output evaluates one id. */
  const char* const* output_names; /* NULL-terminated, for listings */
  int (*output_lookup)(const void* self, const char* quantity);
  int (*output)(const void* self, int id, const double* q, const double* v, double* value, double* work);
  void (*describe)(const void* self, FILE* f); /* rest of one line after "body 'NAME' (TYPE, N coordinates): ": active terms, variant; ends with a newline */
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
  int (*nrows)(const void* self);                /* NULL = 0 (a pure force element) */
  int (*attachment)(const void* self, int k, int* body, double local[2]);
  int (*constraint)(const void* self, const fmbJointEval* ev, double* phi, double* phi_q, double* phi_t,
                    double* phi_tt);
  int (*force)(const void* self, const fmbJointEval* ev, double* Q); /* adds to Q */
  double (*energy)(const void* self, const fmbJointEval* ev);       /* spring potential */
  const char* const* output_names;
  int (*output_lookup)(const void* self, const char* quantity);
  int (*output)(const void* self, int id, const fmbJointEval* ev, double* value);
  void (*describe)(const void* self, FILE* f);
} fmbJointType;

/* what a joint may ask of the evaluation context */
double fmb_eval_time(const fmbJointEval* ev);
int fmb_eval_ncoord(const fmbJointEval* ev, int k);      /* coordinates of body k (0 for ground) */
const double* fmb_eval_q(const fmbJointEval* ev, int k);
const double* fmb_eval_v(const fmbJointEval* ev, int k);
/* position and angle of body k's material point `local`; derivatives wrt body k's coordinates
   go to dpos_dq (row 0 at dpos_dq[0..nk), row 1 at dpos_dq[ld..ld+nk)) and dangle_dq[0..nk);
   either may be NULL. Use ld = the joint's column count to write straight into phi_q rows. */
int fmb_marker(const fmbJointEval* ev, int k, const double local[2], double pos[2], double* angle,
               double* dpos_dq, int ld, double* dangle_dq);
/* scratch for the joint: at least 2 x (ncoord(body 0) + ncoord(body 1)) doubles */
double* fmb_eval_scratch(const fmbJointEval* ev);
/* first column of body k in phi_q / Q (0 for body 0, ncoord(body 0) for body 1) */
int fmb_eval_col0(const fmbJointEval* ev, int k);

/* ---------------------------------------------------------------------------------------------
 * Numerics shared by plugins (one quadrature for the whole project, engine/quad.c).
 * ------------------------------------------------------------------------------------------- */
#define FMB_GAUSS_MAX 10
/* n-point Gauss-Legendre rule on [0, 1] (1 <= n <= FMB_GAUSS_MAX); exact to degree 2n-1.
   Returns 0, or -1 for an unsupported n. */
int fmb_gauss_legendre01(int n, double* x, double* w);

/* ---------------------------------------------------------------------------------------------
 * Registry: the types a loader knows. The engine names no type; the program hands it a table.
 * ------------------------------------------------------------------------------------------- */
typedef struct fmbRegistry {
  const fmbBodyType* const* bodies;
  int nbodies;
  const fmbJointType* const* joints;
  int njoints;
} fmbRegistry;

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
} fmbStats;

typedef struct fmbRunOptions {
  const char* csv_path; /* NULL or "-" = stdout */
  int quiet;            /* no progress lines on stderr */
} fmbRunOptions;

/* Load `path`, applying "PATH=VALUE" overrides (e.g. "solver.rtol=1e-8",
   "bodies.beam.elements=32"). Returns NULL with *diag filled on error. */
fmbModel* fmb_load(const char* path, const char* const* overrides, int noverrides, const fmbRegistry* reg,
                   fmbDiag* diag);
/* Integrate from the scene's t0 to t_end, writing CSV rows as it goes. Returns 0 or an exit code
   (FMB_EXIT_SOLVER) with *diag saying when and why it stopped. */
int fmb_run(const fmbModel* m, const fmbRunOptions* opt, fmbStats* stats, fmbDiag* diag);
void fmb_free(fmbModel* m);
/* the solver settings a loaded scene runs with (its values after --set overrides) */
typedef struct fmbSolverInfo {
  double t0, t_end, rtol, atol, output_step;
} fmbSolverInfo;
/* 0, or -1 when an argument is NULL */
int fmb_model_solver(const fmbModel* m, fmbSolverInfo* out);
/* one line per body and joint: type and active terms */
void fmb_describe(const fmbModel* m, FILE* f);
void fmb_print_stats(const fmbStats* s, FILE* f);

#ifdef __cplusplus
}
#endif
#endif
