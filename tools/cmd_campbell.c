/* cmd_campbell.c — `flexmbd campbell SCENE --speed PATH --speeds A:B:N|S1,S2,... [--count K] [-j J]
 *                    [--at T] [-o campbell.csv] [--plot campbell.png] [--eigen dense|sparse|auto]
 *                    [--set PATH=VALUE]...`
 * For each hub speed (PATH: the scene key that sets it, e.g. joints.spin.speed): the steady state,
 * then its modes. CSV columns: speed, mode1 ... modeK (rad/s; negative = divergent), the modes
 * followed from speed to speed by shape (greatest modal assurance criterion, MAC), not by order.
 * With -o FILE.csv a PNG is drawn beside it (FILE.png, or --plot) with gnuplot. On a failure the
 * speeds done so far are written, the message names the speed that failed, and the exit code is
 * run's (2 bad input, 3 solver: also a crash). -j J: the speeds in J child processes; under
 * mpirun/srun on every rank too (farm.c: rank 0 hands them out, gathers the modes and alone
 * follows them and writes); each child is this command again with one speed and `--modes-out
 * FILE` (internal: the modes of that speed into FILE, tools/modes_pool.c). The diagram itself is
 * the library's (fmb_campbell, engine/campbell.c); this file parses, writes and plots. */
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

/* gnuplot: one curve per tracked mode; a failure here is a warning, the CSV stands. (Not through
   `flexmbd plot`: its CSV reader takes run outputs, whose first column is t.) */
