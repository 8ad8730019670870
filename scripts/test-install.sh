#!/usr/bin/env bash
# Checks that g2s installs as a library others can use: `cmake --install` of a build folder
# (default build/) into a temporary prefix, then the consumer project examples/ configured with
# find_package(g2s) against it, built and run on a synthetic cloud (both examples, in memory and
# out of core), and one example built again with pkg-config alone. scripts/test.sh runs it.
#   scripts/test-install.sh [BUILD-DIR]
set -euo pipefail
cd "$(dirname "$0")/.."
build="${1:-build}"
work="$(mktemp -d)"
trap 'rm -rf "$work"' EXIT
prefix="$work/prefix"
cmake --install "$build" --prefix "$prefix" > "$work/install.log"
cmake -S examples -B "$work/examples" -G Ninja -DCMAKE_BUILD_TYPE=Release \
  -DCMAKE_PREFIX_PATH="$prefix" > "$work/configure.log"
cmake --build "$work/examples" > "$work/build.log"
"$prefix/bin/g2s" synth torus --points 30000 -o "$work/torus.ply" 2> /dev/null
"$work/examples/mesh_in_memory" "$work/torus.ply" "$work/in_memory.ply"
"$work/examples/mesh_out_of_core" "$work/torus.ply" "$work/out_of_core.ply" 10000
test -s "$work/in_memory.ply" && test -s "$work/out_of_core.ply"
pc_dir="$(dirname "$(find "$prefix" -name g2s.pc)")"
# shellcheck disable=SC2046  # pkg-config prints several words on purpose
c++ $(PKG_CONFIG_PATH="$pc_dir" pkg-config --cflags g2s) examples/mesh_in_memory.cpp \
  $(PKG_CONFIG_PATH="$pc_dir" pkg-config --libs g2s) -o "$work/pkg_config_example"
"$work/pkg_config_example" "$work/torus.ply" "$work/pkg_config.ply"
# The Python module, when the build has it (G2S_PYTHON): imported from the prefix, meshing.
if module="$(find "$prefix" -path '*/dist-packages/g2s/__init__.py')" && [ -n "$module" ]; then
  PYTHONPATH="$(dirname "$(dirname "$module")")" /usr/bin/python3 -c '
import sys, g2s, numpy as np
t, s = g2s.mesh(np.random.default_rng(1).normal(size=(2000, 3)) * [1, 1, 0.01])
assert len(t) > 1000 and s["stats"]["non_manifold_edges"] == 0, s
print("test-install: python module imported from", g2s.__file__)'
fi
echo "test-install: g2s installed, found by find_package and pkg-config, examples built and run"
