/* ground.c — a fixed frame with a pose of its own (a base plate, a second anchor). No
 * coordinates; joints attach to it through its marker. The world frame "ground" is always
 * defined by the engine; declare a `type: ground` body only to name another fixed frame. */
#include <math.h>
#include <stdio.h>
#include <stdlib.h>

#include "flexmbd_plugin.h"

typedef struct {
  double pos[2], angle;
} Ground;

static int ground_parse(fmbParser* p, fmbNode item, void** self) {
  Ground* g = calloc(1, sizeof *g);
  if (!g) return fmb_parse_error(p, item, "out of memory");
  *self = g;
  return fmb_get_vec2(p, item, "position", 0, g->pos) || fmb_get_angle(p, item, "angle", FMB_POSE, &g->angle) ? -1 : 0;
}

static void ground_destroy(void* self) { free(self); }
static int ground_ncoord(const void* self) {
  (void)self;
  return 0;
}
static void ground_initial(const void* self, double* q, double* v) {
  (void)self;
  (void)q;
  (void)v;
}
static int ground_residual(const void* self, const fmbEnv* env, const double* q, const double* v, const double* a,
                           double* R, double* work) {
  (void)self, (void)env, (void)q, (void)v, (void)a, (void)R, (void)work;
  return 0;
}
static int ground_marker(const void* self, const double* q, const double local[2], double pos[2], double* angle,
                         double* dpos_dq, double* dangle_dq, double* work) {
  (void)q, (void)dpos_dq, (void)dangle_dq, (void)work;
  const Ground* g = self;
  const double frame[3] = {g->pos[0], g->pos[1], g->angle};
  fmb_frame_point(frame, local, pos, angle, NULL, NULL);
  return 0;
}

static void ground_describe(const void* self, FILE* out) {
  const Ground* g = self;
  fprintf(out, "fixed frame at (%g, %g), angle %g\n", g->pos[0], g->pos[1], g->angle);
}

static const fmbParam ground_params[] = {
    {.key = "position", .kind = FMB_PARAM_VEC2, .unit = "m", .fallback = "[0, 0]", .doc = "origin of the fixed frame"},
    {.key = "angle", .kind = FMB_PARAM_NUMBER, .unit = "rad", .fallback = "0", .doc = "orientation of the fixed frame"},
    {.key = NULL},
};

const fmbBodyType fmb_body_ground = {
    .name = "ground",
    .abi = FMB_ABI_VERSION,
    .parse = ground_parse,
    .describe = ground_describe,
    .destroy = ground_destroy,
    .ncoord = ground_ncoord,
    .initial = ground_initial,
    .residual = ground_residual,
    .marker = ground_marker,
    .params = ground_params,
    .example = "position: [0.5, 0.2]\nangle: 0.1\n",
};
