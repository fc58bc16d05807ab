"""The GIL is released while the library runs, two runs in two threads are those of one thread, and
1000 load/run/free cycles leave the memory where it was."""
import gc
import os
import resource
import subprocess
import sys
import threading

import numpy as np

import flexmbd
from conftest import SRC

PENDULUM = os.path.join(SRC, "scenes", "pendulum.yaml")
SPINUP = os.path.join(SRC, "scenes", "paper", "spinup_w4.yaml")


GIL_SCENARIO = """
import os, sys, threading, time
import flexmbd
pendulum, spinup = sys.argv[1:3]
long = flexmbd.load(pendulum, set={"solver.t_end": 1e6, "solver.min_step": 1e-12, "solver.max_steps": 100000000})
sim = long.start()
box = {}

def worker():
    box["tid"] = threading.get_native_id()
    try:
        sim.advance(1e6)              # ONE call into the library: hours of work unless cancelled
        box["end"] = "returned"
    except flexmbd.Interrupted:
        box["end"] = "interrupted"
    except flexmbd.FlexmbdError as e:
        box["end"] = repr(str(e))

def cpu_ticks(tid):                   # the thread's user + system CPU time (clock ticks)
    with open(f"/proc/self/task/{tid}/stat") as f:
        fields = f.read().rsplit(")", 1)[1].split()
    return int(fields[11]) + int(fields[12])

t = threading.Thread(target=worker)
t.start()
while "tid" not in box:
    time.sleep(0.001)
start = cpu_ticks(box["tid"])
# the worker spends CPU only inside that call: seeing it grow, this thread runs Python while the
# other is in the library
deadline = time.monotonic() + 60
while t.is_alive() and cpu_ticks(box["tid"]) < start + 5 and time.monotonic() < deadline:
    time.sleep(0.01)
grown = cpu_ticks(box["tid"]) - start if t.is_alive() else -1
short = flexmbd.load(spinup).run()   # a whole run, in this thread, meanwhile
still_inside = t.is_alive()
sim.cancel()
t.join(60)
print(grown, short.status, short.t[-1], still_inside, box.get("end"), sim.t)
"""


def test_gil_released_during_a_run(out):
    """One thread makes ONE call into the library that would run for hours (advance to t = 1e6 s
    of the pendulum); it ends only when another thread cancels it. Meanwhile the main thread sees
    the worker's CPU time grow (it spends CPU only inside that call), runs a whole other scene,
    and cancels. Were the GIL held during the call, the main thread could not run a line of Python
    until it returned, which it never does: the scenario runs in a child process, so that a hang
    fails this test after 120 s instead of stalling the suite."""
    script = os.path.join(out, "gil.py")
    with open(script, "w") as f:
        f.write(GIL_SCENARIO)
    try:
        p = subprocess.run([sys.executable, script, PENDULUM, SPINUP], capture_output=True, text=True, timeout=120)
    except subprocess.TimeoutExpired:
        raise AssertionError("the main thread could not run while another was in the library: the GIL is held")
    assert p.returncode == 0, p.stderr
    assert "interrupted" in p.stdout, p.stdout  # else the long call ended by itself: it says why
    grown, status, t_last, still_inside, end, t_stop = p.stdout.split()
    assert int(grown) >= 5, "the worker used no CPU inside the library"
    assert status == "ok" and float(t_last) == 20.0  # the other scene ran to its end meanwhile
    assert still_inside == "True" and end == "interrupted"  # the long call was still going until cancelled
    assert 0.0 < float(t_stop) < 1e6


def test_two_threads_give_the_one_thread_results():
    """Two different scenes run concurrently in two threads give exactly the rows they give alone
    (no state shared between runs: static caches, the registry)."""
    scenes = [(SPINUP, {"bodies.beam.model": "foac"}), (os.path.join(SRC, "scenes", "rotor.yaml"), {})]
    alone = [flexmbd.load(p, set=s).run() for p, s in scenes]
    models = [flexmbd.load(p, set=s) for p, s in scenes]
    together = [None, None]
    barrier = threading.Barrier(2)

    def go(i):
        barrier.wait()
        together[i] = models[i].run()

    threads = [threading.Thread(target=go, args=(i,)) for i in range(2)]
    for th in threads:
        th.start()
    for th in threads:
        th.join()
    for a, b in zip(alone, together):
        assert a.columns == b.columns and np.array_equal(a.values, b.values)


def rss_kib():
    with open("/proc/self/statm") as f:
        return int(f.read().split()[1]) * resource.getpagesize() // 1024


def test_memory_stable_over_1000_cycles():
    """load, run, free 1000 times a tiny scene (0.05 s of the pendulum, 6 rows): after 100 cycles of
    warm-up (allocator pools, numpy's caches), the resident size may not grow by more than 1 MiB
    over the next 1000 — a leak of the model (tens of KiB) or of a row buffer would add several MiB."""
    def cycle():
        m = flexmbd.load(PENDULUM, set={"solver.t_end": 0.05})
        r = m.run()
        assert len(r) == 6
        m.close()

    for _ in range(100):
        cycle()
    gc.collect()
    before = rss_kib()
    for _ in range(1000):
        cycle()
    gc.collect()
    growth = rss_kib() - before
    print(f"RSS growth over 1000 cycles: {growth} KiB")
    assert growth < 1024, f"RSS grew by {growth} KiB over 1000 load/run/free cycles"
