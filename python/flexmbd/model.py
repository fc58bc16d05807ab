"""Loading a scene (`load` → `Model`) and running it (`Model.run` → `Result`)."""
from __future__ import annotations

import contextlib
import ctypes
import math
import os
import signal
import tempfile
import threading
import weakref
from typing import Any, Callable, Dict, List, Mapping, Optional, Sequence, Tuple, Union

import numpy as np

from . import _lib
from ._lib import FlexmbdError
from ._scene import looks_like_yaml, override, scene_text

Source = Union[str, "os.PathLike[str]", Mapping[str, Any]]

# One registry per list of plugins, kept for the life of the process: a model calls its types'
# ops, so the registry must outlive every model loaded with it, and loaded plugin code is never
# unloaded anyway (engine/plugin.c).
_registries: Dict[Tuple[str, ...], int] = {}
_registries_lock = threading.Lock()


def _registry(plugins: Tuple[str, ...]) -> int:
    lib = _lib.library()
    key = tuple(os.path.realpath(p) for p in plugins)  # the same files, whatever the folder or spelling
    with _registries_lock:
        reg = _registries.get(key)
        if reg:
            return reg
        reg = lib.fmb_registry_new()
        if not reg:
            raise MemoryError("flexmbd: out of memory creating a registry")
        diag = _lib.Diag()
        if lib.fmb_registry_add(reg, lib.fmb_builtin_plugin(), b"built-in", ctypes.byref(diag)):
            lib.fmb_registry_free(reg)
            raise _lib.error_from(diag)
        for so in plugins:
            if lib.fmb_registry_load(reg, so.encode(), ctypes.byref(diag)):
                lib.fmb_registry_free(reg)
                raise _lib.error_from(diag)
        _registries[key] = reg
        return reg


def _plugin_path(p: Union[str, "os.PathLike[str]"]) -> str:
    """A plugin file as the command line's --plugin takes it; a bare name means the current folder."""
    p = os.fspath(p)
    return p if os.sep in p else os.path.join(".", p)


Overrides = Union[Mapping[str, Any], Sequence[str], None]


def _overrides(sets: Overrides) -> List[str]:
    """{PATH: VALUE} or ["PATH=VALUE", ...] as the --set strings"""
    if sets is None:
        return []
    if isinstance(sets, Mapping):
        return [override(k, v) for k, v in sets.items()]
    if isinstance(sets, str):
        raise TypeError("flexmbd: set= takes a dict {PATH: VALUE} or a list of 'PATH=VALUE' strings, not one string")
    return [str(s) for s in sets]


def load(scene: Source, set: Overrides = None, plugins: Sequence[Union[str, "os.PathLike[str]"]] = (),
         ) -> "Model":
    """Load a scene: a file path, YAML text, or a dict shaped like a scene file.

    ``set`` holds overrides as ``flexmbd run --set PATH=VALUE`` takes them, e.g.
    ``{"bodies.beam.model": "exact", "solver.rtol": 1e-8}`` (or the strings
    ``["bodies.beam.model=exact", ...]``); ``plugins`` are shared objects with
    more body and joint types (as ``--plugin``).

    Raises SceneError (with .file, .line, .column and .message, ``str()`` the command line's
    message) when the scene, an override or a plugin is refused. Text and dicts are written to a
    temporary file in the current folder (so that file names in them, e.g. a load table, are
    taken from there, as for a scene file there); their errors name ``<string>`` or ``<dict>``
    and count lines in the text (``flexmbd.scene_text(d)`` shows a dict's)."""
    overrides = _overrides(set)
    plugin_files = tuple(_plugin_path(p) for p in plugins)
    if isinstance(scene, Mapping):
        return Model._from_text(scene_text(scene), "<dict>", overrides, plugin_files, ("dict", dict(scene)))
    if isinstance(scene, str) and looks_like_yaml(scene):
        return Model._from_text(scene, "<string>", overrides, plugin_files, ("text", scene))
    path = os.fspath(scene)
    return Model._load(path, None, overrides, plugin_files, ("path", os.path.abspath(path)))


@contextlib.contextmanager
def _scene_file(text: str):
    """The scene text in a temporary file, in the current folder if it can be written (file names
    in the scene are taken from there, as for a scene file there), else in the temporary folder;
    removed after the block."""
    fd = path = None
    for folder in (os.getcwd(), tempfile.gettempdir()):
        try:
            fd, path = tempfile.mkstemp(prefix=".flexmbd-", suffix=".yaml", dir=folder)
            break
        except OSError:
            continue
    if fd is None:
        raise OSError("flexmbd: no folder to write the scene text into")
    try:
        with os.fdopen(fd, "w", encoding="utf-8") as f:
            f.write(text)
        yield path
    finally:
        os.unlink(path)


