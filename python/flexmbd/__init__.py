"""flexmbd from Python: load a scene, run it, step it, analyse it; results as NumPy arrays.

    import flexmbd
    model = flexmbd.load("scenes/paper/spinup_w15.yaml", set={"bodies.beam.model": "foac"})
    result = model.run()
    result["beam.tip_v"]          # numpy array, one value per output row
    result.stats["steps"]         # the stats line as a dict

Everything is computed by the C library (libflexmbd, found as flexmbd._lib describes) through
ctypes; this package converts arguments and results, nothing more. docs/python.md is the guide.
"""
from ._lib import FlexmbdError, FlexmbdWarning, Interrupted, SceneError, SolverError, library_path
from ._scene import scene_text
from .model import Cancel, Model, Result, Simulation, load, output_times
from .analysis import CampbellResult, ModesResult, StaticResult, campbell, modes, static
from .compare import Comparison, compare
from .plot import axis_label, unit
from .study import metric, study

__all__ = ["load", "Model", "Result", "Simulation", "Cancel", "output_times", "FlexmbdWarning", "SceneError", "SolverError", "Interrupted", "FlexmbdError",
           "scene_text", "library_path",
           "static", "modes", "campbell", "StaticResult", "ModesResult", "CampbellResult", "compare", "Comparison",
           "study", "metric", "unit", "axis_label"]
