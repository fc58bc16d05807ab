/* cmd_new.c — `flexmbd new pendulum|beam|rotor|slider-crank > scene.yaml`
 * A commented starter scene on stdout: every key a newcomer needs is there with its unit, and
 * each one runs as it is (tests/ux/test_starters.sh runs and checks all of them). */
#include <stdio.h>
#include <string.h>

#include "cli.h"

typedef struct {
  const char* name;
  const char* what;
  const char* text;
} Starter;

static const Starter starters[] = {
    {"pendulum", "a rigid bar pinned at one end, released horizontally",
     "# A rigid pendulum: a 1 kg bar, 1 m long, pinned at its left end and released horizontally.\n"
     "#   flexmbd run pendulum.yaml -o pendulum.csv\n"
     "#   flexmbd plot pendulum.csv bar.theta\n"
     "# SI units (m, kg, s, N); angles in radians, or with a unit: `angle: 90 deg`.\n"
     "# docs/scenes.md lists every key; `flexmbd types` every body and joint type.\n"
     "solver:\n"
     "  t_end: 5.0              # s: integrate from 0 to t_end\n"
     "  output_step: 0.01       # s: one CSV row every 10 ms\n"
     "gravity: [0.0, -9.81]     # m/s^2\n"
     "bodies:\n"
     "  - name: bar\n"
     "    type: rigid\n"
     "    mass: 1.0             # kg\n"
     "    inertia: 0.0833333    # kg m^2 about the centre of mass (m L^2 / 12)\n"
     "    position: [0.5, 0.0]  # m: the centre of mass, which is the body's frame origin\n"
     "    angle: 0 deg          # the body's x axis from the global x axis\n"
     "joints:\n"
     "  - name: pin\n"
     "    type: revolute        # point1 on body1 and point2 on body2 stay together\n"
     "    body1: ground         # the fixed world frame, always defined\n"
     "    body2: bar\n"
     "    point1: [0.0, 0.0]    # on the ground\n"
     "    point2: [-0.5, 0.0]   # on the bar, in its own frame: its left end\n"
     "# CSV columns (t comes first); energy.total stays constant: no friction, no damping\n"
     "outputs: [bar.theta, bar.omega, energy.kinetic, energy.gravity, energy.total]\n"},
    {"beam", "a flexible beam falling as a pendulum (materials and sections by name)",
     "# A flexible pendulum: an aluminium strip, 1 m long, pinned at its root and released\n"
     "# horizontally. It bends as it swings (the paper's Fig. 4 case, shorter).\n"
     "#   flexmbd run beam.yaml -o beam.csv --vtk beam-vtk     (open beam-vtk/beam.pvd in ParaView)\n"
     "#   flexmbd plot beam.csv beam.tip_v\n"
     "solver:\n"
     "  t_end: 1.0               # s\n"
     "  output_step: 0.01        # s\n"
     "gravity: [0.0, -9.81]\n"
     "# materials and sections are defined once and named by the beams that use them\n"
     "materials:\n"
     "  aluminium: {density: 2767.0, youngs_modulus: 68.95e9}   # kg/m^3, Pa\n"
     "sections:\n"
     "  strip: {area: 2.5e-4, second_moment: 1.302e-10}         # m^2, m^4 (bending about z)\n"
     "bodies:\n"
     "  - name: beam\n"
     "    type: beam\n"
     "    length: 1.0            # m\n"
     "    elements: 8            # finite elements along the length (more: finer, slower)\n"
     "    material: aluminium\n"
     "    section: strip\n"
     "    model: complete        # complete (default), foac or zoac: docs/beam.md\n"
     "    position: [0.0, 0.0]   # m: the root, origin of the beam's floating frame\n"
     "    angle: 0 deg\n"
     "joints:\n"
     "  - {name: pin, type: revolute, body1: ground, body2: beam, point1: [0, 0], point2: [0, 0]}\n"
     "# beam.tip_v: the tip's bending deflection (m) in the beam's frame; beam.shape: the deformed\n"
     "# centreline, one x and y column per node (beam.shape0_x ... beam.shape8_y)\n"
     "outputs: [beam.tip_v, beam.theta, energy.kinetic, energy.strain, energy.gravity, energy.total, beam.shape]\n"},
    {"rotor", "a flexible blade spun up by a motor (dynamic stiffening)",
     "# A flexible rotor blade spun up by a motor: the paper's spin-up (Liu, Hong & Liu 2009), shorter.\n"
     "# The hub's speed rises smoothly from 0 to omega0 over ramp_time, then stays; the blade lags\n"
     "# behind while the hub accelerates, then swings back and vibrates about its straight shape.\n"
     "#   flexmbd run rotor.yaml -o rotor.csv --vtk rotor-vtk\n"
     "#   flexmbd plot rotor.csv beam.tip_v\n"
     "solver:\n"
     "  t_end: 8.0               # s\n"
     "  output_step: 0.02        # s\n"
     "materials:\n"
     "  aluminium: {density: 2767.0, youngs_modulus: 68.95e9}\n"
     "sections:\n"
     "  strip: {area: 2.5e-4, second_moment: 1.302e-10}\n"
     "bodies:\n"
     "  - name: beam\n"
     "    type: beam\n"
     "    length: 1.8            # m\n"
     "    elements: 8\n"
     "    material: aluminium\n"
     "    section: strip\n"
     "joints:\n"
     "  - {name: hub, type: revolute, body1: ground, body2: beam}\n"
     "  # the motor prescribes the hub's angle (body2 relative to body1): the spin-up profile\n"
     "  - {name: motor, type: drive, joint: hub, profile: spinup, omega0: 6.0, ramp_time: 5.0}   # rad/s, s\n"
     "outputs: [beam.tip_v, beam.omega, motor.power, energy.kinetic, energy.strain, beam.shape]\n"},
    {"slider-crank", "a motor-driven crank, a flexible connecting rod and a slider",
     "# A slider-crank: a crank driven at one turn per second, a flexible connecting rod and a\n"
     "# slider (a piston) on a horizontal guide.\n"
     "#   flexmbd run slider-crank.yaml -o slider-crank.csv --vtk slider-crank-vtk\n"
     "#   flexmbd plot slider-crank.csv slider.x\n"
     "# The guide is a prismatic joint: the slider moves along the x axis (stroke x = 0.35 .. 0.65 m)\n"
     "# with its angle held; guide.reaction_y is the force the guide takes.\n"
     "solver:\n"
     "  t_end: 2.0               # s\n"
     "  output_step: 0.005       # s\n"
     "gravity: [0.0, -9.81]\n"
     "materials:\n"
     "  aluminium: {density: 2767.0, youngs_modulus: 68.95e9}\n"
     "sections:\n"
     "  strip: {area: 2.5e-4, second_moment: 1.302e-10}\n"
     "bodies:\n"
     "  - name: crank           # 0.15 m long, pinned to the ground at its left end\n"
     "    type: rigid\n"
     "    mass: 0.3\n"
     "    inertia: 5.6e-4        # m L^2 / 12\n"
     "    position: [0.075, 0.0]\n"
     "  - name: rod             # the connecting rod, 0.5 m, from the crank pin to the slider\n"
     "    type: beam\n"
     "    length: 0.5\n"
     "    elements: 4\n"
     "    material: aluminium\n"
     "    section: strip\n"
     "    position: [0.15, 0.0]\n"
     "    damping: 1.0e-4        # s: stiffness-proportional; damps the axial modes the start rings\n"
     "                           # (at 1.6e4 rad/s) and leaves 0.7 % on the first bending mode\n"
     "  - name: slider\n"
     "    type: rigid\n"
     "    mass: 0.5\n"
     "    inertia: 1.0e-3\n"
     "    position: [0.65, 0.0]\n"
     "joints:\n"
     "  - {name: main, type: revolute, body1: ground, body2: crank, point2: [-0.075, 0]}\n"
     "  - {name: motor, type: drive, joint: main, profile: constant, speed: 6.283185307}   # rad/s\n"
     "  - {name: crankpin, type: revolute, body1: crank, body2: rod, point1: [0.075, 0], point2: [0, 0]}\n"
     "  - {name: wristpin, type: revolute, body1: rod, body2: slider, point1: [0.5, 0], point2: [0, 0]}\n"
     "  - {name: guide, type: prismatic, body1: ground, body2: slider, axis: [1.0, 0.0]}\n"
     "outputs: [crank.theta, slider.x, slider.y, rod.tip_v, guide.reaction_y, motor.power, energy.total]\n"},
};
#define NSTARTERS (int)(sizeof starters / sizeof starters[0])

