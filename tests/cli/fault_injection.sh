#!/bin/sh
# fault_injection.sh PARTIX CASE STEPS TRIALS [OPTION...]
#
# kill -9 at random moments, then resume: the run folder must end as an
# uninterrupted run's. CASE is run to step STEPS in one go (OPTIONs, e.g.
# --set output.checkpoint_every=5, go to every run), timing it (T). Then, in
# each of TRIALS fresh folders, the run is started and killed (SIGKILL) at a
# random moment in (0, T), twice, each time resumed from whatever checkpoint
# it left (or started again when it left none); after every kill the
# checkpoint must pass `partix verify` (a kill while it is written leaves
# the previous one intact); the third attempt runs to the end. Each folder is
# then compared file by file with the uninterrupted one (compare_runs.py).
# Frequent checkpoints make kills land while one is being written.
# Random moments come from awk's rand() seeded with the trial number, so a
# failure can be rerun; they are printed.
set -u
partix=$1 case=$2 steps=$3 trials=$4
shift 4
here=$(cd "$(dirname "$0")" && pwd)
case "$case" in /*) ;; *) case=$(pwd)/$case ;; esac
case "$partix" in /*) ;; *) partix=$(pwd)/$partix ;; esac
tmp=$(mktemp -d) || exit 1
trap 'rm -rf "$tmp"' EXIT
fails=0

now() { date +%s.%N; }

mkdir -p "$tmp/whole"
t0=$(now)
(cd "$tmp/whole" && "$partix" -q run "$case" --out out --steps "$steps" --no-progress "$@") || {
  echo "fault_injection: the uninterrupted run failed"; exit 1; }
t1=$(now)
total=$(awk -v a="$t0" -v b="$t1" 'BEGIN { print b - a }')
echo "fault_injection: uninterrupted run of $steps steps: $total s"

trial=1
while [ "$trial" -le "$trials" ]; do
  dir=$tmp/t$trial
  mkdir -p "$dir"
  attempt=0
  while :; do
    if [ -f "$dir/out/summary.json" ] && grep -q '"status": "finished"' "$dir/out/summary.json"; then
      break
    fi
    if [ -f "$dir/out/checkpoint.pxc" ]; then what=resume; else what=run; fi
    if [ "$attempt" -lt 2 ]; then
      delay=$(awk -v s="$trial$attempt" -v t="$total" 'BEGIN { srand(s); printf "%.3f", rand() * t }')
      if [ "$what" = run ]; then
        (cd "$dir" && exec "$partix" -q run "$case" --out out --steps "$steps" --no-progress "$@") \
          >/dev/null 2>&1 &
      else
        (cd "$dir" && exec "$partix" -q resume out/checkpoint.pxc --no-progress) >/dev/null 2>&1 &
      fi
      pid=$!
      sleep "$delay"
      kill -9 "$pid" 2>/dev/null
      wait "$pid" 2>/dev/null
      echo "fault_injection: trial $trial: $what killed after $delay s"
      if [ -f "$dir/out/checkpoint.pxc" ] && ! "$partix" -q verify "$dir/out" >/dev/null 2>"$tmp/err"; then
        echo "FAIL: trial $trial: the checkpoint left by kill -9 does not verify:"
        sed 's/^/  | /' "$tmp/err"
        fails=$((fails + 1))
        break
      fi
    else
      if [ "$what" = run ]; then
        (cd "$dir" && "$partix" -q run "$case" --out out --steps "$steps" --no-progress "$@") \
          >"$tmp/out" 2>&1
      else
        (cd "$dir" && "$partix" -q resume out/checkpoint.pxc --no-progress) >"$tmp/out" 2>&1
      fi || {
        echo "FAIL: trial $trial: partix $what after the kills failed:"
        sed 's/^/  | /' "$tmp/out" | head -5
        fails=$((fails + 1))
        break
      }
    fi
    attempt=$((attempt + 1))
  done
  if ! python3 "$here/compare_runs.py" "$tmp/whole/out" "$dir/out"; then
    echo "FAIL: trial $trial: the folder differs from the uninterrupted run's"
    fails=$((fails + 1))
  fi
  trial=$((trial + 1))
done
[ "$fails" -eq 0 ] || { echo "fault_injection: $fails of $trials trials failed"; exit 1; }
echo "fault_injection: $trials trials, every folder identical to the uninterrupted run's"
