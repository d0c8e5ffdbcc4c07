"""Periodic orbits by shooting (issue 13, first layer): the stroboscopic map, the finite-difference
monodromy, Newton's outcomes, and the Floquet multipliers against the simulated dynamics.

The cases, on the example rig with line contact, damping D and Coulomb friction (contact is lost
near 998 rev/min, camdyn.analysis.statics.contact_loss_speed), found while writing this module:

* 600 rev/min, permanent contact: the orbit slides backward in the viscous phase of damping D
  all round (no switch over a period); multipliers a complex pair of modulus 5.4e-7 (the contact
  mode's damping over 0.1 s); the 20-revolution warm start is already converged (0 Newton steps);
* 1500 rev/min, one impact per revolution (free flight at the section): from a 2-revolution warm
  start Newton converges in 4 steps; multipliers a complex pair of modulus 0.415 (stable);
* 1200 rev/min, 2 impacts per revolution: from a 2-revolution warm start Newton converges in 5
  steps to an unstable orbit, multipliers 4.17 and 0.039 (the long run there is chaotic).
"""
from __future__ import annotations

import numpy as np
import pytest

import camdyn
from camdyn.errors import ParameterError
from camdyn.model.model import Model
from camdyn.orbits.shooting import OrbitOutcome, ShootingSettings, newton, periodic_orbit
from camdyn.orbits.derivatives import finite_differences
from camdyn.orbits.section_map import DEFAULT_OPTIONS, MapFailure, MapValue, StroboscopicMap, derivative_at

RIG = camdyn.example_rig()
SCENE = camdyn.Scene(contact="line", damping="D", friction="coulomb")
TOL = ShootingSettings().tol          # 1e-8, the scaled residual Newton stops at
SIM = dict(rtol=DEFAULT_OPTIONS.rtol, atol=DEFAULT_OPTIONS.atol)   # simulate as the map runs


def _orbit(speed, warmup, periods=1):
    return periodic_orbit(RIG, SCENE, speed_rpm=speed, warmup_revolutions=warmup, periods=periods)


@pytest.fixture(scope="module")
def contact():
    return _orbit(600.0, 20)


@pytest.fixture(scope="module")
def impacting():
    return _orbit(1500.0, 2)


@pytest.fixture(scope="module")
def unstable():
    return _orbit(1200.0, 2)


def _map(speed, orbit):
    model = Model(RIG, SCENE, camdyn.ConstantSpeed(speed))
    return StroboscopicMap(model, orbit.periods, orbit.phase, model.mode(orbit.mode))


def _sections(speed, revolutions, y0=None):
    """alpha, alpha_dot at t = k T, k = 0..revolutions, by simulate (an independent path: pieces,
    samples, the initial rule at the start)."""
    T = 60.0 / speed
    r = camdyn.simulate(RIG, SCENE, speed_rpm=speed, revolutions=revolutions, sample_rate_Hz=1.0 / T, y0=y0, **SIM)
    assert r.ok, r.outcome.message
    return np.vstack([r.alpha, r.alpha_dot]).T


@pytest.mark.parametrize("case, speed, mode_prefix", [("contact", 600.0, "contact"), ("impacting", 1500.0, "free")])
def test_shooting_converges_and_the_fixed_point_reproduces_itself(request, case, speed, mode_prefix):
    orbit = request.getfixturevalue(case)
    assert orbit.ok, orbit.message
    assert orbit.mode.startswith(mode_prefix) and orbit.residual <= TOL
    P = _map(speed, orbit)
    value = P.evaluate(orbit.state)
    assert value.end_mode == value.start_mode
    # a fresh evaluation of P_n gives the same residual: the map is deterministic at a state
    assert np.max(np.abs(value.state - orbit.state) / orbit.scale) <= TOL


def test_impacting_orbit_needed_newton_and_is_stable(impacting):
    assert impacting.iterations >= 1        # the 2-revolution warm start is not yet periodic
    assert impacting.stable and np.max(np.abs(impacting.multipliers)) < 1


