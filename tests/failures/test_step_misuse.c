/* test_step_misuse.c — the stepping API (flexmbd.h "Stepping", issue 24) answers misuse with an
 * error, never a crash, and a refused call changes nothing. Run under AddressSanitizer in the
 * sanitizer build (label sanitize), where any read of freed memory fails the test:
 *   - NULL model, data, output arrays, names, everywhere;
 *   - advance before init, backwards, to NaN, beyond t_end; a data object of another model;
 *   - a data object after fmb_data_free: the quarantine (step.c) keeps its memory, so every call
 *     finds it freed and refuses without touching freed memory, and a second free is ignored;
 *     a hundred frees later (beyond FMB_DATA_QUARANTINE) its memory is really released, which
 *     is why only the recent past can be checked (not exercised: that is undefined);
 *   - use after a cancel; a failed init; and the state, time and outputs left as they were.
 *   test_step_misuse */
#include <math.h>
#include <stdio.h>
#include <string.h>

#include "testlib.h"

static int warnings;
static void count_warning(void* user, const char* message) {
  (void)user, (void)message;
  ++warnings;
}

static fmbModel* load_text(const char* name, const char* text) {
  char path[1024];
  fmbt_out_path(name, path, sizeof path);
  FILE* f = fopen(path, "w");
  if (!f) return NULL;
  fputs(text, f);
  fclose(f);
  fmbDiag diag;
  fmbModel* m = fmb_load(path, NULL, 0, fmb_builtin_registry(), &diag);
  if (!m) fprintf(stderr, "%s: %s\n", path, diag.msg);
  return m;
}

