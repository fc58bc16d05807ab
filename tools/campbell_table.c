/* campbell_table.c — the work of `flexmbd campbell` once its options are read (tools/cmd_campbell.c):
 * the speeds, each speed's modes (here, in -j child processes or on other ranks: modes_pool.c),
 * the diagram followed by shape (the library's fmb_campbell, engine/campbell.c), its CSV and
 * its gnuplot figure. */
#include <math.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>
#include <unistd.h>

#include "cli.h"
#include "sweep.h"

#define MAX_SPEEDS 10000

/* "A:B:N" (N values from A to B) or "S1,S2,..."; returns the count or -1 */
static int parse_speeds(const char* text, double* out) {
  double a, b;
  int n;
  char tail;
  if (sscanf(text, "%lf:%lf:%d%c", &a, &b, &n, &tail) == 3) {
    if (n < 1 || n > MAX_SPEEDS || !isfinite(a) || !isfinite(b)) return -1; /* nan, inf: bad input */
    for (int i = 0; i < n; ++i) out[i] = n == 1 ? a : a + (b - a) * i / (n - 1);
    return n;
  }
  n = 0;
  const char* p = text;
  while (*p && n < MAX_SPEEDS) {
    char* end;
    out[n++] = strtod(p, &end);
    if (end == p || (*end != ',' && *end != '\0') || !isfinite(out[n - 1])) return -1;
    p = *end ? end + 1 : end;
  }
  return *p ? -1 : n;
}

/* the CSV's name of followed mode k: `modeK` (planar, as always), or in a spatial scene its family
   and its rank in the family, `flap1`, `lag1`, `flap2`, `torsion1` ... (fmb_campbell_family) */
static void curve_name(const fmbCampbell* c, int k, char* name, size_t len) {
  const int f = fmb_campbell_family(c, k);
  if (f == FMB_FAMILY_NONE) {
    snprintf(name, len, "mode%d", k + 1);
    return;
  }
  int rank = 1;
  for (int j = 0; j < k; ++j) rank += fmb_campbell_family(c, j) == f;
  snprintf(name, len, "%s%d", fmb_family_name(f), rank);
}

/* gnuplot: one curve per tracked mode; a failure here is a warning, the CSV stands. (Not through
   `flexmbd plot`: its CSV reader takes run outputs, whose first column is t.) */
static void plot(const char* csv, const char* png, const fmbCampbell* c, int count, const char* title) {
  /* gnuplot writes beside the figure; the figure is replaced only by a finished plot */
  fmbSafeFile* fig = fmb_cli_safe_open(png, NULL, 0);
  const char* fig_path = fmb_safe_write_path(fig);
  FILE* g = fig_path ? popen("gnuplot 2>/dev/null", "w") : NULL;
  if (!g) {
    fprintf(stderr, "flexmbd campbell: %s, no plot\n", fig_path ? "gnuplot not available" : "cannot write the figure");
    fmb_safe_close(fig, 0);
    return;
  }
  /* every file name and the title as gnuplot strings it never expands (tools/cli.c) */
  fprintf(g, "set terminal pngcairo size 900,650 noenhanced\nset output ");
  int bad = fmb_cli_gnuplot_string(g, fig_path);
  fprintf(g, "\nset datafile separator ','\nset key outside right\nset grid\nset xlabel 'hub speed (rad/s)'\n"
             "set ylabel 'frequency (rad/s)'\nset title ");
  bad |= fmb_cli_gnuplot_string(g, title);
  fprintf(g, "\nplot ");
  for (int k = 0; k < count && !bad; ++k) {
    fprintf(g, "%s", k ? ", " : "");
    bad |= fmb_cli_gnuplot_string(g, csv);
    const int f = fmb_campbell_family(c, k);
    if (f == FMB_FAMILY_NONE) {
      fprintf(g, " using 1:%d with linespoints pt 7 ps 0.5 title 'mode %d'", k + 2, k + 1);
    } else { /* a spatial scene: the family names the curve, one point type per family */
      char name[32];
      curve_name(c, k, name, sizeof name);
      fprintf(g, " using 1:%d with linespoints pt %d ps 0.6 title '%s'", k + 2, 5 + 2 * f, name);
    }
  }
  if (bad) fprintf(stderr, "flexmbd campbell: a file name holds a control character, no plot\n");
  fprintf(g, bad ? "\nexit status 1\n" : ", x with lines dt 2 lc rgb 'gray' title '1x speed'\n");
  const int ok = pclose(g) == 0;
  if (fmb_safe_close(fig, ok) != 0 || !ok) fprintf(stderr, "flexmbd campbell: gnuplot failed, no plot (%s)\n", png);
}

