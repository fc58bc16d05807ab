#!/usr/bin/env python3
"""test_doc_numbers.py SOURCE_DIR — no number in the documentation about a run goes stale unseen.

Every number README.md or a page of docs/ states about a run (steps, CPU time, a ratio or a
percentage of cost, an error, a value a block prints) is one of:
  1. shown as the output of a block the docs tests run and compare: a `console` block's output
     line, or a `# prints: TEXT` comment in a ```python block of a page tests/python/test_docs.py
     runs — each number within the tolerance written after it (`8993 ±5%`) or as rounded
     (tests/markdown_blocks.py, match_shown); prose may quote such a number (it is checked
     against the shown one, within the same tolerance)
     (a number of three significant digits or more);
  2. in the scope of a marker `<!-- measured: bench/SCRIPT @ COMMIT on MACHINE -->`: on a line of
     its own it covers the rest of the section it stands in (subsections included), at the end of
     a line of text that paragraph or table. SCRIPT exists under bench/ (or tests/, tools/ for
     what a test or a tool prints, never a time: speed is measured only in bench/), COMMIT (or
     FIRST..LAST) is a commit of this history (checked when git is at hand), MACHINE is named.
  A number stated before this check whose source was not found carries `<!-- unchecked: REASON -->`
  (same scopes): listed, and no more of them than UNCHECKED_MAX.
The run numbers are found by their context, not by a list (docs/regression.md, "Numbers in the
docs", gives the rules and the reasons): a count followed by steps, restarts, Newton
iterations, residuals, Jacobians or error-test failures (or `steps=N`, or after `took`); a time of CPU or of a
run (N s / ms / µs in a sentence about CPU, wall time or what a run took or costs); a ratio (N×,
N times faster, slower, more, less); a percentage in a sentence about cost or time; an error
(a number in scientific notation in a sentence about an error or a difference that is not a
tolerance or a bound given to the solver). Code blocks: a comment on a `print(` line that holds
a digit must be a `# prints:` annotation; the output lines of a `console norun` block and the
comments of any block are read as prose. Exit 1 with document:line and the number for each
number that is neither compared nor measured, or for a marker that does not hold."""
import os
import re
import subprocess
import sys

sys.path.insert(0, os.path.join(os.path.dirname(os.path.abspath(__file__)), ".."))
from markdown_blocks import PRINTS, PYTHON_PAGES, blocks, shown_numbers  # noqa: E402

N = r"(?<![\w.\-+/±])(\d[\d,]*(?:\.\d+)?(?:[eE][-+−]?\d+)?|\d+(?:\.\d+)?\s*·\s*10[⁻⁰¹²³⁴⁵⁶⁷⁸⁹]+)"
RANGE = N + r"(?:\s*(?:–|-|to|or)\s*" + N + r")?"
COUNTS = r"(?:steps?|restarts?|Newton iterations?|iterations|residuals?(?: evaluations)?|Jacobians?|error[- ]test fail\w*)"
PATTERNS = [
    # a count of the integrator's work: "8,993 steps", "2,851 more steps", "steps=8993"
    ("count", re.compile(RANGE + r"\s+(?:(?:more|fewer|extra|short|small|failed|accepted|rejected|integration|"
                         r"integrator|solver|BDF|Radau|IDA|Newton|million|M|k|thousand|of|them|its|the)\s+){0,2}?"
                         + COUNTS + r"\b(?!=)", re.I)),
    ("count", re.compile(r"\b(?:steps|newton_iters|residuals|jacobians|error_test_fails)=" + N)),
    # what a run took: "took 48,600", "took about 0.5 s"
    ("count", re.compile(r"\btook\s+(?:about\s+|~\s*|only\s+)?" + RANGE + r"(?!\d|[.,]\d)(?!\s?(?:s|ms|µs|us|seconds|min)\b)")),
    # a ratio: "1.6×", "1.6–1.9×", "3x faster", "2 times slower"
    ("ratio", re.compile(RANGE + r"\s?[×x](?=\s*(?:[),.;:]|$|(?:faster|slower|more|less|fewer|the|as|longer|shorter|"
                         r"larger|smaller|cheaper|speed-?up|overhead|at|on|with|from|for|in|over)\b))", re.M)),
    ("ratio", re.compile(RANGE + r"\s+times\s+(?:faster|slower|more|less|fewer|as|the)\b", re.I)),
]
TAKES = re.compile(r"\b(?:takes|took|needs|needed)\s+(?:about\s+|~\s*)?" + N
                   + r"(?!\d|[.,]\d)(?!\s?(?:s|ms|µs|us|seconds|min|m|rad|elements?|%|×|x)\b)(?=\s*(?:[,.;)]|at\b|with\b|$))"
                   + r"|\b(?:and|against)\s+" + N + r"(?=\s+at\b)")
