/*
 * beam3d.c — the spatial floating-frame beam (`type: beam` in a `dimension: 3` scene): axial u,
 * chordwise v, flapwise w and torsion phi of a slender Euler-Bernoulli beam in a frame that moves
 * in space, with the complete / FOAC / ZOAC models of docs/formulation-3d.md (equations 3D.n).
 *
 * Coordinates q = [r0 (3, global), e (4, Euler parameters of any length, R = R(e/|e|)), p], p the
 * nodal [u, v, v', w, w', phi] of nodes 1..ne (3D.10; node 0 clamped to the frame); v = q'.
 *
 * The equations are those of the quasi-velocities nu = [v0 = R^T r0', omega (body frame), p']
 * (3D.20-3D.22), M nu' = Q, evaluated as virtual work per quadrature point without forming M:
 * each point (6 Gauss points along x per element times the four-point section rule 3D.15)
 * contributes J_R^T F_R + J_D^T F_D + J_C^T F_C with three force vectors that say which products
 * of the rigid, linear and coupling parts the model keeps (see point_forces). J_C's p-columns
 * -e1 h^T are dense; their scalars h^T a are running integrals of slope products (3D.5) and their
 * transposed action sum_points c h is gathered element by element with tail sums, so one residual
 * costs O(ne * points). The rows are then mapped to q' exactly as bodies/rigid3d.c maps Euler's
 * equations: the r0 rows by R, the four e rows by the virtual rotation (2/|e|^2) L(e)^T plus the
 * gauge d^2/dt^2 |e|^2/2 = 0 along e, scaled by the frame's mean inertia so that the mass block
 * stays positive definite.
 */
#include <math.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>

#include "beam_section.h"
#include "flexmbd_plugin.h"

enum { B3_ZOAC = 0, B3_FOAC = 1, B3_COMPLETE = 2 };
enum { B3_MAX_ELEMENTS = 4096, B3_POINTS = 6, B3_NODE = 6, B3_P0 = 7 };

typedef struct Beam3 {
  double L, rho, A, Iz, Iy, Emod, Gmod, Jt, beta;
  int ne, model, n;
  double pos0[3], quat0[4], vel0[3], omega0[3], tip_vel0[3];
  /* derived */
  double le, jscale;                         /* element length; the gauge row's inertia (tr J / 3) */
  double sy[4], sz[4];                       /* the section rule's points (3D.15), weight A/4 */
  double xg[B3_POINTS], wg[B3_POINTS];       /* Gauss points on [0, 1] */
  double ns[B3_POINTS][4], nd[B3_POINTS][4]; /* Hermite values and x-slopes there (3D.11) */
  double Hg[B3_POINTS][4][4], Hfull[4][4];   /* int_0^x N'_j N'_l dx within an element (3D.5) */
  double kv[4][4], kw[4][4], ka, kt;         /* element stiffness (3D.13): EIz, EIy, EA/le, GJ/le */
} Beam3;

static const char* const model_names[] = {"zoac", "foac", "complete", NULL};

/* ---------------------------------------------------------------------------------------------
 * Small vector helpers.
 * ------------------------------------------------------------------------------------------- */
static void cross(const double a[3], const double b[3], double c[3]) {
  c[0] = a[1] * b[2] - a[2] * b[1];
  c[1] = a[2] * b[0] - a[0] * b[2];
  c[2] = a[0] * b[1] - a[1] * b[0];
}
static void add_cross(const double a[3], const double b[3], double c[3]) {
  double t[3];
  cross(a, b, t);
  c[0] += t[0], c[1] += t[1], c[2] += t[2];
}
static double dot4(const double* a, const double* b) { return a[0] * b[0] + a[1] * b[1] + a[2] * b[2] + a[3] * b[3]; }
/* a^T H b over an element's four Hermite dofs */
static double quad4(const double* H, const double a[4], const double b[4]) {
  double s = 0.0;
  for (int j = 0; j < 4; ++j) s += a[j] * dot4(H + 4 * j, b);
  return s;
}
/* L(e) = [-e_v, e0 I - [e_v]x]: body angular velocity w = (2/|e|^2) L(e) e' (docs/spatial.md) */
static void euler_l(const double e[4], double Lm[3][4]) {
  const double rows[3][4] = {{-e[1], e[0], e[3], -e[2]}, {-e[2], -e[3], e[0], e[1]}, {-e[3], e[2], -e[1], e[0]}};
  memcpy(Lm, rows, sizeof rows);
}
static void euler_rate(double Lm[3][4], double s, const double* ed, double w[3]) {
  for (int i = 0; i < 3; ++i) w[i] = s * dot4(Lm[i], ed);
}

/* ---------------------------------------------------------------------------------------------
 * Element data.
 * ------------------------------------------------------------------------------------------- */
/* element e's dofs of a nodal vector p: axial ends au, bending (v, v') and (w, w') of both nodes,
   torsion ends af; the root node (e = 0's left) is clamped: zeros */
typedef struct {
  double au[2], dv[4], dw[4], af[2];
} ElemDofs;
static void gather(const double* p, int e, ElemDofs* d) {
  const double* r = p + B3_NODE * e;
  const double* l = e > 0 ? p + B3_NODE * (e - 1) : NULL;
  const double z[B3_NODE] = {0};
  if (!l) l = z;
  d->au[0] = l[0], d->au[1] = r[0];
  d->dv[0] = l[1], d->dv[1] = l[2], d->dv[2] = r[1], d->dv[3] = r[2];
  d->dw[0] = l[3], d->dw[1] = l[4], d->dw[2] = r[3], d->dw[3] = r[4];
  d->af[0] = l[5], d->af[1] = r[5];
}
/* adds element forces on the local dofs into the nodal vector F (root dofs dropped) */
static void scatter(double* F, int e, const ElemDofs* f) {
  double* r = F + B3_NODE * e;
  r[0] += f->au[1], r[1] += f->dv[2], r[2] += f->dv[3], r[3] += f->dw[2], r[4] += f->dw[3], r[5] += f->af[1];
  if (e == 0) return;
  double* l = F + B3_NODE * (e - 1);
  l[0] += f->au[0], l[1] += f->dv[0], l[2] += f->dv[1], l[3] += f->dw[0], l[4] += f->dw[1], l[5] += f->af[0];
}

