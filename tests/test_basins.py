"""Basins of attraction and coexisting attractors (issue 29): the initial-state axes of a sweep,
the labelling of attractors across a map, and a bistable case whose map holds both attractors.

The bistable case: the 16 mm experiment rig (preset ``reference-experiment``), damping D and
Coulomb friction, at 125 rev/min.  docs/reproduction.md (Figs. 7-8) continues its two period-1
branches: the contact orbit (permanent contact, grazing at 130.0 rev/min) and the flight orbit
(fold at 116.2 rev/min), both stable between them.  Measured for this test (benchmarks/basins.py,
10 x 10 starts over alpha* + [0, 0.5] rad x [-3, 3] rad/s): the static equilibrium and starts
near it with little rate reach the contact orbit, alpha = alpha* + 1e-9 rad at the section; starts
0.2 rad above it, or with 3 rad/s, reach the flight orbit, alpha = 0.4165 rad,
alpha_dot = -0.5185 rad/s at the section, largest Floquet multiplier 0.63.
"""
from __future__ import annotations

import math

import numpy as np
import pytest

import camdyn
from camdyn.errors import ParameterError
from camdyn.model.cam import ConstantSpeed
from camdyn.sweep import api as S
from camdyn.sweep.attractors import (CHAOTIC, NO_RUN, NOT_SETTLED, AttractorSection, LabelAttractors, attractor_table,
                                 basins)
from camdyn.sweep.spec import OUTCOME_CODES, SweepSpec

RIG = camdyn.load_rig("reference-experiment")
SCENE = camdyn.Scene(contact="line", damping="D", friction="coulomb")
SPEED = 125.0
A_STAR = camdyn.static_equilibrium(RIG).alpha


def first_state(result) -> dict:
    """A measure: the run's first sample."""
    return {"alpha_first": result.alpha[0], "alpha_dot_first": result.alpha_dot[0]}


def test_state_axes_set_each_points_start():
    ds = S.sweep(RIG, SCENE, {"alpha_start": [A_STAR, A_STAR + 0.1], "alpha_dot_start": [-1.0, 0.0, 2.0]},
                 first_state, speed_rpm=SPEED, t_end=1e-4, progress=False)
    a, ad = np.meshgrid(ds["alpha_start"].values, ds["alpha_dot_start"].values, indexing="ij")
    # the first sample is the start itself (t_start), not integrated: equal to the bit
    assert np.array_equal(ds["alpha_first"].values, a)
    assert np.array_equal(ds["alpha_dot_first"].values, ad)
    assert ds["alpha_start"].attrs["units"] == "rad" and ds["alpha_dot_start"].attrs["units"] == "rad/s"


def test_one_state_axis_takes_the_other_component_from_y0():
    ds = S.sweep(RIG, SCENE, {"alpha_dot_start": [0.5]}, first_state, speed_rpm=SPEED, t_end=1e-4,
                 y0=(A_STAR + 0.05, 9.0), progress=False)
    assert ds["alpha_first"].values[0] == A_STAR + 0.05 and ds["alpha_dot_first"].values[0] == 0.5
    with pytest.raises(ParameterError, match="y0"):
        S.sweep(RIG, SCENE, {"alpha_start": [A_STAR]}, first_state, speed_rpm=SPEED, t_end=1e-4, progress=False)


def test_basins_refuses_settings_it_sets():
    for bad in ({"y0": (A_STAR, 0.0)}, {"sample_rate_Hz": 10.0}, {"t_end": 1.0}):
        with pytest.raises(ParameterError):
            basins(RIG, SCENE, alpha=[A_STAR], alpha_dot=[0.0], speed_rpm=SPEED, progress=False, **bad)
    with pytest.raises(ParameterError, match="stop"):
        basins(RIG, SCENE, alpha=[A_STAR], alpha_dot=[0.0], speed_rpm=SPEED, stop=None, progress=False)


