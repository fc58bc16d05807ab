#!/usr/bin/env python3
"""test_view3d.py FLEXMBD SOURCE_DIR OUTDIR [ROD3D_PLUGIN] — `flexmbd view` of a spatial run (issue 34), read back.

The heavy top and the spherical pendulum of tests/ux/scenes/spatial_view.yaml are run and drawn:
  - the page is self-contained (no http(s) URL, no <script src>, no <link>) and holds the 3D view:
    the data say dimension 3 and the page has its own projection (orbit, perspective, axes);
  - its embedded data decode to the run: each body's frame columns are the CSV's x, y, z, qw..qz,
    and the hook's point on the bob, r + R(q) [0, 0, 0.9], computed here from the page's data, sits
    at the ground point [1, 0, 0] (the constraint, 1e-7 m: independent of the drawing);
  - in headless Chromium (skipped, 77, without it) the drawn points (<pre id="drawn">, ?t=T) equal
    the CSV's: the bob's origin bob.x/y/z and the top's axis tips origin + 0.02 R(q) e_k (1e-12),
    the hook's vertex at [1, 0, 0]; no console error;
  - the view turns: screenshots at two camera angles (?yaw=&pitch=) differ, neither is blank;
  - a CSV without the Euler parameters names them and the --set that adds them (exit 2);
  - with ROD3D_PLUGIN (tests/ux/rod3d_plugin.c: a spatial body with a centreline, the path the
    spatial beam takes): the page maps each station to its shapeK_x, _y, _z columns and draws the
    stations there (1e-12), which lie on r + R(q) [sK, 0, 0] of the frame columns (1e-10)."""
import csv
import json
import os
import re
import shutil
import subprocess
import sys

import numpy as np

from png_read import png_pixels

flexmbd, source, out = sys.argv[1:4]
plugin = sys.argv[4] if len(sys.argv) > 4 else None
shutil.rmtree(out, ignore_errors=True)
os.makedirs(out)
scene = os.path.join(source, "tests", "ux", "scenes", "spatial_view.yaml")
failures = []


def check(cond, what):
    if not cond:
        failures.append(what)
        print("FAIL:", what)


def flexmbd_run(args, expect):
    r = subprocess.run([flexmbd] + args, capture_output=True, text=True)
    check(r.returncode == expect, f"{' '.join(args[:3])}... exited {r.returncode}, expected {expect}: {r.stderr[-800:]}")
    return r


run_csv = os.path.join(out, "run.csv")
flexmbd_run(["run", scene, "-o", run_csv, "--quiet"], 0)
page = os.path.join(out, "run.html")
flexmbd_run(["view", run_csv, scene, "-o", page], 0)
html = open(page, encoding="utf-8").read()
check(not re.search(r"https?://", html), "no URL in the page (no network)")
check(not re.search(r"<script[^>]*\bsrc=|<link\b", html, re.I), "no external script or stylesheet")
check("function orbit(" in html and "drawAxes" in html and "4 / (4 + v[2]" in html, "the page has its 3D projection")
m = re.search(r"const D = (\{.*?\});\n", html, re.S)
check(m is not None, "the page embeds its data")
D = json.loads(m.group(1)) if m else {"dimension": 0, "bodies": [], "data": [], "t": []}
check(D.get("dimension") == 3, "the data say dimension 3")
rows = list(csv.DictReader(open(run_csv)))
table = {k: np.array([float(r[k]) for r in rows]) for k in rows[0]}
check(np.array_equal(np.array(D["t"]), table["t"]), "the page's times are the CSV's")


def rotation(q):
    w, x, y, z = np.asarray(q) / np.linalg.norm(q)
    return np.array([[w * w + x * x - y * y - z * z, 2 * (x * y - w * z), 2 * (x * z + w * y)],
                     [2 * (x * y + w * z), w * w - x * x + y * y - z * z, 2 * (y * z - w * x)],
                     [2 * (x * z - w * y), 2 * (y * z + w * x), w * w - x * x - y * y + z * z]])


