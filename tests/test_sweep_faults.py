"""Sweeps that lose nothing: workers that die (process pool, dask), Ctrl-C, a killed process,
then resume; the result equals an uninterrupted sweep's, whatever the executor and chunk size."""
from __future__ import annotations

import os
import signal
import subprocess
import sys
import time
from concurrent.futures import ProcessPoolExecutor
from pathlib import Path

import numpy as np
import pytest

import camdyn
from camdyn.sweep import api as S
from camdyn.cli import app, sweeping
from camdyn.cli import main
from registry import RIG
from sweep_faults import Faulty, InterruptAfter, WithDeathSignal

xr = pytest.importorskip("xarray")
SCENE = camdyn.Scene(damping="D", friction="coulomb")
GRID = {"k_s": [2000.0, 3000.0], "speed_rpm": [900.0, 1000.0, 1100.0, 1200.0, 1300.0, 1400.0]}
KW = dict(revolutions=2, samples_per_revolution=32, rtol=1e-8, progress=False)
NOT_RUN = S.ALL_CODES["NOT_RUN"]


@pytest.fixture(scope="module")
def serial():
    return S.sweep(RIG, SCENE, GRID, S.Summary(1), **KW)


# --- workers that die -----------------------------------------------------------------------------
def test_process_pool_worker_killed_mid_sweep_costs_a_retry(serial, tmp_path):
    marker = tmp_path / "killed"
    with ProcessPoolExecutor(2) as pool:
        ds = S.sweep(RIG, SCENE, GRID, Faulty(1100.0, "exit_once", str(marker)), executor=pool, chunksize=1, **KW)
    assert marker.exists()  # a worker did die: its pool broke, a new one ran the chunks in flight again
    xr.testing.assert_equal(ds, serial)  # values (the measure's repr differs: attrs are not compared)


def test_process_pool_point_that_always_kills_its_worker_is_recorded(serial, caplog):
    with ProcessPoolExecutor(2) as pool:
        ds = S.sweep(RIG, SCENE, GRID, Faulty(1100.0, "exit"), executor=pool, chunksize=1, retries=1, **KW)
    lost = ds["speed_rpm"] == 1100.0
    assert np.all(ds["outcome"].where(lost, drop=True) == NOT_RUN)
    assert all("BrokenProcessPool" in m for m in ds["message"].where(lost, drop=True).values.ravel())
    # only the culprit is blamed: every other point ran, with its usual values
    xr.testing.assert_equal(ds.where(~lost, drop=True), serial.where(~lost, drop=True))
    assert "2 of 12 points could not run: recorded as NOT_RUN" in caplog.text


def test_dask_worker_killed_mid_sweep(serial, tmp_path):
    """On a LocalCluster of processes a worker that dies costs its task a rerun (by the scheduler);
    the sweep completes with the same values, also for another chunk size."""
    distributed = pytest.importorskip("distributed")
    marker = tmp_path / "killed"
    cluster = distributed.LocalCluster(n_workers=2, threads_per_worker=1, processes=True, dashboard_address=None)
    with cluster, distributed.Client(cluster) as client:
        ds = S.sweep(RIG, SCENE, GRID, Faulty(1100.0, "exit_once", str(marker)), executor=client.get_executor(),
                     chunksize=2, **KW)
        assert marker.exists()
        xr.testing.assert_equal(ds, serial)
        plain = S.sweep(RIG, SCENE, GRID, S.Summary(1), executor=client.get_executor(), chunksize=5, **KW)
    xr.testing.assert_identical(plain, serial)  # determinism on dask, attributes included


class ClosingAfter:
    """A dask executor whose client is closed (the cluster lost) when the sweep submits task
    number ``n + 1``: the tasks in flight are cancelled and no more can be submitted."""

    def __init__(self, client, n: int):
        self._client, self.executor, self.n = client, client.get_executor(), n

    def submit(self, *args, **kwargs):
        if self.n == 0:
            self._client.close()
        self.n -= 1
        return self.executor.submit(*args, **kwargs)


def test_dask_cluster_lost_mid_sweep_records_not_run_and_resume_runs_them(serial, tmp_path, caplog):
    distributed = pytest.importorskip("distributed")
    out = tmp_path / "map.nc"
    cluster = distributed.LocalCluster(n_workers=1, threads_per_worker=1, processes=False, dashboard_address=None)
    with cluster:
        client = distributed.Client(cluster)
        ds = S.sweep(RIG, SCENE, GRID, S.Summary(1), executor=ClosingAfter(client, 4), chunksize=1, out=out, **KW)
    lost = ds["outcome"] == NOT_RUN
    assert 8 <= int(lost.sum()) < 12 and int((ds["outcome"] == 0).sum()) == 12 - int(lost.sum())
    assert all("ClosedClientError" in m for m in ds["message"].values[lost.values])
    assert f"{int(lost.sum())} of 12 points could not run: recorded as NOT_RUN" in caplog.text
    assert (tmp_path / "map.nc.parts").is_dir()
    xr.testing.assert_identical(S.resume(out, progress=False), serial)


