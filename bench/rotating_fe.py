#!/usr/bin/env python3
"""rotating_fe.py — an independent value for docs/models.md: the first in-plane frequency of the
seed beam (Liu, Hong & Liu 2009) spinning at Omega about its clamped root, from an inextensible
Euler-Bernoulli model with the exact centrifugal tension T(x) = rho A Omega^2 (L^2 - x^2) / 2:

    EI w'''' - (T w')' - rho A Omega^2 w + rho A w'' = 0      (in-plane: the -rho A Omega^2 w softening)

Cubic Hermite elements (5-point Gauss), clamped root; the first eigenvalue of K - w^2 M by bisection
on the inertia count (Sylvester) of a banded LDL^T. Pure Python, no flexmbd code.

    python3 bench/rotating_fe.py        # prints elements, w(Omega = 0, 1, 4, 15) rad/s
"""
import math

RHO, A, E, I, L = 2767.0, 2.5e-4, 68.95e9, 1.302e-10, 1.8
GX = [-0.9061798459386640, -0.5384693101056831, 0.0, 0.5384693101056831, 0.9061798459386640]
GW = [0.2369268850561891, 0.4786286704993665, 0.5688888888888889, 0.4786286704993665, 0.2369268850561891]


def matrices(omega, ne):
    le, n = L / ne, 2 * ne
    K = [[0.0] * n for _ in range(n)]
    M = [[0.0] * n for _ in range(n)]
    for e in range(ne):
        dofs = [2 * e - 2, 2 * e - 1, 2 * e, 2 * e + 1]  # root node clamped: -2, -1 dropped
        for g, wg in zip(GX, GW):
            xi, w = 0.5 * (g + 1.0), 0.5 * wg * le
            x = (e + xi) * le
            N = [1 - 3 * xi**2 + 2 * xi**3, le * (xi - 2 * xi**2 + xi**3), 3 * xi**2 - 2 * xi**3, le * (xi**3 - xi**2)]
            d1 = [(6 * xi**2 - 6 * xi) / le, 1 - 4 * xi + 3 * xi**2, (6 * xi - 6 * xi**2) / le, 3 * xi**2 - 2 * xi]
            d2 = [(12 * xi - 6) / le**2, (6 * xi - 4) / le, (6 - 12 * xi) / le**2, (6 * xi - 2) / le]
            T = RHO * A * omega**2 * (L * L - x * x) / 2
            for a in range(4):
                for b in range(4):
                    if dofs[a] < 0 or dofs[b] < 0:
                        continue
                    K[dofs[a]][dofs[b]] += w * (E * I * d2[a] * d2[b] + T * d1[a] * d1[b] - RHO * A * omega**2 * N[a] * N[b])
                    M[dofs[a]][dofs[b]] += w * RHO * A * N[a] * N[b]
    return K, M


def count_below(K, M, w, band=4):
    """negative pivots of K - w^2 M (symmetric, half-bandwidth < band): eigenvalues below w^2"""
    n = len(K)
    H = [[K[i][j] - w * w * M[i][j] for j in range(n)] for i in range(n)]
    neg = 0
    for k in range(n):
        d = H[k][k]
        neg += d < 0
        for i in range(k + 1, min(n, k + band)):
            l = H[i][k] / d
            for j in range(i, min(n, k + band)):
                H[j][i] -= l * H[j][k]
    return neg


def first_frequency(omega, ne):
    K, M = matrices(omega, ne)
    lo, hi = 0.5, 50.0
    for _ in range(60):
        mid = 0.5 * (lo + hi)
        if count_below(K, M, mid) >= 1:
            hi = mid
        else:
            lo = mid
    return 0.5 * (lo + hi)


if __name__ == "__main__":
    for ne in (16, 32, 64):
        print(ne, " ".join(f"{first_frequency(om, ne):.6f}" for om in (0.0, 1.0, 4.0, 15.0)))
