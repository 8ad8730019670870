#!/usr/bin/env bash
# Installs everything g2s needs to build, test and benchmark on Debian bookworm, the Python module
# included (pybind11, numpy, pytest), as root or with sudo available. Safe to run again: only
# missing packages are installed. Extra package names given as arguments are installed too
# (scripts/fuzz.sh adds clang and libFuzzer).
set -euo pipefail
packages=(g++ cmake ninja-build pkg-config git time
          libtbb-dev libzstd-dev libfmt-dev libcli11-dev libgtest-dev libgmock-dev libbenchmark-dev
          parallel python3-dev python3-numpy python3-pybind11 pybind11-dev python3-pytest "$@")
missing=()
for p in "${packages[@]}"; do
  dpkg-query -W -f='${Status}' "$p" 2>/dev/null | grep -q "install ok installed" || missing+=("$p")
done
if [ ${#missing[@]} -gt 0 ]; then
  sudo=""
  [ "$(id -u)" -eq 0 ] || sudo="sudo"
  export DEBIAN_FRONTEND=noninteractive
  $sudo apt-get update -qq
  $sudo apt-get install -y -qq --no-install-recommends "${missing[@]}"
fi
