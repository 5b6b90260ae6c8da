#!/bin/sh
# Every shipped case over 3 MPI ranks against 1 rank (issue 21's check):
#
#   bench/mpi_shipped.sh [PARTIX] [RANKS]
#
# For each cases/{lattice,granular,vortex}/*.yaml: the first STEPS steps
# (a few seconds each on one core: the count per case below) on one process
# and on RANKS ranks (default 3), one thread each, compared file by file with
# tests/cli/compare_runs.py, and a checkpoint of 2 ranks at half the steps
# resumed on 1 and 3 ranks (tests/cli/test_mpi_run.sh). Prints one line per
# case and exits 1 if any differs. Several minutes on 2 cores: not a ctest
# (the tests run three cases per solver; this covers all shipped ones).
set -u
cd "$(dirname "$0")/.."
partix=${1:-build/release/partix}
ranks=${2:-3}
[ -x "$partix" ] || { echo "mpi_shipped: no $partix (build first)" >&2; exit 2; }
steps() { # a case's step count for this check
  case $1 in
    lattice/*) echo 120 ;;
    granular/flagship*) echo 300 ;;
    granular/*) echo 2000 ;;
    vortex/cylinder_re550*) echo 20 ;;
    vortex/*) echo 40 ;;
  esac
}
bad=0
for c in cases/lattice/*.yaml cases/granular/*.yaml cases/vortex/*.yaml; do
  name=${c#cases/}
  n=$(steps "$name")
  out=$(RANKS="$ranks" sh tests/cli/test_mpi_run.sh "$partix" "$c" "$n" $((n / 2)) 2>&1)
  if [ $? -eq 0 ]; then
    echo "same    $name ($n steps, $ranks ranks; 2-rank checkpoint resumed on 1 and 3)"
  else
    bad=$((bad + 1))
    echo "DIFFERS $name ($n steps):"
    echo "$out" | sed 's/^/  | /' | tail -15
  fi
done
[ $bad -eq 0 ]
