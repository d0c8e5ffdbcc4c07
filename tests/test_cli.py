"""The camdyn command: outputs, --help everywhere, one-line errors, documented exit codes."""
from __future__ import annotations

import csv
import json
import math
import subprocess
import sys

import numpy as np
import pytest

from camdyn.cli import app, common, model, options
from camdyn.cli import main

PNG = b"\x89PNG\r\n\x1a\n"
QUICK = ["--speed-rpm", "1100", "--revolutions", "2", "--sample-rate-Hz", "5000"]  # impacting, < 1 s


def one_error_line(capsys, starts="camdyn: error:"):
    err = capsys.readouterr().err.strip().splitlines()
    assert len(err) == 1, err
    assert err[0].startswith(starts), err[0]
    return err[0]


def test_simulate_writes_csv(tmp_path, capsys):
    out = tmp_path / "run.csv"
    assert main(["simulate", "--speed-rpm", "300", "--revolutions", "0.2", "--sample-rate-Hz", "2000",
                 "--csv", str(out)]) == 0
    rows = list(csv.reader(out.open()))
    assert rows[0][:3] == ["t (s)", "alpha (rad)", "alpha_dot (rad/s)"] and rows[0][-1] == "regime"
    assert "F_n (N)" in rows[0] and "v_r (m/s)" in rows[0]  # every column says its unit
    assert len(rows) == 1 + 81  # 0.2 rev at 300 rev/min = 0.04 s at 2 kHz: 80 intervals, both ends
    assert "alpha_r: rms" in capsys.readouterr().out


def test_simulate_writes_netcdf_and_plot(tmp_path, capsys):
    xr = pytest.importorskip("xarray")
    pytest.importorskip("matplotlib")
    nc, png = tmp_path / "run.nc", tmp_path / "run.png"
    assert main(["simulate", *QUICK, "--netcdf", str(nc), "--plot", str(png)]) == 0
    assert png.read_bytes()[:8] == PNG
    with xr.open_dataset(nc, engine="scipy") as ds:
        assert ds.attrs["scene"] == "line_d_coulomb_constant_nonlinear"
        assert math.isclose(ds.attrs["period_s"], 60 / 1100)
        assert ds["alpha_r"].attrs["units"] == "rad" and ds["F_n"].attrs["units"] == "N"
        names = ds["regime"].attrs["flag_meanings"].split()
        assert "free" in names and ds["impact_t"].size > 0  # 1100 rev/min is above contact loss
        assert set(np.unique(ds["regime"].values)) <= set(range(len(names)))
    out = capsys.readouterr().out
    assert str(nc) in out and str(png) in out


def test_spectrum_of_a_saved_run_finds_the_cam_harmonics(tmp_path, capsys):
    run = tmp_path / "run.csv"
    assert main(["simulate", "--speed-rpm", "1500", "--revolutions", "10", "--sample-rate-Hz", "2000",
                 "--csv", str(run)]) == 0
    capsys.readouterr()
    spec = tmp_path / "spec.csv"
    assert main(["spectrum", "--input", str(run), "--transient-revolutions", "2", "--peaks", "1",
                 "--csv", str(spec)]) == 0
    out = capsys.readouterr().out
    assert "cam frequency Omega_c = 25 Hz" in out  # period inferred from Theta(t) in the CSV
    ratio = float(out.split(" x Omega_c")[0].split("=")[-1])
    assert abs(ratio - 1) < 0.01  # the strongest peak of alpha is the fundamental
    rows = list(csv.reader(spec.open()))
    assert rows[0] == ["f (Hz)", "amplitude of alpha (rad)"] and len(rows) > 100


def test_spectrum_simulates_and_plots(tmp_path, capsys):
    pytest.importorskip("matplotlib")
    png = tmp_path / "spec.png"
    assert main(["spectrum", *QUICK, "--transient-revolutions", "0.5", "--band", "0", "200",
                 "--plot", str(png)]) == 0
    assert png.read_bytes()[:8] == PNG
    assert "linearized natural frequency" in capsys.readouterr().out


def test_equilibrium_prints_json(capsys):
    assert main(["equilibrium", "--damping", "none", "--friction", "none"]) == 0
    data = json.loads(capsys.readouterr().out)
    assert data["psi_i_star_m"] < 0 and data["natural_frequency_Hz"] > 0


