/* broken.c — a plugin that breaks one rule, chosen at compile time (-DBREAK_...), to prove the
 * loader and `flexmbd conform` catch each (tests/install/run.sh). Without a BREAK_ macro it is a
 * correct 3-dof oscillator: a rigid body tied to its rest pose by springs (-DABI_3_0: the same,
 * with the descriptor and table a plugin built for plugin ABI 3.0 has, tests/core/test_plugin_abi.c),
 *     R = diag(m, m, J) a + k q - m g,     U = k |q|^2 / 2. */
#include <math.h>
#include <stdlib.h>
#include <string.h>

#include <flexmbd_plugin.h>

#ifdef BREAK_ABI
#define ABI ((FMB_PLUGIN_ABI_MAJOR + 1) * 1000) /* built, say, for the next major of the plugin ABI */
#elif defined BREAK_ABI_MINOR
#define ABI (FMB_PLUGIN_ABI + 1) /* a minor newer than this flexmbd's: fields it would not read */
#else
#define ABI FMB_PLUGIN_ABI
#endif

typedef struct {
  double mass, inertia, stiffness;
} Osc;

static int osc_parse(fmbParser* p, fmbNode item, void** self) {
  Osc* o = calloc(1, sizeof *o);
  if (!o) return fmb_parse_error(p, item, "out of memory");
  *self = o;
  return fmb_get_double(p, item, "mass", FMB_REQUIRED | FMB_POSITIVE, &o->mass) ||
                 fmb_get_double(p, item, "inertia", FMB_REQUIRED | FMB_POSITIVE, &o->inertia) ||
                 fmb_get_double(p, item, "stiffness", FMB_REQUIRED | FMB_POSITIVE, &o->stiffness)
             ? -1
             : 0;
}
static void osc_destroy(void* self) { free(self); }
static int osc_ncoord(const void* self) {
  (void)self;
  return 3;
}
static void osc_initial(const void* self, double* q, double* v) {
  (void)self;
  q[0] = 0.1, q[1] = -0.05, q[2] = 0.2;
  v[0] = 0.3, v[1] = 0.1, v[2] = -0.5;
}

#ifdef BREAK_MASS
#define M01 0.1 /* a mass matrix that is not symmetric: M[0][1] = 0.1, M[1][0] = 0 */
#else
#define M01 0.0
#endif

static int osc_residual(const void* self, const fmbEnv* env, const double* q, const double* v, const double* a,
                        double* R, double* work) {
  (void)work, (void)v;
  const Osc* o = self;
  R[0] = o->mass * a[0] + M01 * a[1] + o->stiffness * q[0];
  R[1] = o->mass * a[1] + o->stiffness * q[1];
  R[2] = o->inertia * a[2] + o->stiffness * q[2];
#ifdef BREAK_ENERGY
  R[2] += 0.05 * v[2]; /* a friction the energy does not account for: energy leaks */
#endif
#ifdef BREAK_PATTERN
  R[0] += 3.0 * (q[0] - q[1]), R[1] += 3.0 * (q[1] - q[0]); /* a coupling spring the pattern leaves out */
#endif
  if (env->has_gravity) R[0] -= o->mass * env->gravity[0], R[1] -= o->mass * env->gravity[1];
  return 0;
}

static int osc_jacobian(const void* self, const fmbEnv* env, const double* q, const double* v, const double* a,
                        double* K, double* C, double* M, double* work) {
  (void)env, (void)q, (void)v, (void)a, (void)work;
  const Osc* o = self;
  memset(K, 0, 9 * sizeof(double)), memset(C, 0, 9 * sizeof(double)), memset(M, 0, 9 * sizeof(double));
  K[0] = K[4] = K[8] = o->stiffness;
#ifdef BREAK_JACOBIAN
  K[8] = 2 * o->stiffness; /* wrong: dR_theta/dtheta is k */
#endif
#ifdef BREAK_PATTERN
  K[0] += 3.0, K[4] += 3.0, K[1] = K[3] = -3.0; /* right here; only the sparse pattern omits it */
#endif
#ifdef BREAK_ENERGY
  C[8] = 0.05;
#endif
  M[0] = M[4] = o->mass, M[8] = o->inertia;
  M[3] = M01; /* column 1, row 0 */
  return 0;
}

static int osc_marker(const void* self, const double* q, const double local[2], double pos[2], double* angle,
                      double* dpos_dq, double* dangle_dq, double* work) {
  (void)self, (void)work;
  fmb_frame_point(q, local, pos, angle, dpos_dq, dangle_dq);
  return 0;
}