def test_a_long_run_converges_to_the_stable_fixed_point_at_the_multipliers_rate(impacting):
    """From the static equilibrium the section approaches the fixed point; its distance shrinks
    like the multipliers' modulus 0.415 per revolution (a complex pair: the distance oscillates
    between revolutions, so the rate is taken over 10 revolutions)."""
    x = _sections(1500.0, 60)
    d = np.max(np.abs(x - impacting.state) / impacting.scale, axis=1)
    M = impacting.monodromy * impacting.scale[None, :] / impacting.scale[:, None]
    # the fixed point is known to |(M - I)^-1 r| with r <= TOL (scaled); 2x for the map's noise
    bound = 2 * TOL * np.linalg.norm(np.linalg.inv(M - np.eye(2)), np.inf)
    assert d[-1] <= bound
    rate = (d[14] / d[4]) ** (1 / 10)
    # 10 %: revolutions 4-14 are still a little nonlinear (the distance falls from 5e-2 to 6e-6)
    assert rate == pytest.approx(np.max(np.abs(impacting.multipliers)), rel=0.1)


def test_an_unstable_orbit_repels_at_its_largest_multiplier(unstable):
    """A start 1e-7 (scaled) from the fixed point along the unstable eigenvector moves away by
    the multiplier -4.17 per revolution (a flip: it alternates sides), as simulate shows."""
    assert unstable.ok, unstable.message
    assert unstable.stable is False
    mu, V = np.linalg.eig(unstable.monodromy)
    k = int(np.argmax(np.abs(mu)))
    assert abs(mu[k].imag) == 0 and abs(mu[k].real) > 1
    v = V[:, k].real / np.max(np.abs(V[:, k].real / unstable.scale))
    x = _sections(1200.0, 6, y0=unstable.state + 1e-7 * v)
    offset = (x[:, 0] - unstable.state[0]) / unstable.scale[0]
    # the offset, 1e-7 at the start, is far above the fixed point's own error (~residual /
    # (|mu| - 1) = 3e-10) and stays below 1e-3 after 6 revolutions, where the map is still
    # linear to ~1 %; the mean rate over the 6 revolutions, to 1 %
    assert -(abs(offset[6] / offset[0]) ** (1 / 6)) == pytest.approx(mu[k].real, rel=0.01)
    assert np.all(np.sign(offset[1:]) == -np.sign(offset[:-1]))      # a flip


def test_two_periods_give_the_same_fixed_point_and_squared_multipliers(impacting):
    twice = _orbit(1500.0, 2, periods=2)
    assert twice.ok, twice.message
    # the fixed point of P_2 is P_1's (period-1 orbit): within both searches' tolerance
    assert np.max(np.abs(twice.state - impacting.state) / impacting.scale) <= 10 * TOL
    # P_2 = P_1 o P_1: mu_2 = mu_1^2; to 1e-5 relative, the finite differences' error (~rtol^(2/3))
    assert np.sort(np.abs(twice.multipliers)) == pytest.approx(np.sort(np.abs(impacting.multipliers)) ** 2, rel=1e-5)


def test_monodromy_agrees_with_a_second_step_size(impacting):
    P = _map(1500.0, impacting)
    S = impacting.scale
    J1 = finite_differences(P, S)(impacting.state)[1] * S[None, :] / S[:, None]
    J01 = finite_differences(P, S, step_factor=0.1)(impacting.state)[1] * S[None, :] / S[:, None]
    # entries ~1 (scaled); measured difference 5e-7: the central difference's error ~rtol^(2/3) = 2e-7
    assert np.max(np.abs(J1 - J01)) <= 1e-5


