/* cmd_regress.c — `flexmbd regress [PATH...] [--bless] [--junit FILE] [-j N] [--set PATH=VALUE]...
 *                                  [--slow FACTOR] [--rows N] [--timeout SEC]`
 * The scene regression suite (docs/regression.md). PATH is a scene file or a folder searched
 * recursively for scenes that have a reference (default: the current folder). A scene's reference is
 * the file beside it named SCENE.ref.csv (SCENE without .yaml): a thinned copy of the run's CSV rows
 * behind a '#' header that records how it was made (flexmbd version and commit, date, solver
 * settings, the --set overrides it was made with, status, CPU time) and one tolerance per column.
 *
 * Each scene runs in a child process (a crash or a hang fails that scene only; -j N runs N at once)
 * with the overrides its reference records; every column is compared at the reference's rows with
 * |run - ref| <= atol + rtol * range(ref column). One table row per scene on stdout.
 * Exit 0 all pass, 1 any fails, 2 bad input (a missing path or reference, a malformed reference, a
 * --set that is not PATH=VALUE or does not apply to a scene, or with --bless a scene that does not load), 4 interrupted (every child stopped, nothing left behind).
 * The parts: regress_ref.c (scenes, references, --bless), regress_jobs.c (children, the check),
 * regress_report.c (table, JUnit). */
#include <dirent.h>
#include <errno.h>
#include <math.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>
#include <sys/stat.h>
#include <unistd.h>

#include "regress.h"

#define DEFAULT_TIMEOUT_S 600.0

typedef struct {
  RegressOptions o;
  RegressList paths;
} RegressArgs;

static int regress_read_set(const fmbOptContext* ctx, void* at, const char* value) {
  RegressOptions* o = at;
  if (fmb_cli_check_set(ctx->cmd, value, ctx->next)) return FMB_EXIT_BAD_INPUT;
  o->sets[o->nsets++] = value; /* o->sets has room for every argument */
  return 0;
}

static int regress_path(const fmbOptContext* ctx, const char* arg) {
  RegressArgs* a = ctx->self;
  return regress_list_push(&a->paths, (char*)arg) ? FMB_EXIT_BAD_INPUT : 0;
}

#define STR_(x) #x
#define STR(x) STR_(x)
static const fmbOpt regress_options[] = {
    {"--bless", NULL, FMB_OPT_FLAG, NULL, offsetof(RegressArgs, o.bless),
     "write or update the references (a folder: every *.yaml in it)", NULL, 0, 0, NULL, NULL, 0},
    {"--junit", NULL, FMB_OPT_STRING, "FILE", offsetof(RegressArgs, o.junit), "also write the results as JUnit XML",
     "a file name", 0, 0, NULL, NULL, 0},
    {"--jobs", "-j", FMB_OPT_INT, "N", offsetof(RegressArgs, o.jobs), "run N scenes at once",
     "a whole number from 1 to 256", 1, 256, NULL, NULL, 0},
    {"--set", NULL, FMB_OPT_CALL, "PATH=VALUE", offsetof(RegressArgs, o),
     "override a value of every scene; with --bless the references record it", "PATH=VALUE", 0, 0, NULL,
     regress_read_set, FMB_OPT_REPEAT},
    {"--slow", NULL, FMB_OPT_DOUBLE, "F", offsetof(RegressArgs, o.slow),
     "warn when a scene takes more than F times its reference's CPU time (default 3)", "a factor >= 1", 1, HUGE_VAL,
     NULL, NULL, 0},
    {"--rows", NULL, FMB_OPT_INT, "N", offsetof(RegressArgs, o.rows),
     "rows kept in a reference (default " STR(REGRESS_DEFAULT_ROWS) ")", "a whole number from 2 to 100000", 2, 100000,
     NULL, NULL, 0},
    {"--timeout", NULL, FMB_OPT_DOUBLE, "SEC", offsetof(RegressArgs, o.timeout_s),
     "wall time allowed per scene (default 600)", "a number of seconds > 0", 0, HUGE_VAL, NULL, NULL,
     FMB_OPT_ABOVE_MIN},
};

const fmbCommandSpec fmb_regress_command = {
    "regress",
    "[PATH...]",
    "scenes against their stored references (PATH: a scene, or a folder searched for scenes with a reference "
    "SCENE.ref.csv; default .)",
    regress_options,
    FMB_OPT_COUNT(regress_options),
    regress_path,
    "exit: 0 all pass, 1 a scene fails, 2 bad input, 4 interrupted (docs/regression.md)\n"};

static void remove_tmpdir(const char* dir) {
  DIR* d = opendir(dir);
  if (d) {
    struct dirent* e;
    char p[1200];
    while ((e = readdir(d)) != NULL) {
      if (strcmp(e->d_name, ".") == 0 || strcmp(e->d_name, "..") == 0) continue; /* a killed run leaves .NAME.XXXXXX */
      snprintf(p, sizeof p, "%s/%s", dir, e->d_name);
      remove(p);
    }
    closedir(d);
  }
  rmdir(dir);
}

