"""The Python examples (examples/python) run in their short versions and
their results have the shape the physics says; the notebook's code cells
run in order."""
import importlib.util
import json
import os

import matplotlib
import numpy as np
import pytest

from conftest import SOURCE

matplotlib.use("Agg")
EXAMPLES = os.path.join(SOURCE, "examples", "python")


def load(name):
    spec = importlib.util.spec_from_file_location(name, os.path.join(EXAMPLES, name + ".py"))
    mod = importlib.util.module_from_spec(spec)
    spec.loader.exec_module(mod)
    return mod


def png(path):
    with open(path, "rb") as f:
        assert f.read(8) == b"\x89PNG\r\n\x1a\n"
    assert os.path.getsize(path) > 10000


def test_naca0012_sweep(tmp_path):
    # shorter still than the example's default: the start-up only
    angles, cl = load("naca0012_sweep").main(["--out", str(tmp_path), "--end", "0.3"])
    png(tmp_path / "cl_alpha.png")
    assert angles == [0, 4, 8]
    # a symmetric profile lifts nothing at 0 degrees, more at 8 than at 4
    assert abs(cl[0]) < 0.05 and 0 < cl[1] < cl[2]


def test_lattice_plate(tmp_path):
    loads, w = load("lattice_plate").main(["--out", str(tmp_path)])
    png(tmp_path / "deflection.png")
    # statics of a linear model: deflection proportional to the load
    ratio = np.array(w) / np.array(loads)
    assert ratio.min() > 0 and np.ptp(ratio) < 1e-3 * ratio.mean()


def test_granular_impacts(tmp_path):
    s, en = load("granular_impacts").main(["--out", str(tmp_path)])
    png(tmp_path / "impact_energy.png")
    assert np.all(np.diff(s) > 0) and np.all(en >= 0) and en.sum() > 0


def test_notebook_cells_run_in_order(tmp_path, monkeypatch):
    with open(os.path.join(EXAMPLES, "partix_tour.ipynb"), encoding="utf-8") as f:
        nb = json.load(f)
    # the notebook's folder layout: cases two folders up
    work = tmp_path / "examples" / "python"
    work.mkdir(parents=True)
    os.symlink(os.path.join(SOURCE, "cases"), tmp_path / "cases")
    monkeypatch.chdir(work)
    scope = {}
    ran = 0
    for cell in nb["cells"]:
        if cell["cell_type"] == "code":
            exec(compile("".join(cell["source"]), f"cell {ran}", "exec"), scope)
            ran += 1
    assert ran == 4
    png(work / "out" / "notebook_cylinder" / "wake.png")
    png(work / "out" / "notebook_cylinder" / "loads.png")
    assert scope["sim"].step_index == 160 and len(scope["loads"]["t"]) == 80
