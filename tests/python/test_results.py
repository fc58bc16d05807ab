"""model.run against `flexmbd run`: the same rows, byte for byte, for every shipped scene; the
stats line as a dict; scenes given as text or a dict."""
import os

import numpy as np
import pytest

import flexmbd
from conftest import SRC, cli, scenes


@pytest.mark.parametrize("scene", scenes(), ids=lambda p: os.path.relpath(p, SRC))
def test_every_scene_same_bytes_as_cli(scene, out):
    ref = os.path.join(out, "cli.csv")
    rc, _, err = cli("run", scene, "-o", ref, "--quiet")
    mine = os.path.join(out, "python.csv")
    model = flexmbd.load(scene)
    result = model.run(check=False)
    result.to_csv(mine)
    assert (result.error.code if result.error else 0) == rc, err
    with open(ref, "rb") as a, open(mine, "rb") as b:
        assert a.read() == b.read(), f"{scene}: to_csv differs from flexmbd run -o"
    # the stats line's fields, as the CLI prints them (cpu_s aside, a measurement)
    cli_stats = flexmbd._lib.parse_stats_line(err.strip().splitlines()[-1])
    for key in ("status", "t_reached", "steps", "residuals", "jacobians", "newton_iters", "error_test_fails"):
        assert result.stats[key] == cli_stats[key], key
    assert result.columns[0] == "t" and np.array_equal(result.t, result["t"])
    model.close()


def test_text_and_dict_scenes_run_like_the_file(out):
    path = os.path.join(SRC, "scenes", "pendulum.yaml")
    text = open(path).read()
    by_file = flexmbd.load(path, set={"solver.t_end": 0.5}).run()
    by_text = flexmbd.load(text, set={"solver.t_end": 0.5}).run()
    scene = {"solver": {"t_end": 0.5, "rtol": 1e-8, "atol": 1e-10, "output_step": 0.01}, "gravity": [0.0, -9.81],
             "bodies": [{"name": "bob", "type": "rigid", "mass": 1.0, "inertia": 1e-6,
                         "position": [0.17364817766693, 0.98480775301221], "angle": 2.96705972839036}],
             "joints": [{"name": "pin", "type": "revolute", "body1": "ground", "body2": "bob",
                         "point1": [0.0, 0.0], "point2": [0.0, 1.0]}],
             "outputs": by_file.columns[1:]}
    by_dict = flexmbd.load(scene).run()
    dict_file = os.path.join(out, "dict.yaml")  # the dict as the YAML it is loaded as, run from a file
    with open(dict_file, "w") as f:
        f.write(flexmbd.scene_text(scene))
    for r, ref in ((by_text, by_file), (by_dict, flexmbd.load(dict_file).run())):
        assert r.columns == ref.columns
        assert np.array_equal(r.values, ref.values)
    # a regression reference (with its '#' lines) reads back; its rows (every 5th output time) are
    # the run's rows at those times: compared there (compare evaluates at the first file's rows)
    ref = flexmbd.Result.from_csv(os.path.join(SRC, "scenes", "pendulum.ref.csv"))
    cmp = flexmbd.compare(ref, by_file, columns=["bob.theta"])
    assert cmp["bob.theta"]["rows"] == 11 and cmp["bob.theta"]["max_abs"] < 1e-9


def test_dict_error_points_into_its_text():
    scene = {"solver": {"t_end": 1}, "bodies": [{"name": "bob", "type": "rigid", "mass": -1.0, "inertia": 1.0}]}
    with pytest.raises(flexmbd.SceneError) as e:
        flexmbd.load(scene)
    lines = flexmbd.scene_text(scene).splitlines()
    assert e.value.file == "<dict>"
    assert lines[e.value.line - 1][e.value.column - 1:].startswith("-1.0"), (str(e.value), lines)
    assert "mass" in e.value.message


def test_t_end_and_solver_failure_keeps_rows():
    m = flexmbd.load(os.path.join(SRC, "scenes", "paper", "spinup_w4.yaml"), set={"bodies.beam.model": "zoac"})
    short = m.run(t_end=2.0)
    assert short.t[-1] == 2.0 and short.status == "ok"
    with pytest.raises(flexmbd.SolverError) as e:
        m.run()  # ZOAC spun above its first bending frequency diverges (README): exit 3
    r = e.value.result
    assert r.status == "failed" and 2.0 < r.t[-1] < 20.0 and r.stats["t_reached"] >= r.t[-1]
    assert "ZOAC" in e.value.message
    # the rows so far are the run's rows, to the tolerance (step limits scale with t_end)
    scale = np.ptp(r.values, axis=0) + 1e-300
    assert (np.abs(r.values[: len(short)] - short.values) / scale).max() < 1e-4


def test_to_pandas():
    pd = pytest.importorskip("pandas")
    r = flexmbd.load(os.path.join(SRC, "scenes", "pendulum.yaml"), set={"solver.t_end": 0.1}).run()
    df = r.to_pandas()
    assert isinstance(df, pd.DataFrame) and np.array_equal(df["bob.x"].to_numpy(), r["bob.x"])
