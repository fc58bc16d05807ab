/* check.h — the tests' checks: each reports file:line and the values, and counts itself;
 * fmbt_finish prints the "N passed, N failed" line ctest logs and returns the exit code. Header
 * plus tests/check.c, with no dependency on the engine, so white-box tests that include a plugin's
 * source can use them too. */
#ifndef FLEXMBD_CHECK_H
#define FLEXMBD_CHECK_H
#include <math.h>
#include <stdio.h>

extern int fmbt_failures, fmbt_checks;

#define ENSURE(cond)                                                           \
  do {                                                                         \
    ++fmbt_checks;                                                             \
    if (!(cond)) {                                                             \
      fprintf(stderr, "%s:%d: check failed: %s\n", __FILE__, __LINE__, #cond); \
      ++fmbt_failures;                                                         \
    }                                                                          \
  } while (0)

/* |a - b| <= tol, reporting both values */
#define ENSURE_NEAR(a, b, tol)                                                                                      \
  do {                                                                                                              \
    double fmbt_a = (a), fmbt_b = (b), fmbt_t = (tol);                                                              \
    ++fmbt_checks;                                                                                                  \
    if (!(fabs(fmbt_a - fmbt_b) <= fmbt_t)) {                                                                       \
      fprintf(stderr, "%s:%d: %s = %.12g, %s = %.12g, differ by %.3g > %.3g\n", __FILE__, __LINE__, #a, fmbt_a, #b, \
              fmbt_b, fabs(fmbt_a - fmbt_b), fmbt_t);                                                               \
      ++fmbt_failures;                                                                                              \
    }                                                                                                               \
  } while (0)

/* |a - b| <= rel |b| */
#define ENSURE_REL(a, b, rel) ENSURE_NEAR(a, b, (rel)*fabs((double)(b)))

/* "N passed, N failed" summary (counting every ENSURE*) and the exit code */
int fmbt_finish(const char* name);

#endif
