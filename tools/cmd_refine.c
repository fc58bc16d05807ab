/* cmd_refine.c — `flexmbd refine SCENE.yaml --elements 8,16,32,64 [--column beam.tip_v]
 * [--body beam] [--time-factor F] [-o TABLE.csv] [--set PATH=VALUE]... [--plugin x.so]...`
 *
 * A mesh refinement study in one command (issue 32, item 5; docs/refine.md). The scene runs once
 * per element count at its own tolerances, and once more at rtol / F (and atol / F when the
 * scene gives atol; F = 100 by default) as that mesh's time reference. Per mesh the table gives
 *   - COL.end: the column's value at the last row (the run at the asked tolerance);
 *   - spatial_err: max over the rows of |reference(n) - reference(next finer n)|, the two time
 *     references compared as `flexmbd compare` does (fmb_table_column_error), so the time error
 *     does not pollute it: the change the next refinement brings, the usual estimate of the
 *     mesh's own error once the differences fall geometrically;
 *   - time_err: max over the rows of |run(n) - reference(n)|, the error of the asked tolerance;
 *   - order: log(spatial_err(prev) / spatial_err(n)) / log(n / prev), the observed order;
 *   - cpu_s, steps: the run at the asked tolerance.
 * The runs are in-process, one after the other (fmb_load, fmb_run); their CSVs go to a private
 * temporary folder that is removed at the end. */
#include <errno.h>
#include <math.h>
#include <stddef.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>
#include <unistd.h>

#include "cli.h"
#include "csv_table.h"

enum { MAX_MESHES = 16, REFINE_NCOL = 8 };

typedef struct Mesh {
  int n;
  fmbStats st, ref_st;
  int code, ref_code;
  fmbTable run, ref;
  int have_run, have_ref;
  char run_csv[4200], ref_csv[4200];
} Mesh;

typedef struct RefineArgs {
  fmbCliScene s; /* first: fmb_opt_scene_positional */
  const char *out, *column, *body;
  int ns[MAX_MESHES], nmesh; /* --elements */
  double factor;             /* --time-factor */
} RefineArgs;

/* --elements "8,16,32": 2 to MAX_MESHES rising whole numbers */
static int read_elements(const fmbOptContext* ctx, void* at, const char* text) {
  RefineArgs* a = ctx->self;
  (void)at;
  int k = 0;
  const char* p = text;
  while (*p && k >= 0) {
    char* end;
    const long v = strtol(p, &end, 10);
    if (end == p || (*end && *end != ',') || v < 1 || v > 1000000 || k == MAX_MESHES || (k && v <= a->ns[k - 1]))
      k = -1;
    else {
      a->ns[k++] = (int)v;
      p = *end ? end + 1 : end;
      if (*end && !*p) k = -1; /* a trailing comma */
    }
  }
  if (k < 2) {
    fprintf(stderr,
            "flexmbd refine: --elements needs 2 to %d rising whole numbers separated by commas (8,16,32), got '%s'\n",
            MAX_MESHES, text);
    return FMB_EXIT_BAD_INPUT;
  }
  a->nmesh = k;
  return 0;
}

static const fmbOpt refine_options[] = {
    {"--elements", NULL, FMB_OPT_CALL, "N1,N2,...", 0, "the element counts of the study, rising (required)",
     "N1,N2,... element counts", 0, 0, NULL, read_elements, 0},
    {"--column", NULL, FMB_OPT_STRING, "COL", offsetof(RefineArgs, column),
     "the output column compared (default beam.tip_v)", "an output column (beam.tip_v)", 0, 0, NULL, NULL, 0},
    {"--body", NULL, FMB_OPT_STRING, "NAME", offsetof(RefineArgs, body), "the body refined (default beam)",
     "the name of the body to refine", 0, 0, NULL, NULL, 0},
    {"--time-factor", NULL, FMB_OPT_DOUBLE, "F", offsetof(RefineArgs, factor),
     "the time reference runs at rtol/F (default 100)", "a finite number above 1 (100: rtol/100)", 1, 1e300, NULL, NULL,
     FMB_OPT_ABOVE_MIN},
    {"--output", "-o", FMB_OPT_STRING, "TABLE.csv", offsetof(RefineArgs, out),
     "the table also as CSV (it always goes to stdout)", "a file name", 0, 0, NULL, NULL, 0},
    FMB_OPT_SCENE_ENTRIES(RefineArgs, s),
};

