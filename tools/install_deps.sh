#!/usr/bin/env bash
# Install what flexmbd needs on Debian 12, only if something is missing.
#   --ci  also what CI's robustness step uses: clang and libFuzzer's runtime, valgrind; clang-format-14
#         (tools/format.sh: the committed .clang-format); and
#         python3-vtk9, with which the test vtk_reader reads the ParaView animation back through
#         VTK itself (skipped without it); python3-h5py, with which sweep_runs reads DIR/sweep.h5 back
#         (skipped without it); chromium, in which the test view_page loads the page of
#         `flexmbd view` headless (skipped without it)
# python3 and util-linux (`script`, a pseudo-terminal) run the tests of tests/ux; python3-numpy is
# what the Python package (python/flexmbd, docs/python.md) needs, python3-matplotlib draws its
# plots (optional for the package, used by docs/python.md), python3-pytest runs its tests.
# python3-setuptools, python3-wheel, python3-pip and python3-venv: `pip install --no-index
# --no-build-isolation .` (pyproject.toml, setup.py) into a venv or the system interpreter, and git
# the clean clone the test pip_install installs from; python3-nbclient, python3-nbformat and
# python3-ipykernel execute the notebook docs/tutorial.ipynb (tests/python/test_notebook.py).
set -euo pipefail
# liblapack-dev, libblas-dev: the dense eigen-solvers of `modes` (engine/modes.c);
# libarpack2-dev: its sparse shift-invert path (Arnoldi) for large systems
# libopenmpi-dev, openmpi-bin: `flexmbd sweep` over MPI ranks (mpirun); libhdf5-dev, hdf5-tools: its
# DIR/sweep.h5 and the h5dump that the sweep test reads it with (docs/sweep.md; both optional to build)
pkgs=(build-essential cmake pkg-config libsundials-dev libsuitesparse-dev libyaml-dev gnuplot-nox python3 util-linux
      liblapack-dev libblas-dev libarpack2-dev libopenmpi-dev openmpi-bin libhdf5-dev hdf5-tools python3-numpy
      python3-matplotlib python3-pytest python3-setuptools python3-wheel python3-pip python3-venv git
      python3-nbclient python3-nbformat python3-ipykernel)
if [ "${1:-}" = "--ci" ]; then
  pkgs+=(clang-14 libclang-rt-14-dev clang-format-14 valgrind util-linux python3-vtk9 python3-h5py chromium)
fi
missing=()
for p in "${pkgs[@]}"; do
  dpkg-query -W -f='${Status}' "$p" 2>/dev/null | grep -q "install ok installed" || missing+=("$p")
done
if [ ${#missing[@]} -eq 0 ]; then
  echo "install_deps: all packages present"
  exit 0
fi
echo "install_deps: installing ${missing[*]}"
SUDO=""
[ "$(id -u)" -ne 0 ] && SUDO="sudo"
$SUDO apt-get update -qq
DEBIAN_FRONTEND=noninteractive $SUDO apt-get install -y -qq --no-install-recommends "${missing[@]}" >/dev/null
