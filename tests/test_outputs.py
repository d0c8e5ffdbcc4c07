"""Saved runs describe themselves (issue 14, M): CSV headers with units; NetCDF variables with
units and long names; global attributes with the scene, every rig parameter, the cam motion,
the solver settings, the rig's provenance and camdyn's version -- enough to run it again."""
from __future__ import annotations

import csv

import numpy as np
import pytest

import camdyn
from camdyn.io import files, metadata
from camdyn.cli import main
from camdyn.model.rig import PARAMETERS

xr = pytest.importorskip("xarray")
QUICK = ["--speed-rpm", "1100", "--revolutions", "1", "--sample-rate-Hz", "4000"]


@pytest.fixture(scope="module")
def saved(tmp_path_factory):
    path = tmp_path_factory.mktemp("saved") / "run.nc"
    assert main(["simulate", *QUICK, "--damping", "B", "--netcdf", str(path)]) == 0
    with xr.open_dataset(path, engine="scipy") as ds:
        return ds.load()


def test_every_variable_has_units_and_a_long_name(saved):
    for name in list(saved.data_vars) + ["t"]:
        attrs = saved[name].attrs
        assert attrs.get("long_name"), name
        if name != "regime":
            assert "units" in attrs, name
    assert saved["alpha_r"].attrs["units"] == "rad" and saved["F_n"].attrs["units"] == "N"
    assert saved["t"].attrs["units"] == "s"


def test_global_attributes_hold_scene_rig_cam_solver_and_version(saved):
    a = saved.attrs
    assert a["scene"] == "line_b_coulomb_constant_nonlinear" and a["scene_damping"] == "B"
    rig = camdyn.example_rig()
    for p in PARAMETERS:
        value = getattr(rig, p.name)
        assert (f"rig_{p.name}" in a) == (value is not None), p.name
        if value is not None:
            assert a[f"rig_{p.name}"] == value, p.name
    assert a["rig_name"] == "example" and a["rig_source"].startswith("camdyn preset 'example'")
    assert a["cam_motion"] == "constant" and a["cam_speed_rpm"] == 1100.0
    assert a["solver_method"] == "DOP853" and a["solver_rtol"] == 1e-8 and a["solver_revolutions"] == 1.0
    assert a["solver_sample_rate_Hz"] == 4000.0 and a["solver_backend"]
    assert a["camdyn_version"] == camdyn.__version__
    assert "damping B" in a["title"] and "1100 rev/min" in a["title"]
    assert a["command"].startswith("camdyn simulate")


def test_a_saved_run_runs_again_to_the_same_result(saved):
    again = metadata.from_attributes(saved.attrs).simulate()
    # same inputs, same code, same machine: the same numbers, bit for bit
    assert np.array_equal(again.t, saved["t"].values)
    assert np.array_equal(again.alpha, saved["alpha"].values)
    assert np.array_equal(again.F_n, saved["F_n"].values)
    assert np.array_equal(again.impacts(), saved["impact_t"].values)


def test_a_saved_run_runs_again_with_other_options_given_whole(saved):
    """options= replaces the saved method and tolerances (not refused as given twice); the saved
    span stays."""
    from camdyn.engine import SolverOptions
    from camdyn.runs.request import Span

    saved_run = metadata.from_attributes(saved.attrs)
    options = SolverOptions(method="RK45", rtol=1e-9)
    again = saved_run.simulate(options=options)
    direct = camdyn.simulate(saved_run.rig, saved_run.scene, saved_run.cam, options=options,
                             span=Span(revolutions=1.0, sample_rate_Hz=4000.0))
    assert np.array_equal(again.t, saved["t"].values) and np.array_equal(again.alpha, direct.alpha)
    assert not np.array_equal(again.alpha, saved["alpha"].values)   # another method: other numbers


def test_settings_given_as_objects_are_recorded_as_the_keywords_that_build_them(saved):
    from camdyn.engine import EventSettings, SolverOptions
    from camdyn.runs.request import Span

    options = SolverOptions(rtol=1e-9, events=EventSettings(max_events=10), step_control="scipy", ledger=True)
    settings = {"backend": "python", "span": Span(t_end=0.5, sample_rate_Hz=100.0, t_start=2.0), "options": options}
    result = metadata.from_attributes(saved.attrs).simulate(span=Span(t_end=0.01, sample_rate_Hz=1000.0))
    a = metadata.run_attributes(result, camdyn.example_rig(), settings=settings)
    solver = {k[len("solver_"):]: v for k, v in a.items() if k.startswith("solver_")}
    assert solver == {"backend": "python", "sample_rate_Hz": 100.0, "method": "DOP853", "rtol": 1e-9, "atol": 1e-12,
                      "events": repr(EventSettings(max_events=10)), "energy_ledger": 1, "step_control": "scipy",
                      "t_end": 0.5, "t_start": 2.0}
    assert list(solver)[:5] == ["backend", "sample_rate_Hz", "method", "rtol", "atol"]


def test_a_rig_file_is_recorded_by_its_path(tmp_path):
    rig_file = tmp_path / "my_rig.toml"
    camdyn.example_rig().replace(name="mine", k_s=2500.0).to_toml(rig_file)
    path = tmp_path / "run.nc"
    assert main(["simulate", *QUICK, "--rig", str(rig_file), "--netcdf", str(path)]) == 0
    with xr.open_dataset(path, engine="scipy") as ds:
        assert ds.attrs["rig_source"] == f"file {rig_file.resolve()}"
        assert ds.attrs["rig_name"] == "mine" and ds.attrs["rig_k_s"] == 2500.0
        assert metadata.from_attributes(ds.attrs).rig == camdyn.example_rig().replace(name="mine", k_s=2500.0)


def test_run_attributes_need_the_rig():
    result = camdyn.simulate(camdyn.example_rig(), speed_rpm=300, revolutions=0.05, sample_rate_Hz=2000)
    with pytest.raises(camdyn.ParameterError, match="rig"):
        metadata.run_attributes(result)
    attrs = metadata.run_attributes(result, camdyn.example_rig(), settings={"revolutions": 0.05})
    assert all(isinstance(v, (str, int, float)) for v in attrs.values())  # NetCDF-3 attribute types


def test_csv_headers_carry_units_and_read_back(tmp_path):
    result = camdyn.simulate(camdyn.example_rig(), speed_rpm=300, revolutions=0.05, sample_rate_Hz=2000)
    path = tmp_path / "run.csv"
    files.write_csv(result, path)
    header = next(csv.reader(path.open()))
    assert header[:4] == ["t (s)", "alpha (rad)", "alpha_dot (rad/s)", "Theta (rad)"]
    assert header[-1] == "regime"
    t, x, period = files.read_series(path, "F_n")
    assert np.array_equal(t, result.t) and np.array_equal(x, result.F_n)
    assert period == pytest.approx(0.2, rel=1e-9)  # from Theta(t): 300 rev/min


def test_scene_words_and_options_round_trip():
    for slug in camdyn.Scene.available():
        options = metadata.scene_options(slug)
        assert camdyn.Scene(**options).slug == slug
        assert "_" not in metadata.describe_scene(slug).replace("v_r", "")
    assert metadata.describe_scene("line_d_coulomb_constant_nonlinear") == "line contact, damping D, Coulomb friction"


def test_file_kinds_by_name():
    assert files.check_suffix("run", "netcdf") == "run.nc"
    assert files.check_suffix("run.CSV", "csv") == "run.CSV"
    with pytest.raises(files.FileFormatError, match=r"\.csv is a CSV file"):
        files.check_suffix("run.csv", "netcdf")
