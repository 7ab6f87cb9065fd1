#!/usr/bin/env bash
# Installs the Debian 12 packages this project builds and runs with; skips what is present.
# Run as root (or with sudo available). Safe to run repeatedly. --test: also what only the tests
# use (Blender).
set -euo pipefail

packages=(
  build-essential cmake ninja-build pkg-config
  libopenvdb-dev libopenvdb-tools libboost-iostreams-dev
  libtbb-dev libglm-dev
  libopenimageio-dev openimageio-tools libopenexr-dev
  libgtest-dev libgmock-dev libbenchmark-dev
  nlohmann-json3-dev libcli11-dev
  libembree-dev
  openmpi-bin libopenmpi-dev
  python3-matplotlib python3-numpy python3-openvdb
)

# Only the tests need these: Blender renders baked proxies as a user would (tool.blender_interop).
if [ "${1:-}" = "--test" ]; then
  packages+=(blender)
fi

missing=()
for p in "${packages[@]}"; do
  if ! dpkg-query -W -f='${Status}' "$p" 2>/dev/null | grep -q "install ok installed"; then
    missing+=("$p")
  fi
done

if [ ${#missing[@]} -eq 0 ]; then
  echo "install-deps: all ${#packages[@]} packages present" >&2
  exit 0
fi

echo "install-deps: installing ${missing[*]}" >&2
sudo=""
if [ "$(id -u)" -ne 0 ]; then sudo="sudo"; fi
export DEBIAN_FRONTEND=noninteractive
$sudo apt-get update -qq
$sudo apt-get install -y -qq --no-install-recommends "${missing[@]}"
