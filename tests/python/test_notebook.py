"""docs/tutorial.ipynb executed as a reader would (Debian's python3-nbclient and python3-ipykernel):
every cell runs without an error from docs/ (the notebook's folder), its files go to this test's
folder (FLEXMBD_TUTORIAL_OUT), not the checkout, and what it shows is what it claims: the run's
numbers (checked against a run here), the plots as images, the comparison's line as
`flexmbd compare` prints it, and the animation as the view page inline."""
import html
import os

import numpy as np
import pytest

import flexmbd
from conftest import SRC, cli

nbformat = pytest.importorskip("nbformat")
nbclient = pytest.importorskip("nbclient")

NOTEBOOK = os.path.join(SRC, "docs", "tutorial.ipynb")


def test_tutorial_notebook_runs(out, monkeypatch):
    monkeypatch.setenv("FLEXMBD_TUTORIAL_OUT", out)  # the kernel inherits it
    monkeypatch.setenv("MPLBACKEND", "module://matplotlib_inline.backend_inline")
    nb = nbformat.read(NOTEBOOK, as_version=4)
    assert all(not c.get("outputs") for c in nb.cells if c.cell_type == "code"), "commit the notebook without outputs"
    client = nbclient.NotebookClient(nb, timeout=600, kernel_name="python3",
                                     resources={"metadata": {"path": os.path.join(SRC, "docs")}})
    client.execute()  # raises CellExecutionError with the cell and traceback on an error
    nbformat.write(nb, os.path.join(out, "tutorial.ipynb"))  # the executed notebook, for a look
    code = [c for c in nb.cells if c.cell_type == "code"]

    def text(cell):
        return "".join(o.get("text", "") for o in cell.outputs if o.output_type == "stream" and o.name == "stdout")

    def has(cell, mime):
        return any(mime in o.get("data", {}) for o in cell.outputs)

    assert text(code[0]).strip() == f"flexmbd {flexmbd.__version__}"
    # the run: its numbers are the ones of the same run here, its CSV the command line's
    scene = os.path.join(SRC, "scenes", "paper", "spinup_w4.yaml")
    r = flexmbd.load(scene).run()
    tip = abs(r["beam.tip_v"])
    assert f"{len(r)} rows; peak |tip_v| {tip.max():.4f} m at t = {r.t[tip.argmax()]:.2f} s" in text(code[1])
    rc, _, err = cli("run", scene, "-o", os.path.join(out, "cli.csv"))
    assert rc == 0, err
    assert open(os.path.join(out, "w4.csv"), "rb").read() == open(os.path.join(out, "cli.csv"), "rb").read()
    assert has(code[2], "image/png") and has(code[5], "image/png")
    assert os.path.getsize(os.path.join(out, "w4.png")) > 10000
    assert os.path.getsize(os.path.join(out, "w4_models.png")) > 10000
    sweep = text(code[3]).splitlines()
    assert len(sweep) == 4 and all(" ok " in line for line in sweep), sweep
    assert text(code[4]).startswith("ZOAC: failed after ")  # no centrifugal stiffening: diverges
    # the comparison's line is what flexmbd compare prints for the two runs' CSVs
    foac, complete = os.path.join(out, "foac.csv"), os.path.join(out, "complete.csv")
    flexmbd.load(scene, set={"bodies.beam.model": "foac"}).run().to_csv(foac)
    r.to_csv(complete)
    rc, stdout, _ = cli("compare", foac, complete, "--columns", "beam.tip_v", "--rtol", "0.01")
    assert stdout.strip() == text(code[6]).splitlines()[-1], (stdout, text(code[6]))
    # the animation: the view page inline, and the same page written to the output folder
    shown = [o for o in code[7].outputs if "text/html" in o.get("data", {})]
    assert len(shown) == 1
    frame = shown[0]["data"]["text/html"]
    assert frame.startswith("<iframe srcdoc=")
    page = open(os.path.join(out, "w4_view.html"), encoding="utf-8").read()
    assert html.unescape(frame.split('srcdoc="', 1)[1].split('" style=', 1)[0]) == page
    assert '"shape":[[' in page and '"t":[0,0.05,' in page
    # nothing written into the checkout
    assert not os.path.exists(os.path.join(SRC, "docs", "out"))
