"""Statics, modes and Campbell diagrams (engine/static.c, engine/modes.c through flexmbd.h;
docs/analysis.md): the library solves, this module hands arrays back."""
from __future__ import annotations

import ctypes
import math
import os
import tempfile
from typing import Dict, Optional, Sequence, Union

import numpy as np

from . import _lib
from .model import Model, Overrides, Result, Source, load

ModelLike = Union[Model, Source]


def _model(scene: ModelLike, set: Overrides, plugins: Sequence[str] = ()) -> Model:
    _lib.route_warnings()  # this thread's library messages become FlexmbdWarning
    if isinstance(scene, Model):
        return scene.reload(set) if set else scene
    return load(scene, set=set, plugins=plugins)


class StaticResult:
    """The static equilibrium, or the steady rotation under a constant-speed drive (fmb_static).

    ``y``, ``yp``: the DAE state ([q, v, λ, μ] and its rate, NumPy arrays); ``t``; ``speed``
    (rad/s, 0 for an equilibrium) about ``center``; ``residual`` and ``residual_start`` (2-norms of
    the equations at the solution and at the start), ``iterations``, ``load_steps``; ``outputs``:
    the scene's outputs there (the row ``flexmbd static -o`` writes), name → value."""

    def __init__(self, model: Model, y: np.ndarray, yp: np.ndarray, res: _lib.StaticResult, outputs: Dict[str, float]):
        self.model = model
        self.y, self.yp = y, yp
        self.t = res.t
        self.speed = res.speed
        self.center = (res.center[0], res.center[1])
        self.residual, self.residual_start = res.residual, res.residual_start
        self.iterations, self.load_steps = res.iterations, res.load_steps
        self.outputs = outputs

    def __getitem__(self, name: str) -> float:
        return self.outputs[name]

    def __repr__(self) -> str:
        kind = "steady rotation" if self.speed else "static equilibrium"
        return f"<flexmbd.StaticResult {kind} t={self.t:g} speed={self.speed:g} residual={self.residual:.3e}>"


def _dptr(a: np.ndarray):
    return a.ctypes.data_as(ctypes.POINTER(ctypes.c_double))


def static(scene: ModelLike, *, at: Optional[float] = None, set: Overrides = None,
           plugins: Sequence[str] = (), max_iter: int = 0, max_halvings: int = 0, tol: float = 0.0) -> StaticResult:
    """Solve the static (or steady-rotation) state of a scene, drives held at ``at`` (None: t0),
    as ``flexmbd static`` does. 0 for max_iter, max_halvings, tol means the library's default.
    Raises SceneError (no steady state exists) or SolverError (Newton did not converge)."""
    m = _model(scene, set, plugins)
    lib = _lib.library()
    n = m.state_size
    y, yp = np.zeros(n), np.zeros(n)
    opt = _lib.StaticOptions(t=at or 0.0, has_t=int(at is not None), max_iter=max_iter, max_halvings=max_halvings,
                             tol=tol, quiet=1)
    res = _lib.StaticResult()
    diag = _lib.Diag()
    with m._use() as h:  # kept allocated during the call, whoever closes m meanwhile
        rc = lib.fmb_static(h, ctypes.byref(opt), _dptr(y), _dptr(yp), ctypes.byref(res), ctypes.byref(diag))
    if rc:
        raise m._error(diag, rc)
    return StaticResult(m, y, yp, res, _state_outputs(m, res.t, y, yp))


def _state_outputs(m: Model, t: float, y: np.ndarray, yp: np.ndarray) -> Dict[str, float]:
    """The scene's outputs at a state, through the library's one row writer (fmb_write_state_row)."""
    lib = _lib.library()
    fd, path = tempfile.mkstemp(prefix="flexmbd-state-", suffix=".csv")
    os.close(fd)
    try:
        diag = _lib.Diag()
        with m._use() as h:
            rc = lib.fmb_write_state_row(h, path.encode(), t, _dptr(y), _dptr(yp), ctypes.byref(diag))
        if rc:
            raise m._error(diag, rc)
        r = Result.from_csv(path)
    finally:
        os.unlink(path)
    return {c: float(r[c][0]) for c in r.columns}


class ModesResult:
    """Modes of small motion about a static or steady state (fmb_modes).

    ``frequency`` (rad/s, |s| of the eigenvalue; negative for a divergent mode), ``frequency_hz``,
    ``damping_ratio`` (−Re s/|s|), ``shapes`` (count × nq complex: the generalized coordinates'
    motion, largest component 1), ``speed``, ``nreduced`` (degrees of freedom after the
    constraints), ``sparse`` (computed by the shift-invert Arnoldi path), ``state`` (the
    StaticResult they are about)."""

    def __init__(self, md: _lib.Modes, state: StaticResult):
        k, nq = md.count, md.nq
        self.frequency = np.ctypeslib.as_array(md.frequency, (k,)).copy() if k else np.zeros(0)
        self.damping_ratio = np.ctypeslib.as_array(md.damping_ratio, (k,)).copy() if k else np.zeros(0)
        if k and nq:
            re = np.ctypeslib.as_array(md.shape_re, (k * nq,)).reshape(k, nq)
            im = np.ctypeslib.as_array(md.shape_im, (k * nq,)).reshape(k, nq)
            self.shapes = re + 1j * im
        else:
            self.shapes = np.zeros((k, nq), dtype=complex)
        self.frequency_hz = self.frequency / (2.0 * math.pi)
        self.speed, self.nreduced, self.sparse = md.speed, md.nreduced, bool(md.sparse)
        self.state = state

    def __len__(self) -> int:
        return len(self.frequency)

    def __repr__(self) -> str:
        return f"<flexmbd.ModesResult {len(self)} modes, frequency (rad/s) = {np.array2string(self.frequency, precision=6)}>"


