/* models.c — one scene, several models (fmb_run_models, flexmbd.h): the scene loaded once per
 * model with `bodies.NAME.model=M` after its own overrides, each run written to a CSV of its own in
 * a temporary folder, and the CSVs merged side by side. The merge works on the text of the rows:
 * the values are the run's own %.12g (output.c's one CSV writer), so the merged table holds
 * exactly what each model's own run writes, with no second reading or formatting of numbers. */
#include <errno.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>
#include <sys/stat.h>
#include <unistd.h>

#include "internal.h"

#define MODEL_NAME_MAX 63
#define SET_MAX (FMB_NAME_MAX + MODEL_NAME_MAX + 32)

/* one model's CSV as lines of text (newline removed) */
typedef struct {
  char** line;
  long n, cap;
} Lines;

static void lines_free(Lines* l) {
  for (long i = 0; i < l->n; ++i) free(l->line[i]);
  free(l->line);
  memset(l, 0, sizeof *l);
}

/* 0, or -1 with why in err (the file cannot be read, or has no header) */
static int lines_read(const char* path, Lines* l, char* err, size_t errlen) {
  FILE* f = fopen(path, "r");
  if (!f) {
    snprintf(err, errlen, "%s: %s", path, strerror(errno));
    return -1;
  }
  char* buf = NULL;
  size_t cap = 0;
  ssize_t len;
  int rc = 0;
  while ((len = getline(&buf, &cap, f)) >= 0) {
    while (len > 0 && (buf[len - 1] == '\n' || buf[len - 1] == '\r')) buf[--len] = '\0';
    if (l->n == l->cap) {
      const long ncap = l->cap ? 2 * l->cap : 1024;
      char** grown = realloc(l->line, sizeof(char*) * (size_t)ncap);
      if (!grown) break;
      l->line = grown;
      l->cap = ncap;
    }
    if (!(l->line[l->n] = strdup(buf))) break;
    l->n++;
  }
  if (ferror(f) || !feof(f)) rc = -1, snprintf(err, errlen, "%s: could not read it whole (out of memory?)", path);
  free(buf);
  fclose(f);
  if (!rc && l->n < 1) rc = -1, snprintf(err, errlen, "%s: the run wrote no header", path);
  return rc;
}

/* the fields after a line's first (t): the text after its first comma ("" when none) */
static const char* after_t(const char* line) {
  const char* c = strchr(line, ',');
  return c ? c + 1 : "";
}

static int count_fields(const char* text) {
  if (!*text) return 0;
  int n = 1;
  for (; *text; ++text) n += *text == ',';
  return n;
}

/* t from the longest run, then each model's columns (`NAME@MODEL` in the header, `nan` after its
   last row) */
static int merge(FILE* f, const Lines* part, const char* const* models, int nmodel) {
  long nrow = 0;
  int longest = 0;
  for (int k = 0; k < nmodel; ++k)
    if (part[k].n - 1 > nrow) nrow = part[k].n - 1, longest = k;
  fputc('t', f);
  for (int k = 0; k < nmodel; ++k) {
    const char* h = after_t(part[k].line[0]);
    while (*h) {
      const size_t len = strcspn(h, ",");
      fprintf(f, ",%.*s@%s", (int)len, h, models[k]);
      h += len + (h[len] == ',');
    }
  }
  fputc('\n', f);
  for (long r = 1; r <= nrow; ++r) {
    const char* row = part[longest].line[r];
    fprintf(f, "%.*s", (int)strcspn(row, ","), row);
    for (int k = 0; k < nmodel; ++k) {
      if (r < part[k].n) {
        const char* rest = after_t(part[k].line[r]);
        if (*rest) fprintf(f, ",%s", rest);
      } else {
        for (int c = count_fields(after_t(part[k].line[0])); c > 0; --c) fputs(",nan", f);
      }
    }
    fputc('\n', f);
  }
  return ferror(f) ? -1 : 0;
}

/* the overrides that switch every named body to `model`, one per body (SET_MAX characters each) */
static void set_model(char* sets, const char* const* bodies, int nbody, const char* model) {
  for (int b = 0; b < nbody; ++b)
    snprintf(sets + (size_t)b * SET_MAX, SET_MAX, "bodies.%.*s.model=%s", FMB_NAME_MAX, bodies[b], model);
}

