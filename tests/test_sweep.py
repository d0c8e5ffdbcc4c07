"""Sweeps: any Executor, deterministic order and values, labelled result, NetCDF round trip;
every point checked first, a failing point recorded, results streamed to a self-describing file.
(Workers that die, interrupts and resume: test_sweep_faults.py.)"""
from __future__ import annotations

import math
import os
from concurrent.futures import ProcessPoolExecutor, ThreadPoolExecutor
from pathlib import Path

import numpy as np
import pytest

import camdyn
from camdyn.sweep import api as S
from camdyn.errors import CamdynError, ParameterError
from camdyn.io.files import write_netcdf
from camdyn.sweep.store import TITLE, FolderStore
from registry import RIG
from sweep_faults import Faulty, InterruptAfter

xr = pytest.importorskip("xarray")
SCENE = camdyn.Scene(damping="D", friction="coulomb")
GRID = {"k_s": [2000.0, 3000.0], "speed_rpm": [900.0, 1100.0, 1300.0]}
KW = dict(revolutions=2, samples_per_revolution=32, rtol=1e-8, progress=False)


@pytest.fixture(scope="module")
def serial():
    return S.sweep(RIG, SCENE, GRID, S.Summary(1), **KW)


def _point(k_s, speed):
    """One grid point the plain way: what the sweep must have put at (k_s, speed)."""
    r = camdyn.simulate(RIG.replace(k_s=k_s), SCENE, speed_rpm=speed, revolutions=2,
                        sample_rate_Hz=32 / camdyn.ConstantSpeed(speed).period, rtol=1e-8, backend="compiled")
    return S.Summary(1)(r)


def test_labelled_dimensions_in_grid_order(serial):
    assert serial["impacts_per_rev"].dims == ("k_s", "speed_rpm")
    np.testing.assert_array_equal(serial["speed_rpm"], GRID["speed_rpm"])
    np.testing.assert_array_equal(serial["k_s"], GRID["k_s"])
    for i, k in enumerate(GRID["k_s"]):
        for j, v in enumerate(GRID["speed_rpm"]):
            expect = _point(k, v)
            got = serial.isel(k_s=i, speed_rpm=j)
            assert got["impacts_per_rev"].item() == expect["impacts_per_rev"]
            assert got["alpha_r_rms"].item() == expect["alpha_r_rms"]
    assert (serial["outcome"] == 0).all()
    # above the contact-loss speed the follower impacts, well below it does not
    assert serial["impacts_per_rev"].sel(k_s=2000.0, speed_rpm=1300.0) > 0
    assert serial["impacts_per_rev"].sel(k_s=3000.0, speed_rpm=900.0) == 0


def test_process_pool_gives_the_same_dataset(serial):
    with ProcessPoolExecutor(2) as pool:
        ds = S.sweep(RIG, SCENE, GRID, S.Summary(1), executor=pool, chunksize=1, **KW)
    xr.testing.assert_identical(ds, serial)


@pytest.mark.parametrize("threads, chunksize", [(None, 1), (None, 4), (1, 5), (2, 1), (3, 2)])
def test_any_executor_and_chunk_size_gives_the_same_dataset(serial, threads, chunksize):
    """Serial or threads, any chunk size: the same Dataset (process pools and dask: below and in
    test_sweep_faults.py)."""
    if threads is None:
        ds = S.sweep(RIG, SCENE, GRID, S.Summary(1), chunksize=chunksize, **KW)
    else:
        with ThreadPoolExecutor(threads) as pool:
            ds = S.sweep(RIG, SCENE, GRID, S.Summary(1), executor=pool, chunksize=chunksize, **KW)
    xr.testing.assert_identical(ds, serial)


def test_netcdf_round_trip(serial, tmp_path):
    path = tmp_path / "sweep.nc"
    serial.to_netcdf(path)
    with xr.open_dataset(path) as back:
        xr.testing.assert_identical(back.load(), serial)


