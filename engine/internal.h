/* internal.h — engine-private structures. Model = what the scene fixed (read-only while
 * integrating); state/workspace = what integration changes, allocated once at setup. */
#ifndef FLEXMBD_INTERNAL_H
#define FLEXMBD_INTERNAL_H

#include <yaml.h>

#include "flexmbd_cli.h"
#include "flexmbd_plugin.h"

#define FMB_NAME_MAX 64
#define FMB_WORLD 0 /* body index of the fixed world frame, named "ground" */

typedef struct fmbBodyInst {
  char name[FMB_NAME_MAX];
  const fmbBodyType* type; /* NULL for the world frame */
  void* self;
  int qadr, nq; /* slice of the coordinate vector */
  fmbNode node; /* its item in the scene, for messages about it after parsing */
  size_t workadr, nwork;
  int zadr, nz;     /* auxiliary algebraic unknowns (fmbBodyType.naux): slice of z, at m->zoff in y */
  int aux_iterated; /* fmbBodyType.aux_iterated: Newton iterates on z (not eliminated) */
  /* sparse body block (fmbBodyType.pattern), CSC over nq + nz rows and columns; pnnz < 0: dense.
     Columns are grouped in colours that share no row, for differencing (fd.c). */
  long pnnz;
  long* pcolptr;
  int* prowind;
  int ncolor;
  int *color_ptr, *color_col; /* columns of colour k: color_col[color_ptr[k] .. color_ptr[k+1]) */
  /* with an analytic pattern_jacobian: the declared pairs' count and each pair's entry in the CSC
     (duplicates share one), so the op's values in pair order are summed into place */
  long npair;
  long* ppos;
  /* fmbBodyType.marker3 when the table has it (ABI 3.3 or later), else NULL */
  int (*marker3)(const void* self, const double* q, const double local[3], double pos[3], double R[9], double* dpos_dq,
                 double* rot_dq, int ld, double* work);
  /* fmbBodyType.gauge when the table has it (ABI 3.4 or later), else NULL */
  int (*gauge)(const void* self, const double* q, double* dir);
} fmbBodyInst;

typedef struct fmbJointInst {
  char name[FMB_NAME_MAX];
  const fmbJointType* type;
  void* self;
  int body[2];   /* body indices, -1 = none */
  int line, col; /* its item in the scene (1-based), for messages after parsing (initial pose) */
  int ncol;      /* nq(body0) + nq(body1) */
  int rowadr, nrows;
  /* the columns (of the ncol) its constraint or force can depend on, found by evaluating it at
     random states at load (pattern.c): a joint at a beam's root touches the frame only */
  int nsup;
  int* sup;
  int input; /* its index among the model's inputs (fmbJointType.input said 1), or -1 */
} fmbJointInst;

typedef enum {
  FMB_OUT_TIME,
  FMB_OUT_FRAME,          /* body frame quantity: index into frame_names */
  FMB_OUT_BODY,           /* body plugin output */
  FMB_OUT_JOINT,          /* joint plugin output */
  FMB_OUT_JOINT_POWER,    /* power a joint feeds in: constraint forces lambda^T Phi_t + its forces Q . v */
  FMB_OUT_JOINT_WORK,     /* that power integrated from t0 (an IDA quadrature) */
  FMB_OUT_JOINT_REACTION, /* 0 x, 1 y: force on body2 at its point; 2 torque about that point */
  FMB_OUT_ENERGY,         /* 0 kinetic 1 strain 2 gravity 3 spring 4 total 5 balance */
  FMB_OUT_CONSTRAINT,     /* 0 position 1 velocity */
  FMB_OUT_SHAPE,          /* a centreline station of BODY.shape: id 0 x, 1 y (2 z in space) at body point `local` */
  FMB_OUT_POSE3           /* space: a body's origin and frame from marker3 (id: index into pose3_names) */
} fmbOutKind;

typedef struct fmbOutput {
  char name[2 * FMB_NAME_MAX + 32];
  fmbOutKind kind;
  int owner; /* body or joint index */
  int id;
  double local[2]; /* FMB_OUT_SHAPE: the station's reference point in the body frame */
} fmbOutput;

