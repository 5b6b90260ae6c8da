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
    # a str is passed as text (a YAML double-quoted string): not a number
    assert err.file == '--set vortex.nu="abc"' and err.key == "vortex.nu"
    assert err.line == 0 and "number" in err.message


def test_strings_are_text_as_given(tmp_path):
    # '#' would start a YAML comment and ': ' a map in a plain scalar
    out = tmp_path / "run #2"
    sim = partix.Simulation(case_path("lattice/notched.yaml"),
                            set={"time.steps": 2, "title": "a: b #1"}, out=out)
    sim.run()
    assert sim.out == str(out) and (out / "summary.json").exists()
    assert sim.summary()["title"] == "a: b #1"
    sim.close()
    # the folder holds a run now: a new one there is refused at output.dir
    with pytest.raises(partix.CaseError) as e:
        partix.Simulation(case_path("lattice/notched.yaml"), set={"time.steps": 2}, out=out)
    assert e.value.key == "output.dir" and "holds a run already" in e.value.message


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


def test_resume_refused_key_is_the_key(tmp_path):
    # "--set K=V: K cannot change when a run is resumed: ...": the key is K,
    # the message the whole sentence (not split at its first colon)
    sim = partix.Simulation(case_path("vortex/demo_cylinder.yaml"),
                            set={"time.steps": 2, "output.png": False}, out=tmp_path / "v")
    sim.run()
    with pytest.raises(partix.CaseError) as e:
        partix.resume(tmp_path / "v", set={"vortex.nu": 0.5})
    err = e.value
    assert err.key == "vortex.nu" and err.file == "--set vortex.nu=0.5"
    assert err.message.startswith("vortex.nu cannot change when a run is resumed: ")
    assert str(err).startswith("--set vortex.nu=0.5: vortex.nu cannot change")


@pytest.mark.parametrize("overrides", [[("time.steps", 5)], "time.steps=5", ("time.steps", 5)])
def test_set_that_is_no_dict_is_a_type_error(overrides):
    with pytest.raises(TypeError, match="set: a dict of case keys to values"):
        partix.Simulation(case_path("vortex/demo_cylinder.yaml"), set=overrides)
    with pytest.raises(TypeError, match="set: a dict"):
        partix.check(case_path("vortex/demo_cylinder.yaml"), set=overrides)


def test_log_level_is_checked():
    with pytest.raises(ValueError, match="log: one of 'error', 'warning', 'info', 'debug', not 'loud'"):
        partix.Simulation(case_path("vortex/demo_cylinder.yaml"), log="loud")
    with pytest.raises(TypeError, match="log: one of"):
        partix.Simulation(case_path("vortex/demo_cylinder.yaml"), log=3)
    # the extension refuses it too, for callers of partix._core
    with pytest.raises(ValueError, match="not 'loud'"):
        partix._core.Sim(case_path("vortex/demo_cylinder.yaml"), [], 1, "loud", False)


def test_step_count_is_checked(tmp_path):
    sim = partix.Simulation(case_path("vortex/demo_cylinder.yaml"),
                            set={"time.steps": 3, "output.png": False}, out=tmp_path / "v")
    with pytest.raises(ValueError, match="0 or more"):
        sim.step(-1)
    with pytest.raises(TypeError, match="whole number"):
        sim.step(2.5)
    with pytest.raises(TypeError, match="whole number"):
        sim.step("2")
    assert sim.step_index == 0  # none of them ran a step
    assert sim.step(0) == 0 and sim.step(2) == 2 and sim.step_index == 2
    sim.close()


def test_summary_before_any_is_a_partix_error(tmp_path):
    sim = partix.Simulation(case_path("vortex/demo_cylinder.yaml"),
                            set={"time.steps": 3, "output.png": False}, out=tmp_path / "v")
    with pytest.raises(partix.Error) as e:
        sim.summary()
    assert e.value.status == "NOT_FOUND" and "no summary.json yet" in str(e.value)
    sim.checkpoint()
    assert sim.summary()["step"] == 0
    sim.close()


def test_uninitialised_simulation_is_a_runtime_error():
    sim = partix.Simulation.__new__(partix.Simulation)
    with pytest.raises(RuntimeError, match="has no run"):
        sim.step()
    with pytest.raises(RuntimeError, match="has no run"):
        sim.time
    sim.close()  # nothing to free
