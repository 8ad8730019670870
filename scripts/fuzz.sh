#!/usr/bin/env bash
# Builds the libFuzzer targets of fuzz/ with clang, AddressSanitizer and UBSan (build-fuzz/) and
# runs each for SECONDS (default 300; CI passes a small budget) on a working copy of its seed
# corpus fuzz/corpus/NAME/. A crash stops the script; the input is saved as
# build-fuzz/crashes/NAME/crash-* (add it to the reader tests once fixed).
#   scripts/fuzz.sh [SECONDS-PER-TARGET]
set -euo pipefail
cd "$(dirname "$0")/.."
seconds="${1:-300}"
scripts/install-deps.sh clang libclang-rt-14-dev  # libFuzzer ships with clang's runtime
cmake -S . -B build-fuzz -G Ninja -DCMAKE_BUILD_TYPE=RelWithDebInfo \
  -DCMAKE_CXX_COMPILER=clang++ -DG2S_FUZZ=ON -DG2S_SANITIZE=address,undefined \
  -DG2S_BUILD_TESTS=OFF -DG2S_BUILD_BENCH=OFF
cmake --build build-fuzz -j"$(nproc)"
export UBSAN_OPTIONS=print_stacktrace=1:halt_on_error=1
for seeds in fuzz/corpus/*/; do
  name="$(basename "$seeds")"
  work="build-fuzz/corpus/$name"
  crashes="build-fuzz/crashes/$name"
  mkdir -p "$work" "$crashes"
  echo "== fuzz $name for $seconds s"
  # New inputs go to the working corpus (the first folder), never into the repository.
  "build-fuzz/fuzz/g2s_fuzz_$name" -max_total_time="$seconds" -timeout=10 -rss_limit_mb=2048 \
    -max_len=16384 -print_final_stats=1 -artifact_prefix="$crashes/" "$work" "$seeds"
done
