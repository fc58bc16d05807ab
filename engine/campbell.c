/* campbell.c — Campbell diagrams (flexmbd.h): the modes of a rotating system's steady state at a
 * series of hub speeds, each mode followed by its shape. The model is fixed after load, so each
 * speed is a load of the scene with one more override (`speed_key=SPEED`), its steady state
 * (fmb_static: the rotating-frame terms included) and its modes (fmb_modes).
 *
 * Following a mode: at each new speed the pair (followed mode k, new mode j) with the largest
 * modal assurance criterion |a^H b|^2 / (|a|^2 |b|^2) against k's shape at the speed before is
 * assigned first, then the next largest among the rest (greedy), so two modes that cross in
 * frequency keep their own curves. More modes than followed are computed (EXTRA) so that a mode
 * coming down from above can take over a curve.
 *
 * A spatial scene's modes carry their family (flap, lag, axial, torsion: fmb_modes_classify)
 * about the spin axis; at speed 0, where the state does not turn, the axis is the one the drives
 * give at a unit speed (the scene loaded once more with `speed_key=1`). */
#include <stdio.h>
#include <stdlib.h>
#include <string.h>

#include "data.h"
#include "internal.h"

int fmb_load_steady(const fmbSceneSource* scene, const char* extra, const fmbStaticOptions* opt, fmbModel** m,
                    double** y, double** yp, fmbStaticResult* res, fmbDiag* diag) {
  fmbDiag local;
  if (!diag) diag = &local;
  memset(diag, 0, sizeof *diag);
  if (m) *m = NULL;
  if (y) *y = NULL;
  if (yp) *yp = NULL;
  if (!scene || !m || !y || !yp || !res || scene->noverrides < 0 || (scene->noverrides > 0 && !scene->overrides)) {
    fmb_diag_set(diag, FMB_EXIT_BAD_INPUT, scene && scene->path ? scene->path : "", 0, 0,
                 "fmb_load_steady: a NULL argument, or NULL overrides with a positive count");
    return FMB_EXIT_BAD_INPUT;
  }
  memset(res, 0, sizeof *res);
  const int n = scene->noverrides + (extra ? 1 : 0);
  const char** ov = malloc(sizeof(char*) * (size_t)(n + 1));
  if (!ov) {
    fmb_diag_set(diag, FMB_EXIT_SOLVER, scene->path ? scene->path : "", 0, 0, "out of memory");
    return FMB_EXIT_SOLVER;
  }
  for (int i = 0; i < scene->noverrides; ++i) ov[i] = scene->overrides[i];
  if (extra) ov[scene->noverrides] = extra;
  *m = fmb_load(scene->path, ov, n, scene->reg, diag);
  free(ov);
  if (!*m) return diag->code ? diag->code : FMB_EXIT_BAD_INPUT;
  const int ny = fmb_state_size(*m);
  *y = calloc((size_t)ny, sizeof(double));
  *yp = calloc((size_t)ny, sizeof(double));
  if (!*y || !*yp) {
    fmb_diag_set(diag, FMB_EXIT_SOLVER, (*m)->path, 0, 0, "out of memory");
    return FMB_EXIT_SOLVER;
  }
  return fmb_static(*m, opt, *y, *yp, res, diag);
}

static int campbell_count(const fmbCampbellOptions* opt) { return opt && opt->count > 0 ? opt->count : 4; }

/* the spin axis of the sweep (the drives' rotation at speed 1, time t) for a state at rest */
static int sweep_axis(const fmbSceneSource* scene, const fmbCampbellOptions* opt, double t, fmbRotation3* rot,
                      fmbDiag* diag) {
  char set[600];
  snprintf(set, sizeof set, "%s=1", opt->speed_key);
  const int n = scene->noverrides + 1;
  const char** ov = malloc(sizeof(char*) * (size_t)(n + 1));
  if (!ov) return FMB_EXIT_SOLVER;
  for (int i = 0; i < scene->noverrides; ++i) ov[i] = scene->overrides[i];
  ov[n - 1] = set;
  fmbModel* m = fmb_load(scene->path, ov, n, scene->reg, diag);
  free(ov);
  if (!m) return diag->code ? diag->code : FMB_EXIT_BAD_INPUT;
  fmbData* own = fmb_data_new(m, NULL); /* the run's scratch lives in a data object (issue 35) */
  fmbWorkspace* w = own ? own->w : NULL;
  double* q = calloc((size_t)m->nq + 1, sizeof(double));
  double* v = calloc((size_t)m->nq + 1, sizeof(double));
  int rc = w && q && v ? 0 : FMB_EXIT_SOLVER;
  for (int b = 1; !rc && b < m->nbody; ++b) {
    const fmbBodyInst* bi = &m->body[b];
    bi->type->initial(bi->self, q + bi->qadr, v + bi->qadr);
  }
  if (!rc) rc = fmb_fit_rotation3(m, w, t, q, rot, diag);
  free(q);
  free(v);
  fmb_data_destroy(own);
  fmb_free(m);
  return rc;
}

