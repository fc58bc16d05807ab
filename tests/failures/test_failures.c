/* test_failures.c — scenes built to make the solver fail (the .yaml files here), run through the
 * command line. For each: exit code 3; one error line naming the scene, the time reached (equal
 * to the stats line's t_reached), the cause and what to try; a stats line with status=failed;
 * the stop inside the expected window; and a CSV that holds every output row up to the stop —
 * a header, rows of exactly as many finite numbers, t = k * output_step, nothing cut off.
 *
 *   test_failures FLEXMBD SCENE_DIR OUT_DIR CASE      (one ctest test per case) */
#include <math.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>
#include <sys/stat.h>

#include "runcli.h"

typedef struct {
  const char* name;   /* SCENE_DIR/NAME.yaml */
  double dt;          /* the scene's output step */
  double t_lo, t_hi;  /* the run must stop in [t_lo, t_hi] */
  const char* cause;  /* in the message */
  const char* advice; /* in the message: what to try (NULL: the engine gives none) */
  const char* wrong;  /* must not be in the message: a cause this scene cannot have (NULL: none) */
} Case;

static const Case cases[] = {
    /* the toggle of the non-Grashof four-bar is at crank angle acos(-1/64) = 1.58642 rad */
    {"singular_fourbar", 0.01, 1.5855, 1.5874, "Newton's method failed repeatedly", "singular configuration", NULL},
    /* spun to 100 rad/s in 0.5 s: ZOAC's softening (omega^2 = omega1^2 - Omega^2) makes the bending
       mode grow exponentially once Omega passes omega1 = 3.9 rad/s; the beam's validity check stops
       it when a deflection exceeds the length */
    {"zoac_overspin", 0.01, 0.05, 2.0, "its deformation exceeds its length", "use model: foac or complete", NULL},
    /* the same four-bar with a step floor of 1e-6 s: stops at the floor, which the message names */
    {"min_step_floor", 0.01, 1.585, 1.5874, "the error test failed repeatedly",
     "the step reached solver.min_step = 1e-06 (as given)", NULL},
    {"too_much_work", 2.0, 0.0, 2.0, "too many steps between two outputs", "Try a larger solver.max_steps", NULL},
    {"foac_pendulum", 0.005, 0.02, 0.5, "the mass matrix is no longer positive definite", "use `model: complete`",
     NULL},
    /* a free body: no joints, so no dead point or singular configuration may be named */
    {"overflow_force", 1000.0, 0.0, 0.0, "the equations kept returning non-finite values",
     "Check parameters and initial values", "singular configuration"},
    {"infinite_energy", 0.001, 0.0, 0.0, "is not finite (the solution blew up)",
     "check the initial values and parameters", NULL},
    /* a coupler of 1e200 kg: the parameters' scale is to blame, not the mechanism's geometry */
    {"huge_mass", 0.01, 0.0, 0.0, "a parameter is far beyond a physical scale", "check masses, stiffnesses, forces",
     "singular configuration"},
};

static int failures = 0;
#define CHECK(cond, ...)                              \
  do {                                                \
    if (!(cond)) {                                    \
      fprintf(stderr, "%s:%d: ", __FILE__, __LINE__); \
      fprintf(stderr, __VA_ARGS__);                   \
      fprintf(stderr, "\n");                          \
      ++failures;                                     \
    }                                                 \
  } while (0)

static char* read_all(const char* path, long* len) {
  FILE* f = fopen(path, "rb");
  if (!f) return NULL;
  fseek(f, 0, SEEK_END);
  *len = ftell(f);
  rewind(f);
  char* s = calloc((size_t)*len + 1, 1);
  if (s && *len > 0 && fread(s, 1, (size_t)*len, f) != (size_t)*len) *len = 0;
  fclose(f);
  return s;
}

/* the CSV is complete and parseable; returns the number of data rows, last t in *t_last */
static long check_csv(const char* path, const Case* c, double t_reached, double* t_last) {
  long len = 0;
  char* s = read_all(path, &len);
  CHECK(s != NULL, "%s: no CSV written", path);
  if (!s) return -1;
  CHECK(len > 0 && s[len - 1] == '\n', "%s: empty or the last line is cut off", path);
  char* line = s;
  char* nl = strchr(line, '\n');
  CHECK(nl != NULL && strncmp(line, "t,", 2) == 0, "%s: no header starting with 't,'", path);
  if (!nl) {
    free(s);
    return -1;
  }
  int ncol = 1;
  for (char* p = line; p < nl; ++p) ncol += *p == ',';
  long rows = 0;
  *t_last = -1.0;
  for (line = nl + 1; *line; line = nl + 1) {
    nl = strchr(line, '\n');
    if (!nl) break; /* already reported: cut off */
    int col = 0;
    char* p = line;
    double t = 0.0;
    while (p < nl) {
      char* end = NULL;
      double v = strtod(p, &end);
      CHECK(end != p && (*end == ',' || *end == '\n'), "%s: row %ld, column %d is not a number", path, rows + 1,
            col + 1);
      CHECK(isfinite(v), "%s: row %ld, column %d is not finite", path, rows + 1, col + 1);
      if (end == p) break;
      if (col == 0) t = v;
      ++col;
      p = end + (*end == ',');
    }
    CHECK(col == ncol, "%s: row %ld has %d fields, the header %d", path, rows + 1, col, ncol);
    CHECK(fabs(t - (double)rows * c->dt) <= 1e-9 * fmax(1.0, t), "%s: row %ld at t = %.17g, expected %.17g", path,
          rows + 1, t, (double)rows * c->dt);
    *t_last = t;
    ++rows;
  }
  /* every output time passed was written; the row at a time where the run is stopped by a check
     (mass definiteness, a non-finite output) is not */
  long n = (long)floor(t_reached / c->dt + 1e-9) + 1;
  int at_output = fabs(t_reached - round(t_reached / c->dt) * c->dt) <= 1e-9 * fmax(1.0, t_reached);
  CHECK(rows == n || (at_output && rows == n - 1), "%s: %ld rows, expected %ld for t_reached = %.10g", path, rows, n,
        t_reached);
  CHECK(*t_last <= t_reached + 1e-12, "%s: a row at t = %g after t_reached = %g", path, *t_last, t_reached);
  free(s);
  return rows;
}