typedef struct fmbSolverSettings {
  double t0, t_end, rtol, atol, output_step, max_step;
  /* 1 when the scene gave solver.atol (one value for every coordinate and velocity, as it always
     was); 0 = derived from rtol and the bodies' scales (engine/tolerance.c). atol then holds the
     derived value for one metre of a 1 m body, which the checks that take one scalar use. */
  int atol_given;
  double min_step;    /* IDA's step floor: solver.min_step, default FMB_MIN_STEP_FRACTION (t_end - t0) */
  int min_step_given; /* 1 when the scene set solver.min_step (named in messages either way) */
  /* Newton systems: KLU on the Schur complement of the position rows (schur.c, default), KLU on
     the whole matrix, or SUNDIALS' dense LU on the whole matrix (a reference for both) */
  enum { FMB_LS_KLU = 0, FMB_LS_DENSE = 1, FMB_LS_KLU_FULL = 2 } linear_solver;
  int max_order; /* BDF order cap */
  /* ggl: the stabilized index-2 DAE of system.c (IDA); projected: index-1 equations with
     minimum-norm multipliers, positions and velocities projected onto the constraints after every
     step (CVODE), which passes singular configurations; auto (default): ggl, and where IDA fails
     at a rank-deficient constraint Jacobian the run continues with projected (step.c,
     docs/mechanisms.md) */
  enum { FMB_FORM_GGL = 0, FMB_FORM_PROJECTED = 1, FMB_FORM_AUTO = 2 } formulation;
  int positions_only; /* error test on q only (error_control: positions) */
  /* the GGL system's integrator: IDA (BDF) or Radau IIA of order 5 (integrator_radau.c), which
     keeps order 5 on undamped structural modes where BDF is capped at 2; NULL = auto (default):
     one of them per model by the rule of fmb_integrator_for (integrator_select.c) */
  const struct fmbIntegratorOps* integrator; /* one of fmb_integrators[] (integrator.h), never projected */
  long max_steps_per_output;
  /* the reduced Newton system's LU (schur.c): auto = schur_use_dense's rule; klu or dense to
     compare the two (solver.schur_lu; was the FMB_SCHUR_LU environment variable) */
  enum { FMB_SCHUR_LU_AUTO = 0, FMB_SCHUR_LU_KLU = 1, FMB_SCHUR_LU_DENSE = 2 } schur_lu;
  /* 0: formulation auto skips its scan of rigid closed loops for singular configurations
     (singular.c), so a run reaches the switch at the GGL backend's failure (solver.singular_scan:
     off; was FMB_TEST_NO_SINGULAR_WALK) */
  int singular_scan;
  /* > 0: the reduced Newton setup fails from its Nth factorization on, to exercise the fallback
     to klu_full (solver.fault_reduced_setup, a test's fault injection; was
     FMB_TEST_FAIL_REDUCED_SETUP). 0 = never */
  long fault_reduced_setup;
} fmbSolverSettings;

/* A step this small relative to the whole run means IDA is closing in on a singularity it
   cannot pass rather than resolving dynamics: the FOAC pendulum approached its mass matrix's
   singular crossing with steps of 1e-14 s, 100,000 of them per output (47 s) before giving up.
   With a floor, the first failure there ends the run and the usual diagnosis says why. */
#define FMB_MIN_STEP_FRACTION 1e-12

/* Without solver.atol a coordinate's absolute tolerance is rtol times this fraction of its body's
   length (engine/tolerance.c): the scenes' own rule before (rtol 1e-6 with atol 1e-8, 1e-8 with
   1e-10, for bodies about a metre long), now kept when rtol is lowered. */
#define FMB_ATOL_PER_RTOL 1e-2

/* The absolute tolerance of each of the ny unknowns (q, v, then multipliers and auxiliary
   unknowns): solver.atol as given, or derived from rtol and the bodies' scales (tolerance.c). */
void fmb_absolute_tolerances(const fmbModel* m, double* atol);

