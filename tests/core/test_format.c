/* test_format.c — fmb_format_g12 (engine/format_g12.c) against the C library's own "%.12g", the
 * independent value: the CSV rows' bytes may not change. 2 million random doubles over 1e-33 ..
 * 1e40 (random 53-bit mantissas, both signs), every power of ten and its neighbours (one ulp either
 * side), numbers at and next to the halfway points of the 12th digit (where one rounding decides),
 * the switch between fixed and exponential notation (1e-5, 1e-4, 1e11, 1e12 and 9.999...e11
 * rounding up), exact ties of the 12th digit, integers, zero of both signs, infinities and NaN. Any
 * byte different fails. */
#include <float.h>
#include <stdint.h>
#include <string.h>

#include "internal.h"
#include "testlib.h"

static long mismatches = 0, checked = 0;

static void one(double v) {
  char a[64], b[64];
  fmb_format_g12(v, a);
  snprintf(b, sizeof b, "%.12g", v);
  checked++;
  if (strcmp(a, b) != 0 && mismatches++ < 10) printf("mismatch: %.17g: '%s' against printf's '%s'\n", v, a, b);
}

static uint64_t state = 0x9E3779B97F4A7C15ULL;
static uint64_t next(void) { /* xorshift64* */
  state ^= state >> 12;
  state ^= state << 25;
  state ^= state >> 27;
  return state * 0x2545F4914F6CDD1DULL;
}

int main(void) {
  for (long i = 0; i < 2000000; ++i) {
    const double mant = (double)(next() >> 11) / 9007199254740992.0; /* [0, 1), 53 bits */
    const int e2 = (int)(next() % 245) - 110;                        /* 2^-110 .. 2^134 */
    const double v = ldexp(0.5 + 0.5 * mant, e2);
    one(next() & 1 ? -v : v);
  }
  for (int e = -40; e <= 40; ++e) {
    const double p = pow(10.0, e);
    one(p);
    one(nextafter(p, 0.0));
    one(nextafter(p, INFINITY));
    for (int k = 1; k < 10; ++k) one(k * p);
  }
  /* halfway cases of the 12th significant digit: d.ddddddddddd5 x 10^e and their neighbours */
  for (long i = 0; i < 200000; ++i) {
    const long long base = (long long)(next() % 900000000000ULL) + 100000000000LL; /* 12 digits */
    const int e = (int)(next() % 40) - 20;
    const double v = ((double)base + 0.5) * pow(10.0, e - 11);
    one(v);
    one(nextafter(v, 0.0));
    one(nextafter(v, INFINITY));
  }
  /* exact ties of the 12th digit: |v| 10^k = N + 1/2 exactly with N of 12 digits, i.e.
     v = m / 2^(k+1) with m = (2N + 1) / 5^k odd (printf rounds them to even) */
  for (long i = 0; i < 200000; ++i) {
    const int k = 1 + (int)(next() % 15);
    long long p5 = 1;
    for (int j = 0; j < k; ++j) p5 *= 5;
    const long long lo = 200000000000LL / p5 + 1, hi = 2000000000000LL / p5;
    const long long m = (lo + (long long)(next() % (unsigned long long)(hi - lo))) | 1;
    const double v = ldexp((double)m, -(k + 1));
    one(v);
    one(-v);
    one(nextafter(v, 0.0));
    one(nextafter(v, INFINITY));
  }
  const double special[] = {0.0,
                            -0.0,
                            1.0,
                            -1.0,
                            0.1,
                            0.5,
                            1e-5,
                            9.99999999999e-6,
                            9.999999999995e-5,
                            1e-4,
                            1e11,
                            1e12,
                            999999999999.0,
                            999999999999.5,
                            999999999999.49,
                            123456789012.5,
                            2.5,
                            1e-300,
                            1e300,
                            DBL_MAX,
                            DBL_MIN,
                            5e-324,
                            INFINITY,
                            -INFINITY,
                            NAN,
                            3.14159265358979,
                            20.0,
                            0.005};
  for (size_t i = 0; i < sizeof special / sizeof special[0]; ++i) one(special[i]);
  for (long k = -100000; k <= 100000; k += 7) one((double)k);
  printf("%ld values, %ld differ from printf's %%.12g\n", checked, mismatches);
  ENSURE(mismatches == 0);
  return fmbt_finish("test_format");
}
