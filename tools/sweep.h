/* sweep.h — what the parts of `flexmbd sweep` share (docs/sweep.md):
 *   cmd_sweep.c      the options (one table, tools/options.h)
 *   sweep_main.c    options -> plan -> the engine; --status, --dry-run
 *   sweep_plan.c     grids, zip, samples, random designs
 *   sweep_journal.c  DIR/runs.csv (append-only, one row per finished run), resume, DIR/table.csv
 *   sweep_exec.c     one run as a child (child_pool.c) and its row; the local loop
 *   farm.c           rank 0 hands out runs one at a time to whichever rank (slot) asks
 *   sweep_mpi.c      the farm's messages over MPI (FLEXMBD_HAVE_MPI)
 *   sweep_h5.c       DIR/sweep.h5 from the journal at the end (FLEXMBD_HAVE_HDF5) */
#ifndef FLEXMBD_SWEEP_H
#define FLEXMBD_SWEEP_H
#include <signal.h>
#include <stdint.h>

#include "child_pool.h"
#include "csv_table.h"
#include "farm.h"
#include "flexmbd_cli.h" /* fmbSafeFile */
#include "sweep_plan.h"

#define FMB_SWEEP_MAX_METRICS 64
#define FMB_SWEEP_MAX_FIXED 256
#define FMB_SWEEP_MAX_RETRIES 3   /* starts without a row before a run is marked lost */
#define FMB_SWEEP_CUT "disk_full" /* the status of a row never written: a run cut short by a full disk */
#define FMB_SWEEP_SYNC_S 1.0      /* the journal goes to the disk at most this often (sweep_journal.c) */
/* the stats fields every row carries, in the order of the stats line */
#define FMB_SWEEP_NSTATS 9
extern const char* const fmb_sweep_stat_names[FMB_SWEEP_NSTATS];
/* leading columns of a row, before the swept paths */
#define FMB_SWEEP_LEAD "index,run_id,attempt,status,exit_code,signal,wall_s,rank"

typedef struct fmbSweepMetric {
  char column[160];
  int kind; /* 0 max, 1 min, 2 end, 3 rms */
} fmbSweepMetric;

typedef struct fmbSweep {
  /* options */
  const char* scene;
  const char* dir;
  const char* verb;                       /* run, static, modes */
  const char* fixed[FMB_SWEEP_MAX_FIXED]; /* --set, numbers normalized */
  int nfixed;
  const char* plugins[16];
  int nplugins;
  fmbSweepMetric metric[FMB_SWEEP_MAX_METRICS];
  int nmetric;
  const char* reference; /* --reference REF.csv */
  fmbTable ref;
  int nrefcol;
  int refcol[FMB_SWEEP_MAX_METRICS]; /* columns of ref compared (--columns, or all) */
  int jobs;
  double timeout_s;      /* absolute, or ... */
  double timeout_factor; /* ... N x the median wall of ok runs (after 5 of them) */
  double mem_limit_mb;
  unsigned retry_mask; /* bit per fmbChildStatus re-run on resume */
  int keep_series, quiet, progress;
  int serve;      /* --runner serve: one `flexmbd run --serve` per slot instead of a process per run */
  char exe[4096]; /* this program, for the children */
  /* the plan and its identities */
  fmbSweepPlan plan;
  long nrun;
  uint64_t* id;    /* run id per index */
  long* first;     /* index of the first run with the same id (identical runs run once) */
  uint64_t digest; /* of the whole plan: every id in order */
  /* MPI */
  int rank, nranks;
  /* the journal (rank 0) */
  int journal_fd;
  long* row_at; /* per index: file offset of its latest row in runs.csv, -1 none */
  int* status;  /* per index: its latest status, -1 none */
  int* starts;  /* per index: dispatches recorded in DIR/inflight.log */
  int inflight_fd;
  double last_sync; /* when the journal last went to the disk */
  long count[FMB_CHILD_NSTATUS];
  long done, failed, running, total_todo;
  double t_start, last_progress;
  /* timeouts relative to the median */
  double* ok_wall;
  long nok, okcap;
  double median_wall;
  long median_at;
  volatile sig_atomic_t* stop;
  /* the disk refused a write (the journal, or a run's own CSV): no more runs are handed out, the
     runs cut short get no row (a resume does them again), and the sweep ends non-zero saying so */
  int disk_full;
  char disk_why[600];
  int lock_fd;             /* DIR/sweep.lock, held (flock) while the sweep runs */
  const char* scene_given; /* the scene as the user named it; sw->scene is the snapshot in DIR */
  /* the scene's and the --samples file's bytes, each read once (hashed into the ids, snapshotted
     into DIR/inputs): held for the command's life by the sweep, as its plan is */
  char* scene_text;
  size_t scene_len;
  char* samples_text;
  size_t samples_len;
} fmbSweep;

