"""flexmbd.compare in this process gives what `flexmbd compare` prints, on the same files: the
`compare:` lines (text), the exit code (ok), what it says about failures, and the refusals (exit 2)
as ValueError with the command's message. The rule itself is tools/cmd_compare.c's; the cases here
are the shipped references against each other and files made to reach each branch of it:
interpolation between rows of another grid, a shorter run, NaN, --columns, --common, bad files."""
import glob
import math
import os

import numpy as np
import pytest

import flexmbd
from conftest import SRC, cli

REFS = sorted(glob.glob(os.path.join(SRC, "scenes", "*.ref.csv"))) + [os.path.join(SRC, "scenes", "paper", "pendulum.ref.csv")]


def options(kw):
    args = []
    if kw.get("columns"):
        args += ["--columns", ",".join(kw["columns"])]
    for k in ("rtol", "atol"):
        if k in kw:
            args += [f"--{k}", repr(kw[k])]
    if kw.get("common"):
        args.append("--common")
    return args


def same_as_cli(a, b, **kw):
    """compare(a, b, **kw) against `flexmbd compare a b ...`; returns the Comparison (None when refused)"""
    rc, stdout, stderr = cli("compare", a, b, *options(kw))
    try:
        c = flexmbd.compare(a, b, **kw)
    except ValueError as e:
        assert rc == 2, (a, b, kw, rc, stderr)
        assert str(e) == stderr.strip()
        return None
    assert rc in (0, 1), stderr
    assert c.lines == [x for x in stdout.splitlines() if x.startswith("compare: ")]
    assert c.exit_code == rc and c.ok == (rc == 0)
    assert c.messages == stderr.strip()
    for line in c.lines:  # the dict holds the printed numbers
        fields = dict(item.split("=", 1) for item in line.split()[1:])
        e = c[fields.pop("column")]
        for k, v in fields.items():
            assert (str(e[k]) == v) if k == "status" else (float(v) == e[k] or (math.isnan(e[k]) and v in ("nan", "-nan"))), (k, v)
    return c


@pytest.mark.parametrize("kw", [{}, {"common": True}, {"rtol": 0.01}, {"atol": 1e-3, "common": True}])
def test_shipped_references(kw):
    """every pair of shipped references: same columns (self), others (refused or failing)"""
    n = 0
    for a in REFS:
        for b in REFS:
            if same_as_cli(a, b, **kw) is not None:
                n += 1
    assert n >= len(REFS)


def write(path, header, rows, meta=()):
    with open(path, "w") as f:
        for m in meta:
            f.write(f"#{m}\n")
        f.write(header + "\n")
        for r in rows:
            f.write(",".join(r if isinstance(r, (list, tuple)) else [r]) + "\n")
    return path


def test_interpolation_shorter_run_and_nan(out):
    """another output grid (interpolated), a run that stops early, a NaN, a zero reference"""
    t_ref = np.linspace(0.0, 2.0, 21)
    t_out = np.linspace(0.0, 1.7, 18) + 0.013  # between the reference's rows, and ends before it
    ref = write(os.path.join(out, "ref.csv"), "t,a.x,a.y,z.zero",
                [[repr(t), repr(np.sin(t)), repr(t * t), "0"] for t in t_ref])
    run = write(os.path.join(out, "out.csv"), "t,a.x,a.y,z.zero",
                [[repr(t), repr(np.sin(t) + 1e-4 * t), "nan" if k == 5 else repr(t * t), "1e-9"]
                 for k, t in enumerate(t_out)])
    c = same_as_cli(run, ref, rtol=1e-3)
    assert not c.ok and "a shorter run" in c.messages
    assert math.isnan(c["a.y"]["max_abs"]) and c["a.y"]["status"] == "beyond"
    assert c["z.zero"]["ref_scale"] == 0.0 and c["z.zero"]["max_rel"] == c["z.zero"]["max_abs"]
    # the interpolated reference: sin between rows 0.1 apart, its chord error ~ h^2/8 |sin''|, far below 1e-3
    assert 1e-5 < c["a.x"]["max_abs"] < 2e-3 and c["a.x"]["rows"] == 18
    same_as_cli(run, ref, columns=["a.x"], atol=1.0)
    same_as_cli(ref, run, atol=1.0)  # the reference's rows outside the run's span are not compared
    same_as_cli(run, ref, columns=["a.x", "nope"])  # refused: no such column
    same_as_cli(run, ref, columns=["t"])  # refused: t is not a column to compare


def test_column_sets(out):
    ref = write(os.path.join(out, "ref.csv"), "t,a,b", [["0", "1", "2"], ["1", "3", "4"]], meta=["rtol=1e-3"])
    extra = write(os.path.join(out, "extra.csv"), "t,a,b,c", [["0", "1", "2", "5"], ["1", "3", "4.5", "6"]])
    same_as_cli(extra, ref)
    same_as_cli(ref, extra)
    assert same_as_cli(extra, ref, common=True).ok
    later = write(os.path.join(out, "later.csv"), "t,a,b", [["5", "1", "2"], ["6", "1", "2"]])
    same_as_cli(later, ref)  # refused: no common time


