#!/usr/bin/env bash
# Installs what delayspec needs from Debian 12 packages, only what is missing. Idempotent.
# Run as root (or with sudo available).
set -euo pipefail
packages=(
  build-essential cmake ninja-build pkg-config git
  libeigen3-dev libspectra-dev libarpack2-dev libsuitesparse-dev
  libopenblas-dev liblapack-dev
  libgtest-dev libgmock-dev libbenchmark-dev libpng-dev
  libtomlplusplus-dev libcli11-dev nlohmann-json3-dev libginac-dev
  gnuplot-nox ccache python3
  python3-dev python3-pybind11 pybind11-dev python3-numpy python3-pytest python3-matplotlib
  libopenmpi-dev openmpi-bin
)
missing=()
for p in "${packages[@]}"; do
  dpkg-query -W -f='${Status}' "$p" 2>/dev/null | grep -q "install ok installed" || missing+=("$p")
done
if [ ${#missing[@]} -eq 0 ]; then
  echo "setup: all ${#packages[@]} packages present"
  exit 0
fi
echo "setup: installing ${missing[*]}"
SUDO=""
[ "$(id -u)" -eq 0 ] || SUDO="sudo"
export DEBIAN_FRONTEND=noninteractive
$SUDO apt-get update -qq
$SUDO apt-get install -y -qq --no-install-recommends "${missing[@]}"
