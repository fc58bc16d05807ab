"""flexmbd from Python: load a scene, run it, step it, analyse it; results as NumPy arrays.

    import flexmbd
    model = flexmbd.load("scenes/paper/spinup_w15.yaml", set={"bodies.beam.model": "foac"})
    result = model.run()
    result["beam.tip_v"]          # numpy array, one value per output row
    result.stats["steps"]         # the stats line as a dict

Everything is computed by the C library (libflexmbd, found as flexmbd._lib describes) through
ctypes; this package converts arguments and results, nothing more. docs/python.md is the guide.
"""
import sys as _sys

try:
    import numpy as _numpy  # noqa: F401  (every result is a NumPy array)
except ImportError as _e:
    raise ImportError(
        f"flexmbd needs NumPy, which this Python ({_sys.executable}) cannot import: {_e}. Install it for "
        f"this interpreter ('{_sys.executable} -m pip install numpy'), or use Debian's /usr/bin/python3 with "
        "python3-numpy (apt install python3-numpy), or a venv made with "
        "'/usr/bin/python3 -m venv --system-site-packages', which sees Debian's NumPy") from _e

from ._source import version as _version

#: the project's version (CMakeLists.txt's project(VERSION), recorded at the build)
__version__ = _version()

from ._lib import FlexmbdError, FlexmbdWarning, Interrupted, SceneError, SolverError, library_path
from ._scene import scene_text
from .model import Cancel, Model, Result, Simulation, load, output_times
from .analysis import CampbellResult, ModesResult, StaticResult, campbell, modes, static
from .compare import Comparison, compare
from .plot import axis_label, unit
from .study import metric, study
from .view_page import view

__all__ = ["load", "Model", "Result", "Simulation", "Cancel", "output_times", "FlexmbdWarning", "SceneError", "SolverError", "Interrupted", "FlexmbdError",
           "scene_text", "library_path",
           "static", "modes", "campbell", "StaticResult", "ModesResult", "CampbellResult", "compare", "Comparison",
           "study", "metric", "unit", "axis_label", "view"]