struct fmbModel {
  char path[512];
  int nbody, njoint;
  fmbBodyInst* body;
  fmbJointInst* joint;
  int nq;       /* coordinates */
  int nc;       /* constraint rows */
  int nz;       /* auxiliary algebraic unknowns of the bodies (fmbBodyType.naux) */
  int zoff;     /* their offset in y: y = [q | v | lambda | mu | z] */
  int ny;       /* unknowns of the DAE: 2 nq + 2 nc + nz */
  size_t nwork; /* total plugin scratch doubles */
  int max_joint_cols;
  fmbEnv env;
  fmbSolverSettings solver;
  int noutput;
  fmbOutput* output;
  int assemble;  /* `initial: assemble`: the initial projection may move bodies by any amount */
  int dimension; /* the scene's `dimension:`, 2 (planar, the default) or 3 (docs/spatial.md) */
  int need_energy, need_constraint, check_definiteness;
  int need_work;               /* a work or energy.balance column: integrate every joint's power */
  int nredundant;              /* constraint rows that repeat the others at t0 (found at load, ic.c) */
  int need_multipliers;        /* a reaction or power column: multipliers recomputed at each row */
  int bdf_order_cap;           /* min over bodies' max_bdf_order */
  int bodies_prefer_positions; /* a body's velocity_error_test said 0 */
  int initial_static;          /* scene `initial: static`: runs start from the static or steady state */
  int fresh_body_blocks;       /* a body's reuse_blocks said 0 */
  /* sparsity pattern of the iteration matrix, CSC, fixed at load */
  long nnz;
  long* colptr;      /* ny + 1 */
  long* rowind;      /* nnz */
  char vtk_dir[512]; /* the scene's `vtk` key: "" = no animation unless the run asks */
  /* inputs (fmb_set_input): the joints that take one, in scene order, and their `value:` */
  int ninput;
  int* input_joint;
  double* input_initial;
  /* the files this model was read from (scene, table files, the scene's plugins): no writer of its
     runs may replace one (engine/safe_file.c, fmb_model_inputs) */
  fmbInputs* inputs;
};

/* evaluation context a joint sees */
struct fmbJointEval {
  const fmbModel* m;
  const fmbJointInst* j;
  double t;
  const double* q; /* whole coordinate vector */
  const double* v;
  double* work;                        /* plugin scratch (body markers) */
  double* mk;                          /* 3 x max body ncoord: marker derivatives before scattering */
  double* js;                          /* 2 x max joint columns: the joint's own scratch */
  const struct fmbInputSetting* input; /* the inputs' settings (the workspace's, fmb_set_input) */
};

/* An input's setting (fmb_set_input, fmb_set_input_motion): from t_set on it is
   value + rate tau + accel tau^2 / 2, tau = t - t_set; rate and accel are 0 unless the program
   gave them (a load or drive held between settings). */
typedef struct fmbInputSetting {
  double value, rate, accel, t_set;
  int jumps; /* times a drive's setting has jumped away from where its last one led (warned once) */
  /* the largest |value| set so far: the input's scale, on which a setting within the solver's
     tolerance of where the last one led is no jump (step.c; a value near a zero crossing is not) */
  double magnitude;
} fmbInputSetting;
/* the setting's value and its rate and second rate at time t */
void fmb_input_at(const fmbInputSetting* s, double t, double* value, double* rate, double* accel);

/* ---- registry.c: a growable registry of types; plugin.c: loading plugins ---- */
struct fmbRegistry {
  int nbodies, njoints, cap_bodies, cap_joints;
  const fmbBodyType** bodies;
  const fmbJointType** joints;
  const char** body_names; /* NULL-terminated, for fmb_get_choice */
  const char** joint_names;
  char** body_origin; /* owned copies */
  char** joint_origin;
};
/* a copy of reg that a scene's plugins can be added to */
fmbRegistry* fmb_registry_clone(const fmbRegistry* reg);
/* the scene's `plugins:` list (a node, or -1 when absent): each path, relative to the scene's
   folder, is loaded into a copy of p->reg that p->reg then points to (p->own_reg) */
int fmb_scene_plugins(fmbParser* p, fmbNode list);

/* ---- yaml_get.c: document, overrides, accessors ---- */
struct fmbParser {
  yaml_document_t doc;
  int have_doc;
  const char* path;
  fmbDiag* diag;
  unsigned char* known; /* per node id: key node looked up */
  int* override_of;     /* per node id: index of the --set that made it, or -1 */
  int nnodes_cap;
  const char* const* overrides;
  const char* looked[64]; /* keys looked up in the current item, for "expected one of" */
  int nlooked;
  /* every key the current mapping may have, when known before its keys are read (fmbp_expect):
     the loader's own list (top level, solver, an item's name and type) and the item's type's
     declared params. They make "expected one of" complete, and let a missing required key be
     reported after an unknown key beside it (the typo that explains it, with did you mean). */
  const char* const* valid;
  const fmbParam* params;
  int expect_complete;          /* valid and params name every key the mapping may have */
  const char* what;             /* the mapping for messages ("body 'bob' (type rigid)"), or NULL */
  unsigned plausibility_warned; /* the plausibility rules (yaml_get.c) that have warned: once each */
  /* named materials and sections (top-level `materials:`/`sections:` maps): while a body or
     joint item is parsed, keys it does not have are looked up in the entries it names */
  fmbNode item;         /* the item being parsed, or -1 */
  fmbNode inherited[2]; /* its material and section entries, or -1 */
  fmbModel* model;      /* under construction */
  long key_compares;    /* string comparisons of the duplicate-key check (tests count them) */
  const fmbRegistry* reg;
  fmbRegistry* own_reg; /* the scene's plugins: a copy of the caller's registry, or NULL */
};

