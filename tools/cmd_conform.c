/* cmd_conform.c — `flexmbd conform [--plugin x.so]... [TYPE]...`: the conformance checks of
 * engine/conform.c on the named types, or on every registered type. Exit 0 when all pass, 1 when
 * a check fails, 2 for bad arguments or a plugin that does not load. */
#include <dirent.h>
#include <errno.h>
#include <stddef.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>
#include <sys/stat.h>
#include <unistd.h>

#include "cli.h"

/* empties and removes the private work folder (mkdtemp's: every entry in it is conform's) */
static void remove_work(const char* dir) {
  DIR* d = opendir(dir);
  for (struct dirent* e; d && (e = readdir(d));) {
    if (strcmp(e->d_name, ".") == 0 || strcmp(e->d_name, "..") == 0) continue;
    char path[1400];
    snprintf(path, sizeof path, "%s/%s", dir, e->d_name);
    unlink(path);
  }
  if (d) closedir(d);
  rmdir(dir);
}

static int conform_types(fmbRegistry* reg, const char* const* names, int nnames, const char* work);

typedef struct {
  fmbCliScene s; /* the --plugin files */
  const char* work;
  const char** names; /* the named types: at most one per argument */
  int nnames;
} ConformArgs;

static int conform_type_name(const fmbOptContext* ctx, const char* arg) {
  ConformArgs* o = ctx->self;
  o->names[o->nnames++] = arg;
  return 0;
}

static const fmbOpt conform_options[] = {
    FMB_OPT_PLUGIN(ConformArgs, s),
    {"--work", NULL, FMB_OPT_STRING, "DIR", offsetof(ConformArgs, work),
     "keep the checks' scenes and runs in DIR (default: a temporary folder, removed)", "a folder", 0, 0, NULL, NULL, 0},
};

const fmbCommandSpec fmb_conform_command = {
    "conform",
    "[TYPE]...",
    "conformance checks of every (or the named) body and joint type; exit 1 on a failure",
    conform_options,
    FMB_OPT_COUNT(conform_options),
    conform_type_name,
    NULL};

int fmb_cmd_conform(int argc, char** argv) {
  ConformArgs o;
  memset(&o, 0, sizeof o);
  o.names = calloc((size_t)argc, sizeof *o.names);
  if (!o.names) return FMB_EXIT_BAD_INPUT;
  int rc;
  if (fmb_opt_parse(&fmb_conform_command, argc, argv, &o, &rc)) {
    free(o.names);
    return rc;
  }
  const char** names = o.names;
  const int nnames = o.nnames;
  const char* work = o.work;
  fmbRegistry* reg = fmb_cli_registry();
  rc = reg ? 0 : FMB_EXIT_BAD_INPUT;
  /* the scenes and runs go to a folder of our own (mkdtemp: new, 0700, no link followed into it),
     removed afterwards; --work DIR keeps them in DIR for a look */
  char own[1100] = "";
  if (!rc && !work) {
    if (fmb_cli_private_folder("conform", own, sizeof own)) {
      rc = FMB_EXIT_BAD_INPUT;
      own[0] = '\0';
    }
    work = own;
  } else if (!rc && mkdir(work, 0777) != 0 && errno != EEXIST) {
    fprintf(stderr, "flexmbd conform: cannot create the work folder '%s': %s\n", work, strerror(errno));
    rc = FMB_EXIT_BAD_INPUT;
  }
  if (!rc) rc = conform_types(reg, names, nnames, work);
  if (own[0]) remove_work(own);
  free(names);
  return rc;
}

/* every named type, or every registered one (however many: no fixed list) */
static int conform_types(fmbRegistry* reg, const char* const* names, int nnames, const char* work) {
  const int nb = fmb_registry_nbodies(reg), nj = fmb_registry_njoints(reg);
  const int n = nnames ? nnames : nb + nj;
  int failed = 0, types = 0;
  for (int i = 0; i < n; ++i) {
    const char* name = nnames   ? names[i]
                       : i < nb ? fmb_registry_body(reg, i)->name
                                : fmb_registry_joint(reg, i - nb)->name;
    const int r = fmb_conform(reg, name, work, stdout);
    if (r < 0) {
      fprintf(stderr, "flexmbd conform: no type named '%s' (flexmbd types lists them)\n", name);
      return FMB_EXIT_BAD_INPUT;
    }
    failed += r;
    ++types;
  }
  printf("conform: %d types, %d failed checks\n", types, failed);
  return failed ? 1 : 0;
}
