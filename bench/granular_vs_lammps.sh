#!/bin/sh
# The 2D vibrating box run by partix and by LAMMPS side by side (issue 4):
# N = (nx-1)(ny-1) discs (9801 by default), kn = 2e5 N/m, e = 0.8, mu = 0.4,
# dt = t_c/25, box on a circular orbit (A = 2 mm, 25 Hz), settled for
# NSETTLE steps, then NSTEPS steps timed. Prints one JSON line per code and
# run, and the ratio of disc-steps per second (partix / LAMMPS) on the same
# number of cores.
#
# Usage: bench/granular_vs_lammps.sh [BUILD_DIR] [NX] [NY] [NSETTLE] [NSTEPS]
# Needs Debian's lammps (scripts/deps.sh --bench) and OpenMPI.
# On a machine shared with other work, set OMP_WAIT_POLICY=passive (spinning
# OpenMP barriers then lose less; partix also drops to one thread by itself
# when that is faster). Every line carries the 1-minute load average
# ("load1") of the machine when the run ended; partix's lines also the
# fraction of timed steps its thread tuner ran on more than one thread.
# With 2 cores partix runs three times: with the tuner ("tuner":"tune", as
# `partix run` does), forced to 2 threads ("tuner":"fixed"), and on 1
# thread; the ratio lines give partix / LAMMPS for the first two, and
# "partix_threads_speedup" 2 threads over 1. REPS=k (environment) repeats
# the whole sequence k times, each line tagged "rep", and ends each core
# count with a "summary" line: min, median and max of each ratio. To
# measure on given free cores of a larger machine: `taskset -c 2,3 env
# CORES=2 sh bench/...` (LAMMPS's ranks and partix's threads inherit the
# cores).
set -eu
cd "$(dirname "$0")/.."
build=${1:-build/release}
nx=${2:-100}
ny=${3:-100}
nsettle=${4:-150000}
nsteps=${5:-20000}
exe="$build/bench/granular_vibrobox"
if [ ! -x "$exe" ]; then
  echo "granular_vs_lammps: $exe not found (build first: scripts/build.sh)" >&2
  exit 2
fi
if ! command -v lmp >/dev/null 2>&1; then
  echo "granular_vs_lammps: lmp not found; install with scripts/deps.sh --bench" >&2
  exit 2
fi
tmp=$(mktemp -d)
trap 'rm -rf "$tmp"' EXIT

lammps() { # ranks -> disc-steps/s of the timed run
  np=$1
  ( cd "$tmp" && sed "s/^processors .*/processors $np 1 1/" "$OLDPWD/bench/granular_vibro2d.lmp" > in.lmp &&
    mpirun --allow-run-as-root --oversubscribe -np "$np" lmp -in in.lmp -var nx "$nx" -var ny "$ny" \
      -var nsettle "$nsettle" -var nsteps "$nsteps" -log log.lammps -screen none >/dev/null 2>&1 )
  # the last "Loop time of T on P procs for S steps with N atoms" is the timed
  # run, followed by "C% CPU use with P MPI tasks ...": the CPU time it used
  # (on a shared machine the wall-time rate mostly measures the load)
  cpu=$(grep "% CPU use with" "$tmp/log.lammps" | tail -1 | sed 's/%.*//')
  grep "^Loop time" "$tmp/log.lammps" | tail -1 |
    awk -v np="$np" -v load="$(load1)" -v cpu="${cpu:-0}" '{t=$4; s=$9; n=$12; c=t*np*cpu/100; printf("{\"bench\":\"granular_vs_lammps\",\"code\":\"lammps\",\"ranks\":%d,\"n\":%d,\"steps\":%d,\"seconds\":%.4f,\"cpu_seconds\":%.4f,\"disc_steps_per_s\":%.4g,\"disc_steps_per_cpu_s\":%.4g,\"load1\":%s}\n", np, n, s, t, c, n*s/t, c > 0 ? n*s/c : 0, load)}'
}

