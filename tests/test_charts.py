"""Design charts (issue 29): the two-parameter continuation of the grazing orbit
(camdyn.orbits.continuation.continue_grazing) and the jump chart built on it.

The case: the example rig with a 16 mm line contact (stiff: its contact-loss speed moves by
only -2.3e-6 of itself for the contact's compliance, camdyn.analysis.compliance_shift), damping
D, Coulomb friction, the jump speed against k_s from 2000 to 2400 N/m (24 grazing orbits, ~5 s
here).  Measured while writing it: the grazing speed lies below the inverse-kinematics
contact-loss speed by 2.23e-6 to 2.69e-6 of it, against the first-order compliance shift of
2.30e-6 to 2.76e-6: the remainder, 7e-8, is 3 % of the shift.
"""
from __future__ import annotations


import numpy as np
import pytest

import camdyn
from camdyn.analysis.statics import contact_loss_speed
from camdyn.errors import ParameterError
from camdyn.orbits.continuation import (EVENTS, ContinuationSettings, GrazingOutcome, GrazingSettings,
                                        continue_grazing, continue_orbit, jump_chart)

RIG = camdyn.example_rig().replace(l_lambda=0.016)
SCENE = camdyn.Scene(contact="line", damping="D", friction="coulomb")
K_S = (2000.0, 2400.0)


pytestmark = pytest.mark.usefixtures("quiet_compile")  # (tests/conftest.py)


@pytest.fixture(scope="module")
def chart():
    return jump_chart(RIG, SCENE, "k_s", *K_S)


def test_the_chart_reaches_its_end_and_describes_itself(chart):
    assert chart.attrs["outcome"] == GrazingOutcome.END_REACHED.name, chart.attrs["outcome_message"]
    k = chart["k_s"].values
    assert k[0] == K_S[0] and k[-1] == pytest.approx(K_S[1], rel=1e-9) and np.all(np.diff(k) > 0)
    assert chart["speed_rpm"].attrs["units"] == "rev/min" and chart["k_s"].attrs["units"] == "N/m"
    assert chart.attrs["free"] == "speed_rpm" and chart.attrs["parameter"] == "k_s"
    assert chart.attrs["rig_k_s"] == RIG.k_s and chart.attrs["scene"] == SCENE.slug and chart.attrs["camdyn_version"]
    # every orbit is on the contact side of the grazing, converged at psi_i(t_g) within [-3, -1]
    # gap_tol d (GAP_MARGINS gap_tol d, +- the corrector's tolerance; half a unit more for the largest
    # gap's sampled estimate)
    from camdyn.orbits.continuation.boundary import GAP_MARGINS as MARGIN

    unit = chart.attrs["settings_gap_tol"] * chart.attrs["deflection_scale_m"]
    gap = chart["grazing_gap"].values
    assert np.all(gap < -(MARGIN - 1.5) * unit) and np.all(gap >= -(MARGIN + 1.5) * unit)
    assert np.all(chart["residual"].values <= chart.attrs["settings_tol"])


def test_the_jump_speed_meets_the_quasi_static_limit_on_a_stiff_contact(chart):
    """The inverse kinematics neglect the contact's deflection: on a stiff contact the grazing
    speed is the contact-loss speed shifted by the compliance, whose first-order estimate is
    compliance_shift (its derivation: camdyn.analysis.statics).  The quasi-static error left
    after that shift is of higher order; it is held below a tenth of the shift (measured: 3 %).
    A grazing speed off by the margin's own bias (~5e-7 of it, before the zero-gap step) or by the
    shift's size fails."""
    ratio = chart["speed_rpm"].values / chart["contact_loss_rpm"].values - 1.0
    shift = chart["compliance_shift"].values
    assert np.all(ratio < 0)                                     # a compliant contact lets go earlier
    assert np.max(np.abs(ratio - shift) / np.abs(shift)) < 0.1
    # the contact-loss speed is the inverse kinematics' at each point's k_s
    assert chart["contact_loss_rpm"].values[-1] == contact_loss_speed(RIG.replace(k_s=chart["k_s"].values[-1]))