/* H(xi)_jl = int_0^{xi le} N'_j N'_l dx within one element: degree 4 in xi, so the nested
   3-point Gauss rule on [0, xi] is exact (3D.5; formulation-3d.md section 3) */
static void partial_h(double le, double xi, double H[4][4]) {
  double xs[3], ws[3], nd[4];
  fmb_gauss_legendre01(3, xs, ws);
  memset(H, 0, 16 * sizeof(double));
  for (int k = 0; k < 3; ++k) {
    fmb_beam_hermite(xi * xs[k], le, NULL, nd);
    for (int j = 0; j < 4; ++j)
      for (int l = 0; l < 4; ++l) H[j][l] += le * xi * ws[k] * nd[j] * nd[l];
  }
}

static void beam3_setup(Beam3* b) {
  const double le = b->L / b->ne;
  b->le = le;
  b->n = B3_NODE * b->ne;
  const double ry = sqrt(2.0 * b->Iz / b->A), rz = sqrt(2.0 * b->Iy / b->A); /* 3D.15 */
  const double sy[4] = {ry, -ry, 0.0, 0.0}, sz[4] = {0.0, 0.0, rz, -rz};
  memcpy(b->sy, sy, sizeof sy);
  memcpy(b->sz, sz, sizeof sz);
  fmb_gauss_legendre01(B3_POINTS, b->xg, b->wg);
  for (int g = 0; g < B3_POINTS; ++g) {
    fmb_beam_hermite(b->xg[g], le, b->ns[g], b->nd[g]);
    partial_h(le, b->xg[g], b->Hg[g]);
  }
  partial_h(le, 1.0, b->Hfull);
  const double k[4][4] = {{12.0, 6.0 * le, -12.0, 6.0 * le},
                          {6.0 * le, 4.0 * le * le, -6.0 * le, 2.0 * le * le},
                          {-12.0, -6.0 * le, 12.0, -6.0 * le},
                          {6.0 * le, 2.0 * le * le, -6.0 * le, 4.0 * le * le}}; /* 3D.13 */
  for (int i = 0; i < 4; ++i)
    for (int j = 0; j < 4; ++j) {
      b->kv[i][j] = b->Emod * b->Iz / (le * le * le) * k[i][j];
      b->kw[i][j] = b->Emod * b->Iy / (le * le * le) * k[i][j];
    }
  b->ka = b->Emod * b->A / le;
  b->kt = b->Gmod * b->Jt / le;
  /* the undeformed inertia tensor about the root, diagonal: rho L (Iy + Iz), rho (A L^3/3 + Iy L),
     rho (A L^3/3 + Iz L); its mean scales the gauge row as rigid3d's J_avg */
  const double L = b->L;
  b->jscale = b->rho * (L * (b->Iy + b->Iz) + 2.0 * b->A * L * L * L / 3.0 + L * (b->Iy + b->Iz)) / 3.0;
}

/* ---------------------------------------------------------------------------------------------
 * The equations in quasi-velocities.
 * ------------------------------------------------------------------------------------------- */
/* The three force vectors of one point (3D.21/3D.22), mass-weighted: F_R multiplies J_R^T, F_D
   J_D^T, F_C J_C^T. aR, aD, aC: the rigid, linear and coupling parts of J nu' + g; fb: the body
   force per unit mass (gravity, body frame). complete keeps every product, ZOAC drops J_C and
   g_C, FOAC keeps the coupling only against the rigid part. */
static void point_forces(int model, double mw, const double aR[3], const double aD[3], const double aC[3],
                         const double fb[3], double FR[3], double FD[3], double FC[3]) {
  for (int i = 0; i < 3; ++i) {
    const double rd = aR[i] + aD[i] - fb[i];
    switch (model) {
      case B3_ZOAC: FR[i] = FD[i] = mw * rd, FC[i] = 0.0; break;
      case B3_FOAC:
        FR[i] = mw * (rd + aC[i]);
        FD[i] = mw * rd;
        FC[i] = mw * (aR[i] - fb[i]);
        break;
      default: FR[i] = FD[i] = FC[i] = mw * (rd + aC[i]); break;
    }
  }
}

/* What the three models share of a state: frame quasi-velocities nu = [v0, omega] and the deformation
   rates, and the accelerations nud = [v0', omega', p''] (p'' at nud + 6). */
typedef struct {
  const double *p, *pd, *nu, *nud;
  int velocity_terms; /* 0: g = 0 (F = M nud, for the kinetic energy) */
  const double* fb;   /* gravity per unit mass, body frame, or NULL */
} QuasiState;

/* F (6 + n) = M nud - Q_inertial - Q_body (without K p): virtual work over every point (3D.21,
   3D.22), O(ne * points). cg (ne * B3_POINTS scratch) holds each point's coupling weight for the
   tail sums of J_C^T. */
