#!/usr/bin/env bash
# Install the Debian (bookworm) packages the library, its tests, its tool and its
# Python bindings need.
# Does nothing when they are all present.
set -euo pipefail
packages=(cmake g++ make libpcl-dev libcgal-dev libeigen3-dev libflann-dev
          libgtest-dev pcl-tools xvfb xauth python3-catkin-pkg clang libclang-rt-14-dev
          doxygen pybind11-dev python3-dev python3-numpy python3-pytest
          python3-distributed)
missing=()
for p in "${packages[@]}"; do
  dpkg-query -W -f='${Status}' "$p" 2>/dev/null | grep -q "install ok installed" || missing+=("$p")
done
[ ${#missing[@]} -eq 0 ] && exit 0
sudo=""
[ "$(id -u)" -ne 0 ] && sudo="sudo"
echo "Installing: ${missing[*]}"
$sudo apt-get update -q
DEBIAN_FRONTEND=noninteractive $sudo apt-get install -y -q --no-install-recommends "${missing[@]}"