class _Owned:
    """An object of the library this Python object owns (``_ptr``), freed by ``_free`` (the name
    of the library's function) on close(), at the end of a ``with`` block, or when collected.

    Every call into the library holds a use of the pointer (``with self._use() as ptr``), counted
    under a lock: close() from another thread while a call runs (a model closed during its run)
    does not free the object under it; the last use frees it, and new calls raise ValueError. So
    no close, from any thread, can make the library read freed memory (issue 36)."""

    _ptr: Optional[int] = None
    _free = ""
    _uses = 0
    _closing = False
    _guard: Optional[threading.Lock] = None

    def _own(self, ptr: int) -> None:
        self._guard = threading.Lock()
        self._uses = 0
        self._closing = False
        self._ptr = ptr

    def _closed_error(self) -> ValueError:
        return ValueError(f"flexmbd: the {type(self).__name__} was closed")

    @property
    def handle(self) -> int:
        """The library's pointer (fmbModel*, fmbData*), for calls this package does not wrap
        (valid until close(): hold it only while this object is open)."""
        if not self._ptr or self._closing:
            raise self._closed_error()
        return self._ptr

    @contextlib.contextmanager
    def _use(self):
        """The pointer, kept from being freed until the block ends."""
        guard = self._guard
        if guard is None:
            raise self._closed_error()
        with guard:
            if not self._ptr or self._closing:
                raise self._closed_error()
            self._uses += 1
            ptr = self._ptr
        try:
            yield ptr
        finally:
            with guard:
                self._uses -= 1
                last = self._closing and self._uses == 0
            if last:
                self._release()

    def _release(self) -> None:
        ptr, self._ptr = self._ptr, None
        if ptr:
            getattr(_lib.library(), self._free)(ptr)
            self._released()

    def _released(self) -> None:
        """after the library's object is freed (a Simulation lets go of its model)"""

    def close(self) -> None:
        """Free the library's object now, or, while a call into the library is using it (another
        thread's run), as soon as that call returns. Also done when this one is collected."""
        guard = self._guard
        if guard is None:
            return
        with guard:
            if self._closing:
                return
            self._closing = True
            busy = self._uses > 0
        if not busy:
            self._release()

    def __del__(self) -> None:
        try:
            self.close()
        except Exception:
            pass

    def __enter__(self):
        return self

    def __exit__(self, *exc) -> None:
        self.close()


