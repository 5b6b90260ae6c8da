#!/bin/sh
# Side-by-side speed of two builds (e.g. the commit before a refactoring and
# this one) on the three solvers' step benchmarks, alternating the builds run
# by run so that a change of load hits both alike:
#
#   bench/compare_builds.sh OLD_BUILD NEW_BUILD [REPS] [THREADS]
#
# OLD_BUILD, NEW_BUILD: build directories (with bench/ binaries), e.g. a
# worktree of the older commit built with scripts/build.sh:
#   git worktree add --detach /tmp/old 98b77f6 && (cd /tmp/old && scripts/build.sh)
#   bench/compare_builds.sh /tmp/old/build/release build/release 5 1
# REPS: repetitions of each benchmark per build (default 5); THREADS: threads
# of every run (default 1: the per-core cost, least disturbed by other work).
#
# Benchmarks (sizes chosen for about 1 s per figure on one core):
#   vortex_step 20000 vortices, 1000 panels, cpu, double and mixed, direct
#               sums, 3 timed steps: seconds per step (wall and CPU);
#   granular_vibrobox 40 x 40 box (1521 discs), double, Verlet, 200 settle
#               + 20000 timed steps, fixed thread count: disc-steps/s;
#   lattice_step 46^3 box (97,336 elements), 20 RK4 / 80 leapfrog steps, cpu
#               engine, every precision and link scheme: element-steps/s.
# Prints one JSON line per benchmark configuration: the machine, threads,
# repetitions, the min/median/max of its figure for each build, and
# new/old of the medians (> 1: new is faster, for rates; for seconds the
# ratio is old/new, so > 1 also means faster), then the 1-minute load
# average before and after.
set -eu
[ $# -ge 2 ] || { sed -n 2,25p "$0"; exit 2; }
old=$1 new=$2 reps=${3:-5} threads=${4:-1}
for b in "$old" "$new"; do
  for x in vortex_step granular_vibrobox lattice_step; do
    [ -x "$b/bench/$x" ] || { echo "compare_builds: no $b/bench/$x (build first)" >&2; exit 2; }
  done
done
tmp=$(mktemp -d) || exit 2
trap 'rm -rf "$tmp"' EXIT
load() { cut -d' ' -f1 /proc/loadavg 2>/dev/null || echo -1; }
load_before=$(load)
export OMP_NUM_THREADS="$threads" OMP_PROC_BIND=false

run_one() { # BUILD TAG
  b=$1 tag=$2
  for p in double mixed; do
    "$b/bench/vortex_step" 20000 1000 cpu "$p" "$threads" 3 direct 2>/dev/null |
      sed "s/^{/{\"build\":\"$tag\",/" >>"$tmp/out"
  done
  "$b/bench/granular_vibrobox" 40 40 200 20000 "$threads" double verlet fixed 2>/dev/null |
    sed "s/^{/{\"build\":\"$tag\",/" >>"$tmp/out"
  "$b/bench/lattice_step" --sizes 46 --steps 20 --threads "$threads" --no-opencl \
    --no-baseline 2>/dev/null |
    sed "s/^{/{\"build\":\"$tag\",/" >>"$tmp/out"
}

r=0
while [ "$r" -lt "$reps" ]; do
  # alternate which build goes first
  if [ $((r % 2)) = 0 ]; then run_one "$old" old; run_one "$new" new
  else run_one "$new" new; run_one "$old" old; fi
  r=$((r + 1))
done
load_after=$(load)

python3 - "$tmp/out" "$reps" "$threads" "$load_before" "$load_after" <<'EOF'
import json, statistics, sys, platform
path, reps, threads, lb, la = sys.argv[1:6]
model = "unknown"
try:
    for line in open("/proc/cpuinfo"):
        if line.startswith("model name"):
            model = line.split(":", 1)[1].strip()
            break
except OSError:
    pass
rows = [json.loads(l) for l in open(path) if l.startswith("{")]
groups = {}
for r in rows:
    b = r["bench"]
    if b == "vortex_step":
        key = (b, r["precision"], r["method"]); fig, rate = "step_cpu_s", False
    elif b == "granular_vibrobox":
        key = (b, r["precision"], r["integrator"]); fig, rate = "disc_steps_per_cpu_s", True
    elif b == "lattice_step":
        if r.get("engine") != "cpu":
            continue
        key = (b, r["integrator"], r["precision"], r["scheme"]); fig, rate = "element_steps_per_cpu_s", True
    else:
        continue
    g = groups.setdefault(key, {"figure": fig, "rate": rate, "old": [], "new": []})
    g[r["build"]].append(float(r[fig]))
def mmm(v):
    return [min(v), statistics.median(v), max(v)] if v else None
for key, g in groups.items():
    o, n = mmm(g["old"]), mmm(g["new"])
    speed = None
    if o and n:
        speed = n[1] / o[1] if g["rate"] else o[1] / n[1]
    print(json.dumps({"bench": key[0], "config": "/".join(key[1:]), "figure": g["figure"],
                      "old_min_med_max": o, "new_min_med_max": n,
                      "speed_new_over_old": round(speed, 3) if speed else None,
                      "reps": int(reps), "threads": int(threads), "machine": model,
                      "host": platform.node(), "cpus": __import__("os").cpu_count(), "load1_before": float(lb),
                      "load1_after": float(la)}))
EOF
