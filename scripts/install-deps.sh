#!/usr/bin/env bash
# Installs poundsim's build and test dependencies from Debian packages (Debian 12 "bookworm").
# Runs apt-get only for what is missing; uses sudo when not root.
set -euo pipefail

packages=(
  g++ cmake ninja-build pkg-config
  libeigen3-dev libtomlplusplus-dev nlohmann-json3-dev libcli11-dev libfmt-dev
  libgtest-dev libgmock-dev libbenchmark-dev
  libsqlite3-dev libsqlitecpp-dev libnlopt-dev libnlopt-cxx-dev
  python3 python3-dev python3-matplotlib python3-numpy python3-pandas python3-pytest python3-jsonschema pybind11-dev
  clang-14 libclang-rt-14-dev
  libopenmpi-dev openmpi-bin
)

missing=()
for p in "${packages[@]}"; do
  if ! dpkg-query -W -f='${Status}' "$p" 2>/dev/null | grep -q "install ok installed"; then
    missing+=("$p")
  fi
done
if [ ${#missing[@]} -eq 0 ]; then
  exit 0
fi

if [ "$(id -u)" -eq 0 ]; then sudo=(); else sudo=(sudo); fi
echo "install-deps: installing ${missing[*]}"
"${sudo[@]}" apt-get update -qq
DEBIAN_FRONTEND=noninteractive "${sudo[@]}" apt-get install -y -qq --no-install-recommends "${missing[@]}"