int fmb_campbell_modes_at(const fmbSceneSource* scene, const fmbCampbellOptions* opt, double speed, fmbModes** modes,
                          fmbDiag* diag) {
  fmbDiag local;
  if (!diag) diag = &local;
  memset(diag, 0, sizeof *diag);
  if (modes) *modes = NULL;
  if (!scene || !opt || !opt->speed_key || !modes) {
    fmb_diag_set(diag, FMB_EXIT_BAD_INPUT, scene && scene->path ? scene->path : "", 0, 0,
                 "fmb_campbell_modes_at: a NULL argument (scene, options, speed_key, modes)");
    return FMB_EXIT_BAD_INPUT;
  }
  char set[600];
  if (snprintf(set, sizeof set, "%s=%.17g", opt->speed_key, speed) >= (int)sizeof set) {
    fmb_diag_set(diag, FMB_EXIT_BAD_INPUT, "--set", 0, 0, "the speed key '%.60s...' is too long", opt->speed_key);
    return FMB_EXIT_BAD_INPUT;
  }
  fmbModel* m = NULL;
  double *y = NULL, *yp = NULL;
  fmbStaticResult res;
  int rc = fmb_load_steady(scene, set, &opt->steady, &m, &y, &yp, &res, diag);
  if (!rc) rc = fmb_modes(m, res.t, y, yp, campbell_count(opt) + FMB_CAMPBELL_EXTRA_MODES, opt->method, modes, diag);
  if (!rc && m->dimension == 3 && !(*modes)->family) { /* at rest: the sweep's axis */
    fmbRotation3 rot;
    fmbDiag ad;
    memset(&ad, 0, sizeof ad);
    if (!sweep_axis(scene, opt, res.t, &rot, &ad) && rot.speed != 0.0)
      fmb_modes_classify(m, res.t, y, *modes, rot.axis, rot.center, NULL);
  }
  free(y);
  free(yp);
  fmb_free(m);
  return rc;
}

fmbCampbell* fmb_campbell_new(const double* speeds, int nspeed, int count) {
  if (!speeds || nspeed < 1 || count < 1 || count > FMB_CAMPBELL_MAX_MODES) return NULL;
  fmbCampbell* c = calloc(1, sizeof *c);
  if (!c) return NULL;
  c->nspeed = nspeed;
  c->count = count;
  c->speed = malloc(sizeof(double) * (size_t)nspeed);
  c->frequency = calloc((size_t)nspeed * (size_t)count, sizeof(double));
  c->mac = calloc((size_t)nspeed * (size_t)count, sizeof(double));
  c->track = calloc((size_t)count, sizeof(int));
  c->family = calloc((size_t)nspeed * (size_t)count, sizeof(int));
  if (!c->speed || !c->frequency || !c->mac || !c->track || !c->family) {
    fmb_campbell_free(c);
    return NULL;
  }
  memcpy(c->speed, speeds, sizeof(double) * (size_t)nspeed);
  return c;
}

void fmb_campbell_free(fmbCampbell* c) {
  if (!c) return;
  fmb_modes_free(c->last);
  free(c->speed);
  free(c->frequency);
  free(c->mac);
  free(c->track);
  free(c->family);
  free(c);
}

