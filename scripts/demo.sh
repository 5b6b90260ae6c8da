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
# the demo's own run folders: a run refuses a folder that holds another, so
# a second demo starts afresh
rm -rf out/vortex_demo out/granular_demo out/lattice_demo
$partix info
echo "== vortex: cylinder, Re = 200"
$partix run cases/vortex/demo_cylinder.yaml --no-progress
echo "== granular: wing rib in a vibrating trough"
$partix run cases/granular/demo.yaml --no-progress
echo "== lattice: steel plate, 100 N at a corner (coarse, h = 2.5 mm)"
$partix run cases/lattice/plate.yaml --set lattice.h=2.5e-3 \
  --set output.every=10000 --out out/lattice_demo --no-progress
$partix summary out/vortex_demo out/granular_demo out/lattice_demo
echo "partix demo: pictures in out/vortex_demo, out/granular_demo, out/lattice_demo"
