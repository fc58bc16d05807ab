#!/usr/bin/env python3
"""bench/python.py — what the Python package adds to a run (docs/python.md, "Cost").

For each scene: the CPU time of `flexmbd run` (the stats line's cpu_s, the library's own time)
against `model.run()` from Python (time.process_time around the call: the library's time plus
the package's per-row work: fmb_run_rows' loop calling back into Python with each row, copied
into one NumPy array), the two interleaved in each of REPS repeats (the machine's load changes
both alike), medians and their ratio. The program is $FLEXMBD_PROGRAM, else build/flexmbd.

    PYTHONPATH=python python3 bench/python.py [REPS] > bench/results/python.csv
"""
import os
import statistics
import subprocess
import sys
import time

import flexmbd

REPS = int(sys.argv[1]) if len(sys.argv) > 1 else 5
SCENES = ["scenes/pendulum.yaml", "scenes/paper/spinup_w15.yaml", "scenes/slider_crank.yaml", "scenes/rotor.yaml"]
program = os.environ.get("FLEXMBD_PROGRAM") or os.path.join(os.path.dirname(__file__), "..", "build", "flexmbd")

print("scene,rows,cli_cpu_s,python_cpu_s,ratio")
for scene in SCENES:
    model = flexmbd.load(scene)
    cli, py = [], []
    for _ in range(REPS):
        p = subprocess.run([program, "run", scene, "-o", os.devnull, "--quiet"], capture_output=True, text=True)
        cli.append(flexmbd._lib.parse_stats_line(p.stderr.strip().splitlines()[-1])["cpu_s"])
        c0 = time.process_time()
        r = model.run()
        py.append(time.process_time() - c0)
    a, b = statistics.median(cli), statistics.median(py)
    print(f"{scene},{len(r)},{a:.4f},{b:.4f},{b / a:.2f}")
