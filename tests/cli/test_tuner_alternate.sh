#!/bin/sh
# test_tuner_alternate.sh PARTIX CASES_DIR: the thread tuner (src/core/tuner.h)
# may switch a run between 1 and all threads at any step; the results must
# not change. The tuner's test hook PX_TUNER_ALTERNATE=3 makes each solver's
# cpu engine alternate 1 and 2 threads every 3 steps; such a run must equal
# a 1-thread run byte for byte: every section of the final checkpoint (the
# stored case text aside: it holds the thread count) and every CSV output.
# The bodies are big enough for 2 threads (lattice: above 16384 grid cells;
# granular: 4096 discs), and run.log must show the tuner alternating.
set -u
partix=$1 cases=$2
fails=0 checks=0
tmp=$(mktemp -d) || exit 1
trap 'rm -rf "$tmp"' EXIT

# same NAME CASE STEPS [--set ...]: the 1-thread run against the alternating one
same() {
  name=$1 case=$2 steps=$3
  shift 3
  checks=$((checks + 1))
  before=$fails
  for th in 1 2; do
    if [ "$th" = 1 ]; then alt=""; else alt=3; fi
    if ! PX_TUNER_ALTERNATE=$alt "$partix" run "$cases/$case.yaml" --out "$tmp/$name.$th" \
        --steps "$steps" -q --threads "$th" --set output.png=false --set output.vtk=false \
        "$@" >"$tmp/log" 2>&1; then
      fails=$((fails + 1))
      echo "FAIL: $name: the run on $th thread(s) failed:"
      sed 's/^/  | /' "$tmp/log" | head -5
      return
    fi
    "$partix" verify "$tmp/$name.$th" --sections -q | tail -n +2 | grep -v '^case ' \
      >"$tmp/$name.$th.sections"
  done
  if ! grep -q "PX_TUNER_ALTERNATE=3: 1 and 2 threads in turn" "$tmp/$name.2/run.log"; then
    fails=$((fails + 1))
    echo "FAIL: $name: the tuner did not alternate 1 and 2 threads (run.log):"
    sed 's/^/  | /' "$tmp/$name.2/run.log" | head -8
  fi
  if ! [ -s "$tmp/$name.1.sections" ] ||
      ! cmp -s "$tmp/$name.1.sections" "$tmp/$name.2.sections"; then
    fails=$((fails + 1))
    echo "FAIL: $name: checkpoint sections differ between 1 thread and alternating 1/2:"
    diff "$tmp/$name.1.sections" "$tmp/$name.2.sections" | head -8 | sed 's/^/  | /'
  fi
  for f in "$tmp/$name.1"/*.csv; do
    [ -e "$f" ] || continue
    if ! cmp -s "$f" "$tmp/$name.2/${f##*/}"; then
      fails=$((fails + 1))
      echo "FAIL: $name: ${f##*/} differs between 1 thread and alternating 1/2"
    fi
  done
  [ "$fails" -eq "$before" ] &&
    echo "$name: 1 thread = 1/2 threads alternating every 3 steps ($steps steps)"
}

# lattice: weak bonds break within the steps (the fracture pass too)
W="--set lattice.h=0.3e-3 --set lattice.strength.normal=20 --set lattice.strength.shear=20"
same lattice_rk4 lattice/notched 40 $W --set output.log_every=5
# leapfrog, link-once, on a body 50 planes tall: the planes are split into 6
# slabs taken in turn by the threads (lattice_cpu_impl.h, LT_SLAB_MIN)
same lattice_leapfrog lattice/notched 40 --set lattice.integrator=leapfrog \
  --set lattice.scheme=link_once --set backend.precision=single --set lattice.h=0.6e-3 \
  --set 'lattice.body[0].max=[0.04,0.01,0.03]' --set lattice.strength.normal=20 \
  --set lattice.strength.shear=20
same lattice_gather lattice/notched 40 $W --set lattice.scheme=gather
G="--set granular.media.count=4200 --set granular.media.radius.min=0.0009
  --set granular.media.radius.max=0.0011 --set granular.settle=0 --set output.log_every=20"
same granular_verlet granular/small_box 300 $G --set backend.precision=double
same granular_abm4 granular/small_box 300 $G --set backend.precision=mixed \
  --set granular.integrator=abm4
same vortex_fmm vortex/demo_cylinder 20 --set backend.precision=double \
  --set vortex.velocity.method=fmm
same vortex_direct vortex/demo_cylinder 20 --set backend.precision=mixed \
  --set vortex.velocity.method=direct --set vortex.scheme=euler

echo "$checks configurations, $fails failures"
[ "$fails" -eq 0 ]
