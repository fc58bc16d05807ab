/* steps.c — where a beam's steps go (issue 23, item 5: "profile where the steps go"): one run of a
 * scene as fmb_run runs it (fmb_init, fmb_advance to every output time, each row written by the one
 * CSV writer), with the absolute tolerances of one kind of a beam's coordinates multiplied by a
 * factor before the run starts. The kinds, in the floating beam's coordinate layout (bodies/beam.c:
 * the frame x, y, theta, then per node u, w, w'):
 *   frame    x, y, theta                      axial    every node's u
 *   bending  every node's w and w'            all      every coordinate of the body
 * (each coordinate's velocity slot with it). If loosening a kind leaves the steps where they were,
 * the steps do not resolve that kind's motion (its modes are damped by the method, not followed);
 * if it cuts the steps and the error of an output grows in step, the steps are spent on that kind
 * and the output needs them. Nothing in the engine changes: this only edits the run's tolerance
 * vector (fmbData.atol) between fmb_data_new and fmb_init, so the bench sees the engine as shipped.
 *
 *   steps SCENE.yaml -o OUT.csv [-s PATH=VALUE]... [-b BODY] [-k KIND -f FACTOR] [-p PERIOD]
 * prints one line of key=value pairs: the simulated span (t_end, from t0), the stats (steps, newton_iters, jacobians, error_test_fails,
 * cpu_s of the run, the CPU clock read at its start and end as fmb_run reads it) and
 * steps_per_period: the steps taken in each PERIOD seconds of simulated time (default 1), where in
 * the run they go. bench/steps.sh runs it and compares OUT.csv with a converged reference
 * (flexmbd compare). Exit 2 on bad arguments or input, 3 when the run fails. */
#include <math.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>
#include <time.h>

#include "builtin.h"
#include "data.h"

static int usage(void) {
  fprintf(stderr,
          "usage: steps SCENE.yaml -o OUT.csv [-s PATH=VALUE]... [-b BODY] [-k frame|axial|bending|all -f FACTOR] "
          "[-p PERIOD]\n");
  return 2;
}

/* does coordinate k of a floating beam (0-based within its slice) belong to the kind? */
static int in_kind(const char* kind, int k) {
  if (strcmp(kind, "all") == 0) return 1;
  if (strcmp(kind, "frame") == 0) return k < 3;
  if (k < 3) return 0;
  const int slot = (k - 3) % 3; /* per node: u, w, w' */
  return strcmp(kind, "axial") == 0 ? slot == 0 : slot != 0;
}

int main(int argc, char** argv) {
  const char *scene = NULL, *out = NULL, *body = "beam", *kind = NULL;
  const char* sets[32];
  int nset = 0;
  double factor = 1.0, period = 1.0;
  for (int i = 1; i < argc; ++i) {
    const int more = i + 1 < argc;
    if (strcmp(argv[i], "-s") == 0 && more && nset < 32)
      sets[nset++] = argv[++i];
    else if (strcmp(argv[i], "-o") == 0 && more)
      out = argv[++i];
    else if (strcmp(argv[i], "-b") == 0 && more)
      body = argv[++i];
    else if (strcmp(argv[i], "-k") == 0 && more)
      kind = argv[++i];
    else if (strcmp(argv[i], "-f") == 0 && more)
      factor = atof(argv[++i]);
    else if (strcmp(argv[i], "-p") == 0 && more)
      period = atof(argv[++i]);
    else if (argv[i][0] != '-' && !scene)
      scene = argv[i];
    else
      return usage();
  }
  if (!scene || !out || !(factor > 0.0) || !(period > 0.0)) return usage();
  if (kind && strcmp(kind, "frame") && strcmp(kind, "axial") && strcmp(kind, "bending") && strcmp(kind, "all"))
    return usage();
  fmbDiag diag;
  fmbModel* m = fmb_load(scene, sets, nset, fmb_builtin_registry(), &diag);
  if (!m) {
    fprintf(stderr, "steps: %s: %s\n", scene, diag.msg);
    return 2;
  }
  const fmbBodyInst* bi = NULL;
  for (int b = 1; b < m->nbody; ++b)
    if (strcmp(m->body[b].name, body) == 0) bi = &m->body[b];
  /* the layout above is the floating beam's: 3 frame coordinates and 3 per node */
  if (!bi || strcmp(bi->type->name, "beam") != 0 || bi->nq < 6 || (bi->nq - 3) % 3 != 0) {
    fprintf(stderr, "steps: %s: no body '%s' of type beam\n", scene, body);
    fmb_free(m);
    return 2;
  }
  fmbData* d = fmb_data_new(m, &diag);
  fmbCsv* csv = d ? fmb_csv_open(out, &diag) : NULL;
  if (!d || !csv) {
    fprintf(stderr, "steps: %s\n", diag.msg);
    fmb_data_destroy(d);
    fmb_free(m);
    return 3;
  }
  d->quiet = 1;
  d->untimed = 1;
  int changed = 0;
  for (int k = 0; kind && k < bi->nq; ++k)
    if (in_kind(kind, k)) {
      d->atol[bi->qadr + k] *= factor;
      d->atol[m->nq + bi->qadr + k] *= factor;
      changed++;
    }
  const clock_t c0 = clock();
  int rc = fmb_init(m, d, &diag);
  if (!rc) rc = fmb_csv_header(csv, m) || fmb_csv_row(csv, m, d->w, d->t, d->y, d->yp);
  const double t_end = m->solver.t_end, t0 = m->solver.t0;
  const long nout = fmb_row_count(m) - 1;
  const int nper = (int)ceil((t_end - t0) / period - 1e-9);
  long* per = calloc((size_t)nper + 1, sizeof(long));
  if (!per) rc = 1;
  long steps_before = 0;
  fmbStats st;
  for (long k = 1; !rc && k <= nout; ++k) {
    if ((rc = fmb_advance(m, d, fmb_row_time(m, k), &diag))) break;
    if ((rc = fmb_csv_row(csv, m, d->w, d->t, d->y, d->yp))) break;
    fmb_data_stats(d, &st);
    int p = (int)floor((d->t - t0) / period - 1e-9);
    p = p < 0 ? 0 : p >= nper ? nper - 1 : p;
    per[p] += st.steps - steps_before;
    steps_before = st.steps;
  }
  fmb_data_stats(d, &st);
  fmb_data_destroy(d);
  if (fmb_csv_close(csv) && !rc) rc = 1;
  const double cpu = (double)(clock() - c0) / CLOCKS_PER_SEC;
  if (rc) {
    fprintf(stderr, "steps: %s: the run failed: %s\n", scene, diag.msg);
    free(per);
    fmb_free(m);
    return 3;
  }
  printf("kind=%s factor=%g coordinates=%d t_end=%g steps=%ld newton_iters=%ld jacobians=%ld error_test_fails=%ld "
         "cpu_s=%.4f "
         "steps_per_period=",
         kind ? kind : "none", kind ? factor : 1.0, changed, t_end - t0, st.steps, st.newton_iters, st.jacobians,
         st.error_test_fails, cpu);
  for (int p = 0; p < nper; ++p) printf("%s%ld", p ? ":" : "", per[p]);
  printf("\n");
  free(per);
  fmb_free(m);
  return 0;
}
