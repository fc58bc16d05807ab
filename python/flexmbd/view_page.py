"""`flexmbd.view` (this module: flexmbd.view_page): the page of `flexmbd view` (tools/view.html) for a run, built in this process,
for a notebook (``Result._repr_html_``) or a file.

The page is the command's: its template is the same file (installed as package data,
flexmbd/_data/view.html, or the checkout's tools/view.html), and the data put where its placeholder
stands is what tools/cmd_view.c writes for the same run and scene (byte for byte with the same
title; tests/python/test_view.py checks it): the library's drawing of the scene (fmb_drawing_new)
and the run's columns, BODY.x/y/theta for a body's frame and BODY.shapeK_x/_y for a beam's
centreline; in a spatial scene (dimension 3) BODY.x/y/z/qw/qx/qy/qz and BODY.shapeK_x/_y/_z, drawn by
the page's 3D view. What the run lacks for the drawing is said in the page's notes."""
from __future__ import annotations

import ctypes
import math
import html
import os
from typing import List, Optional, Sequence, Union

import numpy as np

from . import _lib, _source

PLACEHOLDER = "/*FMB_VIEW_DATA*/null"
MAX_TRACES = 8  # cmd_view.c VIEW_MAX_TRACES
DRAW_CENTRELINE, DRAW_OUTLINE, DRAW_FRAME_AXIS, DRAW_JOINT, DRAW_FORCE_ELEMENT = range(5)  # FMB_DRAW_*


class _DrawPoint(ctypes.Structure):
    """fmbDrawPoint"""
    _fields_ = [("body", ctypes.c_int), ("local", ctypes.c_double * 2), ("station", ctypes.c_int)]


class _DrawCell(ctypes.Structure):
    """fmbDrawCell"""
    _fields_ = [("first", ctypes.c_int), ("count", ctypes.c_int), ("part", ctypes.c_int), ("owner", ctypes.c_int)]


class _Drawing(ctypes.Structure):
    """fmbDrawing"""
    _fields_ = [("npoint", ctypes.c_int), ("ncell", ctypes.c_int), ("nconn", ctypes.c_int),
                ("point", ctypes.POINTER(_DrawPoint)), ("cell", ctypes.POINTER(_DrawCell)),
                ("conn", ctypes.POINTER(ctypes.c_int)),
                ("dimension", ctypes.c_int), ("local3", ctypes.POINTER(ctypes.c_double))]  # appended (issue 34)


FRAME_COLUMNS = {2: ("x", "y", "theta"), 3: ("x", "y", "z", "qw", "qx", "qy", "qz")}  # cmd_view.c frame_names


def _library() -> ctypes.CDLL:
    lib = _lib.library()
    lib.fmb_drawing_new.restype = ctypes.POINTER(_Drawing)
    lib.fmb_drawing_new.argtypes = [ctypes.c_void_p]
    lib.fmb_drawing_free.restype = None
    lib.fmb_drawing_free.argtypes = [ctypes.POINTER(_Drawing)]
    lib.fmb_model_njoint.restype = ctypes.c_int
    lib.fmb_model_njoint.argtypes = [ctypes.c_void_p]
    lib.fmb_model_joint.restype = ctypes.c_int
    lib.fmb_model_joint.argtypes = [ctypes.c_void_p, ctypes.c_int, ctypes.POINTER(ctypes.c_char_p),
                                    ctypes.POINTER(ctypes.c_char_p)]
    return lib


def _json_string(s: str) -> str:
    """cmd_view.c json_string: '<', '>', '&' and control characters as \\u00XX (never ends the <script>)"""
    out = ['"']
    for ch in s:
        if ch in '"\\':
            out.append("\\" + ch)
        elif ord(ch) < 0x20 or ch in "<>&":
            out.append(f"\\u{ord(ch):04x}")
        else:
            out.append(ch)
    out.append('"')
    return "".join(out)


def _json_number(v: float) -> str:
    """cmd_view.c json_number: %.12g (the CSV's digits), null when not finite"""
    return "%.12g" % v if np.isfinite(v) else "null"


def _numbers(values) -> str:
    return ",".join(_json_number(v) for v in np.asarray(values, dtype=np.float64).tolist())


class _Body:
    def __init__(self, name: str, dim: int = 2) -> None:
        self.name = name
        self.dim = dim  # components of a point: 2, or 3 in a spatial scene
        self.frame = [0] * len(FRAME_COLUMNS[dim])  # result columns of FRAME_COLUMNS[dim]; 0 = absent
        self.shape: List[int] = []  # dim result columns per station found
        self.drawn = False
        self.centreline = False
        self.nstation = 0
        self.station: List[List[float]] = []

    @property
    def nshape(self) -> int:
        return len(self.shape) // self.dim