static void plot(const char* csv, const char* png, int count, const char* title) {
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
    fprintf(g, " using 1:%d with linespoints pt 7 ps 0.5 title 'mode %d'", k + 2, k + 1);
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
      snprintf(names[k + 1], 16, "mode%d", k + 1);
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

int fmb_cmd_campbell(int argc, char** argv) {
  fmbCliScene s;
  memset(&s, 0, sizeof s);
  fmbCliAnalysis an;
  memset(&an, 0, sizeof an);
  an.count = 4;
  an.count_max = FMB_CAMPBELL_MAX_MODES;
  an.opt.quiet = 1;
  const char *out = NULL, *png = NULL, *path = NULL, *speeds_text = NULL;
  int jobs = 1; /* -j J: the speeds' modes computed in J child processes (per rank, tools/modes_pool.c) */
  /* such a child: this command line with one speed and --modes-out FILE (its -j is not used) */
  const char* modes_out = NULL;
  int speeds_at = 0;
  for (int i = 2; i < argc; ++i) {
    const char* a = argv[i];
    int r = fmb_cli_take_scene_arg("campbell", argc, argv, &i, &s);
    if (!r) r = fmb_cli_take_analysis_arg("campbell", argc, argv, &i, &an);
    if (r == 1) continue;
    if (r) return r;
    if (strcmp(a, "-o") == 0 || strcmp(a, "--output") == 0) {
      if (!(out = fmb_cli_value("campbell", argc, argv, &i, "a file name"))) return FMB_EXIT_BAD_INPUT;
    } else if (strcmp(a, "--plot") == 0) {
      if (!(png = fmb_cli_value("campbell", argc, argv, &i, "a PNG file name"))) return FMB_EXIT_BAD_INPUT;
    } else if (strcmp(a, "--speed") == 0) {
      if (!(path = fmb_cli_value("campbell", argc, argv, &i, "the scene key that sets the speed")))
        return FMB_EXIT_BAD_INPUT;
    } else if (strcmp(a, "-j") == 0 || strcmp(a, "--jobs") == 0) {
      const char* v = fmb_cli_value("campbell", argc, argv, &i, "a number of processes");
      char* end;
      jobs = v ? (int)strtol(v, &end, 10) : 0;
      if (!v || *end || jobs < 1 || jobs > 1024) {
        fprintf(stderr, "flexmbd campbell: -j expects 1 to 1024 processes\n");
        return FMB_EXIT_BAD_INPUT;
      }
    } else if (strcmp(a, "--speeds") == 0) {
      if (!(speeds_text = fmb_cli_value("campbell", argc, argv, &i, "A:B:N or S1,S2,..."))) return FMB_EXIT_BAD_INPUT;
      speeds_at = i;
    } else if (strcmp(a, "--modes-out") == 0) { /* internal: a child of -j or of a rank */
      if (!(modes_out = fmb_cli_value("campbell", argc, argv, &i, "a file name"))) return FMB_EXIT_BAD_INPUT;
    } else {
      fprintf(stderr, "flexmbd campbell: unknown option '%s'\n", a);
      return FMB_EXIT_BAD_INPUT;
    }
  }
  const int count = an.count;
  if (!s.scene || !path || !speeds_text) {
    fprintf(stderr,
            "flexmbd campbell: needs SCENE, --speed PATH (e.g. joints.spin.speed) and --speeds A:B:N|S1,S2,...\n");
    return FMB_EXIT_BAD_INPUT;
  }
  /* outputs are never inputs (the scene, plugins: noted; table files: refused when written) */
  if (fmb_cli_check_output_not_input(out, NULL, 0) || fmb_cli_check_output_not_input(png, NULL, 0))
    return FMB_EXIT_BAD_INPUT;
  if (s.nover >= FMB_CLI_MAX_OVERRIDES) {
    fprintf(stderr, "flexmbd campbell: too many --set overrides\n");
    return FMB_EXIT_BAD_INPUT;
  }
  double* speeds = malloc(MAX_SPEEDS * sizeof(double));
  const int nspeed = speeds ? parse_speeds(speeds_text, speeds) : -1;
  if (nspeed < 1) {
    fprintf(
        stderr,
        "flexmbd campbell: --speeds expects A:B:N (N from 1 to %d) or a list S1,S2,... of finite speeds, got '%s'\n",
        MAX_SPEEDS, speeds_text);
    free(speeds);
    return FMB_EXIT_BAD_INPUT;
  }
  const fmbSceneSource scene = {s.scene, s.overrides, s.nover, fmb_cli_registry()};
  const fmbCampbellOptions opt = {path, count, an.method, an.opt};
  if (modes_out) { /* a child of -j or of a rank: the modes at its one speed into the file */
    if (nspeed != 1) {
      fprintf(stderr, "flexmbd campbell: --modes-out goes with one speed\n");
      free(speeds);
      return FMB_EXIT_BAD_INPUT;
    }
    fmbModes* m = NULL;
    fmbDiag d;
    const int mrc = fmb_campbell_modes_at(&scene, &opt, speeds[0], &m, &d);
    const int saved = fmb_cli_modes_save(modes_out, mrc, &d, m);
    if (saved) fprintf(stderr, "flexmbd campbell: cannot write %s\n", modes_out);
    fmb_modes_free(m);
    free(speeds);
    return saved ? FMB_EXIT_SOLVER : 0;
  }
  /* under mpirun/srun: the ranks share the speeds; only rank 0 writes (every rank has parsed the
     same command line: a bad one ended them all above, alike) */
  fmbFarmTransport ranks;
  const int mpi = fmb_farm_mpi_start("campbell", &ranks);
  if (mpi < 0) { /* built without MPI: rank 0 works alone */
    free(speeds);
    return 0;
  }
  /* the children's command line: this one and --modes-out FILE, the speed and the file set per
     child (without it every speed fails to start, with a message: no rank waits) */
  char exe[4096];
  char** child = NULL;
  if (jobs > 1 || mpi) {
    const ssize_t el = readlink("/proc/self/exe", exe, sizeof exe - 1);
    child = el > 0 ? calloc((size_t)argc + 3, sizeof *child) : NULL;
    if (child) {
      exe[el] = '\0';
      child[0] = exe;
      for (int k = 1; k < argc; ++k) child[k] = argv[k];
      child[argc] = "--modes-out";
    }
  }
  if (mpi && ranks.rank != 0) { /* a worker: the speeds rank 0 hands out, their modes to rank 0 */
    fmbDiag wdiag;
    int wdone;
    const int wrc = fmb_cli_modes_in_children(jobs, child, speeds_at, argc + 1, speeds, nspeed, &ranks,
                                              fmb_cli_catch_stop_signals(), NULL, &wdone, &wdiag);
    free(child);
    free(speeds);
    fmb_sweep_extension_load(0)->mpi_finalize(wrc);
    return wrc;
  }
  /* fmb_campbell in its steps: each speed's modes (computable anywhere, e.g. in other processes),
     then followed in order */
  fmbCampbell* c = fmb_campbell_new(speeds, nspeed, count);
  fmbDiag diag;
  memset(&diag, 0, sizeof diag);
  int rc = c ? 0 : FMB_EXIT_SOLVER;
  if (!c) snprintf(diag.msg, sizeof diag.msg, "out of memory");
  volatile sig_atomic_t* stop = fmb_cli_catch_stop_signals();
  /* -j J or ranks: every speed's modes at once in child processes, then followed in order below */
  fmbModes** pre = jobs > 1 || mpi ? calloc((size_t)nspeed, sizeof *pre) : NULL;
  int pre_done = 0, pre_rc = 0;
  fmbDiag pre_diag;
  memset(&pre_diag, 0, sizeof pre_diag);
  if (!pre && !rc && (jobs > 1 || mpi)) {
    rc = FMB_EXIT_SOLVER;
    snprintf(diag.msg, sizeof diag.msg, "out of memory");
  }
  if (mpi || (pre && !rc)) /* the other ranks wait for rank 0's word: it goes through the farm whatever */
    pre_rc = fmb_cli_modes_in_children(jobs, child, speeds_at, argc + 1, speeds, nspeed, mpi ? &ranks : NULL, stop, pre,
                                       &pre_done, &pre_diag);
  free(child);
  int failed_at = -1; /* the speed whose modes failed */
  for (int i = 0; !rc && i < nspeed; ++i) {
    if (*stop && (!pre || i >= pre_done)) { /* SIGINT/SIGTERM: the speeds done so far are written below */
      memset(&diag, 0, sizeof diag);
      diag.code = FMB_EXIT_INTERRUPTED;
      snprintf(diag.msg, sizeof diag.msg,
               "interrupted (SIGINT/SIGTERM) before speed %g: the %d of %d speeds done are kept", speeds[i], c->done,
               nspeed);
      rc = FMB_EXIT_INTERRUPTED;
      break;
    }
    fmbModes* modes = NULL;
    if (!pre) {
      rc = fmb_campbell_modes_at(&scene, &opt, speeds[i], &modes, &diag);
    } else if (i < pre_done) {
      modes = pre[i];
      pre[i] = NULL;
    } else {
      rc = pre_rc;
      diag = pre_diag;
    }
    if (rc) failed_at = i;
    if (!rc && (rc = fmb_campbell_add(c, modes, &diag)) != 0)
      snprintf(diag.file, sizeof diag.file, "%s", s.scene); /* too few modes: the scene's */
  }
  for (int i = 0; pre && i < nspeed; ++i) fmb_modes_free(pre[i]);
  free(pre);
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
  if (rc) fmb_cli_print_diag(&diag);
  /* nothing done (a bad --speed, a scene that does not load): an earlier result stays as it was */
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
    snprintf(title, sizeof title, "Campbell diagram: %s", s.scene);
    plot(out, png, count, title);
  }
  fprintf(stderr, "stats: status=%s speeds=%d of %d modes=%d\n",
          rc == FMB_EXIT_INTERRUPTED ? "interrupted"
          : rc                       ? "failed"
                                     : "ok",
          done, nspeed, count);
  fmb_campbell_free(c);
  free(speeds);
  fmb_sweep_extension_load(0)->mpi_finalize(rc);
  return rc ? rc : wrc;
}
