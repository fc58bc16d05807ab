#!/usr/bin/env python3
"""test_docs.py SOURCE_DIR BUILD_DIR OUTDIR — the documentation cannot go stale:

1. Every command in README.md and docs/*.md runs. A fenced block tagged `sh` (or `bash`) is a
   script; in a block tagged `console`, the lines starting with `$ ` are commands and the others
   their output, which is checked: each output line must be produced (on stdout or stderr) by the
   command above it, its text verbatim, where `…` stands for any text (numbers that change with the
   machine: `cpu_s=…`), and each number within the tolerance written after it (`8993 ±5%`) or as
   rounded (tests/markdown_blocks.py, match_shown; docs/regression.md, "Numbers in the docs"). So a quoted message or a header of columns (`$ head -n 1 out.csv`) shown
   in a console block cannot drift from what the program prints. A block that must not run (it installs packages, takes minutes, needs a file
   the reader brings) is tagged `sh norun` / `console norun`: the convention is explicit, so an
   untagged block that holds a command is an error too. Each document's commands run in order
   in one bash (`set -e`, so `cd` and files carry over) in a fresh directory that links the
   repository's folders (scenes/, tools/, ...; build/ is BUILD_DIR), with build/ on the PATH so
   that both `./build/flexmbd` and `flexmbd` work; a command that fails names its document and line.
   None may change the repository through those links (git status is compared before and after);
   HOME is the work folder. A page whose commands another test runs within a larger setup says
   so with `<!-- commands run by: PATH -->` (checked: PATH exists and reads the page).
2. No link points outside the repository: every Markdown link or image target is a file or
   folder inside it (web addresses included: the documentation travels with the code), and no
   text refers to the sibling folders the repository was developed beside (`../shared`)."""
import os
import re
import shutil
import signal
import subprocess
import sys

sys.path.insert(0, os.path.join(os.path.dirname(os.path.abspath(__file__)), ".."))
from markdown_blocks import blocks  # noqa: E402  (tests/markdown_blocks.py)

src, build, out = (os.path.abspath(a) for a in sys.argv[1:4])
# A document's commands together get 120 s: a guard against a hang or a block that takes minutes,
# not a benchmark. Under ASan + UBSan (FLEXMBD_SANITIZE=1, set by tests/ux/CMakeLists.txt) every
# run is 3-5x slower, and the suite runs two tests at once: README's block, ~25 s in a plain
# build, took more than 120 s there on a loaded CI machine. The guard scales with the build.
DOC_TIMEOUT = 120 * (5 if os.environ.get("FLEXMBD_SANITIZE") else 1)
shutil.rmtree(out, ignore_errors=True)
os.makedirs(out)
docs = ["README.md"] + sorted("docs/" + f for f in os.listdir(os.path.join(src, "docs")) if f.endswith(".md"))
failures = []
COMMANDISH = re.compile(r"^\s*(\$ )?(\./)?(build/)?(flexmbd|bash|sh|cmake|ctest|tools/|bench/)\b")
# an output line shown under a command is checked by markdown_blocks.match_shown (its text, `…`
# for any text, numbers within their stated tolerance), run as a program from the script
CHECK = (sys.executable, os.path.join(os.path.dirname(os.path.dirname(os.path.abspath(__file__))), "markdown_blocks.py"))


def console_script(doc, line, body):
    """a console block's commands, each followed by checks of the output lines shown under it"""
    out, cmd, expect = [], None, []

    def flush():
        if cmd is None:
            return
        if not expect:
            out.append(cmd)
            return
        # the command's stdout and stderr together; set -e still stops on its failure
        out.append(f"{{ {cmd}\n}} >.console_out 2>&1 || {{ cat .console_out >&2; exit 1; }}")
        for e in expect:
            shown = e.strip().replace("'", "'\\''")
            out.append(f"'{CHECK[0]}' '{CHECK[1]}' .console_out '{shown}' || {{ echo '### {doc}:{line}' >&2; exit 1; }}")

    for l in body:
        if l.startswith("$ "):
            flush()
            cmd, expect = l[2:], []
        elif l.strip() and cmd is not None:
            expect.append(l)
    flush()
    return out


def repo_status():
    """git's view of the working tree (None outside a git checkout): the commands run beside
    links into the repository, and none of them may change it"""
    try:
        r = subprocess.run(["git", "status", "--porcelain", "--ignored=no"], cwd=src, capture_output=True, text=True)
        return r.stdout if r.returncode == 0 else None
    except OSError:
        return None