def page(result, model, *, columns: Optional[Sequence[str]] = None, scale: float = 1.0,
         title: Optional[str] = None) -> str:
    """The HTML page of `flexmbd view` for a Result and the Model it is a run of: ``flexmbd view
    RUN.csv SCENE.yaml [--columns a,b] [--scale S]``. Raises ValueError when nothing can be drawn
    or a plotted column is not in the run."""
    scale = float(scale)
    if not np.isfinite(scale) or scale < 0.0:
        raise ValueError(f"flexmbd view: scale expects a number >= 0 (1 = as computed), got {scale!r}")
    if len(result) == 0:
        raise ValueError("flexmbd view: the run has no rows to show")
    template_path = _source.view_template()
    if template_path is None:
        raise FileNotFoundError("flexmbd view: the page template (flexmbd/_data/view.html) is not installed")
    with open(template_path, encoding="utf-8") as f:
        template = f.read()
    at = template.find(PLACEHOLDER)
    if at < 0:
        raise ValueError(f"flexmbd view: {template_path} has no {PLACEHOLDER}")
    names = list(result.columns)
    index = {n: i for i, n in enumerate(names)}

    def column_of(body: str, quantity: str) -> int:
        c = index.get(f"{body}.{quantity}", 0)
        return c if c >= 1 else 0

    lib = _library()
    d_ptr = lib.fmb_drawing_new(model.handle)
    if not d_ptr:
        raise MemoryError("flexmbd view: fmb_drawing_new failed")
    try:
        d = d_ptr.contents
        dim = 3 if d.dimension == 3 else 2
        points = [(d.point[i].body, tuple(d.local3[3 * i + k] for k in range(3)) if dim == 3
                   else (d.point[i].local[0], d.point[i].local[1]), d.point[i].station) for i in range(d.npoint)]
        cells = [(d.cell[c].first, d.cell[c].count, d.cell[c].part, d.cell[c].owner) for c in range(d.ncell)]
        conn = [d.conn[k] for k in range(d.nconn)]
    finally:
        lib.fmb_drawing_free(d_ptr)
    joint_names = []
    jname, jtype = ctypes.c_char_p(), ctypes.c_char_p()
    for j in range(lib.fmb_model_njoint(model.handle)):
        lib.fmb_model_joint(model.handle, j, ctypes.byref(jname), ctypes.byref(jtype))
        joint_names.append(jname.value.decode())

    bodies = [_Body(n, dim) for n in model.bodies]
    frame_q = FRAME_COLUMNS[dim]
    notes: List[str] = []
    drawable = 0
    for b, v in enumerate(bodies):
        v.frame = [column_of(v.name, q) for q in frame_q]
        if sum(c > 0 for c in v.frame) < len(frame_q):
            v.frame = [0] * len(frame_q)
        mine = [p for p in points if p[0] == b + 1]
        v.drawn = bool(mine)
        v.nstation = sum(p[2] >= 0 for p in mine)
        v.centreline = v.nstation > 0
        while v.centreline:  # BODY.shapeK_x, BODY.shapeK_y (, BODY.shapeK_z) for K = 0, 1, ...
            cols = [column_of(v.name, f"shape{v.nshape}_{c}") for c in "xyz"[:dim]]
            if not all(cols):
                break
            v.shape += cols
        if v.centreline and v.nshape >= 2:
            # the run's stations: the drawing's when as many (BODY.shape: the nodes), else equally
            # spaced from root to tip (BODY.shape_N)
            st0 = st1 = None
            for p in mine:
                if p[2] == 0:
                    st0 = p[1]
                if p[2] == v.nstation - 1:
                    st1 = p[1]
            v.station = [[0.0] * dim for _ in range(v.nshape)]
            for k in range(v.nshape if st0 is not None and st1 is not None else 0):
                same = [p[1] for p in mine if p[2] == k] if v.nshape == v.nstation else []
                if same:
                    v.station[k] = list(same[0][:dim])
                else:
                    w = k / (v.nshape - 1)
                    v.station[k] = [st0[c] + w * (st1[c] - st0[c]) for c in range(dim)]
        if not v.drawn:
            continue
        has_shape = v.centreline and v.nshape >= 2
        if v.frame[0] or has_shape:
            drawable += 1
        lack = []
        if not v.frame[0]:
            lack += [f"{v.name}.{q}" for q in frame_q if not column_of(v.name, q)]
        if v.centreline and not has_shape:
            lack.append(f"{v.name}.shape")
        if not lack:
            continue
        cost = ("not drawn" if not v.centreline or (not has_shape and not v.frame[0])
                else "its centreline is drawn straight, undeformed" if not has_shape
                else "its deformation is drawn at scale 1 only")
        notes.append(f"{v.name}: no {', '.join(lack)}: {cost}")
    if drawable == 0:
        # the run's outputs as a scene lists them (a body's shape columns folded back), plus what is missing
        listed = [n if not _is_shape_column(n) else n[:n.rfind(".")] + ".shape" for n in names[1:]
                  if not _is_shape_column(n) or n[n.rfind(".") + 1:] == "shape0_x"]
        missing = [q for note in notes for q in note.split(": ")[1][3:].split(", ")]
        raise ValueError(f"flexmbd view: nothing to draw: {'; '.join(notes)}; to draw everything, load the scene "
                         f"with set={{'outputs': '[{', '.join(listed + missing)}]'}}")
    geometric = set()
    for v in bodies:
        geometric.update(c for c in v.frame if c)
    if columns:
        plot = []
        for name in columns:
            c = index.get(name, 0)
            if c < 1:
                raise ValueError(f"flexmbd view: the run has no column '{name}' to plot (its columns: "
                                 f"{' '.join(names[1:40])}{' ...' if len(names) > 40 else ''})")
            plot.append(c - 1)
        plot = plot[:64]
    elif len(names) > 1:  # the column that moves most (cmd_view.c default_column)
        # on the CSV's digits, which the command reads and this page draws: motions that differ
        # only beyond them tie, and the tie goes to the first column there too
        plot = [_default_column(names, result._as_written(), geometric,
                                tuple(getattr(model, "plugins", ()) or ())) - 1]
    else:
        plot = []
    if scale != 1.0:
        notes.append("deformation scale %g" % scale)
    if title is None:
        title = f"{model.path or getattr(model, '_shown_path', 'scene')}, run"
    values = np.asarray(result.values, dtype=np.float64)

    out = [template[:at], '{"title":', _json_string(title), ',"dimension":3' if dim == 3 else "", ',"scale":',
           _json_number(scale)]
    out += [',"t":[', _numbers(values[:, 0]), '],"columns":[', ",".join(_json_string(n) for n in names[1:])]
    units = []
    for n in names[1:]:
        u = lib.fmb_output_unit_in(model._reg, n.encode())
        units.append(_json_string(u.decode() if u else ""))
    out += ['],"units":[', ",".join(units), '],"data":[']
    for c in range(1, len(names)):
        out += [",\n[" if c > 1 else "\n[", _numbers(values[:, c]), "]"]
    out.append('],\n"bodies":[')
    for b, v in enumerate(bodies):
        out += [",\n{\"name\":" if b else "\n{\"name\":", _json_string(v.name)]
        out.append(',"frame":[' + ",".join(str(c - 1) for c in v.frame) + "]" if v.frame[0] else ',"frame":null')
        if v.centreline and v.nshape >= 2:
            out.append(',"shape":[' + ",".join("[" + ",".join(str(c - 1) for c in v.shape[dim * k:dim * (k + 1)]) + "]"
                                               for k in range(v.nshape)))
            out.append('],"stations":[' + ",".join("[" + ",".join(_json_number(x) for x in st) + "]"
                                                   for st in v.station))
            out.append("]")
        else:
            out.append(',"shape":null')
        out.append("}")
    # the drawing's points; a centreline's stations are those of the run (resampled when they differ)
    out.append('],\n"points":[')
    npoint = 0
    point_index = [-1] * len(points)
    first_station = [0] * len(bodies)
    for i, (pb, local, station) in enumerate(points):
        v = bodies[pb - 1] if pb > 0 else None
        on_centreline = v is not None and v.centreline and v.nshape >= 2
        if on_centreline and station >= 0:
            if station > 0:
                continue  # the run's stations stand for them, written once
            first_station[pb - 1] = npoint
            for k in range(v.nshape):
                out.append(",\n" if npoint else "\n")
                out.append(f'{{"body":{pb - 1},"local":[{",".join(_json_number(x) for x in v.station[k])}],'
                           f'"station":{k},"joint":null}}')
                npoint += 1
            point_index[i] = first_station[pb - 1]
            continue
        joint = None
        for first, count, part, owner in cells:
            if part in (DRAW_JOINT, DRAW_FORCE_ELEMENT) and i in conn[first:first + count]:
                joint = joint_names[owner] if owner < len(joint_names) else None
                break
        out.append(",\n" if npoint else "\n")
        out.append(f'{{"body":{pb - 1},"local":[{",".join(_json_number(x) for x in local)}],'
                   f'"station":{station if on_centreline else -1},"joint":'
                   f'{_json_string(joint) if joint is not None else "null"}}}')
        point_index[i] = npoint
        npoint += 1
    out.append('],\n"cells":[')
    traces: List[int] = []
    for n, (first, count, part, owner) in enumerate(cells):
        out.append(",\n" if n else "\n")
        v = bodies[owner - 1] if part == DRAW_CENTRELINE and owner > 0 else None
        if v is not None and v.centreline and v.nshape >= 2:
            pts = [first_station[owner - 1] + k for k in range(v.nshape)]
            if len(traces) < MAX_TRACES:
                traces.append(first_station[owner - 1] + v.nshape - 1)  # the tip
        else:
            pts = [point_index[conn[first + k]] for k in range(count)]
            p0 = conn[first]
            if part == DRAW_JOINT and points[p0][0] > 0 and len(traces) < MAX_TRACES:
                traces.append(point_index[p0])
        out.append('{"part":%d,"points":[%s]}' % (part, ",".join(str(p) for p in pts)))
    out.append('],\n"traces":[' + ",".join(map(str, traces)) + '],"plot":[' + ",".join(map(str, plot)))
    out.append('],"notes":[' + ",".join(_json_string(n) for n in notes) + "]}")
    out.append(template[at + len(PLACEHOLDER):])
    return "".join(out)


