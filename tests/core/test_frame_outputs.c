/*
 * test_frame_outputs.c — the frame outputs (x y theta omega vx vy) of every body with a frame, not
 * only of bodies with three or more coordinates (engine/output.c, body_has_frame).
 *
 * A point mass with two coordinates (docs/plugins.md's example, registered here in-process) has a
 * frame: its marker places its origin, with angle 0. Thrown under gravity from (0, 1) at (3, 4) m/s,
 * its outputs must follow the parabola x = 3t, y = 1 + 4t - g t^2/2, vx = 3, vy = 4 - g t,
 * theta = omega = 0 (before: `ball.x` was refused with "available: " and nothing after it). A scene
 * without `outputs:` writes its frame (before: a CSV with only t), and one whose CSV would hold t
 * alone is refused with exit 2. A body whose marker cannot place its origin has no frame.
 */
#include <stdlib.h>
#include <string.h>

#include "testlib.h"

typedef struct {
  double mass, pos[2], vel[2];
  int frameless; /* a body that refuses the point [0, 0]: it has no frame */
} Ball;

static int ball_parse(fmbParser* p, fmbNode item, void** self) {
  Ball* b = calloc(1, sizeof *b);
  if (!b) return fmb_parse_error(p, item, "out of memory");
  *self = b;
  return fmb_get_double(p, item, "mass", FMB_REQUIRED | FMB_POSITIVE, &b->mass) ||
                 fmb_get_vec2(p, item, "position", FMB_OPTIONAL, b->pos) ||
                 fmb_get_vec2(p, item, "velocity", FMB_OPTIONAL, b->vel) ||
                 fmb_get_int(p, item, "frameless", FMB_OPTIONAL, 0, 1, &b->frameless)
             ? -1
             : 0;
}
static void ball_destroy(void* self) { free(self); }
static int ball_ncoord(const void* self) {
  (void)self;
  return 2;
}
static void ball_initial(const void* self, double* q, double* v) {
  const Ball* b = self;
  memcpy(q, b->pos, sizeof b->pos);
  memcpy(v, b->vel, sizeof b->vel);
}
static int ball_residual(const void* self, const fmbEnv* env, const double* q, const double* v, const double* a,
                         double* R, double* work) {
  (void)q, (void)v, (void)work;
  const Ball* b = self;
  for (int i = 0; i < 2; ++i) R[i] = b->mass * (a[i] - (env->has_gravity ? env->gravity[i] : 0.0));
  return 0;
}
static int ball_marker(const void* self, const double* q, const double local[2], double pos[2], double* angle,
                       double* dpos_dq, double* dangle_dq, double* work) {
  (void)work;
  const Ball* b = self;
  if (b->frameless && local[0] == 0.0 && local[1] == 0.0) return -1;
  pos[0] = q[0] + local[0];
  pos[1] = q[1] + local[1];
  if (angle) *angle = 0.0;
  if (dpos_dq) dpos_dq[0] = 1, dpos_dq[1] = 0, dpos_dq[2] = 0, dpos_dq[3] = 1;
  if (dangle_dq) dangle_dq[0] = dangle_dq[1] = 0;
  return 0;
}
static const fmbBodyType ball_type = {.name = "ball",
                                      .abi = FMB_ABI_VERSION,
                                      .parse = ball_parse,
                                      .destroy = ball_destroy,
                                      .ncoord = ball_ncoord,
                                      .initial = ball_initial,
                                      .residual = ball_residual,
                                      .marker = ball_marker};
static const fmbBodyType* const ball_types[] = {&ball_type, NULL};
static const fmbPlugin ball_plugin = {.abi = FMB_ABI_VERSION, .name = "ball", .version = "1", .bodies = ball_types};

static fmbRegistry* reg;

/* write the scene text, load and run it; the load's or run's exit code, the CSV read back */
static int run_text(const char* name, const char* text, fmbtCsv* c, fmbDiag* diag) {
  char scene[1024], out[1024], file[128];
  snprintf(file, sizeof file, "%s.yaml", name);
  fmbt_out_path(file, scene, sizeof scene);
  snprintf(file, sizeof file, "%s.csv", name);
  fmbt_out_path(file, out, sizeof out);
  FILE* f = fopen(scene, "w");
  if (!f) return -1;
  fputs(text, f);
  fclose(f);
  memset(c, 0, sizeof *c);
  fmbModel* m = fmb_load(scene, NULL, 0, reg, diag);
  if (!m) return diag->code;
  fmbRunOptions opt = {.csv_path = out, .quiet = 1};
  fmbStats st;
  const int rc = fmb_run(m, &opt, &st, diag);
  fmb_free(m);
  if (rc == 0) fmbt_csv_read(out, c);
  return rc;
}

