/* fuzz_table.c — libFuzzer harness for time-table files (issue 27): the input bytes become the
 * CSV file `table: fuzz_table.csv` of a torque law (a rigid body on a pin, driven by the table),
 * which fmb_load reads (engine/yaml_get.c: one pass into growing arrays, regular files only, a
 * size and line-length cap); a table that loads is then run for 0.01 s, so the law's
 * interpolation and integral see it too. Any exit code is fine; a crash, a hang or a sanitizer
 * report is a finding. */
#include <stdint.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>
#include <unistd.h>

#include "builtin.h"
#include "flexmbd.h"

static char dir[64], scene[96], table[96], csv[96];

int LLVMFuzzerInitialize(int* argc, char*** argv) {
  (void)argc;
  (void)argv;
  snprintf(dir, sizeof dir, "%s/fuzz_table_%d", access("/dev/shm", W_OK) == 0 ? "/dev/shm" : "/tmp", (int)getpid());
  if (mkdtemp(strcat(dir, "_XXXXXX")) == NULL) abort();
  snprintf(scene, sizeof scene, "%s/scene.yaml", dir);
  snprintf(table, sizeof table, "%s/fuzz_table.csv", dir);
  snprintf(csv, sizeof csv, "%s/out.csv", dir);
  FILE* f = fopen(scene, "w");
  if (!f) abort();
  fputs("solver: {t_end: 0.01, output_step: 0.005}\n"
        "bodies:\n  - {name: hub, type: rigid, mass: 1, inertia: 0.1}\n"
        "joints:\n  - {name: pin, type: revolute, body1: ground, body2: hub}\n"
        "  - {name: motor, type: force, body: hub, torque: 2.0, law: table, table: fuzz_table.csv}\n"
        "outputs: [hub.theta, motor.work]\n",
        f);
  fclose(f);
  return 0;
}

int LLVMFuzzerTestOneInput(const uint8_t* data, size_t size) {
  FILE* f = fopen(table, "wb");
  if (!f) abort();
  if (size && fwrite(data, 1, size, f) != size) abort();
  fclose(f);
  fmbDiag d;
  fmbModel* m = fmb_load(scene, NULL, 0, fmb_builtin_registry(), &d);
  if (m) {
    fmbRunOptions opt = {.csv_path = csv, .quiet = 1};
    fmb_run(m, &opt, NULL, &d);
    fmb_free(m);
  }
  return 0;
}
