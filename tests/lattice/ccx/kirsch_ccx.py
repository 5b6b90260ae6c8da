#!/usr/bin/python3
"""CalculiX on the lattice's own Kirsch body (tests/lattice/test_lattice_kirsch.c).

The lattice test's strip (width W = 8a, length 2W, hole of radius a = NA
elements at its centre, roller on x = 0, uniform tension on x = L) is
voxelized: the hole is the cells whose centres lie inside the circle, a
staircase. This script meshes exactly those cells, each with S x S
plane-strain CPE8R elements, solves it with `ccx` and prints sigma_xx / sigma
at the centres of the first three cells above and below the hole on the two
middle columns (the cell means of the integration points, as the lattice
test reads its elements): the continuum answer for the staircase, against
which the lattice's own error is measured, apart from the error of the
staircase itself. Stresses in a traction-loaded 2-D body do not depend on
the elastic constants (Michell), so nu is immaterial.

Usage: kirsch_ccx.py NA [--sub S] [--keep DIR]   (needs ccx on PATH)
"""
import os
import subprocess
import sys
import tempfile


def main():
    na = int(sys.argv[1])
    sub = int(sys.argv[sys.argv.index("--sub") + 1]) if "--sub" in sys.argv else 2
    keep = sys.argv[sys.argv.index("--keep") + 1] if "--keep" in sys.argv else None
    nw, nl = 8 * na, 16 * na
    cx, cy = 0.5 * nl, 0.5 * nw   # hole centre, in cells (h = 1)
    occ = {(i, j) for i in range(nl) for j in range(nw)
           if (i + 0.5 - cx) ** 2 + (j + 0.5 - cy) ** 2 >= na * na}
    q = 2 * sub                    # node grid points per cell edge
    gx = q * nl + 1
    d = 1.0 / sub

    def nid(i, j):
        return 1 + i + gx * j

    nodes, elems, cell_of = set(), [], {}
    for (i, j) in sorted(occ):
        for a in range(sub):
            for b in range(sub):
                I, J = q * i + 2 * a, q * j + 2 * b
                ring = [(I, J), (I + 2, J), (I + 2, J + 2), (I, J + 2),
                        (I + 1, J), (I + 2, J + 1), (I + 1, J + 2), (I, J + 1)]
                nodes.update(ring)
                elems.append([nid(*p) for p in ring])
                cell_of[len(elems)] = (i, j)
    work = keep or tempfile.mkdtemp(prefix="kirsch_ccx_")
    os.makedirs(work, exist_ok=True)
    top = [(nl // 2 - 1 + c, nw // 2 + na + r) for r in range(3) for c in range(2)]
    bot = [(nl // 2 - 1 + c, nw // 2 - na - 1 - r) for r in range(3) for c in range(2)]
    probe = [e for e, c in cell_of.items() if c in top or c in bot]
    with open(os.path.join(work, "kirsch.inp"), "w") as f:
        f.write("*NODE, NSET=NALL\n")
        for (i, j) in sorted(nodes, key=lambda p: nid(*p)):
            f.write("%d, %.6f, %.6f\n" % (nid(i, j), i * d / 2, j * d / 2))
        f.write("*ELEMENT, TYPE=CPE8R, ELSET=EALL\n")
        for k, e in enumerate(elems, 1):
            f.write("%d, %s\n" % (k, ", ".join(map(str, e))))
        f.write("*ELSET, ELSET=EPROBE\n%s\n" % ",\n".join(map(str, probe)))
        f.write("*NSET, NSET=NROLL\n")
        roll = [nid(0, j) for j in range(q * nw + 1) if (0, j) in nodes]
        for a in range(0, len(roll), 10):
            f.write(", ".join(map(str, roll[a:a + 10])) + ",\n")
        f.write("*NSET, NSET=NPIN\n%d\n" % nid(0, q * nw // 2))
        f.write("*MATERIAL, NAME=M\n*ELASTIC\n1.0, 0.3\n")
        f.write("*SOLID SECTION, ELSET=EALL, MATERIAL=M\n1.0\n")
        f.write("*STEP\n*STATIC\n*BOUNDARY\nNROLL, 1, 1, 0.\nNPIN, 2, 2, 0.\n")
        # unit tension on the face x = L: element face 2 (nodes 2-3) of the
        # last column's elements
        f.write("*DLOAD\n")
        for k, e in enumerate(elems, 1):
            i, j = cell_of[k]
            if i == nl - 1 and (k - 1) % (sub * sub) // sub == sub - 1:
                f.write("%d, P2, -1.0\n" % k)
        f.write("*EL PRINT, ELSET=EPROBE\nS\n*END STEP\n")
    subprocess.run(["ccx", "-i", "kirsch"], cwd=work, check=True, stdout=subprocess.DEVNULL)
    stress, mode = {}, None
    with open(os.path.join(work, "kirsch.dat")) as f:
        for line in f:
            if "stresses" in line:
                mode = "s"
                continue
            try:
                v = [float(x) for x in line.split()]
            except ValueError:
                continue
            if mode == "s" and len(v) == 8:
                stress.setdefault(cell_of[int(v[0])], []).append(v[2])
    for r in range(3):
        cells = [top[2 * r], top[2 * r + 1], bot[2 * r], bot[2 * r + 1]]
        m = sum(sum(stress[c]) / len(stress[c]) for c in cells) / 4
        print("a/h = %d, row %d from the edge: sigma_xx/sigma %.5f" % (na, r, m))


if __name__ == "__main__":
    main()