static void quasi_rows(const Beam3* b, const QuasiState* s, double* F, double* cg) {
  const double *v0 = s->nu, *w = s->nu + 3, *v0d = s->nud, *wd = s->nud + 3, *pdd = s->nud + 6;
  const double zero[3] = {0.0, 0.0, 0.0};
  const double* fb = s->fb ? s->fb : zero;
  const int coupled = b->model != B3_ZOAC;
  memset(F, 0, sizeof(double) * (size_t)(6 + b->n));
  double* Fp = F + 6;
  /* running integrals over the inboard elements of p^T B p, p^T B p', p^T B p'', p'^T B p' */
  double pre_pp = 0.0, pre_pv = 0.0, pre_pa = 0.0, pre_vv = 0.0;
  double wv0[3] = {0.0, 0.0, 0.0};
  if (s->velocity_terms) cross(w, v0, wv0);
  for (int e = 0; e < b->ne; ++e) {
    ElemDofs d, dd, da, f;
    gather(s->p, e, &d);
    gather(s->pd, e, &dd);
    gather(pdd, e, &da);
    memset(&f, 0, sizeof f);
    for (int g = 0; g < B3_POINTS; ++g) {
      const double xi = b->xg[g], x = b->le * (e + xi), mass = b->rho * b->le * b->wg[g] * 0.25 * b->A;
      const double *N = b->ns[g], *Nd = b->nd[g], lin[2] = {1.0 - xi, xi};
      const double u = lin[0] * d.au[0] + lin[1] * d.au[1], ud = lin[0] * dd.au[0] + lin[1] * dd.au[1],
                   ua = lin[0] * da.au[0] + lin[1] * da.au[1];
      const double f0 = lin[0] * d.af[0] + lin[1] * d.af[1], fd = lin[0] * dd.af[0] + lin[1] * dd.af[1],
                   fa = lin[0] * da.af[0] + lin[1] * da.af[1];
      const double v = dot4(N, d.dv), vp = dot4(Nd, d.dv), wv = dot4(N, d.dw), wp = dot4(Nd, d.dw);
      const double vd = dot4(N, dd.dv), vpd = dot4(Nd, dd.dv), wvd = dot4(N, dd.dw), wpd = dot4(Nd, dd.dw);
      const double va = dot4(N, da.dv), vpa = dot4(Nd, da.dv), wva = dot4(N, da.dw), wpa = dot4(Nd, da.dw);
      /* 3D.5: w_c = -1/2 p^T H p, w_c' = -p^T H p', h^T p'' = p^T H p'', p'^T H p' */
      double wc = 0.0, wcd = 0.0, hpa = 0.0, svv = 0.0;
      if (coupled) {
        const double* H = &b->Hg[g][0][0];
        wc = -0.5 * (pre_pp + quad4(H, d.dv, d.dv) + quad4(H, d.dw, d.dw));
        wcd = -(pre_pv + quad4(H, d.dv, dd.dv) + quad4(H, d.dw, dd.dw));
        hpa = pre_pa + quad4(H, d.dv, da.dv) + quad4(H, d.dw, da.dw);
        svv = pre_vv + quad4(H, dd.dv, dd.dv) + quad4(H, dd.dw, dd.dw);
      }
      const double uC[3] = {wc, 0.0, 0.0}, uCd[3] = {wcd, 0.0, 0.0};
      double sx = 0.0, sy = 0.0, sz = 0.0, syx = 0.0, szx = 0.0, sphi = 0.0, sc = 0.0;
      for (int k = 0; k < 4; ++k) {
        const double y = b->sy[k], z = b->sz[k];
        const double r0[3] = {x, y, z};
        const double uD[3] = {u - y * vp - z * wp, v - z * f0, wv + y * f0}; /* 3D.1 */
        const double uDd[3] = {ud - y * vpd - z * wpd, vd - z * fd, wvd + y * fd};
        const double uDa[3] = {ua - y * vpa - z * wpa, va - z * fa, wva + y * fa};
        double aR[3], aD[3], aC[3] = {0.0, 0.0, 0.0}, t[3];
        /* 3D.20: J nu' + g split as in 3D.22 */
        cross(wd, r0, aR);
        cross(wd, uD, aD);
        for (int i = 0; i < 3; ++i) aR[i] += v0d[i], aD[i] += uDa[i];
        if (s->velocity_terms) {
          cross(w, r0, t);
          add_cross(w, t, aR);
          for (int i = 0; i < 3; ++i) aR[i] += wv0[i];
          cross(w, uD, t);
          add_cross(w, t, aD);
          for (int i = 0; i < 3; ++i) t[i] = 2.0 * uDd[i];
          add_cross(w, t, aD);
        }
        if (coupled) {
          cross(wd, uC, aC);
          aC[0] -= hpa;
          if (s->velocity_terms) {
            cross(w, uC, t);
            add_cross(w, t, aC);
            for (int i = 0; i < 3; ++i) t[i] = 2.0 * uCd[i];
            add_cross(w, t, aC);
            aC[0] -= svv;
          }
        }
        double FR[3], FD[3], FC[3];
        point_forces(b->model, mass, aR, aD, aC, fb, FR, FD, FC);
        /* J_R^T F_R = [F_R; rho0 x F_R; 0], J_D^T F_D = [0; u_D x F_D; S_D^T F_D],
           J_C^T F_C = [0; (e1 w_c) x F_C; -h F_Cx] */
        for (int i = 0; i < 3; ++i) F[i] += FR[i];
        add_cross(r0, FR, F + 3);
        add_cross(uD, FD, F + 3);
        if (coupled) add_cross(uC, FC, F + 3);
        sx += FD[0], sy += FD[1], sz += FD[2], syx += y * FD[0], szx += z * FD[0], sphi += y * FD[2] - z * FD[1];
        sc += FC[0];
      }
      /* S_D^T (3D.12) summed over the section */
      for (int j = 0; j < 2; ++j) f.au[j] += lin[j] * sx, f.af[j] += lin[j] * sphi;
      for (int j = 0; j < 4; ++j) {
        f.dv[j] += N[j] * sy - Nd[j] * syx;
        f.dw[j] += N[j] * sz - Nd[j] * szx;
      }
      cg[e * B3_POINTS + g] = sc;
    }
    scatter(Fp, e, &f);
    if (coupled) {
      pre_pp += quad4(&b->Hfull[0][0], d.dv, d.dv) + quad4(&b->Hfull[0][0], d.dw, d.dw);
      pre_pv += quad4(&b->Hfull[0][0], d.dv, dd.dv) + quad4(&b->Hfull[0][0], d.dw, dd.dw);
      pre_pa += quad4(&b->Hfull[0][0], d.dv, da.dv) + quad4(&b->Hfull[0][0], d.dw, da.dw);
      pre_vv += quad4(&b->Hfull[0][0], dd.dv, dd.dv) + quad4(&b->Hfull[0][0], dd.dw, dd.dw);
    }
  }
  if (!coupled) return;
  /* S_C^T F_C = -sum_points c h(x), h(x) = H(x) p: element e's part of every outboard point's h
     is Hfull d_e (the tail sum of c over the outboard elements), its own points' are Hg d_e */
  double tail = 0.0;
  for (int e = b->ne - 1; e >= 0; --e) {
    ElemDofs d, f;
    gather(s->p, e, &d);
    memset(&f, 0, sizeof f);
    double H[4][4];
    for (int j = 0; j < 4; ++j)
      for (int l = 0; l < 4; ++l) {
        H[j][l] = tail * b->Hfull[j][l];
        for (int g = 0; g < B3_POINTS; ++g) H[j][l] += cg[e * B3_POINTS + g] * b->Hg[g][j][l];
      }
    for (int j = 0; j < 4; ++j) f.dv[j] = -dot4(H[j], d.dv), f.dw[j] = -dot4(H[j], d.dw);
    scatter(Fp, e, &f);
    for (int g = 0; g < B3_POINTS; ++g) tail += cg[e * B3_POINTS + g];
  }
}

