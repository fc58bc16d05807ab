"""A drive steered from Python follows the rate it is given (issue 36, the newcomer's hub): the hub
angle 0.1875 t^2 set every 0.01 s with set_load(name, value, rate=, accel=) moves the blade as the
prescribed law that turns the hub so (tests/core/scenes/input_hub_law.yaml, an independent scene:
the ramp law, no input); set by value alone, the hub is at rest between settings and one warning
says what to give instead."""
import os
import warnings

import numpy as np

import flexmbd
from conftest import SRC

HUB = os.path.join(SRC, "tests", "core", "scenes", "input_hub.yaml")
LAW = os.path.join(SRC, "tests", "core", "scenes", "input_hub_law.yaml")
C, H, N = 0.1875, 0.01, 100  # angle C t^2, a setting every H s, N settings (1 s)


def test_drive_input_with_rate_follows_the_law():
    law = flexmbd.load(LAW).run()
    sim = flexmbd.load(HUB).start()
    ke, tip = [], []
    with warnings.catch_warnings():
        warnings.simplefilter("error", flexmbd.FlexmbdWarning)  # no jump may be warned
        for k in range(N):
            t = k * H
            sim.set_load("motor", C * t * t, rate=2 * C * t, accel=2 * C)
            sim.advance(t + H)
            ke.append(sim["energy.kinetic"])
            tip.append(sim["beam.tip_v"])
    ref_ke = np.interp(np.arange(1, N + 1) * H, law["t"], law["energy.kinetic"])
    ref_tip = np.interp(np.arange(1, N + 1) * H, law["t"], law["beam.tip_v"])
    assert np.max(np.abs(ref_ke)) > 0.05 and np.max(np.abs(ref_tip)) > 1e-3  # the law moves the blade
    # rtol 1e-8 and a restart at every setting: the C test measures 8e-7 of the tip's range
    assert np.max(np.abs(np.array(ke) - ref_ke)) <= 1e-6 * np.max(np.abs(ref_ke))
    assert np.max(np.abs(np.array(tip) - ref_tip)) <= 5e-6 * np.max(np.abs(ref_tip))


def test_drive_input_by_value_alone_is_held_and_warned():
    sim = flexmbd.load(HUB).start()
    with warnings.catch_warnings(record=True) as said:
        warnings.simplefilter("always")
        for k in range(20):
            t = k * H
            sim.set_load("motor", C * t * t)
            sim.advance(t + H)
            assert sim["energy.kinetic"] == 0.0  # at rest between settings
    jumps = [str(w.message) for w in said if "jumps" in str(w.message)]
    assert len(jumps) == 1 and "rate=" in jumps[0] and "Simulation.set_load" in jumps[0], jumps