int main(int argc, char** argv) {
  if (argc != 5) {
    fprintf(stderr, "usage: %s FLEXMBD SCENE_DIR OUT_DIR CASE\n", argv[0]);
    return 2;
  }
  const Case* c = NULL;
  for (size_t i = 0; i < sizeof cases / sizeof cases[0]; ++i)
    if (strcmp(cases[i].name, argv[4]) == 0) c = &cases[i];
  if (!c) {
    fprintf(stderr, "no case named '%s'\n", argv[4]);
    return 2;
  }
  mkdir(argv[3], 0755);
  char scene[1024], csv[1024], err[1024];
  snprintf(scene, sizeof scene, "%s/%s.yaml", argv[2], c->name);
  snprintf(csv, sizeof csv, "%s/%s.csv", argv[3], c->name);
  snprintf(err, sizeof err, "%s/%s.stderr", argv[3], c->name);
  remove(csv);
  char* args[] = {argv[1], "run", scene, "-o", csv, NULL};
  runcliResult r;
  if (runcli(args, err, &r)) return 1;
  fprintf(stderr, "%s", r.err);

  CHECK(r.signal == 0, "killed by signal %d", r.signal);
  CHECK(r.exit_code == 3, "exit code %d, expected 3", r.exit_code);
  /* exactly one error line, naming the scene */
  int nerr = 0;
  const char* msg = NULL;
  for (const char* s = r.err; (s = strstr(s, "error: ")) != NULL; s += 7, ++nerr)
    if (!msg) msg = s + 7;
  CHECK(nerr == 1, "%d error lines, expected one", nerr);
  char prefix[1100];
  snprintf(prefix, sizeof prefix, "\n%s: error: ", scene);
  CHECK(strstr(r.err, prefix) != NULL || strncmp(r.err, prefix + 1, strlen(prefix + 1)) == 0, "no line starting '%s'",
        prefix + 1);
  double t_reached = runcli_stat(&r, "t_reached");
  CHECK(strstr(r.err, "stats: status=failed ") != NULL, "no stats line with status=failed");
  /* a backend that took steps before it stopped is named on the stats line (it once said none) */
  CHECK(runcli_stat(&r, "steps") <= 0 || strstr(r.err, " integrator=none ") == NULL,
        "the stats line names no integrator although %g steps were taken", runcli_stat(&r, "steps"));
  CHECK(t_reached >= c->t_lo && t_reached <= c->t_hi, "stopped at t = %.10g, expected within [%g, %g]", t_reached,
        c->t_lo, c->t_hi);
  if (msg) {
    const char* eol = strchr(msg, '\n');
    const char* tq = strstr(msg, "t = ");
    CHECK(tq && (!eol || tq < eol), "the message does not say the time reached");
    if (tq) {
      double tm = strtod(tq + 4, NULL);
      CHECK(fabs(tm - t_reached) <= 1e-5 * fmax(1.0, fabs(t_reached)), "message says t = %g, stats t_reached = %g", tm,
            t_reached);
    }
    CHECK(strstr(msg, c->cause) != NULL, "the message lacks the cause '%s'", c->cause);
    if (c->advice) CHECK(strstr(msg, c->advice) != NULL, "the message lacks the advice '%s'", c->advice);
    if (c->wrong)
      CHECK(strstr(msg, c->wrong) == NULL, "the message names '%s', which this scene cannot have", c->wrong);
  }
  double t_last = -1.0;
  long rows = check_csv(csv, c, t_reached, &t_last);
  printf("%s: exit %d, stopped at t = %.10g, %ld complete rows (last t = %g)\n", c->name, r.exit_code, t_reached, rows,
         t_last);
  free(r.err);
  printf("%s: %s\n", c->name, failures ? "FAILED" : "ok");
  return failures ? 1 : 0;
}
