/* vector.c — the serial N_Vector operations IDA spends its own time in, compiled with ours.
 *
 * Debian 12's libsundials 6.4.1 is built without optimization (its functions keep every local on
 * the stack), so a weighted norm of a 108-vector costs ~3,200 instructions instead of ~400, and
 * IDA's vector arithmetic took 28 % of a beam spin-up (docs/performance.md). SUNDIALS' N_Vector is
 * an ops table for exactly this reason: we keep its serial vector (content, clone, destroy) and
 * point the arithmetic at the loops below. IDA clones its work vectors from y, so they all inherit
 * the table. Semantics follow SUNDIALS' serial implementation operation by operation (the masked
 * norm divides by the full length, as there); every loop is elementwise, so an output may alias
 * an input. */
#include <math.h>
#include <nvector/nvector_serial.h>

#include "internal.h"

#define DATA(v) NV_DATA_S(v)
#define LEN(v) NV_LENGTH_S(v)

static void vec_linear_sum(sunrealtype a, N_Vector x, sunrealtype b, N_Vector y, N_Vector z) {
  const sunindextype n = LEN(z);
  const sunrealtype *xd = DATA(x), *yd = DATA(y);
  sunrealtype* zd = DATA(z);
  for (sunindextype i = 0; i < n; ++i) zd[i] = a * xd[i] + b * yd[i];
}

static void vec_const(sunrealtype c, N_Vector z) {
  const sunindextype n = LEN(z);
  sunrealtype* zd = DATA(z);
  for (sunindextype i = 0; i < n; ++i) zd[i] = c;
}

static void vec_prod(N_Vector x, N_Vector y, N_Vector z) {
  const sunindextype n = LEN(z);
  const sunrealtype *xd = DATA(x), *yd = DATA(y);
  sunrealtype* zd = DATA(z);
  for (sunindextype i = 0; i < n; ++i) zd[i] = xd[i] * yd[i];
}

static void vec_div(N_Vector x, N_Vector y, N_Vector z) {
  const sunindextype n = LEN(z);
  const sunrealtype *xd = DATA(x), *yd = DATA(y);
  sunrealtype* zd = DATA(z);
  for (sunindextype i = 0; i < n; ++i) zd[i] = xd[i] / yd[i];
}

static void vec_scale(sunrealtype c, N_Vector x, N_Vector z) {
  const sunindextype n = LEN(z);
  const sunrealtype* xd = DATA(x);
  sunrealtype* zd = DATA(z);
  for (sunindextype i = 0; i < n; ++i) zd[i] = c * xd[i];
}

static void vec_abs(N_Vector x, N_Vector z) {
  const sunindextype n = LEN(z);
  const sunrealtype* xd = DATA(x);
  sunrealtype* zd = DATA(z);
  for (sunindextype i = 0; i < n; ++i) zd[i] = fabs(xd[i]);
}

static void vec_inv(N_Vector x, N_Vector z) {
  const sunindextype n = LEN(z);
  const sunrealtype* xd = DATA(x);
  sunrealtype* zd = DATA(z);
  for (sunindextype i = 0; i < n; ++i) zd[i] = 1.0 / xd[i];
}

static void vec_add_const(N_Vector x, sunrealtype b, N_Vector z) {
  const sunindextype n = LEN(z);
  const sunrealtype* xd = DATA(x);
  sunrealtype* zd = DATA(z);
  for (sunindextype i = 0; i < n; ++i) zd[i] = xd[i] + b;
}

static sunrealtype vec_dot(N_Vector x, N_Vector y) {
  const sunindextype n = LEN(x);
  const sunrealtype *xd = DATA(x), *yd = DATA(y);
  sunrealtype s = 0.0;
  for (sunindextype i = 0; i < n; ++i) s += xd[i] * yd[i];
  return s;
}

static sunrealtype vec_max_norm(N_Vector x) {
  const sunindextype n = LEN(x);
  const sunrealtype* xd = DATA(x);
  sunrealtype m = 0.0;
  for (sunindextype i = 0; i < n; ++i) m = fmax(m, fabs(xd[i]));
  return m;
}

static sunrealtype vec_min(N_Vector x) {
  const sunindextype n = LEN(x);
  const sunrealtype* xd = DATA(x);
  sunrealtype m = xd[0];
  for (sunindextype i = 1; i < n; ++i) m = fmin(m, xd[i]);
  return m;
}

