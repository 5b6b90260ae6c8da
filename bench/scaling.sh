#!/bin/sh
# Strong scaling on one many-core node: each solver's scaling case run as
# 1 rank x K threads and as K ranks x 1 thread, for K in COUNTS (default
# 1 2 4 8 16), against 1 rank x 1 thread of the same case:
#
#   bench/scaling.sh [PARTIX] [COUNTS] [SOLVER...]
#
# PARTIX: the program (default build/release/partix); COUNTS: a quoted list
# of thread / rank counts (default "1 2 4 8 16"; counts above the cores are
# skipped); SOLVERs: lattice granular vortex (default all).
# The cases (a few seconds on one core, larger than bench/mpi_ranks.sh's so
# that 16 cores still get work):
#   lattice  cases/lattice/plate.yaml at h = 0.5 mm (200 x 100 x 10 =
#            200,000 elements, single, leapfrog, link-once), 200 steps;
#   granular cases/granular/flagship.yaml (20,000 discs), 2,000 steps;
#   vortex   cases/vortex/cylinder_re550.yaml, 150 steps (the wake grows to
#            a few 10^4 vortices; the FMM).
# Ranks are bound one per core (--map-by core --bind-to core) and threads
# placed one per core (OMP_PROC_BIND=close, OMP_PLACES=cores) while K is at
# most the physical cores (lscpu), else one per hardware thread; every run
# writes no VTK or PNG.
# A figure is the solver's seconds per step from run.log's last line ("N
# steps in W s (...; steps S s, ...)": S, without outputs and checkpoints),
# and for K ranks the communication rank 0 counted ("communication"
# line: seconds, operations and bytes per step). One JSON line per run:
# solver, mode (threads / ranks), k, s_per_step, speedup and efficiency
# against the 1 x 1 run, the communication figures, the machine, the load
# average before and after. Runs alternate mode by mode for each K.
set -eu
cd "$(dirname "$0")/.."
partix=${1:-build/release/partix}
counts=${2:-"1 2 4 8 16"}
shift $(($# < 2 ? $# : 2))
solvers=${*:-lattice granular vortex}
[ -x "$partix" ] || { echo "scaling: no $partix (build first)" >&2; exit 2; }
partix=$(cd "$(dirname "$partix")" && pwd)/$(basename "$partix")
cores=$(nproc)
# physical cores: ranks and threads go one per core while there are enough
phys=$(lscpu -p=CORE,SOCKET 2>/dev/null | grep -v '^#' | sort -u | wc -l)
[ "$phys" -gt 0 ] || phys=$cores
root=""
[ "$(id -u)" = 0 ] && root=--allow-run-as-root
tmp=$(mktemp -d) || exit 2
trap 'rm -rf "$tmp"' EXIT
load() { cut -d' ' -f1 /proc/loadavg 2>/dev/null || echo -1; }
model=$(sed -n 's/^model name[^:]*: //p' /proc/cpuinfo | head -n 1)

scaling_case() {
  quiet="--set output.vtk=false --set output.png=false"
  case $1 in
    lattice) echo "cases/lattice/plate.yaml --steps 200 --set lattice.h=5e-4 $quiet" ;;
    granular) echo "cases/granular/flagship.yaml --steps 2000 $quiet" ;;
    vortex) echo "cases/vortex/cylinder_re550.yaml --steps 150 $quiet" ;;
    *) echo "scaling: unknown solver $1" >&2; exit 2 ;;
  esac
}

# one SOLVER MODE K: prints "s_per_step comm_s ops bytes" (comm fields - without)
one() {
  dir=$tmp/$1_$2_$3
  rm -rf "$dir"
  # shellcheck disable=SC2046
  places=cores bind="--map-by core --bind-to core"
  [ "$3" -le "$phys" ] || { places=threads; bind="--use-hwthread-cpus --bind-to hwthread"; }
  if [ "$2" = threads ]; then
    OMP_PROC_BIND=close OMP_PLACES=$places "$partix" -q run $(scaling_case "$1") \
      --threads "$3" --out "$dir" --no-progress >"$dir.out" 2>&1
  else
    # shellcheck disable=SC2086
    mpirun $root $bind -np "$3" "$partix" -q run $(scaling_case "$1") \
      --threads 1 --out "$dir" --no-progress >"$dir.out" 2>&1
  fi || { echo "scaling: $1 $2 $3 failed:" >&2; tail -n 5 "$dir.out" >&2; return 1; }
  sed -n 's/.* \([0-9][0-9]*\) steps in [0-9.]* s (.*; steps \([0-9.]*\) s.*/\1 \2/p' "$dir/run.log" | tail -n 1 >"$dir.t"
  comm=$(sed -n 's/.*communication.*: \([0-9.]*\) s on rank 0.* \([0-9.e+]*\) operations, \([0-9.e+]*\) bytes sent.*/\1 \2 \3/p' "$dir/run.log" | tail -n 1)
  read -r steps secs <"$dir.t"
  awk -v n="$steps" -v s="$secs" -v c="${comm:--}" 'BEGIN {
    split(c, f, " ");
    if (c == "-") printf "%.6g - - -\n", s / n;
    else printf "%.6g %.6g %.6g %.6g\n", s / n, f[1] / n, f[2], f[3] }'
}

for s in $solvers; do
  base=""
  for k in $counts; do
    [ "$k" -le "$cores" ] || continue
    modes="threads ranks"
    [ "$k" = 1 ] && modes=threads
    [ $((k % 4)) = 2 ] && modes="ranks threads"  # alternate which goes first
    for m in $modes; do
      lb=$(load)
      r=$(one "$s" "$m" "$k") || continue
      la=$(load)
      set -- $r
      [ -n "$base" ] || base=$1
      printf '{"bench":"scaling","solver":"%s","mode":"%s","k":%s,"s_per_step":%s,' "$s" "$m" "$k" "$1"
      printf '"speedup":%s,"efficiency":%s,' \
        "$(awk -v b="$base" -v t="$1" 'BEGIN{printf "%.3f", b / t}')" \
        "$(awk -v b="$base" -v t="$1" -v k="$k" 'BEGIN{printf "%.3f", b / t / k}')"
      if [ "$2" = - ]; then
        printf '"comm_s_per_step_rank0":null,"operations_rank0":null,"bytes_sent_rank0":null,'
      else
        printf '"comm_s_per_step_rank0":%s,"operations_rank0":%s,"bytes_sent_rank0":%s,' "$2" "$3" "$4"
      fi
      printf '"cpus":%s,"cores":%s,"machine":"%s","load1_before":%s,"load1_after":%s}\n' \
        "$cores" "$phys" "$model" "$lb" "$la"
    done
  done
done
