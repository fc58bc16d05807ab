/* singular.c — does a model's constraint manifold contain a singular configuration (docs/mechanisms.md,
 * "Singular configurations")? `formulation: auto` asks this once, before the run, to start such a
 * model on the projected formulation instead of leaving the GGL backend where it fails.
 *
 * Why before and not at the failure (the switch in integrate.c, kept as the fallback): IDA often
 * steps across a flat position instead of failing there. The single parallelogram linkage of
 * test_parallelogram at rtol 1e-8 crossed 16 flats on IDA and failed at the 17th (t = 6.99 s):
 * crank error 4.9e-5 rad at t = 10 s, against 1.4e-6 on the projected formulation from the start
 * (same scene, default tolerances). On the projected formulation a stretch of the run that passes
 * a flat commits no more error than one that does not (max over 0.05 s stretches: 1.6e-9 and
 * 2.5e-9 rad).
 *
 * How. Only a model whose constraining joints close a loop of bodies can lose rank (an open chain
 * never does), and only rigid bodies are walked (rigid_bodies_only). From the assembled initial
 * configuration, walk along the constraint manifold (time frozen at t0) in the direction of the
 * initial velocity (a generic direction if the model starts at rest), then the other way, in
 * tangent steps that move no coordinate by more than SCAN_STEP, each projected back onto Phi = 0
 * by the mass-orthogonal Newton steps of augmented.c, and look at the rank of Phi_q after each
 * step. SCAN_STEPS steps each way go past a whole turn of a crank (a one-degree-of-freedom loop's
 * configuration curve is closed: a parallelogram goes flat within a quarter turn). When only
 * gravity and the constraints act, a configuration whose potential energy exceeds the total is out
 * of reach and ends the walk (a linkage swinging below its flat position stays on GGL). A model
 * with no degree of freedom left by its constraints (a fully driven mechanism) is not walked: its
 * drive decides where it goes, and the switch at the failure remains for it. With several degrees
 * of freedom the walk follows one curve of the manifold, not all of it. The rank test is dense
 * (Gram-Schmidt on Phi_q), so only models the projected formulation solves with a dense Newton
 * matrix are walked (2 nq <= SCAN_MAX_UNKNOWNS): a row of 20 linkages (123 coordinates) in about
 * 0.1 s of CPU; a row of 50 would take 1.5 s. */
#include <math.h>
#include <stdlib.h>
#include <string.h>

#include "data.h"

/* largest change of any coordinate per step of the walk (m, rad): the sample nearest a flat
   position lies within half of it, where the relative singular value of Phi_q is ~ SCAN_STEP / 2 */
#define SCAN_STEP 0.02
/* 400 steps of 0.02: 8 rad of the fastest coordinate, more than a turn */
#define SCAN_STEPS 400
/* a row whose part independent of the others falls below this (relative) on the walk is a
   singular configuration; above SCAN_STEP / 2, so a flat between two samples is found */
#define SCAN_RANK_TOL 0.05
/* the projected formulation's dense-Newton limit (integrator_projected.c, PROJ_DENSE_MAX) */
#define SCAN_MAX_UNKNOWNS 256

/* the potential energy at q (gravity, strain, springs) */
static double potential(const fmbModel* m, fmbWorkspace* w, double t, const double* q, const double* zero_v) {
  fmbEnergy e;
  fmb_energy(m, w, t, q, zero_v, &e);
  return e.strain + e.gravity + e.spring;
}

/* Walk from q along dir (both updated). energy_cap: the model's total energy when nothing but
   conservative forces act (a configuration whose potential exceeds it is out of the motion's
   reach: the walk stops there), or INFINITY. */
static int walk(const fmbModel* m, fmbWorkspace* w, fmbAugmented* g, double t0, double* q, const double* v, double* dir,
                double energy_cap) {
  const int nq = m->nq;
  double* zero_v = calloc((size_t)nq, sizeof(double));
  int singular = 0;
  if (!zero_v) return 0;
  for (int step = 0; step < SCAN_STEPS && !singular; ++step) {
    /* the tangent at q nearest the last direction (mass-orthogonal projection), scaled */
    if (fmb_project_state(m, w, g, t0, q, zero_v)) break;
    if (fmb_project_tangent(w, g, dir)) break;
    double big = 0.0;
    for (int i = 0; i < nq; ++i) big = fmax(big, fabs(dir[i]));
    if (!(big > 0.0) || !isfinite(big)) break; /* no freedom left along this curve */
    for (int i = 0; i < nq; ++i) {
      dir[i] *= SCAN_STEP / big;
      q[i] += dir[i];
    }
    memset(zero_v, 0, sizeof(double) * (size_t)nq);
    if (fmb_project_state(m, w, g, t0, q, zero_v)) break;
    memset(zero_v, 0, sizeof(double) * (size_t)nq);
    if (potential(m, w, t0, q, zero_v) > energy_cap) break;
    singular = fmb_rank_deficient_at(m, w, t0, q, v, SCAN_RANK_TOL);
  }
  free(zero_v);
  return singular;
}

