#!/bin/sh
# resume_identity.sh PARTIX CASE N1 N2 N3 [OPTION...]
#
# A run interrupted twice and resumed leaves the same run folder as an
# uninterrupted one, file by file: CASE is run to step N3 in one go, and
# again to N1, resumed to N2 from another directory, and resumed to N3 from a
# third (OPTIONs, e.g. --set key=value, go to both first runs). Every file
# of the two folders must be byte-identical, except
#  - run.log (it holds wall-clock times), which must exist;
#  - summary.json, compared without its "wall_time_s" line;
#  - checkpoint.pxc, compared without its creation time and the CRCs that
#    cover it (docs/checkpoint-format.md: header bytes 48..55, the header CRC,
#    the file CRC).
# Exit 0 when identical; the differing files are listed otherwise.
set -u
partix=$1 case=$2 n1=$3 n2=$4 n3=$5
shift 5
case "$case" in /*) ;; *) case=$(pwd)/$case ;; esac
case "$partix" in /*) ;; *) partix=$(pwd)/$partix ;; esac
tmp=$(mktemp -d) || exit 1
trap 'rm -rf "$tmp"' EXIT
mkdir -p "$tmp/whole" "$tmp/parts" "$tmp/elsewhere/deeper"

fail() { echo "resume_identity: $*"; exit 1; }

(cd "$tmp/whole" && "$partix" -q run "$case" --out out --steps "$n3" --no-progress "$@") ||
  fail "the uninterrupted run failed"
(cd "$tmp/parts" && "$partix" -q run "$case" --out out --steps "$n1" --no-progress "$@") ||
  fail "the first part failed"
(cd "$tmp/elsewhere" && "$partix" -q resume ../parts/out/checkpoint.pxc --steps "$n2" \
  --no-progress) || fail "the first resume failed"
(cd "$tmp/elsewhere/deeper" && "$partix" -q resume "$tmp/parts/out/checkpoint.pxc" \
  --steps "$n3" --no-progress) || fail "the second resume failed"

python3 - "$tmp/whole/out" "$tmp/parts/out" <<'PY' || exit 1
import os, struct, sys
a_dir, b_dir = sys.argv[1], sys.argv[2]

def files(root):
    out = set()
    for d, _, names in os.walk(root):
        for n in names:
            out.add(os.path.relpath(os.path.join(d, n), root))
    return out

def masked_checkpoint(data):
    b = bytearray(data)
    if len(b) < 64 or b[:8] != b"PXCHKPT\0":
        return bytes(b)
    h = struct.unpack_from("<I", b, 16)[0]
    b[48:56] = bytes(8)        # created
    b[h - 4:h] = bytes(4)      # header CRC
    b[len(b) - 8:len(b) - 4] = bytes(4)  # file CRC
    return bytes(b)

def without_wall(data):
    return b"\n".join(l for l in data.split(b"\n") if b'"wall_time_s"' not in l)

fa, fb = files(a_dir), files(b_dir)
bad = []
for n in sorted(fa ^ fb):
    bad.append("%s: only in the %s run" % (n, "uninterrupted" if n in fa else "resumed"))
if "run.log" not in fa or "run.log" not in fb:
    bad.append("run.log missing")
for n in sorted(fa & fb):
    if n == "run.log":
        continue
    x = open(os.path.join(a_dir, n), "rb").read()
    y = open(os.path.join(b_dir, n), "rb").read()
    if n.endswith(".pxc"):
        x, y = masked_checkpoint(x), masked_checkpoint(y)
    elif n == "summary.json":
        x, y = without_wall(x), without_wall(y)
    if x != y:
        bad.append("%s differs (%d and %d bytes)" % (n, len(x), len(y)))
if bad:
    print("resume_identity: %d of %d files differ after resuming twice:" % (len(bad), len(fa | fb)))
    for l in bad:
        print("  " + l)
    sys.exit(1)
print("resume_identity: %d files identical" % len(fa))
PY
