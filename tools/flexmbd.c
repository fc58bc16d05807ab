/* flexmbd.c — the command line.
 *   flexmbd run SCENE.yaml [-o OUT.csv] [--set PATH=VALUE]... [--quiet] [--reference REF.csv [--columns a,b]]
 *   flexmbd check SCENE.yaml [--set PATH=VALUE]...     load, validate, describe; no run
 *   flexmbd types                                       the registered body and joint types
 *   flexmbd compare OUT.csv REF.csv [--columns a,b,...]  max and end error per column (tools/compare.c)
 * Exit codes: 0 ok, 2 bad input, 3 solver failure. The last stderr line of `run` is the stats line. */
#include <stdio.h>
#include <stdlib.h>
#include <string.h>

#include "builtin.h"
#include "flexmbd.h"

#define MAX_OVERRIDES 256

int fmb_compare_main(int argc, char** argv); /* tools/compare.c */

static void usage(FILE* f) {
  fprintf(f,
          "usage: flexmbd run SCENE.yaml [-o OUT.csv] [--set PATH=VALUE]... [--quiet]\n"
          "                  [--reference REF.csv [--columns a,b,...]]   also print the error against REF and the cost\n"
          "       flexmbd check SCENE.yaml [--set PATH=VALUE]...\n"
          "       flexmbd compare OUT.csv REF.csv [--columns a,b,...]   error of a run against a reference\n"
          "       flexmbd types\n"
          "PATH addresses any scene value, bodies and joints by name: solver.rtol=1e-8, bodies.beam.elements=32\n");
}

static void print_diag(const fmbDiag* d) {
  if (d->line > 0)
    fprintf(stderr, "%s:%d:%d: error: %s\n", d->file, d->line, d->col, d->msg);
  else if (d->file[0])
    fprintf(stderr, "%s: error: %s\n", d->file, d->msg);
  else
    fprintf(stderr, "error: %s\n", d->msg);
}

static void list_types(const fmbRegistry* reg) {
  printf("bodies:\n");
  for (int i = 0; i < reg->nbodies; ++i) {
    printf("  %s", reg->bodies[i]->name);
    const char* const* o = reg->bodies[i]->output_names;
    if (o && o[0]) {
      printf("  (outputs:");
      for (; *o; ++o) printf(" %s", *o);
      printf(")");
    }
    printf("\n");
  }
  printf("joints and forces:\n");
  for (int i = 0; i < reg->njoints; ++i) printf("  %s\n", reg->joints[i]->name);
}

int main(int argc, char** argv) {
  if (argc < 2) {
    usage(stderr);
    return FMB_EXIT_BAD_INPUT;
  }
  const fmbRegistry* reg = fmb_builtin_registry();
  const char* cmd = argv[1];
  if (strcmp(cmd, "--help") == 0 || strcmp(cmd, "-h") == 0) {
    usage(stdout);
    return 0;
  }
  if (strcmp(cmd, "types") == 0) {
    list_types(reg);
    return 0;
  }
  if (strcmp(cmd, "compare") == 0) return fmb_compare_main(argc, argv); /* tools/compare.c */
  if (strcmp(cmd, "run") != 0 && strcmp(cmd, "check") != 0) {
    fprintf(stderr, "flexmbd: unknown command '%s'\n", cmd);
    usage(stderr);
    return FMB_EXIT_BAD_INPUT;
  }
  const int run = strcmp(cmd, "run") == 0;
  const char* scene = NULL;
  const char* out = NULL;
  const char* reference = NULL; /* run --reference REF.csv: error against REF and the run's cost */
  const char* columns = NULL;
  const char* overrides[MAX_OVERRIDES];
  int nover = 0, quiet = 0;
  for (int i = 2; i < argc; ++i) {
    const char* a = argv[i];
    if ((strcmp(a, "-o") == 0 || strcmp(a, "--output") == 0) && run) {
      if (++i >= argc) {
        fprintf(stderr, "flexmbd: %s needs a file name\n", a);
        return FMB_EXIT_BAD_INPUT;
      }
      out = argv[i];
    } else if ((strcmp(a, "--reference") == 0 || strcmp(a, "--columns") == 0) && run) {
      if (++i >= argc) {
        fprintf(stderr, "flexmbd: %s needs an argument\n", a);
        return FMB_EXIT_BAD_INPUT;
      }
      if (a[2] == 'r')
        reference = argv[i];
      else
        columns = argv[i];
    } else if (strcmp(a, "--set") == 0) {
      if (++i >= argc) {
        fprintf(stderr, "flexmbd: --set needs PATH=VALUE\n");
        return FMB_EXIT_BAD_INPUT;
      }
      if (nover == MAX_OVERRIDES) {
        fprintf(stderr, "flexmbd: more than %d --set overrides\n", MAX_OVERRIDES);
        return FMB_EXIT_BAD_INPUT;
      }
      overrides[nover++] = argv[i];
    } else if (strncmp(a, "--set=", 6) == 0 && nover < MAX_OVERRIDES) {
      overrides[nover++] = a + 6;
    } else if (strcmp(a, "--quiet") == 0 || strcmp(a, "-q") == 0) {
      quiet = 1;
    } else if (a[0] == '-' && a[1] != '\0') {
      fprintf(stderr, "flexmbd: unknown option '%s'\n", a);
      usage(stderr);
      return FMB_EXIT_BAD_INPUT;
    } else if (!scene) {
      scene = a;
    } else {
      fprintf(stderr, "flexmbd: one scene file at a time (got '%s' and '%s')\n", scene, a);
      return FMB_EXIT_BAD_INPUT;
    }
  }
  if (reference && (!out || strcmp(out, "-") == 0)) {
    fprintf(stderr, "flexmbd: --reference needs the run's CSV in a file (-o OUT.csv)\n");
    return FMB_EXIT_BAD_INPUT;
  }
  if (!scene) {
    fprintf(stderr, "flexmbd: no scene file given\n");
    usage(stderr);
    return FMB_EXIT_BAD_INPUT;
  }

  fmbDiag diag;
  fmbStats stats;
  memset(&stats, 0, sizeof stats);
  fmbModel* m = fmb_load(scene, overrides, nover, reg, &diag);
  if (!m) {
    print_diag(&diag);
    if (run) fmb_print_stats(&stats, stderr);
    return diag.code ? diag.code : FMB_EXIT_BAD_INPUT;
  }
  if (!run) {
    fmb_describe(m, stdout);
    fmb_free(m);
    return 0;
  }
  fmbRunOptions opt = {out, quiet};
  int rc = fmb_run(m, &opt, &stats, &diag);
  if (rc) print_diag(&diag);
  if (reference) {
    /* one line per column on stdout: the error against the reference and what the run cost */
    char tag[160];
    snprintf(tag, sizeof tag, "status=%s cpu_s=%.4f steps=%ld", rc ? "failed" : "ok", stats.cpu_s, stats.steps);
    char* cargv[8] = {argv[0], "compare", (char*)out, (char*)reference, "--tag", tag, NULL, NULL};
    int cargc = 6;
    if (columns) {
      cargv[cargc++] = "--columns";
      cargv[cargc++] = (char*)columns;
    }
    int crc = fmb_compare_main(cargc, cargv);
    if (crc && !rc) rc = crc;
  }
  fmb_print_stats(&stats, stderr);
  fmb_free(m);
  return rc;
}