/* the diagram's rows as the CSV has them: speed, then mode1 ... modeK */
static int write_csv(const char* out, const fmbCampbell* c) {
  const int ncol = c->count + 1;
  double* rows = calloc((size_t)(c->done > 0 ? c->done : 1) * (size_t)ncol, sizeof(double));
  char** names = calloc((size_t)ncol, sizeof(char*));
  char* text = calloc((size_t)ncol, 16);
  fmbDiag wd;
  memset(&wd, 0, sizeof wd);
  int rc = rows && names && text ? 0 : FMB_EXIT_SOLVER;
  if (!rc) {
    names[0] = "speed";
    for (int k = 0; k < c->count; ++k) {
      names[k + 1] = text + 16 * (size_t)(k + 1);
      curve_name(c, k, names[k + 1], 16);
    }
    for (int i = 0; i < c->done; ++i) {
      rows[(size_t)i * ncol] = c->speed[i];
      memcpy(rows + (size_t)i * ncol + 1, c->frequency + (size_t)i * c->count, sizeof(double) * (size_t)c->count);
    }
    rc = fmb_write_table(out, ncol, (const char* const*)names, c->done, rows, &wd);
    if (rc) fmb_cli_print_diag(&wd);
  }
  free(text);
  free(names);
  free(rows);
  return rc;
}

/* a child of -j or of a rank: the modes at its one speed into the file a->modes_out */
static int modes_child(const fmbCliCampbell* a, const fmbSceneSource* scene, const fmbCampbellOptions* opt,
                       const double* speeds, int nspeed) {
  if (nspeed != 1) {
    fprintf(stderr, "flexmbd campbell: --modes-out goes with one speed\n");
    return FMB_EXIT_BAD_INPUT;
  }
  fmbModes* m = NULL;
  fmbDiag d;
  const int mrc = fmb_campbell_modes_at(scene, opt, speeds[0], &m, &d);
  const int saved = fmb_cli_modes_save(a->modes_out, mrc, &d, m);
  if (saved) fprintf(stderr, "flexmbd campbell: cannot write %s\n", a->modes_out);
  fmb_modes_free(m);
  return saved ? FMB_EXIT_SOLVER : 0;
}

/* the children's command line: this one, then `--speeds S --modes-out FILE`, S (slot argc + 1) and
   FILE (slot argc + 3) set per child (a later --speeds wins over the one given, in either form);
   NULL when it cannot be made: every speed then fails to start, with a message (no rank waits) */
static char** child_argv(int argc, char** argv, char* exe, size_t len) {
  const ssize_t el = readlink("/proc/self/exe", exe, len - 1);
  char** child = el > 0 ? calloc((size_t)argc + 5, sizeof *child) : NULL;
  if (!child) return NULL;
  exe[el] = '\0';
  child[0] = exe;
  for (int k = 1; k < argc; ++k) child[k] = argv[k];
  child[argc] = "--speeds";
  child[argc + 2] = "--modes-out";
  return child;
}

/* every speed's modes (pre: from the children, else computed here) added to c in order; the speed
   that failed in *failed_at */
