/* format_g12.c — the bytes of printf's "%.12g", seven times faster (21 against 150 ns a value of
 * the ω0 = 15 spin-up's rows, this machine), for the CSV rows.
 *
 * Why: writing a row's numbers with snprintf("%.12g") was 78 M of the 468 M instructions of the
 * ω0 = 15 spin-up as shipped (glibc's printf_fp works on the exact binary value, ~3,500
 * instructions a number), a sixth of the whole run (docs/performance.md, "radau5 as the
 * default"). The rows' bytes must not change (the regression references compare them), so this
 * is printf's "%.12g" exactly, not a shortest round-trip printer:
 *   - 12 significant digits, rounded to nearest from the value's exact binary expansion;
 *   - decimal exponent X of the rounded value: fixed notation when -4 <= X < 12, else d.ddde+XX;
 *   - trailing zeros and a trailing point removed (no '#' flag); "-0" for negative zero.
 * The 12 digits are exact integer arithmetic: |v| = M 2^E (M < 2^53), so |v| 10^(11 - X) =
 * M 5^k 2^(E + k) with k = 11 - X; M 5^k fits 128 bits for k <= 27, and a shift gives the
 * integer part and the exact remainder, so the rounding (to nearest, a tie to even: glibc's in the
 * default rounding mode) is decided exactly. Values that need k outside 0..27 (|v| >= 1e12 or
 * below ~1e-16), subnormals, infinities and NaN go to snprintf. tests/core/test_format.c compares
 * the two on 2 million values over the whole range, on the halfway cases and on exact ties.
 * (The first version multiplied in x86's long double and sent values within 1e-6 of a tie to
 * snprintf: three times slower, its floorl and x87 conversions switching the rounding mode.)
 * Without a 128-bit integer type (a 32-bit target) everything goes to snprintf. */
#include <math.h>
#include <stdio.h>
#include <string.h>

#include "internal.h"

#define G12_DIGITS 12
#define G12_MAX_POW 27 /* 5^27 < 2^63 */

static int fallback(double v, char* out) { return snprintf(out, 32, "%.12g", v); }

/* the six decimal digits of x < 10^6, leading zeros included */
static void write6(unsigned x, char* d) {
  static const char pairs[] = "00010203040506070809101112131415161718192021222324252627282930313233343536373839"
                              "40414243444546474849505152535455565758596061626364656667686970717273747576777879"
                              "8081828384858687888990919293949596979899";
  const unsigned a = x / 10000, r = x % 10000, b = r / 100, c = r % 100;
  memcpy(d, pairs + 2 * a, 2);
  memcpy(d + 2, pairs + 2 * b, 2);
  memcpy(d + 4, pairs + 2 * c, 2);
}

#ifdef __SIZEOF_INT128__ /* GCC's and Clang's on 64-bit targets; __extension__: not ISO C */
__extension__ typedef unsigned __int128 u128;
#endif

