/* test_beam_output_cache.c — the beam's outputs share their passes per state (bodies/beam.c, "The
 * outputs' cache": energy.* and beam.ang_momentum one energy pass, the tip's u, x, y and u rate one
 * coupling integral, kept in the body's work keyed by the state). The independent value: each
 * output of each state evaluated alone (a model with that one output) in a fresh workspace,
 * where nothing can be reused. One workspace of the model with all the outputs then
 * evaluates the states in an order that would expose a stale entry (back and forth, a state that
 * differs from the previous one in one velocity only, then in one position only, the same state
 * twice), and every value must be the fresh workspace's bit for bit. Three output lists: with the
 * energies (the tip taking w_c from the energy pass), without them (ang_momentum filling the
 * cache without gravity), and the gravity energy alone after ang_momentum (Ug must not come from
 * a pass made without gravity). On the flexible pendulum (gravity) and the w15 spin-up. */
#include <stdlib.h>
#include <string.h>

#include "internal.h"
#include "testlib.h"

enum { NSTATE = 4 };

static void one_list(const char* scene_rel, const char* outputs) {
  char path[600], set_outputs[600];
  fmbt_path(scene_rel, path, sizeof path);
  snprintf(set_outputs, sizeof set_outputs, "outputs=%s", outputs);
  const char* ov[] = {set_outputs, "solver.t_end=0.2"};
  fmbDiag diag;
  fmbModel* m = fmb_load(path, ov, 2, fmb_builtin_registry(), &diag);
  if (!m) fprintf(stderr, "%s: %s\n", scene_rel, diag.msg);
  ENSURE(m != NULL);
  if (!m) return;
  const int ny = m->ny, nq = m->nq, nout = m->noutput;
  /* states: two of the run, then the second with one velocity changed, then with one position */
  double y[NSTATE][256], yp[NSTATE][256], t[NSTATE];
  ENSURE(ny <= 256);
  if (ny > 256) return;
  fmbData* d = fmb_data_new(m, &diag);
  ENSURE(d && fmb_init(m, d, &diag) == 0);
  for (int s = 0; s < 2; ++s) {
    ENSURE(fmb_advance(m, d, 0.05 * (s + 1), &diag) == 0);
    fmb_data_state(d, y[s], yp[s]);
    t[s] = fmb_data_time(d);
  }
  fmb_data_free(d);
  memcpy(y[2], y[1], sizeof y[1]);
  memcpy(yp[2], yp[1], sizeof yp[1]);
  y[2][nq + nq - 2] *= 1.001; /* a deformation rate near the tip */
  memcpy(y[3], y[1], sizeof y[1]);
  memcpy(yp[3], yp[1], sizeof yp[1]);
  y[3][nq - 2] *= 1.001; /* a deformation near the tip */
  t[2] = t[3] = t[1];
  double fresh[NSTATE][64], row[64];
  ENSURE(nout <= 64);
  if (nout > 64) return;
  /* the reference: each column alone (a model with that one output) in a fresh workspace */
  for (int c = 0; c < nout; ++c) {
    char one[200];
    snprintf(one, sizeof one, "outputs=[%s]", m->output[c].name);
    const char* ov1[] = {one, "solver.t_end=0.2"};
    fmbModel* m1 = c ? fmb_load(path, ov1, 2, fmb_builtin_registry(), &diag) : NULL;
    ENSURE(c == 0 || (m1 && m1->ny == ny));
    for (int s = 0; s < NSTATE; ++s) {
      if (c == 0) { /* t */
        fresh[s][0] = t[s];
        continue;
      }
      if (!m1) break;
      fmbWorkspace* w1 = fmb_workspace_new(m1);
      double r1[2];
      ENSURE(w1 && fmb_outputs_eval(m1, w1, t[s], y[s], yp[s], r1) == 0);
      fresh[s][c] = r1[1];
      fmb_workspace_free(w1);
    }
    fmb_free(m1);
  }
  /* the changed states must change some output, or the test could not see a stale one */
  ENSURE(memcmp(fresh[2], fresh[1], sizeof(double) * (size_t)nout) != 0); /* a velocity changed something */
  ENSURE(memcmp(fresh[3], fresh[1], sizeof(double) * (size_t)nout) != 0); /* a position changed something */
  fmbWorkspace* w = fmb_workspace_new(m);
  const int order[] = {0, 1, 0, 1, 2, 1, 3, 3, 2, 3, 0};
  int bad = 0;
  for (size_t k = 0; k < sizeof order / sizeof order[0]; ++k) {
    const int s = order[k];
    fmb_outputs_eval(m, w, t[s], y[s], yp[s], row);
    for (int c = 0; c < nout; ++c)
      if (memcmp(&row[c], &fresh[s][c], sizeof(double)) != 0 && bad++ < 5)
        fprintf(stderr, "%s %s: state %d (evaluation %zu), %s = %.17g, a fresh workspace %.17g\n", scene_rel, outputs,
                s, k, m->output[c].name, row[c], fresh[s][c]);
  }
  ENSURE(bad == 0);
  fmb_workspace_free(w);
  fmb_free(m);
}

int main(void) {
  const char* scenes[] = {"scenes/paper/pendulum.yaml", "scenes/paper/spinup_w15.yaml"};
  const char* lists[] = {
      "[beam.tip_u, beam.tip_v, beam.tip_x, beam.tip_y, beam.tip_u_rate, beam.ang_momentum, energy.kinetic, "
      "energy.strain, energy.gravity, energy.total, beam.node8_u, beam.node8_x]",
      "[beam.tip_x, beam.ang_momentum, beam.tip_u, beam.node8_y, beam.tip_u_rate]",
      "[beam.ang_momentum, energy.gravity, beam.tip_y]"};
  for (size_t i = 0; i < sizeof scenes / sizeof scenes[0]; ++i)
    for (size_t j = 0; j < sizeof lists / sizeof lists[0]; ++j) one_list(scenes[i], lists[j]);
  return fmbt_finish("beam output cache");
}
