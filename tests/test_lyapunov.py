"""Lyapunov exponents of hybrid trajectories (issue 13): against a periodic orbit's multipliers,
the spectrum's sum identity (Liouville with saltation), the chaotic case of tests/test_chaos.py,
and convergence as the tolerance tightens.
"""
from __future__ import annotations

import math

import numpy as np
import pytest

import camdyn
from camdyn.engine.config import SolverOptions
from camdyn.orbits.lyapunov import LyapunovSettings, lyapunov_exponents
from camdyn.orbits.shooting import periodic_orbit

RIG = camdyn.example_rig()
SCENE = camdyn.Scene(contact="line", damping="D", friction="coulomb")
CHAOS_RIG = camdyn.load_rig("reference-experiment")     # tests/test_chaos.py's case
CHAOS_SPEED = 196.0
CHAOS = LyapunovSettings(revolutions=100, transient=100, batches=10)


def _chaos(rtol):
    return lyapunov_exponents(CHAOS_RIG, SCENE, speed_rpm=CHAOS_SPEED, settings=CHAOS,
                              options=SolverOptions(rtol=rtol, atol=1e-3 * rtol))


@pytest.fixture(scope="module")
def chaotic():
    return _chaos(1e-10)


def test_a_periodic_orbits_exponent_is_its_largest_multipliers_rate():
    """Started on the stable 1500 rev/min orbit, lambda_1 = log|mu_max| / T.  Its multipliers are
    a complex pair: a tangent vector's norm after N periods is |mu|^N times a factor within
    [1/kappa, kappa], kappa the condition number of the real basis (Re v, Im v) of the
    eigenvectors, so |lambda_1 - log|mu| / T| <= log(kappa) / (N T)."""
    orbit = periodic_orbit(RIG, SCENE, speed_rpm=1500.0, warmup_revolutions=2)
    assert orbit.ok, orbit.message
    N = 40
    L = lyapunov_exponents(RIG, SCENE, speed_rpm=1500.0, y0=orbit.state,
                           settings=LyapunovSettings(revolutions=N, transient=0, batches=4))
    mu, V = np.linalg.eig(orbit.monodromy)
    T = 60.0 / 1500.0
    kappa = np.linalg.cond(np.column_stack([V[:, 0].real, V[:, 0].imag]))
    expected = math.log(np.max(np.abs(mu))) / T
    assert abs(L.largest - expected) <= math.log(kappa) / (N * T)
    # the pair's product is exact: lambda_1 + lambda_2 = log|det M| / T, to the tangent
    # integration's tolerance (rtol 1e-10) over N periods, and the orbit's own residual
    assert L.exponents.sum() == pytest.approx(math.log(abs(np.linalg.det(orbit.monodromy))) / T, rel=1e-6)


@pytest.mark.parametrize("speed", [1100.0, 1500.0])
def test_spectrum_sum_is_mean_divergence_plus_saltation(speed):
    """lambda_1 + lambda_2 = time mean of d(alpha_ddot)/d(alpha_dot) + sum log|det S| / time
    (Liouville's formula between switches, det of each jump).  The divergence is integrated with
    the tangent dynamics; the QR sums reproduce log|det Phi| to the integration's tolerance:
    relative 1e-6.  (Damping D: det S = 1 at each switch here -- at maximum compression the
    damping force vanishes under both laws, at separation the gap has no alpha_dot
    component -- so the saltation term is ~1e-9 1/s, rounding.)"""
    L = lyapunov_exponents(RIG, SCENE, speed_rpm=speed, settings=LyapunovSettings(40, 20, 4))
    assert L.switches > 0
    assert L.exponents.sum() == pytest.approx(L.divergence_mean + L.saltation_rate, rel=1e-6)
    assert abs(L.saltation_rate) < 1e-6 * abs(L.divergence_mean)


def test_a_contraction_beyond_the_range_of_a_double_is_renormalised_not_lost():
    """The 16 mm line contact of the reference experiment at 135 rev/min with viscous damping
    (model A): a bouncing cascade settles into contact, whose damping contracts the tangent
    vectors by about e^-1500 per revolution, beyond the smallest double (e^-745): without
    re-orthonormalising within the revolution, Phi underflowed to 0 and lambda_1 was -inf.
    Renormalised, both exponents are finite and their sum keeps Liouville's identity (rel 1e-6,
    as above)."""
    scene = camdyn.Scene(contact="line", damping="A", friction="coulomb")
    L = lyapunov_exponents(CHAOS_RIG, scene, speed_rpm=135.0, settings=LyapunovSettings(20, 20, 4))
    assert np.all(np.isfinite(L.exponents))
    assert L.largest * L.period < -745.0           # the case: more than a double's range per revolution
    assert L.exponents.sum() == pytest.approx(L.divergence_mean + L.saltation_rate, rel=1e-6)


def test_the_chaotic_case_has_a_positive_exponent_near_the_measured_divergence(chaotic):
    """tests/test_chaos.py measured two runs 1e-9 rad apart separating by e^0.62 per revolution
    (median of 10 starts, range 0.39-1.04).  lambda_1 T over 100 revolutions: positive by more
    than 3 standard errors, and inside that range."""
    lam, se = chaotic.largest, chaotic.standard_error[0]
    assert lam > 3 * se
    assert 0.39 <= lam * chaotic.period <= 1.04
    assert chaotic.exponents[1] < 0 < chaotic.exponents[0]     # dissipative: the sum is negative
    assert chaotic.revolutions == 100 and chaotic.transient == 100


