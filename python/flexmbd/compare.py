"""`flexmbd.compare`: the error of one run against another, in this process, by the rule of
`flexmbd compare` (tools/cmd_compare.c, on the CSV reader tools/csv_table.c; docs/regression.md).

The rule, as the command applies it: REF is interpolated linearly in time at every row of OUT inside
REF's time span (rows at the same time, to 1e-9 relative, are taken exactly); per column max_abs is
max |OUT - REF| (NaN when a value is not finite), t_max where it occurred first, end_abs the error at
the last compared row t_last, ref_scale = max |REF|, the _rel values the errors over ref_scale (over
1 when it is 0); with rtol and/or atol a column passes when max_abs <= atol + rtol * range, range =
max - min of REF's column, and OUT must reach REF's last time. Without ``columns`` or ``common`` a
column missing from either file is a failure. The numbers are the ones the command prints (its
``compare:`` lines, ``Comparison.lines``, the same text): tests/python/test_compare.py checks both
on the same files. A Result is compared as the CSV it writes (``to_csv``: %.12g, the digits of
``flexmbd run -o``), so comparing a run is comparing its CSV."""
from __future__ import annotations

import math
import os
import re
import stat
from typing import List, Optional, Sequence, Tuple, Union

import numpy as np

from .model import Result

RunLike = Union[Result, str, "os.PathLike[str]"]

#: tools/csv_table.h FMB_CSV_MAX_LINE: a longer line is refused
MAX_LINE = 1 << 20

# One value as strtod(3) reads it when the next character must be ',' or the end of the line:
# leading white space, then a decimal or hexadecimal number, inf[inity] or nan[(chars)].
_NUMBER = re.compile(
    r"[ \t\n\v\f\r]*[+-]?(?:(?:\d+\.?\d*|\.\d+)(?:[eE][+-]?\d+)?"
    r"|0[xX](?:[0-9a-fA-F]+\.?[0-9a-fA-F]*|\.[0-9a-fA-F]+)(?:[pP][+-]?\d+)?"
    r"|(?i:inf(?:inity)?|nan(?:\([0-9A-Za-z_]*\))?))[ \t]*")  # blanks after it too (csv_table.c)
_SIMPLE = re.compile(r"[+-]?(?:\d+\.?\d*|\.\d+)(?:[eE][+-]?\d+)?")


def _strtod(text: str) -> float:
    """a field _NUMBER accepted, as strtod reads it (the blanks after it skipped, as csv_table.c does)"""
    text = text.rstrip(" \t")
    if _SIMPLE.fullmatch(text):
        return float(text)
    s = text.lstrip(" \t\n\v\f\r")
    sign = -1.0 if s[:1] == "-" else 1.0
    body = s[1:] if s[:1] in "+-" else s
    if body[:2].lower() == "0x":
        return sign * float.fromhex(body)
    if body.lower().startswith("nan"):
        return math.copysign(math.nan, sign)
    if body.lower().startswith("inf"):
        return sign * math.inf
    return float(s)


class _Table:
    """a flexmbd CSV read back as tools/csv_table.c reads it: names (t first), rows × columns"""

    def __init__(self, label: str, names: List[str], values: np.ndarray) -> None:
        self.label = label
        self.names = names
        self.values = values
        self.index = {n: i for i, n in enumerate(names)}

    def col(self, name: str) -> int:
        """a column's index (>= 1; never t), or -1 (fmb_table_col)"""
        i = self.index.get(name, -1)
        return i if i >= 1 else -1

    @property
    def t_end(self) -> float:
        return float(self.values[-1, 0])


def _check_names(label: str, lineno: int, names: List[str]) -> None:
    if names[0] != "t":
        raise ValueError(f"{label}:{lineno}: the first column must be 't' (a flexmbd CSV), got '{names[0][:40]}'")
    seen = set()
    for n in names:
        if n in seen:
            raise ValueError(f"{label}:{lineno}: column '{n[:80]}' appears twice in the header")
        seen.add(n)


def _check_times(label: str, values: np.ndarray, linenos: Sequence[int]) -> None:
    t = values[:, 0]
    bad = ~np.isfinite(t)
    bad[1:] |= t[1:] < t[:-1]
    if bad.any():
        raise ValueError(f"{label}:{linenos[int(np.argmax(bad))]}: times must be finite and non-decreasing")


