"""A spatial scene (dimension 3, docs/spatial.md) through the Python package (issue 34): loaded, run
and stepped as a planar one; the run's columns are those of `flexmbd run` (same digits); the state
(Simulation.state / set_state) holds each rigid3d body's [r, p]; a set state is followed as the
C test tests/spatial/test_step3d.c checks; and Result._repr_html_ shows the 3D viewer inline."""
import html
import os
import re

import numpy as np
import pytest

import flexmbd
from conftest import SRC, cli

TOP = os.path.join(SRC, "tests", "spatial", "scenes", "top.yaml")
SPATIAL = os.path.join(SRC, "tests", "ux", "scenes", "spatial_view.yaml")
SETS = {"bodies.top.angular_velocity": "[0, -24.04, 43.86]", "solver.t_end": 0.3, "solver.output_step": 0.01,
        "outputs": "[top.x, top.y, top.z, top.qw, top.qx, top.qy, top.qz, top.wx, top.wy, top.wz, energy.total]"}


def rotation(q):
    w, x, y, z = np.asarray(q) / np.linalg.norm(q)
    return np.array([[w * w + x * x - y * y - z * z, 2 * (x * y - w * z), 2 * (x * z + w * y)],
                     [2 * (x * y + w * z), w * w - x * x + y * y - z * z, 2 * (y * z - w * x)],
                     [2 * (x * z - w * y), 2 * (y * z + w * x), w * w - x * x - y * y + z * z]])


def test_run_is_the_commands(out):
    model = flexmbd.load(TOP, set=SETS)
    result = model.run()
    csv = os.path.join(out, "run.csv")
    rc, _, err = cli("run", TOP, *[a for k, v in SETS.items() for a in ("--set", f"{k}={v}")], "-o", csv)
    assert rc == 0, err
    result.to_csv(os.path.join(out, "py.csv"))
    assert open(os.path.join(out, "py.csv")).read() == open(csv).read()
    # the pivot stays put: the centre of mass 0.1 m from it along the body's z axis, R from the quaternion
    for k in range(0, len(result), 7):
        R = rotation([result[f"top.q{c}"][k] for c in "wxyz"])
        r = np.array([result[f"top.{c}"][k] for c in "xyz"])
        assert np.abs(r + R @ [0, 0, -0.1]).max() < 1e-8


def test_step_state_and_set_state():
    model = flexmbd.load(TOP, set=SETS)
    assert model.state_size == 20  # [r, p] 7, their rates 7, the ball joint's 3 multipliers (+3 of the GGL form)
    sim = flexmbd.Simulation(model)
    sim.advance(0.15)
    y, yp = sim.state()
    p = y[3:7]
    assert sim["top.x"] == y[0] and sim["top.z"] == y[2]
    assert np.allclose(p / np.linalg.norm(p), [sim[f"top.q{c}"] for c in "wxyz"], rtol=0, atol=1e-15)
    sim.advance(0.3)
    went_on = sim.outputs()
    # another simulation set to that state follows (no step history: to the tolerance, 1e-6)
    other = flexmbd.Simulation(model)
    other.set_state(y, yp, t=0.15)
    assert other.t == 0.15 and other["top.qx"] == pytest.approx(y[4] / np.linalg.norm(p), abs=1e-15)
    other.advance(0.3)
    assert max(abs(other[n] - went_on[n]) for n in went_on) < 1e-6
    # the Euler parameters' length is a gauge: p scaled by 3 is the same pose
    scaled = y.copy()
    scaled[3:7] *= 3
    scaled[10:14] *= 3
    other.set_state(scaled, None, t=0.15)
    assert other["top.qw"] == pytest.approx(y[3] / np.linalg.norm(p), abs=1e-14)
    other.advance(0.3)
    assert max(abs(other[n] - went_on[n]) for n in went_on) < 1e-6
    # refused, nothing changed
    with pytest.raises(ValueError, match="state has 20 values"):
        other.set_state(y[:7])
    bad = y.copy()
    bad[0] = np.nan
    with pytest.raises(ValueError, match="not finite"):
        other.set_state(bad)
    with pytest.raises(ValueError, match="t_end"):
        other.set_state(y, t=5.0)
    assert other.t == 0.3


def test_repr_html_shows_the_3d_view():
    result = flexmbd.load(SPATIAL).run()
    shown = result._repr_html_()
    m = re.fullmatch(r'<iframe srcdoc="([^"]*)" style="[^"]*" title="flexmbd view"></iframe>', shown, re.S)
    assert m, shown[:300]
    page = html.unescape(m.group(1))
    data = re.search(r"const D = (\{.*?\});\n", page, re.S).group(1)
    assert '"dimension":3' in data and "function orbit(" in page and not re.search(r"https?://", page)
    assert '"frame":[0,1,2,3,4,5,6]' in data
