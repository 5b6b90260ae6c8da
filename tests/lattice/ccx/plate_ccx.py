#!/usr/bin/python3
"""CalculiX reference for the lattice plate test (tests/lattice/test_lattice_plate.c).

The FRUND solver's own test: a steel plate 100 x 50 x 5 mm, the lower half of
the right face (x = 100 mm, y <= 25 mm) clamped, 100 N down at the top corner
(0, 50, 5) mm. This script writes a CalculiX deck for that problem, runs `ccx`
(Debian package calculix-ccx, installed by scripts/deps.sh --bench) and writes
the reference numbers tests/lattice/test_lattice_plate.c reads:

  * the clamp holds all nodes with x >= 100 mm - CLAMP and y <= CLAMP_Y
    (defaults 0 and 25 mm: the lower half of the right face, the problem as
    stated; the lattice converges to it as h -> 0, see docs/lattice.md);
  * the load is 100 N spread over the volume of the corner 1 mm cube (a GRAV
    body load: density 100 t/mm^3 times 1 mm/s^2 over 1 mm^3), the element
    the lattice loads at h = 1 mm (a true point load has an infinite
    deflection under it in 3-D elasticity, so it cannot be a reference);
  * E = 210 GPa, nu = 0 (default; the lattice's original solid) or --nu
    (lattice.poisson, docs/notes/lattice-poisson.md; the study at nu = 0.3
    uses C3D20R);
  * C3D8I (default; incompatible modes, no shear locking) or C3D20R bricks,
    MESH per mm (default 1), aligned with the lattice cells, so each lattice
    cell's stress is compared with the mean of the integration-point stresses
    of the elements inside that 1 mm cell (the cell average the lattice's
    Love-Weber stress is), and the displacement at a cell centre is
    interpolated with the element shape functions.

Measured (ccx 2.20; corner deflection at the corner cell's centre): C3D8I
-0.41468 mm and C3D20R -0.41589 mm with the clamp over the 1 mm volume
x >= 99 mm (--clamp 1); C3D8I -0.43729 mm with the face clamp. The element
types agree within 0.3 %; the clamp's definition moves the answer by 5.5 %.
Interior von Mises values move by less than 0.6 % between the two clamps.

Usage: plate_ccx.py [OUTPUT] [--mesh N] [--type C3D8I|C3D20R] [--nu NU] [--clamp MM]
                    [--clamp-y MM] [--keep DIR [--no-run]] [--at X,Y,Z ...]
Writes OUTPUT (default: tests/lattice/data/plate_ccx.txt next to this file)
with lines "name x y z value" in mm and MPa. --keep DIR leaves the deck and
CalculiX's outputs in DIR (--no-run: only read the results already there).
Needs ccx on PATH.
"""
import os
import subprocess
import sys
import tempfile
import time

LX, LY, LZ = 100, 50, 5          # mm
E = 210000.0                     # MPa
LOAD = 100.0                     # N, -z
# lattice cell centres (mm) where the stress is compared: away from the clamp
# edge (x = 99 mm, y = 25 mm) and the loaded corner, where it is singular
POINTS = [
    (50.5, 25.5, 4.5), (50.5, 25.5, 0.5), (30.5, 40.5, 4.5), (70.5, 10.5, 4.5),
    (70.5, 40.5, 0.5), (85.5, 20.5, 4.5), (20.5, 20.5, 4.5), (60.5, 30.5, 4.5),
]
CORNER = (0.5, 49.5, 4.5)
# cell centres (mm) where the vertical displacement is compared too
UPOINTS = [(0.5, 49.5, 2.5), (0.5, 49.5, 0.5), (0.5, 45.5, 2.5), (4.5, 49.5, 2.5),
           (0.5, 25.5, 2.5), (25.5, 49.5, 2.5), (0.5, 0.5, 2.5), (50.5, 49.5, 2.5)]


def option(name, default, conv):
    if name in sys.argv:
        return conv(sys.argv[sys.argv.index(name) + 1])
    return default


def positional():
    out, skip = [], False
    for a in sys.argv[1:]:
        if skip:
            skip = False
        elif a.startswith("--"):
            skip = a != "--no-run"  # every other option takes a value
        else:
            out.append(a)
    return out


def shape(etype, xi, eta, zeta):
    """Shape functions of the element's nodes in the deck's node order, at
    local coordinates (xi, eta, zeta) in [-1, 1]^3; nodes as local (a, b, c)."""
    corners = [(-1, -1, -1), (1, -1, -1), (1, 1, -1), (-1, 1, -1),
               (-1, -1, 1), (1, -1, 1), (1, 1, 1), (-1, 1, 1)]
    n = []
    for a, b, c in corners:
        f = (1 + xi * a) * (1 + eta * b) * (1 + zeta * c) / 8.0
        n.append(f * (xi * a + eta * b + zeta * c - 2) if etype == "C3D20R" else f)
    if etype != "C3D20R":
        return n
    mids = [(0, -1, -1), (1, 0, -1), (0, 1, -1), (-1, 0, -1),
            (0, -1, 1), (1, 0, 1), (0, 1, 1), (-1, 0, 1),
            (-1, -1, 0), (1, -1, 0), (1, 1, 0), (-1, 1, 0)]
    for a, b, c in mids:
        if a == 0:
            n.append((1 - xi * xi) * (1 + eta * b) * (1 + zeta * c) / 4.0)
        elif b == 0:
            n.append((1 - eta * eta) * (1 + xi * a) * (1 + zeta * c) / 4.0)
        else:
            n.append((1 - zeta * zeta) * (1 + xi * a) * (1 + eta * b) / 4.0)
    return n


