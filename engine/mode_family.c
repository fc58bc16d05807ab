/* mode_family.c — the families of a spatial scene's modes relative to a spin axis (flexmbd.h
 * fmb_modes_classify, docs/analysis.md "Spatial scenes"), type-agnostically from the bodies'
 * spatial markers:
 *
 * Each body is seen at its stations: a body with a `centreline` op at those (its reference points,
 * read as [x, y, 0] in the body frame), any other at its frame origin. A mode phi (complex, over
 * the coordinates) moves station k by dx_k = (dr_k/dq) phi and turns it by dth_k = G_k phi
 * (marker3). With the unit spin axis a, the radial direction e_k of the station (its distance
 * from the axis, normalized; a station on the axis takes the body's, then x) and t_k = a x e_k:
 *     flap    = sum |a . dx_k|^2           (out of the plane of rotation)
 *     lag     = sum |t_k . dx_k|^2         (in the plane, across the radius: chordwise)
 *     axial   = sum |e_k . dx_k|^2         (along the radius)
 *     torsion = sum (l |e_k . dth_k|)^2    (a turn about the radius; l: the body's span between
 *                                           its first and last station, else 0.1 of its radius)
 * and the mode's family is the largest. A bending mode turns its stations about t_k or a, never
 * about e_k, so torsion takes only what twists. Setup-time code: it allocates. */
#include <math.h>
#include <stdlib.h>
#include <string.h>

#include "data.h"
#include "internal.h"

const char* fmb_family_name(int family) {
  switch (family) {
    case FMB_FAMILY_FLAP: return "flap";
    case FMB_FAMILY_LAG: return "lag";
    case FMB_FAMILY_AXIAL: return "axial";
    case FMB_FAMILY_TORSION: return "torsion";
    default: return "mode";
  }
}

typedef struct {
  int body;       /* body index */
  double e[3];    /* radial unit vector */
  double l;       /* torsion's length scale */
  double *dx, *G; /* 3 x nb each, row-major */
} Station;

static double dot3(const double* a, const double* b) { return a[0] * b[0] + a[1] * b[1] + a[2] * b[2]; }

/* the radial unit vector of point pos about the axis through center; 0 when on the axis */
static int radial(const double axis[3], const double center[3], const double pos[3], double e[3]) {
  double d[3] = {pos[0] - center[0], pos[1] - center[1], pos[2] - center[2]};
  const double along = dot3(d, axis);
  for (int i = 0; i < 3; ++i) d[i] -= along * axis[i];
  const double n = sqrt(dot3(d, d));
  if (!(n > 1e-12)) return 0;
  for (int i = 0; i < 3; ++i) e[i] = d[i] / n;
  return 1;
}

