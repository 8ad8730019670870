#!/usr/bin/env bash
# Style checks of CI: every tracked C++ file formatted as .clang-format says (clang-format, dry
# run), and clang-tidy with the checks of .clang-tidy (likely bugs, needless copies, a few modern
# forms) on the C++ files changed since BASE (default: the previous commit; G2S_TIDY_BASE=<rev>
# to widen, G2S_TIDY_BASE=all for every file of src/ and tools/, which takes a long while on two
# cores). clang-tidy reads build/compile_commands.json: run scripts/test.sh (or cmake) first.
set -euo pipefail
cd "$(dirname "$0")/.."
scripts/install-deps.sh clang-format clang-tidy >/dev/null

git ls-files '*.cpp' '*.hpp' '*.h' | xargs clang-format --dry-run -Werror
echo "clang-format: every tracked C++ file is formatted"

base="${G2S_TIDY_BASE:-HEAD~1}"
if [ "$base" = all ]; then
  files=$(git ls-files 'src/*.cpp' 'tools/*.cpp')
else
  files=$(git diff --name-only --diff-filter=d "$base" -- 'src/*.cpp' 'tools/*.cpp' || true)
fi
if [ -z "$files" ]; then
  echo "clang-tidy: no changed source file since $base"
  exit 0
fi
[ -f build/compile_commands.json ] || cmake -S . -B build -G Ninja >/dev/null
# shellcheck disable=SC2086
run-clang-tidy -quiet -p build -j "$(nproc)" $(printf "$PWD/%s " $files)
echo "clang-tidy: clean"
