#!/bin/sh
# test_sweep.sh PARTIX CASES_DIR: partix sweep runs a grid and a list of runs,
# records a failing run without stopping the others, tabulates every run's
# summary, plots, skips finished runs and resumes interrupted ones when run
# again, and refuses a wrong sweep file before running anything.
set -u
partix=$1 cases=$2
fails=0 checks=0
tmp=$(mktemp -d) || exit 1
trap 'rm -rf "$tmp"' EXIT
# Open MPI's session folder under this test's own folder: two mpirun
# started at once (ctest -j) race to create the shared /tmp/ompi.HOST.UID
# ("orte_session_dir failed ... File exists")
export OMPI_MCA_orte_tmpdir_base="$tmp"
cd "$tmp" || exit 1

check() { # check DESCRIPTION COMMAND...: the command succeeds
  what=$1
  shift
  checks=$((checks + 1))
  if ! "$@" >/dev/null 2>&1; then fails=$((fails + 1)); echo "FAIL: $what"; fi
}

# a 2 x 2 grid of the demo cylinder, two runs at a time, a plot
cat >grid.yaml <<YAML
case: $cases/vortex/demo_cylinder.yaml
dir: out/grid
set: {time.steps: 2, output.png: false}
grid:
  vortex.nu: [0.01, 0.02]
  vortex.v_inf: ["[1, 0]", "[1, 0.1]"]
plot: {x: vortex.nu, y: cx_mean}
YAML
"$partix" sweep grid.yaml --jobs 2 >out.txt 2>err.txt
check "a grid sweep exits 0" test $? -eq 0
check "four run folders" test -f out/grid/nu-0.01_v_inf-1-0/summary.json \
  -a -f out/grid/nu-0.01_v_inf-1-0.1/summary.json -a -f out/grid/nu-0.02_v_inf-1-0/summary.json \
  -a -f out/grid/nu-0.02_v_inf-1-0.1/summary.json
check "the runs ran with their values" grep -q 'nu: 0.02' out/grid/nu-0.02_v_inf-1-0.1/case.yaml
check "sweep.csv has a header and four rows" test "$(wc -l <out/grid/sweep.csv)" -eq 5
check "sweep.csv holds the varied keys and quantities" \
  grep -q '^run,vortex.nu,vortex.v_inf,status,exit,wall_time \[s\],.*"cx_mean \[-\]"' \
  out/grid/sweep.csv