/* the sparse form: the diagonal of K and M (BREAK_PATTERN: its coupling K[0][1] is left out) */
static long osc_pattern(const void* self, int* rows, int* cols) {
  (void)self;
  for (int i = 0; rows && i < 3; ++i) rows[i] = cols[i] = i;
  return 3;
}
static int osc_pattern_jacobian(const void* self, const fmbEnv* env, const double* q, const double* v, const double* a,
                                const double* z, double* K, double* C, double* M, double* work) {
  (void)env, (void)q, (void)v, (void)a, (void)z, (void)work;
  const Osc* o = self;
  for (int i = 0; i < 3; ++i) K[i] = o->stiffness, C[i] = 0.0;
#ifdef BREAK_PATTERN
  K[0] += 3.0, K[1] += 3.0;
#endif
  M[0] = M[1] = o->mass, M[2] = o->inertia;
  return 0;
}

static void osc_energy(const void* self, const fmbEnv* env, const double* q, const double* v, fmbEnergy* e,
                       double* work) {
  (void)work;
  const Osc* o = self;
  e->kinetic = 0.5 * o->mass * (v[0] * v[0] + v[1] * v[1]) + 0.5 * o->inertia * v[2] * v[2];
  e->strain = 0.5 * o->stiffness * (q[0] * q[0] + q[1] * q[1] + q[2] * q[2]);
#ifdef BREAK_PATTERN
  e->strain += 1.5 * (q[0] - q[1]) * (q[0] - q[1]);
#endif
  e->gravity = env->has_gravity ? -o->mass * (env->gravity[0] * q[0] + env->gravity[1] * q[1]) : 0.0;
}

static const fmbParam osc_params[] = {
    {.key = "mass", .kind = FMB_PARAM_NUMBER, .flags = FMB_REQUIRED | FMB_POSITIVE, .unit = "kg"},
    {.key = "inertia", .kind = FMB_PARAM_NUMBER, .flags = FMB_REQUIRED | FMB_POSITIVE, .unit = "kg m^2"},
    {.key = "stiffness", .kind = FMB_PARAM_NUMBER, .flags = FMB_REQUIRED | FMB_POSITIVE, .unit = "N/m"},
    {.key = NULL},
};

static const fmbBodyType oscillator = {
#ifdef BREAK_NAME
    .name = "rigid", /* a built-in type's name */
#else
    .name = "oscillator",
#endif
#ifdef ABI_3_0
    .abi = 3,
#else
    .abi = ABI,
#endif
    .parse = osc_parse,
    .destroy = osc_destroy,
    .ncoord = osc_ncoord,
    .initial = osc_initial,
#ifndef BREAK_OPS
    .residual = osc_residual, /* BREAK_OPS: a required op left out */
#endif
    .marker = osc_marker,
    .jacobian = osc_jacobian,
#ifndef BREAK_MASS /* (its M01 is not in the sparse form) */
    .pattern = osc_pattern,
    .pattern_jacobian = osc_pattern_jacobian,
#endif
    .energy = osc_energy,
    .params = osc_params,
    .example = "mass: 2\ninertia: 0.5\nstiffness: 30\n",
};

static const fmbBodyType* const bodies[] = {&oscillator, NULL};
#ifdef ABI_3_0
/* a plugin built against flexmbd 0.1's header (plugin ABI 3.0, then called ABI 3): its descriptor
   had no `size` (the 4 bytes after `abi` were padding, zero in a static object) and its tables
   said abi 3. The layout is spelled out here as that header had it. */
struct plugin30 {
  int abi;
  const char* name;
  const char* version;
  const fmbBodyType* const* bodies;
  const fmbJointType* const* joints;
};
static const struct plugin30 plugin30 = {.abi = 3, .name = "broken", .version = "0", .bodies = bodies};
#define PLUGIN ((const fmbPlugin*)(const void*)&plugin30)
#else
static const fmbPlugin plugin = {
    .abi = ABI, .size = sizeof(fmbPlugin), .name = "broken", .version = "0", .bodies = bodies};
#define PLUGIN (&plugin)
#endif

#ifndef BREAK_ENTRY
FMB_PLUGIN_EXPORT const fmbPlugin* fmb_plugin_descriptor(void) { return PLUGIN; }
#else
FMB_PLUGIN_EXPORT const fmbPlugin* plugin_descriptor(void) { return PLUGIN; } /* the wrong name */
#endif
