#!/usr/bin/env bash
# Installs dependencies, builds, generates a 300k-point synthetic torus, meshes it to binary STL
# and prints the mesh's defect statistics.
set -euo pipefail
cd "$(dirname "$0")/.."
scripts/install-deps.sh
cmake -S . -B build -G Ninja -DCMAKE_BUILD_TYPE=Release
cmake --build build -j"$(nproc)" --target g2s_cli
mkdir -p out
build/g2s synth torus --points 300000 -o out/demo-torus.ply
build/g2s mesh out/demo-torus.ply -o out/demo-torus.stl
build/g2s stats out/demo-torus.stl --points out/demo-torus.ply
