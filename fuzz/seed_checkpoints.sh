#!/bin/sh
# seed_checkpoints.sh PARTIX CASES DIR: checkpoints of a few steps of one case
# of each solver, as the fuzzers' seeds.
set -eu
# the partix command under ASan: fontconfig keeps its caches at exit (not ours)
export ASAN_OPTIONS="${ASAN_OPTIONS:-}:detect_leaks=0"
partix=$1 cases=$2 dir=$3
mkdir -p "$dir"
tmp=$(mktemp -d)
trap 'rm -rf "$tmp"' EXIT
"$partix" -q run "$cases/vortex/demo_cylinder.yaml" --out "$tmp/v" --steps 3 \
  --set vortex.bodies[0].panels=32 --set output.png=false --no-progress
"$partix" -q run "$cases/lattice/cantilever.yaml" --out "$tmp/l" --steps 3 --set lattice.h=0.002 \
  --set output.png=false --no-progress
"$partix" -q run "$cases/granular/small_box.yaml" --out "$tmp/g" --steps 3 \
  --set granular.media.count=20 --set granular.settle=0 --set output.png=false --no-progress
"$partix" -q run "$cases/lattice/notched.yaml" --out "$tmp/ln" --steps 5 --set lattice.h=1e-3 \
  --set output.png=false --no-progress
"$partix" -q run "$cases/lattice/plate.yaml" --out "$tmp/lp" --steps 12 --set lattice.h=5e-3 \
  --set output.png=false --no-progress
cp "$tmp/ln/checkpoint.pxc" "$dir/lattice_notched.pxc"
cp "$tmp/lp/checkpoint.pxc" "$dir/lattice_plate.pxc"
cp "$tmp/v/checkpoint.pxc" "$dir/vortex.pxc"
cp "$tmp/l/checkpoint.pxc" "$dir/lattice.pxc"
cp "$tmp/g/checkpoint.pxc" "$dir/granular.pxc"
