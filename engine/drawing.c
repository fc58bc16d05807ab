/* drawing.c — what a mechanism looks like (flexmbd.h, fmb_drawing_new): the points and cells
 * that the ParaView animation (vtk.c) and `flexmbd view` (tools/cmd_view.c) draw, fixed once at
 * load from the types' ops alone (the engine knows no body type):
 *   - a body with a `centreline` op: a polyline through its stations (those of BODY.shape);
 *   - any other body with a frame (ncoord >= 3): its outline through the points its joints attach
 *     to (a bar pinned at both ends is the line between its pins; three or more points a closed
 *     polygon) and its frame's x and y axes, a fifth of the body's size long;
 *   - a joint with constraint rows: a vertex at its first attachment point;
 *   - a force element with two attachments (a spring): the line between them.
 * In a spatial scene (dimension 3) the same from the spatial ops (drawing_new3): a centreline's
 * stations [x, y] are the body's [x, y, 0]; any other body is the line or polygon through its
 * joints' attachment3 points and its frame's x, y, z axes; a joint a vertex at its first point.
 * Where the points are at a state is the caller's business (fmb_body_point, fmb_body_point3, or
 * CSV columns). */
#include <math.h>
#include <stdlib.h>

#include "internal.h"

enum { MAX_ATTACH = 64 };

static int add_point(fmbDrawing* d, int body, const double local[2], int station) {
  fmbDrawPoint* p = &d->point[d->npoint];
  p->body = body;
  p->local[0] = local[0];
  p->local[1] = local[1];
  p->station = station;
  return d->npoint++;
}

/* a cell through the points idx[0..count), or when idx == NULL through first .. first + count - 1 */
static void add_cell(fmbDrawing* d, const int* idx, int first, int count, int part, int owner) {
  fmbDrawCell* c = &d->cell[d->ncell++];
  c->first = d->nconn;
  c->count = count;
  c->part = part;
  c->owner = owner;
  for (int i = 0; i < count; ++i) d->conn[d->nconn++] = idx ? idx[i] : first + i;
}

/* the attachment points of every joint on body b, in the body frame; returns how many */
static int attachments_of(const fmbModel* m, int b, double* local, int cap) {
  int n = 0;
  for (int j = 0; j < m->njoint; ++j) {
    const fmbJointInst* ji = &m->joint[j];
    if (!ji->type->attachment) continue;
    for (int k = 0; k < 2; ++k) {
      int body;
      double pt[2];
      if (ji->type->attachment(ji->self, k, &body, pt) || body != b || n == cap) continue;
      local[2 * n] = pt[0];
      local[2 * n + 1] = pt[1];
      ++n;
    }
  }
  return n;
}

/* order points counter-clockwise about their centroid, so three or more make a simple polygon */
static void sort_by_angle(double* pts, int n) {
  double cx = 0.0, cy = 0.0;
  for (int i = 0; i < n; ++i) {
    cx += pts[2 * i] / n;
    cy += pts[2 * i + 1] / n;
  }
  for (int i = 1; i < n; ++i) /* insertion sort: a handful of points */
    for (int k = i; k > 0; --k) {
      double a0 = atan2(pts[2 * k - 1] - cy, pts[2 * k - 2] - cx), a1 = atan2(pts[2 * k + 1] - cy, pts[2 * k] - cx);
      if (a0 <= a1) break;
      for (int c = 0; c < 2; ++c) {
        double tmp = pts[2 * k - 2 + c];
        pts[2 * k - 2 + c] = pts[2 * k + c];
        pts[2 * k + c] = tmp;
      }
    }
}

void fmb_drawing_free(fmbDrawing* d) {
  if (!d) return;
  free(d->local3);
  free(d->point);
  free(d->cell);
  free(d->conn);
  free(d);
}

/* a spatial point: local3 in full, its x, y in local (what planar readers of the drawing see) */
static int add_point3(fmbDrawing* d, int body, const double local[3], int station) {
  const int i = add_point(d, body, local, station);
  for (int k = 0; k < 3; ++k) d->local3[3 * i + k] = local[k];
  return i;
}

/* the attachment3 points of every spatial joint on body b, in the body frame; returns how many */
static int attachments3_of(const fmbModel* m, int b, double* local, int cap) {
  int n = 0;
  for (int j = 0; j < m->njoint; ++j) {
    const fmbJointInst* ji = &m->joint[j];
    if (ji->type->abi < FMB_PLUGIN_ABI_MAJOR * 1000 + 3 || !ji->type->attachment3) continue; /* ABI 3.3 */
    for (int k = 0; k < 2; ++k) {
      int body;
      double pt[3];
      if (ji->type->attachment3(ji->self, k, &body, pt) || body != b || n == cap) continue;
      for (int c = 0; c < 3; ++c) local[3 * n + c] = pt[c];
      ++n;
    }
  }
  return n;
}

