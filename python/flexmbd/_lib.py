"""The C library seen through ctypes: finding libflexmbd.so, the prototypes of engine/flexmbd.h that
the package calls, the few structs it reads, and the translation of an fmbDiag into an exception.

Nothing here computes anything: every number comes from a call into the library.

Where the library is found (the first that exists wins):

1. the file named by the environment variable ``FLEXMBD_LIBRARY`` (asked for explicitly: that file
   or an error, never a fallback; nothing sets it for an installed package);
2. the copy inside the package, ``flexmbd/_libs/libflexmbd.so.ABI``, that ``pip install .`` builds
   and ships (setup.py);
3. the path recorded beside the package at ``cmake --install`` (``_location.py``: the installed
   ``PREFIX/LIBDIR/libflexmbd.so.ABI`` relative to ``PREFIX/lib/python3/dist-packages/flexmbd``);
4. the build tree of a source checkout: ``build/libflexmbd.so.ABI`` beside ``python/`` (what
   ``tools/build.sh`` makes), so that ``PYTHONPATH=python python3`` works from the repository root;
5. the system loader (``libflexmbd.so.ABI`` on ``LD_LIBRARY_PATH`` or in the loader's cache).

ctypes releases the GIL around every call into a ``CDLL``: runs in two threads proceed in parallel.
"""
from __future__ import annotations

import ctypes
import os
import threading
from typing import Optional

#: the program ABI this package's struct layouts are written for: engine/flexmbd.h FMB_SOVERSION,
#: the shared library's SOVERSION (the plugin ABI is a number of its own, flexmbd_plugin.h)
ABI = 3

EXIT_OK = 0
EXIT_BAD_INPUT = 2
EXIT_SOLVER = 3
EXIT_INTERRUPTED = 4

EIGEN_METHODS = {"auto": 0, "dense": 1, "sparse": 2}  # FMB_EIGEN_*


class FlexmbdError(Exception):
    """An error the library reported (an fmbDiag).

    ``str(error)`` is exactly the line the command line prints for it:
    ``FILE:LINE:COLUMN: error: MESSAGE``, ``FILE: error: MESSAGE`` without a location, or
    ``error: MESSAGE`` without a file."""

    def __init__(self, code: int, file: str, line: int, column: int, message: str) -> None:
        self.code = code
        self.file = file
        self.line = line
        self.column = column
        self.message = message
        super().__init__(self.__str__())

    def __str__(self) -> str:  # tools/cli.c: fmb_cli_print_diag
        if self.line > 0:
            return f"{self.file}:{self.line}:{self.column}: error: {self.message}"
        if self.file:
            return f"{self.file}: error: {self.message}"
        return f"error: {self.message}"

    def __reduce__(self):  # picklable across the study's processes
        return (type(self), (self.code, self.file, self.line, self.column, self.message))


class SceneError(FlexmbdError):
    """Bad input (exit code 2 of the command line): a scene, an override or a plugin the library
    refused, with the file, line and column (1-based; 0 when not applicable) it points at."""


class SolverError(FlexmbdError):
    """The solver stopped (exit code 3). ``result`` holds every row computed before it stopped
    (None when the run stopped before its first row)."""

    result = None


class Interrupted(FlexmbdError):
    """The run was cancelled (exit code 4). ``result`` holds the rows so far."""

    result = None


class KeyboardInterrupted(Interrupted, KeyboardInterrupt):
    """A run stopped by Ctrl-C (SIGINT): an Interrupted with the rows so far in ``result``
    (``result.status == "interrupted"``), and a KeyboardInterrupt, so that a script's
    ``except KeyboardInterrupt`` (or none: the program ends) sees it as Python code does."""


