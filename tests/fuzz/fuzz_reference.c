/* fuzz_reference.c — libFuzzer harness for regression references (issue 27): the input bytes
 * become pendulum.ref.csv beside a 0.02 s pendulum scene, and `flexmbd regress` checks the scene
 * against it (fmb_cmd_regress: the reference's '#' header — settings, tolerances, replayed keys —
 * and its rows). A reference that parses makes regress run the scene in a child process. Any
 * exit code is fine; a crash, a hang or a sanitizer report is a finding. stdout is discarded. */
#include <stdint.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>
#include <unistd.h>

#include "cli.h"

static char dir[64], scene[96], ref[96];

int LLVMFuzzerInitialize(int* argc, char*** argv) {
  (void)argc;
  (void)argv;
  snprintf(dir, sizeof dir, "%s/fuzz_ref_%d", access("/dev/shm", W_OK) == 0 ? "/dev/shm" : "/tmp", (int)getpid());
  if (mkdtemp(strcat(dir, "_XXXXXX")) == NULL) abort();
  snprintf(scene, sizeof scene, "%s/pendulum.yaml", dir);
  snprintf(ref, sizeof ref, "%s/pendulum.ref.csv", dir);
  FILE* f = fopen(scene, "w");
  if (!f) abort();
  fputs("solver: {t_end: 0.02, output_step: 0.01}\ngravity: [0, -9.81]\n"
        "bodies:\n  - {name: bob, type: rigid, mass: 1, inertia: 0.1, position: [1, 0]}\n"
        "joints:\n  - {name: pin, type: revolute, body1: ground, body2: bob, point2: [-1, 0]}\n"
        "outputs: [bob.theta, bob.omega]\n",
        f);
  fclose(f);
  if (!freopen("/dev/null", "w", stdout)) abort();
  return 0;
}

int LLVMFuzzerTestOneInput(const uint8_t* data, size_t size) {
  FILE* f = fopen(ref, "wb");
  if (!f) abort();
  if (size && fwrite(data, 1, size, f) != size) abort();
  fclose(f);
  char* argv[] = {"flexmbd", "regress", dir, NULL};
  fmb_cmd_regress(3, argv);
  return 0;
}
