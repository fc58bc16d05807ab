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

static void usage(FILE* f) {
  fprintf(f,
          "usage: flexmbd refine SCENE.yaml --elements N1,N2,... [--column COL] [--body NAME] [--time-factor F]\n"
          "                      [-o TABLE.csv] [--set PATH=VALUE]... [--plugin x.so]...\n"
          "  a mesh refinement study: the scene once per element count of body NAME (default: beam) at its own\n"
          "  tolerances, and once at rtol/F (F = 100; atol/F too when the scene gives atol) as the time reference.\n"
          "  Per mesh: COL.end (the column at the last row; COL default beam.tip_v), spatial_err (max |difference|\n"
          "  of the time references of this mesh and the next finer one), time_err (max |run - its time reference|),\n"
          "  order (observed, from consecutive spatial_err), cpu_s and steps of the run. The table goes to stdout\n"
          "  and, with -o, to TABLE.csv. Pick rtol so that time_err stays well below spatial_err (docs/refine.md).\n");
}

/* "8,16,32": 2 to MAX_MESHES rising whole numbers; the count, or -1 */
static int parse_elements(const char* text, int* n) {
  int k = 0;
  const char* p = text;
  while (*p) {
    char* end;
    const long v = strtol(p, &end, 10);
    if (end == p || (*end && *end != ',') || v < 1 || v > 1000000 || k == MAX_MESHES || (k && v <= n[k - 1])) return -1;
    n[k++] = (int)v;
    p = *end ? end + 1 : end;
    if (*end && !*p) return -1; /* a trailing comma */
  }
  return k >= 2 ? k : -1;
}

static int parse_factor(const char* text, double* f) {
  char* end;
  *f = strtod(text, &end);
  return end != text && !*end && isfinite(*f) && *f > 1.0 ? 0 : -1;
}

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

