/* test_registry.c — the registry has no fixed length and one door:
 *  - 300 body types registered (copies of the rigid table under other names, as 300 plugins
 *    would bring) and a scene using the 250th loads and runs like one using `rigid`;
 *  - fmb_registry_add refuses another plugin ABI (a newer minor in one table, an older major in
 *    the descriptor; tests/core/test_plugin_abi.c has the whole rule), a missing required
 *    op, a name taken by another table and a name listed twice, leaving the registry as it was; the same table twice
 *    is a no-op. */
#include <stdlib.h>
#include <string.h>

#include "internal.h"
#include "testlib.h"

#define NTYPES 300

int main(void) {
  const fmbRegistry* builtin = fmb_builtin_registry();
  const fmbBodyType* rigid = NULL;
  for (int i = 0; i < fmb_registry_nbodies(builtin); ++i)
    if (strcmp(fmb_registry_body(builtin, i)->name, "rigid") == 0) rigid = fmb_registry_body(builtin, i);
  ENSURE(rigid != NULL);
  if (!rigid) return fmbt_finish("test_registry");

  static fmbBodyType copies[NTYPES];
  static char names[NTYPES][16];
  static const fmbBodyType* list[NTYPES + 1];
  for (int i = 0; i < NTYPES; ++i) {
    copies[i] = *rigid;
    snprintf(names[i], sizeof names[i], "copy%d", i);
    copies[i].name = names[i];
    list[i] = &copies[i];
  }
  fmbRegistry* reg = fmb_registry_new();
  fmbDiag d;
  ENSURE(fmb_registry_add(reg, fmb_builtin_plugin(), "built-in", &d) == 0);
  const fmbPlugin many = {.abi = FMB_ABI_VERSION, .name = "many", .bodies = list};
  ENSURE(fmb_registry_add(reg, &many, "many.so", &d) == 0);
  const int n0 = fmb_registry_nbodies(reg);
  ENSURE(n0 == fmb_registry_nbodies(builtin) + NTYPES);
  ENSURE(strcmp(fmb_registry_body_origin(reg, n0 - 1), "many.so") == 0);

  /* a scene with the 250th copy runs exactly like the same scene with rigid */
  char scene[1024], out[1024];
  fmbt_out_path("registry_copy.yaml", scene, sizeof scene);
  FILE* f = fopen(scene, "w");
  ENSURE(f != NULL);
  if (f) {
    fprintf(f, "solver: {t_end: 1}\ngravity: [0, -9.81]\nbodies:\n"
               "  - {name: a, type: copy249, mass: 2, inertia: 1, velocity: [1, 2]}\n  - {name: b, type: rigid, mass: "
               "2, inertia: 1, velocity: [1, 2]}\n"
               "outputs: [a.y, b.y]\n");
    fclose(f);
  }
  fmbModel* m = fmb_load(scene, NULL, 0, reg, &d);
  ENSURE(m != NULL);
  if (m) {
    fmbRunOptions opt = {.csv_path = fmbt_out_path("registry_copy.csv", out, sizeof out), .quiet = 1};
    fmbStats st;
    ENSURE(fmb_run(m, &opt, &st, &d) == 0);
    fmb_free(m);
    fmbtCsv c;
    ENSURE(fmbt_csv_read(out, &c) == 0);
    const double *ya = fmbt_col(&c, "a.y"), *yb = fmbt_col(&c, "b.y");
    /* y(1) = 2 t - g t^2 / 2 for both */
    if (ya && yb) {
      ENSURE_NEAR(ya[c.nrow - 1], yb[c.nrow - 1], 1e-12);
      ENSURE_NEAR(ya[c.nrow - 1], 2.0 - 9.81 / 2, 1e-5);
    }
    fmbt_csv_free(&c);
  }

  /* refusals leave the registry as it was */
  fmbBodyType bad = *rigid;
  bad.name = "other_abi";
  bad.abi = FMB_ABI_VERSION + 1;
  const fmbBodyType* one[] = {&bad, NULL};
  fmbPlugin p = {.abi = FMB_ABI_VERSION, .name = "p", .bodies = one};
  ENSURE(fmb_registry_add(reg, &p, "p.so", &d) != 0);
  ENSURE(d.code == FMB_EXIT_BAD_INPUT && strstr(d.msg, "ABI") != NULL);
  bad.abi = FMB_ABI_VERSION;
  bad.residual = NULL;
  ENSURE(fmb_registry_add(reg, &p, "p.so", &d) != 0);
  ENSURE(strstr(d.msg, "has no residual op") != NULL);
  bad = *rigid; /* a different table named rigid */
  ENSURE(fmb_registry_add(reg, &p, "p.so", &d) != 0);
  ENSURE(strstr(d.msg, "'rigid' is already registered (from built-in)") != NULL);
  fmbBodyType twin = *rigid;
  twin.name = "twin";
  const fmbBodyType* twice[] = {&twin, &twin, NULL};
  const fmbPlugin p2 = {.abi = FMB_ABI_VERSION, .name = "p2", .bodies = twice};
  ENSURE(fmb_registry_add(reg, &p2, "p2.so", &d) != 0);
  ENSURE(strstr(d.msg, "'twin' is listed twice") != NULL);
  p.abi = (FMB_PLUGIN_ABI_MAJOR - 1) * 1000 + FMB_PLUGIN_ABI_MINOR; /* an older major */
  ENSURE(fmb_registry_add(reg, &p, "p.so", &d) != 0);
  ENSURE(strstr(d.msg, "rebuild it") != NULL);
  ENSURE(fmb_registry_nbodies(reg) == n0);
  ENSURE(fmb_registry_add(reg, &many, "many.so", &d) == 0); /* the same tables again: no-op */
  ENSURE(fmb_registry_nbodies(reg) == n0);
  fmb_registry_free(reg);
  return fmbt_finish("test_registry");
}
