/* integrator_radau.c — Radau IIA of order 5 (3 stages, solver.integrator: radau5) and of order 9
 * (5 stages, radau9) on the GGL index-2 system of system.c, after Hairer & Wanner's RADAU5 and
 * RADAU (Solving ODEs II, 2nd ed.: IV.8 for the implementation, VI.1 and VII.4 for index-2
 * problems), written for the fully implicit F(t, y, y') = 0. The description below is of s = 3;
 * s = 5 is the same code with its tableau (RadauTableau): A^-1 has one real eigenvalue and two
 * complex pairs, so each Newton iteration solves one real and two complex systems, the error
 * estimate is the embedded one of order 5 and the step controller's exponent 1/6.
 *
 * Why order 9: the flexible pendulum's tip error against its converged solution is set by the
 * bending modes up to ~2000 rad/s, which must keep their phase over 5 s (docs/performance.md,
 * "Where it is hardest"); Radau IIA's error per step in a mode of frequency w is ~ (w h)^(2s)
 * times (s! (s-1)!)/((2s)! (2s-1)!): 1/7200 for s = 3, 2.2e-9 for s = 5, so order 9 keeps them
 * with 3-4x longer steps.
 *
 * Why: BDF above order 2 amplifies the undamped structural modes of a beam (integrator_ida.c), so
 * IDA buys accuracy at the second-order rate. Radau IIA is L-stable at order 5 (order 5 in q and v
 * also for index-2 systems, VII.4 Theorem 4.4 with s = 3: 2s - 1; order s = 3 in the multipliers).
 *
 * Unknowns are the stage increments Z_i = Y_i - y_n (IV.8 (8.2)); the stage derivatives follow
 * from the collocation conditions as Y'_i = (1/h) sum_j (A^-1)_ij Z_j, and the stage equations
 * are F(t_n + c_i h, y_n + Z_i, Y'_i) = 0, i = 1..3. Simplified Newton with J_y = dF/dy and
 * J_y' = dF/dy' frozen at (t_n, y_n, y'_n):
 *   (I (x) J_y + (1/h) A^-1 (x) J_y') dZ = -F,
 * and with A^-1 = T Lambda T^-1, Lambda = diag(gamma, [[alpha, -beta], [beta, alpha]]), dZ = T dW
 * (IV.8 (8.15)-(8.17)) this splits into one real system of size ny,
 *   (J_y + gamma/h J_y') dW_1 = r_1      (exactly fmb_system_jacobian with cj = gamma/h),
 * and one complex one, (J_y + (alpha + i beta)/h J_y') (dW_2 + i dW_3) = r_2 + i r_3, the real
 * 2ny x 2ny system [[A, -B], [B, A]] written as complex numbers, solved with KLU's complex LU on
 * the model's own pattern. J_y and J_y' are kept apart (two evaluations at cj = 0 and cj = 1, the
 * second reassembling the bodies' blocks of the first: J is linear in cj), so a new step size
 * costs two refactorizations and no new derivatives. By default (solver.linear_solver: klu) both
 * systems are solved with the position rows eliminated (schur.c: their q-blocks are (gamma/h) I
 * and ((alpha + i beta)/h) I up to O(|mu|), kept as their diagonals), so KLU factorizes two
 * matrices with nq fewer rows: a modified simplified Newton iteration, as IDA's; klu_full keeps
 * the whole matrices (the exact simplified Newton). If a run on the reduced systems cannot go on
 * (a factorization fails outright, or the step falls to min_step, or the Newton matrix stays
 * singular), the cause may be the dropped O(|mu|) part rather than the model, so the run
 * continues from the last accepted step with the whole matrices, once, and says so: IDA's
 * fallback (integrator_ida.c).
 *
 * Error estimate (IV.8 (8.19)-(8.20), RADAU5's ESTRAD with the mass matrix J_y'):
 *   err = (J_y + gamma/h J_y')^-1 J_y' (y'_n + (1/h) sum_i d_i Z_i),
 * with a second evaluation through the residual after a rejected or first step (8.20). lambda
 * and mu (index 2) and the bodies' auxiliary unknowns carry an absolute tolerance of 1e30
 * (tolerance.c), which leaves them out of both the error and the Newton norms; RADAU5's h-scaling
 * of index-2 components (VII.4) is therefore not needed. Under solver.error_control: positions the
 * velocities leave the error norm too, as in IDA. Tolerances are mapped as RADAU5 maps them
 * (rtol' = 0.1 rtol^(2/3), atol' = atol rtol'/rtol): the embedded estimate is of order 3 while the
 * solution is of order 5.
 *
 * Step size: RADAU5's controller with Gustafsson's predictive variant (IV.8 (8.21)-(8.25)), the
 * Jacobian kept while Newton contracts fast (theta <= FMB_RADAU_THET) and the factorization kept
 * while the step would change by less than 20 %. Dense output: the collocation polynomial
 * (IV.8 (8.26)-(8.28)), also for the next step's Newton start. Work integrals (m->need_work): the
 * joints' powers at the stages with the Radau quadrature (the method's own weights b_i = a_3i,
 * order 5), and between steps the cubic through the powers at t_n and the stages; applied forces'
 * work is in the error test (try_work), as IDA's quadratures are.
 *
 * Everything is allocated in create(); advance() allocates only when KLU has to choose new pivots
 * (a refactorization whose condition estimate has degraded), as SUNDIALS' own KLU module does. */
#include <klu.h> /* SuiteSparse_long */
#include <math.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>

#include "integrator.h"
#include "klu_policy.h"

/* The methods' coefficients: nodes c_i (c_s = 1), the collocation matrix inverse A^-1, the weights
   b_i = a_si (stiffly accurate: also the work integrals' quadrature), the eigen-decomposition of
   A^-1 (T^-1 A^-1 T = diag(gamma, [[alpha_1, -beta_1], [beta_1, alpha_1]], ...), to 1e-15 when
   written: a wrong digit shows as lost order in tests/integrators) and the error estimate's d_i
   (IV.8 (8.19)): d = gamma (bhat - b)^T A^-1, bhat the embedded weights of order s with bhat_0 =
   1/gamma on f(y_n). s = 3 (order 5) is RADAU5's table; s = 5 (order 9) is RADAU's (Hairer &
   Wanner's variable-order code, the same construction), computed here with 40 digits (mpmath:
   the nodes as the zeros of d^(s-1)/dx^(s-1) (x^(s-1) (x - 1)^s), A by integrating the Lagrange
   basis, T from A^-1's eigenvectors scaled to T's last row (1, 1, 0, 1, 0)); tools/radau_tableau.py
   prints this table (and any other odd s) with 50 digits. */
#define RADAU_SMAX 5
typedef struct {
  int s;
  double c[RADAU_SMAX], ainv[RADAU_SMAX][RADAU_SMAX], b[RADAU_SMAX];
  double gamma, alpha[2], beta[2]; /* the real eigenvalue; the (s - 1)/2 complex pairs */
  double t[RADAU_SMAX][RADAU_SMAX], ti[RADAU_SMAX][RADAU_SMAX], dd[RADAU_SMAX];
} RadauTableau;

