"""Shared fixtures of the Python package's tests: where the sources, the build and the program are.
ctest sets FLEXMBD_* (tests/python/CMakeLists.txt); run by hand from the repository root,
`PYTHONPATH=python python3 -m pytest tests/python` finds build/ by itself."""
import os
import subprocess

import pytest

HERE = os.path.dirname(os.path.abspath(__file__))
SRC = os.environ.get("FLEXMBD_SOURCE_DIR", os.path.normpath(os.path.join(HERE, "..", "..")))
BUILD = os.environ.get("FLEXMBD_BUILD_DIR", os.path.join(SRC, "build"))
PROGRAM = os.environ.get("FLEXMBD_PROGRAM", os.path.join(BUILD, "flexmbd"))
OUT = os.environ.get("FLEXMBD_TEST_OUT", os.path.join(BUILD, "test-out", "python"))


@pytest.fixture
def out(request):
    """a fresh folder for one test's files"""
    d = os.path.join(OUT, request.node.name.replace("/", "_").replace("[", "_").replace("]", ""))
    subprocess.run(["rm", "-rf", d], check=True)
    os.makedirs(d)
    return d


def cli(*args, cwd=None):
    """the flexmbd program: (exit code, stdout, stderr)"""
    p = subprocess.run([PROGRAM, *args], capture_output=True, text=True, cwd=cwd)
    return p.returncode, p.stdout, p.stderr


def scenes():
    """every shipped scene, scenes/**/*.yaml"""
    found = []
    for root, _, files in os.walk(os.path.join(SRC, "scenes")):
        found += [os.path.join(root, f) for f in files if f.endswith(".yaml")]
    return sorted(found)