/* sweep_journal.c */
/* The folder is the sweep's own (docs/sweep.md, "Files"). DIR/sweep.lock: a second sweep on the
   folder is refused, naming the pid and host of the first (flock: a lock whose holder died is free
   again, whatever its pid); 0 or FMB_EXIT_BAD_INPUT after saying so. */
int fmb_sweep_lock(fmbSweep* sw);
/* DIR/name may be written by this sweep: it does not exist, or it is a regular file a sweep made
   there (listed in DIR/.sweep-files with its inode), never a link, never a file of someone else;
   0, or -1 after saying why */
int fmb_sweep_may_write(const fmbSweep* sw, const char* name);
/* DIR/name written through the one safe-file path (engine/safe_file.c: a temporary beside it,
   renamed at fmb_sweep_file_close(keep), never over an input) after fmb_sweep_may_write; the
   file made is recorded as the sweep's. NULL after saying why. */
fmbSafeFile* fmb_sweep_file_open(const fmbSweep* sw, const char* name);
int fmb_sweep_file_close(fmbSweep* sw, const char* name, fmbSafeFile* f, int keep);
/* a full disk (or any refused write of the sweep's own files): noted once, the sweep stops */
void fmb_sweep_disk_full(fmbSweep* sw, const char* what, int err);
/* the header line of runs.csv / table.csv (no newline) into buf; its length or -1 */
int fmb_sweep_header(const fmbSweep* sw, char* buf, size_t len);
/* opens DIR/runs.csv and DIR/inflight.log: resumes (the same plan, or `resume` given), sets aside
   (`fresh`) or refuses another plan (2); fills row_at/status/starts. 0 or an exit code. */
int fmb_journal_open(fmbSweep* sw, int resume, int fresh);
/* appends one row (ending in '\n') to runs.csv with one write (to the disk once a second): 0; 1
   when not recorded (a run cut short by a full disk, or the write refused: sw->disk_full) */
int fmb_journal_append(fmbSweep* sw, long index, const char* row);
/* records the dispatch of run `index` in inflight.log before it starts */
void fmb_journal_started(fmbSweep* sw, long index);
/* DIR/table.csv: the latest row of every planned run, sorted by index (indices of this plan) */
int fmb_journal_write_table(fmbSweep* sw);
/* DIR/plan.csv: index, run_id and the swept values */
int fmb_journal_write_plan(fmbSweep* sw);
/* takes a start back: run `index` was killed because the sweep was interrupted, not lost */
void fmb_journal_cancelled(fmbSweep* sw, long index);
void fmb_journal_close(fmbSweep* sw);
/* `flexmbd sweep --status DIR` */
int fmb_journal_status(const char* dir);

/* sweep_exec.c */
#define FMB_SWEEP_SET_LEN 600 /* one "--set PATH=VALUE" of a swept path */
#define FMB_SWEEP_MAX_ARGS (8 + 2 * (FMB_SWEEP_MAX_FIXED + FMB_SWEEP_MAX_PATHS + 16))
/* argv of `flexmbd VERB SCENE [-o OUT --quiet] --set ... --plugin ...` for run `index` (sets: the
   swept paths' texts, FMB_SWEEP_MAX_PATHS of them); argv has FMB_SWEEP_MAX_ARGS places; argc */
int fmb_sweep_argv(const fmbSweep* sw, long index, const char* verb, const char* out, char** argv,
                   char (*sets)[FMB_SWEEP_SET_LEN]);
/* kills the pool's children on an interrupt and takes their starts back (they are not lost) */
void fmb_sweep_cancel(fmbSweep* sw, fmbPool* pool);
/* the child for run `index` (attempt `attempt`) started in the pool; 0 or -1 */
int fmb_sweep_start(fmbSweep* sw, fmbPool* pool, long index, double timeout_s);
/* the journal row of a finished child (metrics, stats, message), '\n'-terminated, malloc'd */
char* fmb_sweep_row(fmbSweep* sw, const fmbChildResult* r, int attempt);
/* the same from a runner's answer (sweep_serve.c): its stats line and message */
char* fmb_sweep_row_served(fmbSweep* sw, const fmbChildResult* r, int attempt, const char* stats_line,
                           const char* message);