@pytest.mark.parametrize("k_s", K_S)
def test_the_curve_meets_the_one_parameter_grazing(chart, k_s):
    """At either end of the curve (k_s fixed there), continue_orbit in the speed locates the same
    grazing: its bracket is locate_tol of its range in arclength (2e-4 rev/min here), and its event
    is the orbit just past the grazing, so the two agree to twice that."""
    loss = contact_loss_speed(RIG.replace(k_s=k_s))
    settings = ContinuationSettings(switch_depth=0)
    lo, hi = 0.9 * loss, 1.1 * loss
    ds = continue_orbit(RIG.replace(k_s=k_s), SCENE, "speed_rpm", lo, hi, phase_fraction=0.5, settings=settings)
    graze = [float(lam) for kind, lam in zip(ds["event_kind"].values, ds["event_lambda"].values)
             if EVENTS[kind] == "grazing"]
    assert graze, ds.attrs["branch_0_message"]
    i = int(np.argmin(np.abs(chart["k_s"].values - k_s)))
    assert chart["k_s"].values[i] == pytest.approx(k_s, rel=1e-9)
    tol = 2 * settings.locate_tol * (hi - lo)
    assert abs(chart["speed_rpm"].values[i] - graze[0]) <= tol


def test_the_multipliers_at_grazing_are_the_contact_orbits(chart):
    """The contact side's Floquet multipliers: a stiff, damped contact contracts by ~1e-12 per
    revolution; no codimension-2 point on this stretch."""
    assert np.all(chart["multiplier_modulus"].values < 1e-6) and np.all(chart["stable"].values)
    assert chart.sizes["codim2"] == 0


@pytest.mark.parametrize("kwargs, name, valid", [
    (dict(parameter="k_z"), "parameter", "a rig parameter"),
    (dict(end=2000.0), "end", "other than start"),
    (dict(free="k_s"), "free", "other than parameter"),
    (dict(search=(900.0,)), "search", "(low, high)"),
    (dict(search=(900.0, 900.0)), "search", "low != high"),
    (dict(scene=camdyn.Scene(contact="line", damping="D", friction="coulomb", motion="oscillating")), "scene",
     "constant speed"),
    (dict(speed_rpm=1000.0), "speed_rpm", "None"),
    (dict(settings=ContinuationSettings()), "settings", "GrazingSettings"),
])
def test_bad_input_names_the_parameter_and_its_range(kwargs, name, valid):
    args = dict(rig=RIG, scene=SCENE, parameter="k_s", start=2000.0, end=2400.0, search=(900.0, 1100.0))
    args.update(kwargs)
    with pytest.raises(ParameterError) as info:
        continue_grazing(**args)
    assert info.value.name == name and valid in str(info.value)


def test_two_rig_parameters_need_a_speed_and_the_chart_a_rig_parameter():
    with pytest.raises(ParameterError, match="speed_rpm"):
        continue_grazing(RIG, SCENE, "k_s", 2000.0, 2400.0, free="L_us", search=(0.1, 0.12))
    with pytest.raises(ParameterError, match="parameter"):
        jump_chart(RIG, SCENE, "speed_rpm", 900.0, 1000.0)
    with pytest.raises(ParameterError, match="gap_tol"):
        GrazingSettings(gap_tol=0.5)
    for threads in (0, 1.5, True):
        with pytest.raises(ParameterError, match="threads"):
            GrazingSettings(threads=threads)


def test_threads_run_the_same_curve_bit_for_bit():
    """A point's independent runs (the tangent dynamics and the two parameter differences) on two
    threads (GrazingSettings.threads) are the runs made in turn: the same curve, to the bit."""
    curves = [jump_chart(RIG, SCENE, "k_s", 2000.0, 2060.0, settings=GrazingSettings(threads=n)) for n in (1, 2)]
    assert curves[0].sizes["point"] >= 3
    for name in ("speed_rpm", "k_s", "alpha", "alpha_dot", "grazing_gap", "multiplier_real", "multiplier_imag"):
        np.testing.assert_array_equal(curves[0][name].values, curves[1][name].values)


def test_no_grazing_in_the_search_range_ends_the_curve_at_its_start():
    """Below the contact-loss speed the branch never grazes: the curve says so, with no point."""
    ds = continue_grazing(RIG, SCENE, "k_s", 2000.0, 2400.0, search=(800.0, 850.0))
    assert ds.attrs["outcome"] == GrazingOutcome.START_FAILED.name and ds.sizes["point"] == 0
    assert "no grazing" in ds.attrs["outcome_message"]


