#!/bin/sh
# Installs the Debian 12 packages iris needs (only the missing ones) and builds
# iris in Release into build/. Usage: tools/setup.sh [--tests]
#   --tests  also installs what the test suite uses (Blender, POV-Ray, clang's
#            fuzzer runtime, OpenImageIO tools, Chromium, Slurm, plotting).
# Runs as root on a fresh Debian 12 machine; with CI=true or no terminal it
# never prompts.
set -eu
cd "$(dirname "$0")/.."

build_pkgs="build-essential cmake pkg-config libembree-dev libopenexr-dev libopenmesh-dev
  libtinygltf-dev nlohmann-json3-dev libstb-dev libcjson-dev libpng-dev zlib1g-dev
  libdraco-dev libmeshoptimizer-dev libwebp-dev"
test_pkgs="clang libclang-rt-14-dev blender povray openimageio-tools assimp-utils
  python3-matplotlib python3-numpy gnuplot-nox chromium slurm-wlm munge gltfpack webp"

pkgs=$build_pkgs
[ "${1:-}" = "--tests" ] && pkgs="$build_pkgs $test_pkgs"

missing=""
for p in $pkgs; do
  if ! dpkg-query -W -f='${Status}' "$p" 2>/dev/null | grep -q "install ok installed"; then
    missing="$missing $p"
  fi
done
if [ -n "$missing" ]; then
  echo "setup: installing Debian packages:$missing"
  SUDO=""
  [ "$(id -u)" -ne 0 ] && SUDO="sudo"
  export DEBIAN_FRONTEND=noninteractive
  $SUDO apt-get update -qq
  # shellcheck disable=SC2086
  $SUDO apt-get install -y -qq --no-install-recommends $missing </dev/null
fi

jobs=$(nproc 2>/dev/null || echo 2)
cmake -S . -B build -DCMAKE_BUILD_TYPE=Release -DIRIS_WERROR=ON >/dev/null
cmake --build build -j "$jobs"
