#!/usr/bin/env bash
# Installs the Debian 12 packages the project needs, if any is missing.
# Needs root (or sudo) only when something must be installed.
set -euo pipefail
PACKAGES=(build-essential cmake ninja-build pkg-config libeigen3-dev libcgal-dev libgmp-dev libmpfr-dev libceres-dev
          libvtk9-dev libdeflate-dev libgoogle-perftools-dev doctest-dev nlohmann-json3-dev libcli11-dev
          libmuparser-dev libsuitesparse-dev libgmsh-dev gmsh libpetsc-real-dev openmpi-bin
          libgdal-dev libcairo2-dev fonts-dejavu-core
          pybind11-dev python3-dev python3-numpy python3-pytest python3-shapely python3-vtk9
          clang libfuzzer-14-dev)
missing=()
for p in "${PACKAGES[@]}"; do
  dpkg-query -W -f='${Status}' "$p" 2>/dev/null | grep -q "install ok installed" || missing+=("$p")
done
if [ ${#missing[@]} -eq 0 ]; then
  exit 0
fi
echo "installing: ${missing[*]}"
SUDO=""
if [ "$(id -u)" -ne 0 ]; then SUDO="sudo"; fi
export DEBIAN_FRONTEND=noninteractive
$SUDO apt-get update -qq
$SUDO apt-get install -y -qq --no-install-recommends "${missing[@]}"
