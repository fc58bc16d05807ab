#!/usr/bin/env python3
"""rigid_refs.py — closed-form references for the 3D rigid tests, each with an independent check.

  top          heavy symmetric top on a fixed pivot: the steady precession rates (both roots of
               I1 cos(theta) phid^2 - I3 w3 phid + m g l = 0) and, released with no precession,
               the nutation bounds (roots of the cubic in u = cos(theta)) and the nutation period
               4 K(k) / sqrt(beta (u3 - u1)) (K by the arithmetic-geometric mean).
               Checked against a quaternion integration of Euler's equations with gravity
               (RK4, two step sizes).
  torque_free  torque-free asymmetric body spun near its intermediate axis: the period of the
               angular velocity, 4 K(k)/lambda, and the time between flips, 2 K(k)/lambda (Landau &
               Lifshitz, Mechanics §37). Checked against RK4 of Euler's equations over 100 s (energy
               and |L| conserved, zero crossings of omega_2 against the closed form).
  slider_crank a spatial slider-crank: the slider's position, velocity and acceleration in closed
               form for a crank turning at constant rate. Checked by differences of the closed
               form and the loop closure.

    /usr/bin/python3 tools/spatial_refs/rigid_refs.py --write   # (re)makes tests/spatial/ref/{top,torque_free,slider_crank}*.csv
    /usr/bin/python3 tools/spatial_refs/rigid_refs.py --check   # self-checks against the stored files (exit 1 on failure)
"""
import math
import os
import sys

import numpy as np

sys.path.insert(0, os.path.dirname(os.path.abspath(__file__)))
from reflib import Checks, read_csv, write_csv  # noqa: E402

HERE = os.path.dirname(os.path.abspath(__file__))
REF_DIR = os.path.normpath(os.path.join(HERE, "..", "..", "tests", "spatial", "ref"))


def ellipk(k2):
    """complete elliptic integral of the first kind K(k), k2 = k^2, by the AGM: K = pi / (2 AGM(1, k'))"""
    return ellipk_from_kp2(1.0 - k2)


def ellipk_from_kp2(kp2):
    """K with the complementary modulus k'^2 given directly (no cancellation near k = 1)"""
    a, b = 1.0, math.sqrt(kp2)
    for _ in range(60):  # quadratic convergence: a handful of steps; a fixed cap, as a and b may
        if abs(a - b) <= 4e-16 * a:  # end one ulp apart and never meet
            break
        a, b = 0.5 * (a + b), math.sqrt(a * b)
    return math.pi / (a + b)


# ------------------------------------------------------------------------------------------------
# heavy symmetric top: pivot at the origin, z up, gravity -g z; symmetry axis = body z, centre of
# mass at distance l on it; I1 = transverse moment about the PIVOT, I3 axial.
TOP = dict(m=1.0, l=0.2, g=9.81, I1=0.042, I3=0.004, theta0=math.radians(30.0), w3=200.0)


def top_steady(P=TOP):
    """both steady precession rates at tilt theta0 and spin w3 = psid + phid cos(theta)"""
    c = math.cos(P["theta0"])
    a, b, cc = P["I1"] * c, -P["I3"] * P["w3"], P["m"] * P["g"] * P["l"]
    disc = b * b - 4 * a * cc
    r = math.sqrt(disc)
    # the slow root without cancellation: 2 cc / (-b + r)
    return 2 * cc / (-b + r), (-b + r) / (2 * a)