check "every run finished" test "$(grep -c ',finished,0,' out/grid/sweep.csv)" -eq 4
check "sweep.json lists the runs" grep -q '"run": "nu-0.02_v_inf-1-0.1"' out/grid/sweep.json
check "sweep.json is JSON" python3 -c "import json,sys; d=json.load(open('out/grid/sweep.json')); sys.exit(len(d['runs']) != 4)"
check "sweep.png drawn" test -s out/grid/sweep.png
# the quantity of a run equals what `partix summary` reports for it
want=$("$partix" summary --csv out/grid/nu-0.01_v_inf-1-0 | awk -F, '$2 == "cx_mean" {print $3}' | tr -d '"')
check "the table holds the run's summary" grep -q "^nu-0.01_v_inf-1-0,.*,$want," out/grid/sweep.csv
# `partix summary` of the sweep folder's entries: the runs, and for each
# file that is no summary.json (sweep.csv, sweep.json, sweep.png) one line
"$partix" summary out/grid/* >out.txt 2>err.txt
check "partix summary of the sweep folder's entries exits 2" test $? -eq 2
check "one line for each file that is no summary" test "$(wc -l <err.txt)" -eq 3
check "each line names its file" test "$(grep -c '^partix summary: out/grid/sweep\.\(csv\|json\|png\): ' err.txt)" -eq 3
# the sweep folder itself: pointed to its table and its runs
"$partix" summary out/grid >out.txt 2>err.txt
check "partix summary of a sweep folder exits 2" test $? -eq 2
check "it names the sweep's table and how to see its runs" \
  grep -q "a sweep's folder, not a run's: its table is out/grid/sweep.csv" err.txt

# run again: every run finished before, nothing runs
"$partix" sweep grid.yaml >again.txt 2>&1
check "a finished sweep run again exits 0" test $? -eq 0
check "finished runs are skipped" test "$(grep -c 'finished before, skipped' again.txt)" -eq 4
# a run whose summary says it was interrupted is resumed (it finishes)
sed -i 's/"status": "finished"/"status": "interrupted"/' out/grid/nu-0.02_v_inf-1-0/summary.json
"$partix" sweep grid.yaml >resumed.txt 2>&1
check "an interrupted run is resumed" grep -q 'nu-0.02_v_inf-1-0: finished in' resumed.txt
check "the resumed run says finished" grep -q '"status": "finished"' \
  out/grid/nu-0.02_v_inf-1-0/summary.json
check "the run log records the resume" grep -q 'resume of' out/grid/nu-0.02_v_inf-1-0/run.log

# run again with other settings (a copy of the finished grid, its `set`
# changed): no folder made with the old settings is skipped as if its
# results were the new ones; each is left alone and its run failed, exit 1
cp -r out/grid out/changed
sed -e 's|dir: out/grid|dir: out/changed|' -e 's|time.steps: 2,|time.steps: 3,|' grid.yaml >changed.yaml
sum_before=$(cat out/changed/*/summary.json | cksum)
"$partix" sweep changed.yaml >changed.txt 2>&1
check "a sweep over folders made with other settings exits 1" test $? -eq 1
check "no run of other settings is skipped" test "$(grep -c 'finished before' changed.txt)" -eq 0
check "each such run is failed with why" test "$(grep -c ': failed: out/changed/nu-.* was made with other settings' changed.txt)" -eq 4
check "the table says so" test "$(grep -c ',failed,-1,.*made with other settings' out/changed/sweep.csv)" -eq 4
check "the table holds none of their old quantities" \
  test "$(grep -c cx_mean out/changed/sweep.csv)" -eq 0
check "the old results are left alone" test "$(cat out/changed/*/summary.json | cksum)" = "$sum_before"
check "no plot is claimed when none is drawn" sh -c "! tail -n 1 changed.txt | grep -q sweep.png"
check "the earlier sweep.png is named as such" grep -q "the one there is an earlier sweep's" changed.txt
# a folder whose fingerprint is missing (made by an older partix, or the
# file removed) is not trusted either; the others are skipped as before
rm out/changed/.nu-0.01_v_inf-1-0.fingerprint
sed 's|dir: out/grid|dir: out/changed|' grid.yaml >changed_back.yaml
"$partix" sweep changed_back.yaml >back.txt 2>&1
check "a folder without a fingerprint fails the sweep" test $? -eq 1
check "a folder without a fingerprint is not skipped" grep -q 'nu-0.01_v_inf-1-0: failed: .* was made with other settings' back.txt
check "the runs of the same settings are skipped" test "$(grep -c 'finished before, skipped' back.txt)" -eq 3

# a list of runs, one of which fails: recorded, the others go on, exit 1
cat >list.yaml <<YAML
case: $cases/vortex/demo_cylinder.yaml
dir: out/list
set: {time.steps: 2, output.png: false}
runs:
  - {vortex.nu: 0.01}
  - {time.dt: 0.5}
  - {vortex.nu: 0.02}
YAML
"$partix" sweep list.yaml >out.txt 2>err.txt
check "a sweep with a failed run exits 1" test $? -eq 1
check "the failed run is in the table with its error" grep -q '^dt-0.5,.*,failed,2,.*time.dt' out/list/sweep.csv
check "the other runs finished" test "$(grep -c ',finished,0,' out/list/sweep.csv)" -eq 2
check "the failure is reported" grep -q 'dt-0.5: failed' out.txt