#define SQ6 2.449489742783178098197284
static const RadauTableau radau_order5 = {
    .s = 3,
    .c = {(4.0 - SQ6) / 10.0, (4.0 + SQ6) / 10.0, 1.0},
    .ainv = {{3.224744871391589, 1.1678400846904058, -0.2531972647421809},
             {-3.5678400846904057, 0.7752551286084112, 1.053197264742181},
             {5.531972647421811, -7.531972647421811, 5.0}},
    .b = {(16.0 - SQ6) / 36.0, (16.0 + SQ6) / 36.0, 1.0 / 9.0},
    .gamma = 3.6378342527444962,
    .alpha = {2.6810828736277523},
    .beta = {3.0504301992474105},
    .t = {{9.1232394870892942792e-02, -0.14125529502095420843, -3.0029194105147424492e-02},
          {0.24171793270710701896, 0.20412935229379993199, 0.38294211275726193779},
          {0.96604818261509293619, 1.0, 0.0}},
    .ti = {{4.3255798900631553510, 0.33919925181580986954, 0.54177053993587487119},
           {-4.1787185915519047273, -0.32768282076106238708, 0.47662355450055045196},
           {-0.50287263494578687595, 2.5719269498556054292, -0.59603920482822492497}},
    .dd = {-(13.0 + 7.0 * SQ6) / 3.0, (-13.0 + 7.0 * SQ6) / 3.0, -1.0 / 3.0},
};
static const RadauTableau radau_order9 = {
    .s = 5,
    .c = {0.05710419611451768219312, 0.27684301363812382768, 0.5835904323689168200567, 0.8602401356562194478479, 1.0},
    .ainv = {{8.755923977938361667632, 2.891942615380117404357, -0.8751863962002650264163, 0.3997052079399654826217,
              -0.1337061638492158356717},
             {-7.161380720145387027392, 1.80607772408364436353, 2.363797176068608369422, -0.8659007802831345191395,
              0.2743380777751942021738},
             {4.122165246243373781044, -4.496017125813394719849, 0.8567652453971776050862, 2.518320949211064374937,
              -0.6570627571343601062552},
             {-3.878663219724010333635, 3.393151918064954168693, -5.188340906407186879197, 0.5812330525808163637523,
              2.809983655279712329602},
             {8.412424223594288656407, -6.970256116656660967032, 8.777114204150473239214, -18.21928231108810092859,
              13.0}},
    .b = {0.1437135607912259413234, 0.2813560151494620601922, 0.3118265229757412540819, 0.2231039010835707444026, 0.04},
    .gamma = 6.286704751729276645173,
    .alpha = {5.70095329867178941917, 3.655694325463572258243},
    .beta = {3.210265600308549888425, 6.543736899360077294021},
    .t = {{0.01357686734494794324766, -0.01147851525522951470794, -0.01401985889287541028108,
           -0.01024204781790882707009, 0.04767387729029572386318},
          {0.001617900401719087476439, -0.007668830749180162885157, 0.02470857842651852681253,
           0.05017286451737105816299, -0.09433181918161143698066},
          {0.0791578533474472076449, 0.01939846399882895091122, 0.08180035370375117083639, -0.2305395340434179467214,
           0.1027030453801258997922},
          {0.4122560826804614519787, 0.4076011712801990666217, 0.1996824278868025259365, 0.3778939022488612495439,
           0.4667441303324943592896},
          {1.0, 1.0, 0.0, 1.0, 0.0}},
    .ti = {{27.69769377568408840917, 12.783337911304406015, 3.208489386713429859798, -0.9514904122489162212717,
            0.7415504960259896033537},
           {-33.04188021351900000806, -17.37695347906356701945, -0.1721290632540055611515, -0.09916977798254264258817,
            0.5312281158383066671849},
           {-8.6114439798752919777, 9.699991409528808231336, 1.914728639696874284851, 2.418692006084940026427,
            -1.047463487935337418694},
           {5.344186437834911598895, 4.593615567759161004454, -3.036360323459424298646, 1.05066019023145886386,
            -0.2727786118642962705386},
           {3.748059807439804860051, -3.984965736343884667252, -1.044415641608018792942, 1.184098568137948487231,
            -0.4499177701567803688988}},
    .dd = {-27.78093394406463730479, 3.641478498049213152712, -1.252547721169118720491, 0.5920031671845428725662, -0.2},
};

/* RADAU5's defaults (IV.8; WORK(2..9) of the Fortran code): at most NIT Newton iterations, safety
   factor, step ratio bounds 1/8 <= h/hnew <= 5.
   NIT is RADAU5's 7 for 3 stages; with s stages the iteration may use 7 + 2.5 (s - 3) (RADAU's
   rule: 12 for radau9), in its cap and in the prediction of slow convergence (newton()). The step
   size's safety factor keeps RADAU5's NIT: it shrinks the next step by ~6 % per Newton iteration
   beyond one, and the w15 spin-up's accuracy under radau9 depends on it (rtol 1e-6: 6.2e-7 m with
   it, 3.1e-6 m with 12 there too). With 7 iterations radau9 failed to converge 331 and 427 times
   on the 170-degree rigid pendulum (rtol 1e-6, 1e-8, atol rtol/100; 49 and 5 with 12, the error in
   x at 1e-8 1.4e-5 -> 7.1e-7 m) while the smooth scenes never need the 8th iteration
   (docs/performance.md, "Where it is hardest").
   THET: keep the Jacobian when Newton contracted by this factor or better. RADAU5's default is
   0.001 for cheap Jacobians and its documentation suggests 0.1 when they are expensive, as ours
   are (finite differences over the beam's dense blocks).
   QUOT1, QUOT2: keep h (and the two factorizations) when the controller would change it by a ratio
   in [QUOT1, QUOT2]. RADAU5 keeps it for [1, 1.2]; here a factorization pair of the 108 x 108
   spin-up matrix costs as much as about 8 residuals, and the steps' ratios wander between 1.2 and
   2 on smooth motion, so 1.2 refactorized at nearly every step (119 LU pairs for 203 steps at
   rtol 1e-6, 0.15 s); up to 4, but for at most KEEP_MAX steps in a row above 1.2, so that h is
   never held far below what the error allows (0.085 s for 291 steps, the same error; held without
   a limit, h stayed where a ratio of 2-4 kept it, more steps for nothing). Must stay below 1/FACR
   = 8, or h never grows at all. */
#define FMB_RADAU_NIT 7
#define FMB_RADAU_SAFE 0.9
#define FMB_RADAU_FACL 5.0
#define FMB_RADAU_FACR 0.125
#define FMB_RADAU_QUOT1 1.0
#define FMB_RADAU_QUOT2 4.0
#define FMB_RADAU_KEEP_MAX 10
#define FMB_RADAU_THET 0.1
#define FMB_RADAU_MAX_SINGULAR 5
/* FLOOR: where the iteration may stop at the velocities' floor (newton()), RADAU5's largest FNEWT */
#define FMB_RADAU_FLOOR 0.03

typedef struct {
  const fmbModel* m;
  const RadauTableau* tab;      /* the method: order 5 (s = 3) or 9 (s = 5) */
  int s, npair;                 /* stages; complex eigenvalue pairs of A^-1, (s - 1)/2 */
  int nit;                      /* Newton iterations allowed (FMB_RADAU_NIT's comment) */
  double expo;                  /* the step controller's exponent, 1/(s + 1) (IV.8 (8.21)) */
  double cnode[RADAU_SMAX + 1]; /* the dense output's nodes in (t - t_n)/h: c_s, ..., c_1, 0 */
  double xnode[RADAU_SMAX + 1]; /* the same in (t - t_{n+1})/h: c_s - 1, ..., c_1 - 1, -1 */
  fmbWorkspace* w;
  const volatile sig_atomic_t* stop;
  int ny, nerr, nnewt; /* unknowns; components in the error norm (the first nerr); in the Newton norm */
  double rtol;         /* RADAU5's mapped tolerance */
  double *atol, *scal, *ewt;
  double t, h, hold, t_end, hmax;
  double *y, *yp; /* the state at t (last accepted step) */
  double *z[RADAU_SMAX], *wt[RADAU_SMAX],
      *fz[RADAU_SMAX];          /* stage increments, transformed ones, residuals / right sides */
  double *ys, *yps;             /* one stage's value and derivative */
  double* cont[RADAU_SMAX + 1]; /* dense output: y_{n+1} and the Newton-form differences */
  double* e2rhs[2];             /* the complex systems' right sides, interleaved (2 ny) */
  double *err, *err2;
  /* Jacobian parts on the model's CSC pattern, and the two iteration matrices */
  double *jy, *jyp, *e1, *e2; /* e2: the E2 of each pair in turn (decompose) */
  /* J_y' by rows, its nonzeros only (jyp_rows, for the error estimate's product) */
  long *jyp_row_ptr, *jyp_row_next;
  int* jyp_row_col;
  double* jyp_row_val;
  SuiteSparse_long *colptr, *rowind;
  fmbKlu *lu1, *lu2[2]; /* klu_full: E1 (real) and the E2s (complex) on the whole pattern (klu.c) */
  /* solver.linear_solver: klu (default): both systems with the position rows eliminated
     (schur.c); klu_full: KLU on the whole matrices above */
  fmbSchur *red1, *red2[2];
  int fell_back; /* the reduced systems failed once: KLU on the whole matrices since */
  int relaxed;   /* error_control: positions: Newton may stop at a floor of the velocities (newton()) */
  double h_lu;   /* the step the factorizations are for (0: none) */
  int need_jac;  /* the next step evaluates a new Jacobian (RADAU5: not after a fast Newton) */
  int caljac;    /* the Jacobian was evaluated at this step's start (t, y) */
  int first, reject, have_cont, nsing;
  int kept; /* consecutive steps that kept h although it could grow by > 1.2 */
  /* A body iterates on a mixed form's fields (fmbBodyType.aux_iterated: the exact beam's axial
     strains): the iteration's first contraction ratio does not give it up (newton_rate). Its
     first correction is dominated by the extrapolated start of the stiff tip slopes, and the
     first iterate lands where |rho'| is nonlinear against EA: on the exact spin-ups the second
     correction was 1.0-1.2x the first (and 0.5-1x with a fresh Jacobian), the third 10-100x
     smaller, the fourth at FNEWT. Judged at the second iteration as RADAU5 does (diverged at a
     ratio >= 0.99, or too slow from the ratio's prediction), those steps failed, the step was
     cut and a Jacobian taken: the omega0 = 15 spin-up under radau9 had 27 failures and 17
     Jacobians in 171 steps at rtol 1e-6, and the omega0 = 4 one took 254 steps at rtol 1e-4
     against 71 at 1e-6, its step held where Newton gave up. Judging from the third iteration
     on, by that iteration's own ratio: 0-3 failures, 2-10 Jacobians (the complete model's 1-8)
     and steps that fall as rtol is loosened (bench/exact_ratio.sh). A start consistent in the
     strains (z = eps of the extrapolated q) was worse (129 failures), a zero start cost 1.5-2x
     the iterations; bodies without such fields keep RADAU5's test bit for bit. */
  int first_ratio_free;
  double hacc, erracc, faccon, theta, fnewt;
  /* work integrals */
  int nwork, nwork_err; /* work integrals; of them in the error test (applied forces') */
  double *work_old, *work_new, *work_out;
  double *p0, *pst[RADAU_SMAX];    /* the powers at the last accepted step's start and stages (work_at) */
  double *pend, *ptry[RADAU_SMAX]; /* at the current state, and at the stages of the step being tried */
  double* work_atol;               /* per joint: the work's absolute tolerance, 0 = out of the error test */
  fmbStats st;
  long lu_reuses;
} RadauRun;