/* adds K x (3D.8, 3D.13) to Fp */
static void add_stiffness(const Beam3* b, const double* x, double* Fp) {
  for (int e = 0; e < b->ne; ++e) {
    ElemDofs d, f;
    gather(x, e, &d);
    f.au[0] = b->ka * (d.au[0] - d.au[1]), f.au[1] = -f.au[0];
    f.af[0] = b->kt * (d.af[0] - d.af[1]), f.af[1] = -f.af[0];
    for (int j = 0; j < 4; ++j) f.dv[j] = dot4(b->kv[j], d.dv), f.dw[j] = dot4(b->kw[j], d.dw);
    scatter(Fp, e, &f);
  }
}

/* the frame's kinematics of a state: R, L(e), |e|^2 and nu = [R^T r0', omega] */
typedef struct {
  double R[9], Lm[3][4], n2, nu[6];
} FrameState;
static int frame_state(const double* q, const double* v, FrameState* fs) {
  const double* e = q + 3;
  fs->n2 = dot4(e, e);
  if (!(fs->n2 > 0.0) || fmb_quat_matrix(e, fs->R)) return -1;
  euler_l(e, fs->Lm);
  for (int i = 0; i < 3; ++i) fs->nu[i] = fs->R[i] * v[0] + fs->R[3 + i] * v[1] + fs->R[6 + i] * v[2];
  euler_rate(fs->Lm, 2.0 / fs->n2, v + 3, fs->nu + 3);
  return 0;
}

/* ---------------------------------------------------------------------------------------------
 * Ops.
 * ------------------------------------------------------------------------------------------- */
static int b3_ncoord(const void* self) { return B3_P0 + ((const Beam3*)self)->n; }
/* quasi_rows' nud and F (2 (6 + n)), cg (ne * points), the marker's h (n) */
static size_t b3_nwork(const void* self) {
  const Beam3* b = self;
  return 2 * (size_t)(6 + b->n) + (size_t)b->ne * B3_POINTS + (size_t)b->n;
}
static void b3_destroy(void* self) { free(self); }

static int b3_residual(const void* self, const fmbEnv* env, const double* q, const double* v, const double* a,
                       double* Res, double* work) {
  const Beam3* b = self;
  FrameState fs;
  if (frame_state(q, v, &fs)) return 1; /* e = 0: IDA retries with a smaller step */
  double *nud = work, *F = work + 6 + b->n, *cg = F + 6 + b->n;
  const double *e = q + 3, *ed = v + 3, *edd = a + 3;
  /* nu' = [R^T r0'' - omega x v0, (2/n2) L e'' - (2 e.e'/n2) omega] (rigid3d) */
  double wv0[3];
  cross(fs.nu + 3, fs.nu, wv0);
  for (int i = 0; i < 3; ++i) nud[i] = fs.R[i] * a[0] + fs.R[3 + i] * a[1] + fs.R[6 + i] * a[2] - wv0[i];
  euler_rate(fs.Lm, 2.0 / fs.n2, edd, nud + 3);
  const double eed = dot4(e, ed);
  for (int i = 0; i < 3; ++i) nud[3 + i] -= 2.0 * eed / fs.n2 * fs.nu[3 + i];
  memcpy(nud + 6, a + B3_P0, sizeof(double) * (size_t)b->n);
  double fb[3];
  if (env->has_gravity)
    for (int i = 0; i < 3; ++i)
      fb[i] = fs.R[i] * env->gravity3[0] + fs.R[3 + i] * env->gravity3[1] + fs.R[6 + i] * env->gravity3[2];
  const QuasiState s = {q + B3_P0, v + B3_P0, fs.nu, nud, 1, env->has_gravity ? fb : NULL};
  quasi_rows(b, &s, F, cg);
  for (int i = 0; i < 3; ++i) Res[i] = fs.R[3 * i] * F[0] + fs.R[3 * i + 1] * F[1] + fs.R[3 * i + 2] * F[2];
  const double gauge = dot4(e, edd) + dot4(ed, ed), sg = 4.0 * b->jscale / (fs.n2 * fs.n2);
  for (int k = 0; k < 4; ++k)
    Res[3 + k] = 2.0 / fs.n2 * (fs.Lm[0][k] * F[3] + fs.Lm[1][k] * F[4] + fs.Lm[2][k] * F[5]) + sg * e[k] * gauge;
  double* Rp = Res + B3_P0;
  memcpy(Rp, F + 6, sizeof(double) * (size_t)b->n);
  if (b->beta > 0.0) {   /* K (p + beta p'): stiffness-proportional damping */
    double* x = nud + 6; /* free again */
    for (int j = 0; j < b->n; ++j) x[j] = q[B3_P0 + j] + b->beta * v[B3_P0 + j];
    add_stiffness(b, x, Rp);
  } else {
    add_stiffness(b, q + B3_P0, Rp);
  }
  for (int i = 0; i < B3_P0 + b->n; ++i)
    if (!isfinite(Res[i])) return 1;
  return 0;
}

/* the deformation at reference point (x, y, z): u of 3D.1 (ZOAC without u_C), its rate, the
   small rotation (phi, -w', v') and, with dofs not NULL, element e, xi and the element's dofs */
