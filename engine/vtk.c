/* vtk.c — the run as a ParaView animation: a VTK XML collection DIR/SCENE.pvd with one
 * unstructured grid DIR/SCENE_NNNNNN.vtu per output row (or every Nth: --vtk-every N), written
 * directly in the format of "VTK File Formats", VTK User's Guide 11th ed., XML section: VTKFile >
 * UnstructuredGrid > Piece with Points, Cells (connectivity, offsets, types), PointData, CellData,
 * every array in raw binary appended data (<AppendedData encoding="raw">: per array a UInt64 byte
 * count and the values in the machine's byte order, declared in byte_order): exact doubles, about
 * a third of the ASCII size and no number formatting per point.
 *
 * What is drawn is engine/drawing.c's (the same as `flexmbd view`); a beam's centreline stations
 * carry the deformation (body frame) and the cross-section rotation as point data. In a spatial
 * scene (dimension 3) every point of a body carries instead the axes of the frame there, the
 * columns of the marker3's rotation R as point vectors frame_x, frame_y, frame_z (a centreline's
 * cross-section frame: frame_y, frame_z span the section); the ground's points carry zeros.
 * Every file goes through fmb_safe_open: written beside its target and renamed into place (each
 * .vtu when complete, the .pvd when the run ends, also when it stops early, so a run that stops
 * leaves a valid collection of the steps written so far, like its CSV). */
#include <errno.h>
#include <math.h>
#include <stdint.h>
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
  char* stem;            /* the scene's file name without directory and extension */
  fmbSafeFile* pvd_file; /* beside its target until the run closes it (engine/safe_file.c) */
  FILE* pvd;
  long step;
  fmbDrawing* draw; /* what is drawn (engine/drawing.c) */
  int every;        /* write every Nth output row (--vtk-every) */
  long row;         /* output rows seen */
  /* one step's arrays, allocated once: points (3 per point), deformation (3), rotation (1),
     cell and connectivity integers */
  double *pts, *deform, *rot;
  double* frame; /* spatial: R's columns at each point, frame_x, frame_y, frame_z (3 x 3 np) */
  int32_t* i32;
  int64_t* i64;
  uint8_t* u8;
};

static const char pvd_tail[] = "  </Collection>\n</VTKFile>\n";

void fmb_vtk_close(fmbVtk* v) {
  if (!v) return;
  fmb_safe_close(v->pvd_file, 1);
  free(v->dir);
  free(v->stem);
  fmb_drawing_free(v->draw);
  free(v->pts);
  free(v->deform);
  free(v->rot);
  free(v->frame);
  free(v->i32);
  free(v->i64);
  free(v->u8);
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
  v->every = 1;
  if (v->draw) {
    const size_t np = (size_t)v->draw->npoint + 1, nc = (size_t)v->draw->ncell + 1;
    const size_t nint = (size_t)v->draw->nconn + nc;
    v->pts = calloc(3 * np, sizeof *v->pts);
    v->deform = calloc(3 * np, sizeof *v->deform);
    v->rot = calloc(np, sizeof *v->rot);
    v->frame = calloc(9 * np, sizeof *v->frame);
    v->i32 = calloc(nc, sizeof *v->i32);
    v->i64 = calloc(nint, sizeof *v->i64);
    v->u8 = calloc(nc, sizeof *v->u8);
  }
  if (!v->stem || !v->dir || !v->pts || !v->deform || !v->rot || !v->frame || !v->i32 || !v->i64 || !v->u8) {
    fmb_diag_set(diag, FMB_EXIT_SOLVER, m->path, 0, 0, "out of memory setting up the VTK output");
    fmb_vtk_close(v);
    return NULL;
  }
  char* ext = strrchr(v->stem, '.');
  if (ext && ext != v->stem) *ext = '\0';
  char path[1200];
  snprintf(path, sizeof path, "%s/%s.pvd", dir, v->stem);
  char err[300] = "";
  v->pvd_file = fmb_safe_open_guarded(path, m->inputs, err, sizeof err);
  v->pvd = fmb_safe_stream(v->pvd_file);
  if (!v->pvd) {
    fmb_diag_set(diag, FMB_EXIT_BAD_INPUT, path, 0, 0, "cannot write the VTK collection: %s",
                 err[0] ? err : strerror(errno));
    fmb_vtk_close(v);
    return NULL;
  }
  fprintf(v->pvd,
          "<?xml version=\"1.0\"?>\n<VTKFile type=\"Collection\" version=\"0.1\" byte_order=\"LittleEndian\">\n"
          "  <Collection>\n%s",
          pvd_tail);
  fflush(v->pvd);
  return v;
}

/* The arrays of one step, in the order their raw blocks follow <AppendedData encoding="raw">_
   (VTK's appended format: each block a UInt64 byte count, then the values in the machine's byte
   order, which the header declares). */