static int follow_modes(fmbCampbell* c, const fmbCliCampbell* a, const fmbSceneSource* scene,
                        const fmbCampbellOptions* opt, const double* speeds, int nspeed, fmbModes** pre, int pre_done,
                        int pre_rc, const fmbDiag* pre_diag, volatile sig_atomic_t* stop, int* failed_at,
                        fmbDiag* diag) {
  int rc = 0;
  for (int i = 0; !rc && i < nspeed; ++i) {
    if (*stop && (!pre || i >= pre_done)) { /* SIGINT/SIGTERM: the speeds done so far are written */
      memset(diag, 0, sizeof *diag);
      diag->code = FMB_EXIT_INTERRUPTED;
      snprintf(diag->msg, sizeof diag->msg,
               "interrupted (SIGINT/SIGTERM) before speed %g: the %d of %d speeds done are kept", speeds[i], c->done,
               nspeed);
      return FMB_EXIT_INTERRUPTED;
    }
    fmbModes* modes = NULL;
    if (!pre) {
      rc = fmb_campbell_modes_at(scene, opt, speeds[i], &modes, diag);
    } else if (i < pre_done) {
      modes = pre[i];
      pre[i] = NULL;
    } else {
      rc = pre_rc;
      *diag = *pre_diag;
    }
    if (rc) *failed_at = i;
    if (!rc && (rc = fmb_campbell_add(c, modes, diag)) != 0)
      snprintf(diag->file, sizeof diag->file, "%s", a->s.scene); /* too few modes: the scene's */
  }
  return rc;
}

/* the warnings, the CSV and its figure, the stats line; returns the command's exit code */
static int report(const fmbCliCampbell* a, const fmbCampbell* c, const double* speeds, int nspeed, int rc,
                  int failed_at, const fmbDiag* diag) {
  const int count = a->an.count;
  const int done = c ? c->done : 0;
  for (int i = 1; i < done; ++i)
    for (int k = 0; k < count; ++k)
      if (c->mac[(size_t)i * count + k] < 0.5)
        fprintf(stderr,
                "flexmbd campbell: at speed %g mode %d matches its shape at the last speed poorly (MAC %.2f): "
                "take finer speed steps\n",
                speeds[i], k + 1, c->mac[(size_t)i * count + k]);
  if (failed_at >= 0 && rc != FMB_EXIT_INTERRUPTED)
    fprintf(stderr, "flexmbd campbell: no modes at speed %.17g (speed %d of %d); the %d speeds before it are kept:\n",
            speeds[failed_at], failed_at + 1, nspeed, failed_at);
  if (rc) fmb_cli_print_diag(diag);
  /* nothing done (a bad --speed, a scene that does not load): an earlier result stays as it was */
  const char *out = a->out, *png = a->png;
  const int wrc = c && done > 0 ? write_csv(out, c) : 0;
  char pngbuf[1024];
  if (!png && out && strcmp(out, "-") != 0) {
    const size_t len = strlen(out);
    const int has_csv = len > 4 && strcmp(out + len - 4, ".csv") == 0;
    snprintf(pngbuf, sizeof pngbuf, "%.*s.png", (int)(has_csv ? len - 4 : len), out);
    png = pngbuf;
  }
  if (!wrc && done > 0 && png && out && strcmp(out, "-") != 0) {
    char title[700];
    snprintf(title, sizeof title, "Campbell diagram: %s", a->s.scene);
    plot(out, png, c, count, title);
  }
  fprintf(stderr, "stats: status=%s speeds=%d of %d modes=%d\n",
          rc == FMB_EXIT_INTERRUPTED ? "interrupted"
          : rc                       ? "failed"
                                     : "ok",
          done, nspeed, count);
  return rc ? rc : wrc;
}