def test_natural_frequency_alias_and_friction_direction(capsys):
    hz = {}
    for speed in ("300", "-300"):
        assert main(["natural-frequency", "--speed-rpm", speed]) == 0
        hz[speed] = json.loads(capsys.readouterr().out)["natural_frequency_Hz"]
    assert hz["300"] != hz["-300"]  # de- and self-energizing differ (Section 7.1)


def test_contact_loss_single_and_over_k_s(capsys):
    assert main(["contact-loss"]) == 0
    single = float(capsys.readouterr().out)
    assert main(["contact-loss", "--k-s", "2000,8000"]) == 0
    lines = capsys.readouterr().out.splitlines()
    assert lines[0] == "k_s (N/m),contact_loss_speed (rev/min)"
    speeds = [float(line.split(",")[1]) for line in lines[1:]]
    assert math.isclose(speeds[0], single, rel_tol=1e-9)
    assert math.isclose(speeds[1], 2 * speeds[0], rel_tol=1e-5)  # Omega_loss ~ sqrt(k_s)


def test_lyapunov_prints_the_exponents_and_json(capsys):
    run = ["lyapunov", "--speed-rpm", "1500", "--revolutions", "20", "--transient-revolutions", "10",
           "--batches", "4"]
    assert main(run) == 0
    lines = capsys.readouterr().out.splitlines()
    assert lines[0].startswith("lambda_1 = ") and lines[1].startswith("lambda_2 = ")
    assert main(run + ["--json"]) == 0
    data = json.loads(capsys.readouterr().out)
    # the stable 1500 rev/min orbit (tests/test_orbits.py): both exponents negative, their sum
    # the mean divergence (the saltation matrices of damping D have det 1), to rtol 1e-6
    assert all(x < 0 for x in data["exponents_per_s"]) and data["revolutions"] == 20
    assert math.isclose(sum(data["exponents_per_s"]), data["divergence_mean_per_s"], rel_tol=1e-6)
    assert main(["lyapunov", "--speed-rpm", "1500", "--revolutions", "15"]) == 2
    assert "revolutions" in one_error_line(capsys)


def test_sweep_bifurcation_and_contact_map(tmp_path, capsys):
    xr = pytest.importorskip("xarray")
    pytest.importorskip("matplotlib")
    nc, png = tmp_path / "bif.nc", tmp_path / "bif.png"
    scipy = []  # the compiled loop is cached once per machine
    assert main(["sweep", "--speeds", "1200,1500", "--revolutions", "4", "--transient-revolutions", "2",
                 "--netcdf", str(nc), "--plot", str(png), *scipy]) == 0
    assert png.read_bytes()[:8] == PNG
    with xr.open_dataset(nc, engine="scipy") as ds:
        assert ds["alpha_section"].dims == ("speed_rpm", "revolution")
        assert ds["alpha_section"].shape == (2, 3)  # after revolutions 2, 3, 4
        assert np.all(np.isfinite(ds["alpha_section"].values))
        assert np.all(ds["impacts_per_rev"].values > 0)
    assert "2 points" in capsys.readouterr().out
    nc2, png2 = tmp_path / "map.nc", tmp_path / "map.png"
    assert main(["sweep", "--speeds", "1200,1500", "--param", "k_s", "--values", "200,400",
                 "--revolutions", "2", "--transient-revolutions", "1", "--samples-per-revolution", "20",
                 "--out", str(nc2), "--plot", str(png2), *scipy]) == 0  # --out: the deprecated name
    assert "--out is deprecated here; use --netcdf" in capsys.readouterr().err
    assert png2.read_bytes()[:8] == PNG
    with xr.open_dataset(nc2, engine="scipy") as ds:
        assert ds["impacts_per_rev"].dims == ("k_s", "speed_rpm")
        assert "loss_speed_predicted" in ds
    assert main(["sweep", "--speeds", "1200", "--revolutions", "4.5", "--transient-revolutions", "2", *scipy]) == 2
    assert "whole --revolutions" in capsys.readouterr().err


def test_continue_prints_the_events_and_writes_netcdf(tmp_path, capsys):
    xr = pytest.importorskip("xarray")
    nc = tmp_path / "branch.nc"
    assert main(["continue", "--start", "1650", "--end", "1750", "--netcdf", str(nc)]) == 0
    out = capsys.readouterr().out
    # the example rig's period doubling (tests/test_continuation.py: 1710.2 rev/min)
    rows = [line.split(",") for line in out.splitlines() if line.startswith("period_doubling,")]
    assert rows and 1700 < float(rows[0][1]) < 1720
    assert "branch 1 (period 2 T)" in out and str(nc) in out
    with xr.open_dataset(nc, engine="scipy") as ds:
        assert ds.attrs["parameter"] == "speed_rpm" and ds["lambda"].attrs["units"] == "rev/min"
        assert ds.sizes["event"] == len(rows)