def test_the_chart_plots_and_saves(chart, tmp_path):
    pytest.importorskip("matplotlib")
    from camdyn.io import plots

    fig = plots.jump_chart(chart, title="jump chart")
    assert len(fig.axes) == 2                                   # the chart, and the quasi-static panel
    assert fig.axes[0].get_ylabel() == "jump speed (rev/min)" and fig.axes[1].get_xlabel() == "k_s (N/m)"
    fig.savefig(tmp_path / "chart.png")
    path = tmp_path / "chart.nc"
    chart.to_netcdf(path, engine="scipy")
    import xarray as xr
    with xr.open_dataset(path, engine="scipy") as back:
        assert np.array_equal(back["speed_rpm"].values, chart["speed_rpm"].values)
        assert back.attrs["outcome"] == chart.attrs["outcome"]


def test_the_chart_command_prints_csv_and_writes_files(tmp_path, capsys):
    from camdyn.cli.app import main

    nc, png = tmp_path / "jump.nc", tmp_path / "jump.png"
    code = main(["--no-progress", "chart", "--param", "k_s", "--start", "2000", "--end", "2040", "--contact", "line",
                 "--damping", "D", "--friction", "coulomb", "--netcdf", str(nc)]
                + (["--plot", str(png)] if _has_matplotlib() else []))
    out = capsys.readouterr().out
    assert code == 0, out
    rows = [line.split(",") for line in out.splitlines() if line[:1].isdigit()]
    assert float(rows[0][0]) == 2000.0 and float(rows[-1][0]) == pytest.approx(2040.0)
    assert all(float(r[1]) < float(r[2]) for r in rows)          # the jump below the quasi-static limit
    assert nc.exists() and (png.exists() or not _has_matplotlib())
    assert main(["chart", "--param", "k_s", "--start", "2000", "--end", "2000"]) == 2


def _has_matplotlib() -> bool:
    try:
        import matplotlib  # noqa: F401
    except ImportError:
        return False
    return True


def test_a_multiplier_through_minus_one_at_grazing_is_located_in_arclength(monkeypatch):
    """The codimension-2 locator on a curve of made-up orbits whose multiplier at grazing is
    -1 + 3 (s - s*) along the arclength s: found, named, and within locate_tol of s*; the
    multiplier through +1 (det(M - I)) changes sign nowhere here and is not reported."""
    from camdyn.orbits.continuation import grazing_curve as C

    root, settings = 0.0123, ContinuationSettings(locate_tol=1e-6)

    def orbit(s: float):
        M = np.diag([-1.0 + 3.0 * (s - root), 0.5])
        return C.GrazingPoint(np.full(5, s), 1000.0 + s, 2000.0 + s, np.zeros(2), 0.5, M, np.eye(5)[4], None, None,
                              1, 1000.0 + s, np.zeros(5), np.nan)
    monkeypatch.setattr(C, "step", lambda leg, p, s, final=False: orbit(float(p.z[0]) + s))
    leg = C.Leg(None, None, settings)
    found = C.located(leg, orbit(0.0), orbit(0.03), 0.03, 7)
    assert [f.kind for f in found] == ["grazing_period_doubling"] and found[0].point == 7
    assert abs(float(found[0].at.z[0]) - root) <= settings.locate_tol
    assert C.located(leg, orbit(0.0), orbit(0.01), 0.01, 7) == []          # no sign change before s*


def test_two_rig_parameters_at_a_fixed_speed_keep_the_jump_at_that_speed():
    """The grazing curve in (L_us, k_s) at 1000 rev/min: at every point the rig's jump speed is
    1000 rev/min, so its inverse-kinematics contact-loss speed is 1000 rev/min less the compliance
    shift (as in the chart above, to a tenth of the shift)."""
    from camdyn.analysis.statics import compliance_shift

    ds = continue_grazing(RIG, SCENE, "k_s", 2000.0, 2100.0, free="L_us", speed_rpm=1000.0,
                          search=(1.02 * RIG.L_us, 0.98 * RIG.L_us))
    assert ds.attrs["outcome"] == GrazingOutcome.END_REACHED.name, ds.attrs["outcome_message"]
    assert ds["L_us"].attrs["units"] == "m" and np.all(np.diff(ds["L_us"].values) < 0)   # stiffer: less preload
    for L_us, k_s in zip(ds["L_us"].values[::6], ds["k_s"].values[::6]):
        rig = RIG.replace(L_us=float(L_us), k_s=float(k_s))
        ratio, shift = 1000.0 / contact_loss_speed(rig) - 1.0, compliance_shift(rig, SCENE)
        assert abs(ratio - shift) < 0.1 * abs(shift)


