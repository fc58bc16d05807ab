/* inputs.c — what a controller in the loop costs (issue 35, item 2: "a controller stepping at 1 kHz
 * costs <= 2x the same run with a continuous law"). One mechanism in two scenes: its load following
 * a continuous law (law: harmonic, frequency f), and the same load with `law: input`, where this program
 * evaluates the same law in C and sets it every PERIOD seconds of simulated time (1 ms: 1 kHz)
 * through the public stepping API, as a controller would:
 *   hold     fmb_set_input(value): the law's value, held until the next setting (zero-order hold)
 *   motion   fmb_set_input_motion(value, rate, accel): the law's Taylor polynomial at the setting
 * Every setting changes the equations, so the integrator restarts there (fmb_set_input: its reinit
 * op keeps its memory). Outputs are read at the scene's output grid (fmb_row_time) in all three.
 * Each repeat runs the three once, interleaved, timed in CPU time of the process; printed: the
 * medians, the ratios to the continuous run, the steps, and the largest difference of the first
 * output column from the continuous run (motion: the restarts' own error; hold: plus the hold's
 * O(PERIOD) lag).
 *
 *   inputs LAW.yaml INPUT.yaml -l LOAD -f FREQUENCY_RAD_S [-p PERIOD] [-r REPEATS] [-H] [-U]
 * (INPUT.yaml: LAW.yaml with the load's `law: input, value: 0` instead of `law: harmonic`;
 * -U: the data objects do not time each advance (the monotonic clock), fmb_data_set_timing)
 * prints one CSV line (header with -H):
 *   scene,period_s,settings,steps_law,steps_hold,steps_motion,cpu_law_s,cpu_hold_s,cpu_motion_s,
 *   ratio_hold,ratio_motion,diff_hold,diff_motion,library_clock
 * Only the public API (flexmbd.h): bench/inputs.sh builds it against another tree's library too.
 * Exit 2 on bad arguments or input, 3 when a run fails. */
#include <math.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>
#include <time.h>

#include "bench_cpu.h"
#include "builtin.h"
#include "flexmbd.h"

enum { WAY_LAW, WAY_HOLD, WAY_MOTION, NWAY };

typedef struct {
  const char* load;
  double omega, period;
  int clock; /* the data objects time each advance for fmb_data_stats (the default) */
} Controller;

/* one run: the outputs' first column at every row into col0 (rows), the steps into *steps */
static int run(const fmbModel* m, int way, const Controller* c, double* col0, long* steps, double* cpu) {
  fmbDiag diag;
  fmbSolverInfo si;
  fmb_model_solver(m, &si);
  const long rows = fmb_row_count(m);
  double* out = calloc((size_t)fmb_noutput(m) + 1, sizeof(double));
  const double c0 = cpu_now();
  fmbData* d = fmb_data_new(m, &diag);
  if (!c->clock) fmb_data_set_timing(d, 0); /* this program times the run itself */
  int rc = !out || !d || fmb_init(m, d, &diag);
  long setting = 0;
  for (long k = 0; !rc && k < rows; ++k) {
    const double t_row = fmb_row_time(m, k);
    /* the controller's settings before this row (one at the row's time comes after the row) */
    while (!rc && way != WAY_LAW && k > 0) {
      const double t = si.t0 + (double)setting * c->period;
      if (t >= t_row - 1e-9 * c->period) break;
      if ((rc = fmb_advance(m, d, fmax(t, fmb_data_time(d)), &diag))) break;
      const double s = sin(c->omega * t), co = cos(c->omega * t);
      rc = way == WAY_HOLD ? fmb_set_input(m, d, c->load, s)
                           : fmb_set_input_motion(m, d, c->load, s, c->omega * co, -c->omega * c->omega * s);
      ++setting;
    }
    if (!rc) rc = fmb_advance(m, d, t_row, &diag);
    if (!rc) rc = fmb_outputs(m, d, out);
    col0[k] = out ? out[0] : NAN;
  }
  *cpu = cpu_now() - c0;
  fmbStats st;
  if (d && !fmb_data_stats(d, &st)) *steps = st.steps;
  if (rc) fprintf(stderr, "inputs: run %d failed: %s\n", way, diag.msg);
  fmb_data_free(d);
  free(out);
  return rc;
}

