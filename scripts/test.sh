#!/usr/bin/env bash
# Installs dependencies, builds (Release) and runs the whole test suite with ctest, then checks
# that the library installs and builds the examples/ consumer project and that the installed
# Python module imports (scripts/test-install.sh).
set -euo pipefail
cd "$(dirname "$0")/.."
scripts/install-deps.sh
# The Python module too (G2S_PYTHON; its pytest suite is a ctest test), with Debian's python3,
# where python3-numpy and python3-pybind11 are.
cmake -S . -B build -G Ninja -DCMAKE_BUILD_TYPE=Release -DG2S_WERROR=ON -DG2S_PYTHON=ON \
  -DPython3_EXECUTABLE=/usr/bin/python3
cmake --build build -j"$(nproc)"
ctest --test-dir build --output-on-failure -j"$(nproc)"
scripts/test-install.sh build
