"""reflib.py — what the reference scripts of tools/spatial_refs/ share: the self-check tally and a fast
3-vector cross product."""
import os

import numpy as np


class Checks:
    """expect(ok, what) prints ok/FAIL and keeps the failures; done() prints the count and gives the exit code"""

    def __init__(self):
        self.fails = []

    def __call__(self, ok, what):
        print(("ok   " if ok else "FAIL ") + what)
        if not ok:
            self.fails.append(what)

    def done(self):
        print(f"{len(self.fails)} failure(s)")
        return 1 if self.fails else 0


def cross(a, b):
    """3-vector cross product (np.cross costs ~50 us a call; the integrators make millions)"""
    return np.array([a[1] * b[2] - a[2] * b[1], a[2] * b[0] - a[0] * b[2], a[0] * b[1] - a[1] * b[0]])


def write_csv(path, header, rows, comment):
    """a CSV with '# ' comment lines first, then the header; written beside the target and renamed"""
    tmp = path + ".tmp"
    with open(tmp, "w") as f:
        for line in comment:
            f.write("# " + line + "\n")
        f.write(",".join(header) + "\n")
        for r in rows:
            f.write(",".join(repr(float(v)) for v in r) + "\n")
    os.replace(tmp, path)


def read_csv(path):
    """(column names, rows as a 2D array) of a file write_csv made"""
    with open(path) as f:
        lines = [ln for ln in f if not ln.startswith("#")]
    return lines[0].strip().split(","), np.array([[float(v) for v in ln.split(",")] for ln in lines[1:]])
