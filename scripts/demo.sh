#!/bin/sh
# Set up a Debian 12 machine, build partix and run the demo.
set -eu
cd "$(dirname "$0")/.."
scripts/deps.sh
scripts/build.sh
build/release/partix info