static void radau_destroy(void* self) {
  RadauRun* c = self;
  if (!c) return;
  fmb_klu_free(c->lu1);
  fmb_schur_free(c->red1);
  for (int p = 0; p < 2; ++p) {
    fmb_klu_free(c->lu2[p]);
    fmb_schur_free(c->red2[p]);
    free(c->e2rhs[p]);
  }
  free(c->e2);
  double** vs[] = {&c->atol,     &c->scal,     &c->ewt,  &c->y,        &c->yp,   &c->ys,
                   &c->yps,      &c->err,      &c->err2, &c->jy,       &c->jyp,  &c->e1,
                   &c->work_old, &c->work_new, &c->p0,   &c->work_out, &c->pend, &c->work_atol};
  for (size_t i = 0; i < sizeof vs / sizeof vs[0]; ++i) free(*vs[i]);
  for (int k = 0; k < RADAU_SMAX; ++k) {
    free(c->z[k]);
    free(c->wt[k]);
    free(c->fz[k]);
    free(c->pst[k]);
    free(c->ptry[k]);
  }
  for (int k = 0; k <= RADAU_SMAX; ++k) free(c->cont[k]);
  free(c->colptr);
  free(c->rowind);
  free(c->jyp_row_ptr);
  free(c->jyp_row_next);
  free(c->jyp_row_col);
  free(c->jyp_row_val);
  free(c);
}

static double* dalloc(size_t n) { return calloc(n ? n : 1, sizeof(double)); }

/* RADAU5's weights: scal_i = atol_i + rtol |y_i| */
static void update_scal(RadauRun* c) {
  for (int i = 0; i < c->ny; ++i) {
    c->scal[i] = c->atol[i] + c->rtol * fabs(c->y[i]);
    c->ewt[i] = 1.0 / c->scal[i];
  }
}

/* the joints' powers at (t, y) into p (njoint) */
static int powers(RadauRun* c, double t, const double* y, double* p) {
  const fmbModel* m = c->m;
  for (int j = 0; j < m->njoint; ++j) {
    p[j] = fmb_joint_power(m, c->w, j, t, y, y + m->nq, y + 2 * m->nq);
    if (!isfinite(p[j])) return 1;
  }
  return 0;
}

/* The step history set for a start from (y0, yp0) at t0: what create does after allocating, and
   fmb_set_input's restart (integrator.h) without allocating. The factorizations' symbolic
   analysis (KLU, schur.c) and the counters stay; the fallback to klu_full (fell_back) too. */
static int radau_start(RadauRun* c, double t0, const double* y0, const double* yp0, fmbDiag* diag) {
  const fmbSolverSettings* so = &c->m->solver;
  memcpy(c->y, y0, sizeof(double) * (size_t)c->ny);
  memcpy(c->yp, yp0, sizeof(double) * (size_t)c->ny);
  c->t = t0;
  /* a small first step: RADAU5 leaves it to the caller; the first-step rejection (h / 10) and
     the growth bound (8x per step) reach the dynamics' step within a few steps */
  c->h = fmin(c->hmax, 1e-3 * so->output_step);
  c->h = fmax(c->h, 10.0 * so->min_step);
  c->hold = 0.0;
  c->first = 1;
  c->need_jac = 1;
  c->caljac = 0;
  c->reject = 0;
  c->have_cont = 0;
  c->nsing = 0;
  c->kept = 0;
  c->h_lu = 0.0;
  c->hacc = 0.0;
  c->erracc = 0.0;
  c->faccon = 1.0;
  c->theta = 1.0;
  update_scal(c);
  if (c->nwork) {
    const size_t nw = (size_t)c->nwork;
    memset(c->work_old, 0, sizeof(double) * nw);
    memset(c->work_new, 0, sizeof(double) * nw);
    memset(c->work_out, 0, sizeof(double) * nw);
    if (powers(c, t0, c->y, c->pend)) {
      fmb_diag_set(diag, FMB_EXIT_SOLVER, c->m->path, 0, 0, "%s: a joint's power is not finite at t = %g",
                   c->tab->s == 3 ? "radau5" : "radau9", t0);
      return -1;
    }
  }
  return 0;
}

/* fmb_set_input's restart: the start's step history, but neither the start's small first step
   nor a new Jacobian. Radau IIA is a one-step method, so nothing of the jump at t0 lies inside a
   step that starts there, and the step the controller had chosen for the dynamics before the
   setting fits them after it (a jump that excites faster motion is met by the first step's
   rejection, h / 10): from 1e-3 output_step every restart climbed back by the growth bound (8x a
   step). The Jacobian and, while h stays, its LU are kept too, with the Jacobian marked as not
   fresh (caljac 0), so a Newton iteration that fails on it evaluates a new one, as between any two
   steps; an input seldom enters the Jacobian (a load is additive, a drive's row is theta - u(t)).
   Keeping only the Jacobian was tried with the small first step: its first Newton iteration after
   every restart then failed, 965 times in docs/python.md's 1000 settings, +17 % CPU. With the step
   kept, bench/scenes/input_rotor.yaml's load set every 10 ms with fmb_set_input_motion took 427
   steps (1176 before, 181 with the continuous law), every 1 ms by value 2003 (8168), and
   docs/python.md's speed controller 5370 steps with 220 Jacobians (8105 with 999 keeping the step
   alone, -18 % CPU; 8981 before either). */
static int radau_reinit(void* self, double t0, const double* y0, const double* yp0, fmbDiag* diag) {
  RadauRun* c = self;
  const double h_before = c->h; /* the step the controller proposed next */
  const double h_lu = c->h_lu;
  const int have_jacobian = !c->need_jac;
  const int rc = radau_start(c, t0, y0, yp0, diag);
  if (rc) return rc;
  if (h_before > c->h) c->h = fmin(h_before, c->hmax);
  if (have_jacobian) {
    c->need_jac = 0;
    c->h_lu = h_lu; /* decompose again only for another h (radau_step) */
  }
  return 0;
}

/* klu_full's KLU objects on the whole pattern (at create, or at the fallback from the reduced
   systems): 0, or 1 when out of memory or KLU could not analyze the pattern */
static int full_lu_new(RadauRun* c) {
  const fmbModel* m = c->m;
  const size_t n = (size_t)c->ny, nnz = (size_t)m->nnz;
  if (!c->colptr) { /* KLU's index type; made here only: the reduced systems have their own */
    c->colptr = malloc(sizeof(SuiteSparse_long) * (n + 1));
    c->rowind = malloc(sizeof(SuiteSparse_long) * (nnz ? nnz : 1));
    if (!c->colptr || !c->rowind) return 1;
    for (size_t i = 0; i <= n; ++i) c->colptr[i] = (SuiteSparse_long)m->colptr[i];
    for (size_t k = 0; k < nnz; ++k) c->rowind[k] = (SuiteSparse_long)m->rowind[k];
  }
  /* the iteration matrices' values, which only this path stores (the reduced systems read
     J_y and J_y' as they go: fmb_schur_factor_pencil): one E2 for every pair, each formed and
     factorized in turn (decompose), the factorizations keeping what they need */
  if (!c->e1 && !(c->e1 = dalloc(nnz))) return 1;
  if (c->npair && !c->e2 && !(c->e2 = dalloc(2 * nnz))) return 1;
  if (!(c->lu1 = fmb_klu_new(c->ny, c->colptr, c->rowind, 0))) return 1;
  for (int p = 0; p < c->npair; ++p)
    if (!(c->lu2[p] = fmb_klu_new(c->ny, c->colptr, c->rowind, FMB_KLU_COMPLEX))) return 1;
  return 0;
}