def read_csv(path: Union[str, "os.PathLike[str]"]) -> _Table:
    """A flexmbd CSV file as `flexmbd compare` reads it (tools/csv_table.c fmb_table_load), or
    ValueError with its message ("PATH:LINE: what was expected")."""
    label = os.fspath(path)
    try:
        st = os.stat(label)
    except OSError as e:
        raise ValueError(f"{label}: cannot open: {os.strerror(e.errno or 0)}") from None
    if not stat.S_ISREG(st.st_mode):
        raise ValueError(f"{label}: not a regular file (a CSV file was expected)")
    try:
        with open(label, "rb") as f:
            data = f.read()
    except OSError as e:
        raise ValueError(f"{label}: cannot open: {os.strerror(e.errno or 0)}") from None
    lines = data.split(b"\n")
    if data.endswith(b"\n") or not data:
        lines.pop()  # what follows the last newline is no line
    # a byte-order mark (a spreadsheet's "CSV UTF-8") is no part of the first name or comment: the
    # first line loses it once read, so it still counts towards that line's length (csv_table.c)
    mark = 3 if lines and lines[0].startswith(b"\xef\xbb\xbf") else 0
    if mark:
        lines[0] = lines[0][mark:]

    def too_long(k: int) -> bool:
        return len(lines[k]) + (mark if k == 0 else 0) > MAX_LINE

    k = 0
    while k < len(lines) and lines[k][:1] == b"#":  # metadata lines before the header
        if too_long(k):
            raise ValueError(f"{label}:{k + 1}: line longer than {MAX_LINE} bytes (not a flexmbd CSV?)")
        k += 1
    if k == len(lines):
        raise ValueError(f"{label}: empty (no header row)")
    lineno = k + 1
    raw = lines[k]
    if too_long(k):
        raise ValueError(f"{label}:{lineno}: line longer than {MAX_LINE} bytes (not a flexmbd CSV?)")
    header = raw[:-1] if raw.endswith(b"\r") else raw
    names = []
    for tok in header.decode("utf-8", "surrogateescape").split(","):
        tok = tok.strip(" \t\n\v\f\r")
        if not tok:
            raise ValueError(f"{label}:{lineno}: column {len(names) + 1} of the header has no name")
        names.append(tok)
    _check_names(label, lineno, names)
    ncol = len(names)
    rows: List[List[float]] = []
    linenos: List[int] = []
    for raw in lines[k + 1:]:
        if len(raw) > MAX_LINE:  # the reader counts the line only once it is read
            raise ValueError(f"{label}:{lineno}: line longer than {MAX_LINE} bytes (not a flexmbd CSV?)")
        lineno += 1
        line = raw[:-1] if raw.endswith(b"\r") else raw
        if not line:
            continue
        fields = line.decode("utf-8", "surrogateescape").split(",")
        if len(fields) != ncol or not all(_NUMBER.fullmatch(x) for x in fields):
            if rows:  # the reader checks each row's time as it reads it: an earlier bad time is said first
                _check_times(label, np.array(rows, dtype=np.float64), linenos)
            raise ValueError(f"{label}:{lineno}: expected {ncol} comma-separated numbers (the header's columns)")
        try:
            rows.append([float(x) for x in fields])
        except ValueError:  # a form float() does not read (hexadecimal, nan(...), white space)
            rows.append([_strtod(x) for x in fields])
        linenos.append(lineno)
    if not rows:
        raise ValueError(f"{label}: no data rows")
    values = np.array(rows, dtype=np.float64)
    _check_times(label, values, linenos)
    return _Table(label, names, values)


def _from_result(r: Result, label: str) -> _Table:
    """a Result as the table of the CSV it writes: its values to %.12g"""
    names = list(r.columns)
    if not names or len(r) == 0:
        raise ValueError(f"{label}: no data rows")
    _check_names(label, 1, names)
    values = r._as_written()
    _check_times(label, values, list(range(2, len(values) + 2)))
    return _Table(label, names, values)


