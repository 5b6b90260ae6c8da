#!/bin/sh
# State hashes after a few steps of every solver, engine, precision, thread
# count and feature (fracture, FMM, ABM4, rk2, ...): the proof that a
# refactoring of the engines changed no bit of the physics.
#
#   bench/state_hashes.sh [PARTIX] > NEW            hashes of this build
#   bench/state_hashes.sh --check REF [PARTIX]      compare with REF (exit 1
#                                                    naming each differing
#                                                    config and section)
#   ONLY=REGEX bench/state_hashes.sh ...            only the configurations
#                                                    whose names match (grep -E)
#
# Each configuration runs `partix run CASE --steps N --set ...` into a
# scratch folder, then `partix verify --sections` hashes every section of
# the final checkpoint (FNV-1a of its bytes; the stored case text is left
# out: its wording is not the state). Every configuration is run twice and
# must give the same hashes both times (a configuration that is not
# reproducible run to run is reported as `varies`, never compared). Output
# lines:
#   CONFIG SECTION HASH
# bench/state_hashes.ref holds the hashes of the commit before the engine
# refactoring (issue 20), recorded with this script on the CI machine kind
# (x86-64, gcc 12 Release, POCL CPU device); a change that is meant to move
# bits must say so in its commit and re-record the file.
# The vortex hashes hold for one CPU model only: on an AMD EPYC (Zen 5) 8
# of its 9 configurations differed from the file recorded on an Intel Xeon,
# already with the code of c38251b, which reproduced all of them on the
# Xeon (2026-11-27; OPENBLAS_CORETYPE=SkylakeX does not bring them back:
# the default build is -march=native, and the panel matrix's factors and
# the wall terms go through OpenBLAS and libm, which pick their code by
# CPU). The panel solve by the inverse (97f4263) moved on purpose the bits
# of the 5 cpu configurations that solve in double (not cpu single, which
# solves by its float LU, nor opencl, which multiplied by the same inverse
# already): the file's vortex lines were then re-recorded on the Zen 5 VM.
# The OpenCL engine's sums per panel and per row by work-groups (a82e0de,
# 77e30d4: the generation's right-hand side, the absorbed circulation, the
# solve) moved on purpose the bits of the 3 opencl configurations (POCL):
# re-recorded on the Zen 5 VM, 2026-11-28.
# The VVD's distances by an estimate of 1/sqrt and two Newton steps
# (px_vortex_radii) and the panel coefficients' atan2 inline (vx_atan2)
# moved on purpose the bits of the 6 cpu configurations (within a few ulp
# per distance and angle): re-recorded on the Zen 5 VM, 2026-11-28.
# The wall quadrature's sub-intervals listed 8 panels at a time, in rounds
# (vortex_wall.c: the same points and weights, summed in another order)
# moved on purpose the bits of the same 6: re-recorded there, 2026-11-28.
# vortex_cpu2_mixed_fmm_rk2_700panels (the compressed inverse; the others
# have too few panels for it) added there, 2026-11-28.
# The FMM's P2M summing each point's terms in vector lanes, then the lanes
# (fmm_cpu_ops.h; M2M and L2L with powers in four chains) moved on purpose
# the bits of the 3 cpu FMM configurations: re-recorded there, 2026-11-28.
# The convective sum extending the generation's (px_nbody_velocity_extend:
# the old wake's tree and multipoles kept, the newborns in a tree of their
# own) moved the bits of the same 3: re-recorded there, 2026-11-28.
# The sheet's field near the wall in vector loops over (vortex, panel) pairs
# with a branch-free log (vx_log) instead of the C library's moved the bits
# of the 7 cpu configurations: re-recorded there, 2026-11-28.
# The generation's near-vortex correction summed in a vector loop (its lanes)
# moved the bits of 6 of them (not cpu single): re-recorded there, 2026-11-28.
# The lattice's and granular's 732 hashes were reproduced on both. On
# another CPU, record the base commit's hashes on that machine and check
# those:
#   bench/state_hashes.sh OLD/partix > base.ref
#   bench/state_hashes.sh --check base.ref build/release/partix
set -eu
cd "$(dirname "$0")/.."
ref=""
if [ "${1:-}" = "--check" ]; then ref=$2; shift 2; fi
partix=${1:-build/release/partix}
[ -x "$partix" ] || { echo "state_hashes: no $partix (build first)" >&2; exit 2; }
tmp=$(mktemp -d) || exit 2
trap 'rm -rf "$tmp"' EXIT
opencl=0
"$partix" info 2>/dev/null | grep -q 'opencl platform' && opencl=1

# config NAME CASE STEPS [--set k=v | --threads N]...
config() {
  name=$1 case=$2 steps=$3
  shift 3
  if [ -n "${ONLY:-}" ] && ! echo "$name" | grep -Eq "$ONLY"; then return; fi
  for rep in 1 2; do
    d="$tmp/$name.$rep"
    if ! OMP_NUM_THREADS=2 "$partix" run "cases/$case.yaml" --out "$d" --steps "$steps" -q \
        --set output.png=false --set output.vtk=false "$@" >"$tmp/log" 2>&1; then
      echo "$name run-failed $(head -c 300 "$tmp/log" | tr '\n' ' ')"
      return
    fi
    "$partix" verify "$d" --sections -q 2>/dev/null | tail -n +2 | grep -v '^case ' |
      awk -v n="$name" '{print n, $1, $4}' >"$tmp/$name.h$rep"
  done
  # a configuration any section of which differs between the two runs (e.g.
  # force sums in the order of a neighbour list built with atomics) is not
  # reproducible: all its sections are reported as `varies` and never
  # compared (a section that happened to agree twice may differ the third
  # time)
  if cmp -s "$tmp/$name.h1" "$tmp/$name.h2"; then
    cat "$tmp/$name.h1"
  else
    awk '{print $1, $2, "varies"}' "$tmp/$name.h1"
  fi
  rm -rf "$tmp/$name.1" "$tmp/$name.2"
}

