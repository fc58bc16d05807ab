#!/usr/bin/env python3
"""test_bricard.py FLEXMBD SOURCE_DIR OUTDIR — Bricard's overconstrained linkage (issue 34's tests).

Grubler counts 0 degrees of freedom (5 rods x 6 - 6 revolute joints x 5); the mechanism moves because
the closure equations have rank 29 of 30 along its motion. The engine must find the redundant row
(its message names it), keep one degree of freedom and follow the motion that
tools/spatial_refs/bricard_ref.py integrates in the one minimal coordinate (RK4, its own step
halving agrees to 3.6e-12 m): tests/spatial/ref/bricard.csv. Compared over the 10 s: joint A's
angle and the point P3 (vertex C, the joint between rods bc and cd, placed from cd's centre and
quaternion), and the energy balance (no work is done: T + V constant).
The tolerance follows the run: at the scene's rtol 1e-8 the agreement is ~2e-6 m, and rtol 1e-10
must come closer (the agreement is convergence, not chance).
"""
import os
import subprocess
import sys

import numpy as np

flexmbd, src, out = sys.argv[1:4]
os.makedirs(out, exist_ok=True)
scene = os.path.join(src, "tests", "spatial", "scenes", "bricard.yaml")
fails = []


def load(path):
    lines = [s for s in open(path) if not s.startswith("#")]
    head = lines[0].strip().split(",")
    data = np.array([[float(x) for x in s.split(",")] for s in lines[1:]])
    return {k: data[:, i] for i, k in enumerate(head)}


def rotation(w, x, y, z):
    return np.array([[1 - 2 * (y * y + z * z), 2 * (x * y - w * z), 2 * (x * z + w * y)],
                     [2 * (x * y + w * z), 1 - 2 * (x * x + z * z), 2 * (y * z - w * x)],
                     [2 * (x * z - w * y), 2 * (y * z + w * x), 1 - 2 * (x * x + y * y)]])


ref = load(os.path.join(src, "tests", "spatial", "ref", "bricard.csv"))
p3_ref = np.stack([ref["P3_x"], ref["P3_y"], ref["P3_z"]], 1)
errors = {}
for rtol in ("1e-8", "1e-10"):
    csv = os.path.join(out, f"bricard_{rtol}.csv")
    run = subprocess.run([flexmbd, "run", scene, "-o", csv, "--set", f"solver.rtol={rtol}"], capture_output=True,
                         text=True)
    if run.returncode != 0:
        sys.exit(f"FAIL: the run at rtol {rtol} exited {run.returncode}: {run.stderr.strip().splitlines()[-1:]}")
    if "redundant constraints" not in run.stderr:
        fails.append(f"rtol {rtol}: no redundant row reported (stderr: {run.stderr.strip()[:200]})")
    got = load(csv)
    if len(got["t"]) != len(ref["t"]) or np.abs(got["t"] - ref["t"]).max() > 1e-12:
        sys.exit(f"FAIL: rows at other times than the reference's ({len(got['t'])} against {len(ref['t'])})")
    local_c = np.array([0.0, 0.0, -0.5])  # vertex C in rod cd's frame
    p3 = np.array([[got["cd.x"][i], got["cd.y"][i], got["cd.z"][i]] +
                   rotation(got["cd.qw"][i], got["cd.qx"][i], got["cd.qy"][i], got["cd.qz"][i]) @ local_c
                   for i in range(len(got["t"]))])
    e_p3 = np.abs(p3 - p3_ref).max()
    e_theta = np.abs(got["A.angle"] - ref["theta_A"]).max()
    drift = np.ptp(got["energy.total"])
    errors[rtol] = e_p3
    print(f"rtol {rtol}: P3 within {e_p3:.3g} m of the reference (P3 moves {np.ptp(p3_ref[:, 0]):.3g} m in x), "
          f"joint A's angle within {e_theta:.3g} rad (range {np.ptp(ref['theta_A']):.3g}), T + V varies "
          f"{drift:.3g} J (of {abs(ref['energy'][0]):.3g})")
    if e_p3 > 1e-5 or e_theta > 1e-5:
        fails.append(f"rtol {rtol}: the motion departs from the reference: P3 {e_p3:.3g} m, angle {e_theta:.3g} rad "
                     "(limit 1e-5)")
    if drift > 1e-4:
        fails.append(f"rtol {rtol}: energy not conserved: {drift:.3g} J (limit 1e-4)")
if not errors["1e-10"] < 0.5 * errors["1e-8"]:
    fails.append(f"rtol 1e-10 does not come closer to the reference than 1e-8: {errors['1e-10']:.3g} against "
                 f"{errors['1e-8']:.3g} m")
for f in fails:
    print("FAIL:", f)
sys.exit(1 if fails else 0)
