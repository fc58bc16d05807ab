/* test_output_units.c — the units on plot and `view` axes for a type's own outputs
 * (fmb_output_unit_in, the types' output_units; issue 27 item 6):
 *  - the built-in types' quantities get their declared unit, numbered names through their
 *    nodeK_ form, and the engine's own columns keep theirs;
 *  - a quantity two types declare with different units gets none (an axis without a unit rather
 *    than a wrong one), and an unknown quantity none;
 *  - a table whose output_units do not pair with its output_names is refused at registration;
 *  - the rate outputs' units are their quantity's per second, checked against the numbers: a
 *    beam's tip_v_rate equals the difference quotient of tip_v over a short run. */
#include <math.h>
#include <stdlib.h>
#include <string.h>

#include "internal.h"
#include "testlib.h"

static int same(const char* a, const char* b) { return a && b ? strcmp(a, b) == 0 : a == b; }

int main(void) {
  const fmbRegistry* builtin = fmb_builtin_registry();
  ENSURE(same(fmb_output_unit_in(builtin, "beam.tip_v"), "m"));
  ENSURE(same(fmb_output_unit_in(builtin, "beam.tip_v_rate"), "m/s"));
  ENSURE(same(fmb_output_unit_in(builtin, "beam.tip_angle"), "rad"));
  ENSURE(same(fmb_output_unit_in(builtin, "rotor.node12_v"), "m"));
  ENSURE(same(fmb_output_unit_in(builtin, "pin.angle"), "rad"));
  ENSURE(same(fmb_output_unit_in(builtin, "coil.tension"), "N")); /* spring and prismatic agree */
  ENSURE(same(fmb_output_unit_in(builtin, "hub.torque"), "N m"));
  ENSURE(same(fmb_output_unit_in(builtin, "t"), "s"));
  ENSURE(same(fmb_output_unit_in(builtin, "energy.total"), "J"));
  ENSURE(same(fmb_output_unit_in(builtin, "beam.no_such_quantity"), NULL));
  ENSURE(same(fmb_output_unit_in(NULL, "beam.tip_v"), NULL)); /* without types, only the engine's */
  ENSURE(same(fmb_output_unit_in(builtin, NULL), NULL));

  /* a plugin whose revolute-like joint calls its `angle` degrees: the registry now disagrees */
  const fmbJointType* revolute = NULL;
  for (int i = 0; i < fmb_registry_njoints(builtin); ++i)
    if (strcmp(fmb_registry_joint(builtin, i)->name, "revolute") == 0) revolute = fmb_registry_joint(builtin, i);
  ENSURE(revolute != NULL);
  if (!revolute) return fmbt_finish("test_output_units");
  static const char* const deg[] = {"deg", NULL};
  fmbJointType in_degrees = *revolute;
  in_degrees.name = "revolute_deg";
  in_degrees.output_units = deg;
  const fmbJointType* joints[] = {&in_degrees, NULL};
  const fmbPlugin plugin = {.abi = FMB_ABI_VERSION, .name = "deg", .joints = joints};
  fmbRegistry* reg = fmb_registry_new();
  fmbDiag d;
  ENSURE(fmb_registry_add(reg, fmb_builtin_plugin(), "built-in", &d) == 0);
  ENSURE(fmb_registry_add(reg, &plugin, "deg.so", &d) == 0);
  ENSURE(same(fmb_output_unit_in(reg, "pin.angle"), NULL));
  ENSURE(same(fmb_output_unit_in(reg, "beam.tip_v"), "m"));

  /* units that do not pair with the names are refused, the registry left as it was */
  static const char* const too_few[] = {NULL};
  fmbJointType short_units = *revolute;
  short_units.name = "revolute_short";
  short_units.output_units = too_few;
  const fmbJointType* joints2[] = {&short_units, NULL};
  const fmbPlugin bad = {.abi = FMB_ABI_VERSION, .name = "short", .joints = joints2};
  const int nj = fmb_registry_njoints(reg);
  ENSURE(fmb_registry_add(reg, &bad, "short.so", &d) != 0);
  ENSURE(strstr(d.msg, "output_units") != NULL);
  ENSURE(fmb_registry_njoints(reg) == nj);
  fmb_registry_free(reg);

  /* tip_v_rate is tip_v per second: its value is tip_v's derivative (central difference of the
     rows of a spin-up, where tip_v moves smoothly) */
  const char* overrides[] = {"solver.t_end=0.5", "solver.output_step=0.001", "solver.rtol=1e-10",
                             "outputs=[beam.tip_v, beam.tip_v_rate]"};
  char path[1024];
  fmbModel* m = fmb_load(fmbt_path("scenes/paper/spinup_w4.yaml", path, sizeof path), overrides, 4, builtin, &d);
  ENSURE(m != NULL);
  if (m) {
    fmbData* data = fmb_data_new(m, &d);
    ENSURE(data && fmb_init(m, data, &d) == 0);
    double prev[2] = {0, 0}, cur[2] = {0, 0}, worst = 0.0, scale = 0.0;
    const double h = 0.001;
    for (int k = 1; k <= 400 && data; ++k) {
      double row[2];
      if (fmb_advance(m, data, k * h, &d) || fmb_outputs(m, data, row)) break;
      if (k >= 3) {
        const double rate = (row[0] - prev[0]) / (2 * h); /* at the middle row, cur */
        worst = fmax(worst, fabs(rate - cur[1]));
        scale = fmax(scale, fabs(cur[1]));
      }
      memcpy(prev, cur, sizeof prev);
      memcpy(cur, row, sizeof cur);
    }
    ENSURE(scale > 0.0);
    ENSURE_NEAR(worst / scale, 0.0, 1e-3);
    fmb_data_free(data);
    fmb_free(m);
  }
  return fmbt_finish("test_output_units");
}