def test_scenes_lists_generated_scenes(capsys):
    assert main(["scenes", "--json"]) == 0
    data = json.loads(capsys.readouterr().out)
    assert "line_d_coulomb_constant_nonlinear" in data["scenes"] and "example" in data["rigs"]
    assert "friction" in data["options"]


COMMANDS = ["simulate", "spectrum", "equilibrium", "natural-frequency", "contact-loss", "lyapunov", "sweep", "basins",
            "continue",
            "regenerate", "reproduce", "scenes"]


@pytest.mark.parametrize("command", [None] + COMMANDS)
def test_help_everywhere(command, capsys):
    with pytest.raises(SystemExit) as exc:
        main(([command] if command else []) + ["--help"])
    assert exc.value.code == 0
    out = capsys.readouterr().out
    assert out.startswith("usage: camdyn") and "exit codes:" in out


def test_every_command_is_documented_in_the_top_level_help(capsys):
    with pytest.raises(SystemExit):
        main(["--help"])
    out = capsys.readouterr().out
    for command in COMMANDS:
        assert command in out


def test_errors_are_one_line_with_exit_code_2(tmp_path, capsys):
    bad = tmp_path / "bad.toml"
    bad.write_text("name = 'x'\n[parameters]\nr_c = -1\n")
    assert main(["contact-loss", "--rig", str(bad)]) == 2
    one_error_line(capsys)
    assert main(["simulate", "--speed-rpm", "nan", "--revolutions", "1"]) == 2
    assert "speed_rpm" in one_error_line(capsys)


@pytest.mark.parametrize("argv, words", [
    (["frobnicate"], "invalid choice"),
    (["simulate"], "a cam motion is needed"),
    (["simulate", "--speed-rpm", "300", "--damping", "X"], "--damping"),
    (["simulate", "--speed-rpm", "fast"], "--speed-rpm"),
    (["simulate", "--speed-rpm", "300", "--oscillating-rpm", "40"], "not both"),
    (["simulate", "--speed-rpm", "300", "--rig", "missing.toml"], "missing.toml"),
    (["simulate", "--speed-rpm", "300", "--model", "linear_paper", "--damping", "B"], "constant damping coefficient"),
    (["simulate", "--speed-rpm", "300", "--csv", "/no/such/folder/run.csv"], "does not exist"),
    (["simulate", "--speed-rpm", "300", "--rtol", "1"], "rtol"),
    (["sweep", "--speeds", "1:2"], "start:stop:count"),
    (["sweep", "--speeds", "1000", "--param", "k_x", "--values", "1,2"], "not a rig parameter"),
    (["sweep", "--speeds", "1000", "--values", "1,2"], "needs --param"),
    (["spectrum", "--input", "nothere.csv"], "no such file"),
    (["continue", "--start", "1000", "--end", "1000"], "other than start"),
    (["continue", "--param", "k_s", "--start", "1000", "--end", "2000"], "give --speed-rpm"),
    (["regenerate", "--derive", "."], "not a camdyn derive/ folder"),
])
def test_bad_input_is_one_line_and_exit_code_2(argv, words, capsys):
    assert main(argv) == 2
    assert words in one_error_line(capsys)


def test_a_scene_outside_the_catalog_without_sympy_is_exit_code_2(capsys, monkeypatch, tmp_path):
    from camdyn.model import ondemand
    monkeypatch.setenv("CAMDYN_CACHE_DIR", str(tmp_path))  # nothing derived earlier
    monkeypatch.setattr(ondemand, "sympy_version", lambda: None)
    assert main(["simulate", "--speed-rpm", "300", "--contact", "point", "--damping", "B"]) == 2
    assert 'pip install "camdyn[derive]"' in one_error_line(capsys)


