/* rigid.c — a planar rigid body. Coordinates q = [x, y, theta] of the centre of mass and the
 * body's orientation; the body frame sits at the centre of mass, so the equations are
 *   m (a_x, a_y) = m g,   J alpha = 0          (Newton–Euler, no velocity terms)
 * and everything else (joints, springs, applied loads) comes in through markers. */
#include <math.h>
#include <stdlib.h>

#include "flexmbd_plugin.h"

typedef struct {
  double mass, inertia;
  double pos[2], angle, vel[2], omega;
} Rigid;

static int rigid_parse(fmbParser* p, fmbNode item, void** self) {
  Rigid* r = calloc(1, sizeof *r);
  if (!r) return fmb_parse_error(p, item, "out of memory");
  *self = r;
  if (fmb_get_double(p, item, "mass", FMB_REQUIRED | FMB_POSITIVE, &r->mass) ||
      fmb_get_double(p, item, "inertia", FMB_REQUIRED | FMB_POSITIVE, &r->inertia) ||
      fmb_get_vec2(p, item, "position", 0, r->pos) || fmb_get_angle(p, item, "angle", FMB_POSE, &r->angle) ||
      fmb_get_vec2(p, item, "velocity", 0, r->vel) || fmb_get_double(p, item, "angular_velocity", 0, &r->omega))
    return -1;
  /* subnormal values pass "positive" but their inverses overflow */
  if (!isnormal(r->mass))
    return fmb_parse_error(p, fmb_find_key(p, item, "mass"), "mass %g is too small to compute with", r->mass);
  if (!isnormal(r->inertia))
    return fmb_parse_error(p, fmb_find_key(p, item, "inertia"), "inertia %g is too small to compute with", r->inertia);
  return 0;
}

static void rigid_destroy(void* self) { free(self); }
static int rigid_ncoord(const void* self) {
  (void)self;
  return 3;
}

static void rigid_initial(const void* self, double* q, double* v) {
  const Rigid* r = self;
  q[0] = r->pos[0];
  q[1] = r->pos[1];
  q[2] = r->angle;
  v[0] = r->vel[0];
  v[1] = r->vel[1];
  v[2] = r->omega;
}

static int rigid_residual(const void* self, const fmbEnv* env, const double* q, const double* v, const double* a,
                          double* R, double* work) {
  (void)q;
  (void)v;
  (void)work;
  const Rigid* r = self;
  R[0] = r->mass * a[0];
  R[1] = r->mass * a[1];
  R[2] = r->inertia * a[2];
  if (env->has_gravity) {
    R[0] -= r->mass * env->gravity[0];
    R[1] -= r->mass * env->gravity[1];
  }
  return 0;
}

static int rigid_jacobian(const void* self, const fmbEnv* env, const double* q, const double* v, const double* a,
                          double* K, double* C, double* M, double* work) {
  (void)env;
  (void)q;
  (void)v;
  (void)a;
  (void)work;
  const Rigid* r = self;
  for (int i = 0; i < 9; ++i) K[i] = C[i] = M[i] = 0.0;
  M[0] = M[4] = r->mass;
  M[8] = r->inertia;
  return 0;
}

static int rigid_marker(const void* self, const double* q, const double local[2], double pos[2], double* angle,
                        double* dpos_dq, double* dangle_dq, double* work) {
  (void)self;
  (void)work;
  fmb_frame_point(q, local, pos, angle, dpos_dq, dangle_dq); /* q is the frame: the body is its frame */
  return 0;
}

static void rigid_energy(const void* self, const fmbEnv* env, const double* q, const double* v, fmbEnergy* e,
                         double* work) {
  (void)work;
  const Rigid* r = self;
  e->kinetic = 0.5 * r->mass * (v[0] * v[0] + v[1] * v[1]) + 0.5 * r->inertia * v[2] * v[2];
  e->gravity = env->has_gravity ? -r->mass * (env->gravity[0] * q[0] + env->gravity[1] * q[1]) : 0.0;
}

static void rigid_describe(const void* self, FILE* f) {
  const Rigid* r = self;
  fprintf(f, "mass %g kg, inertia %g kg m^2 about the centre of mass\n", r->mass, r->inertia);
}

static const fmbParam rigid_params[] = {
    {.key = "mass", .kind = FMB_PARAM_NUMBER, .flags = FMB_REQUIRED | FMB_POSITIVE, .unit = "kg", .doc = "mass"},
    {.key = "inertia",
     .kind = FMB_PARAM_NUMBER,
     .flags = FMB_REQUIRED | FMB_POSITIVE,
     .unit = "kg m^2",
     .doc = "moment of inertia about the centre of mass"},
    {.key = "position", .kind = FMB_PARAM_VEC2, .unit = "m", .fallback = "[0, 0]", .doc = "initial centre of mass"},
    {.key = "angle", .kind = FMB_PARAM_NUMBER, .unit = "rad", .fallback = "0", .doc = "initial orientation"},
    {.key = "velocity",
     .kind = FMB_PARAM_VEC2,
     .unit = "m/s",
     .fallback = "[0, 0]",
     .doc = "initial velocity of the centre of mass"},
    {.key = "angular_velocity",
     .kind = FMB_PARAM_NUMBER,
     .unit = "rad/s",
     .fallback = "0",
     .doc = "initial angular velocity"},
    {.key = NULL},
};

const fmbBodyType fmb_body_rigid = {
    .name = "rigid",
    .abi = FMB_ABI_VERSION,
    .parse = rigid_parse,
    .destroy = rigid_destroy,
    .ncoord = rigid_ncoord,
    .initial = rigid_initial,
    .residual = rigid_residual,
    .marker = rigid_marker,
    .jacobian = rigid_jacobian,
    .energy = rigid_energy,
    .describe = rigid_describe,
    .params = rigid_params,
    .example = "mass: 2\ninertia: 0.3\nposition: [0.1, 0.2]\nangle: 0.3\nvelocity: [0.5, 1.0]\nangular_velocity: 2.0\n",
    .flags = FMB_TYPE_CONFORM_FIXTURE, /* conform's two bodies a and b */
};