def _at_times(b: _Table, cb: int, t: np.ndarray) -> Tuple[np.ndarray, np.ndarray]:
    """b's column cb at times t (fmb_table_at_time): (inside b's span?, value), linear in time
    between b's rows, a row at t (to 1e-9 relative) exactly"""
    bt = b.values[:, 0]
    t_lo, t_hi = float(bt[0]), float(bt[-1])
    tol_t = 1e-9 * max(1.0, max(abs(t_lo), abs(t_hi)))
    inside = (t >= t_lo - tol_t) & (t <= t_hi + tol_t)
    ti = t[inside]
    j = np.searchsorted(bt, ti + tol_t, side="right") - 1  # the last row at or before t (+ tol)
    j = np.clip(j, 0, len(bt) - 1)
    t0 = bt[j]
    exact = (np.abs(t0 - ti) <= tol_t) | (j + 1 >= len(bt))
    j1 = np.minimum(j + 1, len(bt) - 1)
    col = b.values[:, cb]
    with np.errstate(invalid="ignore", divide="ignore"):
        s = (ti - t0) / (bt[j1] - t0)
        interp = (1.0 - s) * col[j] + s * col[j1]
    return inside, np.where(exact, col[j], interp)


def _column_error(a: _Table, ca: int, b: _Table, cb: int) -> dict:
    """fmb_table_column_error: rows, max_abs, t_max, end_abs, t_last"""
    t = a.values[:, 0]
    inside, bv = _at_times(b, cb, t)
    if not inside.any():
        return {"rows": 0}
    ta = t[inside]
    with np.errstate(invalid="ignore"):
        err = np.abs(a.values[inside, ca] - bv)
    if math.isnan(err[0]):  # the first row sets the maximum, a NaN is never exceeded
        k = 0
    else:
        k = int(np.argmax(np.where(np.isnan(err), -np.inf, err)))  # the first of the largest
    max_abs = float(err[k]) if np.isfinite(err).all() else math.nan
    return {"rows": int(inside.sum()), "max_abs": max_abs, "t_max": float(ta[k]), "end_abs": float(err[-1]),
            "t_last": float(ta[-1])}


def _column_scale(tb: _Table, c: int) -> Tuple[float, float]:
    """fmb_table_column_scale: range (max - min, NaN ignored) and max |value|"""
    x = tb.values[:, c]
    x = x[~np.isnan(x)]
    if len(x) == 0:
        return -math.inf, 0.0
    with np.errstate(invalid="ignore"):  # inf - inf: NaN, as in C
        return float(x.max() - x.min()), max(0.0, float(np.abs(x).max()))


def _tolerance(name: str, value: Optional[float]) -> Optional[float]:
    if value is None:
        return None
    x = float(value)
    if not math.isfinite(x) or x < 0.0:
        raise ValueError(f"flexmbd compare: --{name} needs a number >= 0, got '{value!r}'")
    return x


def _table(r: RunLike, which: str) -> _Table:
    try:
        return _from_result(r, f"<{which} Result>") if isinstance(r, Result) else read_csv(r)
    except ValueError as e:
        raise ValueError(f"flexmbd compare: {e}") from None


def _c_double(x: float, fmt: str) -> str:
    """printf's text of a double: Python's % gives C's digits and inf, but drops a NaN's sign, which
    glibc prints ("-nan", e.g. 0 * -inf on x86)"""
    if math.isnan(x):
        return "-nan" if math.copysign(1.0, x) < 0 else "nan"
    return fmt % x