static void* radau_create_tab(const RadauTableau* tab, const fmbIntegratorSetup* s, double t0, const double* y0,
                              const double* yp0, fmbDiag* diag) {
  const fmbModel* m = s->m;
  const int ny = m->ny;
  RadauRun* c = calloc(1, sizeof *c);
  if (!c) goto oom;
  c->tab = tab;
  c->s = tab->s;
  c->npair = (tab->s - 1) / 2;
  c->expo = 1.0 / (tab->s + 1);
  c->nit = FMB_RADAU_NIT + 5 * (tab->s - 3) / 2;
  for (int j = 0; j <= tab->s; ++j) {
    c->cnode[j] = j < tab->s ? tab->c[tab->s - 1 - j] : 0.0;
    c->xnode[j] = c->cnode[j] - 1.0;
  }
  c->m = m;
  c->w = s->w;
  c->stop = s->stop;
  c->ny = ny;
  const size_t n = (size_t)ny, nnz = (size_t)m->nnz;
  c->atol = dalloc(n);
  c->scal = dalloc(n);
  c->ewt = dalloc(n);
  c->y = dalloc(n);
  c->yp = dalloc(n);
  c->ys = dalloc(n);
  c->yps = dalloc(n);
  c->err = dalloc(n);
  c->err2 = dalloc(n);
  c->jy = dalloc(nnz);
  c->jyp = dalloc(nnz);
  c->jyp_row_ptr = calloc(n + 1, sizeof(long));
  c->jyp_row_next = calloc(n + 1, sizeof(long));
  /* J_y' by rows holds J_y''s nonzeros only (jyp_rows), a fraction of the pattern: sized for all,
     written as far as they go (malloc: the pages beyond are never touched, where calloc's clearing
     touched them all; each first touch costs a page fault) */
  c->jyp_row_col = malloc(sizeof(int) * (nnz ? nnz : 1));
  c->jyp_row_val = malloc(sizeof(double) * (nnz ? nnz : 1));
  int ok = c->atol && c->scal && c->ewt && c->y && c->yp && c->ys && c->yps && c->err && c->err2 && c->jy && c->jyp &&
           c->jyp_row_ptr && c->jyp_row_next && c->jyp_row_col && c->jyp_row_val;
  for (int p = 0; p < c->npair; ++p) ok = ok && (c->e2rhs[p] = dalloc(2 * n));
  for (int k = 0; k < c->s; ++k) {
    c->z[k] = dalloc(n);
    c->wt[k] = dalloc(n);
    c->fz[k] = dalloc(n);
    ok = ok && c->z[k] && c->wt[k] && c->fz[k];
  }
  for (int k = 0; k <= c->s; ++k) ok = ok && (c->cont[k] = dalloc(n));
  if (!ok) goto oom;
  int lu_ok = 1;
  if (m->solver.linear_solver == FMB_LS_KLU) {
    lu_ok = (c->red1 = fmb_schur_new(m, 0)) != NULL;
    for (int p = 0; p < c->npair; ++p) lu_ok = lu_ok && (c->red2[p] = fmb_schur_new_like(c->red1, 1));
  } else {
    lu_ok = full_lu_new(c) == 0;
  }
  if (!lu_ok) {
    fmb_diag_set(diag, FMB_EXIT_SOLVER, m->path, 0, 0, "radau5: KLU could not analyze the Newton matrix's pattern");
    radau_destroy(c);
    return NULL;
  }

  /* RADAU5's tolerance map (see the head comment); the index-2 unknowns keep their 1e30 */
  const fmbSolverSettings* so = &m->solver;
  c->rtol = 0.1 * pow(so->rtol, 2.0 / 3.0);
  const double quot = c->rtol / so->rtol;
  const int ndiff = so->positions_only ? m->nq : 2 * m->nq;
  for (int i = 0; i < ny; ++i) {
    c->atol[i] = s->atol[i] >= 1e29 ? s->atol[i] : s->atol[i] * quot;
    if (s->atol[i] < 1e29) c->nnewt++;
    if (i < ndiff && s->atol[i] < 1e29) c->nerr++;
  }
  if (c->nnewt == 0) c->nnewt = 1;
  if (c->nerr == 0) c->nerr = 1;
  c->relaxed = so->positions_only;
  for (int b = 1; b < m->nbody; ++b) c->first_ratio_free |= m->body[b].nz > 0 && m->body[b].aux_iterated;
  /* Newton's stopping tolerance, relative to the error weights (IV.8 (8.12), RADAU5's FNEWT) */
  c->fnewt = fmax(10.0 * 2.220446049250313e-16 / c->rtol, fmin(0.03, sqrt(c->rtol)));

  c->t_end = so->t_end;
  c->hmax = so->max_step > 0 ? so->max_step : so->t_end - so->t0;

  if (m->need_work && m->njoint > 0) {
    c->nwork = m->njoint;
    const size_t nw = (size_t)m->njoint;
    c->work_old = dalloc(nw);
    c->work_new = dalloc(nw);
    c->p0 = dalloc(nw);
    c->work_out = dalloc(nw);
    c->pend = dalloc(nw);
    c->work_atol = dalloc(nw);
    ok = c->work_old && c->work_new && c->p0 && c->work_out && c->pend && c->work_atol;
    for (int k = 0; k < c->s; ++k) ok = ok && (c->pst[k] = dalloc(nw)) && (c->ptry[k] = dalloc(nw));
    if (!ok) goto oom;
    /* Applied forces' work is in the error test, as in IDA (integrator_ida.c: a load law with a
       kink, a ramp or a table, is otherwise integrated across the kink by one polynomial: the
       rotor's energy.balance stayed at 2.7e-2 J at rtol 1e-9, IDA 1.2e-5 J); a constraint's is not
       (its power goes through the multipliers, roundoff of order eps/h^2). The same tolerance as
       IDA's quadratures, mapped as the state's. */
    for (int j = 0; j < m->njoint; ++j)
      if (m->joint[j].nrows == 0) {
        c->work_atol[j] = so->atol * quot;
        c->nwork_err++;
      }
  }
  if (radau_start(c, t0, y0, yp0, diag)) {
    radau_destroy(c);
    return NULL;
  }
  return c;
oom:
  fmb_diag_set(diag, FMB_EXIT_SOLVER, m->path, 0, 0, "out of memory setting up the integrator");
  radau_destroy(c);
  return NULL;
}

/* J_y' by rows, its nonzeros only (jyp_times), after each Jacobian: a counting sort of the CSC
   pattern, columns visited in ascending order so that each row's entries are */
static void jyp_rows(RadauRun* c) {
  const fmbModel* m = c->m;
  long* ptr = c->jyp_row_ptr;
  memset(ptr, 0, sizeof(long) * (size_t)(c->ny + 1));
  for (long k = 0; k < m->nnz; ++k)
    if (c->jyp[k] != 0.0) ptr[m->rowind[k] + 1]++;
  for (int r = 0; r < c->ny; ++r) ptr[r + 1] += ptr[r];
  long* next = c->jyp_row_next;
  memcpy(next, ptr, sizeof(long) * (size_t)c->ny);
  for (int col = 0; col < c->ny; ++col)
    for (long k = m->colptr[col]; k < m->colptr[col + 1]; ++k) {
      if (c->jyp[k] == 0.0) continue;
      const long at = next[m->rowind[k]]++;
      c->jyp_row_col[at] = col;
      c->jyp_row_val[at] = c->jyp[k];
    }
}

/* J_y and J_y' at (t, y, y') from two evaluations of fmb_system_jacobian (J = J_y + cj J_y'):
   cj = 0 with fresh derivatives, then cj = 1 reassembling the same bodies' blocks */
static int evaluate_jacobian(RadauRun* c) {
  const fmbModel* m = c->m;
  /* the auxiliary unknowns, placeholders between Jacobians, made consistent (system.c) */
  if (m->nz > 0 && fmb_system_aux_eliminate(m, c->w, c->y, c->yp)) return 1;
  int rc = fmb_system_jacobian(m, c->w, c->t, 0.0, c->y, c->yp, c->ewt, 0, c->jy, NULL);
  if (rc) return rc;
  rc = fmb_system_jacobian(m, c->w, c->t, 1.0, c->y, c->yp, c->ewt, 1, c->jyp, NULL);
  if (rc) return rc;
  for (long k = 0; k < m->nnz; ++k) c->jyp[k] -= c->jy[k];
  jyp_rows(c);
  c->st.jacobians++;
  c->caljac = 1;
  return 0;
}

/* the iteration matrices' values from J_y and J_y' for the full-pattern KLU (element-wise: AVX2
   clones, internal.h): E1 = J_y + (gamma/h) J_y', and E2_p = J_y + ((alpha_p + i beta_p)/h) J_y'
   into the one E2 buffer, pair by pair (each is factorized before the next is formed: KLU keeps
   what it needs) */
FMB_VECTOR_CLONES static void iteration_matrix_real(RadauRun* c) {
  const long nnz = c->m->nnz;
  const double g = c->tab->gamma / c->h;
  const double* restrict jy = c->jy, * restrict jyp = c->jyp;
  double* restrict e1 = c->e1;
  for (long k = 0; k < nnz; ++k) e1[k] = jy[k] + g * jyp[k];
}

FMB_VECTOR_CLONES static void iteration_matrix_complex(RadauRun* c, int p) {
  const long nnz = c->m->nnz;
  const double a = c->tab->alpha[p] / c->h, b = c->tab->beta[p] / c->h;
  const double* restrict jy = c->jy, * restrict jyp = c->jyp;
  double* restrict e2 = c->e2;
  for (long k = 0; k < nnz; ++k) {
    e2[2 * k] = jy[k] + a * jyp[k];
    e2[2 * k + 1] = b * jyp[k];
  }
}

/* E1 and each E2_p factorized: 0 ok, 1 singular, -1 a reduced factorization failed outright
   (KLU, or the tests' fault injection) */