def test_a_run_that_stops_early_exits_3_and_still_writes(tmp_path, monkeypatch, capsys):
    import camdyn.runs.simulation
    from camdyn.outcome import Outcome

    real = camdyn.runs.simulation.simulate

    def stopping(*args, **kwargs):
        result = real(*args, **kwargs)
        result.outcome = Outcome.CHATTER
        return result

    monkeypatch.setattr(camdyn.runs.simulation, "simulate", stopping)
    out = tmp_path / "run.csv"
    assert main(["simulate", *QUICK, "--csv", str(out)]) == 3
    assert out.exists()
    assert "stopped early" in one_error_line(capsys, starts="camdyn: the run stopped early")


def test_missing_optional_parts_exit_4(monkeypatch, capsys):
    monkeypatch.setitem(sys.modules, "matplotlib", None)  # as if not installed
    assert main(["simulate", *QUICK, "--plot", "x.png"]) == 4
    assert 'pip install "camdyn[plot]"' in one_error_line(capsys)
    monkeypatch.setitem(sys.modules, "camdyn.studies", None)
    assert main(["reproduce", "fig10"]) == 4
    assert "camdyn.studies" in one_error_line(capsys)


def test_reproduce_lists_and_checks_study_names(capsys):
    pytest.importorskip("camdyn.studies")
    assert main(["reproduce", "--list"]) == 0
    assert "fig9" in capsys.readouterr().out
    assert main(["reproduce", "fig99"]) == 2
    assert "did you mean 'fig9'" in one_error_line(capsys)


def test_backend_option_reaches_simulate(monkeypatch, capsys):
    import camdyn.runs.simulation

    real = camdyn.runs.simulation.simulate
    seen = []

    def spy(*args, **kwargs):
        seen.append(kwargs.get("backend"))
        return real(*args, **kwargs)

    monkeypatch.setattr(camdyn.runs.simulation, "simulate", spy)
    assert main(["simulate", *QUICK, "--backend", "python"]) == 0
    assert seen == ["python"]

def test_internal_errors_are_one_line_exit_5_and_traceback_on_request(monkeypatch, capsys):
    def broken(args):
        raise RuntimeError("boom")

    monkeypatch.setattr(model, "cmd_scenes", broken)
    assert main(["scenes"]) == 5
    line = one_error_line(capsys, starts="camdyn: internal error")
    assert "boom" in line and "--traceback" in line
    assert main(["--traceback", "scenes"]) == 5
    assert "Traceback (most recent call last)" in capsys.readouterr().err


def test_interrupt_exits_130(monkeypatch, capsys):
    def interrupted(args):
        raise KeyboardInterrupt

    monkeypatch.setattr(model, "cmd_scenes", interrupted)
    assert main(["scenes"]) == 130
    assert capsys.readouterr().err.strip() == "camdyn: interrupted"


def test_a_closed_pipe_is_quiet():
    proc = subprocess.run(f"{sys.executable} -m camdyn.cli scenes | head -1", shell=True, capture_output=True,
                          text=True)
    assert proc.stdout.startswith("generated scenes") and proc.stderr == ""


def test_console_script_exit_code_and_no_traceback():
    proc = subprocess.run([sys.executable, "-m", "camdyn.cli", "simulate", "--speed-rpm", "1e9"],
                          capture_output=True, text=True)
    assert proc.returncode == 2
    assert proc.stderr.count("\n") == 1 and "Traceback" not in proc.stderr
    assert proc.stdout == ""


def test_parse_values():
    assert common._parse_values("1:3:3", "x") == [1.0, 2.0, 3.0]
    assert common._parse_values("1,10", "x") == [1.0, 10.0]
    assert np.allclose(common._parse_values("1:100:3:log", "x"), [1, 10, 100])
    for bad in ("", "1:2", "1:2:0", "a,b", "0:1:3:log", "1:2:3:lin"):
        with pytest.raises(common.UsageError):
            common._parse_values(bad, "x")


# ------------------------------------------------------------------ issue 14: messages (D)
@pytest.fixture
def no_simulation(monkeypatch):
    """simulate() fails the test if called: the command must stop before any work."""
    import camdyn.runs.simulation

    def forbidden(*args, **kwargs):
        raise AssertionError("simulate() was called: the error should come before any work")

    monkeypatch.setattr(camdyn.runs.simulation, "simulate", forbidden)


def test_a_cam_at_rest_asks_for_t_end_not_revolutions(capsys, no_simulation):
    assert main(["simulate", "--speed-rpm", "0"]) == 2
    line = one_error_line(capsys)
    assert "--speed-rpm 0 holds the cam still" in line and "--t-end" in line
    assert "out of range" not in line  # was: "revolutions = 3.0 is out of range: must be t_end (s)..."