typedef struct {
  int e;
  double xi, u[3], ud[3], theta[3];
  ElemDofs d;
} PointDeformation;
static int deformation_at(const Beam3* b, const double* p, const double* pd, const double local[3],
                          PointDeformation* pt) {
  const double x = local[0], y = local[1], z = local[2];
  if (!(x >= -1e-12 * b->L && x <= b->L * (1.0 + 1e-12))) return -1;
  fmb_beam_locate(b->le, b->ne, x, &pt->e, &pt->xi);
  const double xi = pt->xi;
  ElemDofs dd;
  gather(p, pt->e, &pt->d);
  double N[4], Nd[4];
  fmb_beam_hermite(xi, b->le, N, Nd);
  const ElemDofs* d = &pt->d;
  const double lin[2] = {1.0 - xi, xi};
  const double u = lin[0] * d->au[0] + lin[1] * d->au[1], f = lin[0] * d->af[0] + lin[1] * d->af[1];
  const double vp = dot4(Nd, d->dv), wp = dot4(Nd, d->dw);
  pt->u[0] = u - y * vp - z * wp, pt->u[1] = dot4(N, d->dv) - z * f, pt->u[2] = dot4(N, d->dw) + y * f;
  pt->theta[0] = f, pt->theta[1] = -wp, pt->theta[2] = vp;
  memset(pt->ud, 0, sizeof pt->ud);
  if (pd) {
    gather(pd, pt->e, &dd);
    const double udot = lin[0] * dd.au[0] + lin[1] * dd.au[1], fd = lin[0] * dd.af[0] + lin[1] * dd.af[1];
    pt->ud[0] = udot - y * dot4(Nd, dd.dv) - z * dot4(Nd, dd.dw);
    pt->ud[1] = dot4(N, dd.dv) - z * fd, pt->ud[2] = dot4(N, dd.dw) + y * fd;
  }
  if (b->model == B3_ZOAC || x <= 0.0) return 0;
  /* u_C = e1 w_c (3D.3, 3D.5): the inboard elements whole, this one to xi */
  double pp = 0.0, pv = 0.0, H[4][4];
  for (int k = 0; k <= pt->e; ++k) {
    ElemDofs dk, dkd;
    gather(p, k, &dk);
    if (pd) gather(pd, k, &dkd);
    if (k < pt->e) {
      memcpy(H, b->Hfull, sizeof H);
    } else {
      partial_h(b->le, xi, H);
    }
    pp += quad4(&H[0][0], dk.dv, dk.dv) + quad4(&H[0][0], dk.dw, dk.dw);
    if (pd) pv += quad4(&H[0][0], dk.dv, dkd.dv) + quad4(&H[0][0], dk.dw, dkd.dw);
  }
  pt->u[0] += -0.5 * pp;
  pt->ud[0] += -pv;
  return 0;
}

/* R_s = exp(theta~) (Rodrigues: orthonormal, so the joints' axes stay unit) and its left Jacobian
   J_l: d exp(theta~) exp(-theta~) = (J_l dtheta)~ */
static void small_rotation(const double th[3], double Rs[9], double Jl[9]) {
  const double a2 = th[0] * th[0] + th[1] * th[1] + th[2] * th[2], a = sqrt(a2);
  double c1, c2, c3;
  if (a < 1e-4) { /* series to beyond double precision at this size */
    c1 = 1.0 - a2 / 6.0 + a2 * a2 / 120.0;
    c2 = 0.5 - a2 / 24.0 + a2 * a2 / 720.0;
    c3 = 1.0 / 6.0 - a2 / 120.0 + a2 * a2 / 5040.0;
  } else {
    c1 = sin(a) / a, c2 = (1.0 - cos(a)) / a2, c3 = (a - sin(a)) / (a2 * a);
  }
  const double S[9] = {0.0, -th[2], th[1], th[2], 0.0, -th[0], -th[1], th[0], 0.0};
  for (int i = 0; i < 3; ++i)
    for (int j = 0; j < 3; ++j) {
      double s2 = 0.0;
      for (int k = 0; k < 3; ++k) s2 += S[3 * i + k] * S[3 * k + j];
      const double id = i == j ? 1.0 : 0.0;
      Rs[3 * i + j] = id + c1 * S[3 * i + j] + c2 * s2;
      Jl[3 * i + j] = id + c2 * S[3 * i + j] + c3 * s2;
    }
}

/* A point (x, y, z) of the beam (also the `beam` table's marker3: a spatial scene's beam items are
   always this file's, through the variant): r0 + R (rho0 + u) with the model's u, its section's rotation R R_s,
   R_s = exp((phi, -w', v')~) (formulation-3d.md section 10: the small rotation, here made
   orthonormal), dpos/dq and the virtual rotation G (global), at x = 0 exactly the frame's. */
int fmb_beam3d_marker3(const void* self, const double* q, const double local[3], double pos[3], double Rout[9],
                       double* dpos, double* rot, int ld, double* work) {
  const Beam3* b = self;
  PointDeformation pt;
  if (deformation_at(b, q + B3_P0, NULL, local, &pt)) return -1;
  const double loc[3] = {local[0] + pt.u[0], local[1] + pt.u[1], local[2] + pt.u[2]};
  double R[9], Rs[9], Jl[9];
  if (fmb_frame3_point(q, loc, pos, R, dpos, rot, ld)) return -1;
  small_rotation(pt.theta, Rs, Jl);
  if (Rout)
    for (int i = 0; i < 3; ++i)
      for (int j = 0; j < 3; ++j)
        Rout[3 * i + j] = R[3 * i] * Rs[j] + R[3 * i + 1] * Rs[3 + j] + R[3 * i + 2] * Rs[6 + j];
  if (!dpos && !rot) return 0;
  const int n = b->n;
  /* body-frame columns over p: S (3D.12 with S_C = -e1 h^T) and dtheta/dp */
  double N[4], Nd[4];
  fmb_beam_hermite(pt.xi, b->le, N, Nd);
  const double lin[2] = {1.0 - pt.xi, pt.xi}, y = local[1], z = local[2];
  double* h = work; /* h = H(x) p over the v and w dofs up to element e */
  memset(h, 0, sizeof(double) * (size_t)n);
  if (b->model != B3_ZOAC && local[0] > 0.0)
    for (int k = 0; k <= pt.e; ++k) {
      ElemDofs dk, hk;
      gather(q + B3_P0, k, &dk);
      memset(&hk, 0, sizeof hk);
      double H[4][4];
      if (k < pt.e)
        memcpy(H, b->Hfull, sizeof H);
      else
        partial_h(b->le, pt.xi, H);
      for (int j = 0; j < 4; ++j) hk.dv[j] = dot4(H[j], dk.dv), hk.dw[j] = dot4(H[j], dk.dw);
      scatter(h, k, &hk);
    }
  for (int r = 0; r < 3; ++r) {
    if (dpos) memset(dpos + r * ld + B3_P0, 0, sizeof(double) * (size_t)n);
    if (rot) memset(rot + r * ld + B3_P0, 0, sizeof(double) * (size_t)n);
  }
  /* column c of p with body-frame displacement s and rotation t: R s and R J_l t */
  double RJ[9];
  for (int i = 0; i < 3; ++i)
    for (int j = 0; j < 3; ++j) RJ[3 * i + j] = R[3 * i] * Jl[j] + R[3 * i + 1] * Jl[3 + j] + R[3 * i + 2] * Jl[6 + j];
  for (int c = 0; c < n; ++c) {
    double sv[3] = {-h[c], 0.0, 0.0}, tv[3] = {0.0, 0.0, 0.0};
    const int node = c / B3_NODE + 1, k = c % B3_NODE; /* node 1..ne */
    const int side = node == pt.e + 1 ? 1 : node == pt.e ? 0 : -1;
    if (side >= 0) {
      const int hv = 2 * side + (k == 2 || k == 4); /* Hermite index of v/v' or w/w' */
      switch (k) {
        case 0: sv[0] += lin[side]; break;
        case 1:
        case 2:
          sv[0] += -y * Nd[hv], sv[1] += N[hv];
          tv[2] = Nd[hv];
          break;
        case 3:
        case 4:
          sv[0] += -z * Nd[hv], sv[2] += N[hv];
          tv[1] = -Nd[hv];
          break;
        default:
          sv[1] += -z * lin[side], sv[2] += y * lin[side];
          tv[0] = lin[side];
          break;
      }
    }
    for (int r = 0; r < 3; ++r) {
      if (dpos) dpos[r * ld + B3_P0 + c] = R[3 * r] * sv[0] + R[3 * r + 1] * sv[1] + R[3 * r + 2] * sv[2];
      if (rot) rot[r * ld + B3_P0 + c] = RJ[3 * r] * tv[0] + RJ[3 * r + 1] * tv[1] + RJ[3 * r + 2] * tv[2];
    }
  }
  return 0;
}

