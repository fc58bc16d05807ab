#include "check.h"

int fmbt_failures = 0, fmbt_checks = 0;

int fmbt_finish(const char* name) {
  printf("%s: %d passed, %d failed\n", name, fmbt_checks - fmbt_failures, fmbt_failures);
  return fmbt_failures ? 1 : 0;
}