@pytest.mark.parametrize("kind, rig, search, window", [
    ("period_doubling", camdyn.example_rig(), (1650.0, 1750.0), (1700.0, 1850.0)),
    ("fold", RIG, (1600.0, 900.0), (1600.0, 900.0)),
])
def test_the_fold_and_period_doubling_curves_meet_the_one_parameter_ones(kind, rig, search, window):
    """The curve of a period doubling (example rig, 1.6 mm line contact: 1710.2 rev/min at k_s =
    2000) and of a fold (16 mm: the impacting branch turns back at 1289.6 rev/min) in (speed, k_s)
    up to k_s = 2200: the critical multiplier is -1 or +1 within DET_TOL along it, and at its end
    continue_orbit in speed locates the same bifurcation to twice its bracket (measured: 6e-5 and
    7e-7 rev/min)."""
    from camdyn.orbits.continuation import continue_bifurcation
    from camdyn.orbits.continuation.codim1 import DET_TOL, SIGNS

    ds = continue_bifurcation(rig, SCENE, kind, "k_s", 2000.0, 2200.0, search=search)
    assert ds.attrs["outcome"] == GrazingOutcome.END_REACHED.name, ds.attrs["outcome_message"]
    assert ds["k_s"].values[-1] == 2200.0
    critical = ds["multiplier_real"].values[:, 0]
    assert np.all(np.abs(critical + SIGNS[kind]) < 10 * DET_TOL) and np.all(ds["multiplier_imag"].values == 0)
    settings = ContinuationSettings(switch_depth=0)
    branch = continue_orbit(rig.replace(k_s=2200.0), SCENE, "speed_rpm", *window, settings=settings)
    located = [float(lam) for k, lam in zip(branch["event_kind"].values, branch["event_lambda"].values)
               if EVENTS[k] == kind]
    assert located, branch.attrs["branch_0_message"]
    assert abs(ds["speed_rpm"].values[-1] - located[0]) <= 2 * settings.locate_tol * abs(window[1] - window[0])


def test_a_largest_gap_within_the_correctors_tolerance_is_the_grazing_one():
    """The grazing orbit is converged with psi_i(t_g) in [-3, -1] gap_tol d (boundary.GAP_MARGINS):
    another sample's gap up to +gap_tol d is the same maximum or noise (a stiff contact's psi_i
    noise, ~1e-17 m on reference-experiment, once ended the jump chart as a double grazing);
    beyond +gap_tol d another maximum has overtaken it."""
    from types import SimpleNamespace

    from camdyn.orbits.continuation.grazing import is_largest

    system = SimpleNamespace(gap_tol=1e-6, deflection=4.7e-10)
    unit = system.gap_tol * system.deflection
    assert is_largest(system, SimpleNamespace(max_gap=-unit)) and is_largest(system, SimpleNamespace(max_gap=1.9e-17))
    assert not is_largest(system, SimpleNamespace(max_gap=1.5 * unit))


def test_a_step_whose_orbit_has_no_contact_side_difference_is_retried_shorter(monkeypatch):
    """A corrected orbit whose parameter differences lift off on both sides at every step
    (Unresolved: an orbit at the grazing's noise) is a failed step (None: follow() halves it),
    not the curve's end; a derivative that cannot be evaluated at all still ends it."""
    from types import SimpleNamespace

    from camdyn.orbits.continuation import grazing_curve
    from camdyn.orbits.derivatives import Unresolved
    from camdyn.orbits.section_map import MapFailure

    leg = SimpleNamespace(system=SimpleNamespace(free="speed_rpm", parameter="k_s"),
                          layout=SimpleNamespace(split=lambda z: (None, 0.5, 1000.0, 2000.0)))
    p = SimpleNamespace(tangent=np.zeros(5), derivatives=SimpleNamespace(steps=np.ones(2)))
    monkeypatch.setattr(grazing_curve, "predicted", lambda *a: None)
    monkeypatch.setattr(grazing_curve, "corrected", lambda *a: (np.zeros(5), SimpleNamespace(max_gap=-1.0), 2))
    monkeypatch.setattr(grazing_curve, "is_largest", lambda system, e: True)
    for failure, ends in ((Unresolved("no step keeps the path"), False), (MapFailure("no tangent dynamics"), True)):
        def point(*a, failure=failure):
            raise failure
        monkeypatch.setattr(grazing_curve, "_point", point)
        got = grazing_curve.step(leg, p, 0.01)
        assert (isinstance(got, grazing_curve.Ended) and got.outcome == GrazingOutcome.NO_DERIVATIVES) if ends \
            else got is None