def test_streamed_sweep_writes_the_same_dataset_self_described(serial, tmp_path):
    out = tmp_path / "map.nc"
    ds = S.sweep(RIG, SCENE, GRID, S.Summary(1), out=out, chunksize=2, **KW)
    xr.testing.assert_identical(ds, serial)
    assert not (tmp_path / "map.nc.parts").exists()  # every point ran: the folder is gone
    with xr.open_dataset(out, engine="scipy") as back:
        back = back.load()
    xr.testing.assert_identical(back, serial)
    a = back.attrs
    assert a["camdyn_version"] == camdyn.__version__ and a["grid"] == "k_s speed_rpm"
    assert a["scene"] == SCENE.slug and a["scene_damping"] == "D" and a["scene_friction"] == "coulomb"
    for name, value in RIG.to_dict().items():  # every parameter of the base rig
        if value is not None and name not in ("name", "description"):
            assert a[f"rig_{name}"] == value, name
    assert a["rig_source"] == (RIG.origin or "not recorded (a Rig built in code)")
    assert a["simulate_rtol"] == 1e-8 and a["simulate_revolutions"] == 2 and a["samples_per_revolution"] == 32
    assert a["measure"] == "Summary(transient_revolutions=1)" and a["measure_transient_revolutions"] == 1
    assert back["speed_rpm"].attrs["units"] == "rev/min" and back["k_s"].attrs["units"] == "N/m"
    assert back["alpha_r_rms"].attrs["units"] == "rad" and "long_name" in back["impacts_per_rev"].attrs
    flags = dict(zip(back["outcome"].attrs["flag_meanings"].split(), back["outcome"].attrs["flag_values"]))
    assert flags["SUCCESS"] == 0 and flags["ERROR"] == S.ALL_CODES["ERROR"]
    # the file alone gives back the rig and the scene it was swept on
    assert S.rig_of(a) == RIG and S.scene_of(a) == SCENE


def test_a_folder_in_progress_is_never_overwritten(tmp_path):
    out = tmp_path / "map.nc"
    (tmp_path / "map.nc.parts").mkdir()
    with pytest.raises(S.StoreError, match="resume"):
        S.sweep(RIG, SCENE, GRID, S.Summary(1), out=out, **KW)
    with pytest.raises(S.StoreError, match="no sweep to resume"):
        S.resume(tmp_path / "other.nc")
    with pytest.raises(S.StoreError, match="does not exist"):
        S.sweep(RIG, SCENE, GRID, S.Summary(1), out=tmp_path / "no" / "map.nc", **KW)


def test_progress_bar_counts_points(capsys):
    with ThreadPoolExecutor(2) as pool:
        S.sweep(RIG, SCENE, {"speed_rpm": [300.0, 400.0, 500.0]}, executor=pool, revolutions=0.2,
                samples_per_revolution=16, progress=True)
    err = capsys.readouterr().err
    assert "3/3" in err


def test_bifurcation_and_contact_loss_map():
    bif = S.bifurcation(RIG, SCENE, [800.0, 1300.0], revolutions=6, transient_revolutions=2, progress=False)
    assert bif["alpha_section"].dims == ("speed_rpm", "revolution")
    assert bif.sizes["revolution"] == 5  # samples at revolutions 2..6
    sliding = bif["alpha_section"].sel(speed_rpm=800.0)
    assert float(sliding.max() - sliding.min()) < 1e-3  # periodic: one point per revolution
    cmap = S.contact_loss_map(RIG, SCENE, [2000.0, 4000.0], [900.0, 1300.0], revolutions=3,
                              transient_revolutions=1, samples_per_revolution=16, progress=False)
    predicted = cmap["loss_speed_predicted"].values
    assert predicted[1] > predicted[0]  # a stiffer spring keeps contact to a higher speed
    lost = cmap["contact_lost"]
    for i, loss in enumerate(predicted):
        for j, v in enumerate(cmap["speed_rpm"].values):
            if abs(v - loss) > 0.15 * loss:  # away from the boundary: simulation agrees with Section 6
                assert lost[i, j] == int(v > loss)


# --- every point checked before any work ---------------------------------------------------------
def test_an_invalid_point_refuses_the_sweep_and_names_the_valid_one_untouched(tmp_path):
    """The issue's two examples: the valid point is not lost, nothing runs, one clear error."""
    bad_e = 1.5 * RIG.r_c
    with pytest.raises(S.InvalidGridError) as info:
        S.sweep(RIG, SCENE, {"speed_rpm": [300.0], "e": [0.001, bad_e]}, revolutions=1, progress=False,
                out=tmp_path / "e.nc")
    assert info.value.invalid == {1: info.value.invalid[1]} and "1 of 2 grid points" in str(info.value)
    assert "e=0.0375" in str(info.value) and "< r_c" in str(info.value)
    assert not list(tmp_path.iterdir())  # refused before any work: no folder, no file
    with pytest.raises(S.InvalidGridError, match=r"speed_rpm=1e\+06: speed_rpm = 1000000.0 is out of range"):
        S.sweep(RIG, SCENE, {"speed_rpm": [300.0, 1e6]}, revolutions=1, progress=False)