class ArgumentError(SceneError, ValueError):
    """A bad argument to a call of this package (a ValueError), named in Python's terms: the
    method and parameter, what was given and what is allowed. Also a SceneError (exit code 2, as
    the command line gives bad input), for code written before it existed."""

    def __init__(self, message: str) -> None:
        super().__init__(EXIT_BAD_INPUT, "", 0, 0, message)

    def __str__(self) -> str:  # the call and parameter name it: no file to point at
        return self.message

    def __reduce__(self):
        return (type(self), (self.message,))


class Diag(ctypes.Structure):
    """fmbDiag"""
    _fields_ = [("code", ctypes.c_int), ("file", ctypes.c_char * 512), ("line", ctypes.c_int),
                ("col", ctypes.c_int), ("msg", ctypes.c_char * 1024)]


class SolverInfo(ctypes.Structure):
    """fmbSolverInfo"""
    _fields_ = [(n, ctypes.c_double) for n in ("t0", "t_end", "rtol", "atol", "output_step")]


class StaticOptions(ctypes.Structure):
    """fmbStaticOptions"""
    _fields_ = [("t", ctypes.c_double), ("has_t", ctypes.c_int), ("max_iter", ctypes.c_int),
                ("max_halvings", ctypes.c_int), ("tol", ctypes.c_double), ("quiet", ctypes.c_int)]


class StaticResult(ctypes.Structure):
    """fmbStaticResult"""
    _fields_ = [("t", ctypes.c_double), ("speed", ctypes.c_double), ("center", ctypes.c_double * 2),
                ("residual", ctypes.c_double), ("residual_start", ctypes.c_double), ("iterations", ctypes.c_int),
                ("load_steps", ctypes.c_int)]


class Modes(ctypes.Structure):
    """fmbModes"""
    _fields_ = [("count", ctypes.c_int), ("nq", ctypes.c_int), ("nreduced", ctypes.c_int), ("sparse", ctypes.c_int),
                ("speed", ctypes.c_double), ("frequency", ctypes.POINTER(ctypes.c_double)),
                ("damping_ratio", ctypes.POINTER(ctypes.c_double)), ("shape_re", ctypes.POINTER(ctypes.c_double)),
                ("shape_im", ctypes.POINTER(ctypes.c_double)), ("family", ctypes.POINTER(ctypes.c_int)),
                ("axis", ctypes.c_double * 3), ("center", ctypes.c_double * 3)]


class CampbellOptions(ctypes.Structure):
    """fmbCampbellOptions"""
    _fields_ = [("speed_key", ctypes.c_char_p), ("count", ctypes.c_int), ("method", ctypes.c_int),
                ("steady", StaticOptions)]


class Campbell(ctypes.Structure):
    """fmbCampbell (`last` and `track` are the library's own)"""
    _fields_ = [("nspeed", ctypes.c_int), ("done", ctypes.c_int), ("count", ctypes.c_int),
                ("speed", ctypes.POINTER(ctypes.c_double)), ("frequency", ctypes.POINTER(ctypes.c_double)),
                ("mac", ctypes.POINTER(ctypes.c_double)), ("last", ctypes.c_void_p), ("track", ctypes.c_void_p),
                ("family", ctypes.POINTER(ctypes.c_int))]


class SceneSource(ctypes.Structure):
    """fmbSceneSource"""
    _fields_ = [("path", ctypes.c_char_p), ("overrides", ctypes.POINTER(ctypes.c_char_p)),
                ("noverrides", ctypes.c_int), ("reg", ctypes.c_void_p)]


#: fmbStats is only ever passed to the library (fmb_data_stats fills it, fmb_print_stats prints it), never
#: read field by field: the package reads the stats *line*, so fields the library adds later
#: (e.g. integrator=) appear without a change here. The buffer is larger than the struct will be.
STATS_BYTES = 1024

