"""flexmbd.study: one process per run, one row per override set in the given order; a crashed or
timed-out process costs its own row only; metrics are the runs' own numbers."""
import os
import time


import flexmbd
from conftest import SRC

SPINUP = os.path.join(SRC, "scenes", "paper", "spinup_w4.yaml")




def test_study_statuses_and_metrics():
    sets = [{"bodies.beam.model": m, "solver.t_end": 5} for m in ("complete", "foac", "zoac")]
    sets.append({"bodies.beam.model": "nonsense"})
    rows = flexmbd.study(SPINUP, sets, processes=2, metrics=["beam.tip_v:max", "beam.tip_v:end"])
    assert [r["bodies.beam.model"] for r in rows] == ["complete", "foac", "zoac", "nonsense"]
    assert [r["status"] for r in rows] == ["ok", "ok", "ok", "bad_input"]
    assert "nonsense" in rows[3]["message"] and rows[3]["exit_code"] == 2
    direct = flexmbd.load(SPINUP, set=sets[1]).run()
    assert rows[1]["beam.tip_v:max"] == direct["beam.tip_v"].max()
    assert rows[1]["beam.tip_v:end"] == direct["beam.tip_v"][-1] and rows[1]["steps"] == direct.stats["steps"]


def test_a_crash_costs_one_row():
    sets = [{"bodies.beam.model": m, "solver.t_end": 2} for m in ("complete", "foac", "complete")]

    def measure(result):
        if result.stats["steps"] and abs(result["beam.tip_v"][-1] - foac_end) < 1e-12:
            os.abort()  # the foac run's process dies, as with a plugin's segfault
        return {"rows": len(result)}

    foac_end = flexmbd.load(SPINUP, set=sets[1]).run()["beam.tip_v"][-1]
    rows = flexmbd.study(SPINUP, sets, processes=2, measure=measure)
    assert [r["status"] for r in rows] == ["ok", "crashed", "ok"]
    assert rows[1]["exit_code"] == -6 and "signal 6" in rows[1]["message"]
    assert rows[0]["rows"] == rows[2]["rows"] == 201


def test_timeout_kills_one_run():
    def measure(result):
        if result.t[-1] == 0.3:
            time.sleep(600)  # a run that hangs
        return {}

    sets = [{"solver.t_end": 0.3}, {"solver.t_end": 0.5}]
    rows = flexmbd.study(os.path.join(SRC, "scenes", "pendulum.yaml"), sets, processes=2, timeout=4, measure=measure)
    assert [r["status"] for r in rows] == ["timeout", "ok"]


def test_study_of_a_model_keeps_results():
    """a Model (loaded with its own override, t_end = 1) is re-loaded in each child with the
    set on top; keep_results brings each Result back"""
    base = flexmbd.load(SPINUP, set={"solver.t_end": 1})
    rows = flexmbd.study(base, [{"bodies.beam.elements": 4}, {"bodies.beam.elements": 8}], processes=2,
                         keep_results=True)
    for row in rows:
        direct = flexmbd.load(SPINUP, set={"solver.t_end": 1, "bodies.beam.elements": row["bodies.beam.elements"]}).run()
        assert row["status"] == "ok" and row["result"].columns == direct.columns
        assert (row["result"].values == direct.values).all()
