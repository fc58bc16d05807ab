/* spatial_pair.c — shared pieces of the spatial joints (spatial_pair.h). */
#include "spatial_pair.h"

#include <math.h>
#include <stdlib.h>
#include <string.h>

static void cross(const double a[3], const double b[3], double c[3]) {
  c[0] = a[1] * b[2] - a[2] * b[1];
  c[1] = a[2] * b[0] - a[0] * b[2];
  c[2] = a[0] * b[1] - a[1] * b[0];
}

/* an orthonormal frame (columns, row-major) whose third axis is the unit vector z */
void fmbj3_frame_about(const double z[3], double F[9]) {
  const double helper[3] = {fabs(z[0]) < 0.9 ? 1.0 : 0.0, fabs(z[0]) < 0.9 ? 0.0 : 1.0, 0.0};
  double x[3], y[3];
  cross(helper, z, y);
  const double ny = sqrt(y[0] * y[0] + y[1] * y[1] + y[2] * y[2]);
  for (int i = 0; i < 3; ++i) y[i] /= ny;
  cross(y, z, x);
  for (int i = 0; i < 3; ++i) F[3 * i] = x[i], F[3 * i + 1] = y[i], F[3 * i + 2] = z[i];
}

int fmbj3_parse_points(fmbParser* p, fmbNode item, fmbSpatialPair* sp) {
  memset(sp, 0, sizeof *sp);
  return fmb_get_body(p, item, "body1", FMB_REQUIRED, &sp->body[0]) ||
                 fmb_get_body(p, item, "body2", FMB_REQUIRED, &sp->body[1]) ||
                 fmb_get_point3(p, item, "point1", 0, sp->body[0], sp->point[0]) ||
                 fmb_get_point3(p, item, "point2", 0, sp->body[1], sp->point[1])
             ? -1
             : 0;
}

int fmbj3_direction(fmbParser* p, fmbNode item, const char* key, double dir[3]) {
  if (fmb_get_vec3(p, item, key, 0, dir)) return -1;
  const double n = sqrt(dir[0] * dir[0] + dir[1] * dir[1] + dir[2] * dir[2]);
  if (!(n > 0.0) || !isfinite(n))
    return fmb_parse_error(p, fmb_find_key(p, item, key), "expected a nonzero direction [x, y, z] for '%s'", key);
  for (int i = 0; i < 3; ++i) dir[i] /= n;
  return 0;
}

int fmbj3_set_frame(fmbParser* p, fmbNode item, const double F[9], fmbSpatialPair* sp) {
  for (int k = 0; k < 2; ++k) {
    double pos[3], R[9];
    if (fmb_initial_marker3(p, sp->body[k], sp->point[k], pos, R))
      return fmb_parse_error(p, item, "cannot place point%d on its body in space", k + 1);
    for (int i = 0; i < 3; ++i) /* R^T F */
      for (int c = 0; c < 3; ++c) sp->frame[k][3 * i + c] = R[i] * F[c] + R[3 + i] * F[3 + c] + R[6 + i] * F[6 + c];
  }
  return 0;
}

int fmbj3_parse(fmbParser* p, fmbNode item, const char* axis_key, fmbSpatialPair* sp) {
  double axis[3] = {0.0, 0.0, 1.0}, F[9];
  if (fmbj3_parse_points(p, item, sp) || (axis_key && fmbj3_direction(p, item, axis_key, axis))) return -1;
  fmbj3_frame_about(axis, F);
  return fmbj3_set_frame(p, item, F, sp);
}

void fmbj3_bodies(const void* self, int body[2]) {
  const fmbSpatialPair* sp = self;
  body[0] = sp->body[0];
  body[1] = sp->body[1];
}

int fmbj3_attachment(const void* self, int k, int* body, double local[3]) {
  const fmbSpatialPair* sp = self;
  if (k != 0 && k != 1) return -1;
  *body = sp->body[k];
  for (int i = 0; i < 3; ++i) local[i] = sp->point[k][i];
  return 0;
}

int fmbj3_new(fmbParser* p, fmbNode item, void** self, fmbSpatialPair** sp) {
  *sp = calloc(1, sizeof **sp);
  *self = *sp;
  return *sp ? 0 : fmb_parse_error(p, item, "out of memory");
}

void fmbj3_destroy(void* self) { free(self); }

int fmbj3_eval(const fmbJointEval* ev, const fmbSpatialPair* sp, int derivatives, int ld, fmbSpatialEval* e) {
  double pos[2][3], R[2][9];
  double* G = derivatives ? fmb_eval_scratch(ev) : NULL;
  double* gap_q = G ? G + 3 * (size_t)ld : NULL;
  for (int k = 0; k < 2; ++k) {
    const int c0 = fmb_eval_col0(ev, k), n = fmb_eval_ncoord(ev, k);
    const int rc = fmb_marker3(ev, k, sp->point[k], pos[k], R[k], gap_q ? gap_q + c0 : NULL, G ? G + c0 : NULL, ld);
    if (rc) return rc;
    if (k == 1 && gap_q)
      for (int i = 0; i < 3; ++i)
        for (int c = 0; c < n; ++c) gap_q[(size_t)i * ld + c0 + c] = -gap_q[(size_t)i * ld + c0 + c];
    for (int i = 0; i < 3; ++i) /* X = R frame */
      for (int c = 0; c < 3; ++c)
        e->X[k][3 * i + c] = R[k][3 * i] * sp->frame[k][c] + R[k][3 * i + 1] * sp->frame[k][3 + c] +
                             R[k][3 * i + 2] * sp->frame[k][6 + c];
  }
  for (int i = 0; i < 3; ++i) e->gap[i] = pos[0][i] - pos[1][i];
  e->G = G;
  e->gap_q = gap_q;
  e->ld = ld;
  return 0;
}

