"""Pseudo-arclength continuation of periodic orbits (issue 13, item 4): the branch stays on fixed
points, its multipliers are periodic_orbit's, its events are where the brute-force diagram and
the inverse kinematics put them, and the period-doubling switch gives a period-2 orbit.

The cases, on the example rig (line contact 1.6 mm, damping D, Coulomb friction), found while
writing this module (see the module's docstring in camdyn.orbits.continuation):

* 1650 -> 1850 rev/min: the impacting period-1 orbit (one impact per revolution) loses
  stability by a period doubling at 1710.2 rev/min; the switched period-2 branch doubles
  again at 1798.9 rev/min; the brute-force diagram goes from P1 to P2 between 1710 and 1720;
* 0.9 -> 1.1 x the contact-loss speed (997.87 rev/min), section at T/2: the permanent-contact
  orbit grazes (its largest gap psi_i reaches 0) at 997.845 rev/min, 0.0215 rev/min below the
  inverse-kinematics speed, then the branch ends a few rev/min above, where the map is not smooth;
  on the reference rig (section at 3T/4) at 2010.0035 rev/min, 0.248 below 2010.2518.
"""
from __future__ import annotations

import dataclasses
import functools
import math

import numpy as np
import pytest

import camdyn
from camdyn.analysis.statics import compliance_shift
from camdyn.orbits.continuation import EVENTS, ContinuationOutcome, ContinuationSettings, continue_orbit, events_table
from camdyn.orbits.continuation.corners import NO_LANDINGS
from camdyn.engine.config import SolverOptions
from camdyn.errors import ParameterError
from camdyn.model.model import Model
from camdyn.orbits.derivatives import SHRINK, finite_difference_steps, finite_differences
from camdyn.orbits.section_map import MapValue, StroboscopicMap
from camdyn.sweep.api import bifurcation

RIG = camdyn.example_rig()
SCENE = camdyn.Scene(contact="line", damping="D", friction="coulomb")
TOL = ContinuationSettings().tol            # 1e-8: the corrector's scaled residual
PD_RANGE = (1650.0, 1850.0)


pytestmark = pytest.mark.usefixtures("quiet_compile")  # (tests/conftest.py)


@pytest.fixture(scope="module")
def pd_branch():
    return continue_orbit(RIG, SCENE, "speed_rpm", *PD_RANGE)


def _events(ds, kind):
    return [e for e in events_table(ds) if e[0] == kind]


def _map(ds, i, periods=None):
    model = Model(RIG, SCENE, camdyn.ConstantSpeed(float(ds["lambda"][i])))
    return StroboscopicMap(model, periods or int(ds["periods"][i]), ds.attrs["phase_fraction"] * model.period,
                           int(ds["mode"][i]))


def _scaled(ds, d):
    return np.max(np.abs(d) / np.array([ds.attrs["scale_alpha"], ds.attrs["scale_alpha_dot"]]))


def test_the_branch_reaches_the_end_on_fixed_points(pd_branch):
    ds = pd_branch
    assert ds.attrs["branch_0_message"] == ContinuationOutcome.END_REACHED.message
    first = ds["point_branch"].values == 0
    lam = ds["lambda"].values[first]
    assert lam[0] == PD_RANGE[0] and np.all(np.diff(lam) > 0)
    # the last predictor stops at the end; the corrector moves off it (normal to the tangent) by
    # the predictor's error, second order in the step: measured 1e-3 rev/min, 5e-6 of the range
    assert 0 <= lam[-1] - PD_RANGE[1] <= 1e-4 * np.ptp(PD_RANGE)
    for i in np.flatnonzero(first):
        x = np.array([ds["alpha"][i], ds["alpha_dot"][i]])
        # a fresh run of P from the stored point: the map is deterministic, so the corrector's
        # residual (<= TOL) holds again, to 2 x for the map rebuilt from a rounded speed
        assert _scaled(ds, _map(ds, i)(x) - x) <= 2 * TOL