def main():
    args = positional()
    per_mm = option("--mesh", 1, int)
    etype = option("--type", "C3D8I", str).upper()
    nu = option("--nu", 0.0, float)
    clamp = option("--clamp", 0.0, float)
    clamp_y = option("--clamp-y", LY / 2, float)
    keep = option("--keep", None, str)
    # extra points (mm) where uz is written as "uz_at" lines (e.g. the centre
    # of the lattice's corner element at another h); the test ignores them
    extra = [tuple(float(v) for v in a.split(",")) for a in
             [sys.argv[i + 1] for i, w in enumerate(sys.argv) if w == "--at"]]
    if etype not in ("C3D20R", "C3D8I"):
        sys.exit("--type must be C3D20R or C3D8I")
    quad = etype == "C3D20R"
    here = os.path.dirname(os.path.abspath(__file__))
    out = args[0] if args else os.path.join(here, "..", "data", "plate_ccx.txt")
    nx, ny, nz = LX * per_mm, LY * per_mm, LZ * per_mm
    d = 1.0 / per_mm
    q = 2 if quad else 1          # node grid points per element edge
    s = d / q                     # node grid spacing
    gx, gy, gz = q * nx + 1, q * ny + 1, q * nz + 1

    def nid(i, j, k):
        return 1 + i + gx * (j + gy * k)

    def exists(i, j, k):
        # 20-node bricks: no nodes at face or body centres
        return not quad or (i % 2) + (j % 2) + (k % 2) <= 1

    def eid(i, j, k):
        return 1 + i + nx * (j + ny * k)

    def enodes(i, j, k):
        I, J, K = q * i, q * j, q * k
        c = [(I, J, K), (I + q, J, K), (I + q, J + q, K), (I, J + q, K),
             (I, J, K + q), (I + q, J, K + q), (I + q, J + q, K + q), (I, J + q, K + q)]
        if not quad:
            return c
        return c + [(I + 1, J, K), (I + 2, J + 1, K), (I + 1, J + 2, K), (I, J + 1, K),
                    (I + 1, J, K + 2), (I + 2, J + 1, K + 2), (I + 1, J + 2, K + 2),
                    (I, J + 1, K + 2), (I, J, K + 1), (I + 2, J, K + 1),
                    (I + 2, J + 2, K + 1), (I, J + 2, K + 1)]

    def cell_elems(x, y, z):
        """Elements inside the 1 mm lattice cell whose centre is (x, y, z)."""
        i0, j0, k0 = int(x - 0.5) * per_mm, int(y - 0.5) * per_mm, int(z - 0.5) * per_mm
        return [(i0 + a, j0 + b, k0 + c) for a in range(per_mm) for b in range(per_mm)
                for c in range(per_mm)]

    def locate(x, y, z):
        i = min(int(x / d), nx - 1)
        j = min(int(y / d), ny - 1)
        k = min(int(z / d), nz - 1)
        loc = (2 * (x - i * d) / d - 1, 2 * (y - j * d) / d - 1, 2 * (z - k * d) / d - 1)
        return (i, j, k), loc

    work = keep or tempfile.mkdtemp(prefix="plate_ccx_")
    os.makedirs(work, exist_ok=True)
    deck = os.path.join(work, "plate.inp")
    loaded = set(cell_elems(*CORNER))
    probes = sorted(set(eid(*e) for p in POINTS for e in cell_elems(*p)))
    uelems = [locate(*p)[0] for p in [CORNER] + UPOINTS + extra]
    with open(deck, "w") as f:
        f.write("*HEADING\nlattice plate reference, nu = %g, %s, %d per mm\n*NODE, NSET=NALL\n"
                % (nu, etype, per_mm))
        for k in range(gz):
            for j in range(gy):
                for i in range(gx):
                    if exists(i, j, k):
                        f.write("%d, %.6f, %.6f, %.6f\n" % (nid(i, j, k), i * s, j * s, k * s))
        f.write("*ELEMENT, TYPE=%s, ELSET=EALL\n" % etype)
        for k in range(nz):
            for j in range(ny):
                for i in range(nx):
                    ids = [nid(*p) for p in enodes(i, j, k)]
                    if quad:  # 20-node lines continue on a second line
                        f.write("%d, %s,\n%s\n" % (eid(i, j, k), ", ".join(map(str, ids[:15])),
                                                   ", ".join(map(str, ids[15:]))))
                    else:
                        f.write("%d, %s\n" % (eid(i, j, k), ", ".join(map(str, ids))))
        f.write("*ELSET, ELSET=ELOAD\n%s\n" % ",\n".join(str(eid(*e)) for e in sorted(loaded)))
        f.write("*ELSET, ELSET=EPROBE\n%s\n" % ",\n".join(map(str, probes)))
        rest = [eid(i, j, k) for k in range(nz) for j in range(ny) for i in range(nx)
                if (i, j, k) not in loaded]
        f.write("*ELSET, ELSET=EREST\n")
        for a in range(0, len(rest), 12):
            f.write(", ".join(map(str, rest[a:a + 12])) + ",\n")
        f.write("*NSET, NSET=NFIX\n")
        fixed = [nid(i, j, k) for k in range(gz) for j in range(gy) for i in range(gx)
                 if exists(i, j, k) and i * s >= LX - clamp - 1e-9 and j * s <= clamp_y + 1e-9]
        for a in range(0, len(fixed), 10):
            f.write(", ".join(map(str, fixed[a:a + 10])) + ",\n")
        unodes = sorted(set(nid(*p) for e in uelems for p in enodes(*e)))
        f.write("*NSET, NSET=NPROBE\n%s\n" % ",\n".join(map(str, unodes)))
        f.write("*MATERIAL, NAME=STEEL\n*ELASTIC\n%.1f, %.4f\n" % (E, nu))
        f.write("*MATERIAL, NAME=LOADED\n*ELASTIC\n%.1f, %.4f\n*DENSITY\n%.6g\n"
                % (E, nu, LOAD / 1.0))  # over the 1 mm^3 corner cell
        f.write("*SOLID SECTION, ELSET=EREST, MATERIAL=STEEL\n")
        f.write("*SOLID SECTION, ELSET=ELOAD, MATERIAL=LOADED\n")
        f.write("*STEP\n*STATIC\n*BOUNDARY\nNFIX, 1, 3, 0.\n")
        f.write("*DLOAD\nELOAD, GRAV, 1., 0., 0., -1.\n")
        f.write("*NODE PRINT, NSET=NPROBE\nU\n")
        f.write("*EL PRINT, ELSET=EPROBE\nS\n")
        f.write("*END STEP\n")
    t0 = time.time()
    if "--no-run" not in sys.argv:
        with open(os.path.join(work, "ccx.log"), "w") as log:
            subprocess.run(["ccx", "-i", "plate"], cwd=work, check=True, stdout=log,
                           stderr=subprocess.STDOUT)
    wall = time.time() - t0
    disp, stress = {}, {}
    mode = None
    with open(os.path.join(work, "plate.dat")) as f:
        for line in f:
            w = line.split()
            if "displacements" in line:
                mode = "u"
                continue
            if "stresses" in line:
                mode = "s"
                continue
            try:
                vals = [float(v) for v in w]
            except ValueError:
                continue
            if mode == "u" and len(vals) == 4:
                disp[int(vals[0])] = vals[1:]
            elif mode == "s" and len(vals) == 8:
                stress.setdefault(int(vals[0]), []).append(vals[2:])

    def uz_at(p):
        e, loc = locate(*p)
        n = shape(etype, *loc)
        return sum(w * disp[nid(*node)][2] for w, node in zip(n, enodes(*e)))

    with open(out, "w") as f:
        f.write("# CalculiX %s reference for the lattice plate (written by "
                "tests/lattice/ccx/plate_ccx.py\n# --type %s --mesh %d --nu %g --clamp %g --clamp-y %g; "
                "ccx wall time %.1f s): name x y z value [mm, mm, mm, mm|MPa]\n"
                % (ccx_version(), etype, per_mm, nu, clamp, clamp_y, wall))
        f.write("corner_uz %.1f %.1f %.1f %.9g\n" % (CORNER + (uz_at(CORNER),)))
        for p in UPOINTS:
            f.write("uz %.1f %.1f %.1f %.9g\n" % (p + (uz_at(p),)))
        for p in extra:
            f.write("uz_at %.4f %.4f %.4f %.9g\n" % (p + (uz_at(p),)))
        for p in POINTS:
            ip = [r for e in cell_elems(*p) for r in stress[eid(*e)]]
            sxx, syy, szz, sxy, sxz, syz = [sum(r[k] for r in ip) / len(ip) for k in range(6)]
            vm = (0.5 * ((sxx - syy) ** 2 + (syy - szz) ** 2 + (szz - sxx) ** 2)
                  + 3 * (sxy ** 2 + sxz ** 2 + syz ** 2)) ** 0.5
            f.write("von_mises %.1f %.1f %.1f %.9g\n" % (p + (vm,)))
    print(open(out).read(), end="")


def ccx_version():
    try:
        r = subprocess.run(["ccx", "-v"], capture_output=True, text=True)
        w = (r.stdout + r.stderr).split()
        for a, b in zip(w, w[1:]):
            if a == "Version":
                return b.rstrip(".")
    except OSError:
        pass
    return "?"


if __name__ == "__main__":
    main()