def test_every_invalid_point_is_listed_with_its_reason():
    grid = {"speed_rpm": [300.0, 1e6, 0.0], "e": [0.001, 1.5 * RIG.r_c]}
    with pytest.raises(S.InvalidGridError) as info:
        S.sweep(RIG, SCENE, grid, revolutions=1, progress=False)
    err = info.value
    assert sorted(err.invalid) == [1, 2, 3, 4, 5]  # flat C order over (speed_rpm, e): only (300, 0.001) runs
    assert err.lines[0].startswith("e=0.0375 (every speed_rpm): e = ")
    assert err.lines[1].startswith("speed_rpm=1e+06 (every e): speed_rpm = 1000000.0 is out of range")
    assert err.lines[2].startswith("speed_rpm=0, e=0.001: revolutions") and "no period" in err.lines[2]
    assert len(err.lines) == 3 and "5 of 6 grid points are invalid" in str(err)


def test_skip_records_invalid_points_and_runs_the_rest():
    grid = {"speed_rpm": [900.0, 1e6], "k_s": [2000.0, -1.0]}
    ds = S.sweep(RIG, SCENE, grid, S.Summary(1), invalid="skip", revolutions=2, samples_per_revolution=32,
                 rtol=1e-8, progress=False)
    codes = ds["outcome"].values
    assert codes[0, 0] == 0 and np.all(codes.ravel()[1:] == S.ALL_CODES["INVALID"])
    assert "k_s = -1.0 is out of range" in ds["message"].values[0, 1]
    assert "speed_rpm = 1000000.0" in ds["message"].values[1, 0]
    assert np.all(np.isnan(ds["alpha_r_rms"].values.ravel()[1:]))
    assert ds["alpha_r_rms"].values[0, 0] == _point(2000.0, 900.0)["alpha_r_rms"]  # the valid point, as if alone


def test_a_point_beyond_the_run_limits_is_invalid():
    """simulate's limits that join a rig to a speed (here the samples of a run) are checked per point."""
    with pytest.raises(S.InvalidGridError, match="speed_rpm=1: sample_rate_Hz .* at most 50000000 samples"):
        S.sweep(RIG, SCENE, {"speed_rpm": [1.0, 1000.0]}, revolutions=60, sample_rate_Hz=1e6, progress=False)


def test_a_rig_too_stiff_for_an_explicit_method_is_an_invalid_point():
    """simulate's rate limit (simulation.MAX_RATE) is checked per rig of the grid, before any run."""
    with pytest.raises(S.InvalidGridError, match=r"zeta_D=1e\+06 \(every speed_rpm\): the fastest rate") as info:
        S.sweep(RIG, SCENE, {"speed_rpm": [900.0], "zeta_D": [0.1, 1e6]}, revolutions=1, progress=False)
    assert sorted(info.value.invalid) == [1]


@pytest.mark.parametrize("settings, error, match", [
    (dict(revolutions=2, rtol=1.0), ParameterError, "rtol"),
    (dict(revolution=3), ParameterError, "revolution is not a keyword of camdyn.simulate .did you mean .revolutions.?"),
    (dict(revolutions=2, t_end=1.0), ParameterError, "t_end"), (dict(revolutions=-1), ParameterError, "revolutions"),
    (dict(revolutions=2, backend="gpu"), ParameterError, "backend"),
    (dict(revolutions=2, y0=[1.0]), ParameterError, "y0")])
def test_settings_shared_by_every_point_are_checked_at_once(settings, error, match):
    with pytest.raises(error, match=match):
        S.sweep(RIG, SCENE, {"speed_rpm": [900.0]}, progress=False, **settings)


@pytest.mark.parametrize("settings", [dict(revolutions=2, rtol=1.0), dict(revolution=3),
                                      dict(revolutions=2, t_end=1.0), dict(revolutions=-1),
                                      dict(revolutions=2, backend="gpu"), dict(revolutions=2, y0=[1.0]),
                                      dict(revolutions=2, options=camdyn.engine.SolverOptions(), atol=1e-9),
                                      dict(t_end=0.1, sample_rate_Hz=0)])