# a physical value counts in a sentence that says a run printed or reached it
VALUE = re.compile(RANGE + r"\s?(?:m|mm|rad|rad/s|J|N|W|m/s|N m)\b(?!/)(?!\s+(?:beam|bar|rod|blade|long|wide|arm|link))")
RESULT_WORDS = re.compile(r"\bprints?\b|\bprinted\b|\breach(?:es|ed)\b|\bdeflects\b|\bpeak\b|\bfinal\b|"
                          r"\bends at\b|\bswings\b|\bcomes out\b", re.I)
# a time, a percentage or an error counts only in a sentence about a run's cost or error
TIME = re.compile(RANGE + r"\s?(?:s|ms|µs|us|seconds|min)\b")
PERCENT = re.compile(RANGE + r"\s?%")
SCI = re.compile(r"(?<![\w.\-+/])(\d+(?:\.\d+)?[eE][-−]\d+|\d+(?:\.\d+)?\s*·\s*10[⁻⁰¹²³⁴⁵⁶⁷⁸⁹]+)")
COST_WORDS = re.compile(r"\bCPU\b|\bcpu_s\b|\bwall\b|\btook\b|\btakes\b|\bcost|\bfaster\b|\bslower\b|\bmedian|\boverhead\b|"
                        r"\bspent\b|\bruns? in\b|\btime per\b", re.I)
ERROR_WORDS = re.compile(r"\berror\b|\bdiffer|\bdeviat|\bdrift|\bmax_abs\b|\bmax_rel\b|\bagree", re.I)
# a number given to the solver or a test, not found by a run: rtol 1e-6, to 1e-6, below 1e-6
GIVEN = re.compile(r"(?:rtol|atol|tol\w*|tolerance|bound|below|under|within|to|than|≤|<|<=|=|of order|at most|"
                   r"threshold|limit|if|when|uses?|used|above|over|at|~|≈|≲|≳|[a-z_]+:|=\s*\[)\s*:?\s*$", re.I)
BOUND = re.compile(r"(?:\bup to|\bat most|\bat least|\bmax(?:imum)?(?: of)?|\bthan|\bevery|\bafter|\bwithin|"
                   r"\blimit(?: of)?|≤|<|>|≥|~)\s*$", re.I)
# a time given to the run, not measured: every 2 ms, for 3 s, t = 2 s, t_end 20 s, a timeout of 600 s
INPUT_TIME = re.compile(r"(?:\bevery|\bfor|\bat|\bof|\bafter|\bwithin|\bunder|\bover|\bto|\buntil|\bt\s*=|\bt_end|"
                        r"\bt_end:|\bstep|\bh\s*=|\bdefault|\btimeout|\babove|\bbelow|\bthan|\bfirst|\blast|\beach|"
                        r"\bup to|\bper|\bonly|\bby|\bthe|\bits|\bits first|\bits last|≤|<|>|=)\s*$", re.I)
MARKER = re.compile(r"<!--\s*(measured|unchecked):\s*(.*?)\s*-->")
MARKER_FORM = re.compile(r"^((?:bench|tests|tools)/\S+(?:\s*,\s*(?:bench|tests|tools)/\S+)*)\s+@\s+([0-9a-f]{7,40}(?:\.\.[0-9a-f]{7,40})?)\s+on\s+(\S.*)$")
# numbers under `<!-- unchecked: REASON -->` (stated before this check, source not yet found): they may only
# become fewer; lower this when you give some a block or a measured marker
UNCHECKED_MAX = 16
HEADING = re.compile(r"^(#{1,6})\s")


def sentences(text):
    """the sentences of a paragraph (a table row or a list item counts as one)"""
    return re.split(r"(?<=[.;:!?])\s+(?=[A-Z(`*])|\n(?=\s*[-*|]\s)", text)