int fmb_run_models(const fmbSceneSource* scene, const char* const* bodies, int nbody, const char* const* models,
                   int nmodel, const fmbRunOptions* opt, fmbModelsResult* res, fmbDiag* diag) {
  fmbDiag local_diag;
  fmbModelsResult local_res;
  if (!diag) diag = &local_diag;
  if (!res) res = &local_res;
  memset(diag, 0, sizeof *diag);
  memset(res, 0, sizeof *res);
  const char* path = scene && scene->path ? scene->path : "";
  const char* misuse =
      !scene || !scene->path || !scene->reg || scene->noverrides < 0 || (scene->noverrides > 0 && !scene->overrides)
          ? "no scene (path, registry, overrides)"
      : !bodies || nbody < 1                                      ? "no body to switch"
      : !models || nmodel < 1 || nmodel > FMB_MODELS_MAX          ? "from 1 to 8 models"
      : !opt || !opt->csv_path || strcmp(opt->csv_path, "-") == 0 ? "the merged CSV needs a file (opt->csv_path)"
                                                                  : NULL;
  if (misuse) {
    fmb_diag_set(diag, FMB_EXIT_BAD_INPUT, path, 0, 0, "fmb_run_models: %s", misuse);
    return FMB_EXIT_BAD_INPUT;
  }
  for (int k = 0; k < nmodel; ++k)
    if (!models[k] || !*models[k] || strlen(models[k]) > MODEL_NAME_MAX) {
      fmb_diag_set(diag, FMB_EXIT_BAD_INPUT, path, 0, 0, "fmb_run_models: model %d has no name or one longer than %d",
                   k + 1, MODEL_NAME_MAX);
      return FMB_EXIT_BAD_INPUT;
    }
  /* two runs of one model would give two columns of one name (NAME@MODEL twice) */
  for (int k = 0; k < nmodel; ++k)
    for (int j = 0; j < k; ++j)
      if (strcmp(models[j], models[k]) == 0) {
        fmb_diag_set(diag, FMB_EXIT_BAD_INPUT, path, 0, 0,
                     "fmb_run_models: model '%s' is named twice (models %d and %d): each model runs once", models[k],
                     j + 1, k + 1);
        return FMB_EXIT_BAD_INPUT;
      }
  /* overrides: the scene's, then one per body for this model */
  const int nov = scene->noverrides + nbody;
  const char** ov = calloc((size_t)nov, sizeof(char*));
  char* sets = calloc((size_t)nbody, SET_MAX);
  Lines part[FMB_MODELS_MAX];
  memset(part, 0, sizeof part);
  char dir[600] = "", file[700];
  int rc = 0;
  if (!ov || !sets) {
    fmb_diag_set(diag, FMB_EXIT_SOLVER, path, 0, 0, "out of memory");
    rc = FMB_EXIT_SOLVER;
  }
  for (int i = 0; !rc && i < scene->noverrides; ++i) ov[i] = scene->overrides[i];
  for (int b = 0; b < nbody && !rc; ++b) ov[scene->noverrides + b] = sets + (size_t)b * SET_MAX;
  /* every model must load before any runs */
  /* the files the models read (scene, table files, plugins): the merged table may replace none */
  fmbInputs* inputs = fmb_inputs_new();
  if (!rc && !inputs) {
    fmb_diag_set(diag, FMB_EXIT_SOLVER, path, 0, 0, "out of memory");
    rc = FMB_EXIT_SOLVER;
  }
  for (int k = 0; k < nmodel && !rc; ++k) {
    set_model(sets, bodies, nbody, models[k]);
    fmbModel* m = fmb_load(scene->path, ov, nov, scene->reg, diag);
    if (!m) rc = diag->code ? diag->code : FMB_EXIT_BAD_INPUT;
    if (m) fmb_inputs_add(inputs, fmb_model_inputs(m));
    fmb_free(m);
  }
  /* refused before any run, not after all of them */
  char input[512];
  if (!rc && fmb_inputs_at(inputs, opt->csv_path, input, sizeof input)) {
    fmb_diag_set(diag, FMB_EXIT_BAD_INPUT, opt->csv_path, 0, 0,
                 "cannot write the merged table: it is the input '%s': refusing to overwrite it", input);
    rc = FMB_EXIT_BAD_INPUT;
  }
  /* each model's own CSV, in a folder of this call's (nothing of the caller's is touched) */
  if (!rc) {
    const char* tmp = getenv("TMPDIR");
    snprintf(dir, sizeof dir, "%s/flexmbd-models-XXXXXX", tmp && *tmp ? tmp : "/tmp");
    if (!mkdtemp(dir)) {
      fmb_diag_set(diag, FMB_EXIT_BAD_INPUT, dir, 0, 0, "cannot make a temporary folder: %s", strerror(errno));
      dir[0] = '\0';
      rc = FMB_EXIT_BAD_INPUT;
    }
  }
  int read = 0;
  for (int k = 0; k < nmodel && !rc; ++k) {
    snprintf(file, sizeof file, "%s/%s.csv", dir, models[k]);
    set_model(sets, bodies, nbody, models[k]);
    fmbModel* m = fmb_load(scene->path, ov, nov, scene->reg, &res->diag[k]);
    if (!m) {
      *diag = res->diag[k];
      rc = diag->code ? diag->code : FMB_EXIT_BAD_INPUT;
      res->code[k] = rc;
      res->ran = k + 1;
      break;
    }
    /* an animation (opt->vtk_dir, else the scene's `vtk` key) per model, in MODEL/ below it: one
       folder for all would hold the last model's frames under the first's collection */
    const char* vtk_base = opt->vtk_dir ? opt->vtk_dir : (m->vtk_dir[0] ? m->vtk_dir : NULL);
    char vtk[1200] = "";
    if (vtk_base && mkdir(vtk_base, 0777) != 0 && errno != EEXIST) {
      fmb_diag_set(&res->diag[k], FMB_EXIT_BAD_INPUT, vtk_base, 0, 0, "cannot create the VTK directory: %s",
                   strerror(errno));
      *diag = res->diag[k];
      rc = res->code[k] = FMB_EXIT_BAD_INPUT;
      res->ran = k + 1;
      fmb_free(m);
      break;
    }
    if (vtk_base && snprintf(vtk, sizeof vtk, "%s/%s", vtk_base, models[k]) >= (int)sizeof vtk) vtk[0] = '\0';
    const fmbRunOptions o = {.csv_path = file,
                             .quiet = opt->quiet,
                             .stop = opt->stop,
                             .vtk_dir = vtk[0] ? vtk : NULL,
                             .vtk_every = opt->vtk_every};
    res->code[k] = fmb_run(m, &o, &res->stats[k], &res->diag[k]);
    res->ran = k + 1;
    fmb_free(m);
    char err[900];
    if (lines_read(file, &part[k], err, sizeof err)) {
      fmb_diag_set(diag, FMB_EXIT_SOLVER, path, 0, 0, "model %s: %s", models[k], err);
      rc = FMB_EXIT_SOLVER;
    }
    remove(file);
    if (!rc) read = k + 1;
    if (res->code[k] == FMB_EXIT_INTERRUPTED) break; /* the models so far are written, the rest not run */
  }
  int worst = 0;
  for (int k = 0; k < res->ran; ++k)
    if (res->code[k] > worst) worst = res->code[k];
  const int interrupted = res->ran > 0 && res->code[res->ran - 1] == FMB_EXIT_INTERRUPTED;
  if (!rc && read > 0 && (read == nmodel || interrupted)) {
    char err[300] = "";
    fmbSafeFile* sf = fmb_safe_open_guarded(opt->csv_path, inputs, err, sizeof err); /* beside it, renamed in */
    FILE* f = fmb_safe_stream(sf);
    if (!f || merge(f, part, models, read)) {
      fmb_safe_close(sf, 0);
      fmb_diag_set(diag, FMB_EXIT_BAD_INPUT, opt->csv_path, 0, 0, "cannot write the merged table: %s",
                   err[0] ? err : "a write failed");
      rc = FMB_EXIT_BAD_INPUT;
    } else if (fmb_safe_close(sf, 1)) {
      fmb_diag_set(diag, FMB_EXIT_BAD_INPUT, opt->csv_path, 0, 0, "cannot write the merged table: %s", strerror(errno));
      rc = FMB_EXIT_BAD_INPUT;
    }
  }
  if (!rc && worst) {
    rc = worst;
    for (int k = 0; k < res->ran && !diag->code; ++k)
      if (res->code[k]) *diag = res->diag[k];
  }
  for (int k = 0; k < nmodel; ++k) lines_free(&part[k]);
  if (dir[0]) rmdir(dir);
  fmb_inputs_free(inputs);
  free(ov);
  free(sets);
  return rc > worst ? rc : worst;
}