def _synthetic(rows):
    """A map of 2 x 4 starts with given (outcome, period, cycle alpha, cycle alpha_dot, lambda, se)
    per point, as the sweep assembles it, and its spec (nothing runs)."""
    import xarray as xr

    axes = {"alpha_start": np.array([0.3, 0.4]), "alpha_dot_start": np.array([0.0, 1.0, 2.0, 3.0])}
    spec = SweepSpec(RIG, SCENE, axes, AttractorSection(), {"cam": ConstantSpeed(SPEED)}, 1)
    width = max(len(r[2]) for r in rows)
    cyc = np.full((8, width, 2), np.nan)
    for i, r in enumerate(rows):
        cyc[i, :len(r[2]), 0], cyc[i, :len(r[3]), 1] = r[2], r[3]
    dims = ("alpha_start", "alpha_dot_start")
    ds = xr.Dataset({"outcome": (dims, np.array([r[0] for r in rows], dtype=np.int32).reshape(2, 4)),
                     "stop_period": (dims, np.array([r[1] for r in rows], dtype=float).reshape(2, 4)),
                     "cycle_alpha": (dims + ("cycle",), cyc[..., 0].reshape(2, 4, width)),
                     "cycle_alpha_dot": (dims + ("cycle",), cyc[..., 1].reshape(2, 4, width)),
                     "lyapunov": (dims, np.array([r[4] for r in rows]).reshape(2, 4)),
                     "lyapunov_se": (dims, np.array([r[5] for r in rows]).reshape(2, 4))},
                    coords={k: (k, v) for k, v in axes.items()})
    return ds, spec


OK, FAILED = OUTCOME_CODES["SUCCESS"], OUTCOME_CODES["ANGLE_LIMIT"]
NAN = math.nan
OMEGA = 2 * math.pi * SPEED / 60.0      # rad/s: alpha_dot's tolerance is tol * Omega_c
ROWS = [
    (OK, 1, [0.30], [-0.50], NAN, NAN),                          # attractor 0
    (OK, 1, [0.30 + 5e-7], [-0.50 + 5e-7 * OMEGA], NAN, NAN),     # within tol of 0 in both: 0
    (OK, 1, [0.30 + 5e-6], [-0.50], NAN, NAN),                   # 5 tol away in alpha: a new P1 (1)
    (OK, 2, [0.20, 0.35], [0.1, -0.2], NAN, NAN),                # a P2 (2)
    (OK, 2, [0.35, 0.20], [-0.2, 0.1], NAN, NAN),                # the same cycle in the other phase: 2
    (OK, 0, [0.1] * 8, [0.0] * 8, 0.5, 0.1),                     # lambda_1 5 se above 0: chaotic
    (OK, 0, [0.1] * 8, [0.0] * 8, 0.2, 0.1),                     # 2 se: not settled
    (FAILED, 0, [], [], NAN, NAN),                               # no run
]


def test_attractors_are_labelled_by_period_and_section_points():
    ds, spec = _synthetic(ROWS)
    out = LabelAttractors(tol=1e-6, chaos_se=3.0, confirm=False)(ds, spec)
    assert out["attractor"].values.ravel().tolist() == [0, 0, 1, 2, 2, CHAOTIC, NOT_SETTLED, NO_RUN]
    assert out["attractor_period"].values.tolist() == [1, 1, 2]
    assert out["attractor_points"].values.tolist() == [2, 1, 2]
    # the representative: the first point reaching it (C order over the grid)
    assert out["attractor_alpha"].values[1, 0] == 0.30 + 5e-6
    assert out.attrs["attractors"] == 3 and out["attractor"].attrs["flag_meanings"] == "chaotic not_settled no_run"
    rows = attractor_table(out)
    assert [r["id"] for r in rows] == [0, 1, 2, "chaotic", "not_settled", "no_run"]


def test_a_cycle_is_reduced_to_its_minimal_period_within_tol():
    """Seen on the 100 x 100 map at 125 rev/min (benchmarks/basins.py, before this reduction): 10
    of 10,000 runs stopped with stop_period 2 at the flight orbit (largest multiplier modulus
    0.63), labelled a P2 attractor whose first section point was 3e-11 rad from the P1 one and
    whose shooting orbit had multipliers of modulus 0.39 = 0.63^2: the P1 orbit counted twice.
    Within the map's tol such a cycle is the P1 attractor."""
    rows = [(OK, 1, [0.30], [-0.50], NAN, NAN),
            (OK, 2, [0.30 + 1e-7, 0.30 - 1e-7], [-0.50, -0.50 + 1e-7], NAN, NAN),      # P1 within tol
            (OK, 2, [0.30 + 4e-6, 0.30 - 4e-6], [-0.50, -0.50], NAN, NAN),             # a true P2
            (OK, 4, [0.2, 0.3, 0.2 + 1e-8, 0.3 + 1e-8], [0.1, 0.2, 0.1, 0.2], NAN, NAN)]  # a P2 as P4
    ds, spec = _synthetic(rows + [(FAILED, 0, [], [], NAN, NAN)] * 4)
    out = LabelAttractors(confirm=False)(ds, spec)
    assert out["attractor"].values.ravel().tolist()[:4] == [0, 0, 1, 2]
    assert out["attractor_period"].values.tolist() == [1, 2, 2]
    assert out["attractor_alpha"].values[2, :2].tolist() == [0.2, 0.3]