const fmbCommandSpec fmb_refine_command = {
    "refine",
    "SCENE.yaml",
    "a mesh refinement study: spatial and time error and CPU per mesh",
    refine_options,
    FMB_OPT_COUNT(refine_options),
    fmb_opt_scene_positional,
    "The scene runs once per element count of --body at its own tolerances, and once at rtol/F\n"
    "(atol/F too when the scene gives atol) as that mesh's time reference. Per mesh: COL.end (the\n"
    "column at the last row), spatial_err (max |difference| of the time references of this mesh and\n"
    "the next finer one), time_err (max |run - its time reference|), order (observed, from\n"
    "consecutive spatial_err), cpu_s and steps of the run. Pick rtol so that time_err stays well\n"
    "below spatial_err (docs/refine.md)."};

/* the scene with the user's overrides plus `extra`, run into csv; its exit code */
static int run_one(const fmbCliScene* s, const char* const* extra, int nextra, const char* csv, fmbStats* st,
                   volatile sig_atomic_t* stop, fmbDiag* diag) {
  const char* ov[FMB_CLI_MAX_OVERRIDES];
  int nov = 0;
  for (int k = 0; k < s->nover; ++k) ov[nov++] = s->overrides[k];
  for (int k = 0; k < nextra; ++k) ov[nov++] = extra[k];
  fmbModel* m = fmb_load(s->scene, ov, nov, fmb_cli_registry(), diag);
  if (!m) return diag->code ? diag->code : FMB_EXIT_BAD_INPUT;
  const fmbRunOptions opt = {.csv_path = csv, .quiet = 1, .stop = stop};
  memset(st, 0, sizeof *st);
  const int rc = fmb_run(m, &opt, st, diag);
  fmb_free(m);
  return rc;
}

/* the solver settings of the scene with the overrides plus `extra` (0, or an exit code after saying why) */
static int scene_solver(const fmbCliScene* s, const char* extra, fmbSolverInfo* info, int* has_column,
                        const char* column) {
  const char* ov[FMB_CLI_MAX_OVERRIDES];
  int nov = 0;
  for (int k = 0; k < s->nover; ++k) ov[nov++] = s->overrides[k];
  if (extra) ov[nov++] = extra;
  fmbDiag diag;
  fmbModel* m = fmb_load(s->scene, ov, nov, fmb_cli_registry(), &diag);
  if (!m) {
    fmb_cli_print_diag(&diag);
    return diag.code ? diag.code : FMB_EXIT_BAD_INPUT;
  }
  fmb_model_solver(m, info);
  if (has_column) {
    *has_column = 0;
    for (int i = 0; i < fmb_noutput(m); ++i)
      if (strcmp(fmb_output_name(m, i), column) == 0) *has_column = 1;
  }
  fmb_free(m);
  return 0;
}

static double column_error(const fmbTable* a, const fmbTable* b, const char* column) {
  const int ca = fmb_table_col(a, column), cb = fmb_table_col(b, column);
  if (ca < 1 || cb < 1) return NAN;
  fmbColumnError e;
  fmb_table_column_error(a, ca, b, cb, &e);
  return e.rows > 0 ? e.max_abs : NAN;
}

/* the study's tolerances: the time reference's rtol/F, and atol/F when the scene (or a --set) gives
   atol. A derived atol follows rtol (engine/scene.c), which is how a given one is told apart:
   loaded with rtol doubled, a given atol stays where it is. 0, or an exit code after saying why. */
static int reference_tolerances(const RefineArgs* a, char* rtol_ov, char* atol_ov, size_t len, int* atol_given,
                                double* rtol) {
  char elements_ov[300], probe_ov[64];
  fmbSolverInfo info, probe;
  int has_column = 0;
  snprintf(elements_ov, sizeof elements_ov, "bodies.%s.elements=%d", a->body, a->ns[0]);
  int rc = scene_solver(&a->s, elements_ov, &info, &has_column, a->column);
  if (rc) return rc;
  if (!has_column) {
    fprintf(stderr,
            "%s: error: the scene has no output column '%s' (give it with --column; `flexmbd check` lists them)\n",
            a->s.scene, a->column);
    return FMB_EXIT_BAD_INPUT;
  }
  snprintf(probe_ov, sizeof probe_ov, "solver.rtol=%.17g", 2.0 * info.rtol);
  if ((rc = scene_solver(&a->s, probe_ov, &probe, NULL, NULL))) return rc;
  *atol_given = probe.atol == info.atol;
  *rtol = info.rtol;
  snprintf(rtol_ov, len, "solver.rtol=%.17g", info.rtol / a->factor);
  snprintf(atol_ov, len, "solver.atol=%.17g", info.atol / a->factor);
  return 0;
}