static int decompose(RadauRun* c) {
  int failed = 0;
  if (c->red1) { /* the reduced factorizations read the matrices' entries from J_y and J_y' */
    failed = fmb_schur_factor_pencil(c->red1, c->jy, c->jyp, c->tab->gamma / c->h, 0.0);
    for (int p = 0; p < c->npair && !failed; ++p)
      failed = fmb_schur_factor_pencil(c->red2[p], c->jy, c->jyp, c->tab->alpha[p] / c->h, c->tab->beta[p] / c->h);
  } else {
    iteration_matrix_real(c);
    failed = fmb_klu_factor(c->lu1, c->e1) != FMB_KLU_OK;
    for (int p = 0; p < c->npair && !failed; ++p) {
      iteration_matrix_complex(c, p);
      failed = fmb_klu_factor(c->lu2[p], c->e2) != FMB_KLU_OK;
    }
  }
  if (failed) {
    c->h_lu = 0.0;
    return failed < 0 ? -1 : 1; /* -1: the reduced factorization failed outright */
  }
  c->h_lu = c->h;
  return 0;
}

/* in place: b = E1^-1 b, and b = E2_p^-1 b with b complex (interleaved); 0 ok, 1 failed */
static int solve_real(RadauRun* c, double* b) {
  if (c->red1) return fmb_schur_solve(c->red1, b);
  return fmb_klu_solve(c->lu1, b);
}

static int solve_complex(RadauRun* c, int p, double* b) {
  if (c->red1) return fmb_schur_solve(c->red2[p], b);
  return fmb_klu_solve(c->lu2[p], b);
}

/* y += J_y' x, by rows from jyp_rows' copy: each row's sum in a register, over its columns in
   ascending order, which is the order the column-wise product added them into y[row] (the same
   result, zeros of J_y' left out: adding a zero product never changes a sum that starts at
   y[row]). By columns every product was a load and a store through y[row], a chain of
   store-to-load dependencies: a quarter of the integrator's own time on the shipped pendulum. */
static void jyp_times(const RadauRun* c, const double* x, double* y) {
  for (int row = 0; row < c->ny; ++row) {
    double sum = y[row];
    for (long k = c->jyp_row_ptr[row]; k < c->jyp_row_ptr[row + 1]; ++k)
      sum += c->jyp_row_val[k] * x[c->jyp_row_col[k]];
    y[row] = sum;
  }
}

/* out = sum_j a[j] v[j] over the s stages, summed from j = 0; by whole vectors (they vectorize) */
FMB_VECTOR_CLONES static void stage_combination(const RadauRun* c, const double* a, double* const* v,
                                                double* restrict out) {
  const int ny = c->ny;
  const double a0 = a[0], *restrict v0 = v[0];
  for (int k = 0; k < ny; ++k) out[k] = a0 * v0[k];
  for (int j = 1; j < c->s; ++j) {
    const double aj = a[j], *restrict vj = v[j];
    for (int k = 0; k < ny; ++k) out[k] += aj * vj[k];
  }
}

/* Y'_i = (1/h) sum_j (A^-1)_ij Z_j into out */
static void stage_derivative(const RadauRun* c, int i, double h, double* out) {
  double a[RADAU_SMAX] = {0.0};
  for (int j = 0; j < c->s; ++j) a[j] = c->tab->ainv[i][j] / h;
  stage_combination(c, a, c->z, out);
}

enum { NEWTON_OK = 0, NEWTON_SLOW = 1, NEWTON_DIVERGED = 2, NEWTON_FATAL = 3 };

/* The iteration's contraction rate theta and its predicted error after nit iterations (IV.8
   (8.13)-(8.14)) */
typedef struct {
  double dynold, thqold, theta, faccon;
  int second_look; /* the first ratio was not judged: the second one alone is the rate */
} NewtonRate;

/* the rate after iteration newt of the norm dyno: NEWTON_OK (go on), NEWTON_SLOW (with *hfac) or
   NEWTON_DIVERGED. With c->first_ratio_free a verdict at the second iteration is deferred to the
   third, which is judged by its own ratio (RadauRun.first_ratio_free); a second ratio that passes
   goes on as RADAU5's, averaged with the first. */
static int newton_rate(const RadauRun* c, NewtonRate* r, double dyno, int newt, double* hfac) {
  if (newt > 1 && newt < c->nit) {
    const double thq = dyno / r->dynold;
    r->theta = newt == 2 || (newt == 3 && r->second_look) ? thq : sqrt(thq * r->thqold);
    r->thqold = thq;
    int verdict = NEWTON_OK;
    if (r->theta >= 0.99)
      verdict = NEWTON_DIVERGED;
    else {
      r->faccon = r->theta / (1.0 - r->theta);
      const double dyth = r->faccon * dyno * pow(r->theta, c->nit - 1 - newt) / c->fnewt;
      if (dyth >= 1.0) {
        const double qnewt = fmax(1e-4, fmin(20.0, dyth));
        *hfac = 0.8 * pow(qnewt, -1.0 / (4.0 + c->nit - 1 - newt));
        verdict = NEWTON_SLOW;
      }
    }
    if (verdict != NEWTON_OK && newt == 2 && c->first_ratio_free) {
      /* a third iteration judges, by its own ratio; no convergence declared at this one */
      r->second_look = 1;
      r->faccon = 1e10;
      verdict = NEWTON_OK;
    }
    if (verdict != NEWTON_OK) return verdict;
  }
  r->dynold = fmax(dyno, 2.220446049250313e-16);
  return NEWTON_OK;
}

/* The simplified Newton iteration of IV.8 (8.12)-(8.16) on the stage increments, started from
   the current c->z: W = (T^-1 (x) I) Z, one real system for W_1 and one complex one per pair
   (W_2p + i W_2p+1). NEWTON_SLOW sets *hfac, RADAU5's prediction of a step that converges.

   Under error_control: positions the iteration may also stop at a floor (c->relaxed). A refined
   beam's highest bending modes (at its free tip; omega h ~ 10-30 at 64 elements) leave a floor in
   their velocities' corrections that the frozen Jacobian cannot go below: on the pendulum at rtol
   1e-10 the plain norm (velocities held to their own scal_v) stalls at 10-600 x FNEWT after a
   slow contraction, while the steps that converge at the 2nd iteration pass only on theta's
   extrapolation. With 64 elements 456 of 5,896 steps of the first 0.2 s failed so (each a new
   Jacobian and a halved step), 2,212 of 5,610 with 128. The positions do not see that floor: a
   correction dv moves them by h dv within the step, and the error test does not weigh v. So when
   the plain norm gives up (slow, diverging, out of iterations) after two iterations while the
   correction weighted as the positions see it (velocities by min(1/scal_v, h/scal_q)) is below
   FMB_RADAU_FLOOR (RADAU5's loosest Newton tolerance, 0.03), the iterate stands and the next step
   takes a new Jacobian: 0 failures, 2.5 iterations per step at 64 and 128 elements. A run whose
   iteration never gave up (the shipped 16-element pendulum) keeps its iterates bit for bit.
   Stopping already when the plain norm stalled (a ratio >= 0.3) saved iterations but moved the
   shipped pendulum's tip error 1.2e-7 -> 3.0e-7 m, and weighing every iteration's velocities by h
   (stopping at the 2nd) to 4.5e-7 m: a slow mode's velocity error is not damped and grows into the
   positions over the run. */
