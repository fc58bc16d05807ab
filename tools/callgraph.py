#!/usr/bin/env python3
"""callgraph.py — which engine file calls which, through the functions they export.

Usage: tools/callgraph.py [--cycles] [--single] [DIR ...]   (default DIR: engine)
  (no option)  one line per edge "caller.c -> callee.c: functions"
  --cycles     the strongly connected components of more than one file (circles), exit 1 if any
  --single     exported functions with exactly one caller file elsewhere (candidates to sit beside it)

A function is exported when it is defined at column 0 without `static`; a call is its name
followed by '(' in another file (comments included: a cheap over-approximation, which errs
toward reporting a circle rather than hiding one)."""
import glob
import os
import re
import sys


def main(argv):
    opts = [a for a in argv if a.startswith("--")]
    dirs = [a for a in argv if not a.startswith("--")] or ["engine"]
    files = sorted(f for d in dirs for f in glob.glob(os.path.join(d, "*.c")))
    text = {f: open(f, encoding="utf-8").read() for f in files}
    defined = {}
    for f in files:
        for m in re.finditer(r"^(?!static\b)[A-Za-z][\w \*]*?\b(fmbp?_\w+)\s*\([^;{]*\)\s*\{", text[f], re.M):
            defined.setdefault(m.group(1), f)
    edges = {}
    callers = {}
    for f in files:
        called = set(re.findall(r"\b(fmbp?_\w+)\s*\(", text[f]))
        for fn in sorted(called):
            home = defined.get(fn)
            if home and home != f:
                edges.setdefault((f, home), []).append(fn)
                callers.setdefault(fn, []).append(f)
    if "--single" in opts:
        for fn in sorted(callers):
            if len(callers[fn]) == 1:
                print(f"{fn}: defined in {defined[fn]}, called only from {callers[fn][0]}")
        return 0
    if "--cycles" not in opts:
        for (a, b), fns in sorted(edges.items()):
            print(f"{a} -> {b}: {' '.join(sorted(fns))}")
        return 0
    # Tarjan's strongly connected components
    graph = {f: sorted({b for (a, b) in edges if a == f}) for f in files}
    index, low, stack, on, comps = {}, {}, [], set(), []

    def visit(v):
        index[v] = low[v] = len(index)
        stack.append(v)
        on.add(v)
        for w in graph[v]:
            if w not in index:
                visit(w)
                low[v] = min(low[v], low[w])
            elif w in on:
                low[v] = min(low[v], index[w])
        if low[v] == index[v]:
            comp = []
            while True:
                w = stack.pop()
                on.discard(w)
                comp.append(w)
                if w == v:
                    break
            if len(comp) > 1:
                comps.append(sorted(comp))

    sys.setrecursionlimit(10000)
    for f in files:
        if f not in index:
            visit(f)
    for comp in comps:
        print("circle: " + " ".join(comp))
        for a in comp:
            for b in comp:
                if (a, b) in edges:
                    print(f"  {a} -> {b}: {' '.join(sorted(edges[(a, b)]))}")
    return 1 if comps else 0


if __name__ == "__main__":
    sys.exit(main(sys.argv[1:]))