/* the first moment s = int rho (rho0 + u) dV (body frame; the section's y, z integrate out) */
static void first_moment(const Beam3* b, const double* p, double s[3]) {
  s[0] = s[1] = s[2] = 0.0;
  double pre = 0.0;
  for (int e = 0; e < b->ne; ++e) {
    ElemDofs d;
    gather(p, e, &d);
    for (int g = 0; g < B3_POINTS; ++g) {
      const double xi = b->xg[g], m = b->rho * b->A * b->le * b->wg[g];
      double wc = 0.0;
      if (b->model != B3_ZOAC)
        wc = -0.5 * (pre + quad4(&b->Hg[g][0][0], d.dv, d.dv) + quad4(&b->Hg[g][0][0], d.dw, d.dw));
      s[0] += m * (b->le * (e + xi) + (1.0 - xi) * d.au[0] + xi * d.au[1] + wc);
      s[1] += m * dot4(b->ns[g], d.dv);
      s[2] += m * dot4(b->ns[g], d.dw);
    }
    pre += quad4(&b->Hfull[0][0], d.dv, d.dv) + quad4(&b->Hfull[0][0], d.dw, d.dw);
  }
}

/* T = 1/2 nu^T M nu of the model (3D.23), U_e = 1/2 p^T K p, U_g = -g . (m r0 + R s) */
static void b3_energy(const void* self, const fmbEnv* env, const double* q, const double* v, fmbEnergy* en,
                      double* work) {
  const Beam3* b = self;
  FrameState fs;
  memset(en, 0, sizeof *en);
  if (frame_state(q, v, &fs)) return;
  double *nud = work, *F = work + 6 + b->n, *cg = F + 6 + b->n;
  memcpy(nud, fs.nu, 6 * sizeof(double));
  memcpy(nud + 6, v + B3_P0, sizeof(double) * (size_t)b->n);
  const QuasiState s = {q + B3_P0, v + B3_P0, fs.nu, nud, 0, NULL};
  quasi_rows(b, &s, F, cg);
  double T = 0.0;
  for (int i = 0; i < 6 + b->n; ++i) T += nud[i] * F[i];
  en->kinetic = 0.5 * T;
  memset(F, 0, sizeof(double) * (size_t)b->n);
  add_stiffness(b, q + B3_P0, F);
  double U = 0.0;
  for (int i = 0; i < b->n; ++i) U += q[B3_P0 + i] * F[i];
  en->strain = 0.5 * U;
  if (env && env->has_gravity) {
    double sm[3];
    first_moment(b, q + B3_P0, sm);
    const double m = b->rho * b->A * b->L;
    for (int i = 0; i < 3; ++i)
      en->gravity -=
          env->gravity3[i] * (m * q[i] + fs.R[3 * i] * sm[0] + fs.R[3 * i + 1] * sm[1] + fs.R[3 * i + 2] * sm[2]);
  }
}

enum {
  O_TIP_U,
  O_TIP_V,
  O_TIP_W,
  O_TIP_PHI,
  O_TIP_U_RATE,
  O_TIP_V_RATE,
  O_TIP_W_RATE,
  O_TIP_PHI_RATE,
  O_TIP_X,
  O_TIP_Y,
  O_TIP_Z,
  O_X,
  O_Y,
  O_Z,
  O_QW,
  O_QX,
  O_QY,
  O_QZ,
  O_VX,
  O_VY,
  O_VZ,
  O_WX,
  O_WY,
  O_WZ,
  O_N
};
static const char* const b3_outputs[] = {
    "tip_u", "tip_v", "tip_w", "tip_phi", "tip_u_rate", "tip_v_rate", "tip_w_rate", "tip_phi_rate", "tip_x",
    "tip_y", "tip_z", "x",     "y",       "z",          "qw",         "qx",         "qy",           "qz",
    "vx",    "vy",    "vz",    "wx",      "wy",         "wz",         NULL};
static const char* const b3_units[] = {"m",   "m",   "m",   "rad",   "m/s",   "m/s",   "m/s", "rad/s", "m",
                                       "m",   "m",   "m",   "m",     "m",     "1",     "1",   "1",     "1",
                                       "m/s", "m/s", "m/s", "rad/s", "rad/s", "rad/s", NULL};