def test_a_sweep_refuses_the_settings_simulate_refuses_with_its_message(settings):
    """One builder (camdyn.runs.request.run_request) for both: the same error, word for word."""
    with pytest.raises(ParameterError) as direct:
        camdyn.simulate(RIG, SCENE, speed_rpm=900.0, **settings)
    with pytest.raises(ParameterError) as swept:
        S.sweep(RIG, SCENE, {"speed_rpm": [900.0]}, progress=False, **settings)
    assert str(swept.value) == str(direct.value)


def test_span_and_options_given_whole_run_the_same_points_and_are_recorded_as_keywords(serial, tmp_path):
    """A sweep takes simulate's span= and options= as simulate does; the file records them as the
    loose keywords (method and tolerances always, max_step where it is not the default)."""
    from camdyn.engine import SolverOptions
    from camdyn.runs.request import Span

    out = tmp_path / "whole.nc"
    options = SolverOptions(rtol=1e-8, max_step=0.5)   # longer than a run: the same steps as without it
    ds = S.sweep(RIG, SCENE, GRID, S.Summary(1), span=Span(revolutions=2), options=options,
                 samples_per_revolution=32, progress=False, out=out)
    xr.testing.assert_equal(ds, serial)   # values, not the attributes
    a = ds.attrs
    assert (a["simulate_revolutions"], a["simulate_method"], a["simulate_rtol"], a["simulate_atol"]) == \
        (2.0, "DOP853", 1e-8, 1e-12)
    assert a["simulate_max_step"] == 0.5 and "simulate_sample_rate_Hz" not in a   # set per point
    assert not [k for k in a if k in ("simulate_span", "simulate_options")]
    xr.testing.assert_equal(S.resume(out, progress=False), serial)   # finished: read back


def test_a_point_that_raises_in_a_worker_is_recorded_and_the_sweep_completes(serial, caplog):
    with ProcessPoolExecutor(2) as pool:
        ds = S.sweep(RIG, SCENE, GRID, Faulty(1100.0, "raise"), executor=pool, chunksize=2, **KW)
    failed = ds["speed_rpm"] == 1100.0
    assert np.all(ds["outcome"].where(failed, drop=True) == S.ALL_CODES["ERROR"])
    assert np.all(ds["message"].where(failed, drop=True) == "ValueError: this measure fails at 1100.0 rev/min")
    xr.testing.assert_equal(ds.where(~failed, drop=True), serial.where(~failed, drop=True))  # the others as ever
    assert np.all(np.isnan(ds["alpha_r_rms"].where(failed, drop=True)))
    assert "2 of 6 points raised" in caplog.text


def test_a_run_that_stops_early_is_recorded_with_its_outcome():
    """An engine outcome that is not SUCCESS: its code and message, and the measure's NaN."""
    from camdyn.engine import EventSettings

    ds = S.sweep(RIG.replace(k_s=2000.0), SCENE, {"speed_rpm": [1300.0]}, S.Summary(0), revolutions=2,
                 samples_per_revolution=32, events=EventSettings(max_events=1), progress=False)
    assert ds["outcome"].item() == S.ALL_CODES["MAX_EVENTS"]
    assert ds["message"].item() == camdyn.Outcome.MAX_EVENTS.message and math.isnan(ds["alpha_r_rms"].item())


@pytest.mark.parametrize("grid, name", [({"k_z": [1.0]}, "grid"), ({"speed_rpm": []}, "speed_rpm"),
                                        ({"k_s": [1.0, np.nan], "speed_rpm": [1.0]}, "k_s"), ({}, "grid")])
def test_bad_grid_names_the_parameter(grid, name):
    with pytest.raises(ParameterError, match=name):
        S.sweep(RIG, SCENE, grid, revolutions=1, progress=False)


def test_missing_speed_is_an_error():
    with pytest.raises(ParameterError, match="speed_rpm"):
        S.sweep(RIG, SCENE, {"k_s": [2000.0]}, revolutions=1, progress=False)


