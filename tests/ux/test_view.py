#!/usr/bin/env python3
"""test_view.py FLEXMBD SOURCE_DIR OUTDIR — `flexmbd view` read back in headless Chromium.

The slider-crank (a rigid crank, a flexible rod, a rigid slider) is run with the frame and shape
columns the drawing needs, `view` writes one HTML page, and Chromium (Debian's `chromium`; the
test is skipped, exit 77, without it) loads it:
  - self-contained: no http(s) URL, no <script src>, no <link>;
  - no console error and nothing in the page's error box;
  - the drawn coordinates (the page's <pre id="drawn"> for ?t=T) equal the CSV's: the rod's
    stations its shape columns (the same numbers: 1e-12), the slider's frame origin slider.x/y, the
    crank's pin `a` (crank frame + A(theta) point1) the rod's root rod.x/y and the rod's point at
    its tip (joint `b`, between stations) rod.tip_x/tip_y (other outputs: the constraint
    tolerance, 1e-6 m); with ?scale=10 the tip station is u + 10 (r - u), u the undeformed
    station from rod.x, rod.y, rod.theta;
  - a screenshot's drawing area is not blank (non-white pixels), and differs between two times;
  - a `run --models` CSV drawn with --model zoac shows the zoac run's stations;
  - a CSV without the columns says which are missing and the --set that adds them (exit 2 when
    nothing can be drawn); an output onto the CSV is refused (exit 2)."""
import csv
import json
import math
import os
import re
import shutil
import subprocess
import sys

from png_read import png_pixels

flexmbd, source, out = sys.argv[1:4]
chromium = shutil.which("chromium") or shutil.which("chromium-browser")
if not chromium:
    print("SKIP: no chromium (Debian: apt-get install chromium)")
    sys.exit(77)
shutil.rmtree(out, ignore_errors=True)
os.makedirs(out)
scene = os.path.join(source, "scenes", "slider_crank.yaml")
failures = []


def check(cond, what):
    if not cond:
        failures.append(what)
        print("FAIL:", what)


def run(args, expect):
    r = subprocess.run([flexmbd] + args, capture_output=True, text=True)
    check(r.returncode == expect, f"{' '.join(args[:3])}... exited {r.returncode}, expected {expect}: {r.stderr[-800:]}")
    return r


outputs = ("outputs=[crank.x, crank.y, crank.theta, rod.x, rod.y, rod.theta, rod.shape, rod.tip_x, rod.tip_y, "
           "slider.x, slider.y, slider.theta, slide.displacement, energy.total]")
run_csv = os.path.join(out, "run.csv")
run(["run", scene, "-o", run_csv, "--quiet", "--set", outputs, "--set", "solver.t_end=0.03"], 0)
page = os.path.join(out, "run.html")
r = run(["view", run_csv, scene, "-o", page, "--columns", "slide.displacement,energy.total"], 0)
check("wrote" in r.stderr, f"view says what it wrote: {r.stderr}")
html = open(page, encoding="utf-8").read()
check(not re.search(r"https?://", html), "no URL in the page (no network)")
check(not re.search(r"<script[^>]*\bsrc=|<link\b", html, re.I), "no external script or stylesheet")

rows = list(csv.DictReader(open(run_csv)))
times = [float(row["t"]) for row in rows]


def chrome(url, *extra):
    args = [chromium, "--headless", "--no-sandbox", "--disable-gpu", "--hide-scrollbars", "--enable-logging=stderr",
            "--v=0", "--virtual-time-budget=3000", "--window-size=940,900", *extra, url]
    return subprocess.run(args, capture_output=True, text=True, timeout=120)