int fmbp_open(fmbParser* p, const char* path, const char* const* overrides, int noverrides, fmbDiag* diag);
void fmbp_close(fmbParser* p);
fmbNode fmbp_root(fmbParser* p);
yaml_node_t* fmbp_node(fmbParser* p, fmbNode n);
/* start a new item (resets the looked-up key list); check that every key of `map` was looked up */
void fmbp_begin_item(fmbParser* p);
/* the scene's top-level keys, the two required ones (solver, bodies) first (engine/scene.c) */
extern const char* const fmb_scene_keys[];
/* the keys the current mapping may have: `keys` (NULL-terminated) and a type's `params`, either
   NULL; `complete` when together they name every key it may have; `what` names the mapping in
   messages (kept as a pointer: it must live while the mapping is read). Reset by fmbp_begin_item. */
void fmbp_expect(fmbParser* p, const char* what, const char* const* keys, const fmbParam* params, int complete);
/* the keys every body and joint item takes besides its type's (scene.c): name, type, material,
   section; NULL-terminated */
extern const char* const fmb_item_keys[];
int fmbp_check_unknown(fmbParser* p, fmbNode map, const char* what);
int fmbp_is_map(fmbParser* p, fmbNode n);
int fmbp_is_seq(fmbParser* p, fmbNode n);
int fmbp_seq_len(fmbParser* p, fmbNode seq);
fmbNode fmbp_seq_item(fmbParser* p, fmbNode seq, int i);
const char* fmbp_scalar(fmbParser* p, fmbNode n); /* NULL if not a scalar */
int fmbp_get_name(fmbParser* p, fmbNode map, const char* key, char out[FMB_NAME_MAX]);

/* ---- diag.c ---- */
void fmb_diag_set(fmbDiag* d, int code, const char* file, int line, int col, const char* fmt, ...)
#if defined(__GNUC__)
    __attribute__((format(printf, 6, 7)))
#endif
    ;
/* an override as messages show it, on one line (control characters as \n, \t, \xNN) and cut
   after FMB_OVERRIDE_SHOWN characters so the reason that follows is never lost */
#define FMB_OVERRIDE_SHOWN 80
const char* fmbp_shown_override(const char* text, char buf[FMB_OVERRIDE_SHOWN + 32]);
/* a warning about a scene's node that does not stop the load: FILE:LINE:COL: warning: ... */
void fmbp_warning_at(fmbParser* p, fmbNode node, const char* fmt, ...)
#if defined(__GNUC__)
    __attribute__((format(printf, 3, 4)))
#endif
    ;

/* ---- system.c: DAE residual and iteration matrix ---- */
typedef struct fmbWorkspace fmbWorkspace;
/* made by fmb_data_new only (step.c): every run, analysis and check gets its scratch from a data
   object, the caller's or one its public wrapper makes (docs/api.md "Analyses on a data object") */
fmbWorkspace* fmb_workspace_new(const fmbModel* m);
/* mode_family.c: fmb_modes_classify on the caller's scratch (fmb_modes' data object) */
int fmb_modes_classify_with(const fmbModel* m, fmbWorkspace* w, double t, const double* y, fmbModes* md,
                            const double axis[3], const double center[3], fmbDiag* diag);
void fmb_workspace_free(fmbWorkspace* w);
long fmb_workspace_count(void); /* workspaces made so far in this process (a test's check) */
/* hold = 1: fmb_system_jacobian neither reads nor writes the bodies' block cache, which stays the
   run's (an analysis between advances must not change what the run's next Jacobian reuses) */
void fmb_workspace_hold_cache(fmbWorkspace* w, int hold);
double* fmb_workspace_plugin(fmbWorkspace* w);
/* the inputs' settings (m->ninput; the scene's `value:` at rest when the workspace is made, and
   again after fmb_workspace_inputs_reset) */
fmbInputSetting* fmb_workspace_inputs(fmbWorkspace* w);
void fmb_workspace_inputs_reset(const fmbModel* m, fmbWorkspace* w);
/* where messages of the run on this workspace go (fn NULL: the thread's default, warn.c) */
typedef struct {
  fmbWarnFn fn;
  void* user;
  long warnings; /* messages starting "warning" said through this sink (fmbStats.warnings) */
} fmbWarnSink;
fmbWarnSink* fmb_workspace_warn(fmbWorkspace* w);