int fmb_cmd_refine(int argc, char** argv) {
  fmbCliScene s;
  memset(&s, 0, sizeof s);
  const char *out = NULL, *column = "beam.tip_v", *body = "beam", *elements_text = NULL;
  double factor = 100.0;
  for (int i = 2; i < argc; ++i) {
    const char* a = argv[i];
    if (strcmp(a, "--help") == 0 || strcmp(a, "-h") == 0) {
      usage(stdout);
      return 0;
    }
    const int r = fmb_cli_take_scene_arg("refine", argc, argv, &i, &s);
    if (r == 1) continue;
    if (r) return r;
    const char* v = NULL;
    if (strcmp(a, "-o") == 0 || strcmp(a, "--output") == 0) {
      if (!(out = fmb_cli_value("refine", argc, argv, &i, "a file name"))) return FMB_EXIT_BAD_INPUT;
    } else if (strcmp(a, "--column") == 0) {
      if (!(column = fmb_cli_value("refine", argc, argv, &i, "an output column (beam.tip_v)")))
        return FMB_EXIT_BAD_INPUT;
    } else if (strcmp(a, "--body") == 0) {
      if (!(body = fmb_cli_value("refine", argc, argv, &i, "the name of the body to refine")))
        return FMB_EXIT_BAD_INPUT;
    } else if (strcmp(a, "--elements") == 0) {
      if (!(elements_text = fmb_cli_value("refine", argc, argv, &i, "N1,N2,... element counts")))
        return FMB_EXIT_BAD_INPUT;
    } else if (strcmp(a, "--time-factor") == 0) {
      if (!(v = fmb_cli_value("refine", argc, argv, &i, "a factor above 1"))) return FMB_EXIT_BAD_INPUT;
      if (parse_factor(v, &factor)) {
        fprintf(stderr, "flexmbd refine: --time-factor expects a finite number above 1 (100: rtol/100), got '%s'\n", v);
        return FMB_EXIT_BAD_INPUT;
      }
    } else {
      fprintf(stderr, "flexmbd refine: unknown option '%s' (flexmbd refine --help)\n", a);
      return FMB_EXIT_BAD_INPUT;
    }
  }
  if (!s.scene || !elements_text) {
    fprintf(stderr, "flexmbd refine: needs SCENE and --elements N1,N2,... (flexmbd refine --help)\n");
    return FMB_EXIT_BAD_INPUT;
  }
  int ns[MAX_MESHES];
  const int nmesh = parse_elements(elements_text, ns);
  if (nmesh < 0) {
    fprintf(stderr,
            "flexmbd refine: --elements expects 2 to %d rising whole numbers separated by commas (8,16,32), got '%s'\n",
            MAX_MESHES, elements_text);
    return FMB_EXIT_BAD_INPUT;
  }
  if (s.nover + 3 > FMB_CLI_MAX_OVERRIDES) {
    fprintf(stderr, "flexmbd refine: too many --set overrides\n");
    return FMB_EXIT_BAD_INPUT;
  }
  if (fmb_cli_check_output_not_input(out, NULL, 0)) return FMB_EXIT_BAD_INPUT;
  /* the tolerances of the time reference: rtol / F, and atol / F when the scene (or a --set)
     gives atol. A derived atol follows rtol (engine/scene.c), which is how a given one is told
     apart: loaded with rtol doubled, a given atol stays where it is. */
  char elements_ov[300], rtol_ov[64], atol_ov[64], probe_ov[64];
  fmbSolverInfo info, probe;
  int has_column = 0;
  snprintf(elements_ov, sizeof elements_ov, "bodies.%s.elements=%d", body, ns[0]);
  {
    const int rc = scene_solver(&s, elements_ov, &info, &has_column, column);
    if (rc) return rc;
  }
  if (!has_column) {
    fprintf(stderr,
            "%s: error: the scene has no output column '%s' (give it with --column; `flexmbd check` lists them)\n",
            s.scene, column);
    return FMB_EXIT_BAD_INPUT;
  }
  snprintf(probe_ov, sizeof probe_ov, "solver.rtol=%.17g", 2.0 * info.rtol);
  {
    const int rc = scene_solver(&s, probe_ov, &probe, NULL, NULL);
    if (rc) return rc;
  }
  const int atol_given = probe.atol == info.atol;
  snprintf(rtol_ov, sizeof rtol_ov, "solver.rtol=%.17g", info.rtol / factor);
  snprintf(atol_ov, sizeof atol_ov, "solver.atol=%.17g", info.atol / factor);
  /* a private folder for the runs' CSVs, removed at the end with what was made in it */
  const char* tmp = getenv("TMPDIR");
  char dir[4096];
  snprintf(dir, sizeof dir, "%s/flexmbd-refine-XXXXXX", tmp && *tmp ? tmp : "/tmp");
  if (!mkdtemp(dir)) {
    fprintf(stderr, "flexmbd refine: cannot make a temporary folder %s: %s\n", dir, strerror(errno));
    return FMB_EXIT_SOLVER;
  }
  Mesh* mesh = calloc((size_t)nmesh, sizeof *mesh);
  if (!mesh) {
    rmdir(dir);
    fprintf(stderr, "flexmbd refine: out of memory\n");
    return FMB_EXIT_SOLVER;
  }
  volatile sig_atomic_t* stop = fmb_cli_catch_stop_signals();
  int rc = 0;
  fprintf(stderr, "refine: %s, %d meshes of body %s, rtol %g%s; time reference at rtol %g%s\n", s.scene, nmesh, body,
          info.rtol, atol_given ? " and the scene's atol" : "", info.rtol / factor, atol_given ? " and atol / F" : "");
  for (int k = 0; k < nmesh && !rc; ++k) {
    Mesh* me = &mesh[k];
    me->n = ns[k];
    snprintf(elements_ov, sizeof elements_ov, "bodies.%s.elements=%d", body, me->n);
    snprintf(me->run_csv, sizeof me->run_csv, "%s/n%d.csv", dir, me->n);
    snprintf(me->ref_csv, sizeof me->ref_csv, "%s/n%d_ref.csv", dir, me->n);
    const char* run_extra[1] = {elements_ov};
    const char* ref_extra[3] = {elements_ov, rtol_ov, atol_ov};
    fmbDiag diag;
    char err[512];
    me->code = run_one(&s, run_extra, 1, me->run_csv, &me->st, stop, &diag);
    if (me->code) fprintf(stderr, "refine: %d elements: ", me->n), fmb_cli_print_diag(&diag);
    if (me->code == FMB_EXIT_BAD_INPUT || me->code == FMB_EXIT_INTERRUPTED) {
      rc = me->code;
      break;
    }
    me->ref_code = run_one(&s, ref_extra, atol_given ? 3 : 2, me->ref_csv, &me->ref_st, stop, &diag);
    if (me->ref_code) fprintf(stderr, "refine: %d elements, time reference: ", me->n), fmb_cli_print_diag(&diag);
    if (me->ref_code == FMB_EXIT_BAD_INPUT || me->ref_code == FMB_EXIT_INTERRUPTED) {
      rc = me->ref_code;
      break;
    }
    /* a run that stopped keeps its rows: its differences cover what it reached */
    me->have_run = fmb_table_load(me->run_csv, &me->run, err, sizeof err) == 0;
    me->have_ref = fmb_table_load(me->ref_csv, &me->ref, err, sizeof err) == 0;
    fprintf(stderr, "refine: %d elements: cpu %.3g s (%ld steps), time reference %.3g s\n", me->n, me->st.cpu_s,
            me->st.steps, me->ref_st.cpu_s);
  }
  /* the table: one row per mesh that ran */
  static const char* const names[REFINE_NCOL] = {"elements", NULL,    "spatial_err", "time_err",
                                                 "order",    "cpu_s", "steps",       "ref_cpu_s"};
  char end_name[300];
  snprintf(end_name, sizeof end_name, "%s.end", column);
  const char* cols[REFINE_NCOL];
  memcpy(cols, names, sizeof cols);
  cols[1] = end_name;
  double* rows = calloc((size_t)nmesh * REFINE_NCOL, sizeof(double));
  int nrow = 0, solver_failed = 0;
  double prev_spatial = NAN;
  for (int k = 0; rows && k < nmesh && mesh[k].n; ++k) {
    const Mesh* me = &mesh[k];
    double* r = rows + (size_t)nrow * REFINE_NCOL;
    const int c = me->have_run ? fmb_table_col(&me->run, column) : -1;
    solver_failed |= me->code != 0 || me->ref_code != 0;
    r[0] = me->n;
    r[1] = c >= 1 && me->run.nrow > 0 ? fmb_table_at(&me->run, me->run.nrow - 1, c) : NAN;
    r[2] =
        k + 1 < nmesh && me->have_ref && mesh[k + 1].have_ref ? column_error(&me->ref, &mesh[k + 1].ref, column) : NAN;
    r[3] = me->have_run && me->have_ref ? column_error(&me->run, &me->ref, column) : NAN;
    r[4] = k > 0 ? log(prev_spatial / r[2]) / log((double)me->n / mesh[k - 1].n) : NAN;
    r[5] = me->st.cpu_s;
    r[6] = (double)me->st.steps;
    r[7] = me->ref_st.cpu_s;
    prev_spatial = r[2];
    ++nrow;
  }
  if (rows && nrow > 0) {
    printf("%-9s %-16s %-12s %-12s %-7s %-9s %-8s %s\n", "elements", end_name, "spatial_err", "time_err", "order",
           "cpu_s", "steps", "ref_cpu_s");
    for (int k = 0; k < nrow; ++k) {
      const double* r = rows + (size_t)k * REFINE_NCOL;
      printf("%-9d %-16.10g %-12.3e %-12.3e %-7.2f %-9.4f %-8ld %.4f\n", (int)r[0], r[1], r[2], r[3], r[4], r[5],
             (long)r[6], r[7]);
    }
    /* what the table says: where the time error is not well below the mesh's */
    for (int k = 0; k < nrow; ++k) {
      const double* r = rows + (size_t)k * REFINE_NCOL;
      if (isfinite(r[2]) && isfinite(r[3]) && r[3] > 0.1 * r[2])
        printf("note: at %d elements the time error %.2e is not well below the mesh error %.2e: lower solver.rtol "
               "(--set solver.rtol=...) for this study\n",
               (int)r[0], r[3], r[2]);
    }
    fflush(stdout);
    if (out) {
      fmbDiag diag;
      if (fmb_write_table(out, REFINE_NCOL, cols, nrow, rows, &diag)) {
        fmb_cli_print_diag(&diag);
        if (!rc) rc = FMB_EXIT_BAD_INPUT;
      }
    }
  }
  if (!rows) fprintf(stderr, "flexmbd refine: out of memory\n"), rc = rc ? rc : FMB_EXIT_SOLVER;
  if (!rc && solver_failed) rc = FMB_EXIT_SOLVER;
  for (int k = 0; k < nmesh; ++k) {
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
