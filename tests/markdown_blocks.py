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