/* ---- warn.c: the library's one way to say something (issue 24): to the workspace's sink, else
   the thread's default handler (fmb_set_warn), else stderr; w may be NULL (load time) ---- */
void fmb_warn(fmbWorkspace* w, const char* fmt, ...)
#if defined(__GNUC__)
    __attribute__((format(printf, 2, 3)))
#endif
    ;
/* a body declared its own sparse pattern (pattern op): dense whole-model systems are avoided */
int fmb_model_has_sparse_body(const fmbModel* m);
/* a type's output id for `quantity`: its output_lookup op, or without one the index in its
   output_names (-1: none) */
int fmb_type_output_id(int (*output_lookup)(const void*, const char*), const void* self, const char* const* names,
                       const char* quantity);
/* F(t, y, yp) of the stabilized index-2 (GGL) system; returns 0, >0 recoverable, <0 fatal */
int fmb_system_residual(const fmbModel* m, fmbWorkspace* w, double t, const double* y, const double* yp, double* F);
/* The same F with the bodies' auxiliary unknowns eliminated: each such body's rows from its
   `residual` (z eliminated), its Rz rows 0, so the z in y are placeholders. What the integrators
   iterate on (system.c says why), with the Newton matrix evaluated where z is consistent. */
int fmb_system_residual_eliminated(const fmbModel* m, fmbWorkspace* w, double t, const double* y, const double* yp,
                                   double* F);
/* The bodies' auxiliary unknowns in y (its slice at m->zoff) set to the z that satisfy Rz = 0 at
   (q, v, a = v' from yp), by aux_initial: 0 ok, nonzero not finite */
int fmb_system_aux_eliminate(const fmbModel* m, fmbWorkspace* w, double* y, const double* yp);
/* J = dF/dy + cj dF/dyp into a CSC matrix with the model's pattern (data only), or a dense
   column-major ny x ny matrix when dense != NULL. ewt: IDA's error weights (for FD steps).
   reuse_blocks: assemble with the bodies' K, C, M from the last fresh call (only cj changed). */
int fmb_system_jacobian(const fmbModel* m, fmbWorkspace* w, double t, double cj, const double* y, const double* yp,
                        const double* ewt, int reuse_blocks, double* csc_data, double* dense);
/* building blocks shared by the residual, Jacobian and initial conditions */
int fmb_joint_constraint(const fmbModel* m, fmbWorkspace* w, int j, double t, const double* q, const double* v,
                         double* phi, double* phi_q, double* phi_t, double* phi_tt);
int fmb_body_blocks(const fmbModel* m, fmbWorkspace* w, int b, const double* q, const double* v, const double* a,
                    const double* ewt, double* K, double* C, double* M);
int fmb_body_mass(const fmbModel* m, fmbWorkspace* w, int b, const double* q, const double* v, double* M);
int fmb_generalized_forces(const fmbModel* m, fmbWorkspace* w, double t, const double* q, const double* v,
                           double* Qtot);
int fmb_constraints_all(const fmbModel* m, fmbWorkspace* w, double t, const double* q, const double* v, double* phi,
                        double* phi_q_dense, double* phi_t, double* phi_tt);
/* gamma = -(Phi_q v)_q v - Phi_tt (nc), the right side of Phi_q a = gamma */
int fmb_constraints_gamma(const fmbModel* m, fmbWorkspace* w, double t, const double* q, const double* v,
                          double* gamma);
/* scratch for augmented.c: the joint column list, a joint's phi / phi_q / phi_t / phi_tt (0..3)
   buffers, one nq vector */
int* fmb_workspace_cols(fmbWorkspace* w);
double* fmb_workspace_joint_scratch(fmbWorkspace* w, int which);
double* fmb_workspace_qscratch(fmbWorkspace* w);
void fmb_energy(const fmbModel* m, fmbWorkspace* w, double t, const double* q, const double* v, fmbEnergy* e);
int fmb_joint_cols(const fmbModel* m, const fmbJointInst* j, int* cols);
/* the joint's columns its equations can depend on (indices into fmb_joint_cols' list, increasing) */
int fmb_joint_support(const fmbModel* m, fmbWorkspace* w, int j, int* sup);
void fmb_constraint_norms(const fmbModel* m, fmbWorkspace* w, double t, const double* q, const double* v, double* pos,
                          double* vel);
double fmb_joint_power(const fmbModel* m, fmbWorkspace* w, int j, double t, const double* q, const double* v,
                       const double* lambda);