/* a row for a run that never ran to a result (lost after three starts) */
char* fmb_sweep_row_lost(fmbSweep* sw, long index, int attempt);
/* the deadline of the next run (absolute, or N x median) */
double fmb_sweep_timeout(fmbSweep* sw);
/* after a row: counts, the median of ok walls, the progress line */
void fmb_sweep_account(fmbSweep* sw, int status, double wall_s);
void fmb_sweep_progress(fmbSweep* sw, int final);
/* the runs still to do, in-flight ones (started, no row) first: *n_inflight of them; malloc'd */
long* fmb_sweep_todo(fmbSweep* sw, long* n, long* n_inflight);
/* the whole sweep in this process (t NULL) or over the ranks of t (rank 0 plans, keeps the
   journal and hands out runs, sweep_mpi.c); 0, or FMB_EXIT_INTERRUPTED (resumable) */
int fmb_sweep_farm(fmbSweep* sw, const fmbFarmTransport* t);
/* the same with persistent runners (`--runner serve`, sweep_serve.c): rank 0 with process per
   run when there are other ranks, which use runners */
int fmb_sweep_serve(fmbSweep* sw, const fmbFarmTransport* t);
/* where the runners' runs come from and their rows go: the local journal, or rank 0 (MPI) */
typedef struct fmbRunFeed {
  /* the next run: 1 with its index, attempt and time limit; 0 none now; -1 none any more */
  int (*next)(void* ctx, long* index, int* attempt, double* timeout);
  /* a finished run's row (malloc'd, taken over; NULL when out of memory) */
  void (*done)(void* ctx, const fmbChildResult* res, char* row);
  /* optional, called every round: fetch what arrived (nonzero when something did) */
  int (*pump)(void* ctx);
  /* optional: a run killed because the sweep was interrupted */
  void (*cancelled)(void* ctx, long index);
  void* ctx;
} fmbRunFeed;
int fmb_sweep_serve_feed(fmbSweep* sw, const fmbRunFeed* feed);
/* runs the in-flight runs of a crash one at a time (each alone: one may be what crashed) */
int fmb_sweep_rerun_inflight(fmbSweep* sw, const long* todo, long n);

/* MPI and HDF5 live in a module loaded only by `flexmbd sweep` (libflexmbd_sweep.so, built from
   sweep_mpi.c, sweep_h5.c and sweep_extension.c when the libraries are found): linked into the
   program, their 40 libraries would be loaded by every child `flexmbd run` too, 12 ms each (the
   four-bar runs in 4 ms). sweep_load.c finds it beside the program (build tree) or in
   LIBDIR/flexmbd (installed); without it the sweep is the local pool and writes no sweep.h5. */
typedef struct fmbSweepExtension {
  int has_mpi, has_hdf5;
  /* MPI_Init; *t: this rank, their number and the farm's messages (farm.h); 0 or -1 */
  int (*mpi_init)(fmbFarmTransport* t);
  void (*mpi_finalize)(int rc); /* MPI_Finalize, or MPI_Abort when interrupted */
  /* the HDF5 file at `path` (the safe path's temporary for DIR/sweep.h5, cmd_sweep.c) from
     DIR/plan.csv, DIR/table.csv and (--keep series) the series; 0 or -1 */
  int (*write_h5)(const fmbSweep* sw, const char* path);
} fmbSweepExtension;
/* started by mpirun or srun (their environment variables: OMPI_COMM_WORLD_SIZE, PMIX_RANK, ...) */
int fmb_sweep_launched_by_mpi(void);
/* Under mpirun/srun, MPI started through the module (`who`: the command, for messages): 1 with
   *t when there is more than one rank; 0 otherwise (this process alone); -1 when this rank has
   nothing to do (built without MPI: rank 0 works alone, the others should leave at once) */
int fmb_farm_mpi_start(const char* who, fmbFarmTransport* t);
/* `sweep`'s options besides those stored in fmbSweep (tools/cmd_sweep.c) */
typedef struct fmbSweepArgs {
  fmbSweep sw;
  const char *columns, *status_dir, *samples_name;
  int dry, resume, fresh, yes, seed_given;
  int design_lhs; /* -1 not given, 0 mc, 1 lhs */
  int verb;       /* run, static, modes */
  int runner;     /* auto, spawn, serve */
  int count;      /* --count N */
} fmbSweepArgs;
/* the sweep of the parsed options (tools/sweep_main.c): the command's exit code */
int fmb_sweep_main(fmbSweepArgs* a);
/* "flexmbd sweep: " and fmt with what, on stderr; FMB_EXIT_BAD_INPUT */
int fmb_sweep_bad(const char* fmt, const char* what);
/* with `load`, the module's table (loaded once), or fallbacks (local pool, no HDF5) when it cannot
   be loaded; without, the fallbacks until it is */
const fmbSweepExtension* fmb_sweep_extension_load(int load);
/* in the module (sweep_mpi.c, sweep_h5.c) */
int fmb_sweep_mpi_init(fmbFarmTransport* t);
void fmb_sweep_mpi_finalize(int rc);
int fmb_sweep_write_h5(const fmbSweep* sw, const char* path);
#endif
