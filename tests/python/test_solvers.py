"""Each solver through the partix module: the arrays it gives equal the
run's own files (the CSV series to the digits printed, the VTK snapshots
read with VTK's readers), a loop of step() leaves the files run() leaves,
results stay valid after later steps, resume continues a run."""
import csv
import filecmp
import os
import signal
import threading

import numpy as np
import pytest
from vtkmodules.util.numpy_support import vtk_to_numpy
from vtkmodules.vtkIOXML import vtkXMLImageDataReader, vtkXMLPolyDataReader

import partix
from conftest import case_path

SHORT = {"time.steps": 20, "output.every": 10, "output.log_every": 5, "output.png": False}


def read_csv(path):
    with open(path, newline="") as f:
        rows = list(csv.reader(f))
    head = rows[0]
    return head, np.array([[float(v) for v in r] for r in rows[1:]])


def check_series(series, path):
    """Columns named "name [units]" as the file's header; values as printed."""
    head, rows = read_csv(path)
    assert [f"{k} [{series.units[k]}]" for k in series] == head
    for c, k in enumerate(series):
        a = series[k]
        assert a.dtype == np.float64 and a.shape == (rows.shape[0],)
        np.testing.assert_allclose(a, rows[:, c], rtol=6e-10, atol=0, equal_nan=True,
                                   err_msg=f"{path}: {k}")


def read_vtk(cls, path):
    r = cls()
    r.SetFileName(path)
    r.Update()
    return r.GetOutput()


def test_vortex_state_and_loads(tmp_path):
    out = tmp_path / "vortex"
    sim = partix.Simulation(case_path("vortex/demo_cylinder.yaml"), set=SHORT, out=out)
    assert sim.solver == "vortex" and sim.step_index == 0
    assert sim.step(7) == 7 and sim.step_index == 7
    early = sim.state()
    x7 = early["x"].copy()
    while sim.step(5):
        pass
    assert sim.step_index == 20 and sim.time == pytest.approx(20 * sim.dt)
    # an array taken earlier still shows its step after later steps
    assert early.step == 7 and np.array_equal(early["x"], x7)
    check_series(sim.loads(), out / "loads.csv")
    assert sim.series_names() == ["loads"]
    wake = sim.state()
    assert wake.step == 20 and wake.units["gamma"] == "m^2/s"
    assert not wake["x"].flags.writeable
    with pytest.raises(ValueError):
        wake["x"][0] = 1.0
    poly = read_vtk(vtkXMLPolyDataReader, str(out / "wake_000020.vtp"))
    pts = vtk_to_numpy(poly.GetPoints().GetData())
    pd = poly.GetPointData()
    np.testing.assert_array_equal(wake["x"], pts[:, 0])
    np.testing.assert_array_equal(wake["y"], pts[:, 1])
    np.testing.assert_array_equal(wake["gamma"], vtk_to_numpy(pd.GetArray("Gamma")))
    np.testing.assert_array_equal(wake["core_radius"], vtk_to_numpy(pd.GetArray("core_radius")))
    np.testing.assert_array_equal(wake["u"], vtk_to_numpy(pd.GetArray("velocity"))[:, 0])
    # the loads' vortex count is the state's
    assert sim.loads()["vortices"][-1] == len(wake["x"])
    assert sim.summary()["status"] == "finished"
    sim.close()
    assert len(wake["x"]) > 0 and np.isfinite(wake["x"]).all()  # outlives the run