/* force (global x, y) and torque (about the joint's point) that joint j's constraint forces exert
   on body2 (on body1, negated, when body2 has no frame); 0 or non-zero when not available */
int fmb_joint_reaction(const fmbModel* m, fmbWorkspace* w, int j, double t, const double* q, const double* v,
                       const double* lambda, double out[3]);
/* its spatial twin (dimension 3): force (global) and torque (global, about the joint's point,
   fmbJointType.attachment3, else about the body's origin) on body2 (body1's negated when body2
   is the ground), from a body's marker3: the wrench [F; tau] whose generalized force
   (dr/dq)^T F + G^T tau is the constraint force on the body's coordinates (least squares) */
int fmb_joint_reaction3(const fmbModel* m, fmbWorkspace* w, int j, double t, const double* q, const double* v,
                        const double* lambda, double out[6]);
/* work done by each joint since t0 (njoint entries, filled by the integrator before each row) and
   the force elements' potential energy at t0 (energy.balance) */
double* fmb_workspace_work(fmbWorkspace* w);
/* per constraint row: 1 = redundant, out of the equations; *count (may be NULL) = how many */
unsigned char* fmb_workspace_redundant(fmbWorkspace* w, int* count);
double* fmb_workspace_spring_energy0(fmbWorkspace* w);
/* the slot of an object a layer above keeps with the workspace (output.c's multipliers), freed
   with it by free_fn (set when not NULL): the workspace calls nothing above system.c */
void** fmb_workspace_attached(fmbWorkspace* w, void (*free_fn)(void*));
int fmb_joint_output(const fmbModel* m, fmbWorkspace* w, int j, int id, double t, const double* q, const double* v,
                     double* value);
/* reduced mass check for models that may lose definiteness: 0 ok, else body index + 1.
   singular_tol > 0 also flags a nearly singular matrix (a pivot^2 below singular_tol times its
   diagonal entry): used to explain a solver failure at the crossing itself. */
int fmb_check_mass(const fmbModel* m, fmbWorkspace* w, double t, const double* q, const double* v, double singular_tol);

/* ---- integrator_ida.c: the model's CSC pattern into a SUNDIALS sparse matrix (ny x ny, nnz) ---- */
struct _generic_SUNMatrix;
void fmb_sparse_pattern_into(const fmbModel* m, struct _generic_SUNMatrix* J);

/* ---- vector.c: optimized serial N_Vector arithmetic for IDA ---- */
struct _generic_N_Vector;
void fmb_vector_use_fast_ops(struct _generic_N_Vector* v);

/* ---- static.c: the analyses see a mixed form's body (aux_iterated) in its displacement form ---- */
int fmb_aux_iterated_consistent(const fmbModel* m, fmbWorkspace* w, double* y, const double* yp);
int fmb_aux_iterated_fold(const fmbModel* m, double* J); /* dense ny x ny; 0, -1 singular or no memory */

/* ---- dense.c: small dense linear algebra (initial conditions, checks) ---- */
int fmb_lu_factor(int n, double* A, int* piv); /* column-major, in place; 0 ok */
void fmb_lu_solve(int n, const double* LU, const int* piv, double* b);
int fmb_cholesky(int n, double* A); /* lower, in place; 0 ok, else k+1 */
int fmb_independent_rows(int nr, int nc, const double* A, double tol, int* order, double* work);

/* ---- ic.c ---- */
/* constraint rows that depend on the others at the initial state and nearby (redundant, not a
   singular start); 0 when none or when the joints cannot be satisfied (the run says why) */
int fmb_count_redundant(const fmbModel* m);
typedef struct fmbAugmented fmbAugmented; /* augmented.c: the index-1 system on a sparse matrix */
enum { FMB_AUG_MASS_FAILED = 1, FMB_AUG_FORCES_FAILED, FMB_AUG_SINGULAR, FMB_AUG_NOT_FINITE };
fmbAugmented* fmb_augmented_new(const fmbModel* m);
void fmb_augmented_free(fmbAugmented* g);
/* accelerations a (nq) and multipliers lambda (nc) consistent with q, v at t; either may be NULL */
int fmb_augmented_solve(const fmbModel* m, fmbWorkspace* w, fmbAugmented* g, double t, const double* q, const double* v,
                        const unsigned char* drop, double tikhonov, double* a, double* lambda);
/* project q onto Phi(q, t) = 0 and v onto Phi_q v + Phi_t = 0 (mass-orthogonal corrections with
   a Tikhonov shift, so rank-deficient Phi_q is fine); 0, or 1 not converged */
