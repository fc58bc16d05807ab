/* conform.c — the conformance checks every registered type must pass (`flexmbd conform`,
 * docs/plugins.md "Conformance"). They run on the type's declared example (fmbBodyType.example)
 * placed in a small generated scene, and compare each op with something independent of it:
 *   params    every declared range violated (and every required key left out) is refused with
 *             exit 2 at the key's own line, naming the key; the keys parse reads are declared
 *   jacobian  the analytic K, C, M (when the type has a jacobian op) against central
 *             differences of its residual
 *   pattern   the sparse analytic Jacobian (pattern_jacobian) against central differences of
 *             [R; Rz] over every entry, and the declared pattern holding every nonzero
 *   mass      M = dR/da symmetric and positive definite (Cholesky)
 *   marker    position and angle derivatives against central differences (a spatial body: position
 *             and the virtual rotation G of marker3, dR/dq_k = [G_k]x R, against differences)
 *   gravity   with has_gravity = 0 the residual and energy do not read env->gravity (it is NaN
 *             there): the leave-out contract
 *   phi_q     a joint's constraint derivative against central differences of its rows
 *   force     a joint's generalized force = -dV/dq of its energy, at rest, without gravity
 *   energy    a free run keeps the total energy (unless the type feeds energy in); a damped run
 *             (the example plus example_damped) loses it and never gains any
 *   outputs   every output of the type stays finite along the run
 * A planar type (or one working in both dimensions) runs in the planar fixture, a spatial-only type
 * in the spatial one: each is the fixture types (FMB_TYPE_CONFORM_FIXTURE) of that dimension.
 * Every check can fail: tests/plugins/bad_*.c are plugins that each break one. */
#include <fcntl.h>
#include <math.h>
#include <stdarg.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>

#include <unistd.h>

#include "data.h"

#define CONFORM_T_END 1.0
#define ENERGY_TOL 1e-5 /* relative to the largest energy component along the run (rtol 1e-10) */
#define FD_TOL 1e-5     /* analytic vs central differences, relative to the block's largest entry */
#define MAX_LINES 64

typedef struct {
  FILE* f;
  const char* type;
  int failed;
} Report;

static void result(Report* r, int ok, const char* check, const char* fmt, ...)
#if defined(__GNUC__)
    __attribute__((format(printf, 4, 5)))
#endif
    ;
/* ok: 1 passed, 0 failed, SKIP: the type lacks what the check needs (said why) */
#define SKIP 2
static void result(Report* r, int ok, const char* check, const char* fmt, ...) {
  va_list ap;
  va_start(ap, fmt);
  fprintf(r->f, "%s %s %s: ", ok == SKIP ? "skip" : ok ? "ok  " : "FAIL", r->type, check);
  vfprintf(r->f, fmt, ap);
  fprintf(r->f, "\n");
  va_end(ap);
  if (!ok) r->failed++;
}

/* ---- the generated scene ---------------------------------------------------------------- */

/* the item's lines, `key: value` each, editable by key */
typedef struct {
  int n;
  char line[MAX_LINES][256];
} Lines;

static void lines_parse(Lines* l, const char* text) {
  l->n = 0;
  while (text && *text && l->n < MAX_LINES) {
    const char* e = strchr(text, '\n');
    const int len = e ? (int)(e - text) : (int)strlen(text);
    if (len > 0) snprintf(l->line[l->n++], sizeof l->line[0], "%.*s", len < 255 ? len : 255, text);
    text = e ? e + 1 : text + len;
  }
}
static int lines_find(const Lines* l, const char* key) {
  const size_t k = strlen(key);
  for (int i = 0; i < l->n; ++i)
    if (strncmp(l->line[i], key, k) == 0 && l->line[i][k] == ':') return i;
  return -1;
}
/* set key to value (value NULL: remove the key); returns the line index or -1 */
static int lines_set(Lines* l, const char* key, const char* value) {
  int i = lines_find(l, key);
  if (!value) {
    if (i >= 0) memmove(l->line[i], l->line[i + 1], (size_t)(l->n - i - 1) * sizeof l->line[0]), l->n--;
    return -1;
  }
  if (i < 0) {
    if (l->n == MAX_LINES) return -1;
    i = l->n++;
  }
  snprintf(l->line[i], sizeof l->line[0], "%.120s: %.120s", key, value);
  return i;
}

typedef struct {
  int joint;           /* probing a joint type */
  double gravity;      /* -9.81 or 0 */
  const char* outputs; /* the outputs list, or NULL */
  /* the fixture's body and joint types (FMB_TYPE_CONFORM_FIXTURE): the engine names no type */
  const char *fixture_body, *fixture_joint;
  int spatial; /* the spatial fixture (dimension: 3): a probe of a spatial-only type */
} SceneSpec;

/* the first registered body or joint type that declares itself fit for the fixture and works in
   the fixture's dimension (FMB_DIM_PLANAR or FMB_DIM_SPATIAL), or NULL */
static const char* fixture_type(const fmbRegistry* reg, int joint, unsigned dim) {
  if (joint) {
    for (int i = 0; i < reg->njoints; ++i) {
      const fmbJointType* t = reg->joints[i];
      if ((t->flags & FMB_TYPE_CONFORM_FIXTURE) && (fmb_type_dimensions(t->abi, t->dimensions) & dim)) return t->name;
    }
  } else {
    for (int i = 0; i < reg->nbodies; ++i) {
      const fmbBodyType* t = reg->bodies[i];
      if ((t->flags & FMB_TYPE_CONFORM_FIXTURE) && (fmb_type_dimensions(t->abi, t->dimensions) & dim)) return t->name;
    }
  }
  return NULL;
}

