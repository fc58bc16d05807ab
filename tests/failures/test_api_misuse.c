/* test_api_misuse.c — the library answers misuse with an error, never a crash (issue 12):
 *   1. every public function of engine/flexmbd.h called with NULL pointers and bad values;
 *   2. (and messages: a long override is shortened, control characters escaped)
 *   1b. the rest of the API (issue 27: seven calls crashed): quadrature, constraints check,
 *      model queries, drawing, statics, modes (a NaN state or time is refused before LAPACK,
 *      whose error handler would end the program with status 0), mode files, tables, the
 *      input registry, each with NULL pointers and out-of-range values;
 *   3. the duplicate-key check is linear: a mapping of 100,000 keys costs fewer than 2 string
 *      comparisons per key (counted, not timed: the old pairwise check made n^2/2 = 5e9), and
 *      a duplicate at its end is still found, at the right line.
 *
 *   test_api_misuse OUT_DIR */
#include <math.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>
#include <sys/stat.h>
#include <unistd.h>

#include "builtin.h"
#include "check.h"
#include "internal.h"

static const char* scene_text =
    "solver: {t_end: 0.01, output_step: 0.005}\n"
    "gravity: [0, -9.81]\n"
    "bodies:\n"
    "  - {name: bob, type: rigid, mass: 1, inertia: 0.1, position: [1, 0]}\n"
    "joints:\n"
    "  - {name: pin, type: revolute, body1: ground, body2: bob, point1: [0, 0], point2: [-1, 0]}\n";

static void write_file(const char* path, const char* text) {
  FILE* f = fopen(path, "w");
  if (!f) {
    perror(path);
    exit(1);
  }
  fputs(text, f);
  fclose(f);
}

/* Five calls that answered edge inputs with a plausible wrong result instead of an error: the
   MAC of modes out of range (0.0, "orthogonal"), a table of -1 rows (an empty table, exit 0), a
   mode animation of amplitude 0, -1 or nan (a still or inverted mode), an unknown eigen-solver
   (the dense one, silently), a time of nan for the linearization; and fmb_eval_col0 of body 2
   (0: body 0's column; see parser_misuse). The writers also left a caller's earlier error in
   *diag (the first error wins) instead of their own. */
static void wrong_results(const fmbModel* m, const char* csv) {
  fmbDiag d = {.code = FMB_EXIT_SOLVER, .msg = "an earlier error"}; /* each call reports its own */
  double shape[2] = {1.0, 0.0}, freq = 1.0, zeta = 0.0;
  fmbModes one = {
      .count = 1, .nq = 1, .frequency = &freq, .damping_ratio = &zeta, .shape_re = shape, .shape_im = shape + 1};
  ENSURE(fmb_modes_mac(&one, 0, &one, 0) == 1.0);
  ENSURE(isnan(fmb_modes_mac(&one, 1, &one, 0)) && isnan(fmb_modes_mac(&one, 0, &one, -1)));
  ENSURE(isnan(fmb_modes_mac(NULL, 0, &one, 0)));
  const char* names[1] = {"a"};
  const double values[1] = {1.0};
  ENSURE(fmb_write_table(csv, 1, names, -1, values, &d) == FMB_EXIT_BAD_INPUT && strstr(d.msg, "negative row count"));
  ENSURE(fmb_write_table(csv, 1, names, 1, values, &d) == 0);
  const int ny = fmb_state_size(m);
  double* y = calloc((size_t)ny, sizeof(double));
  double* yp = calloc((size_t)ny, sizeof(double));
  fmbModes* md = NULL;
  ENSURE(y && yp);
  if (!y || !yp) return;
  ENSURE(fmb_modes(m, 0.0, y, yp, 0, 7, &md, &d) == FMB_EXIT_BAD_INPUT && md == NULL && strstr(d.msg, "method 7"));
  ENSURE(fmb_modes(m, NAN, y, yp, 0, FMB_EIGEN_DENSE, &md, &d) == FMB_EXIT_BAD_INPUT && strstr(d.msg, "not finite"));
  double mshape[3] = {0.0, 0.0, 1.0}, mim[3] = {0.0, 0.0, 0.0};
  fmbModes mode = {
      .count = 1, .nq = m->nq, .frequency = &freq, .damping_ratio = &zeta, .shape_re = mshape, .shape_im = mim};
  ENSURE(m->nq == 3);
  char dir[1100];
  snprintf(dir, sizeof dir, "%s.anim", csv);
  const double bad_amplitude[3] = {0.0, -1.0, NAN};
  for (int k = 0; k < 3 && m->nq == 3; ++k)
    ENSURE(fmb_write_mode_animation(m, 0.0, y, &mode, 0, bad_amplitude[k], 4, dir, &d) == FMB_EXIT_BAD_INPUT);
  free(y);
  free(yp);
}

