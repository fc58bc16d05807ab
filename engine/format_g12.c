/* format_g12.c — the bytes of printf's "%.12g", about ten times faster, for the CSV rows.
 *
 * Why: writing a row's numbers with snprintf("%.12g") was 78 M of the 468 M instructions of the
 * ω0 = 15 spin-up as shipped (glibc's printf_fp works on the exact binary value, ~3,500
 * instructions a number), a sixth of the whole run (docs/performance.md, "radau5 as the
 * default"). The rows' bytes must not change (the regression references compare them), so this
 * is printf's "%.12g" exactly, not a shortest round-trip printer:
 *   - 12 significant digits, rounded to nearest from the value's exact binary expansion;
 *   - decimal exponent X of the rounded value: fixed notation when -4 <= X < 12, else d.ddde+XX;
 *   - trailing zeros and a trailing point removed (no '#' flag); "-0" for negative zero.
 * The 12 digits come from |v| x 10^(11 - X) in long double (x86's 64-bit mantissa): powers of ten
 * up to 10^27 are exact there, so the product or quotient carries one rounding, 2^-64 relative,
 * ~5e-9 of the last digit. Where that could decide the rounding (the digit's fraction within 1e-6
 * of one half) or where the scale is out of the exact range, the value goes to snprintf. So the
 * result is snprintf's whenever this code answers at all; tests/core/test_format.c compares the
 * two on 2 million values over the whole range and on the halfway cases. Off x86 (no 80-bit long
 * double) everything goes to snprintf. */
#include <float.h>
#include <math.h>
#include <stdio.h>
#include <string.h>

#include "internal.h"

#define G12_DIGITS 12
#define G12_MAX_POW 27 /* 10^27 = 2^27 5^27, 5^27 < 2^63: exact in a 64-bit mantissa */

static int fallback(double v, char* out) { return snprintf(out, 32, "%.12g", v); }

int fmb_format_g12(double v, char* out) {
#if LDBL_MANT_DIG != 64 || !(defined(__x86_64__) || defined(__i386__)) /* the x87 80-bit format read below */
  return fallback(v, out);
#else
  /* integers, so each literal is exact in a 64-bit mantissa */
  static const long double pow10[G12_MAX_POW + 1] = {
      1e0L,  1e1L,  1e2L,  1e3L,  1e4L,  1e5L,  1e6L,  1e7L,  1e8L,  1e9L,  1e10L, 1e11L, 1e12L, 1e13L,
      1e14L, 1e15L, 1e16L, 1e17L, 1e18L, 1e19L, 1e20L, 1e21L, 1e22L, 1e23L, 1e24L, 1e25L, 1e26L, 1e27L};
  if (!isfinite(v) || v == 0.0) {
    if (v != 0.0) return fallback(v, out);
    strcpy(out, signbit(v) ? "-0" : "0");
    return signbit(v) ? 2 : 1;
  }
  const long double a = fabsl((long double)v);
  /* the decimal exponent from the binary one: |v| in [2^e2, 2^(e2+1)), so x = floor(e2 log10 2)
     (78913 / 2^18, exact for |e2| < 1650) or one more, corrected below; no log10() call */
  unsigned long long vbits = 0;
  memcpy(&vbits, &v, sizeof vbits);
  const int e2 = (int)((vbits >> 52) & 0x7ff) - 1023; /* subnormals: far outside 10^±27, to snprintf */
  int x = (e2 * 78913) >> 18;                         /* an arithmetic shift: floor for e2 < 0 too */
  long double m = 0.0L;
  unsigned long long digits = 0;
  for (int attempt = 0; attempt < 3; ++attempt) {
    const int k = G12_DIGITS - 1 - x;
    if (k > G12_MAX_POW || -k > G12_MAX_POW) return fallback(v, out);
    m = k >= 0 ? a * pow10[k] : a / pow10[-k];
    if (m < pow10[G12_DIGITS - 1]) { /* fewer than 12 digits before the point */
      --x;
      continue;
    }
    if (m >= pow10[G12_DIGITS]) {
      ++x;
      continue;
    }
    /* m rounded to the nearest integer without floorl() or a conversion, both of which switch
       the x87 rounding mode (fldcw: 55 % of this function's cycles): 2^63 + m, with 1 as its
       last place in a 64-bit mantissa, is rounded to nearest by the addition, and its mantissa
       bits are then 2^63 + the integer (m < 10^12, exact below 2^63). */
    const long double shifted = m + 9223372036854775808.0L;
    unsigned long long bits = 0;
    memcpy(&bits, &shifted, sizeof bits); /* x86's 80-bit format: the mantissa first */
    const unsigned long long nearest = bits - 9223372036854775808ULL;
    const long double off = m - (long double)nearest; /* in [-1/2, 1/2] (exact) when rounding to nearest */
    /* too close to halfway to decide (or another rounding mode is set: snprintf knows it) */
    if (fabsl(off) > 0.5L - 1e-6L) return fallback(v, out);
    digits = nearest;
    break;
  }
  if (!digits) return fallback(v, out);
  if (digits >= 1000000000000ULL) { /* rounded up to 10^12: one more decimal place */
    digits /= 10;
    ++x;
  }
  char d[G12_DIGITS + 1];
  for (int i = G12_DIGITS - 1; i >= 0; --i, digits /= 10) d[i] = (char)('0' + digits % 10);
  int nd = G12_DIGITS; /* significant digits kept: trailing zeros dropped */
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