def test_multipliers_match_periodic_orbit_on_both_sides_of_the_period_doubling(pd_branch):
    ds = pd_branch
    on_first = np.flatnonzero(ds["point_branch"].values == 0)
    for i in on_first[[2, len(on_first) // 2, -3]]:          # stable, near and beyond the doubling
        x = np.array([ds["alpha"][i], ds["alpha_dot"][i]])
        orbit = camdyn.periodic_orbit(RIG, SCENE, speed_rpm=float(ds["lambda"][i]), y0=x, warmup_revolutions=1)
        assert orbit.ok, orbit.message
        mu = ds["multiplier_real"].values[i] + 1j * ds["multiplier_imag"].values[i]
        # two finite-difference monodromies at fixed points within TOL of each other: their entries
        # agree to ~rtol^(2/3) = 2e-7 of the scale (section_map.finite_difference_steps); 1e-5
        # leaves room for a multiplier ~1.7 times that and the scales differing
        assert np.sort_complex(mu) == pytest.approx(np.sort_complex(orbit.multipliers), abs=1e-5)


def test_period_doubling_is_where_the_brute_force_diagram_goes_from_p1_to_p2(pd_branch):
    doublings = _events(pd_branch, "period_doubling")
    first = [e for e in doublings if e[2] == 0]
    assert len(first) == 1
    speeds = np.arange(1690.0, 1741.0, 10.0)
    diagram = bifurcation(RIG, SCENE, speeds, revolutions=300, transient_revolutions=200, progress=False,
                          rtol=1e-10, atol=1e-13)
    # distinct section values after the transient, to 1e-6 rad (the P2 values differ by > 1e-2)
    count = [np.unique(np.round(row, 6)).size for row in diagram["alpha_section"].values]
    last_p1 = max(s for s, c in zip(speeds, count) if c == 1)
    first_p2 = min(s for s, c in zip(speeds, count) if c == 2)
    assert last_p1 < first_p2
    # the diagram knows the transition to one grid step (10 rev/min); next to it the multiplier
    # ~ -1 slows the convergence, so a speed there may show neither 1 nor 2 values
    assert last_p1 <= first[0][1] <= first_p2
    mu = pd_branch["event_multiplier_real"].values[doublings.index(first[0])]
    assert np.min(np.abs(mu + 1.0)) < 1e-3    # the located point's multiplier is -1 (bisection to 1e-6)


def test_the_switched_branch_is_period_two_and_stable_where_the_diagram_shows_p2(pd_branch):
    ds = pd_branch
    assert ds.sizes["branch"] == 2 and int(ds["branch_periods"][1]) == 2 and int(ds["branch_parent"][1]) == 0
    second = np.flatnonzero(ds["point_branch"].values == 1)
    for i in second[::5]:
        x = np.array([ds["alpha"][i], ds["alpha_dot"][i]])
        assert _scaled(ds, _map(ds, i)(x) - x) <= 2 * TOL                  # P_2(x) = x
        assert _scaled(ds, _map(ds, i, periods=1)(x) - x) > 1e-3            # P_1(x) != x: not the P1 orbit
    lam = ds["lambda"].values[second]
    # the diagram above shows a stable P2 from 1720 rev/min; the second doubling is at 1798.9
    inside = (lam > 1720.0) & (lam < 1790.0)
    assert inside.any() and ds["stable"].values[second][inside].all()
    assert not ds["stable"].values[ds["point_branch"].values == 0][-1]      # P1 beyond the doubling: unstable


@pytest.mark.parametrize("preset, phase_fraction", [("example", 0.5), ("reference", 0.75)])
def test_grazing_is_the_inverse_kinematics_speed_less_the_contact_compliance(preset, phase_fraction):
    """The permanent-contact branch over 0.9-1.1 x the contact-loss speed L; the section where
    the branch is smooth up to grazing (on the reference rig at T/2 it ends at 1998.8 rev/min,
    at a non-smooth point of the friction)."""
    rig = camdyn.load_rig(preset)
    loss = camdyn.contact_loss_speed(rig)
    ds = continue_orbit(rig, SCENE, "speed_rpm", 0.9 * loss, 1.1 * loss, phase_fraction=phase_fraction)
    grazing = _events(ds, "grazing")
    assert len(grazing) == 1
    shift = compliance_shift(rig, SCENE)          # example: -2.30e-5 (-0.023 rev/min); reference: -1.19e-4 (-0.24)
    assert shift < 0
    speed = grazing[0][1]
    # measured (speed - L) / L: example -2.15e-5, reference -1.235e-4: the first-order shift to 7 % and 4 %;
    # 30 % allows for the second-order terms ((Omega/vartheta)^2 ~ 1e-4 of it), the contact damping
    # and the locating (1e-6 of the range in arclength: 1 % of the shift)
    assert speed < loss
    assert abs((speed - loss) / loss - shift) <= 0.3 * abs(shift)
    gap = ds["max_gap"].values
    before = ds["lambda"].values < speed
    assert np.all(gap[before] < 0) and np.any(gap[~before] > 0)   # in contact before it, flight after
    # the located orbit's largest gap is 0 (measured 1e-14 and 5e-13 m); 1e-11 m is 0.04 and 0.014 rev/min
    # at the gap's slopes along the branches (2.7e-10 and 7e-10 m per rev/min).  The multipliers may jump
    # there too (the orbit meets a new surface: a multiplier_jump event beside it), so the grazing is
    # picked by its kind
    at = int(np.flatnonzero(ds["event_kind"].values == EVENTS.index("grazing"))[0])
    assert abs(float(ds["event_max_gap"][at])) < 1e-11


def test_a_fold_turns_the_branch_back_and_a_jump_of_the_multipliers_is_not_a_bifurcation():
    """The benchmark rig (line contact 16 mm) from 1.6 x the contact-loss speed down: the stable
    impacting orbit folds at 1289.6 rev/min (the diagram of benchmarks/performance.py loses it
    near 1320, where the long runs leave for another attractor) and comes back unstable, until at
    1510.70 rev/min the test functions change sign across a point whose differences cross other
    switches than its orbit (unresolved, camdyn.orbits.derivatives): the map is not smooth there, the
    event is a multiplier jump, and no branch is switched to.  (Before the rule of
    camdyn.orbits.derivatives, differences straddling the jump placed it at 1509.6.)"""
    rig = RIG.replace(l_lambda=0.016)
    loss = camdyn.contact_loss_speed(rig)
    ds = continue_orbit(rig, SCENE, "speed_rpm", 1.6 * loss, 0.8 * loss)
    kinds = [e[0] for e in events_table(ds)]
    assert kinds == ["fold", "multiplier_jump"] and ds.sizes["branch"] == 1
    lam = ds["lambda"].values
    fold = int(ds["event_point"][0])
    assert np.all(np.diff(lam[:fold + 1]) < 0) and np.all(np.diff(lam[fold + 1:]) > 0)   # down, then up
    assert lam[fold] >= ds["event_lambda"].values[0] <= lam[fold + 1]                # the turning point
    # the fold's multiplier is +1: located by bisection to 1e-6 of the range in arclength
    assert np.min(np.abs(ds["event_multiplier_real"].values[0] - 1.0)) < 1e-3
    assert ds["stable"].values[:fold].all() and not ds["stable"].values[fold + 1:].any()


def test_any_jacobian_provider_plugs_in(pd_branch):
    """A provider factory (map, scale) -> (x -> (P(x), dP/dx)) replaces the default, as the
    variational one with saltation matrices will: here finite differences with a step 10 times
    smaller, counted."""
    calls = []

    def counted(section_map, scale):
        provider = finite_differences(section_map, scale, step_factor=0.1)

        def call(x):
            calls.append(1)
            return provider(x)
        return call

    ds = continue_orbit(RIG, SCENE, "speed_rpm", 1650.0, 1700.0, jacobian=counted)
    assert calls and ds.attrs["branch_0_message"] == ContinuationOutcome.END_REACHED.message
    i = int(np.argmin(np.abs(pd_branch["lambda"].values - 1650.0)))        # the common first orbit
    # the noise part of a central difference grows as 1/h: ~10 rtol^(2/3) = 2e-6 here; 1e-4 is 50 x that
    assert ds["multiplier_real"].values[0] == pytest.approx(pd_branch["multiplier_real"].values[i], abs=1e-4)


@pytest.fixture(scope="module")
def impacting_start():
    """A first point whose finite differences resolve at their first pair of steps (the example
    rig at 1650 rev/min, one impact per revolution), and its leg (problem, period, scale, settings)."""
    from camdyn.orbits.continuation import Problem, follow
    started = follow.start(Problem(RIG, SCENE, "speed_rpm", 1650.0, 1700.0), 20, ContinuationSettings())
    assert not isinstance(started, str), started
    first, leg = started
    assert first.derivation.provider == "finite_differences" and first.resolved
    return leg, first


def _counting(monkeypatch):
    """The engine runs made from now on (every run of a map goes through section_map's integrate)."""
    import camdyn.orbits.section_map as SM
    runs, real = [], SM.integrate
    monkeypatch.setattr(SM, "integrate", lambda *a, **k: runs.append(1) or real(*a, **k))
    return runs


def _first_pair(leg, p) -> bool:
    """Whether each of p's three differences (alpha, alpha_dot, lambda) was taken at its second
    step, the first pair that can agree: 2 x 2 runs each."""
    problem = leg.problem
    first = np.append(finite_difference_steps(p.x, leg.scale, problem.options.rtol),
                      problem.options.rtol ** (1 / 3) * max(abs(p.lam), problem.span))
    return np.allclose(p.derivation.steps, first / SHRINK, rtol=1e-12)


def test_a_converged_point_runs_its_orbit_once(impacting_start, monkeypatch):
    """A step's orbit is run once: the corrector's last run gives the point's largest gap and
    the map's value to the provider, which does not run it again (camdyn.orbits.continuation.corrector.orbit_run).
    So a step that converges in k chord iterations costs k + 1 runs, and its derivatives 12 where
    each of the 3 differences (2 columns, lambda) resolves at its first pair of steps (h and
    h / 4, 2 runs each: camdyn.orbits.derivatives); the first point 1 + 12."""
    from camdyn.orbits.continuation import corrector as C
    leg, first = impacting_start
    evaluations = []
    real_evaluate = C.evaluate
    monkeypatch.setattr(C, "evaluate", lambda *a: evaluations.append(1) or real_evaluate(*a))
    runs = _counting(monkeypatch)
    q = C.step(leg, first, 1e-3)
    assert q is not None and len(evaluations) == 1          # a chord step, derivatives at the point only
    assert q.derivation.provider == "finite_differences" and q.resolved and _first_pair(leg, q)
    assert len(runs) == q.iterations + 1 + 12
    # the gap comes from the corrector's run: the same as a run of its own (the samples' end is P_n(x))
    again = C.orbit_run(leg, q.lam, q.x, first.mode)
    assert C.gap(again)[0] == q.max_gap and np.array_equal(C.gap(again)[1], q.alpha_revolutions)
    del runs[:]
    p = C.first_point(leg, first.lam, first.x, first.mode, 1.0)
    assert _first_pair(leg, p) and len(runs) == 1 + 12


def test_a_rig_parameter_is_continued_at_a_fixed_speed():
    ds = continue_orbit(RIG, SCENE, "k_s", 2000.0, 2400.0, speed_rpm=1600.0)
    assert ds.attrs["parameter"] == "k_s" and ds["lambda"].attrs["units"] == "N/m"
    assert ds.attrs["branch_0_message"] == ContinuationOutcome.END_REACHED.message
    # the corrector's own stopping rule
    assert np.all(ds["residual"].values <= TOL)
    # stable with a complex pair at 1600 rev/min (test_orbits: 1500) all the way: no event
    assert ds.sizes["event"] == 0 and ds["stable"].values.all()


def test_a_start_where_shooting_fails_is_an_outcome_not_an_exception():
    """The benchmark rig (line contact 16 mm) in permanent contact at the section t = 0, where the
    stiff contact is barely loaded (deflection 1.4e-9 m): every finite-difference step above the
    noise floor leaves the contact mode.  Without the variational fallback shooting has no
    derivative and the start fails, saying why; with it (the default) every point's derivative
    is the variational one, and says so."""
    rig = RIG.replace(l_lambda=0.016)
    alone = functools.partial(finite_differences, fallback=False)
    ds = continue_orbit(rig, SCENE, "speed_rpm", 948.0, 960.0, phase_fraction=0.0, jacobian=alone)
    assert ds.sizes["point"] == 0 and ds.sizes["event"] == 0
    message = ds.attrs["branch_0_message"]
    assert message.startswith(ContinuationOutcome.START_FAILED.message) and "finite differences unresolved" in message
    ds = continue_orbit(rig, SCENE, "speed_rpm", 948.0, 960.0, phase_fraction=0.0)
    assert ds.attrs["branch_0_message"] == ContinuationOutcome.END_REACHED.message
    assert ds.attrs["providers"] == "variational" and ds["resolved"].values.all()


def test_the_dataset_round_trips_through_netcdf(pd_branch, tmp_path):
    xr = pytest.importorskip("xarray")
    path = tmp_path / "branch.nc"
    pd_branch.to_netcdf(path, engine="scipy")
    with xr.open_dataset(path, engine="scipy") as back:
        assert back["stable"].dtype == bool
        assert [EVENTS[k] for k in back["event_kind"].values] == [e[0] for e in events_table(pd_branch)]
        np.testing.assert_array_equal(back["lambda"].values, pd_branch["lambda"].values)


def test_a_compliant_branch_lands_no_impacts_and_has_no_corner_impact(pd_branch):
    """A compliant contact has no Newton impacts: its orbits' impact angles are NaN (one column, the
    Dataset's least) and no corner_impact is told (camdyn.orbits.continuation.corners)."""
    assert pd_branch.sizes["impact"] == 1 and np.isnan(pd_branch["impact_angle"].values).all()
    assert "corner_impact" not in [e[0] for e in events_table(pd_branch)]


def test_the_branches_plot_over_a_diagram(pd_branch):
    pytest.importorskip("matplotlib")
    from camdyn.io import plots
    diagram = bifurcation(RIG, SCENE, [1700.0, 1750.0], revolutions=20, transient_revolutions=10, progress=False)
    fig = plots.branches(pd_branch, diagram=diagram)
    ax = fig.axes[0]
    styles = {line.get_linestyle() for line in ax.lines if len(line.get_xdata()) > 1}
    assert {"-", "--"} <= styles                         # stable and unstable parts
    labels = [t.get_text() for t in ax.get_legend().get_texts()]
    assert "period doubling" in labels and any("period 2 T" in t for t in labels)


@pytest.mark.parametrize("kwargs, name", [
    (dict(parameter="k_q", start=1.0, end=2.0, speed_rpm=100.0), "parameter"),
    (dict(parameter="speed_rpm", start=1000.0, end=1000.0), "end"),
    (dict(parameter="speed_rpm", start=1000.0, end=-1000.0), "end"),
    (dict(parameter="speed_rpm", start=1000.0, end=1100.0, speed_rpm=1000.0), "speed_rpm"),
    (dict(parameter="k_s", start=2000.0, end=3000.0), "speed_rpm"),
    (dict(parameter="speed_rpm", start=float("nan"), end=1100.0), "start"),
    (dict(parameter="speed_rpm", start=1000.0, end=1100.0, phase_fraction=1.0), "phase_fraction"),
    (dict(parameter="speed_rpm", start=1000.0, end=1100.0, periods=0), "periods"),
    (dict(parameter="speed_rpm", start=1000.0, end=1100.0, settings={"step": 0.1}), "settings"),
    (dict(parameter="k_s", start=-5.0, end=3000.0, speed_rpm=1000.0), "k_s"),
])
def test_bad_input_names_the_parameter(kwargs, name):
    with pytest.raises(ParameterError) as exc:
        continue_orbit(RIG, SCENE, **kwargs)
    assert exc.value.name == name


@pytest.mark.parametrize("kwargs, name", [(dict(step=0.1), "step"), (dict(min_step=0.0), "min_step"),
                                          (dict(max_points=1), "max_points"), (dict(tol=2.0), "tol")])
def test_bad_settings_name_the_setting(kwargs, name):
    with pytest.raises(ParameterError) as exc:
        ContinuationSettings(**kwargs)
    assert exc.value.name == name


def test_the_unknowns_are_laid_out_in_one_place():
    """z = (x / scale, lambda / span): Leg.z builds it in the order of camdyn.vocabulary.STATE with
    lambda last, Leg.split inverts it (to the two roundings of a division and a product: 2 ulp),
    and Leg.along points along lambda alone."""
    from camdyn.orbits.continuation.problem import Z_LAMBDA, Z_SIZE, Leg, Problem
    problem = Problem(RIG, SCENE, "speed_rpm", 1650.0, 1850.0)
    leg = Leg(problem, 1, np.array([0.02, 30.0]), ContinuationSettings())
    x = np.array([0.013, -7.5])
    z = leg.z(1700.0, x)
    assert z.shape == (Z_SIZE,) == (len(camdyn.vocabulary.STATE) + 1,)
    assert z[camdyn.vocabulary.STATE_ALPHA] == 0.013 / 0.02 and z[Z_LAMBDA] == 1700.0 / 200.0
    lam, back = leg.split(z)
    assert lam == pytest.approx(1700.0, rel=4.5e-16) and back == pytest.approx(x, rel=4.5e-16)
    assert np.array_equal(leg.along(-1.0), np.eye(Z_SIZE)[Z_LAMBDA] * -1.0)
    assert leg.doubled().periods == 2 and leg.doubled().scale is leg.scale


def test_the_event_table_names_every_kind_once():
    """Every kind of the table (camdyn.orbits.continuation.events.KINDS) with a test function has a
    locator; ``unless`` names a kind that has a test function; only the period doubling switches
    branches; EVENTS (the Dataset's event_kinds) is the table's order."""
    from camdyn.orbits.continuation import events as E
    assert EVENTS == tuple(k.name for k in E.KINDS) and len(set(EVENTS)) == len(EVENTS)
    names = {k.name for k in E.DETECTED}
    assert all(k.locate is not None for k in E.DETECTED)
    assert all(k.unless in names for k in E.KINDS if k.unless is not None)
    assert [k.name for k in E.KINDS if k.switch_branch] == ["period_doubling"]
    assert [k.name for k in E.KINDS if k.test is None] == ["multiplier_jump"]


@pytest.mark.parametrize("f_lo, f_hi, expected", [
    (-1.0, 3.0, 0.325),                 # the secant root: 0.2 + 0.5 / 4
    (-1e-12, 2e-8, 0.2005),             # the root at lo + 2.5e-5: kept tol / 2 inside
    (5.0, -1e-9, 0.6995),               # the root next to hi: kept tol / 2 inside
    (-2.0, float("nan"), 0.45),         # hi has no value (a failed step): the midpoint
    (1.0, 1.0, 0.45)])                  # no slope: the midpoint
def test_each_location_trial_is_inside_the_bracket_by_half_the_tolerance(f_lo, f_hi, expected):
    """The secant trial of the event location (camdyn.orbits.continuation.events.trial) stays tol/2 inside
    [lo, hi] = [0.2, 0.7] (tol = 1e-3), so every trial shrinks the bracket by at least that and
    the location ends; the midpoint when an end has no value."""
    from camdyn.orbits.continuation.events import trial
    assert trial(0.2, 0.7, f_lo, f_hi, 1e-3) == pytest.approx(expected, rel=1e-12)


@pytest.mark.parametrize("lo, hi, contact, far, expected", [
    (0.2, 0.7, [(0.2, -1.0)], 1.0, 0.45),                                # one contact-side point: the midpoint
    (0.2, 0.7, [(0.0, -2.0), (0.2, -1.0)], 1.0, 0.4 + 2.5e-4),           # root 0.4: tol / 4 past it
    (0.2, 0.7, [(0.0, -2.0), (0.1, -1.5), (0.2, -1.0)], 1.0, 0.4 + 2.5e-4),   # the root settled: past it
    (0.2, 0.7, [(0.0, -1.0), (0.1, -0.8), (0.2, -0.5)], 1.0, 0.2 + 1 / 6 + 2.5e-4 - (0.5 - 0.2 - 1 / 6)),
    # ... root 0.3667 moved 0.1333 from 0.5: short by that
    (0.2, 0.7, [(0.0, -1.0), (0.1, -0.9), (0.2, -0.5)], 1.0, 0.2 + 0.125 / 2),   # moved more than to lo: halfway
    (0.6, 0.7, [(0.5, -1.0), (0.6, -0.5)], 1.0, 0.65),                   # root 0.7, not inside: the midpoint
    (0.6, 0.7, [(0.5, -0.1996), (0.6, -0.0996)], 1.0, 0.7 - 7.5e-4),     # root 0.6996: no nearer hi than 0.75 tol
    (0.2, 0.7, [(0.7, -1.0), (0.5, -0.5)], -1.0, 0.3 - 2.5e-4),          # contact side at hi: past root 0.3 toward lo
])
def test_each_grazing_trial_aims_from_the_contact_side(lo, hi, contact, far, expected):
    """camdyn.orbits.continuation.events.grazing_trial (tol = 1e-3): past the contact-side secant's root by
    tol / 4 (GRAZING_PAST), short of it by its change while that exceeds tol / 4, never nearer
    the far end than 0.75 tol nor the contact end than tol / 4; the midpoint otherwise."""
    from camdyn.orbits.continuation.events import grazing_trial
    assert grazing_trial(lo, hi, contact, far, 1e-3) == pytest.approx(expected, rel=1e-12)


@pytest.fixture(scope="module")
def grazing_step():
    """Two orbits of the benchmark rig's contact branch (line contact 16 mm, section at T/2) on
    either side of its grazing at 0.999998 x the contact-loss speed L: p at 0.995 L in permanent
    contact, q 0.6 of the range 0.995-1.005 L on, at 1.001 L, in flight."""
    from camdyn.orbits.continuation import Problem, corrector, follow
    loss = camdyn.contact_loss_speed(RIG.replace(l_lambda=0.016))
    problem = Problem(RIG.replace(l_lambda=0.016), SCENE, "speed_rpm", 0.995 * loss, 1.005 * loss, phase_fraction=0.5)
    p, leg = follow.start(problem, 20, ContinuationSettings())
    q = corrector.step(leg, p, 0.6)
    assert p.max_gap < 0 < q.max_gap
    return leg, p, q


def test_grazing_is_located_where_bisection_locates_it_in_fewer_trials(grazing_step, monkeypatch):
    """The contact-side secant trials against the former rule, bisection (the midpoint as every
    trial), between the same two orbits: both brackets hold the grazing within locate_tol of
    arclength, so their points agree to twice that; measured 8 trials against 20, and the
    located orbits 1.0e-7 of the range apart."""
    from camdyn.orbits.continuation import events as C
    leg, p, q = grazing_step
    problem, settings = leg.problem, leg.settings
    trials = []
    corrected = C.corrected
    monkeypatch.setattr(C, "corrected", lambda *a: trials.append(a[2]) or corrected(*a))
    located = C.locate(leg, C.KIND["grazing"], p, q, 0.6)
    secant = len(trials)
    monkeypatch.setattr(C, "grazing_trial", lambda lo, hi, *_: 0.5 * (lo + hi))
    del trials[:]
    bisected = C.locate(leg, C.KIND["grazing"], p, q, 0.6)
    assert len(trials) == 20                   # log2(0.6 / locate_tol) = 19.2: the bracket halved 20 times
    assert secant <= len(trials) // 2
    tol = settings.locate_tol * problem.span   # in lambda: |d lambda / ds| <= the range (the tangent is a unit vector)
    for before, after in (located, bisected):
        assert before.max_gap < 0 < after.max_gap
        assert 0 < after.lam - before.lam <= tol
        assert np.all(np.isfinite(before.jacobian)) and np.all(np.isfinite(after.jacobian))   # the event's multipliers
    assert abs(located[1].lam - bisected[1].lam) <= 2 * tol


# --- the detectors on maps whose bifurcations are known in closed form -----------------------------
class _AnalyticMap:
    """P(x; lambda) in closed form, with the interface the continuation reads of a map."""

    def __init__(self, f, lam):
        self.f, self.lam = f, lam

    def __call__(self, x):
        return self.f(np.asarray(x, dtype=float), self.lam)

    def admits(self, x):
        return True

    def evaluate(self, x):
        return MapValue(self(x), 0, 0, 0)


@dataclasses.dataclass(frozen=True)
class _AnalyticProblem:
    """What camdyn.orbits.continuation reads of its Problem, for a map given in closed form; its
    Jacobian is central differences with a step of 1e-6 (error ~1e-12 on these polynomials)."""

    f: object
    start: float
    end: float
    parameter: str = "lambda"
    options: object = dataclasses.field(default_factory=lambda: SolverOptions(rtol=1e-10, atol=1e-13))

    @property
    def span(self):
        return abs(self.end - self.start)

    def section_map(self, lam, mode, periods=None):
        return _AnalyticMap(self.f, lam)

    def jacobian(self, section_map, scale):
        def provider(x):
            J = np.column_stack([(section_map(x + e) - section_map(x - e)) / 2e-6 for e in np.eye(2) * 1e-6])
            return section_map(x), J
        return provider


def _continued(f, start, end, monkeypatch):
    """Follow the fixed point x = 0 of f from start to end: the branch and its events."""
    from camdyn.orbits.continuation import Branch, corrector, follow
    from camdyn.orbits.continuation.problem import Leg

    def run(leg, lam, x, mode):          # P_n(x) alone: no engine run to sample
        return corrector.Run(None, leg.section_map(lam, mode).evaluate(x), None, np.zeros(0))
    monkeypatch.setattr(corrector, "orbit_run", run)
    monkeypatch.setattr(corrector, "gap", lambda run: (-1.0, np.zeros(1), 0))
    monkeypatch.setattr(corrector, "landings", lambda run: NO_LANDINGS)
    monkeypatch.setattr(corrector, "lift_off", lambda run: math.nan)     # no constrained contact
    leg = Leg(_AnalyticProblem(f, start, end), 1, np.ones(2), ContinuationSettings())
    first = corrector.first_point(leg, start, np.zeros(2), 0, 1.0)
    branch, events = Branch(1), []
    follow.follow(leg, branch, 0, first, events)
    return branch, [e[0] for e in events]


def test_a_neimark_sacker_bifurcation_is_located_where_the_complex_pair_crosses_the_unit_circle(monkeypatch):
    """x -> r(lambda) R(1 rad) x with r = 0.8 + 0.4 lambda: a complex pair of modulus r, which
    crosses 1 at lambda = 0.5.  Located within 1e-5 (the location's tolerance, 1e-6 of the
    range in arclength, with the branch's arclength close to its lambda here)."""
    c, s = np.cos(1.0), np.sin(1.0)

    def f(x, lam):
        return (0.8 + 0.4 * lam) * np.array([c * x[0] - s * x[1], s * x[0] + c * x[1]])

    branch, events = _continued(f, 0.0, 1.0, monkeypatch)
    assert branch.outcome is ContinuationOutcome.END_REACHED
    assert [e.kind for e in events] == ["neimark_sacker"]
    assert events[0].lam == pytest.approx(0.5, abs=1e-5)
    assert np.abs(events[0].multipliers) == pytest.approx([1.0, 1.0], abs=1e-4)


def test_a_branch_point_is_told_from_a_fold(monkeypatch):
    """x1 -> x1 + (lambda x1 - x1^3) / 2, x2 -> x2 / 2: the fixed point x = 0 for every lambda,
    its multiplier 1 + lambda / 2 crossing +1 at lambda = 0 where the branches x1 = +-sqrt(lambda)
    cross it (a pitchfork); the branch goes on through it without turning: a branch point, no fold."""
    def f(x, lam):
        return np.array([x[0] + 0.5 * (lam * x[0] - x[0] ** 3), 0.5 * x[1]])

    branch, events = _continued(f, -1.0, 1.0, monkeypatch)
    assert branch.outcome is ContinuationOutcome.END_REACHED
    assert [e.kind for e in events] == ["branch_point"]
    assert events[0].lam == pytest.approx(0.0, abs=1e-5)
