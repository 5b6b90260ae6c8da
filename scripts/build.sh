#!/bin/sh
# Configure and build partix (Release, warnings as errors) into build/release.
#   scripts/build.sh [extra cmake arguments]
set -eu
cd "$(dirname "$0")/.."
jobs=$(nproc 2>/dev/null || echo 2)
cmake -S . -B build/release -DCMAKE_BUILD_TYPE=Release -DPX_WERROR=ON "$@" >/dev/null
cmake --build build/release -j "$jobs"
