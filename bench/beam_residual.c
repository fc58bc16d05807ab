/* beam_residual.c — the beam's residual and Jacobians per second against the mesh (issue 32,
 * item 3: "a cheaper evaluation of the beam's integrals"). White-box, like tests/beam: it includes
 * a version of bodies/beam.c (BEAM_SOURCE, default this tree's) and calls its static ops on the
 * seed beam (complete model, default quadrature) at a fixed random state, so the same program
 * built from two commits' beam.c times the two evaluations side by side (bench/beam_residual.sh).
 *
 *   beam_residual [-n "8 16 ..."] [-r REPEATS] [-t SECONDS]
 *   beam_residual -g
 *
 * Per mesh and per evaluation (residual: the dense residual, residual_aux: the banded assembly's,
 * jacobian: the dense K, C, M, pattern_jacobian: the banded blocks), one line
 *   n=.. what=.. per_s=.. (median of REPEATS timings, each as many calls as fill SECONDS of CPU)
 *   checksum=.. (the sum of |R|: the two builds evaluate the same thing)
 * -g instead prints, per model (8 elements, a random state with gravity), how much the residual
 * moves when evaluated with 3...9 Gauss points instead of 10, over the largest inertial row (the
 * elastic rows K p are exact at any count): which quadrature each model's integrands need. */
#ifndef BEAM_SOURCE
#define BEAM_SOURCE "../bodies/beam.c"
#endif
#include BEAM_SOURCE

#include "bench_cpu.h"

static unsigned long long rng = 88172645463325252ULL;
static double urand(void) {
  rng ^= rng << 13;
  rng ^= rng >> 7;
  rng ^= rng << 17;
  return (double)(rng >> 11) / 9007199254740992.0 * 2.0 - 1.0;
}

static Beam* seed_beam(int ne, int banded) {
  Beam* b = calloc(1, sizeof *b);
  b->model = BEAM_COMPLETE;
  b->ne = ne;
  b->ng = default_points(b->model);
  b->L = 1.8, b->rho = 2767.0, b->A = 2.5e-4, b->Izz = 1.302e-10, b->Emod = 68.95e9;
  b->banded = banded;
  beam_setup(b);
  return b;
}

typedef struct {
  Beam* b;
  fmbEnv env;
  double *q, *v, *a, *z, *R, *Rz, *work, *K, *C, *M;
  int what;
} Case;

enum { RESIDUAL, RESIDUAL_AUX, JACOBIAN, PATTERN_JACOBIAN, NWHAT };
static const char* const what_names[NWHAT] = {"residual", "residual_aux", "jacobian", "pattern_jacobian"};

static double run_once(Case* c) {
  switch (c->what) {
    case RESIDUAL: beam_residual(c->b, &c->env, c->q, c->v, c->a, c->R, c->work); break;
    case RESIDUAL_AUX: beam_residual_aux(c->b, &c->env, c->q, c->v, c->a, c->z, c->R, c->Rz, c->work); break;
    case JACOBIAN: beam_jacobian(c->b, &c->env, c->q, c->v, c->a, c->K, c->C, c->M, c->work); break;
    default: beam_pattern_jacobian(c->b, &c->env, c->q, c->v, c->a, c->z, c->K, c->C, c->M, c->work); break;
  }
  return c->R[3 + c->b->n - 1];
}

static Beam* model_beam(int model, int ne, int ng) {
  Beam* b = seed_beam(ne, 0);
  b->model = model;
  b->ng = ng;
  beam_setup(b);
  return b;
}

static int gauss_table(void) {
  const char* const names[] = {"zoac", "foac", "complete"};
  enum { NE = 8, NC = 3 + 3 * NE };
  const fmbEnv env = {.gravity = {0.3, -9.81}, .has_gravity = 1}, still = {.has_gravity = 0};
  for (int model = BEAM_ZOAC; model <= BEAM_COMPLETE; ++model) {
    double q[NC], v[NC], a[NC], none[NC] = {0.0}, Rel[NC], R10[NC], R[NC];
    for (int i = 0; i < NC; ++i) {
      q[i] = i < 3 ? urand() : 0.05 * urand();
      v[i] = 5.0 * urand();
      a[i] = 100.0 * urand();
    }
    Beam* b10 = model_beam(model, NE, 10);
    double* work = calloc(beam_nwork(b10) + 1, sizeof(double));
    beam_residual(b10, &env, q, v, a, R10, work);
    beam_residual(b10, &still, q, none, none, Rel, work); /* K p alone */
    double scale = 0.0;
    for (int i = 0; i < NC; ++i) scale = fmax(scale, fabs(R10[i] - Rel[i]));
    printf("%s:", names[model]);
    for (int ng = 3; ng <= 9; ++ng) {
      Beam* b = model_beam(model, NE, ng);
      beam_residual(b, &env, q, v, a, R, work);
      double d = 0.0;
      for (int i = 0; i < NC; ++i) d = fmax(d, fabs(R[i] - R10[i]));
      printf(" %d:%.2e", ng, d / scale);
      free(b);
    }
    printf("\n");
    free(work);
    free(b10);
  }
  return 0;
}