_P = ctypes.c_void_p
_D = ctypes.POINTER(Diag)
_PROTOTYPES = {
    "fmb_registry_new": (_P, []),
    "fmb_output_unit_in": (ctypes.c_char_p, [_P, ctypes.c_char_p]),
    "fmb_registry_free": (None, [_P]),
    "fmb_registry_add": (ctypes.c_int, [_P, _P, ctypes.c_char_p, _D]),
    "fmb_registry_load": (ctypes.c_int, [_P, ctypes.c_char_p, _D]),
    "fmb_builtin_plugin": (_P, []),
    "fmb_load": (_P, [ctypes.c_char_p, ctypes.POINTER(ctypes.c_char_p), ctypes.c_int, _P, _D]),
    "fmb_free": (None, [_P]),
    "fmb_print_stats": (None, [_P, _P]),
    "fmb_model_solver": (ctypes.c_int, [_P, ctypes.POINTER(SolverInfo)]),
    "fmb_model_nbody": (ctypes.c_int, [_P]),
    "fmb_model_body": (ctypes.c_int, [_P, ctypes.c_int, ctypes.POINTER(ctypes.c_char_p),
                                      ctypes.POINTER(ctypes.c_char_p)]),
    "fmb_state_size": (ctypes.c_int, [_P]),
    "fmb_static": (ctypes.c_int, [_P, ctypes.POINTER(StaticOptions), ctypes.POINTER(ctypes.c_double),
                                  ctypes.POINTER(ctypes.c_double), ctypes.POINTER(StaticResult), _D]),
    "fmb_modes": (ctypes.c_int, [_P, ctypes.c_double, ctypes.POINTER(ctypes.c_double),
                                 ctypes.POINTER(ctypes.c_double), ctypes.c_int, ctypes.c_int,
                                 ctypes.POINTER(ctypes.POINTER(Modes)), _D]),
    "fmb_modes_free": (None, [ctypes.POINTER(Modes)]),
    "fmb_modes_mac": (ctypes.c_double, [ctypes.POINTER(Modes), ctypes.c_int, ctypes.POINTER(Modes), ctypes.c_int]),
    "fmb_write_state_row": (ctypes.c_int, [_P, ctypes.c_char_p, ctypes.c_double, ctypes.POINTER(ctypes.c_double),
                                           ctypes.POINTER(ctypes.c_double), _D]),
    "fmb_data_new": (_P, [_P, _D]),
    "fmb_data_free": (None, [_P]),
    "fmb_init": (ctypes.c_int, [_P, _P, _D]),
    "fmb_advance": (ctypes.c_int, [_P, _P, ctypes.c_double, _D]),
    "fmb_data_time": (ctypes.c_double, [_P]),
    "fmb_data_state": (ctypes.c_int, [_P, ctypes.POINTER(ctypes.c_double), ctypes.POINTER(ctypes.c_double)]),
    "fmb_data_set_state": (ctypes.c_int, [_P, _P, ctypes.c_double, ctypes.POINTER(ctypes.c_double),
                                          ctypes.POINTER(ctypes.c_double), _D]),
    "fmb_noutput": (ctypes.c_int, [_P]),
    "fmb_output_name": (ctypes.c_char_p, [_P, ctypes.c_int]),
    "fmb_outputs": (ctypes.c_int, [_P, _P, ctypes.POINTER(ctypes.c_double)]),
    "fmb_data_stats": (ctypes.c_int, [_P, _P]),
    "fmb_row_count": (ctypes.c_long, [_P]),
    "fmb_row_time": (ctypes.c_double, [_P, ctypes.c_long]),
    "fmb_run_rows": (ctypes.c_int, [_P, _P, _P, _P, _D]),
    "fmb_data_cancel": (None, [_P]),
    "fmb_data_set_warn": (None, [_P, _P, _P]),
    "fmb_set_warn": (None, [_P, _P]),
    "fmb_ninput": (ctypes.c_int, [_P]),
    "fmb_input_name": (ctypes.c_char_p, [_P, ctypes.c_int]),
    "fmb_set_input": (ctypes.c_int, [_P, _P, ctypes.c_char_p, ctypes.c_double]),
    "fmb_set_input_motion": (ctypes.c_int, [_P, _P, ctypes.c_char_p, ctypes.c_double, ctypes.c_double, ctypes.c_double]),
    "fmb_get_input": (ctypes.c_int, [_P, _P, ctypes.c_char_p, ctypes.POINTER(ctypes.c_double)]),
    "fmb_campbell": (ctypes.c_int, [ctypes.POINTER(SceneSource), ctypes.POINTER(CampbellOptions),
                                    ctypes.POINTER(ctypes.c_double), ctypes.c_int,
                                    ctypes.POINTER(ctypes.POINTER(Campbell)), _D]),
    "fmb_campbell_free": (None, [ctypes.POINTER(Campbell)]),
    "fmb_write_table": (ctypes.c_int, [ctypes.c_char_p, ctypes.c_int, ctypes.POINTER(ctypes.c_char_p), ctypes.c_int,
                                       ctypes.POINTER(ctypes.c_double), _D]),
}


