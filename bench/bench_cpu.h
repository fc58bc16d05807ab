/* bench_cpu.h — what the bench programs time with (rows.c, inputs.c): the process's CPU time (as
 * fmb_run's cpu_s counts it) and the median of repeated measurements. Header-only: each bench
 * program is one file built on its own (CMakeLists.txt). */
#ifndef FMB_BENCH_CPU_H
#define FMB_BENCH_CPU_H

#include <stdlib.h>
#include <time.h>

static double cpu_now(void) {
  struct timespec ts;
  clock_gettime(CLOCK_PROCESS_CPUTIME_ID, &ts);
  return (double)ts.tv_sec + 1e-9 * (double)ts.tv_nsec;
}

static int cmp_d(const void* a, const void* b) {
  const double x = *(const double*)a, y = *(const double*)b;
  return (x > y) - (x < y);
}

/* sorts v */
static double median(double* v, int n) {
  qsort(v, (size_t)n, sizeof *v, cmp_d);
  return n % 2 ? v[n / 2] : 0.5 * (v[n / 2 - 1] + v[n / 2]);
}

#endif