# the same grid handed to the ranks of an MPI job (rank 0 hands out, ranks 1
# and 2 run): the same table but for the wall times
if command -v mpirun >/dev/null 2>&1 && "$partix" info 2>/dev/null | grep -q '^MPI: yes'; then
  root=""
  [ "$(id -u)" = 0 ] && root=--allow-run-as-root
  sed 's|dir: out/grid|dir: out/grid_mpi|' grid.yaml >grid_mpi.yaml
  # under ASan, leaks are not checked in this one: Open MPI's plugins are
  # unloaded before LeakSanitizer runs, so their allocations cannot be told
  # from partix's (memory errors are still checked)
  ASAN_OPTIONS="${ASAN_OPTIONS:+$ASAN_OPTIONS:}detect_leaks=0" \
    mpirun $root --oversubscribe -np 3 "$partix" sweep grid_mpi.yaml >mpi.txt 2>&1
  check "an MPI sweep exits 0" test $? -eq 0
  check "the ranks ran the runs" grep -q 'on rank 2' mpi.txt
  # columns but wall time (6) compared; the interrupted-and-resumed run of
  # out/grid has its own checkpoint history, so its row is left out
  check "the MPI sweep's table equals the local one" python3 -c "
import csv, sys
def rows(path):
    out = []
    for row in csv.DictReader(open(path)):
        row.pop('wall_time [s]')
        if row['run'] != 'nu-0.02_v_inf-1-0':
            out.append(row)
    return out
sys.exit(rows('out/grid/sweep.csv') != rows('out/grid_mpi/sweep.csv'))"
else
  echo "test_sweep: no mpirun or no MPI in this build: the MPI sweep is not checked"
fi

# Ctrl-C (SIGINT to the sweep alone): no more runs start, the running ones
# stop at a checkpoint, the table says so, exit 130
cat >stop.yaml <<YAML
case: $cases/vortex/demo_cylinder.yaml
dir: out/stop
set: {time.steps: 400, output.png: false, backend.threads: 1}
grid:
  vortex.nu: [0.01, 0.02, 0.03]
YAML
"$partix" sweep stop.yaml --jobs 2 >stop.txt 2>&1 &
pid=$!
sleep 2
kill -INT $pid
wait $pid
check "an interrupted sweep exits 130" test $? -eq 130
check "the running runs are interrupted" test "$(grep -c ',interrupted,130,' out/stop/sweep.csv)" -eq 2
check "the third run was not started" grep -q '^nu-0.03,"0.03",not run,-1,' out/stop/sweep.csv
check "the sweep says how to continue" grep -q 'run the same command again' stop.txt
# run again with an override added: the interrupted runs are not resumed
# (that would drop the new override), their checkpoints are left alone
sed -e 's|backend.threads: 1}|backend.threads: 1, vortex.v_inf: "[1, 0.1]"}|' \
  -e 's|\[0.01, 0.02, 0.03\]|[0.01, 0.02]|' stop.yaml >stop2.yaml
ck_before=$(cat out/stop/nu-0.01/checkpoint.pxc out/stop/nu-0.02/checkpoint.pxc | cksum)
"$partix" sweep stop2.yaml >stop2.txt 2>&1
check "a sweep over interrupted runs of other settings exits 1" test $? -eq 1
check "interrupted runs of other settings are not resumed" \
  test "$(grep -c 'was made with other settings' out/stop/sweep.csv)" -eq 2
check "their checkpoints are left alone" \
  test "$(cat out/stop/nu-0.01/checkpoint.pxc out/stop/nu-0.02/checkpoint.pxc | cksum)" = "$ck_before"
check "their logs record no resume" test "$(cat out/stop/nu-0.0[12]/run.log | grep -c 'resume of')" -eq 0

# the sweep killed outright (SIGKILL: it cannot forward Ctrl-C): its run
# does not go on orphaned, writing into a folder a rerun would use too; it
# gets SIGINT, writes its checkpoint and stops
cat >kill.yaml <<YAML
case: $cases/vortex/demo_cylinder.yaml
dir: out/kill
set: {time.steps: 100000, output.png: false, backend.threads: 1}
grid:
  vortex.nu: [0.01]
YAML
alive() { # alive PID: the process runs (a zombie does not)
  [ -r "/proc/$1/stat" ] && ! grep -q '^[0-9]* (.*) Z' "/proc/$1/stat"
}
"$partix" sweep kill.yaml >kill.txt 2>&1 &
pid=$!
sleep 2
child=$(pgrep -P $pid | head -n 1)
kill -KILL $pid
wait $pid 2>/dev/null
i=0
while [ -n "$child" ] && alive "$child" && [ $i -lt 100 ]; do
  sleep 0.1
  i=$((i + 1))