def test_an_interrupt_inside_a_point_stops_the_sweep():
    """Ctrl-C inside compiled code reaches Python as a SystemError caused by the KeyboardInterrupt
    (numba's dispatcher): it must stop the sweep, not be recorded as the point's error."""
    def measure(result):
        try:
            raise KeyboardInterrupt
        except KeyboardInterrupt as exc:
            raise SystemError("CPUDispatcher(...) returned a result with an exception set") from exc

    with pytest.raises(KeyboardInterrupt):
        S.sweep(RIG, SCENE, {"speed_rpm": [900.0]}, measure, revolutions=1, samples_per_revolution=8, progress=False)


def test_a_method_the_engine_does_not_have_refuses_the_sweep():
    """The engine runs explicit Runge-Kutta pairs only: found once, before any work (not as an
    ERROR at every point)."""
    with pytest.raises(ParameterError, match="method"):
        S.sweep(RIG, SCENE, {"speed_rpm": [900.0, 1000.0]}, revolutions=1, method="Radau", progress=False)


# --- the output and the folder: nothing lost, nothing ignored ---------------------------------------
ONE = {"speed_rpm": [900.0]}


def test_a_finished_file_is_replaced_only_with_overwrite(tmp_path):
    out = tmp_path / "done.nc"
    S.sweep(RIG, SCENE, ONE, S.Summary(1), out=out, **KW)
    before = out.read_bytes()
    with pytest.raises(S.StoreError, match=r"done.nc exists: .*overwrite=True"):
        S.sweep(RIG, SCENE, {"speed_rpm": [1000.0]}, S.Summary(1), out=out, **KW)
    assert out.read_bytes() == before and not (tmp_path / "done.nc.parts").exists()
    S.sweep(RIG, SCENE, {"speed_rpm": [1000.0]}, S.Summary(1), out=out, overwrite=True, **KW)
    with xr.open_dataset(out, engine="scipy") as ds:
        assert ds["speed_rpm"].values.tolist() == [1000.0]


def test_out_is_checked_before_any_point_runs(tmp_path, monkeypatch):
    marker = tmp_path / "measured"
    measure = Faulty(900.0, "mark", str(marker))
    (tmp_path / "folder.nc").mkdir()
    with pytest.raises(S.StoreError, match="folder.nc is a folder"):
        S.sweep(RIG, SCENE, ONE, measure, out=tmp_path / "folder.nc", **KW)
    locked = tmp_path / "locked"
    locked.mkdir()
    real_access = os.access
    monkeypatch.setattr(os, "access", lambda path, mode: False if Path(path) == locked else real_access(path, mode))
    with pytest.raises(S.StoreError, match="locked is not writable"):
        S.sweep(RIG, SCENE, ONE, measure, out=locked / "map.nc", **KW)
    assert not marker.exists()  # no point was measured
    assert sorted(p.name for p in tmp_path.iterdir()) == ["folder.nc", "locked"]


def test_a_folder_is_locked_by_the_process_that_writes_it(tmp_path):
    out = tmp_path / "map.nc"
    (tmp_path / "map.nc.parts").mkdir()
    with pytest.raises(S.StoreError, match="unfinished"):
        S.sweep(RIG, SCENE, ONE, S.Summary(1), out=out, **KW)
    (tmp_path / "map.nc.parts").rmdir()
    with InterruptAfter(0) as executor, pytest.raises(KeyboardInterrupt):  # leaves an unfinished folder
        S.sweep(RIG, SCENE, GRID, S.Summary(1), executor=executor, out=out, **KW)
    with FolderStore.open(out):
        with pytest.raises(S.StoreError, match="map.nc.parts is in use by this process"):
            S.resume(out, progress=False)
        with pytest.raises(S.StoreError, match="in use by this process"):
            S.sweep(RIG, SCENE, GRID, S.Summary(1), out=out, **KW)
    ds = S.resume(out, progress=False)  # released: resume runs it
    assert (ds["outcome"] == 0).all() and not (tmp_path / "map.nc.parts").exists()


