#!/usr/bin/env python3
"""test_rotating_cantilever.py FLEXMBD SOURCE_DIR OUTDIR — the spatial beam's Campbell diagram, its flapwise and
chordwise families, against the rotating cantilever's references (tools/spatial_refs/beam3d_ref.py, which computes
them without flexmbd; tests/spatial/ref/rotating_cantilever*.csv say how, and how accurate they are).

Scene: tests/spatial/scenes/rotating_cantilever.yaml, the seed beam (16 elements, complete model, I_y = I_z) on a
hub of radius 0 turned about z by revolute3d's constant profile. `flexmbd campbell` names its columns by family
(flap1, lag1, ...: engine/mode_family.c classifies each mode by where its stations move relative to the spin axis).
Checks, each failing when the physics is wrong:
  1. families: at every speed the first flapwise and the first chordwise mode are found (flap1, lag1), the two
     differ above 1 rad/s (flapwise stiffens by Omega^2 more);
  2. Southwell at low speed: omega^2 = omega_0^2 + K Omega^2 with the continuum's K (flapwise 1.193 from
     mu_flap_series, chordwise K - 1) within 1 % where the continuum itself follows the linear law that closely
     (flapwise to 0.5 omega_0, chordwise to 0.25 omega_0), and the flapwise secant against the continuum's own
     secant to 1e-3 up to lambda = 3 (0.85 omega_0);
  3. the continuum up to lambda = 12 (Omega = 12 sqrt(EI / rho A L^4) = 13.3 rad/s, 3.4 omega_0): the flapwise
     eigenvalue against the Frobenius series to 1e-4 (16 elements: the element's own error is 6e-6), the chordwise
     against the inextensible continuum to 5e-3 (the beam keeps its axial motion, whose Coriolis coupling the
     inextensible reference leaves out: the seed file's chord_fe16 carries it);
  4. the seed beam with its axial coordinates: flap_fe16, chord_fe16 of rotating_cantilever_seed.csv at
     0, 1, 4, 15 rad/s to 1e-4;
  5. ZOAC misses the stiffening: its flapwise mode stays at omega_0 (1e-4) while complete's rises, and its
     chordwise mode softens as sqrt(omega_0^2 - Omega^2).

ctest: spatial_rotating_cantilever (tests/spatial/CMakeLists.txt).
"""
import math
import os
import subprocess
import sys

import numpy as np

flexmbd, src, out = sys.argv[1:4]
sys.path.insert(0, os.path.join(src, "tools", "spatial_refs"))
from reflib import read_csv  # noqa: E402

os.makedirs(out, exist_ok=True)
SCENE = os.path.join(src, "tests", "spatial", "scenes", "rotating_cantilever.yaml")
L, RHO, AREA, I2, E = 1.8, 2767.0, 2.5e-4, 1.302e-10, 68.95e9
SCALE = math.sqrt(E * I2 / (RHO * AREA * L ** 4))  # rad/s per unit of lambda, mu
fails = []


def table(path):
    names, rows = read_csv(path)
    return {k: rows[:, i] for i, k in enumerate(names)}


def check(ok, what):
    print(("ok   " if ok else "FAIL ") + what)
    if not ok:
        fails.append(what)


def campbell(tag, speeds, *sets):
    """the Campbell CSV as {column: array}; its columns flap1, lag1, ... by family"""
    csv = os.path.join(out, f"{tag}.csv")
    args = [flexmbd, "campbell", SCENE, "--speed", "joints.spin.speed", "--speeds",
            ",".join(repr(float(s)) for s in speeds), "--count", "6", "-o", csv, "--plot", os.path.join(out, f"{tag}.png")]
    for s in sets:
        args += ["--set", s]
    r = subprocess.run(args, capture_output=True, text=True)
    if r.returncode != 0:
        sys.stderr.write(r.stderr)
        sys.exit(f"flexmbd campbell failed ({r.returncode}): {' '.join(args)}")
    return table(csv)


ref = table(os.path.join(src, "tests", "spatial", "ref", "rotating_cantilever.csv"))
seed = table(os.path.join(src, "tests", "spatial", "ref", "rotating_cantilever_seed.csv"))