static void load_and_run_misuse(const char* scene, const char* csv) {
  const fmbRegistry* reg = fmb_builtin_registry();
  fmbDiag d;
  const char* ov[1] = {NULL};

  /* fmb_load: each required argument missing, a broken registry, diag optional */
  ENSURE(fmb_load(NULL, NULL, 0, reg, &d) == NULL && d.code == FMB_EXIT_BAD_INPUT && strstr(d.msg, "no scene path"));
  ENSURE(fmb_load(scene, NULL, 0, NULL, &d) == NULL && d.code == FMB_EXIT_BAD_INPUT && strstr(d.msg, "no registry"));
  ENSURE(fmb_load(scene, NULL, 1, reg, &d) == NULL && d.code == FMB_EXIT_BAD_INPUT);
  ENSURE(fmb_load(scene, ov, 1, reg, &d) == NULL && d.code == FMB_EXIT_BAD_INPUT && strstr(d.msg, "override is NULL"));
  ENSURE(fmb_load(scene, ov, -1, reg, &d) == NULL && d.code == FMB_EXIT_BAD_INPUT);
  ENSURE(fmb_load(NULL, NULL, 0, NULL, NULL) == NULL);
  /* an empty registry (no types): a located error for the unknown type, not a crash */
  fmbRegistry* empty = fmb_registry_new();
  ENSURE(empty != NULL);
  if (empty) {
    ENSURE(fmb_load(scene, NULL, 0, empty, &d) == NULL && d.code == FMB_EXIT_BAD_INPUT && d.line > 0);
    fmb_registry_free(empty);
  }
  /* the registry's own functions, the plugin loader, conformance, frame kinematics */
  ENSURE(fmb_registry_nbodies(NULL) == 0 && fmb_registry_njoints(NULL) == 0);
  ENSURE(fmb_registry_body(NULL, 0) == NULL && fmb_registry_joint(NULL, 0) == NULL);
  ENSURE(fmb_registry_body_origin(NULL, 0) == NULL && fmb_registry_joint_origin(NULL, 0) == NULL);
  ENSURE(fmb_registry_body(reg, -1) == NULL && fmb_registry_joint(reg, 1 << 30) == NULL);
  ENSURE(fmb_registry_add(NULL, fmb_builtin_plugin(), "built-in", &d) != 0 && d.code == FMB_EXIT_BAD_INPUT);
  fmbRegistry* r2 = fmb_registry_new();
  ENSURE(r2 && fmb_registry_add(r2, NULL, NULL, NULL) != 0);
  ENSURE(fmb_registry_load(NULL, "x.so", &d) != 0 && d.code == FMB_EXIT_BAD_INPUT);
  ENSURE(r2 && fmb_registry_load(r2, NULL, NULL) != 0);
  ENSURE(fmb_conform(NULL, "rigid", "/tmp", stdout) == -1 && fmb_conform(r2, NULL, "/tmp", stdout) == -1);
  fmb_registry_free(r2);
  fmb_registry_free(NULL);
  double pos[2] = {7, 7};
  fmb_frame_point(NULL, NULL, NULL, NULL, NULL, NULL);
  fmb_frame_point((const double[3]){1, 2, 0}, (const double[2]){0.5, 0}, pos, NULL, NULL, NULL);
  ENSURE(pos[0] == 1.5 && pos[1] == 2.0);
  ENSURE(fmb_model_solver(NULL, NULL) == -1);
  /* the safe-file writer: NULL handles answer neutrally; a folder as the target is refused with why */
  char why[200] = "";
  ENSURE(fmb_safe_open(NULL, why, sizeof why) == NULL && why[0]);
  ENSURE(fmb_safe_open("/tmp", why, sizeof why) == NULL && strstr(why, "directory"));
  ENSURE(fmb_safe_stream(NULL) == NULL && fmb_safe_fd(NULL) == -1 && fmb_safe_write_path(NULL) == NULL);
  ENSURE(!fmb_safe_is_temporary(NULL) && fmb_safe_close(NULL, 1) == 0);

  /* fmb_run: no model; stats and diag optional */
  fmbStats st;
  ENSURE(fmb_run(NULL, NULL, NULL, NULL) == FMB_EXIT_BAD_INPUT);
  ENSURE(fmb_run(NULL, NULL, &st, &d) == FMB_EXIT_BAD_INPUT && d.code == FMB_EXIT_BAD_INPUT && !st.status_ok);
  fmbModel* m = fmb_load(scene, NULL, 0, reg, NULL);
  ENSURE(m != NULL);
  if (m) {
    fmbRunOptions opt = {.csv_path = csv, .quiet = 1};
    ENSURE(fmb_run(m, &opt, NULL, NULL) == 0);
    /* a directory as the output: an error, not a crash, and the model still runs after it */
    opt.csv_path = "/";
    ENSURE(fmb_run(m, &opt, &st, &d) == FMB_EXIT_BAD_INPUT && d.code == FMB_EXIT_BAD_INPUT);
    opt.csv_path = csv;
    ENSURE(fmb_run(m, &opt, &st, &d) == 0 && st.status_ok && st.rows_written == 3);
    /* a stop flag already set: interrupted before the first row, nothing written */
    volatile sig_atomic_t stop = 1;
    opt.stop = &stop;
    ENSURE(fmb_run(m, &opt, &st, &d) == FMB_EXIT_INTERRUPTED && st.interrupted && st.rows_written == 0);
    fmb_describe(m, NULL);
    wrong_results(m, csv);
  }
  fmb_describe(NULL, stdout);
  fmb_print_stats(NULL, stdout);
  fmb_print_stats(&st, NULL);
  fmb_free(NULL);
  fmb_free(m);
}