def top_nutation(P=TOP, phid0=0.0):
    """released at theta0 with thetad = 0, precession phid0: (theta_min, theta_max, period)"""
    I1, I3, m, g, l = P["I1"], P["I3"], P["m"], P["g"], P["l"]
    u0 = math.cos(P["theta0"])
    s2 = 1 - u0 * u0
    ppsi = I3 * P["w3"]
    pphi = I1 * phid0 * s2 + ppsi * u0
    Ep = 0.5 * I1 * phid0**2 * s2 + m * g * l * u0  # E - I3 w3^2 / 2
    beta = 2 * m * g * l / I1
    # f(u) = (2/I1)(Ep - m g l u)(1 - u^2) - ((pphi - ppsi u)/I1)^2 = beta u^3 + ...
    c3 = beta
    c2 = -(2 * Ep / I1) - (ppsi / I1) ** 2
    c1 = -beta + 2 * pphi * ppsi / I1**2
    c0 = 2 * Ep / I1 - (pphi / I1) ** 2

    def f(u):
        return ((c3 * u + c2) * u + c1) * u + c0

    def fp(u):
        return (3 * c3 * u + 2 * c2) * u + c1

    roots = sorted(np.roots([c3, c2, c1, c0]).real)
    roots = [r - f(r) / fp(r) for r in roots]  # one Newton polish each
    roots = [r - f(r) / fp(r) for r in roots]
    u1, u2, u3 = roots
    # u0 is one of the turning points u1 (theta_max) or u2 (theta_min)
    k2 = (u2 - u1) / (u3 - u1)
    period = 4 * ellipk(k2) / math.sqrt(beta * (u3 - u1))
    return math.acos(u2), math.acos(u1), period


def rk4_list(f, y, h):
    """RK4 on a list of floats (numpy's per-call cost dominates for 7 unknowns)"""
    k1 = f(y)
    k2 = f([a + 0.5 * h * b for a, b in zip(y, k1)])
    k3 = f([a + 0.5 * h * b for a, b in zip(y, k2)])
    k4 = f([a + h * b for a, b in zip(y, k3)])
    return [a + h / 6 * (b + 2 * c + 2 * d + e) for a, b, c, d, e in zip(y, k1, k2, k3, k4)]


def top_integrate(P, phid0, T, h):
    """Euler's equations about the pivot in the body frame with a unit quaternion (w, x, y, z), RK4;
    returns samples (t, theta, azimuth of the symmetry axis)"""
    I1, I3, l, mg = P["I1"], P["I3"], P["l"], P["m"] * P["g"]
    th0 = P["theta0"]
    # z-x-z Euler angles phi = psi = 0: R = Rx(theta0); body rates from phid, thetad = 0, w3

    def rhs(y):
        qw, qx, qy, qz, w1, w2, w3 = y
        # gravity in the body frame: R^T (0, 0, -m g) = -m g (third row of R)
        gx = 2 * (qx * qz - qw * qy)
        gy = 2 * (qy * qz + qw * qx)
        # torque (0, 0, l) x (-m g)(gx, gy, .) = m g l (gy, -gx, 0)
        t1, t2 = mg * l * gy, -mg * l * gx
        return [0.5 * (-qx * w1 - qy * w2 - qz * w3), 0.5 * (qw * w1 + qy * w3 - qz * w2),
                0.5 * (qw * w2 + qz * w1 - qx * w3), 0.5 * (qw * w3 + qx * w2 - qy * w1),
                (t1 - (I3 - I1) * w2 * w3) / I1, (t2 - (I1 - I3) * w3 * w1) / I1, 0.0]

    y = [math.cos(th0 / 2), math.sin(th0 / 2), 0.0, 0.0, 0.0, phid0 * math.sin(th0), P["w3"]]
    out = []
    n = int(round(T / h))
    for i in range(n + 1):
        qw, qx, qy, qz = y[:4]
        ax = (2 * (qx * qz + qw * qy), 2 * (qy * qz - qw * qx), 1 - 2 * (qx * qx + qy * qy))
        out.append((i * h, math.acos(max(-1.0, min(1.0, ax[2]))), math.atan2(ax[1], ax[0])))
        y = rk4_list(rhs, y, h)
        nq = math.sqrt(sum(v * v for v in y[:4]))
        y[:4] = [v / nq for v in y[:4]]
    return np.array(out)


# ------------------------------------------------------------------------------------------------
# torque-free asymmetric body, principal moments I1 < I2 < I3, body frame
TF = dict(I=(1.0, 2.0, 3.0), w0=(0.01, 1.0, 0.0), T=100.0)