def _default_column(names, values, geometric, plugins) -> int:
    """cmd_view.c default_column: the column that moves most, its range against the largest |value|
    of any column in its unit (a column of unknown unit is its own scale), so that round-off about
    zero is no motion; the plot's own columns before the drawing's; ties to the first."""
    from .plot import unit

    n = len(names)
    rng, scale, group, units = [0.0] * n, [0.0] * n, list(range(n)), {}
    for c in range(1, n):
        col = values[:, c]
        seen = col[~np.isnan(col)]  # fmin/fmax pass NaN by, as the C scan does
        lo, hi = (float(seen.min()), float(seen.max())) if len(seen) else (math.inf, -math.inf)
        rng[c] = hi - lo if len(col) else 0.0
        am = float(np.abs(seen).max()) if len(seen) else 0.0
        u = unit(names[c], plugins)
        if u is not None and u in units:
            group[c] = units[u]
        elif u is not None and len(units) < 64:
            units[u] = c
        if math.isfinite(am):
            scale[group[c]] = max(scale[group[c]], am)
    best, best_motion = 1, 0.0
    for drawing_pass in (False, True):
        if best_motion != 0.0:
            break
        for c in range(1, n):
            if (_is_shape_column(names[c]) or c in geometric) != drawing_pass:
                continue
            sc = scale[group[c]]
            motion = rng[c] / sc if math.isfinite(rng[c]) and sc > 0.0 and rng[c] > 1e-9 * sc else 0.0
            if motion > best_motion:
                best_motion, best = motion, c
    return best