int fmb_project_state(const fmbModel* m, fmbWorkspace* w, fmbAugmented* g, double t, double* q, double* v);
/* x (nq) onto the tangent space Phi_q x = 0 of the last fmb_project_state (mass-orthogonally) */
int fmb_project_tangent(fmbWorkspace* w, fmbAugmented* g, double* x);
int fmb_augmented_failed_body(const fmbAugmented* g);
/* 1 when Phi_q at (q, t) has lower rank, to the relative tolerance tol, than its rows less the
   redundant ones: a singular configuration (or near one) */
int fmb_rank_deficient_at(const fmbModel* m, fmbWorkspace* w, double t, const double* q, const double* v, double tol);
/* "joint 'a' row 2, ..." for the constraint rows marked in rows[] */
void fmb_name_rows(const fmbModel* m, const unsigned char* rows, char* buf, size_t len);
/* Tikhonov shift (relative) that makes the multipliers of redundant rows minimum-norm */
#define FMB_MIN_NORM_SHIFT 1e-10
int fmb_initial_conditions(const fmbModel* m, fmbWorkspace* w, double* y, double* yp, fmbStats* st, fmbDiag* diag);
/* a consistent state at t from y's q and v (projected onto the constraints), for a restart after
   an input changed (step.c); 0 or an exit code with diag set */
int fmb_consistent_state(const fmbModel* m, fmbWorkspace* w, double t, double* y, double* yp, fmbDiag* diag);
/* how closely the joints hold at t0 and after a restart; coordinates whose double cannot resolve
   it (|q| DBL_EPSILON above it) are refused, in a scene (ic.c) as from fmb_set_input (step.c) */
#define FMB_IC_PHI_TOL 1e-10 /* m or rad: joints hold to 0.1 nm, 0.1 nrad at t0 */

/* ---- static.c ---- */
/* the poses q at time t against the joints, as a run checks them (ic.c): joints that cannot be
   satisfied, or poses they would move by more than FMB_ASSEMBLY_TOL without `initial: assemble`,
   are bad input (FMB_EXIT_BAD_INPUT, named at the joint); q is left projected onto them */
int fmb_pose_check(const fmbModel* m, fmbWorkspace* w, double t, double* q, fmbDiag* diag);
int fmb_static_solve(const fmbModel* m, fmbWorkspace* w, const fmbStaticOptions* opt, double* y, double* yp,
                     fmbStaticResult* res, fmbDiag* diag);
/* a steady rotation refused (rotation3.c; static.c's planar fit uses it too): the drives are not one
   rigid rotation, or they accelerate; sets *diag, returns FMB_EXIT_BAD_INPUT */
enum { FMB_STEADY_NOT_RIGID, FMB_STEADY_ACCELERATING };
int fmb_steady_refusal(const fmbModel* m, int why, double t, double value, fmbDiag* diag);
/* v and a (nq each) of every body's frame turning rigidly at `speed` about `center` */
void fmb_rigid_rotation(const fmbModel* m, double speed, const double center[2], const double* q, double* v, double* a);
/* rotating-frame terms of a steady rotation: K += W C E + W^2 M E^2, Cg += 2 W M E (if not NULL);
   nq x nq column-major with leading dimension ld */
void fmb_rotation_terms(const fmbModel* m, double speed, const double* C, const double* M, int ld, double* K,
                        double* Cg);

/* ---- rotation3.c: statics and modes of spatial scenes (docs/analysis.md) ---- */
/* a rigid rotation in space: `speed` (rad/s) about the unit `axis` through `center` */
typedef struct {
  double speed, axis[3], center[3];
  double screw; /* internal: the fit's translation along the axis (0 for a rotation) */
} fmbRotation3;
/* the bodies' gauge directions (fmbBodyType.gauge): their count; into D (nq x ng column-major,
   leading dimension ld) the directions over all coordinates, returning ng (-1: a body gives too many) */
int fmb_gauge_count(const fmbModel* m, const double* q);
int fmb_gauge_rows(const fmbModel* m, const double* q, double* D, int ld);
/* the coordinate velocities of every body's rigid motion z = [Omega; s] (origin velocity
   Omega x r0 - s): V nq x 6 column-major; -1 when a body has no marker3 */
int fmb_rotation3_basis(const fmbModel* m, fmbWorkspace* w, const double* q, double* V);
/* v and a (nq each) of the steady rotation rot at q */
int fmb_rigid_rotation3(const fmbModel* m, fmbWorkspace* w, const fmbRotation3* rot, const double* q, double* v,
                        double* a);
