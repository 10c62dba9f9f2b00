#!/bin/sh
# A long libFuzzer campaign over every harness in tests/fuzz, resumable.
#
#   tools/fuzz_campaign.sh [--build DIR] [--state DIR] [--hours H] [--slice S]
#                          [--merge-every K] [--timeout T] [--harness NAME]...
#
# The harnesses take turns in slices of S seconds (default 600) until H hours
# (default 8) of fuzzing have been spent in this invocation, so that stopping
# at any moment leaves every harness with a fair share. Everything lives in the
# state folder (default DIR/campaign): per harness a growing corpus/, the
# findings in artifacts/, one log per slice in logs/, and one line per slice
# in stats.tsv (harness, slice, seconds, executions, cov, ft, corpus units,
# slowest input in s, peak RSS MB, findings so far). Running the script again
# with the same state folder resumes: the corpus is kept, slices are numbered
# on, and totals add up (tools/fuzz_campaign.sh --report prints them).
# Every K slices of a harness (default 4) and at the end its corpus is
# minimised with -merge=1 (the seeds are read again each slice, never written).
# libFuzzer's timeout is wall-clock; a timeout whose input re-runs in less than
# half the timeout of CPU time moves to slow-under-load/ instead of counting.
#
# Seeds per harness are those of the fuzz.<format>.short tests (docs/fuzzing.md):
# tests/fuzz/corpus/<format>/, shared/assets/<format>/, shared/assets/bad/<format>/
# and the findings shared/fuzz-findings/<format>-*.
# Build first:
#   cmake -S . -B build-fuzz -DCMAKE_C_COMPILER=clang -DCMAKE_CXX_COMPILER=clang++ \
#         -DCMAKE_BUILD_TYPE=RelWithDebInfo -DIRIS_FUZZ=ON
#   cmake --build build-fuzz -j2 --target $(cd tests/fuzz && ls fuzz_*.c | sed 's/\.c$//')
set -u
cd "$(dirname "$0")/.." || exit 1
build=build-fuzz
state=
hours=8
slice=600
merge_every=4
timeout=2
harnesses=
report_only=0
while [ $# -gt 0 ]; do
  case "$1" in
    --build) build=$2; shift 2 ;;
    --state) state=$2; shift 2 ;;
    --hours) hours=$2; shift 2 ;;
    --slice) slice=$2; shift 2 ;;
    --merge-every) merge_every=$2; shift 2 ;;
    --timeout) timeout=$2; shift 2 ;;
    --harness) harnesses="$harnesses $2"; shift 2 ;;
    --report) report_only=1; shift ;;
    -h|--help) sed -n '2,27p' "$0"; exit 0 ;;
    *) echo "fuzz_campaign: unknown argument '$1'" >&2; exit 2 ;;
  esac
done
[ -n "$state" ] || state=$build/campaign
shared=${IRIS_SHARED_DIR:-../shared}
[ -d "$shared/assets" ] || shared=$(cd .. && pwd)/shared
[ -n "$harnesses" ] || harnesses=$(cd tests/fuzz && ls fuzz_*.c | sed 's/\.c$//')
mkdir -p "$state"
stats=$state/stats.tsv
[ -f "$stats" ] || printf 'harness\tslice\tseconds\texecs\tcov\tft\tunits\tslowest_s\trss_mb\tfindings\n' >"$stats"

report() {
  echo "| harness | hours | executions | exec/s | cov | ft | corpus units | slowest input s | findings |"
  echo "|---|---:|---:|---:|---:|---:|---:|---:|---:|"
  awk -F'\t' 'NR > 1 { s[$1] += $3; e[$1] += $4; cov[$1] = $5; ft[$1] = $6; u[$1] = $7;
                       if ($8 > slow[$1]) slow[$1] = $8; f[$1] = $10 }
    END { for (h in s) printf "| %s | %.2f | %d | %.0f | %s | %s | %s | %.2f | %s |\n",
                              h, s[h] / 3600, e[h], e[h] / (s[h] > 0 ? s[h] : 1), cov[h], ft[h], u[h], slow[h], f[h] }' "$stats" | sort
}
if [ "$report_only" = 1 ]; then report; exit 0; fi

