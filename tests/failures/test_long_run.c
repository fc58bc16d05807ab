/* test_long_run.c — memory stays flat over long runs. Each scene runs twice through the command
 * line, to a short horizon (~1e4 solver steps) and a ten times longer one (>= 1e5 steps); the
 * child's peak RSS (wait4) may not grow by more than SLACK_KB between the two. A leak or a
 * growing buffer of even 5 bytes per step would add 500 kB over the extra 9e4 steps.
 *
 * Under AddressSanitizer the peak RSS measures ASan's quarantine and fake stacks, not the engine;
 * a sanitized build passes --sanitized and the test is skipped (exit 77), saying so. Leaks there
 * are LeakSanitizer's job.
 *
 *   test_long_run FLEXMBD SCENE_DIR OUT_DIR [--sanitized] */
#include <math.h>
#include <stdio.h>
#include <string.h>
#include <sys/stat.h>

#include "runcli.h"

#define SLACK_KB 512

typedef struct {
  const char* name; /* SCENE_DIR/NAME.yaml */
  double t_short;   /* solver.t_end giving ~1e4 steps; the long run starts at 10x that and is */
} Case;             /* stretched until it takes >= 1e5 steps (solver changes move step counts) */

static const Case cases[] = {
    {"long_run_pendulum", 25.0},
    {"long_run_beam", 0.15},
};

/* one run to t_end; fills steps and peak RSS; 0 ok */
static int run_to(const char* bin, const char* scene, const char* err, double t_end, double* steps, long* rss) {
  char set[64];
  snprintf(set, sizeof set, "solver.t_end=%.6g", t_end);
  char* args[] = {(char*)bin, "run", (char*)scene, "-o", "/dev/null", "--quiet", "--set", set, NULL};
  runcliResult r;
  if (runcli(args, err, &r)) return -1;
  *steps = runcli_stat(&r, "steps");
  *rss = r.maxrss_kb;
  int ok = r.exit_code == 0 && strstr(r.err, "status=ok") != NULL;
  if (!ok) fprintf(stderr, "%s (%s): run failed, exit %d:\n%s", scene, set, r.exit_code, r.err);
  printf("%s t_end=%.6g: %.0f steps, peak RSS %ld kB\n", scene, t_end, *steps, *rss);
  free(r.err);
  return ok ? 0 : -1;
}

int main(int argc, char** argv) {
  if (argc == 5 && strcmp(argv[4], "--sanitized") == 0) {
    printf("SKIP: a sanitized build: peak RSS would measure ASan's quarantine, not the engine\n");
    return 77;
  }
  if (argc != 4) {
    fprintf(stderr, "usage: %s FLEXMBD SCENE_DIR OUT_DIR [--sanitized]\n", argv[0]);
    return 2;
  }
  mkdir(argv[3], 0755);
  int failures = 0;
  for (size_t i = 0; i < sizeof cases / sizeof cases[0]; ++i) {
    const Case* c = &cases[i];
    char scene[1024], err[1024];
    snprintf(scene, sizeof scene, "%s/%s.yaml", argv[2], c->name);
    snprintf(err, sizeof err, "%s/%s.stderr", argv[3], c->name);
    long rss[2] = {0, 0};
    double steps[2] = {0, 0};
    if (run_to(argv[1], scene, err, c->t_short, &steps[0], &rss[0])) ++failures;
    double t_long = 10.0 * c->t_short;
    if (run_to(argv[1], scene, err, t_long, &steps[1], &rss[1])) ++failures;
    for (int tries = 0; tries < 3 && steps[1] > 0 && steps[1] < 1e5; ++tries) {
      t_long *= 1.3e5 / steps[1];
      if (run_to(argv[1], scene, err, t_long, &steps[1], &rss[1])) ++failures;
    }
    if (!(steps[1] >= 1e5 && steps[0] <= 0.2 * steps[1])) {
      fprintf(stderr, "%s: %.0f and %.0f steps: the horizons do not give ~1e4 and >= 1e5 steps\n", c->name, steps[0],
              steps[1]);
      ++failures;
    }
    if (rss[1] - rss[0] > SLACK_KB) {
      fprintf(stderr, "%s: peak RSS grew by %ld kB (from %ld to %ld kB) over %.0f more steps\n", c->name,
              rss[1] - rss[0], rss[0], rss[1], steps[1] - steps[0]);
      ++failures;
    }
  }
  printf("test_long_run: %s\n", failures ? "FAILED" : "ok");
  return failures ? 1 : 0;
}
