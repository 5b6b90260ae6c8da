#!/bin/sh
# Long fuzzing runs: bench/fuzz.sh [SECONDS] [TARGET...]
# Builds the libFuzzer harnesses (build/fuzz: clang, ASan + UBSan, PX_FUZZ)
# and runs each target for SECONDS (default 3600) on one core, keeping its
# corpus in build/fuzz/fuzz/corpus/TARGET between runs. A finding is written
# as build/fuzz/fuzz/TARGET-crash-* (or leak-, timeout-, oom-): copy it into
# fuzz/regressions/TARGET/ with the fix, so that every ctest run replays it.
# Prints one JSON line per target with its executions and findings.
set -eu
cd "$(dirname "$0")/.."
seconds=${1:-3600}
[ $# -gt 0 ] && shift
targets=${*:-"fuzz_case fuzz_checkpoint fuzz_resume fuzz_dxf fuzz_selig fuzz_mesh"}
CC=clang cmake -S . -B build/fuzz -DCMAKE_BUILD_TYPE=RelWithDebInfo -DPX_SANITIZE=ON \
  -DPX_FUZZ=ON -DPX_BUILD_TESTS=OFF -DPX_BUILD_BENCH=OFF >/dev/null
cmake --build build/fuzz -j "$(nproc)" >/dev/null
ctest --test-dir build/fuzz -R fuzz_seed >/dev/null
for t in $targets; do
  exe=build/fuzz/fuzz/$t
  [ -x "$exe" ] || { echo "{\"target\":\"$t\",\"error\":\"not built\"}"; continue; }
  mkdir -p "build/fuzz/fuzz/corpus/$t"
  seeds=""
  [ -d "build/fuzz/fuzz/seeds/${t#fuzz_}" ] && seeds="build/fuzz/fuzz/seeds/${t#fuzz_}"
  log="build/fuzz/fuzz/$t.log"
  status=0
  OMP_NUM_THREADS=1 "$exe" -max_total_time="$seconds" -timeout=20 -rss_limit_mb=3000 \
    -print_final_stats=1 -artifact_prefix="build/fuzz/fuzz/$t-" \
    "build/fuzz/fuzz/corpus/$t" "fuzz/regressions/$t" $seeds >"$log" 2>&1 || status=$?
  execs=$(sed -n 's/^stat::number_of_executed_units: *//p' "$log" | tail -1)
  corpus=$(ls "build/fuzz/fuzz/corpus/$t" | wc -l)
  echo "{\"target\":\"$t\",\"seconds\":$seconds,\"executions\":${execs:-0},\"corpus\":$corpus,\"exit\":$status,\"log\":\"$log\"}"
done