/* row of d(A . B)/dq, A = axis ca of frame 1, B = axis cb of frame 2; returns A . B */
static double axes_row(const fmbSpatialEval* e, int ca, int cb, double* row, int ncol0) {
  const double A[3] = {e->X[0][ca], e->X[0][3 + ca], e->X[0][6 + ca]};
  const double B[3] = {e->X[1][cb], e->X[1][3 + cb], e->X[1][6 + cb]};
  if (row && e->G) {
    double AxB[3];
    cross(A, B, AxB);
    for (int c = 0; c < e->ld; ++c) {
      const double s = c < ncol0 ? 1.0 : -1.0; /* body2 sees B x A */
      row[c] = s * (e->G[c] * AxB[0] + e->G[e->ld + c] * AxB[1] + e->G[2 * (size_t)e->ld + c] * AxB[2]);
    }
  }
  return A[0] * B[0] + A[1] * B[1] + A[2] * B[2];
}

/* row of d(gap . A)/dq, A = axis ca of frame 1 (turning with body1); returns gap . A */
static double gap_row(const fmbSpatialEval* e, int ca, double* row, int ncol0) {
  const double A[3] = {e->X[0][ca], e->X[0][3 + ca], e->X[0][6 + ca]};
  const size_t ld = (size_t)e->ld;
  if (row && e->G) {
    double Axd[3];
    cross(A, e->gap, Axd);
    for (int c = 0; c < e->ld; ++c) {
      row[c] = e->gap_q[c] * A[0] + e->gap_q[ld + c] * A[1] + e->gap_q[2 * ld + c] * A[2];
      if (c < ncol0) row[c] += e->G[c] * Axd[0] + e->G[ld + c] * Axd[1] + e->G[2 * ld + c] * Axd[2];
    }
  }
  return e->gap[0] * A[0] + e->gap[1] * A[1] + e->gap[2] * A[2];
}

int fmbj3_rows(const fmbJointEval* ev, const fmbSpatialPair* sp, const fmbj3Row* rows, int nrows, double* phi,
               double* phi_q) {
  const int n0 = fmb_eval_ncoord(ev, 0), ld = n0 + fmb_eval_ncoord(ev, 1);
  fmbSpatialEval e;
  const int rc = fmbj3_eval(ev, sp, phi_q != NULL, ld, &e);
  if (rc) return rc;
  for (int r = 0; r < nrows; ++r) {
    double* row = phi_q ? phi_q + (size_t)r * ld : NULL;
    const fmbj3Row* w = &rows[r];
    if (w->kind == FMBJ3_GAP) {
      phi[r] = e.gap[w->a];
      for (int c = 0; row && c < ld; ++c) row[c] = e.gap_q[(size_t)w->a * ld + c];
    } else if (w->kind == FMBJ3_AXES) {
      phi[r] = axes_row(&e, w->a, w->b, row, n0);
    } else {
      phi[r] = gap_row(&e, w->a, row, n0);
    }
  }
  return 0;
}

double fmbj3_turn(const fmbSpatialEval* e) {
  const double *X1 = e->X[0], *X2 = e->X[1];
  const double x1[3] = {X1[0], X1[3], X1[6]}, z1[3] = {X1[2], X1[5], X1[8]}, x2[3] = {X2[0], X2[3], X2[6]};
  double c[3];
  cross(x1, x2, c);
  return atan2(c[0] * z1[0] + c[1] * z1[1] + c[2] * z1[2], x1[0] * x2[0] + x1[1] * x2[1] + x1[2] * x2[2]);
}

double fmbj3_turn_row(const fmbSpatialEval* e, double* row, int ncol0) {
  if (!row || !e->G) return fmbj3_turn(e);
  double* ds = row; /* d(y1 . x2) first, then combined in place with d(x1 . x2) column by column */
  const double s = axes_row(e, 1, 0, ds, ncol0);
  const double c = axes_row(e, 0, 0, NULL, ncol0);
  const double A[3] = {e->X[0][0], e->X[0][3], e->X[0][6]}, B[3] = {e->X[1][0], e->X[1][3], e->X[1][6]};
  double AxB[3];
  cross(A, B, AxB);
  const double r2 = s * s + c * c;
  for (int k = 0; k < e->ld; ++k) {
    const double sign = k < ncol0 ? 1.0 : -1.0; /* as axes_row: body2 sees B x A */
    const double dc = sign * (e->G[k] * AxB[0] + e->G[e->ld + k] * AxB[1] + e->G[2 * (size_t)e->ld + k] * AxB[2]);
    row[k] = (c * ds[k] - s * dc) / r2;
  }
  return atan2(s, c);
}

double fmbj3_slide(const fmbSpatialEval* e) {
  return -(e->gap[0] * e->X[0][2] + e->gap[1] * e->X[0][5] + e->gap[2] * e->X[0][8]);
}
