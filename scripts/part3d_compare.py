#!/usr/bin/python3
"""Compare two surface maps of the same part (partix part3d: DIR/surface.csv),
e.g. the study with K sections against 2K, or two seeds of the media.

Usage: scripts/part3d_compare.py A/surface.csv B/surface.csv [COLUMN]

COLUMN is the name before its unit (default energy_n_area). Prints, for
each map, the mean and the range of the column over the vertices, and the
RMS of the difference between the maps relative to the RMS of B (the
vertices are the same mesh's, row by row).
"""
import csv
import math
import sys


def column(path, name):
    with open(path, newline="") as f:
        rows = list(csv.reader(f))
    head = rows[0]
    for i, h in enumerate(head):
        if h.split(" [")[0] == name:
            return h, [float(r[i]) for r in rows[1:]]
    sys.exit("%s: no column %s (columns: %s)" % (path, name, ", ".join(head)))


def main():
    if len(sys.argv) not in (3, 4):
        sys.exit(__doc__)
    name = sys.argv[3] if len(sys.argv) == 4 else "energy_n_area"
    ha, a = column(sys.argv[1], name)
    hb, b = column(sys.argv[2], name)
    if len(a) != len(b):
        sys.exit("the maps have %d and %d vertices: not the same mesh" % (len(a), len(b)))
    for path, v in ((sys.argv[1], a), (sys.argv[2], b)):
        print("%s: %s mean %.4g, min %.4g, max %.4g" % (path, ha, sum(v) / len(v), min(v),
                                                        max(v)))
    rms_b = math.sqrt(sum(x * x for x in b) / len(b))
    rms_d = math.sqrt(sum((x - y) ** 2 for x, y in zip(a, b)) / len(b))
    print("RMS difference %.4g, %.1f %% of the RMS of %s" % (rms_d, 100 * rms_d / rms_b if rms_b
                                                            else 0, sys.argv[2]))


main()
