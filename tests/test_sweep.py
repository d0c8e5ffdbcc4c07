"""Sweeps: any Executor, deterministic order and values, labelled result, NetCDF round trip."""
from __future__ import annotations

from concurrent.futures import ProcessPoolExecutor, ThreadPoolExecutor

import numpy as np
import pytest

import camdyn
from camdyn import sweep as S
from camdyn.errors import ParameterError
from registry import RIG

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


def test_dask_local_cluster_gives_the_same_dataset(serial):
    distributed = pytest.importorskip("distributed")
    with distributed.LocalCluster(n_workers=2, threads_per_worker=1, processes=True, dashboard_address=None) as cluster, \
            distributed.Client(cluster) as client:
        ds = S.sweep(RIG, SCENE, GRID, S.Summary(1), executor=client.get_executor(), chunksize=2, **KW)
    xr.testing.assert_identical(ds, serial)


def test_netcdf_round_trip(serial, tmp_path):
    path = tmp_path / "sweep.nc"
    serial.to_netcdf(path)
    with xr.open_dataset(path) as back:
        xr.testing.assert_identical(back.load(), serial)


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


@pytest.mark.parametrize("grid, name", [({"k_z": [1.0]}, "grid"), ({"speed_rpm": []}, "speed_rpm"),
                                        ({"k_s": [1.0, np.nan], "speed_rpm": [1.0]}, "k_s"), ({}, "grid")])
def test_bad_grid_names_the_parameter(grid, name):
    with pytest.raises(ParameterError, match=name):
        S.sweep(RIG, SCENE, grid, revolutions=1, progress=False)


def test_missing_speed_is_an_error():
    with pytest.raises(ParameterError, match="speed_rpm"):
        S.sweep(RIG, SCENE, {"k_s": [2000.0]}, revolutions=1, progress=False)
