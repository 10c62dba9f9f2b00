#!/bin/sh
# The main job: set everything up, then render the built-in Cornell box with
# the default method to out/cornell-box.exr and out/cornell-box.png.
set -eu
cd "$(dirname "$0")/.."
tools/setup.sh
mkdir -p out
build/tools/iris render cornell-box --spp 256 -o out/cornell-box.exr --png out/cornell-box.png
echo "demo: wrote out/cornell-box.exr and out/cornell-box.png"