int fmb_campbell_add(fmbCampbell* c, fmbModes* cur, fmbDiag* diag) {
  fmbDiag local;
  if (!diag) diag = &local;
  memset(diag, 0, sizeof *diag);
  if (!c || !cur || c->done >= c->nspeed) {
    fmb_modes_free(cur);
    fmb_diag_set(diag, FMB_EXIT_BAD_INPUT, "", 0, 0, "fmb_campbell_add: %s",
                 !c || !cur ? "a NULL diagram or modes" : "every speed of the diagram is done");
    return FMB_EXIT_BAD_INPUT;
  }
  const int count = c->count, i = c->done;
  if (cur->count < count) {
    fmb_diag_set(diag, FMB_EXIT_BAD_INPUT, "", 0, 0, "the scene has only %d modes; %d were asked for", cur->count,
                 count);
    fmb_modes_free(cur);
    return FMB_EXIT_BAD_INPUT;
  }
  double* freq = c->frequency + (size_t)i * count;
  double* mac = c->mac + (size_t)i * count;
  if (!c->last) {
    for (int k = 0; k < count; ++k) {
      c->track[k] = k;
      mac[k] = 1.0;
    }
  } else {
    /* greedy: the best remaining (followed, new) pair first */
    unsigned char taken_k[FMB_CAMPBELL_MAX_MODES] = {0};
    unsigned char* taken_j = calloc((size_t)cur->count, 1);
    int next[FMB_CAMPBELL_MAX_MODES];
    if (!taken_j) {
      fmb_modes_free(cur);
      fmb_diag_set(diag, FMB_EXIT_SOLVER, "", 0, 0, "out of memory");
      return FMB_EXIT_SOLVER;
    }
    for (int n = 0; n < count; ++n) {
      double best = -1.0;
      int bk = 0, bj = 0;
      for (int k = 0; k < count; ++k)
        for (int j = 0; j < cur->count && !taken_k[k]; ++j) {
          if (taken_j[j]) continue;
          const double v = fmb_modes_mac(c->last, c->track[k], cur, j);
          if (v > best) {
            best = v;
            bk = k;
            bj = j;
          }
        }
      taken_k[bk] = taken_j[bj] = 1;
      next[bk] = bj;
      mac[bk] = best;
    }
    free(taken_j);
    memcpy(c->track, next, sizeof(int) * (size_t)count);
  }
  for (int k = 0; k < count; ++k) freq[k] = cur->frequency[c->track[k]];
  for (int k = 0; k < count && c->family; ++k)
    c->family[(size_t)i * count + k] = cur->family ? cur->family[c->track[k]] : 0;
  fmb_modes_free(c->last);
  c->last = cur;
  c->done = i + 1;
  return 0;
}

int fmb_campbell(const fmbSceneSource* scene, const fmbCampbellOptions* opt, const double* speeds, int nspeed,
                 fmbCampbell** out, fmbDiag* diag) {
  fmbDiag local;
  if (!diag) diag = &local;
  memset(diag, 0, sizeof *diag);
  if (out) *out = NULL;
  if (!scene || !opt || !opt->speed_key || !speeds || nspeed < 1 || !out) {
    fmb_diag_set(diag, FMB_EXIT_BAD_INPUT, scene && scene->path ? scene->path : "", 0, 0,
                 "fmb_campbell: a NULL argument (scene, options, speed_key, speeds, out) or no speed");
    return FMB_EXIT_BAD_INPUT;
  }
  const int count = campbell_count(opt);
  if (count > FMB_CAMPBELL_MAX_MODES) {
    fmb_diag_set(diag, FMB_EXIT_BAD_INPUT, scene->path ? scene->path : "", 0, 0,
                 "fmb_campbell: %d modes asked for, at most %d can be followed", count, FMB_CAMPBELL_MAX_MODES);
    return FMB_EXIT_BAD_INPUT;
  }
  *out = fmb_campbell_new(speeds, nspeed, count);
  if (!*out) {
    fmb_diag_set(diag, FMB_EXIT_SOLVER, scene->path ? scene->path : "", 0, 0, "out of memory");
    return FMB_EXIT_SOLVER;
  }
  int rc = 0;
  for (int i = 0; !rc && i < nspeed; ++i) {
    fmbModes* cur = NULL;
    rc = fmb_campbell_modes_at(scene, opt, speeds[i], &cur, diag);
    if (!rc && (rc = fmb_campbell_add(*out, cur, diag)) != 0 && !diag->file[0])
      snprintf(diag->file, sizeof diag->file, "%s", scene->path ? scene->path : "");
  }
  return rc;
}

int fmb_campbell_family(const fmbCampbell* c, int k) {
  if (!c || !c->family || k < 0 || k >= c->count) return FMB_FAMILY_NONE;
  int votes[FMB_FAMILY_TORSION + 1] = {0}, best = FMB_FAMILY_NONE;
  for (int i = 0; i < c->done; ++i) {
    const int f = c->family[(size_t)i * c->count + k];
    if (f > FMB_FAMILY_NONE && f <= FMB_FAMILY_TORSION) ++votes[f];
  }
  for (int f = FMB_FAMILY_FLAP; f <= FMB_FAMILY_TORSION; ++f)
    if (votes[f] > votes[best]) best = f;
  return best;
}
