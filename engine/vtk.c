/* vtk.c — the run as a ParaView animation: a VTK XML collection DIR/SCENE.pvd with one
 * unstructured grid DIR/SCENE_NNNNNN.vtu per output row, written directly (ASCII, the format of
 * "VTK File Formats", VTK User's Guide 11th ed., XML section: VTKFile > UnstructuredGrid > Piece
 * with Points, Cells (connectivity, offsets, types), PointData, CellData).
 *
 * What is drawn knows no body type, only ops:
 *   - a body with a `centreline` op: a polyline through the centreline stations (marker
 *     positions), with the deformation (body frame) and the cross-section rotation as point data;
 *   - any other body with a frame (ncoord >= 3): its outline through the points its joints attach
 *     to (a bar pinned at both ends is the line between its pins) and its frame's x and y axes;
 *   - a joint with constraint rows: a vertex at its first attachment point;
 *   - a force element with two attachments (a spring): the line between them.
 * Every file goes through fmb_safe_open: written beside its target and renamed into place (each
 * .vtu when complete, the .pvd when the run ends, also when it stops early, so a run that stops
 * leaves a valid collection of the steps written so far, like its CSV). Numbers are printed as
 * the CSV prints them (%.12g). */
#include <errno.h>
#include <math.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>
#include <sys/stat.h>

#include "internal.h"

enum { VTK_VERTEX = 1, VTK_LINE = 3, VTK_POLY_LINE = 4 };
/* cell data "part": what a cell draws */
enum { PART_CENTRELINE = 0, PART_OUTLINE = 1, PART_FRAME_AXIS = 2, PART_JOINT = 3, PART_FORCE_ELEMENT = 4 };

/* one drawn point: a material point of a body (body 0 = the world frame) */
typedef struct {
  int body;
  double local[2];
  int deforms; /* a centreline station: deformation and rotation are point data */
} VtkPoint;

typedef struct {
  int first, count, type, part, owner; /* owner: body or joint index */
} VtkCell;

struct fmbVtk {
  char* dir;
  char* stem; /* the scene's file name without directory and extension */
  fmbSafeFile* pvd_file; /* beside its target until the run closes it (engine/safe_file.c) */
  FILE* pvd;
  long step;
  int npoint, ncell;
  VtkPoint* point;
  VtkCell* cell;
  int* conn; /* connectivity: point indices, cells in order */
  int nconn;
  double* xy; /* current positions, 2 per point */
};

static int add_point(fmbVtk* v, int body, const double local[2], int deforms) {
  VtkPoint* p = &v->point[v->npoint];
  p->body = body;
  p->local[0] = local[0];
  p->local[1] = local[1];
  p->deforms = deforms;
  return v->npoint++;
}

