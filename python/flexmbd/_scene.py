"""What `flexmbd.load` accepts, turned into what `fmb_load` reads: a scene file and its overrides.

A dict is written as block-style YAML (one key per line), so that an error in it still points at
a line and column of the text the package wrote (shown as ``<dict>``; ``scene_text(d)`` prints
it). Overrides are the command line's ``--set PATH=VALUE`` strings."""
from __future__ import annotations

import json
import math
import os
import re
from typing import Any, Mapping, Union

PathLike = Union[str, "os.PathLike[str]"]

_PLAIN = re.compile(r"^[A-Za-z0-9_][A-Za-z0-9_.+\-/ ]*$")
_YAML_WORDS = {"true", "false", "yes", "no", "on", "off", "null", "~", "y", "n"}


def scalar(value: Any) -> str:
    """One YAML scalar as flexmbd reads it: numbers and words plain, other text double-quoted."""
    if isinstance(value, bool):
        return "true" if value else "false"
    if isinstance(value, int):
        return str(value)
    if isinstance(value, float):
        if math.isnan(value):
            return ".nan"
        if math.isinf(value):
            return ".inf" if value > 0 else "-.inf"
        return repr(value)
    if value is None:
        return "null"
    text = str(value)
    if _PLAIN.match(text) and text.lower() not in _YAML_WORDS and not text.endswith(" "):
        return text
    return json.dumps(text)  # a JSON string is a YAML double-quoted scalar


def _emit(value: Any, indent: int, out: list) -> None:
    pad = " " * indent
    if isinstance(value, Mapping):
        for k, v in value.items():
            if isinstance(v, Mapping) and v:
                out.append(f"{pad}{scalar(k)}:")
                _emit(v, indent + 2, out)
            elif isinstance(v, (list, tuple)) and v and not all(_is_scalar(x) for x in v):
                out.append(f"{pad}{scalar(k)}:")
                _emit(v, indent + 2, out)
            else:
                out.append(f"{pad}{scalar(k)}: {_inline(v)}")
    elif isinstance(value, (list, tuple)):
        for item in value:
            if isinstance(item, Mapping) and item:
                sub: list = []
                _emit(item, indent + 2, sub)
                out.append(f"{pad}- {sub[0].lstrip()}")
                out.extend(sub[1:])
            else:
                out.append(f"{pad}- {_inline(item)}")
    else:
        out.append(pad + _inline(value))


def _is_scalar(x: Any) -> bool:
    return not isinstance(x, (Mapping, list, tuple)) or (isinstance(x, (list, tuple)) and all(
        not isinstance(y, (Mapping, list, tuple)) for y in x))


def _inline(v: Any) -> str:
    if isinstance(v, Mapping):
        return "{" + ", ".join(f"{scalar(k)}: {_inline(x)}" for k, x in v.items()) + "}"
    if isinstance(v, (list, tuple)):
        return "[" + ", ".join(_inline(x) for x in v) + "]"
    if hasattr(v, "tolist"):  # a NumPy number
        return _inline(v.tolist())
    return scalar(v)


def scene_text(scene: Mapping) -> str:
    """The YAML text a dict is loaded as (block style, keys in the dict's order)."""
    out: list = []
    _emit(scene, 0, out)
    return "\n".join(out) + "\n"


def override(path: str, value: Any) -> str:
    """`PATH=VALUE` as `--set` takes it."""
    if isinstance(value, (list, tuple, Mapping)) or hasattr(value, "tolist"):
        return f"{path}={_inline(value)}"
    return f"{path}={scalar(value) if not isinstance(value, str) else value}"


def looks_like_yaml(text: str) -> bool:
    """A string holding a scene rather than naming a file: several lines, or a `key: value`."""
    return "\n" in text or (": " in text and not os.path.exists(text)) or text.lstrip().startswith("{")