/* every other public call with NULL pointers and out-of-range values: an error, never a crash */
static void analysis_misuse(const char* scene, const char* dir) {
  fmbDiag d;
  double x[FMB_GAUSS_MAX + 1], w[FMB_GAUSS_MAX + 1];
  ENSURE(fmb_gauss_legendre01(3, NULL, NULL) == -1 && fmb_gauss_legendre01(0, x, w) == -1 &&
         fmb_gauss_legendre01(FMB_GAUSS_MAX + 1, x, w) == -1);
  ENSURE(fmb_gauss_lobatto01(3, NULL, NULL) == -1 && fmb_gauss_lobatto01(1, x, w) == -1 &&
         fmb_gauss_lobatto01(FMB_GAUSS_MAX + 1, x, w) == -1);
  ENSURE(fmb_gauss_lobatto01(3, x, w) == 0 && fabs(w[0] + w[1] + w[2] - 1.0) < 1e-15); /* still works */
  ENSURE(fmb_eval_col0(NULL, 0) == -1 && fmb_eval_col0(NULL, 7) == -1);                /* no context: no column */
  ENSURE(fmb_model_nbody(NULL) == 0 && fmb_model_body(NULL, 0, NULL, NULL) == -1);
  ENSURE(fmb_model_njoint(NULL) == 0 && fmb_model_joint(NULL, 0, NULL, NULL) == -1);
  ENSURE(fmb_state_size(NULL) == 0 && fmb_drawing_new(NULL) == NULL);
  fmb_drawing_free(NULL);
  ENSURE(fmb_check_constraints(NULL, stdout, &d) == FMB_EXIT_BAD_INPUT && d.code == FMB_EXIT_BAD_INPUT);
  ENSURE(isnan(fmb_modes_mac(NULL, 0, NULL, 0)));
  fmb_modes_free(NULL);
  const char* names[2] = {"a", NULL};
  const double values[4] = {1, 2, 3, 4};
  char path[1200];
  snprintf(path, sizeof path, "%s/table.csv", dir);
  memset(&d, 0, sizeof d); /* the first error a diag holds wins: start afresh for this message */
  ENSURE(fmb_write_table(path, 2, names, 2, values, &d) == FMB_EXIT_BAD_INPUT && strstr(d.msg, "NULL name"));
  ENSURE(fmb_write_table(path, 2, NULL, 2, values, NULL) == FMB_EXIT_BAD_INPUT);
  ENSURE(fmb_write_table(path, 1, names, -2, values, &d) == FMB_EXIT_BAD_INPUT);
  ENSURE(fmb_write_table(NULL, 0, NULL, 0, NULL, NULL) == FMB_EXIT_BAD_INPUT);
  /* names the header cannot hold (no quoting: issue 36): refused, nothing written, and a good
     table is read back by the program's reader column for column */
  {
    const char* bad[][2] = {{"t", "a,b"}, {"t", "two\nlines"}, {"t", "cr\r"}, {"t", "quote\"d"},
                            {"t", ""},    {"t", " padded"},    {"#t", "a"},   {"t", "tab\there"}};
    for (size_t k = 0; k < sizeof bad / sizeof bad[0]; ++k) {
      remove(path);
      memset(&d, 0, sizeof d);
      ENSURE(fmb_write_table(path, 2, bad[k], 2, values, &d) == FMB_EXIT_BAD_INPUT &&
             strstr(d.msg, "a CSV name may not"));
      ENSURE(access(path, F_OK) != 0);
    }
    const char* good[2] = {"t", "bob.x@complete"};
    ENSURE(fmb_write_table(path, 2, good, 2, values, &d) == 0);
    FILE* f = fopen(path, "r");
    char line[256] = "";
    ENSURE(f && fgets(line, sizeof line, f) && strcmp(line, "t,bob.x@complete\n") == 0);
    if (f) fclose(f);
  }
  ENSURE(fmb_inputs_note(NULL, path) == -1 && fmb_inputs_at(NULL, path, NULL, 0) == 0);
  ENSURE(fmb_inputs_add(NULL, NULL) == -1 && fmb_inputs_count(NULL) == 0 && fmb_model_inputs(NULL) == NULL);
  fmb_inputs_forget(NULL, path);
  fmb_inputs_free(NULL);
  {
    fmbInputs* in = fmb_inputs_new();
    ENSURE(in && fmb_inputs_note(in, NULL) == -1 && fmb_inputs_note(in, "-") == -1 && fmb_inputs_note(in, dir) == -1);
    ENSURE(fmb_inputs_at(in, NULL, NULL, 0) == 0);
    fmb_inputs_forget(in, NULL);
    fmb_inputs_free(in);
  }

  /* the pendulum turned 0.5 rad down from horizontal (horizontal is a dead point for statics) */
  const char* turned[] = {"bodies.bob.position=[0.8775825618903728, -0.479425538604203]", "bodies.bob.angle=-0.5"};
  fmbModel* m = fmb_load(scene, turned, 2, fmb_builtin_registry(), &d);
  ENSURE(m != NULL);
  if (!m) return;
  ENSURE(fmb_check_constraints(m, NULL, &d) == FMB_EXIT_BAD_INPUT);
  ENSURE(fmb_check_constraints(m, stdout, NULL) == 0); /* diag optional */
  ENSURE(fmb_model_body(m, -1, NULL, NULL) == -1 && fmb_model_body(m, 1, NULL, NULL) == -1);
  ENSURE(fmb_model_joint(m, -1, NULL, NULL) == -1 && fmb_model_joint(m, 1, NULL, NULL) == -1);
  const char* name = NULL;
  ENSURE(fmb_model_joint(m, 0, &name, NULL) == 0 && name && strcmp(name, "pin") == 0);
  const int n = fmb_state_size(m);
  double* y = calloc((size_t)n, sizeof(double));
  double* yp = calloc((size_t)n, sizeof(double));
  fmbStaticResult res;
  fmbModes* md = NULL;
  ENSURE(fmb_static(NULL, NULL, y, yp, &res, &d) == FMB_EXIT_BAD_INPUT);
  ENSURE(fmb_static(m, NULL, NULL, NULL, &res, &d) == FMB_EXIT_BAD_INPUT);
  const fmbStaticOptions nan_t = {.t = NAN, .has_t = 1};
  ENSURE(fmb_static(m, &nan_t, y, yp, &res, &d) == FMB_EXIT_BAD_INPUT && strstr(d.msg, "not finite"));
  ENSURE(fmb_static(m, NULL, y, yp, &res, NULL) == 0); /* the pendulum hangs down */
  ENSURE(fmb_modes(m, 0.0, y, yp, 2, 77, &md, &d) == FMB_EXIT_BAD_INPUT && md == NULL);
  ENSURE(fmb_modes(m, NAN, y, yp, 2, FMB_EIGEN_DENSE, &md, &d) == FMB_EXIT_BAD_INPUT && strstr(d.msg, "not finite"));
  const double keep = y[0];
  y[0] = NAN;
  ENSURE(fmb_modes(m, 0.0, y, yp, 2, FMB_EIGEN_DENSE, &md, &d) == FMB_EXIT_BAD_INPUT && strstr(d.msg, "not finite"));
  y[0] = keep;
  ENSURE(fmb_modes(m, 0.0, y, yp, 1, FMB_EIGEN_DENSE, NULL, &d) == FMB_EXIT_BAD_INPUT);
  ENSURE(fmb_modes(m, 0.0, y, yp, 1, FMB_EIGEN_DENSE, &md, NULL) == 0 && md && md->count == 1);
  if (md) { /* a pendulum of 1 m from its centre, I = 0.1: w^2 = m g l / (I + m l^2) */
    ENSURE_REL(md->frequency[0], sqrt(9.81 / 1.1), 1e-6);
    snprintf(path, sizeof path, "%s/anim", dir);
    ENSURE(fmb_write_mode_animation(m, 0.0, y, md, 0, NAN, 8, path, &d) == FMB_EXIT_BAD_INPUT);
    ENSURE(fmb_write_mode_animation(m, 0.0, y, md, 0, 0.1, 1 << 30, path, &d) == FMB_EXIT_BAD_INPUT);
    ENSURE(fmb_write_mode_animation(m, 0.0, y, md, 5, 0.1, 8, path, &d) == FMB_EXIT_BAD_INPUT);
    const fmbModes lying = {.count = 2, .nq = md->nq}; /* no shapes behind its count */
    snprintf(path, sizeof path, "%s/shapes.csv", dir);
    ENSURE(fmb_write_mode_shapes(m, 0.0, y, yp, &lying, path, &d) == FMB_EXIT_BAD_INPUT);
    ENSURE(fmb_write_mode_animation(m, 0.0, y, &lying, 0, 0.1, 8, path, &d) == FMB_EXIT_BAD_INPUT);
  }
  ENSURE(fmb_write_state_row(m, path, 0.0, NULL, NULL, &d) == FMB_EXIT_BAD_INPUT);
  /* the scene is an input from its load on: no writer replaces it */
  memset(&d, 0, sizeof d);
  ENSURE(fmb_write_state_row(m, scene, 0.0, y, yp, &d) == FMB_EXIT_BAD_INPUT && strstr(d.msg, "refusing to overwrite"));
  fmb_modes_free(md);
  free(y);
  free(yp);
  fmb_free(m);
}