int main(int argc, char** argv) {
  const char *scene = NULL, *scene_input = NULL;
  Controller c = {NULL, NAN, 1e-3, 1};
  int repeats = 5, header = 0;
  for (int i = 1; i < argc; ++i) {
    const int more = i + 1 < argc;
    if (strcmp(argv[i], "-l") == 0 && more)
      c.load = argv[++i];
    else if (strcmp(argv[i], "-f") == 0 && more)
      c.omega = atof(argv[++i]);
    else if (strcmp(argv[i], "-p") == 0 && more)
      c.period = atof(argv[++i]);
    else if (strcmp(argv[i], "-r") == 0 && more)
      repeats = atoi(argv[++i]);
    else if (strcmp(argv[i], "-H") == 0)
      header = 1;
    else if (strcmp(argv[i], "-U") == 0)
      c.clock = 0;
    else if (argv[i][0] != '-' && !scene)
      scene = argv[i];
    else if (argv[i][0] != '-' && !scene_input)
      scene_input = argv[i];
    else
      scene = NULL, i = argc;
  }
  if (!scene || !scene_input || !c.load || !(c.omega > 0) || !(c.period > 0) || repeats < 1) {
    fprintf(stderr,
            "usage: inputs LAW.yaml INPUT.yaml -l LOAD -f FREQUENCY_RAD_S [-p PERIOD] [-r REPEATS] [-H] [-U]\n");
    return 2;
  }
  fmb_set_warn(NULL, NULL); /* the hold's first jump is warned about: not the bench's business */
  fmbDiag diag;
  fmbModel* law = fmb_load(scene, NULL, 0, fmb_builtin_registry(), &diag);
  fmbModel* input = law ? fmb_load(scene_input, NULL, 0, fmb_builtin_registry(), &diag) : NULL;
  if (!law || !input) {
    fprintf(stderr, "inputs: %s\n", diag.msg);
    return 2;
  }
  const long rows = fmb_row_count(law);
  double* col[NWAY];
  double* cpu[NWAY];
  long steps[NWAY] = {0};
  for (int w = 0; w < NWAY; ++w) {
    col[w] = calloc((size_t)rows, sizeof(double));
    cpu[w] = calloc((size_t)repeats, sizeof(double));
  }
  int rc = 0;
  for (int r = 0; r < repeats && !rc; ++r)
    for (int w = 0; w < NWAY && !rc; ++w) rc = run(w == WAY_LAW ? law : input, w, &c, col[w], &steps[w], &cpu[w][r]);
  if (rc) return 3;
  double diff[NWAY] = {0};
  for (int w = 1; w < NWAY; ++w)
    for (long k = 0; k < rows; ++k) diff[w] = fmax(diff[w], fabs(col[w][k] - col[WAY_LAW][k]));
  double med[NWAY];
  for (int w = 0; w < NWAY; ++w) med[w] = median(cpu[w], repeats);
  fmbSolverInfo si;
  fmb_model_solver(law, &si);
  if (header)
    printf("scene,period_s,settings,steps_law,steps_hold,steps_motion,cpu_law_s,cpu_hold_s,cpu_motion_s,ratio_hold,"
           "ratio_motion,diff_hold,diff_motion,library_clock\n");
  printf("%s,%g,%ld,%ld,%ld,%ld,%.4f,%.4f,%.4f,%.2f,%.2f,%.3e,%.3e,%d\n", scene, c.period,
         (long)floor((si.t_end - si.t0) / c.period + 1e-9) + 1, steps[WAY_LAW], steps[WAY_HOLD], steps[WAY_MOTION],
         med[WAY_LAW], med[WAY_HOLD], med[WAY_MOTION], med[WAY_HOLD] / med[WAY_LAW], med[WAY_MOTION] / med[WAY_LAW],
         diff[WAY_HOLD], diff[WAY_MOTION], c.clock);
  for (int w = 0; w < NWAY; ++w) {
    free(col[w]);
    free(cpu[w]);
  }
  fmb_free(input);
  fmb_free(law);
  return 0;
}
