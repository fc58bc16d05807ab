"""pip_install.py SOURCE_DIR BUILD_DIR WORK_DIR — `pip install .` as a user does it (docs/python.md):

1. a clean copy of the repository (git clone of SOURCE_DIR: its committed tree, no build/);
2. a fresh venv made with `python3 -m venv --system-site-packages` (Debian's NumPy visible), and
   `pip install --no-index --no-build-isolation CLONE` into it: setup.py builds the library with
   CMake and ships it inside the package;
3. in another folder, with no FLEXMBD_* variable, no PYTHONPATH and no LD_LIBRARY_PATH, the venv's
   Python imports flexmbd, finds the library inside the package (flexmbd/_libs), reports the
   project version of CMakeLists.txt, and runs scenes/pendulum.yaml: its CSV is byte for byte the
   CSV of the command line built in BUILD_DIR; compare and the view page work in-process (no
   `flexmbd` program on PATH);
4. the same into the system interpreter itself (this python3, no venv; `--prefix` into WORK_DIR so
   that the machine's own site-packages stay untouched), and the same checks;
5. an interpreter without NumPy is told what to install.
Run by this interpreter (CMake's FLEXMBD_SYSTEM_PYTHON3, Debian's /usr/bin/python3)."""
import glob
import os
import re
import shutil
import subprocess
import sys

SRC, BUILD, WORK = (os.path.abspath(a) for a in sys.argv[1:4])
fails = []


def check(cond, what):
    print(("ok   " if cond else "FAIL ") + what, flush=True)
    if not cond:
        fails.append(what)


def clean_env():
    """what a user's shell has: none of the build's variables"""
    env = {k: v for k, v in os.environ.items()
           if not k.startswith("FLEXMBD_") and k not in ("PYTHONPATH", "LD_LIBRARY_PATH", "PYTHONHOME")}
    env["PATH"] = "/usr/bin:/bin"  # no build tree, so no `flexmbd` program, on PATH
    return env


def run(cmd, **kw):
    p = subprocess.run(cmd, capture_output=True, text=True, **kw)
    if p.returncode != 0:
        print(f"$ {' '.join(cmd)}\n{p.stdout[-3000:]}\n{p.stderr[-3000:]}", flush=True)
    return p


shutil.rmtree(WORK, ignore_errors=True)
os.makedirs(WORK)
clone = os.path.join(WORK, "clone")
p = run(["git", "clone", "-q", SRC, clone])
check(p.returncode == 0 and not os.path.exists(os.path.join(clone, "build")), "git clone of the source tree, no build/")
with open(os.path.join(SRC, "CMakeLists.txt")) as f:
    version = re.search(r"project\(flexmbd VERSION ([0-9.]+)", f.read()).group(1)

# the command line's CSV of the scene, the reference the installed package must reproduce byte for byte
scene = os.path.join(SRC, "scenes", "pendulum.yaml")
cli_csv = os.path.join(WORK, "cli.csv")
p = run([os.path.join(BUILD, "flexmbd"), "run", scene, "--set", "solver.t_end=2", "-o", cli_csv])
check(p.returncode == 0, "flexmbd run scenes/pendulum.yaml (the CLI's CSV)")

elsewhere = os.path.join(WORK, "elsewhere")
os.makedirs(elsewhere)
USE = r"""
import os, sys
{path}
import flexmbd
lib = os.path.realpath(flexmbd.library_path())
pkg = os.path.realpath(os.path.dirname(flexmbd.__file__))
print("library", lib)
print("inside", lib.startswith(os.path.join(pkg, "_libs") + os.sep))
print("version", flexmbd.__version__)
r = flexmbd.load({scene!r}, set={{"solver.t_end": 2}}).run()
r.to_csv("py.csv")
print("same_csv", open("py.csv", "rb").read() == open({cli!r}, "rb").read())
c = flexmbd.compare("py.csv", {cli!r}, rtol=0.0, atol=0.0)
print("compare", c.ok, c["bob.theta"]["max_abs"] if "bob.theta" in c else c)
page = flexmbd.load({scene!r}, set={{"solver.t_end": 0.2}}).run()._repr_html_()
print("view", page.startswith("<iframe srcdoc=") and "/*FMB_VIEW_DATA*/null" not in page and "&quot;bodies&quot;" in page)
"""


