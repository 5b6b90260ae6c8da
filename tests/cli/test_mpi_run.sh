#!/bin/sh
# test_mpi_run.sh PARTIX CASE STEPS CKSTEP [OPTION...]
#
# One case over several MPI ranks gives the 1-rank answer, file by file:
#  1. CASE run to STEPS on one process (no mpirun), then under
#     `mpirun -np K` for K = 2, 3, 4 (RANKS overrides the list): each run folder
#     must equal the 1-rank one (compare_runs.py: byte for byte but run.log,
#     the wall time and the checkpoint's creation time);
#  2. a run on 2 ranks stopped at CKSTEP, resumed to STEPS on 1 rank and on
#     3 ranks (each from its own copy of the folder): both equal the
#     uninterrupted 1-rank run.
# Every process gets one thread (--threads 1: the ranks share 2 cores here,
# --oversubscribe). OPTIONs (e.g. --set key=value) go to every first run.
# With LOGK=PATTERN (K one of the rank counts, e.g. LOG4), the K-rank run's
# run.log must match PATTERN (grep, e.g. the rank grid it used).
# With KILL=1, also: rank 1 of a 2-rank run killed (SIGKILL) after its first
# checkpoint: the job exits non-zero with a message and the checkpoint left
# behind loads (`partix verify`).
# Exit 0 when all hold; 77 (ctest: skipped) without mpirun or an MPI build,
# or without an OpenCL platform when the OPTIONs ask for the opencl backend.
#
# Registered per solver in its tests/*/CMakeLists.txt, e.g.
#   add_test(NAME test_mpi_run_lattice_plate COMMAND sh
#     ${PROJECT_SOURCE_DIR}/tests/cli/test_mpi_run.sh $<TARGET_FILE:partix>
#     ${PROJECT_SOURCE_DIR}/cases/lattice/plate.yaml 20 10 --set output.every=10)
#   set_tests_properties(test_mpi_run_lattice_plate PROPERTIES LABELS "unit;mpi"
#     SKIP_RETURN_CODE 77 TIMEOUT 600)
set -u
partix=$1 case=$2 steps=$3 ckstep=$4
shift 4
case "$case" in /*) ;; *) case=$(pwd)/$case ;; esac
case "$partix" in /*) ;; *) partix=$(pwd)/$partix ;; esac
here=$(cd "$(dirname "$0")" && pwd)
command -v mpirun >/dev/null 2>&1 || {
  echo "test_mpi_run: no mpirun"
  exit 77
}
"$partix" info 2>/dev/null | grep -q '^MPI: yes' || {
  echo "test_mpi_run: this partix is built without MPI"
  exit 77
}
case " $* " in *" --backend opencl "* | *"backend.type=opencl"*)
  "$partix" info 2>/dev/null | grep -q 'opencl platform' || {
    echo "test_mpi_run: no OpenCL platform"
    exit 77
  }
  ;;
esac
tmp=$(mktemp -d) || exit 1
trap 'rm -rf "$tmp"' EXIT
# Open MPI's session folder under this test's own folder: two mpirun
# started at once (ctest -j) race to create the shared /tmp/ompi.HOST.UID
# ("orte_session_dir failed ... File exists")
export OMPI_MCA_orte_tmpdir_base="$tmp"
root=""
[ "$(id -u)" = 0 ] && root=--allow-run-as-root
# Open MPI's plugins are unloaded before LeakSanitizer runs, so their
# allocations cannot be told from partix's: leaks are not checked under
# mpirun (memory errors still are)
export ASAN_OPTIONS="${ASAN_OPTIONS:+$ASAN_OPTIONS:}detect_leaks=0"
mpi() { mpirun $root --oversubscribe -np "$@"; }
fails=0 checks=0
fail() {
  fails=$((fails + 1))
  echo "FAIL: $*"
}
same() { # same NAME FOLDER: FOLDER equals the 1-rank run
  checks=$((checks + 1))
  if ! python3 "$here/compare_runs.py" "$tmp/r1/out" "$2" >"$tmp/cmp.txt" 2>&1; then
    fail "$1 differs from the 1-rank run:"
    sed 's/^/  | /' "$tmp/cmp.txt" | head -20
  fi
}
run() { # run DIR [mpi K] -- ARGS: a partix command in DIR, its output in DIR.txt
  dir=$1
  shift
  mkdir -p "$dir"
  (cd "$dir" && "$@") >"$dir.txt" 2>&1
  code=$?
  if [ $code -ne 0 ]; then
    fail "exit $code: $*"
    sed 's/^/  | /' "$dir.txt" | tail -20
  fi
  return $code
}
opts="--threads 1 --no-progress"

run "$tmp/r1" "$partix" -q run "$case" --out out --steps "$steps" $opts "$@" ||
  exit 1
for k in ${RANKS:-2 3 4}; do
  run "$tmp/r$k" mpi "$k" "$partix" -q run "$case" --out out --steps "$steps" $opts "$@" &&
    same "$k ranks" "$tmp/r$k/out"
  eval "pattern=\${LOG$k:-}"
  if [ -n "$pattern" ]; then
    checks=$((checks + 1))
    grep -q "$pattern" "$tmp/r$k/out/run.log" 2>/dev/null || fail "no '$pattern' in run.log of $k ranks"
  fi
done

# a checkpoint of 2 ranks resumed on 1 and 3
if run "$tmp/c2" mpi 2 "$partix" -q run "$case" --out out --steps "$ckstep" $opts "$@"; then
  cp -r "$tmp/c2" "$tmp/c2on3"
  run "$tmp/c2" "$partix" -q resume out/checkpoint.pxc --steps "$steps" $opts &&
    same "2 ranks resumed on 1" "$tmp/c2/out"
  run "$tmp/c2on3" mpi 3 "$partix" -q resume out/checkpoint.pxc --steps "$steps" $opts &&
    same "2 ranks resumed on 3" "$tmp/c2on3/out"
fi

if [ "${KILL:-0}" = 1 ]; then
  # rank 1 killed once the first checkpoint (every CKSTEP steps) is written;
  # the run is long enough (100 x STEPS) not to end first
  long=$((100 * steps))
  mkdir -p "$tmp/k"
  (cd "$tmp/k" && mpi 2 "$partix" -q run "$case" --out out --steps "$long" $opts \
    --set output.checkpoint_every="$ckstep" "$@") >"$tmp/k.txt" 2>&1 &
  job=$!
  i=0
  while [ ! -f "$tmp/k/out/checkpoint.pxc" ] && [ $i -lt 600 ]; do
    sleep 0.1
    i=$((i + 1))
  done
  victim=""
  # this job's rank 1 only: another test may run the same case at the same
  # time (ctest -j), so the process must also work in this job's folder
  kdir=$(cd "$tmp/k" && pwd -P)
  for p in $(pgrep -f "$partix -q run $case" || true); do
    [ "$(readlink "/proc/$p/cwd" 2>/dev/null)" = "$kdir" ] || continue
    if tr '\0' '\n' <"/proc/$p/environ" 2>/dev/null | grep -q '^OMPI_COMM_WORLD_RANK=1$'; then
      victim=$p
    fi
  done
  checks=$((checks + 1))
  if [ -z "$victim" ]; then
    fail "no rank 1 to kill (the run ended or never wrote a checkpoint)"
    wait $job
  else
    kill -KILL "$victim"
    wait $job
    code=$?
    checks=$((checks + 1))
    [ $code -ne 0 ] || fail "a job with a killed rank exited 0"
    checks=$((checks + 1))
    grep -qi "signal 9\|killed" "$tmp/k.txt" || {
      fail "no message names the killed rank:"
      sed 's/^/  | /' "$tmp/k.txt" | tail -10
    }
    checks=$((checks + 1))
    "$partix" verify "$tmp/k/out/checkpoint.pxc" >"$tmp/kv.txt" 2>&1 || {
      fail "the checkpoint left by the killed job does not load:"
      sed 's/^/  | /' "$tmp/kv.txt"
    }
  fi
fi

echo "test_mpi_run: $checks checks, $fails failed ($(basename "$case"), $steps steps)"
[ $fails -eq 0 ]
