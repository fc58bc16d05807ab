"""Plans of `flexmbd sweep` (docs/sweep.md, "Plans") against values computed here, independently,
from the documented formulas: grids (linear and log, first key slowest), zipped lists, a samples
file, random designs (the counter-based generator re-implemented in Python; LHS checked by its
defining property, one sample per stratum; the normal sampler by its mean and spread), run ids
that do not depend on how overrides are ordered or numbers written, and bad specs refused (exit 2).
usage: python3 test_plan.py FLEXMBD SOURCE_DIR WORK_DIR"""
import csv
import math
import os
import shutil
import subprocess
import sys

flexmbd, src, work = sys.argv[1:4]
scene = os.path.join(src, "scenes", "fourbar.yaml")
shutil.rmtree(work, ignore_errors=True)
os.makedirs(work)
failures = []


def check(cond, what):
    if not cond:
        failures.append(what)
        print("FAIL:", what)


def plan(name, *args):
    d = os.path.join(work, name)
    r = subprocess.run([flexmbd, "sweep", scene, "-o", d, "--dry-run", *args], capture_output=True, text=True)
    if r.returncode != 0:
        print(r.stdout, r.stderr)
        check(False, f"{name}: dry run exit {r.returncode}")
        return []
    with open(os.path.join(d, "plan.csv")) as f:
        return list(csv.DictReader(f))


def g17(v):
    return "%.17g" % v


# grids: full factorial, first key slowest; log spacing exp(log a + (log b - log a) i/(n-1)), exact ends
rows = plan("grid", "--grid", "solver.rtol=1e-3:1e-7:5:log", "--grid", "bodies.crank.mass=1,2.5")
la, lb = math.log(1e-3), math.log(1e-7)
expect = []
for i in range(5):
    r = 1e-3 if i == 0 else 1e-7 if i == 4 else math.exp(la + (lb - la) * i / 4)
    for m in (1.0, 2.5):
        expect.append((g17(r), g17(m)))
got = [(r["solver.rtol"], r["bodies.crank.mass"]) for r in rows]
check(got == expect, f"log grid x list: {got[:3]}... != {expect[:3]}...")
check([int(r["index"]) for r in rows] == list(range(10)), "indices 0..9")

rows = plan("linear", "--grid", "solver.t_end=0.5:1.5:3")
check([r["solver.t_end"] for r in rows] == ["0.5", "1", "1.5"], "linear grid 0.5:1.5:3")

# zip: paired lists, crossed with a grid
rows = plan("zip", "--zip", "bodies.crank.mass=1,2,3", "--zip", "bodies.rocker.mass=4,5,6", "--grid", "solver.t_end=1,2")
got = [(r["bodies.crank.mass"], r["bodies.rocker.mass"], r["solver.t_end"]) for r in rows]
expect = [(str(a), str(b), str(t)) for (a, b) in ((1, 4), (2, 5), (3, 6)) for t in (1, 2)]
check(got == expect, f"zip x grid: {got} != {expect}")

# a samples file (header = paths), as SALib or OpenTURNS would write it
sf = os.path.join(work, "samples.csv")
with open(sf, "w") as f:
    f.write("# a design\nbodies.crank.mass,solver.rtol\n1.5,1e-6\n2.25, 3e-7\n")
rows = plan("samples", "--samples", sf)
got = [(r["bodies.crank.mass"], r["solver.rtol"]) for r in rows]
check(got == [("1.5", g17(1e-6)), ("2.25", g17(3e-7))], f"samples: {got}")

# random designs: the generator of docs/sweep.md, written again here
M = 2**64


def mix64(z):
    z = ((z ^ (z >> 30)) * 0xBF58476D1CE4E5B9) % M
    z = ((z ^ (z >> 27)) * 0x94D049BB133111EB) % M
    return z ^ (z >> 31)


def uniform(seed, sample, stream):
    z = (mix64(seed) + 0x9E3779B97F4A7C15 * (sample + 1) + 0xD1B54A32D192ED03 * (stream + 1)) % M
    return ((mix64(z) >> 11) + 0.5) * 2.0**-53


def quantile(u):
    lo, hi = -40.0, 40.0
    while True:
        mid = 0.5 * (lo + hi)
        if mid <= lo or mid >= hi:
            return mid
        if 0.5 * math.erfc(-mid / math.sqrt(2.0)) < u:
            lo = mid
        else:
            hi = mid


N, seed = 40, 12345
rows = plan("mc", "--random", "bodies.crank.mass=uniform(1,3)", "--random", "bodies.rocker.mass=normal(3,0.2)",
            "--random", "solver.rtol=lognormal(-16,0.5)", "--count", str(N), "--seed", str(seed))