static int regress(const RegressOptions* op, const RegressList* sc, RegressList* notes);

/* options and the scenes to run; returns -1 to go on, or an exit code (everything it allocates
   hangs off o, paths and scenes, which the caller frees) */
static int parse_arguments(int argc, char** argv, RegressOptions* op, RegressList* pathsp, RegressList* scenesp,
                           RegressList* notes) {
  RegressArgs args = {*op, {0}};
  RegressList scenes = {0};
  int rc = -1;
#define return_code(c) \
  do {                 \
    rc = (c);          \
    goto out;          \
  } while (0)
  if (fmb_opt_parse(&fmb_regress_command, argc, argv, &args, &rc)) goto out;
  rc = -1;
  if (args.paths.n == 0 && regress_list_push(&args.paths, ".")) return_code(FMB_EXIT_BAD_INPUT);
  /* the scenes */
  for (int i = 0; i < args.paths.n; ++i) {
    struct stat st;
    const char* p = args.paths.v[i];
    if (stat(p, &st) != 0) {
      fprintf(stderr, "flexmbd regress: %s: %s\n", p, strerror(errno));
      return_code(FMB_EXIT_BAD_INPUT);
    }
    if (S_ISDIR(st.st_mode)) {
      int before = scenes.n;
      char why[1400];
      if (regress_walk(p, args.o.bless, &scenes, notes, why, sizeof why)) {
        fprintf(stderr, "flexmbd regress: %s\n", why);
        return_code(FMB_EXIT_BAD_INPUT);
      }
      if (scenes.n == before) {
        fprintf(stderr, "flexmbd regress: no scene %sunder %s%s\n", args.o.bless ? "" : "with a reference ", p,
                args.o.bless ? "" : " (make references with: flexmbd regress --bless PATH)");
        return_code(FMB_EXIT_BAD_INPUT);
      }
    } else if (S_ISREG(st.st_mode)) {
      char* d = strdup(p);
      if (!d || regress_list_push(&scenes, d)) {
        free(d);
        fprintf(stderr, "flexmbd regress: out of memory\n");
        return_code(FMB_EXIT_BAD_INPUT);
      }
    } else {
      fprintf(stderr, "flexmbd regress: %s: not a scene file or a folder\n", p);
      return_code(FMB_EXIT_BAD_INPUT);
    }
  }
out:
#undef return_code
  *op = args.o;
  *pathsp = args.paths;
  *scenesp = scenes;
  return rc;
}

int fmb_cmd_regress(int argc, char** argv) {
  RegressOptions o;
  memset(&o, 0, sizeof o);
  o.jobs = 1;
  o.rows = REGRESS_DEFAULT_ROWS;
  o.slow = 3.0;
  o.timeout_s = DEFAULT_TIMEOUT_S;
  o.sets = calloc((size_t)argc, sizeof *o.sets);
  if (!o.sets) return FMB_EXIT_BAD_INPUT;
  RegressList paths = {0}, scenes = {0}, notes = {0};
  int rc = parse_arguments(argc, argv, &o, &paths, &scenes, &notes);
  if (rc < 0) rc = regress(&o, &scenes, &notes);
  for (int i = 0; i < notes.n; ++i) free(notes.v[i]);
  free(notes.v);
  for (int i = 0; i < scenes.n; ++i) free(scenes.v[i]);
  free(scenes.v);
  free(paths.v);
  free(o.sets);
  return rc;
}

/* two scenes that would share one reference (a.yaml and a.yml): -1 after saying so. The twin is
   looked for beside each scene, not only among the scenes named: `regress --bless a.yml` after
   `--bless a.yaml` would otherwise check a.yml against a.yaml's reference and call it unchanged. */
static int shared_reference(RegressJob* const* jobs, int n) {
  for (int i = 0; i < n; ++i) {
    char* twin = regress_twin_scene(jobs[i]->scene);
    if (twin) {
      fprintf(stderr, "flexmbd regress: %s and %s would share one reference %s: rename one of them\n", jobs[i]->scene,
              twin, jobs[i]->ref_path);
      free(twin);
      return -1;
    }
  }
  for (int i = 0; i < n; ++i)
    for (int k = i + 1; k < n; ++k)
      if (strcmp(jobs[i]->ref_path, jobs[k]->ref_path) == 0) {
        fprintf(stderr, "flexmbd regress: %s and %s would share one reference %s: rename one of them\n", jobs[i]->scene,
                jobs[k]->scene, jobs[i]->ref_path);
        return -1;
      }
  return 0;
}