class Model(_Owned):
    """A loaded scene (the library's fmbModel): fixed after loading, runnable many times.

    Attributes: ``path`` (the scene file, None for text or a dict), ``overrides`` (the
    ``PATH=VALUE`` strings applied), ``plugins``, ``solver`` (t0, t_end, rtol, atol, output_step
    after the overrides), ``bodies`` (name → type), ``output_names`` (the CSV's columns after t),
    ``inputs`` (what Simulation.set_load can set) and ``state_size``."""

    _free = "fmb_free"

    def __init__(self) -> None:  # use flexmbd.load
        self._ptr = None
        self._rename: Dict[str, str] = {}

    @classmethod
    def _from_text(cls, text: str, shown: str, overrides: List[str], plugins: Tuple[str, ...], source) -> "Model":
        with _scene_file(text) as path:
            return cls._load(path, shown, overrides, plugins, source)

    @classmethod
    def _load(cls, path: str, shown: Optional[str], overrides: List[str], plugins: Tuple[str, ...], source) -> "Model":
        lib = _lib.library()
        reg = _registry(plugins)
        arr = (ctypes.c_char_p * max(1, len(overrides)))(*[o.encode() for o in overrides])
        diag = _lib.Diag()
        rename = {path: shown} if shown else {}
        _lib.route_warnings()
        ptr = lib.fmb_load(path.encode(), arr, len(overrides), reg, ctypes.byref(diag))
        if not ptr:
            raise _lib.error_from(diag, rename)
        m = cls()
        m._own(ptr)
        m._rename = rename
        m._reg = reg
        m.path = None if shown else path
        m._shown_path = shown or path
        m.overrides = list(overrides)
        m.plugins = list(plugins)
        m._source = source
        info = _lib.SolverInfo()
        lib.fmb_model_solver(ptr, ctypes.byref(info))
        m.solver = _SolverSettings({k: getattr(info, k) for k, _ in _lib.SolverInfo._fields_})
        m.solver._model = weakref.ref(m)
        m.bodies = {}
        name, typ = ctypes.c_char_p(), ctypes.c_char_p()
        for i in range(lib.fmb_model_nbody(ptr)):
            lib.fmb_model_body(ptr, i, ctypes.byref(name), ctypes.byref(typ))
            m.bodies[name.value.decode()] = typ.value.decode()
        m.state_size = lib.fmb_state_size(ptr)
        m.output_names = [lib.fmb_output_name(ptr, i).decode() for i in range(lib.fmb_noutput(ptr))]
        m.inputs = [lib.fmb_input_name(ptr, i).decode() for i in range(lib.fmb_ninput(ptr))]
        return m

    def __repr__(self) -> str:
        where = self.path or self._rename.get(next(iter(self._rename), ""), "?")
        return f"<flexmbd.Model {where} bodies={list(self.bodies)} t_end={self.solver['t_end']:g}>"

    # -- copies: a Model owns its fmbModel; a copy is the scene loaded again (an owner of its own) --
    def __copy__(self) -> "Model":
        """A new Model of the same scene, overrides and plugins, loaded again: it owns its own
        library model (two Python objects never free one)."""
        return self.reload()

    def __deepcopy__(self, memo) -> "Model":
        return self.reload()

    def __reduce__(self):
        """Pickled as what it was loaded from (the scene's path, text or dict, the overrides and
        plugins): unpickling loads it again (in another process too, as flexmbd.study does)."""
        self.handle  # a closed model cannot be copied: ValueError
        return (_model_from_source, (self._source, self._shown_path, list(self.overrides), list(self.plugins)))

    def reload(self, set: Overrides = None) -> "Model":
        """The same scene loaded again with more overrides (later ones win)."""
        self.handle  # ValueError when closed
        kind, what = self._source
        extra = _overrides(set)
        if kind == "path":
            return Model._load(what, None, self.overrides + extra, tuple(self.plugins), self._source)
        return Model._from_text(self._text(), self._shown_path, self.overrides + extra, tuple(self.plugins),
                                self._source)

    def _text(self) -> str:
        kind, what = self._source
        return scene_text(what) if kind == "dict" else what

    @contextlib.contextmanager
    def _scene_source(self, extra: Sequence[str] = ()):
        """An fmbSceneSource for the analyses that load the scene again themselves (fmb_campbell):
        the file (a temporary one for text or a dict, its name shown as the model's in errors),
        the overrides plus `extra`, the registry."""
        overrides = self.overrides + list(extra)
        arr = (ctypes.c_char_p * max(1, len(overrides)))(*[o.encode() for o in overrides])
        with contextlib.ExitStack() as stack:
            if self._source[0] == "path":
                path = self._source[1]
            else:
                path = stack.enter_context(_scene_file(self._text()))
                self._rename[path] = self._shown_path
            try:
                yield _lib.SceneSource(path=path.encode(), overrides=arr, noverrides=len(overrides), reg=self._reg)
            finally:
                if self._source[0] != "path":
                    self._rename.pop(path, None)

    def _error(self, diag: _lib.Diag, default_code: int = _lib.EXIT_SOLVER) -> FlexmbdError:
        return _lib.error_from(diag, self._rename, default_code)

    # -- running -------------------------------------------------------------------------------
    def run(self, t_end: Optional[float] = None, *, check: bool = True, cancel: Optional["Cancel"] = None,
            warn: Optional[Callable[[str], None]] = None) -> "Result":
        """Integrate from t0 to t_end (None: the scene's ``solver.t_end``) and return the outputs.

        The rows are the ones ``flexmbd run`` writes (``Result.to_csv`` gives the same bytes).
        When the solver stops, SolverError is raised with the rows so far in its ``.result``
        (``check=False``: the Result is returned, ``.status`` says ``failed``, ``.error`` why).
        ``cancel.set()`` from another thread stops the run after its current step (Interrupted).
        The library's messages go to ``warn(text)``, by default Python's warnings
        (flexmbd.FlexmbdWarning). The library runs without the GIL: other Python threads run
        meanwhile."""
        if t_end is not None and t_end != self.solver["t_end"]:
            with self.reload({"solver.t_end": float(t_end)}) as m:
                return m.run(check=check, cancel=cancel, warn=warn)
        return _run_whole(self, check, cancel, warn)

    def start(self, *, warn: Optional[Callable[[str], None]] = None, cancel: Optional["Cancel"] = None
              ) -> "Simulation":
        """A run to step by hand, initialised at t0 (see Simulation)."""
        return Simulation(self, warn=warn, cancel=cancel)


