#!/bin/sh
# test_part3d.sh PARTIX CASES_DIR: partix part3d cuts the shipped wing
# segment into 3 sections, runs each as a short 2D case (sections/K), maps
# the statistics onto the surface (surface.vtp read back by VTK, with the
# values of surface.csv), skips finished sections when run again but
# refuses to reuse them once the file is edited (other sections, another
# set: value), resumes one stopped by SIGINT, cuts an inward mesh as the
# outward one, and refuses a wrong file, an open mesh, a part contour that
# is not a dxf shape, wrong units, a part outside or larger than the
# container and a contour of too many points before running anything.
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
check "each section's run recorded" test "$(grep -c '^fnv1a64 [0-9a-f]\{16\}$' \
  out/p/sections/1.fingerprint out/p/sections/2.fingerprint out/p/sections/3.fingerprint |
  grep -c ':1')" -eq 3

# the file edited: runs made for other sections or settings are not reused,
# the study refused before anything is written or removed, --dry-run too
cp out/p/sections.csv csv.before
sed 's/sections: 3/sections: 2/' part.yaml >p2.yaml
"$partix" part3d p2.yaml >out.txt 2>err.txt
check "other sections: exit 2" test $? -eq 2
check "... sections/1 named" grep -q \
  "^p2.yaml: out/p/sections/1 holds a run made with other settings than section 1 has now" err.txt
check "... and sections/2" grep -q "out/p/sections/2 holds a run made with other settings" err.txt
check "... how to go on" grep -q "nothing was run or removed. To run the study as the file says \
now, remove those folders (or the whole out/p), or give dir: another folder; to go on" err.txt
check "... nothing written" cmp -s csv.before out/p/sections.csv
check "... nothing removed" test -f out/p/sections/1/summary.json -a -f out/p/sections/3/summary.json
"$partix" part3d p2.yaml --dry-run >out.txt 2>err.txt
check "... --dry-run: exit 2" test $? -eq 2
sed 's/time.end: 0.16/time.end: 0.17/' part.yaml >p3.yaml
"$partix" part3d p3.yaml --dry-run >out.txt 2>err.txt
check "another set: value: exit 2" test $? -eq 2
check "... every section named" test "$(grep -c 'holds a run made with other settings' err.txt)" -eq 3
mv out/p/sections/2.fingerprint fp2
"$partix" part3d part.yaml --dry-run >out.txt 2>err.txt
check "a run with no record: exit 2" test $? -eq 2
check "... named" grep -q "out/p/sections/2 holds a run with no record of the settings" err.txt
mv fp2 out/p/sections/2.fingerprint
# the same sections from a copy of the mesh, and from the mesh with every
# triangle turned inward (a binary STL, corners 2 and 3 swapped): the
# same runs (the inward surface is turned outward before it is cut)
cp "$cases/part3d/wing_segment.stl" copy.stl
/usr/bin/python3 - "$cases/part3d/wing_segment.stl" inward.stl <<'PY'
import struct, sys
d = open(sys.argv[1], "rb").read()
n = struct.unpack("<I", d[80:84])[0]
o = bytearray(d[:84])
for i in range(n):
    r = d[84 + 50 * i:84 + 50 * (i + 1)]
    o += r[0:12] + r[12:24] + r[36:48] + r[24:36] + r[48:50]
open(sys.argv[2], "wb").write(o)
PY
sed "s|mesh: .*|mesh: $tmp/copy.stl|" part.yaml >copy.yaml
"$partix" part3d copy.yaml --dry-run >out.txt 2>err.txt
check "a copy of the mesh: the same runs" test $? -eq 0
sed "s|mesh: .*|mesh: $tmp/inward.stl|" part.yaml >inward.yaml
"$partix" part3d inward.yaml --dry-run >out.txt 2>err.txt
check "an inward mesh: the same runs" test $? -eq 0
check "... the same sections" grep -q 'section 2 at 0.03 m: 1 loop, area 0.000439954 m^2' out.txt

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

# a part that does not fit the 2D case, refused at its key before anything
# is written (--dry-run too): units beyond sense, a millimetre mesh left at
# 1 m per unit (a 70 m part in a 0.16 m box), a centre outside the box, a
# contour of more points than the granular solver takes segments
sed 's/dir: out\/p/dir: out\/u/; s/units: 0.001/units: 1e20/' part.yaml >u20.yaml
"$partix" part3d u20.yaml --dry-run >out.txt 2>err.txt
check "units 1e20: exit 2" test $? -eq 2
check "... at its key" grep -q "^u20.yaml:3:8: units: '1e20' is not metres per mesh unit from" err.txt
sed 's/units: 1e20/units: 1e3/' u20.yaml >u3.yaml
"$partix" part3d u3.yaml >out.txt 2>err.txt
check "units 1e3: exit 2" test $? -eq 2
check "... larger than the container" grep -q \
  "^u3.yaml:3:8: units: section 1 (at 10000 m) is .* larger than its container 'box' (0.16 m x 0.16 m)" err.txt
check "... nothing written" test ! -e out/u
sed '/^units:/d' u20.yaml >u1.yaml
"$partix" part3d u1.yaml --dry-run >out.txt 2>err.txt
check "units not given for a mm mesh: exit 2" test $? -eq 2
check "... said" grep -q "units (not given: 1 m per mesh unit): section 1 (at 10 m) is 66.65 m x" err.txt
sed 's/center: .*/center: [5, 5]/' u1.yaml >c5.yaml
sed -i 's/^mesh: \(.*\)/mesh: \1\nunits: 0.001/' c5.yaml
"$partix" part3d c5.yaml --dry-run >out.txt 2>err.txt
check "a centre outside the container: exit 2" test $? -eq 2
check "... at center" grep -q "^c5.yaml:[0-9]*:[0-9]*: center: section 1 (at 0.01 m) spans .* not inside \
its container 'box' (x 0 to 0.16 m, y 0 to 0.16 m)" err.txt
sed 's/set: {backend.threads: 1,/set: {backend.threads: 1, granular.segment_length: 1e-8,/' \
  u20.yaml >seg.yaml
sed -i 's/units: 1e20/units: 0.001/' seg.yaml
"$partix" part3d seg.yaml >out.txt 2>err.txt
check "1e-8 m segments: exit 2" test $? -eq 2
check "... too many points" grep -q "would take 1.384e+07 points at the 2D case's segment length \
1e-08 m: more than the 1000000 a section may have" err.txt
check "... nothing written" test ! -e out/u

echo "test_part3d: $((checks - fails)) of $checks checks passed"
[ "$fails" -eq 0 ]