static void list_starters(FILE* f) {
  for (int i = 0; i < NSTARTERS; ++i) fprintf(f, "  %-13s %s\n", starters[i].name, starters[i].what);
}

typedef struct {
  const char* name;
} NewArgs;

static int starter_name(const fmbOptContext* ctx, const char* arg) {
  NewArgs* o = ctx->self;
  if (o->name) {
    fprintf(stderr, "flexmbd new: one starter at a time (got '%s' and '%s')\n", o->name, arg);
    return FMB_EXIT_BAD_INPUT;
  }
  o->name = arg;
  return 0;
}

const fmbCommandSpec fmb_new_command = {"new",
                                        "pendulum|beam|rotor|slider-crank > scene.yaml",
                                        "a commented starter scene on stdout",
                                        NULL,
                                        0,
                                        starter_name,
                                        NULL};

int fmb_cmd_new(int argc, char** argv) {
  NewArgs o = {NULL};
  int rc;
  if (fmb_opt_parse(&fmb_new_command, argc, argv, &o, &rc)) return rc;
  if (!o.name) {
    fprintf(stderr, "usage: flexmbd new NAME > scene.yaml, with NAME one of:\n");
    list_starters(stderr);
    return FMB_EXIT_BAD_INPUT;
  }
  for (int i = 0; i < NSTARTERS; ++i)
    if (strcmp(o.name, starters[i].name) == 0) {
      fputs(starters[i].text, stdout);
      return fflush(stdout) == 0 ? 0 : FMB_EXIT_BAD_INPUT;
    }
  fprintf(stderr, "flexmbd new: no starter named '%s'; there are:\n", o.name);
  list_starters(stderr);
  return FMB_EXIT_BAD_INPUT;
}