/* --junit FILE may not replace a scene or a reference: -1 after saying so */
static int junit_replaces_input(const char* junit, RegressJob* const* jobs, int n) {
  const char** inputs = calloc(2 * (size_t)n + 1, sizeof *inputs);
  if (!inputs) return -1;
  int k = 0;
  for (int i = 0; i < n; ++i) inputs[k++] = jobs[i]->scene, inputs[k++] = jobs[i]->ref_path;
  const int bad = fmb_cli_check_output_not_input(junit, inputs, k);
  free(inputs);
  return bad ? -1 : 0;
}

/* run (or bless) every scene; the exit code */
static int regress(const RegressOptions* op, const RegressList* sc, RegressList* notes) {
  RegressOptions o = *op;
  const RegressList scenes = *sc;
  int rc = 0;
  /* with --bless each scene's job is followed by its companions (same scene, neighbouring rtol) */
  const int per = o.bless ? 1 + REGRESS_NCOMPANION : 1;
  RegressJob* all = calloc((size_t)scenes.n * (size_t)per + 1, sizeof *all);
  RegressJob** jobs = calloc((size_t)scenes.n + 1, sizeof *jobs);
  if (!all || !jobs) {
    free(all), free(jobs);
    fprintf(stderr, "flexmbd regress: out of memory\n");
    return FMB_EXIT_BAD_INPUT;
  }
  for (int i = 0; i < scenes.n; ++i) {
    RegressJob* j = jobs[i] = &all[i * per];
    j->scene = scenes.v[i];
    j->ref_path = regress_reference_path(j->scene);
    j->ref.cpu_s = NAN;
    char why[700];
    if (!j->ref_path) {
      j->bad_input = 1;
      regress_say(j->why, sizeof j->why, "out of memory");
    } else if (regress_file_exists(j->ref_path)) {
      if (regress_reference_load(j->ref_path, &j->ref, why, sizeof why, notes)) {
        j->bad_input = 1;
        regress_say(j->why, sizeof j->why, "%s", why);
      }
    } else if (!o.bless) {
      j->bad_input = 1;
      regress_say(j->why, sizeof j->why, "no reference %s (make it with: flexmbd regress --bless %s)", j->ref_path,
                  j->scene);
    }
    for (int k = 1; k < per; ++k) {
      RegressJob* c = &all[i * per + k];
      c->scene = j->scene;
      c->ref = j->ref; /* shared, read-only; freed with the scene's own job */
      c->companion = k;
      c->bad_input = j->bad_input;
    }
  }
  /* nothing is run or written before every output is known not to replace an input */
  for (int i = 0; i < scenes.n && !rc; ++i)
    if (!jobs[i]->ref_path) rc = FMB_EXIT_BAD_INPUT;
  if (!rc && (shared_reference(jobs, scenes.n) || (o.junit && junit_replaces_input(o.junit, jobs, scenes.n))))
    rc = FMB_EXIT_BAD_INPUT;
  if (rc) goto out;
  if (fmb_cli_private_folder("regress", o.tmpdir, sizeof o.tmpdir)) {
    rc = FMB_EXIT_BAD_INPUT;
    goto out;
  }
  if (regress_run_all(all, scenes.n * per, &o) == FMB_EXIT_INTERRUPTED) {
    remove_tmpdir(o.tmpdir);
    fprintf(stderr, "flexmbd regress: interrupted: every run stopped, nothing checked\n");
    rc = FMB_EXIT_INTERRUPTED;
    goto out;
  }
  int nfail = 0, bad = 0;
  for (int i = 0; i < scenes.n; ++i) {
    RegressJob* j = jobs[i];
    if (!j->failed && !j->bad_input) {
      if (o.bless)
        regress_bless_job(j, &o);
      else
        regress_check_job(j);
      if (!o.bless && !j->failed && isfinite(j->ref.cpu_s) && j->ref.cpu_s >= 0.05 &&
          j->run.cpu_s > o.slow * j->ref.cpu_s)
        j->warn_slow = 1;
    }
    bad += j->bad_input;
    nfail += j->failed || j->bad_input;
  }
  regress_print_table(jobs, scenes.n, &o);
  /* what the search passed over and what a reference asked for in vain: said, never silent */
  for (int i = 0; i < notes->n; ++i) printf("note: %s\n", notes->v[i]);
  printf("regress: %d passed, %d failed\n", scenes.n - nfail, nfail);
  rc = bad ? FMB_EXIT_BAD_INPUT : nfail ? 1 : 0;
  if (o.junit && regress_write_junit(o.junit, jobs, scenes.n)) rc = FMB_EXIT_BAD_INPUT;
  remove_tmpdir(o.tmpdir);
out:
  for (int i = 0; i < scenes.n; ++i) {
    regress_reference_free(&jobs[i]->ref);
    free(jobs[i]->ref_path);
  }
  free(jobs);
  free(all);
  return rc;
}
