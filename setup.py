"""The build step of `pip install .` (pyproject.toml: setuptools): the Python package python/flexmbd
plus, inside it, what it needs at run time from the rest of the project:

- flexmbd/_libs/libflexmbd.so.ABI: the C library, built by CMake with the project's own
  CMakeLists.txt (the target flexmbd_shared only). An existing configured build tree of this
  checkout, ./build (tools/build.sh's), is brought up to date and used; otherwise a fresh one is
  configured in setuptools' temporary folder. CMake and the C dependencies must be installed
  (tools/install_deps.sh); CMAKE_BUILD_PARALLEL_LEVEL sets the jobs (default: all cores).
- flexmbd/_data/view.html: `flexmbd view`'s page template (tools/view.html), for Result._repr_html_.
- flexmbd/_version.py: the project version of CMakeLists.txt, for flexmbd.__version__.

The package's _lib.py looks for flexmbd/_libs/ right after FLEXMBD_LIBRARY, so an installed package
needs no environment variable."""
import glob
import importlib.util
import os
import re
import shutil
import subprocess
import sys

from setuptools import setup
from setuptools.command.build_py import build_py
from setuptools.dist import Distribution

SRC = os.path.dirname(os.path.abspath(__file__))


def _source_module():
    """python/flexmbd/_source.py, loaded by path (importing the package would need NumPy and the library)"""
    spec = importlib.util.spec_from_file_location("flexmbd_source", os.path.join(SRC, "python", "flexmbd", "_source.py"))
    mod = importlib.util.module_from_spec(spec)
    spec.loader.exec_module(mod)
    return mod


VERSION = _source_module().project_version(os.path.join(SRC, "CMakeLists.txt"))


def _say(text):
    print(f"flexmbd setup: {text}", file=sys.stderr, flush=True)


def _reusable_build_tree(path):
    """./build when it is a CMake tree configured from this checkout, not a sanitizer build (whose
    library an uninstrumented Python cannot load)"""
    try:
        with open(os.path.join(path, "CMakeCache.txt"), encoding="utf-8", errors="replace") as f:
            cache = f.read()
    except OSError:
        return False
    home = re.search(r"^CMAKE_HOME_DIRECTORY:INTERNAL=(.*)$", cache, re.MULTILINE)
    if not home or os.path.realpath(home.group(1).strip()) != os.path.realpath(SRC):
        return False
    return not re.search(r"^FLEXMBD_SANITIZE:BOOL=(ON|1|TRUE|YES)$", cache, re.MULTILINE | re.IGNORECASE)


def _run(cmd):
    _say(" ".join(cmd))
    try:
        subprocess.run(cmd, check=True, stdout=sys.stderr)
    except FileNotFoundError:
        sys.exit(f"flexmbd setup: '{cmd[0]}' not found: building the C library needs CMake, a C compiler and "
                 "the libraries of tools/install_deps.sh (Debian 12: sudo bash tools/install_deps.sh)")
    except subprocess.CalledProcessError as e:
        sys.exit(f"flexmbd setup: '{' '.join(cmd)}' failed (exit {e.returncode}); the C library's dependencies "
                 "are installed by tools/install_deps.sh")


def build_library(temp):
    """Build libflexmbd (CMake target flexmbd_shared); returns the path of its SONAME file."""
    tree = os.path.join(SRC, "build")
    if not _reusable_build_tree(tree):
        tree = os.path.join(os.path.abspath(temp), "cmake")
        _run(["cmake", "-S", SRC, "-B", tree, "-DCMAKE_BUILD_TYPE=Release"])
    cmd = ["cmake", "--build", tree, "--target", "flexmbd_shared"]
    if not os.environ.get("CMAKE_BUILD_PARALLEL_LEVEL"):
        cmd += ["--parallel", str(os.cpu_count() or 1)]
    _run(cmd)
    # libflexmbd.so.ABI, the name the library's SONAME gives and _lib.py looks for
    sonames = [p for p in glob.glob(os.path.join(tree, "libflexmbd.so.*")) if re.search(r"\.so\.\d+$", p)]
    if len(sonames) != 1:
        sys.exit(f"flexmbd setup: expected one libflexmbd.so.N in {tree}, found {sonames}")
    return sonames[0]


class BuildPyWithLibrary(build_py):
    """build_py, then the library, the view template and the version into the built package"""

    def run(self):
        super().run()
        package = os.path.join(self.build_lib, "flexmbd")
        lib = build_library(self.get_finalized_command("build").build_temp)
        os.makedirs(os.path.join(package, "_libs"), exist_ok=True)
        shutil.copyfile(lib, os.path.join(package, "_libs", os.path.basename(lib)))  # the file, not the link
        os.makedirs(os.path.join(package, "_data"), exist_ok=True)
        shutil.copyfile(os.path.join(SRC, "tools", "view.html"), os.path.join(package, "_data", "view.html"))
        with open(os.path.join(package, "_version.py"), "w", encoding="utf-8") as f:
            f.write(f'# written by setup.py from CMakeLists.txt\'s project(VERSION)\nVERSION = "{VERSION}"\n')


class BinaryDistribution(Distribution):
    """a wheel for this platform and Python (it holds a compiled library), not py3-none-any"""

    def has_ext_modules(self):
        return True


setup(
    version=VERSION,
    package_dir={"": "python"},
    packages=["flexmbd"],
    cmdclass={"build_py": BuildPyWithLibrary},
    distclass=BinaryDistribution,
    # setuptools' own build folder, apart from CMake's ./build
    options={"build": {"build_base": os.path.join("build", "setuptools")}},
    zip_safe=False,
)