/* the scene spec of a probe: the fixture of the type's dimension */
static SceneSpec scene_spec(const fmbRegistry* reg, int joint, int spatial, const char* outputs) {
  const unsigned dim = spatial ? FMB_DIM_SPATIAL : FMB_DIM_PLANAR;
  SceneSpec s = {joint, -9.81, outputs, fixture_type(reg, 0, dim), fixture_type(reg, 1, dim), spatial};
  return s;
}

/* Writes the scene; returns the file line (1-based) of the probe's first item line. The fixture
   (fmbJointType's comment): body a pinned to ground at its left end, body b to its right, of the
   types flagged FMB_TYPE_CONFORM_FIXTURE (a rigid body and a pin). The spatial fixture is the same
   in space: a (centre [0.5, 0, 0]) on a ball joint at its end [-0.5, 0, 0], b at [1.5, 0, 0], both
   turning about all three axes, gravity along -y as in the plane. */
static int scene_write(const char* path, const char* type, const Lines* l, const SceneSpec* s) {
  /* never through a link that someone else put in the work folder (O_NOFOLLOW) */
  const int fd = open(path, O_WRONLY | O_CREAT | O_TRUNC | O_NOFOLLOW | O_CLOEXEC, 0666);
  FILE* f = fd >= 0 ? fdopen(fd, "w") : NULL;
  if (!f) {
    if (fd >= 0) close(fd);
    return -1;
  }
  int line = 1;
#define EMIT(...) (fprintf(f, __VA_ARGS__), line++)
  EMIT("solver: {t_end: %g, rtol: 1e-10, atol: 1e-12, output_step: %g}\n", CONFORM_T_END, CONFORM_T_END / 100);
  if (s->spatial) {
    EMIT("dimension: 3\n");
    EMIT("gravity: [0, %g, 0]\n", s->gravity);
    EMIT("bodies:\n");
    /* a's velocity is omega x [0.5, 0, 0]: consistent with the ball joint */
    EMIT("  - {name: a, type: %s, mass: 1, inertia: [0.1, 0.08, 0.05], position: [0.5, 0, 0], velocity: [0, 0.5, 0.2], "
         "angular_velocity: [0.3, -0.4, 1]}\n",
         s->fixture_body);
    EMIT("  - {name: b, type: %s, mass: 1.5, inertia: [0.2, 0.15, 0.1], position: [1.5, 0, 0], velocity: [0.3, -0.2, "
         "0.1], angular_velocity: [0.5, 0.2, -1]}\n",
         s->fixture_body);
  } else {
    EMIT("gravity: [0, %g]\n", s->gravity);
    EMIT("bodies:\n");
    EMIT("  - {name: a, type: %s, mass: 1, inertia: 0.1, position: [0.5, 0], velocity: [0, 0.5], angular_velocity: "
         "1}\n",
         s->fixture_body);
    EMIT("  - {name: b, type: %s, mass: 1.5, inertia: 0.2, position: [1.5, 0], velocity: [0.3, -0.2], "
         "angular_velocity: -1}\n",
         s->fixture_body);
  }
  if (!s->joint) EMIT("  - name: probe\n    type: %s\n", type), line++;
  const int first_body_line = line;
  if (!s->joint)
    for (int i = 0; i < l->n; ++i) EMIT("    %s\n", l->line[i]);
  EMIT("joints:\n");
  EMIT("  - {name: pin, type: %s, body1: ground, body2: a, point2: [-0.5, 0%s]}\n", s->fixture_joint,
       s->spatial ? ", 0" : "");
  if (s->joint) EMIT("  - name: probe\n    type: %s\n", type), line++;
  const int first_joint_line = line;
  if (s->joint)
    for (int i = 0; i < l->n; ++i) EMIT("    %s\n", l->line[i]);
  if (s->outputs) EMIT("outputs: [%s]\n", s->outputs);
#undef EMIT
  fclose(f);
  return s->joint ? first_joint_line : first_body_line;
}

static fmbModel* scene_load(const char* path, const char* type, const Lines* l, const SceneSpec* s,
                            const fmbRegistry* reg, fmbDiag* d, int* first_line) {
  memset(d, 0, sizeof *d);
  const int fl = scene_write(path, type, l, s);
  if (first_line) *first_line = fl;
  if (fl < 0) {
    fmb_diag_set(d, FMB_EXIT_BAD_INPUT, path, 0, 0, "cannot write the conformance scene");
    return NULL;
  }
  return fmb_load(path, NULL, 0, reg, d);
}

/* ---- params: generated bad scenes --------------------------------------------------------- */

static int mentions(const char* msg, const char* key) {
  char q[128];
  snprintf(q, sizeof q, "'%s'", key);
  return strstr(msg, q) != NULL;
}

/* one bad value (NULL: the key left out) must be refused at its line, naming the key */
static void bad_case(Report* r, const char* path, const char* type, const Lines* example, const SceneSpec* s,
                     const fmbRegistry* reg, const char* key, const char* value) {
  Lines l = *example;
  const int idx = lines_set(&l, key, value);
  fmbDiag d;
  int first = 0;
  fmbModel* m = scene_load(path, type, &l, s, reg, &d, &first);
  char what[192];
  snprintf(what, sizeof what, value ? "refuses %s: %s" : "refuses a scene without required %s%s", key,
           value ? value : "");
  if (m) {
    fmb_free(m);
    result(r, 0, "params", "%s: accepted, expected exit 2 at the key's line", what);
    return;
  }
  const int want_line = value ? first + idx : 0;
  const int ok =
      d.code == FMB_EXIT_BAD_INPUT && d.line > 0 && (!want_line || d.line == want_line) && mentions(d.msg, key);
  if (ok)
    result(r, 1, "params", "%s (line %d)", what, d.line);
  else
    result(r, 0, "params", "%s: got exit %d at line %d (expected %d) '%s' (expected a message naming '%s')", what,
           d.code, d.line, want_line, d.msg, key);
}

