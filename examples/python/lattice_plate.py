#!/usr/bin/python3
"""Lattice plate: corner deflection against the load.

cases/lattice/plate.yaml (a steel plate 100 x 50 x 5 mm, half of one end
clamped, a load at the opposite top corner) relaxed to statics at several
loads through the partix Python module; the corner's deflection (probe
`corner.uz`) against the load, and the deflected plate of the largest load
from sim.state() (element centres + displacements, von Mises colour).

    /usr/bin/python3 examples/python/lattice_plate.py [--full] [--out DIR]

Short by default (2.5 mm elements, 3 loads, about half a minute); --full
uses the case's 1 mm elements and 4 loads (minutes). The model is linear
until links break, so the points lie on a line through 0.
"""
import argparse
import os
import sys

import matplotlib

matplotlib.use("Agg")
import matplotlib.pyplot as plt  # noqa: E402
import numpy as np  # noqa: E402

import partix  # noqa: E402

HERE = os.path.dirname(os.path.abspath(__file__))
CASE = os.path.join(HERE, "..", "..", "cases", "lattice", "plate.yaml")


def main(argv=None):
    ap = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    ap.add_argument("--full", action="store_true", help="1 mm elements, 4 loads (minutes)")
    ap.add_argument("--out", default="out/python_plate", help="output folder")
    a = ap.parse_args(argv)
    loads = [25.0, 50.0, 100.0, 200.0] if a.full else [25.0, 50.0, 100.0]
    extra = {} if a.full else {"lattice.h": 2.5e-3}
    w, state = [], None
    for f in loads:
        sim = partix.Simulation(CASE, out=os.path.join(a.out, f"load{f:g}"),
                                set={"lattice.boundary[1].force": [0, 0, -f], "output.png": False,
                                     "output.vtk": False, **extra})
        sim.run()
        uz = sim.probes()["corner.uz"]
        w.append(-1e3 * float(uz[-1]))  # deflection downwards [mm]
        print(f"load {f:6.1f} N: corner deflection {w[-1]:.4f} mm after {sim.step_index} steps")
        state = sim.state()
        sim.close()
    fig, (ax, ax2) = plt.subplots(1, 2, figsize=(10, 4), gridspec_kw={"width_ratios": [1, 1.3]})
    ax.plot(loads, w, "o", label="partix (statics)")
    k = np.dot(loads, w) / np.dot(loads, loads)
    ax.plot([0, loads[-1]], [0, k * loads[-1]], "--", color="0.5",
            label=f"line through 0: {1e3 * k:.3f} mm/kN")
    ax.set_xlabel("corner load [N]")
    ax.set_ylabel("corner deflection [mm]")
    ax.set_title("plate 100 x 50 x 5 mm")
    ax.grid(True, alpha=0.3)
    ax.legend()
    x, u, vm = state["position"], state["displacement"], state["von_mises"]
    top = x[:, 2] > x[:, 2].max() - 1e-9  # the top layer of elements
    sc = ax2.scatter(1e3 * x[top, 0], 1e3 * x[top, 1], c=-1e3 * u[top, 2], s=12, cmap="viridis")
    fig.colorbar(sc, ax=ax2, label=f"deflection at {loads[-1]:g} N [mm]")
    ax2.set_xlabel("x [mm]")
    ax2.set_ylabel("y [mm]")
    ax2.set_aspect("equal")
    ax2.set_title(f"top layer; largest von Mises {vm.max() / 1e6:.0f} MPa")
    fig.tight_layout()
    path = os.path.join(a.out, "deflection.png")
    fig.savefig(path, dpi=110)
    print("plot:", path)
    return loads, w


if __name__ == "__main__":
    main(sys.argv[1:])
