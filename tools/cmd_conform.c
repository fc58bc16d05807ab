/* cmd_conform.c — `flexmbd conform [--plugin x.so]... [TYPE]...`: the conformance checks of
 * engine/conform.c on the named types, or on every registered type. Exit 0 when all pass, 1 when
 * a check fails, 2 for bad arguments or a plugin that does not load. */
#include <errno.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>
#include <sys/stat.h>

#include "cli.h"

int fmb_cmd_conform(int argc, char** argv) {
  fmbCliScene s;
  memset(&s, 0, sizeof s);
  const char* names[256];
  int nnames = 0;
  const char* work = NULL;
  for (int i = 2; i < argc; ++i) {
    if (strcmp(argv[i], "--work") == 0) {
      if (!(work = fmb_cli_value("conform", argc, argv, &i, "a folder"))) return FMB_EXIT_BAD_INPUT;
      continue;
    }
    if (argv[i][0] != '-') {
      if (nnames == 256) return FMB_EXIT_BAD_INPUT;
      names[nnames++] = argv[i];
      continue;
    }
    int r = fmb_cli_take_scene_arg("conform", argc, argv, &i, &s);
    if (r != 1 || s.nover) {
      if (r > 1) return r;
      fprintf(stderr, "flexmbd conform: unknown option '%s'\n", argv[i]);
      return FMB_EXIT_BAD_INPUT;
    }
  }
  fmbRegistry* reg = fmb_cli_registry();
  if (!reg) return FMB_EXIT_BAD_INPUT;
  if (!work) work = getenv("TMPDIR") ? getenv("TMPDIR") : "/tmp";
  if (mkdir(work, 0777) != 0 && errno != EEXIST) {
    fprintf(stderr, "flexmbd conform: cannot create the work folder '%s': %s\n", work, strerror(errno));
    return FMB_EXIT_BAD_INPUT;
  }
  int failed = 0, types = 0;
  if (nnames == 0) {
    for (int i = 0; i < fmb_registry_nbodies(reg); ++i) names[nnames++] = fmb_registry_body(reg, i)->name;
    for (int i = 0; i < fmb_registry_njoints(reg) && nnames < 256; ++i) names[nnames++] = fmb_registry_joint(reg, i)->name;
  }
  for (int i = 0; i < nnames; ++i) {
    const int r = fmb_conform(reg, names[i], work, stdout);
    if (r < 0) {
      fprintf(stderr, "flexmbd conform: no type named '%s' (flexmbd types lists them)\n", names[i]);
      return FMB_EXIT_BAD_INPUT;
    }
    failed += r;
    ++types;
  }
  printf("conform: %d types, %d failed checks\n", types, failed);
  return failed ? 1 : 0;
}
