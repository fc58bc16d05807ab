#!/usr/bin/env bash
# The test command: install what is missing, build, and run the whole ctest suite.
# Pass ctest arguments through, e.g. `tools/test.sh -L quick` or `tools/test.sh -LE long`.
set -euo pipefail
cd "$(dirname "$0")/.."
bash tools/install_deps.sh
bash tools/build.sh
ctest --test-dir build --output-on-failure -j"$(nproc)" "$@"