def test_the_chaotic_exponent_converges_as_rtol_tightens(chaotic):
    """A chaotic trajectory changes with the tolerance, its exponent only within its
    statistical error: rtol 1e-9 and 1e-11 against 1e-10 within 4 combined standard errors."""
    for rtol in (1e-9, 1e-11):
        other = _chaos(rtol)
        combined = math.hypot(other.standard_error[0], chaotic.standard_error[0])
        assert abs(other.largest - chaotic.largest) <= 4 * combined


def test_bad_settings_name_the_parameter():
    with pytest.raises(camdyn.ParameterError, match="revolutions"):
        LyapunovSettings(revolutions=15, batches=10)
    with pytest.raises(camdyn.ParameterError, match="transient"):
        LyapunovSettings(transient=-1)
    with pytest.raises(camdyn.ParameterError, match="settings"):
        lyapunov_exponents(RIG, SCENE, speed_rpm=1500.0, settings=None)


# --- the largest exponent from two neighbouring runs (issue 29: every damping law) ------------------
@pytest.fixture(scope="module")
def by_differences():
    from camdyn.model.model import Model
    from camdyn.orbits.lyapunov import largest_by_differences

    def estimate(damping):
        scene = camdyn.Scene(contact="line", damping=damping, friction="coulomb")
        return largest_by_differences(Model(CHAOS_RIG, scene, camdyn.ConstantSpeed(CHAOS_SPEED)), CHAOS)
    return estimate


def test_the_difference_estimate_agrees_with_the_tangent_dynamics_on_the_chaotic_run(chaotic, by_differences):
    """Damping D, where both work: the same run, the same revolutions; two estimates of one number,
    within their combined standard error (measured 2.62 and 2.65 1/s, standard errors 0.31, 0.34),
    and the neighbour's distance changes it by less than one standard error (measured 2e-4 1/s)."""
    d = by_differences("D")
    assert abs(d.largest - chaotic.largest) < math.hypot(d.standard_error, chaotic.standard_error[0])
    assert abs(d.delta_difference) < d.standard_error


@pytest.mark.parametrize("damping", ["C", "E"])
def test_damping_laws_without_tangent_dynamics_get_an_exponent_and_a_verdict(by_differences, damping):
    """C and E (c ~ |psi_i|^(1/4)): the tangent integration cannot pass first contact; two
    neighbouring runs give lambda_1 (measured 1.59 +- 0.28 and 1.45 +- 0.24 1/s at 196 rev/min:
    chaotic, as the periodicity heuristic said), its distance's effect below one standard error."""
    from camdyn.orbits.tangent import TangentFailure
    from camdyn.studies.common import chaos_by_lyapunov

    scene = camdyn.Scene(contact="line", damping=damping, friction="coulomb")
    with pytest.raises(TangentFailure):
        lyapunov_exponents(CHAOS_RIG, scene, speed_rpm=CHAOS_SPEED, settings=CHAOS)
    d = by_differences(damping)
    assert math.isfinite(d.largest) and abs(d.delta_difference) < d.standard_error
    verdict = chaos_by_lyapunov(CHAOS_RIG, damping, CHAOS_SPEED, CHAOS.transient, CHAOS.revolutions, CHAOS.batches)
    assert verdict["lyapunov_method"] == "differences" and verdict["chaos"] == "chaotic"


def test_a_stable_orbit_of_damping_C_is_regular_at_both_distances():
    """Below the contact-loss speed (130 rev/min on reference-experiment) damping C's follower
    rides the cam on a stable period-1 orbit: both neighbours of the two-run estimate sink
    towards it, the estimate is negative at delta and at 10 delta by many standard errors,
    whatever its size there (which the distance sets: the runs' error floor over delta), and
    the verdict is regular (the chaos tables' C and E rows at 140-145 rev/min)."""
    from camdyn.model.model import Model
    from camdyn.orbits.lyapunov import largest_by_differences

    scene = camdyn.Scene(contact="line", damping="C", friction="coulomb")
    d = largest_by_differences(Model(CHAOS_RIG, scene, camdyn.ConstantSpeed(110.0)),
                               LyapunovSettings(revolutions=20, transient=20, batches=5))
    assert d.largest < -3 * d.standard_error and d.at_ten_delta < -3 * d.standard_error
    assert d.verdict(3.0) == "regular"


def test_the_two_run_verdict_holds_only_where_both_distances_agree():
    """The rule of DifferenceEstimate.verdict on made-up estimates: a sign that flips between the
    two distances, or an estimate within the bound of zero, is undecided."""
    from camdyn.orbits.lyapunov import DifferenceEstimate

    def verdict(at_delta, at_ten_delta, se=0.1):
        return DifferenceEstimate(at_delta, se, at_ten_delta, 100, 100, 0.4, 1e-7).verdict(3.0)
    assert verdict(2.0, 2.5) == "chaotic" and verdict(-13.6, -20.0) == "regular"
    assert verdict(2.0, -2.0) == "undecided" and verdict(2.0, 0.2) == "undecided" and verdict(-0.2, -5.0) == "undecided"