def test_a_cam_at_rest_runs_for_t_end(capsys):
    assert main(["simulate", "--speed-rpm", "0", "--t-end", "0.005", "--sample-rate-Hz", "2000"]) == 0
    assert "11 samples" in capsys.readouterr().out  # 0.005 s at 2 kHz, both ends


@pytest.mark.parametrize("argv, words", [
    (["simulate", "--speed-rpm", "300", "--rig", "exmaple"], ["--rig exmaple", "did you mean 'example'"]),
    (["simulate", "--speed-rpm", "300", "--method", "Radau"],
     ["invalid choice: 'Radau'", "'DOP853'", "'RK45'"]),
    (["simulate", "--speed-rpm", "300", "--method", "RK54"], ["did you mean 'RK45'", "camdyn simulate --help"]),
    (["simulate", "--speed-rpm", "300", "--backend", "scipy"], ["invalid choice: 'scipy'", "'compiled', 'python'"]),
    (["simulate", "--speed-rpm", "300", "--damping", "d"], ["did you mean 'D'"]),
    (["simulate", "--speed-rpmm", "300"], ["unrecognized option --speed-rpmm", "did you mean --speed-rpm?",
                                           "see 'camdyn simulate --help'"]),
    (["sweep", "--speeds", "1000", "--transient-revs", "3"], ["did you mean --transient-revolutions?",
                                                              "see 'camdyn sweep --help'"]),
])
def test_messages_name_the_option_suggest_and_point_at_the_commands_help(argv, words, capsys, no_simulation):
    assert main(argv) == 2
    line = one_error_line(capsys)
    for w in words:
        assert w in line
    assert "is not a real number" not in line  # a name is not a number


def test_solver_names_come_from_the_engine():
    """The CLI's backends and methods are the engine's (one helper), not a list of its own."""
    from camdyn.engine.tableau import TABLEAUS
    from camdyn.engine import BACKENDS

    backends, methods = options._solvers()
    assert tuple(backends) == tuple(BACKENDS) and set(methods) == set(TABLEAUS)
    help_text = app._parser().parse_args.__self__.commands["simulate"].format_help()
    for name in (*backends, *methods):
        assert name in help_text


# ------------------------------------------------------------------ file formats, checked first (E)
@pytest.mark.parametrize("flag, name, words", [
    ("--plot", "run.jpgx", "matplotlib cannot write .jpgx figures"),
    ("--netcdf", "run.csv", "a NetCDF file name ends in .nc"),
    ("--csv", "run.nc", "a CSV file name ends in .csv"),
])
def test_output_formats_are_checked_before_the_run(flag, name, words, tmp_path, capsys, no_simulation):
    pytest.importorskip("matplotlib")
    assert main(["simulate", *QUICK, flag, str(tmp_path / name)]) == 2
    line = one_error_line(capsys)
    assert line.startswith(f"camdyn: error: {flag} ") and words in line
    assert not list(tmp_path.iterdir())


def test_a_plot_with_no_ending_is_a_png_and_says_so(tmp_path, capsys):
    pytest.importorskip("matplotlib")
    assert main(["simulate", "--speed-rpm", "300", "--revolutions", "0.05", "--sample-rate-Hz", "2000",
                 "--plot", str(tmp_path / "runnoext")]) == 0
    written = tmp_path / "runnoext.png"
    assert written.read_bytes()[:8] == PNG
    assert f"wrote {written}" in capsys.readouterr().out


@pytest.mark.parametrize("name, words", [
    ("image.png", "a saved run is a .csv or .nc file"),
    ("image.csv", "not a text file"),
    ("image.nc", "not a NetCDF file"),
])
def test_spectrum_input_must_be_a_saved_run(name, words, tmp_path, capsys):
    path = tmp_path / name
    path.write_bytes(PNG + bytes(range(256)))  # a PNG, whatever its name
    assert main(["spectrum", "--input", str(path)]) == 2
    line = one_error_line(capsys)
    assert words in line and "codec" not in line


# ------------------------------------------------------------------ values with a minus sign (F)
def test_ranges_may_start_with_a_minus_sign(capsys):
    args = app._parser().parse_args(["sweep", "--speeds", "-1500:-1200:2"])
    assert common._parse_values(args.speeds, "--speeds") == [-1500.0, -1200.0]
    assert main(["contact-loss", "--k-s", "-500:8000:5:log"]) == 2
    assert "a log range needs positive ends" in one_error_line(capsys)  # read, then refused with the reason
    assert main(["contact-loss", "--k-s", "-500,8000"]) == 2
    assert "--k-s -500.0 is out of range" in one_error_line(capsys)   # told by the flag the user typed


