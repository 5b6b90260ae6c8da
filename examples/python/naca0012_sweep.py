#!/usr/bin/python3
"""NACA 0012 at Re = 1000: lift coefficient C_L against the angle of attack.

Runs cases/vortex/naca0012_aoa5.yaml at several angles through the partix
Python module and plots the mean C_L (the loads' `cy`, lift for the free
stream along +x) against the angle with Matplotlib.

    /usr/bin/python3 examples/python/naca0012_sweep.py [--full] [--out DIR]

By default a short version (3 angles, 1 s of flow, 160 panels: about 1.5
minutes of CPU time; C_L is still the start-up's, averaged over
t = 0.5..1 s: 0.00, 0.22, 0.46 at 0, 4, 8 degrees); --full
runs the case as it is (5 angles, 6 s, 400 panels; means over t = 4..6 s,
the window summary.json reports; about an hour on 2 cores).
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
CASE = os.path.join(HERE, "..", "..", "cases", "vortex", "naca0012_aoa5.yaml")


def main(argv=None):
    ap = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    ap.add_argument("--full", action="store_true", help="the whole case (about an hour)")
    ap.add_argument("--out", default="out/python_naca0012", help="output folder")
    ap.add_argument("--end", type=float, default=1.0,
                    help="short version: simulated time [s] (the mean is over its second half)")
    a = ap.parse_args(argv)
    if a.full:
        angles, window = [0, 2, 4, 6, 8], (4.0, 6.0)
        extra = {}
    else:
        angles, window = [0, 4, 8], (a.end / 2, a.end)
        extra = {"time.end": a.end, "vortex.bodies[0].panels": 160}
    cl = []
    for angle in angles:
        sim = partix.Simulation(CASE, out=os.path.join(a.out, f"aoa{angle}"),
                                set={"vortex.bodies[0].angle": angle, "output.png": False,
                                     "output.vtk": False, "output.log_every": 5, **extra})
        sim.run()
        loads = sim.loads()
        t, cy = loads["t"], loads["cy"]
        inside = (t >= window[0]) & (t <= window[1])
        cl.append(float(np.mean(cy[inside])))
        print(f"angle {angle:4.1f} deg: C_L = {cl[-1]:.4f} (mean over t = {window[0]}..{window[1]} s,"
              f" {inside.sum()} rows)")
        sim.close()
    fig, ax = plt.subplots(figsize=(6, 4.2))
    ax.plot(angles, cl, "o-", label=f"partix, mean over t = {window[0]:g}..{window[1]:g} s")
    ax.plot(angles, 2 * np.pi * np.radians(angles), "--", color="0.5",
            label=r"thin-airfoil theory $2\pi\alpha$ (inviscid)")
    ax.set_xlabel(r"angle of attack $\alpha$ [deg]")
    ax.set_ylabel(r"lift coefficient $C_L$ [-]")
    ax.set_title("NACA 0012, Re = 1000" + ("" if a.full else " (short run)"))
    ax.grid(True, alpha=0.3)
    ax.legend()
    fig.tight_layout()
    path = os.path.join(a.out, "cl_alpha.png")
    fig.savefig(path, dpi=110)
    print("plot:", path)
    return angles, cl


if __name__ == "__main__":
    main(sys.argv[1:])