static sunrealtype vec_wsqr_sum(N_Vector x, N_Vector w) {
  const sunindextype n = LEN(x);
  const sunrealtype *xd = DATA(x), *wd = DATA(w);
  sunrealtype s = 0.0;
  for (sunindextype i = 0; i < n; ++i) {
    const sunrealtype p = xd[i] * wd[i];
    s += p * p;
  }
  return s;
}

static sunrealtype vec_wsqr_sum_mask(N_Vector x, N_Vector w, N_Vector id) {
  const sunindextype n = LEN(x);
  const sunrealtype *xd = DATA(x), *wd = DATA(w), *idd = DATA(id);
  sunrealtype s = 0.0;
  for (sunindextype i = 0; i < n; ++i) {
    const sunrealtype p = idd[i] > 0.0 ? xd[i] * wd[i] : 0.0;
    s += p * p;
  }
  return s;
}

static sunrealtype vec_wrms_norm(N_Vector x, N_Vector w) { return sqrt(vec_wsqr_sum(x, w) / (sunrealtype)LEN(x)); }

static sunrealtype vec_wrms_norm_mask(N_Vector x, N_Vector w, N_Vector id) {
  return sqrt(vec_wsqr_sum_mask(x, w, id) / (sunrealtype)LEN(x));
}

/* z = sum_j c[j] X[j] */
static int vec_linear_combination(int nv, sunrealtype* c, N_Vector* X, N_Vector z) {
  const sunindextype n = LEN(z);
  sunrealtype* zd = DATA(z);
  if (nv < 1) return -1;
  const sunrealtype* x0 = DATA(X[0]);
  for (sunindextype i = 0; i < n; ++i) zd[i] = c[0] * x0[i];
  for (int j = 1; j < nv; ++j) {
    const sunrealtype* xj = DATA(X[j]);
    const sunrealtype cj = c[j];
    for (sunindextype i = 0; i < n; ++i) zd[i] += cj * xj[i];
  }
  return 0;
}

/* Z[j] = a[j] x + Y[j] */
static int vec_scale_add_multi(int nv, sunrealtype* a, N_Vector x, N_Vector* Y, N_Vector* Z) {
  const sunindextype n = LEN(x);
  const sunrealtype* xd = DATA(x);
  if (nv < 1) return -1;
  for (int j = 0; j < nv; ++j) {
    const sunrealtype *yd = DATA(Y[j]), aj = a[j];
    sunrealtype* zd = DATA(Z[j]);
    for (sunindextype i = 0; i < n; ++i) zd[i] = aj * xd[i] + yd[i];
  }
  return 0;
}

void fmb_vector_use_fast_ops(N_Vector v) {
  N_Vector_Ops o = v->ops;
  o->nvlinearsum = vec_linear_sum;
  o->nvconst = vec_const;
  o->nvprod = vec_prod;
  o->nvdiv = vec_div;
  o->nvscale = vec_scale;
  o->nvabs = vec_abs;
  o->nvinv = vec_inv;
  o->nvaddconst = vec_add_const;
  o->nvdotprod = vec_dot;
  o->nvmaxnorm = vec_max_norm;
  o->nvwrmsnorm = vec_wrms_norm;
  o->nvwrmsnormmask = vec_wrms_norm_mask;
  o->nvmin = vec_min;
  o->nvdotprodlocal = vec_dot;
  o->nvmaxnormlocal = vec_max_norm;
  o->nvminlocal = vec_min;
  o->nvwsqrsumlocal = vec_wsqr_sum;
  o->nvwsqrsummasklocal = vec_wsqr_sum_mask;
  o->nvlinearcombination = vec_linear_combination;
  o->nvscaleaddmulti = vec_scale_add_multi;
  /* the array forms fall back to the operations above, one vector at a time */
  o->nvlinearsumvectorarray = NULL;
  o->nvscalevectorarray = NULL;
  o->nvconstvectorarray = NULL;
  o->nvwrmsnormvectorarray = NULL;
  o->nvwrmsnormmaskvectorarray = NULL;
  o->nvscaleaddmultivectorarray = NULL;
  o->nvlinearcombinationvectorarray = NULL;
  o->nvdotprodmulti = NULL;
}
