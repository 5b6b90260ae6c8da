#!/bin/sh
# test_mpi_opencl.sh PARTIX CASE STEPS CKSTEP [OPTION...]
#
# The vortex solver over MPI ranks on the opencl engine (each rank's device
# computes its contiguous share of the direct sums' targets, vortex_ranks.h):
#  1. tests/cli/test_mpi_run.sh with OPTIONs: 1..4 ranks give the 1-rank
#     opencl run folder byte for byte, a 2-rank checkpoint resumes on 1 and 3;
#  2. a 2-rank run really splits: run.log's last split gives each rank about
#     half of the vortices (not the whole sum on every rank).
# Exit 77 (skipped) without an OpenCL platform or mpirun.
set -u
partix=$1
shift
here=$(cd "$(dirname "$0")" && pwd)
"$partix" info 2>/dev/null | grep -q 'opencl platform' || {
  echo "test_mpi_opencl: no OpenCL platform"
  exit 77
}
command -v mpirun >/dev/null 2>&1 || {
  echo "test_mpi_opencl: no mpirun"
  exit 77
}
sh "$here/../cli/test_mpi_run.sh" "$partix" "$@" || exit $?
case=$1
shift 3
case "$case" in /*) ;; *) case=$(pwd)/$case ;; esac
tmp=$(mktemp -d) || exit 1
trap 'rm -rf "$tmp"' EXIT
# Open MPI's session folder under this test's own folder: two mpirun
# started at once (ctest -j) race to create the shared /tmp/ompi.HOST.UID
# ("orte_session_dir failed ... File exists")
export OMPI_MCA_orte_tmpdir_base="$tmp"
root=""
[ "$(id -u)" = 0 ] && root=--allow-run-as-root
export ASAN_OPTIONS="${ASAN_OPTIONS:+$ASAN_OPTIONS:}detect_leaks=0"
(cd "$tmp" && mpirun $root --oversubscribe -np 2 "$partix" -q run "$case" --out out --steps 2 \
  --threads 1 "$@") >"$tmp/run.txt" 2>&1 || {
  echo "FAIL: the 2-rank run failed:"
  tail -20 "$tmp/run.txt"
  exit 1
}
# "last split of the convective sum A to B of N vortices per rank, of the
# diffusive sum A to B of N"
for sum in convective diffusive; do
  line=$(grep -o "$sum sum [0-9]* to [0-9]* of [0-9]*" "$tmp/out/run.log")
  set -- $line x x x x x
  lo=$3 hi=$5 n=$7
  case "$lo$hi$n" in *[!0-9]*) n=0 ;; esac
  if [ "$n" -lt 2 ] || [ $((lo + hi)) -ne "$n" ] || [ $((hi - lo)) -gt 1 ]; then
    echo "FAIL: 2 ranks did not split the $sum sum in halves: '$line'"
    exit 1
  fi
  echo "test_mpi_opencl: 2 ranks split the $sum sum of $n vortices into $lo and $hi"
done
