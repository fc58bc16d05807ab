#!/usr/bin/env python3
"""test_refs.py FLEXMBD SOURCE_DIR OUTDIR CASE — a spatial scene run by the engine against the reference
that tools/spatial_refs/ computes without it (tests/spatial/ref/*.csv, each file's comment says how).

bricard: Bricard's overconstrained linkage (tests/spatial/scenes/bricard.yaml). Grubler counts 0 degrees
  of freedom (5 rods x 6 - 6 revolute joints x 5); the mechanism moves because the closure equations have
  rank 29 of 30 along its motion. The engine must find the redundant row (its message names it), keep one
  degree of freedom and follow the motion bricard_ref.py integrates in the one minimal coordinate (RK4,
  its own step halving agrees to 3.6e-12 m): joint A's angle and the point P3 (vertex C, placed from rod
  cd's centre and quaternion) over 10 s, and T + V constant (no work is done). At the scene's rtol 1e-8
  the agreement is ~2e-6 m; rtol 1e-10 must come closer (the agreement is convergence, not chance).
slider_crank: a crank driven at 2 pi rad/s (revolute3d with a profile), a rod on a ball and a Cardan
  joint, a slider on a line off the crank's plane (tests/spatial/scenes/slider_crank.yaml): the slider's
  position and velocity and the crank's angle against the closed form of rigid_refs.py over two turns
  (the driven turn continues past pi), at rtol 1e-9 within 1e-7 m and 1e-6 m/s.
"""
import os
import subprocess
import sys

import numpy as np

flexmbd, src, out, case = sys.argv[1:5]
sys.path.insert(0, os.path.join(src, "tools", "spatial_refs"))
from reflib import read_csv  # noqa: E402

os.makedirs(out, exist_ok=True)
fails = []


def table(path):
    names, rows = read_csv(path)
    return {k: rows[:, i] for i, k in enumerate(names)}


def run(scene, tag, *sets):
    csv = os.path.join(out, f"{tag}.csv")
    args = [flexmbd, "run", os.path.join(src, "tests", "spatial", "scenes", scene), "-o", csv]
    for s in sets:
        args += ["--set", s]
    p = subprocess.run(args, capture_output=True, text=True)
    if p.returncode != 0:
        sys.exit(f"FAIL: {scene} {' '.join(sets)} exited {p.returncode}: {p.stderr.strip().splitlines()[-1:]}")
    return table(csv), p.stderr


def same_rows(got, ref):
    if len(got["t"]) != len(ref["t"]) or np.abs(got["t"] - ref["t"]).max() > 1e-12:
        sys.exit(f"FAIL: rows at other times than the reference's ({len(got['t'])} against {len(ref['t'])})")


def rotation(w, x, y, z):
    return np.array([[1 - 2 * (y * y + z * z), 2 * (x * y - w * z), 2 * (x * z + w * y)],
                     [2 * (x * y + w * z), 1 - 2 * (x * x + z * z), 2 * (y * z - w * x)],
                     [2 * (x * z - w * y), 2 * (y * z + w * x), 1 - 2 * (x * x + y * y)]])


def bricard():
    ref = table(os.path.join(src, "tests", "spatial", "ref", "bricard.csv"))
    p3_ref = np.stack([ref["P3_x"], ref["P3_y"], ref["P3_z"]], 1)
    errors = {}
    for rtol in ("1e-8", "1e-10"):
        got, err = run("bricard.yaml", f"bricard_{rtol}", f"solver.rtol={rtol}")
        same_rows(got, ref)
        if "redundant constraints" not in err:
            fails.append(f"rtol {rtol}: no redundant row reported (stderr: {err.strip()[:200]})")
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
            fails.append(f"rtol {rtol}: the motion departs from the reference: P3 {e_p3:.3g} m, angle "
                         f"{e_theta:.3g} rad (limit 1e-5)")
        if drift > 1e-4:
            fails.append(f"rtol {rtol}: energy not conserved: {drift:.3g} J (limit 1e-4)")
    if not errors["1e-10"] < 0.5 * errors["1e-8"]:
        fails.append(f"rtol 1e-10 does not come closer to the reference than 1e-8: {errors['1e-10']:.3g} against "
                     f"{errors['1e-8']:.3g} m")


def slider_crank():
    ref = table(os.path.join(src, "tests", "spatial", "ref", "slider_crank.csv"))
    got, _ = run("slider_crank.yaml", "slider_crank")
    same_rows(got, ref)
    e_s = np.abs(got["slider.x"] - ref["slider_s"]).max()
    e_v = np.abs(got["slider.vx"] - ref["slider_v"]).max()
    e_a = np.abs(np.unwrap(got["motor.angle"]) - ref["crank_angle"]).max()
    e_w = np.abs(got["motor.speed"] - 2 * np.pi).max()
    off = max(np.abs(got["slider.y"] - 0.1).max(), np.abs(got["slider.z"] - 0.12).max())
    print(f"slider within {e_s:.3g} m (stroke {np.ptp(ref['slider_s']):.3g} m) and {e_v:.3g} m/s of the closed "
          f"form, crank angle within {e_a:.3g} rad over {ref['crank_angle'][-1]:.3g} rad, its speed within "
          f"{e_w:.3g} rad/s of 2 pi, the slider off its line by {off:.3g} m")
    if e_s > 1e-7 or e_v > 1e-6 or e_a > 1e-7 or e_w > 1e-6 or off > 1e-9:
        fails.append("the slider-crank departs from its closed form")


{"bricard": bricard, "slider_crank": slider_crank}[case]()
for f in fails:
    print("FAIL:", f)
sys.exit(1 if fails else 0)
