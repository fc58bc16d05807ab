/* run_models.c — `flexmbd run SCENE --models zoac,foac,complete,exact -o OUT.csv`: the same scene
 * once per beam model (every body of type beam gets `model: M` through --set), the outputs side by
 * side in one CSV as `beam.tip_v@complete`, ..., and one stats line per model
 * (`stats: model=M status=...`). A model whose run stops (ZOAC diverging, FOAC losing its mass's
 * definiteness) keeps its rows; later rows of its columns are `nan`, and the exit code is 3. */
#include <errno.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>
#include <unistd.h>

#include "cli.h"
#include "csv_table.h"

#define MAX_MODELS 8
#define MAX_BEAMS 32

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

int fmb_run_models(const fmbCliScene* s, const char* list, const char* out, int quiet, volatile sig_atomic_t* stop) {
  if (!out || strcmp(out, "-") == 0) {
    fprintf(stderr, "flexmbd run: --models needs the CSV in a file (-o OUT.csv)\n");
    return FMB_EXIT_BAD_INPUT;
  }
  char words[256];
  const char* model[MAX_MODELS];
  int nmodel = 0;
  if (snprintf(words, sizeof words, "%s", list) >= (int)sizeof words) {
    fprintf(stderr, "flexmbd run: --models list too long\n");
    return FMB_EXIT_BAD_INPUT;
  }
  for (char* tok = strtok(words, ","); tok; tok = strtok(NULL, ",")) {
    if (nmodel == MAX_MODELS || strlen(tok) > 63 || strspn(tok, "abcdefghijklmnopqrstuvwxyz") != strlen(tok)) {
      fprintf(stderr, "flexmbd run: --models expects up to %d model names separated by commas (zoac,foac,complete,exact), "
                      "got '%s'\n", MAX_MODELS, list);
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
  fmbStats stats;
  memset(&stats, 0, sizeof stats);
  fmbModel* m = fmb_load(s->scene, s->overrides, s->nover, fmb_cli_registry(), &diag);
  if (!m) {
    fmb_cli_print_diag(&diag);
    fmb_print_stats(&stats, stderr);
    return diag.code ? diag.code : FMB_EXIT_BAD_INPUT;
  }
  /* the scene's table files are inputs now too: refuse before any run, not after all of them */
  const char* scene_input[1] = {s->scene};
  if (fmb_cli_check_output_not_input(out, scene_input, 1)) {
    fmb_free(m);
    return FMB_EXIT_BAD_INPUT;
  }
  static char set[MAX_MODELS][MAX_BEAMS][224];
  char beam[MAX_BEAMS][128];
  int nbeam = 0;
  for (int i = 0; i < fmb_model_nbody(m); ++i) {
    const char *name, *type;
    fmb_model_body(m, i, &name, &type);
    if (strcmp(type, "beam") == 0 && nbeam < MAX_BEAMS) snprintf(beam[nbeam++], sizeof beam[0], "%s", name);
  }
  fmb_free(m);
  if (nbeam == 0) {
    fprintf(stderr, "%s: error: --models switches the model of the scene's beams, and it has no body of type beam\n",
            s->scene);
    return FMB_EXIT_BAD_INPUT;
  }
  if (s->nover + nbeam > FMB_CLI_MAX_OVERRIDES) {
    fprintf(stderr, "flexmbd run: too many --set overrides with --models\n");
    return FMB_EXIT_BAD_INPUT;
  }

  /* every model must load before any runs (a misspelt model is bad input, not a late failure) */
  const char* ov[MAX_MODELS][FMB_CLI_MAX_OVERRIDES];
  for (int k = 0; k < nmodel; ++k) {
    memcpy(ov[k], s->overrides, sizeof(ov[k][0]) * (size_t)s->nover);
    for (int b = 0; b < nbeam; ++b) {
      snprintf(set[k][b], sizeof set[k][b], "bodies.%.127s.model=%.63s", beam[b], model[k]);
      ov[k][s->nover + b] = set[k][b];
    }
    fmbModel* mk = fmb_load(s->scene, ov[k], s->nover + nbeam, fmb_cli_registry(), &diag);
    if (!mk) {
      fmb_cli_print_diag(&diag);
      fmb_print_stats(&stats, stderr);
      return diag.code ? diag.code : FMB_EXIT_BAD_INPUT;
    }
    fmb_free(mk);
  }

  fmbTable table[MAX_MODELS];
  memset(table, 0, sizeof table);
  int rc = 0, loaded = 0;
  /* each model's own CSV, in a folder of this run's (nothing of the user's is touched) */
  char partdir[600];
  const char* tmp = getenv("TMPDIR");
  snprintf(partdir, sizeof partdir, "%s/flexmbd-models-XXXXXX", tmp && *tmp ? tmp : "/tmp");
  if (!mkdtemp(partdir)) {
    fprintf(stderr, "flexmbd run: cannot make a temporary folder %s: %s\n", partdir, strerror(errno));
    return FMB_EXIT_BAD_INPUT;
  }
  for (int k = 0; k < nmodel; ++k) {
    char part[1024];
    if (snprintf(part, sizeof part, "%s/%s.csv", partdir, model[k]) >= (int)sizeof part) {
      fprintf(stderr, "flexmbd run: output path too long\n");
      rc = FMB_EXIT_BAD_INPUT;
      break;
    }
    memset(&stats, 0, sizeof stats);
    fmbModel* mk = fmb_load(s->scene, ov[k], s->nover + nbeam, fmb_cli_registry(), &diag);
    if (!mk) {
      fmb_cli_print_diag(&diag);
      print_model_stats(model[k], &stats);
      rc = diag.code ? diag.code : FMB_EXIT_BAD_INPUT;
      break;
    }
    fmbRunOptions opt = {.csv_path = part, .quiet = quiet, .stop = stop};
    int rk = fmb_run(mk, &opt, &stats, &diag);
    if (rk) {
      fprintf(stderr, "model %s: ", model[k]);
      fmb_cli_print_diag(&diag);
      if (rk > rc) rc = rk;
    }
    print_model_stats(model[k], &stats);
    fmb_free(mk);
    char err[512];
    if (fmb_table_load(part, &table[k], err, sizeof err)) {
      fprintf(stderr, "flexmbd run: %s\n", err);
      remove(part);
      rc = FMB_EXIT_SOLVER > rc ? FMB_EXIT_SOLVER : rc;
      break;
    }
    remove(part);
    loaded = k + 1;
    if (rk == FMB_EXIT_INTERRUPTED) break; /* the models run so far are written, the rest not run */
  }
  if (loaded > 0 && (loaded == nmodel || rc == FMB_EXIT_INTERRUPTED)) {
    /* one table: t from the longest run, then each model's columns in turn */
    long nrow = 0;
    int longest = 0;
    for (int k = 0; k < loaded; ++k)
      if (table[k].nrow > nrow) nrow = table[k].nrow, longest = k;
    char err[300] = "";
    fmbSafeFile* sf = fmb_safe_open(out, err, sizeof err); /* beside it, renamed into place */
    FILE* f = fmb_safe_stream(sf);
    if (!f) {
      fprintf(stderr, "flexmbd run: cannot write %s: %s\n", out, err[0] ? err : "no stream");
      fmb_safe_close(sf, 0);
      rc = FMB_EXIT_BAD_INPUT;
    } else {
      fprintf(f, "t");
      for (int k = 0; k < loaded; ++k)
        for (int c = 1; c < table[k].ncol; ++c) fprintf(f, ",%s@%s", table[k].name[c], model[k]);
      fprintf(f, "\n");
      for (long r = 0; r < nrow; ++r) {
        fprintf(f, "%.12g", fmb_table_at(&table[longest], r, 0));
        for (int k = 0; k < loaded; ++k)
          for (int c = 1; c < table[k].ncol; ++c) {
            if (r < table[k].nrow)
              fprintf(f, ",%.12g", fmb_table_at(&table[k], r, c));
            else
              fprintf(f, ",nan");
          }
        fprintf(f, "\n");
      }
      if (fmb_safe_close(sf, 1)) {
        fprintf(stderr, "flexmbd run: cannot write %s: %s\n", out, strerror(errno));
        rc = FMB_EXIT_BAD_INPUT;
      }
    }
  }
  for (int k = 0; k < nmodel; ++k) fmb_table_free(&table[k]);
  rmdir(partdir);
  return rc;
}