def use(python, label, path_line=""):
    code = USE.format(path=path_line, scene=scene, cli=cli_csv)
    p = run([python, "-c", code], cwd=elsewhere, env=clean_env())
    out = dict(line.split(" ", 1) for line in p.stdout.splitlines() if " " in line)
    check(p.returncode == 0, f"{label}: imports flexmbd and runs a scene (no environment variable, cwd elsewhere)")
    check(out.get("inside") == "True", f"{label}: the library found inside the package: {out.get('library')}")
    check(out.get("version") == version, f"{label}: __version__ {out.get('version')} = CMakeLists.txt's {version}")
    check(out.get("same_csv") == "True", f"{label}: the run's CSV is the command line's, byte for byte")
    check(out.get("compare", "").startswith("True 0.0"), f"{label}: compare in-process: {out.get('compare')}")
    check(out.get("view") == "True", f"{label}: Result._repr_html_ shows the view page (template as package data)")


# 2-3. a venv that sees Debian's packages
venv = os.path.join(WORK, "venv")
p = run([sys.executable, "-m", "venv", "--system-site-packages", venv])
check(p.returncode == 0, "python3 -m venv --system-site-packages")
env = clean_env()
env["PATH"] = os.pathsep.join(["/usr/local/bin", "/usr/bin", "/bin"])  # cmake, cc
env.setdefault("CMAKE_BUILD_PARALLEL_LEVEL", "2")
vpy = os.path.join(venv, "bin", "python")
p = run([vpy, "-m", "pip", "install", "--no-index", "--no-build-isolation", clone], cwd=WORK, env=env)
check(p.returncode == 0, "pip install --no-index --no-build-isolation CLONE into the venv")
built = glob.glob(os.path.join(venv, "lib", "python3*", "site-packages", "flexmbd", "_libs", "libflexmbd.so.*"))
check(len(built) == 1, f"the venv's package holds the library: {built}")
use(vpy, "venv")
p = run(["git", "status", "--porcelain"], cwd=clone)
check(p.returncode == 0 and p.stdout == "", f"the build leaves the clone's tree clean: {p.stdout!r}")

# 4. the system interpreter itself (its own scheme; a prefix of our own instead of /usr/local)
prefix = os.path.join(WORK, "system-prefix")
p = run([sys.executable, "-m", "pip", "install", "--no-index", "--no-build-isolation", "--prefix", prefix, clone],
        cwd=WORK, env=env)
check(p.returncode == 0, f"{sys.executable} -m pip install --no-index --no-build-isolation (no venv)")
site = [os.path.dirname(os.path.dirname(f)) for f in glob.glob(os.path.join(prefix, "**", "flexmbd", "__init__.py"),
                                                                 recursive=True)]
check(len(site) == 1, f"installed under the prefix: {site}")
if site:
    use(sys.executable, "system python3", f"sys.path.insert(0, {site[0]!r})")

# 5. no NumPy (-S: without site-packages, as a pyenv or conda Python without it)
p = run([sys.executable, "-S", "-c", f"import sys; sys.path.insert(0, {os.path.join(SRC, 'python')!r}); import flexmbd"],
        cwd=elsewhere, env=clean_env())
check(p.returncode != 0 and "flexmbd needs NumPy" in p.stderr and "-m pip install numpy" in p.stderr
      and "python3-numpy" in p.stderr, "without NumPy: says what to install: " + p.stderr.strip().splitlines()[-1][:160])

print(f"pip_install: {len(fails)} failed checks")
sys.exit(1 if fails else 0)