@pytest.mark.slow   # three continuations, ~9 s; the guessed start alone runs in every chart above
def test_the_guessed_start_and_the_searched_one_find_the_same_grazing():
    """jump_chart starts from the orbit at its guess (the contact-loss speed less the compliance
    shift, 1e-4 below); continue_grazing without a guess searches the branch over ``search``; a
    guess past the grazing (an impacting orbit there) falls back to the search.  The three first
    grazing speeds agree to the jump speed's own scatter on this stiff contact (the orbit is
    converged to gap_tol of the deflection; measured 4e-8 of the speed between the two starts
    on reference-experiment), held to 1e-6 of it."""
    from camdyn.analysis.statics import compliance_shift

    loss = contact_loss_speed(RIG.replace(k_s=2000.0))
    guess = loss * (1 + compliance_shift(RIG.replace(k_s=2000.0), SCENE)) * (1 - 1e-4)
    search = (0.9 * loss, 1.05 * loss)
    firsts = [continue_grazing(RIG, SCENE, "k_s", 2000.0, 2001.0, search=search, guess=g)["speed_rpm"].values[0]
              for g in (guess, None, 1.02 * loss)]
    np.testing.assert_allclose(firsts, firsts[1], rtol=1e-6)


# --- a codimension-2 point on a real rig, located on both curves that meet there (issue 29) -------------
#: the example rig with a polymer cam (Y_c 3 GPa), a stiff spring and a crowned follower (point
#: contact), lightly damped (law A, zeta_A 2e-3): its contact branch folds just below the jump speed
#: (a resonance of the contact, bent by the Hertz law), and the fold curve meets the grazing curve
FOLD_RIG = camdyn.example_rig().replace(Y_c=3e9, k_s=20000.0, zeta_A=2e-3)
FOLD_SCENE = camdyn.Scene(contact="point", damping="A", friction="none")


