#!/usr/bin/env python3
"""test_starters.py FLEXMBD OUTDIR — every `flexmbd new` starter passes `check`, runs, and does
what its comments say, judged by a balance or a kinematic fact, not by stored numbers:
  pendulum       T + U_g constant (no friction): drift < 1e-4 of the swing's kinetic energy
                 (rtol 1e-6 leaves 4e-5)
  beam           T + U_e + U_g constant (complete model, undamped): drift < 1e-4 of max T
  rotor          the motor's work (trapezoid of motor.power) = T + U_e at the end (1e-3), and
                 the hub at omega0 = 6 rad/s after the ramp
  slider-crank   the slider's stroke is 0.35 .. 0.65 m (crank 0.15 m; 1 mm for the rod's
                 flexibility and sampling), the prismatic guide keeps it on its line, and the crank
                 has turned twice in 2 s
An unknown starter is exit 2."""
import csv
import os
import shutil
import subprocess
import sys

flexmbd, out = sys.argv[1:3]
shutil.rmtree(out, ignore_errors=True)
os.makedirs(out)
failures = []


def check(cond, what):
    print(("ok:   " if cond else "FAIL: ") + what)
    if not cond:
        failures.append(what)


def column(rows, name):
    return [float(r[name]) for r in rows]


def run_starter(name):
    scene = os.path.join(out, name + ".yaml")
    with open(scene, "w") as f:
        r = subprocess.run([flexmbd, "new", name], stdout=f, stderr=subprocess.PIPE, text=True)
    check(r.returncode == 0, f"new {name}")
    r = subprocess.run([flexmbd, "check", scene], capture_output=True, text=True)
    check(r.returncode == 0 and "warning" not in r.stderr, f"check {name}: {r.stderr.strip()[:300]}")
    csv_path = os.path.join(out, name + ".csv")
    r = subprocess.run([flexmbd, "run", scene, "-o", csv_path], capture_output=True, text=True)
    check(r.returncode == 0, f"run {name}: {r.stderr.strip().splitlines()[-1] if r.stderr else ''}")
    return list(csv.DictReader(open(csv_path))) if r.returncode == 0 else []


rows = run_starter("pendulum")
if rows:
    e = column(rows, "energy.total")
    tmax = max(column(rows, "energy.kinetic"))
    check(max(abs(x - e[0]) for x in e) < 1e-4 * tmax, f"pendulum: energy drift {max(abs(x - e[0]) for x in e):.2e} J (T max {tmax:.3g} J)")

rows = run_starter("beam")
if rows:
    e = column(rows, "energy.total")
    tmax = max(column(rows, "energy.kinetic"))
    check(max(abs(x - e[0]) for x in e) < 1e-4 * tmax, f"beam: energy drift {max(abs(x - e[0]) for x in e):.2e} J (T max {tmax:.3g} J)")
    check(max(abs(v) for v in column(rows, "beam.tip_v")) > 1e-4, "beam: the beam bends")
    check("beam.shape8_y" in rows[0], "beam: beam.shape gives one column pair per node")

rows = run_starter("rotor")
if rows:
    t, p = column(rows, "t"), column(rows, "motor.power")
    work = sum(0.5 * (p[i] + p[i + 1]) * (t[i + 1] - t[i]) for i in range(len(t) - 1))
    energy = float(rows[-1]["energy.kinetic"]) + float(rows[-1]["energy.strain"])
    check(abs(work - energy) < 1e-3 * energy, f"rotor: motor work {work:.6g} J = T + U_e {energy:.6g} J")
    check(abs(float(rows[-1]["beam.omega"]) - 6.0) < 1e-6, f"rotor: hub at {rows[-1]['beam.omega']} rad/s")

rows = run_starter("slider-crank")
if rows:
    x, y = column(rows, "slider.x"), column(rows, "slider.y")
    check(abs(min(x) - 0.35) < 1e-3 and abs(max(x) - 0.65) < 1e-3, f"slider-crank: stroke {min(x):.5f} .. {max(x):.5f} m")
    check(max(abs(v) for v in y) < 1e-9, f"slider-crank: the prismatic guide keeps it on its line: off by {max(abs(v) for v in y):.2e} m")
    check(abs(float(rows[-1]["crank.theta"]) - 4 * 3.141592653589793) < 1e-6, "slider-crank: two turns in 2 s")

r = subprocess.run([flexmbd, "new", "catapult"], capture_output=True, text=True)
check(r.returncode == 2 and "slider-crank" in r.stderr, "an unknown starter: exit 2 with the list")
sys.exit(1 if failures else 0)
