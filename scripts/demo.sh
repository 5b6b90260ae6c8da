#!/bin/sh
# Set up a Debian 12 machine, build partix and run one short case of each
# solver (about a minute in all on 2 cores). Pictures land in out/:
#   out/vortex_demo/wake_*.png, loads.png        flow past a cylinder, Re = 200
#   out/granular_demo/particles_*.png, *_energy_n_area.png
#                                                 wing rib in a vibrating trough
#   out/lattice_demo/*.png                        steel plate under a corner load
set -eu
cd "$(dirname "$0")/.."
scripts/deps.sh
scripts/build.sh
partix=build/release/partix
$partix info
for case in cases/vortex/demo_cylinder.yaml cases/granular/demo.yaml @LATTICE@; do
  echo "== partix run $case"
  $partix run "$case" --no-progress
done
echo "partix demo: pictures in out/vortex_demo, out/granular_demo, out/lattice_demo"