def test_monodromy_determinant_obeys_liouville_in_permanent_contact(contact):
    """With no switch over the period, det M = exp(integral of d alpha_ddot / d alpha_dot dt)
    (Liouville's formula), from the generated Jacobian (Eqs. 21-22) along the orbit."""
    model = Model(RIG, SCENE, camdyn.ConstantSpeed(600.0))
    from camdyn.engine.driver import integrate
    t = np.linspace(0.0, model.period, 4001)
    tr = integrate(model, (0.0, model.period), contact.state, t, DEFAULT_OPTIONS, mode=model.mode(contact.mode))
    assert tr.outcome.ok and not tr.switches
    trace = [model.jacobian(int(m), ti, a, ad)[1] for m, ti, a, ad in zip(tr.mode, tr.t, tr.y[0], tr.y[1])]
    liouville = np.exp(np.trapezoid(trace, tr.t))
    # 1 %: measured 5e-4; det ~ 3e-13 is the product of two multipliers of 5.4e-7, each
    # entry known to ~rtol^(2/3) of the motion's scale
    assert np.linalg.det(contact.monodromy) == pytest.approx(liouville, rel=0.01)
    assert contact.stable and np.max(np.abs(contact.multipliers)) < 1e-5


def test_the_contact_orbit_is_where_a_long_run_settles(contact):
    x = _sections(600.0, 30)
    # the multipliers are 5e-7: after 30 revolutions only the integration noise is left
    # (~rtol of the scale; 1e-8 is Newton's tolerance)
    assert np.max(np.abs(x[-1] - contact.state) / contact.scale) <= TOL


def test_a_failing_warm_up_is_reported_not_raised():
    from camdyn.engine.config import EventSettings, SolverOptions
    options = SolverOptions(rtol=1e-10, atol=1e-13, events=EventSettings(max_events=2))
    orbit = periodic_orbit(RIG, SCENE, speed_rpm=1500.0, warmup_revolutions=5, options=options)
    # one impact per revolution is 3 switches: the warm-up stops at the second
    assert orbit.outcome is OrbitOutcome.RUN_FAILED and not orbit.ok
    assert "max_events" in orbit.message and orbit.stable is None and orbit.multipliers.size == 0


def test_a_search_that_does_not_converge_gives_no_multipliers():
    """The 1500 rev/min search from 2 warm-up revolutions needs 4 Newton steps; stopped after one,
    its last iterate is no orbit: no multipliers, no verdict, the outcome says what to do."""
    orbit = periodic_orbit(RIG, SCENE, speed_rpm=1500.0, warmup_revolutions=2, settings=ShootingSettings(max_iterations=1))
    assert orbit.outcome is OrbitOutcome.MAX_ITERATIONS and orbit.residual > TOL
    assert orbit.multipliers.size == 0 and orbit.stable is None and "max_iterations" in orbit.message
    assert np.all(np.isfinite(orbit.monodromy)) and np.all(np.isfinite(orbit.state))


# ------------------------------------------------------------------ the map and its modes
def test_a_given_mode_is_refused_outside_its_domain_and_the_initial_rule_chooses_otherwise():
    model = Model(RIG, SCENE, camdyn.ConstantSpeed(600.0))
    lifted = np.array([0.01, 0.0])            # 0.01 rad off the cam: the gap is open
    in_contact = StroboscopicMap(model, mode=model.mode("contact_unloading_bwd"))
    with pytest.raises(MapFailure, match="gap"):
        in_contact(lifted)
    assert StroboscopicMap(model).start_mode(lifted) == model.mode("free")
    assert StroboscopicMap(model).start_mode(model.static_state()) != model.mode("free")


