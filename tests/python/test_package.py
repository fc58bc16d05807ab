"""The package itself: its ctypes structs match flexmbd.h (compiled and measured), a plugin loads
from Python, the installed package imports and finds the installed library, plots carry units."""
import ctypes
import os
import shutil
import subprocess
import sys

import numpy as np
import pytest

import flexmbd
from flexmbd import _lib
from conftest import BUILD, SRC, cli

STRUCTS = {"fmbDiag": _lib.Diag, "fmbSolverInfo": _lib.SolverInfo,
           "fmbStaticOptions": _lib.StaticOptions, "fmbStaticResult": _lib.StaticResult, "fmbModes": _lib.Modes,
           "fmbSceneSource": _lib.SceneSource, "fmbCampbellOptions": _lib.CampbellOptions, "fmbCampbell": _lib.Campbell}


def test_struct_layouts_match_the_header(out):
    """sizeof and every field's offset, printed by a C program compiled against engine/flexmbd.h"""
    cc = shutil.which("cc") or shutil.which("gcc")
    if not cc:
        pytest.skip("no C compiler")
    lines = ["#include <stddef.h>", "#include <stdio.h>", '#include "flexmbd.h"', "int main(void) {"]
    expect = []
    for cname, cls in STRUCTS.items():
        lines.append(f'  printf("%zu\\n", sizeof({cname}));')
        expect.append(ctypes.sizeof(cls))
        for field, _ in cls._fields_:
            lines.append(f'  printf("%zu\\n", offsetof({cname}, {field}));')
            expect.append(getattr(cls, field).offset)
    lines += ["  return 0;", "}"]
    c = os.path.join(out, "layout.c")
    open(c, "w").write("\n".join(lines) + "\n")
    exe = os.path.join(out, "layout")
    subprocess.run([cc, "-std=c11", "-I", os.path.join(SRC, "engine"), c, "-o", exe], check=True)
    got = [int(x) for x in subprocess.run([exe], capture_output=True, text=True, check=True).stdout.split()]
    assert got == expect
    abi = [l for l in open(os.path.join(SRC, "engine", "flexmbd.h")) if l.startswith("#define FMB_SOVERSION")]
    assert int(abi[0].split()[2]) == _lib.ABI


def test_plugin_loaded_from_python(out):
    so = os.environ.get("FLEXMBD_TEST_PLUGIN", os.path.join(BUILD, "tests", "python", "foundation.so"))
    scene = os.path.join(out, "bar.yaml")
    # examples/plugin's scene without its plugins: line (the plugin comes from load's plugins=)
    text = "".join(l for l in open(os.path.join(SRC, "examples", "plugin", "foundation.yaml"))
                   if not l.startswith("plugins:"))
    open(scene, "w").write(text)
    with pytest.raises(flexmbd.SceneError) as e:
        flexmbd.load(scene)  # without the plugin the type is unknown, at its line
    assert "foundation_bar" in e.value.message and e.value.line > 0
    r = flexmbd.load(scene, plugins=[so], set={"solver.t_end": 0.5}).run()
    mine = os.path.join(out, "python.csv")
    r.to_csv(mine)
    ref = os.path.join(out, "cli.csv")
    rc, _, err = cli("run", scene, "--plugin", so, "--set", "solver.t_end=0.5", "-o", ref)
    assert rc == 0, err
    assert open(mine, "rb").read() == open(ref, "rb").read()
    # heave about the sag y0 = -m g / (k L) (examples/plugin/check_foundation.c): y(t) = y0 (1 - cos w t)
    m, g, k, L = 2.0, 9.81, 500.0, 1.2
    y0, w = -m * g / (k * L), np.sqrt(k * L / m)
    np.testing.assert_allclose(r["bar.y"], y0 * (1 - np.cos(w * r.t)), atol=1e-6)


def test_installed_package_finds_the_installed_library(out):
    prefix = os.path.join(out, "prefix")
    subprocess.run(["cmake", "--install", BUILD, "--prefix", prefix], check=True, capture_output=True)
    site = os.path.join(prefix, "lib", "python3", "dist-packages")
    assert os.path.isfile(os.path.join(site, "flexmbd", "__init__.py"))
    env = {k: v for k, v in os.environ.items() if not k.startswith("FLEXMBD_") and k != "PYTHONPATH"}
    env["PYTHONPATH"] = site
    code = ("import flexmbd; print(flexmbd.library_path()); "
            f"print(flexmbd.load({os.path.join(SRC, 'scenes', 'pendulum.yaml')!r}, set={{'solver.t_end': 0.1}}).run().t[-1])")
    p = subprocess.run([sys.executable, "-c", code], env=env, cwd=out, capture_output=True, text=True)
    assert p.returncode == 0, p.stderr
    lib, t_end = p.stdout.split()
    assert os.path.realpath(lib).startswith(os.path.realpath(prefix)) and float(t_end) == 0.1


def test_plot_has_units(out):
    matplotlib = pytest.importorskip("matplotlib")
    matplotlib.use("Agg")
    spin = os.path.join(SRC, "scenes", "paper", "spinup_w4.yaml")
    r = flexmbd.load(spin, set={"solver.t_end": 1}).run()
    ax = r.plot("beam.tip_v")
    assert ax.get_xlabel() == "t (s)" and ax.get_ylabel() == "beam.tip_v (m)"
    ax = r.plot("beam.tip_v", "beam.tip_u")
    assert ax.get_ylabel() == "(m)"
    assert flexmbd.unit("beam.omega") == "rad/s" and flexmbd.unit("energy.total") == "J"
    assert flexmbd.unit("beam.node3_v") == "m" and flexmbd.unit("constraint.position") is None
    ax.figure.savefig(os.path.join(out, "tip.png"))


def test_cmake_installed_package_has_version_and_view_template(out):
    """cmake --install gives the package what pip install . gives it: __version__ (CMakeLists.txt's
    project version) and flexmbd view's page template as package data"""
    import re

    prefix = os.path.join(out, "prefix")
    subprocess.run(["cmake", "--install", BUILD, "--prefix", prefix], check=True, capture_output=True)
    site = os.path.join(prefix, "lib", "python3", "dist-packages")
    env = {k: v for k, v in os.environ.items() if not k.startswith("FLEXMBD_") and k != "PYTHONPATH"}
    env["PYTHONPATH"] = site
    code = "import flexmbd, flexmbd._source as s; print(flexmbd.__version__); print(s.view_template())"
    p = subprocess.run([sys.executable, "-c", code], env=env, cwd=out, capture_output=True, text=True)
    assert p.returncode == 0, p.stderr
    version, template = p.stdout.split()
    with open(os.path.join(SRC, "CMakeLists.txt")) as f:
        assert version == re.search(r"project\(flexmbd VERSION ([0-9.]+)", f.read()).group(1)
    assert template == os.path.join(site, "flexmbd", "_data", "view.html")
    assert open(template, "rb").read() == open(os.path.join(SRC, "tools", "view.html"), "rb").read()
