"""What the package takes from the project itself: its version and the page template of
`flexmbd view`, from the files the build put into the package (``pip install .``, ``cmake
--install``) or, in a source checkout used with ``PYTHONPATH=python``, from the checkout.

No NumPy and no library here: setup.py loads this file by its path to read the version."""
from __future__ import annotations

import os
import re
from typing import Optional

HERE = os.path.dirname(os.path.abspath(__file__))
#: the source checkout this package folder sits in (python/flexmbd), when it does
CHECKOUT = os.path.normpath(os.path.join(HERE, "..", ".."))


def project_version(cmakelists: str) -> str:
    """The version of ``project(flexmbd VERSION X.Y.Z ...)`` in a CMakeLists.txt: the one source
    of the version (the library's VERSION, the package's metadata, ``flexmbd.__version__``)."""
    with open(cmakelists, encoding="utf-8") as f:
        m = re.search(r"^\s*project\s*\(\s*flexmbd\s+VERSION\s+([0-9][0-9.]*)", f.read(), re.MULTILINE)
    if not m:
        raise ValueError(f"{cmakelists}: no 'project(flexmbd VERSION X.Y.Z' line")
    return m.group(1)


def version() -> str:
    """The package's version: _version.py written by the build, else the checkout's CMakeLists.txt."""
    try:
        from ._version import VERSION  # written by setup.py's build step and by cmake --install

        return VERSION
    except ImportError:
        pass
    path = os.path.join(CHECKOUT, "CMakeLists.txt")
    return project_version(path) if os.path.isfile(path) else "unknown"


def view_template() -> Optional[str]:
    """The file of `flexmbd view`'s page, tools/view.html: installed as package data
    (flexmbd/_data/view.html), else the checkout's; None when neither is there."""
    for path in (os.path.join(HERE, "_data", "view.html"), os.path.join(CHECKOUT, "tools", "view.html")):
        if os.path.isfile(path):
            return path
    return None