def _candidates() -> list:
    name = f"libflexmbd.so.{ABI}"
    here = os.path.dirname(os.path.abspath(__file__))
    found = []
    env = os.environ.get("FLEXMBD_LIBRARY")
    if env:
        return [env]  # asked for explicitly: that file or an error, never a silent fallback
    bundled = os.path.join(here, "_libs", name)  # pip install . (setup.py)
    if os.path.exists(bundled):
        found.append(bundled)
    try:
        from . import _location  # written by cmake --install

        found.append(os.path.normpath(os.path.join(here, _location.LIBRARY)))
    except ImportError:
        pass
    found.append(os.path.normpath(os.path.join(here, "..", "..", "build", name)))
    found.append(name)  # the system loader
    return found


_lib: Optional[ctypes.CDLL] = None
_lib_path: Optional[str] = None
_lock = threading.Lock()


def library() -> ctypes.CDLL:
    """The loaded libflexmbd (loaded on first use, prototypes declared)."""
    global _lib, _lib_path
    if _lib is not None:
        return _lib
    with _lock:
        if _lib is not None:
            return _lib
        errors = []
        for path in _candidates():
            if os.sep in path and not os.path.exists(path):
                errors.append(f"{path}: no such file")
                continue
            try:
                # RTLD_GLOBAL: a plugin built without linking libflexmbd resolves its fmb_* calls
                # against this copy, as it does inside the flexmbd program
                lib = ctypes.CDLL(path, mode=ctypes.RTLD_GLOBAL)
            except OSError as e:
                errors.append(str(e))
                continue
            missing = [fn for fn in _PROTOTYPES if not hasattr(lib, fn)]
            if missing:  # another ABI: its structs would not be ours either
                errors.append(f"{path} has no {missing[0]} (not flexmbd ABI {ABI})")
                continue
            for fn, (res, args) in _PROTOTYPES.items():
                f = getattr(lib, fn)
                f.restype = res
                f.argtypes = args
            _lib_path = path
            _lib = lib
            return lib
        raise ImportError("flexmbd: cannot load libflexmbd (build it with tools/build.sh, install it with cmake "
                          "--install, or name it in FLEXMBD_LIBRARY): " + "; ".join(errors))


def library_path() -> str:
    """The file the library was loaded from."""
    library()
    return _lib_path or ""


def has(fn: str) -> bool:
    """Does the loaded library export `fn` (a call added after this package's minimum ABI)?"""
    return hasattr(library(), fn)


def error_from(diag: Diag, rename: Optional[dict] = None, default_code: int = EXIT_BAD_INPUT) -> FlexmbdError:
    """The exception for a filled fmbDiag (SceneError, SolverError or Interrupted). `rename` maps a
    file name the library saw (a temporary scene file) to the one the user knows."""
    code = diag.code or default_code
    file = diag.file.decode("utf-8", "replace")
    msg = diag.msg.decode("utf-8", "replace")
    for old, new in (rename or {}).items():
        file = file.replace(old, new)
        msg = msg.replace(old, new)
    cls = {EXIT_BAD_INPUT: SceneError, EXIT_SOLVER: SolverError, EXIT_INTERRUPTED: Interrupted}.get(code, FlexmbdError)
    return cls(code, file, diag.line, diag.col, msg)


