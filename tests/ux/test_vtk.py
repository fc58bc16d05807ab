#!/usr/bin/env python3
"""test_vtk.py FLEXMBD SCENE OUTDIR — the ParaView animation of `run --vtk` read back.

XML level: the .pvd is a VTK Collection whose DataSets name existing .vtu files, one per CSV row,
at the CSV's times (every Nth with --vtk-every N); every .vtu is an UnstructuredGrid in raw binary
appended form (each array a UInt64 byte count and its values, read here with struct), whose
array sizes agree with its Piece's
NumberOfPoints/NumberOfCells, whose offsets rise and end at the connectivity's length, whose
indices are in range and whose cell types (vertex 1, line 3, polyline 4) have valid point counts.

Numbers: the beam's centreline points equal the CSV's BEAM.shape columns (the same marker op,
so to the last printed digit), its last station equals BEAM.tip_x/tip_y and its deformation
point data there BEAM.tip_u/tip_v (the beam's own output op, a different code path: 1e-9 m);
the rigid body's frame origin is BODY.x/y; the pin vertex sits on the beam tip (1e-6 m, the
constraint tolerance)."""
import csv
import math
import struct
import os
import shutil
import subprocess
import sys
import xml.etree.ElementTree as ET

flexmbd, scene, out = sys.argv[1:4]
shutil.rmtree(out, ignore_errors=True)
os.makedirs(out)
csv_path = os.path.join(out, "run.csv")
anim = os.path.join(out, "anim")
r = subprocess.run([flexmbd, "run", scene, "-o", csv_path, "--vtk", anim], capture_output=True, text=True)
if r.returncode != 0:
    sys.exit(f"FAIL: run exited {r.returncode}: {r.stderr}")

failures = []


def check(cond, what):
    if not cond:
        failures.append(what)


rows = list(csv.DictReader(open(csv_path)))
stem = os.path.splitext(os.path.basename(scene))[0]
pvd = ET.parse(os.path.join(anim, stem + ".pvd")).getroot()
check(pvd.tag == "VTKFile" and pvd.get("type") == "Collection", "pvd root is a VTKFile Collection")
datasets = pvd.findall("./Collection/DataSet")
check(len(datasets) == len(rows), f"{len(datasets)} DataSets for {len(rows)} CSV rows")


VTK_TYPES = {"Float64": "d", "Int32": "i", "Int64": "q", "UInt8": "B"}
raw = b""  # the current file's appended data, from the byte after '_'
endian = "<"


def read_vtu(path):
    """the XML tree of a .vtu (its binary appended part cut off) and that part"""
    global raw, endian
    data = open(path, "rb").read()
    start = data.find(b'<AppendedData encoding="raw">')
    check(start > 0, f"{path}: raw appended data")
    under = data.index(b"_", start) + 1
    raw = data[under:]
    root = ET.fromstring(data[:start] + b"</VTKFile>")
    check(root.get("header_type") == "UInt64", f"{path}: UInt64 block headers")
    endian = "<" if root.get("byte_order") == "LittleEndian" else ">"
    return root


def numbers(arr, cast=float):
    if arr.get("format") != "appended":
        return [cast(x) for x in (arr.text or "").split()]
    off = int(arr.get("offset"))
    (nbytes,) = struct.unpack(endian + "Q", raw[off:off + 8])
    code = VTK_TYPES[arr.get("type")]
    n = nbytes // struct.calcsize(code)
    return [cast(x) for x in struct.unpack(f"{endian}{n}{code}", raw[off + 8:off + 8 + nbytes])]


def arrays(parent):
    return {a.get("Name"): a for a in parent.findall("DataArray")}


