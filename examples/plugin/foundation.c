/* foundation.c — a flexmbd body plugin: a rigid bar on an elastic (Winkler) foundation.
 *
 * The bar (mass m, moment of inertia J about its centre, length L) lies along its body x axis,
 * centred on its frame; coordinates q = [x, y, theta]. Every point s in [-L/2, L/2] of the bar
 * rests on a bed of springs and dampers along the global line y = 0 that push vertically:
 *     h(s) = y + s sin(theta)                 height of the point above the bed
 *     f(s) = -k h(s) - c dh/dt                force per unit length (k: N/m^2, c: N s/m^2)
 * and the bed is frictionless (no horizontal force). The generalized forces are
 *     Q_y = int f ds,   Q_theta = int f s cos(theta) ds
 * and the foundation stores U = (k/2) int h^2 ds = (k/2) (L y^2 + L^3 sin^2(theta) / 12).
 * Equations of motion (the residual):  R = diag(m, m, J) a - Q - m g.
 * Analytic solutions (examples/plugin/check_foundation.c): heave is linear, omega_y^2 = k L / m,
 * about the sag y0 = m g_y / (k L); rocking is a pendulum in 2 theta, omega_t^2 = k L^3 / (12 J).
 *
 * Built against the installed flexmbd only (docs/plugins.md): flexmbd_plugin.h and libflexmbd. */
#include <math.h>
#include <stdlib.h>
#include <string.h>

#include <flexmbd_plugin.h>

typedef struct {
  double mass, inertia, length, stiffness, damping;
  double pos[2], angle, vel[2], omega;
  double s[2], w[2]; /* Gauss points and weights along the bar (2 points: h^2 is quadratic in s) */
} Bar;

static int bar_parse(fmbParser* p, fmbNode item, void** self) {
  Bar* b = calloc(1, sizeof *b);
  if (!b) return fmb_parse_error(p, item, "out of memory");
  *self = b; /* set before reading: the engine destroys it if a key is refused */
  if (fmb_get_double(p, item, "mass", FMB_REQUIRED | FMB_POSITIVE, &b->mass) ||
      fmb_get_double(p, item, "inertia", FMB_REQUIRED | FMB_POSITIVE, &b->inertia) ||
      fmb_get_double(p, item, "length", FMB_REQUIRED | FMB_POSITIVE, &b->length) ||
      fmb_get_double(p, item, "stiffness", FMB_REQUIRED | FMB_POSITIVE, &b->stiffness) ||
      fmb_get_double(p, item, "damping", FMB_NONNEGATIVE, &b->damping) ||
      fmb_get_vec2(p, item, "position", FMB_OPTIONAL, b->pos) || fmb_get_double(p, item, "angle", 0, &b->angle) ||
      fmb_get_vec2(p, item, "velocity", FMB_OPTIONAL, b->vel) ||
      fmb_get_double(p, item, "angular_velocity", 0, &b->omega))
    return -1;
  /* Gauss-Legendre on [0, 1] mapped to [-L/2, L/2] */
  fmb_gauss_legendre01(2, b->s, b->w);
  for (int g = 0; g < 2; ++g) {
    b->s[g] = (b->s[g] - 0.5) * b->length;
    b->w[g] *= b->length;
  }
  return 0;
}

static void bar_destroy(void* self) { free(self); }
static int bar_ncoord(const void* self) {
  (void)self;
  return 3;
}

static void bar_initial(const void* self, double* q, double* v) {
  const Bar* b = self;
  q[0] = b->pos[0], q[1] = b->pos[1], q[2] = b->angle;
  v[0] = b->vel[0], v[1] = b->vel[1], v[2] = b->omega;
}

/* Q of the foundation at (q, v); with K, C (3 x 3 column-major, may be NULL) its Jacobian
   -dQ/dq and -dQ/dv, which the residual R = M a - Q has as dR/dq and dR/dv */
static void foundation(const Bar* b, const double* q, const double* v, double Q[3], double* K, double* C) {
  const double sn = sin(q[2]), cs = cos(q[2]);
  Q[0] = Q[1] = Q[2] = 0.0;
  if (K) memset(K, 0, 9 * sizeof(double)), memset(C, 0, 9 * sizeof(double));
  for (int g = 0; g < 2; ++g) {
    const double s = b->s[g], w = b->w[g];
    const double h = q[1] + s * sn, hdot = v[1] + s * cs * v[2];
    const double f = -b->stiffness * h - b->damping * hdot;
    Q[1] += w * f;
    Q[2] += w * f * s * cs;
    if (!K) continue;
    /* df/dy, df/dtheta, df/dydot, df/dthetadot */
    const double fy = -b->stiffness, ft = -b->stiffness * s * cs + b->damping * s * sn * v[2];
    const double fyd = -b->damping, ftd = -b->damping * s * cs;
    K[3 * 1 + 1] -= w * fy;                         /* dR_y/dy */
    K[3 * 2 + 1] -= w * ft;                         /* dR_y/dtheta */
    K[3 * 1 + 2] -= w * fy * s * cs;                /* dR_theta/dy */
    K[3 * 2 + 2] -= w * (ft * s * cs - f * s * sn); /* dR_theta/dtheta */
    C[3 * 1 + 1] -= w * fyd;
    C[3 * 2 + 1] -= w * ftd;
    C[3 * 1 + 2] -= w * fyd * s * cs;
    C[3 * 2 + 2] -= w * ftd * s * cs;
  }
}

