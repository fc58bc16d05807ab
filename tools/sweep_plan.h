/* sweep_plan.h — the runs of a sweep: factors (grids, zipped lists, a samples file, a random
 * design) multiplied out in full factorial order, first factor slowest (docs/sweep.md, "Plans").
 * Every value is text: numbers are printed %.17g (so `--set PATH=VALUE` reproduces them bit for
 * bit), anything else (a model name) is kept as written. */
#ifndef FLEXMBD_SWEEP_PLAN_H
#define FLEXMBD_SWEEP_PLAN_H
#include <stdint.h>
#include <stdio.h>

#define FMB_SWEEP_MAX_PATHS 64

typedef struct fmbSweepFactor {
  int npath;
  int path[FMB_SWEEP_MAX_PATHS]; /* indices into fmbSweepPlan.path */
  long nrow;
  char** value;           /* nrow x npath; a grid A:B:N gets its values only in fmb_plan_finish, once the
                   plan's size has been accepted (a refused plan of 1e9 runs allocates nothing) */
  int is_range, logscale; /* a grid A:B:N[:log] not yet laid out */
  double a, b;
} fmbSweepFactor;

typedef struct fmbSweepPlan {
  int npath;
  char* path[FMB_SWEEP_MAX_PATHS];
  int nfactor;
  fmbSweepFactor factor[FMB_SWEEP_MAX_PATHS];
  /* random design, drawn once the count is known (fmb_plan_draw_random) */
  int nrandom;
  int random_path[FMB_SWEEP_MAX_PATHS];
  int random_kind[FMB_SWEEP_MAX_PATHS]; /* 0 uniform(a,b), 1 normal(m,s), 2 lognormal(m,s) */
  double random_p[FMB_SWEEP_MAX_PATHS][2];
  long count;    /* --count N */
  uint64_t seed; /* --seed S */
  int lhs;       /* --design lhs */
} fmbSweepPlan;

/* Each adds a factor (or a random path); 0, or -1 with "what was expected" in err. */
int fmb_plan_add_grid(fmbSweepPlan* p, const char* spec, char* err, size_t len); /* PATH=A:B:N[:log] | PATH=v1,v2 */
int fmb_plan_add_zip(fmbSweepPlan* p, const char* spec, char* err, size_t len);  /* PATH=v1,v2,... (paired) */
/* CSV, header = paths: `text` (len bytes) is the file's content, read once (fmb_sweep_read_input), `file` its name */
int fmb_plan_add_samples(fmbSweepPlan* p, const char* file, const char* text, size_t textlen, char* err, size_t len);
int fmb_plan_add_random(fmbSweepPlan* p, const char* spec, char* err, size_t len); /* PATH=uniform(a,b)|... */
/* after all options and after the size was accepted: grids laid out, the random factor (needs
   --count); 0 or -1 */
int fmb_plan_finish(fmbSweepPlan* p, char* err, size_t len);
/* the number of runs, as a double (a product that may not fit a long: checked before use) */
double fmb_plan_size(const fmbSweepPlan* p);
/* the value of path k in run i */
const char* fmb_plan_value(const fmbSweepPlan* p, long i, int k);
void fmb_plan_free(fmbSweepPlan* p);
/* the longest value a plan holds (a longer one is refused, never cut) */
#define FMB_PLAN_VALUE_MAX 255
/* A whole input file into memory (malloc'd, NUL-terminated, *n bytes): opened without waiting
   (O_NONBLOCK: a FIFO never blocks) and refused unless a regular file of at most max bytes, so a
   FIFO, /dev/zero or a terminal given as an input is an error, not a hang. 0, or -1 with
   "PATH: why" in err. */
int fmb_sweep_read_input(const char* path, size_t max, char** text, size_t* n, char* err, size_t errlen);

/* the counter-based generator: a uniform number in (0, 1) for (seed, sample, stream), the same
   whatever the order samples are drawn in (splitmix64's finalizer over a combined counter) */
double fmb_plan_uniform(uint64_t seed, uint64_t sample, uint64_t stream);
/* the standard normal quantile (bisection on erfc: slow, exact to the last bits, reproducible) */
double fmb_plan_normal_quantile(double u);

/* splitmix64's output function: a bijection of 64-bit words that scatters every input bit */
uint64_t fmb_mix64(uint64_t z);
/* FNV-1a 64 over bytes, continuing from h (start with FMB_FNV_OFFSET) */
#define FMB_FNV_OFFSET 0xcbf29ce484222325ULL
uint64_t fmb_fnv1a(uint64_t h, const void* data, size_t n);
#endif
