/* builtin.c — the types shipped with flexmbd, as one plugin descriptor: they enter a registry
 * through fmb_registry_add exactly as a loaded plugin does (engine/registry.c), so the engine has
 * one path. A new type is best written out of tree as a plugin (docs/plugins.md); to ship one
 * with flexmbd, add its file to CMakeLists.txt and one line here. */
#include "builtin.h"

#include <pthread.h>
#include <stddef.h>
#include <stdio.h>

extern const fmbBodyType fmb_body_ground, fmb_body_rigid, fmb_body_beam, fmb_body_rigid3d;
extern const fmbJointType fmb_joint_revolute, fmb_joint_fixed, fmb_joint_drive, fmb_joint_spring, fmb_joint_force,
    fmb_joint_prismatic, fmb_joint_torsion, fmb_joint_spherical, fmb_joint_revolute3d, fmb_joint_fixed3d,
    fmb_joint_universal, fmb_joint_prismatic3d, fmb_joint_cylindrical, fmb_joint_torsion3d, fmb_joint_force3d;

static const fmbBodyType* const builtin_bodies[] = {
    &fmb_body_ground,
    &fmb_body_rigid,
    &fmb_body_beam,    /* and, behind it, model: exact (fmb_body_beam_exact) */
    &fmb_body_rigid3d, /* dimension: 3 (docs/spatial.md) */
    NULL,
};

static const fmbJointType* const builtin_joints[] = {
    &fmb_joint_revolute,
    &fmb_joint_fixed,
    &fmb_joint_drive,
    &fmb_joint_spring,
    &fmb_joint_force,
    &fmb_joint_prismatic,
    &fmb_joint_torsion,
    /* dimension: 3 (docs/spatial.md) */
    &fmb_joint_spherical,
    &fmb_joint_revolute3d,
    &fmb_joint_fixed3d,
    &fmb_joint_universal,
    &fmb_joint_prismatic3d,
    &fmb_joint_cylindrical,
    &fmb_joint_torsion3d,
    &fmb_joint_force3d,
    NULL,
};

static const fmbPlugin builtin_plugin = {
    .abi = FMB_ABI_VERSION,
    .name = "built-in",
    .version = "flexmbd",
    .bodies = builtin_bodies,
    .joints = builtin_joints,
};

const fmbPlugin* fmb_builtin_plugin(void) { return &builtin_plugin; }

/* built once for the process (tests and tools share it), under pthread_once: two threads asking
   first at the same time get the same registry, fully made (issue 35 item 3). It is never changed
   after, so reading it from any thread is safe. */
static fmbRegistry* builtin_reg;
static pthread_once_t builtin_reg_once = PTHREAD_ONCE_INIT;
static void make_builtin_registry(void) {
  fmbDiag d;
  fmbRegistry* reg = fmb_registry_new();
  if (reg && fmb_registry_add(reg, &builtin_plugin, "built-in", &d)) {
    fprintf(stderr, "flexmbd: the built-in types do not register: %s\n", d.msg);
    fmb_registry_free(reg);
    reg = NULL;
  }
  builtin_reg = reg;
}

const fmbRegistry* fmb_builtin_registry(void) {
  pthread_once(&builtin_reg_once, make_builtin_registry);
  return builtin_reg;
}