# ------------------------------------------------------------------ whole periods after the transient (G)
def test_spectrum_keeps_every_whole_period_after_the_transient(capsys):
    """1100 rev/min at 5 kHz is 272.7 samples per revolution: 4 revolutions less 1 are 3 periods
    to within a sample, which used to be rounded down to 2."""
    assert main(["spectrum", "--speed-rpm", "1100", "--revolutions", "4", "--transient-revolutions", "1",
                 "--sample-rate-Hz", "5000", "--peaks", "1"]) == 0
    out = capsys.readouterr().out
    assert "(3 cam periods" in out
    samples = int(out.split("spectrum of alpha: ")[1].split(" samples")[0])
    assert abs(samples - 3 * 5000 * 60 / 1100) <= 1


# ------------------------------------------------------------------ one name, honest help (H)
def test_simulate_and_sweep_save_netcdf_with_the_same_option():
    for argv in (["simulate", "--speed-rpm", "1", "--netcdf", "a.nc"], ["sweep", "--speeds", "1", "--netcdf", "a.nc"]):
        args = app._parser().parse_args(argv)
        assert (args.netcdf if argv[0] == "simulate" else args.out) == "a.nc"


@pytest.mark.parametrize("argv", [
    ["sweep", "--speeds", "1300", "--revolutions", "2", "--transient-revolutions", "1"],
    ["sweep", "--speeds", "1300", "--param", "k_s", "--values", "2000", "--revolutions", "2",
     "--transient-revolutions", "1", "--samples-per-revolution", "8"],
    ["simulate", "--speed-rpm", "1300", "--revolutions", "2", "--sample-rate-Hz", "1000"],
    ["lyapunov", "--speed-rpm", "1300", "--revolutions", "2", "--transient-revolutions", "0", "--batches", "2"]])
def test_every_command_that_runs_the_engine_takes_every_solver_option(argv, capsys):
    """The solver options are built in one place for every command (the sweep once dropped
    --max-step and --max-events): one switch allowed stops the run as MAX_EVENTS."""
    code = main(["--no-progress", *argv, "--max-events", "1"])
    out, err = capsys.readouterr()
    if argv[0] == "sweep":
        assert code == 3 and "1 MAX_EVENTS" in out, out
    elif argv[0] == "simulate":
        assert code == 3 and ": MAX_EVENTS (more regime switches than" in out, out
    else:   # the exponents need the whole run: refused as bad input
        assert code == 2 and "more regime switches than EventSettings.max_events" in err, err


def _help(command, capsys):
    with pytest.raises(SystemExit):
        main([command, "--help"])
    return " ".join(capsys.readouterr().out.split())


def test_backend_and_method_help_state_the_real_defaults_and_names(capsys):
    text = _help("simulate", capsys)
    backends, methods = options._solvers()
    for command in ("simulate", "sweep"):
        text = " ".join(_help(command, capsys).split())
        assert f"(default: {options._default_backend()};" in text and "{default_backend}" not in text
        assert f"{', '.join(backends)} (default" in text and f"{', '.join(methods)} (default: DOP853)" in text


def test_cache_lists_and_clears_only_what_it_is_asked_to(tmp_path, monkeypatch, capsys):
    """`camdyn cache` lists the per-user cache folders; --clear-stale keeps the current one."""
    from camdyn.engine import cache

    monkeypatch.setenv("CAMDYN_CACHE_DIR", str(tmp_path))
    (tmp_path / cache.engine_key() / "numba").mkdir(parents=True)
    (tmp_path / cache.engine_key() / "numba" / "x.nbi").write_bytes(b"0" * 1000)
    (tmp_path / "0.0.1-oldengine").mkdir()
    assert main(["cache"]) == 0
    out = capsys.readouterr().out
    assert str(tmp_path) in out and f"{cache.engine_key()}" in out and "current" in out and "stale" in out
    assert main(["cache", "--clear-stale"]) == 0
    assert [p.name for p in tmp_path.iterdir()] == [cache.engine_key()]
    assert main(["cache", "--clear"]) == 0
    assert list(tmp_path.iterdir()) == []