static int newton(RadauRun* c, int* newt_out, double* hfac) {
  const fmbModel* m = c->m;
  const RadauTableau* tab = c->tab;
  const int ny = c->ny, s = c->s, nq = m->nq;
  const double h = c->h;
  for (int i = 0; i < s; ++i) stage_combination(c, tab->ti[i], c->z, c->wt[i]);
  c->faccon = pow(fmax(c->faccon, 2.220446049250313e-16), 0.8);
  c->theta = fabs(FMB_RADAU_THET);
  NewtonRate plain = {.theta = c->theta, .faccon = c->faccon};
  int at_floor = 0; /* the last correction, weighted as the positions see it, <= FMB_RADAU_FLOOR */
  int newt = 0;
  for (;;) {
    if (newt >= c->nit) {
      *newt_out = newt;
      if (at_floor) { /* out of iterations at the floor: as a stall (below) */
        c->theta = fmax(c->theta, 1.0);
        break;
      }
      return NEWTON_DIVERGED;
    }
    if (fmb_stop_requested(c->stop)) return NEWTON_FATAL;
    for (int i = 0; i < s; ++i) {
      for (int k = 0; k < ny; ++k) c->ys[k] = c->y[k] + c->z[i][k];
      stage_derivative(c, i, h, c->yps);
      const int rc = fmb_system_residual_eliminated(m, c->w, c->t + tab->c[i] * h, c->ys, c->yps, c->fz[i]);
      c->st.residuals++;
      if (rc < 0) return NEWTON_FATAL;
      if (rc > 0) { /* not finite: a smaller step */
        *newt_out = newt;
        return NEWTON_DIVERGED;
      }
    }
    /* right sides -(T^-1 (x) I) F: pair p's interleaved into e2rhs[p], the real one into fz[0]
       last (through ys, free here: fz[0] is an input to all of them) */
    for (int p = 0; p < c->npair; ++p) {
      double* restrict rhs = c->e2rhs[p];
      stage_combination(c, tab->ti[1 + 2 * p], c->fz, c->yps);
      for (int k = 0; k < ny; ++k) rhs[2 * k] = -c->yps[k];
      stage_combination(c, tab->ti[2 + 2 * p], c->fz, c->yps);
      for (int k = 0; k < ny; ++k) rhs[2 * k + 1] = -c->yps[k];
    }
    stage_combination(c, tab->ti[0], c->fz, c->ys);
    for (int k = 0; k < ny; ++k) c->fz[0][k] = -c->ys[k];
    int failed = solve_real(c, c->fz[0]);
    for (int p = 0; p < c->npair && !failed; ++p) failed = solve_complex(c, p, c->e2rhs[p]);
    if (failed) {
      *newt_out = newt;
      return NEWTON_DIVERGED;
    }
    newt++;
    c->st.newton_iters++;
    double dyno = 0.0, dynr = 0.0;
    for (int k = 0; k < ny; ++k) {
      const double e = c->ewt[k], a = c->fz[0][k] * e;
      double sum = a * a; /* summed as the s = 3 code did, (a^2 + b^2) + d^2: its runs stay bit for bit */
      for (int p = 0; p < c->npair; ++p) {
        const double b = c->e2rhs[p][2 * k] * e, d = c->e2rhs[p][2 * k + 1] * e;
        sum += b * b;
        sum += d * d;
      }
      dyno += sum;
      if (c->relaxed) {
        const double ratio = k >= nq && k < 2 * nq ? fmin(1.0, h * c->ewt[k - nq] / e) : 1.0;
        dynr += sum * ratio * ratio;
      }
    }
    dyno = sqrt(dyno / ((double)s * c->nnewt));
    dynr = sqrt(dynr / ((double)s * c->nnewt));
    if (!isfinite(dyno)) {
      *newt_out = newt;
      return NEWTON_DIVERGED;
    }
    const int verdict = newton_rate(c, &plain, dyno, newt, hfac);
    at_floor = c->relaxed && newt > 2 && dynr <= FMB_RADAU_FLOOR;
    const int stalled = at_floor && verdict != NEWTON_OK;
    if (verdict != NEWTON_OK && !stalled) {
      c->theta = plain.theta;
      *newt_out = newt;
      return verdict;
    }
    for (int k = 0; k < ny; ++k) c->wt[0][k] += c->fz[0][k];
    for (int p = 0; p < c->npair; ++p) {
      double* restrict wr = c->wt[1 + 2 * p], * restrict wi = c->wt[2 + 2 * p];
      const double* restrict rhs = c->e2rhs[p];
      for (int k = 0; k < ny; ++k) {
        wr[k] += rhs[2 * k];
        wi[k] += rhs[2 * k + 1];
      }
    }
    for (int i = 0; i < s; ++i) stage_combination(c, tab->t[i], c->wt, c->z[i]);
    c->theta = plain.theta;
    c->faccon = plain.faccon;
    if (plain.faccon * dyno <= c->fnewt) break;
    if (stalled) { /* the iterate stands; a new Jacobian for the next step */
      c->theta = fmax(plain.theta, 1.0);
      break;
    }
  }
  *newt_out = newt;
  return NEWTON_OK;
}

static double err_norm(const RadauRun* c, const double* e) {
  double s = 0.0;
  for (int k = 0; k < c->nerr; ++k) {
    if (c->atol[k] >= 1e29) continue;
    const double r = e[k] * c->ewt[k];
    s += r * r;
  }
  return fmax(sqrt(s / c->nerr), 1e-10);
}

/* RADAU5's ESTRAD for F(t, y, y') = 0 (IV.8 (8.19)-(8.20)); -1 when a solve or residual failed */
static double estimate_error(RadauRun* c) {
  const int ny = c->ny;
  const double h = c->h;
  double* delta = c->ys; /* (1/h) sum d_i Z_i */
  stage_combination(c, c->tab->dd, c->z, delta);
  for (int k = 0; k < ny; ++k) delta[k] /= h;
  for (int k = 0; k < ny; ++k) {
    c->err[k] = 0.0;
    c->yps[k] = c->yp[k] + delta[k];
  }
  jyp_times(c, c->yps, c->err);
  if (solve_real(c, c->err)) return -1.0;
  double err = err_norm(c, c->err);
  if (err >= 1.0 && (c->first || c->reject)) {
    /* (8.20): the estimate once more through the residual at y_n + err, which filters the stiff
       components that the linear estimate overstates; F(t, y, -delta) = -(f(y) + M delta) */
    for (int k = 0; k < ny; ++k) {
      c->err2[k] = c->y[k] + c->err[k];
      c->yps[k] = -delta[k];
    }
    const int rc = fmb_system_residual_eliminated(c->m, c->w, c->t, c->err2, c->yps, c->err);
    c->st.residuals++;
    if (rc) return -1.0;
    for (int k = 0; k < ny; ++k) c->err[k] = -c->err[k];
    if (solve_real(c, c->err)) return -1.0;
    err = err_norm(c, c->err);
  }
  return err;
}

/* the collocation polynomial of the step just accepted (IV.8 (8.26)), Newton form in x = (t -
   t_{n+1})/h through the nodes x_j = c_{s-j} - 1 (Z_{s-j}, j < s) and x_s = -1 (y_n): cont[0] =
   y_{n+1}, cont[l] the l-th divided difference */
static void store_dense_output(RadauRun* c) {
  const int s = c->s;
  const double* x = c->cnode; /* node differences as differences of the c_i: the s = 3 code's
                                 divisors (c2 - 1, c1 - c2, c1, ...) bit for bit */
  /* the divided-difference table by whole vectors, cont[j] holding d_j and Z_s standing for d_0
     (it is not overwritten): the same operations per component as a table per component, but
     the divisions of all components run together instead of in one dependent chain per
     component (a fifth of the integrator's own time on the shipped pendulum, perf) */
  const int ny = c->ny;
  for (int j = 1; j < s; ++j) memcpy(c->cont[j], c->z[s - 1 - j], sizeof(double) * (size_t)ny);
  memset(c->cont[s], 0, sizeof(double) * (size_t)ny);
  for (int l = 1; l <= s; ++l)
    for (int j = s; j >= l; --j) {
      const double dx = x[j] - x[j - l];
      double* restrict dj = c->cont[j];
      const double* restrict dprev = j - 1 == 0 ? c->z[s - 1] : c->cont[j - 1];
      for (int k = 0; k < ny; ++k) dj[k] = (dj[k] - dprev[k]) / dx;
    }
  memcpy(c->cont[0], c->y, sizeof(double) * (size_t)ny);
  c->have_cont = 1;
}

/* the polynomial's part after cont[0] at x for every component (p), and its x-derivative (dp,
   unless NULL): Horner on the Newton form, by whole vectors (the recurrences of all components run
   together; per component the same operations as one at a time). The one
   evaluation of the step's polynomial: dense output and the Newton start. */
FMB_VECTOR_CLONES static void dense_poly(const RadauRun* c, double x, double* restrict p, double* restrict dp) {
  const int ny = c->ny;
  memcpy(p, c->cont[c->s], sizeof(double) * (size_t)ny);
  if (dp) memset(dp, 0, sizeof(double) * (size_t)ny);
  for (int l = c->s - 1; l >= 1; --l) {
    const double dx = x - c->xnode[l];
    const double* restrict cl = c->cont[l];
    if (dp)
      for (int k = 0; k < ny; ++k) dp[k] = p[k] + dx * dp[k];
    for (int k = 0; k < ny; ++k) p[k] = cl[k] + dx * p[k];
  }
}

/* y and y' of the last step's polynomial at t (within it): p in y and dp in yp, then combined */
FMB_VECTOR_CLONES static void dense_output(const RadauRun* c, double t, double* restrict y, double* restrict yp) {
  const double x = (t - c->t) / c->hold;
  dense_poly(c, x, y, yp);
  const double* restrict c0 = c->cont[0];
  for (int k = 0; k < c->ny; ++k) {
    const double p = y[k];
    yp[k] = (p + x * yp[k]) / c->hold;
    y[k] = c0[k] + x * p;
  }
}

/* the Newton start: the last step's polynomial extrapolated to the new stages (RADAU5), also
   after a rejected step; zero on the first step, where there is no polynomial yet, and after the
   third Newton failure of a step in a row (radau_step) */
static void starting_values(RadauRun* c, int zero) {
  if (zero || !c->have_cont) {
    for (int i = 0; i < c->s; ++i) memset(c->z[i], 0, sizeof(double) * (size_t)c->ny);
    return;
  }
  const double ratio = c->h / c->hold;
  for (int i = 0; i < c->s; ++i) {
    const double xq = c->tab->c[i] * ratio;
    double* zi = c->z[i];
    dense_poly(c, xq, zi, NULL);
    for (int k = 0; k < c->ny; ++k) zi[k] *= xq;
  }
}

/* wgt[k] = int_0^theta l_k, l_k the Lagrange basis on the nodes 0, c_1, ..., c_s: the weights of
   the polynomial through a step's start and its stages, by 3-point Gauss-Legendre (exact to
   degree 5 >= s) */