def _model_from_source(source, shown: str, overrides: List[str], plugins: List[str]) -> Model:
    """A pickled Model loaded again (Model.__reduce__)."""
    kind, what = source
    if kind == "path":
        return Model._load(what, None, overrides, tuple(plugins), source)
    text = scene_text(what) if kind == "dict" else what
    return Model._from_text(text, shown, overrides, tuple(plugins), source)


class Cancel:
    """A flag that stops runs from another thread: ``c = flexmbd.Cancel()``, pass it to
    ``Model.run(cancel=c)`` or ``Model.start(cancel=c)``, then ``c.set()``. The advance in progress
    returns at its next step (fmb_data_cancel) and the run raises Interrupted with its rows."""

    def __init__(self) -> None:
        self._set = False
        self._sims: "weakref.WeakSet[Simulation]" = weakref.WeakSet()
        self._others: "weakref.WeakSet[Cancel]" = weakref.WeakSet()
        self._lock = threading.Lock()

    def set(self) -> None:
        with self._lock:
            self._set = True
            sims = list(self._sims)
            others = list(self._others)
        for sim in sims:
            sim.cancel()
        for other in others:
            other.set()

    def is_set(self) -> bool:
        return self._set

    def _also(self, other: "Cancel") -> None:
        """set() sets `other` too (a run's own flag, which Ctrl-C also sets)."""
        with self._lock:
            self._others.add(other)
            already = self._set
        if already:
            other.set()

    def _watch(self, sim: "Simulation") -> None:
        with self._lock:
            self._sims.add(sim)
            already = self._set
        if already:
            sim.cancel()


class _SolverSettings(dict):
    """Model.solver: the solver settings as a dict, which knows its model (output_times)."""
    _model: Optional[Callable[[], Optional["Model"]]] = None


def _row_times(model: "Model") -> np.ndarray:
    """The times of the rows `flexmbd run` writes, from the library's grid (fmb_row_time)."""
    lib = _lib.library()
    with model._use() as ptr:
        return np.array([lib.fmb_row_time(ptr, k) for k in range(lib.fmb_row_count(ptr))])


def output_times(solver: Union["Model", Mapping[str, float]]) -> np.ndarray:
    """The times of the rows `flexmbd run` writes for a model (or its ``Model.solver``): t0 +
    k output_step, the last one t_end, as the library computes them (fmb_row_time)."""
    model = solver if isinstance(solver, Model) else (solver._model() if isinstance(solver, _SolverSettings)
                                                      and solver._model is not None else None)
    if model is None:
        raise TypeError("flexmbd.output_times: pass the Model (or its .solver); the grid is the library's "
                        "(fmb_row_time), computed for a loaded scene")
    return _row_times(model)


