/*
 * test_library_analyses.c — the analyses callable from flexmbd.h without the command line:
 *  - fmb_campbell on the rotating cantilever (hub of radius 0) against the continuum: the first
 *    in-plane frequency mu_c^2 = mu_f1^2 - lambda^2 with the flapwise (Southwell-type) mu_f1(lambda)
 *    of test_modes_rotating.c (same reference, same 5e-4 tolerance), at all five speeds of one
 *    diagram; the diagram built in steps (fmb_campbell_new/modes_at/add) equal to the one-shot
 *    call (to 1e-9: ARPACK's start vector differs between calls); too many modes asked for and NULL arguments refused with exit 2;
 *  - fmb_run_models against each model's own run (fmb_run with --set bodies.beam.model=M): the
 *    merged columns NAME@MODEL hold exactly that run's values; a model that stops (ZOAC above its
 *    critical speed) gives exit 3, its stats and message, nan cells after its last row, and the
 *    other model complete; bad use refused with exit 2.
 */
#include "analysis.h"

static fmbSceneSource rotating(const char* const* ov, int nov, char* path, size_t len) {
  const fmbSceneSource s = {fmbt_path("tests/analysis/scenes/rotating.yaml", path, len), ov, nov,
                            fmb_builtin_registry()};
  return s;
}

/* the hub speed's key, `count` modes, quiet steady states */
static fmbCampbellOptions campbell_options(int count) {
  fmbCampbellOptions opt;
  memset(&opt, 0, sizeof opt);
  opt.speed_key = "joints.spin.speed";
  opt.count = count;
  opt.steady.quiet = 1;
  return opt;
}

static void campbell_against_continuum(void) {
  const double scale = seed_omega_scale();
  const double lambda[5] = {1, 2, 4, 8, 12};
  const double mu_f[5] = {3.681646814, 4.137319573, 5.585001421, 9.256837601, 13.17015049};
  double speeds[5];
  for (int i = 0; i < 5; ++i) speeds[i] = lambda[i] * scale;
  char path[1024];
  const char* ov[] = {"bodies.beam.model=complete"};
  const fmbSceneSource scene = rotating(ov, 1, path, sizeof path);
  const fmbCampbellOptions opt = campbell_options(2);
  fmbCampbell* c = NULL;
  fmbDiag d;
  ENSURE(fmb_campbell(&scene, &opt, speeds, 5, &c, &d) == 0);
  ENSURE(c && c->done == 5 && c->count == 2);
  if (!c || c->done != 5) return;
  for (int i = 0; i < 5; ++i) {
    const double exact = sqrt(mu_f[i] * mu_f[i] - lambda[i] * lambda[i]) * scale;
    printf("campbell lambda %4.1f: mode1 %.7f rad/s, continuum %.7f, error %.2e; MAC with the speed before %.4f\n",
           lambda[i], c->frequency[2 * i], exact, c->frequency[2 * i] / exact - 1.0, c->mac[2 * i]);
    ENSURE_REL(c->speed[i], speeds[i], 0.0);
    ENSURE_REL(c->frequency[2 * i], exact, 5e-4);
    /* the first bending mode is followed as itself: its shape changes little between speeds */
    ENSURE(c->mac[2 * i] > 0.9 && c->mac[2 * i] <= 1.0 + 1e-12);
    ENSURE(c->frequency[2 * i + 1] > c->frequency[2 * i]);
  }
  /* the same diagram in steps, as a caller computing each speed elsewhere would build it */
  fmbCampbell* s = fmb_campbell_new(speeds, 5, 2);
  ENSURE(s != NULL);
  for (int i = 0; s && i < 5; ++i) {
    fmbModes* modes = NULL;
    ENSURE(fmb_campbell_modes_at(&scene, &opt, speeds[i], &modes, &d) == 0);
    ENSURE(modes && modes->count >= 2 + FMB_CAMPBELL_EXTRA_MODES);
    ENSURE(fmb_campbell_add(s, modes, &d) == 0);
  }
  if (s) {
    ENSURE(s->done == 5);
    /* to the eigen-solver's precision, not bit for bit: ARPACK's random start vector continues its
       seed from one call to the next within a process (measured: 1e-13 apart) */
    double worst = 0.0;
    for (int k = 0; k < 10; ++k) {
      ENSURE_REL(s->frequency[k], c->frequency[k], 1e-9);
      ENSURE_NEAR(s->mac[k], c->mac[k], 1e-9);
      worst = fmax(worst, fabs(s->frequency[k] / c->frequency[k] - 1.0));
    }
    printf("campbell in steps vs in one call: frequencies within %.2e (relative)\n", worst);
    /* a sixth speed does not fit: refused, the modes freed (ASan: no leak) */
    fmbModes* extra = NULL;
    ENSURE(fmb_campbell_modes_at(&scene, &opt, speeds[0], &extra, &d) == 0);
    ENSURE(fmb_campbell_add(s, extra, &d) == FMB_EXIT_BAD_INPUT);
  }
  fmb_campbell_free(s);
  fmb_campbell_free(c);
}