@pytest.mark.skipif(not sys.platform.startswith("linux"), reason="the parent-death signal is Linux's prctl")
def test_process_pool_workers_end_with_their_parent_also_after_a_break(tmp_path):
    """Every point ran in a worker that the kernel kills when the sweep's process dies: those of
    process_pool, and those of the pool that replaces it after a worker died."""
    marker = tmp_path / "killed"
    with S.process_pool(2) as pool:
        ds = S.sweep(RIG, SCENE, GRID, WithDeathSignal(1100.0, "exit_once", str(marker)), executor=pool,
                     chunksize=1, **KW)
    assert marker.exists() and (ds["outcome"] == 0).all()
    assert (ds["death_signal"] == signal.SIGKILL).all()
    with ProcessPoolExecutor(1) as plain:  # the check can fail: a plain pool's workers have none
        ds = S.sweep(RIG, SCENE, {"speed_rpm": [900.0]}, WithDeathSignal(0.0, ""), executor=plain, **KW)
    assert (ds["death_signal"] == 0).all()


# --- interrupted, then resumed ----------------------------------------------------------------------
def test_interrupt_after_half_the_chunks_then_resume_equals_the_uninterrupted_sweep(serial, tmp_path):
    out = tmp_path / "map.nc"
    chunks = tmp_path / "map.nc.parts" / "chunks"
    with InterruptAfter(7) as executor, pytest.raises(KeyboardInterrupt):
        S.sweep(RIG, SCENE, GRID, S.Summary(1), executor=executor, chunksize=1, out=out, **KW)
    finished = len(list(chunks.glob("*.nc")))
    assert 5 <= finished <= 7  # about half of the 12 chunks are kept; nothing else was written
    assert not out.exists()
    partial = S.load_partial(out)
    assert int((partial["outcome"] == 0).sum()) == finished
    assert int((partial["outcome"] == NOT_RUN).sum()) == 12 - finished
    next(iter(chunks.glob("*.nc"))).write_bytes(b"half a file")  # a damaged chunk: its points run again
    # resume on another executor with another chunk size: bit for bit the uninterrupted result
    with ProcessPoolExecutor(2) as pool:
        ds = S.resume(out, executor=pool, chunksize=2, progress=False)
    xr.testing.assert_identical(ds, serial)
    with xr.open_dataset(out, engine="scipy") as back:
        xr.testing.assert_identical(back.load(), serial)
    assert not chunks.parent.exists()
    xr.testing.assert_identical(S.resume(out), serial)  # a finished sweep: its file


def test_lost_points_are_run_by_resume(serial, tmp_path):
    """A sweep that could not run some points writes what it has and keeps its folder; resume
    runs them (here the point that killed its worker no longer does)."""
    out, marker = tmp_path / "map.nc", tmp_path / "fixed"
    with ProcessPoolExecutor(2) as pool:
        ds = S.sweep(RIG, SCENE, GRID, Faulty(1100.0, "exit_unless", str(marker)), executor=pool, chunksize=3,
                     retries=0, out=out, **KW)
    # the chunks holding 1100 rev/min (3 points each, one per k_s) could not run
    assert int((ds["outcome"] == NOT_RUN).sum()) == 6 and (tmp_path / "map.nc.parts").is_dir() and out.exists()
    marker.write_text("fixed")
    resumed = S.resume(out, progress=False)
    xr.testing.assert_equal(resumed, serial)
    assert not (tmp_path / "map.nc.parts").exists()


# --- the command line: a killed sweep, then Ctrl-C, then resumed ------------------------------------
CLI = ["--no-progress", "sweep", "--speeds", "600:900:12", "--revolutions", "60", "--transient-revolutions", "20"]
CHILD = ("import signal, sys; signal.signal(signal.SIGINT, signal.default_int_handler); "
         "from camdyn.cli import main; sys.exit(main(sys.argv[1:]))")


def _start(args: list[str]) -> subprocess.Popen:
    return subprocess.Popen([sys.executable, "-c", CHILD, *args], stdout=subprocess.PIPE, stderr=subprocess.PIPE,
                            text=True)