def run_numbers(text):
    """[(number as written, kind)] of the numbers about a run in a piece of prose"""
    found = []
    for sentence in sentences(text):
        plain = re.sub(r"<!--.*?-->", "", sentence)
        for kind, pattern in PATTERNS:
            for m in pattern.finditer(plain):
                # a bound or a rate given, not a count found: up to 12 Newton iterations, 4 residuals per colour
                if BOUND.search(plain[:m.start()]) or re.match(r"\s*(?:per|each)\b", plain[m.end():]):
                    continue
                found += [(g, kind) for g in m.groups()[:2] if g]
        if re.search(r"\b" + COUNTS + r"\b", plain, re.I):
            # in a sentence about steps: "the spring-damper takes 2851", "and 11991 at 1 ms"
            for m in TAKES.finditer(plain):
                found += [(g, "count") for g in m.groups()[:2] if g]
        if RESULT_WORDS.search(plain):
            # a value a run reached: "the tip deflects 0.196 m", "peak 0.068 m", "prints 3.0032 rad/s"
            for m in VALUE.finditer(plain):
                if not GIVEN.search(plain[:m.start()]) and not BOUND.search(plain[:m.start()]):
                    found += [(g, "value") for g in m.groups()[:2] if g]
        cost, error = COST_WORDS.search(plain), ERROR_WORDS.search(plain)
        if cost:
            for m in TIME.finditer(plain):
                if not INPUT_TIME.search(plain[:m.start()]):
                    found += [(g, "time") for g in m.groups()[:2] if g]
        if cost or error:
            for m in PERCENT.finditer(plain):
                if not GIVEN.search(plain[:m.start()]):
                    found += [(g, "percentage") for g in m.groups()[:2] if g]
        if error:
            for m in SCI.finditer(plain):
                if not GIVEN.search(plain[:m.start()]):
                    found.append((m.group(1), "error"))
    kinds = {}
    for number, kind in found:  # one entry a number; a time is a time (measured only in bench/)
        if number not in kinds or kind == "time":
            kinds[number] = kind
    return list(kinds.items())


def value(number):
    n = number.replace(",", "").replace("−", "-")
    m = re.match(r"^(\d+(?:\.\d+)?)\s*·\s*10([⁻⁰¹²³⁴⁵⁶⁷⁸⁹]+)$", n)
    if m:
        sup = str.maketrans("⁻⁰¹²³⁴⁵⁶⁷⁸⁹", "-0123456789")
        return float(m.group(1)) * 10.0 ** int(m.group(2).translate(sup)), 0.0
    from markdown_blocks import half_unit
    return float(n), half_unit(n)


def git(*args):
    try:
        r = subprocess.run(["git", *args], cwd=SRC, capture_output=True, text=True)
        return r.returncode, r.stdout.strip()
    except OSError:
        return None, ""


_history = []


def history():
    """the commits HEAD descends from (read once)"""
    if not _history:
        _history.extend(git("rev-list", "HEAD")[1].split())
    return _history


def check_marker(doc, n, kind, text, failures):
    """a measured marker names scripts under bench/ (or tests/) that exist, a commit of this history and a
    machine; an unchecked marker gives a reason. Returns the sources (None for unchecked)"""
    if kind == "unchecked":
        if len(text) < 10:
            failures.append(f"{doc}:{n}: `<!-- unchecked: REASON -->` without a reason")
        return None
    m = MARKER_FORM.match(text)
    if not m:
        failures.append(f"{doc}:{n}: a measured marker reads `<!-- measured: bench/SCRIPT @ COMMIT on MACHINE -->`, "
                        f"not `{text}`")
        return []
    scripts = re.split(r"\s*,\s*", m.group(1))
    for script in scripts:
        if not os.path.isfile(os.path.join(SRC, script)):
            failures.append(f"{doc}:{n}: measured by {script}: no such file")
    for commit in m.group(2).split("..") if HAVE_GIT else []:  # one commit, or FIRST..LAST measured across
        if not any(c.startswith(commit) for c in history()):
            failures.append(f"{doc}:{n}: measured on {commit}: not a commit of this history")
    return scripts


def compared_numbers(doc, page_blocks, delegated):
    """[(value, tolerance)] of the numbers the docs tests compare on this page"""
    out = []
    for line, info, body in page_blocks:
        if "norun" in info or not info:
            continue
        shown = []
        if info[0] == "console" and not delegated:
            cmd = False
            for l in body:
                if l.startswith("$ "):
                    cmd = True
                elif l.strip() and cmd:
                    shown.append(l)
        elif info[0] == "python" and doc in PYTHON_PAGES:
            shown = [m.group(1) for m in map(PRINTS.search, body) if m]
        for text in shown:
            # a prose number may quote one of three significant digits or more (8993, 3.0032), not a
            # 2 or a 0.5 that any output holds
            out += [(v, tol) for v, tol, _, _, shown_text in shown_numbers(text) if significant(shown_text) >= 3]
    return out


def significant(shown):
    """significant digits of a number as written: 8993 -> 4, 0.0032 -> 2, 1.5e-3 -> 2"""
    mant = shown.lower().lstrip("+-").split("e")[0].replace(".", "").lstrip("0")
    return len(mant)


