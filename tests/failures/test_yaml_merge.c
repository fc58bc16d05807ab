/* test_yaml_merge.c — YAML merge keys work (issue 12): failures/merge_keys.yaml builds three
 * bodies from one anchored mapping; the loaded model must hold exactly the masses and inertias
 * the merge rules give (own keys win, then the merged mappings in order), and run. */
#include <stdlib.h>
#include <string.h>

#include "testlib.h"

int main(void) {
  char path[1024];
  fmbDiag d;
  fmbModel* m =
      fmb_load(fmbt_path("tests/failures/merge_keys.yaml", path, sizeof path), NULL, 0, fmb_builtin_registry(), &d);
  ENSURE(m != NULL);
  if (!m) {
    fprintf(stderr, "%s:%d: %s\n", d.file, d.line, d.msg);
    return fmbt_finish("yaml_merge");
  }
  char* text = NULL;
  size_t len = 0;
  FILE* f = open_memstream(&text, &len);
  fmb_describe(m, f);
  fclose(f);
  printf("%s", text);
  ENSURE(strstr(text, "body 'a' (rigid, 3 coordinates): mass 1 kg, inertia 0.1 kg m^2") != NULL);
  ENSURE(strstr(text, "body 'b' (rigid, 3 coordinates): mass 2 kg, inertia 0.1 kg m^2") != NULL);
  ENSURE(strstr(text, "body 'c' (rigid, 3 coordinates): mass 1 kg, inertia 0.1 kg m^2") != NULL);
  free(text);
  fmbStats st;
  fmbtCsv c;
  ENSURE(fmbt_run_read("tests/failures/merge_keys.yaml", NULL, 0, "merge_keys.csv", &c, &st) == 0);
  /* the merged positions are the bodies' own: a chain along x, assembled as given */
  const double *xb = fmbt_col(&c, "b.x"), *xc = fmbt_col(&c, "c.x");
  if (xb && xc && c.nrow > 0) {
    ENSURE_NEAR(xb[0], 3.0, 1e-12);
    ENSURE_NEAR(xc[0], 5.0, 1e-12);
  }
  ENSURE(st.ic_position_correction == 0.0);
  fmbt_csv_free(&c);
  fmb_free(m);
  return fmbt_finish("yaml_merge");
}