def _when_chunks(chunks: Path, n: int, proc: subprocess.Popen, timeout: float = 120.0) -> None:
    start = time.monotonic()
    while len(list(chunks.glob("*.nc"))) < n:
        assert proc.poll() is None, proc.communicate()
        assert time.monotonic() - start < timeout, "the sweep made no progress"
        time.sleep(0.01)


def test_cli_sweep_killed_then_interrupted_then_resumed_equals_the_uninterrupted_one(tmp_path, capsys):
    """Killed (its lock goes with it), resumed by a process that holds the folder's lock (a second
    resume is refused), interrupted (the hint keeps its options), resumed to the end."""
    pytest.importorskip("matplotlib")
    out, png = tmp_path / "bif.nc", tmp_path / "bif.png"
    chunks = tmp_path / "bif.nc.parts" / "chunks"
    proc = _start(CLI + ["--out", str(out)])
    _when_chunks(chunks, 4, proc)
    proc.send_signal(signal.SIGKILL)  # a crash: no chance to clean up
    proc.communicate()
    crashed = len(list(chunks.glob("*.nc")))
    assert 4 <= crashed < 12 and not out.exists()
    proc = _start(["--no-progress", "sweep", "--resume", str(out), "--jobs", "2", "--plot", str(png)])
    _when_locked(tmp_path / "bif.nc.parts", proc)
    capsys.readouterr()
    assert main(["--no-progress", "sweep", "--resume", str(out)]) == 2  # a second resume, meanwhile
    assert f"bif.nc.parts is in use by another camdyn sweep (process {proc.pid})" in capsys.readouterr().err
    _when_chunks(chunks, crashed + 2, proc)
    proc.send_signal(signal.SIGINT)  # Ctrl-C
    stdout, err = proc.communicate()
    assert f"applied: --jobs 2, --plot {png}" in stdout
    assert proc.returncode == 130
    assert f"'camdyn --no-progress sweep --resume {out} --jobs 2 --plot {png}' runs the rest" in err
    assert crashed + 2 <= len(list(chunks.glob("*.nc"))) < 12
    assert main(["--no-progress", "sweep", "--resume", str(out)]) == 0
    reference = S.bifurcation(RIG, camdyn.Scene(), np.linspace(600, 900, 12), revolutions=60, transient_revolutions=20,
                              method="DOP853", rtol=1e-8, atol=1e-12, progress=False)
    with xr.open_dataset(out, engine="scipy") as back:
        xr.testing.assert_identical(back.load(), reference)
    assert not chunks.parent.exists()
    capsys.readouterr()
    assert main(["--no-progress", "sweep", "--resume", str(out)]) == 0  # again: nothing left to run
    assert "was complete: nothing to run" in capsys.readouterr().out


def _when_locked(folder: Path, proc: subprocess.Popen, timeout: float = 60.0) -> None:
    """Once the process holds the folder's lock (its id is in the lock file)."""
    start = time.monotonic()
    while not ((folder / "lock").exists() and (folder / "lock").read_text().strip() == str(proc.pid)):
        assert proc.poll() is None, proc.communicate()
        assert time.monotonic() - start < timeout, "the resume never took the lock"
        time.sleep(0.01)


def test_cli_sweep_killed_leaves_no_workers(tmp_path):
    """SIGKILL to 'camdyn sweep --jobs 2': its pool workers end too (and so release its pipes)."""
    psutil = pytest.importorskip("psutil")
    out = tmp_path / "bif.nc"
    proc = _start(CLI + ["--jobs", "2", "--netcdf", str(out)])
    _when_chunks(tmp_path / "bif.nc.parts" / "chunks", 1, proc)
    workers = psutil.Process(proc.pid).children(recursive=True)
    assert len(workers) >= 2
    proc.kill()
    proc.wait()
    _, alive = psutil.wait_procs(workers, timeout=10)
    for worker in alive:  # not left behind by a failing test
        worker.kill()
    assert not alive, alive
    proc.communicate(timeout=10)  # the pipes closed: no worker holds them


