#!/usr/bin/env python3
"""compare_runs.py A B: two run folders hold the same files, byte for byte,
except run.log (wall-clock times; it must exist in both), the "wall_time_s"
line of summary.json, and in checkpoint.pxc its creation time and the CRCs
that cover it (docs/checkpoint-format.md: header bytes 48..55, the header
CRC, the file CRC). Exit 0 when identical; lists the differences otherwise.
Used by resume_identity.sh and fault_injection.sh."""
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
    bad.append("%s: only in %s" % (n, a_dir if n in fa else b_dir))
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
    print("compare_runs: %d of %d files differ:" % (len(bad), len(fa | fb)))
    for l in bad:
        print("  " + l)
    sys.exit(1)
print("compare_runs: %d files identical" % len(fa))
