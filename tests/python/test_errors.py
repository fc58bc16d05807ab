"""SceneError for every case of the bad-scene catalogue (tests/bad_scenes/expected.txt): the same
file:line:column, code and message as the command line, str() its exact line."""
import os
import warnings

import pytest

import flexmbd
from conftest import SRC, cli

CATALOGUE = os.path.join(SRC, "tests", "bad_scenes")


def cases():
    for line in open(os.path.join(CATALOGUE, "expected.txt"), encoding="utf-8"):
        if line.startswith("#") or not line.strip():
            continue
        parts = line.rstrip("\n").split("\t")
        file, code, where, frag = parts[:4]
        yield pytest.param(file, int(code), where, frag, parts[4] if len(parts) > 4 else None, id=file)


@pytest.mark.parametrize("file,code,where,frag,override", list(cases()))
def test_bad_scene(file, code, where, frag, override, out):
    scene = os.path.join(CATALOGUE, file)
    sets = [override] if override else []  # the --set string itself (95: one without '=')
    args = ["run", scene, "-o", os.path.join(out, "x.csv")] + (["--set", override] if override else [])
    rc, _, err = cli(*args)
    cli_line = [l for l in err.splitlines() if "warning: " not in l][0]  # plausibility warnings may come first
    with pytest.raises(flexmbd.FlexmbdError) as e, warnings.catch_warnings():
        warnings.simplefilter("ignore", flexmbd.FlexmbdWarning)  # those warnings, as FlexmbdWarning
        flexmbd.load(scene, set=sets).run()  # where '-' or 'run:': found when the run projects the pose
    assert isinstance(e.value, flexmbd.SceneError) and e.value.code == code == rc
    assert str(e.value) == cli_line
    assert frag in e.value.message
    if where == "--set":
        assert e.value.file == "--set" and e.value.line == 0 and e.value.message.startswith(override + ": ")
    elif where == "-":
        assert e.value.file == scene and e.value.line == 0
    else:
        line, col = (int(x) for x in where.split(":")[-2:])  # LINE:COL or run:LINE:COL
        assert (e.value.file, e.value.line, e.value.column) == (scene, line, col)


def test_missing_file_and_plugin():
    with pytest.raises(flexmbd.SceneError) as e:
        flexmbd.load("no/such/scene.yaml")
    assert e.value.file == "no/such/scene.yaml" and str(e.value).startswith("no/such/scene.yaml: error: ")
    with pytest.raises(flexmbd.SceneError) as e:
        flexmbd.load(os.path.join(SRC, "scenes", "pendulum.yaml"), plugins=["/nonexistent/plugin.so"])
    assert "plugin.so" in str(e.value)


def test_library_warnings_become_python_warnings():
    """a load-time warning (an angle of 170 taken as radians) arrives as FlexmbdWarning with the
    text the command line prints"""
    scene = os.path.join(SRC, "scenes", "pendulum.yaml")
    _, _, err = cli("check", scene, "--set", "bodies.bob.angle=170")
    cli_warning = [l for l in err.splitlines() if "warning:" in l][0]
    with pytest.warns(flexmbd.FlexmbdWarning) as w:
        flexmbd.load(scene, set={"bodies.bob.angle": 170})
    assert [str(x.message) for x in w] == [cli_warning]
