/* run_models.c — `flexmbd run SCENE --models zoac,foac,complete,exact -o OUT.csv`: the same scene
 * once per beam model (every body of type beam gets `model: M` through --set), the outputs side by
 * side in one CSV as `beam.tip_v@complete`, ..., and one stats line per model
 * (`stats: model=M status=...`); with --vtk DIR, each model's animation in DIR/MODEL. A model whose run stops (ZOAC diverging, FOAC losing its mass's
 * definiteness) keeps its rows; later rows of its columns are `nan`, and the exit code is 3.
 * The runs and the merge are the library's (fmb_run_models, engine/models.c); this file parses the
 * list, picks the beams and prints. */
#include <stdio.h>
#include <stdlib.h>
#include <string.h>

#include "cli.h"

static void print_model_stats(const char* model, const fmbStats* st) {
  char* text = NULL;
  size_t len = 0;
  FILE* mem = open_memstream(&text, &len);
  if (!mem) return;
  fmb_print_stats(st, mem);
  fclose(mem);
  const char* rest = strncmp(text, "stats: ", 7) == 0 ? text + 7 : text;
  fprintf(stderr, "stats: model=%s %s", model, rest);
  free(text);
}

int fmb_cli_run_models(const fmbCliScene* s, const char* list, const char* out, int quiet, const char* vtk,
                       int vtk_every, volatile sig_atomic_t* stop) {
  if (!out || strcmp(out, "-") == 0) {
    fprintf(stderr, "flexmbd run: --models needs the CSV in a file (-o OUT.csv)\n");
    return FMB_EXIT_BAD_INPUT;
  }
  char words[256];
  const char* model[FMB_MODELS_MAX];
  int nmodel = 0;
  if (snprintf(words, sizeof words, "%s", list) >= (int)sizeof words) {
    fprintf(stderr, "flexmbd run: --models list too long\n");
    return FMB_EXIT_BAD_INPUT;
  }
  for (char* tok = strtok(words, ","); tok; tok = strtok(NULL, ",")) {
    if (nmodel == FMB_MODELS_MAX || strlen(tok) > 63 || strspn(tok, "abcdefghijklmnopqrstuvwxyz") != strlen(tok)) {
      fprintf(stderr,
              "flexmbd run: --models expects up to %d model names separated by commas (zoac,foac,complete,exact), "
              "got '%s'\n",
              FMB_MODELS_MAX, list);
      return FMB_EXIT_BAD_INPUT;
    }
    for (int k = 0; k < nmodel; ++k)
      if (strcmp(model[k], tok) == 0) {
        fprintf(stderr, "flexmbd run: --models names '%s' twice ('%s'): each model runs once\n", tok, list);
        return FMB_EXIT_BAD_INPUT;
      }
    model[nmodel++] = tok;
  }
  if (nmodel == 0) {
    fprintf(stderr, "flexmbd run: --models needs at least one model (zoac,foac,complete,exact)\n");
    return FMB_EXIT_BAD_INPUT;
  }
  /* the beams to switch: every body of type beam */
  fmbDiag diag;
  fmbModel* m = fmb_load(s->scene, s->overrides, s->nover, fmb_cli_registry(), &diag);
  if (!m) { /* nothing ran: the error line is the last, no stats line */
    fmb_cli_print_diag(&diag);
    return diag.code ? diag.code : FMB_EXIT_BAD_INPUT;
  }
  /* the scene's table files are inputs now too: refuse before any run, not after all of them */
  fmb_cli_note_model(m);
  if (fmb_cli_check_output_not_input(out, NULL, 0)) {
    fmb_free(m);
    return FMB_EXIT_BAD_INPUT;
  }
  /* the beams' names point into m, kept until the runs are done */
  const int nbody = fmb_model_nbody(m);
  const char** beams = calloc((size_t)(nbody > 0 ? nbody : 1), sizeof *beams);
  int nbeam = 0;
  for (int i = 0; beams && i < nbody; ++i) {
    const char *name, *type;
    fmb_model_body(m, i, &name, &type);
    if (strcmp(type, "beam") == 0) beams[nbeam++] = name;
  }
  if (!beams || nbeam == 0) {
    if (beams)
      fprintf(stderr, "%s: error: --models switches the model of the scene's beams, and it has no body of type beam\n",
              s->scene);
    else
      fprintf(stderr, "flexmbd run: out of memory\n");
    free(beams);
    fmb_free(m);
    return beams ? FMB_EXIT_BAD_INPUT : FMB_EXIT_SOLVER;
  }
  if (s->nover + nbeam > FMB_CLI_MAX_OVERRIDES) {
    fprintf(stderr, "flexmbd run: too many --set overrides with --models\n");
    free(beams);
    fmb_free(m);
    return FMB_EXIT_BAD_INPUT;
  }
  const fmbSceneSource scene = {s->scene, s->overrides, s->nover, fmb_cli_registry()};
  const fmbRunOptions opt = {.csv_path = out, .quiet = quiet, .stop = stop, .vtk_dir = vtk, .vtk_every = vtk_every};
  fmbModelsResult* res = calloc(1, sizeof *res);
  if (!res) {
    fprintf(stderr, "flexmbd run: out of memory\n");
    free(beams);
    fmb_free(m);
    return FMB_EXIT_SOLVER;
  }
  const int rc = fmb_run_models(&scene, beams, nbeam, model, nmodel, &opt, res, &diag);
  int told = 0; /* diag is one of the runs' own, printed with its model */
  for (int k = 0; k < res->ran; ++k) {
    if (res->code[k]) {
      fprintf(stderr, "model %s: ", model[k]);
      fmb_cli_print_diag(&res->diag[k]);
      told |= strcmp(res->diag[k].msg, diag.msg) == 0;
    }
    if (res->code[k] != FMB_EXIT_BAD_INPUT) print_model_stats(model[k], &res->stats[k]); /* bad input ran nothing */
  }
  if (rc && !told) fmb_cli_print_diag(&diag);
  free(res);
  free(beams);
  fmb_free(m);
  return rc;
}