/* a cell through the points idx[0..count), or when idx == NULL through first .. first + count - 1 */
static void add_cell(fmbVtk* v, const int* idx, int first, int count, int type, int part, int owner) {
  VtkCell* c = &v->cell[v->ncell++];
  c->first = v->nconn;
  c->count = count;
  c->type = type;
  c->part = part;
  c->owner = owner;
  for (int i = 0; i < count; ++i) v->conn[v->nconn++] = idx ? idx[i] : first + i;
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

/* fix the geometry once: which points and cells each step draws */
static int build_geometry(fmbVtk* v, const fmbModel* m) {
  enum { MAX_ATTACH = 64 };
  int npt = 0, ncell = 0;
  for (int b = 1; b < m->nbody; ++b) {
    const fmbBodyInst* bi = &m->body[b];
    if (bi->type->centreline) {
      npt += bi->type->centreline(bi->self, 0, NULL);
      ncell += 1;
    } else if (bi->nq >= 3) {
      npt += MAX_ATTACH + 2 + 3; /* outline (closed: +1), origin, frame axes */
      ncell += 3;
    }
  }
  npt += 2 * m->njoint;
  ncell += m->njoint;
  v->point = calloc((size_t)npt + 1, sizeof *v->point);
  v->cell = calloc((size_t)ncell + 1, sizeof *v->cell);
  v->conn = calloc(2 * (size_t)npt + 1, sizeof *v->conn); /* a frame draws 3 points in 4 entries */
  v->xy = calloc(2 * (size_t)npt + 2, sizeof *v->xy);
  double* local = calloc(2 * (size_t)(MAX_ATTACH + 1) + 2, sizeof *local);
  int rc = (v->point && v->cell && v->conn && v->xy && local) ? 0 : -1;
  for (int b = 1; b < m->nbody && rc == 0; ++b) {
    const fmbBodyInst* bi = &m->body[b];
    if (bi->type->centreline) {
      int n = bi->type->centreline(bi->self, 0, NULL);
      double* st = calloc(2 * (size_t)n, sizeof *st);
      if (!st) {
        rc = -1;
        break;
      }
      bi->type->centreline(bi->self, n, st);
      int first = v->npoint;
      for (int i = 0; i < n; ++i) add_point(v, b, st + 2 * i, 1);
      add_cell(v, NULL, first, n, VTK_POLY_LINE, PART_CENTRELINE, b);
      free(st);
    } else if (bi->nq >= 3) {
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
        int first = v->npoint, count = n >= 3 ? n + 1 : n;
        for (int i = 0; i < count; ++i) add_point(v, b, local + 2 * i, 0);
        add_cell(v, NULL, first, count, VTK_POLY_LINE, PART_OUTLINE, b);
      }
      /* the frame: axes a fifth of the body's size long (0.1 m for a body with no joints) */
      const double len = size > 0.0 ? 0.2 * size : 0.1;
      const double axes[3][2] = {{0.0, 0.0}, {len, 0.0}, {0.0, len}};
      int origin = add_point(v, b, axes[0], 0);
      add_point(v, b, axes[1], 0);
      add_point(v, b, axes[2], 0);
      const int x_axis[2] = {origin, origin + 1}, y_axis[2] = {origin, origin + 2};
      add_cell(v, x_axis, 0, 2, VTK_LINE, PART_FRAME_AXIS, b);
      add_cell(v, y_axis, 0, 2, VTK_LINE, PART_FRAME_AXIS, b);
    }
  }
  for (int j = 0; j < m->njoint && rc == 0; ++j) {
    const fmbJointInst* ji = &m->joint[j];
    if (!ji->type->attachment) continue;
    int body[2];
    double pt[2][2];
    if (ji->type->attachment(ji->self, 0, &body[0], pt[0])) continue;
    int first = add_point(v, body[0], pt[0], 0);
    if (ji->nrows == 0 && ji->type->attachment(ji->self, 1, &body[1], pt[1]) == 0) {
      add_point(v, body[1], pt[1], 0);
      add_cell(v, NULL, first, 2, VTK_LINE, PART_FORCE_ELEMENT, j);
    } else {
      add_cell(v, NULL, first, 1, VTK_VERTEX, PART_JOINT, j);
    }
  }
  free(local);
  return rc;
}

static const char pvd_tail[] = "  </Collection>\n</VTKFile>\n";

void fmb_vtk_close(fmbVtk* v) {
  if (!v) return;
  fmb_safe_close(v->pvd_file, 1);
  free(v->dir);
  free(v->stem);
  free(v->point);
  free(v->cell);
  free(v->conn);
  free(v->xy);
  free(v);
}

/* `text` as an XML attribute value: a scene named `a&b.yaml` or `"q".yaml` must not break the
   collection file (its frames' names carry the scene's) */
static void fputs_xml_attribute(const char* text, FILE* f) {
  for (const char* c = text; *c; ++c) switch (*c) {
      case '&': fputs("&amp;", f); break;
      case '<': fputs("&lt;", f); break;
      case '>': fputs("&gt;", f); break;
      case '"': fputs("&quot;", f); break;
      case '\'': fputs("&apos;", f); break;
      default: fputc(*c, f);
    }
}