/* the diagram at the parsed speeds: here, or (-j, ranks) the modes in children, then followed */
static int campbell_at(const fmbCliCampbell* a, const double* speeds, int nspeed, int argc, char** argv) {
  const fmbSceneSource scene = {a->s.scene, a->s.overrides, a->s.nover, fmb_cli_registry()};
  const fmbCampbellOptions opt = {a->path, a->an.count, a->an.method, a->an.opt};
  if (a->modes_out) return modes_child(a, &scene, &opt, speeds, nspeed);
  /* under mpirun/srun: the ranks share the speeds; only rank 0 writes (every rank has parsed the
     same command line: a bad one ended them all above, alike) */
  fmbFarmTransport ranks;
  const int mpi = fmb_farm_mpi_start("campbell", &ranks);
  if (mpi < 0) return 0; /* built without MPI: rank 0 works alone */
  char exe[4096];
  char** child = a->jobs > 1 || mpi ? child_argv(argc, argv, exe, sizeof exe) : NULL;
  if (mpi && ranks.rank != 0) { /* a worker: the speeds rank 0 hands out, their modes to rank 0 */
    fmbDiag wdiag;
    int wdone;
    const int wrc = fmb_cli_modes_in_children(a->jobs, child, argc + 1, argc + 3, speeds, nspeed, &ranks,
                                              fmb_cli_catch_stop_signals(), NULL, &wdone, &wdiag);
    free(child);
    fmb_sweep_extension_load(0)->mpi_finalize(wrc);
    return wrc;
  }
  /* fmb_campbell in its steps: each speed's modes (computable anywhere, e.g. in other processes),
     then followed in order */
  fmbCampbell* c = fmb_campbell_new(speeds, nspeed, a->an.count);
  fmbDiag diag;
  memset(&diag, 0, sizeof diag);
  int rc = c ? 0 : FMB_EXIT_SOLVER;
  if (!c) snprintf(diag.msg, sizeof diag.msg, "out of memory");
  volatile sig_atomic_t* stop = fmb_cli_catch_stop_signals();
  /* -j J or ranks: every speed's modes at once in child processes, then followed in order below */
  fmbModes** pre = a->jobs > 1 || mpi ? calloc((size_t)nspeed, sizeof *pre) : NULL;
  int pre_done = 0, pre_rc = 0, failed_at = -1;
  fmbDiag pre_diag;
  memset(&pre_diag, 0, sizeof pre_diag);
  if (!pre && !rc && (a->jobs > 1 || mpi)) {
    rc = FMB_EXIT_SOLVER;
    snprintf(diag.msg, sizeof diag.msg, "out of memory");
  }
  if (mpi || (pre && !rc)) /* the other ranks wait for rank 0's word: it goes through the farm whatever */
    pre_rc = fmb_cli_modes_in_children(a->jobs, child, argc + 1, argc + 3, speeds, nspeed, mpi ? &ranks : NULL, stop,
                                       pre, &pre_done, &pre_diag);
  free(child);
  if (!rc)
    rc = follow_modes(c, a, &scene, &opt, speeds, nspeed, pre, pre_done, pre_rc, &pre_diag, stop, &failed_at, &diag);
  for (int i = 0; pre && i < nspeed; ++i) fmb_modes_free(pre[i]);
  free(pre);
  const int code = report(a, c, speeds, nspeed, rc, failed_at, &diag);
  fmb_campbell_free(c);
  fmb_sweep_extension_load(0)->mpi_finalize(rc);
  return code;
}

int fmb_cli_campbell(const fmbCliCampbell* a, int argc, char** argv) {
  double* speeds = malloc(MAX_SPEEDS * sizeof(double));
  const int nspeed = speeds ? parse_speeds(a->speeds_text, speeds) : -1;
  if (nspeed < 1) {
    fprintf(
        stderr,
        "flexmbd campbell: --speeds expects A:B:N (N from 1 to %d) or a list S1,S2,... of finite speeds, got '%s'\n",
        MAX_SPEEDS, a->speeds_text);
    free(speeds);
    return FMB_EXIT_BAD_INPUT;
  }
  const int rc = campbell_at(a, speeds, nspeed, argc, argv);
  free(speeds);
  return rc;
}
