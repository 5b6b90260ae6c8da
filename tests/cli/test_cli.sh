#!/bin/sh
# test_cli.sh PARTIX CASES_DIR: the partix command's exit codes and messages.
set -u
partix=$1 cases=$2
fails=0 checks=0
tmp=$(mktemp -d) || exit 1
trap 'rm -rf "$tmp"' EXIT

# expect CODE DESCRIPTION -- COMMAND...: run, compare the exit code.
expect() {
  want=$1 what=$2
  shift 3
  checks=$((checks + 1))
  "$@" >"$tmp/out" 2>"$tmp/err"
  got=$?
  if [ "$got" -ne "$want" ]; then
    fails=$((fails + 1))
    echo "FAIL: $what: exit $got, expected $want"
    sed 's/^/  | /' "$tmp/err" | head -5
  fi
}
# contains FILE TEXT DESCRIPTION: the file holds the fixed string.
contains() {
  checks=$((checks + 1))
  if ! grep -qF -- "$2" "$1"; then
    fails=$((fails + 1))
    echo "FAIL: $3: no '$2' in:"
    sed 's/^/  | /' "$1" | head -5
  fi
}

expect 0 "--help" -- "$partix" --help
contains "$tmp/out" "usage" "--help prints the usage"
expect 2 "unknown command" -- "$partix" frobnicate
contains "$tmp/err" "frobnicate" "unknown command is named"
expect 2 "a device index beyond an int" -- "$partix" -q run "$cases/granular/small_box.yaml" \
  --steps 2 --device 2147483648 --out "$tmp/dev_big" --no-progress
contains "$tmp/err" "backend.device: must be in [0, 1024] (got 2147483648)" "refused by its range"
expect 0 "info" -- "$partix" info
contains "$tmp/out" "vortex" "info lists the solvers"
# An OpenCL run that names no device takes the one `partix info` marks as the
# default (the first GPU, else device 0) and says which in run.log.
if grep -q "^    device 0:" "$tmp/out"; then
  contains "$tmp/out" "(the default: backend.device not given)" "info marks the default device"
  expect 0 "opencl run, no device" -- "$partix" -q run "$cases/granular/small_box.yaml" --steps 2 \
    --backend opencl --out "$tmp/dev_auto" --no-progress
  contains "$tmp/dev_auto/run.log" "automatic: backend.device = " "run.log names the device taken"
  expect 0 "opencl run, device 0" -- "$partix" -q run "$cases/granular/small_box.yaml" --steps 2 \
    --backend opencl --device 0 --out "$tmp/dev_0" --no-progress
  checks=$((checks + 1))
  if grep -q "automatic: backend.device" "$tmp/dev_0/run.log"; then
    fails=$((fails + 1))
    echo "FAIL: backend.device given, yet logged as automatic"
  fi
  expect 2 "a device that does not exist" -- "$partix" -q run "$cases/granular/small_box.yaml" \
    --steps 2 --backend opencl --device 99 --out "$tmp/dev_99" --no-progress
  contains "$tmp/err" "backend.device: cannot start the opencl backend" "it names backend.device"
  # a granular checkpoint of the cpu engine resumes on cpu only, and says so
  expect 0 "granular run on cpu" -- "$partix" -q run "$cases/granular/small_box.yaml" --steps 4 \
    --out "$tmp/gr_cpu" --no-progress
  expect 2 "its resume on opencl is refused" -- "$partix" -q resume "$tmp/gr_cpu/checkpoint.pxc" \
    --more 2 --backend opencl --no-progress
  contains "$tmp/err" "resumes on that backend (--backend cpu)" "the refusal says where it resumes"
fi