status_before = repo_status()
DELEGATED = re.compile(r"<!-- commands run by: (\S+) -->")
ran = skipped = 0
for doc in docs:
    # a page whose commands another test runs as part of a larger setup (plugins.md: install,
    # build a plugin against the installed package) says which; the claim is checked: that test
    # exists and reads this page
    text = open(os.path.join(src, doc), encoding="utf-8").read()
    delegated = DELEGATED.search(text)
    if delegated:
        runner = os.path.join(src, delegated.group(1))
        if not (os.path.isfile(runner) and doc in open(runner, encoding="utf-8").read()):
            failures.append(f"{doc}: its commands are said to be run by {delegated.group(1)}, which does not read {doc}")
        skipped += sum(1 for _, info, _ in blocks(os.path.join(src, doc)) if info[:1] in (["sh"], ["bash"], ["console"]))
        continue
    script = ["set -e"]
    for line, info, body in blocks(os.path.join(src, doc)):
        lang = info[0] if info else ""
        if "norun" in info:
            skipped += 1
            continue
        if lang in ("sh", "bash"):
            cmds = body
        elif lang == "console":
            cmds = console_script(doc, line, body)
        else:
            bad = [l for l in body if COMMANDISH.match(l)] if lang in ("", "text") else []
            if bad:
                failures.append(f"{doc}:{line}: an untagged block holds a command ({bad[0].strip()!r}): tag it sh, console, or sh norun")
            continue
        if not any(c.strip() and not c.strip().startswith("#") for c in cmds):
            continue
        ran += 1
        script.append(f"echo '### {doc}:{line}' >&2")
        script.extend(cmds)
    if len(script) == 1:
        continue
    work = os.path.join(out, doc.replace("/", "_").replace(".md", ""))
    os.makedirs(work)
    for entry in os.listdir(src):
        if entry in ("build", ".git", "out") or entry.startswith("."):  # out/: the pages write there, in the scratch folder
            continue
        os.symlink(os.path.join(src, entry), os.path.join(work, entry))
    os.symlink(build, os.path.join(work, "build"))
    # HOME is the work folder too: a command that installs into $HOME stays in the sandbox
    env = dict(os.environ, PATH=build + os.pathsep + os.environ.get("PATH", ""), HOME=work)
    with open(os.path.join(work, "commands.sh"), "w") as f:
        f.write("\n".join(script) + "\n")
    # its own session, so that a command that hangs is ended with everything it started
    proc = subprocess.Popen(["bash", "commands.sh"], cwd=work, env=env, stdout=subprocess.PIPE, stderr=subprocess.PIPE,
                            text=True, start_new_session=True)
    try:
        _, err = proc.communicate(timeout=DOC_TIMEOUT)
    except subprocess.TimeoutExpired:
        os.killpg(proc.pid, signal.SIGKILL)
        _, err = proc.communicate()
        err += (f"\ntimed out after {DOC_TIMEOUT} s (the document's commands together): a block that takes minutes "
                "belongs in `sh norun`")
    r = subprocess.CompletedProcess(proc.args, proc.returncode, None, err)
    if r.returncode != 0:
        where = [l for l in r.stderr.splitlines() if l.startswith("### ")]
        failures.append(f"{where[-1][4:] if where else doc}: a command failed (exit {r.returncode}): "
                        + " | ".join(l for l in r.stderr.splitlines()[-4:] if not l.startswith("### ")))

status_after = repo_status()
if status_before is not None and status_after != status_before:
    failures.append("a documented command changed the repository (git status before/after differ): mark it norun or "
                    "make it write into the current folder")

# links
LINK = re.compile(r"!?\[[^\]]*\]\(([^)\s]+)(?:\s+\"[^\"]*\")?\)")
nlinks = 0
for doc in docs:
    text = open(os.path.join(src, doc), encoding="utf-8").read()
    for n, line in enumerate(text.split("\n"), 1):
        if "../shared" in line:
            failures.append(f"{doc}:{n}: refers to ../shared, outside the repository")
        for target in LINK.findall(line):
            nlinks += 1
            if re.match(r"^[a-z]+:", target):
                failures.append(f"{doc}:{n}: link to {target}: outside the repository")
                continue
            if target.startswith("#"):
                continue
            path = os.path.normpath(os.path.join(src, os.path.dirname(doc), target.split("#")[0]))
            if not (path == src or path.startswith(src + os.sep)):
                failures.append(f"{doc}:{n}: link {target} leaves the repository")
            elif not os.path.exists(path):
                failures.append(f"{doc}:{n}: link {target}: no such file")

for f in failures:
    print("FAIL:", f)
print(f"{len(docs)} documents: {ran} command blocks run, {skipped} marked norun, {nlinks} links checked")
sys.exit(1 if failures else 0)