class Simulation(_Owned):
    """One run of a model, stepped by the caller (the library's fmbData): ``model.start()``.

        sim = model.start()
        while sim.t < 5:
            sim.set_load("motor", -k * sim["hub.theta"])   # a joint with profile/law: input
            sim.advance(sim.t + 0.01)

    ``advance(t_out)`` integrates to t_out (time ≤ t_out ≤ the scene's t_end); a changed input
    takes effect from the current time as a step and the integrator restarts there (no history
    across the jump). ``outputs()`` gives the scene's outputs now (the values a CSV row at this time
    holds), ``sim[name]`` one of them, ``state()`` the DAE state (y, y'), ``stats`` the counters so
    far. Errors: SolverError (the state stays at the last good one: a later advance goes on from
    it), Interrupted (``cancel()``, from any thread), and for a bad argument a ValueError
    (flexmbd.ArgumentError) naming the call and the parameter: t_out before t, NaN or beyond t_end;
    an unknown input, or a value a scene would refuse. Each call into the library releases the
    GIL. A Simulation holds its model open: ``model.close()`` meanwhile frees it only after the
    Simulation is closed. It cannot be copied or pickled (start another with ``model.start()``)."""

    _free = "fmb_data_free"

    def __init__(self, model: Model, warn: Optional[Callable[[str], None]] = None,
                 cancel: Optional[Cancel] = None, _init: bool = True) -> None:
        lib = _lib.library()
        self.model = model
        # the model stays allocated while this run exists, whoever closes it meanwhile
        self._model_use = model._use()
        self._mptr = self._model_use.__enter__()
        diag = _lib.Diag()
        _lib.route_warnings()
        ptr = lib.fmb_data_new(self._mptr, ctypes.byref(diag))
        if not ptr:
            self._released()
            raise model._error(diag)
        self._own(ptr)
        # this run's messages go to `warn` or Python's warnings whichever thread advances it
        self._warn_handler = warn
        self._warn = _lib.WarnFn(lambda user, msg: _lib.deliver(msg, warn)) if warn is not None else _lib.WARN_TO_PYTHON
        lib.fmb_data_set_warn(self._ptr, ctypes.cast(self._warn, ctypes.c_void_p), None)
        self.output_names: List[str] = model.output_names
        self._t_end = model.solver["t_end"]
        self._row = np.zeros(len(self.output_names))
        self._row_ptr = self._row.ctypes.data_as(ctypes.POINTER(ctypes.c_double))
        if cancel is not None:
            cancel._watch(self)
        if _init:  # not for _run_whole: fmb_run_rows initialises
            self.restart()

    def _released(self) -> None:
        use, self._model_use = getattr(self, "_model_use", None), None
        if use is not None:
            use.__exit__(None, None, None)

    def __reduce__(self):
        raise TypeError("flexmbd: a Simulation (a run in progress, the library's fmbData) cannot be pickled or "
                        "copied; start another with model.start() (and restart() or advance() it to where you want)")

    def __copy__(self):
        self.__reduce__()

    def __deepcopy__(self, memo):
        self.__reduce__()

    def restart(self) -> None:
        """Back to the consistent state at t0 (fmb_init), inputs at their scene values."""
        diag = _lib.Diag()
        with self._use() as d:
            rc = _lib.library().fmb_init(self._mptr, d, ctypes.byref(diag))
        if rc:
            raise self.model._error(diag, rc)

    @property
    def t(self) -> float:
        """The time the state is at."""
        with self._use() as d:
            return _lib.library().fmb_data_time(d)

    def advance(self, t_out: float) -> None:
        """Integrate to t_out, t ≤ t_out ≤ the scene's t_end (raises SolverError, Interrupted, or
        ValueError for a t_out outside that range)."""
        try:
            t_out = float(t_out)
        except (TypeError, ValueError):
            raise _lib.ArgumentError(f"Simulation.advance(t_out={t_out!r}): t_out must be a number (seconds)") from None
        t = self.t
        if math.isnan(t_out) or t_out < t:
            raise _lib.ArgumentError(
                f"Simulation.advance(t_out={t_out!r}): t_out is before the simulation's time t = {t!r}; a run goes "
                "forward (sim.restart() starts it again at t0)")
        if t_out > self._t_end:
            raise _lib.ArgumentError(
                f"Simulation.advance(t_out={t_out!r}): t_out is beyond the scene's t_end = {self._t_end!r} (load it "
                "with set={'solver.t_end': ...} for a longer run)")
        diag = _lib.Diag()
        with self._use() as d:
            rc = _lib.library().fmb_advance(self._mptr, d, t_out, ctypes.byref(diag))
        if rc == _lib.EXIT_BAD_INPUT:  # a misuse the checks above did not foresee: still the caller's
            raise _lib.ArgumentError(f"Simulation.advance(t_out={t_out!r}): " +
                                     diag.msg.decode("utf-8", "replace").replace("fmb_advance: ", ""))
        if rc:
            raise self.model._error(diag, rc)

    def _outputs_into(self, out) -> int:
        with self._use() as d:
            return _lib.library().fmb_outputs(self._mptr, d, out)

    def outputs(self) -> Dict[str, float]:
        """The scene's outputs at time t, name → value (a non-finite value raises SolverError)."""
        rc = self._outputs_into(self._row_ptr)
        if rc == _lib.EXIT_SOLVER:
            raise _lib.SolverError(rc, self.model.path or "", 0, 0, f"an output is not finite at t = {self.t:.6g}")
        if rc:
            raise _lib.FlexmbdError(rc, "", 0, 0, "fmb_outputs refused the call")
        return dict(zip(self.output_names, self._row.tolist()))

    def __getitem__(self, name: str) -> float:
        if name == "t":
            return self.t
        values = self.outputs()
        try:
            return values[name]
        except KeyError:
            raise KeyError(f"no output '{name}' (outputs: {', '.join(self.output_names)}; add it to the scene's "
                           "outputs: list)") from None

    def state(self) -> Tuple[np.ndarray, np.ndarray]:
        """(y, y') of the DAE: [q, v, λ, μ, z] and its rate (copies)."""
        n = self.model.state_size
        y, yp = np.zeros(n), np.zeros(n)
        with self._use() as d:
            _lib.library().fmb_data_state(d, y.ctypes.data_as(ctypes.POINTER(ctypes.c_double)),
                                          yp.ctypes.data_as(ctypes.POINTER(ctypes.c_double)))
        return y, yp

    def set_state(self, y, yp=None, t: Optional[float] = None) -> None:
        """Set the state (fmb_data_set_state): y (and y', None = zeros) as state() gives them, at time
        t (None: the current time; t0 ≤ t ≤ t_end). The next advance first makes it consistent (the
        constraints, then the accelerations and multipliers) and starts without step history. A
        spatial body's coordinates are [r, p], Euler parameters p of any nonzero length
        (docs/spatial.md). Raises ValueError for a wrong length, a value that is not finite or t
        outside the run; nothing is changed then."""
        n = self.model.state_size
        arrays = []
        for name, a in (("y", y), ("yp", yp)):
            if a is None:
                arrays.append(None)
                continue
            a = np.ascontiguousarray(a, dtype=np.float64)
            if a.shape != (n,):
                raise _lib.ArgumentError(f"Simulation.set_state: {name} has shape {a.shape}, the state has {n} values "
                                         "(model.state_size)")
            arrays.append(a)
        t = self.t if t is None else float(t)
        ptr = [None if a is None else a.ctypes.data_as(ctypes.POINTER(ctypes.c_double)) for a in arrays]
        diag = _lib.Diag()
        with self._use() as d:
            rc = _lib.library().fmb_data_set_state(self._mptr, d, t, ptr[0], ptr[1], ctypes.byref(diag))
        if rc:
            raise _lib.ArgumentError("Simulation." + diag.msg.decode("utf-8", "replace").replace("fmb_data_", ""))

    @property
    def inputs(self) -> List[str]:
        """The names of the inputs set_load can change (joints with profile/law: input)."""
        return self.model.inputs

    def _no_input(self, call: str, name: str) -> _lib.ArgumentError:
        have = ", ".join(repr(n) for n in self.inputs) if self.inputs else "none"
        return _lib.ArgumentError(
            f"{call}: no input named {name!r}; this scene's inputs: {have} (an input is a joint with "
            "`profile: input` (a drive, a prismatic joint) or `law: input` (a force), named by the joint)")

    def set_load(self, name: str, value: float, rate: Optional[float] = None, accel: float = 0.0) -> None:
        """Set input `name` (a load with `law: input`, a drive with `profile: input`) from now on.

        Without `rate` (fmb_set_input) the value holds, piecewise constant: a drive set so is at rest
        between settings, and the library warns once when such a drive jumps. With `rate` (and
        optionally `accel`, fmb_set_input_motion) the input is value + rate*tau + accel*tau**2/2 from
        now on (tau = t - now), so a drive fed a smooth motion moves with it: its velocities and the
        kinetic energy follow the rate (docs/api.md, "Inputs"). A bad name or value (not finite, or
        one a scene's `value:` would be refused for) raises ValueError naming it."""
        call = f"Simulation.set_load({name!r}, {value!r}" + ("" if rate is None else f", rate={rate!r}") + ")"
        if not isinstance(name, str):
            raise _lib.ArgumentError(f"{call}: the input's name must be a str")
        if name not in self.inputs:
            raise self._no_input(call, name)
        try:
            value = float(value)
            motion = rate is not None or accel != 0.0
            rate = 0.0 if rate is None else float(rate)
            accel = float(accel)
        except (TypeError, ValueError):
            raise _lib.ArgumentError(f"{call}: the value, rate and accel must be numbers") from None
        fn = "fmb_set_input_motion" if motion else "fmb_set_input"
        with _lib.captured_messages() as said, self._use() as d:
            if motion:
                rc = _lib.library().fmb_set_input_motion(self._mptr, d, name.encode(), value, rate, accel)
            else:
                rc = _lib.library().fmb_set_input(self._mptr, d, name.encode(), value)
        if rc:
            why = "; ".join(m.replace(fn + ": ", "") for m in said) or "refused"
            raise _lib.ArgumentError(f"{call}: {why}")
        for m in said:  # a jump of a drive held by value: the library's warning, in Python's terms
            text = m.replace(fn + ": ", call + ": ").replace("fmb_set_input_motion (docs/api.md)",
                                                            "set_load(name, value, rate=...) (docs/python.md)")
            _lib.deliver(text.encode(), self._warn_handler)

    def get_load(self, name: str) -> float:
        """The current value of input `name`."""
        v = ctypes.c_double()
        with self._use() as d:
            rc = _lib.library().fmb_get_input(self._mptr, d, name.encode(), ctypes.byref(v))
        if rc:
            raise KeyError(str(self._no_input(f"Simulation.get_load({name!r})", name)))
        return v.value

    @property
    def stats(self) -> dict:
        """The counters so far, as the stats line's fields (status says ok: the run goes on)."""
        buf = ctypes.create_string_buffer(_lib.STATS_BYTES)
        with self._use() as d:
            _lib.library().fmb_data_stats(d, buf)
        return _lib.stats_dict(buf)

    def cancel(self) -> None:
        """Stop the advance in progress (or the next one) with Interrupted; safe from any thread."""
        try:
            with self._use() as d:
                _lib.library().fmb_data_cancel(d)
        except ValueError:  # closed: nothing runs
            pass

    def __repr__(self) -> str:
        return f"<flexmbd.Simulation t={self.t:g} of {self.model!r}>" if self._ptr and not self._closing else "<flexmbd.Simulation closed>"


