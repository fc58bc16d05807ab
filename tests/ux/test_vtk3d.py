#!/usr/bin/env python3
"""test_vtk3d.py FLEXMBD SCENE OUTDIR — the ParaView animation of a spatial run read back (numpy).

The scene (tests/ux/scenes/spatial_view.yaml) has a heavy top and a spherical pendulum on ball
joints. Each .vtu is parsed from its raw appended data and checked against the run's CSV, which
comes from the bodies' own output op (rigid3d's x, y, z, qw..qz), not from the drawing:
  - every point carries frame_x, frame_y, frame_z; at a body's points they are orthonormal and
    right-handed, and equal to the columns of R(q) of the CSV's quaternion (12 printed digits:
    1e-10);
  - each body's three frame-axis cells start at its origin (= the CSV's x, y, z) and end at
    origin + len R e_k: the axis directions equal R's columns too;
  - the pendulum's bob: its origin equals bob.x/y/z, its outline runs from the hook's point (at
    rest at [1, 0, 0], the joint's vertex there) to the bob, 0.9 m long; the top's outline from the
    pivot at the origin;
  - the bob really moves in 3D (the test is not comparing a still picture)."""
import csv
import os
import shutil
import subprocess
import sys
import xml.etree.ElementTree as ET

import numpy as np

flexmbd, scene, out = sys.argv[1:4]
shutil.rmtree(out, ignore_errors=True)
os.makedirs(out)
csv_path = os.path.join(out, "run.csv")
anim = os.path.join(out, "anim")
r = subprocess.run([flexmbd, "run", scene, "-o", csv_path, "--vtk", anim, "--quiet"], capture_output=True, text=True)
if r.returncode != 0:
    sys.exit(f"FAIL: run exited {r.returncode}: {r.stderr}")
failures = []


def check(cond, what):
    if not cond:
        failures.append(what)


rows = list(csv.DictReader(open(csv_path)))
stem = os.path.splitext(os.path.basename(scene))[0]
datasets = ET.parse(os.path.join(anim, stem + ".pvd")).getroot().findall("./Collection/DataSet")
check(len(datasets) == len(rows), f"{len(datasets)} DataSets for {len(rows)} CSV rows")
DTYPE = {"Float64": "f8", "Int32": "i4", "Int64": "i8", "UInt8": "u1"}


def read_vtu(path):
    """{array name: numpy array (n x ncomp)} of a .vtu in raw appended form, and its piece's counts"""
    data = open(path, "rb").read()
    start = data.find(b'<AppendedData encoding="raw">')
    raw = data[data.index(b"_", start) + 1:]
    root = ET.fromstring(data[:start] + b"</VTKFile>")
    end = "<" if root.get("byte_order") == "LittleEndian" else ">"
    piece = root.find("UnstructuredGrid/Piece")
    out = {}
    for arr in piece.iter("DataArray"):
        off = int(arr.get("offset"))
        nbytes = int(np.frombuffer(raw[off:off + 8], dtype=end + "u8")[0])
        vals = np.frombuffer(raw[off + 8:off + 8 + nbytes], dtype=end + DTYPE[arr.get("type")])
        ncomp = int(arr.get("NumberOfComponents"))
        out[arr.get("Name")] = vals.reshape(-1, ncomp) if ncomp > 1 else vals
    return out, int(piece.get("NumberOfPoints")), int(piece.get("NumberOfCells"))


def quat_matrix(p):
    w, x, y, z = np.asarray(p) / np.linalg.norm(p)
    return np.array([[w * w + x * x - y * y - z * z, 2 * (x * y - w * z), 2 * (x * z + w * y)],
                     [2 * (x * y + w * z), w * w - x * x + y * y - z * z, 2 * (y * z - w * x)],
                     [2 * (x * z - w * y), 2 * (y * z + w * x), w * w - x * x - y * y + z * z]])