int main(int argc, char** argv) {
  if (argc == 2 && strcmp(argv[1], "-g") == 0) return gauss_table();
  const char* ns = "8 16 32 64 128 256 512 1024";
  int repeats = 7;
  double span = 0.2;
  for (int i = 1; i + 1 < argc; i += 2) {
    if (strcmp(argv[i], "-n") == 0)
      ns = argv[i + 1];
    else if (strcmp(argv[i], "-r") == 0)
      repeats = atoi(argv[i + 1]);
    else if (strcmp(argv[i], "-t") == 0)
      span = atof(argv[i + 1]);
    else {
      fprintf(stderr, "usage: beam_residual [-n \"8 16 ...\"] [-r REPEATS] [-t SECONDS]\n");
      return 2;
    }
  }
  if (repeats < 1 || repeats > 99 || !(span > 0.0)) return 2;
  char* list = strdup(ns);
  for (char* tok = strtok(list, " ,"); tok; tok = strtok(NULL, " ,")) {
    const int ne = atoi(tok);
    if (ne < 1 || ne > MAX_ELEMENTS) return 2;
    Beam* dense = seed_beam(ne, 0);
    Beam* banded = seed_beam(ne, 1);
    const int nc = 3 + dense->n, nz = aux_per_element(banded) * ne;
    Case c = {.env = {.gravity = {0.0, -9.81}, .has_gravity = 1}};
    c.q = calloc((size_t)(4 * nc + 2 * nz), sizeof(double));
    c.v = c.q + nc, c.a = c.v + nc, c.R = c.a + nc, c.z = c.R + nc, c.Rz = c.z + nz;
    c.work = calloc(beam_nwork(dense) + 1, sizeof(double));
    const long npat = beam_pattern(banded, NULL, NULL);
    const size_t nk = (size_t)nc * (size_t)nc > (size_t)npat + 1 ? (size_t)nc * (size_t)nc : (size_t)npat + 1;
    const int jac_dense = ne <= 256; /* the dense Jacobian is O(ne^2) per call */
    c.K = calloc(3 * nk, sizeof(double));
    c.C = c.K + nk, c.M = c.C + nk;
    /* a deformed, moving state with the amplitudes of the pendulum's (tip ~ 0.05 m) */
    c.q[2] = 0.3, c.v[2] = 2.0, c.a[0] = 0.5, c.a[1] = -3.0, c.a[2] = 4.0;
    for (int i = 3; i < nc; ++i) {
      c.q[i] = 1e-3 * urand() * (i % 3 == 0 ? 0.01 : 1.0);
      c.v[i] = 1e-2 * urand();
      c.a[i] = 1.0 * urand();
    }
    beam_aux_initial(banded, &c.env, c.q, c.v, c.a, c.z, c.work);
    for (int w = 0; w < NWHAT; ++w) {
      if (w == JACOBIAN && !jac_dense) continue;
      c.what = w;
      c.b = (w == RESIDUAL_AUX || w == PATTERN_JACOBIAN) ? banded : dense;
      /* calls per timing: enough for SPAN seconds, from one calibration run */
      long calls = 1;
      for (;;) {
        double t0 = cpu_now();
        for (long k = 0; k < calls; ++k) run_once(&c);
        if (cpu_now() - t0 > 0.02 || calls > (1L << 40)) {
          calls = (long)(calls * span / fmax(cpu_now() - t0, 1e-9)) + 1;
          break;
        }
        calls *= 2;
      }
      double rate[99], sink = 0.0;
      for (int r = 0; r < repeats; ++r) {
        double t0 = cpu_now();
        for (long k = 0; k < calls; ++k) sink += run_once(&c);
        rate[r] = (double)calls / (cpu_now() - t0);
      }
      double check = 0.0;
      if (w == RESIDUAL || w == RESIDUAL_AUX)
        for (int i = 0; i < nc; ++i) check += fabs(c.R[i]);
      else
        for (size_t i = 0; i < (w == JACOBIAN ? (size_t)nc * nc : (size_t)npat); ++i)
          check += fabs(c.K[i]) + fabs(c.M[i]);
      printf("n=%d what=%s per_s=%.1f checksum=%.15e%s\n", ne, what_names[w], median(rate, repeats), check,
             sink == 12345.6789 ? " " : "");
    }
    free(c.K), free(c.work), free(c.q), free(dense), free(banded);
  }
  free(list);
  return 0;
}
