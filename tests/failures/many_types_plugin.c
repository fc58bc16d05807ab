/* many_types_plugin.c — a plugin with 300 body types (copies of the built-in rigid body named
 * many0 .. many299, without an example so that `conform` fails each at once): `flexmbd conform`
 * on every registered type once overflowed a fixed list of 256 names (issue 27). Also a loaded
 * plugin file, which no output may replace (tests/failures/inputs_overwritten.sh). */
#include <stdio.h>
#include <string.h>

#include "flexmbd_plugin.h"

enum { MANY = 300 };
static fmbBodyType types[MANY];
static char names[MANY][16];
static const fmbBodyType* list[MANY + 1];
static fmbPlugin plugin = {.abi = FMB_ABI_VERSION, .name = "many_types", .version = "1", .bodies = list};

FMB_PLUGIN_EXPORT const fmbPlugin* fmb_plugin_descriptor(void) {
  if (!list[0]) {
    const fmbPlugin* builtin = fmb_builtin_plugin();
    const fmbBodyType* rigid = NULL;
    for (int i = 0; builtin->bodies[i]; ++i)
      if (strcmp(builtin->bodies[i]->name, "rigid") == 0)
        rigid = builtin->bodies[i]; /* not rigid3d: conform skips it */
    for (int i = 0; rigid && i < MANY; ++i) {
      types[i] = *rigid;
      snprintf(names[i], sizeof names[i], "many%d", i);
      types[i].name = names[i];
      types[i].example = NULL;
      types[i].example_damped = NULL;
      list[i] = &types[i];
    }
  }
  return &plugin;
}
