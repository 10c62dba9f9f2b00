#!/bin/sh
# Sets everything up and runs the whole test suite:
#   1. an ASan + UBSan build running every test not labelled "slow",
#   2. a clang libFuzzer build running each fuzzer for a short time,
#   3. the Release build running every test; its CTest summary is printed last.
# Exit status is non-zero if any stage failed.
set -u
cd "$(dirname "$0")/.."
tools/setup.sh --tests || exit 1
jobs=$(nproc 2>/dev/null || echo 2)
status=0

echo "== ASan + UBSan build =="
if cmake -S . -B build-asan -DCMAKE_BUILD_TYPE=RelWithDebInfo -DIRIS_SANITIZE=ON >/dev/null &&
   cmake --build build-asan -j "$jobs" >/dev/null; then
  ASAN_OPTIONS=detect_leaks=1 UBSAN_OPTIONS=print_stacktrace=1 \
    ctest --test-dir build-asan -j "$jobs" -LE "^(slow|fuzz)$" --output-on-failure --timeout 600 \
    >build-asan/ctest.log 2>&1 || status=1
  tail -n 25 build-asan/ctest.log
else
  echo "test: the sanitizer build failed"; status=1
fi

echo "== libFuzzer build (short runs) =="
if cmake -S . -B build-fuzz -DCMAKE_BUILD_TYPE=RelWithDebInfo -DIRIS_FUZZ=ON \
     -DCMAKE_C_COMPILER=clang -DCMAKE_CXX_COMPILER=clang++ >/dev/null &&
   cmake --build build-fuzz -j "$jobs" --target $(cd tests/fuzz && ls fuzz_*.c | sed 's/\.c$//') >/dev/null; then
  ctest --test-dir build-fuzz -j "$jobs" -L "^fuzz$" --output-on-failure >build-fuzz/ctest.log 2>&1 || status=1
  tail -n 15 build-fuzz/ctest.log
else
  echo "test: the fuzzer build failed"; status=1
fi

echo "== Release build: all tests =="
ctest --test-dir build -j "$jobs" --output-on-failure --timeout 900 || status=1
exit $status
