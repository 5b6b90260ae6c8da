#!/bin/sh
# Each solver's step bench on 1 thread, 2 threads and auto (the thread tuner,
# core/tuner.h, as `partix run` with backend.threads 0), first on an idle
# machine, then with a competing busy loop pinned to one core (taskset),
# alternating idle and busy ROUNDS times (issue 22: 2 threads must not be
# slower than 1 when another process takes a core). Short sizes: it shows
# the ranking, not figures for the docs.
#
# Usage: bench/compete.sh [BUILD_DIR] [ROUNDS]
#   BUSY_CORE=0   the core the busy loop is pinned to
# Prints each bench's JSON lines with two fields put first: "load" ("idle" or
# "busy_core") and "round"; the rest are the bench's own (threads_requested,
# threads_used, tuner, parallel_step_fraction, threads_used_mean, load1_before,
# load1_after, min/median/max where the bench repeats: bench/README.md).
# "idle" means no loop of this script runs; other work on the machine still
# shows in load1_before / load1_after.
set -eu
cd "$(dirname "$0")/.."
build=${1:-build/release}
rounds=${2:-1}
core=${BUSY_CORE:-0}
b="$build/bench"
for p in lattice_step granular_vibrobox vortex_step; do
  [ -x "$b/$p" ] || { echo "compete: $b/$p not found (build first: scripts/build.sh)" >&2; exit 2; }
done
command -v taskset >/dev/null || { echo "compete: taskset not found (util-linux)" >&2; exit 2; }
busy=""
stop_busy() {
  if [ -n "$busy" ]; then
    kill "$busy" 2>/dev/null || true
    wait "$busy" 2>/dev/null || true
    busy=""
  fi
}
trap stop_busy EXIT INT TERM

# tag LOAD ROUND: the bench's lines with the load and round put first
tag() { sed "s/^{/{\"load\":\"$1\",\"round\":$2,/"; }

# one_solver LOAD ROUND: the three benches on 1, 2 threads and auto
benches() {
  for th in 1 2 auto; do
    # lattice: a 40^3 box (64000 elements, 3 engine threads allowed), RK4
    # in both precisions and link schemes, 40 timed steps
    "$b/lattice_step" --sizes 40 --steps 40 --threads "$th" --no-opencl --no-baseline \
      --integrator rk4 | tag "$1" "$2"
    # granular: 4900 discs (2 threads allowed from 4096), 1000 steps settled
    # then 2000 timed; "fixed" keeps the count, "tune" is auto
    if [ "$th" = auto ]; then gth=2 mode=tune; else gth=$th mode=fixed; fi
    "$b/granular_vibrobox" 71 71 1000 2000 "$gth" double verlet "$mode" | tag "$1" "$2"
    # vortex: 20000 vortices, 800 panels, FMM, 8 timed steps (0: auto)
    if [ "$th" = auto ]; then vth=0; else vth=$th; fi
    "$b/vortex_step" 20000 800 cpu double "$vth" 8 fmm 1e-6 | tag "$1" "$2"
  done
}

r=1
while [ "$r" -le "$rounds" ]; do
  benches idle "$r"
  taskset -c "$core" sh -c 'while :; do :; done' &
  busy=$!
  benches busy_core "$r"
  stop_busy
  r=$((r + 1))
done
