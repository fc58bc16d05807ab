"""static, modes, campbell and compare from Python give the command line's numbers, and the
rotating beam's first frequency at rest is the clamped beam's (1.87510)^2 sqrt(EI / (rho A L^4))."""
import math
import os

import numpy as np

import flexmbd
from conftest import SRC, cli

CAMPBELL = os.path.join(SRC, "scenes", "campbell_beam.yaml")


def test_static_equals_cli(out):
    path = os.path.join(out, "static.csv")
    rc, _, err = cli("static", CAMPBELL, "-o", path, "--set", "joints.spin.speed=6")
    assert rc == 0, err
    s = flexmbd.static(CAMPBELL, set={"joints.spin.speed": 6})
    row = flexmbd.Result.from_csv(path)
    assert s.outputs == {c: float(row[c][0]) for c in row.columns}
    assert abs(s.speed - 6.0) < 1e-9 and s.residual < 1e-8 and len(s.y) == flexmbd.load(CAMPBELL).state_size
    assert s["beam.tip_u"] > 0  # spun: the centrifugal load stretches the beam


def test_modes_equal_cli_and_clamped_beam(out):
    path = os.path.join(out, "modes.csv")
    rc, _, err = cli("modes", CAMPBELL, "--count", "3", "-o", path, "--set", "joints.spin.speed=0")
    assert rc == 0, err
    md = flexmbd.modes(CAMPBELL, count=3, set={"joints.spin.speed": 0})
    ref = flexmbd.Result.from_csv(path)  # columns mode, frequency, frequency_hz, damping_ratio
    np.testing.assert_allclose(md.frequency, ref.values[:, ref.columns.index("frequency")], rtol=1e-11)
    np.testing.assert_allclose(md.damping_ratio, ref.values[:, ref.columns.index("damping_ratio")], atol=1e-12)
    E, I, rho, A, L = 68.95e9, 1.302e-10, 2767.0, 2.5e-4, 1.8
    w1 = 1.8751040687**2 * math.sqrt(E * I / (rho * A * L**4))
    assert abs(md.frequency[0] - w1) < 1e-4 * w1, (md.frequency[0], w1)
    assert md.shapes.shape[0] == 3 and md.shapes.dtype == complex
    assert np.isclose(np.abs(md.shapes[0]).max(), 1.0)


def test_campbell_equals_cli(out):
    path = os.path.join(out, "campbell.csv")
    rc, _, err = cli("campbell", CAMPBELL, "--speed", "joints.spin.speed", "--speeds", "0:12:4", "--count", "3",
                     "-o", path, "--plot", os.path.join(out, "c.png"))
    assert rc == 0, err
    c = flexmbd.campbell(CAMPBELL, "joints.spin.speed", np.linspace(0, 12, 4), count=3)
    with open(path) as f:
        f.readline()
        ref = np.loadtxt(f, delimiter=",", ndmin=2)
    np.testing.assert_array_equal(c.speeds, ref[:, 0])
    np.testing.assert_allclose(c.frequencies, ref[:, 1:], rtol=1e-11)
    assert np.all(np.diff(c.frequencies[:, 0]) > 0)  # dynamic stiffening: the first mode rises with speed


def test_compare_numbers():
    spin = os.path.join(SRC, "scenes", "paper", "spinup_w4.yaml")
    a = flexmbd.load(spin, set={"bodies.beam.model": "foac"}).run()
    b = flexmbd.load(spin).run()
    c = flexmbd.compare(a, b, columns=["beam.tip_v"], rtol=0.01)
    # the same output grid: the error is the plain difference of the two CSVs' values
    diff = np.abs(a["beam.tip_v"] - b["beam.tip_v"])
    e = c["beam.tip_v"]
    assert math.isclose(e["max_abs"], diff.max(), rel_tol=1e-5) and e["t_max"] == a.t[diff.argmax()]
    assert e["rows"] == len(a) and e["status"] == "ok" and c.ok
    tight = flexmbd.compare(a, b, columns=["beam.tip_v"], rtol=1e-6)
    assert not tight.ok and tight["beam.tip_v"]["status"] == "beyond"


def test_campbell_of_text_and_errors():
    """a scene given as text goes to fmb_campbell as a temporary file, named <string> in errors;
    a failure carries the speeds done"""
    text = open(CAMPBELL).read()
    c = flexmbd.campbell(text, "joints.spin.speed", [0.0, 6.0], count=2)
    ref = flexmbd.campbell(flexmbd.load(CAMPBELL), "joints.spin.speed", [0.0, 6.0], count=2)
    np.testing.assert_allclose(c.frequencies, ref.frequencies, rtol=1e-10)  # ARPACK: its start vector differs per call
    assert c.mac[0].tolist() == [1.0, 1.0] and (c.mac > 0.9).all() and not c.poor_matches
    try:
        flexmbd.campbell(text, "joints.spin.sped", [0.0, 6.0], count=2)
    except flexmbd.SceneError as e:
        assert e.file in ("--set", "<string>") and "sped" in str(e), str(e)
    else:
        raise AssertionError("a misspelt speed key was accepted")
