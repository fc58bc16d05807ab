/* test_plugin_abi.c — the plugin ABI rule (flexmbd_plugin.h, engine/registry.c) on plugins loaded
 * as a program loads them, through the shared library alone (no engine internals):
 *  - a plugin built for plugin ABI 3.0 (flexmbd 0.1's header: no `size` in its descriptor, tables
 *    saying abi 3) loads, and its type passes `conform` (its tables are read where 3.0 put them:
 *    Jacobian against differences, energy kept and lost, outputs);
 *  - the same plugin built for this minor (FMB_PLUGIN_HEAD) loads and conforms;
 *  - another major, and a newer minor, are refused with exit code 2 naming both numbers and the
 *    library's version, the registry left as it was; a descriptor whose size no ABI 3 layout has
 *    is refused;
 *  - fmb_version() is the version `flexmbd --version` prints, fmb_plugin_abi() the header's.
 * argv: the flexmbd program, the folder of the plugins (tests/install/broken.c built 4 ways), a
 * work folder. */
#include <stdio.h>
#include <stdlib.h>
#include <string.h>
#include <sys/stat.h>

#include "flexmbd_plugin.h"

static int failures;
#define CHECK(cond, ...)                                              \
  do {                                                                \
    if (!(cond)) {                                                    \
      ++failures;                                                     \
      fprintf(stderr, "FAIL %s:%d: %s: ", __FILE__, __LINE__, #cond); \
      fprintf(stderr, __VA_ARGS__);                                   \
      fputc('\n', stderr);                                            \
    }                                                                 \
  } while (0)

static fmbRegistry* with_builtins(void) {
  fmbRegistry* reg = fmb_registry_new();
  fmbDiag d;
  if (reg && fmb_registry_add(reg, fmb_builtin_plugin(), "built-in", &d) != 0) {
    fmb_registry_free(reg);
    return NULL;
  }
  return reg;
}

/* the plugin `name` of dir loads into a fresh registry and its oscillator conforms */
static void loads_and_conforms(const char* dir, const char* name, const char* work) {
  char path[4096];
  snprintf(path, sizeof path, "%s/%s", dir, name);
  fmbRegistry* reg = with_builtins();
  fmbDiag d;
  const int n0 = fmb_registry_nbodies(reg);
  const int rc = fmb_registry_load(reg, path, &d);
  CHECK(rc == 0, "%s refused: %s", name, d.msg);
  CHECK(fmb_registry_nbodies(reg) == n0 + 1, "%s: %d body types, expected %d", name, fmb_registry_nbodies(reg), n0 + 1);
  if (rc == 0) {
    const int failed = fmb_conform(reg, "oscillator", work, stdout);
    CHECK(failed == 0, "%s: conform failed %d checks", name, failed);
  }
  fmb_registry_free(reg);
}

/* the plugin `name` of dir is refused with exit code 2 and a message holding each of `want` */
static void refused(const char* dir, const char* name, const char* const* want) {
  char path[4096];
  snprintf(path, sizeof path, "%s/%s", dir, name);
  fmbRegistry* reg = with_builtins();
  fmbDiag d;
  const int n0 = fmb_registry_nbodies(reg);
  CHECK(fmb_registry_load(reg, path, &d) != 0, "%s loaded", name);
  CHECK(d.code == FMB_EXIT_BAD_INPUT, "%s: code %d", name, d.code);
  for (int i = 0; want[i]; ++i) CHECK(strstr(d.msg, want[i]) != NULL, "%s: no '%s' in: %s", name, want[i], d.msg);
  CHECK(fmb_registry_nbodies(reg) == n0, "%s: the registry changed", name);
  printf("ok: %s refused: %s\n", name, d.msg);
  fmb_registry_free(reg);
}

int main(int argc, char** argv) {
  if (argc != 4) {
    fprintf(stderr, "usage: test_plugin_abi FLEXMBD PLUGIN_DIR WORK_DIR\n");
    return 2;
  }
  const char *flexmbd = argv[1], *dir = argv[2], *work = argv[3];
  { /* the work folder and its parent (a fresh build has neither) */
    char parent[4096];
    snprintf(parent, sizeof parent, "%s", work);
    char* slash = strrchr(parent, '/');
    if (slash) *slash = '\0', mkdir(parent, 0755);
    mkdir(work, 0755);
  }

  /* the library's version against the program's (two builds of one number: a stale library
     beside a new program would differ) */
  char cmd[4200], line[512] = "";
  snprintf(cmd, sizeof cmd, "'%s' --version", flexmbd);
  FILE* p = popen(cmd, "r");
  CHECK(p && fgets(line, sizeof line, p), "no output from %s", cmd);
  if (p) pclose(p);
  char program_version[64] = "";
  CHECK(sscanf(line, "flexmbd %63s", program_version) == 1, "unexpected --version line: %s", line);
  CHECK(strcmp(program_version, fmb_version()) == 0, "fmb_version() '%s', flexmbd --version '%s'", fmb_version(),
        program_version);
  char abi_text[64];
  snprintf(abi_text, sizeof abi_text, "plugin ABI %d.%d)", FMB_PLUGIN_ABI_MAJOR, FMB_PLUGIN_ABI_MINOR);
  CHECK(strstr(line, abi_text) != NULL, "no '%s' in: %s", abi_text, line);
  CHECK(fmb_plugin_abi() == FMB_PLUGIN_ABI, "fmb_plugin_abi() %d, header %d", fmb_plugin_abi(), FMB_PLUGIN_ABI);
  printf("ok: fmb_version() %s = flexmbd --version; plugin ABI %d\n", fmb_version(), fmb_plugin_abi());

  loads_and_conforms(dir, "abi_3_0.so", work);
  loads_and_conforms(dir, "abi_current.so", work);

  char mine[64], major[64], minor[64];
  snprintf(mine, sizeof mine, "this flexmbd %s has plugin ABI %d.%d", fmb_version(), FMB_PLUGIN_ABI_MAJOR,
           FMB_PLUGIN_ABI_MINOR);
  snprintf(major, sizeof major, "built for flexmbd plugin ABI %d.0;", FMB_PLUGIN_ABI_MAJOR + 1);
  snprintf(minor, sizeof minor, "built for flexmbd plugin ABI %d.%d;", FMB_PLUGIN_ABI_MAJOR, FMB_PLUGIN_ABI_MINOR + 1);
  refused(dir, "abi_major.so", (const char* const[]){major, mine, "rebuild it", NULL});
  refused(dir, "abi_minor.so", (const char* const[]){minor, mine, "newer flexmbd", NULL});

  /* a descriptor of this minor whose size no ABI 3 layout has (a corrupt one) */
  fmbRegistry* reg = with_builtins();
  fmbDiag d;
  fmbPlugin odd = {FMB_PLUGIN_HEAD, .name = "odd"};
  odd.size = 12;
  CHECK(fmb_registry_add(reg, &odd, "odd.so", &d) != 0 && strstr(d.msg, "descriptor says it is 12 bytes"),
        "a 12-byte descriptor: %s", d.msg);
  odd.size = sizeof odd + 8;
  CHECK(fmb_registry_add(reg, &odd, "odd.so", &d) != 0, "a descriptor longer than this minor's loaded");
  /* a descriptor written with the 0.1 names (.abi = FMB_ABI_VERSION, no size): read as 3.0 */
  const fmbPlugin old_source = {.abi = FMB_ABI_VERSION, .name = "old_source"};
  CHECK(fmb_registry_add(reg, &old_source, "old.so", &d) == 0, "a descriptor without size: %s", d.msg);
  fmb_registry_free(reg);

  printf("test_plugin_abi: %d failures\n", failures);
  return failures != 0;
}
