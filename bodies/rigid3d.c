/* rigid3d.c — a rigid body in space (docs/spatial.md). Coordinates q = [r; p]: the centre of mass
 * r (3) and Euler parameters p = [e0, e1, e2, e3] (4) of any nonzero length, the rotation being
 * R(p / |p|) (engine/frame3.c); velocities v = q' = [r'; p'].
 *
 * The body has 6 degrees of freedom and 7 coordinates, and no constraint rows of its own: the
 * length of p is a gauge that no physics sees (R, the angular velocity and the markers depend on
 * p / |p| only), fixed by one equation of the body. With L(p) = [-e, e0 I - [e]x] (3 x 4, L p = 0),
 * n2 = p.p, the body-frame angular velocity and its rate are
 *   w = (2 / n2) L(p) p',    w' = (2 / n2) L(p) p'' - (2 p.p' / n2) w            (L(p') p' = 0)
 * and the rows are
 *   R_r = m r'' - m g
 *   R_p = (2 / n2) L^T (J w' + w x J w) + (4 J_avg / n2^2) p (p.p'' + p'.p')
 * The first part of R_p is Euler's equation projected by the virtual rotation (2 / n2) L^T, the
 * same map by which a joint's torque reaches p (Phi_p^T lambda), so it carries torques exactly;
 * it is orthogonal to p. The second part, along p, is the gauge d^2/dt^2 (|p|^2 / 2) = 0: |p|
 * stays at its initial 1 up to the integration error of p.p', harmlessly, since nothing depends on
 * it. Scaled by J_avg = tr J / 3 the mass block (4 / n2^2)(L^T J L + J_avg p p^T) is symmetric
 * positive definite (4 J_avg I for a sphere at |p| = 1). Cost: one coordinate and one equation
 * more than a minimal set, no singularity anywhere (unlike three angles), no constraint row. */
#include <math.h>
#include <stdlib.h>
#include <string.h>

#include "flexmbd_plugin.h"

typedef struct {
  double mass, J[9], Javg; /* J: inertia tensor about the centre of mass, body frame (row-major) */
  double principal[3], principal_axes[4];
  double pos[3], quat[4], vel[3], omega[3]; /* initial; omega in the global frame */
} Rigid3;

/* L(p) = [-e, e0 I - [e]x]: body-frame angular velocity w = 2 L(p) p' for unit p */
static void body_l(const double p[4], double L[3][4]) {
  const double e0 = p[0], e1 = p[1], e2 = p[2], e3 = p[3];
  const double rows[3][4] = {{-e1, e0, e3, -e2}, {-e2, -e3, e0, e1}, {-e3, e2, -e1, e0}};
  memcpy(L, rows, sizeof rows);
}

static void mat_vec(const double A[9], const double x[3], double y[3]) {
  for (int i = 0; i < 3; ++i) y[i] = A[3 * i] * x[0] + A[3 * i + 1] * x[1] + A[3 * i + 2] * x[2];
}
static void mat_t_vec(const double A[9], const double x[3], double y[3]) {
  for (int i = 0; i < 3; ++i) y[i] = A[i] * x[0] + A[3 + i] * x[1] + A[6 + i] * x[2];
}
static void cross(const double a[3], const double b[3], double c[3]) {
  c[0] = a[1] * b[2] - a[2] * b[1];
  c[1] = a[2] * b[0] - a[0] * b[2];
  c[2] = a[0] * b[1] - a[1] * b[0];
}

/* body-frame angular velocity of (p, p') */
static void body_omega(const double* p, const double* pd, double w[3]) {
  double L[3][4];
  body_l(p, L);
  const double s = 2.0 / (p[0] * p[0] + p[1] * p[1] + p[2] * p[2] + p[3] * p[3]);
  for (int i = 0; i < 3; ++i) w[i] = s * (L[i][0] * pd[0] + L[i][1] * pd[1] + L[i][2] * pd[2] + L[i][3] * pd[3]);
}