@pytest.mark.slow   # two curves, ~10 s
def test_the_grazing_fold_point_is_found_on_the_grazing_curve_and_on_the_fold_curve():
    """In (speed, Y_c): the grazing curve's multiplier at grazing passes +1 (grazing_fold, the
    codimension-2 locator of grazing_curve), and the fold curve's orbit grazes (the mirror,
    codim1.located) at the same point.  The two agree to the sum of what each locator leaves:
    the brackets (locate_tol of each curve's scaled arclength: lambda2 in units of its range,
    lambda1 of its start value); the grazing curve's orbits sitting gap_tol d below zero gap and the
    fold curve's located orbit its codim2_max_gap from it (each gap over the fold curve's slope
    d gap / d Y_c); the fold curve's det(M - I) solved only to DET_TOL (over the grazing curve's
    slope d det(M - I) / d Y_c).  The slopes are secants over each curve's step at the point, and
    the gap has a corner at zero: the first-order sum is doubled for their remainder."""
    from camdyn.orbits.continuation import continue_bifurcation
    from camdyn.orbits.continuation.codim1 import DET_TOL
    from camdyn.orbits.continuation.events import CRITICAL
    from camdyn.orbits.tangent import variational

    loss = contact_loss_speed(FOLD_RIG)
    graze = continue_grazing(FOLD_RIG, FOLD_SCENE, "Y_c", 3e9, 2.5e9, search=(0.95 * loss, 0.995 * loss),
                             guess=0.988 * loss, settings=GrazingSettings(gap_tol=1e-8))
    fold = continue_bifurcation(FOLD_RIG.replace(Y_c=2.55e9), FOLD_SCENE, "fold", "Y_c", 2.55e9, 2.7e9,
                                search=(0.95 * loss, 0.98 * loss), phase_fraction=0.5, warm="quasistatic",
                                jacobian=variational, det_step=1e-6)
    for ds in (graze, fold):
        assert ds.attrs["outcome"] == GrazingOutcome.END_REACHED.name, ds.attrs["outcome_message"]
        assert ds.sizes["codim2"] == 1 and ds.attrs["codim2_kinds"].split()[int(ds["codim2_kind"][0])] == "grazing_fold"
        assert abs(ds["codim2_multiplier_real"].values[0, 0] - 1.0) < CRITICAL
    i, j = int(graze["codim2_point"][0]), int(fold["codim2_point"][0])
    Y, S = fold["Y_c"].values[j:j + 2], fold["speed_rpm"].values[j:j + 2]
    gap_slope = abs(np.diff(fold["max_gap"].values[j:j + 2])[0] / np.diff(Y)[0])
    mu = graze["multiplier_real"].values[i:i + 2, :] + 1j * graze["multiplier_imag"].values[i:i + 2, :]
    det = np.real(np.prod(1.0 - mu, axis=1))
    det_slope = abs(np.diff(det)[0] / np.diff(graze["Y_c"].values[i:i + 2])[0])
    margin = graze.attrs["settings_gap_tol"] * graze.attrs["deflection_scale_m"]
    off = (margin + abs(fold["codim2_max_gap"].values[0])) / gap_slope + DET_TOL / det_slope
    tol = ContinuationSettings().locate_tol
    spans = abs(graze.attrs["end"] - graze.attrs["start"]) + abs(fold.attrs["end"] - fold.attrs["start"])
    tol_Y = 2 * (tol * spans + off)
    tol_S = 2 * (tol * (graze["speed_rpm"].values[0] + fold["speed_rpm"].values[0]) + abs(np.diff(S)[0] / np.diff(Y)[0]) * off)
    assert abs(graze["codim2_Y_c"].values[0] - fold["codim2_Y_c"].values[0]) <= tol_Y
    assert abs(graze["codim2_speed_rpm"].values[0] - fold["codim2_speed_rpm"].values[0]) <= tol_S


def test_a_warm_start_not_offered_is_refused():
    with pytest.raises(ParameterError, match="warm"):
        continue_orbit(RIG, SCENE, "speed_rpm", 900.0, 1000.0, warm="equilibrium")


def test_a_prediction_moves_to_the_contact_side_by_its_expected_error():
    """The corrector starts from the prediction moved CONTACT_SIDE times its expected error
    (the last step's, ``miss ds^2``) down the gap's row: the linearised residual changes in that
    row alone, by that amount, and the move stays on the arclength hyperplane (the arclength
    condition is the prediction's); the first point (miss NaN) is not moved."""
    from types import SimpleNamespace

    from camdyn.orbits.continuation.grazing import R_GAP
    from camdyn.orbits.continuation.grazing_curve import CONTACT_SIDE, contact_side

    rng = np.random.default_rng(7)
    A, direction = rng.normal(size=(4, 5)), rng.normal(size=5)
    p = SimpleNamespace(miss=3e-4, derivatives=SimpleNamespace(A=A))
    move = contact_side(p, direction, 0.05)
    expected = np.zeros(4)
    expected[R_GAP] = -CONTACT_SIDE * 3e-4 * 0.05 ** 2
    np.testing.assert_allclose(A @ move, expected, atol=1e-15)
    assert abs(direction @ move) < 1e-15
    assert not np.any(contact_side(SimpleNamespace(miss=np.nan, derivatives=p.derivatives), direction, 0.05))


def test_the_chord_steps_on_from_an_iterate_off_the_smooth_side_without_new_derivatives():
    """An iterate whose run left the cam has a residual above the smooth one (the flight's gap;
    here three times it): the chord step from it lands on the contact side, and with ``smooth``
    told, the next iterate's contraction is not measured against it: no derivatives are
    evaluated (without it, a Newton step's are), and the corrector converges to the same z."""
    from camdyn.orbits.continuation.corrector import chord

    def residual(z):
        g = z[0] - 1.0
        return np.array([3.0 * g if g > 0 else g]), g <= 0

    calls = []

    def derivatives(z, payload):
        calls.append(z.copy())
        return np.array([[1.0, 0.0]])
    settings = ContinuationSettings(tol=1e-12)
    z_pred, direction, A = np.array([1.5, 0.2]), np.array([0.0, 1.0]), np.array([[1.0, 0.0]])
    z, smooth_side, iterations = chord(residual, derivatives, z_pred, direction, A, settings, lambda s: s)
    assert not calls and smooth_side and iterations == 2 and np.allclose(z, [1.0, 0.2], atol=1e-12)
    chord(residual, derivatives, z_pred, direction, A, settings)
    assert calls