static int b3_output(const void* self, int id, const double* q, const double* v, double* value, double* work) {
  const Beam3* b = self;
  if (id < 0 || id >= O_N) return -1;
  const double tip[3] = {b->L, 0.0, 0.0};
  if (id <= O_TIP_PHI_RATE) {
    PointDeformation pt;
    if (deformation_at(b, q + B3_P0, v + B3_P0, tip, &pt)) return -1;
    const double* pdn = v + B3_P0 + B3_NODE * (b->ne - 1);
    const double vals[8] = {pt.u[0], pt.u[1], pt.u[2], pt.theta[0], pt.ud[0], pt.ud[1], pt.ud[2], pdn[5]};
    *value = vals[id];
    return 0;
  }
  if (id <= O_TIP_Z) {
    double pos[3];
    if (fmb_beam3d_marker3(b, q, tip, pos, NULL, NULL, NULL, 0, work)) return -1;
    *value = pos[id - O_TIP_X];
    return 0;
  }
  if (id <= O_Z) {
    *value = q[id - O_X];
    return 0;
  }
  const double* e = q + 3;
  const double en = sqrt(dot4(e, e));
  if (id <= O_QZ) {
    *value = e[id - O_QW] / en;
    return 0;
  }
  if (id <= O_VZ) {
    *value = v[id - O_VX];
    return 0;
  }
  FrameState fs;
  if (frame_state(q, v, &fs)) return -1;
  const double* w = fs.nu + 3;
  const int i = id - O_WX;
  *value = fs.R[3 * i] * w[0] + fs.R[3 * i + 1] * w[1] + fs.R[3 * i + 2] * w[2];
  return 0;
}

static void b3_initial(const void* self, double* q, double* v) {
  const Beam3* b = self;
  const int nc = B3_P0 + b->n;
  memset(q, 0, sizeof(double) * (size_t)nc);
  memset(v, 0, sizeof(double) * (size_t)nc);
  memcpy(q, b->pos0, 3 * sizeof(double));
  memcpy(q + 3, b->quat0, 4 * sizeof(double));
  memcpy(v, b->vel0, 3 * sizeof(double));
  double R[9], wb[3], Lm[3][4];
  fmb_quat_matrix(b->quat0, R);
  for (int i = 0; i < 3; ++i) wb[i] = R[i] * b->omega0[0] + R[3 + i] * b->omega0[1] + R[6 + i] * b->omega0[2];
  euler_l(b->quat0, Lm);
  for (int k = 0; k < 4; ++k) v[3 + k] = 0.5 * (Lm[0][k] * wb[0] + Lm[1][k] * wb[1] + Lm[2][k] * wb[2]);
  /* tip_velocity: the axial part spread linearly, the transverse parts as the static cantilever
     under a tip load, v(x) = v_tip (3 s^2 - s^3) / 2, s = x / L */
  for (int i = 1; i <= b->ne; ++i) {
    const double s = (double)i / b->ne, shape = 0.5 * (3.0 * s * s - s * s * s), slope = 1.5 * (2.0 * s - s * s) / b->L;
    double* vn = v + B3_P0 + B3_NODE * (i - 1);
    vn[0] = b->tip_vel0[0] * s;
    vn[1] = b->tip_vel0[1] * shape, vn[2] = b->tip_vel0[1] * slope;
    vn[3] = b->tip_vel0[2] * shape, vn[4] = b->tip_vel0[2] * slope;
  }
}

static int b3_parse(fmbParser* p, fmbNode item, void** self) {
  Beam3* b = calloc(1, sizeof *b);
  if (!b) return fmb_parse_error(p, item, "out of memory");
  b->quat0[0] = 1.0;
  b->model = B3_COMPLETE;
  b->Iy = b->Gmod = b->Jt = NAN;
  int err = 0;
  err |= fmb_get_double(p, item, "length", FMB_REQUIRED | FMB_POSITIVE, &b->L);
  err |= fmb_get_int(p, item, "elements", FMB_REQUIRED, 1, B3_MAX_ELEMENTS, &b->ne);
  err |= fmb_get_double(p, item, "density", FMB_REQUIRED | FMB_POSITIVE, &b->rho);
  err |= fmb_get_double(p, item, "area", FMB_REQUIRED | FMB_POSITIVE, &b->A);
  err |= fmb_get_double(p, item, "second_moment", FMB_REQUIRED | FMB_POSITIVE, &b->Iz);
  err |= fmb_get_double(p, item, "youngs_modulus", FMB_REQUIRED | FMB_POSITIVE, &b->Emod);
  if (!err) b->Iy = b->Iz;
  err |= fmb_get_double(p, item, "second_moment_flap", FMB_POSITIVE, &b->Iy);
  if (!err) b->Jt = b->Iy + b->Iz, b->Gmod = b->Emod / 2.6;
  err |= fmb_get_double(p, item, "torsion_constant", FMB_POSITIVE, &b->Jt);
  err |= fmb_get_double(p, item, "shear_modulus", FMB_POSITIVE, &b->Gmod);
  err |= fmb_get_choice(p, item, "model", FMB_OPTIONAL, model_names, &b->model);
  err |= fmb_get_double(p, item, "damping", FMB_NONNEGATIVE, &b->beta);
  err |= fmb_get_vec3(p, item, "position", 0, b->pos0);
  err |= fmb_get_quat(p, item, "orientation", 0, b->quat0);
  err |= fmb_get_vec3(p, item, "velocity", 0, b->vel0);
  err |= fmb_get_vec3(p, item, "angular_velocity", 0, b->omega0);
  err |= fmb_get_vec3(p, item, "tip_velocity", 0, b->tip_vel0);
  if (err) {
    free(b);
    return -1;
  }
  beam3_setup(b);
  const double me = b->rho * b->A * b->le, k_bend = fmax(b->kv[0][0], b->kw[0][0]), k_axial = b->ka;
  if (!isnormal(me) || !isnormal(k_bend) || !isnormal(k_axial) || !isnormal(b->kt) ||
      !isfinite(fmax(k_bend, k_axial) / me) || !isfinite(b->kv[1][1]) || !isfinite(b->kw[1][1])) {
    fmb_beam_refuse_degenerate(p, item, b->L, b->ne, b->rho, b->A, b->Iz, b->Emod, me, k_bend, k_axial);
    free(b);
    return -1;
  }
  *self = b;
  return 0;
}

/* the metres a point moves per unit of a coordinate: 1 for r0 and the displacements, 2 L for e (a
   unit of e turns the frame by up to 2 rad), L for the slopes and the twist */
static void b3_length_scale(const void* self, double* mpu) {
  const Beam3* b = self;
  for (int i = 0; i < B3_P0 + b->n; ++i) mpu[i] = 1.0;
  for (int k = 3; k < 7; ++k) mpu[k] = 2.0 * b->L;
  for (int i = 0; i < b->ne; ++i) {
    double* m = mpu + B3_P0 + B3_NODE * i;
    m[2] = m[4] = b->L;
  }
}