def tf_period(P=TF):
    """(period of omega, time between flips of omega_2) from Landau & Lifshitz §37"""
    I1, I2, I3 = P["I"]
    w = np.array(P["w0"])
    Iw = np.array(P["I"]) * w
    E2 = float(np.dot(np.array(P["I"]), w * w))  # 2E
    L2 = float(Iw @ Iw)
    if L2 < E2 * I2:  # polhode around axis 1: swap the roles of axes 1 and 3
        I1, I3 = I3, I1
    lam = math.sqrt(abs((I3 - I2) * (L2 - E2 * I1) / (I1 * I2 * I3)))
    # k'^2 = (I3 - I1)(L^2 - 2E I2) / ((I3 - I2)(L^2 - 2E I1)): computed directly, no cancellation
    kp2 = (I3 - I1) * (L2 - E2 * I2) / ((I3 - I2) * (L2 - E2 * I1))
    K = ellipk_from_kp2(kp2)
    return 4 * K / lam, 2 * K / lam


def tf_integrate(P, h, every):
    I1, I2, I3 = P["I"]

    def rhs(w):
        return [(I2 - I3) * w[1] * w[2] / I1, (I3 - I1) * w[2] * w[0] / I2, (I1 - I2) * w[0] * w[1] / I3]

    w = [float(v) for v in P["w0"]]
    n = int(round(P["T"] / h))
    rows, crossings = [], []
    for i in range(n + 1):
        if i % every == 0:
            rows.append((i * h, *w))
        if i == n:
            break
        wn = rk4_list(rhs, w, h)
        if w[1] * wn[1] < 0:
            # cubic Hermite on [t, t+h] for omega_2, root by bisection
            f0, f1, d0, d1 = w[1], wn[1], rhs(w)[1] * h, rhs(wn)[1] * h
            lo, hi = 0.0, 1.0
            for _ in range(60):
                s = 0.5 * (lo + hi)
                val = (2 * s**3 - 3 * s**2 + 1) * f0 + (s**3 - 2 * s**2 + s) * d0 + (-2 * s**3 + 3 * s**2) * f1 + (s**3 - s**2) * d1
                if val * f0 > 0:
                    lo = s
                else:
                    hi = s
            crossings.append((i + 0.5 * (lo + hi)) * h)
        w = wn
    return np.array(rows), crossings


# ------------------------------------------------------------------------------------------------
# spatial slider-crank: crank of radius r turning about the global z axis through the origin at a
# constant rate Omega (revolute to ground); crank pin P = (r cos t, r sin t, 0); a rod of length l
# from P (spherical joint) to the slider S (universal joint), which slides along the global x axis
# offset to the line S(s) = (s, e_y, e_z) (prismatic to ground). The slider line does not lie in
# the crank plane (e_z != 0): the rod moves in space.
SC = dict(r=0.08, l=0.3, ey=0.1, ez=0.12, Omega=2 * math.pi, T=2.0)


def sc_closed(t, P=SC):
    """slider position s, velocity, acceleration and the rod's unit direction (S - P)/l"""
    r, l, ey, ez, Om = P["r"], P["l"], P["ey"], P["ez"], P["Omega"]
    th = Om * t
    c, s_ = math.cos(th), math.sin(th)
    a = ey - r * s_  # the rod's y extent
    root = math.sqrt(l * l - a * a - ez * ez)  # its x extent (s - r cos)
    s = r * c + root
    ad = -r * c * Om
    add = r * s_ * Om * Om
    rootd = -a * ad / root
    rootdd = -(ad * ad + a * add) / root - a * ad * (a * ad) / root**3
    sd = -r * s_ * Om + rootd
    sdd = -r * c * Om * Om + rootdd
    d = np.array([root, a, ez]) / l
    return s, sd, sdd, d