static void node_weights(const RadauRun* c, double theta, double wgt[RADAU_SMAX + 1]) {
  static const double gx[3] = {-0.7745966692414834, 0.0, 0.7745966692414834}, gw[3] = {5.0 / 9.0, 8.0 / 9.0, 5.0 / 9.0};
  const int n = c->s + 1;
  double nodes[RADAU_SMAX + 1];
  nodes[0] = 0.0;
  for (int i = 0; i < c->s; ++i) nodes[i + 1] = c->tab->c[i];
  for (int k = 0; k < n; ++k) wgt[k] = 0.0;
  for (int g = 0; g < 3; ++g) {
    const double s = 0.5 * theta * (gx[g] + 1.0);
    for (int k = 0; k < n; ++k) {
      double l = 1.0;
      for (int j = 0; j < n; ++j)
        if (j != k) l *= (s - nodes[j]) / (nodes[k] - nodes[j]);
      wgt[k] += 0.5 * theta * gw[g] * l;
    }
  }
}

/* work integrals at t within the last step: W_old + h int_0^theta p, p the polynomial through the
   powers at the step's start and its stages */
static void work_at(RadauRun* c, double t, double* out) {
  const double t_old = c->t - c->hold, theta = (t - t_old) / c->hold;
  double wgt[RADAU_SMAX + 1];
  node_weights(c, theta, wgt);
  for (int j = 0; j < c->nwork; ++j) {
    double sum = wgt[0] * c->p0[j];
    for (int i = 0; i < c->s; ++i) sum += wgt[i + 1] * c->pst[i][j];
    out[j] = c->work_old[j] + c->hold * sum;
  }
}

/* the step's quadrature sum_i b_i p_i of the powers at the stages */
static double stage_quadrature(const RadauRun* c, double* const* pst, int j) {
  double sum = c->tab->b[0] * pst[0][j];
  for (int i = 1; i < c->s; ++i) sum += c->tab->b[i] * pst[i][j];
  return sum;
}

/* The joints' powers at the stages of the step being tried (from c->t, c->y), and the work
   integrals' contribution to its error norm: sum over the joints in the test of the squared
   weighted difference between the step's quadrature (Radau, order 2s - 1) and the polynomial's
   through the step's start and stages (node_weights(1), exact to degree s), an estimate of order
   h^(s+2) P^(s+1), as the state's of order h^(s+1). *sum = -1 when a power is not finite. */
static void try_work(RadauRun* c, double h, double* sum) {
  *sum = 0.0;
  for (int i = 0; i < c->s; ++i) {
    for (int k = 0; k < c->ny; ++k) c->ys[k] = c->y[k] + c->z[i][k];
    if (powers(c, c->t + c->tab->c[i] * h, c->ys, c->ptry[i])) {
      *sum = -1.0;
      return;
    }
  }
  if (!c->nwork_err) return;
  double wc[RADAU_SMAX + 1];
  node_weights(c, 1.0, wc);
  for (int j = 0; j < c->nwork; ++j) {
    if (c->work_atol[j] <= 0.0) continue;
    const double radau = stage_quadrature(c, c->ptry, j);
    double poly = wc[0] * c->pend[j];
    for (int i = 0; i < c->s; ++i) poly += wc[i + 1] * c->ptry[i][j];
    const double w = c->work_new[j] + h * radau;
    const double r = h * (radau - poly) / (c->work_atol[j] + c->rtol * fmax(fabs(w), fabs(c->work_new[j])));
    *sum += r * r;
  }
}

/* the step accepted: its powers become the last step's, and the work runs to its end */
static void accept_work(RadauRun* c, double h) {
  memcpy(c->work_old, c->work_new, sizeof(double) * (size_t)c->nwork);
  memcpy(c->p0, c->pend, sizeof(double) * (size_t)c->nwork);
  for (int i = 0; i < c->s; ++i) memcpy(c->pst[i], c->ptry[i], sizeof(double) * (size_t)c->nwork);
  memcpy(c->pend, c->ptry[c->s - 1], sizeof(double) * (size_t)c->nwork);
  for (int j = 0; j < c->nwork; ++j) c->work_new[j] = c->work_old[j] + h * stage_quadrature(c, c->pst, j);
}

typedef enum { FAIL_NONE, FAIL_STEPS, FAIL_MIN_STEP, FAIL_SINGULAR, FAIL_RESIDUAL, FAIL_JACOBIAN, FAIL_POWER } FailKind;

/* the backend's name, as solver.integrator spells it */
static const char* radau_name(const RadauRun* c) {
  return c->s == 5 ? fmb_integrator_radau9.name : fmb_integrator_radau5.name;
}

static void describe_failure(const RadauRun* c, FailKind kind, char* why, size_t len) {
  const fmbSolverSettings* so = &c->m->solver;
  const char* name = radau_name(c);
  switch (kind) {
    case FAIL_STEPS:
      snprintf(
          why, len,
          "too many steps between two outputs (solver.max_steps = %ld): the problem is very stiff or changing very "
          "fast here. Try a larger solver.max_steps, a looser rtol, or solver.integrator: ida",
          so->max_steps_per_output);
      break;
    case FAIL_MIN_STEP:
      snprintf(why, len,
               "the step fell to solver.min_step = %.3g (%s) after repeated Newton or error-test failures (Newton "
               "contraction %.3g): the solution is blowing up or jumps, or the mechanism passes a singular "
               "configuration. Check the model; solver.integrator: ida may pass where %s stops [%s]",
               so->min_step, so->min_step_given ? "as given" : "the default, 1e-12 x (t_end - t0)", c->theta, name,
               name);
      break;
    case FAIL_SINGULAR:
      snprintf(why, len,
               "the Newton matrix could not be factorized %d times in a row (it is singular): a singular mechanism "
               "configuration (a dead point) or a mass matrix that lost definiteness [%s]",
               FMB_RADAU_MAX_SINGULAR, name);
      break;
    case FAIL_RESIDUAL: snprintf(why, len, "a plugin could not evaluate its equations [%s]", name); break;
    case FAIL_JACOBIAN:
      snprintf(why, len, "the Newton matrix could not be evaluated at the last good state [%s]", name);
      break;
    case FAIL_POWER: snprintf(why, len, "a joint's power (the work outputs) is not finite [%s]", name); break;
    default: snprintf(why, len, "the integrator stopped [%s]", name); break;
  }
}

/* One accepted step from c->t (RADAU5's main loop, IV.8: labels 10 new Jacobian, 20 new LU, 30
   new step); FAIL_NONE, or why none could be taken. *interrupted on a stop request. */
