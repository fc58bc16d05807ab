#!/usr/bin/env python3
"""test_refine.py FLEXMBD SOURCE_DIR OUTDIR — `flexmbd refine` (tools/cmd_refine.c, docs/refine.md).

1. Its columns are the runs' own differences: the ω0 = 4 spin-up (complete model, first 5 s) at
   2, 4, 8, 16 elements, rtol 1e-8. Each mesh is run again here by hand with `flexmbd run` at
   rtol 1e-8 and at rtol 1e-10 (the time reference, rtol / 100), and the table's spatial_err
   (max |reference(n) - reference(2n)|) and time_err (max |run(n) - reference(n)|) must equal the
   differences of those CSVs (to the 12 printed digits), COL.end the run's last value.
2. Its order is the beam's: cubic Hermite elements give the tip deflection an error falling as
   h^4 on this smooth case (measured 3.97, 3.97); the observed order must lie in 3.5..4.5, and
   the spatial error must fall at least 10x per halving (a wrong pairing of meshes or the time
   error standing in for the mesh's would not).
3. Bad input exits 2 and writes no table: falling element counts, an unknown column, an
   output that is the scene itself."""
import csv
import os
import shutil
import subprocess
import sys

exe, src, out = sys.argv[1], os.path.abspath(sys.argv[2]), os.path.abspath(sys.argv[3])
shutil.rmtree(out, ignore_errors=True)
os.makedirs(out)
scene = os.path.join(src, "scenes", "paper", "spinup_w4.yaml")
common = ["--set", "solver.t_end=5"]
meshes = [2, 4, 8, 16]
fails = []


def check(ok, what):
    print(("ok   " if ok else "FAIL ") + what)
    if not ok:
        fails.append(what)


def column(path, name):
    with open(path) as f:
        rows = list(csv.DictReader(f))
    return [float(r["t"]) for r in rows], [float(r[name]) for r in rows]


def max_diff(a, b):
    ta, va = a
    tb, vb = b
    assert ta == tb, "the runs share the output grid"
    return max(abs(x - y) for x, y in zip(va, vb))


table = os.path.join(out, "table.csv")
p = subprocess.run([exe, "refine", scene, "--elements", ",".join(map(str, meshes)), "-o", table] + common +
                   ["--set", "solver.rtol=1e-8"], capture_output=True, text=True, timeout=300)
print(p.stdout, p.stderr)
check(p.returncode == 0, f"refine exits 0 (got {p.returncode})")
with open(table) as f:
    rows = list(csv.DictReader(f))
check([int(float(r["elements"])) for r in rows] == meshes, "one row per mesh, in order")

runs, refs = {}, {}
for n in meshes:
    for rtol, store in (("1e-8", runs), ("1e-10", refs)):
        path = os.path.join(out, f"n{n}_{rtol}.csv")
        subprocess.run([exe, "run", scene, "-o", path, "--quiet", "--set", f"bodies.beam.elements={n}", "--set",
                        f"solver.rtol={rtol}"] + common, check=True, capture_output=True, timeout=120)
        store[n] = column(path, "beam.tip_v")


def close(a, b):
    return abs(a - b) <= 1e-9 * max(abs(a), abs(b)) + 1e-300


for k, n in enumerate(meshes):
    r = rows[k]
    check(close(float(r["beam.tip_v.end"]), runs[n][1][-1]), f"{n} elements: beam.tip_v.end is the run's last value")
    t_err = max_diff(runs[n], refs[n])
    check(close(float(r["time_err"]), t_err), f"{n} elements: time_err {r['time_err']} = the runs' own {t_err:.12g}")
    if k + 1 < len(meshes):
        s_err = max_diff(refs[n], refs[meshes[k + 1]])
        check(close(float(r["spatial_err"]), s_err),
              f"{n} elements: spatial_err {r['spatial_err']} = the references' own {s_err:.12g}")
    else:
        check(r["spatial_err"] == "nan", "the finest mesh has no spatial_err")
for k in (1, 2):
    order = float(rows[k]["order"])
    check(3.5 <= order <= 4.5, f"{meshes[k]} elements: observed order {order:.3f} is the cubic beam's 4")
    check(float(rows[k]["spatial_err"]) * 10 <= float(rows[k - 1]["spatial_err"]),
          f"{meshes[k]} elements: the spatial error falls at least 10x per halving")

# bad input: exit 2, no table
for args, what in (([scene, "--elements", "8,4"], "falling element counts"),
                   ([scene, "--elements", "2,4", "--column", "beam.nope"], "an unknown column"),
                   ([scene, "--elements", "2,4", "-o", scene], "the scene as the output")):
    bad = os.path.join(out, "bad.csv")
    argv = [exe, "refine"] + args + ([] if "-o" in args else ["-o", bad]) + common
    p = subprocess.run(argv, capture_output=True, text=True, timeout=60)
    check(p.returncode == 2 and not os.path.exists(bad), f"{what}: exit 2, nothing written ({p.stderr.strip()})")
with open(scene) as f:
    check("Liu, Hong" in f.read(), "the scene is untouched")

sys.exit(1 if fails else 0)
