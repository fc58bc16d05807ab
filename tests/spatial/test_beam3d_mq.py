#!/usr/bin/env python3
"""test_beam3d_mq.py — the spatial beam's M and Q (bodies/beam3d.c) against the independent numpy
implementation of docs/formulation-3d.md (tools/spatial_refs/beam3d_ref.py --mq), at one random
state: a tilted frame, Euler parameters of length 1.3 with a rate along themselves (the gauge),
nonzero p and p', a spinning and translating frame, gravity; for complete, FOAC and ZOAC.

    test_beam3d_mq.py BEAM3D_MQ FLEXMBD_SOURCE_DIR OUT_DIR

beam3d_mq reads M's columns off the C residual (R(a = e_k) - R(a = 0), mapped to the
quasi-velocities) and Q = -R(a = 0); Q is compared without its elastic part K p (the same linear
K in both, and 1e5 times the rest at this state). And marker3's derivatives (dpos/dq, the virtual rotation G)
at an off-axis section point against central differences of its position and rotation matrix. Tolerance 1e-10 of each block's largest entry: a dropped or
wrong term (a coupling product, a Coriolis factor 2, gravity on u_C) is orders of magnitude above it.
"""
import json
import os
import subprocess
import sys

import numpy as np

exe, src, out = sys.argv[1], sys.argv[2], sys.argv[3]
os.makedirs(out, exist_ok=True)
ref = os.path.join(src, "tools", "spatial_refs", "beam3d_ref.py")

L, rho, A, Iz, Iy, E, G, J, ne = 1.8, 2767.0, 2.5e-4, 1.302e-10, 2.1e-10, 68.95e9, 26.5e9, 2.7e-10, 3
n = 6 * ne
grav = [1.5, -9.81, 2.5]
rng = np.random.default_rng(34)
e = np.array([0.9, 0.3, -0.4, 0.2])
e *= 1.3 / np.linalg.norm(e)
eu = e / np.linalg.norm(e)
w0, x, y, z = eu
R = np.array([[1 - 2 * (y * y + z * z), 2 * (x * y - w0 * z), 2 * (x * z + w0 * y)],
              [2 * (x * y + w0 * z), 1 - 2 * (x * x + z * z), 2 * (y * z - w0 * x)],
              [2 * (x * z - w0 * y), 2 * (y * z + w0 * x), 1 - 2 * (x * x + y * y)]])
scale = np.tile([1e-3, 0.05, 0.03, 0.06, 0.04, 0.02], ne)  # u, v, v', w, w', phi
p = rng.uniform(-1, 1, n) * scale
pd = rng.uniform(-1, 1, n) * scale * 10
v0 = np.array([0.4, -0.7, 0.25])      # body frame
om = np.array([1.1, -0.6, 3.2])       # body frame
r0 = np.array([0.3, 0.2, -0.1])
Lm = np.array([[-e[1], e[0], e[3], -e[2]], [-e[2], -e[3], e[0], e[1]], [-e[3], e[2], -e[1], e[0]]])
ed = 0.5 * Lm.T @ om + 0.37 * e        # omega = (2/|e|^2) L e' (the part along e is the gauge)
assert np.allclose(2 / (e @ e) * Lm @ ed, om)
q = np.concatenate([r0, e, p])
v = np.concatenate([R @ v0, ed, pd])
with open(os.path.join(out, "beam3d_mq_state.txt"), "w") as f:
    f.write(" ".join(repr(float(c)) for c in np.concatenate([q, v])) + "\n")

