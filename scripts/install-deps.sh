#!/usr/bin/env bash
# Installs the Debian 12 packages jello builds, tests and runs with (see src/ARCHITECTURE.md, "Building by hand").
# Idempotent: packages already present are skipped, and apt is not touched when none is missing.
set -euo pipefail

packages=(
  cmake ninja-build g++ pkg-config ccache
  libeigen3-dev libsuitesparse-dev libopenblas0-pthread libsundials-dev libfftw3-dev
  freeglut3-dev libgl1-mesa-dev libglu1-mesa-dev xvfb xauth libstb-dev libimgui-dev
  libgtest-dev libgmock-dev libbenchmark-dev
  libspectra-dev libcli11-dev nlohmann-json3-dev gnuplot-nox libopenmpi-dev openmpi-bin
  clang-14 libclang-rt-14-dev clang-format-14
  python3 python3-dev pybind11-dev python3-numpy python3-scipy python3-matplotlib python3-pytest
  python3-hypothesis python3-pip python3-setuptools python3-wheel python3-venv ffmpeg
)

missing=()
for p in "${packages[@]}"; do
  if ! dpkg-query -W -f='${Status}' "$p" 2>/dev/null | grep -q '^install ok installed$'; then
    missing+=("$p")
  fi
done

if [ ${#missing[@]} -eq 0 ]; then
  echo "install-deps: all ${#packages[@]} packages present"
  exit 0
fi

echo "install-deps: installing ${missing[*]}"
sudo_cmd=()
[ "$(id -u)" -eq 0 ] || sudo_cmd=(sudo)
export DEBIAN_FRONTEND=noninteractive
"${sudo_cmd[@]}" apt-get update -qq
"${sudo_cmd[@]}" apt-get install -y -qq --no-install-recommends "${missing[@]}" >/dev/null
echo "install-deps: done"
