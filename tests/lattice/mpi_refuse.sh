#!/bin/sh
# mpi_refuse.sh PARTIX CASES: what the lattice cannot run over ranks is
# refused by key before any step, with the reason: more ranks than z-planes
# (lattice.body), on the cpu and (when built with it) the opencl engine.
# Exit 77 (ctest: skipped) without mpirun.
set -u
partix=$1 cases=$2
command -v mpirun >/dev/null 2>&1 || {
  echo "mpi_refuse: no mpirun"
  exit 77
}
root=""
[ "$(id -u)" = 0 ] && root=--allow-run-as-root
export ASAN_OPTIONS="${ASAN_OPTIONS:+$ASAN_OPTIONS:}detect_leaks=0"
tmp=$(mktemp -d) || exit 1
trap 'rm -rf "$tmp"' EXIT
fails=0
refused() { # refused NAME PATTERN ARGS...: a 2-rank run exits non-zero saying PATTERN
  name=$1 pattern=$2
  shift 2
  (cd "$tmp" && mpirun $root --oversubscribe -np 2 "$partix" -q run --threads 1 --no-progress \
    --out "$name" "$@") >"$tmp/$name.txt" 2>&1 && {
    fails=$((fails + 1))
    echo "FAIL: $name ran"
    return
  }
  grep -q "$pattern" "$tmp/$name.txt" || {
    fails=$((fails + 1))
    echo "FAIL: $name: no '$pattern' in:"
    sed 's/^/  | /' "$tmp/$name.txt" | head -10
  }
  [ ! -e "$tmp/$name/checkpoint.pxc" ] || {
    fails=$((fails + 1))
    echo "FAIL: $name wrote a checkpoint"
  }
}
# the plate at h = 5 mm is one element thick
refused thin "lattice.body: 2 ranks, but the body's grid (20 x 10 x 1 cells.*only 1 z-plane" \
  "$cases/lattice/plate.yaml" --steps 5 --set lattice.h=0.005
if "$partix" info 2>/dev/null | grep -q 'opencl platform'; then
  refused thin_opencl "lattice.body: 2 ranks, but the body's grid (20 x 10 x 1 cells" \
    "$cases/lattice/plate.yaml" --steps 5 --set lattice.h=0.005 --backend opencl
fi
echo "mpi_refuse: $fails failed"
[ $fails -eq 0 ]
