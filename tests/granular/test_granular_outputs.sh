#!/bin/sh
# test_granular_outputs.sh PARTIX CASE
#
# The outputs of a granular run as a user meets them. CASE (resume_rib.yaml:
# impacts from the first steps, every impact logged, hardening in HV and
# residual stress in MPa) is run to step 2900, off every output schedule
# (every 1000, png_every 1500, log_every 200), then:
#  - the last state is written whatever the schedule: particles/walls VTK
#    files and .pvd entries, the PNG, a media.csv row at t = 2900 dt;
#  - every CSV header is "name [unit]", with the case's units for hardening
#    and residual stress;
#  - summary.json's quantities equal what the CSVs give: impacts per contour
#    (segment table and impacts.csv rows), mean impact energy, removal
#    (Archard, Finnie), the segments hit most, time averages of media.csv;
#  - `partix render` rewrites the run's pictures, identical to the run's
#    own, and no other file (case.yaml, CSV, VTK, summary.json, run.log);
#  - resuming may change a picture key and may not change the media;
#  - a contour name that is not a plain file name ("../rib") is refused.
# Exit 0 when all hold; each failure is listed otherwise.
set -u
partix=$1 case=$2
case "$case" in /*) ;; *) case=$(pwd)/$case ;; esac
case "$partix" in /*) ;; *) partix=$(pwd)/$partix ;; esac
tmp=$(mktemp -d) || exit 1
trap 'rm -rf "$tmp"' EXIT
cd "$tmp" || exit 1

fail() { echo "test_granular_outputs: $*"; exit 1; }

"$partix" -q run "$case" --out out --steps 2900 --no-progress || fail "the run failed"
python3 - out before.json <<'PY' || exit 1
import hashlib, json, os, sys
root = sys.argv[1]
out = {}
for d, _, names in os.walk(root):
    for n in names:
        p = os.path.join(d, n)
        st = os.stat(p)
        out[os.path.relpath(p, root)] = [hashlib.sha256(open(p, "rb").read()).hexdigest(),
                                         st.st_ino, st.st_mtime_ns]
json.dump(out, open(sys.argv[2], "w"))
PY
"$partix" -q render out/checkpoint.pxc > render.log 2>&1 || fail "render failed: $(cat render.log)"
"$partix" -q resume out/checkpoint.pxc --steps 3000 --no-progress \
  --set granular.media.count=10 > refused.log 2>&1 && fail "resume accepted a new media count"
grep -q "granular.media.count cannot change" refused.log ||
  fail "the refusal does not name the key: $(cat refused.log)"

python3 - out before.json <<'PY'
import csv, hashlib, json, math, os, re, sys
root, before = sys.argv[1], json.load(open(sys.argv[2]))
bad = []
def check(ok, what):
    if not ok:
        bad.append(what)
def rows(name):
    with open(os.path.join(root, name)) as f:
        r = list(csv.reader(f))
    return r[0], [[float(v) for v in row] for row in r[1:]]
def col(head, data, name):
    if name not in head:
        bad.append("no column %r in %s" % (name, head[:4]))
        return [0.0] * len(data)
    i = head.index(name)
    return [row[i] for row in data]
class Missing(dict):
    def __missing__(self, key):
        bad.append("summary.json: no quantity %s" % key)
        return {"value": float("nan"), "unit": ""}
def close(a, b, rel=1e-8, what=""):
    ok = abs(a - b) <= rel * max(abs(a), abs(b), 1e-300)
    check(ok, "%s: summary %.17g, CSV %.17g" % (what, a, b))

summary = json.load(open(os.path.join(root, "summary.json")))
q = Missing(summary["quantities"])
dt, step = summary["dt_s"], summary["step"]
check(step == 2900, "summary step %s, expected 2900" % step)
t_end = step * dt

# --- the last state, off every schedule
for f in ["particles_00002900.vtp", "walls_00002900.vtp", "particles_00002900.png"]:
    check(os.path.exists(os.path.join(root, f)), "last state: %s missing" % f)
for pvd in ["particles.pvd", "walls.pvd"]:
    text = open(os.path.join(root, pvd)).read()
    check("_00002900.vtp" in text, "last state: no entry in %s" % pvd)
head, media = rows("media.csv")
check(abs(media[-1][0] - t_end) <= 1e-9 * t_end, "media.csv ends at t = %g, not %g" % (media[-1][0], t_end))

# --- units in every CSV header
unit = re.compile(r"^\S.* \[[^\[\]]+\]$")
for name in sorted(os.listdir(root)):
    if name.endswith(".csv"):
        h = open(os.path.join(root, name)).readline().strip().split(",")
        for c in h:
            check(unit.match(c) is not None, "%s: header %r has no unit" % (name, c))
h, seg = rows("segments_rib.csv")
check("hardening [HV]" in h, "segments_rib.csv: no 'hardening [HV]' (%s)" % h[-2:])
check("residual_stress [MPa]" in h, "segments_rib.csv: no 'residual_stress [MPa]'")
check(h[0] == "s [m]" and "energy_n [J]" in h and "impacts [-]" in h, "segment header %s" % h[:8])
check(head[0] == "t [s]", "media.csv starts with %r" % head[0])

# --- summary.json against the CSVs
ih, imp = rows("impacts.csv")
contour_of = {}
total_summary = 0
for f in sorted(os.listdir(root)):
    m = re.match(r"segments_(.*)\.csv$", f)
    if not m:
        continue
    name = m.group(1)
    key = re.sub(r"[^A-Za-z0-9_]", "_", name)
    h, s = rows(f)
    n = col(h, s, "impacts [-]")
    en = col(h, s, "energy_n [J]")
    total = sum(n)
    check(q[key + ".impacts"]["value"] == round(total), "%s.impacts %s, segment table %s" % (key, q[key + ".impacts"]["value"], total))
    total_summary += q[key + ".impacts"]["value"]
    if total > 0:
        close(q[key + ".impact_energy_mean"]["value"], sum(en) / total, 1e-8, key + ".impact_energy_mean")
    close(q[key + ".archard_volume"]["value"] + 1e-300, sum(col(h, s, "archard_volume [m^3]")) + 1e-300, 1e-8, key + ".archard_volume")
    close(q[key + ".finnie_volume"]["value"] + 1e-300, sum(col(h, s, "finnie_volume [m^3]")) + 1e-300, 1e-8, key + ".finnie_volume")
    i = max(range(len(n)), key=lambda k: (n[k], -k))
    if n[i] > 0:
        close(q[key + ".most_impacts.s"]["value"], col(h, s, "s [m]")[i], 1e-9, key + ".most_impacts.s")
    else:
        check(q[key + ".most_impacts.s"]["value"] is None, key + ".most_impacts.s: not hit, not null")
    check(q[key + ".most_impacts.impacts"]["value"] == n[i], key + ".most_impacts.impacts")
    ea = col(h, s, "energy_n_area [J/m^2]")
    j = max(range(len(ea)), key=lambda k: (ea[k], -k))
    close(q[key + ".most_energy.energy_n_area"]["value"] + 1e-300, ea[j] + 1e-300, 1e-8, key + ".most_energy.energy_n_area")
    hard = col(h, s, "hardening [HV]")
    close(q[key + ".hardening_max"]["value"], max(hard), 1e-8, key + ".hardening_max")
    check(q[key + ".hardening_max"]["unit"] == "HV", key + ".hardening_max unit")
check(total_summary == len(imp) and len(imp) >= 50,
      "impacts: summary %s, impacts.csv %s rows (expected the same, >= 50)" % (total_summary, len(imp)))
en_log = sum(col(ih, imp, "energy_n [J]"))
en_sum = sum(q[k]["value"] for k in list(q) if k.endswith(".energy_n"))
close(en_sum, en_log, 1e-7, "normal impact energy, all contours (impacts.csv)")
start = q["statistics.start"]["value"]
t = col(head, media, "t [s]")
ke = [a + b for a, b in zip(col(head, media, "kinetic [J]"), col(head, media, "kinetic_rotation [J]"))]
area = sum(0.5 * (t[k] - t[k - 1]) * (ke[k] + ke[k - 1]) for k in range(1, len(t)) if t[k - 1] >= start)
close(q["media.kinetic_mean"]["value"], area / (t[-1] - t[0]) if t[-1] > t[0] else 0.0, 1e-7,
      "media.kinetic_mean")
close(q["media.com_travel"]["value"], col(head, media, "com_travel [m]")[-1], 1e-8, "media.com_travel")
check(q["media.count"]["value"] == 500, "media.count")

# --- render: the same pictures, nothing else touched
after = {}
for d, _, names in os.walk(root):
    for n in names:
        p = os.path.join(d, n)
        st = os.stat(p)
        after[os.path.relpath(p, root)] = [hashlib.sha256(open(p, "rb").read()).hexdigest(),
                                           st.st_ino, st.st_mtime_ns]
redrawn = 0
for n in sorted(set(before) | set(after)):
    if n not in after:
        bad.append("render removed %s" % n)
    elif n not in before:
        bad.append("render wrote %s" % n)
    elif before[n][0] != after[n][0]:
        bad.append("render changed %s" % n)
    elif before[n] != after[n]:
        if n.endswith(".png"):
            redrawn += 1
        else:
            bad.append("render rewrote %s (pictures only)" % n)
check(redrawn >= 5, "render redrew %d pictures" % redrawn)
if bad:
    print("test_granular_outputs: %d failures:" % len(bad))
    for b in bad:
        print("  " + b)
    sys.exit(1)
print("test_granular_outputs: %d impacts, summary = CSVs, render wrote pictures only" % len(imp))
PY
[ $? -eq 0 ] || exit 1
# a contour name becomes part of file names: never a path
"$partix" check "$case" --set "granular.contours[1].name=../rib" > name.log 2>&1 &&
  fail "a contour named ../rib was accepted"
grep -q "becomes part of output file names" name.log ||
  fail "the refusal of ../rib does not say why: $(cat name.log)"
"$partix" -q resume out/checkpoint.pxc --steps 3000 --no-progress \
  --set granular.picture.color=spin || fail "resume refused a new picture colour"
