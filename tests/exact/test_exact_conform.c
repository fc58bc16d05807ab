/*
 * test_exact_conform.c — `flexmbd conform`'s checks (engine/conform.c) on the exact beam's own ops
 * table. The registry holds type beam through bodies/beam.c, whose `variant` op hands `model:
 * exact` items to bodies/beam_exact.c; conform runs what is registered, so this test registers the
 * exact table as type beam in a fresh registry (with the other built-in types conform's fixture uses): parameter refusals, the example's consistent start, the
 * analytic Jacobian and the marker's derivatives against differences, a positive-definite
 * mass, gravity left out when absent, and energy conservation of a free run under gravity.
 * The same for `kinematics: intrinsic`'s table (bodies/beam_intrinsic.c, Jacobian by differences).
 */
#include <stdio.h>

#include "check.h"
#include "flexmbd_plugin.h"

extern const fmbBodyType fmb_body_beam_exact, fmb_body_beam_intrinsic, fmb_body_ground, fmb_body_rigid;
extern const fmbJointType fmb_joint_revolute, fmb_joint_fixed, fmb_joint_drive, fmb_joint_spring, fmb_joint_force;

int main(int argc, char** argv) {
  const char* work = argc > 1 ? argv[1] : ".";
  const fmbBodyType* tables[] = {&fmb_body_beam_exact, &fmb_body_beam_intrinsic};
  const char* names[] = {"exact beam's (cable)", "intrinsic exact beam's"};
  for (int t = 0; t < 2; ++t) {
    /* the built-in types conform's fixture uses, with the table as type beam */
    const fmbBodyType* bodies[] = {&fmb_body_ground, &fmb_body_rigid, tables[t], NULL};
    const fmbJointType* joints[] = {&fmb_joint_revolute, &fmb_joint_fixed, &fmb_joint_drive,
                                    &fmb_joint_spring,   &fmb_joint_force, NULL};
    const fmbPlugin plugin = {
        .abi = FMB_ABI_VERSION, .name = "exact-beam-test", .version = "1", .bodies = bodies, .joints = joints};
    fmbRegistry* reg = fmb_registry_new();
    fmbDiag diag;
    ENSURE(reg && fmb_registry_add(reg, &plugin, "test", &diag) == 0);
    const int failed = fmb_conform(reg, "beam", work, stdout);
    printf("conform on the %s table: %d failed checks\n", names[t], failed);
    ENSURE(failed == 0);
    fmb_registry_free(reg);
  }
  return fmbt_finish("test_exact_conform");
}
