"""`flexmbd.study`: a list of override sets run on several processes, one process per run, into
one table: the local form of ``flexmbd sweep``. A run that crashes its process (a plugin's
segfault, an abort) or overruns its timeout costs its own row, nothing else."""
from __future__ import annotations

import faulthandler
import math
import multiprocessing
import os
import time
import traceback
from multiprocessing.connection import wait
from typing import Any, Callable, Dict, List, Mapping, Optional, Sequence, Union

import numpy as np

from . import _lib
from .model import Model, Result, Source, load

# exit codes of the library → the statuses `flexmbd sweep` writes (docs/python.md)
_STATUS = {_lib.EXIT_OK: "ok", _lib.EXIT_BAD_INPUT: "bad_input", _lib.EXIT_SOLVER: "solver_stopped",
           _lib.EXIT_INTERRUPTED: "interrupted"}
_METRICS = ("max", "min", "end", "rms")


def metric(result: Result, spec: str) -> float:
    """``COLUMN:max|min|end|rms`` of a result (``flexmbd sweep --metric`` notation); NaN without rows."""
    col, _, how = spec.rpartition(":")
    if how not in _METRICS or not col:
        raise ValueError(f"flexmbd: a metric is COLUMN:max|min|end|rms, got {spec!r}")
    x = result[col]
    if x.size == 0:
        return math.nan
    return float({"max": np.max, "min": np.min, "end": lambda a: a[-1],
                  "rms": lambda a: np.sqrt(np.mean(a * a))}[how](x))


def _keys(over) -> Dict[str, Any]:
    """a set's values for its row: {PATH: VALUE} as given, or "PATH=VALUE" strings split"""
    if isinstance(over, Mapping):
        return dict(over)
    return dict(item.partition("=")[::2] for item in over)


def _one_run(scene, over: Mapping[str, Any], plugins, t_end, metrics, measure, keep, conn) -> None:
    """In the child: load, run, reduce, send one dict back."""
    faulthandler.disable()  # a crash is reported in its row; no traceback dump from the child
    row: Dict[str, Any] = {}
    try:
        m = scene.reload(over) if isinstance(scene, Model) else load(scene, set=over, plugins=plugins)
        with m:
            r = m.run(t_end, check=False)
        code = r.error.code if r.error is not None else 0
        row.update(status=_STATUS.get(code, "failed"), exit_code=code, message=str(r.error) if r.error else "")
        for key in ("t_reached", "steps", "cpu_s"):
            row[key] = r.stats.get(key, math.nan)
        for spec in metrics:
            row[spec] = metric(r, spec)
        if measure is not None:
            row.update(measure(r))
        if keep:
            row["result"] = r
    except _lib.FlexmbdError as e:
        row.update(status=_STATUS.get(e.code, "failed"), exit_code=e.code, message=str(e))
    except Exception:  # a bug in `measure`, say: this row says so, the study goes on
        row.update(status="error", exit_code=-1, message=traceback.format_exc(limit=3).strip())
    conn.send(row)
    conn.close()


def study(scene: Union[Model, Source], overrides: Sequence[Union[Mapping[str, Any], Sequence[str]]], *, processes: Optional[int] = None,
          metrics: Sequence[str] = (), measure: Optional[Callable[[Result], Mapping[str, Any]]] = None,
          t_end: Optional[float] = None, timeout: Optional[float] = None, keep_results: bool = False,
          plugins: Sequence[str] = ()) -> List[Dict[str, Any]]:
    """Run the scene once per override set, each run in its own process, ``processes`` at a time
    (default: the number of CPUs), and return one row per set, in the order given.

    A row holds the set's values (its keys as given), ``status`` (``ok``, ``solver_stopped``,
    ``bad_input``, ``interrupted``, ``crashed`` — the process died, ``exit_code`` is minus the
    signal —, ``timeout`` — killed after ``timeout`` seconds of wall time —, ``error`` — an
    exception in ``measure``), ``exit_code``, ``message``, ``t_reached``, ``steps``, ``cpu_s``,
    one value per ``metrics`` entry (``"beam.tip_v:max"``; ``max``, ``min``, ``end`` or ``rms``
    of the column), whatever ``measure(result)`` returns (a dict, computed in the child), and with
    ``keep_results`` the Result itself. Processes are forked: ``measure`` may be any callable.
    A Model is re-loaded in each child with the set applied (``Model.reload``)."""
    ctx = multiprocessing.get_context("fork")
    processes = max(1, processes or os.cpu_count() or 1)
    rows: List[Optional[Dict[str, Any]]] = [None] * len(overrides)
    pending = list(range(len(overrides)))
    running: Dict[Any, tuple] = {}  # connection -> (index, process, start time)

    def finish(conn, row) -> None:
        i, proc, _ = running.pop(conn)
        proc.join()
        if row is None:
            code = proc.exitcode if proc.exitcode is not None else -9
            row = {"status": "crashed", "exit_code": code,
                   "message": f"the run's process died ({'signal ' + str(-code) if code < 0 else 'exit ' + str(code)})"}
        rows[i] = {**_keys(overrides[i]), **row}
        conn.close()

    while pending or running:
        while pending and len(running) < processes:
            i = pending.pop(0)
            recv, send = ctx.Pipe(duplex=False)
            proc = ctx.Process(target=_one_run, args=(scene, overrides[i], plugins, t_end, metrics, measure,
                                                      keep_results, send), daemon=True)
            proc.start()
            send.close()
            running[recv] = (i, proc, time.monotonic())
        deadline = None
        if timeout is not None:
            deadline = min(start for _, _, start in running.values()) + timeout - time.monotonic()
        ready = wait(list(running), timeout=None if deadline is None else max(0.0, deadline))
        for conn in ready:
            try:
                row = conn.recv()
            except (EOFError, OSError):
                row = None  # the process ended without an answer: it crashed
            finish(conn, row)
        if timeout is not None:
            now = time.monotonic()
            for conn, (i, proc, start) in list(running.items()):
                if now - start >= timeout and not conn.poll():
                    proc.kill()
                    proc.join()
                    finish(conn, {"status": "timeout", "exit_code": -9,
                                  "message": f"killed after {timeout:g} s of wall time"})
    return rows  # type: ignore[return-value]
