/* test_draw3d.c — how a spatial body with a centreline is drawn and written (issue 34, item 5),
 * before the spatial beam exists: a test type `rod3d`, rigid3d's ops with a centreline of five
 * stations along its x axis (from -0.5 to 0.5 m) and no outputs of its own, swings and spins on a
 * ball joint. Its twin, the same scene with `type: rigid3d`, gives the independent values (its own
 * output op, from its coordinates):
 *  - the engine's pose columns of a spatial body without its own (marker3 at the origin):
 *    rod.x, y, z equal the twin's, rod.qw..qz the twin's Euler parameters up to their sign;
 *  - BODY.shape in space: columns shapeK_x, _y, _z, the station [sK, 0] of the body at r + R [sK, 0, 0]
 *    (R from the twin's quaternion, 1e-10: the CSV's 12 digits);
 *  - the drawing (fmb_drawing_new): dimension 3, the centreline a polyline through the five
 *    stations (local3 [sK, 0, 0]), the ball joint a vertex at the ground's point;
 *  - the VTK animation: the centreline's points equal the shape columns, and the point vectors
 *    frame_y, frame_z there (the cross-section frame) R's second and third columns.
 * The spatial beam (`type: beam`, dimension 3) reaches the same code through its centreline op. */
#include <math.h>
#include <stdint.h>
#include <stdlib.h>
#include <string.h>
#include <unistd.h>

#include "testlib.h"

/* the test type itself: the plugin tests/ux/test_view3d.py loads with --plugin, compiled in (one
   definition of rod3d for both tests) */
#include "../ux/rod3d_plugin.c"

#define SCENE(TYPE)                                                                                         \
  "dimension: 3\ngravity: [0, 0, -9.81]\nsolver: {t_end: 0.5, rtol: 1e-9, output_step: 0.05}\n"             \
  "bodies:\n  - {name: rod, type: " TYPE ", mass: 1, inertia: [0.001, 0.08, 0.08], position: [0.5, 0, 0], " \
  "velocity: [0, 1, 0], angular_velocity: [3, 0, 2]}\n"                                                     \
  "joints:\n  - {name: ball, type: spherical, body1: ground, body2: rod, point2: [-0.5, 0, 0]}\n"

static fmbModel* load_text(fmbRegistry* reg, const char* name, const char* text, fmbDiag* diag) {
  char path[1024];
  fmbt_out_path(name, path, sizeof path);
  FILE* f = fopen(path, "w");
  if (!f) return NULL;
  fputs(text, f);
  fclose(f);
  return fmb_load(path, NULL, 0, reg, diag);
}

/* the Float64 array `name` of a .vtu in raw appended form (n values into out, at most cap) */
static int vtu_array(const char* text, size_t len, const char* name, double* out, int cap) {
  char key[128];
  snprintf(key, sizeof key, "Name=\"%s\"", name);
  const char* at = strstr(text, key);
  const char* raw = strstr(text, "<AppendedData encoding=\"raw\">");
  if (!at || !raw || !(at = strstr(at, "offset=\"")) || !(raw = strchr(raw, '_'))) return -1;
  const size_t off = strtoull(at + 8, NULL, 10);
  const char* block = raw + 1 + off;
  uint64_t bytes;
  if ((size_t)(block - text) + 8 > len) return -1;
  memcpy(&bytes, block, 8);
  const int n = (int)(bytes / 8);
  if (n > cap || (size_t)(block - text) + 8 + bytes > len) return -1;
  memcpy(out, block + 8, bytes);
  return n;
}