static FailKind radau_step(RadauRun* c, int* interrupted) {
  const fmbSolverSettings* so = &c->m->solver;
  int zero_start = c->first;
  int newton_fails = 0; /* of this step, in a row */
  c->caljac = 0;
  for (;;) {
    if (fmb_stop_requested(c->stop)) {
      *interrupted = 1;
      return FAIL_NONE;
    }
    /* the last step ends on t_end exactly (RADAU5's LAST) */
    c->h = fmin(c->h, c->hmax);
    const int last = c->t + c->h * 1.0000001 >= c->t_end;
    if (last) c->h = c->t_end - c->t;
    if (c->h < so->min_step && !last) return FAIL_MIN_STEP;
    if (c->need_jac) {
      const int rc = evaluate_jacobian(c);
      if (rc < 0) return FAIL_JACOBIAN;
      if (rc > 0) {
        c->h *= 0.5;
        c->reject = 1;
        continue;
      }
      c->need_jac = 0;
      c->h_lu = 0.0;
    }
    if (c->h != c->h_lu) {
      const int dc = decompose(c);
      if (dc < 0 && c->red1) return FAIL_SINGULAR; /* the reduced systems' own failure: the fallback */
      if (dc) {
        if (++c->nsing >= FMB_RADAU_MAX_SINGULAR) return FAIL_SINGULAR;
        c->h *= 0.5;
        c->reject = 1;
        c->need_jac = !c->caljac;
        continue;
      }
      c->nsing = 0;
      if (!c->caljac) c->lu_reuses++;
    }
    starting_values(c, zero_start);
    int newt = 0;
    double hfac = 0.5;
    const int nr = newton(c, &newt, &hfac);
    if (nr == NEWTON_FATAL) {
      if (fmb_stop_requested(c->stop)) {
        *interrupted = 1;
        return FAIL_NONE;
      }
      return FAIL_RESIDUAL;
    }
    if (nr != NEWTON_OK) {
      /* RADAU5's "unexpected step rejection" (label 78) or its cut for slow convergence; a new
         Jacobian unless this one is already fresh. The retry starts from the extrapolated
         polynomial, as RADAU5's does; from the third failure of the step in a row, from zero.
         Zero at once stalled the slider-crank's rigid limit (radau5 2,025 failures in 1,724
         steps, radau9 stopped; now 101 in 214 and 51 in 60), extrapolation alone stopped radau5
         at rtol 1e-12, atol 1e-14 on the shipped slider-crank (t = 0.0053 s; now through). */
      c->st.conv_fails++;
      c->h *= nr == NEWTON_SLOW ? hfac : 0.5;
      c->reject = 1;
      zero_start = ++newton_fails >= 3;
      c->need_jac = !c->caljac;
      continue;
    }
    double err = estimate_error(c);
    if (err >= 0.0 && c->nwork) {
      double wsum = 0.0;
      try_work(c, c->h, &wsum);
      if (wsum < 0.0) return FAIL_POWER;
      if (c->nwork_err) err = fmax(sqrt((err * err * c->nerr + wsum) / (c->nerr + c->nwork_err)), 1e-10);
    }
    if (err < 0.0) { /* a solve or the residual failed: as a Newton failure */
      c->st.conv_fails++;
      c->h *= 0.5;
      c->reject = 1;
      c->need_jac = !c->caljac;
      continue;
    }
    /* step size (IV.8 (8.21)-(8.25)): the safety factor shrinks with the Newton iterations used,
       by RADAU5's NIT for every s (FMB_RADAU_NIT's comment) */
    const double cfac = FMB_RADAU_SAFE * (1 + 2 * FMB_RADAU_NIT);
    const double fac = fmin(FMB_RADAU_SAFE, cfac / (newt + 2 * FMB_RADAU_NIT));
    double quot = fmax(FMB_RADAU_FACR, fmin(FMB_RADAU_FACL, pow(err, c->expo) / fac));
    double hnew = c->h / quot;
    if (err >= 1.0) {
      c->st.error_test_fails++;
      c->reject = 1;
      c->h = c->first ? 0.1 * c->h : hnew;
      c->need_jac = !c->caljac;
      continue;
    }
    /* accepted; Gustafsson's predictive controller (IV.8 (8.25)) */
    if (!c->first) { /* not on a start's first step (a run's, or radau_reinit's: no hacc, erracc yet) */
      double facgus = (c->hacc / c->h) * pow(err * err / c->erracc, c->expo) / FMB_RADAU_SAFE;
      facgus = fmax(FMB_RADAU_FACR, fmin(FMB_RADAU_FACL, facgus));
      quot = fmax(quot, facgus);
      hnew = c->h / quot;
    }
    c->hacc = c->h;
    c->erracc = fmax(1e-2, err);
    const double t_old = c->t, h = c->h;
    /* y_{n+1} = y_n + Z_3 (stiffly accurate); y'_{n+1} = Y'_3 */
    stage_derivative(c, c->s - 1, h, c->yp);
    for (int k = 0; k < c->ny; ++k) c->y[k] += c->z[c->s - 1][k];
    c->t = last ? c->t_end : t_old + h;
    c->hold = h;
    c->st.steps++;
    store_dense_output(c);
    if (c->nwork) accept_work(c, h);
    update_scal(c);
    c->first = 0;
    hnew = fmin(hnew, c->hmax);
    if (c->reject) hnew = fmin(hnew, h);
    c->reject = 0;
    /* keep h and the factorizations when Newton converged fast and the step would change little;
       keep the Jacobian (a new LU only) when Newton converged fast */
    const double qt = hnew / h;
    const int keep = c->theta <= FMB_RADAU_THET && qt >= FMB_RADAU_QUOT1 && qt <= FMB_RADAU_QUOT2 &&
                     (qt <= 1.2 || c->kept < FMB_RADAU_KEEP_MAX);
    c->kept = keep && qt > 1.2 ? c->kept + 1 : 0;
    if (!keep) c->h = hnew;
    c->need_jac = c->theta > FMB_RADAU_THET;
    return FAIL_NONE;
  }
}

/* the fallback (head comment): the whole matrices from here on, a fresh Jacobian, and the step
   size of the last accepted step (the failed attempts drove h to where the reduced systems gave
   up); 0 ok, 1 KLU could not analyze the whole pattern (the caller then reports the failure) */
static int fall_back_to_full(RadauRun* c) {
  fmb_schur_free(c->red1);
  c->red1 = NULL;
  for (int p = 0; p < c->npair; ++p) {
    fmb_schur_free(c->red2[p]);
    c->red2[p] = NULL;
  }
  c->fell_back = 1;
  if (full_lu_new(c)) return 1;
  if (c->hold > 0.0) c->h = c->hold;
  c->need_jac = 1;
  c->h_lu = 0.0;
  c->nsing = 0;
  c->reject = 1;
  fmb_warn(c->w,
           "note: t = %.6g: %s failed with the reduced Newton solve (solver.linear_solver: klu); continuing "
           "from the last good step with klu_full (the whole matrices)",
           c->t, radau_name(c));
  return 0;
}

static int radau_advance(void* self, double tout, double* t_reached, double* y, double* yp, double* h, char* why,
                         size_t why_len) {
  RadauRun* c = self;
  const fmbModel* m = c->m;
  long steps = 0;
  int interrupted = 0;
  FailKind fail = FAIL_NONE;
  while (c->t < tout - 1e-14 * fmax(1.0, fabs(tout))) {
    if (steps >= m->solver.max_steps_per_output) {
      fail = FAIL_STEPS;
      break;
    }
    fail = radau_step(c, &interrupted);
    if (!interrupted && c->red1 && (fail == FAIL_MIN_STEP || fail == FAIL_SINGULAR)) {
      if (fall_back_to_full(c)) break;
      fail = FAIL_NONE;
      continue;
    }
    if (fail != FAIL_NONE || interrupted) break;
    steps++;
  }
  *h = c->h;
  if (fail == FAIL_NONE && !interrupted) {
    if (c->have_cont && tout < c->t) {
      dense_output(c, tout, y, yp);
      if (c->nwork) work_at(c, tout, c->work_out);
    } else {
      memcpy(y, c->y, sizeof(double) * (size_t)c->ny);
      memcpy(yp, c->yp, sizeof(double) * (size_t)c->ny);
      if (c->nwork) memcpy(c->work_out, c->work_new, sizeof(double) * (size_t)c->nwork);
    }
    *t_reached = tout;
    return FMB_ADVANCE_OK;
  }
  /* the last good state: the end of the last accepted step */
  memcpy(y, c->y, sizeof(double) * (size_t)c->ny);
  memcpy(yp, c->yp, sizeof(double) * (size_t)c->ny);
  *t_reached = c->t;
  if (c->nwork) memcpy(c->work_out, c->work_new, sizeof(double) * (size_t)c->nwork);
  if (interrupted) return FMB_ADVANCE_INTERRUPTED;
  describe_failure(c, fail, why, why_len);
  return FMB_ADVANCE_FAILED;
}

static void radau_work(void* self, double* work) {
  RadauRun* c = self;
  memcpy(work, c->work_out, sizeof(double) * (size_t)c->nwork);
}

static void radau_stats(const void* self, fmbStats* st) {
  const RadauRun* c = self;
  st->steps = c->st.steps;
  st->residuals = c->st.residuals;
  st->jacobians = c->st.jacobians;
  st->newton_iters = c->st.newton_iters;
  st->error_test_fails = c->st.error_test_fails;
  st->conv_fails = c->st.conv_fails;
  st->jacobians_reused = c->lu_reuses;
  st->integrator = radau_name(c);
}

/* radau5's cross-key rules */
/* radau5's and radau9's cross-key rules */
static int radau_check(const fmbModel* m, fmbParser* p, fmbNode solver) {
  const char* name = m->solver.integrator ? m->solver.integrator->name : fmb_integrator_radau5.name;
  /* radau integrates the GGL system; the projected formulation has its own backend (CVODE) */
  if (m->solver.formulation == FMB_FORM_PROJECTED)
    return fmb_parse_error(p, fmb_find_key(p, solver, "integrator"),
                           "integrator: %s integrates the GGL formulation; formulation: projected has its own "
                           "integrator (CVODE): drop one of the two keys",
                           name);
  /* radau's systems are complex as well as real; SUNDIALS' dense LU is real only */
  if (m->solver.linear_solver == FMB_LS_DENSE)
    return fmb_parse_error(p, fmb_find_key(p, solver, "linear_solver"),
                           "integrator: %s solves with KLU: linear_solver klu (the position rows eliminated, "
                           "default) or klu_full (the whole matrix); dense is IDA's only",
                           name);
  return 0;
}

static void* radau5_create(const fmbIntegratorSetup* s, double t0, const double* y0, const double* yp0, fmbDiag* diag) {
  return radau_create_tab(&radau_order5, s, t0, y0, yp0, diag);
}

static void* radau9_create(const fmbIntegratorSetup* s, double t0, const double* y0, const double* yp0, fmbDiag* diag) {
  return radau_create_tab(&radau_order9, s, t0, y0, yp0, diag);
}

const fmbIntegratorOps fmb_integrator_radau5 = {
    .name = "radau5",
    .projected = 0,
    .check = radau_check,
    .create = radau5_create,
    .reinit = radau_reinit,
    .advance = radau_advance,
    .work = radau_work,
    .stats = radau_stats,
    .after_row = NULL,
    .destroy = radau_destroy,
};

/* Radau IIA of order 9 (5 stages, the order-9 member of Hairer & Wanner's RADAU): the same code
   with one real and two complex systems per Newton iteration; the order the flexible pendulum's
   resolved bending modes need (docs/performance.md, "Where it is hardest") */
const fmbIntegratorOps fmb_integrator_radau9 = {
    .name = "radau9",
    .projected = 0,
    .check = radau_check,
    .create = radau9_create,
    .reinit = radau_reinit,
    .advance = radau_advance,
    .work = radau_work,
    .stats = radau_stats,
    .after_row = NULL,
    .destroy = radau_destroy,
};