static void check_params(Report* r, const char* path, const char* type, const fmbParam* params, const Lines* ex,
                         const SceneSpec* s, const fmbRegistry* reg) {
  if (!params) {
    result(r, 0, "params", "no parameter declarations (fmbBodyType.params): the keys cannot be checked or listed");
    return;
  }
  int ncase = 0;
  for (const fmbParam* p = params; p->key; ++p) {
    char v[64];
    if (p->flags & FMB_REQUIRED) bad_case(r, path, type, ex, s, reg, p->key, NULL), ncase++;
    switch (p->kind) {
      case FMB_PARAM_NUMBER:
        if (p->flags & FMB_POSITIVE) bad_case(r, path, type, ex, s, reg, p->key, "0"), ncase++;
        if (p->flags & FMB_NONNEGATIVE) bad_case(r, path, type, ex, s, reg, p->key, "-1"), ncase++;
        bad_case(r, path, type, ex, s, reg, p->key, "not_a_number"), ncase++;
        break;
      case FMB_PARAM_INT:
        snprintf(v, sizeof v, "%ld", p->lo - 1);
        bad_case(r, path, type, ex, s, reg, p->key, v), ncase++;
        snprintf(v, sizeof v, "%ld", p->hi + 1);
        bad_case(r, path, type, ex, s, reg, p->key, v), ncase++;
        break;
      case FMB_PARAM_VEC2: bad_case(r, path, type, ex, s, reg, p->key, "[1, 2, 3]"), ncase++; break;
      case FMB_PARAM_CHOICE: bad_case(r, path, type, ex, s, reg, p->key, "no_such_choice"), ncase++; break;
      case FMB_PARAM_BODY: bad_case(r, path, type, ex, s, reg, p->key, "no_such_body"), ncase++; break;
      case FMB_PARAM_JOINT: bad_case(r, path, type, ex, s, reg, p->key, "no_such_joint"), ncase++; break;
      case FMB_PARAM_TABLE: bad_case(r, path, type, ex, s, reg, p->key, "[[0, 1, 2]]"), ncase++; break;
      case FMB_PARAM_MAP: bad_case(r, path, type, ex, s, reg, p->key, "[1, 2]"), ncase++; break;
      case FMB_PARAM_VEC3: bad_case(r, path, type, ex, s, reg, p->key, "[1, 2]"), ncase++; break;
      case FMB_PARAM_QUAT: bad_case(r, path, type, ex, s, reg, p->key, "[0, 0, 0, 0]"), ncase++; break;
    }
  }
  /* the keys parse reads are declared: an unknown key's message lists what was read */
  Lines l = *ex;
  lines_set(&l, "conform_undeclared_key", "1");
  fmbDiag d;
  fmbModel* m = scene_load(path, type, &l, s, reg, &d, NULL);
  if (m) {
    fmb_free(m);
    result(r, 0, "params", "an unknown key is accepted: read keys only through the fmb_get_* accessors");
    return;
  }
  const char* list = strstr(d.msg, "expected one of: ");
  if (!list) {
    result(r, 0, "params", "an unknown key gave '%s', expected the unknown-key message", d.msg);
    return;
  }
  list += strlen("expected one of: ");
  char undeclared[512] = "";
  while (*list && *list != ')') {
    const size_t n = strcspn(list, ",)");
    char key[64];
    snprintf(key, sizeof key, "%.*s", (int)n, list);
    int known = 0;
    for (const char* const* k = fmb_item_keys; !known && *k; ++k) known = strcmp(*k, key) == 0;
    for (const fmbParam* p = params; !known && p->key; ++p) known = strcmp(p->key, key) == 0;
    if (!known) snprintf(undeclared + strlen(undeclared), sizeof undeclared - strlen(undeclared), " %s", key);
    list += n;
    while (*list == ',' || *list == ' ') ++list;
  }
  result(r, !undeclared[0], "params", "%d generated bad scenes; keys read but not declared:%s", ncase,
         undeclared[0] ? undeclared : " none");
}

/* ---- bodies: ops against differences -------------------------------------------------------- */

static double urand(unsigned* s) {
  *s = *s * 1103515245u + 12345u;
  return ((*s >> 8) & 0xffff) / 65535.0 - 0.5;
}

/* max |A - B| / max(max |B|, floor) over n entries */
static double rel_err(const double* A, const double* B, int n, double floor_) {
  double e = 0.0, s = floor_;
  for (int i = 0; i < n; ++i) {
    e = fmax(e, fabs(A[i] - B[i]));
    s = fmax(s, fabs(B[i]));
  }
  return e / s;
}

/* a spatial body's marker3 at two material points: dpos/dq against differences of pos, and the
   virtual rotation G against differences of R (dR/dq_k = [G_k]x R); the worst error relative to
   1 + |difference|. dp, G: 3 x n each */
static double marker3_error(const fmbBodyType* t, const void* self, double* q, int n, double* dp, double* G,
                            double* work) {
  static const double locals[2][3] = {{0.0, 0.0, 0.0}, {0.3, 0.05, -0.1}};
  double worst = 0.0;
  for (int k = 0; k < 2; ++k) {
    double pos[3], R[9], p1[3], p2[3], R1[9], R2[9];
    if (t->marker3(self, q, locals[k], pos, R, dp, G, n, work)) return INFINITY;
    for (int j = 0; j < n; ++j) {
      const double x0 = q[j], h = 1e-6 * (1.0 + fabs(x0));
      q[j] = x0 + h;
      t->marker3(self, q, locals[k], p1, R1, NULL, NULL, n, work);
      q[j] = x0 - h;
      t->marker3(self, q, locals[k], p2, R2, NULL, NULL, n, work);
      q[j] = x0;
      const double g[3] = {G[j], G[n + j], G[2 * n + j]};
      for (int i = 0; i < 3; ++i) {
        const double fd = (p1[i] - p2[i]) / (2 * h);
        worst = fmax(worst, fabs(dp[(size_t)i * n + j] - fd) / (1.0 + fabs(fd)));
        for (int c = 0; c < 3; ++c) { /* ([g]x R)_ic = (g x column c of R)_i */
          const int i1 = (i + 1) % 3, i2 = (i + 2) % 3;
          const double an = g[i1] * R[3 * i2 + c] - g[i2] * R[3 * i1 + c];
          const double fdR = (R1[3 * i + c] - R2[3 * i + c]) / (2 * h);
          worst = fmax(worst, fabs(an - fdR) / (1.0 + fabs(fdR)));
        }
      }
    }
  }
  return worst;
}

