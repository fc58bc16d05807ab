#!/usr/bin/env python3
"""test_view_default.py FLEXMBD OUTDIR — `flexmbd view` opens its plot on a column with motion
(issue 36), not on the first column: a rotor blade pinned at its root has beam.x and beam.y of
round-off (+-1e-23 m) where its shape spans 1.8 m; the page's default column must be one whose
range is a real part of its unit's scale in the run, and --columns still chooses. Needs no browser:
the page's data ("plot":[...], the plotted columns' indices) is read from the HTML."""
import csv
import json
import os
import re
import subprocess
import sys

flexmbd, out = sys.argv[1], sys.argv[2]
os.makedirs(out, exist_ok=True)
os.chdir(out)
failures = []


def run(*args):
    p = subprocess.run([flexmbd, *args], capture_output=True, text=True, timeout=300)
    if p.returncode != 0:
        failures.append(f"flexmbd {' '.join(args)}: exit {p.returncode}: {p.stderr}")
    return p.stdout


def page_plot(html):
    text = open(html).read()
    columns = json.loads(re.search(r'"columns":(\[[^]]*\])', text).group(1))
    return [columns[i] for i in json.loads(re.search(r'"plot":(\[[0-9,]*\])', text).group(1))]


with open("rotor.yaml", "w") as f:
    f.write(run("new", "rotor"))
cases = {
    # the plot's own columns: x and y are round-off, the others move
    "own": "outputs=[beam.x, beam.y, beam.tip_v, beam.omega, energy.kinetic, beam.shape]",
    # only the drawing's columns: the pose's x and y are round-off, theta and the shape move
    "drawing": "outputs=[beam.x, beam.y, beam.theta, beam.shape]",
}
for name, outputs in cases.items():
    run("run", "rotor.yaml", "-o", f"{name}.csv", "--quiet", "--set", "solver.t_end=1", "--set", outputs)
    run("view", f"{name}.csv", "rotor.yaml", "-o", f"{name}.html")
    rows = list(csv.DictReader(open(f"{name}.csv")))
    plot = page_plot(f"{name}.html")
    if len(plot) != 1:
        failures.append(f"{name}: default plot {plot}, expected one column")
        continue
    col = plot[0]
    values = [float(r[col]) for r in rows]
    span = max(values) - min(values)
    # the run's scale of lengths: its largest coordinate (the blade is 1.8 m long)
    lengths = [abs(float(r[c])) for r in rows for c in r if c.endswith(("_x", "_y", ".x", ".y", "tip_v"))]
    if col in ("beam.x", "beam.y") or span < 1e-3 * max(max(abs(v) for v in values), 1e-300):
        failures.append(f"{name}: opens on '{col}', whose range {span:.3g} is round-off")
    if col.endswith(("_x", "_y", ".x", ".y", "tip_v")) and span < 1e-3 * max(lengths):
        failures.append(f"{name}: opens on '{col}' ({span:.3g} m against lengths of {max(lengths):.3g} m)")
    print(f"{name}: opens on {col} (range {span:.3g})")
run("view", "own.csv", "rotor.yaml", "-o", "chosen.html", "--columns", "beam.x")
if page_plot("chosen.html") != ["beam.x"]:
    failures.append(f"--columns beam.x: plot {page_plot('chosen.html')}")
for f in failures:
    print("FAIL:", f)
print("test_view_default:", "ok" if not failures else f"{len(failures)} failures")
sys.exit(1 if failures else 0)
