"""The GIL is released while the library runs, two runs in two threads are those of one thread, and
1000 load/run/free cycles leave the memory where it was."""
import gc
import os
import resource
import threading

import numpy as np

import flexmbd
from conftest import SRC

PENDULUM = os.path.join(SRC, "scenes", "pendulum.yaml")
SPINUP = os.path.join(SRC, "scenes", "paper", "spinup_w4.yaml")


def test_gil_released_during_a_run():
    """A run that would take hours (t_end = 1e6 s) is started in a thread; it can end only by the
    Cancel another thread sets. While it is inside the library, the main thread loads and runs a
    whole other scene to the end, then cancels it. Were the GIL held during the C call, the main
    thread could not run a line of Python before the long run ended: the test would hang (ctest's
    timeout fails it) instead of passing."""
    long = flexmbd.load(PENDULUM, set={"solver.t_end": 1e6})
    cancel = flexmbd.Cancel()
    entered = threading.Event()
    got = {}

    def long_run():
        entered.set()
        got["long"] = long.run(check=False, cancel=cancel)

    t = threading.Thread(target=long_run)
    t.start()
    assert entered.wait(30)
    short = flexmbd.load(SPINUP).run()  # a whole run while the other one goes on
    alive_after_short = t.is_alive()
    cancel.set()
    t.join(60)
    assert not t.is_alive()
    assert short.status == "ok" and short.t[-1] == 20.0
    assert alive_after_short, "the long run ended by itself: it cannot (t_end = 1e6 s)"
    r = got["long"]
    assert r.status == "interrupted" and isinstance(r.error, flexmbd.Interrupted)
    assert 0.0 < r.t[-1] < 1e6 and r.stats["t_reached"] >= r.t[-1]


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
