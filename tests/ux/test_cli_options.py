#!/usr/bin/env python3
"""test_cli_options.py FLEXMBD OUTDIR — every command's --help lists exactly the options it accepts
(issue 35, item 5). The help is written from the command's option table (tools/options.h), and
the command reads its arguments with the same table; this checks the two against each other from
outside, through the program alone:

  - `flexmbd --help` names the commands; `flexmbd CMD --help` (and `flexmbd help CMD`, the same
    text) lists CMD's options, each `-s, --long VALUE` or `--long`;
  - every listed option, long name and short alias, is accepted: called with a value when the help
    shows one, it is never "unknown option" and nothing crashes; called without its value it says
    it `needs` one (exit 2); a flag given a value (`--flag=1`) says it takes none (exit 2);
  - every option another command lists but CMD does not, and a made-up one, is refused:
    "unknown option", exit 2; a near miss of a listed name gets "did you mean '--name'?".

The calls run in an empty folder and leave out what would start real work (no scene, no CSV,
conform given a type that does not exist), so each ends at once with the arguments read."""
import os
import re
import subprocess
import sys
from concurrent.futures import ThreadPoolExecutor

flexmbd, out = os.path.abspath(sys.argv[1]), os.path.abspath(sys.argv[2])
os.makedirs(out, exist_ok=True)
os.chdir(out)
failures = []

# what keeps a call from doing real work once its options are read: conform would check every type
EXTRA = {"conform": ["no-such-type"]}


def run(*args):
    p = subprocess.run([flexmbd, *args], capture_output=True, text=True, timeout=60, stdin=subprocess.DEVNULL)
    return p.returncode, p.stdout, p.stderr


def expect(cond, what):
    if not cond:
        failures.append(what)


rc, usage, _ = run("--help")
commands = re.findall(r"^(?:usage:|\s+) flexmbd ([a-z]+)\b", usage, re.M)
expect(rc == 0 and len(commands) >= 13, f"flexmbd --help: exit {rc}, commands {commands}")

OPTION = re.compile(r"^  (?:(-[A-Za-z]), )?\s*(--[a-z][a-z-]*)(?: (\S+))?")
listed = {}  # command -> {name: takes a value}
for cmd in commands:
    rc, text, err = run(cmd, "--help")
    expect(rc == 0 and text.startswith(f"usage: flexmbd {cmd}"), f"flexmbd {cmd} --help: exit {rc}: {err!r}")
    rc2, text2, _ = run("help", cmd)
    expect(rc2 == 0 and text2 == text, f"flexmbd help {cmd} differs from flexmbd {cmd} --help")
    opts = {}
    section = text.split("\noptions:\n", 1)[1] if "\noptions:\n" in text else ""
    for line in section.splitlines():
        m = OPTION.match(line)
        if m:
            short, name, meta = m.groups()
            takes = bool(meta) and meta != "..."
            opts[name] = takes
            if short:
                opts[short] = takes
    expect(bool(opts) or cmd == "new", f"flexmbd {cmd} --help lists no option")
    listed[cmd] = opts

checks = []  # (arguments, what the result must satisfy, why)
for cmd, opts in listed.items():
    extra = EXTRA.get(cmd, [])
    for name, takes in opts.items():
        args = [cmd, name] + (["x"] if takes else []) + extra
        checks.append((args, lambda rc, err: "unknown option" not in err and 0 <= rc < 128,
                       "listed in --help, yet refused (or a crash)"))
        if takes:  # its value is required: without it the option says what it needs
            checks.append(([cmd, *extra, name], lambda rc, err, n=name: rc == 2 and f"{n} needs " in err,
                           "no value: expected exit 2 and 'needs'"))
        elif name.startswith("--"):  # a flag takes no value
            checks.append(([cmd, f"{name}=1", *extra], lambda rc, err: rc == 2 and "takes no value" in err,
                           "a flag given a value: expected exit 2 and 'takes no value'"))
    others = set().union(*listed.values()) - set(opts)
    for name in sorted(others | {"--no-such-option", "-Z"}):
        checks.append(([cmd, name, "x", *extra], lambda rc, err, n=name: rc == 2 and f"unknown option '{n}'" in err,
                       "not in its --help, yet not refused as unknown"))
    longs = sorted(n for n in opts if n.startswith("--") and len(n) > 5)
    if longs:  # a letter dropped: the message names the option meant
        typo = longs[0][:-2] + longs[0][-1]
        checks.append(([cmd, typo, *extra], lambda rc, err, n=longs[0]: rc == 2 and f"did you mean '{n}'?" in err,
                       "a near miss without did-you-mean"))


def call(check):
    args, ok, why = check
    rc, _, err = run(*args)
    expect(ok(rc, err), f"flexmbd {' '.join(args)}: {why} (exit {rc}): {err!r}")


with ThreadPoolExecutor(max_workers=4) as pool:  # each call is a short process; list.append is atomic
    list(pool.map(call, checks))
calls = len(checks)

print(f"{len(commands)} commands, {sum(len(o) for o in listed.values())} listed options, {calls} calls")
for f in failures:
    print("FAIL:", f)
sys.exit(1 if failures else 0)
