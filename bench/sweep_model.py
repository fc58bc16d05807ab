"""bench/sweep_model.py — scheduling efficiency of a sweep at 16..1024 workers, modelled from
measured run costs (docs/performance.md, "Sweeps"). A list-scheduling simulator:
  dynamic        each free worker gets the next run from rank 0, which hands out one run per
                 `dispatch` seconds at most (its journal write and flush are serial)
  longest-first  the same, runs sorted by cost, longest first (needs a cost estimate up front)
  static         contiguous blocks of n/P runs per worker, no manager (Slurm-array-like)
E = sum of costs / (P * makespan). Workloads: the measured costs as they are, and resampled to
larger plans with a fixed seed (a Monte Carlo of 10^5 four-bar runs; a Campbell diagram of 500
spin-up speeds), plus the work-precision study's own costs (bench/results/runs.csv: cpu_med).
usage: python3 sweep_model.py FOURBAR_COSTS SPINUP_COSTS BENCH_RUNS_CSV [DISPATCH_MS]"""
import csv
import heapq
import random
import sys


def read_costs(path):
    return [float(x) for x in open(path) if x.strip()]


def dynamic(costs, p, dispatch):
    free = [0.0] * p  # when each worker is free
    heapq.heapify(free)
    manager, end = 0.0, 0.0
    for c in costs:
        t = heapq.heappop(free)
        start = max(t, manager)
        manager = start + dispatch
        finish = manager + c
        end = max(end, finish)
        heapq.heappush(free, finish)
    return end


def static(costs, p):
    n = len(costs)
    return max(sum(costs[k * n // p:(k + 1) * n // p]) for k in range(p))


def main():
    four, spin, bench = sys.argv[1:4]
    dispatch = float(sys.argv[4]) * 1e-3 if len(sys.argv) > 4 else 1e-4
    rnd = random.Random(2026)
    loads = {"fourbar_400": read_costs(four), "spinup_60": read_costs(spin)}
    loads["montecarlo_1e5_fourbar"] = [rnd.choice(loads["fourbar_400"]) for _ in range(100000)]
    loads["campbell_500_spinup"] = [rnd.choice(loads["spinup_60"]) for _ in range(500)]
    try:
        wp = [float(r["cpu_med"]) for r in csv.DictReader(open(bench)) if r.get("cpu_med") not in (None, "", "nan")]
        if wp:
            loads["workprecision_%d" % len(wp)] = wp
    except OSError:
        pass
    print("workload,runs,sum_cost_s,max_cost_s,workers,dynamic,longest_first,static,dispatch_ms")
    for name, costs in loads.items():
        total = sum(costs)
        longest = sorted(costs, reverse=True)
        for p in (1, 2, 16, 64, 256, 1024):
            e = [total / (p * dynamic(costs, p, dispatch)), total / (p * dynamic(longest, p, dispatch)),
                 total / (p * static(costs, p))]
            print("%s,%d,%.4g,%.4g,%d,%.3f,%.3f,%.3f,%.4g" % (name, len(costs), total, max(costs), p, *e, dispatch * 1e3))


main()
