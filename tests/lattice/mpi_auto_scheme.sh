#!/bin/sh
# mpi_auto_scheme.sh PARTIX CASE ARG...: with lattice.scheme auto, a lattice
# with fewer z-planes than ranks runs with the gather scheme on a y x z rank
# grid instead of being refused (link_once splits z only): `partix run CASE
# ARG...` on 2 MPI ranks (one thread each) succeeds, its run.log names the
# choice, and its probes.csv equals that of one process with
# lattice.scheme=gather, byte for byte. Exit 77 (ctest: skipped) without
# mpirun or an MPI build.
set -u
partix=$1 case=$2
shift 2
case "$partix" in /*) ;; *) partix=$(pwd)/$partix ;; esac
case "$case" in /*) ;; *) case=$(pwd)/$case ;; esac
command -v mpirun >/dev/null 2>&1 || { echo "mpi_auto_scheme: no mpirun"; exit 77; }
"$partix" info 2>/dev/null | grep -q '^MPI: yes' || { echo "mpi_auto_scheme: no MPI"; exit 77; }
root=""
[ "$(id -u)" = 0 ] && root=--allow-run-as-root
export ASAN_OPTIONS="${ASAN_OPTIONS:+$ASAN_OPTIONS:}detect_leaks=0"
tmp=$(mktemp -d) || exit 1
trap 'rm -rf "$tmp"' EXIT
# Open MPI's session folder under this test's own folder: two mpirun
# started at once (ctest -j) race to create the shared /tmp/ompi.HOST.UID
# ("orte_session_dir failed ... File exists")
export OMPI_MCA_orte_tmpdir_base="$tmp"
(cd "$tmp" && mpirun $root --oversubscribe -np 2 "$partix" -q run "$case" --threads 1 \
  --no-progress --out two "$@") >"$tmp/two.txt" 2>&1 || {
  echo "FAIL: the 2-rank run failed:"
  sed 's/^/  | /' "$tmp/two.txt" | tail -10
  exit 1
}
grep -q "automatic: lattice.scheme = gather (2 ranks" "$tmp/two/run.log" || {
  echo "FAIL: run.log does not name the gather choice:"
  grep -i "scheme\|rank" "$tmp/two/run.log" | sed 's/^/  | /'
  exit 1
}
(cd "$tmp" && "$partix" -q run "$case" --threads 1 --no-progress --out one "$@" \
  --set lattice.scheme=gather) >"$tmp/one.txt" 2>&1 || {
  echo "FAIL: the 1-process run failed"
  exit 1
}
cmp "$tmp/one/probes.csv" "$tmp/two/probes.csv" || {
  echo "FAIL: probes.csv differs from the 1-process gather run"
  exit 1
}
echo "mpi_auto_scheme: 2 ranks took gather on a y x z grid, the 1-process answer"