fmbVtk* fmb_vtk_open(const fmbModel* m, const char* dir, fmbDiag* diag) {
  if (mkdir(dir, 0777) != 0 && errno != EEXIST) {
    fmb_diag_set(diag, FMB_EXIT_BAD_INPUT, dir, 0, 0, "cannot create the VTK directory: %s", strerror(errno));
    return NULL;
  }
  fmbVtk* v = calloc(1, sizeof *v);
  if (!v) return NULL;
  const char* base = strrchr(m->path, '/');
  base = base ? base + 1 : m->path;
  v->stem = strdup(base);
  v->dir = strdup(dir);
  if (!v->stem || !v->dir || build_geometry(v, m)) {
    fmb_diag_set(diag, FMB_EXIT_SOLVER, m->path, 0, 0, "out of memory setting up the VTK output");
    fmb_vtk_close(v);
    return NULL;
  }
  char* ext = strrchr(v->stem, '.');
  if (ext && ext != v->stem) *ext = '\0';
  char path[1200];
  snprintf(path, sizeof path, "%s/%s.pvd", dir, v->stem);
  char err[300] = "";
  v->pvd_file = fmb_safe_open(path, err, sizeof err);
  v->pvd = fmb_safe_stream(v->pvd_file);
  if (!v->pvd) {
    fmb_diag_set(diag, FMB_EXIT_BAD_INPUT, path, 0, 0, "cannot write the VTK collection: %s", err[0] ? err : strerror(errno));
    fmb_vtk_close(v);
    return NULL;
  }
  fprintf(v->pvd, "<?xml version=\"1.0\"?>\n<VTKFile type=\"Collection\" version=\"0.1\" byte_order=\"LittleEndian\">\n"
                  "  <Collection>\n%s", pvd_tail);
  fflush(v->pvd);
  return v;
}

static void array_open(FILE* f, const char* type, const char* name, int ncomp) {
  fprintf(f, "        <DataArray type=\"%s\" Name=\"%s\" NumberOfComponents=\"%d\" format=\"ascii\">\n         ", type, name,
          ncomp);
}
static void array_close(FILE* f) { fprintf(f, "\n        </DataArray>\n"); }

