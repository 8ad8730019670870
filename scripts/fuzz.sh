#!/usr/bin/env bash
# Builds the libFuzzer targets fuzz/NAME_fuzz.cpp with clang, AddressSanitizer and UBSan
# (build-fuzz/) and runs each for SECONDS (default 300; CI passes a small budget), starting from
# its seed corpus fuzz/corpus/NAME/. New inputs stay in build-fuzz/corpus/NAME/ (kept between
# local runs, never written to the repository). A crash stops the script with the input saved
# as build-fuzz/crashes/NAME/crash-*: fix it and add the input to the reader tests.
#   scripts/fuzz.sh [SECONDS-PER-TARGET]
set -euo pipefail
cd "$(dirname "$0")/.."
seconds="${1:-300}"
scripts/install-deps.sh clang libclang-rt-14-dev  # libFuzzer ships with clang's runtime
cmake -S . -B build-fuzz -G Ninja -DCMAKE_BUILD_TYPE=RelWithDebInfo \
  -DCMAKE_CXX_COMPILER=clang++ -DG2S_FUZZ=ON -DG2S_SANITIZE=address,undefined \
  -DG2S_BUILD_TESTS=OFF -DG2S_BUILD_BENCH=OFF
names=()
for source in fuzz/*_fuzz.cpp; do
  name="$(basename "$source" _fuzz.cpp)"
  names+=("$name")
done
cmake --build build-fuzz -j"$(nproc)" --target "${names[@]/#/g2s_fuzz_}"
export UBSAN_OPTIONS=print_stacktrace=1:halt_on_error=1
for name in "${names[@]}"; do
  work="build-fuzz/corpus/$name"
  crashes="build-fuzz/crashes/$name"
  mkdir -p "$work" "$crashes"
  echo "== fuzz $name for $seconds s"
  "build-fuzz/fuzz/g2s_fuzz_$name" -max_total_time="$seconds" -timeout=10 -rss_limit_mb=2048 \
    -max_len=16384 -print_final_stats=1 -artifact_prefix="$crashes/" "$work" "fuzz/corpus/$name"
done