@pytest.mark.parametrize("case", ["contact", "impacting"])
def test_the_maps_value_is_the_same_to_the_bit_when_the_run_is_sampled(request, case):
    """StroboscopicMap.run: the run sampled along the orbit (the continuation's 257 samples of
    the largest gap) ends where the map's run sampled at t0 + n T alone does, to the bit and in
    as many steps (the engine's steps do not depend on the sample times), from the fixed point
    and from states off it (the corrector's iterates)."""
    orbit = request.getfixturevalue(case)
    speed = 600.0 if case == "contact" else 1500.0
    P = _map(speed, orbit)
    t0, t1 = P.t_span
    t_eval = np.linspace(t0, t1, 257)
    for dx in (np.zeros(2), 1e-7 * orbit.scale, -3e-7 * orbit.scale):   # within the contact modes
        x = orbit.state + dx
        sampled, tr = P.run(x, t_eval)
        alone = P.evaluate(x)
        assert np.array_equal(sampled.state, alone.state) and sampled.steps == alone.steps
        assert tr.t.size == t_eval.size and np.array_equal(tr.y[:2, -1], alone.state)
    with pytest.raises(ParameterError, match="t_eval"):
        P.run(orbit.state, t_eval[:-1])                # not ending at t0 + n T: no map value


@pytest.mark.parametrize("kw, name", [(dict(periods=0), "periods"), (dict(periods=1.5), "periods"),
                                      (dict(phase=-0.01), "phase"), (dict(phase=0.2), "phase"),
                                      (dict(mode=99), "mode"), (dict(options=None), "options")])
def test_bad_map_input_names_the_parameter(kw, name):
    model = Model(RIG, SCENE, camdyn.ConstantSpeed(600.0))     # T = 0.1 s
    with pytest.raises(ParameterError, match=name):
        StroboscopicMap(model, **kw)


def test_bad_shooting_input_names_the_parameter():
    with pytest.raises(ParameterError, match="tol"):
        ShootingSettings(tol=0.0)
    with pytest.raises(ParameterError, match="warmup_revolutions"):
        periodic_orbit(RIG, SCENE, speed_rpm=600.0, warmup_revolutions=0)
    with pytest.raises(ParameterError, match="speed_rpm"):
        periodic_orbit(RIG, SCENE, camdyn.ConstantSpeed(600.0), speed_rpm=600.0)


# ------------------------------------------------------------------ Newton on maps with known answers
class FakeMap:
    """A map with the StroboscopicMap interface the provider and Newton use."""

    options = DEFAULT_OPTIONS

    def __init__(self, fn):
        self.fn = fn

    def __call__(self, x):
        return np.asarray(self.fn(np.asarray(x, dtype=float)), dtype=float)

    def admits(self, x):
        return True

    def evaluate(self, x):
        return MapValue(self(x), 0, 0, 0)


A = np.array([[0.5, 0.3], [-0.2, 0.1]])
X_STAR = np.array([0.2, -1.0])


def _quadratic(x):
    d = x - X_STAR
    return X_STAR + A @ d + 0.4 * d ** 2


def test_central_differences_are_exact_on_a_quadratic_map():
    J = finite_differences(FakeMap(_quadratic), np.ones(2))(X_STAR)[1]
    # central differences of a quadratic are exact up to rounding (~eps / h = 1e-13)
    np.testing.assert_allclose(J, A, atol=1e-9)


def test_a_provider_told_p_spares_its_base_run_and_gives_the_same_jacobian():
    """finite_differences' provider told the map's value at x (derivative_at's base) returns
    that P and the same J to the bit (the columns are central differences, which never read the
    base run's state) with 8 runs of the map instead of 9; a plain callable x -> (P, J) is called
    with x alone and named as the provider."""
    calls = []
    P = FakeMap(lambda x: calls.append(1) or _quadratic(x))
    provider = finite_differences(P, np.ones(2))
    x = X_STAR + [0.1, -0.2]
    base, J = provider(x)
    assert len(calls) == 9                                # the base run, and 2 steps x 2 runs per column
    known = MapValue(np.array([7.0, 8.0]), 0, 0, 0)      # not P(x): shows that the provider returns what it is told
    told = derivative_at(provider, x, known)
    assert len(calls) == 9 + 8
    assert np.array_equal(told.value, known.state) and np.array_equal(told.jacobian, J)
    assert told.provider == "finite_differences" and told.resolved and np.all(told.steps > 0)
    seen = []

    def mine(x):
        return seen.append(x) or (base, J)
    plain = derivative_at(mine, x, known)
    assert plain.value is not known.state and np.array_equal(plain.value, base) and len(seen) == 1
    assert plain.provider == "mine" and "taken as given" in plain.note


