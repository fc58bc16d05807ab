/* run_serve.c — `flexmbd run SCENE --serve [--set PATH=VALUE]... [--plugin x.so]...`: a runner
 * that stays, for `flexmbd sweep --runner serve` (docs/sweep.md). Each line on stdin asks for one
 * run of the scene, `OUT.csv<TAB>PATH=VALUE<TAB>...`; it is loaded and run exactly as
 * `flexmbd run SCENE -o OUT.csv --quiet --set ...` would (the same fmb_load and fmb_run), and
 * one line answers on stdout: `EXIT<TAB>stats: ...<TAB>message`. Ends at the end of stdin.
 * What it saves is the process start of each run (exec and linking: ~3 ms of CPU per run, as
 * much as a four-bar run computes); what it gives up is a fresh process per run: a crash or a
 * hang ends the runner, which the sweep records for the run in flight and replaces. */
#include <stdio.h>
#include <stdlib.h>
#include <string.h>

#include "cli.h"

int fmb_run_serve(const fmbCliScene* s) {
  const char* sets[FMB_CLI_MAX_OVERRIDES + 128];
  char* line = NULL;
  size_t cap = 0;
  ssize_t got;
  while ((got = getline(&line, &cap, stdin)) > 0) {
    if (line[got - 1] == '\n') line[--got] = '\0';
    int n = 0;
    for (int k = 0; k < s->nover; ++k) sets[n++] = s->overrides[k];
    char* save = NULL;
    const char* out = strtok_r(line, "\t", &save);
    for (char* t = strtok_r(NULL, "\t", &save); t && n < (int)(sizeof sets / sizeof sets[0]);
         t = strtok_r(NULL, "\t", &save))
      sets[n++] = t;
    fmbDiag diag;
    memset(&diag, 0, sizeof diag);
    fmbStats stats;
    memset(&stats, 0, sizeof stats);
    char msg[sizeof diag.file + sizeof diag.msg + 64] = "";
    int rc;
    fmbModel* m = out ? fmb_load(s->scene, sets, n, fmb_cli_registry(), &diag) : NULL;
    if (!m) {
      rc = diag.code ? diag.code : FMB_EXIT_BAD_INPUT;
      if (out)
        fmb_cli_format_diag(&diag, msg, sizeof msg);
      else
        snprintf(msg, sizeof msg, "error: an empty request");
    } else {
      fmbRunOptions opt = {.csv_path = out, .quiet = 1};
      rc = fmb_run(m, &opt, &stats, &diag);
      if (rc) fmb_cli_format_diag(&diag, msg, sizeof msg);
      fmb_free(m);
    }
    for (char* c = msg; *c; ++c)
      if (*c == '\t' || *c == '\n') *c = ' ';
    char* text = NULL;
    size_t len = 0;
    FILE* ms = open_memstream(&text, &len);
    if (ms) {
      fmb_print_stats(&stats, ms); /* the stats line of `flexmbd run`, the same function */
      fclose(ms);
    }
    if (text && len && text[len - 1] == '\n') text[len - 1] = '\0';
    printf("%d\t%s\t%s\n", rc, text ? text : "", msg);
    free(text);
    if (fflush(stdout) != 0) break; /* the sweep is gone */
  }
  free(line);
  return 0;
}