def check_page(doc, failures):
    path = os.path.join(SRC, doc)
    lines = open(path, encoding="utf-8").read().split("\n")
    page_blocks = list(blocks(path))
    delegated = any("<!-- commands run by:" in l for l in lines)
    compared = compared_numbers(doc, page_blocks, delegated)
    in_code = {}
    for line, info, body in page_blocks:
        for k in range(len(body) + 2):
            in_code[line + k] = (line, info)
    # measured scopes: from a marker to the next heading at or above its section's level
    measured = [None] * (len(lines) + 2)  # per line: the sources of the marker in scope (None: unchecked)
    level = 0
    for i, l in enumerate(lines, 1):
        h = HEADING.match(l) if i not in in_code else None
        if h:
            level = len(h.group(1))
        for m in MARKER.finditer(re.sub(r"`[^`]*`", "", l)) if i not in in_code else []:
            sources = check_marker(doc, i, m.group(1), m.group(2), failures)
            mark = ("unchecked", m.group(2)) if sources is None else ("measured", sources)
            if MARKER.sub("", l).strip():  # (the marker at the end of a line of text)
                # at the end of a line of text: that paragraph (or table, or list)
                a = b = i
                while a > 1 and lines[a - 2].strip() and a - 1 not in in_code:
                    a -= 1
                while b < len(lines) and lines[b].strip() and b + 1 not in in_code:
                    b += 1
                for j in range(a, b + 1):
                    measured[j] = mark
                continue
            for j in range(i, len(lines) + 1):
                hj = HEADING.match(lines[j - 1]) if j > i and j not in in_code else None
                if hj and len(hj.group(1)) <= level:  # (before the first heading: the whole page)
                    break
                measured[j] = mark
    # the pieces of text read as prose: paragraphs, code comments, norun console output
    pieces = []  # (first line number, [lines])
    para = []
    for i, l in enumerate(lines, 1):
        if i in in_code or not l.strip() or HEADING.match(l):
            if para:
                pieces.append((para[0][0], para))
            para = []
            continue
        para.append((i, l))
    if para:
        pieces.append((para[0][0], para))
    for line, info, body in page_blocks:
        lang = info[0] if info else ""
        runs = "norun" not in info
        for k, l in enumerate(body):
            n = line + 1 + k
            if lang == "console" and not l.startswith("$ "):
                if not runs or delegated:
                    pieces.append((n, [(n, l)]))
                continue
            comment = re.search(r"(?:^|\s)(?:#|//|/\*)\s*(.*)$", l)
            if not comment:
                continue
            if lang == "python" and PRINTS.search(l):
                if not runs or doc not in PYTHON_PAGES:
                    failures.append(f"{doc}:{n}: a `# prints:` comment in a block no test runs")
                continue
            if lang == "python" and "print(" in l and re.search(r"\d", comment.group(1)):
                failures.append(f"{doc}:{n}: a comment on a print line shows a number ({comment.group(1).strip()!r}): "
                                "write it as `# prints: TEXT`, which the docs test compares")
                continue
            pieces.append((n, [(n, comment.group(1))]))
    for _, para in pieces:
        text = "\n".join(l for _, l in para)
        for number, kind in run_numbers(text):
            where = next((n for n, l in para if number in l), para[0][0])
            v, half = value(number)
            if any(abs(v - c) <= tol + half + 1e-12 * abs(c) for c, tol in compared):
                continue
            if measured[where] and measured[where][0] == "unchecked":
                unchecked.append(f"{doc}:{where}: {number} ({kind})")
                continue
            if measured[where]:
                if kind == "time" and not any(src.startswith("bench/") for src in measured[where][1]):
                    failures.append(f"{doc}:{where}: {number} ({kind}) is a time, measured only in bench/ (the marker "
                                    f"names {', '.join(measured[where][1])})")
                continue
            failures.append(f"{doc}:{where}: {number} ({kind}) is neither printed by a block the docs test compares "
                            "nor in the scope of a `<!-- measured: bench/SCRIPT @ COMMIT on MACHINE -->` marker")