enum { ARR_DEFORMATION, ARR_ROTATION, ARR_PART, ARR_OWNER, ARR_POINTS, ARR_CONNECTIVITY, ARR_OFFSETS, ARR_TYPES, NARR };
typedef struct {
  const char *type, *name;
  int ncomp;
  size_t size; /* bytes of one value */
} ArraySpec;
static const ArraySpec array_spec[NARR] = {
    {"Float64", "deformation", 3, 8}, {"Float64", "rotation", 1, 8}, {"Int32", "part", 1, 4},
    {"Int32", "owner", 1, 4},         {"Float64", "Points", 3, 8},   {"Int64", "connectivity", 1, 8},
    {"Int64", "offsets", 1, 8},       {"UInt8", "types", 1, 1},
};
/* a spatial scene's point data, in place of deformation and rotation (the other arrays as above);
   three vectors take the room of the two planar arrays, so the spatial offsets are computed with
   this table in front */
enum { ARR3_FRAME_X, ARR3_FRAME_Y, ARR3_FRAME_Z, NARR3 };
static const ArraySpec array3_spec[NARR3] = {
    {"Float64", "frame_x", 3, 8}, {"Float64", "frame_y", 3, 8}, {"Float64", "frame_z", 3, 8}};

static void tag_of(FILE* f, const ArraySpec* a, uint64_t offset) {
  fprintf(
      f, "        <DataArray type=\"%s\" Name=\"%s\" NumberOfComponents=\"%d\" format=\"appended\" offset=\"%llu\"/>\n",
      a->type, a->name, a->ncomp, (unsigned long long)offset);
}
static void array_tag(FILE* f, int k, const uint64_t* offset) { tag_of(f, &array_spec[k], offset[k]); }

static void block(FILE* f, const void* data, uint64_t bytes) {
  fwrite(&bytes, sizeof bytes, 1, f);
  if (bytes) fwrite(data, 1, (size_t)bytes, f);
}

int fmb_vtk_set_every(fmbVtk* v, int every) {
  if (!v || every < 0) return -1;
  v->every = every > 1 ? every : 1;
  return 0;
}