check(len(rows) == N, f"mc: {len(rows)} runs, expected {N}")
worst = 0.0
for i, r in enumerate(rows):
    u0, u1, u2 = uniform(seed, i, 0), uniform(seed, i, 2), uniform(seed, i, 4)
    check(r["bodies.crank.mass"] == g17(1 + 2 * u0), f"mc sample {i} uniform: {r['bodies.crank.mass']} != {g17(1 + 2 * u0)}")
    for key, v in (("bodies.rocker.mass", 3 + 0.2 * quantile(u1)), ("solver.rtol", math.exp(-16 + 0.5 * quantile(u2)))):
        worst = max(worst, abs(float(r[key]) - v) / abs(v))
check(worst < 1e-12, f"mc normal/lognormal samples: relative difference {worst:.3g} (expected < 1e-12)")

# the same seed with more samples: the first 40 do not change (sample i depends on (seed, i) only)
rows2 = plan("mc_more", "--random", "bodies.crank.mass=uniform(1,3)", "--random", "bodies.rocker.mass=normal(3,0.2)",
             "--random", "solver.rtol=lognormal(-16,0.5)", "--count", "100", "--seed", str(seed))
check([r["bodies.crank.mass"] for r in rows2[:N]] == [r["bodies.crank.mass"] for r in rows], "mc: sample i independent of --count")

# normal: mean and spread of 2000 samples (4 standard errors)
rows = plan("normal", "--random", "bodies.crank.mass=normal(3,0.2)", "--count", "2000", "--seed", "1")
x = [float(r["bodies.crank.mass"]) for r in rows]
mean = sum(x) / len(x)
sd = math.sqrt(sum((v - mean) ** 2 for v in x) / (len(x) - 1))
check(abs(mean - 3) < 4 * 0.2 / math.sqrt(2000), f"normal(3,0.2): mean {mean}")
check(abs(sd - 0.2) < 4 * 0.2 / math.sqrt(2 * 2000), f"normal(3,0.2): sd {sd}")

# Latin hypercube: exactly one sample in each of the N strata of each path
rows = plan("lhs", "--random", "bodies.crank.mass=uniform(1,3)", "--random", "bodies.rocker.mass=uniform(2,4)",
            "--count", "25", "--seed", "9", "--design", "lhs")
for key, a in (("bodies.crank.mass", 1.0), ("bodies.rocker.mass", 2.0)):
    strata = sorted(int((float(r[key]) - a) / 2.0 * 25) for r in rows)
    check(strata == list(range(25)), f"lhs {key}: strata {strata}")

# ids: independent of the order of --set and of how a number is written
a = plan("ids_a", "--grid", "solver.t_end=1,2", "--set", "solver.rtol=1e-8", "--set", "bodies.crank.mass=2")
b = plan("ids_b", "--grid", "solver.t_end=1.0,2.0", "--set", "bodies.crank.mass=2.0", "--set", "solver.rtol=0.00000001")
check([r["run_id"] for r in a] == [r["run_id"] for r in b] and len(a) == 2, "run ids depend on --set order or number spelling")
c = plan("ids_c", "--grid", "solver.t_end=1,2", "--set", "solver.rtol=1e-8", "--set", "bodies.crank.mass=2.0000001")
check(len(c) == 2 and c[0]["run_id"] != a[0]["run_id"], "run ids: another value must give another id")

# bad specs: a message, exit 2, nothing run
bad = [
    (["--grid", "bodies.nope.mass=1,2"], "no item named 'nope'"),
    (["--grid", "solver.rtol="], "empty value"),
    (["--grid", "solver.rtol=1e-3:1e-6:0"], "N (the number of values) must be a whole number"),
    (["--grid", "solver.t_end=1:2:10000", "--grid", "solver.rtol=1e-6:1e-8:1000"], "add --yes"),
    (["--random", "solver.rtol=uniform(1,2)"], "--count"),
    (["--zip", "solver.rtol=1,2", "--zip", "solver.t_end=1,2,3"], "same length"),
    (["--grid", "solver.rtol=1,2", "--set", "solver.rtol=3"], "both swept and fixed"),
    (["--random", "solver.rtol=gauss(1,2)", "--count", "3"], "--random expects"),
]
for args, msg in bad:
    d = os.path.join(work, "bad")
    r = subprocess.run([flexmbd, "sweep", scene, "-o", d, *args], capture_output=True, text=True)
    check(r.returncode == 2 and msg in r.stderr, f"bad spec {args}: exit {r.returncode}, stderr {r.stderr.strip()!r}")
    check(not os.path.exists(os.path.join(d, "runs.csv")), f"bad spec {args}: a journal was written")

print("test_plan:", "FAILED" if failures else "ok", len(failures))
sys.exit(1 if failures else 0)