def _ctrl_c_waits(work: Callable[[], None], on_ctrl_c: Callable[[], None]) -> bool:
    """work() so that Ctrl-C stops it at once: in the main thread with Python's own SIGINT handler,
    work runs in a helper thread and this one waits; SIGINT raises KeyboardInterrupt here (a wait is
    interrupted by signals, a call into the library is not), which calls on_ctrl_c (it cancels the
    advance in progress: fmb_data_cancel, after the step being taken) and waits on for work to
    return. Elsewhere (another thread, a handler of the program's own) work runs here. True when
    Ctrl-C was pressed."""
    if (threading.current_thread() is not threading.main_thread()
            or signal.getsignal(signal.SIGINT) is not signal.default_int_handler):
        work()
        return False
    failed: List[BaseException] = []
    done = threading.Event()

    def body() -> None:
        try:
            work()
        except BaseException as e:  # handed to the waiting thread
            failed.append(e)
        finally:
            done.set()

    helper = threading.Thread(target=body, name="flexmbd-run", daemon=True)
    helper.start()
    pressed = False
    # an Event, not Thread.join: a join that KeyboardInterrupt breaks into may report the thread
    # ended while it runs on (CPython 3.11); Event.wait cleans up after an interruption
    while not done.is_set():
        try:
            done.wait(0.05)
        except KeyboardInterrupt:
            pressed = True
            on_ctrl_c()
    helper.join()
    if failed:
        raise failed[0]
    return pressed