/* a point in the drawing's dimension: local [x, y, z] (z read in space only) */
static int add_point_in(fmbDrawing* d, int body, const double local[3], int station) {
  return d->local3 ? add_point3(d, body, local, station) : add_point(d, body, local, station);
}

/* attachment k of a joint in the scene's dimension (attachment3 in space, ABI 3.3); 0 ok */
static int joint_point(const fmbModel* m, const fmbJointInst* ji, int k, int* body, double pt[3]) {
  if (m->dimension == 3)
    return ji->type->abi >= FMB_PLUGIN_ABI_MAJOR * 1000 + 3 && ji->type->attachment3
               ? ji->type->attachment3(ji->self, k, body, pt)
               : -1;
  return ji->type->attachment ? ji->type->attachment(ji->self, k, body, pt) : -1;
}

/* body b's centreline: a polyline through its stations (in space the body's [x, y, 0]); 0 ok */
static int add_centreline(fmbDrawing* d, const fmbBodyInst* bi, int b) {
  const int n = bi->type->centreline(bi->self, 0, NULL);
  double* st = calloc(2 * (size_t)n + 2, sizeof *st);
  if (!st) return -1;
  bi->type->centreline(bi->self, n, st);
  const int first = d->npoint;
  for (int i = 0; i < n; ++i) add_point_in(d, b, (const double[3]){st[2 * i], st[2 * i + 1], 0.0}, i);
  add_cell(d, NULL, first, n, FMB_DRAW_CENTRELINE, b);
  free(st);
  return 0;
}

/* every joint: one with constraint rows a vertex at its first point, a force element with two
   points (a spring) the line between them */
static void add_joints(const fmbModel* m, fmbDrawing* d) {
  for (int j = 0; j < m->njoint; ++j) {
    const fmbJointInst* ji = &m->joint[j];
    int body[2];
    double pt[2][3] = {{0.0, 0.0, 0.0}, {0.0, 0.0, 0.0}};
    if (joint_point(m, ji, 0, &body[0], pt[0])) continue;
    const int first = add_point_in(d, body[0], pt[0], -1);
    if (ji->nrows == 0 && joint_point(m, ji, 1, &body[1], pt[1]) == 0) {
      add_point_in(d, body[1], pt[1], -1);
      add_cell(d, NULL, first, 2, FMB_DRAW_FORCE_ELEMENT, j);
    } else {
      add_cell(d, NULL, first, 1, FMB_DRAW_JOINT, j);
    }
  }
}

/* does body b get an outline and a frame (planar: a frame in its first coordinates; spatial: a marker3)? */
static int framed(const fmbModel* m, const fmbBodyInst* bi) {
  return m->dimension == 3 ? bi->nq > 0 && bi->marker3 != NULL : bi->nq >= 3;
}

/* the most points and cells the scene's parts take */
static void count_parts(const fmbModel* m, int* npt, int* ncell) {
  const int axes = m->dimension == 3 ? 3 : 2;
  *npt = *ncell = 0;
  for (int b = 1; b < m->nbody; ++b) {
    const fmbBodyInst* bi = &m->body[b];
    if (bi->type->centreline) {
      *npt += bi->type->centreline(bi->self, 0, NULL);
      *ncell += 1;
    } else if (framed(m, bi)) {
      *npt += MAX_ATTACH + 2 + axes; /* outline (closed: +1), origin, frame axes */
      *ncell += 1 + axes;
    }
  }
  *npt += 2 * m->njoint;
  *ncell += m->njoint;
}

