#!/usr/bin/env python3
"""bricard_ref.py — Bricard's overconstrained 6R linkage (IFToMM Library of Computational Benchmark
Problems, problem A04) integrated in its ONE minimal coordinate, for the 3D rigid tests.

Geometry used (the benchmark's, as its specification is reproduced by public implementations of
A04 — an OpenSim port and Chrono/MATLAB course drivers; the specification itself was not reachable
from here): six vertices
    A (0,0,0)  B (1,0,0)  C (1,-1,0)  D (1,-1,1)  E (0,-1,1)  F (0,0,1)   [m]
five moving rods AB, BC, CD, DE, EF (length 1 m, mass 1 kg, square section 0.1 m: centroidal
moments m (L^2 + a^2)/12 transverse, m a^2/6 axial); the ground closes F -> A. Revolute joints at
the six vertices, each axis normal to both rods it joins:
    A: y   B: z   C: x   D: y   E: z   F: x
Gravity 9.81 m/s^2 along -y. Released from rest; 10 s. The named point is P3 = C, the joint
between rods BC and CD (the benchmark's reference output).

Grubler: 6 x 5 moving rods - 5 x 6 joints = 0 DOF; the motion exists because the six closure equations
have rank 5 along it. Method: the chain A..E is serial in its joint angles q1..q5; the closure at F
(F's position, and rod EF's joint axis along ground x: 5 equations) is solved for q2..q5 given
q1 = theta by Gauss-Newton (the 5 x 4 system is consistent: its residual is checked). Then
q_dot = Gamma theta_dot (Gamma spans the one-dimensional null space of the closure Jacobian),
q_ddot = Gamma theta_ddot + gamma (gamma from the closure's acceleration bias), and the equation of
motion is Gamma^T (M_q q_ddot + h) = 0 (the reactions do no work along Gamma). RK4 in (theta,
theta_dot).

    /usr/bin/python3 tools/spatial_refs/bricard_ref.py --write   # makes tests/spatial/ref/bricard.csv (10 s; minutes)
    /usr/bin/python3 tools/spatial_refs/bricard_ref.py --check   # a short run at two steps, energy, the stored file
"""
import math
import os
import sys

import numpy as np

sys.path.insert(0, os.path.dirname(os.path.abspath(__file__)))
from reflib import Checks, cross  # noqa: E402

HERE = os.path.dirname(os.path.abspath(__file__))
REF_DIR = os.path.normpath(os.path.join(HERE, "..", "..", "tests", "spatial", "ref"))

VERT = np.array([[0, 0, 0], [1, 0, 0], [1, -1, 0], [1, -1, 1], [0, -1, 1], [0, 0, 1]], dtype=float)
AXES = np.array([[0, 1, 0], [0, 0, 1], [1, 0, 0], [0, 1, 0], [0, 0, 1], [1, 0, 0]], dtype=float)
LINKS = [VERT[k + 1] - VERT[k] for k in range(5)]  # rod k in its own frame (= global at q = 0)
MASS, SIDE, G = 1.0, 0.1, np.array([0.0, -9.81, 0.0])
I_T = MASS * (1.0 + SIDE**2) / 12
I_A = MASS * SIDE**2 / 6
I0 = [I_T * (np.eye(3) - np.outer(n, n)) + I_A * np.outer(n, n) for n in LINKS]


def rot(a, t):
    k = np.array([[0, -a[2], a[1]], [a[2], 0, -a[0]], [-a[1], a[0], 0]])
    return np.eye(3) + math.sin(t) * k + (1 - math.cos(t)) * k @ k


def chain(q):
    """rotation R_k, origin o_k (joint k's vertex) and global axis z_k of rods k = 0..4, and the
    chain's end (should be F)"""
    R, o = np.eye(3), np.zeros(3)
    Rs, os_, zs = [], [], []
    for k in range(5):
        z = R @ AXES[k]
        R = R @ rot(AXES[k], q[k])
        Rs.append(R), os_.append(o.copy()), zs.append(z)
        o = o + R @ LINKS[k]
    return Rs, os_, zs, o