static void check_body_ops(Report* r, const fmbModel* m, fmbWorkspace* w, int b, const double* y, int spatial) {
  const fmbBodyInst* bi = &m->body[b];
  const fmbBodyType* t = bi->type;
  const int n = bi->nq;
  double* work = fmb_workspace_plugin(w) + bi->workadr;
  double* buf = calloc((size_t)(8 * n + 6 * n * n + 16), sizeof(double));
  double *q = buf, *v = q + n, *a = v + n, *R0 = a + n, *R1 = R0 + n, *Rm = R1 + n;
  double *K = Rm + n, *C = K + n * n, *M = C + n * n, *Kd = M + n * n, *Cd = Kd + n * n, *Md = Cd + n * n;
  unsigned seed = 11;
  for (int i = 0; i < n; ++i) {
    q[i] = y[bi->qadr + i] + 1e-2 * urand(&seed);
    v[i] = y[m->nq + bi->qadr + i] + 0.5 * urand(&seed);
    a[i] = 0.5 * urand(&seed);
  }
  /* central differences of the residual: K = dR/dq, C = dR/dv, M = dR/da (column-major) */
  double* xs[3] = {q, v, a};
  double* blocks[3] = {Kd, Cd, Md};
  int rc = 0;
  for (int k = 0; k < 3; ++k)
    for (int j = 0; j < n; ++j) {
      /* R is linear in a (R = M a - Q): a unit step there is exact and free of round-off */
      const double x0 = xs[k][j], h = k == 2 ? 1.0 : 1e-6 * (1.0 + fabs(x0));
      xs[k][j] = x0 + h;
      rc |= t->residual(bi->self, &m->env, q, v, a, R1, work);
      xs[k][j] = x0 - h;
      rc |= t->residual(bi->self, &m->env, q, v, a, Rm, work);
      xs[k][j] = x0;
      for (int i = 0; i < n; ++i) blocks[k][(size_t)j * n + i] = (R1[i] - Rm[i]) / (2 * h);
    }
  if (rc) result(r, 0, "residual", "the residual failed (%d) at the example's state", rc);
  const double* Muse = Md;
  if (t->jacobian) {
    rc = t->jacobian(bi->self, &m->env, q, v, a, K, C, M, work);
    const double eK = rel_err(K, Kd, n * n, 1e-12), eC = rel_err(C, Cd, n * n, 1e-12),
                 eM = rel_err(M, Md, n * n, 1e-12);
    result(r, !rc && eK < FD_TOL && eC < FD_TOL && eM < FD_TOL, "jacobian",
           "analytic vs central differences: K %.2g, C %.2g, M %.2g (tolerance %g)", eK, eC, eM, FD_TOL);
    Muse = M;
  } else {
    result(r, SKIP, "jacobian", "no jacobian op: the engine differentiates the residual (engine/fd.c)");
  }
  /* mass: symmetric, positive definite */
  double asym = 0.0, mmax = 1e-300;
  for (int i = 0; i < n; ++i)
    for (int j = 0; j < n; ++j) {
      asym = fmax(asym, fabs(Muse[(size_t)j * n + i] - Muse[(size_t)i * n + j]));
      mmax = fmax(mmax, fabs(Muse[(size_t)j * n + i]));
    }
  memcpy(Kd, Muse, (size_t)n * n * sizeof(double));
  const int chol = fmb_cholesky(n, Kd);
  result(r, asym <= 1e-9 * mmax, "mass", "M symmetric: max |M - M^T| / max |M| = %.2g", asym / mmax);
  if (chol && t->indefinite_mass && t->indefinite_mass(bi->self))
    result(r, SKIP, "mass", "M not positive definite at this perturbed state, as the type declares it can be: %s",
           t->indefinite_mass(bi->self));
  else
    result(r, chol == 0, "mass", "M positive definite (Cholesky %s)", chol ? "breaks down" : "succeeds");
  /* marker: derivatives against differences, at two material points */
  static const double locals[2][2] = {{0.0, 0.0}, {0.3, 0.05}};
  double worst = 0.0;
  if (spatial) worst = marker3_error(t, bi->self, q, n, K, C, work);
  for (int k = 0; k < 2 && !spatial; ++k) {
    double pos[2], ang, p1[2], p2[2], a1, a2;
    double* dp = K; /* 2 x n */
    double* da = C;
    if (t->marker(bi->self, q, locals[k], pos, &ang, dp, da, work)) continue;
    for (int j = 0; j < n; ++j) {
      const double x0 = q[j], h = 1e-6 * (1.0 + fabs(x0));
      q[j] = x0 + h;
      t->marker(bi->self, q, locals[k], p1, &a1, NULL, NULL, work);
      q[j] = x0 - h;
      t->marker(bi->self, q, locals[k], p2, &a2, NULL, NULL, work);
      q[j] = x0;
      const double fd[3] = {(p1[0] - p2[0]) / (2 * h), (p1[1] - p2[1]) / (2 * h), (a1 - a2) / (2 * h)};
      const double an[3] = {dp[j], dp[n + j], da[j]};
      for (int i = 0; i < 3; ++i) worst = fmax(worst, fabs(an[i] - fd[i]) / (1.0 + fabs(fd[i])));
    }
  }
  result(r, worst < FD_TOL, "marker", "%s derivatives vs central differences: %.2g",
         spatial ? "position and virtual rotation (marker3)" : "position and angle", worst);
  /* leave-out: no gravity in the scene, so env->gravity must not be read (it is NaN here) */
  fmbEnv nog = {{NAN, NAN}, 0, {NAN, NAN, NAN}};
  rc = t->residual(bi->self, &nog, q, v, a, R0, work);
  int finite = !rc;
  for (int i = 0; i < n; ++i) finite &= isfinite(R0[i]);
  fmbEnergy e = {0, 0, 0, 0};
  if (t->energy) t->energy(bi->self, &nog, q, v, &e, work);
  finite &= isfinite(e.kinetic) && isfinite(e.strain) && isfinite(e.spring) && e.gravity == 0.0;
  result(r, finite, "gravity", "with has_gravity = 0 the residual and energy leave gravity out%s",
         finite ? "" : " (they read env->gravity or report a gravity energy)");
  free(buf);
}

