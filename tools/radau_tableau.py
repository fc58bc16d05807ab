#!/usr/bin/env python3
"""radau_tableau.py — the Radau IIA coefficients engine/integrator_radau.c writes as RadauTableau,
computed with 50 digits (mpmath: Debian's python3-mpmath; a developer's tool, not a dependency of
the build or the tests).

    python3 tools/radau_tableau.py S      (S = 3, 5, 7, ...: stages; order 2S - 1)

prints the C initializer. The construction (Hairer & Wanner II.7, IV.8):
  - nodes c_i: the zeros of d^(s-1)/dx^(s-1) (x^(s-1) (x - 1)^s), c_s = 1;
  - A_ij = int_0^c_i l_j (l_j the Lagrange basis on the nodes), A^-1, b_i = a_si;
  - A^-1's eigenvalues: one real, gamma, and (s - 1)/2 pairs alpha_p +- i beta_p (beta_p > 0,
    ordered by alpha descending); T's columns the real eigenvector and the real and imaginary
    parts of the eigenvector of alpha_p - i beta_p, each scaled to last component 1, so that
    T^-1 A^-1 T = diag(gamma, [[alpha_1, -beta_1], [beta_1, alpha_1]], ...) and T's last row is
    (1, 1, 0, 1, 0, ...);
  - the error estimate's d = gamma (bhat - b)^T A^-1, bhat the weights on c of the embedded
    quadrature of order s that puts 1/gamma on the step's start (IV.8 (8.19)).
For S = 5 it reproduces radau_order9 to every digit written there. For S = 3 it gives the same
c, A^-1, gamma, alpha, beta and d as radau_order5; that table's T and T^-1 are RADAU5's own, scaled
differently (any scaling of the eigenvectors gives the same method). The block-diagonal check's
residual is printed to stderr.
"""
import sys

import mpmath as mp

mp.mp.dps = 50


def polymul(a, b):
    r = [mp.mpf(0)] * (len(a) + len(b) - 1)
    for i, ai in enumerate(a):
        for j, bj in enumerate(b):
            r[i + j] += ai * bj
    return r


def tableau(s):
    p = [mp.mpf(1)]  # x^(s-1) (x - 1)^s, highest power first
    for _ in range(s - 1):
        p = polymul(p, [1, 0])
    for _ in range(s):
        p = polymul(p, [1, -1])
    for _ in range(s - 1):
        n = len(p) - 1
        p = [p[i] * (n - i) for i in range(n)]
    c = sorted(mp.re(r) for r in mp.polyroots(p, maxsteps=200, extraprec=200))
    c[-1] = mp.mpf(1)
    A = mp.matrix(s, s)
    for j in range(s):
        lj, den = [mp.mpf(1)], mp.mpf(1)  # l_j, lowest power first
        for k in range(s):
            if k == j:
                continue
            lj = [(lj[i - 1] if i > 0 else 0) - c[k] * (lj[i] if i < len(lj) else 0) for i in range(len(lj) + 1)]
            den *= c[j] - c[k]
        for i in range(s):
            A[i, j] = sum(lj[k] * c[i] ** (k + 1) / (k + 1) for k in range(len(lj))) / den
    ainv = A**-1
    b = [A[s - 1, j] for j in range(s)]
    ev, vec = mp.eig(ainv)
    tiny = mp.mpf(10) ** -30
    real = [k for k in range(s) if abs(mp.im(ev[k])) < tiny]
    assert len(real) == 1
    gamma = mp.re(ev[real[0]])
    pairs = sorted((k for k in range(s) if mp.im(ev[k]) < -tiny), key=lambda k: -mp.re(ev[k]))
    T = mp.matrix(s, s)
    v = [vec[i, real[0]] for i in range(s)]
    for i in range(s):
        T[i, 0] = mp.re(v[i] / v[-1])
    alpha, beta = [], []
    for q, k in enumerate(pairs):
        v = [vec[i, k] for i in range(s)]
        for i in range(s):
            T[i, 1 + 2 * q] = mp.re(v[i] / v[-1])
            T[i, 2 + 2 * q] = mp.im(v[i] / v[-1])
        alpha.append(mp.re(ev[k]))
        beta.append(-mp.im(ev[k]))
    ti = T**-1
    blk = ti * ainv * T
    off = max(abs(blk[i, j]) for i in range(s) for j in range(s)
              if not (i == j or (i > 0 and j > 0 and (i - 1) // 2 == (j - 1) // 2)))
    M, rhs = mp.matrix(s, s), mp.matrix(s, 1)
    for k in range(s):
        for i in range(s):
            M[k, i] = c[i] ** k
        rhs[k] = mp.mpf(1) / (k + 1) - (1 / gamma if k == 0 else 0)
    bhat = M**-1 * rhs
    dd = [gamma * sum((bhat[i] - b[i]) * ainv[i, j] for i in range(s)) for j in range(s)]
    return dict(c=c, ainv=ainv, b=b, gamma=gamma, alpha=alpha, beta=beta, t=T, ti=ti, dd=dd, off=off)


def num(x):
    t = mp.nstr(x, 22)
    return t if ("." in t or "e" in t) else t + ".0"


def main():
    if len(sys.argv) != 2 or not sys.argv[1].isdigit() or int(sys.argv[1]) < 3 or int(sys.argv[1]) % 2 == 0:
        sys.stderr.write("usage: radau_tableau.py S   (S odd, >= 3: the stages)\n")
        return 2
    s = int(sys.argv[1])
    r = tableau(s)
    row = lambda m, i: "{" + ", ".join(num(m[i, j]) for j in range(s)) + "}"
    print("static const RadauTableau radau_order%d = {" % (2 * s - 1))
    print("    .s = %d," % s)
    print("    .c = {%s}," % ", ".join(num(x) for x in r["c"]))
    print("    .ainv = {%s}," % ",\n             ".join(row(r["ainv"], i) for i in range(s)))
    print("    .b = {%s}," % ", ".join(num(x) for x in r["b"]))
    print("    .gamma = %s," % num(r["gamma"]))
    print("    .alpha = {%s}," % ", ".join(num(x) for x in r["alpha"]))
    print("    .beta = {%s}," % ", ".join(num(x) for x in r["beta"]))
    print("    .t = {%s}," % ",\n          ".join(row(r["t"], i) for i in range(s)))
    print("    .ti = {%s}," % ",\n           ".join(row(r["ti"], i) for i in range(s)))
    print("    .dd = {%s}," % ", ".join(num(x) for x in r["dd"]))
    print("};")
    sys.stderr.write("T^-1 A^-1 T off the blocks: %s\n" % mp.nstr(r["off"], 3))
    return 0


if __name__ == "__main__":
    sys.exit(main())
