/* rod3d_plugin.c — a test plugin for drawing a spatial body with a centreline before the spatial
 * beam exists (tests/ux/test_view3d.py): type `rod3d` is the built-in rigid3d with a centreline of
 * five stations along its x axis, -0.5 .. 0.5 m, and no outputs of its own (the engine's pose
 * columns and BODY.shape stand in), so `flexmbd run/view --plugin` take the path the spatial beam
 * will take. Built from the installed library's rigid3d at load (the entry is a function). */
#include <string.h>

#include "builtin.h"
#include "flexmbd.h"
#include "flexmbd_plugin.h"

static int rod_centreline(const void* self, int n, double* local) {
  (void)self;
  if (n <= 0) return 5;
  for (int i = 0; i < n; ++i) {
    local[2 * i] = -0.5 + (double)i / (n - 1);
    local[2 * i + 1] = 0.0;
  }
  return n;
}

static fmbBodyType rod_type;
static const fmbBodyType* rod_types[] = {&rod_type, NULL};
static const fmbPlugin rod_plugin = {.abi = FMB_ABI_VERSION, .name = "rod3d", .version = "1", .bodies = rod_types};

FMB_PLUGIN_EXPORT const fmbPlugin* fmb_plugin_descriptor(void) {
  const fmbRegistry* builtin = fmb_builtin_registry();
  for (int i = 0; builtin && i < fmb_registry_nbodies(builtin); ++i)
    if (strcmp(fmb_registry_body(builtin, i)->name, "rigid3d") == 0) rod_type = *fmb_registry_body(builtin, i);
  if (!rod_type.name) return NULL;
  rod_type.name = "rod3d";
  rod_type.centreline = rod_centreline;
  rod_type.output_names = NULL;
  rod_type.output_lookup = NULL;
  rod_type.output_units = NULL;
  return &rod_plugin;
}
