#!/usr/bin/python3
"""Write wing_segment.stl (binary STL, millimetres) and wing_segment_mid.dxf:
a wing-rib-like part for `partix part3d` (cases/part3d/wing_segment.yaml).

The part: a 60 mm span of a tapered, twisted wing. Its sections normal to z
are NACA 0018 profiles (closed trailing edge) whose chord runs from 70 mm at
z = 0 to 50 mm at z = 60 mm and which turn by 8 degrees (nose down) about
their 30 % chord point (on the z axis) over the span. The surface is 13
rings of 48 profile points each (cosine spacing, points at both edges),
joined by quads cut into two triangles; the end caps are fans from a centre
vertex at 35 % chord (the profile is convex). The mid-span profile
(z = 30 mm) is also written as a closed LWPOLYLINE in
wing_segment_mid.dxf: the 2D case's own part (cases/part3d/wing_section.yaml).

Usage: /usr/bin/python3 make_wing_segment_stl.py [OUT_DIR]
"""
import math
import os
import struct
import sys

SPAN = 60.0
RINGS = 13
NPROF = 48  # points around a profile: 25 on the upper surface (both edges), 23 below


def chord(z):
    return 70.0 - 20.0 * z / SPAN


def twist(z):
    return math.radians(-8.0 * z / SPAN)


def half_thickness(t):
    """NACA 0018 half thickness per unit chord, closed trailing edge."""
    return 5 * 0.18 * (0.2969 * math.sqrt(t) - 0.1260 * t - 0.3516 * t * t + 0.2843 * t ** 3
                       - 0.1036 * t ** 4)


def profile(z):
    """NPROF points counter-clockwise: trailing edge, upper surface, leading
    edge, lower surface; the 30 % chord point at the origin."""
    c, a = chord(z), twist(z)
    half = NPROF // 2
    pts = []
    for i in range(NPROF):
        if i <= half:  # trailing edge -> leading edge along the upper surface
            t = 0.5 * (1 + math.cos(math.pi * i / half))
            y = half_thickness(t)
        else:          # leading edge -> trailing edge along the lower surface
            t = 0.5 * (1 - math.cos(math.pi * (i - half) / half))
            y = -half_thickness(t)
        x, y = (t - 0.3) * c, y * c
        pts.append((x * math.cos(a) - y * math.sin(a), x * math.sin(a) + y * math.cos(a), z))
    return pts


def centre(z):
    c, a = chord(z), twist(z)
    x = 0.05 * c
    return (x * math.cos(a), x * math.sin(a), z)


def main():
    out = sys.argv[1] if len(sys.argv) > 1 else os.path.dirname(os.path.abspath(__file__))
    zs = [SPAN * j / (RINGS - 1) for j in range(RINGS)]
    rings = [profile(z) for z in zs]
    tris = []
    for j in range(RINGS - 1):
        a, b = rings[j], rings[j + 1]
        for i in range(NPROF):
            k = (i + 1) % NPROF
            # counter-clockwise profile: a[i] -> a[k] -> b[k] faces outward
            tris.append((a[i], a[k], b[k]))
            tris.append((a[i], b[k], b[i]))
    c0, c1 = centre(0.0), centre(SPAN)
    for i in range(NPROF):
        k = (i + 1) % NPROF
        tris.append((c1, rings[-1][i], rings[-1][k]))  # top cap, normal +z
        tris.append((c0, rings[0][k], rings[0][i]))    # bottom cap, normal -z
    with open(os.path.join(out, "wing_segment.stl"), "wb") as f:
        f.write(b"wing_segment.stl: tapered twisted NACA 0018 span, mm".ljust(80, b" "))
        f.write(struct.pack("<I", len(tris)))
        for t in tris:
            f.write(struct.pack("<3f", 0.0, 0.0, 0.0))
            for p in t:
                f.write(struct.pack("<3f", *p))
            f.write(struct.pack("<H", 0))
    mid = profile(SPAN / 2)
    with open(os.path.join(out, "wing_segment_mid.dxf"), "w") as f:
        f.write("0\nSECTION\n2\nENTITIES\n0\nLWPOLYLINE\n8\nPART\n90\n%d\n70\n1\n" % NPROF)
        for p in mid:
            f.write("10\n%.6f\n20\n%.6f\n" % (p[0], p[1]))
        f.write("0\nENDSEC\n0\nEOF\n")


main()
