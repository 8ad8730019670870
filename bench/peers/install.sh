#!/usr/bin/env bash
# Installs the Debian bookworm packages the peer drivers (bench/peers/, CMake option
# G2S_BUILD_PEERS) and the benchmark plots need: CGAL, PCL, Open3D and gnuplot. Run as root or
# with sudo; safe to run again (only missing packages are installed). See bench/peers/README.md.
set -euo pipefail
packages=(libcgal-dev libpcl-dev libopen3d-dev gnuplot-nox time)
missing=()
for p in "${packages[@]}"; do
  dpkg-query -W -f='${Status}' "$p" 2>/dev/null | grep -q "install ok installed" || missing+=("$p")
done
if ((${#missing[@]})); then
  sudo=()
  (($(id -u) == 0)) || sudo=(sudo)
  export DEBIAN_FRONTEND=noninteractive
  # Other users of the machine may hold the dpkg lock: wait for it rather than fail.
  "${sudo[@]}" apt-get -o DPkg::Lock::Timeout=600 update -qq
  "${sudo[@]}" apt-get -o DPkg::Lock::Timeout=600 install -y -qq --no-install-recommends "${missing[@]}"
fi