done
check "the sweep had a run going" test -n "$child"
check "the run of a killed sweep stops" eval "! alive '$child'"
check "it stopped at a checkpoint" test -f out/kill/nu-0.01/checkpoint.pxc
[ -n "$child" ] && alive "$child" && kill -KILL "$child"

# a wrong sweep file is refused before anything runs, with file:line:col
printf 'case: %s/vortex/demo_cylinder.yaml\ndir: out/bad\ngird:\n  vortex.nu: [1]\n' "$cases" >bad.yaml
"$partix" sweep bad.yaml >out.txt 2>err.txt
check "an unknown key exits 2" test $? -eq 2
check "the unknown key is located" grep -q 'bad.yaml:3:1: unknown key .gird.' err.txt
printf 'case: %s/vortex/demo_cylinder.yaml\ndir: out/bad\ngrid:\n  vortex.nuu: [1, 2]\n' "$cases" >bad2.yaml
"$partix" sweep bad2.yaml >out.txt 2>err.txt
check "a misspelt case key exits 2" test $? -eq 2
check "the misspelt key is named" grep -q 'vortex.nuu' err.txt
check "nothing ran" test ! -e out/bad
printf 'case: %s/vortex/demo_cylinder.yaml\ndir: out/bad\ngrid:\n  vortex.nu: []\n' "$cases" >bad3.yaml
"$partix" sweep bad3.yaml >out.txt 2>err.txt
check "an empty list of values exits 2" test $? -eq 2
check "the empty list is located" grep -q 'bad3.yaml:4:3: grid: vortex.nu: ' err.txt

# values that differ only in characters a folder name cannot hold get
# folders of their own, named from their own values whatever their order
printf 'case: %s/vortex/demo_cylinder.yaml\ndir: out/names\ngrid:\n  title: ["a/b", "a-b", "a:b"]\n' "$cases" >names.yaml
printf 'case: %s/vortex/demo_cylinder.yaml\ndir: out/names\ngrid:\n  title: ["a:b", "a-b", "a/b"]\n' "$cases" >names2.yaml
"$partix" sweep names.yaml --dry-run >names.txt 2>&1
"$partix" sweep names2.yaml --dry-run >names2.txt 2>&1
check "three values, three folders" test "$(cut -d: -f1 names.txt | sort -u | wc -l)" -eq 3
check "a value the name keeps names its folder alone" grep -q '^out/names/title-a-b: --set title=a-b$' names.txt
check "the folders do not depend on the order" test "$(sort names.txt)" = "$(sort names2.txt)"
printf 'case: %s/vortex/demo_cylinder.yaml\ndir: out/bad\nruns:\n  - {vortex.nu: 0.01}\n  - {vortex.nu: "0.01"}\n' "$cases" >same.yaml
"$partix" sweep same.yaml --dry-run >out.txt 2>err.txt
check "two runs of one folder are refused" test $? -eq 2
check "the refusal names both runs" grep -q 'same.yaml:5:.*runs 1 and 2 would share the folder out/bad/nu-0.01' err.txt

# a key a run leaves out: the table shows the case's value it ran with
cat >keep.yaml <<YAML
case: $cases/vortex/demo_cylinder.yaml
dir: out/keep
set: {time.steps: 2, output.png: false}
runs:
  - {vortex.nu: 0.01}
  - {vortex.v_inf: "[1, 0.1]"}
YAML
"$partix" sweep keep.yaml >out.txt 2>&1
check "a key a run leaves out shows the case's value (csv)" \
  grep -q '^nu-0.01,"0.01","\[1, 0\]",finished,' out/keep/sweep.csv
check "a key a run leaves out shows the case's value (json)" python3 -c "
import json, sys
d = json.load(open('out/keep/sweep.json'))
sys.exit(d['runs'][1]['values']['vortex.nu'] != '0.005')"

"$partix" sweep grid.yaml --dry-run >dry.txt 2>&1
check "--dry-run lists the runs" test "$(grep -c -- '--set vortex.nu=' dry.txt)" -eq 4

if [ "$fails" -ne 0 ]; then
  echo "test_sweep: $fails of $checks checks failed"
  exit 1
fi
echo "test_sweep: all $checks checks passed"