def test_granular_state_segments_series(tmp_path):
    out = tmp_path / "granular"
    sim = partix.Simulation(case_path("granular/small_box.yaml"), set=SHORT, out=out)
    sim.run()
    discs, seg = sim.state(), sim.segments()
    check_series(sim.series("media"), out / "media.csv")
    check_series(sim.series("speed_histogram"), out / "speed_histogram.csv")
    head, rows = read_csv(out / "segments_part.csv")
    assert list(seg)[0] == "contour" and len(seg) == len(head) + 1
    for c, k in enumerate(list(seg)[1:]):
        assert f"{k} [{seg.units[k]}]" == head[c]
        np.testing.assert_allclose(seg[k], rows[:, c], rtol=6e-10, atol=0)
    poly = read_vtk(vtkXMLPolyDataReader, str(out / "particles_00000020.vtp"))
    pts = vtk_to_numpy(poly.GetPoints().GetData())
    pd = poly.GetPointData()
    np.testing.assert_array_equal(discs["x"], pts[:, 0])
    np.testing.assert_array_equal(discs["y"], pts[:, 1])
    np.testing.assert_array_equal(discs["radius"], vtk_to_numpy(pd.GetArray("radius")))
    np.testing.assert_array_equal(discs["vy"], vtk_to_numpy(pd.GetArray("velocity"))[:, 1])
    # kinetic energy of the media, as media.csv's last row has it
    media = sim.series("media")
    e = 0.5 * np.sum(discs["mass"] * (discs["vx"] ** 2 + discs["vy"] ** 2))
    assert e == pytest.approx(media["kinetic"][-1], rel=1e-12)


def test_lattice_state_and_probes(tmp_path):
    out = tmp_path / "lattice"
    sim = partix.Simulation(case_path("lattice/cantilever.yaml"), set=SHORT, out=out)
    sim.run()
    el, probes = sim.state(), sim.probes()
    check_series(probes, out / "probes.csv")
    assert el["displacement"].shape == (len(el["cell"]), 3)
    assert el["stress"].shape == (len(el["cell"]), 6)
    assert el["broken_links"].dtype == np.uint8
    img = read_vtk(vtkXMLImageDataReader, str(out / "lattice_000020.vti"))
    cd = img.GetCellData()
    cells = el["cell"]  # a box: every cell is an element, in cell order
    assert np.array_equal(cells, np.arange(img.GetNumberOfCells()))
    # the snapshot holds f32
    np.testing.assert_array_equal(el["displacement"].astype(np.float32),
                                  vtk_to_numpy(cd.GetArray("displacement")))
    np.testing.assert_array_equal(el["von_mises"].astype(np.float32),
                                  vtk_to_numpy(cd.GetArray("von_mises")))
    np.testing.assert_array_equal(el["broken_links"], vtk_to_numpy(cd.GetArray("broken_links")))
    u = np.linalg.norm(el["displacement"], axis=1)
    assert u.max() == pytest.approx(probes["max_displacement"][-1], rel=1e-12)
    with pytest.raises(partix.Error) as e:
        sim.segments()
    assert e.value.status == "UNSUPPORTED"


def test_lattice_rotation_is_the_half_curl(tmp_path):
    """The elements' rotation vectors against the continuum rotation of the
    displacement field, half its curl (central differences on the grid),
    in the bent cantilever (41 x 4 x 4, on its way to statics): the same
    field to 1 %, and no rotation about the beam's axis or the load."""
    sim = partix.Simulation(case_path("lattice/cantilever.yaml"),
                            set={"time.steps": 3000, "output.every": 3000, "output.png": False},
                            out=tmp_path / "bent")
    sim.run()
    el = sim.state()
    assert el["rotation"].shape == (len(el["cell"]), 3)
    n = (41, 4, 4)
    u = el["displacement"].reshape(n[2], n[1], n[0], 3)  # a box: cell order
    rot = el["rotation"].reshape(n[2], n[1], n[0], 3)
    h = 1e-3
    half_curl_y = 0.5 * (np.gradient(u[..., 0], h, axis=0) - np.gradient(u[..., 2], h, axis=2))
    inner = (slice(None), slice(None), slice(3, n[0] - 3))  # off the clamp and the load
    a, b = rot[..., 1][inner], half_curl_y[inner]
    assert np.abs(b).max() > 1e-4  # bent
    assert np.linalg.norm(a - b) / np.linalg.norm(b) < 0.01
    assert np.abs(rot[..., 0]).max() < 1e-9 * np.abs(b).max()
    assert np.abs(rot[..., 2]).max() < 1e-9 * np.abs(b).max()