# Every case file shipped with partix is valid (schema, geometry, stability).
n=0
for f in "$cases"/*/*.yaml; do
  case $f in */sweeps/*) continue ;; esac
  if grep -q '^mesh:' "$f"; then # a part3d study: its sections cut, its runs' cases valid
    expect 0 "part3d --dry-run $f" -- "$partix" part3d "$f" --dry-run
    continue
  fi
  n=$((n + 1))
  expect 0 "check $f" -- "$partix" check "$f"
  contains "$tmp/out" ": ok (" "check $f reports ok"
done
# ... and every shipped sweep (each of its runs' cases validated)
for f in "$cases"/sweeps/*.yaml; do
  expect 0 "sweep --dry-run $f" -- "$partix" sweep "$f" --dry-run
done
checks=$((checks + 1))
if [ "$n" -lt 10 ]; then fails=$((fails + 1)); echo "FAIL: only $n case files in $cases"; fi

# A misspelt key: file:line:col, the key, a suggestion; usage exit code.
cat >"$tmp/typo.yaml" <<'Y'
solver: vortex
time: {dt: 0.01, end: 0.1}
vortex:
  nu: 0.01
  bodies:
    - {type: circle, radius: 0.5, panels: 64}
  gama_max: 0.001
Y
expect 2 "misspelt key" -- "$partix" check "$tmp/typo.yaml"
contains "$tmp/err" "typo.yaml:7:3" "misspelt key located"
contains "$tmp/err" "gamma_max" "misspelt key gets a suggestion"
expect 2 "missing file" -- "$partix" check "$tmp/none.yaml"
contains "$tmp/err" "none.yaml" "missing file named"

# The vortex solver's diffusion step: a floor of eps* far below sqrt(nu dt)
# is warned about (nu dt / eps_min^2 = 0.01 * 0.02 / 0.001^2 = 200); the
# default floor (0.5 sqrt(nu dt) here) is not.
cat >"$tmp/cfl.yaml" <<'Y'
solver: vortex
time: {dt: 0.02, end: 0.1}
vortex:
  nu: 0.01
  v_inf: [1.0, 0.0]
  bodies:
    - {type: circle, radius: 0.5, panels: 64}
  eps_min: 0.001
Y
expect 0 "small eps_min" -- "$partix" check "$tmp/cfl.yaml"
contains "$tmp/err" "nu dt / eps_min^2 = 200" "small eps_min warned about"
sed '/eps_min/d' "$tmp/cfl.yaml" >"$tmp/cfl0.yaml"
expect 0 "default eps_min" -- "$partix" check "$tmp/cfl0.yaml"
checks=$((checks + 1))
if grep -q "warning.*eps_min" "$tmp/err"; then
  fails=$((fails + 1))
  echo "FAIL: the default eps_min warned:"
  sed 's/^/  | /' "$tmp/err" | head -5
fi

# An MPI launch of one rank runs as without mpirun (the multi-rank runs are
# tested in tests/cli/test_mpi_run.sh).
expect 0 "single-rank launch" -- env OMPI_COMM_WORLD_SIZE=1 "$partix" run \
  "$cases/vortex/demo_cylinder.yaml" --out "$tmp/one" --steps 2 --no-progress
contains "$tmp/one/loads.csv" "t" "single-rank run writes its loads"

# output.png: false: no picture at all, the end-of-run plots included (each
# solver), while `partix render` still draws them.
for c in vortex/demo_cylinder lattice/cantilever granular/small_box; do
  d="$tmp/nopng_${c%%/*}"
  expect 0 "$c with output.png false" -- "$partix" run "$cases/$c.yaml" --out "$d" \
    --steps 30 --set output.png=false -q
  checks=$((checks + 1))
  if [ -n "$(find "$d" -name '*.png')" ]; then
    fails=$((fails + 1)); echo "FAIL: $c with output.png false drew $(find "$d" -name '*.png')"
  fi
done
# verify --sections: a hash of every section; two identical runs hold the
# same state bit for bit, a run of more steps does not
expect 0 "the same run again" -- "$partix" run "$cases/vortex/demo_cylinder.yaml" \
  --out "$tmp/nopng_again" --steps 30 --set output.png=false -q
expect 0 "one step more" -- "$partix" run "$cases/vortex/demo_cylinder.yaml" \
  --out "$tmp/nopng_more" --steps 31 --set output.png=false -q
for d in nopng_vortex nopng_again nopng_more; do
  "$partix" verify "$tmp/$d" --sections -q | tail -n +2 | grep -v '^case ' >"$tmp/$d.sections"
done
contains "$tmp/nopng_vortex.sections" "vortex.x f64 " "verify --sections lists the wake"
checks=$((checks + 1))
cmp -s "$tmp/nopng_vortex.sections" "$tmp/nopng_again.sections" ||
  { fails=$((fails + 1)); echo "FAIL: two identical runs gave different section hashes"; }
checks=$((checks + 1))
if grep -q '^vortex.x ' "$tmp/nopng_more.sections" &&
   ! cmp -s "$tmp/nopng_vortex.sections" "$tmp/nopng_more.sections"; then :; else
  fails=$((fails + 1)); echo "FAIL: verify --sections did not tell a step more apart"
fi
expect 2 "--sections belongs to verify" -- "$partix" check "$cases/vortex/demo_cylinder.yaml" --sections
expect 0 "render a run made without pictures" -- "$partix" render "$tmp/nopng_vortex/checkpoint.pxc" -q
checks=$((checks + 1))
[ -f "$tmp/nopng_vortex/loads.png" ] || { fails=$((fails + 1)); echo "FAIL: render drew no loads.png"; }


# ---- A user's first hour: a case with a profile file next to it, run from
# one directory, resumed, checked and rendered from others.
mkdir -p "$tmp/mycase" "$tmp/work" "$tmp/elsewhere"
cp "$cases/vortex/naca0012.dat" "$tmp/mycase/profile.dat"
cat >"$tmp/mycase/wing.yaml" <<'Y'
solver: vortex
time: {dt: 0.01, steps: 4}
output: {every: 2, checkpoint_every: 2}
vortex:
  nu: 0.001
  v_inf: [1.0, 0.0]
  bodies:
    - {type: selig, file: profile.dat, panels: 80}
  fields: {grid: [-0.5, 1.5, -0.5, 0.5], cells: [20, 10]}
Y
expect 0 "run with a profile file, quiet after the command" -- sh -c \
  "cd '$tmp/work' && '$partix' run ../mycase/wing.yaml --out out_r -q"
checks=$((checks + 1))
if [ -s "$tmp/err" ]; then
  fails=$((fails + 1)); echo "FAIL: -q after the command still printed:"; sed 's/^/  | /' "$tmp/err"
fi
contains "$tmp/work/out_r/case.yaml" 'file: "input/profile.dat"' "the run records its copy of the profile"
checks=$((checks + 1))
if ! cmp -s "$tmp/mycase/profile.dat" "$tmp/work/out_r/input/profile.dat"; then
  fails=$((fails + 1)); echo "FAIL: the run folder holds no copy of the profile"
fi
contains "$tmp/work/out_r/case.yaml" "cells: [20, 10]" "whole numbers written as such"
expect 0 "resume from another directory" -- sh -c \
  "cd '$tmp/elsewhere' && '$partix' resume ../work/out_r/checkpoint.pxc --more 2 --no-progress"
contains "$tmp/work/out_r/summary.json" '"step": 6,' "--more 2 ran two more steps"
expect 0 "check the run's case from another directory" -- sh -c \
  "cd '$tmp/elsewhere' && '$partix' check ../work/out_r/case.yaml"
expect 2 "a new run into a folder that holds a run is refused" -- sh -c \
  "cd '$tmp/work' && '$partix' run ../mycase/wing.yaml --out out_r -q"
contains "$tmp/err" "out_r holds a run already" "the refusal names the folder"
contains "$tmp/err" "partix resume out_r/checkpoint.pxc" "the refusal says how to continue the run"
contains "$tmp/work/out_r/summary.json" '"step": 6,' "the refused run left the record as it was"
expect 2 "a resume into another folder is refused" -- sh -c \
  "cd '$tmp/work' && '$partix' resume out_r/checkpoint.pxc --more 2 --out out_r2 -q"
contains "$tmp/err" "cp -a out_r out_r2" "the refusal says how to branch a run"
expect 0 "--out takes the folder name as given (no YAML: '#' is not a comment)" -- sh -c \
  "cd '$tmp/work' && '$partix' run ../mycase/wing.yaml --out \"my run #2\" --steps 1 -q"
checks=$((checks + 1))
[ -f "$tmp/work/my run #2/summary.json" ] || {
  fails=$((fails + 1)); echo "FAIL: --out 'my run #2' did not write to that folder"; ls "$tmp/work"
}
cp "$tmp/work/out_r/case.yaml" "$tmp/case_before.yaml"
expect 2 "render without a run" -- "$partix" render
contains "$tmp/err" "no run folder or checkpoint given" "render says what it takes"
expect 2 "render refuses a key that defines the state" -- sh -c \
  "cd '$tmp/elsewhere' && '$partix' render ../work/out_r --set vortex.nu=0.01"
contains "$tmp/err" "render draws the state stored" "render says why it refuses vortex.nu"
expect 0 "render from another directory" -- sh -c \
  "cd '$tmp/elsewhere' && '$partix' render ../work/out_r --set vortex.picture.width=400"
checks=$((checks + 1))
if ! cmp -s "$tmp/case_before.yaml" "$tmp/work/out_r/case.yaml"; then
  fails=$((fails + 1)); echo "FAIL: render rewrote the run's case.yaml"
fi
checks=$((checks + 1))
if grep -q "resuming" "$tmp/out" "$tmp/err"; then
  fails=$((fails + 1)); echo "FAIL: render says it is resuming"
fi
expect 2 "resume to an end before the checkpoint" -- "$partix" resume \
  "$tmp/work/out_r/checkpoint.pxc" --steps 5 --no-progress
contains "$tmp/err" "the run is at step 6" "an end before the checkpoint is refused"
expect 2 "resume a finished run without a new end" -- "$partix" resume \
  "$tmp/work/out_r/checkpoint.pxc" --no-progress
contains "$tmp/err" "--more N" "a finished run says how to run further"
expect 2 "resume with a changed physical key" -- "$partix" resume \
  "$tmp/work/out_r/checkpoint.pxc" --more 2 --set vortex.nu=0.01 --no-progress
contains "$tmp/err" "vortex.nu cannot change when a run is resumed" "the refused key is named"
contains "$tmp/err" "time.steps" "the keys that may change are listed"
expect 2 "--more with --steps" -- "$partix" resume "$tmp/work/out_r/checkpoint.pxc" \
  --more 2 --steps 9
expect 0 "summary of the run" -- "$partix" summary "$tmp/work/out_r"
contains "$tmp/out" "finished" "partix summary shows the status"
contains "$tmp/out" "wall time [s]" "partix summary shows the wall time"
contains "$tmp/work/out_r/run.log" "info: partix " "run.log starts each segment with a header"
contains "$tmp/work/out_r/run.log" "resume of ../work/out_r/checkpoint.pxc at step 4" \
  "run.log records the resume"
expect 0 "verify a run's checkpoint" -- "$partix" verify "$tmp/work/out_r"
contains "$tmp/out" "ok: vortex checkpoint at step 6" "verify names what it checked"
cp "$tmp/work/out_r/checkpoint.pxc" "$tmp/damaged.pxc"
printf 'X' | dd of="$tmp/damaged.pxc" bs=1 seek=300 conv=notrunc 2>/dev/null
expect 2 "verify a damaged checkpoint" -- "$partix" verify "$tmp/damaged.pxc"
contains "$tmp/err" "damaged.pxc" "the damaged checkpoint is named"
expect 2 "summary of a folder without one" -- "$partix" summary "$tmp/mycase"
contains "$tmp/err" "no summary.json" "a folder without a summary is named"

if [ "$fails" -ne 0 ]; then
  echo "test_cli: $fails of $checks checks failed"
  exit 1
fi
echo "test_cli: all $checks checks passed"