def closure(q):
    """5 closure residuals: F's position (3) and rod EF's F-axis along ground x (its y, z parts)"""
    Rs, os_, zs, end = chain(q)
    e = Rs[4] @ AXES[5]
    return np.concatenate([end - VERT[5], e[1:]])


def closure_jac(q):
    Rs, os_, zs, end = chain(q)
    e = Rs[4] @ AXES[5]
    J = np.zeros((5, 5))
    for j in range(5):
        J[:3, j] = cross(zs[j], end - os_[j])
        J[3:, j] = cross(zs[j], e)[1:]
    return J


def solve_dependent(theta, guess):
    q = guess.copy()
    q[0] = theta
    for _ in range(30):
        r = closure(q)
        if np.abs(r).max() < 1e-15:
            break
        J = closure_jac(q)[:, 1:]
        dq = np.linalg.lstsq(J, -r, rcond=None)[0]
        q[1:] += dq
        if np.abs(dq).max() < 1e-16:
            break
    return q


def dynamics(q, theta_dot):
    """theta_ddot, Gamma, and the energy at (q, theta_dot)"""
    Rs, os_, zs, end = chain(q)
    e = Rs[4] @ AXES[5]
    Jc = closure_jac(q)
    Gam = np.concatenate([[1.0], np.linalg.lstsq(Jc[:, 1:], -Jc[:, 0], rcond=None)[0]])
    qd = Gam * theta_dot
    # velocities and the q_ddot = 0 accelerations, recursively along the chain
    w = np.zeros(3)
    al0 = np.zeros(3)
    a0_o = np.zeros(3)  # acceleration of the current rod's origin with q_ddot = 0
    Mq = np.zeros((5, 5))
    h = np.zeros(5)
    T = V = 0.0
    for k in range(5):
        al0 = al0 + cross(w, zs[k] * qd[k])
        w = w + zs[k] * qd[k]
        c = os_[k] + 0.5 * Rs[k] @ LINKS[k]
        rc = c - os_[k]
        ac0 = a0_o + cross(al0, rc) + cross(w, cross(w, rc))
        Jv = np.zeros((3, 5))
        Jw = np.zeros((3, 5))
        for j in range(k + 1):
            Jv[:, j] = cross(zs[j], c - os_[j])
            Jw[:, j] = zs[j]
        Ig = Rs[k] @ I0[k] @ Rs[k].T
        Mq += MASS * Jv.T @ Jv + Jw.T @ Ig @ Jw
        h += MASS * Jv.T @ (ac0 - G) + Jw.T @ (Ig @ al0 + cross(w, Ig @ w))
        v = Jv @ qd
        T += 0.5 * MASS * v @ v + 0.5 * w @ Ig @ w
        V -= MASS * G @ c
        rl = Rs[k] @ LINKS[k]
        a0_o = a0_o + cross(al0, rl) + cross(w, cross(w, rl))
    # closure acceleration bias: F's acceleration and d2/dt2 of e (y, z) with q_ddot = 0
    aF0 = a0_o  # after the loop: the chain end's acceleration (the end of rod EF)
    ee = cross(al0, e) + cross(w, cross(w, e))
    bias = np.concatenate([aF0, ee[1:]])
    gam = np.concatenate([[0.0], np.linalg.lstsq(Jc[:, 1:], -bias, rcond=None)[0]])
    thdd = -(Gam @ (Mq @ gam + h)) / (Gam @ Mq @ Gam)
    return thdd, Gam, T + V


class Integrator:
    def __init__(self):
        self.q = np.zeros(5)

    def rhs(self, y):
        self.q = solve_dependent(y[0], self.q)
        thdd, _, _ = dynamics(self.q, y[1])
        return np.array([y[1], thdd])

    def run(self, T, h, every):
        y = np.array([0.0, 0.0])
        n = int(round(T / h))
        out = []
        for i in range(n + 1):
            if i % every == 0:
                q = solve_dependent(y[0], self.q)
                _, Gam, E = dynamics(q, y[1])
                Rs, os_, zs, end = chain(q)
                P3 = os_[2]  # vertex C: the origin of rod CD
                out.append((i * h, *P3, y[0], y[1], E, np.abs(closure(q)).max()))
            if i == n:
                break
            k1 = self.rhs(y)
            k2 = self.rhs(y + 0.5 * h * k1)
            k3 = self.rhs(y + 0.5 * h * k2)
            k4 = self.rhs(y + h * k3)
            y = y + h / 6 * (k1 + 2 * k2 + 2 * k3 + k4)
        return np.array(out)


