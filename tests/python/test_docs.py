"""docs/python.md (and README.md's ```python blocks) run as written: docs/python.md's ```python blocks in order in one session (one namespace)
and its ```sh blocks with bash, in a scratch folder that links the repository's folders (as the
docs_commands test does for the other pages; docs_commands delegates docs/python.md here). `python3`
in the sh blocks is this interpreter; `sh norun` / `python norun` blocks are shown only. A
`# prints: TEXT` comment in a python block is checked against what the block printed."""
import contextlib
import io
import os
import subprocess
import sys
import warnings

from conftest import BUILD, SRC

sys.path.insert(0, os.path.join(SRC, "tests"))
from markdown_blocks import PRINTS, blocks, match_shown  # noqa: E402  (tests/markdown_blocks.py, shared with tests/ux/test_docs.py)

PAGE = os.path.join(SRC, "docs", "python.md")
def test_python_md_runs(out):
    assert run_page(PAGE, out) >= 10
    for png in ("w15_tip.png", "w15_models.png", "campbell.png"):
        assert os.path.getsize(os.path.join(out, "out", png)) > 10000, png


def test_readme_python_blocks_run(out):
    assert run_page(os.path.join(SRC, "README.md"), out, langs=("python",)) >= 1


def run_page(page, out, langs=("sh", "bash", "python")):
    """run the page's blocks in `out`; returns how many ran"""
    doc = os.path.relpath(page, SRC)
    for entry in os.listdir(SRC):
        if entry not in ("build", ".git", "out") and not entry.startswith("."):  # out/: the page writes there
            os.symlink(os.path.join(SRC, entry), os.path.join(out, entry))
    os.symlink(BUILD, os.path.join(out, "build"))
    shim = os.path.join(out, ".bin")
    os.makedirs(shim)
    os.symlink(sys.executable, os.path.join(shim, "python3"))
    # the sh blocks find the library as a reader would (no FLEXMBD_LIBRARY: build/ beside python/,
    # or the installed prefix's _location.py)
    env = {k: v for k, v in os.environ.items() if not k.startswith("FLEXMBD_") and k != "PYTHONPATH"}
    env.update(PATH=os.pathsep.join([shim, BUILD, os.environ.get("PATH", "")]), HOME=out, MPLBACKEND="Agg")
    namespace = {"__name__": "__docs__"}
    cwd = os.getcwd()
    os.chdir(out)
    ran = 0
    try:
        for line, info, code in blocks(page):
            if "norun" in info or not info or info[0] not in langs:
                continue
            where = f"{doc}:{line}"
            if info[0] in ("sh", "bash"):
                p = subprocess.run(["bash", "-e", "-c", "\n".join(code)], cwd=out, env=env, capture_output=True, text=True)
                assert p.returncode == 0, f"{where}: exit {p.returncode}: {p.stderr[-800:]}"
            elif info[0] == "python":
                buf = io.StringIO()
                with contextlib.redirect_stdout(buf), warnings.catch_warnings():
                    warnings.simplefilter("error", DeprecationWarning)
                    try:
                        exec(compile("\n".join(code) + "\n", where, "exec"), namespace)
                    except Exception as e:
                        raise AssertionError(f"{where}: {type(e).__name__}: {e}\noutput so far:\n{buf.getvalue()}")
                print(f"--- {where}\n{buf.getvalue()}")
                # what a `# prints: ...` comment shows is printed by its block, in order, each
                # number within its stated tolerance (docs/regression.md, "Numbers in the docs")
                printed = buf.getvalue().split("\n")
                for k, text in enumerate(code):
                    shown = PRINTS.search(text)
                    if not shown:
                        continue
                    why = match_shown(shown.group(1), "\n".join(printed))
                    assert why is None, f"{doc}:{line + 1 + k}: # prints: {shown.group(1)}: {why}"
                    # later annotations match later lines
                    first = next(i for i, l in enumerate(printed) if match_shown(shown.group(1), l) is None)
                    printed = printed[first + 1:]
            else:
                continue
            ran += 1
    finally:
        os.chdir(cwd)
    return ran