#define THROW                                                             \
  "solver: {t_end: 1.0, rtol: 1.0e-8, atol: 1.0e-10, output_step: 0.1}\n" \
  "gravity: [0, -9.81]\n"                                                 \
  "bodies:\n"                                                             \
  "  - {name: ball, type: ball, mass: 0.5, position: [0, 1], velocity: [3, 4]}\n"

int main(void) {
  fmbDiag diag;
  reg = fmb_registry_new();
  ENSURE(reg && fmb_registry_add(reg, fmb_builtin_plugin(), "built-in", &diag) == 0 &&
         fmb_registry_add(reg, &ball_plugin, "test", &diag) == 0);
  if (!reg) return 1;

  /* 1. the six frame outputs of a two-coordinate body against the parabola */
  fmbtCsv c;
  ENSURE(run_text("frame_ball", THROW "outputs: [ball.x, ball.y, ball.theta, ball.omega, ball.vx, ball.vy]\n", &c,
                  &diag) == 0);
  const double *t = fmbt_col(&c, "t"), *x = fmbt_col(&c, "ball.x"), *y = fmbt_col(&c, "ball.y"),
               *th = fmbt_col(&c, "ball.theta"), *om = fmbt_col(&c, "ball.omega"), *vx = fmbt_col(&c, "ball.vx"),
               *vy = fmbt_col(&c, "ball.vy");
  ENSURE((c.nrow) == (11));
  double err = 0.0;
  for (int r = 0; t && x && y && th && om && vx && vy && r < c.nrow; ++r) {
    const double tr = t[r];
    const double e[6] = {x[r] - 3.0 * tr, y[r] - (1.0 + 4.0 * tr - 0.5 * 9.81 * tr * tr),
                         th[r],           om[r],
                         vx[r] - 3.0,     vy[r] - (4.0 - 9.81 * tr)};
    for (int k = 0; k < 6; ++k) err = fmax(err, fabs(e[k]));
  }
  printf("point mass thrown: max |frame output - parabola| = %.3g over %d rows\n", err, c.nrow);
  ENSURE_NEAR(err, 0.0, 1e-6); /* rtol 1e-8 on values of order 1..5 */
  fmbt_csv_free(&c);

  /* 2. no `outputs:`: the frame of every moving body with one */
  ENSURE((run_text("frame_default", THROW, &c, &diag)) == (0));
  ENSURE(c.ncol == 5 && fmbt_col(&c, "ball.x") && fmbt_col(&c, "ball.omega"));
  fmbt_csv_free(&c);

  /* 3. a CSV of t alone is refused, at the list or the scene */
  ENSURE((run_text("frame_empty", THROW "outputs: []\n", &c, &diag)) == (FMB_EXIT_BAD_INPUT));
  printf("outputs: [] -> %s:%d:%d: %s\n", diag.file, diag.line, diag.col, diag.msg);
  ENSURE(diag.line == 5 && strstr(diag.msg, "only the time column t: 'outputs' is empty") != NULL);
  const char* frameless = "solver: {t_end: 1.0}\nbodies:\n  - {name: ball, type: ball, mass: 1, frameless: 1}\n";
  ENSURE((run_text("frame_none", frameless, &c, &diag)) == (FMB_EXIT_BAD_INPUT));
  printf("no outputs, no frame -> %s\n", diag.msg);
  ENSURE(strstr(diag.msg, "no 'outputs' and no body with a frame") != NULL);

  /* 4. a body whose marker cannot place its origin has no frame outputs, and says what it has */
  char text[512];
  snprintf(text, sizeof text, "%soutputs: [ball.x]\n", frameless);
  ENSURE((run_text("frame_refused", text, &c, &diag)) == (FMB_EXIT_BAD_INPUT));
  printf("frameless ball.x -> %s\n", diag.msg);
  ENSURE(strstr(diag.msg, "unknown quantity 'x'") != NULL);
  fmb_registry_free(reg);
  return fmbt_finish("test_frame_outputs");
}