npoints_seen = 0
for ds, row in zip(datasets, rows):
    t = float(row["t"])
    check(abs(float(ds.get("timestep")) - t) <= 1e-12 * max(1.0, abs(t)), f"DataSet time {ds.get('timestep')} = CSV t {t}")
    path = os.path.join(anim, ds.get("file"))
    check(os.path.isfile(path), f"{path} exists")
    root = read_vtu(path)
    check(root.tag == "VTKFile" and root.get("type") == "UnstructuredGrid", f"{path}: an UnstructuredGrid")
    grid = root.find("UnstructuredGrid")
    tv = arrays(grid.find("FieldData"))["TimeValue"]
    check(abs(numbers(tv)[0] - t) <= 1e-12 * max(1.0, abs(t)), f"{path}: TimeValue")
    piece = grid.find("Piece")
    n, c = int(piece.get("NumberOfPoints")), int(piece.get("NumberOfCells"))
    pts = numbers(arrays(piece.find("Points"))["Points"])
    check(len(pts) == 3 * n, f"{path}: {len(pts)} coordinates for {n} points")
    cells = arrays(piece.find("Cells"))
    conn = numbers(cells["connectivity"], int)
    offs = numbers(cells["offsets"], int)
    types = numbers(cells["types"], int)
    check(len(offs) == c and len(types) == c, f"{path}: offsets and types per cell")
    check(all(b > a for a, b in zip([0] + offs, offs)) and offs[-1] == len(conn), f"{path}: offsets rise to the end")
    check(all(0 <= i < n for i in conn), f"{path}: connectivity in range")
    for k, ty in enumerate(types):
        cnt = offs[k] - (offs[k - 1] if k else 0)
        check((ty == 1 and cnt == 1) or (ty == 3 and cnt == 2) or (ty == 4 and cnt >= 2), f"{path}: cell {k} type {ty} with {cnt} points")
    pdata = arrays(piece.find("PointData"))
    cdata = arrays(piece.find("CellData"))
    deform = numbers(pdata["deformation"])
    check(len(deform) == 3 * n and len(numbers(pdata["rotation"])) == n, f"{path}: point data per point")
    part = numbers(cdata["part"], int)
    owner = numbers(cdata["owner"], int)
    check(len(part) == c and len(owner) == c, f"{path}: cell data per cell")

    def cell_points(k):
        start = offs[k - 1] if k else 0
        return conn[start:offs[k]]

    # the centreline (part 0) against the CSV
    beam = [k for k in range(c) if part[k] == 0]
    check(len(beam) == 1, f"{path}: one centreline")
    ids = cell_points(beam[0])
    nst = sum(1 for key in row if key.startswith("arm.shape") and key.endswith("_x"))
    check(len(ids) == nst, f"{path}: {len(ids)} centreline points, {nst} shape stations in the CSV")
    for s, i in enumerate(ids):
        for d, comp in enumerate("xy"):
            csvv = float(row[f"arm.shape{s}_{comp}"])
            check(abs(pts[3 * i + d] - csvv) <= 1e-12 * max(1.0, abs(csvv)), f"{path}: station {s} {comp} {pts[3*i+d]} = CSV {csvv}")
    tip = ids[-1]
    check(math.hypot(pts[3 * tip] - float(row["arm.tip_x"]), pts[3 * tip + 1] - float(row["arm.tip_y"])) < 1e-9, f"{path}: tip position")
    check(math.hypot(deform[3 * tip] - float(row["arm.tip_u"]), deform[3 * tip + 1] - float(row["arm.tip_v"])) < 1e-9,
          f"{path}: tip deformation {deform[3*tip:3*tip+2]} = CSV {row['arm.tip_u']}, {row['arm.tip_v']}")
    # the bob's frame: its first axis starts at the centre of mass
    axes = [k for k in range(c) if part[k] == 2]
    check(len(axes) == 2, f"{path}: the rigid body's two frame axes")
    o = cell_points(axes[0])[0]
    # the .vtu holds exact doubles, the CSV 12 significant digits: equal to the CSV's rounding
    check(math.hypot(pts[3 * o] - float(row["bob.x"]), pts[3 * o + 1] - float(row["bob.y"])) < 1e-11, f"{path}: frame origin")
    # the joints: vertices; the pin at the tip (joint 1) on the beam's tip; the spring a line
    joints = {owner[k]: cell_points(k) for k in range(c) if part[k] == 3}
    check(sorted(joints) == [0, 1], f"{path}: vertices for the two pins")
    j = joints[1][0]
    check(math.hypot(pts[3 * j] - pts[3 * tip], pts[3 * j + 1] - pts[3 * tip + 1]) < 1e-6, f"{path}: pin on the tip")
    springs = [k for k in range(c) if part[k] == 4]
    check(len(springs) == 1 and types[springs[0]] == 3, f"{path}: the spring as a line")
    a = cell_points(springs[0])[0]
    check(pts[3 * a] == 1.0 and pts[3 * a + 1] == 0.5, f"{path}: the spring's fixed end at the anchor")
    npoints_seen += n

# --vtk-every 3: rows 0, 3, 6, ... of the same run
every = os.path.join(out, "every")
r = subprocess.run([flexmbd, "run", scene, "-o", os.path.join(out, "every.csv"), "--vtk", every, "--vtk-every", "3"],
                   capture_output=True, text=True)
sets = ET.parse(os.path.join(every, stem + ".pvd")).getroot().findall("./Collection/DataSet") if r.returncode == 0 else []
check(len(sets) == (len(rows) + 2) // 3, f"--vtk-every 3: {len(sets)} steps for {len(rows)} rows")
check(all(abs(float(ds.get("timestep")) - float(row["t"])) <= 1e-12 * max(1.0, abs(float(row["t"])))
          for ds, row in zip(sets, rows[::3])), "--vtk-every 3: the steps are rows 0, 3, 6, ...")
r = subprocess.run([flexmbd, "run", scene, "-o", os.path.join(out, "x.csv"), "--vtk", every, "--vtk-every", "0"],
                   capture_output=True, text=True)
check(r.returncode == 2 and "--vtk-every needs" in r.stderr, f"--vtk-every 0: exit {r.returncode}")

# the scene key `vtk` does the same as the option (added here by an override)
keyed = os.path.join(out, "keyed")
r = subprocess.run([flexmbd, "run", scene, "-o", os.path.join(out, "keyed.csv"), "--set", "vtk=" + keyed], capture_output=True, text=True)
check(r.returncode == 0 and len(ET.parse(os.path.join(keyed, stem + ".pvd")).getroot().findall("./Collection/DataSet")) == len(rows),
      "the scene key vtk writes the same collection")
# a directory that cannot be made: bad input, said so
r = subprocess.run([flexmbd, "run", scene, "-o", os.path.join(out, "x.csv"), "--vtk", os.path.join(out, "no", "such", "dir")],
                   capture_output=True, text=True)
check(r.returncode == 2 and "cannot create the VTK directory" in r.stderr, f"an impossible --vtk directory: exit {r.returncode}")

# the beam moved: the test is not comparing zeros
last = rows[-1]
check(abs(float(last["arm.tip_v"])) > 1e-4, f"the tip deflects ({last['arm.tip_v']})")
if failures:
    print("\n".join("FAIL: " + f for f in failures[:20]))
    sys.exit(1)
print(f"ok: {len(datasets)} VTK steps, {npoints_seen} points read back and matched to the CSV")
