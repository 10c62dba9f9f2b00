#!/bin/sh
# The failure-stability suite in one command (docs/stability.md): builds
# stress_suite, renders (or reuses) the mis references, runs every method on
# every stress scene at equal time, re-renders methods that fail the z-tests
# for 8x the time, and writes the table into docs/stability.md between the
# "stress-table" markers, with the command and the machine load.
#
# usage: bench/stress/run_stress.sh [BUILD_DIR [OUT_DIR]] [-- stress_suite options]
#   defaults: BUILD_DIR=build-stress, OUT_DIR=out/stress, --time 4 --ref-time 120
#   STRESS_DOC=path  write the table into another Markdown file (default docs/stability.md)
#   STRESS_NO_DOC=1  leave the doc alone (results stay in OUT_DIR)
# Also regenerates the CI test's stored references (tests/stress/ref, 64 x 48)
# when STRESS_TEST_REFS=1.
# Exit status: that of stress_suite (1 when any method gave NaN/Inf, light in
# the closed box, or a z-test failure that does not shrink with time).
set -eu
ORIG_ARGS="$*"
HERE=$(cd "$(dirname "$0")" && pwd)
ROOT=$(cd "$HERE/../.." && pwd)
B=${1:-$ROOT/build-stress}
O=${2:-$ROOT/out/stress}
[ $# -ge 1 ] && shift
[ $# -ge 1 ] && shift
[ "${1:-}" = "--" ] && shift
DOC=${STRESS_DOC:-$ROOT/docs/stability.md}

if [ ! -f "$B/CMakeCache.txt" ]; then
  cmake -S "$ROOT" -B "$B" -DCMAKE_BUILD_TYPE=Release > /dev/null
fi
cmake --build "$B" -j2 --target stress_suite > /dev/null
SUITE=$B/bench/stress/stress_suite
mkdir -p "$O"

if [ "${STRESS_TEST_REFS:-0}" = 1 ]; then
  # 64 x 48 references for tests/stress at 2048 spp (about a minute each on 2 busy cores)
  "$SUITE" --refs "$ROOT/tests/stress/ref" --refs-only --width 64 --height 48 --ref-spp 2048 --seed 77
fi

CMD="bench/stress/run_stress.sh${ORIG_ARGS:+ $ORIG_ARGS}"
LOAD_BEFORE=$(cut -d' ' -f1-3 /proc/loadavg)
START=$(date +%s)
set +e
"$SUITE" --refs "$O/refs" --images "$O/images" --markdown "$O/table.md" --csv "$O/results.csv" \
  --time 4 --ref-time 120 "$@" 2> "$O/log.txt"
RC=$?
set -e
END=$(date +%s)
LOAD_AFTER=$(cut -d' ' -f1-3 /proc/loadavg)
cat "$O/log.txt" >&2
[ -f "$O/table.md" ] || exit "$RC"
{
  echo "Command: \`$CMD\` (stress_suite exit status $RC, $((END - START)) s wall-clock;"
  echo "$(nproc) cores, load average $LOAD_BEFORE before and $LOAD_AFTER after; $(date -u +%Y-%m-%d))."
  echo
  cat "$O/table.md"
} > "$O/section.md"
if [ "${STRESS_NO_DOC:-0}" != 1 ] && [ -f "$DOC" ] && grep -q '<!-- stress-table:begin -->' "$DOC"; then
  /usr/bin/python3 - "$DOC" "$O/section.md" <<'EOF'
import sys
doc, section = sys.argv[1], open(sys.argv[2]).read()
text = open(doc).read()
a = text.index('<!-- stress-table:begin -->') + len('<!-- stress-table:begin -->')
b = text.index('<!-- stress-table:end -->')
open(doc + '.tmp', 'w').write(text[:a] + '\n' + section + text[b:])
EOF
  mv "$DOC.tmp" "$DOC"
  echo "table written to $DOC" >&2
fi
exit "$RC"