/* The sparse Jacobian (fmbBodyType.pattern_jacobian) summed into dense blocks over [R; Rz] x
   [q; z] (K), v (C), a (M), against central differences of residual_aux (or residual); every
   difference outside the declared pattern must vanish (a missing pair would silently drop a
   coupling from the Newton matrix). */
static void check_pattern_jacobian(Report* r, const fmbModel* m, fmbWorkspace* w, int b, const double* y) {
  const fmbBodyInst* bi = &m->body[b];
  const fmbBodyType* t = bi->type;
  if (!t->pattern_jacobian || !t->pattern) {
    result(r, SKIP, "pattern", "no pattern_jacobian op");
    return;
  }
  const long np = t->pattern(bi->self, NULL, NULL);
  if (np < 0) { /* one dense block: the engine uses the jacobian op (checked above) */
    result(r, SKIP, "pattern", "dense block at this size: the jacobian op serves it");
    return;
  }
  const int n = bi->nq, nz = t->naux ? t->naux(bi->self) : 0, N = n + nz;
  double* work = fmb_workspace_plugin(w) + bi->workadr;
  const size_t NN = (size_t)N * N, Nn = (size_t)N * n;
  double* buf =
      calloc(3 * (size_t)n + (size_t)nz + 3 * (size_t)N + 2 * (NN + 2 * Nn) + 3 * (size_t)np + 8, sizeof(double));
  int* pr = calloc(2 * (size_t)np + 2, sizeof(int));
  if (!buf || !pr) {
    result(r, 0, "pattern", "out of memory");
    free(buf);
    free(pr);
    return;
  }
  int* pc = pr + np + 1;
  double *q = buf, *v = q + n, *a = v + n, *z = a + n, *F1 = z + nz, *Fm = F1 + N, *F0 = Fm + N;
  double *Ka = F0 + N, *Ca = Ka + NN, *Ma = Ca + Nn, *Kd = Ma + Nn, *Cd = Kd + NN, *Md = Cd + Nn;
  double *Kp = Md + Nn, *Cp = Kp + np, *Mp = Cp + np;
  unsigned seed = 23;
  for (int i = 0; i < n; ++i) {
    q[i] = y[bi->qadr + i] + 1e-2 * urand(&seed);
    v[i] = y[m->nq + bi->qadr + i] + 0.5 * urand(&seed);
    a[i] = 0.5 * urand(&seed);
  }
  int rc = 0;
  if (nz) rc |= t->aux_initial ? t->aux_initial(bi->self, &m->env, q, v, a, z, work) : 1;
  for (int i = 0; i < nz; ++i) z[i] *= 1.0 + 0.01 * urand(&seed); /* off the consistent z: Rz != 0 */
  t->pattern(bi->self, pr, pc);
  rc |= t->pattern_jacobian(bi->self, &m->env, q, v, a, nz ? z : NULL, Kp, Cp, Mp, work);
  for (long k = 0; k < np; ++k) {
    if (pr[k] < 0 || pr[k] >= N || pc[k] < 0 || pc[k] >= N) {
      result(r, 0, "pattern", "pair %ld = (%d, %d) outside the %d x %d block", k, pr[k], pc[k], N, N);
      free(buf);
      free(pr);
      return;
    }
    Ka[(size_t)pc[k] * N + pr[k]] += Kp[k];
    if (pc[k] < n) {
      Ca[(size_t)pc[k] * N + pr[k]] += Cp[k];
      Ma[(size_t)pc[k] * N + pr[k]] += Mp[k];
    }
  }
  /* [R; Rz] at (q, v, a, z) */
#define EVAL(F)                                                        \
  (nz ? t->residual_aux(bi->self, &m->env, q, v, a, z, F, F + n, work) \
      : t->residual(bi->self, &m->env, q, v, a, F, work))
  double* xs[4] = {q, v, a, z};
  for (int k = 0; k < 4; ++k) {
    const int len = k == 3 ? nz : n;
    for (int j = 0; j < len; ++j) {
      const double x0 = xs[k][j], h = k == 2 ? 1.0 : 1e-6 * (1.0 + fabs(x0));
      xs[k][j] = x0 + h;
      rc |= EVAL(F1);
      xs[k][j] = x0 - h;
      rc |= EVAL(Fm);
      xs[k][j] = x0;
      double* col = k == 0   ? Kd + (size_t)j * N
                    : k == 1 ? Cd + (size_t)j * N
                    : k == 2 ? Md + (size_t)j * N
                             : Kd + (size_t)(n + j) * N;
      for (int i = 0; i < N; ++i) col[i] = (F1[i] - Fm[i]) / (2 * h);
    }
  }
#undef EVAL
  if (rc) {
    result(r, 0, "pattern", "the residual or pattern_jacobian failed at the example's state");
    free(buf);
    free(pr);
    return;
  }
  const double eK = rel_err(Ka, Kd, (int)NN, 1e-12), eC = rel_err(Ca, Cd, (int)Nn, 1e-12),
               eM = rel_err(Ma, Md, (int)Nn, 1e-12);
  /* differences outside the pattern: mark the declared entries, then look at the rest */
  double scale = 1e-300, outside = 0.0;
  for (size_t i = 0; i < NN; ++i) scale = fmax(scale, fabs(Kd[i]));
  for (size_t i = 0; i < Nn; ++i) scale = fmax(scale, fmax(fabs(Cd[i]), fabs(Md[i])));
  memset(Ka, 0, NN * sizeof(double));
  for (long k = 0; k < np; ++k) Ka[(size_t)pc[k] * N + pr[k]] = 1.0;
  for (int c = 0; c < N; ++c)
    for (int i = 0; i < N; ++i) {
      if (Ka[(size_t)c * N + i] != 0.0) continue;
      outside = fmax(outside, fabs(Kd[(size_t)c * N + i]));
      if (c < n) outside = fmax(outside, fmax(fabs(Cd[(size_t)c * N + i]), fabs(Md[(size_t)c * N + i])));
    }
  result(r, eK < FD_TOL && eC < FD_TOL && eM < FD_TOL, "pattern",
         "pattern_jacobian vs central differences over %d rows and columns (%ld pairs): K %.2g, C %.2g, M %.2g "
         "(tolerance %g)",
         N, np, eK, eC, eM, FD_TOL);
  result(r, outside < FD_TOL * scale, "pattern",
         "largest difference outside the declared pattern: %.2g of the largest entry", outside / scale);
  free(buf);
  free(pr);
}

