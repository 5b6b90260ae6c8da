#!/bin/sh
# Ranks against threads, side by side: each solver's bench case run as
# 1 rank x T threads and as K ranks x 1 thread (K = T, default 2), the two
# alternating run by run so that a change of load hits both alike:
#
#   bench/mpi_ranks.sh [PARTIX] [REPS] [K] [SOLVER...]
#
# PARTIX: the program (default build/release/partix); REPS: repetitions of
# each configuration (default 3); K: ranks, and threads of the 1-rank run
# (default 2); SOLVERs: lattice lattice-gather granular vortex (default all;
# lattice-gather: the plate with the gather scheme, whose ranks cut across y:
# a K x 1 (y x z) rank grid).
# Ranks are not bound to cores (--bind-to none: the rank's one thread may
# run on any free core, as the threads of the 1-rank run may).
#
# Each run is `partix run CASE --steps N` into a scratch folder; its figure
# is the time of the solver's steps per step (run.log's last line: "N steps
# in W s (...; steps S s, outputs ..., checkpoints ...)": S, without the
# outputs and the final checkpoint, whose fsync alone can cost as much as
# a short run's steps), and for
# the K-rank runs the time rank 0 spent in communication per step (messages
# and waits for slower ranks) with the operations and bytes it sent per step
# (counted by src/core/comm.c; run.log's "communication" line). Prints one JSON line per solver: the
# min/median/max seconds per step of each configuration, the efficiency
# t(1 x K threads) / t(K ranks x 1) of the medians (>= 0.9 is the target of
# issue 21: ranks cost no more than threads on free cores), communication per
# step, the machine, and the 1-minute load average before and after.
set -eu
cd "$(dirname "$0")/.."
partix=${1:-build/release/partix}
reps=${2:-3}
k=${3:-2}
shift $(($# < 3 ? $# : 3))
solvers=${*:-lattice lattice-gather granular vortex}
[ -x "$partix" ] || { echo "mpi_ranks: no $partix (build first)" >&2; exit 2; }
command -v mpirun >/dev/null 2>&1 || { echo "mpi_ranks: no mpirun" >&2; exit 2; }
partix=$(cd "$(dirname "$partix")" && pwd)/$(basename "$partix")
root=""
[ "$(id -u)" = 0 ] && root=--allow-run-as-root
tmp=$(mktemp -d) || exit 2
trap 'rm -rf "$tmp"' EXIT
load() { cut -d' ' -f1 /proc/loadavg 2>/dev/null || echo -1; }

# the bench case of each solver: a few seconds per run on one core
bench_case() {
  case $1 in
    lattice) echo "cases/lattice/plate.yaml --steps 1000 --set output.vtk=false --set output.png=false" ;;
    lattice-gather) echo "cases/lattice/plate.yaml --steps 1000 --set output.vtk=false --set output.png=false --set lattice.scheme=gather" ;;
    granular) echo "cases/granular/flagship.yaml --steps 3000 --set output.vtk=false --set output.png=false" ;;
    vortex) echo "cases/vortex/demo_cylinder.yaml --steps 120 --set output.vtk=false --set output.png=false" ;;
  esac
}

one() { # SOLVER TAG RANKS THREADS
  dir=$tmp/$1_$2_$r
  set -- "$1" "$2" "$3" "$4" $(bench_case "$1")
  s=$1 tag=$2 np=$3 th=$4
  shift 4
  if [ "$np" = 1 ]; then
    "$partix" -q run "$@" --threads "$th" --out "$dir" --no-progress >/dev/null 2>&1
  else
    mpirun $root --oversubscribe --bind-to none -np "$np" "$partix" -q run "$@" \
      --threads "$th" --out "$dir" --no-progress >/dev/null 2>&1
  fi || { echo "mpi_ranks: $s $tag failed (see a run by hand)" >&2; return 1; }
  echo "$s $tag $dir" >>"$tmp/runs"
}

load_before=$(load)
r=0
while [ "$r" -lt "$reps" ]; do
  for s in $solvers; do
    if [ $((r % 2)) = 0 ]; then
      one "$s" threads 1 "$k"; one "$s" ranks "$k" 1
    else
      one "$s" ranks "$k" 1; one "$s" threads 1 "$k"
    fi
  done
  r=$((r + 1))
done
load_after=$(load)

python3 - "$tmp/runs" "$reps" "$k" "$load_before" "$load_after" <<'EOF'
import json, os, platform, re, statistics, sys
runs, reps, k, lb, la = sys.argv[1:6]
model = "unknown"
for line in open("/proc/cpuinfo"):
    if line.startswith("model name"):
        model = line.split(":", 1)[1].strip()
        break
fig = {}
for line in open(runs):
    solver, tag, d = line.split()
    log = open(os.path.join(d, "run.log")).read()
    m = re.search(r"(\d+) steps in [0-9.]+ s \(.*?; steps ([0-9.]+) s", log)
    c = re.search(r"communication .*?: ([0-9.]+) s on rank 0.*?([0-9.e+]+) operations, "
                  r"([0-9.e+]+) bytes sent", log)
    steps, secs = int(m.group(1)), float(m.group(2))
    f = fig.setdefault(solver, {"threads": [], "ranks": [], "comm": [], "ops": [], "bytes": []})
    f[tag].append(secs / steps)
    if c:
        f["comm"].append(float(c.group(1)) / steps)
        f["ops"].append(float(c.group(2)))
        f["bytes"].append(float(c.group(3)))
def mmm(v):
    return [min(v), statistics.median(v), max(v)] if v else None
for solver, f in fig.items():
    t, r = mmm(f["threads"]), mmm(f["ranks"])
    print(json.dumps({
        "bench": "mpi_ranks", "solver": solver,
        "one_rank_threads": int(k), "ranks_one_thread": int(k),
        "s_per_step_1rank_min_med_max": t, "s_per_step_ranks_min_med_max": r,
        "efficiency_threads_over_ranks": round(t[1] / r[1], 3) if t and r else None,
        "comm_s_per_step_rank0_median": statistics.median(f["comm"]) if f["comm"] else None,
        "operations_per_step_rank0": statistics.median(f["ops"]) if f["ops"] else None,
        "bytes_sent_per_step_rank0": statistics.median(f["bytes"]) if f["bytes"] else None,
        "timed": "the solver's steps (run.log), without outputs and checkpoints",
        "reps": int(reps), "machine": model, "host": platform.node(),
        "cpus": os.cpu_count(), "load1_before": float(lb), "load1_after": float(la)}))
EOF