/* 0 ok; -1 a file could not be written (the caller stops the run, as for the CSV) */
int fmb_vtk_step(fmbVtk* v, const fmbModel* m, fmbWorkspace* w, double t, const double* y) {
  /* --vtk-every N: every Nth output row, from the first */
  if (v->every > 1 && v->row++ % v->every != 0) return 0;
  const double* q = y;
  const fmbDrawing* d = v->draw;
  const int np = d->npoint, nc = d->ncell, nconn = d->nconn;
  char name[600], path[1400];
  snprintf(name, sizeof name, "%s_%06ld.vtu", v->stem, v->step);
  snprintf(path, sizeof path, "%s/%s", v->dir, name);
  const int spatial = d->dimension == 3;
  /* spatial: positions and the frame's axes at each point (marker3's R by columns) */
  for (int i = 0; spatial && i < np; ++i) {
    const fmbDrawPoint* p = &d->point[i];
    double* pt = v->pts + 3 * i;
    double R[9] = {0, 0, 0, 0, 0, 0, 0, 0, 0};
    if (p->body == FMB_WORLD)
      for (int k = 0; k < 3; ++k) pt[k] = d->local3[3 * i + k];
    else if (fmb_body_point3(m, w, p->body, q, d->local3 + 3 * i, pt, R))
      pt[0] = pt[1] = pt[2] = NAN;
    for (int c = 0; c < 3; ++c)
      for (int k = 0; k < 3; ++k) v->frame[3 * (size_t)np * c + 3 * i + k] = R[3 * k + c];
  }
  /* planar: positions, and for centreline stations the deformation in the body frame,
     u = A(theta)^T (r - r0) - local, and the cross-section's rotation angle - theta */
  for (int i = 0; !spatial && i < np; ++i) {
    const fmbDrawPoint* p = &d->point[i];
    double* pt = v->pts + 3 * i;
    double* u = v->deform + 3 * i;
    pt[2] = u[0] = u[1] = u[2] = v->rot[i] = 0.0;
    if (p->body == FMB_WORLD) {
      pt[0] = p->local[0];
      pt[1] = p->local[1];
      continue;
    }
    double ang = 0.0;
    if (fmb_body_point(m, w, p->body, q, p->local, pt, &ang)) {
      pt[0] = pt[1] = NAN;
      continue;
    }
    if (p->station >= 0) {
      const double* qb = q + m->body[p->body].qadr;
      const double c = cos(qb[2]), sn = sin(qb[2]), dx = pt[0] - qb[0], dy = pt[1] - qb[1];
      u[0] = c * dx + sn * dy - p->local[0];
      u[1] = -sn * dx + c * dy - p->local[1];
      v->rot[i] = ang - qb[2];
    }
  }
  const uint64_t count[NARR] = {3 * (uint64_t)np, (uint64_t)np,    (uint64_t)nc, (uint64_t)nc,
                                3 * (uint64_t)np, (uint64_t)nconn, (uint64_t)nc, (uint64_t)nc};
  uint64_t offset[NARR], offset3[NARR3], at = 0;
  for (int k = 0; spatial && k < NARR3; ++k) {
    offset3[k] = at;
    at += sizeof(uint64_t) + 3 * (uint64_t)np * array3_spec[k].size;
  }
  for (int k = 0; k < NARR; ++k) {
    offset[k] = at;
    if (spatial && (k == ARR_DEFORMATION || k == ARR_ROTATION)) continue; /* not written */
    at += sizeof(uint64_t) + count[k] * array_spec[k].size;
  }
  fmbSafeFile* sf = fmb_safe_open_guarded(path, m->inputs, NULL, 0);
  FILE* f = fmb_safe_stream(sf);
  if (!f) {
    fmb_safe_close(sf, 0);
    return -1;
  }
  const uint16_t one = 1;
  const int little = *(const unsigned char*)&one == 1;
  fprintf(
      f,
      "<?xml version=\"1.0\"?>\n<VTKFile type=\"UnstructuredGrid\" version=\"1.0\" byte_order=\"%s\" "
      "header_type=\"UInt64\">\n  <UnstructuredGrid>\n    <FieldData>\n"
      "      <DataArray type=\"Float64\" Name=\"TimeValue\" NumberOfTuples=\"1\" format=\"ascii\">%.12g</DataArray>\n"
      "    </FieldData>\n    <Piece NumberOfPoints=\"%d\" NumberOfCells=\"%d\">\n"
      "      <PointData %s>\n",
      little ? "LittleEndian" : "BigEndian", t, np, nc,
      spatial ? "Vectors=\"frame_x\"" : "Vectors=\"deformation\" Scalars=\"rotation\"");
  for (int k = 0; spatial && k < NARR3; ++k) tag_of(f, &array3_spec[k], offset3[k]);
  if (!spatial) {
    array_tag(f, ARR_DEFORMATION, offset);
    array_tag(f, ARR_ROTATION, offset);
  }
  fprintf(f, "      </PointData>\n      <CellData Scalars=\"part\">\n");
  array_tag(f, ARR_PART, offset);
  array_tag(f, ARR_OWNER, offset);
  fprintf(f, "      </CellData>\n      <Points>\n");
  array_tag(f, ARR_POINTS, offset);
  fprintf(f, "      </Points>\n      <Cells>\n");
  array_tag(f, ARR_CONNECTIVITY, offset);
  array_tag(f, ARR_OFFSETS, offset);
  array_tag(f, ARR_TYPES, offset);
  fprintf(f, "      </Cells>\n    </Piece>\n  </UnstructuredGrid>\n  <AppendedData encoding=\"raw\">\n   _");
  for (int k = 0; spatial && k < NARR3; ++k) block(f, v->frame + 3 * (size_t)np * k, 3 * (uint64_t)np * 8);
  if (!spatial) {
    block(f, v->deform, count[ARR_DEFORMATION] * 8);
    block(f, v->rot, count[ARR_ROTATION] * 8);
  }
  for (int c = 0; c < nc; ++c) v->i32[c] = d->cell[c].part;
  block(f, v->i32, count[ARR_PART] * 4);
  for (int c = 0; c < nc; ++c) v->i32[c] = d->cell[c].owner;
  block(f, v->i32, count[ARR_OWNER] * 4);
  block(f, v->pts, count[ARR_POINTS] * 8);
  for (int k = 0; k < nconn; ++k) v->i64[k] = d->conn[k];
  block(f, v->i64, count[ARR_CONNECTIVITY] * 8);
  for (int c = 0; c < nc; ++c) v->i64[c] = d->cell[c].first + d->cell[c].count;
  block(f, v->i64, count[ARR_OFFSETS] * 8);
  for (int c = 0; c < nc; ++c) v->u8[c] = (uint8_t)cell_type(d->cell[c].part);
  block(f, v->u8, count[ARR_TYPES]);
  fprintf(f, "\n  </AppendedData>\n</VTKFile>\n");
  const int bad = ferror(f);
  if (fmb_safe_close(sf, !bad) != 0 || bad) return -1;
  /* the new entry replaces the collection's closing tags, which follow it again */
  if (fseek(v->pvd, -(long)(sizeof pvd_tail - 1), SEEK_END) != 0) return -1;
  fprintf(v->pvd, "    <DataSet timestep=\"%.12g\" group=\"\" part=\"0\" file=\"", t);
  fmb_write_xml_text(v->pvd, name);
  fprintf(v->pvd, "\"/>\n%s", pvd_tail);
  if (fflush(v->pvd) != 0 || ferror(v->pvd)) return -1;
  v->step++;
  return 0;
}