_libc = ctypes.CDLL(None)
_libc.open_memstream.restype = _P
_libc.open_memstream.argtypes = [ctypes.POINTER(ctypes.c_void_p), ctypes.POINTER(ctypes.c_size_t)]
_libc.fclose.argtypes = [_P]
_libc.free.argtypes = [_P]


def print_to_string(fn, *args) -> str:
    """What a library function that prints to a FILE* (its last argument) writes, as a string
    (a memory stream: the library keeps the one formatter of its lines)."""
    buf = ctypes.c_void_p()
    size = ctypes.c_size_t()
    f = _libc.open_memstream(ctypes.byref(buf), ctypes.byref(size))
    if not f:
        raise MemoryError("open_memstream failed")
    try:
        fn(*args, f)
    finally:
        _libc.fclose(f)
    text = ctypes.string_at(buf, size.value).decode("utf-8", "replace") if buf.value else ""
    _libc.free(buf)
    return text


def parse_stats_line(line: str) -> dict:
    """`stats: status=ok t_reached=20 steps=...` as a dict; numbers as int or float."""
    out: dict = {}
    for item in line.strip().split()[1:]:
        key, _, value = item.partition("=")
        for conv in (int, float):
            try:
                out[key] = conv(value)
                break
            except ValueError:
                continue
        else:
            out[key] = value
    return out


def stats_dict(stats_buffer) -> dict:
    """The stats line fmb_print_stats prints for an fmbStats, as a dict."""
    lib = library()
    return parse_stats_line(print_to_string(lib.fmb_print_stats, stats_buffer))


class FlexmbdWarning(UserWarning):
    """A message of the library (a note, a warning) while loading or running: the text the
    command line prints on stderr."""


WarnFn = ctypes.CFUNCTYPE(None, ctypes.c_void_p, ctypes.c_char_p)
#: fmbRowFn (fmb_run_rows): user, the row's time, its values (an address: a POINTER would be made
#: anew for every row), their count; non-zero stops the run
RowFn = ctypes.CFUNCTYPE(ctypes.c_int, ctypes.c_void_p, ctypes.c_double, ctypes.c_void_p, ctypes.c_int)


_capture = threading.local()  # .messages: a list while a call's messages are wanted as its error text


def deliver(message: bytes, handler=None) -> None:
    """A library message: into the capture list of this thread when one is open, else to
    `handler(text)`, else to Python's warnings."""
    text = message.decode("utf-8", "replace")
    held = getattr(_capture, "messages", None)
    if held is not None:
        held.append(text)
    elif handler is not None:
        handler(text)
    else:
        import warnings

        warnings.warn(text, FlexmbdWarning, stacklevel=3)


class captured_messages:
    """`with captured_messages() as msgs:` — the library's messages during the block, for a call
    that reports misuse only as a message (fmb_set_input)."""

    def __enter__(self) -> list:
        self._outer = getattr(_capture, "messages", None)
        _capture.messages = []
        return _capture.messages

    def __exit__(self, *exc) -> None:
        _capture.messages = self._outer


def _to_warnings(user, message) -> None:
    deliver(message)


#: the library's messages become Python warnings (flexmbd.FlexmbdWarning): kept alive here, as
#: the library holds the pointer
WARN_TO_PYTHON = WarnFn(_to_warnings)


def route_warnings() -> None:
    """Send this thread's library messages (loading, statics, runs without their own handler) to
    Python's warnings (fmb_set_warn's handler is per thread)."""
    library().fmb_set_warn(ctypes.cast(WARN_TO_PYTHON, ctypes.c_void_p), None)