def _run_whole(model: Model, check: bool, cancel: Optional[Cancel], warn) -> "Result":
    """The library's run loop (fmb_run_rows, the loop fmb_run writes its CSV from): fmb_init, then
    each output row handed to a ctypes callback that copies it into one NumPy array, sized from
    the library's grid (fmb_row_count). Ctrl-C stops it after the step in progress (not the output
    row: the advance is cancelled inside the library) and keeps the rows so far, status
    "interrupted" (_ctrl_c_waits)."""
    names = ["t"] + model.output_names
    box: Dict[str, Any] = {"values": np.zeros((0, len(names))), "nrow": 0, "error": None, "sim": None}
    stop = Cancel()  # set by Ctrl-C, and by the caller's Cancel
    if cancel is not None:
        cancel._also(stop)

    def work() -> None:
        lib = _lib.library()
        sim = box["sim"] = Simulation(model, warn=warn, cancel=stop, _init=False)
        ncol = len(names)
        values = box["values"] = np.zeros((lib.fmb_row_count(sim._mptr), ncol))
        flat = (ctypes.c_double * values.size).from_address(values.ctypes.data)  # values' memory
        base, row_bytes, count = values.ctypes.data, 8 * ncol, [0]
        memmove = ctypes.memmove

        def on_row(user, t, vals, n):  # one call per row, with the GIL: kept to a few operations
            k = count[0]
            flat[k * ncol] = t
            memmove(base + k * row_bytes + 8, vals, 8 * n)
            count[0] = k + 1
            return stop._set

        row_fn = _lib.RowFn(on_row)
        diag = _lib.Diag()
        with sim._use() as d:
            rc = lib.fmb_run_rows(sim._mptr, d, row_fn, None, ctypes.byref(diag))
        box["nrow"] = count[0]
        if rc:
            box["error"] = model._error(diag, rc)

    pressed = _ctrl_c_waits(work, stop.set)
    error, sim, nrow = box["error"], box["sim"], box["nrow"]
    if isinstance(error, _lib.Interrupted) or (pressed and error is None and nrow < len(box["values"])):
        t_stop = sim.t if sim is not None and sim._ptr else model.solver["t0"]
        how = "Ctrl-C (SIGINT)" if pressed else "Cancel.set()"
        cls = _lib.KeyboardInterrupted if pressed else _lib.Interrupted
        error = cls(_lib.EXIT_INTERRUPTED, model._shown_path, 0, 0,
                    f"interrupted at t = {t_stop:.6g} ({how}): the {nrow} rows so far are kept in .result")
    stats = {}
    if sim is not None:
        stats = sim.stats
        stats["status"] = "ok" if error is None else ("interrupted" if isinstance(error, _lib.Interrupted) else "failed")
        sim.close()
    result = Result(names, box["values"][:nrow], stats)
    result._scene = (model._source[1], list(model.overrides), list(model.plugins))  # for flexmbd.view
    if error is not None:
        result.error = error
        error.result = result
        if check:
            raise error
    return result


