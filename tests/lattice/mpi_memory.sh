#!/bin/sh
# mpi_memory.sh PARTIX CASE ARG...: the lattice's memory is distributed over
# MPI ranks. `partix run CASE ARG...` on one process and on 4 ranks (one
# thread each): every rank but 0 allocates at most half of what the one
# process does (partix's own allocations, run.log's "peak memory": a count,
# not a timing), also when the 1-process checkpoint is resumed on 4 ranks,
# and probes.csv is the 1-process one, byte for byte. Exit 77
# (ctest: skipped) without mpirun or an MPI build.
set -u
partix=$1 case=$2
shift 2
case "$partix" in /*) ;; *) partix=$(pwd)/$partix ;; esac
case "$case" in /*) ;; *) case=$(pwd)/$case ;; esac
command -v mpirun >/dev/null 2>&1 || { echo "mpi_memory: no mpirun"; exit 77; }
"$partix" info 2>/dev/null | grep -q '^MPI: yes' || { echo "mpi_memory: no MPI"; exit 77; }
root=""
[ "$(id -u)" = 0 ] && root=--allow-run-as-root
export ASAN_OPTIONS="${ASAN_OPTIONS:+$ASAN_OPTIONS:}detect_leaks=0"
tmp=$(mktemp -d) || exit 1
trap 'rm -rf "$tmp"' EXIT
# Open MPI's session folder under this test's own folder: two mpirun
# started at once (ctest -j) race to create the shared /tmp/ompi.HOST.UID
# ("orte_session_dir failed ... File exists")
export OMPI_MCA_orte_tmpdir_base="$tmp"
(cd "$tmp" && "$partix" -q run "$case" --threads 1 --no-progress --out one "$@") \
  >"$tmp/one.txt" 2>&1 || { echo "FAIL: the 1-process run failed"; exit 1; }
(cd "$tmp" && mpirun $root --oversubscribe -np 4 "$partix" -q run "$case" --threads 1 \
  --no-progress --out four "$@") >"$tmp/four.txt" 2>&1 || {
  echo "FAIL: the 4-rank run failed:"
  sed 's/^/  | /' "$tmp/four.txt" | tail -10
  exit 1
}
one=$(sed -n 's/.*peak memory \([0-9.]*\) MiB;.*/\1/p' "$tmp/one/run.log")
most=$(sed -n 's/.*peak memory [0-9.]* MiB on rank 0, [0-9.]*-\([0-9.]*\) MiB on ranks 1-3;.*/\1/p' \
  "$tmp/four/run.log")
[ -n "$one" ] && [ -n "$most" ] || {
  echo "FAIL: no peak memory in run.log:"
  grep "peak memory" "$tmp/one/run.log" "$tmp/four/run.log" | sed 's/^/  | /'
  exit 1
}
awk -v one="$one" -v most="$most" 'BEGIN { exit !(most <= 0.5 * one) }' || {
  echo "FAIL: ranks 1-3 allocate up to $most MiB, one process $one MiB (want at most half)"
  exit 1
}
cmp "$tmp/one/probes.csv" "$tmp/four/probes.csv" || {
  echo "FAIL: probes.csv differs from the 1-process run"
  exit 1
}
# the 1-process checkpoint resumed on 4 ranks: each reads the state in
# pieces and keeps its window
(cd "$tmp" && mpirun $root --oversubscribe -np 4 "$partix" -q resume one/checkpoint.pxc \
  --more 2 --threads 1 --no-progress) >"$tmp/resume.txt" 2>&1 || {
  echo "FAIL: the resume on 4 ranks failed:"
  sed 's/^/  | /' "$tmp/resume.txt" | tail -10
  exit 1
}
again=$(sed -n 's/.*peak memory [0-9.]* MiB on rank 0, [0-9.]*-\([0-9.]*\) MiB on ranks 1-3;.*/\1/p' \
  "$tmp/one/run.log" | tail -1)
[ -n "$again" ] && awk -v one="$one" -v most="$again" 'BEGIN { exit !(most <= 0.5 * one) }' || {
  echo "FAIL: resumed on 4 ranks, ranks 1-3 allocate up to ${again:-?} MiB, one process $one MiB"
  exit 1
}
echo "mpi_memory: one process $one MiB, ranks 1-3 of 4 at most $most MiB (resumed: $again MiB);" \
  "the same probes"