fails = 0
for model in ("complete", "foac", "zoac"):
    scene = os.path.join(out, f"beam3d_mq_{model}.yaml")
    with open(scene, "w") as f:
        f.write(f"""dimension: 3
solver: {{t_end: 1}}
gravity: {grav}
bodies:
  - {{name: beam, type: beam, length: {L}, elements: {ne}, density: {rho}, area: {A}, second_moment: {Iz},
     second_moment_flap: {Iy}, youngs_modulus: {E}, shear_modulus: {G}, torsion_constant: {J}, model: {model}}}
""")
    res = subprocess.run([exe, scene, os.path.join(out, "beam3d_mq_state.txt")], capture_output=True, text=True)
    if res.returncode != 0:
        print(f"FAIL {model}: beam3d_mq exit {res.returncode}: {res.stderr}")
        fails += 1
        continue
    lines = res.stdout.strip().splitlines()
    mk = [float(c) for c in lines.pop().split()[1:]]
    # marker3 at (0.37 L, 4 mm, -3 mm): dpos/dq and G against central differences (step 1e-6: error ~1e-10)
    okm = mk[0] < 1e-7 * mk[1] and mk[2] < 1e-7 * mk[3]
    print(f"{'ok  ' if okm else 'FAIL'} {model}: marker3 dpos/dq off differences by {mk[0]:.2e} of {mk[1]:.3g}, "
          f"G by {mk[2]:.2e} of {mk[3]:.3g} (limit 1e-7 relative)")
    fails += 0 if okm else 1
    rows = [list(map(float, line.split())) for line in lines]
    Mc, Qc = np.array(rows[:-1]).T, np.array(rows[-1])  # each line of M is a column
    st = {"L": L, "rho": rho, "A": A, "Iy": Iy, "Iz": Iz, "E": E, "GJ": G * J, "ne": ne, "model": model,
          "R": R.flatten().tolist(), "p": p.tolist(), "nu": np.concatenate([v0, om, pd]).tolist(), "gravity": grav}
    sp = os.path.join(out, f"beam3d_mq_{model}.json")
    with open(sp, "w") as f:
        json.dump(st, f)
    rr = subprocess.run([sys.executable, ref, "--mq", sp], capture_output=True, text=True, check=True)
    rj = json.loads(rr.stdout)
    Mr, Qr, Kp = np.array(rj["M"]), np.array(rj["Q"]), np.array(rj["Kp"])
    # Q's inertial and gravity part alone (K p, 1e5 times larger here, would hide an error in it)
    Qc[6:] += Kp
    Qr[6:] += Kp
    # blocks: frame (6) and deformation (n) rows and columns, each against its own largest entry
    blocks = [(slice(0, 6), slice(0, 6)), (slice(0, 6), slice(6, None)), (slice(6, None), slice(6, None))]
    worst = 0.0
    for bi, bj in blocks:
        errM = np.max(np.abs(Mc[bi, bj] - Mr[bi, bj])) / np.max(np.abs(Mr[bi, bj]))
        errMt = np.max(np.abs(Mc[bj, bi] - Mr[bj, bi])) / np.max(np.abs(Mr[bj, bi]))
        worst = max(worst, errM, errMt)
    errQ = [np.max(np.abs(Qc[s] - Qr[s])) / np.max(np.abs(Qr[s])) for s in (slice(0, 6), slice(6, None))]
    ok = worst < 1e-10 and max(errQ) < 1e-10
    print(f"{'ok  ' if ok else 'FAIL'} {model}: M relative error {worst:.2e}, Q frame {errQ[0]:.2e}, "
          f"deformation {errQ[1]:.2e} (limit 1e-10); |M| {np.max(np.abs(Mr)):.3g}, |Q| {np.max(np.abs(Qr)):.3g}")
    if not ok:
        fails += 1
        d = np.abs(Mc - Mr)
        i, j = np.unravel_index(np.argmax(d), d.shape)
        print(f"   worst M entry ({i}, {j}): C {Mc[i, j]:.12g} ref {Mr[i, j]:.12g}")
        k = np.argmax(np.abs(Qc - Qr))
        print(f"   worst Q entry {k}: C {Qc[k]:.12g} ref {Qr[k]:.12g}")
sys.exit(1 if fails else 0)