def test_newton_finds_a_known_fixed_point_and_its_multipliers():
    P = FakeMap(_quadratic)
    found = newton(P, finite_differences(P, np.ones(2)), X_STAR + [0.5, -0.4], np.ones(2))
    assert found.outcome is OrbitOutcome.CONVERGED and found.residual <= TOL
    np.testing.assert_allclose(found.x, X_STAR, atol=1e-8)     # |x - x*| ~ |(A - I)^-1| r
    np.testing.assert_allclose(np.sort(np.linalg.eigvals(found.jacobian)), np.sort(np.linalg.eigvals(A)), atol=1e-9)


def test_newton_reports_each_failure():
    ones = np.ones(2)
    shift = FakeMap(lambda x: x + 1.0)                          # no fixed point, dP/dx = I
    assert newton(shift, finite_differences(shift, ones), np.zeros(2), ones).outcome is OrbitOutcome.SINGULAR
    P = FakeMap(_quadratic)
    few = newton(P, finite_differences(P, ones), X_STAR + 0.5, ones, ShootingSettings(tol=1e-14, max_iterations=1))
    assert few.iterations == 1
    assert few.outcome is OrbitOutcome.MAX_ITERATIONS and np.isfinite(few.residual)

    def only_here(x):                                          # fails everywhere but near the start
        if np.max(np.abs(x - 3.0)) > 1e-3:
            raise MapFailure("a failed run")
        return _quadratic(x)
    P = FakeMap(only_here)
    stalled = newton(P, finite_differences(P, ones), np.full(2, 3.0), ones)
    assert stalled.outcome is OrbitOutcome.NEWTON_STALLED and np.all(stalled.x == 3.0)
    failing = FakeMap(lambda x: (_ for _ in ()).throw(MapFailure("a failed run", camdyn.Outcome.CHATTER)))
    assert newton(failing, finite_differences(failing, ones), np.zeros(2), ones).outcome is OrbitOutcome.RUN_FAILED


def test_a_flight_orbit_coexists_with_the_contact_orbit_below_the_contact_loss_speed():
    """The hysteresis behind Fig. 8's jump (docs/reproduction.md, fig7-8: the flight orbit's
    branch folds at about 116 rev/min): at 125 rev/min, below the experiment rig's contact-loss
    speed (130 rev/min), shooting finds a stable orbit in permanent contact (from rest; the
    variational Jacobian, since its deflection is below any finite-difference step) and a stable
    orbit of large flights (warmed up from the 150 rev/min flight orbit).  Bounds: 'distinct'
    is 0.1 rad apart at the section, half the flight orbit's measured distance from the contact
    orbit (0.21 rad); 'stable' is every |multiplier| < 1 (measured 0 and 0.63)."""
    from camdyn.orbits.tangent import variational
    rig = camdyn.load_rig("reference-experiment")
    scene = camdyn.Scene(contact="line", damping="D", friction="coulomb")
    assert 125.0 < camdyn.contact_loss_speed(rig)
    contact = camdyn.periodic_orbit(rig, scene, speed_rpm=125.0, jacobian=variational)
    flight = camdyn.periodic_orbit(rig, scene, speed_rpm=125.0,
                                   y0=camdyn.periodic_orbit(rig, scene, speed_rpm=150.0).state)
    assert contact.ok and flight.ok, (contact.message, flight.message)
    assert contact.stable and flight.stable
    assert abs(flight.state[0] - contact.state[0]) > 0.1