/* ---- joints: constraint rows and forces against differences -------------------------------- */

static void check_joint_ops(Report* r, fmbModel* m, fmbWorkspace* w, int j, const double* y) {
  const fmbJointInst* ji = &m->joint[j];
  const int nq = m->nq, nc = m->nc;
  double* buf = calloc((size_t)(4 * nq + 2 * nc + 2 * nc * nq + 8), sizeof(double));
  double *q = buf, *v = q + nq, *Q = v + nq, *dV = Q + nq, *phi1 = dV + nq, *phi2 = phi1 + nc;
  double *J = phi2 + nc, *Jd = J + nc * nq;
  unsigned seed = 5;
  for (int i = 0; i < nq; ++i) q[i] = y[i] + 1e-2 * urand(&seed);
  if (ji->nrows > 0) {
    int rc = fmb_constraints_all(m, w, 0.3, q, v, NULL, J, NULL, NULL);
    for (int c = 0; c < nq; ++c) {
      const double x0 = q[c], h = 1e-6 * (1.0 + fabs(x0));
      q[c] = x0 + h;
      rc |= fmb_constraints_all(m, w, 0.3, q, v, phi1, NULL, NULL, NULL);
      q[c] = x0 - h;
      rc |= fmb_constraints_all(m, w, 0.3, q, v, phi2, NULL, NULL, NULL);
      q[c] = x0;
      for (int row = 0; row < nc; ++row) Jd[(size_t)row * nq + c] = (phi1[row] - phi2[row]) / (2 * h);
    }
    /* only the probe's rows */
    const double e = rel_err(J + (size_t)ji->rowadr * nq, Jd + (size_t)ji->rowadr * nq, ji->nrows * nq, 1e-12);
    result(r, !rc && e < FD_TOL, "phi_q", "constraint derivative vs central differences: %.2g", e);
  }
  if (ji->type->force && !ji->type->energy)
    result(r, SKIP, "force", "a force without an energy op: not compared with a potential");
  if (ji->type->force && ji->type->energy) {
    /* at rest and without gravity the bodies (rigid) exert nothing: Q is the probe's force */
    const fmbEnv env = m->env;
    m->env.has_gravity = 0;
    memset(v, 0, (size_t)nq * sizeof(double));
    int rc = fmb_generalized_forces(m, w, 0.3, q, v, Q);
    for (int c = 0; c < nq; ++c) {
      const double x0 = q[c], h = 1e-6 * (1.0 + fabs(x0));
      fmbEnergy e1, e2;
      q[c] = x0 + h;
      fmb_energy(m, w, 0.3, q, v, &e1);
      q[c] = x0 - h;
      fmb_energy(m, w, 0.3, q, v, &e2);
      q[c] = x0;
      dV[c] = -(e1.spring - e2.spring) / (2 * h);
    }
    m->env = env;
    const double e = rel_err(Q, dV, nq, 1e-12);
    result(r, !rc && e < FD_TOL, "force", "generalized force vs -dV/dq of its energy: %.2g", e);
  }
  free(buf);
}

/* ---- runs: energy and outputs --------------------------------------------------------------- */

typedef struct {
  int ncol, nrow;
  char names[64][96];
  double* data; /* row-major */
} Table;

static int table_read(const char* path, Table* t) {
  memset(t, 0, sizeof *t);
  FILE* f = fopen(path, "r");
  if (!f) return -1;
  char line[8192];
  if (!fgets(line, sizeof line, f)) return fclose(f), -1;
  for (char* s = strtok(line, ",\n"); s && t->ncol < 64; s = strtok(NULL, ",\n"))
    snprintf(t->names[t->ncol++], sizeof t->names[0], "%s", s);
  int cap = 0;
  while (fgets(line, sizeof line, f)) {
    if (t->nrow == cap) {
      cap = cap ? 2 * cap : 256;
      double* d = realloc(t->data, (size_t)cap * t->ncol * sizeof(double));
      if (!d) return fclose(f), -1;
      t->data = d;
    }
    char* s = line;
    for (int c = 0; c < t->ncol; ++c) {
      t->data[(size_t)t->nrow * t->ncol + c] = strtod(s, &s);
      if (*s == ',') ++s;
    }
    t->nrow++;
  }
  fclose(f);
  return 0;
}
static int table_col(const Table* t, const char* name) {
  for (int c = 0; c < t->ncol; ++c)
    if (strcmp(t->names[c], name) == 0) return c;
  return -1;
}

