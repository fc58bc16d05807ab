"""Plots with units on the axes (matplotlib, optional: imported only when a plot is asked for)."""
from __future__ import annotations

from typing import Optional, Sequence


def unit(column: str, plugins: Sequence[str] = ()) -> Optional[str]:
    """The SI unit of an output column (``beam.tip_v`` → ``m``; ``t`` → ``s``), None if unknown.

    Asked of the library (fmb_output_unit_in): the engine's own columns, and a type's own outputs
    as the registered types declare them (output_units; the built-ins and ``plugins``)."""
    from . import _lib
    from .model import _registry, _plugin_path

    reg = _registry(tuple(_plugin_path(p) for p in plugins))
    u = _lib.library().fmb_output_unit_in(reg, column.encode())
    return u.decode() if u else None


def axis_label(column: str) -> str:
    """``beam.tip_v (m)``"""
    u = unit(column)
    return f"{column} ({u})" if u else column


def _axes(ax):
    if ax is not None:
        return ax
    try:
        import matplotlib.pyplot as plt
    except ImportError as e:
        raise ImportError("flexmbd: plotting needs matplotlib (Debian: python3-matplotlib)") from e
    _, ax = plt.subplots()
    return ax


def plot_result(result, columns: Sequence[str], ax=None, label: Optional[str] = None, **style):
    """Columns of a Result against t; the y axis names its unit when all columns share one."""
    ax = _axes(ax)
    columns = list(columns) or [c for c in result.columns if c != "t"][:1]
    for c in columns:
        name = label if label and len(columns) == 1 else (f"{label}: {c}" if label else c)
        ax.plot(result.t, result[c], label=name, **style)
    ax.set_xlabel(axis_label("t"))
    units = {unit(c) for c in columns}
    if len(columns) == 1:
        ax.set_ylabel(axis_label(columns[0]))
    elif len(units) == 1 and None not in units:
        ax.set_ylabel(f"({units.pop()})")
    if len(columns) > 1 or label:
        ax.legend()
    ax.grid(True)
    return ax


def plot_campbell(c, ax=None, **style):
    """A CampbellResult: one curve per tracked mode, and the 1× speed line."""
    import numpy as np

    ax = _axes(ax)
    for k in range(c.frequencies.shape[1]):
        ax.plot(c.speeds, c.frequencies[:, k], marker="o", ms=3, label=f"mode {k + 1}", **style)
    ax.plot(c.speeds, np.asarray(c.speeds), ls="--", color="gray", label="1x speed")
    ax.set_xlabel("hub speed (rad/s)")
    ax.set_ylabel("frequency (rad/s)")
    ax.legend()
    ax.grid(True)
    return ax
