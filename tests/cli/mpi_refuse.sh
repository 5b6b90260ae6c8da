#!/bin/sh
# mpi_refuse.sh PARTIX PATTERN ARG...: what a solver cannot run over ranks is
# refused by key before any step, with the reason: `partix run ARG...` on 2
# MPI ranks (one thread each) exits non-zero, its message matches PATTERN
# (grep), and it writes no checkpoint. Paths among the ARGs must be absolute
# (the run starts in a scratch folder). Exit 77 (ctest: skipped) without
# mpirun or an MPI build, or without an OpenCL platform when ARGs ask for the
# opencl backend.
set -u
partix=$1 pattern=$2
shift 2
case "$partix" in /*) ;; *) partix=$(pwd)/$partix ;; esac
command -v mpirun >/dev/null 2>&1 || { echo "mpi_refuse: no mpirun"; exit 77; }
"$partix" info 2>/dev/null | grep -q '^MPI: yes' || { echo "mpi_refuse: no MPI"; exit 77; }
case " $* " in *" --backend opencl "*)
  "$partix" info 2>/dev/null | grep -q 'opencl platform' || {
    echo "mpi_refuse: no opencl platform"
    exit 77
  }
  ;;
esac
root=""
[ "$(id -u)" = 0 ] && root=--allow-run-as-root
export ASAN_OPTIONS="${ASAN_OPTIONS:+$ASAN_OPTIONS:}detect_leaks=0"
tmp=$(mktemp -d) || exit 1
trap 'rm -rf "$tmp"' EXIT
# Open MPI's session folder under this test's own folder: two mpirun
# started at once (ctest -j) race to create the shared /tmp/ompi.HOST.UID
# ("orte_session_dir failed ... File exists")
export OMPI_MCA_orte_tmpdir_base="$tmp"
# MPMD_RANK1="ARGS": rank 1 gets ARGS beyond the others' (an MPMD launch,
# `mpirun -np 1 A : -np 1 A ARGS`), to check that ranks given other options
# are refused, not left to hang
if [ -n "${MPMD_RANK1:-}" ]; then
  # shellcheck disable=SC2086
  set -- -np 1 "$partix" -q run --threads 1 --no-progress --out out "$@" : \
    -np 1 "$partix" -q run --threads 1 --no-progress --out out "$@" $MPMD_RANK1
else
  set -- -np 2 "$partix" -q run --threads 1 --no-progress --out out "$@"
fi
if (cd "$tmp" && timeout 60 mpirun $root --oversubscribe "$@") >"$tmp/out.txt" 2>&1; then
  echo "FAIL: the run was not refused"
  exit 1
fi
grep -q "$pattern" "$tmp/out.txt" || {
  echo "FAIL: no '$pattern' in:"
  sed 's/^/  | /' "$tmp/out.txt" | head -10
  exit 1
}
[ ! -e "$tmp/out/checkpoint.pxc" ] || { echo "FAIL: a refused run wrote a checkpoint"; exit 1; }
echo "mpi_refuse: refused as expected"