bodies = {b["name"]: b for b in D["bodies"]}
for name in ("top", "bob"):
    f = bodies.get(name, {}).get("frame") or []
    check(len(f) == 7 and all(np.array_equal(np.array(D["data"][c]), table[f"{name}.{q}"])
                              for c, q in zip(f, ("x", "y", "z", "qw", "qx", "qy", "qz"))),
          f"{name}'s frame in the page is its CSV columns x, y, z, qw..qz")
f = bodies["bob"]["frame"]
hook_err = max(np.abs(np.array([D["data"][f[i]][r] for i in range(3)]) +
                      rotation([D["data"][f[i]][r] for i in range(3, 7)]) @ [0, 0, 0.9] - [1, 0, 0]).max()
               for r in range(len(D["t"])))
check(hook_err < 1e-7, f"the page's bob hangs from the hook at [1, 0, 0] (off {hook_err:.3g} m)")

chromium = shutil.which("chromium") or shutil.which("chromium-browser")
if not chromium:
    print("SKIP: no chromium (Debian: apt-get install chromium); the page's data checked:", "ok" if not failures else failures)
    sys.exit(1 if failures else 77)


def chrome(query, *extra):
    args = [chromium, "--headless", "--no-sandbox", "--disable-gpu", "--hide-scrollbars", "--enable-logging=stderr",
            "--v=0", "--virtual-time-budget=3000", "--window-size=940,900", *extra,
            "file://" + os.path.abspath(page) + query]
    return subprocess.run(args, capture_output=True, text=True, timeout=120)


