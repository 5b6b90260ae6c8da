#!/bin/sh
# mpi_refuse.sh PARTIX CASES: what the granular solver cannot run over ranks
# is refused by key before any step, with the reason: the opencl engine
# (backend.type, when built with it and a platform is present; its state
# lives on one device). Exit 77 (ctest: skipped) without mpirun or without an
# opencl platform.
set -u
partix=$1 cases=$2
command -v mpirun >/dev/null 2>&1 || {
  echo "mpi_refuse: no mpirun"
  exit 77
}
"$partix" info 2>/dev/null | grep -q 'opencl platform' || {
  echo "mpi_refuse: no opencl platform"
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
refused opencl "backend.type: the opencl engine runs on one rank only (2 ranks asked)" \
  "$cases/granular/small_box.yaml" --steps 5 --backend opencl
echo "mpi_refuse: $fails failed"
[ $fails -eq 0 ]