def self_test():
    """the check catches what it is for, on pages made here (a check that cannot fail is no check)"""
    global SRC, HAVE_GIT
    import tempfile
    from markdown_blocks import match_shown
    saved = SRC, HAVE_GIT, list(unchecked)
    cases = [  # (page, how many failures)
        ("The controller took 70,400 steps where the spring-damper took 48,600.\n", 2),
        ("It takes 70,400 steps where the spring-damper takes 48,600, and 88,100 at 1 ms.\n", 3),
        ("```console\n$ ./ctl\ncontroller: 8993 ±5% steps\n```\n\nIt takes 8,993 steps.\n", 0),
        ("```console\n$ ./ctl\ncontroller: 8993 ±5% steps\n```\n\nIt takes 70,400 steps.\n", 1),
        ("```console norun\n$ ./ctl\ncontroller: 8993 ±5% steps\n```\n\nIt takes 8,993 steps.\n", 1),
        ("```python\nprint(x)  # 3.0010\n```\n", 1),
        ("```python norun\nprint(x)  # prints: 3.0010\n```\n", 1),
        ("That costs 1 to 13 % more CPU; 1.5× slower at 64.\n", 3),
        ("## Cost\n<!-- measured: bench/x.sh @ abc1234 on a 2-core machine -->\n\nIt took 0.5 s of CPU, 2× faster.\n"
         "\n## Next\n\nIt took 0.7 s of CPU.\n", 1),
        ("## Cost\n<!-- measured: bench/missing.sh @ abc1234 on a 2-core machine -->\n\nIt took 0.5 s of CPU.\n", 1),
        ("## Cost\n<!-- measured: tests/t.c @ abc1234 on a 2-core machine -->\n\nIt took 0.5 s of CPU.\n", 1),
        ("It took 12 steps. <!-- measured: bench/x.sh @ abc1234 on a 2-core machine -->\n\nThen 13 steps.\n", 1),
        ("At rtol 1e-6, changing the torque every 2 ms for 3 s took longer; up to 12 Newton iterations.\n", 0),
        ("```console\n$ ./step\nt = 2.0  x = 0.123\n```\n\nIt runs 2× faster.\n", 1),
        ("```console\n$ ./hub\nhub at 3.0032 rad/s\n```\n\nThe hub reaches 3.0032 rad/s, the tip deflects 0.196 m.\n", 1),
    ]
    problems = []
    with tempfile.TemporaryDirectory() as d:
        os.makedirs(os.path.join(d, "bench"))
        os.makedirs(os.path.join(d, "tests"))
        open(os.path.join(d, "bench", "x.sh"), "w").close()
        open(os.path.join(d, "tests", "t.c"), "w").close()
        SRC, HAVE_GIT = d, False
        for page, want in cases:
            with open(os.path.join(d, "page.md"), "w", encoding="utf-8") as f:
                f.write(page)
            got = []
            check_page("page.md", got)
            if len(got) != want:
                problems.append(f"self-test: {len(got)} failures where {want} were due on {page!r}: {got}")
    SRC, HAVE_GIT = saved[0], saved[1]
    unchecked[:] = saved[2]
    for shown, printed, ok in [("controller: 8993 ±5% steps", "controller: 9100 steps", True),
                               ("controller: 8993 ±5% steps", "controller: 70400 steps", False),
                               ("hub at 3.0010 rad/s", "hub at 3.0032 rad/s", False),
                               ("peak 0.196 m", "peak 0.19612 m", True),
                               ("max_abs=1.09…e-05 …", "max_abs=1.097841e-05 t_max=1", True),
                               ("2001 rows", "12001 rows", False),
                               ("lag 0.306 ±0.005 m at t = 2.18 ±0.05 s", "lag 0.303 m at t = 2.2 s", True),
                               ("lag 0.306 ±0.005 m at t = 2.18 ±0.05 s", "lag 0.316 m at t = 2.18 s", False)]:
        if (match_shown(shown, printed) is None) != ok:
            problems.append(f"self-test: `{shown}` against `{printed}`: {'refused' if ok else 'accepted'}")
    return problems


SRC = os.path.abspath(sys.argv[1]) if len(sys.argv) > 1 else os.getcwd()
HAVE_GIT = git("rev-parse", "--git-dir")[0] == 0
unchecked = []
if __name__ == "__main__":
    selftest = self_test()
    docs = ["README.md"] + sorted("docs/" + f for f in os.listdir(os.path.join(SRC, "docs")) if f.endswith(".md"))
    failures = list(selftest)
    for doc in docs:
        check_page(doc, failures)
    if UNCHECKED_MAX >= 0 and len(unchecked) > UNCHECKED_MAX:
        failures.append(f"{len(unchecked)} numbers under `<!-- unchecked: -->` markers, more than the "
                        f"{UNCHECKED_MAX} allowed: give the new ones a compared block or a measured marker")
    for f in failures:
        print("FAIL:", f)
    for u in unchecked:
        print("unchecked:", u)
    print(f"{len(docs)} documents: {len(failures)} failures; {len(unchecked)} numbers about runs under unchecked "
          f"markers (at most {UNCHECKED_MAX})" + ("" if HAVE_GIT else "; no git here: the markers' commits are not checked"))
    sys.exit(1 if failures else 0)
