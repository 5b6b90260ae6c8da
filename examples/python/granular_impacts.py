#!/usr/bin/python3
"""Granular impact energy along the part.

cases/granular/small_box.yaml (600 steel discs in a box vibrating at 25 Hz
with a round part inside) through the partix Python module; the impact
statistics of the part per wall segment (sim.segments(): energy_n, the
normal impact energy per segment, and the impact count) against the
position along the part's contour, and the discs at the end (sim.state()).

    /usr/bin/python3 examples/python/granular_impacts.py [--full] [--out DIR]

Short by default (0.16 s: 0.1 s of settling, then 0.06 s of vibration);
--full runs the case's 0.3 s.
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
CASE = os.path.join(HERE, "..", "..", "cases", "granular", "small_box.yaml")


def main(argv=None):
    ap = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    ap.add_argument("--full", action="store_true", help="the case's 0.3 s")
    ap.add_argument("--out", default="out/python_granular", help="output folder")
    a = ap.parse_args(argv)
    extra = {} if a.full else {"time.end": 0.16}
    sim = partix.Simulation(CASE, out=a.out,
                            set={"output.png": False, "output.vtk": False, **extra})
    sim.run()
    seg, disc = sim.segments(), sim.state()
    media = sim.series("media")
    part = seg["contour"] == seg["contour"].max()  # the reported contour: the part
    s, en = seg["s"][part], seg["energy_n"][part]
    print(f"t = {sim.time:.3f} s: {int(seg['impacts'][part].sum())} impacts on the part, "
          f"normal energy {en.sum():.3e} J")
    fig, axs = plt.subplots(1, 3, figsize=(14, 4))
    ax = axs[0]
    ax.plot(1e3 * s, 1e6 * en, "-", drawstyle="steps-mid")
    ax.set_xlabel("position along the part's contour s [mm]")
    ax.set_ylabel(f"normal impact energy [uJ per segment]")
    ax.set_title("impact energy along the part")
    ax.grid(True, alpha=0.3)
    ax = axs[1]
    ax.scatter(1e3 * disc["x"], 1e3 * disc["y"], s=4, c=np.hypot(disc["vx"], disc["vy"]))
    ax.scatter(1e3 * seg["x"][part], 1e3 * seg["y"][part], s=8, c=en, cmap="inferno")
    ax.set_aspect("equal")
    ax.set_xlabel("x [mm]")
    ax.set_ylabel("y [mm]")
    ax.set_title(f"discs (speed) and the part (energy), t = {sim.time:.3f} s")
    ax = axs[2]
    ax.plot(media["t"], media["kinetic"])
    ax.set_xlabel("t [s]")
    ax.set_ylabel("kinetic energy of the discs [J]")
    ax.grid(True, alpha=0.3)
    fig.tight_layout()
    path = os.path.join(a.out, "impact_energy.png")
    fig.savefig(path, dpi=100)
    print("plot:", path)
    sim.close()
    return s, en


if __name__ == "__main__":
    main(sys.argv[1:])