for k in (len(rows) // 2, len(rows) - 1):
    t = float(rows[k]["t"])
    r = chrome(f"?t={t!r}&yaw=0.3&pitch=0.7", "--dump-dom")
    console = [line for line in r.stderr.splitlines() if ":CONSOLE" in line or "Uncaught" in line]
    check(not console, f"console messages at t={t}: {console[:3]}")
    errors = re.search(r'<pre id="errors">(.*?)</pre>', r.stdout, re.S)
    check(errors is not None and errors.group(1).strip() == "", f"page errors at t={t}: {errors and errors.group(1)}")
    got = re.search(r'<pre id="drawn">(.*?)</pre>', r.stdout, re.S)
    check(got is not None, f"the page at t={t} has its drawn coordinates")
    if not got:
        continue
    d = json.loads(got.group(1).replace("&quot;", '"').replace("&amp;", "&").replace("&lt;", "<").replace("&gt;", ">"))
    check(d["view"]["yaw"] == 0.3 and d["view"]["pitch"] == 0.7, f"the camera from the URL: {d.get('view')}")
    row = {key: float(v) for key, v in rows[k].items()}
    pts = d["points"]
    xyz = lambda p: np.array([p["x"], p["y"], p["z"]])
    bob = [p for p in pts if p["body"] == "bob" and p["local"] == [0, 0, 0]]
    csv_bob = np.array([row[f"bob.{c}"] for c in "xyz"])
    check(bob and np.abs(xyz(bob[0]) - csv_bob).max() <= 1e-12, f"t={t}: the bob drawn at {bob[:1]}, CSV {csv_bob}")
    R = rotation([row[f"top.q{c}"] for c in "wxyz"])
    origin = np.array([row[f"top.{c}"] for c in "xyz"])
    for e in range(3):
        local = [0, 0, 0]
        local[e] = 0.02
        tip = [p for p in pts if p["body"] == "top" and p["local"] == local]
        check(tip and np.abs(xyz(tip[0]) - (origin + R @ local)).max() <= 1e-12, f"t={t}: the top's axis {e} tip")
    hook = [p for p in pts if p["joint"] == "hook"]
    check(hook and np.abs(xyz(hook[0]) - [1, 0, 0]).max() == 0, f"t={t}: the hook's vertex {hook[:1]}")


def drawing_pixels(query):
    shot = os.path.join(out, f"shot_{len(os.listdir(out))}.png")
    chrome(query, f"--screenshot={shot}")
    if not os.path.isfile(shot):
        check(False, f"chromium made no screenshot for {query}")
        return set()
    w, h, px = png_pixels(shot)
    return {(x, y) for y in range(24, min(h, 500)) for x in range(min(w, 900)) if px[y][x] != (255, 255, 255)}


t_end = rows[-1]["t"]
a, b = drawing_pixels(f"?t={t_end}&yaw=0&pitch=0"), drawing_pixels(f"?t={t_end}&yaw=1.2&pitch=0.9")
print(f"screenshots: {len(a)} and {len(b)} non-white pixels at two camera angles, {len(a ^ b)} differ")
check(len(a) > 300 and len(b) > 300, f"the drawing is not blank ({len(a)}, {len(b)} non-white pixels)")
check(len(a ^ b) > 100, f"turning the camera changes the picture ({len(a ^ b)} pixels differ)")

# a CSV without the Euler parameters: nothing to draw, and the --set that adds them
bare = os.path.join(out, "bare.csv")
flexmbd_run(["run", scene, "-o", bare, "--quiet", "--set", "outputs=[top.x, top.y, top.z, bob.x]",
             "--set", "solver.t_end=0.02"], 0)
r = flexmbd_run(["view", bare, scene, "-o", os.path.join(out, "bare.html")], 2)
check("nothing to draw" in r.stderr and "top.qw, top.qx, top.qy, top.qz" in r.stderr and "bob.y, bob.z, bob.qw" in r.stderr,
      f"the missing columns named: {r.stderr}")

# a spatial centreline (the test plugin's rod3d): stations from shapeK_x, _y, _z
if plugin:
    rod_scene = os.path.join(source, "tests", "ux", "scenes", "rod3d.yaml")
    rod_csv, page = os.path.join(out, "rod.csv"), os.path.join(out, "rod.html")
    flexmbd_run(["run", rod_scene, "--plugin", plugin, "-o", rod_csv, "--quiet"], 0)
    flexmbd_run(["view", rod_csv, rod_scene, "--plugin", plugin, "-o", page], 0)
    text = open(page, encoding="utf-8").read()
    D = json.loads(re.search(r"const D = (\{.*?\});\n", text, re.S).group(1))
    rod_rows = list(csv.DictReader(open(rod_csv)))
    names = D["columns"]
    rod = D["bodies"][0]
    check(rod["shape"] == [[names.index(f"rod.shape{k}_{c}") for c in "xyz"] for k in range(5)],
          f"the page maps the 5 stations to their x, y, z columns: {rod['shape']}")
    check(rod["stations"] == [[-0.5 + 0.25 * k, 0, 0] for k in range(5)], f"the stations' places: {rod['stations']}")
    last = {key: float(v) for key, v in rod_rows[-1].items()}
    R = rotation([last[f"rod.q{c}"] for c in "wxyz"])
    r0 = np.array([last[f"rod.{c}"] for c in "xyz"])
    on_rod = max(np.abs(np.array([last[f"rod.shape{k}_{c}"] for c in "xyz"]) - (r0 + R @ [-0.5 + 0.25 * k, 0, 0])).max()
                 for k in range(5))
    check(on_rod < 1e-10, f"the shape columns lie on the rod's axis (off {on_rod:.3g} m)")
    r = chrome(f"?t={rod_rows[-1]['t']}", "--dump-dom")
    got = re.search(r'<pre id="drawn">(.*?)</pre>', r.stdout, re.S)
    check(got is not None, "the rod's page has its drawn coordinates")
    if got:
        d = json.loads(got.group(1).replace("&quot;", '"').replace("&amp;", "&"))
        st = sorted((p["station"], [p["x"], p["y"], p["z"]]) for p in d["points"] if p["body"] == "rod" and p["station"] >= 0)
        check(len(st) == 5 and all(np.abs(np.array(xyz) - [last[f"rod.shape{k}_{c}"] for c in "xyz"]).max() <= 1e-12
                                   for k, xyz in st), f"the rod's stations drawn at the CSV's: {st}")
        print(f"rod3d: 5 stations drawn at their shape columns, on the rod's axis to {on_rod:.2g} m")
if failures:
    sys.exit(f"{len(failures)} failure(s)")
print("view 3D: all checks passed")
