/* faulty.c — a body plugin that fails on purpose, for the fault tests of `flexmbd sweep`
 * (tests/sweep/test_faults.sh): its key `fault` picks how the run that loads it ends.
 *   0 nothing (a unit mass held at its rest pose by unit springs: R = a + q)
 *   1 segmentation fault   2 abort   3 hang (never returns)   4 allocate without end
 *   5 exit 7 (an exit code flexmbd never returns)
 *   6 its output `level` is NaN from a finite state (tests/failures' nan_output: the message names the
 *     column and blames the output op, not the run's tolerances)
 *   7 nothing wrong, but it prints on stdout when loaded, lines shaped like a runner's answers
 *     (test_hostile.sh: the serve runner's answers must not be read from stdout)
 * The fault happens at the first evaluation of the equations (so `flexmbd check`, which only
 * loads the scene, passes), in the child, as a broken plugin's would. */
#include <math.h>
#include <signal.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>
#include <unistd.h>

#include <flexmbd_plugin.h>

static void fail(int fault) {
  switch (fault) {
    case 1: raise(SIGSEGV); break;
    case 2: abort();
    case 3:
      for (;;) sleep(1);
    case 4:
      for (;;) { /* a leak that never stops: RLIMIT_AS (sweep --mem-limit) ends it */
        char* p = malloc(64u << 20);
        if (!p) abort(); /* what a program that does not check would do, one step later */
        memset(p, 1, 64u << 20);
      }
    case 5: _exit(7);
    default: break;
  }
}

static int faulty_parse(fmbParser* p, fmbNode item, void** self) {
  int* fault = calloc(1, sizeof *fault);
  if (!fault) return fmb_parse_error(p, item, "out of memory");
  *self = fault;
  if (fmb_get_int(p, item, "fault", 0, 0, 7, fault)) return -1;
  if (*fault == 7) { /* the old one-line answer and the framed one (serve_protocol.h) */
    printf("0\tstats: status=ok t_reached=9 steps=1\tprinted by a plugin\nA 1 0 0 0\n");
    fflush(stdout);
    *fault = 0;
  }
  return 0;
}
static void faulty_destroy(void* self) { free(self); }
static int faulty_ncoord(const void* self) {
  (void)self;
  return 3;
}
static void faulty_initial(const void* self, double* q, double* v) {
  (void)self;
  memset(q, 0, 3 * sizeof *q), memset(v, 0, 3 * sizeof *v);
}
static int faulty_residual(const void* self, const fmbEnv* env, const double* q, const double* v, const double* a,
                           double* R, double* work) {
  (void)env, (void)v, (void)work;
  fail(*(const int*)self);
  for (int i = 0; i < 3; ++i) R[i] = a[i] + q[i];
  return 0;
}
static int faulty_marker(const void* self, const double* q, const double local[2], double pos[2], double* angle,
                         double* dpos_dq, double* dangle_dq, double* work) {
  (void)self, (void)work;
  fmb_frame_point(q, local, pos, angle, dpos_dq, dangle_dq);
  return 0;
}
/* `level`: 0, or NaN with fault 6 (a broken output op; the equations stay finite) */
static const char* const faulty_output_names[] = {"level", NULL};
static int faulty_output(const void* self, int id, const double* q, const double* v, double* value, double* work) {
  (void)id, (void)q, (void)v, (void)work;
  *value = *(const int*)self == 6 ? NAN : 0.0;
  return 0;
}
static const fmbParam faulty_params[] = {
    {.key = "fault", .kind = FMB_PARAM_NUMBER, .flags = 0, .unit = "-"},
    {.key = NULL},
};
static const fmbBodyType faulty = {.name = "faulty",
                                   .abi = FMB_ABI_VERSION,
                                   .parse = faulty_parse,
                                   .destroy = faulty_destroy,
                                   .ncoord = faulty_ncoord,
                                   .initial = faulty_initial,
                                   .residual = faulty_residual,
                                   .marker = faulty_marker,
                                   .output_names = faulty_output_names,
                                   .output = faulty_output,
                                   .params = faulty_params,
                                   .example = "fault: 0\n"};
static const fmbBodyType* const bodies[] = {&faulty, NULL};
static const fmbPlugin plugin = {.abi = FMB_ABI_VERSION, .name = "faulty", .version = "0", .bodies = bodies};
FMB_PLUGIN_EXPORT const fmbPlugin* fmb_plugin_descriptor(void) { return &plugin; }