static int root(int* parent, int b) {
  while (parent[b] != b) b = parent[b] = parent[parent[b]];
  return b;
}

/* 1 when the joints that constrain close a loop of bodies (the ground counts as one body): only
   then can Phi_q lose rank on the motion; an open chain (a pendulum, a rotor) is never scanned */
static int has_closed_loop(const fmbModel* m) {
  int* parent = malloc(sizeof(int) * (size_t)(m->nbody + 1));
  int loop = 0;
  if (!parent) return 0;
  for (int b = 0; b < m->nbody; ++b) parent[b] = b;
  for (int j = 0; j < m->njoint && !loop; ++j) {
    const fmbJointInst* ji = &m->joint[j];
    if (ji->nrows == 0) continue;
    const int a = root(parent, ji->body[0] > 0 ? ji->body[0] : 0), b = root(parent, ji->body[1] > 0 ? ji->body[1] : 0);
    if (a == b)
      loop = 1;
    else
      parent[a] = b;
  }
  free(parent);
  return loop;
}

/* every body moves rigidly in the plane (3 coordinates): the walk steps every coordinate by up to
   SCAN_STEP, which for a deformation coordinate is no motion the body makes; flexible loops (the
   slider-crank's rod) stay on the GGL path and its switch at a failure */
static int rigid_bodies_only(const fmbModel* m) {
  for (int b = 1; b < m->nbody; ++b)
    if (m->body[b].nq != 3) return 0;
  return 1;
}

int fmb_needs_singular_method(const fmbModel* m) {
  /* solver.singular_scan: off: no walk, so that test_parallelogram still reaches the switch at
     the GGL backend's failure (the fallback for what the walk does not find) */
  if (!m || !m->solver.singular_scan) return 0;
  if (m->nc == 0 || m->nz > 0 || 2 * m->nq > SCAN_MAX_UNKNOWNS || !rigid_bodies_only(m) || !has_closed_loop(m))
    return 0;
  const int nq = m->nq, nc = m->nc;
  fmbData* scratch = fmb_data_new(m, NULL);
  fmbWorkspace* w = scratch ? scratch->w : NULL;
  fmbAugmented* g = fmb_augmented_new(m);
  double* y = calloc((size_t)m->ny + 1, sizeof(double));
  double* yp = calloc((size_t)m->ny + 1, sizeof(double));
  double* dir = calloc((size_t)nq, sizeof(double));
  double* dir_start = calloc((size_t)nq, sizeof(double));
  double* q_start = calloc((size_t)nq, sizeof(double));
  double* PhiQ = calloc((size_t)nc * nq, sizeof(double));
  double* work = calloc((size_t)nc * nq + nc, sizeof(double));
  int* order = calloc((size_t)nc, sizeof(int));
  int singular = 0;
  fmbStats st;
  fmbDiag diag;
  memset(&st, 0, sizeof st);
  memset(&diag, 0, sizeof diag);
  if (w && g && y && yp && dir && dir_start && q_start && PhiQ && work && order &&
      !fmb_initial_conditions(m, w, y, yp, &st, &diag)) {
    const double t0 = m->solver.t0;
    double* q = y;
    double* v = y + nq;
    /* degrees of freedom at t0: none, nothing to walk along */
    const int rank = fmb_constraints_all(m, w, t0, q, v, NULL, PhiQ, NULL, NULL)
                         ? nq
                         : fmb_independent_rows(nc, nq, PhiQ, 1e-9, order, work);
    if (rank < nq) {
      /* gravity, springs and constraints only (no joint applies forces: nothing feeds energy in)
         bound the configurations the motion can reach by its total energy */
      int conservative = 1;
      for (int j = 0; j < m->njoint; ++j)
        if (m->joint[j].type->force) conservative = 0;
      double cap = INFINITY;
      if (conservative) {
        fmbEnergy e0;
        fmb_energy(m, w, t0, q, v, &e0);
        const double total = e0.kinetic + e0.strain + e0.gravity + e0.spring;
        cap = total + 1e-9 * (fabs(total) + fabs(e0.kinetic)); /* the start's own rounding */
      }
      double vn = 0.0;
      for (int i = 0; i < nq; ++i) vn += v[i] * v[i];
      for (int i = 0; i < nq; ++i) dir[i] = vn > 0.0 ? v[i] : sin(1.7 * i + 0.3);
      /* the way it moves first, then the other way (a swing turns back) */
      memcpy(q_start, q, sizeof(double) * (size_t)nq);
      memcpy(dir_start, dir, sizeof(double) * (size_t)nq);
      singular = walk(m, w, g, t0, q, v, dir, cap);
      if (!singular) {
        memcpy(q, q_start, sizeof(double) * (size_t)nq);
        for (int i = 0; i < nq; ++i) dir[i] = -dir_start[i];
        singular = walk(m, w, g, t0, q, v, dir, cap);
      }
    }
  }
  free(order);
  free(work);
  free(PhiQ);
  free(dir);
  free(dir_start);
  free(q_start);
  free(yp);
  free(y);
  fmb_augmented_free(g);
  fmb_data_destroy(scratch);
  return singular;
}