/* each mesh run at the scene's tolerances and at the reference's, into dir; 0, or the exit code
   that stopped the study (bad input, interrupted). A run that stopped keeps its rows: its
   differences cover what it reached. */
static int run_meshes(const RefineArgs* a, Mesh* mesh, const char* dir, const char* rtol_ov, const char* atol_ov,
                      int atol_given) {
  volatile sig_atomic_t* stop = fmb_cli_catch_stop_signals();
  for (int k = 0; k < a->nmesh; ++k) {
    Mesh* me = &mesh[k];
    char elements_ov[300], err[512];
    me->n = a->ns[k];
    snprintf(elements_ov, sizeof elements_ov, "bodies.%s.elements=%d", a->body, me->n);
    snprintf(me->run_csv, sizeof me->run_csv, "%s/n%d.csv", dir, me->n);
    snprintf(me->ref_csv, sizeof me->ref_csv, "%s/n%d_ref.csv", dir, me->n);
    const char* run_extra[1] = {elements_ov};
    const char* ref_extra[3] = {elements_ov, rtol_ov, atol_ov};
    fmbDiag diag;
    me->code = run_one(&a->s, run_extra, 1, me->run_csv, &me->st, stop, &diag);
    if (me->code) fprintf(stderr, "refine: %d elements: ", me->n), fmb_cli_print_diag(&diag);
    if (me->code == FMB_EXIT_BAD_INPUT || me->code == FMB_EXIT_INTERRUPTED) return me->code;
    me->ref_code = run_one(&a->s, ref_extra, atol_given ? 3 : 2, me->ref_csv, &me->ref_st, stop, &diag);
    if (me->ref_code) fprintf(stderr, "refine: %d elements, time reference: ", me->n), fmb_cli_print_diag(&diag);
    if (me->ref_code == FMB_EXIT_BAD_INPUT || me->ref_code == FMB_EXIT_INTERRUPTED) return me->ref_code;
    me->have_run = fmb_table_load(me->run_csv, &me->run, err, sizeof err) == 0;
    me->have_ref = fmb_table_load(me->ref_csv, &me->ref, err, sizeof err) == 0;
    fprintf(stderr, "refine: %d elements: cpu %.3g s (%ld steps), time reference %.3g s\n", me->n, me->st.cpu_s,
            me->st.steps, me->ref_st.cpu_s);
  }
  return 0;
}

/* the table's rows, one per mesh that ran, into rows[nmesh * REFINE_NCOL]; the row count.
   *solver_failed: a run or a reference did not reach t_end */
static int table_rows(const RefineArgs* a, const Mesh* mesh, double* rows, int* solver_failed) {
  int nrow = 0;
  double prev_spatial = NAN;
  *solver_failed = 0;
  for (int k = 0; k < a->nmesh && mesh[k].n; ++k) {
    const Mesh* me = &mesh[k];
    double* r = rows + (size_t)nrow * REFINE_NCOL;
    const int c = me->have_run ? fmb_table_col(&me->run, a->column) : -1;
    *solver_failed |= me->code != 0 || me->ref_code != 0;
    r[0] = me->n;
    r[1] = c >= 1 && me->run.nrow > 0 ? fmb_table_at(&me->run, me->run.nrow - 1, c) : NAN;
    r[2] = k + 1 < a->nmesh && me->have_ref && mesh[k + 1].have_ref
               ? column_error(&me->ref, &mesh[k + 1].ref, a->column)
               : NAN;
    r[3] = me->have_run && me->have_ref ? column_error(&me->run, &me->ref, a->column) : NAN;
    r[4] = k > 0 ? log(prev_spatial / r[2]) / log((double)me->n / mesh[k - 1].n) : NAN;
    r[5] = me->st.cpu_s;
    r[6] = (double)me->st.steps;
    r[7] = me->ref_st.cpu_s;
    prev_spatial = r[2];
    ++nrow;
  }
  return nrow;
}

/* the table on stdout, a note where the time error is not well below the mesh's, and with -o the
   CSV (0, or an exit code after saying why) */