int main(void) {
  fmb_set_warn(count_warning, NULL);
  fmbModel* m =
      load_text("step_misuse_a.yaml", "solver: {t_end: 1, output_step: 0.1}\n"
                                      "gravity: [0, -9.81]\n"
                                      "bodies: [{name: bob, type: rigid, mass: 1, inertia: 0.1, position: [1, 0]}]\n"
                                      "joints:\n"
                                      "  - {name: pin, type: revolute, body1: ground, body2: bob, point2: [-1, 0]}\n"
                                      "  - {name: kick, type: force, body: bob, force: [0, 1], law: input, value: 0}\n"
                                      "outputs: [bob.theta, bob.omega]\n");
  fmbModel* other = load_text("step_misuse_b.yaml", "solver: {t_end: 1}\n"
                                                    "bodies: [{name: bob, type: rigid, mass: 1, inertia: 0.1}]\n");
  ENSURE(m && other);
  if (!m || !other) return fmbt_finish("test_step_misuse");
  fmbDiag diag;
  double y[64], yp[64], out[8];
  fmbStats st;

  /* NULL everywhere */
  ENSURE(fmb_data_new(NULL, &diag) == NULL && diag.code == FMB_EXIT_BAD_INPUT);
  ENSURE(fmb_data_new(NULL, NULL) == NULL);
  fmb_data_free(NULL);
  fmbData* d = fmb_data_new(m, NULL);
  ENSURE(d != NULL);
  ENSURE(fmb_init(NULL, d, &diag) == FMB_EXIT_BAD_INPUT && strstr(diag.msg, "no model"));
  ENSURE(fmb_init(m, NULL, &diag) == FMB_EXIT_BAD_INPUT && strstr(diag.msg, "no data object"));
  ENSURE(fmb_init(m, NULL, NULL) == FMB_EXIT_BAD_INPUT);
  ENSURE(fmb_advance(NULL, d, 0.1, &diag) == FMB_EXIT_BAD_INPUT);
  ENSURE(fmb_advance(m, NULL, 0.1, NULL) == FMB_EXIT_BAD_INPUT);
  ENSURE(isnan(fmb_data_time(NULL)));
  ENSURE(fmb_data_state(NULL, y, yp) == FMB_EXIT_BAD_INPUT);
  ENSURE(fmb_noutput(NULL) == 0 && fmb_output_name(NULL, 0) == NULL);
  ENSURE(fmb_output_name(m, -1) == NULL && fmb_output_name(m, 2) == NULL);
  ENSURE(fmb_output_name(m, 1) && strcmp(fmb_output_name(m, 1), "bob.omega") == 0);
  ENSURE(fmb_outputs(NULL, d, out) == FMB_EXIT_BAD_INPUT && fmb_outputs(m, NULL, out) == FMB_EXIT_BAD_INPUT);
  ENSURE(fmb_outputs(m, d, NULL) == FMB_EXIT_BAD_INPUT);
  ENSURE(fmb_data_stats(NULL, &st) == FMB_EXIT_BAD_INPUT && fmb_data_stats(d, NULL) == FMB_EXIT_BAD_INPUT);
  fmb_data_cancel(NULL);
  fmb_data_set_warn(NULL, count_warning, NULL);
  ENSURE(fmb_ninput(NULL) == 0 && fmb_input_name(NULL, 0) == NULL && fmb_input_name(m, 5) == NULL);
  ENSURE(fmb_set_input(NULL, d, "kick", 1.0) == FMB_EXIT_BAD_INPUT);
  ENSURE(fmb_set_input(m, NULL, "kick", 1.0) == FMB_EXIT_BAD_INPUT);
  ENSURE(fmb_set_input(m, d, NULL, 1.0) == FMB_EXIT_BAD_INPUT);
  ENSURE(fmb_get_input(m, d, "kick", NULL) == FMB_EXIT_BAD_INPUT);

  /* before init: no state to advance, read or write out */
  ENSURE(isnan(fmb_data_time(d)));
  ENSURE(fmb_advance(m, d, 0.1, &diag) == FMB_EXIT_BAD_INPUT && strstr(diag.msg, "fmb_init first"));
  ENSURE(fmb_data_state(d, y, yp) == FMB_EXIT_BAD_INPUT);
  ENSURE(fmb_outputs(m, d, out) == FMB_EXIT_BAD_INPUT);

  /* a data object of another model */
  fmbData* od = fmb_data_new(other, &diag);
  ENSURE(fmb_init(m, od, &diag) == FMB_EXIT_BAD_INPUT && strstr(diag.msg, "another model"));
  ENSURE(fmb_advance(m, od, 0.1, &diag) == FMB_EXIT_BAD_INPUT);
  ENSURE(fmb_outputs(m, od, out) == FMB_EXIT_BAD_INPUT);
  ENSURE(fmb_set_input(m, od, "kick", 1.0) == FMB_EXIT_BAD_INPUT);

  /* bad times: nothing moves */
  ENSURE(fmb_init(m, d, &diag) == 0);
  ENSURE(fmb_advance(m, d, 0.3, &diag) == 0);
  ENSURE(fmb_data_state(d, y, NULL) == 0 && fmb_data_state(d, NULL, yp) == 0 && fmb_data_state(d, NULL, NULL) == 0);
  double before[8], after[8];
  ENSURE(fmb_outputs(m, d, before) == 0);
  ENSURE(fmb_advance(m, d, 0.2, &diag) == FMB_EXIT_BAD_INPUT && strstr(diag.msg, "a run goes forward"));
  ENSURE(fmb_advance(m, d, NAN, &diag) == FMB_EXIT_BAD_INPUT);
  ENSURE(fmb_advance(m, d, 1.5, &diag) == FMB_EXIT_BAD_INPUT && strstr(diag.msg, "t_end"));
  ENSURE(fmb_advance(m, d, INFINITY, &diag) == FMB_EXIT_BAD_INPUT);
  ENSURE(fmb_advance(m, d, -INFINITY, &diag) == FMB_EXIT_BAD_INPUT);
  ENSURE(fmb_data_time(d) == 0.3);
  ENSURE(fmb_outputs(m, d, after) == 0 && memcmp(before, after, sizeof(double) * 2) == 0);
  ENSURE(fmb_advance(m, d, 0.3, &diag) == 0 && fmb_data_time(d) == 0.3); /* no time to go: nothing */
  warnings = 0;
  ENSURE(fmb_set_input(m, d, "no_such_input", 1.0) == FMB_EXIT_BAD_INPUT);
  ENSURE(warnings == 1); /* says why through the handler */

  /* cancel, then go on */
  fmb_data_cancel(d);
  fmb_data_cancel(d); /* twice is once */
  ENSURE(fmb_advance(m, d, 0.5, &diag) == FMB_EXIT_INTERRUPTED && fmb_data_time(d) == 0.3);
  ENSURE(fmb_data_stats(d, &st) == 0 && st.interrupted && !st.status_ok);
  ENSURE(fmb_advance(m, d, 0.5, &diag) == 0 && fmb_data_time(d) == 0.5);
  ENSURE(fmb_data_stats(d, &st) == 0 && st.t_reached == 0.5 && st.steps > 0 && st.status_ok && !st.interrupted);

  /* after free: refused without reading freed memory (ASan would say so), a second free ignored */
  fmb_data_free(d);
  ENSURE(fmb_advance(m, d, 0.6, &diag) == FMB_EXIT_BAD_INPUT && strstr(diag.msg, "freed"));
  ENSURE(fmb_init(m, d, &diag) == FMB_EXIT_BAD_INPUT && strstr(diag.msg, "freed"));
  ENSURE(fmb_outputs(m, d, out) == FMB_EXIT_BAD_INPUT);
  ENSURE(isnan(fmb_data_time(d)));
  ENSURE(fmb_data_state(d, y, yp) == FMB_EXIT_BAD_INPUT);
  ENSURE(fmb_data_stats(d, &st) == FMB_EXIT_BAD_INPUT);
  ENSURE(fmb_set_input(m, d, "kick", 1.0) == FMB_EXIT_BAD_INPUT);
  fmb_data_set_warn(d, count_warning, NULL);
  fmb_data_cancel(d);
  fmb_data_free(d); /* double free: ignored */
  /* many objects made and freed since: the quarantine turns over, nothing leaks or breaks */
  for (int k = 0; k < 2 * FMB_DATA_QUARANTINE + 5; ++k) fmb_data_free(fmb_data_new(other, NULL));

  /* a failed init (joints 4 m off the poses given: exit 2) leaves no state to advance, and the
     object stays usable */
  fmbModel* bad =
      load_text("step_misuse_c.yaml", "solver: {t_end: 1}\n"
                                      "bodies: [{name: a, type: rigid, mass: 1, inertia: 0.1, position: [1, 0]},\n"
                                      "         {name: b, type: rigid, mass: 1, inertia: 0.1, position: [5, 0]}]\n"
                                      "joints: [{name: p, type: revolute, body1: a, body2: b}]\n");
  ENSURE(bad != NULL);
  if (bad) {
    fmbData* bd = fmb_data_new(bad, &diag);
    ENSURE(fmb_init(bad, bd, &diag) == FMB_EXIT_BAD_INPUT && strstr(diag.msg, "not satisfied"));
    ENSURE(fmb_advance(bad, bd, 0.5, &diag) == FMB_EXIT_BAD_INPUT && strstr(diag.msg, "fmb_init first"));
    ENSURE(fmb_init(bad, bd, &diag) == FMB_EXIT_BAD_INPUT); /* again: the same answer */
    fmb_data_free(bd);
    fmb_free(bad);
  }
  fmb_data_free(od);
  fmb_free(m);
  fmb_free(other);
  return fmbt_finish("test_step_misuse");
}
