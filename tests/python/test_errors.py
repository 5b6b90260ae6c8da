"""Errors through the partix module: they raise (CaseError with where and
which key, Error with the status), never abort the interpreter."""
import pytest

import partix
from conftest import case_path


def test_check_ok():
    info = partix.check(case_path("lattice/cantilever.yaml"))
    assert info["solver"] == "lattice" and info["steps"] == 50000 and info["dt"] > 0


def test_case_error_in_file(tmp_path):
    bad = tmp_path / "bad.yaml"
    bad.write_text("solver: vortex\ntime: {steps: 10}\nvortex:\n  nu: 0.001\n  v_inf: [1, 0]\n"
                   "  bodies: []\n  re: 5\n")
    with pytest.raises(partix.CaseError) as e:
        partix.check(bad)
    err = e.value
    assert isinstance(err, ValueError) and isinstance(err, partix.Error)
    assert err.status == "CONFIG"
    bad_key = [x for x in err.errors if x[3] == "vortex.re"]
    assert bad_key, err.errors
    f, line, col, key, msg = bad_key[0]
    assert f == str(bad) and (line, col) == (7, 3) and "unknown key" in msg
    assert f"{bad}:7:3: vortex.re: unknown key" in str(err)


def test_case_error_in_override():
    with pytest.raises(partix.CaseError) as e:
        partix.Simulation(case_path("vortex/demo_cylinder.yaml"), set={"vortex.nu": "abc"})
    err = e.value
    assert err.file == "--set vortex.nu=abc" and err.key == "vortex.nu"
    assert err.line == 0 and err.message


def test_value_out_of_range(tmp_path):
    with pytest.raises(partix.CaseError) as e:
        partix.Simulation(case_path("lattice/cantilever.yaml"), set={"lattice.E": -1},
                          out=tmp_path / "x")
    assert e.value.key == "lattice.E"


def test_missing_file():
    with pytest.raises(partix.Error) as e:
        partix.Simulation("no/such/case.yaml")
    assert not isinstance(e.value, partix.CaseError)
    assert e.value.status == "IO" and "no/such/case.yaml" in str(e.value)


def test_unknown_series_and_closed(tmp_path):
    sim = partix.Simulation(case_path("vortex/demo_cylinder.yaml"),
                            set={"time.steps": 3, "output.png": False}, out=tmp_path / "v")
    with pytest.raises(partix.Error) as e:
        sim.series("nothing")
    assert e.value.status == "NOT_FOUND"
    assert sim.step(10) == 3  # fewer at the run's end
    assert sim.step(1) == 0
    sim.close()
    with pytest.raises(RuntimeError, match="closed"):
        sim.step(1)


def test_resume_refuses_changed_key(tmp_path):
    sim = partix.Simulation(case_path("vortex/demo_cylinder.yaml"),
                            set={"time.steps": 4, "output.png": False}, out=tmp_path / "v")
    sim.run()
    with pytest.raises(partix.Error) as e:
        partix.resume(tmp_path / "v", set={"vortex.nu": 0.5, "time.steps": 8})
    assert e.value.status == "CONFIG" and "vortex.nu" in str(e.value)


def test_unstable_time_step_refused(tmp_path):
    # a time step far past the stable one is refused when the run is built
    with pytest.raises(partix.CaseError) as e:
        partix.Simulation(case_path("lattice/cantilever.yaml"), set={"time.dt": 1e-3},
                          out=tmp_path / "blow")
    assert e.value.key == "time.dt" and "stability limit" in e.value.message