BAD_AND_ODD = [
    ("empty", ""),
    ("only_meta", "#x\n"),
    ("no_name", "t,,a\n0,1,2\n"),
    ("first_not_t", "time,a\n0,1\n"),
    ("twice", "t,a,a\n0,1,2\n"),
    ("no_rows", "t,a\n\n"),
    ("short_row", "t,a\n0,1\n1\n"),
    ("trailing_space", "t,a\n0,1 \n"),
    ("not_a_number", "t,a\n0,x\n"),
    ("time_back", "t,a\n0,1\n1,2\n0.5,3\nbad\n"),
    ("time_nan", "t,a\nnan,1\n"),
    ("crlf_hex_inf", "t,a\r\n0,0x1p-2\r\n\r\n1, -inf\r\n2,+1.5e0\r\n"),
    # a spreadsheet's CSV: padded cells, a byte-order mark on the first line (only there)
    ("padded", "t,a\n0 ,\t1\t\n1 , 0x1p1 \r\n2,inf \n"),
    ("blank_then_text", "t,a\n0,1 x\n"),
    ("blank_cell", "t,a\n0, \n"),
    ("bom", "\ufefft,a\r\n0,1\r\n"),
    ("bom_meta", "\ufeff# rtol=1e-3\nt,a\n0,1\n"),
    ("bom_only", "\ufeff"),
    ("bom_blank_line", "\ufeff\r\nt,a\n0,1\n"),
    ("bom_second_line", "t,a\n\ufeff0,1\n"),
    ("bom_twice", "\ufeff\ufefft,a\n0,1\n"),
    # the mark counts towards the first line's length limit (1 << 20 bytes): this one is 2 over
    ("bom_long_line", "\ufeff#" + "x" * ((1 << 20) - 2) + "\nt,a\n0,1\n"),
]


@pytest.mark.parametrize("name,text", BAD_AND_ODD, ids=[name for name, _ in BAD_AND_ODD])
def test_bad_and_odd_files(out, name, text):
    """the reader's messages (file:line: what was expected) and the forms strtod accepts"""
    path = os.path.join(out, name + ".csv")
    with open(path, "wb") as f:
        f.write(text.encode("utf-8"))
    ok = write(os.path.join(out, "ok.csv"), "t,a", [["0", "1"], ["2", "1"]])
    same_as_cli(path, ok)
    same_as_cli(ok, path)


def test_non_finite_reference(out):
    """a reference column all NaN (range -inf: rtol 0 gives tol = 0 * -inf, a NaN printed "-nan" by
    glibc) or with infinities"""
    ref = write(os.path.join(out, "ref.csv"), "t,a,b", [["0", "nan", "inf"], ["1", "nan", "inf"]])
    run = write(os.path.join(out, "out.csv"), "t,a,b", [["0", "1", "2"], ["1", "1", "2"]])
    for kw in ({"rtol": 0.0}, {"rtol": 0.5}, {"atol": 1.0}, {}):
        same_as_cli(run, ref, **kw)
        same_as_cli(ref, run, **kw)


def test_missing_file_and_folder(out):
    ok = write(os.path.join(out, "ok.csv"), "t,a", [["0", "1"]])
    same_as_cli(os.path.join(out, "none.csv"), ok)
    same_as_cli(out, ok)


def test_result_is_compared_as_its_csv(out):
    """a Result compares as the CSV it writes: the numbers of `flexmbd compare` on that file"""
    scene = os.path.join(SRC, "scenes", "pendulum.yaml")
    a = flexmbd.load(scene, set={"solver.t_end": 1}).run()
    b = flexmbd.load(scene, set={"solver.t_end": 1, "solver.output_step": 0.03, "solver.rtol": 1e-6}).run()
    pa, pb = os.path.join(out, "a.csv"), os.path.join(out, "b.csv")
    a.to_csv(pa)
    b.to_csv(pb)
    files = same_as_cli(pa, pb, rtol=1e-4)
    mem = flexmbd.compare(a, b, rtol=1e-4)
    assert mem == files and mem.exit_code == files.exit_code
    assert files["bob.x"]["max_abs"] > 0 and files.lines == mem.lines
    with pytest.raises(ValueError, match="needs a number >= 0"):
        flexmbd.compare(a, b, rtol=-1)


def test_no_program_needed(monkeypatch, out):
    """compare runs without the flexmbd program (none on PATH, FLEXMBD_PROGRAM unset)"""
    monkeypatch.delenv("FLEXMBD_PROGRAM", raising=False)
    monkeypatch.setenv("PATH", out)
    ref = os.path.join(SRC, "scenes", "pendulum.ref.csv")
    assert flexmbd.compare(ref, ref, rtol=0.0).ok