static void campbell_refusals(void) {
  char path[1024];
  const char* ov[] = {"bodies.beam.elements=1"};
  const fmbSceneSource scene = rotating(ov, 1, path, sizeof path);
  fmbCampbellOptions opt = campbell_options(FMB_CAMPBELL_MAX_MODES);
  const double speeds[2] = {0.0, 1.0};
  fmbCampbell* c = NULL;
  fmbDiag d;
  ENSURE(fmb_campbell(&scene, &opt, speeds, 2, &c, &d) == FMB_EXIT_BAD_INPUT);
  ENSURE(strstr(d.msg, "has only") != NULL && c && c->done == 0);
  fmb_campbell_free(c);
  opt.count = FMB_CAMPBELL_MAX_MODES + 1;
  ENSURE(fmb_campbell(&scene, &opt, speeds, 2, &c, &d) == FMB_EXIT_BAD_INPUT && c == NULL);
  opt.count = 2;
  opt.speed_key = "joints.spin.nosuchkey";
  ENSURE(fmb_campbell(&scene, &opt, speeds, 2, &c, &d) == FMB_EXIT_BAD_INPUT && c && c->done == 0);
  fmb_campbell_free(c);
  opt.speed_key = NULL;
  ENSURE(fmb_campbell(&scene, &opt, speeds, 2, &c, &d) == FMB_EXIT_BAD_INPUT && c == NULL);
  ENSURE(fmb_campbell(NULL, &opt, speeds, 2, &c, &d) == FMB_EXIT_BAD_INPUT);
  ENSURE(fmb_campbell(&scene, &opt, NULL, 2, &c, NULL) == FMB_EXIT_BAD_INPUT);
  ENSURE(fmb_campbell_add(NULL, NULL, &d) == FMB_EXIT_BAD_INPUT);
  ENSURE(fmb_campbell_new(speeds, 0, 2) == NULL);
  fmb_campbell_free(NULL);
}

/* the column NAME of the model's own run equals NAME@MODEL of the merged table, row for row */
static void same_as_own_run(const fmbtCsv* merged, const char* scene_rel, const char* model, const char* name,
                            const char* t_end) {
  char set[64], t[64], col[128], out[64];
  snprintf(set, sizeof set, "bodies.beam.model=%s", model);
  snprintf(t, sizeof t, "solver.t_end=%s", t_end);
  snprintf(col, sizeof col, "%s@%s", name, model);
  snprintf(out, sizeof out, "models_own_%s.csv", model);
  const char* ov[] = {set, t};
  fmbtCsv own;
  fmbStats st;
  fmbt_run_read(scene_rel, ov, 2, out, &own, &st);
  const double *a = fmbt_col(merged, col), *b = fmbt_col(&own, name);
  ENSURE(a && b && own.nrow <= merged->nrow);
  int same = a && b;
  for (int r = 0; same && r < own.nrow; ++r) same = a[r] == b[r];
  ENSURE(same);
  printf("models: %s equals the %s model's own run over its %d rows: %s\n", col, model, own.nrow, same ? "yes" : "no");
  fmbt_csv_free(&own);
}