run_all() {
  # lattice: the notched specimen with weak bonds (links break within the
  # steps), rk4 and leapfrog, both link schemes
  W="--set lattice.strength.normal=20 --set lattice.strength.shear=20"
  config lattice_cpu1_double_rk4_gather lattice/notched 300 --threads 1 \
    --set backend.precision=double --set lattice.scheme=gather $W
  config lattice_cpu2_double_rk4_gather lattice/notched 300 --threads 2 \
    --set backend.precision=double --set lattice.scheme=gather $W
  config lattice_cpu1_double_rk4_linkonce lattice/notched 300 --threads 1 \
    --set backend.precision=double --set lattice.scheme=link_once $W
  config lattice_cpu1_single_rk4 lattice/notched 300 --threads 1 \
    --set backend.precision=single $W
  config lattice_cpu2_mixed_leapfrog lattice/notched 300 --threads 2 \
    --set backend.precision=mixed --set lattice.integrator=leapfrog $W
  config lattice_cpu1_double_leapfrog_linkonce lattice/notched 300 --threads 1 \
    --set backend.precision=double --set lattice.integrator=leapfrog \
    --set lattice.scheme=link_once $W
  # granular: the small box shaken from the start (no settling) under a
  # strong oblique gravity, so that within the steps discs collide, slide,
  # spin and hit the walls and the part (statistics from t = 0); verlet and
  # ABM4
  G="--set granular.settle=0 --set granular.gravity=[3000,-20000] --set granular.statistics.start=0"
  for p in single double mixed; do
    config granular_cpu1_${p}_verlet granular/small_box 400 --threads 1 \
      --set backend.precision=$p $G
  done
  config granular_cpu2_double_verlet granular/small_box 400 --threads 2 \
    --set backend.precision=double $G
  config granular_cpu1_double_abm4 granular/small_box 400 --threads 1 \
    --set backend.precision=double --set granular.integrator=abm4 $G
  config granular_cpu2_mixed_abm4 granular/small_box 400 --threads 2 \
    --set backend.precision=mixed --set granular.integrator=abm4 $G
  # vortex: the demo cylinder, direct sums and FMM, euler and rk2
  for p in single double mixed; do
    config vortex_cpu1_${p}_direct_rk2 vortex/demo_cylinder 40 --threads 1 \
      --set backend.precision=$p --set vortex.velocity.method=direct
  done
  config vortex_cpu2_double_direct_euler vortex/demo_cylinder 40 --threads 2 \
    --set backend.precision=double --set vortex.velocity.method=direct --set vortex.scheme=euler
  config vortex_cpu1_double_fmm_rk2 vortex/demo_cylinder 40 --threads 1 \
    --set backend.precision=double --set vortex.velocity.method=fmm
  config vortex_cpu2_mixed_fmm_rk2 vortex/demo_cylinder 40 --threads 2 \
    --set backend.precision=mixed --set vortex.velocity.method=fmm
  # 700 panels: the solve by the compressed inverse (px_vortex_panels_compress)
  config vortex_cpu2_mixed_fmm_rk2_700panels vortex/demo_cylinder 40 --threads 2 \
    --set backend.precision=mixed --set vortex.velocity.method=fmm \
    --set "vortex.bodies[0].panels=700" --set time.dt=0.004
  if [ "$opencl" != 1 ]; then echo "opencl no-device -"; return; fi
  for p in single double mixed; do
    config lattice_opencl_${p}_rk4 lattice/notched 300 --set backend.type=opencl \
      --set backend.precision=$p $W
    config granular_opencl_${p}_verlet granular/small_box 400 --set backend.type=opencl \
      --set backend.precision=$p $G
    config vortex_opencl_${p}_direct_rk2 vortex/demo_cylinder 40 --set backend.type=opencl \
      --set backend.precision=$p --set vortex.velocity.method=direct
  done
  config lattice_opencl_double_leapfrog lattice/notched 300 --set backend.type=opencl \
    --set backend.precision=double --set lattice.integrator=leapfrog $W
}

if [ -z "$ref" ]; then
  run_all
  exit 0
fi
run_all >"$tmp/new"
# every line of the reference must be found unchanged; configurations new
# since the reference are listed but not judged
status=0
n=0
while read -r cfg sec hash; do
  [ "$hash" = varies ] && continue
  if [ -n "${ONLY:-}" ] && ! echo "$cfg" | grep -Eq "$ONLY"; then continue; fi
  got=$(awk -v c="$cfg" -v s="$sec" '$1 == c && $2 == s {print $3}' "$tmp/new")
  if [ "$got" != "$hash" ]; then
    echo "DIFFERS: $cfg $sec: reference $hash, now ${got:-missing}"
    status=1
  fi
  n=$((n + 1))
done <"$ref"
[ "$status" = 0 ] && echo "state_hashes: all $n section hashes of $ref compared are reproduced"
exit $status
