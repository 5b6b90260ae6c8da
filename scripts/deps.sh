#!/bin/sh
# Install the Debian 12 packages partix needs; does nothing when all are present.
#   scripts/deps.sh          build + test dependencies
#   scripts/deps.sh --bench  also the peer codes the benchmarks compare with
#                            (LAMMPS, CalculiX)
set -eu

packages="build-essential cmake pkg-config git
  libfyaml-dev
  ocl-icd-opencl-dev opencl-headers pocl-opencl-icd clinfo
  libopenmpi-dev openmpi-bin
  liblapacke-dev libopenblas-dev
  libcairo2-dev fonts-dejavu-core
  python3 python3-dev python3-numpy python3-pytest python3-matplotlib python3-vtk9
  clang libomp-dev libclang-rt-14-dev"

if [ "${1:-}" = "--bench" ]; then
  packages="$packages lammps calculix-ccx hyperfine"
fi

missing=""
for p in $packages; do
  if ! dpkg-query -W -f='${Status}' "$p" 2>/dev/null | grep -q "install ok installed"; then
    missing="$missing $p"
  fi
done

if [ -z "$missing" ]; then
  exit 0
fi

echo "partix: installing missing Debian packages:$missing"
if [ "$(id -u)" -eq 0 ]; then
  sudo=""
elif command -v sudo >/dev/null 2>&1; then
  sudo="sudo"
else
  echo "partix: run as root (or install sudo) to install:$missing" >&2
  exit 1
fi
export DEBIAN_FRONTEND=noninteractive
$sudo apt-get update -qq
# shellcheck disable=SC2086
$sudo apt-get install -y -qq --no-install-recommends $missing
