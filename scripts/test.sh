#!/usr/bin/env bash
# Installs dependencies, builds (Release) and runs the whole test suite with ctest, then checks
# that the library installs and builds the examples/ consumer project (scripts/test-install.sh).
set -euo pipefail
cd "$(dirname "$0")/.."
scripts/install-deps.sh
cmake -S . -B build -G Ninja -DCMAKE_BUILD_TYPE=Release -DG2S_WERROR=ON
cmake --build build -j"$(nproc)"
ctest --test-dir build --output-on-failure -j"$(nproc)"
scripts/test-install.sh build