def test_an_iterate_outside_the_last_modes_domain_starts_in_the_initial_rules_mode(monkeypatch):
    """The corrector runs each iterate in the last point's start mode, unless its state is
    outside that mode's domain at the section (across a surface the orbit passes close to
    there): then in the mode the automaton's initial rule chooses (mode None), not a failure."""
    from types import SimpleNamespace

    from camdyn.orbits.continuation import grazing_curve

    modes = []

    def evaluate(system, layout, z, mode):
        modes.append(mode)
        return SimpleNamespace(residual=np.zeros(4), max_gap=-1.0)
    monkeypatch.setattr(grazing_curve, "evaluate", evaluate)
    for admitted, expected in ((True, 3), (False, None)):
        system = SimpleNamespace(section_map=lambda free, lam, mode, ok=admitted: SimpleNamespace(admits=lambda x: ok))
        leg = SimpleNamespace(system=system, layout=SimpleNamespace(split=lambda z: (np.zeros(2), 0.5, 1.0, 2.0)))
        grazing_curve._residual(leg, np.zeros(5), 3)
        assert modes[-1] == expected


def test_a_run_that_left_the_cam_gives_the_corrector_its_largest_gap_alone():
    """The residual of a lifted-off run: the gap's row from the run's largest gap (positive, so
    the chord step from it is toward the contact side; the same row a contact run with that
    psi_i(t_g) would have), zeros in the orbit's and the rate's rows."""
    from types import SimpleNamespace

    from camdyn.orbits.continuation.boundary import GAP_MARGINS as MARGIN, GRAZING
    from camdyn.orbits.continuation.grazing import R_GAP, flight_residual

    system = SimpleNamespace(deflection=4.7e-10, gap_tol=1e-6, tol=1e-8, boundary=GRAZING, pinned=False)
    period = SimpleNamespace(model=SimpleNamespace(period=0.46))
    r = flight_residual(system, SimpleNamespace(max_gap=4.7e-14, section_map=period))
    assert r[R_GAP] == pytest.approx((1e-4 + MARGIN * 1e-6) * 1e-8 / 1e-6, rel=1e-12)
    assert np.count_nonzero(r) == 1


def test_the_last_step_is_predicted_along_the_tangent_to_the_ranges_end():
    """The final step's prediction reaches lambda2's end exactly, moved there along the tangent
    from the second-order prediction (not lambda2 alone set: the other unknowns keep their place
    on the curve to first order)."""
    from types import SimpleNamespace

    from camdyn.orbits.continuation.grazing import G_RANGE
    from camdyn.orbits.continuation.grazing_curve import predicted

    t = np.array([0.1, -0.2, 0.05, 0.9, 0.36])
    t /= np.linalg.norm(t)
    p = SimpleNamespace(z=np.array([1.0, 2.0, 0.5, 1.0, 0.2]), tangent=t, curvature=np.full(5, 0.3), miss=np.nan,
                        derivatives=SimpleNamespace(A=np.zeros((4, 5))))
    leg = SimpleNamespace(end=30.0, layout=SimpleNamespace(sigma_range=100.0))
    got = predicted(leg, p, 0.25, final=True)
    assert got.z[G_RANGE] == 0.3 and np.array_equal(got.direction, np.eye(5)[G_RANGE])
    moved = got.z - (p.z + 0.25 * t + 0.5 * 0.25 ** 2 * p.curvature)
    np.testing.assert_allclose(moved, moved[G_RANGE] / t[G_RANGE] * t, atol=1e-15)


