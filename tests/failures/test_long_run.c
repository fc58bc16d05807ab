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
  const char* name;         /* SCENE_DIR/NAME.yaml */
  const char* t_short;      /* solver.t_end values */
  const char* t_long;
} Case;

static const Case cases[] = {
    {"long_run_pendulum", "25", "250"},
    {"long_run_beam", "0.15", "1.5"},
};

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
    for (int k = 0; k < 2; ++k) {
      char set[64];
      snprintf(set, sizeof set, "solver.t_end=%s", k ? c->t_long : c->t_short);
      char* args[] = {argv[1], "run", scene, "-o", "/dev/null", "--quiet", "--set", set, NULL};
      runcliResult r;
      if (runcli(args, err, &r)) return 1;
      steps[k] = runcli_stat(&r, "steps");
      rss[k] = r.maxrss_kb;
      if (r.exit_code != 0 || !strstr(r.err, "status=ok")) {
        fprintf(stderr, "%s (%s): run failed, exit %d:\n%s", c->name, set, r.exit_code, r.err);
        ++failures;
      }
      printf("%s t_end=%s: %.0f steps, peak RSS %ld kB\n", c->name, k ? c->t_long : c->t_short, steps[k], rss[k]);
      free(r.err);
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