def test_the_measure_keeps_the_cycle_from_its_smallest_alpha():
    class Fake:
        ok, t = True, np.arange(10.0)
        q = np.array([0, 0, 0, 0, 0, 0, 0, 0.4, 0.2, 0.3])  # the follower's coordinate (Result.q: alpha here)
        q_dot = np.arange(10.0)
        stats = {"stop_period": 3}

    got = AttractorSection()(Fake(), None)
    assert got["cycle_alpha"][1].tolist() == [0.2, 0.3, 0.4] and got["cycle_alpha_dot"][1].tolist() == [8, 9, 7]


def test_basin_map_plot(tmp_path):
    pytest.importorskip("matplotlib")
    from camdyn.io import plots

    ds, spec = _synthetic(ROWS)
    fig = plots.basin_map(LabelAttractors(confirm=False)(ds, spec), title="synthetic")
    labels = [t.get_text() for t in fig.axes[0].get_legend().get_texts()]
    assert labels[:3] == ["attractor 0: P1, 25 % of starts", "attractor 1: P1, 12 % of starts",
                          "attractor 2: P2, 25 % of starts"]
    assert labels[3:] == ["chaotic", "not settled", "no run"]
    fig.savefig(tmp_path / "basins.png")


BISTABLE = dict(alpha=[A_STAR, A_STAR + 0.2], alpha_dot=[0.0, 3.0], speed_rpm=SPEED)


@pytest.fixture(scope="module")
def bistable(tmp_path_factory):
    """The 2 x 2 map at 125 rev/min, streamed to a file: (its Dataset, the file)."""
    out = tmp_path_factory.mktemp("basins") / "basins.nc"
    return basins(RIG, SCENE, **BISTABLE, out=out, progress=False), out


def test_bistable_map_holds_both_attractors(bistable):
    """The contact orbit and the flight orbit at 125 rev/min, both reached and both confirmed as
    stable period-1 orbits by shooting; the map streamed to a file reads back the same."""
    ds, out = bistable
    assert ds.attrs["attractors"] == 2
    codes = ds["attractor"].values
    contact, flight = codes[0, 0], codes[1, 0]          # from the equilibrium; from 0.2 rad above it
    assert contact != flight and set(codes.ravel()) == {contact, flight}
    assert ds["attractor_period"].values.tolist() == [1, 1]
    assert ds["attractor_confirmed"].values.tolist() == [1, 1]
    # the contact orbit rests on the cam: within its contact deflection (~1e-9 rad) of alpha*,
    # checked to 1e-6 rad (the map's tol); the flight orbit lifts 0.2057 rad above it
    assert abs(ds["attractor_alpha"].values[contact, 0] - A_STAR) < 1e-6
    assert ds["attractor_alpha"].values[flight, 0] - A_STAR > 0.1
    assert ds["attractor_orbit_multiplier"].values[flight] < 1.0
    saved = S.load_sweep(out)
    assert np.array_equal(saved["attractor"].values, codes)
    assert saved["attractor_alpha"].attrs["units"] == "rad"


def test_an_interrupted_map_resumed_equals_the_uninterrupted_one(bistable, tmp_path):
    """Ctrl-C after at most two of the four starts (one a chunk), then resume: the labels and the table
    are made from the assembled points, so they equal the uninterrupted map's, value for value."""
    import xarray as xr
    from sweep_faults import InterruptAfter

    out = tmp_path / "basins.nc"
    with InterruptAfter(2) as executor, pytest.raises(KeyboardInterrupt):
        basins(RIG, SCENE, **BISTABLE, out=out, executor=executor, chunksize=1, progress=False)
    # the interrupt lands when the third task is submitted: one or two chunks have finished
    assert not out.exists() and 1 <= len(list((tmp_path / "basins.nc.parts" / "chunks").glob("*.nc"))) <= 2
    xr.testing.assert_identical(S.resume(out, progress=False), bistable[0])