/* 0 ok; -1 a file could not be written (the caller stops the run, as for the CSV) */
int fmb_vtk_step(fmbVtk* v, const fmbModel* m, fmbWorkspace* w, double t, const double* y) {
  const double* q = y;
  char name[600], path[1400];
  snprintf(name, sizeof name, "%s_%06ld.vtu", v->stem, v->step);
  snprintf(path, sizeof path, "%s/%s", v->dir, name);
  fmbSafeFile* sf = fmb_safe_open(path, NULL, 0);
  FILE* f = fmb_safe_stream(sf);
  if (!f) {
    fmb_safe_close(sf, 0);
    return -1;
  }
  fprintf(f, "<?xml version=\"1.0\"?>\n<VTKFile type=\"UnstructuredGrid\" version=\"0.1\" byte_order=\"LittleEndian\">\n"
             "  <UnstructuredGrid>\n    <FieldData>\n"
             "      <DataArray type=\"Float64\" Name=\"TimeValue\" NumberOfTuples=\"1\" format=\"ascii\">%.12g</DataArray>\n"
             "    </FieldData>\n    <Piece NumberOfPoints=\"%d\" NumberOfCells=\"%d\">\n",
          t, v->npoint, v->ncell);
  /* positions, and for centreline stations the deformation in the body frame,
     u = A(theta)^T (r - r0) - local, and the cross-section's rotation angle - theta */
  fprintf(f, "      <PointData Vectors=\"deformation\" Scalars=\"rotation\">\n");
  for (int i = 0; i < v->npoint; ++i) {
    const VtkPoint* p = &v->point[i];
    if (p->body == FMB_WORLD) {
      v->xy[2 * i] = p->local[0];
      v->xy[2 * i + 1] = p->local[1];
    } else if (fmb_body_point(m, w, p->body, q, p->local, v->xy + 2 * i, NULL)) {
      v->xy[2 * i] = v->xy[2 * i + 1] = NAN;
    }
  }
  array_open(f, "Float64", "deformation", 3);
  for (int i = 0; i < v->npoint; ++i) {
    const VtkPoint* p = &v->point[i];
    double u[2] = {0.0, 0.0};
    if (p->deforms) {
      const double* qb = q + m->body[p->body].qadr;
      const double c = cos(qb[2]), s = sin(qb[2]), dx = v->xy[2 * i] - qb[0], dy = v->xy[2 * i + 1] - qb[1];
      u[0] = c * dx + s * dy - p->local[0];
      u[1] = -s * dx + c * dy - p->local[1];
    }
    fprintf(f, "%s%.12g %.12g 0", i ? " " : "", u[0], u[1]);
  }
  array_close(f);
  array_open(f, "Float64", "rotation", 1);
  for (int i = 0; i < v->npoint; ++i) {
    const VtkPoint* p = &v->point[i];
    double r = 0.0, pos[2], ang = 0.0;
    if (p->deforms && fmb_body_point(m, w, p->body, q, p->local, pos, &ang) == 0) r = ang - q[m->body[p->body].qadr + 2];
    fprintf(f, "%s%.12g", i ? " " : "", r);
  }
  array_close(f);
  fprintf(f, "      </PointData>\n      <CellData Scalars=\"part\">\n");
  array_open(f, "Int32", "part", 1);
  for (int c = 0; c < v->ncell; ++c) fprintf(f, "%s%d", c ? " " : "", v->cell[c].part);
  array_close(f);
  array_open(f, "Int32", "owner", 1);
  for (int c = 0; c < v->ncell; ++c) fprintf(f, "%s%d", c ? " " : "", v->cell[c].owner);
  array_close(f);
  fprintf(f, "      </CellData>\n      <Points>\n");
  array_open(f, "Float64", "Points", 3);
  for (int i = 0; i < v->npoint; ++i) fprintf(f, "%s%.12g %.12g 0", i ? " " : "", v->xy[2 * i], v->xy[2 * i + 1]);
  array_close(f);
  fprintf(f, "      </Points>\n      <Cells>\n");
  array_open(f, "Int64", "connectivity", 1);
  for (int k = 0; k < v->nconn; ++k) fprintf(f, "%s%d", k ? " " : "", v->conn[k]);
  array_close(f);
  array_open(f, "Int64", "offsets", 1);
  for (int c = 0; c < v->ncell; ++c) fprintf(f, "%s%d", c ? " " : "", v->cell[c].first + v->cell[c].count);
  array_close(f);
  array_open(f, "UInt8", "types", 1);
  for (int c = 0; c < v->ncell; ++c) fprintf(f, "%s%d", c ? " " : "", v->cell[c].type);
  array_close(f);
  fprintf(f, "      </Cells>\n    </Piece>\n  </UnstructuredGrid>\n</VTKFile>\n");
  const int bad = ferror(f);
  if (fmb_safe_close(sf, !bad) != 0 || bad) return -1;
  /* the new entry replaces the collection's closing tags, which follow it again */
  if (fseek(v->pvd, -(long)(sizeof pvd_tail - 1), SEEK_END) != 0) return -1;
  fprintf(v->pvd, "    <DataSet timestep=\"%.12g\" group=\"\" part=\"0\" file=\"", t);
  fputs_xml_attribute(name, v->pvd);
  fprintf(v->pvd, "\"/>\n%s", pvd_tail);
  if (fflush(v->pvd) != 0 || ferror(v->pvd)) return -1;
  v->step++;
  return 0;
}