def test_the_step_grows_to_where_the_predictions_expected_error_is_easy():
    """After an easy point the step grows by GROWTH, or up to MAX_GROWTH times where the
    prediction's error per ds^2 puts the step of EASY_MISS tol further, never beyond max_step; a
    point without the estimate (NaN, a codimension-1 curve's) grows by GROWTH."""
    from types import SimpleNamespace

    from camdyn.orbits.continuation.follow import GROWTH
    from camdyn.orbits.continuation.grazing_curve import EASY_MISS, MAX_GROWTH, grown

    settings = ContinuationSettings(step=0.01, max_step=0.05, tol=1e-8)
    at = lambda h: SimpleNamespace(miss=EASY_MISS * settings.tol / h ** 2)      # noqa: E731  the miss for step h
    assert grown(settings, SimpleNamespace(miss=np.nan), 0.01) == pytest.approx(GROWTH * 0.01)
    assert grown(settings, at(0.025), 0.01) == pytest.approx(0.025)
    assert grown(settings, at(1.0), 0.01) == pytest.approx(MAX_GROWTH * 0.01)
    assert grown(settings, at(1.0), 0.02) == settings.max_step
    assert grown(settings, at(0.001), 0.01) == pytest.approx(GROWTH * 0.01)


def test_the_default_section_is_half_a_period_from_the_grazing(chart):
    """jump_chart's section (section_away_from_loss) lies half a period from the cam angle where
    the inverse kinematics lose contact, and the grazing orbits' gap has its maximum there: the
    grazing's phase after the section is 1/2 to within the angle's grid (1/3600 of a revolution)
    and the compliance's shift of the maximum (measured: 0.5001 here, and on reference-experiment
    0.4794 of the period against its grazing's 0.4795; the former default section, 0.5, put this
    grazing at 0.4847)."""
    from camdyn.analysis.statics import contact_loss_angle
    from camdyn.model.cam import RPM

    assert np.all(np.abs(chart["grazing_phase"].values - 0.5) < 1e-3)
    rig = RIG.replace(k_s=K_S[0])
    loss = contact_loss_speed(rig)
    theta = contact_loss_angle(rig)
    _, curvature, spring = camdyn.analysis.statics.rigid_kinematics(rig, np.array([theta]))
    moment = rig.inertia * curvature[0] * (loss * RPM) ** 2 + spring[0]
    assert abs(moment) < 1e-3 * abs(spring[0])        # the rigid contact's moment vanishes there, at the loss speed


def test_a_parameter_differences_side_that_surely_lifts_off_is_not_run():
    """A side whose linearised gap lies SURE_LIFT margins past zero gap is not run: the
    difference is the one-sided one the run would have given (that run leaving the path), from
    one run instead of two; a side the linearisation keeps in contact is run."""
    from types import SimpleNamespace

    from camdyn.orbits.continuation.boundary import GAP_MARGINS as MARGIN, GRAZING
    from camdyn.orbits.continuation.grazing import SURE_LIFT, R_GAP, _lifts, contact_side_difference
    from camdyn.orbits.derivatives import Column
    from camdyn.orbits.section_map import MapValue

    base = MapValue(np.array([0.0, 0.0, 0.5, 0.0]), 0, 0, 100, (3,))
    offsets = []

    def evaluate_at(offset):           # +offset lifts off (another path), -offset keeps it: slope 2
        offsets.append(offset)
        return MapValue(base.state + 2.0 * offset, 0, 0, 100, (3,) if offset < 0 else (3, 4, 5))
    column = Column.of(1.0, np.ones(4), 1e-10, first=1e-3)
    plain = contact_side_difference(evaluate_at, base, column)
    assert offsets == [1e-3, -1e-3]
    system = SimpleNamespace(tol=1e-8, gap_tol=1e-6, deflection=4.7e-10, boundary=GRAZING, pinned=False)  # margin 2e-8
    lifts = _lifts(system, SimpleNamespace(residual=np.array([0.0, 0.0, 0.0, 0.0])), 1.0)
    assert lifts(1e-3) and not lifts(-1e-3) and not lifts((SURE_LIFT + 0.5) * MARGIN * 1e-8)
    offsets.clear()
    skipped = contact_side_difference(evaluate_at, base, column, lifts=lifts)
    assert offsets == [-1e-3]
    np.testing.assert_array_equal(skipped[0], plain[0])
    assert skipped[1:] == plain[1:] and skipped[0][R_GAP] == pytest.approx(2.0)