class Result:
    """The outputs of a run: ``.t`` and ``result["beam.tip_v"]`` are NumPy arrays, ``.columns``
    the CSV's column names (``t`` first), ``.values`` the rows × columns array, ``.stats`` the
    stats line as a dict (``status``, ``t_reached``, ``steps``, ... ``cpu_s``), ``.status``
    (``ok``, ``failed``, ``interrupted``) and ``.error`` (None, or the SolverError/Interrupted)."""

    def __init__(self, columns: Sequence[str], values: np.ndarray, stats: Optional[dict] = None) -> None:
        self.columns: List[str] = list(columns)
        self.values: np.ndarray = values
        self.stats: dict = stats or {}
        self.error: Optional[FlexmbdError] = None
        self._index = {c: i for i, c in enumerate(self.columns)}

    @classmethod
    def from_csv(cls, path: Union[str, "os.PathLike[str]"]) -> "Result":
        """A CSV written by ``flexmbd run -o`` (or ``to_csv``) read back; the ``#`` lines a
        regression reference carries before its header are skipped."""
        with open(path, encoding="utf-8") as f:
            header = f.readline()
            while header.startswith("#"):
                header = f.readline()
            header = header.strip()
            values = np.loadtxt(f, delimiter=",", ndmin=2)
        columns = header.split(",") if header else []
        if values.size == 0:
            values = np.zeros((0, len(columns)))
        return cls(columns, values)

    @property
    def status(self) -> str:
        return str(self.stats.get("status", "ok" if self.error is None else "failed"))

    @property
    def t(self) -> np.ndarray:
        return self["t"]

    def __getitem__(self, name: str) -> np.ndarray:
        try:
            return self.values[:, self._index[name]]
        except KeyError:
            raise KeyError(f"no column '{name}' (columns: {', '.join(self.columns)})") from None

    def __contains__(self, name: str) -> bool:
        return name in self._index

    def __len__(self) -> int:
        return self.values.shape[0]

    def __repr__(self) -> str:
        span = f"t = {self.t[0]:g} .. {self.t[-1]:g}" if len(self) else "no rows"
        return f"<flexmbd.Result {len(self)} rows, {span}, status={self.status}, columns={self.columns}>"

    def to_csv(self, path: Union[str, "os.PathLike[str]"]) -> None:
        """Write the rows through the library's CSV writer: the bytes ``flexmbd run -o`` writes
        ("-" = standard output)."""
        lib = _lib.library()
        names = (ctypes.c_char_p * len(self.columns))(*[c.encode() for c in self.columns])
        vals = np.ascontiguousarray(self.values, dtype=np.float64)
        diag = _lib.Diag()
        rc = lib.fmb_write_table(os.fspath(path).encode(), len(self.columns), names, vals.shape[0],
                                 vals.ctypes.data_as(ctypes.POINTER(ctypes.c_double)), ctypes.byref(diag))
        if rc:
            raise _lib.error_from(diag, None, rc)

    def _as_written(self) -> np.ndarray:
        """the values as the CSV to_csv writes holds them (%.12g, fmb_write_table's digits): what a
        command given that CSV computes on (flexmbd.compare, flexmbd.view's default column)"""
        values = np.asarray(self.values, dtype=np.float64)
        return np.char.mod("%.12g", values).astype(np.float64).reshape(values.shape)  # (0, n) stays 2-D

    def to_pandas(self):
        """A pandas DataFrame indexed by t (needs pandas)."""
        try:
            import pandas as pd
        except ImportError as e:
            raise ImportError("flexmbd: Result.to_pandas needs pandas (Debian: python3-pandas)") from e
        return pd.DataFrame(self.values, columns=self.columns).set_index("t")

    def to_dict(self) -> Dict[str, np.ndarray]:
        """Column name → array."""
        return {c: self[c] for c in self.columns}

    def plot(self, *columns: str, ax=None, label: Optional[str] = None, **style):
        """Plot columns against t with matplotlib, units on the axes (see flexmbd.unit); returns
        the Axes. Several results overlay when given the same ``ax``."""
        from .plot import plot_result

        return plot_result(self, columns, ax=ax, label=label, **style)

    def _repr_html_(self) -> Optional[str]:
        """In a notebook: the run's animation, the page of `flexmbd view` (flexmbd.view)."""
        from .view_page import inline

        return inline(self)