def drawn(t, scale=None):
    url = "file://" + os.path.abspath(page) + f"?t={t!r}" + (f"&scale={scale}" if scale is not None else "")
    r = chrome(url, "--dump-dom")
    console = [line for line in r.stderr.splitlines() if ":CONSOLE" in line or "Uncaught" in line]
    check(not console, f"console messages at t={t}: {console[:3]}")
    m = re.search(r'<pre id="drawn">(.*?)</pre>', r.stdout, re.S)
    check(m is not None, f"the page at t={t} has its drawn coordinates (stdout {r.stdout[:200]!r})")
    errors = re.search(r'<pre id="errors">(.*?)</pre>', r.stdout, re.S)
    check(errors is not None and errors.group(1).strip() == "", f"page errors at t={t}: {errors and errors.group(1)}")
    if not m:
        return None
    text = m.group(1).replace("&quot;", '"').replace("&amp;", "&").replace("&lt;", "<").replace("&gt;", ">")
    return json.loads(text)


def near(a, b, tol):
    return a is not None and b is not None and abs(a - b) <= tol


nstation = 9  # 8 elements: one station per node
for k in (len(rows) // 3, len(rows) - 1):
    row = {key: float(v) for key, v in rows[k].items()}
    d = drawn(times[k])
    if d is None:
        continue
    check(abs(d["t"] - times[k]) <= 1e-12 * max(1.0, times[k]), f"page shows t={d['t']} for ?t={times[k]}")
    pts = d["points"]
    stations = [p for p in pts if p["body"] == "rod" and p["station"] >= 0]
    check(len(stations) == nstation, f"{len(stations)} rod stations drawn, expected {nstation}")
    for p in stations:
        K = p["station"]
        check(near(p["x"], row[f"rod.shape{K}_x"], 1e-12) and near(p["y"], row[f"rod.shape{K}_y"], 1e-12),
              f"t={times[k]}: station {K} drawn at ({p['x']}, {p['y']}), CSV ({row[f'rod.shape{K}_x']}, {row[f'rod.shape{K}_y']})")
    origin = [p for p in pts if p["body"] == "slider" and p["local"] == [0, 0] and p["joint"] is None]
    check(origin and near(origin[0]["x"], row["slider.x"], 1e-12) and near(origin[0]["y"], row["slider.y"], 1e-12),
          f"t={times[k]}: slider origin {origin[:1]} vs ({row['slider.x']}, {row['slider.y']})")
    pin_a = [p for p in pts if p["joint"] == "a"]
    check(pin_a and near(pin_a[0]["x"], row["rod.x"], 1e-6) and near(pin_a[0]["y"], row["rod.y"], 1e-6),
          f"t={times[k]}: pin a {pin_a[:1]} vs rod root ({row['rod.x']}, {row['rod.y']})")
    pin_b = [p for p in pts if p["joint"] == "b"]
    check(pin_b and near(pin_b[0]["x"], row["rod.tip_x"], 1e-6) and near(pin_b[0]["y"], row["rod.tip_y"], 1e-6),
          f"t={times[k]}: pin b {pin_b[:1]} vs rod tip ({row['rod.tip_x']}, {row['rod.tip_y']})")
    # the deformation scale: u + 10 (r - u) at the tip station
    d10 = drawn(times[k], 10)
    if d10 is None:
        continue
    tip = [p for p in d10["points"] if p["body"] == "rod" and p["station"] == nstation - 1]
    c, s = math.cos(row["rod.theta"]), math.sin(row["rod.theta"])
    ux, uy = row["rod.x"] + 0.3 * c, row["rod.y"] + 0.3 * s
    ex = ux + 10 * (row[f"rod.shape{nstation - 1}_x"] - ux)
    ey = uy + 10 * (row[f"rod.shape{nstation - 1}_y"] - uy)
    check(tip and near(tip[0]["x"], ex, 1e-10) and near(tip[0]["y"], ey, 1e-10),
          f"t={times[k]}: scaled tip {tip[:1]} vs ({ex}, {ey})")


def drawing_pixels(t):
    shot = os.path.join(out, f"shot_{len(os.listdir(out))}.png")
    chrome("file://" + os.path.abspath(page) + f"?t={t!r}", f"--screenshot={shot}")
    if not os.path.isfile(shot):
        check(False, f"chromium made no screenshot at t={t}")
        return set()
    w, h, px = png_pixels(shot)
    # the drawing area: the canvas at the top left, 900 x 520, below its time label
    return {(x, y) for y in range(24, min(h, 520)) for x in range(min(w, 900)) if px[y][x] != (255, 255, 255)}


a, b = drawing_pixels(times[0]), drawing_pixels(times[-1])
print(f"screenshot: {len(a)} and {len(b)} non-white pixels in the drawing, {len(a ^ b)} differ")
check(len(a) > 500 and len(b) > 500, f"the drawing is not blank ({len(a)}, {len(b)} non-white pixels)")
check(len(a ^ b) > 100, f"the drawing moves between t = {times[0]} and {times[-1]} ({len(a ^ b)} pixels differ)")

# a `run --models` CSV: --model picks one model's columns (NAME@MODEL)
models_csv = os.path.join(out, "models.csv")
run(["run", scene, "-o", models_csv, "--quiet", "--models", "zoac,complete", "--set", outputs, "--set",
     "solver.t_end=0.01"], 0)
models_page = os.path.join(out, "models.html")
run(["view", models_csv, scene, "-o", models_page, "--model", "zoac"], 0)
mrows = list(csv.DictReader(open(models_csv)))
# the page's drawn stations at the last row equal the zoac columns (and differ from complete's)
page, saved_page = models_page, page
d = drawn(float(mrows[-1]["t"]))
page = saved_page
if d is not None:
    last = {k: float(v) for k, v in mrows[-1].items()}
    st = [p for p in d["points"] if p["body"] == "rod" and p["station"] >= 0]
    check(len(st) == nstation and all(near(p["x"], last[f"rod.shape{p['station']}_x@zoac"], 1e-12) and
                                      near(p["y"], last[f"rod.shape{p['station']}_y@zoac"], 1e-12) for p in st),
          "view --model zoac draws the zoac run's stations")
    check(any(abs(last[f"rod.shape{k}_y@zoac"] - last[f"rod.shape{k}_y@complete"]) > 1e-9 for k in range(nstation)),
          "the two models' shapes differ (the check above can tell them apart)")

# what the CSV lacks is said, with the --set that adds it
bare = os.path.join(out, "bare.csv")
run(["run", scene, "-o", bare, "--quiet", "--set", "outputs=[crank.theta, slider.x]", "--set", "solver.t_end=0.002"], 0)
r = run(["view", bare, scene, "-o", os.path.join(out, "bare.html")], 2)
check("crank.x, crank.y" in r.stderr and "--set 'outputs=[crank.theta, slider.x, crank.x, crank.y" in r.stderr
      and "rod.shape" in r.stderr and "nothing to draw" in r.stderr, f"the missing columns named: {r.stderr}")
check(not os.path.exists(os.path.join(out, "bare.html")), "nothing written when nothing can be drawn")
partial = os.path.join(out, "partial.csv")
run(["run", scene, "-o", partial, "--quiet", "--set", "outputs=[crank.x, crank.y, crank.theta]", "--set",
     "solver.t_end=0.002"], 0)
r = run(["view", partial, scene, "-o", os.path.join(out, "partial.html")], 0)
check("rod: no rod.x, rod.y, rod.theta, rod.shape: not drawn" in r.stderr and "1 of 3 bodies drawn" in r.stderr,
      f"a partial drawing says what is left out: {r.stderr}")
# inputs are never outputs
before = open(run_csv).read()
run(["view", run_csv, scene, "-o", run_csv], 2)
check(open(run_csv).read() == before, "view -o onto its CSV leaves the CSV as it was")
run(["view", run_csv, scene, "-o", page, "--columns", "no.such"], 2)

if failures:
    sys.exit(f"{len(failures)} failure(s)")
print("view: all checks passed")