_EIGEN_HELP = "method is 'auto', 'dense' or 'sparse'"


def _method(method: str) -> int:
    if method not in _lib.EIGEN_METHODS:
        raise ValueError(f"flexmbd: {_EIGEN_HELP}, got {method!r}")
    return _lib.EIGEN_METHODS[method]


def _modes_at(m: Model, state: StaticResult, count: int, method: int) -> ctypes.POINTER(_lib.Modes):
    lib = _lib.library()
    out = ctypes.POINTER(_lib.Modes)()
    diag = _lib.Diag()
    with m._use() as h:
        rc = lib.fmb_modes(h, state.t, _dptr(state.y), _dptr(state.yp), count, method, ctypes.byref(out),
                           ctypes.byref(diag))
    if rc:
        raise m._error(diag, rc)
    return out


def modes(scene: ModelLike, *, count: int = 10, at: Optional[float] = None, method: str = "auto",
          set: Overrides = None, plugins: Sequence[str] = ()) -> ModesResult:
    """Frequencies, damping ratios and shapes about the static or steady state at ``at`` (None:
    t0), as ``flexmbd modes --count COUNT --at AT --eigen METHOD`` (count <= 0: all, dense)."""
    m = _model(scene, set, plugins)
    state = static(m, at=at)
    md = _modes_at(m, state, count, _method(method))
    try:
        return ModesResult(md.contents, state)
    finally:
        _lib.library().fmb_modes_free(md)


class CampbellResult:
    """A Campbell diagram (fmb_campbell): ``speeds`` (rad/s) and ``frequencies`` (len(speeds) ×
    count, rad/s, negative = divergent), each column one mode followed from speed to speed by its
    shape, as ``flexmbd campbell`` tracks them; ``mac``: each mode's modal assurance criterion with
    its own shape at the speed before (1 at the first); ``poor_matches``: (speed, mode, MAC) where
    it is below 0.5 (the speeds are too far apart to follow that mode reliably)."""

    def __init__(self, speeds: np.ndarray, frequencies: np.ndarray, mac: np.ndarray):
        self.speeds = speeds
        self.frequencies = frequencies
        self.mac = mac
        self.poor_matches = [(float(speeds[i]), k + 1, float(mac[i, k])) for i, k in zip(*np.nonzero(mac < 0.5))]

    def plot(self, ax=None, **style):
        """Frequencies against speed with the 1× speed line (matplotlib); returns the Axes."""
        from .plot import plot_campbell

        return plot_campbell(self, ax=ax, **style)


def campbell(scene: ModelLike, speed: str, speeds: Sequence[float], *, count: int = 4, at: Optional[float] = None,
             method: str = "auto", set: Overrides = None, plugins: Sequence[str] = ()) -> CampbellResult:
    """The modes at each hub speed, by the library's fmb_campbell (as ``flexmbd campbell``):
    ``speed`` is the scene key that sets it (e.g. ``joints.spin.speed``), given each value of
    ``speeds`` as an override; at each speed the steady state, then its modes, followed across
    speeds by their shapes (modal assurance criterion). Raises SceneError/SolverError with the
    speeds done so far in the error's ``.result``."""
    m = _model(scene, set, plugins)  # loaded once here: a bad scene or set fails before any speed
    lib = _lib.library()
    speeds = np.ascontiguousarray(speeds, dtype=float)
    opt = _lib.CampbellOptions(speed_key=speed.encode(), count=count, method=_method(method),
                               steady=_lib.StaticOptions(t=at or 0.0, has_t=int(at is not None), quiet=1))
    out = ctypes.POINTER(_lib.Campbell)()
    diag = _lib.Diag()
    with m._scene_source() as src:
        rc = lib.fmb_campbell(ctypes.byref(src), ctypes.byref(opt), _dptr(speeds), len(speeds), ctypes.byref(out),
                              ctypes.byref(diag))
        err = m._error(diag, rc) if rc else None  # while the scene's temporary name is known
    result = None
    if out:
        c = out.contents

        def rows(ptr) -> np.ndarray:  # the speeds done, count values each
            flat = np.ctypeslib.as_array(ptr, (c.nspeed * c.count,)) if c.nspeed * c.count else np.zeros(0)
            return flat[: c.done * c.count].reshape(c.done, c.count).copy()

        result = CampbellResult(speeds[: c.done].copy(), rows(c.frequency), rows(c.mac))
        lib.fmb_campbell_free(out)
    if err is not None:
        err.result = result
        raise err
    return result
