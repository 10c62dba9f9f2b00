#!/bin/sh
# Render-pass seconds of two iris binaries (or one binary with two option
# sets), alternating, one thread, paired medians: bench/render/cpu_ab.sh with
# MEASURE=passes (its header says what is measured and how far to trust it),
# with defaults for the per-sample cost of the guided methods.
# usage: bench/render/passes_ab.sh IRIS_A IRIS_B SCENE METHOD [SPP [PAIRS [WIDTH HEIGHT]]]
# (env ARGS_A / ARGS_B: more `iris render` options for A / B)
# e.g. bench/render/passes_ab.sh /tmp/base/build/tools/iris build/tools/iris sky-room guided-nee 48 10
set -eu
MEASURE=passes exec "$(dirname "$0")/cpu_ab.sh" "$1" "$2" "$3" "$4" "${5:-48}" "${6:-10}" "${7:-108}" "${8:-72}"
