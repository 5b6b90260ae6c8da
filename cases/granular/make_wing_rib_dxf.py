#!/usr/bin/python3
"""Write wing_rib.dxf: a wing-rib-like part (millimetres) for the flagship
granular case, drawn the way a CAD program would export it.

Outline: an airfoil-shaped rib (NACA 0015 thickness law on a 350 mm chord,
upper and lower surfaces as SPLINEs through fit points) with a flat front
spar flange (LINEs) and the trailing edge cut square (LINE), two stringer
notches on the upper surface (LWPOLYLINE with bulged, i.e. rounded, corners),
two round lightening holes (CIRCLE) and one slotted hole (LWPOLYLINE with two
half-circle bulges). Entities are written in mixed directions on purpose (the
importer chains and reverses them).

Usage: /usr/bin/python3 make_wing_rib_dxf.py [out.dxf]
"""
import math
import sys

CHORD = 350.0
THICK = 0.15  # NACA 0015
X0 = 35.0     # front spar flange at x = X0 (the nose is cut off there)
X1 = 325.0    # trailing edge cut at x = X1


def half_thickness(x):
    """NACA 4-digit half thickness at x (mm) for the chord CHORD."""
    t = x / CHORD
    return 5 * THICK * CHORD * (0.2969 * math.sqrt(t) - 0.1260 * t - 0.3516 * t * t
                                + 0.2843 * t ** 3 - 0.1036 * t ** 4)


out = []


def g(code, value):
    out.append("%d\n%s\n" % (code, value))


def line(a, b):
    g(0, "LINE"), g(8, "RIB"), g(10, "%.6f" % a[0]), g(20, "%.6f" % a[1]), g(30, "0.0")
    g(11, "%.6f" % b[0]), g(21, "%.6f" % b[1]), g(31, "0.0")


def spline_fit(points):
    """A SPLINE given by fit points only (as many CAD programs export)."""
    g(0, "SPLINE"), g(8, "RIB"), g(70, 8), g(71, 3), g(72, 0), g(73, 0), g(74, len(points))
    for p in points:
        g(11, "%.6f" % p[0]), g(21, "%.6f" % p[1]), g(31, "0.0")


def lwpolyline(points, bulges, closed):
    g(0, "LWPOLYLINE"), g(8, "RIB"), g(90, len(points)), g(70, 1 if closed else 0)
    for p, b in zip(points, bulges):
        g(10, "%.6f" % p[0]), g(20, "%.6f" % p[1])
        if b:
            g(42, "%.9f" % b)


def circle(c, r):
    g(0, "CIRCLE"), g(8, "RIB"), g(10, "%.6f" % c[0]), g(20, "%.6f" % c[1]), g(40, "%.6f" % r)


def main():
    path = sys.argv[1] if len(sys.argv) > 1 else "wing_rib.dxf"
    g(0, "SECTION"), g(2, "HEADER"), g(9, "$ACADVER"), g(1, "AC1015"), g(9, "$INSUNITS"), g(70, 4)
    g(0, "ENDSEC")
    g(0, "SECTION"), g(2, "ENTITIES")

    # stringer notches on the upper surface: x ranges (mm), depth 9 mm
    notches = [(120.0, 140.0), (220.0, 238.0)]
    depth = 9.0

    def upper(x):
        return half_thickness(x)

    def lower(x):
        return -half_thickness(x)

    # upper surface pieces between the notches, as fit-point splines drawn
    # from the trailing edge towards the front (reversed on import)
    edges = [X0] + [v for n in notches for v in n] + [X1]
    for k in range(0, len(edges), 2):
        a, b = edges[k], edges[k + 1]
        n = max(6, int((b - a) / 8))
        pts = [(b - (b - a) * i / n, upper(b - (b - a) * i / n)) for i in range(n + 1)]
        spline_fit(pts)
    # the notches: down, across, up, with rounded bottom corners (bulges of
    # quarter circles, radius 3 mm)
    r = 3.0
    bq = math.tan(math.pi / 8)  # bulge of a 90 degree arc
    for (a, b) in notches:
        ya, yb = upper(a), upper(b)
        yb0 = min(ya, yb) - depth
        pts = [(a, ya), (a, yb0 + r), (a + r, yb0), (b - r, yb0), (b, yb0 + r), (b, yb)]
        # walking a -> b the bottom corners turn left: counter-clockwise arcs
        bul = [0.0, bq, 0.0, bq, 0.0, 0.0]
        lwpolyline(pts, bul, False)
    # lower surface, one spline from the front to the back
    n = 36
    pts = [(X0 + (X1 - X0) * i / n, lower(X0 + (X1 - X0) * i / n)) for i in range(n + 1)]
    spline_fit(pts)
    # front spar flange (a straight cut) and the square trailing edge
    line((X0, lower(X0)), (X0, upper(X0)))
    line((X1, upper(X1)), (X1, lower(X1)))

    # lightening holes
    circle((95.0, -2.0), 13.0)
    circle((180.0, -3.0), 15.0)
    # a slot between x = 255 and 285, 14 mm wide: two lines and two half circles
    y0, w = -2.0, 7.0
    lwpolyline([(255.0, y0 - w), (285.0, y0 - w), (285.0, y0 + w), (255.0, y0 + w)],
               [0.0, 1.0, 0.0, 1.0], True)

    g(0, "ENDSEC"), g(0, "EOF")
    with open(path, "w") as f:
        f.write("".join(out))


if __name__ == "__main__":
    main()
