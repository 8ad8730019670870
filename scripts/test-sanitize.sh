#!/usr/bin/env bash
# Builds the library, CLI and tests with AddressSanitizer and UndefinedBehaviorSanitizer
# (build-asan/, RelWithDebInfo: optimised so the real-scan tests finish, with line numbers in
# reports) and runs the test suite but its `slow` tests (the 6M-point alpe scan and the largest
# tiled runs, minutes each under the sanitizers; the rest runs every code path they run, on the
# other scans). Any sanitizer report fails its test.
set -euo pipefail
cd "$(dirname "$0")/.."
scripts/install-deps.sh
cmake -S . -B build-asan -G Ninja -DCMAKE_BUILD_TYPE=RelWithDebInfo -DG2S_WERROR=ON \
  -DG2S_SANITIZE=address,undefined -DG2S_BUILD_BENCH=OFF
cmake --build build-asan -j"$(nproc)"
export ASAN_OPTIONS=detect_leaks=1
export UBSAN_OPTIONS=print_stacktrace=1:halt_on_error=1
# The Slurm test (label slurm) runs the same grow and stitch code as the pipeline tests, through a
# scheduler; scripts/test.sh runs it, so it is left out here.
ctest --test-dir build-asan --output-on-failure -j"$(nproc)" -LE 'slurm|slow'