int fmb_modes_classify_with(const fmbModel* m, fmbWorkspace* w, double t, const double* y, fmbModes* md,
                            const double axis[3], const double center[3], fmbDiag* diag) {
  fmbDiag local;
  if (!diag) diag = &local;
  memset(diag, 0, sizeof *diag);
  (void)t;
  if (!m || !y || !md || !axis || !center || m->dimension != 3 || md->nq != m->nq || md->count < 0 ||
      (md->count > 0 && (!md->shape_re || !md->shape_im))) {
    fmb_diag_set(diag, FMB_EXIT_BAD_INPUT, m ? m->path : "", 0, 0,
                 "fmb_modes_classify: a NULL argument, a planar scene or modes of another model");
    return FMB_EXIT_BAD_INPUT;
  }
  const double an = sqrt(dot3(axis, axis));
  if (!(an > 0.0) || !isfinite(an)) {
    fmb_diag_set(diag, FMB_EXIT_BAD_INPUT, m->path, 0, 0, "fmb_modes_classify: the spin axis is zero or not finite");
    return FMB_EXIT_BAD_INPUT;
  }
  const double a[3] = {axis[0] / an, axis[1] / an, axis[2] / an};
  int nst = 0, cap = 0, rc = w ? 0 : FMB_EXIT_SOLVER;
  Station* st = NULL;
  for (int b = 1; !rc && b < m->nbody; ++b) {
    const fmbBodyInst* bi = &m->body[b];
    if (!bi->type || !bi->marker3 || bi->nq == 0) continue;
    const int ncl = bi->type->centreline ? bi->type->centreline(bi->self, 0, NULL) : 0;
    const int n = ncl > 0 ? ncl : 1;
    double* loc = calloc((size_t)2 * n, sizeof(double));
    if (!loc || (ncl > 0 && bi->type->centreline(bi->self, n, loc) < 0)) rc = FMB_EXIT_SOLVER;
    if (!rc && nst + n > cap) {
      cap = 2 * (nst + n);
      Station* more = realloc(st, sizeof(Station) * (size_t)cap);
      if (!more)
        rc = FMB_EXIT_SOLVER;
      else
        st = more;
    }
    double first[3] = {0.0, 0.0, 0.0}, last[3] = {0.0, 0.0, 0.0}, body_e[3] = {1.0, 0.0, 0.0};
    int have_e = 0;
    const int s0 = nst;
    for (int k = 0; !rc && k < n; ++k) {
      Station* s = &st[nst];
      const double pt[3] = {loc[2 * k], loc[2 * k + 1], 0.0};
      double pos[3], R[9];
      s->body = b;
      s->dx = calloc((size_t)3 * bi->nq, sizeof(double));
      s->G = calloc((size_t)3 * bi->nq, sizeof(double));
      ++nst;
      if (!s->dx || !s->G ||
          bi->marker3(bi->self, y + bi->qadr, pt, pos, R, s->dx, s->G, bi->nq, fmb_workspace_plugin(w) + bi->workadr)) {
        rc = FMB_EXIT_SOLVER;
        break;
      }
      if (k == 0) memcpy(first, pos, sizeof pos);
      memcpy(last, pos, sizeof pos);
      s->l = 0.0;
      if (radial(a, center, pos, s->e)) {
        if (!have_e) memcpy(body_e, s->e, sizeof body_e);
        have_e = 1;
      } else {
        s->e[0] = NAN; /* on the axis: the body's radial direction, below */
      }
    }
    if (!rc) {
      /* a body on the axis (a hub): its span's direction across the axis, else x turned off a */
      if (!have_e) {
        double d[3] = {last[0] - first[0], last[1] - first[1], last[2] - first[2]};
        const double along = dot3(d, a);
        for (int i = 0; i < 3; ++i) d[i] -= along * a[i];
        double dn = sqrt(dot3(d, d));
        if (!(dn > 1e-12)) {
          const double x[3] = {fabs(a[0]) < 0.9 ? 1.0 : 0.0, fabs(a[0]) < 0.9 ? 0.0 : 1.0, 0.0};
          const double ax = dot3(x, a);
          for (int i = 0; i < 3; ++i) d[i] = x[i] - ax * a[i];
          dn = sqrt(dot3(d, d));
        }
        for (int i = 0; i < 3; ++i) body_e[i] = d[i] / dn;
      }
      const double span =
          sqrt((last[0] - first[0]) * (last[0] - first[0]) + (last[1] - first[1]) * (last[1] - first[1]) +
               (last[2] - first[2]) * (last[2] - first[2]));
      double rad[3] = {first[0] - center[0], first[1] - center[1], first[2] - center[2]};
      const double along = dot3(rad, a);
      for (int i = 0; i < 3; ++i) rad[i] -= along * a[i];
      const double l = n > 1 && span > 0.0 ? span : fmax(0.1 * sqrt(dot3(rad, rad)), 1e-3);
      for (int k = s0; k < nst; ++k) {
        if (isnan(st[k].e[0])) memcpy(st[k].e, body_e, sizeof body_e);
        st[k].l = l;
      }
    }
    free(loc);
  }
  int* family = rc ? NULL : malloc(sizeof(int) * (size_t)md->count + 1);
  if (!rc && !family) rc = FMB_EXIT_SOLVER;
  for (int k = 0; !rc && k < md->count; ++k) {
    const double* re = md->shape_re + (size_t)k * md->nq;
    const double* im = md->shape_im + (size_t)k * md->nq;
    double score[5] = {0.0, 0.0, 0.0, 0.0, 0.0};
    for (int j = 0; j < nst; ++j) {
      const Station* s = &st[j];
      const fmbBodyInst* bi = &m->body[s->body];
      const double tv[3] = {a[1] * s->e[2] - a[2] * s->e[1], a[2] * s->e[0] - a[0] * s->e[2],
                            a[0] * s->e[1] - a[1] * s->e[0]};
      for (int part = 0; part < 2; ++part) {
        const double* phi = (part ? im : re) + bi->qadr;
        double dx[3] = {0.0, 0.0, 0.0}, th[3] = {0.0, 0.0, 0.0};
        for (int i = 0; i < 3; ++i)
          for (int c = 0; c < bi->nq; ++c) {
            dx[i] += s->dx[(size_t)i * bi->nq + c] * phi[c];
            th[i] += s->G[(size_t)i * bi->nq + c] * phi[c];
          }
        const double f = dot3(a, dx), g = dot3(tv, dx), x = dot3(s->e, dx), r = s->l * dot3(s->e, th);
        score[FMB_FAMILY_FLAP] += f * f;
        score[FMB_FAMILY_LAG] += g * g;
        score[FMB_FAMILY_AXIAL] += x * x;
        score[FMB_FAMILY_TORSION] += r * r;
      }
    }
    int best = FMB_FAMILY_NONE;
    double top = 0.0;
    for (int f = FMB_FAMILY_FLAP; f <= FMB_FAMILY_TORSION; ++f)
      if (score[f] > top) {
        top = score[f];
        best = f;
      }
    family[k] = best;
  }
  if (rc) {
    free(family);
    fmb_diag_set(diag, FMB_EXIT_SOLVER, m->path, 0, 0, "the bodies' markers cannot be evaluated to classify the modes");
  } else {
    free(md->family);
    md->family = family;
    memcpy(md->axis, a, sizeof a);
    memcpy(md->center, center, sizeof md->center);
  }
  for (int j = 0; j < nst; ++j) {
    free(st[j].dx);
    free(st[j].G);
  }
  free(st);
  return rc;
}

/* the public entry: its scratch from a data object made for the call (issue 35: a run's scratch
   lives in fmbData; fmb_modes passes its own) */
int fmb_modes_classify(const fmbModel* m, double t, const double* y, fmbModes* md, const double axis[3],
                       const double center[3], fmbDiag* diag) {
  fmbData* own = m ? fmb_data_new(m, NULL) : NULL;
  const int rc = fmb_modes_classify_with(m, own ? own->w : NULL, t, y, md, axis, center, diag);
  fmb_data_destroy(own);
  return rc;
}