def test_step_loop_writes_what_run_writes(tmp_path):
    a, b = tmp_path / "run", tmp_path / "steps"
    partix.Simulation(case_path("vortex/demo_cylinder.yaml"), set=SHORT, out=a).run()
    sim = partix.Simulation(case_path("vortex/demo_cylinder.yaml"), set=SHORT, out=b)
    while sim.step(3):
        pass
    # (checkpoint.pxc holds the case, whose output.dir differs)
    for name in ["loads.csv", "wake_000000.vtp", "wake_000010.vtp", "wake_000020.vtp",
                 "wake.pvd"]:
        assert filecmp.cmp(a / name, b / name, shallow=False), name


def test_checkpoint_and_resume(tmp_path):
    out = tmp_path / "vortex"
    sim = partix.Simulation(case_path("vortex/demo_cylinder.yaml"), set=SHORT, out=out)
    sim.step(10)
    path = sim.checkpoint()
    assert os.path.samefile(path, out / "checkpoint.pxc")
    x10 = sim.state()["x"]
    sim.close()
    r = partix.resume(out)
    assert r.step_index == 10 and r.steps == 20
    np.testing.assert_array_equal(r.state()["x"], x10)
    assert r.step(100) == 10 and r.step_index == 20
    assert r.loads()["t"][0] > 10 * r.dt  # this process's rows only


def test_ctrl_c_in_step(tmp_path):
    sim = partix.Simulation(case_path("vortex/demo_cylinder.yaml"),
                            set={"time.steps": 100000, "output.png": False, "output.vtk": False},
                            out=tmp_path / "long")
    sim.step(1)
    timer = threading.Timer(0.5, os.kill, (os.getpid(), signal.SIGINT))
    timer.start()
    with pytest.raises(KeyboardInterrupt):
        sim.step(100000)
    timer.join()
    n = sim.step_index
    assert 1 < n < 100000
    # a whole step's state: it goes on
    assert len(sim.state()["x"]) > 0 and sim.step(1) == 1 and sim.step_index == n + 1


@pytest.mark.parametrize("case,vtk,names", [
    ("vortex/demo_cylinder.yaml", "wake_000010.vtp", {"gamma": "Gamma"}),
    ("granular/small_box.yaml", "particles_00000010.vtp", {"radius": "radius"}),
])
def test_opencl_state_is_the_snapshot(tmp_path, case, vtk, names):
    """The OpenCL engines keep their state on the device: the arrays are
    brought to the host as the snapshots are."""
    out = tmp_path / "ocl"
    try:
        sim = partix.Simulation(case_path(case), out=out,
                                set={**SHORT, "time.steps": 10, "backend.type": "opencl"})
    except partix.Error as e:
        pytest.skip(f"no OpenCL backend here: {e}")
    sim.run()
    st = sim.state()
    poly = read_vtk(vtkXMLPolyDataReader, str(out / vtk))
    pts = vtk_to_numpy(poly.GetPoints().GetData())
    np.testing.assert_array_equal(st["x"], pts[:, 0])
    np.testing.assert_array_equal(st["y"], pts[:, 1])
    for ours, theirs in names.items():
        np.testing.assert_array_equal(st[ours], vtk_to_numpy(poly.GetPointData().GetArray(theirs)))


def test_ctrl_c_in_run_writes_a_checkpoint(tmp_path):
    out = tmp_path / "long"
    sim = partix.Simulation(case_path("vortex/demo_cylinder.yaml"),
                            set={"time.steps": 100000, "output.png": False, "output.vtk": False},
                            out=out)
    timer = threading.Timer(1.0, os.kill, (os.getpid(), signal.SIGINT))
    timer.start()
    with pytest.raises(KeyboardInterrupt, match="checkpoint written"):
        sim.run()
    timer.join()
    n = sim.step_index
    assert 0 < n < 100000 and sim.summary()["status"] == "interrupted"
    sim.close()
    r = partix.resume(out, set={"time.steps": n + 2})
    assert r.step_index == n and r.step(5) == 2
