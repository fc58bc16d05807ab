/* regress.h — what the parts of `flexmbd regress` share (docs/regression.md):
 *   cmd_regress.c     options, the order of work, exit codes
 *   regress_ref.c     finding scenes, reading and writing (--bless) references
 *   regress_jobs.c    each scene run in a child process (child_pool.c, shared with `sweep`) and
 *                     compared with its reference
 *   regress_report.c  the table on stdout and JUnit XML */
#ifndef FLEXMBD_REGRESS_H
#define FLEXMBD_REGRESS_H
#include <stddef.h>

#include "cli.h"
#include "csv_table.h"

/* Default column tolerance (docs/regression.md): --bless also runs the scene at rtol x 0.97 and
   x 1.03. Those companions take other, equally valid step sequences, as another compiler or a fused
   multiply-add does; their largest difference from the run, per column, is the column's noise:
     atol_col = NOISE_FACTOR noise + SOLVER_FACTOR atol,   rtol_col = SOLVER_FACTOR rtol
   Measured on the shipped scenes (docs/regression.md): an FMA build differs from the plain one by
   at most 1.5x the noise; a 1e-3 relative change of a length, a modulus or a mass goes 4x to 6000x
   beyond the tolerance. */
#define REGRESS_NOISE_FACTOR 10.0
#define REGRESS_SOLVER_FACTOR 10.0
#define REGRESS_NCOMPANION 2
extern const double regress_companion_rtol[REGRESS_NCOMPANION];
#define REGRESS_DEFAULT_ROWS 201
#define REGRESS_MAX_DEPTH 256 /* folders below a searched PATH; a deeper one is refused */

typedef struct {
  char name[160];
  double atol, rtol;
  int override; /* set by a person: --bless keeps it */
  int line;     /* its line in the reference (a second line for the same column is refused) */
} RegressTol;

typedef struct {
  int present;
  char** sets; /* the --set overrides the reference was made with (only keys that change numbers) */
  int nsets;
  RegressTol* tol;
  int ntol;
  int status_ok;
  double t_reached, cpu_s;
  fmbTable data;
} RegressRef;

/* what a child process reports about its run */
typedef struct {
  int loaded;    /* 0: the scene did not load (msg says why) */
  int bad_set;   /* it did not load because of a command-line --set: bad input, not a failed scene */
  int exit_code; /* fmb_run's */
  int status_ok;
  double t_reached, cpu_s;
  long steps;
  fmbSolverInfo solver;
  char msg[1024];
} RegressRun;

typedef struct RegressJob {
  char* scene;
  char* ref_path;
  int companion; /* 0 the run itself; k > 0 runs at rtol x companion_rtol[k - 1] (--bless) */
  RegressRef ref;
  int pipe_fd;
  char csv[600], err[600]; /* the child's CSV and stderr */
  RegressRun run;
  /* verdict */
  int failed, bad_input, warn_slow;
  char worst[160];
  double worst_err, worst_tol, worst_t;
  char why[1200];
  const char* action; /* bless: "written", "unchanged" */
} RegressJob;

typedef struct {
  const char** sets; /* command-line --set */
  int nsets;
  int bless, jobs, rows;
  double slow;
  double timeout_s; /* per scene (wall time) */
  const char* junit;
  char tmpdir[512];
} RegressOptions;

typedef struct {
  char** v;
  int n, cap;
} RegressList;

/* regress_ref.c */
/* the CSV the job's run wrote, read into *out (the caller frees it); -1 with job->failed and
   job->why set when it is missing or unreadable (bless and check read it the same way) */
int regress_load_run_csv(RegressJob* job, fmbTable* out);
void regress_say(char* buf, size_t len, const char* fmt, ...) __attribute__((format(printf, 3, 4)));
/* 0, or -1 when out of memory */
int regress_list_push(RegressList* l, char* s);
int regress_file_exists(const char* p);
/* SCENE.ref.csv beside SCENE.yaml (or .yml); NULL when out of memory */
char* regress_reference_path(const char* scene);
/* the scene beside `scene` that has the same reference (SCENE.yml beside SCENE.yaml and the other
   way round) when it exists, or NULL; the caller frees it */
char* regress_twin_scene(const char* scene);
/* Every scene below dir (with `all`, every .yaml or .yml scene, otherwise those with a reference)
   into out, following symbolic links (each folder searched once); what it passes over that a user
   may have meant (scenes without a reference, links to nothing or to a folder searched already,
   unreadable folders) is listed in `skipped` with the reason. 0, or -1 with why when a folder lies
   more than REGRESS_MAX_DEPTH below dir (it is not searched: bad input, never a quiet pass). */
int regress_walk(const char* dir, int all, RegressList* out, RegressList* skipped, char* why, size_t len);
/* 0, or -1 with why (a malformed reference is bad input); `warn` gets notes about what it ignores */
int regress_reference_load(const char* path, RegressRef* r, char* why, size_t len, RegressList* warn);
void regress_reference_free(RegressRef* r);
const RegressTol* regress_find_tol(const RegressRef* r, const char* col);
/* write (or keep) the reference of a finished run (its companions follow it in the job list);
   0, or -1 with why */
int regress_bless_job(RegressJob* job, const RegressOptions* o);

/* regress_jobs.c */
/* runs every job in a child process, o->jobs at once; returns FMB_EXIT_INTERRUPTED when SIGINT or
   SIGTERM came (every child killed), else 0 */
int regress_run_all(RegressJob* jobs, int n, const RegressOptions* o);
/* compares a finished run with its reference: fills the verdict */
void regress_check_job(RegressJob* job);

/* regress_report.c */
int regress_write_junit(const char* path, RegressJob* const* jobs, int n);
void regress_print_table(RegressJob* const* jobs, int n, const RegressOptions* o);
#endif