static int write_table(const RefineArgs* a, const double* rows, int nrow) {
  static const char* const names[REFINE_NCOL] = {"elements", NULL,    "spatial_err", "time_err",
                                                 "order",    "cpu_s", "steps",       "ref_cpu_s"};
  char end_name[300];
  snprintf(end_name, sizeof end_name, "%s.end", a->column);
  const char* cols[REFINE_NCOL];
  memcpy(cols, names, sizeof cols);
  cols[1] = end_name;
  printf("%-9s %-16s %-12s %-12s %-7s %-9s %-8s %s\n", "elements", end_name, "spatial_err", "time_err", "order",
         "cpu_s", "steps", "ref_cpu_s");
  for (int k = 0; k < nrow; ++k) {
    const double* r = rows + (size_t)k * REFINE_NCOL;
    printf("%-9d %-16.10g %-12.3e %-12.3e %-7.2f %-9.4f %-8ld %.4f\n", (int)r[0], r[1], r[2], r[3], r[4], r[5],
           (long)r[6], r[7]);
  }
  for (int k = 0; k < nrow; ++k) {
    const double* r = rows + (size_t)k * REFINE_NCOL;
    if (isfinite(r[2]) && isfinite(r[3]) && r[3] > 0.1 * r[2])
      printf("note: at %d elements the time error %.2e is not well below the mesh error %.2e: lower solver.rtol "
             "(--set solver.rtol=...) for this study\n",
             (int)r[0], r[3], r[2]);
  }
  fflush(stdout);
  fmbDiag diag;
  if (a->out && fmb_write_table(a->out, REFINE_NCOL, cols, nrow, rows, &diag)) {
    fmb_cli_print_diag(&diag);
    return FMB_EXIT_BAD_INPUT;
  }
  return 0;
}

int fmb_cmd_refine(int argc, char** argv) {
  RefineArgs a;
  memset(&a, 0, sizeof a);
  a.column = "beam.tip_v";
  a.body = "beam";
  a.factor = 100.0;
  int rc;
  if (fmb_opt_parse(&fmb_refine_command, argc, argv, &a, &rc)) return rc;
  if (!a.s.scene || !a.nmesh) {
    fprintf(stderr, "flexmbd refine: needs SCENE and --elements N1,N2,... (flexmbd refine --help)\n");
    return FMB_EXIT_BAD_INPUT;
  }
  if (a.s.nover + 3 > FMB_CLI_MAX_OVERRIDES) {
    fprintf(stderr, "flexmbd refine: too many --set overrides\n");
    return FMB_EXIT_BAD_INPUT;
  }
  if (fmb_cli_check_output_not_input(a.out, NULL, 0)) return FMB_EXIT_BAD_INPUT;
  char rtol_ov[64], atol_ov[64];
  int atol_given;
  double rtol;
  if ((rc = reference_tolerances(&a, rtol_ov, atol_ov, sizeof rtol_ov, &atol_given, &rtol))) return rc;
  /* a private folder for the runs' CSVs, removed at the end with what was made in it */
  char dir[4096];
  if (fmb_cli_private_folder("refine", dir, sizeof dir)) return FMB_EXIT_SOLVER;
  Mesh* mesh = calloc((size_t)a.nmesh, sizeof *mesh);
  double* rows = calloc((size_t)a.nmesh * REFINE_NCOL, sizeof(double));
  if (!mesh || !rows) {
    fprintf(stderr, "flexmbd refine: out of memory\n");
    rc = FMB_EXIT_SOLVER;
  } else {
    fprintf(stderr, "refine: %s, %d meshes of body %s, rtol %g%s; time reference at rtol %g%s\n", a.s.scene, a.nmesh,
            a.body, rtol, atol_given ? " and the scene's atol" : "", rtol / a.factor,
            atol_given ? " and atol / F" : "");
    rc = run_meshes(&a, mesh, dir, rtol_ov, atol_ov, atol_given);
    int solver_failed;
    const int nrow = table_rows(&a, mesh, rows, &solver_failed);
    const int wrc = nrow > 0 ? write_table(&a, rows, nrow) : 0;
    if (!rc) rc = wrc ? wrc : solver_failed ? FMB_EXIT_SOLVER : 0;
  }
  for (int k = 0; mesh && k < a.nmesh; ++k) {
    if (mesh[k].have_run) fmb_table_free(&mesh[k].run);
    if (mesh[k].have_ref) fmb_table_free(&mesh[k].ref);
    if (mesh[k].run_csv[0]) unlink(mesh[k].run_csv);
    if (mesh[k].ref_csv[0]) unlink(mesh[k].ref_csv);
  }
  rmdir(dir);
  free(rows);
  free(mesh);
  return rc;
}