def compare(out: RunLike, ref: RunLike, *, columns: Optional[Sequence[str]] = None, rtol: Optional[float] = None,
            atol: Optional[float] = None, common: bool = False) -> "Comparison":
    """Compare a run with a reference run (Results or CSV files), as ``flexmbd compare OUT REF``.

    Returns {column: {"rows", "t_last", "max_abs", "t_max", "max_rel", "end_abs", "end_rel",
    "ref_scale"[, "range", "tol", "status"]}} with the numbers the command prints (its `compare:`
    lines, in ``.lines``); ``status`` is "ok" or "beyond" when rtol or atol is given. A comparison the
    command refuses (no common time, unknown column, unreadable file: its exit 2) raises ValueError
    with its message; a column beyond tolerance, a missing or extra column or a shorter run (the
    command's exit 1) make ``.ok`` False, and ``.messages`` holds what the command says about them."""
    r_tol, a_tol = _tolerance("rtol", rtol), _tolerance("atol", atol)
    check = r_tol is not None or a_tol is not None
    r_tol, a_tol = r_tol or 0.0, a_tol or 0.0
    a, b = _table(out, "out"), _table(ref, "ref")
    messages: List[str] = []
    beyond = False
    pairs: List[Tuple[int, int]] = []
    if isinstance(columns, str):
        columns = [columns]
    if columns:
        for tok in ",".join(columns).split(","):  # as --columns a,b takes them
            if not tok:
                continue
            ca, cb = a.col(tok), b.col(tok)
            if ca < 0 or cb < 0:
                raise ValueError(f"flexmbd compare: no column '{tok}' in '{a.label if ca < 0 else b.label}'")
            if len(pairs) == len(a.names):
                break
            pairs.append((ca, cb))
    else:
        if not common:
            for name in a.names[1:]:
                if b.col(name) < 0:
                    messages.append(f"flexmbd compare: column '{name}' of {a.label} is not in {b.label} (an extra column)")
            for name in b.names[1:]:
                if a.col(name) < 0:
                    messages.append(f"flexmbd compare: column '{name}' of {b.label} is missing from {a.label}")
            beyond = bool(messages)
        pairs = [(ca, b.col(name)) for ca, name in enumerate(a.names) if ca >= 1 and b.col(name) >= 0]
    if not pairs:  # what was said before comes with it, as on the command's stderr
        raise ValueError("\n".join(messages + ["flexmbd compare: no column to compare"]))
    table = Comparison()
    for ca, cb in pairs:
        e = _column_error(a, ca, b, cb)
        if e["rows"] == 0:
            raise ValueError("\n".join(messages + [
                f"flexmbd compare: no row of '{a.label}' lies in the time span "
                f"[{_c_double(float(b.values[0, 0]), '%g')}, {_c_double(b.t_end, '%g')}] of '{b.label}'"]))
        rng, scale = _column_scale(b, cb)
        sc = scale if scale > 0.0 else 1.0
        with np.errstate(invalid="ignore"):
            printed = [("rows", str(e["rows"])), ("t_last", _c_double(e["t_last"], "%.10g")),
                       ("max_abs", _c_double(e["max_abs"], "%.6e")), ("t_max", _c_double(e["t_max"], "%.10g")),
                       ("max_rel", _c_double(e["max_abs"] / sc, "%.6e")), ("end_abs", _c_double(e["end_abs"], "%.6e")),
                       ("end_rel", _c_double(e["end_abs"] / sc, "%.6e")), ("ref_scale", _c_double(scale, "%.6e"))]
        if check:
            tol = a_tol + r_tol * rng
            ok = e["max_abs"] <= tol  # False for NaN
            printed += [("range", _c_double(rng, "%.6e")), ("tol", _c_double(tol, "%.6e")),
                        ("status", "ok" if ok else "beyond")]
            beyond = beyond or not ok
        name = a.names[ca]
        table.lines.append(f"compare: column={name} " + " ".join(f"{k}={v}" for k, v in printed))
        table[name] = {k: _number(v) for k, v in printed}
    if check:
        t_out, t_ref = a.t_end, b.t_end
        if t_out < t_ref - 1e-9 * max(1.0, abs(t_ref)):
            messages.append(f"flexmbd compare: {a.label} ends at t = {t_out:.10g}, before {b.label} "
                            f"(t = {t_ref:.10g}): a shorter run")
            beyond = True
    table.exit_code = 1 if beyond else 0
    table.messages = "\n".join(messages)
    return table


def _number(text: str):
    try:
        return int(text)
    except ValueError:
        try:
            return float(text)
        except ValueError:
            return text


class Comparison(dict):
    """{column: error measures}; ``ok``: every column within tolerance and the column sets and
    time spans agree (the command's exit 0); ``exit_code`` (0 or 1, as the command's);
    ``messages``: what the command would say on stderr about a failure; ``lines``: the command's
    ``compare:`` lines, one per column."""

    exit_code = 0
    messages = ""

    def __init__(self, *args, **kwargs) -> None:
        super().__init__(*args, **kwargs)
        self.lines: List[str] = []

    @property
    def ok(self) -> bool:
        return self.exit_code == 0