def _is_shape_column(name: str) -> bool:
    """cmd_view.c is_shape_column: BODY.shape..._..."""
    dot = name.rfind(".")
    return dot >= 0 and name[dot + 1:].startswith("shape") and "_" in name[dot:]


def view(result, scene=None, path: Union[str, "os.PathLike[str]", None] = None, *,
         columns: Optional[Sequence[str]] = None, scale: float = 1.0) -> str:
    """The animation of a run as `flexmbd view` draws it: returns the page's HTML and, with
    ``path``, writes it there (a temporary beside it, then renamed). ``scene``: the Model, scene file,
    text or dict the result is a run of (None: the one ``Model.run`` recorded in the result)."""
    from .model import Model, load

    owned = None
    if isinstance(scene, Model):
        model = scene
    else:
        if scene is None:
            recipe = getattr(result, "_scene", None)
            if recipe is None:
                raise ValueError("flexmbd view: this result does not know its scene (read from a CSV?): "
                                 "pass scene=, the Model or scene file it is a run of")
            what, overrides, plugins = recipe
            owned = load(what, set=list(overrides), plugins=list(plugins))
        else:
            owned = load(scene)
        model = owned
    try:
        text = page(result, model, columns=columns, scale=scale)
    finally:
        if owned is not None:
            owned.close()
    if path is not None:
        path = os.fspath(path)
        tmp = f"{path}.tmp{os.getpid()}"
        with open(tmp, "w", encoding="utf-8") as f:
            f.write(text)
        os.replace(tmp, path)
    return text


def inline(result, height: int = 860) -> Optional[str]:
    """``Result._repr_html_``: the page in an iframe (its script and element ids kept apart from the
    notebook's); when the run cannot be drawn, its repr and why."""
    try:
        text = view(result)
    except (ValueError, _lib.FlexmbdError, OSError) as e:
        return f"<pre>{html.escape(repr(result))}</pre><p>(no animation: {html.escape(str(e))})</p>"
    return (f'<iframe srcdoc="{html.escape(text, quote=True)}" style="width: 100%; max-width: 940px; '
            f'height: {int(height)}px; border: 1px solid #ddd" title="flexmbd view"></iframe>')