def main(argv):
    if "--write" in argv:
        # top
        slow, fast = top_steady()
        tmin, tmax, per = top_nutation()
        path = os.path.join(REF_DIR, "top.csv")
        with open(path + ".tmp", "w") as f:
            f.write("# Heavy symmetric top, made by tools/spatial_refs/rigid_refs.py --write. Pivot at the origin, z up,\n")
            f.write("# gravity -g z. m 1 kg, l 0.2 m (pivot to centre of mass on the symmetry axis), I1 0.042 kg m^2 about\n")
            f.write("# the pivot (transverse), I3 0.004 kg m^2 (axial), g 9.81, tilt theta0 30 deg, spin w3 = psid + phid cos 200 rad/s.\n")
            f.write("# steady_*: precession rates (rad/s) with theta constant (closed form, both roots); released at theta0\n")
            f.write("# with thetad = phid = 0: nutation bounds (rad) and period (s) from the cubic in cos(theta) and K(k) by AGM.\n")
            f.write("# Accuracy: closed form to rounding; --check integrates Euler's equations (RK4) and agrees to 1e-8.\n")
            f.write("quantity,value\n")
            for k, v in (("steady_slow", slow), ("steady_fast", fast), ("theta_min", tmin), ("theta_max", tmax), ("nutation_period", per)):
                f.write(f"{k},{v!r}\n")
        os.replace(path + ".tmp", path)
        # torque-free
        full, flip = tf_period()
        rows, _ = tf_integrate(TF, 1e-3, 500)
        write_csv(os.path.join(REF_DIR, "torque_free.csv"), ["t", "w1", "w2", "w3"], rows, [
            "Torque-free body, principal moments (1, 2, 3) kg m^2, omega(0) = (0.01, 1, 0) rad/s in the body frame",
            "(near the intermediate axis). Made by tools/spatial_refs/rigid_refs.py --write: RK4 of Euler's equations,",
            "h = 1e-3 s, every 0.5 s for 100 s; agrees with h = 5e-4 to 1e-9 (--check). Closed form (Landau-Lifshitz §37,",
            f"K by AGM): period of omega = 4K/lambda = {full!r} s, time between flips of omega_2 = 2K/lambda = {flip!r} s.",
            "Energy and |L| conserved: 2E = 2.0001 J, |L|^2 = 4.0001 (kg m^2/s)^2."])
        rows = []
        for i in range(201):
            t = i * SC["T"] / 200
            s, sd, sdd, d = sc_closed(t)
            rows.append((t, SC["Omega"] * t, s, sd, sdd, *d))
        write_csv(os.path.join(REF_DIR, "slider_crank.csv"), ["t", "crank_angle", "slider_s", "slider_v", "slider_a", "rod_dx", "rod_dy", "rod_dz"], rows, [
            "Spatial slider-crank, closed form (tools/spatial_refs/rigid_refs.py --write). Crank radius 0.08 m about the",
            "global z axis through the origin, angle = 2 pi t (rad, constant rate); crank pin (r cos, r sin, 0), spherical;",
            "rod 0.3 m to the slider (universal joint), which slides along the line (s, 0.1, 0.12) (prismatic, axis x).",
            "slider_s/v/a: its x position, velocity, acceleration; rod_d*: the rod's unit vector from pin to slider.",
            "Accuracy: rounding (closed form); --check confirms v and a by differences (1e-7) and the rod length (1e-15)."])
        print("wrote", REF_DIR)
    return check()