/* run the scene; energy drift and the largest rise, relative to the energy scale */
static int energy_run(Report* r, const char* scene, const char* csv, const fmbRegistry* reg, double* drift,
                      double* rise, double* lost, int check_outputs) {
  fmbDiag d;
  fmbModel* m = fmb_load(scene, NULL, 0, reg, &d);
  if (!m) {
    result(r, 0, "energy", "the run's scene does not load: %s:%d:%d: %s", d.file, d.line, d.col, d.msg);
    return -1;
  }
  fmbRunOptions opt = {.csv_path = csv, .quiet = 1};
  fmbStats st;
  const int rc = fmb_run(m, &opt, &st, &d);
  fmb_free(m);
  if (rc) {
    result(r, 0, "energy", "the run stopped at t = %g: %s", st.t_reached, d.msg);
    return -1;
  }
  Table t;
  if (table_read(csv, &t) || t.nrow < 2) {
    result(r, 0, "energy", "cannot read the run's output %s", csv);
    free(t.data);
    return -1;
  }
  const int ct = table_col(&t, "energy.total");
  double scale = 1e-300;
  static const char* const parts[] = {"energy.kinetic", "energy.strain", "energy.gravity", "energy.spring"};
  for (int i = 0; i < t.nrow; ++i) {
    double s = 0.0;
    for (int k = 0; k < 4; ++k) s += fabs(t.data[(size_t)i * t.ncol + table_col(&t, parts[k])]);
    scale = fmax(scale, s);
  }
  const double e0 = t.data[ct];
  *drift = *rise = 0.0;
  for (int i = 1; i < t.nrow; ++i) {
    const double e = t.data[(size_t)i * t.ncol + ct];
    *drift = fmax(*drift, fabs(e - e0) / scale);
    *rise = fmax(*rise, (e - t.data[(size_t)(i - 1) * t.ncol + ct]) / scale);
  }
  *lost = (e0 - t.data[(size_t)(t.nrow - 1) * t.ncol + ct]) / scale;
  if (check_outputs) {
    int bad = -1;
    for (size_t k = 0; k < (size_t)t.nrow * t.ncol && bad < 0; ++k)
      if (!isfinite(t.data[k])) bad = (int)(k % (size_t)t.ncol);
    result(r, bad < 0, "outputs", "%d columns finite over %d rows%s%s", t.ncol, t.nrow, bad < 0 ? "" : ": not ",
           bad < 0 ? "" : t.names[bad]);
  }
  free(t.data);
  return 0;
}

static void check_energy(Report* r, const char* base, const char* type, const Lines* ex, const char* damped,
                         unsigned flags, int has_energy, const char* outputs, int joint, int spatial,
                         const fmbRegistry* reg) {
  char scene[1100], csv[1100];
  SceneSpec s = scene_spec(reg, joint, spatial, outputs);
  double drift, rise, lost;
  snprintf(scene, sizeof scene, "%s-free.yaml", base);
  snprintf(csv, sizeof csv, "%s-free.csv", base);
  if (scene_write(scene, type, ex, &s) < 0) return;
  if (energy_run(r, scene, csv, reg, &drift, &rise, &lost, 1)) return;
  if (flags & FMB_TYPE_DOES_WORK) {
    result(r, SKIP, "energy", "feeds energy in (FMB_TYPE_DOES_WORK): no conservation run");
    return;
  }
  if (!has_energy) {
    result(r, SKIP, "energy", "no energy op: the energy balance cannot be checked");
    return;
  }
  const double free_drift = drift;
  result(r, drift < ENERGY_TOL, "energy",
         "a free run keeps the total energy: drift %.2g of the energy scale (tolerance %g)", drift, ENERGY_TOL);
  if (!damped) {
    result(r, SKIP, "energy", "no example_damped: dissipation not checked");
    return;
  }
  Lines l = *ex;
  Lines extra;
  lines_parse(&extra, damped);
  for (int i = 0; i < extra.n; ++i) {
    char key[128];
    snprintf(key, sizeof key, "%.*s", (int)strcspn(extra.line[i], ":"), extra.line[i]);
    const char* val = extra.line[i] + strlen(key) + 1;
    while (*val == ' ') ++val;
    lines_set(&l, key, val);
  }
  snprintf(scene, sizeof scene, "%s-damped.yaml", base);
  snprintf(csv, sizeof csv, "%s-damped.csv", base);
  if (scene_write(scene, type, &l, &s) < 0 || energy_run(r, scene, csv, reg, &drift, &rise, &lost, 0)) return;
  /* dissipation must stand well above the integration error of the free run, and never reverse */
  result(
      r, lost > 100 * fmax(free_drift, 1e-10) && rise < ENERGY_TOL, "energy",
      "a damped run loses energy: %.2g of the energy scale lost (100 x the free run's drift: %.2g), largest rise %.2g",
      lost, 100 * fmax(free_drift, 1e-10), rise);
}

/* ---- the driver ------------------------------------------------------------------------------ */