COLS = ["t", "P3_x", "P3_y", "P3_z", "theta_A", "theta_A_rate", "energy", "closure"]


def write(T=10.0, h=2e-3, every=5):
    a = Integrator().run(T, h, every)
    b = Integrator().run(T, h / 2, 2 * every)
    diff = np.abs(a[:, 1:4] - b[:, 1:4]).max()
    drift = np.ptp(b[:, 6])
    path = os.path.join(REF_DIR, "bricard.csv")
    with open(path + ".tmp", "w") as f:
        for line in [
                "Bricard's mechanism (IFToMM benchmark A04 geometry; see tools/spatial_refs/bricard_ref.py for the",
                "vertices, joint axes, rod inertia m(L^2+a^2)/12, m a^2/6 with a = 0.1 m, gravity -9.81 y, released at rest).",
                f"Integrated in the one minimal coordinate theta_A (joint A's angle) by RK4, h = {h / 2:g} s, every 0.01 s;",
                f"against h = {h:g} s the point P3 (vertex C) differs by at most {diff:.1e} m over 10 s; energy = T + V (J,",
                f"V = m g y of the rods' centres) varies by {drift:.1e} J; closure = the largest loop residual (m)."]:
            f.write("# " + line + "\n")
        f.write(",".join(COLS) + "\n")
        for r in b:
            f.write(",".join(repr(float(v)) for v in r) + "\n")
    os.replace(path + ".tmp", path)
    print(f"wrote {path}: P3 step-halving difference {diff:.2e} m, energy drift {drift:.2e} J")


def check():
    expect = Checks()

    # one degree of freedom although Grubler counts none: the closure Jacobian has rank 4 of 5
    # columns at the start and along the motion, and the 5 x 4 Gauss-Newton system is consistent
    sv = np.linalg.svd(closure_jac(np.zeros(5)), compute_uv=False)
    expect(sv[-1] < 1e-14 and sv[-2] > 0.1, f"closure Jacobian singular values {np.array2string(sv, precision=3)}: rank 4, one DOF")
    a = Integrator().run(1.0, 4e-3, 25)
    b = Integrator().run(1.0, 2e-3, 50)
    d = np.abs(a[:, 1:4] - b[:, 1:4]).max()
    expect(d < 1e-10, f"RK4 h 4e-3 / 2e-3 agree on P3 over 1 s: {d:.1e} m")
    expect(np.ptp(b[:, 6]) < 1e-9, f"energy conserved: {np.ptp(b[:, 6]):.1e} J over 1 s")
    expect(b[:, 7].max() < 1e-13, f"loop closed: {b[:, 7].max():.1e} m")
    expect(np.abs(b[-1, 1:4] - VERT[2]).max() > 0.05, f"the linkage moves: P3 at 1 s {np.array2string(b[-1, 1:4], precision=4)}")
    # every rod keeps its length and each rotation stays orthogonal by construction; the stored file
    path = os.path.join(REF_DIR, "bricard.csv")
    with open(path) as f:
        rows = np.array([[float(v) for v in ln.split(",")] for ln in f if not ln.startswith("#") and not ln.startswith("t,")])
    k = [i for i in range(len(rows)) if abs(rows[i, 0] - 1.0) < 1e-9][0]
    d = np.abs(rows[k, 1:4] - b[-1, 1:4]).max()
    expect(d < 1e-9, f"bricard.csv at t = 1 s equals this run: {d:.1e} m")
    expect(np.ptp(rows[:, 6]) < 1e-8 and rows[:, 7].max() < 1e-13, f"bricard.csv: energy drift {np.ptp(rows[:, 6]):.1e} J over 10 s, closure {rows[:, 7].max():.1e}")
    return expect.done()


if __name__ == "__main__":
    if "--write" in sys.argv:
        write()
    sys.exit(check())
