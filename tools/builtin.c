/* builtin.c — the built-in body and joint types: the one place a type is registered.
 * Adding a type: write bodies/NAME.c (or joints/NAME.c) exporting its ops table, add one line
 * here, and list the file in CMakeLists.txt (docs/plugins.md). */
#include "builtin.h"

extern const fmbBodyType fmb_body_ground, fmb_body_rigid, fmb_body_beam;
extern const fmbJointType fmb_joint_revolute, fmb_joint_fixed, fmb_joint_drive, fmb_joint_spring, fmb_joint_force;

static const fmbBodyType* const builtin_bodies[] = {
    &fmb_body_ground,
    &fmb_body_rigid,
    &fmb_body_beam,
};

static const fmbJointType* const builtin_joints[] = {
    &fmb_joint_revolute,
    &fmb_joint_fixed,
    &fmb_joint_drive,
    &fmb_joint_spring,
    &fmb_joint_force,
};

static const fmbRegistry builtin_registry = {
    builtin_bodies, (int)(sizeof builtin_bodies / sizeof builtin_bodies[0]),
    builtin_joints, (int)(sizeof builtin_joints / sizeof builtin_joints[0]),
};

const fmbRegistry* fmb_builtin_registry(void) { return &builtin_registry; }