/* the drawing of a spatial scene (the file's comment): the planar one's parts from the spatial ops */
static int drawing_new3(const fmbModel* m, fmbDrawing* d) {
  int npt, ncell;
  count_parts(m, &npt, &ncell);
  d->dimension = 3;
  d->point = calloc((size_t)npt + 1, sizeof *d->point);
  d->local3 = calloc(3 * (size_t)npt + 3, sizeof *d->local3);
  d->cell = calloc((size_t)ncell + 1, sizeof *d->cell);
  d->conn = calloc(2 * (size_t)npt + 1, sizeof *d->conn); /* a frame draws 4 points in 6 entries */
  double* local = calloc(3 * (size_t)(MAX_ATTACH + 1) + 3, sizeof *local);
  int rc = (d->point && d->local3 && d->cell && d->conn && local) ? 0 : -1;
  for (int b = 1; b < m->nbody && rc == 0; ++b) {
    const fmbBodyInst* bi = &m->body[b];
    if (bi->type->centreline) {
      rc = add_centreline(d, bi, b);
    } else if (framed(m, bi)) {
      int n = attachments3_of(m, b, local, MAX_ATTACH);
      double size = 0.0;
      for (int i = 0; i < n; ++i) size = fmax(size, hypot(hypot(local[3 * i], local[3 * i + 1]), local[3 * i + 2]));
      if (n == 1) { /* hanging from one point: the line from it to the origin */
        local[3] = local[4] = local[5] = 0.0;
        n = 2;
      }
      if (n >= 2) {
        if (n >= 3) /* closed, in the joints' order (no plane to sort the points in) */
          for (int c = 0; c < 3; ++c) local[3 * n + c] = local[c];
        const int first = d->npoint, count = n >= 3 ? n + 1 : n;
        for (int i = 0; i < count; ++i) add_point3(d, b, local + 3 * i, -1);
        add_cell(d, NULL, first, count, FMB_DRAW_OUTLINE, b);
      }
      /* the frame: axes a fifth of the body's size long (0.1 m for a body with no joints) */
      const double len = size > 0.0 ? 0.2 * size : 0.1;
      const double axes[4][3] = {{0.0, 0.0, 0.0}, {len, 0.0, 0.0}, {0.0, len, 0.0}, {0.0, 0.0, len}};
      const int origin = add_point3(d, b, axes[0], -1);
      for (int k = 1; k <= 3; ++k) {
        add_point3(d, b, axes[k], -1);
        const int axis[2] = {origin, origin + k};
        add_cell(d, axis, 0, 2, FMB_DRAW_FRAME_AXIS, b);
      }
    }
  }
  if (rc == 0) add_joints(m, d);
  free(local);
  return rc;
}

fmbDrawing* fmb_drawing_new(const fmbModel* m) {
  if (!m) return NULL;
  fmbDrawing* d = calloc(1, sizeof *d);
  if (!d) return NULL;
  d->dimension = 2;
  if (m->dimension == 3) {
    if (drawing_new3(m, d)) {
      fmb_drawing_free(d);
      return NULL;
    }
    return d;
  }
  int npt, ncell;
  count_parts(m, &npt, &ncell);
  d->point = calloc((size_t)npt + 1, sizeof *d->point);
  d->cell = calloc((size_t)ncell + 1, sizeof *d->cell);
  d->conn = calloc(2 * (size_t)npt + 1, sizeof *d->conn); /* a frame draws 3 points in 4 entries */
  double* local = calloc(2 * (size_t)(MAX_ATTACH + 1) + 2, sizeof *local);
  int rc = (d->point && d->cell && d->conn && local) ? 0 : -1;
  for (int b = 1; b < m->nbody && rc == 0; ++b) {
    const fmbBodyInst* bi = &m->body[b];
    if (bi->type->centreline) {
      rc = add_centreline(d, bi, b);
    } else if (framed(m, bi)) {
      int n = attachments_of(m, b, local, MAX_ATTACH);
      double size = 0.0;
      for (int i = 0; i < n; ++i) size = fmax(size, hypot(local[2 * i], local[2 * i + 1]));
      if (n == 1) { /* a link hanging from one pin: the line from its pin to its centre */
        local[2] = local[3] = 0.0;
        n = 2;
      }
      if (n >= 2) {
        if (n >= 3) {
          sort_by_angle(local, n);
          local[2 * n] = local[0];
          local[2 * n + 1] = local[1];
        }
        int first = d->npoint, count = n >= 3 ? n + 1 : n;
        for (int i = 0; i < count; ++i) add_point(d, b, local + 2 * i, -1);
        add_cell(d, NULL, first, count, FMB_DRAW_OUTLINE, b);
      }
      /* the frame: axes a fifth of the body's size long (0.1 m for a body with no joints) */
      const double len = size > 0.0 ? 0.2 * size : 0.1;
      const double axes[3][2] = {{0.0, 0.0}, {len, 0.0}, {0.0, len}};
      int origin = add_point(d, b, axes[0], -1);
      add_point(d, b, axes[1], -1);
      add_point(d, b, axes[2], -1);
      const int x_axis[2] = {origin, origin + 1}, y_axis[2] = {origin, origin + 2};
      add_cell(d, x_axis, 0, 2, FMB_DRAW_FRAME_AXIS, b);
      add_cell(d, y_axis, 0, 2, FMB_DRAW_FRAME_AXIS, b);
    }
  }
  if (rc == 0) add_joints(m, d);
  free(local);
  if (rc) {
    fmb_drawing_free(d);
    return NULL;
  }
  return d;
}