static int rigid3_parse(fmbParser* p, fmbNode item, void** self) {
  Rigid3* r = calloc(1, sizeof *r);
  if (!r) return fmb_parse_error(p, item, "out of memory");
  *self = r;
  r->quat[0] = r->principal_axes[0] = 1.0;
  if (fmb_get_double(p, item, "mass", FMB_REQUIRED | FMB_POSITIVE, &r->mass) ||
      fmb_get_vec3(p, item, "inertia", FMB_REQUIRED | FMB_POSITIVE, r->principal) ||
      fmb_get_vec3(p, item, "position", 0, r->pos) || fmb_get_vec3(p, item, "velocity", 0, r->vel) ||
      fmb_get_vec3(p, item, "angular_velocity", 0, r->omega))
    return -1;
  if (fmb_get_quat(p, item, "orientation", 0, r->quat) || fmb_get_quat(p, item, "principal_axes", 0, r->principal_axes))
    return -1;
  if (!isnormal(r->mass))
    return fmb_parse_error(p, fmb_find_key(p, item, "mass"), "mass %g is too small to compute with", r->mass);
  const double* I = r->principal;
  for (int i = 0; i < 3; ++i) {
    if (!isnormal(I[i]))
      return fmb_parse_error(p, fmb_find_key(p, item, "inertia"), "inertia %g is too small to compute with", I[i]);
    /* a rigid body's principal moments obey the triangle inequality (I1 + I2 >= I3: the mass lies
       at a distance from each axis); a violation is a typo, not a body */
    if (I[i] > (I[(i + 1) % 3] + I[(i + 2) % 3]) * (1.0 + 1e-12))
      return fmb_parse_error(p, fmb_find_key(p, item, "inertia"),
                             "inertia [%g, %g, %g]: %g exceeds the sum of the other two, which no rigid body "
                             "has (principal moments about the centre of mass obey the triangle inequality)",
                             I[0], I[1], I[2], I[i]);
  }
  /* J = A diag(I) A^T, A the principal axes in the body frame */
  double A[9];
  fmb_quat_matrix(r->principal_axes, A);
  for (int i = 0; i < 3; ++i)
    for (int j = 0; j < 3; ++j)
      r->J[3 * i + j] =
          A[3 * i] * I[0] * A[3 * j] + A[3 * i + 1] * I[1] * A[3 * j + 1] + A[3 * i + 2] * I[2] * A[3 * j + 2];
  r->Javg = (I[0] + I[1] + I[2]) / 3.0;
  return 0;
}

static void rigid3_destroy(void* self) { free(self); }
static int rigid3_ncoord(const void* self) {
  (void)self;
  return 7;
}

static void rigid3_initial(const void* self, double* q, double* v) {
  const Rigid3* r = self;
  double R[9], wb[3], L[3][4];
  for (int i = 0; i < 3; ++i) q[i] = r->pos[i], v[i] = r->vel[i];
  memcpy(q + 3, r->quat, sizeof r->quat);
  fmb_quat_matrix(r->quat, R);
  mat_t_vec(R, r->omega, wb); /* body frame */
  body_l(r->quat, L);
  for (int k = 0; k < 4; ++k)
    v[3 + k] = 0.5 * (L[0][k] * wb[0] + L[1][k] * wb[1] + L[2][k] * wb[2]); /* p' = L^T w / 2 */
}

static int rigid3_residual(const void* self, const fmbEnv* env, const double* q, const double* v, const double* a,
                           double* Res, double* work) {
  (void)work;
  const Rigid3* r = self;
  for (int i = 0; i < 3; ++i) Res[i] = r->mass * (a[i] - (env->has_gravity ? env->gravity3[i] : 0.0));
  const double *p = q + 3, *pd = v + 3, *pdd = a + 3;
  const double n2 = p[0] * p[0] + p[1] * p[1] + p[2] * p[2] + p[3] * p[3];
  if (!(n2 > 0.0)) return 1; /* p = 0: no rotation; IDA retries with a smaller step */
  double L[3][4], w[3], wd[3], Jw[3], Jwd[3], wxJw[3], h[3];
  body_l(p, L);
  body_omega(p, pd, w);
  body_omega(p, pdd, wd);
  const double ppd = p[0] * pd[0] + p[1] * pd[1] + p[2] * pd[2] + p[3] * pd[3];
  for (int i = 0; i < 3; ++i) wd[i] -= 2.0 * ppd / n2 * w[i];
  mat_vec(r->J, w, Jw);
  mat_vec(r->J, wd, Jwd);
  cross(w, Jw, wxJw);
  for (int i = 0; i < 3; ++i) h[i] = Jwd[i] + wxJw[i];
  const double gauge = (p[0] * pdd[0] + p[1] * pdd[1] + p[2] * pdd[2] + p[3] * pdd[3]) +
                       (pd[0] * pd[0] + pd[1] * pd[1] + pd[2] * pd[2] + pd[3] * pd[3]);
  const double s = 2.0 / n2, sg = 4.0 * r->Javg / (n2 * n2);
  for (int k = 0; k < 4; ++k) Res[3 + k] = s * (L[0][k] * h[0] + L[1][k] * h[1] + L[2][k] * h[2]) + sg * p[k] * gauge;
  return 0;
}

