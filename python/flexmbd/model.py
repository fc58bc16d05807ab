"""Loading a scene (`load` → `Model`) and running it (`Model.run` → `Result`)."""
from __future__ import annotations

import ctypes
import os
import tempfile
import threading
from typing import Any, Dict, List, Mapping, Optional, Sequence, Tuple, Union

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
    with _registries_lock:
        reg = _registries.get(plugins)
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
        _registries[plugins] = reg
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


class Model:
    """A loaded scene (the library's fmbModel): fixed after loading, runnable many times.

    Attributes: ``path`` (the scene file, None for text or a dict), ``overrides`` (the
    ``PATH=VALUE`` strings applied), ``plugins``, ``solver`` (t0, t_end, rtol, atol, output_step
    after the overrides), ``bodies`` (name → type) and ``state_size``."""

    def __init__(self) -> None:  # use flexmbd.load
        self._ptr: Optional[int] = None
        self._rename: Dict[str, str] = {}

    @classmethod
    def _from_text(cls, text: str, shown: str, overrides: List[str], plugins: Tuple[str, ...], source) -> "Model":
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
            return cls._load(path, shown, overrides, plugins, source)
        finally:
            os.unlink(path)

    @classmethod
    def _load(cls, path: str, shown: Optional[str], overrides: List[str], plugins: Tuple[str, ...], source) -> "Model":
        lib = _lib.library()
        reg = _registry(plugins)
        arr = (ctypes.c_char_p * max(1, len(overrides)))(*[o.encode() for o in overrides])
        diag = _lib.Diag()
        rename = {path: shown} if shown else {}
        ptr = lib.fmb_load(path.encode(), arr, len(overrides), reg, ctypes.byref(diag))
        if not ptr:
            raise _lib.error_from(diag, rename)
        m = cls()
        m._ptr = ptr
        m._rename = rename
        m.path = None if shown else path
        m.overrides = list(overrides)
        m.plugins = list(plugins)
        m._source = source
        info = _lib.SolverInfo()
        lib.fmb_model_solver(ptr, ctypes.byref(info))
        m.solver = {k: getattr(info, k) for k, _ in _lib.SolverInfo._fields_}
        m.bodies = {}
        name, typ = ctypes.c_char_p(), ctypes.c_char_p()
        for i in range(lib.fmb_model_nbody(ptr)):
            lib.fmb_model_body(ptr, i, ctypes.byref(name), ctypes.byref(typ))
            m.bodies[name.value.decode()] = typ.value.decode()
        m.state_size = lib.fmb_state_size(ptr)
        return m

    # -- lifetime ------------------------------------------------------------------------------
    def close(self) -> None:
        """Free the library's model now (also done when the object is collected)."""
        ptr, self._ptr = self._ptr, None
        if ptr:
            _lib.library().fmb_free(ptr)

    def __del__(self) -> None:
        try:
            self.close()
        except Exception:
            pass

    def __enter__(self) -> "Model":
        return self

    def __exit__(self, *exc) -> None:
        self.close()

    @property
    def handle(self) -> int:
        """The fmbModel pointer (for calls this package does not wrap)."""
        if not self._ptr:
            raise ValueError("flexmbd: the model was closed")
        return self._ptr

    def __repr__(self) -> str:
        where = self.path or self._rename.get(next(iter(self._rename), ""), "?")
        return f"<flexmbd.Model {where} bodies={list(self.bodies)} t_end={self.solver['t_end']:g}>"

    def reload(self, set: Overrides = None) -> "Model":
        """The same scene loaded again with more overrides (later ones win)."""
        kind, what = self._source
        extra = _overrides(set)
        if kind == "path":
            return Model._load(what, None, self.overrides + extra, tuple(self.plugins), self._source)
        text = scene_text(what) if kind == "dict" else what
        return Model._from_text(text, "<dict>" if kind == "dict" else "<string>", self.overrides + extra,
                                tuple(self.plugins), self._source)

    def _error(self, diag: _lib.Diag, default_code: int = _lib.EXIT_SOLVER) -> FlexmbdError:
        return _lib.error_from(diag, self._rename, default_code)

    # -- running -------------------------------------------------------------------------------
    def run(self, t_end: Optional[float] = None, *, check: bool = True, cancel: Optional["Cancel"] = None) -> "Result":
        """Integrate from t0 to t_end (None: the scene's ``solver.t_end``) and return the outputs.

        The rows are the ones ``flexmbd run`` writes (``Result.to_csv`` gives the same bytes).
        When the solver stops, SolverError is raised with the rows so far in its ``.result``
        (``check=False``: the Result is returned, ``.status`` says ``failed``, ``.error`` why).
        ``cancel.set()`` from another thread stops the run after its current step (Interrupted).
        The library runs without the GIL: other Python threads run meanwhile."""
        if t_end is not None and t_end != self.solver["t_end"]:
            with self.reload({"solver.t_end": float(t_end)}) as m:
                return m.run(check=check, cancel=cancel)
        return _run_whole(self, check, cancel)


class Cancel:
    """A flag that stops a run from another thread (``flexmbd.Cancel()``, ``.set()``)."""

    def __init__(self) -> None:
        self._flag = ctypes.c_int(0)
        self._hooks: list = []

    def set(self) -> None:
        self._flag.value = 1
        for hook in list(self._hooks):
            hook()

    def is_set(self) -> bool:
        return bool(self._flag.value)


def _run_whole(model: Model, check: bool, cancel: Optional[Cancel]) -> "Result":
    """fmb_run into a temporary CSV, read back."""
    lib = _lib.library()
    fd, path = tempfile.mkstemp(prefix="flexmbd-run-", suffix=".csv")
    os.close(fd)
    try:
        stop = cancel._flag if cancel is not None else ctypes.c_int(0)
        opt = _lib.RunOptions(csv_path=path.encode(), quiet=1, progress=0, progress_after_s=0.0, vtk_dir=None,
                              stop=ctypes.pointer(stop))
        stats = ctypes.create_string_buffer(_lib.STATS_BYTES)
        diag = _lib.Diag()
        rc = lib.fmb_run(model.handle, ctypes.byref(opt), stats, ctypes.byref(diag))
        result = Result.from_csv(path) if os.path.getsize(path) > 0 else None
        st = _lib.stats_dict(stats)
    finally:
        os.unlink(path)
    if result is None:
        result = Result([], np.zeros((0, 0)), st)
    result.stats = st
    if rc:
        err = model._error(diag, rc)
        result.error = err
        err.result = result
        if check or rc == _lib.EXIT_BAD_INPUT:
            raise err
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
