#!/usr/bin/env python3
"""test_messages.py FLEXMBD OUTDIR — messages that name the mistake in the caller's terms (issue 36):
  - `--set solver.rtol 1e-6` (a space for =) says the --set value needs PATH=VALUE, for run, check
    and regress, exit 2 (not "one scene file at a time");
  - `flexmbd runn` says "did you mean 'run'?" instead of printing the whole usage; a word that is
    no typo of a command still gets the usage;
  - an unknown key in any item of every starter scene lists every key that item may have: each key
    the starter itself writes there (material and section among them) is in "expected one of".
"""
import os
import re
import subprocess
import sys

flexmbd, out = sys.argv[1], sys.argv[2]
os.makedirs(out, exist_ok=True)
os.chdir(out)
failures = []


def run(*args):
    p = subprocess.run([flexmbd, *args], capture_output=True, text=True, timeout=120)
    return p.returncode, p.stdout, p.stderr


def items(text):
    """(group, name, keys) of each body and joint item of a starter scene: block items
    (`  - name: x` then `    key: ...`) and flow items (`  - {name: x, key: ...}`); no YAML module
    needed (Debian's python3 without python3-yaml)"""
    group, item, found = None, None, []
    for line in text.splitlines():
        line = line.split("#", 1)[0].rstrip()
        top = re.match(r"^(\w+):", line)
        if top:
            group, item = (top.group(1) if top.group(1) in ("bodies", "joints") else None), None
            continue
        if not group or not line.strip():
            continue
        flow = re.match(r"^\s*-\s*\{(.*)\}\s*$", line)
        if flow:
            keys = re.findall(r"(?:^|,)\s*(\w+)\s*:", re.sub(r"\[[^]]*\]", "", flow.group(1)))
            name = re.search(r"name:\s*([\w-]+)", flow.group(1)).group(1)
            found.append((group, name, keys))
            continue
        block = re.match(r"^\s*(-\s*)?(\w+):\s*(.*)$", line)
        if block and block.group(1):
            item = [group, None, []]
            found.append(item)
        if block and item is not None:
            item[2].append(block.group(2))
            if block.group(2) == "name":
                item[1] = block.group(3).strip()
    return [tuple(i) for i in found]


def expect(cond, what):
    if not cond:
        failures.append(what)


scene = "pendulum.yaml"
with open(scene, "w") as f:
    f.write(run("new", "pendulum")[1])

# a space for '='
for cmd in (["run", scene, "-o", "p.csv"], ["check", scene], ["regress", scene]):
    rc, _, err = run(*cmd, "--set", "solver.rtol", "1e-6")
    expect(rc == 2, f"{cmd[0]} --set solver.rtol 1e-6: exit {rc}, expected 2")
    expect("solver.rtol: expected PATH=VALUE in one argument" in err and "--set solver.rtol=1e-6" in err,
           f"{cmd[0]} --set solver.rtol 1e-6 does not name the mistake: {err!r}")
    expect("one scene file at a time" not in err, f"{cmd[0]}: blames a second scene file: {err!r}")
rc, _, err = run("run", scene, "-o", "p.csv", "--set", "solver.rtol")
expect(rc == 2 and "solver.rtol: expected PATH=VALUE" in err, f"--set without a value: exit {rc}: {err!r}")
rc, _, err = run("run", scene, "-o", "p.csv", "--set=solver.rtol=1e-9")
expect(rc == 0, f"--set=PATH=VALUE still works: exit {rc}: {err!r}")

# a misspelt command
for typed, meant in (("runn", "run"), ("chekc", "check"), ("regres", "regress"), ("veiw", "view")):
    rc, outp, err = run(typed, scene)
    expect(rc == 2, f"flexmbd {typed}: exit {rc}, expected 2")
    expect(f"unknown command '{typed}'; did you mean '{meant}'?" in err, f"flexmbd {typed}: {err!r}")
    expect("usage:" not in err, f"flexmbd {typed} still prints the whole usage")
rc, _, err = run("frobnicate")
expect(rc == 2 and "unknown command 'frobnicate'" in err and "usage:" in err and "did you mean" not in err,
       f"flexmbd frobnicate: exit {rc}: {err!r}")

# every key a starter item uses is among those its unknown-key message lists
for starter in ("pendulum", "beam", "rotor", "slider-crank"):
    text = run("new", starter)[1]
    path = f"{starter}.yaml"
    with open(path, "w") as f:
        f.write(text)
    found = items(text)
    expect(len(found) >= 2, f"{starter}: found {len(found)} items")
    for group, name, keys in found:
        rc, _, err = run("check", path, "--set", f"{group}.{name}.no_such_key=1")
        m = re.search(r"expected one of: ([^)]*)\)", err)
        expect(rc == 2 and m, f"{starter}: {group}.{name}: no key list: {err!r}")
        if not m:
            continue
        listed = [k.strip() for k in m.group(1).split(",")]
        missing = [k for k in keys if k not in listed]
        expect(not missing, f"{starter}: {group}.{name}: keys it uses but the list omits: {missing}")
        expect(len(set(listed)) == len(listed), f"{starter}: {group}.{name}: a key listed twice")
        expect("name" in keys and "type" in keys, f"{starter}: {group}.{name}: the scene reader missed keys: {keys}")
# and the starter beam's own `material` and `section` are named by that rule
text = run("new", "beam")[1].replace("    material: aluminium", "    materail: aluminium")
with open("typo.yaml", "w") as f:
    f.write(text)
rc, _, err = run("check", "typo.yaml")
expect(rc == 2 and "did you mean 'material'?" in err, f"materail: {err!r}")

for f in failures:
    print("FAIL:", f)
print("test_messages:", "ok" if not failures else f"{len(failures)} failures")
sys.exit(1 if failures else 0)
