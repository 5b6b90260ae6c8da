#!/bin/sh
# The OpenCL device figures quoted in docs/notes/device-2026-11-27.md, on
# the default OpenCL device (the first GPU or accelerator: `partix info`
# marks it) next to the CPU at T threads:
#
#   bench/gpu_figures.sh [BUILD] [T]
#
# BUILD: the build folder (default build/release); T: CPU threads (default
# all of nproc). Prints the benches' own JSON lines (bench/README.md), each
# prefixed with its part's name, then one JSON line per granular run:
#   nbody    the direct Biot-Savart sum, N = 1e5 and 1e6 on the device, 1e5
#            on the CPU, single and double;
#   vortex   one vortex step at the paper's size (N = 50k, n = 2576) with
#            the device's direct sum (mixed), at N = 200k, and the CPU's FMM
#            on T threads and on 1;
#   lattice  lattice_step at 10^6 and 10^7 elements, every engine;
#   granular cases/granular/flagship.yaml (20,000 discs), 2,000 steps,
#            backend opencl against cpu on T threads (run.log's time loop).
# Each part has its own time limit (timeout), so a slow device still prints
# the parts before it.
set -u
cd "$(dirname "$0")/.."
build=${1:-build/release}
threads=${2:-$(nproc)}
b=$build/bench
[ -x "$build/partix" ] || { echo "gpu_figures: no $build/partix (build first)" >&2; exit 2; }
part() { # NAME LIMIT COMMAND...
  name=$1 limit=$2
  shift 2
  timeout "$limit" "$@" | sed "s/^/$name /"
}
part nbody 120 "$b/nbody_direct" --backend opencl --n 100000,1000000 --precision all --reps 3
part nbody 120 "$b/nbody_direct" --backend cpu --n 100000 --precision all --threads "$threads" --reps 3
part vortex 60 "$b/vortex_step" 50000 2576 opencl mixed "$threads" 5 direct 1e-6 euler none
part vortex 60 "$b/vortex_step" 200000 2576 opencl mixed "$threads" 3 direct 1e-6 euler none
part vortex 60 "$b/vortex_step" 50000 2576 cpu mixed "$threads" 5 fmm 1e-6 euler none
part vortex 60 "$b/vortex_step" 50000 2576 cpu mixed 1 3 fmm 1e-6 euler none
part lattice 300 "$b/lattice_step" --sizes 100,215 --steps 20 --threads "$threads"
tmp=$(mktemp -d) || exit 2
trap 'rm -rf "$tmp"' EXIT
for be in opencl cpu; do
  timeout 120 "$build/partix" -q run cases/granular/flagship.yaml --steps 2000 --backend "$be" \
    --threads "$threads" --set output.vtk=false --set output.png=false --out "$tmp/$be" \
    --no-progress >/dev/null 2>&1 || { echo "gpu_figures: granular $be failed" >&2; continue; }
  sed -n 's/.* \([0-9][0-9]*\) steps in [0-9.]* s (.*; steps \([0-9.]*\) s.*/\1 \2/p' "$tmp/$be/run.log" | tail -n 1 |
    awk -v be="$be" -v t="$threads" '{ printf "granular {\"bench\":\"granular_flagship\",\"backend\":\"%s\",\"threads\":%s,\"discs\":20000,\"steps\":%s,\"s_per_step\":%.6g}\n", be, t, $1, $2 / $1 }'
done