static int rigid3_marker3(const void* self, const double* q, const double local[3], double pos[3], double R[9],
                          double* dpos_dq, double* rot_dq, int ld, double* work) {
  (void)self;
  (void)work;
  return fmb_frame3_point(q, local, pos, R, dpos_dq, rot_dq, ld); /* q is the frame: the body is its frame */
}

static void rigid3_energy(const void* self, const fmbEnv* env, const double* q, const double* v, fmbEnergy* e,
                          double* work) {
  (void)work;
  const Rigid3* r = self;
  double w[3], Jw[3];
  body_omega(q + 3, v + 3, w);
  mat_vec(r->J, w, Jw);
  e->kinetic =
      0.5 * r->mass * (v[0] * v[0] + v[1] * v[1] + v[2] * v[2]) + 0.5 * (w[0] * Jw[0] + w[1] * Jw[1] + w[2] * Jw[2]);
  e->gravity =
      env->has_gravity ? -r->mass * (env->gravity3[0] * q[0] + env->gravity3[1] * q[1] + env->gravity3[2] * q[2]) : 0.0;
}

/* the metres a point at the radius of gyration moves per unit of each coordinate: 1 for r, and
   for p (a unit of p turns the body by up to 2 rad) twice that radius */
static void rigid3_length_scale(const void* self, double* metres_per_unit) {
  const Rigid3* r = self;
  const double gyration = sqrt(1.5 * r->Javg / r->mass);
  for (int i = 0; i < 7; ++i) metres_per_unit[i] = i < 3 ? 1.0 : fmax(2.0 * gyration, 1e-300);
}

enum {
  OUT_X,
  OUT_Y,
  OUT_Z,
  OUT_QW,
  OUT_QX,
  OUT_QY,
  OUT_QZ,
  OUT_VX,
  OUT_VY,
  OUT_VZ,
  OUT_WX,
  OUT_WY,
  OUT_WZ,
  OUT_W1,
  OUT_W2,
  OUT_W3,
  OUT_LX,
  OUT_LY,
  OUT_LZ,
  OUT_ROLL,
  OUT_PITCH,
  OUT_YAW,
  OUT_N
};
static const char* const rigid3_outputs[] = {"x",  "y",  "z",  "qw",   "qx",    "qy",  "qz", "vx",
                                             "vy", "vz", "wx", "wy",   "wz",    "w1",  "w2", "w3",
                                             "Lx", "Ly", "Lz", "roll", "pitch", "yaw", NULL};
static const char* const rigid3_units[] = {"m",     "m",     "m",     "1",     "1",     "1",     "1",     "m/s",
                                           "m/s",   "m/s",   "rad/s", "rad/s", "rad/s", "rad/s", "rad/s", "rad/s",
                                           "N m s", "N m s", "N m s", "rad",   "rad",   "rad",   NULL};

