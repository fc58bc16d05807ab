/* fuzz_load.c — libFuzzer harness for the scene loader: the input bytes are a scene file, loaded
 * with the built-in registry (every plugin's parse), described, and freed. The integrator is not
 * run. Any crash, sanitizer report or leak is a finding; a rejected scene must say where and why
 * (a diagnostic with a code and a message), which is checked too. */
#include <stdint.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>
#include <unistd.h>

#include "builtin.h"
#include "flexmbd.h"

static char path[64];
static int fd = -1;
static FILE* devnull;

int LLVMFuzzerInitialize(int* argc, char*** argv) {
  (void)argc;
  (void)argv;
  /* the scene goes through a file (fmb_load takes a path): in memory when /dev/shm exists */
  snprintf(path, sizeof path, "%s/fuzz_load_XXXXXX", access("/dev/shm", W_OK) == 0 ? "/dev/shm" : "/tmp");
  fd = mkstemp(path);
  devnull = fopen("/dev/null", "w");
  if (fd < 0 || !devnull) abort();
  return 0;
}

/* Sizes are the benchmarks' business, not the fuzzer's (fuzz_override.c says why): a scene whose
   text asks for more than FUZZ_MAX_ELEMENTS beam elements is skipped. */
#define FUZZ_MAX_ELEMENTS 256
static int too_large(const uint8_t* data, size_t size) {
  static const char key[] = "elements";
  for (size_t i = 0; i + sizeof key < size; ++i) {
    if (memcmp(data + i, key, sizeof key - 1) != 0) continue;
    size_t k = i + sizeof key - 1;
    while (k < size && (data[k] == ':' || data[k] == ' ' || data[k] == '=')) ++k;
    double v = 0.0;
    while (k < size && data[k] >= '0' && data[k] <= '9' && v <= FUZZ_MAX_ELEMENTS) v = 10.0 * v + (data[k++] - '0');
    if (v > FUZZ_MAX_ELEMENTS) return 1;
  }
  return 0;
}

int LLVMFuzzerTestOneInput(const uint8_t* data, size_t size) {
  if (too_large(data, size)) return 0;
  if (ftruncate(fd, 0) != 0 || pwrite(fd, data, size, 0) != (ssize_t)size) abort();
  fmbDiag diag;
  fmbModel* m = fmb_load(path, NULL, 0, fmb_builtin_registry(), &diag);
  if (m) {
    fmb_describe(m, devnull);
    fmb_free(m);
  } else if (diag.code != FMB_EXIT_BAD_INPUT || diag.msg[0] == '\0') {
    abort(); /* a rejection must be a bad-input diagnostic with a message */
  }
  return 0;
}
