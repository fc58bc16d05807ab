/* vtk.c — the run as a ParaView animation: a VTK XML collection DIR/SCENE.pvd with one
 * unstructured grid DIR/SCENE_NNNNNN.vtu per output row, written directly (ASCII, the format of
 * "VTK File Formats", VTK User's Guide 11th ed., XML section: VTKFile > UnstructuredGrid > Piece
 * with Points, Cells (connectivity, offsets, types), PointData, CellData).
 *
 * What is drawn is engine/drawing.c's (the same as `flexmbd view`); a beam's centreline stations
 * carry the deformation (body frame) and the cross-section rotation as point data.
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

/* the VTK cell type of each drawn part (FMB_DRAW_*) */
static int cell_type(int part) {
  switch (part) {
    case FMB_DRAW_FRAME_AXIS:
    case FMB_DRAW_FORCE_ELEMENT: return VTK_LINE;
    case FMB_DRAW_JOINT: return VTK_VERTEX;
    default: return VTK_POLY_LINE;
  }
}

struct fmbVtk {
  char* dir;
  char* stem; /* the scene's file name without directory and extension */
  fmbSafeFile* pvd_file; /* beside its target until the run closes it (engine/safe_file.c) */
  FILE* pvd;
  long step;
  fmbDrawing* draw; /* what is drawn (engine/drawing.c) */
  double* xy;       /* current positions, 2 per point */
};

static const char pvd_tail[] = "  </Collection>\n</VTKFile>\n";

void fmb_vtk_close(fmbVtk* v) {
  if (!v) return;
  fmb_safe_close(v->pvd_file, 1);
  free(v->dir);
  free(v->stem);
  fmb_drawing_free(v->draw);
  free(v->xy);
  free(v);
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
  v->draw = fmb_drawing_new(m);
  v->xy = v->draw ? calloc(2 * (size_t)v->draw->npoint + 2, sizeof *v->xy) : NULL;
  if (!v->stem || !v->dir || !v->xy) {
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
          t, v->draw->npoint, v->draw->ncell);
  /* positions, and for centreline stations the deformation in the body frame,
     u = A(theta)^T (r - r0) - local, and the cross-section's rotation angle - theta */
  fprintf(f, "      <PointData Vectors=\"deformation\" Scalars=\"rotation\">\n");
  for (int i = 0; i < v->draw->npoint; ++i) {
    const fmbDrawPoint* p = &v->draw->point[i];
    if (p->body == FMB_WORLD) {
      v->xy[2 * i] = p->local[0];
      v->xy[2 * i + 1] = p->local[1];
    } else if (fmb_body_point(m, w, p->body, q, p->local, v->xy + 2 * i, NULL)) {
      v->xy[2 * i] = v->xy[2 * i + 1] = NAN;
    }
  }
  array_open(f, "Float64", "deformation", 3);
  for (int i = 0; i < v->draw->npoint; ++i) {
    const fmbDrawPoint* p = &v->draw->point[i];
    double u[2] = {0.0, 0.0};
    if (p->station >= 0) {
      const double* qb = q + m->body[p->body].qadr;
      const double c = cos(qb[2]), s = sin(qb[2]), dx = v->xy[2 * i] - qb[0], dy = v->xy[2 * i + 1] - qb[1];
      u[0] = c * dx + s * dy - p->local[0];
      u[1] = -s * dx + c * dy - p->local[1];
    }
    fprintf(f, "%s%.12g %.12g 0", i ? " " : "", u[0], u[1]);
  }
  array_close(f);
  array_open(f, "Float64", "rotation", 1);
  for (int i = 0; i < v->draw->npoint; ++i) {
    const fmbDrawPoint* p = &v->draw->point[i];
    double r = 0.0, pos[2], ang = 0.0;
    if (p->station >= 0 && fmb_body_point(m, w, p->body, q, p->local, pos, &ang) == 0) r = ang - q[m->body[p->body].qadr + 2];
    fprintf(f, "%s%.12g", i ? " " : "", r);
  }
  array_close(f);
  fprintf(f, "      </PointData>\n      <CellData Scalars=\"part\">\n");
  array_open(f, "Int32", "part", 1);
  for (int c = 0; c < v->draw->ncell; ++c) fprintf(f, "%s%d", c ? " " : "", v->draw->cell[c].part);
  array_close(f);
  array_open(f, "Int32", "owner", 1);
  for (int c = 0; c < v->draw->ncell; ++c) fprintf(f, "%s%d", c ? " " : "", v->draw->cell[c].owner);
  array_close(f);
  fprintf(f, "      </CellData>\n      <Points>\n");
  array_open(f, "Float64", "Points", 3);
  for (int i = 0; i < v->draw->npoint; ++i) fprintf(f, "%s%.12g %.12g 0", i ? " " : "", v->xy[2 * i], v->xy[2 * i + 1]);
  array_close(f);
  fprintf(f, "      </Points>\n      <Cells>\n");
  array_open(f, "Int64", "connectivity", 1);
  for (int k = 0; k < v->draw->nconn; ++k) fprintf(f, "%s%d", k ? " " : "", v->draw->conn[k]);
  array_close(f);
  array_open(f, "Int64", "offsets", 1);
  for (int c = 0; c < v->draw->ncell; ++c) fprintf(f, "%s%d", c ? " " : "", v->draw->cell[c].first + v->draw->cell[c].count);
  array_close(f);
  array_open(f, "UInt8", "types", 1);
  for (int c = 0; c < v->draw->ncell; ++c) fprintf(f, "%s%d", c ? " " : "", cell_type(v->draw->cell[c].part));
  array_close(f);
  fprintf(f, "      </Cells>\n    </Piece>\n  </UnstructuredGrid>\n</VTKFile>\n");
  const int bad = ferror(f);
  if (fmb_safe_close(sf, !bad) != 0 || bad) return -1;
  /* the new entry replaces the collection's closing tags, which follow it again */
  if (fseek(v->pvd, -(long)(sizeof pvd_tail - 1), SEEK_END) != 0) return -1;
  fprintf(v->pvd, "    <DataSet timestep=\"%.12g\" group=\"\" part=\"0\" file=\"%s\"/>\n%s", t, name, pvd_tail);
  if (fflush(v->pvd) != 0 || ferror(v->pvd)) return -1;
  v->step++;
  return 0;
}