def test_a_file_that_is_not_a_sweep_is_refused_in_one_line(tmp_path):
    run = camdyn.simulate(RIG, SCENE, speed_rpm=900.0, revolutions=0.5, sample_rate_Hz=2000.0)
    write_netcdf(run, tmp_path / "run.nc", RIG)
    (tmp_path / "garbage.nc").write_bytes(b"half a file")
    (tmp_path / "empty.nc").write_bytes(b"")
    xr.Dataset({"x": ("n", [1.0])}, attrs={"title": TITLE}).to_netcdf(tmp_path / "cut.nc", engine="scipy")
    cases = {"run.nc": "its title is 'camdyn run: ", "garbage.nc": "it is not a netCDF3 file",
             "empty.nc": "the file is empty", "cut.nc": "has no 'outcome'"}
    for name, what in cases.items():
        for read in (S.resume, S.settings_of):
            with pytest.raises(S.NotASweepError, match="is not a") as info:
                read(tmp_path / name)
            text = str(info.value)
            assert isinstance(info.value, CamdynError) and str(tmp_path / name) in text and what in text
            assert "\n" not in text and "netcdf4" not in text


def _unfinished(tmp_path):
    """A folder of a sweep interrupted before its first chunk."""
    out = tmp_path / "map.nc"
    with InterruptAfter(0) as executor, pytest.raises(KeyboardInterrupt):
        S.sweep(RIG, SCENE, GRID, Faulty(1100.0, "raise"), executor=executor, out=out, **KW)
    return out, tmp_path / "map.nc.parts"


def test_a_damaged_manifest_is_named(tmp_path):
    out, folder = _unfinished(tmp_path)
    manifest = folder / "manifest.json"
    manifest.write_text("{not json")
    with pytest.raises(S.StoreError, match=r"map.nc.parts/manifest.json cannot be read \(JSONDecodeError: .*delete"):
        S.resume(out, progress=False)
    manifest.unlink()
    for read in (lambda: S.resume(out, progress=False), lambda: S.settings_of(out), lambda: S.load_partial(out)):
        with pytest.raises(S.StoreError, match="map.nc.parts/manifest.json is missing"):
            read()


def test_a_damaged_pickle_gets_no_import_hint(tmp_path):
    out, folder = _unfinished(tmp_path)
    pickled = folder / "sweep.pickle"
    good = pickled.read_bytes()
    pickled.write_bytes(b"garbage")
    with pytest.raises(S.StoreError, match="map.nc.parts/sweep.pickle is damaged") as info:
        S.resume(out, progress=False)
    assert "importable" not in str(info.value)
    pickled.write_bytes(good.replace(b"sweep_faults", b"sweep_faulty"))  # a measure this process cannot import
    with pytest.raises(S.StoreError, match="must be importable"):
        S.resume(out, progress=False)
    pickled.write_bytes(good)
    assert int((S.resume(out, progress=False)["outcome"] == S.ALL_CODES["ERROR"]).sum()) == 2  # not locked


def test_a_damaged_chunk_is_named_in_one_line_and_runs_again(tmp_path, caplog):
    out = tmp_path / "map.nc"
    with InterruptAfter(2) as executor, pytest.raises(KeyboardInterrupt):
        S.sweep(RIG, SCENE, GRID, S.Summary(1), executor=executor, chunksize=2, out=out, **KW)
    damaged = sorted((tmp_path / "map.nc.parts" / "chunks").glob("*.nc"))[0]
    damaged.write_bytes(b"half a file")
    ds = S.resume(out, progress=False)
    lines = [r.getMessage() for r in caplog.records if damaged.name in r.getMessage()]
    assert lines == [f"{damaged} cannot be read (it is not a netCDF3 file); its points will run again"]
    assert (ds["outcome"] == 0).all()


def test_a_stopping_sweep_says_what_it_saved(caplog):
    """Runs too short to stop (16 revolutions at the least) ran every revolution asked for, though
    their last sample falls a revolution short at one sample per revolution."""
    caplog.set_level("INFO", logger="camdyn.sweep.api")
    ds = S.bifurcation(RIG, SCENE, [900.0, 1000.0], revolutions=4, transient_revolutions=2, progress=False)
    assert ds["revolutions_run"].values.tolist() == [4.0, 4.0] and (ds["stop_period"] == 0).all()
    assert "stopped once periodic: 0 of the 2 points that ran; 8 of 8 revolutions run, 0 (0 %) saved" in caplog.text
    ds = S.bifurcation(RIG, SCENE, [700.0], revolutions=40, transient_revolutions=2, progress=False)
    run = ds["revolutions_run"].item()
    assert ds["stop_period"].item() > 0 and run < 40  # below contact loss the section settles: it stopped
    assert f"1 of the 1 points that ran; {run:g} of 40 revolutions run, {40 - run:g}" in caplog.text