static int b3_gauge(const void* self, const double* q, double* dir) {
  const Beam3* b = self;
  if (dir) {
    memset(dir, 0, sizeof(double) * (size_t)(B3_P0 + b->n));
    memcpy(dir + 3, q + 3, 4 * sizeof(double));
  }
  return 1;
}

static int b3_centreline(const void* self, int n, double* local) {
  const Beam3* b = self;
  return fmb_beam_centreline(b->L, b->ne, n, local);
}

static void b3_describe(const void* self, FILE* f) {
  const Beam3* b = self;
  fprintf(f,
          "spatial %s model, %d elements, %d Gauss points/element x 4 section points; EIz %g, EIy %g, GJ %g N m^2; "
          "Euler parameters%s\n",
          model_names[b->model], b->ne, B3_POINTS, b->Emod * b->Iz, b->Emod * b->Iy, b->Gmod * b->Jt,
          b->beta > 0.0 ? ", stiffness-proportional damping" : "");
}

static const char* b3_indefinite_mass(const void* self) {
  const Beam3* b = self;
  if (b->model != B3_FOAC) return NULL;
  return "the FOAC beam's kinetic energy is not positive definite (docs/formulation-3d.md section 9): with its "
         "frame free its mass matrix loses definiteness at a small deflection; use `model: complete` (FOAC is "
         "usable only under prescribed rotation)";
}
static int b3_max_bdf_order(const void* self) {
  (void)self;
  return 2; /* as the planar beam: undamped stiff modes, A-stable BDF2 */
}
static int b3_velocity_error_test(const void* self) {
  (void)self;
  return 0; /* as the planar beam */
}
static const char* b3_invalid_state(const void* self, const double* q, const double* v) {
  (void)v;
  const Beam3* b = self;
  for (int i = 0; i < b->ne; ++i) {
    const double* d = q + B3_P0 + B3_NODE * i;
    if (!(fabs(d[0]) <= b->L && fabs(d[1]) <= b->L && fabs(d[3]) <= b->L))
      return b->model == B3_ZOAC
                 ? "its deformation exceeds its length: the solution is diverging. ZOAC has no dynamic stiffening and "
                   "is unstable when spun above its first bending frequency; use model: foac or complete"
                 : "its deformation exceeds its length: the beam has left the range of this model (a floating frame "
                   "with small strains)";
  }
  return NULL;
}

static const char* const b3_model_choices[] = {"zoac", "foac", "complete", NULL};
const fmbParam fmb_beam3d_params[] = {
    FMB_BEAM_SECTION_PARAMS(B3_MAX_ELEMENTS),
    {.key = "model",
     .kind = FMB_PARAM_CHOICE,
     .fallback = "complete",
     .choices = b3_model_choices,
     .doc = "coupling deformation of both bending directions kept in full, to first order, or left out "
            "(docs/formulation-3d.md)"},
    {.key = "second_moment_flap",
     .kind = FMB_PARAM_NUMBER,
     .flags = FMB_POSITIVE,
     .unit = "m^4",
     .fallback = "second_moment",
     .doc = "dimension 3: I_y = int z^2 dA, flapwise bending w (second_moment is I_z, chordwise v)"},
    {.key = "torsion_constant",
     .kind = FMB_PARAM_NUMBER,
     .flags = FMB_POSITIVE,
     .unit = "m^4",
     .fallback = "second_moment + second_moment_flap",
     .doc = "dimension 3: St-Venant torsion constant J (torsional stiffness G J)"},
    {.key = "shear_modulus",
     .kind = FMB_PARAM_NUMBER,
     .flags = FMB_POSITIVE,
     .unit = "Pa",
     .fallback = "youngs_modulus / 2.6 (Poisson 0.3)",
     .doc = "dimension 3: G of the torsional stiffness"},
    {.key = "damping",
     .kind = FMB_PARAM_NUMBER,
     .flags = FMB_NONNEGATIVE,
     .unit = "s",
     .fallback = "0",
     .doc = "stiffness-proportional damping time beta: forces K (p + beta dp/dt)"},
    {.key = "position", .kind = FMB_PARAM_VEC3, .unit = "m", .fallback = "[0, 0, 0]", .doc = "initial root"},
    {.key = "orientation",
     .kind = FMB_PARAM_QUAT,
     .fallback = "[1, 0, 0, 0]",
     .doc = "initial frame orientation, Euler parameters [w, x, y, z]"},
    {.key = "velocity", .kind = FMB_PARAM_VEC3, .unit = "m/s", .fallback = "[0, 0, 0]", .doc = "initial root velocity"},
    {.key = "angular_velocity",
     .kind = FMB_PARAM_VEC3,
     .unit = "rad/s",
     .fallback = "[0, 0, 0]",
     .doc = "initial frame angular velocity, global frame"},
    {.key = "tip_velocity",
     .kind = FMB_PARAM_VEC3,
     .unit = "m/s",
     .fallback = "[0, 0, 0]",
     .doc = "dimension 3: initial deformation rate [u, v, w] of the tip (frame components), spread linearly (u) "
            "and as the static cantilever's shape (v, w)"},
    {.key = NULL},
};

const fmbBodyType fmb_body_beam3d = {
    .name = "beam",
    .abi = FMB_PLUGIN_ABI,
    .parse = b3_parse,
    .destroy = b3_destroy,
    .ncoord = b3_ncoord,
    .initial = b3_initial,
    .residual = b3_residual,
    .nwork = b3_nwork,
    .energy = b3_energy,
    .output_names = b3_outputs,
    .output = b3_output,
    .describe = b3_describe,
    .indefinite_mass = b3_indefinite_mass,
    .max_bdf_order = b3_max_bdf_order,
    .velocity_error_test = b3_velocity_error_test,
    .invalid_state = b3_invalid_state,
    .params = fmb_beam3d_params,
    .example = "length: 1\nelements: 2\ndensity: 1000\narea: 1e-3\nsecond_moment: 1e-7\nyoungs_modulus: 1e6\n"
               "angular_velocity: [0, 0, 3]\nvelocity: [0.2, 0.5, 0.1]\n",
    .centreline = b3_centreline,
    .length_scale = b3_length_scale,
    .output_units = b3_units,
    .dimensions = FMB_DIM_SPATIAL,
    .marker3 = fmb_beam3d_marker3,
    .gauge = b3_gauge,
};
