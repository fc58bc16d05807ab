"""Stepping from Python (model.start, Simulation): it gives the whole run's rows; a controller in
the loop (set_load between steps) converges to the continuous law at first order in its step."""
import math
import os

import numpy as np
import pytest

import flexmbd
from conftest import SRC, cli

SPINUP = os.path.join(SRC, "scenes", "paper", "spinup_w15.yaml")


def test_stepping_equals_the_whole_run(out):
    """advance to each output time by hand (times accumulated as a user would: t + 0.01) and
    compare with the command line's CSV of the whole run (fmb_run, in C)"""
    ref = os.path.join(out, "cli.csv")
    rc, _, err = cli("run", SPINUP, "-o", ref)
    assert rc == 0, err
    whole = flexmbd.Result.from_csv(ref)
    m = flexmbd.load(SPINUP)
    sim = m.start()
    rows = [[sim.t] + list(sim.outputs().values())]
    while sim.t < m.solver["t_end"] - 1e-9:
        sim.advance(min(sim.t + m.solver["output_step"], m.solver["t_end"]))
        rows.append([sim.t] + [sim[c] for c in m.output_names])
    rows = np.array(rows)
    assert rows.shape == whole.values.shape
    # the integrator stops at each advance's t_out, so times that differ from t0 + k dt in their
    # last bits make other steps: the rows agree to the integration tolerance (rtol 1e-6 of
    # each column's range), not to the bit
    scale = np.ptp(whole.values, axis=0) + 1e-300
    worst = (np.abs(rows - whole.values) / scale).max()
    assert worst < m.solver["rtol"], worst
    # advancing to the run's own output times (t0 + k dt in double, as engine/run.c) gives the
    # CLI's bytes exactly
    sim.restart()
    times = flexmbd.output_times(m.solver)
    exact = flexmbd.Result(whole.columns, np.array([[t] + _advance(sim, t) for t in times]))
    mine = os.path.join(out, "stepped.csv")
    exact.to_csv(mine)
    assert open(mine, "rb").read() == open(ref, "rb").read()


def _advance(sim, t):
    if t > sim.t:
        sim.advance(t)
    return list(sim.outputs().values())


# A hub of inertia J = 1 pinned at its centre, driven by a torque input: PD control towards
# theta0 from Python. The continuous law J theta'' + c theta' + k (theta - theta0) = 0 has the
# closed form below (the torsion joint, its spring-damper form, must match it to the tolerance).
HUB = {"solver": {"t_end": 5, "rtol": 1e-10, "atol": 1e-12, "output_step": 0.01}, "gravity": [0, 0],
       "bodies": [{"name": "hub", "type": "rigid", "mass": 1, "inertia": 1}],
       "joints": [{"name": "pin", "type": "revolute", "body1": "ground", "body2": "hub"},
                  {"name": "motor", "type": "force", "body": "hub", "torque": 1, "law": "input", "value": 0}],
       "outputs": ["hub.theta", "hub.omega"]}
K, C, THETA0 = 4.0, 0.4, 1.0


def closed_form(t):
    wn, z = math.sqrt(K), C / (2 * math.sqrt(K))
    wd = wn * math.sqrt(1 - z * z)
    return THETA0 * (1 - np.exp(-z * wn * t) * (np.cos(wd * t) + z / math.sqrt(1 - z * z) * np.sin(wd * t)))


def pd_error(model, h):
    """max |theta - closed form| of the sampled PD loop with step h (zero-order hold)"""
    sim = model.start()
    err = 0.0
    for i in range(int(round(model.solver["t_end"] / h))):
        sim.set_load("motor", -K * (sim["hub.theta"] - THETA0) - C * sim["hub.omega"])
        sim.advance((i + 1) * h)
        err = max(err, abs(sim["hub.theta"] - closed_form(sim.t)))
    return err


def test_controller_in_the_loop():
    m = flexmbd.load(HUB)
    assert m.inputs == ["motor"]
    spring = dict(HUB, joints=[HUB["joints"][0], {"name": "pd", "type": "torsion", "body1": "ground", "body2": "hub",
                                                  "stiffness": K, "damping": C, "angle0": THETA0}])
    r = flexmbd.load(spring).run()
    assert np.abs(r["hub.theta"] - closed_form(r.t)).max() < 1e-7  # the continuous law itself
    e2, e1 = pd_error(m, 2e-3), pd_error(m, 1e-3)
    # a zero-order hold delays the torque by h/2 on average: the error is O(h), here about
    # theta0 wn h (1.9e-3 at h = 1e-3), and halves with h
    assert e1 < 3 * THETA0 * math.sqrt(K) * 1e-3
    assert 1.8 < e2 / e1 < 2.2, (e2, e1)


def test_inputs_and_misuse():
    m = flexmbd.load(HUB)
    sim = m.start()
    sim.set_load("motor", 2.0)
    assert sim.get_load("motor") == 2.0
    sim.advance(1.0)
    assert sim["hub.omega"] == pytest.approx(2.0, rel=1e-8)  # J omega' = 2 from rest
    with pytest.raises(flexmbd.SceneError):
        sim.set_load("nothing", 1.0)
    with pytest.raises(flexmbd.SceneError):
        sim.set_load("motor", float("nan"))
    with pytest.raises(flexmbd.SceneError):
        sim.advance(0.5)  # backwards
    with pytest.raises(flexmbd.SceneError):
        sim.advance(m.solver["t_end"] + 1)
    assert sim.t == 1.0  # a refused call changes nothing
    with pytest.raises(KeyError):
        sim["hub.nothing"]
    sim.restart()
    assert sim.t == 0.0 and sim.get_load("motor") == 0.0 and sim["hub.omega"] == 0.0
    sim.close()
    with pytest.raises(ValueError):
        sim.advance(1.0)
