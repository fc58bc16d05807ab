/* fuzz_compare.c — libFuzzer harness for `flexmbd compare` (issue 12): the input bytes, split at
 * the first NUL byte, become OUT.csv and REF.csv (a fixed small reference when there is no NUL),
 * written to temporary files and compared through fmb_cmd_compare with and without --columns.
 * Any exit code is fine; a crash, a hang or a sanitizer report is a finding. stdout is discarded. */
#include <stdint.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>
#include <unistd.h>

#include "cli.h"

static const char reference[] = "t,a.x,energy.total\n0,1,2\n0.5,1.5,2\n1,2,2\n";
static char out_path[64], ref_path[64];

static void write_file(const char* path, const uint8_t* data, size_t size) {
  FILE* f = fopen(path, "wb");
  if (!f) abort();
  if (size && fwrite(data, 1, size, f) != size) abort();
  fclose(f);
}

int LLVMFuzzerInitialize(int* argc, char*** argv) {
  (void)argc;
  (void)argv;
  const char* dir = access("/dev/shm", W_OK) == 0 ? "/dev/shm" : "/tmp";
  snprintf(out_path, sizeof out_path, "%s/fuzz_compare_out_%d.csv", dir, (int)getpid());
  snprintf(ref_path, sizeof ref_path, "%s/fuzz_compare_ref_%d.csv", dir, (int)getpid());
  if (!freopen("/dev/null", "w", stdout)) abort();
  return 0;
}

int LLVMFuzzerTestOneInput(const uint8_t* data, size_t size) {
  const uint8_t* nul = memchr(data, 0, size);
  if (nul) {
    write_file(out_path, data, (size_t)(nul - data));
    write_file(ref_path, nul + 1, size - (size_t)(nul - data) - 1);
  } else {
    write_file(out_path, data, size);
    write_file(ref_path, (const uint8_t*)reference, sizeof reference - 1);
  }
  char* argv1[] = {"flexmbd", "compare", out_path, ref_path, NULL};
  fmb_cmd_compare(4, argv1);
  char* argv2[] = {"flexmbd", "compare", out_path, ref_path, "--columns", "a.x,energy.total", "--rtol", "1e-3", NULL};
  fmb_cmd_compare(8, argv2);
  return 0;
}