int fmb_format_g12(double v, char* out) {
#ifndef __SIZEOF_INT128__
  return fallback(v, out);
#else
  /* 5^k, k = 0..27: 5^27 < 2^63 */
  static const unsigned long long pow5[G12_MAX_POW + 1] = {1ULL,
                                                           5ULL,
                                                           25ULL,
                                                           125ULL,
                                                           625ULL,
                                                           3125ULL,
                                                           15625ULL,
                                                           78125ULL,
                                                           390625ULL,
                                                           1953125ULL,
                                                           9765625ULL,
                                                           48828125ULL,
                                                           244140625ULL,
                                                           1220703125ULL,
                                                           6103515625ULL,
                                                           30517578125ULL,
                                                           152587890625ULL,
                                                           762939453125ULL,
                                                           3814697265625ULL,
                                                           19073486328125ULL,
                                                           95367431640625ULL,
                                                           476837158203125ULL,
                                                           2384185791015625ULL,
                                                           11920928955078125ULL,
                                                           59604644775390625ULL,
                                                           298023223876953125ULL,
                                                           1490116119384765625ULL,
                                                           7450580596923828125ULL};
  static const unsigned long long p11 = 100000000000ULL, p12 = 1000000000000ULL;
  if (!isfinite(v) || v == 0.0) {
    if (v != 0.0) return fallback(v, out);
    strcpy(out, signbit(v) ? "-0" : "0");
    return signbit(v) ? 2 : 1;
  }
  /* |v| = M 2^E exactly, M < 2^53 */
  unsigned long long vbits = 0;
  memcpy(&vbits, &v, sizeof vbits);
  const int biased = (int)((vbits >> 52) & 0x7ff);
  if (biased == 0) return fallback(v, out); /* subnormal: far outside 10^-27 */
  const unsigned long long mant = (vbits & ((1ULL << 52) - 1)) | (1ULL << 52);
  const int e = biased - 1075;
  /* the decimal exponent: |v| in [2^e2, 2^(e2+1)), so X = floor(e2 log10 2) (78913 / 2^18, exact
     for |e2| < 1650; an arithmetic shift floors for e2 < 0 too) or one more, corrected below */
  const int e2 = biased - 1023;
  int x = (e2 * 78913) >> 18;
  unsigned long long digits = 0;
  for (int attempt = 0; attempt < 2 && !digits; ++attempt) {
    /* |v| 10^k = M 5^k 2^(E + k), k = 11 - X: its integer part N has 12 digits when X is right.
       M 5^k < 2^116 is exact in 128 bits; the shift leaves N and the exact remainder. */
    const int k = G12_DIGITS - 1 - x, shift = -(e + k);
    if (k < 0 || k > G12_MAX_POW || shift <= 0 || shift >= 127) return fallback(v, out); /* |v| >= 1e12 or < 1e-16 */
    const u128 prod = (u128)mant * pow5[k];
    const u128 n = prod >> shift, rem = prod - (n << shift), half = (u128)1 << (shift - 1);
    if (n >= p12) { /* X was one too small */
      ++x;
      continue;
    }
    /* to nearest, a tie to even: printf's rounding in the default rounding mode */
    digits = (unsigned long long)n + (rem > half || (rem == half && (n & 1)));
  }
  if (digits < p11) return fallback(v, out); /* not reached: X is never too large */
  if (digits >= p12) {                       /* rounded up to 10^12: one more decimal place */
    digits /= 10;
    ++x;
  }
  char d[G12_DIGITS + 1];
  write6((unsigned)(digits / 1000000), d);     /* two halves of six digits, two digits at a time: */
  write6((unsigned)(digits % 1000000), d + 6); /* not twelve dependent divisions by 10 */
  int nd = G12_DIGITS;                         /* significant digits kept: trailing zeros dropped */
  while (nd > 1 && d[nd - 1] == '0') --nd;
  char* o = out;
  if (v < 0) *o++ = '-';
  if (x >= -4 && x < G12_DIGITS) {
    if (x < 0) { /* 0.000ddd */
      *o++ = '0';
      *o++ = '.';
      for (int i = 0; i < -x - 1; ++i) *o++ = '0';
      memcpy(o, d, (size_t)nd);
      o += nd;
    } else { /* ddd[.ddd] */
      for (int i = 0; i <= x; ++i) *o++ = d[i];
      if (nd > x + 1) {
        *o++ = '.';
        memcpy(o, d + x + 1, (size_t)(nd - x - 1));
        o += nd - x - 1;
      }
    }
  } else { /* d[.ddd]e+XX */
    *o++ = d[0];
    if (nd > 1) {
      *o++ = '.';
      memcpy(o, d + 1, (size_t)(nd - 1));
      o += nd - 1;
    }
    *o++ = 'e';
    *o++ = x < 0 ? '-' : '+';
    const int ax = x < 0 ? -x : x;
    if (ax >= 100) *o++ = (char)('0' + ax / 100);
    *o++ = (char)('0' + ax / 10 % 10);
    *o++ = (char)('0' + ax % 10);
  }
  *o = '\0';
  return (int)(o - out);
#endif
}