# 1, 2: Southwell at low speed, the families
omega0 = ref["mu_flap_series"][0] * SCALE
lam = ref["lambda"]
K_flap = (ref["mu_flap_series"][1] ** 2 - ref["mu_flap_series"][0] ** 2) / lam[1] ** 2  # lambda = 0.5: 1.193
# The linear law is the low-speed limit: the continuum's own secant (mu^2 - mu_0^2) / lambda^2 falls 0.27 % below
# K at 0.5 omega_0 and 1.1 % at omega_0 (docs/formulation-3d.md section 8), an absolute drift that is 1.7 % of the
# chordwise K - 1 already at 0.5 omega_0. So the law is asked to 1 % where the continuum obeys it (flapwise to
# 0.5 omega_0, chordwise to 0.25 omega_0), and beyond, up to lambda = 3 (0.85 omega_0), the beam's flapwise
# secant is asked to follow the continuum's own secant (Frobenius series) to 1e-3.
low = np.array([0.0, 0.1, 0.25, 0.5]) * omega0
c = campbell("southwell", low)
check("flap1" in c and "lag1" in c, f"families named: columns {sorted(k for k in c if k != 'speed')}")
if "flap1" in c and "lag1" in c:
    w0f, w0c = c["flap1"][0], c["lag1"][0]
    check(abs(w0f / omega0 - 1) < 1e-4 and abs(w0c / omega0 - 1) < 1e-4,
          f"at rest both families at omega_0 = {omega0:.8g} rad/s: flap {w0f:.8g}, lag {w0c:.8g}")
    for i in range(1, len(low)):
        W = low[i]
        kf = (c["flap1"][i] ** 2 - w0f ** 2) / W ** 2
        kc = (c["lag1"][i] ** 2 - w0c ** 2) / W ** 2
        check(abs(kf / K_flap - 1) < 0.01, f"Southwell flapwise at {W:.4g} rad/s: K = {kf:.5f} (continuum {K_flap:.5f})")
        if W <= 0.25 * omega0 * (1 + 1e-9):
            check(abs(kc / (K_flap - 1) - 1) < 0.01,
                  f"Southwell chordwise at {W:.4g} rad/s: K - 1 = {kc:.5f} (continuum {K_flap - 1:.5f})")
    mid = (lam >= 1) & (lam <= 3)
    cm = campbell("secant", np.concatenate(([0.0], lam[mid] * SCALE)))
    if "flap1" in cm:
        sec_fe = (cm["flap1"][1:] ** 2 - cm["flap1"][0] ** 2) / (lam[mid] * SCALE) ** 2
        sec_ct = (ref["mu_flap_series"][mid] ** 2 - ref["mu_flap_series"][0] ** 2) / lam[mid] ** 2
        e = np.max(np.abs(sec_fe / sec_ct - 1))
        check(e < 1e-3, f"flapwise secant against the continuum's at lambda 1..3 (to 0.85 omega_0): {e:.2e} relative "
                        f"(continuum secant {sec_ct.min():.5f}..{sec_ct.max():.5f}, K {K_flap:.5f})")
    check(c["flap1"][-1] > c["lag1"][-1] * 1.05, "flapwise stiffens more than chordwise")

# 3: the continuum up to lambda = 12
sel = lam > 0
c = campbell("continuum", lam[sel] * SCALE)
if "flap1" in c and "lag1" in c:
    ef = np.max(np.abs(c["flap1"] / SCALE / ref["mu_flap_series"][sel] - 1))
    ec = np.max(np.abs(c["lag1"] / SCALE / ref["mu_chord_continuum"][sel] - 1))
    check(ef < 1e-4, f"flapwise against the Frobenius series up to lambda 12: {ef:.2e} relative")
    check(ec < 5e-3, f"chordwise against the inextensible continuum up to lambda 12: {ec:.2e} relative")

# 4: the seed beam with its axial coordinates
c = campbell("seed", seed["Omega"])
if "flap1" in c and "lag1" in c:
    ef = np.max(np.abs(c["flap1"] / seed["flap_fe16"] - 1))
    ec = np.max(np.abs(c["lag1"] / seed["chord_fe16"] - 1))
    check(ef < 1e-4 and ec < 1e-4, f"seed beam at 0, 1, 4, 15 rad/s: flap {ef:.2e}, chord {ec:.2e} relative")

# 5: ZOAC misses the stiffening
W = 2.0 * SCALE  # lambda = 2: ZOAC's chordwise mode still stable
c = campbell("zoac", [0.0, W], "bodies.beam.model=zoac")
if "flap1" in c and "lag1" in c:
    check(abs(c["flap1"][1] / omega0 - 1) < 1e-4, f"ZOAC flapwise at lambda 2: {c['flap1'][1]:.8g} rad/s = omega_0")
    zc = math.sqrt(omega0 ** 2 - W ** 2)
    check(abs(c["lag1"][1] / zc - 1) < 1e-3, f"ZOAC chordwise softens: {c['lag1'][1]:.8g} rad/s ({zc:.8g})")

print(f"test_rotating_cantilever: {len(fails)} failed")
sys.exit(1 if fails else 0)