load1() { cut -d' ' -f1 /proc/loadavg; }

partix() { # threads tune|fixed -> JSON line of granular_vibrobox
  "$exe" "$nx" "$ny" "$nsettle" "$nsteps" "$1" mixed verlet "$2" |
    sed 's/"bench":"granular_vibrobox"/"bench":"granular_vs_lammps"/'
}

rate() { sed 's/.*"disc_steps_per_s":\([0-9.e+-]*\).*/\1/'; }
cpurate() { sed 's/.*"disc_steps_per_cpu_s":\([0-9.e+-]*\).*/\1/'; }

# min, median and max of the numbers on stdin as "NAME_min":..,"NAME_median":..,"NAME_max":..
stats() {
  sort -g | awk -v n="$1" '{v[NR] = $1}
    END {m = NR % 2 ? v[(NR + 1) / 2] : (v[NR / 2] + v[NR / 2 + 1]) / 2;
      printf("\"%s_min\":%.3f,\"%s_median\":%.3f,\"%s_max\":%.3f", n, v[1], n, m, n, v[NR])}'
}

reps=${REPS:-1}
for cores in ${CORES:-2 1}; do
  rtune="" rfixed="" rspeed=""
  rep=1
  while [ "$rep" -le "$reps" ]; do
    tag() { sed "s/^{/{\"rep\":$rep,/"; }
    l=$(lammps "$cores" | tag)
    echo "$l"
    lr=$(echo "$l" | rate)
    modes="tune"
    [ "$cores" -gt 1 ] && modes="tune fixed"
    for mode in $modes; do
      p=$(partix "$cores" "$mode" | tag)
      echo "$p"
      pr=$(echo "$p" | rate)
      ratio=$(awk -v a="$pr" -v b="$lr" 'BEGIN{printf("%.3f", a/b)}')
      awk -v a="$pr" -v b="$lr" -v ac="$(echo "$p" | cpurate)" -v bc="$(echo "$l" | cpurate)" -v c="$cores" -v m="$mode" -v r="$rep" 'BEGIN{printf("{\"rep\":%d,\"bench\":\"granular_vs_lammps\",\"cores\":%d,\"tuner\":\"%s\",\"ratio_partix_over_lammps\":%.3f,\"ratio_per_cpu_second\":%.3f}\n", r, c, m, a/b, bc > 0 ? ac/bc : 0)}'
      if [ "$mode" = fixed ]; then
        p2=$pr
        rfixed="$rfixed $ratio"
      else
        rtune="$rtune $ratio"
      fi
    done
    if [ "$cores" -gt 1 ]; then
      # partix on 1 thread of the same cores: the threads' speed-up (forced
      # to `cores` threads over 1)
      p1=$(partix 1 fixed | tag)
      echo "$p1"
      sp=$(awk -v a="$p2" -v b="$(echo "$p1" | rate)" 'BEGIN{printf("%.3f", a/b)}')
      rspeed="$rspeed $sp"
      printf '{"rep":%d,"bench":"granular_vs_lammps","cores":%d,"partix_threads_speedup":%s}\n' \
        "$rep" "$cores" "$sp"
    fi
    rep=$((rep + 1))
  done
  if [ "$reps" -gt 1 ]; then
    # over the repetitions (each a LAMMPS run and the partix runs right after
    # it: a host whose speed drifts between the repetitions moves each
    # ratio less than the rates)
    sum="{\"bench\":\"granular_vs_lammps\",\"summary\":true,\"cores\":$cores,\"reps\":$reps"
    sum="$sum,$(printf '%s\n' $rtune | stats ratio_tune)"
    [ -n "$rfixed" ] && sum="$sum,$(printf '%s\n' $rfixed | stats ratio_fixed)"
    [ -n "$rspeed" ] && sum="$sum,$(printf '%s\n' $rspeed | stats partix_threads_speedup)"
    echo "$sum}"
  fi
done