int main(void) {
  fmbDiag diag;
  const fmbPlugin* rod3d = fmb_plugin_descriptor(); /* rigid3d's ops, a centreline, no outputs of its own */
  ENSURE(rod3d != NULL);
  fmbRegistry* reg = fmb_registry_new();
  ENSURE(reg && fmb_registry_add(reg, fmb_builtin_plugin(), "built-in", &diag) == 0);
  ENSURE(fmb_registry_add(reg, rod3d, "test", &diag) == 0);
  if (fmbt_failures) return fmbt_finish("test_draw3d");

  /* the twin: rigid3d's own columns */
  fmbModel* twin = load_text(
      reg, "twin3d.yaml", SCENE("rigid3d") "outputs: [rod.x, rod.y, rod.z, rod.qw, rod.qx, rod.qy, rod.qz]\n", &diag);
  fmbModel* rod = load_text(reg, "rod3d.yaml",
                            SCENE("rod3d") "outputs: [rod.x, rod.y, rod.z, rod.qw, rod.qx, rod.qy, "
                                           "rod.qz, rod.shape]\n",
                            &diag);
  ENSURE(twin && rod);
  if (!twin || !rod) return fmbt_finish("test_draw3d");
  char twin_csv[1024], rod_csv[1024], vtk_dir[1024];
  fmbt_out_path("twin3d.csv", twin_csv, sizeof twin_csv);
  fmbt_out_path("rod3d.csv", rod_csv, sizeof rod_csv);
  fmbt_out_path("rod3d_vtk", vtk_dir, sizeof vtk_dir);
  fmbStats st;
  fmbRunOptions opt_twin = {.csv_path = twin_csv, .quiet = 1},
                opt_rod = {.csv_path = rod_csv, .vtk_dir = vtk_dir, .quiet = 1};
  ENSURE(fmb_run(twin, &opt_twin, &st, &diag) == 0);
  ENSURE(fmb_run(rod, &opt_rod, &st, &diag) == 0);
  fmbtCsv ct, cr;
  ENSURE(fmbt_csv_read(twin_csv, &ct) == 0 && fmbt_csv_read(rod_csv, &cr) == 0);
  ENSURE(cr.nrow == ct.nrow && cr.nrow == 11);
  ENSURE(cr.ncol == 1 + 7 + 15); /* t, the pose, 5 stations x 3 */

  /* the pose columns, and the shape against r + R [sK, 0, 0] */
  const char* pose[7] = {"rod.x", "rod.y", "rod.z", "rod.qw", "rod.qx", "rod.qy", "rod.qz"};
  double worst_pose = 0.0, worst_shape = 0.0, moved = 0.0;
  for (int r = 0; r < ct.nrow && !fmbt_failures; ++r) {
    double pt[7], pr[7];
    for (int k = 0; k < 7; ++k) pt[k] = fmbt_col(&ct, pose[k])[r], pr[k] = fmbt_col(&cr, pose[k])[r];
    const double sign = pt[3] * pr[3] + pt[4] * pr[4] + pt[5] * pr[5] + pt[6] * pr[6] < 0 ? -1.0 : 1.0;
    for (int k = 0; k < 7; ++k) worst_pose = fmax(worst_pose, fabs((k < 3 ? 1.0 : sign) * pr[k] - pt[k]));
    double R[9];
    fmb_quat_matrix(pt + 3, R);
    for (int s = 0; s < 5; ++s) {
      const double sk = -0.5 + 0.25 * s;
      for (int c = 0; c < 3; ++c) {
        char name[64];
        snprintf(name, sizeof name, "rod.shape%d_%c", s, "xyz"[c]);
        const double* col = fmbt_col(&cr, name);
        if (col) worst_shape = fmax(worst_shape, fabs(col[r] - (pt[c] + R[3 * c] * sk)));
      }
    }
    moved = fmax(moved, fabs(pt[2]));
  }
  ENSURE(worst_pose < 1e-11);
  ENSURE(worst_shape < 1e-10);
  ENSURE(moved > 0.05); /* it swings out of its start: the comparison is not of constants */
  printf("pose columns from marker3 within %.3g of rigid3d's own; shape within %.3g of r + R s\n", worst_pose,
         worst_shape);

  /* the drawing */
  fmbDrawing* d = fmb_drawing_new(rod);
  ENSURE(d && d->dimension == 3 && d->local3);
  int centre = -1, vertex = -1, axes = 0;
  for (int c = 0; d && c < d->ncell; ++c) {
    if (d->cell[c].part == FMB_DRAW_CENTRELINE) centre = c;
    if (d->cell[c].part == FMB_DRAW_JOINT) vertex = c;
    axes += d->cell[c].part == FMB_DRAW_FRAME_AXIS;
  }
  ENSURE(centre >= 0 && vertex >= 0 && axes == 0);
  if (centre < 0 || vertex < 0) return fmbt_finish("test_draw3d");
  ENSURE(d->cell[centre].count == 5 && d->cell[centre].owner == 1);
  for (int s = 0; s < d->cell[centre].count; ++s) {
    const int i = d->conn[d->cell[centre].first + s];
    ENSURE(d->point[i].station == s && d->point[i].body == 1);
    ENSURE(d->local3[3 * i] == -0.5 + 0.25 * s && d->local3[3 * i + 1] == 0.0 && d->local3[3 * i + 2] == 0.0);
  }
  const int j = d->conn[d->cell[vertex].first];
  ENSURE(d->point[j].body == 0 && d->local3[3 * j] == 0.0 && d->local3[3 * j + 1] == 0.0 &&
         d->local3[3 * j + 2] == 0.0);

  /* the last VTK step: the centreline's points and cross-section frames */
  char vtu[1200];
  snprintf(vtu, sizeof vtu, "%s/%ld-rod3d_%06d.vtu", vtk_dir, (long)getpid(), cr.nrow - 1); /* fmbt_out_path's name */
  size_t len = 0;
  char* text = fmbt_slurp(vtu, &len);
  ENSURE(text != NULL);
  const int np = d->npoint;
  double* pts = calloc(3 * (size_t)np, sizeof *pts);
  double* fy = calloc(3 * (size_t)np, sizeof *fy);
  double* fz = calloc(3 * (size_t)np, sizeof *fz);
  ENSURE(text && vtu_array(text, len, "Points", pts, 3 * np) == 3 * np &&
         vtu_array(text, len, "frame_y", fy, 3 * np) == 3 * np &&
         vtu_array(text, len, "frame_z", fz, 3 * np) == 3 * np);
  const int last = cr.nrow - 1;
  double q[4], R[9], worst_vtk = 0.0;
  for (int k = 0; k < 4; ++k) q[k] = fmbt_col(&ct, pose[3 + k])[last];
  fmb_quat_matrix(q, R);
  for (int s = 0; s < 5; ++s) {
    const int i = d->conn[d->cell[centre].first + s];
    for (int c = 0; c < 3; ++c) {
      char name[64];
      snprintf(name, sizeof name, "rod.shape%d_%c", s, "xyz"[c]);
      const double* col = fmbt_col(&cr, name);
      if (col) worst_vtk = fmax(worst_vtk, fabs(pts[3 * i + c] - col[last]));
      worst_vtk = fmax(worst_vtk, fabs(fy[3 * i + c] - R[3 * c + 1]));
      worst_vtk = fmax(worst_vtk, fabs(fz[3 * i + c] - R[3 * c + 2]));
    }
  }
  ENSURE(worst_vtk < 1e-10);
  /* the section turned: frame_z is no longer the global z (the spin about the rod's axis shows) */
  ENSURE(fabs(R[8]) < 0.99);
  printf("VTK: the centreline's points and cross-section frames within %.3g of the CSV\n", worst_vtk);
  free(text), free(pts), free(fy), free(fz);
  fmb_drawing_free(d);
  fmbt_csv_free(&ct);
  fmbt_csv_free(&cr);
  fmb_free(twin);
  fmb_free(rod);
  fmb_registry_free(reg);
  return fmbt_finish("test_draw3d");
}