int fmb_conform(fmbRegistry* reg, const char* type_name, const char* work_dir, FILE* report) {
  if (!reg || !type_name || !work_dir || !report) return -1;
  /* "TYPE:key=value,key=value" checks the example with those keys set (a variant such as
     beam:model=exact, or a setting such as beam:assembly=banded) */
  char name[128], label[300];
  snprintf(label, sizeof label, "%s", type_name);
  snprintf(name, sizeof name, "%.*s", (int)strcspn(type_name, ":"), type_name);
  const char* extra = strchr(type_name, ':');
  const fmbBodyType* bt = NULL;
  const fmbJointType* jt = NULL;
  for (int i = 0; i < reg->nbodies && !bt; ++i)
    if (strcmp(reg->bodies[i]->name, name) == 0) bt = reg->bodies[i];
  for (int i = 0; i < reg->njoints && !bt && !jt; ++i)
    if (strcmp(reg->joints[i]->name, name) == 0) jt = reg->joints[i];
  if (!bt && !jt) return -1;
  type_name = name;
  Report r = {report, label, 0};
  const int joint = jt != NULL;
  /* a spatial-only type is probed in the spatial fixture; a type of both dimensions in the planar one */
  const int spatial =
      !(fmb_type_dimensions(joint ? jt->abi : bt->abi, joint ? jt->dimensions : bt->dimensions) & FMB_DIM_PLANAR);
  const char* example = joint ? jt->example : bt->example;
  if (!example) {
    result(&r, 0, "example", "the type declares no example instance (fmbBodyType.example): nothing can be checked");
    return r.failed;
  }
  char base[1024], scene[1100];
  snprintf(base, sizeof base, "%s/conform-%s", work_dir, type_name);
  Lines ex;
  lines_parse(&ex, example);
  for (const char* e = extra; e && *e;) { /* the "key=value" list after ':' */
    ++e;
    size_t len = 0; /* up to the next comma outside {} and [] (reduction={modes: 3, axial_modes: 1}) */
    for (int depth = 0; e[len] && (depth > 0 || e[len] != ','); ++len)
      depth += (e[len] == '{' || e[len] == '[') - (e[len] == '}' || e[len] == ']');
    char kv[256];
    snprintf(kv, sizeof kv, "%.*s", (int)len, e);
    char* eq = strchr(kv, '=');
    if (!eq || eq == kv) {
      result(&r, 0, "example", "'%s': expected TYPE:key=value[,key=value]", label);
      return r.failed;
    }
    *eq = '\0';
    lines_set(&ex, kv, eq + 1);
    snprintf(base + strlen(base), sizeof base - strlen(base), "-%s-%s", kv, eq + 1);
    e += len;
  }
  snprintf(scene, sizeof scene, "%s.yaml", base);
  SceneSpec s = scene_spec(reg, joint, spatial, NULL);
  if (!s.fixture_body || !s.fixture_joint) {
    result(&r, 0, "example",
           "no %s%s type in the registry declares FMB_TYPE_CONFORM_FIXTURE: the conformance scene has "
           "no fixture (register the built-in types too)",
           spatial ? "spatial " : "", !s.fixture_body ? "body" : "joint");
    return r.failed;
  }
  /* the declared parameters are the registered table's: a variant's own keys are checked by
     the plain type's run */
  if (!extra) check_params(&r, scene, type_name, joint ? jt->params : bt->params, &ex, &s, reg);

  fmbDiag d;
  fmbModel* m = scene_load(scene, type_name, &ex, &s, reg, &d, NULL);
  if (!m) {
    result(&r, 0, "example", "the example does not load: %s:%d:%d: %s", d.file, d.line, d.col, d.msg);
    return r.failed;
  }
  /* a variant (beam:model=exact) is its own ops table: check that one's outputs and damping */
  if (bt && m->nbody > 1 && m->body[m->nbody - 1].type) bt = m->body[m->nbody - 1].type;
  fmbData* run = fmb_data_new(m, NULL); /* the scratch of the checks below */
  fmbWorkspace* w = run ? run->w : NULL;
  double* y = calloc((size_t)m->ny, sizeof(double));
  double* yp = calloc((size_t)m->ny, sizeof(double));
  fmbStats st;
  const int ic = (w && y && yp) ? fmb_initial_conditions(m, w, y, yp, &st, &d) : -1;
  result(&r, ic == 0, "example", "loads and its initial state is consistent%s%s", ic ? ": " : "", ic ? d.msg : "");
  /* the probe: the last body or joint of the scene */
  char outputs[2048] = "energy.kinetic, energy.strain, energy.gravity, energy.spring, energy.total";
  /* the type's listed outputs that its lookup accepts literally (a listing may show a pattern) */
  const char* const* own = joint ? jt->output_names : bt->output_names;
  const void* self = joint ? m->joint[m->njoint - 1].self : m->body[m->nbody - 1].self;
  int (*lookup)(const void*, const char*) = joint ? jt->output_lookup : bt->output_lookup;
  for (const char* const* names = own; own && *own; ++own)
    if (fmb_type_output_id(lookup, self, names, *own) >= 0)
      snprintf(outputs + strlen(outputs), sizeof outputs - strlen(outputs), ", probe.%s", *own);
  const int has_coordinates = !joint && m->body[m->nbody - 1].nq > 0;
  if (ic == 0) {
    if (joint)
      check_joint_ops(&r, m, w, m->njoint - 1, y);
    else if (m->body[m->nbody - 1].nq > 0) {
      check_body_ops(&r, m, w, m->nbody - 1, y, spatial);
      check_pattern_jacobian(&r, m, w, m->nbody - 1, y);
    } else
      result(&r, 1, "dynamics", "no coordinates: nothing to differentiate");
  }
  if (!joint && !spatial && m->body[m->nbody - 1].nq >= 3)
    strncat(outputs, ", probe.x, probe.omega", sizeof outputs - strlen(outputs) - 1);
  free(y), free(yp);
  fmb_data_destroy(run);
  fmb_free(m);
  if (ic == 0)
    check_energy(&r, base, type_name, &ex, joint ? jt->example_damped : bt->example_damped,
                 joint ? jt->flags : bt->flags, joint || bt->energy || !has_coordinates, outputs, joint, spatial, reg);
  fprintf(report, "%s %s: %d failed checks\n", r.failed ? "FAIL" : "ok  ", type_name, r.failed);
  return r.failed;
}