/* a long override is shortened in the message, which still ends with the reason; control
   characters are escaped so the message stays on one line */
static void long_override(const char* scene) {
  char ov[400] = "solver.rtol=[";
  for (int i = 0; i < 150; ++i) strcat(ov, "1,");
  strcat(ov, "1]");
  const char* list[] = {ov};
  fmbDiag d;
  ENSURE(fmb_load(scene, list, 1, fmb_builtin_registry(), &d) == NULL);
  printf("long override: %s: %s\n", d.file, d.msg);
  ENSURE(strlen(d.msg) < 200);
  ENSURE(strstr(d.msg, "...(315 characters): expected a number for 'rtol', found a list") != NULL);
  const char* two[] = {"solver.rtol=1e-8\n---\n2"};
  ENSURE(fmb_load(scene, two, 1, fmb_builtin_registry(), &d) == NULL);
  ENSURE(strchr(d.msg, '\n') == NULL && strstr(d.msg, "solver.rtol=1e-8\\n---\\n2: expected one YAML value") != NULL);
}

static void parser_misuse(const char* scene) {
  fmbParser p;
  memset(&p, 0, sizeof p);
  fmbDiag d;
  memset(&d, 0, sizeof d);
  ENSURE(fmbp_open(&p, scene, NULL, 0, &d) == 0);
  fmbNode root = fmbp_root(&p);
  double x = 0, v[2];
  int i = 0, body = 0;
  const char* const words[] = {"a", NULL};
  /* no parser, no key, no output */
  ENSURE(fmb_get_double(NULL, root, "gravity", 0, &x) == -1);
  ENSURE(fmb_get_double(&p, root, NULL, 0, &x) == -1);
  ENSURE(fmb_get_double(&p, root, "gravity", 0, NULL) == -1);
  ENSURE(fmb_get_int(NULL, root, "k", 0, 0, 1, &i) == -1);
  ENSURE(fmb_get_int(&p, root, "k", 0, 0, 1, NULL) == -1);
  ENSURE(fmb_get_vec2(NULL, root, "gravity", 0, v) == -1);
  ENSURE(fmb_get_angle(NULL, root, "angle", FMB_REQUIRED, &x) == -1);
  ENSURE(fmb_get_angle(&p, root, "angle", 0, NULL) == -1);
  ENSURE(fmb_get_point(NULL, root, "point", 0, 0, v) == -1);
  ENSURE(fmb_get_point(&p, root, "point", 0, 0, NULL) == -1);
  ENSURE(fmb_initial_marker(NULL, 0, v, v, NULL) == -1);
  ENSURE(fmb_initial_marker(&p, 0, NULL, v, NULL) == -1);
  ENSURE(fmb_get_vec2(&p, root, "gravity", 0, NULL) == -1);
  ENSURE(fmb_get_choice(NULL, root, "k", 0, words, &i) == -1);
  ENSURE(fmb_get_choice(&p, root, "k", 0, NULL, &i) == -1);
  ENSURE(fmb_get_choice(&p, root, "k", 0, words, NULL) == -1);
  ENSURE(fmb_get_body(NULL, root, "body1", 0, &i) == -1);
  ENSURE(fmb_get_body(&p, root, "body1", 0, NULL) == -1);
  ENSURE(fmb_get_joint(NULL, root, "joint", 0, &i) == -1);
  ENSURE(fmb_get_joint(&p, root, "joint", 0, NULL) == -1);
  ENSURE(fmb_joint_attachment(NULL, 0, 0, &body, v) == -1);
  ENSURE(fmb_joint_attachment(&p, 0, 0, NULL, v) == -1);
  ENSURE(fmb_joint_attachment(&p, 0, 2, &body, v) == -1);
  ENSURE(fmb_find_key(NULL, root, "solver") == -1);
  ENSURE(fmb_find_key(&p, root, NULL) == -1);
  ENSURE(fmb_parse_error(NULL, root, "x") == -1);
  ENSURE(fmb_parse_error(&p, root, NULL) == -1);
  /* and a valid call still works (the parser was not damaged) */
  ENSURE(fmb_get_vec2(&p, root, "gravity", 0, v) == 0 && v[1] == -9.81);
  ENSURE(d.code == 0);
  fmbp_close(&p);

  /* the evaluation context a joint sees */
  ENSURE(isnan(fmb_eval_time(NULL)));
  ENSURE(fmb_eval_ncoord(NULL, 0) == 0);
  ENSURE(fmb_eval_q(NULL, 0) == NULL && fmb_eval_v(NULL, 1) == NULL);
  ENSURE(fmb_eval_scratch(NULL) == NULL);
  ENSURE(fmb_eval_col0(NULL, 1) == -1 && fmb_eval_col0(NULL, 0) == -1); /* not 0: body 0's column */
  double pos[2], ang;
  ENSURE(fmb_marker(NULL, 0, v, pos, &ang, NULL, 0, NULL) == -1);

  /* the quadrature: bad n, NULL arrays; a good rule integrates x^5 exactly (1/6) */
  double xg[FMB_GAUSS_MAX], wg[FMB_GAUSS_MAX];
  ENSURE(fmb_gauss_legendre01(0, xg, wg) == -1);
  ENSURE(fmb_gauss_legendre01(FMB_GAUSS_MAX + 1, xg, wg) == -1);
  ENSURE(fmb_gauss_legendre01(3, NULL, wg) == -1);
  ENSURE(fmb_gauss_legendre01(3, xg, NULL) == -1);
  ENSURE(fmb_gauss_legendre01(3, xg, wg) == 0);
  double s = 0;
  for (int k = 0; k < 3; ++k) s += wg[k] * pow(xg[k], 5);
  ENSURE_NEAR(s, 1.0 / 6.0, 1e-15);
}

