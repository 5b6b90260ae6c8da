#!/bin/sh
# test_part3d.sh PARTIX CASES_DIR: partix part3d cuts the shipped wing
# segment into 3 sections, runs each as a short 2D case (sections/K), maps
# the statistics onto the surface (surface.vtp read back by VTK, with the
# values of surface.csv), skips finished sections when run again, resumes
# one stopped by SIGINT, and refuses a wrong file, an open mesh and a part
# contour that is not a dxf shape before running anything.
set -u
partix=$1 cases=$2
fails=0 checks=0
tmp=$(mktemp -d) || exit 1
trap 'rm -rf "$tmp"' EXIT
cd "$tmp" || exit 1

check() { # check DESCRIPTION COMMAND...: the command succeeds
  what=$1
  shift
  checks=$((checks + 1))
  if ! "$@" >/dev/null 2>&1; then
    fails=$((fails + 1))
    echo "FAIL: $what"
    tail -3 out.txt err.txt 2>/dev/null | sed 's/^/  | /' # the last command's words
  fi
}

# short runs: 400 discs around the part, a few vibration periods
cat >part.yaml <<YAML
case: $cases/part3d/wing_section.yaml
mesh: $cases/part3d/wing_segment.stl
units: 0.001
normal: [0, 0, 1]
vibration: [1, 0, 0]
center: [0.08, 0.03]
sections: 3
dir: out/p
set: {backend.threads: 1, time.end: 0.16, granular.settle: 0.04, granular.media.count: 400,
      output.png: false}
YAML
"$partix" part3d part.yaml --dry-run >out.txt 2>err.txt
check "--dry-run exits 0" test $? -eq 0
check "--dry-run lists 3 runs" test "$(grep -c '^out/p/sections/[123]: --set' out.txt)" -eq 3
check "--dry-run runs nothing" test ! -d out/p/sections
check "the sections' areas" grep -q 'section 2 at 0.03 m: 1 loop, area 0.000439954 m^2' out.txt

"$partix" part3d part.yaml --jobs 2 >out.txt 2>err.txt
check "part3d exits 0" test $? -eq 0
for f in sections.csv sections.png sections/sweep.csv surface.vtp surface.csv surface_energy.png \
  surface_removal.png surface_summary.json contours/section-3.dxf; do
  check "writes $f" test -s "out/p/$f"
done
check "three section runs finished" test "$(grep -c '"status": "finished"' \
  out/p/sections/1/summary.json out/p/sections/2/summary.json out/p/sections/3/summary.json |
  grep -c ':1')" -eq 3
check "one row per vertex" test "$(wc -l <out/p/surface.csv)" -eq 627
check "summary names the hottest vertex" grep -q '"hottest": {"value"' out/p/surface_summary.json
# ParaView's reader: 626 points, 1248 triangles, the CSV's energies
cat >read.py <<'PY'
import csv, sys
from vtkmodules.vtkIOXML import vtkXMLPolyDataReader
r = vtkXMLPolyDataReader()
r.SetFileName("out/p/surface.vtp")
r.Update()
g = r.GetOutput()
a = g.GetPointData().GetArray("energy_n_area")
rows = list(csv.DictReader(open("out/p/surface.csv")))
assert g.GetNumberOfPoints() == 626 and g.GetNumberOfPolys() == 1248, "size"
assert g.GetCell(0).GetNumberOfPoints() == 3, "triangles"
e = [float(x["energy_n_area [J/m^2]"]) for x in rows]
assert max(e) > 0, "some energy"
for i in range(626):
    assert abs(a.GetValue(i) - e[i]) <= 1e-9 * max(e), (i, a.GetValue(i), e[i])
    assert abs(g.GetPoint(i)[2] - float(rows[i]["z [m]"])) < 1e-12
PY
check "surface.vtp read by VTK matches surface.csv" /usr/bin/python3 read.py

# again: every section finished before, the map written anew
rm out/p/surface.csv
"$partix" part3d part.yaml >out.txt 2>err.txt
check "a second run exits 0" test $? -eq 0
check "finished sections skipped" test "$(grep -c 'finished before, skipped' out.txt)" -eq 3
check "the map written again" test -s out/p/surface.csv

# SIGINT while the runs run: 130, then the same command finishes them
sed 's|dir: out/p|dir: out/q|; s|time.end: 0.16|time.end: 0.4|' part.yaml >q.yaml
"$partix" part3d q.yaml --jobs 3 >out.txt 2>err.txt &
pid=$!
i=0
# stopped once the three runs have started (their run.log; a section's
# checkpoint is written only at its end or on Ctrl-C, checkpoint_every 0):
# a second in, while the 0.4 s runs take some 20 s on 2 cores
while [ $i -lt 1800 ] && ! [ -f out/q/sections/1/run.log -a \
  -f out/q/sections/2/run.log -a -f out/q/sections/3/run.log ]; do
  sleep 0.1
  i=$((i + 1))
done
sleep 1
kill -INT $pid
wait $pid
check "interrupted: exit 130" test $? -eq 130
check "no map from stopped runs" test ! -f out/q/surface.csv
check "each stopped run left its checkpoint" test -f out/q/sections/1/checkpoint.pxc -a \
  -f out/q/sections/2/checkpoint.pxc -a -f out/q/sections/3/checkpoint.pxc
"$partix" part3d q.yaml --jobs 3 >out.txt 2>err.txt
check "the same command finishes the study" test $? -eq 0
check "its map" test -s out/q/surface.csv

# refusals, before anything runs
printf 'case: %s\nmesh: %s\nnormal: [0, 0, 1]\nvibration: [0, 0, 2]\ncenter: [0, 0]\nsections: 2\nbogus: 1\n' \
  "$cases/part3d/wing_section.yaml" "$cases/part3d/wing_segment.stl" >bad.yaml
"$partix" part3d bad.yaml >out.txt 2>err.txt
check "unknown key: exit 2" test $? -eq 2
check "unknown key located" grep -q "bad.yaml:7:1: unknown key 'bogus'" err.txt
sed '/bogus/d' bad.yaml >bad2.yaml
"$partix" part3d bad2.yaml >out.txt 2>err.txt
check "vibration along the normal: exit 2" test $? -eq 2
check "vibration along the normal named" grep -q "along the section normal" err.txt
head -c 2000 "$cases/part3d/wing_segment.stl" >open.stl
printf '\001\000\000\000' | dd of=open.stl bs=1 seek=80 conv=notrunc 2>/dev/null
# 84 + 50 bytes: one triangle, an open surface
head -c 134 open.stl >open1.stl
sed "s|mesh: .*|mesh: $tmp/open1.stl|; s|vibration: .*|vibration: [1, 0, 0]|" bad2.yaml >open.yaml
"$partix" part3d open.yaml >out.txt 2>err.txt
check "open mesh: exit 2" test $? -eq 2
check "open mesh: its edges" grep -q "3 edges are not shared" err.txt
sed "s|case: .*|case: $cases/granular/small_box.yaml|; s|vibration: .*|vibration: [1, 0, 0]|" \
  bad2.yaml >circle.yaml
"$partix" part3d circle.yaml >out.txt 2>err.txt
check "a part that is not a dxf shape: exit 2" test $? -eq 2
check "... named" grep -q "contour 'part' is a circle; the sections replace a dxf shape" err.txt

echo "test_part3d: $((checks - fails)) of $checks checks passed"
[ "$fails" -eq 0 ]
