"""flexmbd.view and Result._repr_html_: the page of `flexmbd view` built in this process from the
same template file, byte for byte the command's for the same run, scene, options and title; in a
notebook the page sits in an iframe; a run that cannot be drawn says why."""
import html
import os
import re

import pytest

import flexmbd
from flexmbd import view_page
from conftest import SRC, cli

SPIN = os.path.join(SRC, "scenes", "paper", "spinup_w4.yaml")
MECHANISM = os.path.join(SRC, "tests", "ux", "scenes", "vtk_mechanism.yaml")
SPATIAL = os.path.join(SRC, "tests", "ux", "scenes", "spatial_view.yaml")  # a top and a spherical pendulum
BEAM_OUTPUTS = {"solver.t_end": 1, "outputs": "[beam.x, beam.y, beam.theta, beam.shape, beam.tip_v, energy.total]"}


def cli_page(out, scene, sets, *extra):
    csv, page = os.path.join(out, "run.csv"), os.path.join(out, "cli.html")
    args = [a for k, v in sets.items() for a in ("--set", f"{k}={v}")]
    rc, _, err = cli("run", scene, *args, "-o", csv)
    assert rc == 0, err
    rc, _, err = cli("view", csv, scene, *args, "-o", page, *extra)
    assert rc == 0, err
    with open(page, encoding="utf-8") as f:
        return csv, f.read()


@pytest.mark.parametrize("scene,sets,columns,scale", [
    (SPIN, BEAM_OUTPUTS, None, 1.0),
    (SPIN, BEAM_OUTPUTS, ["energy.total", "beam.tip_v"], 20.0),
    (SPIN, dict(BEAM_OUTPUTS, outputs="[beam.x, beam.y, beam.theta, beam.shape_5]"), None, 1.0),  # resampled stations
    (SPIN, dict(BEAM_OUTPUTS, outputs="[beam.shape, beam.tip_v]"), None, 1.0),  # no frame: a note
    (MECHANISM, {}, None, 1.0),  # joints, a spring, a body not drawn
    (SPATIAL, {}, None, 1.0),  # dimension 3: frames from x, y, z, qw..qz, the 3D view
    (SPATIAL, {"outputs": "[top.x, top.y, top.z, top.qw, top.qx, top.qy, top.qz, bob.x]"}, None, 1.0),  # a note
])
def test_page_is_the_commands(out, scene, sets, columns, scale):
    extra = (["--columns", ",".join(columns)] if columns else []) + (["--scale", repr(scale)] if scale != 1 else [])
    csv, expected = cli_page(out, scene, sets, *extra)
    model = flexmbd.load(scene, set=sets)
    result = model.run()
    got = view_page.page(result, model, columns=columns, scale=scale, title=f"{scene}, {csv}")
    assert got == expected
    # the same from the CSV read back (the numbers the command drew)
    assert view_page.page(flexmbd.Result.from_csv(csv), model, columns=columns, scale=scale,
                          title=f"{scene}, {csv}") == expected


def test_repr_html_is_the_page_in_an_iframe(out):
    result = flexmbd.load(SPIN, set=BEAM_OUTPUTS).run()
    shown = result._repr_html_()
    m = re.fullmatch(r'<iframe srcdoc="([^"]*)" style="[^"]*" title="flexmbd view"></iframe>', shown, re.S)
    assert m, shown[:200]
    page = html.unescape(m.group(1))
    assert page == flexmbd.view(result)
    assert page.startswith("<!DOCTYPE html>") and "/*FMB_VIEW_DATA*/null" not in page and '"shape":[[' in page
    path = os.path.join(out, "run.html")
    assert flexmbd.view(result, path=path) == page and open(path, encoding="utf-8").read() == page
    # a run with t_end asked of run(): drawn from the scene it ran (reloaded with that t_end)
    short = flexmbd.load(SPIN, set=BEAM_OUTPUTS).run(t_end=0.5)
    assert '"t":[0,0.01,' in flexmbd.view(short) and "<iframe" in short._repr_html_()


def test_repr_html_says_why_not(out):
    plain = flexmbd.load(SPIN, set={"solver.t_end": 0.2}).run()  # no frame or shape columns
    shown = plain._repr_html_()
    assert "no animation" in shown and "nothing to draw" in shown and "beam.shape" in shown
    path = os.path.join(out, "r.csv")
    plain.to_csv(path)
    shown = flexmbd.Result.from_csv(path)._repr_html_()
    assert "does not know its scene" in shown
    with pytest.raises(ValueError, match="no column 'nope' to plot"):
        flexmbd.view(flexmbd.load(SPIN, set=BEAM_OUTPUTS).run(), columns=["nope"])


def test_default_column_on_the_csv_digits(out):
    """the column the plot opens on is chosen on the digits the page and the CSV carry (%.12g), as
    the command reads them: two columns whose motions differ only beyond the 12th digit tie, and a
    tie goes to the first (a page of the run in memory once chose the second)"""
    scene = os.path.join(SRC, "scenes", "pendulum.yaml")
    model = flexmbd.load(scene, set={"solver.t_end": 0.02})
    run = model.run()
    values = run.values[:2].copy()
    names = list(run.columns)
    for c in range(1, len(names)):
        if names[c] not in ("bob.x", "bob.y", "bob.theta"):
            values[:, c] = 0.25  # held: no motion
    values[:, names.index("bob.vx")] = [-0.5, 0.5]
    values[:, names.index("bob.vy")] = [-0.5, 0.5 + 1e-14]  # the same range and scale to 12 digits
    memory = flexmbd.Result(names, values, dict(run.stats))
    csv, page = os.path.join(out, "tie.csv"), os.path.join(out, "tie.html")
    memory.to_csv(csv)
    rc, _, err = cli("view", csv, scene, "--set", "solver.t_end=0.02", "-o", page)
    assert rc == 0, err
    with open(page, encoding="utf-8") as f:
        expected = f.read()
    title = f"{scene}, {csv}"
    assert f'"plot":[{names.index("bob.vx") - 1}]' in expected  # the first of the tie
    assert view_page.page(memory, model, title=title) == expected
    assert view_page.page(flexmbd.Result.from_csv(csv), model, title=title) == expected
