/* plugin.c — loading a plugin from a shared object: dlopen, look up the one entry point
 * fmb_plugin_descriptor, and hand its descriptor to fmb_registry_add, which checks the ABI and
 * the ops before any type is used (engine/registry.c). docs/plugins.md.
 *
 * Rules (docs/plugins.md, "Loading"): only files the user named are loaded (a path without '/'
 * is taken in the current folder, never searched for on the system's library path); symbols are
 * bound now and kept local (RTLD_NOW | RTLD_LOCAL), so a plugin missing a host symbol fails at
 * load with the symbol's name; loaded code is never unloaded, since destroy ops of instances and
 * the type tables themselves live in it. */
#include <dlfcn.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>

#include "internal.h"

int fmb_registry_load(fmbRegistry* reg, const char* path, fmbDiag* diag) {
  fmbDiag local_diag;
  if (!diag) diag = &local_diag;
  memset(diag, 0, sizeof *diag);
  if (!reg) {
    fmb_diag_set(diag, FMB_EXIT_BAD_INPUT, path ? path : "", 0, 0, "fmb_registry_load: the registry is NULL");
    return -1;
  }
  if (!path || !path[0]) {
    fmb_diag_set(diag, FMB_EXIT_BAD_INPUT, "", 0, 0, "empty plugin path: expected a shared object file (x.so)");
    return -1;
  }
  char local[1024];
  if (!strchr(path, '/')) {
    snprintf(local, sizeof local, "./%s", path); /* dlopen would search the library path otherwise */
    path = local;
  }
  void* h = dlopen(path, RTLD_NOW | RTLD_LOCAL);
  if (!h) {
    fmb_diag_set(diag, FMB_EXIT_BAD_INPUT, path, 0, 0, "cannot load plugin: %s", dlerror());
    return -1;
  }
  dlerror();
  fmbPluginEntry entry;
  *(void**)&entry = dlsym(h, FMB_PLUGIN_ENTRY); /* POSIX: an object pointer converted to a function */
  if (!entry) {
    fmb_diag_set(diag, FMB_EXIT_BAD_INPUT, path, 0, 0,
                 "not a flexmbd plugin: it has no symbol %s (declare it "
                 "with FMB_PLUGIN_EXPORT, docs/plugins.md)",
                 FMB_PLUGIN_ENTRY);
    return -1;
  }
  const fmbPlugin* desc = entry();
  if (!desc) {
    fmb_diag_set(diag, FMB_EXIT_BAD_INPUT, path, 0, 0, "%s() returned no descriptor", FMB_PLUGIN_ENTRY);
    return -1;
  }
  /* its code is never unloaded; the file is an input of whoever loaded it (a scene's plugins:
     its model's, fmb_scene_plugins; a program's: its own set) */
  return fmb_registry_add(reg, desc, path, diag);
}

/* plugins: [path, ...] at the scene's top level, paths relative to the scene file's folder */
int fmb_scene_plugins(fmbParser* p, fmbNode list) {
  if (list < 0) return 0;
  if (!fmbp_is_seq(p, list))
    return fmb_parse_error(p, list, "expected a list of plugin files for 'plugins' (paths relative to the scene)");
  const int n = fmbp_seq_len(p, list);
  if (n == 0) return 0;
  p->own_reg = fmb_registry_clone(p->reg);
  if (!p->own_reg) return fmb_parse_error(p, list, "out of memory");
  p->reg = p->own_reg;
  const char* slash = strrchr(p->path, '/');
  const int dirlen = slash ? (int)(slash - p->path) + 1 : 0;
  for (int i = 0; i < n; ++i) {
    const fmbNode item = fmbp_seq_item(p, list, i);
    const char* file = fmbp_scalar(p, item);
    if (!file || !file[0]) return fmb_parse_error(p, item, "expected a plugin file name (a path to a .so)");
    char path[2048];
    if (file[0] == '/')
      snprintf(path, sizeof path, "%s", file);
    else
      snprintf(path, sizeof path, "%.*s%s", dirlen, p->path, file);
    fmbDiag d;
    if (fmb_registry_load(p->own_reg, path, &d)) return fmb_parse_error(p, item, "plugin %s: %s", d.file, d.msg);
    if (p->model) fmb_inputs_note(p->model->inputs, path); /* no output of its runs may replace it */
  }
  return 0;
}
