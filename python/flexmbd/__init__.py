"""flexmbd from Python: load a scene, run it, step it, analyse it; results as NumPy arrays.

    import flexmbd
    model = flexmbd.load("scenes/paper/spinup_w15.yaml", set={"bodies.beam.model": "foac"})
    result = model.run()
    result["beam.tip_v"]          # numpy array, one value per output row
    result.stats["steps"]         # the stats line as a dict

Everything is computed by the C library (libflexmbd, found as flexmbd._lib describes) through
ctypes; this package converts arguments and results, nothing more. docs/python.md is the guide.
"""
try:
    import numpy as _numpy  # noqa: F401  (every result is a NumPy array)
except ImportError as _e:  # a python3 other than Debian's, without NumPy: say what to install
    import sys as _sys

    raise ImportError(
        f"flexmbd needs NumPy, which this Python ({_sys.executable}, {_sys.version.split()[0]}) cannot import "
        f"({_e}). With Debian's python3: `sudo apt install python3-numpy` and run /usr/bin/python3. In a venv: make "
        "it with `python3 -m venv --system-site-packages` over Debian's python3 (it then sees python3-numpy), or "
        "install numpy into it (`python -m pip install numpy`). With pyenv or conda: install numpy into that "
        "interpreter (`pip install numpy` / `conda install numpy`)."
    ) from _e

from ._source import version as _version

#: the project's version (CMakeLists.txt's project(VERSION), recorded at the build)
__version__ = _version()

from ._lib import ArgumentError, KeyboardInterrupted, FlexmbdError, FlexmbdWarning, Interrupted, SceneError, SolverError, library_path
from ._scene import scene_text
from .model import Cancel, Model, Result, Simulation, load, output_times
from .analysis import CampbellResult, ModesResult, StaticResult, campbell, modes, static
from .compare import Comparison, compare
from .plot import axis_label, unit
from .study import metric, study
from .view_page import view

__all__ = ["load", "Model", "Result", "Simulation", "Cancel", "output_times", "FlexmbdWarning", "SceneError", "SolverError", "Interrupted", "FlexmbdError",
           "ArgumentError", "KeyboardInterrupted",
           "scene_text", "library_path",
           "static", "modes", "campbell", "StaticResult", "ModesResult", "CampbellResult", "compare", "Comparison",
           "study", "metric", "unit", "axis_label", "view"]