static int bar_residual(const void* self, const fmbEnv* env, const double* q, const double* v, const double* a,
                        double* R, double* work) {
  (void)work;
  const Bar* b = self;
  double Q[3];
  foundation(b, q, v, Q, NULL, NULL);
  R[0] = b->mass * a[0] - Q[0];
  R[1] = b->mass * a[1] - Q[1];
  R[2] = b->inertia * a[2] - Q[2];
  if (env->has_gravity) { /* leave gravity out entirely when the scene has none */
    R[0] -= b->mass * env->gravity[0];
    R[1] -= b->mass * env->gravity[1];
  }
  return isfinite(R[0]) && isfinite(R[1]) && isfinite(R[2]) ? 0 : 1; /* 1: IDA retries a smaller step */
}

static int bar_jacobian(const void* self, const fmbEnv* env, const double* q, const double* v, const double* a,
                        double* K, double* C, double* M, double* work) {
  (void)env, (void)a, (void)work;
  const Bar* b = self;
  double Q[3];
  foundation(b, q, v, Q, K, C);
  memset(M, 0, 9 * sizeof(double));
  M[0] = M[4] = b->mass;
  M[8] = b->inertia;
  return 0;
}

static int bar_marker(const void* self, const double* q, const double local[2], double pos[2], double* angle,
                      double* dpos_dq, double* dangle_dq, double* work) {
  (void)self, (void)work;
  fmb_frame_point(q, local, pos, angle, dpos_dq, dangle_dq); /* the bar is rigid: its coordinates are its frame */
  return 0;
}

static void bar_energy(const void* self, const fmbEnv* env, const double* q, const double* v, fmbEnergy* e,
                       double* work) {
  (void)work;
  const Bar* b = self;
  const double sn = sin(q[2]), L = b->length;
  e->kinetic = 0.5 * b->mass * (v[0] * v[0] + v[1] * v[1]) + 0.5 * b->inertia * v[2] * v[2];
  e->strain = 0.5 * b->stiffness * (L * q[1] * q[1] + L * L * L * sn * sn / 12.0);
  e->gravity = env->has_gravity ? -b->mass * (env->gravity[0] * q[0] + env->gravity[1] * q[1]) : 0.0;
}

/* outputs beyond the frame's: the bed's total reaction and the bar's lowest point */
static const char* const bar_outputs[] = {"reaction", "lowest", NULL};
static int bar_output(const void* self, int id, const double* q, const double* v, double* value, double* work) {
  (void)work;
  const Bar* b = self;
  double Q[3];
  foundation(b, q, v, Q, NULL, NULL);
  *value = id == 0 ? Q[1] : q[1] - 0.5 * b->length * fabs(sin(q[2]));
  return 0;
}

static void bar_describe(const void* self, FILE* f) {
  const Bar* b = self;
  fprintf(f, "rigid bar %g m on a Winkler foundation k = %g N/m^2, c = %g N s/m^2\n", b->length, b->stiffness,
          b->damping);
}

static const fmbParam bar_params[] = {
    {.key = "mass", .kind = FMB_PARAM_NUMBER, .flags = FMB_REQUIRED | FMB_POSITIVE, .unit = "kg", .doc = "mass"},
    {.key = "inertia",
     .kind = FMB_PARAM_NUMBER,
     .flags = FMB_REQUIRED | FMB_POSITIVE,
     .unit = "kg m^2",
     .doc = "moment of inertia about the centre"},
    {.key = "length", .kind = FMB_PARAM_NUMBER, .flags = FMB_REQUIRED | FMB_POSITIVE, .unit = "m", .doc = "bar length"},
    {.key = "stiffness",
     .kind = FMB_PARAM_NUMBER,
     .flags = FMB_REQUIRED | FMB_POSITIVE,
     .unit = "N/m^2",
     .doc = "foundation modulus k (force per unit length per unit height)"},
    {.key = "damping",
     .kind = FMB_PARAM_NUMBER,
     .flags = FMB_NONNEGATIVE,
     .unit = "N s/m^2",
     .fallback = "0",
     .doc = "foundation damping c per unit length"},
    {.key = "position", .kind = FMB_PARAM_VEC2, .unit = "m", .fallback = "[0, 0]", .doc = "initial centre"},
    {.key = "angle", .kind = FMB_PARAM_NUMBER, .unit = "rad", .fallback = "0", .doc = "initial angle"},
    {.key = "velocity", .kind = FMB_PARAM_VEC2, .unit = "m/s", .fallback = "[0, 0]", .doc = "initial velocity"},
    {.key = "angular_velocity", .kind = FMB_PARAM_NUMBER, .unit = "rad/s", .fallback = "0", .doc = "initial rate"},
    {.key = NULL},
};

static const fmbBodyType foundation_bar = {
    .name = "foundation_bar",
    .abi = FMB_ABI_VERSION,
    .parse = bar_parse,
    .destroy = bar_destroy,
    .ncoord = bar_ncoord,
    .initial = bar_initial,
    .residual = bar_residual,
    .marker = bar_marker,
    .jacobian = bar_jacobian,
    .energy = bar_energy,
    .output_names = bar_outputs,
    .output = bar_output,
    .describe = bar_describe,
    .params = bar_params,
    .example = "mass: 2\ninertia: 0.2\nlength: 1\nstiffness: 400\nposition: [0, 0.02]\nangle: 0.1\n"
               "velocity: [0.3, 0]\nangular_velocity: 1\n",
    .example_damped = "damping: 5\n",
};

static const fmbBodyType* const bodies[] = {&foundation_bar, NULL};
static const fmbPlugin plugin = {
    .abi = FMB_ABI_VERSION, .name = "foundation", .version = "1.0", .bodies = bodies, .joints = NULL};

/* the one symbol flexmbd looks up */
FMB_PLUGIN_EXPORT const fmbPlugin* fmb_plugin_descriptor(void) { return &plugin; }