def test_cli_resume_refuses_an_option_that_differs_and_applies_the_run_options(tmp_path, capsys):
    pytest.importorskip("matplotlib")
    out, png, toml = tmp_path / "map.nc", tmp_path / "map.png", tmp_path / "stiff.toml"
    with InterruptAfter(3) as executor, pytest.raises(KeyboardInterrupt):
        S.sweep(RIG, SCENE, GRID, S.Summary(1), executor=executor, chunksize=1, out=out, **KW)
    RIG.replace(k_s=2500.0).to_toml(toml)
    chunks = lambda: sorted((tmp_path / "map.nc.parts" / "chunks").glob("*.nc"))  # noqa: E731
    kept = chunks()
    refused = {("--damping", "B"): f"--damping B: {out} was swept with damping = 'D'",
               ("--revolutions", "3"): f"--revolutions 3.0: {out} was swept with revolutions = 2",
               ("--rtol", "1e-9"): f"--rtol 1e-09: {out} was swept with rtol = 1e-08",
               ("--rig", str(toml)): f"{out} was swept on rig 'example', whose k_s is 2000.0 (not 2500.0)",
               ("--speeds", "900,1000"): f"{out} was swept over 6 values of speeds, 900 to 1400",
               ("--netcdf", str(tmp_path / "b.nc")): f"was swept into {out}",
               ("--skip-invalid",): "--skip-invalid starts a new sweep: it does not go with --resume",
               ("--overwrite",): "--overwrite starts a new sweep"}
    for option, message in refused.items():
        assert main(["sweep", "--resume", str(out), *option]) == 2, option
        err = capsys.readouterr().err
        assert message in err and len(err.splitlines()) == 1, err
        assert f"drop {option[0]}" in err or "starts a new sweep" in message
    assert kept and chunks() == kept  # nothing ran
    same = ["--damping", "D", "--rtol", "1e-8", "--param", "k_s", "--values", "2000,3000", "--rig", "example"]
    assert main(["sweep", "--resume", str(out), *same, "--jobs", "2", "--plot", str(png)]) == 0
    stdout = capsys.readouterr().out
    assert (f"applied: --jobs 2, --plot {png}; the same as the sweep's: --rig, --damping, --param, --values, --rtol"
            in stdout)
    assert png.read_bytes()[:4] == b"\x89PNG" and not (tmp_path / "map.nc.parts").exists()


def test_cli_report_says_how_to_run_the_points_not_run(tmp_path, capsys):
    out = tmp_path / "map.nc"
    with InterruptAfter(0) as executor, pytest.raises(KeyboardInterrupt):
        S.sweep(RIG, SCENE, GRID, S.Summary(1), executor=executor, out=out, **KW)
    args = app._parser().parse_args(["sweep", "--resume", str(out), "--jobs", "2"])
    assert sweeping._sweep_report(S.load_partial(out), args, S, str(out)) == 3
    report = capsys.readouterr().out
    assert "12 points, 0 without impacts after the transient, 0 impacting, 12 did not succeed" in report
    assert f"the 12 NOT_RUN points are kept for later: 'camdyn sweep --resume {out} --jobs 2' runs them" in report


def test_cli_lists_invalid_points_or_skips_them(tmp_path, capsys, monkeypatch):
    """Skipped on purpose (--skip-invalid): exit 0, counted as skipped, left out of the plot."""
    pytest.importorskip("matplotlib")
    args = ["sweep", "--speeds", "900,1e6", "--param", "e", "--values", f"0.001,{1.5 * RIG.r_c}", "--revolutions", "2",
            "--transient-revolutions", "1", "--samples-per-revolution", "16"]
    assert main(args) == 2
    err = capsys.readouterr().err
    assert "speed_rpm=1e+06 (every e): speed_rpm = 1000000.0 is out of range" in err and "e=0.0375 (every" in err
    assert "3 of 4 grid points are invalid (listed above); --skip-invalid runs the others" in err
    assert not list(tmp_path.iterdir())
    figures = []
    monkeypatch.setattr(sweeping, "_save_figure", lambda fig, path: figures.append(fig))
    assert main(args + ["--skip-invalid", "--out", str(tmp_path / "e.nc"), "--plot", str(tmp_path / "e.png")]) == 0
    out = capsys.readouterr().out
    assert "4 points, 1 without impacts after the transient, 0 impacting, 3 skipped as invalid (--skip-invalid), " \
           "0 did not succeed" in out and "3 INVALID" in out
    ax = figures[0].axes[0]
    assert ax.get_xlim()[1] < 1e4 and ax.get_ylim()[1] < 1.5 * RIG.r_c  # the skipped speed and e are not on it
    assert [t.get_text() for t in ax.get_legend().get_texts()] == ["sliding"]  # nothing drawn as failed
    with xr.open_dataset(tmp_path / "e.nc", engine="scipy") as ds:
        assert int((ds["outcome"] == 0).sum()) == 1
    assert main(["sweep", "--resume", str(tmp_path / "e.nc"), "--speeds", "1"]) == 2
    assert os.listdir(tmp_path) == ["e.nc"]