/* E (nq x nq, leading dimension ld): the generator of the unit-speed rotation about rot's axis */
int fmb_rotation3_generator(const fmbModel* m, fmbWorkspace* w, const fmbRotation3* rot, const double* q, double* E,
                            int ld);
/* K += W C E + W^2 M E^2, Cg += 2 W M E (if not NULL) with E nq x nq (leading dimension nq) and
   C, M, K, Cg at leading dimension ld */
void fmb_rotation3_terms(int nq, double speed, const double* E, const double* C, const double* M, int ld, double* K,
                         double* Cg);
/* the rotation the drives prescribe at t (static.c's fit_rotation in space): 0 (speed 0: static)
   or FMB_EXIT_BAD_INPUT with *diag */
int fmb_fit_rotation3(const fmbModel* m, fmbWorkspace* w, double t, const double* q, fmbRotation3* rot, fmbDiag* diag);
/* the rigid rotation a state's velocities v describe (speed 0 when they are not one) */
int fmb_state_rotation3(const fmbModel* m, fmbWorkspace* w, const double* q, const double* v, fmbRotation3* rot);
/* the largest turn (rad) of a body's frame when its coordinates move by dq */
double fmb_turn3(const fmbModel* m, fmbWorkspace* w, const double* q, const double* dq);

/* ---- output.c ---- */
int fmb_outputs_resolve(fmbParser* p, fmbModel* m, fmbNode list);
/* global position of a body's material point (its marker); 0 ok */
int fmb_body_point(const fmbModel* m, fmbWorkspace* w, int b, const double* q, const double local[2], double pos[2],
                   double* angle);
/* its spatial twin (dimension 3): position and rotation matrix (row-major; R may be NULL) of a
   material point from the body's marker3; 0 ok, -1 for a body without one */
int fmb_body_point3(const fmbModel* m, fmbWorkspace* w, int b, const double* q, const double local[3], double pos[3],
                    double R[9]);
/* no `outputs:` list: x, y, theta, omega of every moving body with a frame; 0, or -1 out of memory */
int fmb_outputs_default(fmbParser* p, fmbModel* m);
typedef struct fmbCsv fmbCsv;
/* "-"/NULL = stdout; a regular file is written beside the target and renamed by close */
fmbCsv* fmb_csv_open(const char* path, fmbDiag* diag);
/* the same, refusing a path that is one of `inputs` (a model's files, fmb_model_inputs) */
fmbCsv* fmb_csv_open_guarded(const char* path, const fmbInputs* inputs, fmbDiag* diag);
int fmb_csv_header(fmbCsv* c, const fmbModel* m); /* 0 ok, -1 write failed */
int fmb_csv_row(fmbCsv* c, const fmbModel* m, fmbWorkspace* w, double t, const double* y, const double* yp);
/* a body out of its model's range (fmbBodyType.model_range) named through fmb_warn, once: warned
   has nbody entries, 1 once a body was named */
void fmb_warn_model_range(const fmbModel* m, fmbWorkspace* w, double t, const double* y, unsigned char* warned);
/* the rows gathered so far to the file (a temporary one gathers them); 0, or -1 a write failed */
int fmb_csv_flush(fmbCsv* c);
/* puts a file with a header in place (rename), removes one without; -1 with errno on failure */
int fmb_csv_close(fmbCsv* c);
/* tables other than the scene's outputs (modes, Campbell): named columns, rows of values */
int fmb_csv_header_names(fmbCsv* c, int n, const char* const* names);
int fmb_csv_values(fmbCsv* c, const double* values);
/* v as printf's "%.12g" writes it, into out (>= 32 bytes); the length (format_g12.c) */
int fmb_format_g12(double v, char* out);
/* the scene's outputs at (t, y) into row[noutput]; 0 ok, 1 a value is not finite */
int fmb_outputs_eval(const fmbModel* m, fmbWorkspace* w, double t, const double* y, const double* yp, double* row);

/* ---- vtk.c: the run as a ParaView collection (DIR/SCENE.pvd, one .vtu per output row) ---- */
typedef struct fmbVtk fmbVtk;
fmbVtk* fmb_vtk_open(const fmbModel* m, const char* dir, fmbDiag* diag);
int fmb_vtk_step(fmbVtk* v, const fmbModel* m, fmbWorkspace* w, double t, const double* y); /* 0 ok, -1 write failed */
int fmb_vtk_set_every(fmbVtk* v, int every); /* write every Nth step only (0, 1: each); -1 when every < 0 */
void fmb_vtk_close(fmbVtk* v);

#endif
