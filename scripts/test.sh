#!/bin/sh
# Set up a Debian 12 machine, build partix and run the test suite:
#  1. Release build with gcc, warnings as errors: every test except label `long`
#     (includes the OpenCL conformance tests on POCL's CPU device);
#  2. ASan + UBSan build with clang, warnings as errors: tests labelled `sanitize`;
#  3. the libFuzzer harnesses (fuzz/), 60 s each (longer runs: bench/fuzz.sh).
# Longer validations: ctest --test-dir build/release -L long (see bench/).
set -eu
cd "$(dirname "$0")/.."
scripts/deps.sh
jobs=$(nproc 2>/dev/null || echo 2)
start=$(date +%s)

echo "== Release build (gcc) =="
# the Python module is part of what is tested: a missing NumPy is an error here
CC=gcc scripts/build.sh -DPX_WITH_PYTHON=ON
echo "== Tests (Release) =="
ctest --test-dir build/release -LE long --output-on-failure -j "$jobs"

echo "== ASan+UBSan build (clang) =="
CC=clang cmake -S . -B build/asan -DCMAKE_BUILD_TYPE=RelWithDebInfo -DPX_WERROR=ON \
  -DPX_SANITIZE=ON -DPX_BUILD_BENCH=OFF >/dev/null
cmake --build build/asan -j "$jobs"
echo "== Tests (ASan+UBSan) =="
ASAN_OPTIONS=detect_leaks=1:abort_on_error=1 UBSAN_OPTIONS=print_stacktrace=1 \
  ctest --test-dir build/asan -L sanitize --output-on-failure -j "$jobs"

echo "== Fuzzing (libFuzzer + ASan + UBSan, clang) =="
# Its own build: the coverage counters libFuzzer needs slow every other test.
CC=clang cmake -S . -B build/fuzz -DCMAKE_BUILD_TYPE=RelWithDebInfo -DPX_WERROR=ON \
  -DPX_SANITIZE=ON -DPX_FUZZ=ON -DPX_BUILD_TESTS=OFF -DPX_BUILD_BENCH=OFF >/dev/null
cmake --build build/fuzz -j "$jobs"
ASAN_OPTIONS=detect_leaks=1 UBSAN_OPTIONS=print_stacktrace=1 \
  ctest --test-dir build/fuzz -L fuzz --output-on-failure -j "$jobs"

echo "partix: all tests passed in $(( $(date +%s) - start )) s"