static int rigid3_output(const void* self, int id, const double* q, const double* v, double* value, double* work) {
  (void)work;
  const Rigid3* r = self;
  const double* p = q + 3;
  const double n = sqrt(p[0] * p[0] + p[1] * p[1] + p[2] * p[2] + p[3] * p[3]);
  double R[9], w[3], wg[3], Jw[3], Lg[3];
  if (fmb_quat_matrix(p, R)) return -1;
  body_omega(p, v + 3, w);
  mat_vec(R, w, wg);
  mat_vec(r->J, w, Jw);
  mat_vec(R, Jw, Lg);
  /* Euler angles z-y-x (yaw, pitch, roll): R = Rz(yaw) Ry(pitch) Rx(roll) */
  const double euler[3] = {atan2(R[7], R[8]), asin(fmax(-1.0, fmin(1.0, -R[6]))), atan2(R[3], R[0])};
  if (id < 0 || id >= OUT_N) return -1;
  const double all[OUT_N] = {q[0],  q[1],  q[2],  p[0] / n, p[1] / n, p[2] / n, p[3] / n, v[0],
                             v[1],  v[2],  wg[0], wg[1],    wg[2],    w[0],     w[1],     w[2],
                             Lg[0], Lg[1], Lg[2], euler[0], euler[1], euler[2]};
  *value = all[id];
  return 0;
}

static void rigid3_describe(const void* self, FILE* f) {
  const Rigid3* r = self;
  fprintf(f, "mass %g kg, principal inertia [%g, %g, %g] kg m^2 about the centre of mass; Euler parameters\n", r->mass,
          r->principal[0], r->principal[1], r->principal[2]);
}

static const fmbParam rigid3_params[] = {
    {.key = "mass", .kind = FMB_PARAM_NUMBER, .flags = FMB_REQUIRED | FMB_POSITIVE, .unit = "kg", .doc = "mass"},
    {.key = "inertia",
     .kind = FMB_PARAM_VEC3,
     .flags = FMB_REQUIRED | FMB_POSITIVE,
     .unit = "kg m^2",
     .doc = "principal moments of inertia about the centre of mass [I1, I2, I3]"},
    {.key = "principal_axes",
     .kind = FMB_PARAM_QUAT,
     .fallback = "[1, 0, 0, 0]",
     .doc = "Euler parameters [w, x, y, z] of the principal axes in the body frame"},
    {.key = "position", .kind = FMB_PARAM_VEC3, .unit = "m", .fallback = "[0, 0, 0]", .doc = "initial centre of mass"},
    {.key = "orientation",
     .kind = FMB_PARAM_QUAT,
     .fallback = "[1, 0, 0, 0]",
     .doc = "initial orientation, Euler parameters [w, x, y, z] (normalized)"},
    {.key = "velocity",
     .kind = FMB_PARAM_VEC3,
     .unit = "m/s",
     .fallback = "[0, 0, 0]",
     .doc = "initial velocity of the centre of mass"},
    {.key = "angular_velocity",
     .kind = FMB_PARAM_VEC3,
     .unit = "rad/s",
     .fallback = "[0, 0, 0]",
     .doc = "initial angular velocity, global frame"},
    {.key = NULL},
};

/* ABI 3.4: the one gauge direction, the length of the Euler parameters (R depends on p / |p|) */
static int rigid3_gauge(const void* self, const double* q, double* dir) {
  (void)self;
  if (dir) {
    memset(dir, 0, 7 * sizeof *dir);
    memcpy(dir + 3, q + 3, 4 * sizeof *dir);
  }
  return 1;
}

const fmbBodyType fmb_body_rigid3d = {
    .name = "rigid3d",
    .abi = FMB_ABI_VERSION,
    .parse = rigid3_parse,
    .destroy = rigid3_destroy,
    .ncoord = rigid3_ncoord,
    .initial = rigid3_initial,
    .residual = rigid3_residual,
    .energy = rigid3_energy,
    .length_scale = rigid3_length_scale,
    .output_names = rigid3_outputs,
    .output_units = rigid3_units,
    .output = rigid3_output,
    .describe = rigid3_describe,
    .params = rigid3_params,
    .example = "mass: 2\ninertia: [0.1, 0.2, 0.25]\nposition: [0, 0, 1]\norientation: [1, 0.2, 0, 0]\n"
               "angular_velocity: [0.3, 1.0, 0.2]\n",
    .dimensions = FMB_DIM_SPATIAL,
    .flags = FMB_TYPE_CONFORM_FIXTURE, /* conform's two bodies a and b in space */
    .marker3 = rigid3_marker3,
    .gauge = rigid3_gauge,
};