seeds_of() { # harness -> seed folders (space separated; none contains a space)
  f=${1#fuzz_}
  for d in tests/fuzz/corpus/$f tests/fuzz/corpus/$1 "$shared/assets/$f" "$shared/assets/bad/$f" "$state/$1/findings-seeds"; do
    [ -d "$d" ] && printf '%s ' "$d"
  done
}

minimise() { # harness
  dir=$state/$1
  [ -d "$dir/corpus" ] || return 0
  rm -rf "$dir/corpus.min" && mkdir -p "$dir/corpus.min"
  if "$build/tests/fuzz/$1" -merge=1 -timeout="$timeout" -rss_limit_mb=2048 -max_len=1048576 \
       "$dir/corpus.min" "$dir/corpus" >"$dir/logs/merge.log" 2>&1; then
    rm -rf "$dir/corpus" && mv "$dir/corpus.min" "$dir/corpus"
  else
    echo "fuzz_campaign: $1: minimisation failed (see $dir/logs/merge.log); corpus kept"
    rm -rf "$dir/corpus.min"
  fi
}

for h in $harnesses; do
  [ -x "$build/tests/fuzz/$h" ] || { echo "fuzz_campaign: $build/tests/fuzz/$h missing (build it first)" >&2; exit 2; }
  mkdir -p "$state/$h/corpus" "$state/$h/artifacts" "$state/$h/logs" "$state/$h/findings-seeds"
  for f in "$shared"/fuzz-findings/"${h#fuzz_}"-*; do
    [ -f "$f" ] && cp -n "$f" "$state/$h/findings-seeds/"
  done
done

budget=$(awk -v h="$hours" 'BEGIN { printf "%d", h * 3600 }')
spent=0
while [ "$spent" -lt "$budget" ]; do
  for h in $harnesses; do
    [ "$spent" -lt "$budget" ] || break
    dir=$state/$h
    n=$(awk -F'\t' -v h="$h" '$1 == h { n = $2 } END { print n + 1 }' "$stats")
    log=$dir/logs/slice-$n.log
    left=$((budget - spent)); secs=$slice; [ "$left" -lt "$secs" ] && secs=$left
    start=$(date +%s)
    # shellcheck disable=SC2046
    "$build/tests/fuzz/$h" "$dir/corpus" $(seeds_of "$h") -max_total_time="$secs" \
      -timeout="$timeout" -rss_limit_mb=2048 -max_len=1048576 -print_final_stats=1 \
      -artifact_prefix="$dir/artifacts/" >"$log" 2>&1
    rc=$?
    took=$(( $(date +%s) - start )); spent=$((spent + took))
    execs=$(sed -n 's/^stat::number_of_executed_units: *//p' "$log" | tail -n 1)
    slowest=$(sed -n 's/^stat::slowest_unit_time_sec: *//p' "$log" | tail -n 1)
    rss=$(sed -n 's/^stat::peak_rss_mb: *//p' "$log" | tail -n 1)
    line=$(grep -E '^#[0-9]+' "$log" | grep 'cov:' | tail -n 1)
    cov=$(printf '%s' "$line" | sed -n 's/.* cov: \([0-9]*\).*/\1/p')
    ft=$(printf '%s' "$line" | sed -n 's/.* ft: \([0-9]*\).*/\1/p')
    [ -n "$execs" ] || execs=$(printf '%s' "$line" | sed -n 's/^#\([0-9]*\).*/\1/p')
    # libFuzzer's timeout is wall-clock: re-run each new timeout and keep it as
    # a finding only when its CPU time is at least half the timeout.
    for t in "$dir"/artifacts/timeout-*; do
      [ -f "$t" ] || continue
      /usr/bin/time -f '%U' -o "$dir/.cpu" "$build/tests/fuzz/$h" "$t" >/dev/null 2>&1
      cpu=$(tail -n 1 "$dir/.cpu" 2>/dev/null)
      if awk -v c="${cpu:-999}" -v t="$timeout" 'BEGIN { exit !(c < t / 2) }'; then
        mkdir -p "$dir/slow-under-load" && mv "$t" "$dir/slow-under-load/"
        echo "fuzz_campaign: $h: $(basename "$t") takes ${cpu} s CPU: a timeout under load, not a finding"
      fi
    done
    units=$(ls "$dir/corpus" | wc -l)
    findings=$(ls "$dir/artifacts" | wc -l)
    printf '%s\t%s\t%s\t%s\t%s\t%s\t%s\t%s\t%s\t%s\n' "$h" "$n" "$took" "${execs:-0}" "${cov:-}" \
      "${ft:-}" "$units" "${slowest:-0}" "${rss:-0}" "$findings" >>"$stats"
    echo "fuzz_campaign: $h slice $n: ${took}s, ${execs:-0} executions, cov ${cov:-?}, rc $rc, findings $findings"
    [ $((n % merge_every)) -eq 0 ] && minimise "$h"
  done
done
for h in $harnesses; do minimise "$h"; done
report