def check():
    expect = Checks()

    # AGM against a known value: K(sin 45 deg) = 1.854074677301372
    expect(abs(ellipk(0.5) - 1.854074677301372) < 1e-15, f"K(k^2 = 1/2) = {ellipk(0.5):.15f}")

    # top: steady precession holds theta constant; the released top nutates between the roots
    vals = {}
    with open(os.path.join(REF_DIR, "top.csv")) as f:
        for ln in f:
            if ln.startswith("#") or ln.startswith("quantity"):
                continue
            k, v = ln.strip().split(",")
            vals[k] = float(v)
    slow, fast = top_steady()
    tmin, tmax, per = top_nutation()
    expect(abs(vals["steady_slow"] - slow) < 1e-14 * slow and abs(vals["nutation_period"] - per) < 1e-14 * per, "top.csv reproduced")
    # (RK4's error here scales as h^4: at h = 2e-4 the steady tilt drifts 4e-8 rad, at 5e-5 2e-10)
    for rate, name in ((slow, "slow"), (fast, "fast")):
        a = top_integrate(TOP, rate, 0.5, 5e-5)
        drift = np.abs(a[:, 1] - TOP["theta0"]).max()
        az = np.unwrap(a[:, 2])
        meas = (az[-1] - az[0]) / 0.5
        expect(drift < 2e-9 and abs(meas - rate) < 1e-8 * rate,
               f"top steady {name}: theta drift {drift:.1e} rad, precession {meas:.10f} vs {rate:.10f} rad/s")
    a1 = top_integrate(TOP, 0.0, 1.1 * per, 1e-4)
    a2 = top_integrate(TOP, 0.0, 1.1 * per, 5e-5)
    d12 = np.abs(a1[:, 1] - a2[::2, 1]).max()
    expect(d12 < 1e-7, f"top RK4 steps 1e-4 / 5e-5 agree: {d12:.1e} rad")
    th, t = a2[:, 1], a2[:, 0]
    # released at theta0 without precession it falls: theta0 is theta_min, the cubic's other root theta_max
    j = int(np.argmax(th))
    # the maximum and its time from the parabola through the three samples around it
    y0, y1, y2 = th[j - 1], th[j], th[j + 1]
    den = y0 - 2 * y1 + y2
    off = 0.5 * (y0 - y2) / den
    thmax, tmaxt = y1 - 0.25 * (y0 - y2) * off, t[j] + off * (t[1] - t[0])
    expect(abs(th.min() - tmin) < 1e-12 and abs(thmax - tmax) < 2e-9,
           f"top nutation: theta in [{th.min():.10f}, {thmax:.10f}] vs [{tmin:.10f}, {tmax:.10f}] rad")
    k = j + int(np.argmin(th[j:]))
    expect(abs(t[k] - per) < 1e-4 and abs(2 * tmaxt - per) < 1e-6,
           f"top nutation period {per:.9f} s: back at theta_min at {t[k]:.5f} s, half period from the maximum {2 * tmaxt:.9f} s")

    # torque-free: closed form vs RK4 zero crossings; conservation; two step sizes
    full, flip = tf_period()
    rows1, cr1 = tf_integrate(TF, 1e-3, 500)
    rows2, cr2 = tf_integrate(TF, 5e-4, 1000)  # pure-Python RK4: about 3 s for both
    I = np.array(TF["I"])
    E = 0.5 * (rows2[:, 1:] ** 2 * I).sum(axis=1)
    L = np.sqrt(((rows2[:, 1:] * I) ** 2).sum(axis=1))
    expect(np.ptp(E) < 1e-10 * E[0] and np.ptp(L) < 1e-10 * L[0], f"torque-free: energy {np.ptp(E):.1e}, |L| {np.ptp(L):.1e} over 100 s")
    expect(np.abs(rows1[:, 1:] - rows2[:, 1:]).max() < 1e-9, f"torque-free: RK4 h 1e-3 / 5e-4 agree {np.abs(rows1[:, 1:] - rows2[:, 1:]).max():.1e}")
    gaps = np.diff(cr2)
    expect(len(gaps) >= 2 and np.abs(gaps - flip).max() < 1e-8 * flip,
           f"torque-free: {len(cr2)} flips of omega_2, spacing {gaps.mean():.10f} s vs 2K/lambda = {flip:.10f} s")
    _, stored = read_csv(os.path.join(REF_DIR, "torque_free.csv"))
    expect(np.abs(stored[:, 1:] - rows1[:, 1:]).max() < 1e-13, "torque_free.csv reproduced")

    # slider-crank: derivatives by differences, loop closure
    worst_v = worst_a = worst_l = 0.0
    for t in np.linspace(0.0, 1.0, 37):
        s, sd, sdd, d = sc_closed(t)
        h = 1e-4
        sp, sm = sc_closed(t + h)[0], sc_closed(t - h)[0]
        worst_v = max(worst_v, abs((sp - sm) / (2 * h) - sd))
        worst_a = max(worst_a, abs((sp - 2 * s + sm) / h**2 - sdd))
        th = SC["Omega"] * t
        P = np.array([SC["r"] * math.cos(th), SC["r"] * math.sin(th), 0.0])
        S = np.array([s, SC["ey"], SC["ez"]])
        worst_l = max(worst_l, abs(np.linalg.norm(S - P) - SC["l"]), np.abs((S - P) / SC["l"] - d).max())
    expect(worst_v < 1e-7 and worst_a < 1e-5 and worst_l < 1e-15,
           f"slider-crank: v by differences {worst_v:.1e}, a {worst_a:.1e}, rod length {worst_l:.1e}")
    return expect.done()


if __name__ == "__main__":
    sys.exit(main(sys.argv[1:]))