BODIES = {1: "top", 2: "bob"}  # drawing numbers (fmbDrawPoint.body) in the scene's order
bob_path = []
for ds, row in zip(datasets, rows):
    a, n, c = read_vtu(os.path.join(anim, ds.get("file")))
    where = f"t={row['t']}"
    pts = a["Points"]
    check(pts.shape == (n, 3) and all(a[f"frame_{k}"].shape == (n, 3) for k in "xyz"), f"{where}: 3 frame vectors per point")
    check("deformation" not in a and "rotation" not in a, f"{where}: no planar point data in space")
    offs = a["offsets"]
    starts = np.concatenate([[0], offs[:-1]])
    cells = [a["connectivity"][s:e] for s, e in zip(starts, offs)]
    part, owner = a["part"], a["owner"]
    for b, name in BODIES.items():
        R = quat_matrix([float(row[f"{name}.q{k}"]) for k in "wxyz"])
        origin_csv = np.array([float(row[f"{name}.{k}"]) for k in "xyz"])
        axes = [cells[k] for k in range(c) if part[k] == 2 and owner[k] == b]
        check(len(axes) == 3, f"{where}: {name} has three frame axes ({len(axes)})")
        if len(axes) != 3:
            continue
        o = axes[0][0]
        check(all(ax[0] == o for ax in axes), f"{where}: {name}'s axes start at one origin")
        check(np.abs(pts[o] - origin_csv).max() < 1e-10, f"{where}: {name}'s origin {pts[o]} = CSV {origin_csv}")
        F = np.column_stack([a["frame_x"][o], a["frame_y"][o], a["frame_z"][o]])
        check(np.abs(F.T @ F - np.eye(3)).max() < 1e-13 and np.linalg.det(F) > 0, f"{where}: {name}'s frame orthonormal")
        check(np.abs(F - R).max() < 1e-10, f"{where}: {name}'s frame vectors = R(CSV quaternion), off {np.abs(F - R).max():.3g}")
        dirs = np.column_stack([pts[ax[1]] - pts[o] for ax in axes])
        lengths = np.linalg.norm(dirs, axis=0)
        check(np.ptp(lengths) < 1e-12 and lengths[0] > 0, f"{where}: {name}'s axes equally long")
        check(np.abs(dirs / lengths - R).max() < 1e-10, f"{where}: {name}'s axis points = R(CSV quaternion)")
        # every point of the body carries the body's frame (a rigid body: one R)
        mine = np.unique(np.concatenate([cells[k] for k in range(c) if owner[k] == b and part[k] in (1, 2)]))
        check(all(np.abs(np.column_stack([a[f"frame_{k}"][i] for k in "xyz"]) - R).max() < 1e-10 for i in mine),
              f"{where}: {name}'s points carry its frame")
    # the pendulum: outline from the hook (at rest at [1, 0, 0]) to the bob; the hook's vertex there
    line = [cells[k] for k in range(c) if part[k] == 1 and owner[k] == 2]
    hook = [cells[k] for k in range(c) if part[k] == 3 and owner[k] == 1]
    bob = np.array([float(row[f"bob.{k}"]) for k in "xyz"])
    bob_path.append(bob)
    check(len(line) == 1 and len(line[0]) == 2, f"{where}: the bob's outline is one line")
    check(len(hook) == 1, f"{where}: the hook is a vertex")
    if len(line) == 1 and len(hook) == 1:
        check(np.abs(pts[line[0][0]] - [1, 0, 0]).max() < 1e-7, f"{where}: the outline starts at the hook {pts[line[0][0]]}")
        check(np.abs(pts[line[0][1]] - bob).max() < 1e-10, f"{where}: the bob {pts[line[0][1]]} = CSV {bob}")
        check(np.abs(pts[hook[0][0]] - [1, 0, 0]).max() == 0.0, f"{where}: the hook's vertex is the ground point")
        check(abs(np.linalg.norm(pts[line[0][0]] - pts[line[0][1]]) - 0.9) < 1e-7, f"{where}: the rod is 0.9 m")
    pivot = [cells[k] for k in range(c) if part[k] == 1 and owner[k] == 1]
    check(len(pivot) == 1 and np.abs(pts[pivot[0][0]]).max() < 1e-7, f"{where}: the top's outline starts at the pivot")
bob_path = np.array(bob_path)
check(np.ptp(bob_path[:, 0]) > 0.05 and np.ptp(bob_path[:, 1]) > 0.3 and np.ptp(bob_path[:, 2]) > 0.01,
      f"the bob moves in all three directions (ranges {np.ptp(bob_path, axis=0)})")
if failures:
    print("\n".join("FAIL: " + f for f in failures[:20]))
    sys.exit(1)
print(f"ok: {len(datasets)} spatial VTK steps matched to the CSV (frames, origins, the pendulum's bob)")