def test_a_compiled_run_writes_nothing_inside_the_package():
    """Issue 12 (8): numba's cache goes to the per-user folder, not next to camdyn's files."""
    from pathlib import Path

    import camdyn.generated

    camdyn.simulate(camdyn.example_rig(), camdyn.Scene(), speed_rpm=300, t_end=1e-3)
    for root in (Path(camdyn.__file__).parent, Path(camdyn.generated.__file__).parent):
        assert not [p for p in root.rglob("*") if p.suffix in (".nbi", ".nbc")], root


def test_warnings_print_as_one_note_line_not_python_source(capsys, monkeypatch):
    """A CompileNotice (or any warning) on the command line: `camdyn: note: ...`, no file and line."""
    import warnings

    import camdyn.model.presets

    def noisy():
        warnings.warn("compiling, once", camdyn.CompileNotice)
        return ["example"]
    monkeypatch.setattr(camdyn.model.presets, "available", noisy)
    assert main(["scenes"]) == 0
    err = capsys.readouterr().err
    assert "camdyn: note: compiling, once" in err and ".py:" not in err


# ------------------------------------------------------------------ messages in the command's own terms (issue 25)
@pytest.mark.parametrize("argv, starts", [
    (["lyapunov", "--speed-rpm", "0"], "camdyn: error: --speed-rpm is zero: must be nonzero"),
    (["lyapunov", "--speed-rpm", "300", "--transient-revolutions", "-1"], "camdyn: error: --transient-revolutions -1"),
    (["lyapunov", "--speed-rpm", "300", "--revolutions", "10", "--batches", "3"], "camdyn: error: --revolutions 10"),
    (["continue", "--start", "0", "--end", "100"], "camdyn: error: --end 100"),
    (["continue", "--start", "1600", "--end", "1700", "--min-arclength-step", "0"],
     "camdyn: error: --min-arclength-step 0"),
    (["sweep", "--speeds", "600:1500:0"], "camdyn: error: --speeds 600:1500:0: the count (the third field) must be "
                                          "at least 1, got 0"),
])
def test_an_error_names_the_option_the_user_typed(argv, starts, capsys):
    """A library parameter's error is told by the command's flag (--transient-revolutions, not the
    library's 'transient'), with what is wrong."""
    assert main(argv) == 2
    line = one_error_line(capsys)
    assert line.startswith(starts), line


def _words_left(text: str) -> list[str]:
    """The library's option names (snake_case words) left in a message after _in_flags."""
    import re
    return re.findall(r"(?<![-\w.=])[a-z][a-z0-9]*(?:_[a-zA-Z0-9]+)+(?![\w(])", text)


@pytest.mark.parametrize("command, extra", [("continue", ["--start", "1", "--end", "2"]),
                                            ("simulate", ["--speed-rpm", "100"]),
                                            ("lyapunov", ["--speed-rpm", "100"])])
def test_every_piece_of_advice_a_command_prints_is_one_of_its_options(command, extra):
    """The outcomes a command can print (a branch's, its first orbit's, a run's) advise changing
    settings by the library's names; printed by the command they name its flags, which it has."""
    from camdyn.orbits.continuation import ContinuationOutcome
    from camdyn.orbits.shooting import OrbitOutcome
    from camdyn.outcome import Outcome
    args = app._parser().parse_args([command, *extra])
    enums = (ContinuationOutcome, OrbitOutcome, Outcome) if command == "continue" else (Outcome,)
    for enum in enums:
        for outcome in enum:
            text = common._in_flags(outcome.message, args)
            left = [w for w in _words_left(text) if w not in ("t_end", "n T")]
            assert not left, (command, outcome.name, left, text)
            assert "=camdyn" not in text and "='" not in text, (command, outcome.name, text)
    flags = args.flags
    for needed in ("min_arclength_step", "max_arclength_step", "switch_depth", "jacobian", "max_step", "max_events") \
            if command == "continue" else ("max_step", "max_events", "rtol", "atol", "friction"):
        assert needed in flags, (command, needed)


def test_continue_follows_period_two_to_four_with_switch_depth(capsys):
    """--switch-depth 2 switches at the period-2 branch's doubling too (the example rig: period 1 ->
    2 at 1710.2 rev/min, 2 -> 4 at 1798.8)."""
    assert main(["continue", "--start", "1700", "--end", "1810", "--switch-depth", "2"]) == 0
    out = capsys.readouterr().out
    assert "(period 2 T)" in out and "(period 4 T)" in out
