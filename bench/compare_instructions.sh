#!/bin/sh
# Instructions executed per step by two builds (valgrind's callgrind), for
# the three solvers' step benchmarks on one thread: a figure that does not
# move with the load of a shared machine, to go with the timings of
# bench/compare_builds.sh (which on a shared VM can spread by 2x).
#
#   bench/compare_instructions.sh OLD_BUILD NEW_BUILD
#
# Both builds without -march=native (valgrind does not run AVX-512 code):
#   cmake -S . -B build/cg -DCMAKE_BUILD_TYPE=Release -DPX_NATIVE=OFF -DPX_BUILD_TESTS=OFF
#   cmake --build build/cg --target vortex_step granular_vibrobox lattice_step
#
# Each figure is the difference of two runs that differ only in the number
# of steps, so set-up and start-up cancel:
#   vortex_double, vortex_mixed: vortex_step, 4000 vortices, 400 panels,
#       direct sums: 2 steps;
#   granular: granular_vibrobox, 30 x 30 box (841 discs), double, Verlet:
#       2000 steps;
#   lattice: lattice_step, 16^3 box, every cpu configuration (RK4 and
#       leapfrog, single and double, both link schemes): 4 RK4 and 16
#       leapfrog steps each.
# Prints one JSON line per figure: instructions of each build and new/old.
set -eu
[ $# -eq 2 ] || { sed -n 2,22p "$0"; exit 2; }
command -v valgrind >/dev/null || { echo "compare_instructions: no valgrind" >&2; exit 2; }
tmp=$(mktemp -d) || exit 2
trap 'rm -rf "$tmp"' EXIT
export OMP_NUM_THREADS=1

ir() { # instructions of one run of "$@"
  valgrind --tool=callgrind --callgrind-out-file="$tmp/cg" "$@" >/dev/null 2>&1 ||
    { echo "compare_instructions: failed under valgrind: $*" >&2; exit 1; }
  awk '/^(summary|totals):/ {print $2; exit}' "$tmp/cg"
}

steps() { # FIGURE BUILD: instructions of the steps the figure counts
  b=$2/bench
  [ -x "$b/vortex_step" ] || { echo "compare_instructions: no $b (build first)" >&2; exit 2; }
  case $1 in
    vortex_double | vortex_mixed)
      p=${1#vortex_}
      echo $(($(ir "$b/vortex_step" 4000 400 cpu "$p" 1 3 direct) -
        $(ir "$b/vortex_step" 4000 400 cpu "$p" 1 1 direct)))
      ;;
    granular)
      echo $(($(ir "$b/granular_vibrobox" 30 30 100 3000 1 double verlet fixed) -
        $(ir "$b/granular_vibrobox" 30 30 100 1000 1 double verlet fixed)))
      ;;
    lattice)
      echo $(($(ir "$b/lattice_step" --sizes 16 --steps 6 --threads 1 --no-opencl --no-baseline) -
        $(ir "$b/lattice_step" --sizes 16 --steps 2 --threads 1 --no-opencl --no-baseline)))
      ;;
  esac
}

for f in vortex_double vortex_mixed granular lattice; do
  o=$(steps "$f" "$1")
  n=$(steps "$f" "$2")
  python3 -c "import json, sys; o, n = int(sys.argv[2]), int(sys.argv[3]); \
print(json.dumps({'figure': sys.argv[1], 'old_instructions': o, 'new_instructions': n, \
'new_over_old': round(n / o, 4)}))" "$f" "$o" "$n"
done
