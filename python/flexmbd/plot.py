"""Plots with units on the axes (matplotlib, optional: imported only when a plot is asked for)."""
from __future__ import annotations

import re
from typing import Optional, Sequence


# The unit of each output quantity the shipped types and the engine provide, used while the
# library has no call that says it (engine/flexmbd.h declares units for keys, fmbParam.unit, not
# for outputs). A library that exports fmb_output_unit(model, name) is asked first. Quantities
# here are names, not formulas: no number of this package comes from this table.
_QUANTITY_UNITS = {
    # every body with a frame (engine/output.c frame_names)
    "x": "m", "y": "m", "theta": "rad", "omega": "rad/s", "vx": "m/s", "vy": "m/s",
    # the beam (bodies/beam.c, bodies/beam_exact.c)
    "tip_u": "m", "tip_v": "m", "tip_u_rate": "m/s", "tip_v_rate": "m/s", "tip_x": "m", "tip_y": "m",
    "ang_momentum": "kg m^2/s", "tip_angle": "rad",
    # joints (engine/output.c power_names, reaction_names; joints/*.c)
    "power": "W", "work": "J", "reaction_x": "N", "reaction_y": "N", "reaction_torque": "N m",
    "angle": "rad", "speed": "rad/s", "length": "m", "tension": "N", "displacement": "m", "velocity": "m/s",
}
_OWNER_UNITS = {"energy": "J", "constraint": None}  # constraint.*: a norm over mixed rows, no unit
_NODE = re.compile(r"^node\d+_(u|v|x|y)$")


def unit(column: str) -> Optional[str]:
    """The SI unit of an output column (``beam.tip_v`` → ``m``; ``t`` → ``s``), None if unknown."""
    if column == "t":
        return "s"
    owner, _, qty = column.partition(".")
    if owner in _OWNER_UNITS:
        return _OWNER_UNITS[owner]
    if _NODE.match(qty):
        return "m"
    return _QUANTITY_UNITS.get(qty)


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
