"""The fenced code blocks of a Markdown page, for the tests that run the documentation
(tests/ux/test_docs.py: shell blocks; tests/python/test_docs.py: Python blocks)."""
import re

FENCE = re.compile(r"^(\s*)```+\s*([^`]*)$")


def blocks(path):
    """(line, info words, lines) of every fenced block"""
    lines = open(path, encoding="utf-8").read().split("\n")
    i = 0
    while i < len(lines):
        m = FENCE.match(lines[i])
        if not m:
            i += 1
            continue
        start, info, body = i + 1, m.group(2).split(), []
        i += 1
        while i < len(lines) and not re.match(r"^\s*```+\s*$", lines[i]):
            body.append(lines[i])
            i += 1
        yield start, info, body
        i += 1


# --- Output shown in a page, compared with what a block prints -------------------------------
# An output line shown in a page (a `console` block's line under its `$ ` command, or the text of a
# `# prints: ...` comment in a ```python block) must be printed by the block: its text verbatim,
# `…` (or `...`) standing for any text, and every number compared as a number: within the
# tolerance written right after it (`8993 ±5%` relative, `3.0032 ±0.002` absolute), else within
# half a unit of its last digit (`0.196` is what prints as 0.196; a whole number is exact). A number
# cut short by `…` (`1.09…e-05`) is text: the printed number starts with those digits.
# The tolerance is part of the page: the reader sees how far the number may move.
NUMBER = r"[-+]?\d+(?:\.\d+)?(?:[eE][-+]?\d+)?"
# a number in shown text: not inside a name (w15, x1), an exponent (the 05 of e-05) or a version
SHOWN_NUMBER = re.compile(r"(?<![\w.\-+])(" + NUMBER + r")(\s*±\s*(\d+(?:\.\d+)?(?:[eE][-+]?\d+)?)(?:\s*(%))?)?")
PRINTS = re.compile(r"#[^#]*?\bprints:\s*(.*)$")
# the pages whose ```python blocks tests/python/test_docs.py runs (and so compares their `# prints:`)
PYTHON_PAGES = ("docs/python.md", "README.md")


def half_unit(shown):
    """half a unit of the last digit of a number as written: 0.196 -> 5e-4, 1.09e-05 -> 5e-8, 2001 -> 0.5"""
    mant, _, exp = shown.lower().lstrip("+-").partition("e")
    decimals = len(mant.split(".")[1]) if "." in mant else 0
    return 0.5 * 10.0 ** (-decimals + (int(exp) if exp else 0))


def shown_numbers(text):
    """[(value, tolerance, start, end, shown)] of the numbers in shown text; tolerance as stated
    (±5% relative, ±0.002 absolute) or half a unit of the last digit"""
    found = []
    for m in SHOWN_NUMBER.finditer(text):
        if not m.group(2) and text[m.end():m.end() + 1] in ("…", "."):
            continue  # `1.09…e-05`: digits cut short, matched as text (these digits, then any)
        value = float(m.group(1))
        if m.group(2):
            tol = float(m.group(3)) * (abs(value) / 100.0 if m.group(4) else 1.0)
        else:
            tol = half_unit(m.group(1))
        found.append((value, tol, m.start(), m.end(), m.group(1)))
    return found


def expected_pattern(text):
    """(compiled regex, [(value, tol, shown)]) for a shown output line: `…` any text, each number a
    captured number (its ± tolerance is not part of the output)"""
    nums, parts, pos = [], [], 0
    text = text.strip()
    for value, tol, start, end, shown in shown_numbers(text):
        parts.append(_literal(text[pos:start]))
        parts.append(r"(?<![\d.])(" + NUMBER + r")")
        nums.append((value, tol, shown))
        pos = end
    parts.append(_literal(text[pos:]))
    return re.compile("".join(parts)), nums


def _literal(text):
    return ".*".join(re.escape(p) for p in re.split(r"…|\.\.\.", text))


def match_shown(expected, output):
    """None if a line of `output` shows `expected` (numbers within their tolerance), else why not"""
    pattern, nums = expected_pattern(expected)
    near = None
    for line in output.split("\n"):
        m = pattern.search(line)
        if not m:
            continue
        off = [(shown, tol, float(got)) for (value, tol, shown), got in zip(nums, m.groups())
               if abs(float(got) - value) > tol * (1 + 1e-12)]
        if not off:
            return None
        near = near or (line, off)
    if near:
        line, off = near
        return "printed: " + line.strip() + " (" + "; ".join(
            f"{got:g} is not {shown} ± {tol:g}" for shown, tol, got in off) + ")"
    return "not printed"


if __name__ == "__main__":
    # `python3 markdown_blocks.py FILE EXPECTED`: the check a console block's output line gets in
    # tests/ux/test_docs.py (exit 1 with the reason when FILE does not show EXPECTED)
    import sys
    why = match_shown(sys.argv[2], open(sys.argv[1], encoding="utf-8", errors="replace").read())
    if why:
        print(f"not as shown: {sys.argv[2].strip()}\n  {why}", file=sys.stderr)
    sys.exit(1 if why else 0)
