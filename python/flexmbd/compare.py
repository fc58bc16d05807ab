"""`flexmbd.compare`: the error of one run against another, by the command line's own `compare`.

The comparison (interpolation of the reference in time, the error measures, the tolerance rule of
docs/regression.md) lives in one place, tools/cmd_compare.c; the library has no call for it yet, so
this runs the `flexmbd` program beside the library and reads its machine-readable lines. The
numbers are therefore the command's, by construction."""
from __future__ import annotations

import os
import shutil
import subprocess
import tempfile
from typing import Optional, Sequence, Union

from . import _lib
from .model import Result

RunLike = Union[Result, str, "os.PathLike[str]"]


def program() -> str:
    """The `flexmbd` program that belongs to the loaded library: ``FLEXMBD_PROGRAM``, else
    PREFIX/bin/flexmbd beside an installed PREFIX/LIBDIR, else flexmbd in a build tree beside the
    library, else the one on PATH."""
    env = os.environ.get("FLEXMBD_PROGRAM")
    if env:
        return env
    libdir = os.path.dirname(os.path.realpath(_lib.library_path()) or ".")
    for cand in (os.path.join(libdir, "flexmbd"), os.path.join(libdir, "..", "bin", "flexmbd"),
                 os.path.join(libdir, "..", "..", "bin", "flexmbd")):
        if os.path.isfile(cand) and os.access(cand, os.X_OK):
            return os.path.normpath(cand)
    found = shutil.which("flexmbd")
    if not found:
        raise FileNotFoundError("flexmbd.compare needs the flexmbd program (set FLEXMBD_PROGRAM)")
    return found


def _number(text: str):
    try:
        return int(text)
    except ValueError:
        try:
            return float(text)
        except ValueError:
            return text


def compare(out: RunLike, ref: RunLike, *, columns: Optional[Sequence[str]] = None, rtol: Optional[float] = None,
            atol: Optional[float] = None, common: bool = False) -> "Comparison":
    """Compare a run with a reference run (Results or CSV files), as ``flexmbd compare OUT REF``.

    Returns {column: {"rows", "t_last", "max_abs", "t_max", "max_rel", "end_abs", "end_rel",
    "ref_scale"[, "range", "tol", "status"]}} with the numbers the command prints (its `compare:`
    lines); ``status`` is "ok" or "beyond" when rtol or atol is given. A comparison the command
    refuses (no common time, unknown column, unreadable file) raises ValueError with its message;
    a column beyond tolerance, a missing or extra column or a shorter run (the command's exit 1)
    make ``.ok`` False, and ``.messages`` holds what the command said about them."""
    with tempfile.TemporaryDirectory(prefix="flexmbd-compare-") as tmp:
        files = []
        for i, r in enumerate((out, ref)):
            if isinstance(r, Result):
                path = os.path.join(tmp, f"{'out' if i == 0 else 'ref'}.csv")
                r.to_csv(path)
                files.append(path)
            else:
                files.append(os.fspath(r))
        cmd = [program(), "compare", files[0], files[1]]
        if columns:
            cmd += ["--columns", ",".join(columns)]
        if rtol is not None:
            cmd += ["--rtol", repr(float(rtol))]
        if atol is not None:
            cmd += ["--atol", repr(float(atol))]
        if common:
            cmd.append("--common")
        p = subprocess.run(cmd, capture_output=True, text=True)
    if p.returncode not in (0, 1):
        raise ValueError(p.stderr.strip() or f"flexmbd compare exited {p.returncode}")
    table = Comparison()
    table.exit_code = p.returncode
    table.messages = p.stderr.strip()
    for line in p.stdout.splitlines():
        if not line.startswith("compare: "):
            continue
        fields = dict(item.partition("=")[::2] for item in line.split()[1:])
        name = fields.pop("column")
        table[name] = {k: _number(v) for k, v in fields.items()}
    return table


class Comparison(dict):
    """{column: error measures}; ``ok``: every column within tolerance and the column sets and
    time spans agree (the command's exit 0); ``exit_code``; ``messages``: the command's stderr."""

    exit_code = 0
    messages = ""

    @property
    def ok(self) -> bool:
        return self.exit_code == 0