static void models(void) {
  char path[1024], out[1024];
  const char* bodies[] = {"beam"};
  fmbModelsResult res;
  fmbDiag d;
  {
    const char* ov[] = {"solver.t_end=2"};
    const fmbSceneSource scene = {fmbt_path("scenes/paper/spinup_w1.yaml", path, sizeof path), ov, 1,
                                  fmb_builtin_registry()};
    const char* list[] = {"complete", "exact"};
    const fmbRunOptions opt = {.csv_path = fmbt_out_path("models_w1.csv", out, sizeof out), .quiet = 1};
    ENSURE(fmb_run_models(&scene, bodies, 1, list, 2, &opt, &res, &d) == 0);
    ENSURE(res.ran == 2 && res.code[0] == 0 && res.code[1] == 0 && res.stats[0].status_ok && res.stats[1].status_ok);
    fmbtCsv merged;
    ENSURE(fmbt_csv_read(out, &merged) == 0);
    same_as_own_run(&merged, "scenes/paper/spinup_w1.yaml", "complete", "beam.tip_v", "2");
    same_as_own_run(&merged, "scenes/paper/spinup_w1.yaml", "exact", "beam.tip_v", "2");
    fmbt_csv_free(&merged);
  }
  {
    const fmbSceneSource scene = {fmbt_path("scenes/paper/spinup_w4.yaml", path, sizeof path), NULL, 0,
                                  fmb_builtin_registry()};
    const char* list[] = {"zoac", "complete"};
    const fmbRunOptions opt = {.csv_path = fmbt_out_path("models_w4.csv", out, sizeof out), .quiet = 1};
    ENSURE(fmb_run_models(&scene, bodies, 1, list, 2, &opt, &res, &d) == FMB_EXIT_SOLVER);
    ENSURE(res.ran == 2 && res.code[0] == FMB_EXIT_SOLVER && res.code[1] == 0);
    ENSURE(strstr(res.diag[0].msg, "diverging") != NULL && strstr(d.msg, "diverging") != NULL);
    fmbtCsv merged;
    ENSURE(fmbt_csv_read(out, &merged) == 0);
    const double *z = fmbt_col(&merged, "beam.tip_v@zoac"), *c = fmbt_col(&merged, "beam.tip_v@complete");
    ENSURE(z && c && isnan(z[merged.nrow - 1]) && isfinite(c[merged.nrow - 1]));
    ENSURE(res.stats[0].t_reached < 20.0 && res.stats[1].t_reached == 20.0);
    fmbt_csv_free(&merged);
  }
  {
    const fmbSceneSource scene = {fmbt_path("scenes/paper/spinup_w1.yaml", path, sizeof path), NULL, 0,
                                  fmb_builtin_registry()};
    const char* bad[] = {"complete", "cubic"};
    const fmbRunOptions opt = {.csv_path = fmbt_out_path("models_bad.csv", out, sizeof out), .quiet = 1};
    ENSURE(fmb_run_models(&scene, bodies, 1, bad, 2, &opt, &res, &d) == FMB_EXIT_BAD_INPUT);
    ENSURE(strstr(d.msg, "cubic") != NULL && res.ran == 0);
    const fmbRunOptions to_stdout = {.csv_path = "-"};
    ENSURE(fmb_run_models(&scene, bodies, 1, bad, 1, &to_stdout, &res, &d) == FMB_EXIT_BAD_INPUT);
    ENSURE(fmb_run_models(&scene, bodies, 1, bad, 0, &opt, &res, &d) == FMB_EXIT_BAD_INPUT);
    ENSURE(fmb_run_models(&scene, NULL, 1, bad, 1, &opt, NULL, NULL) == FMB_EXIT_BAD_INPUT);
    ENSURE(fmb_run_models(NULL, bodies, 1, bad, 1, &opt, &res, &d) == FMB_EXIT_BAD_INPUT);
  }
}

int main(void) {
  campbell_against_continuum();
  campbell_refusals();
  models();
  return fmbt_finish("test_library_analyses");
}
