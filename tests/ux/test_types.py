#!/usr/bin/env python3
"""test_types.py FLEXMBD SOURCE_DIR OUT_DIR: `flexmbd types` lists exactly the outputs a scene may
ask of each built-in type (issue 27 item 3). For an item of every type in the shipped scenes:
  - every output `types` lists for its type, asked at once, runs (exit 0) and writes its columns;
  - a quantity it does not list is refused (exit 2), and the loader's "available:" list is the
    same set as the one `types` printed (shape and shape_N aside: they expand into columns).
Before: `types` left out the joints' work and reaction_* and the beams' shape, and gave every body
the frame outputs although the loader refused them for bodies with fewer than 3 coordinates."""
import os
import re
import subprocess
import sys

flexmbd, src, out = sys.argv[1:4]
os.makedirs(out, exist_ok=True)
failures = 0


def check(what, ok, detail=""):
    global failures
    print(("ok: " if ok else "FAIL: ") + what + (("  (" + detail + ")") if detail and not ok else ""))
    failures += 0 if ok else 1


text = subprocess.run([flexmbd, "types"], capture_output=True, text=True, check=True).stdout
listed, current = {}, None
for line in text.splitlines():
    m = re.match(r"^  (\w+)  \(", line)
    if m:
        current = m.group(1)
    m = re.match(r"^    outputs:(.*)$", line)
    if m and current:
        listed[current] = m.group(1).split()
        current = None

# one item of each type: (scene, item, type)
items = [
    ("tests/ux/scenes/vtk_mechanism.yaml", "anchor", "ground"),
    ("tests/ux/scenes/vtk_mechanism.yaml", "arm", "beam"),
    ("tests/ux/scenes/vtk_mechanism.yaml", "bob", "rigid"),
    ("tests/ux/scenes/vtk_mechanism.yaml", "pivot", "revolute"),
    ("tests/ux/scenes/vtk_mechanism.yaml", "tether", "spring"),
    ("scenes/rotor.yaml", "root1", "fixed"),
    ("scenes/rotor.yaml", "motor", "force"),
    ("scenes/slider_crank.yaml", "motor", "drive"),
    ("scenes/slider_crank.yaml", "slide", "prismatic"),
]
check("types lists outputs for every built-in type",
      all(t in listed for _, _, t in items), str(sorted(listed)))


def concrete(name):
    """a listed pattern as a scene writes it"""
    return name.replace("nodeK_", "node1_").replace("shape_N", "shape_3")


for scene, item, typ in items:
    names = listed.get(typ, [])
    # shape and shape_N draw the same centreline (one of them per body): shape here
    wanted = [item + "." + concrete(n) for n in names if n != "shape_N"]
    csv = os.path.join(out, f"{item}_{typ}.csv")
    r = subprocess.run([flexmbd, "run", os.path.join(src, scene), "-o", csv, "--quiet",
                        "--set", "solver.t_end=0.01", "--set", "solver.output_step=0.005", "--set", "outputs=[" + ", ".join(wanted) + "]"],
                       capture_output=True, text=True)
    header = open(csv).readline().strip().split(",") if r.returncode == 0 else []
    columns = [w.replace(".shape", ".shape0_x") for w in wanted]
    check(f"{typ} ({item} in {scene}): all {len(names)} listed outputs run and are columns",
          r.returncode == 0 and all(c in header for c in columns), r.stderr.strip()[-300:])
    r = subprocess.run([flexmbd, "run", os.path.join(src, scene), "-o", os.path.join(out, "x.csv"), "--quiet",
                        "--set", f"outputs=[{item}.no_such_quantity]"], capture_output=True, text=True)
    m = re.search(r"\(available: ([^)]*)\)", r.stderr)
    avail = set(m.group(1).split(", ")) if m else set()
    expect = set(n for n in names if n not in ("shape", "shape_N"))
    check(f"{typ}: an unlisted quantity is refused and the loader offers exactly the listed ones",
          r.returncode == 2 and avail == expect, f"exit {r.returncode}, loader {sorted(avail)}, types {sorted(expect)}")
sys.exit(1 if failures else 0)