/* a top-level mapping `many:` of n keys k0 .. k(n-1), plus optionally k0 again at the end */
static void write_many_keys(const char* path, int n, int duplicate_last) {
  FILE* f = fopen(path, "w");
  if (!f) {
    perror(path);
    exit(1);
  }
  fputs(scene_text, f);
  fputs("many:\n", f);
  for (int k = 0; k < n; ++k) fprintf(f, "  k%d: %d\n", k, k);
  if (duplicate_last) fputs("  k0: 0\n", f);
  fclose(f);
}

static void many_keys(const char* dir) {
  const int n = 100000;
  char path[1024];
  snprintf(path, sizeof path, "%s/many_keys.yaml", dir);
  write_many_keys(path, n, 0);
  fmbParser p;
  memset(&p, 0, sizeof p);
  fmbDiag d;
  memset(&d, 0, sizeof d);
  ENSURE(fmbp_open(&p, path, NULL, 0, &d) == 0);
  printf("100000 distinct keys: %ld string comparisons\n", p.key_compares);
  ENSURE(p.key_compares < 2L * n);
  fmbp_close(&p);
  /* the whole load: refused for the unknown key, after a linear check */
  fmbModel* m = fmb_load(path, NULL, 0, fmb_builtin_registry(), &d);
  ENSURE(m == NULL && d.code == FMB_EXIT_BAD_INPUT && strstr(d.msg, "unknown key 'many'"));

  write_many_keys(path, n, 1);
  memset(&p, 0, sizeof p);
  memset(&d, 0, sizeof d);
  ENSURE(fmbp_open(&p, path, NULL, 0, &d) != 0);
  printf("duplicate after 100000 keys: %ld string comparisons; %s:%d:%d: %s\n", p.key_compares, d.file, d.line, d.col,
         d.msg);
  ENSURE(p.key_compares < 2L * n);
  /* the scene's 6 lines, "many:", then k0 .. k99999: the duplicate is on line 6 + 1 + n + 1 */
  ENSURE(d.line == 6 + 1 + n + 1 && d.col == 3);
  ENSURE(strstr(d.msg, "duplicate key 'k0' (first given at line 8)") != NULL);
  fmbp_close(&p);
}

int main(int argc, char** argv) {
  if (argc != 2) {
    fprintf(stderr, "usage: %s OUT_DIR\n", argv[0]);
    return 2;
  }
  mkdir(argv[1], 0755);
  char scene[1024], csv[1024];
  snprintf(scene, sizeof scene, "%s/pendulum.yaml", argv[1]);
  snprintf(csv, sizeof csv, "%s/pendulum.csv", argv[1]);
  write_file(scene, scene_text);
  load_and_run_misuse(scene, csv);
  analysis_misuse(scene, argv[1]);
  parser_misuse(scene);
  long_override(scene);
  many_keys(argv[1]);
  return fmbt_finish("api_misuse");
}