def test_a_chaotic_start_is_judged_by_its_lyapunov_exponent():
    """196 rev/min, tests/test_chaos.py's chaotic case: two runs 1e-9 rad apart separate by
    e^0.62 per revolution there, lambda_1 ~ 0.62 * 196 / 60 = 2.0 1/s.  60 revolutions do not
    settle, and lambda_1 over 60 more is positive by more than 3 standard errors (measured:
    2.2 +- 0.3 and 2.5 +- 0.3 1/s from the two starts)."""
    ds = basins(RIG, SCENE, alpha=[A_STAR, A_STAR + 0.1], alpha_dot=[0.0], speed_rpm=196.0, revolutions=60,
                lyapunov_revolutions=60, progress=False)
    assert (ds["stop_period"].values == 0).all()
    assert (ds["attractor"].values == CHAOTIC).all()
    # e^0.62 per revolution (median of 10 starts, range 0.39-1.04: tests/test_chaos.py) in 1/s
    assert (ds["lyapunov"].values > 0.39 * 196 / 60 / 2).all() and (ds["lyapunov"].values < 1.04 * 196 / 60 * 2).all()
    assert ds.attrs["attractors"] == 0 and "attractor_period" not in ds


def test_attractors_at_different_speeds_are_different():
    """A (speed, initial condition) map: the same section point at two speeds is two attractors,
    each with its speed in the table."""
    import xarray as xr

    axes = {"speed_rpm": np.array([120.0, 125.0]), "alpha_start": np.array([0.3]),
            "alpha_dot_start": np.array([0.0, 1.0])}
    spec = SweepSpec(RIG, SCENE, axes, AttractorSection(), {}, 1)
    dims = tuple(axes)
    ds = xr.Dataset({"outcome": (dims, np.zeros((2, 1, 2), dtype=np.int32)),
                     "stop_period": (dims, np.ones((2, 1, 2))),
                     "cycle_alpha": (dims + ("cycle",), np.full((2, 1, 2, 1), 0.4)),
                     "cycle_alpha_dot": (dims + ("cycle",), np.full((2, 1, 2, 1), -0.5)),
                     "lyapunov": (dims, np.full((2, 1, 2), np.nan)),
                     "lyapunov_se": (dims, np.full((2, 1, 2), np.nan))}, coords=axes)
    out = LabelAttractors(confirm=False)(ds, spec)
    assert out["attractor"].values.ravel().tolist() == [0, 0, 1, 1]
    assert out["attractor_speed_rpm"].values.tolist() == [120.0, 125.0]
    assert out["attractor_speed_rpm"].attrs["units"] == "rev/min"


def test_the_basins_command_prints_the_attractor_table(tmp_path, capsys):
    pytest.importorskip("matplotlib")
    from camdyn.cli.app import main

    nc, png = tmp_path / "b.nc", tmp_path / "b.png"
    assert main(["--no-progress", "basins", "--rig", "reference-experiment", "--speed-rpm", "125",
                 "--from-equilibrium", "--alpha", "0,0.2", "--alpha-dot", "0", "--no-confirm",
                 "--netcdf", str(nc), "--plot", str(png)]) == 0
    out = capsys.readouterr().out
    assert "2 starts, 2 attractors" in out and "attractor 1: P1" in out
    assert nc.is_file() and png.is_file()
    assert main(["--no-progress", "sweep", "--resume", str(nc)]) == 0      # a finished map reads back
    assert "2 attractors" in capsys.readouterr().out


def test_two_run_estimates_must_agree_for_a_chaotic_verdict():
    """Damping C and E: lambda_1 by two neighbouring runs at two distances (lyapunov and
    lyapunov_check); a start is chaotic only where both are above chaos_se standard errors
    (camdyn.orbits.lyapunov.verdict), else not settled."""
    ds, spec = _synthetic(ROWS)
    check = ds["lyapunov"].values.copy()
    check[1, 1] = 0.1                        # the chaotic row's second estimate: 1 se, no verdict
    ds["lyapunov_check"] = (("alpha_start", "alpha_dot_start"), check)
    codes, _ = LabelAttractors().label(ds, spec)
    assert codes[5] == NOT_SETTLED
    ds["lyapunov_check"] = ds["lyapunov"]
    assert LabelAttractors().label(ds, spec)[0][5] == CHAOTIC


def test_a_chaotic_start_under_damping_C_gets_its_exponent_from_two_runs():
    """Damping C cannot run the tangent dynamics past first contact: the exponent of a start that
    does not settle comes from two neighbouring runs (tests/test_lyapunov.py measured 1.59 +- 0.28
    1/s at 196 rev/min over 100 revolutions), and the start is chaotic where both distances agree."""
    scene = camdyn.Scene(contact="line", damping="C", friction="coulomb")
    ds = basins(RIG, scene, alpha=[A_STAR], alpha_dot=[0.0], speed_rpm=196.0, revolutions=60,
                lyapunov_revolutions=60, progress=False)
    assert (ds["stop_period"].values == 0).all()
    assert np.isfinite(ds["lyapunov"].values).all() and np.isfinite(ds["lyapunov_check"].values).all()
    assert (ds["attractor"].values == CHAOTIC).all()
