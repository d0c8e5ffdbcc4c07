"""Derivatives of the stroboscopic map are checked before they are used (issue 25, item 1).

Found by an independent implementation: on rigs with a small contact margin (a soft spring, a
small preload, a large eccentricity), at 0.8-0.95 x their contact-loss speed, the central
differences of the map stepped across the orbit's contact margin, the perturbed runs separated
and re-impacted while the orbit stayed in contact, and the Floquet multipliers were off by up to
0.96, reported CONVERGED.  On the same kind of rig with a point contact, the perturbed runs keep
the contact but the Hertz law is so curved at the step's scale that the difference is off by
0.01-0.03.  camdyn.orbits.derivatives now takes a difference only along the base run's hybrid path and
only once two steps agree, else falls back to the variational provider, else says the
multipliers are unresolved.

The synthetic maps below test the rule itself; the rigs test it where it was found.
"""
from __future__ import annotations

import functools
import math

import numpy as np
import pytest

import camdyn
from camdyn.analysis.statics import contact_loss_speed
from camdyn.orbits.derivatives import (SHRINK, Column, FiniteDifferences, Unresolved, finite_differences,
                                       resolved_difference, step_floor)
from camdyn.engine.config import SolverOptions
from camdyn.orbits.shooting import OrbitOutcome
from camdyn.orbits.section_map import DEFAULT_OPTIONS, MapDerivative, MapFailure, MapValue
from camdyn.orbits.tangent import variational
from registry import SMALL_MARGIN

RTOL = DEFAULT_OPTIONS.rtol


# ------------------------------------------------------------------ the rule on maps given in closed form
def _line(f, paths=lambda offset: (), domain=math.inf):
    """A map along one direction: P(offset) = f(offset), its path (transitions) a function of the
    offset, refused (outside the mode's domain) beyond ``domain``."""
    def evaluate(offset):
        if abs(offset) > domain:
            raise MapFailure("outside the mode's domain")
        return MapValue(np.asarray(f(offset), dtype=float), 0, 0, 0, paths(offset))
    return evaluate


def _cubic(offset):
    return np.array([2.0 * offset + 0.5 * offset ** 3, -offset])


COLUMN = Column.of(1.0, np.ones(2), RTOL)       # first step rtol^(1/3) = 4.6e-4, floor rtol^(1/2) = 1e-5


def test_a_smooth_map_is_differenced_at_its_first_pair_of_steps():
    evaluate = _line(_cubic)
    column, h = resolved_difference(evaluate, evaluate(0.0), COLUMN)
    assert h == COLUMN.first / SHRINK
    # central differences of a cubic: error 0.5 h^2 = 6.7e-9 at h = 1.2e-4
    np.testing.assert_allclose(column, [2.0, -1.0], atol=1e-8)


def test_a_step_across_a_switch_is_shrunk_below_it():
    """The path changes (an impact gained) beyond 2e-4: the first step (4.6e-4) is refused, the
    next pair within the margin (1.2e-4, 2.9e-5) agrees and the smaller is taken."""
    evaluate = _line(_cubic, paths=lambda offset: (3,) if abs(offset) > 2e-4 else ())
    column, h = resolved_difference(evaluate, evaluate(0.0), COLUMN)
    assert h == COLUMN.first / SHRINK ** 2
    np.testing.assert_allclose(column, [2.0, -1.0], atol=1e-8)


def test_a_margin_with_one_step_above_the_floor_is_unresolved():
    """Beyond 5e-5 the path changes: one step (2.9e-5) keeps it above the floor (1e-5), and no
    smaller one can confirm it."""
    evaluate = _line(_cubic, paths=lambda offset: (3,) if abs(offset) > 5e-5 else ())
    with pytest.raises(Unresolved, match="no smaller step above the floor confirms it"):
        resolved_difference(evaluate, evaluate(0.0), COLUMN)


def test_a_step_outside_the_mode_is_shrunk_like_a_switch():
    evaluate = _line(_cubic, domain=2e-4)
    column, h = resolved_difference(evaluate, evaluate(0.0), COLUMN)
    assert h == COLUMN.first / SHRINK ** 2
    np.testing.assert_allclose(column, [2.0, -1.0], atol=1e-8)


def test_a_margin_below_the_floor_is_unresolved_and_says_why():
    """The orbit's margin (1e-6) is below the floor (1e-5): no difference is a derivative; the
    secant across the first step that ran is kept as a direction, not as a derivative."""
    evaluate = _line(_cubic, paths=lambda offset: (3,) * 100 if abs(offset) > 1e-6 else ())
    with pytest.raises(Unresolved, match="made 100 switches against the base run's 0") as info:
        resolved_difference(evaluate, evaluate(0.0), COLUMN)
    difference, h = info.value.secant
    assert h == COLUMN.first


def test_a_map_curved_below_the_floor_is_unresolved():
    """tanh(offset / 1e-6): the same path everywhere, but no two steps above the floor agree."""
    evaluate = _line(lambda offset: np.array([math.tanh(offset / 1e-6), 0.0]))
    with pytest.raises(Unresolved, match="not smooth at that scale"):
        resolved_difference(evaluate, evaluate(0.0), COLUMN)


def test_a_map_curved_above_the_floor_is_resolved_where_two_steps_agree():
    """0.05 tanh(offset / 0.05): the central difference's error h^2 / (3 0.05^2) is 2.8e-5 at the
    first step, so the first pair differs by more than the tolerance 1e-5; the next pair agrees,
    and the smaller step's difference meets the derivative 1 to 1.8e-6."""
    evaluate = _line(lambda offset: np.array([0.05 * math.tanh(offset / 0.05), 0.0]))
    column, h = resolved_difference(evaluate, evaluate(0.0), COLUMN)
    assert h == COLUMN.first / SHRINK ** 2
    assert abs(column[0] - 1.0) <= COLUMN.tol


def test_a_failed_run_is_not_taken_for_a_domain_change():
    def evaluate(offset):
        if offset:
            raise MapFailure("chatter", camdyn.Outcome.CHATTER)
        return MapValue(np.zeros(2), 0, 0, 0)
    with pytest.raises(MapFailure, match="chatter"):
        resolved_difference(evaluate, evaluate(0.0), COLUMN)


def test_the_floor_is_the_noise_level_of_the_difference():
    # rtol times the size over the step is the noise's share: rtol^(1/2) of the size at the floor
    assert step_floor(2.0, 1e-10) == pytest.approx(2e-5)
    assert COLUMN.tol == pytest.approx(1e-5)


# ------------------------------------------------------------------ the provider: fallback or unresolved
class _SwitchyMap:
    """P(x) = A x, whose runs gain an impact once x[0] leaves +-1e-7: no derivative in column 0."""

    options = DEFAULT_OPTIONS
    A = np.array([[0.5, 0.2], [0.1, 0.3]])

    def __init__(self):
        self.runs = 0

    def admits(self, x):
        return True

    def evaluate(self, x):
        self.runs += 1
        x = np.asarray(x, dtype=float)
        return MapValue(self.A @ x, 0, 0, 0, (1,) if abs(x[0]) > 1e-7 else ())

    def __call__(self, x):
        return self.evaluate(x).state


class _StiffContactMap(_SwitchyMap):
    """P(x) = A x in a mode whose domain is x[0] <= 1e-7 (a stiff contact's deflection smaller
    than any step above the floor): a perturbed state in column 0 is outside it."""

    def admits(self, x):
        return x[0] <= 1e-7

    def evaluate(self, x):
        if not self.admits(x):
            raise MapFailure(f"the state {tuple(x)} is outside the mode's domain")
        return super().evaluate(x)


def test_an_unresolved_column_without_fallback_is_reported_unresolved():
    d = FiniteDifferences(_SwitchyMap(), np.ones(2)).derivative(np.zeros(2))
    assert not d.resolved and d.provider == "finite_differences"
    assert "column 0" in d.note and "column 1" not in d.note
    np.testing.assert_allclose(d.jacobian[:, 1], _SwitchyMap.A[:, 1], atol=1e-9)   # the resolved column


def test_an_unresolved_column_falls_back_and_says_so():
    exact = MapDerivative(np.zeros(2), _SwitchyMap.A.copy(), "exact")
    d = FiniteDifferences(_SwitchyMap(), np.ones(2), fallback=lambda m: (lambda x: (exact.value, exact.jacobian))) \
        .derivative(np.zeros(2))
    assert d.resolved and np.array_equal(d.jacobian, _SwitchyMap.A) and "finite differences unresolved" in d.note

    section_map = _SwitchyMap()
    FiniteDifferences(section_map, np.ones(2), fallback=lambda m: (lambda x: (exact.value, exact.jacobian))) \
        .derivative(np.zeros(2))
    assert section_map.runs == 1 + 2 * 3     # the base, then column 0's three steps above the floor; not column 1

    def failing(section_map):
        raise MapFailure("the scene has no variational kernels (a linear model)")
    d = FiniteDifferences(_SwitchyMap(), np.ones(2), fallback=failing).derivative(np.zeros(2))
    assert not d.resolved and "the fallback failed: the scene has no variational kernels" in d.note


def test_a_step_outside_the_start_modes_domain_is_shrunk_without_a_run():
    """No run is made from a perturbed state the start mode's domain does not hold (the check
    costs no run): the base run alone, then the fallback."""
    exact = MapDerivative(np.zeros(2), _SwitchyMap.A.copy(), "exact")
    section_map = _StiffContactMap()
    d = FiniteDifferences(section_map, np.ones(2), fallback=lambda m: (lambda x: (exact.value, exact.jacobian))) \
        .derivative(np.zeros(2))
    assert section_map.runs == 1
    assert d.resolved and "outside it" in d.note and "column 1" not in d.note


# ------------------------------------------------------------------ rigs with a small contact margin
TIGHT = SolverOptions(rtol=1e-12, atol=1e-15)
#: the multipliers of a resolved derivative against the tight reference: the resolved difference's
#: tolerance rtol^(1/2) = 1e-5 (scaled) bounds the Jacobian's error, and the multipliers of a 2 x 2
#: matrix with distinct eigenvalues move by about as much; the variational provider's own error
#: is ~1e-11 here (measured against the tight reference: 5e-14 to 5e-11)
AGREE = 1e-5


@pytest.fixture(scope="module", params=sorted(SMALL_MARGIN))
def small_margin(request):
    rig, scene = SMALL_MARGIN[request.param]
    return request.param, rig, scene, contact_loss_speed(rig)


@pytest.mark.parametrize("fraction", [0.8, 0.9, 0.95])
def test_small_margin_multipliers_agree_with_a_tight_reference_or_are_unresolved(small_margin, fraction):
    """At 0.8-0.95 x the contact-loss speed: the default provider (finite differences, with the
    variational fallback) gives the multipliers of the variational provider at rtol 1e-12; the
    finite differences alone give them too, or say they are unresolved; never CONVERGED with other
    numbers (the old differences were off by 0.01-0.96 on these rigs)."""
    name, rig, scene, loss = small_margin
    speed = fraction * loss
    reference = camdyn.periodic_orbit(rig, scene, speed_rpm=speed, jacobian=variational, options=TIGHT)
    assert reference.outcome is OrbitOutcome.CONVERGED, (name, reference.message)
    default = camdyn.periodic_orbit(rig, scene, speed_rpm=speed)
    assert default.outcome is OrbitOutcome.CONVERGED, (name, default.message)
    assert np.max(np.abs(default.multipliers - reference.multipliers)) < AGREE, (name, default.jacobian_provider)
    alone = camdyn.periodic_orbit(rig, scene, speed_rpm=speed, jacobian=functools.partial(finite_differences,
                                                                                         fallback=False))
    if alone.outcome is OrbitOutcome.MULTIPLIERS_UNRESOLVED:
        assert alone.multipliers.size == 0 and alone.stable is None and "unresolved" in alone.message
    else:
        assert alone.outcome is OrbitOutcome.CONVERGED and alone.jacobian_provider == "finite_differences"
        assert np.max(np.abs(alone.multipliers - reference.multipliers)) < AGREE, name


def test_an_orbit_says_which_provider_gave_its_multipliers():
    rig, scene = SMALL_MARGIN["soft spring"]
    orbit = camdyn.periodic_orbit(rig, scene, speed_rpm=0.9 * contact_loss_speed(rig))
    assert orbit.jacobian_provider == "variational" and np.all(np.isnan(orbit.difference_steps))
    assert orbit.jacobian_note.startswith("finite differences unresolved")
    impacting = camdyn.periodic_orbit(camdyn.example_rig(), camdyn.Scene(damping="D", friction="coulomb"), speed_rpm=1500.0)
    assert impacting.jacobian_provider == "finite_differences" and np.all(impacting.difference_steps > 0)
    assert impacting.jacobian_note == ""


def test_a_branch_on_a_small_margin_rig_states_its_provider_and_steps():
    """The continuation takes its derivatives under the same rule (dP/dx from the provider,
    dP/dlambda by the resolved difference): each point says how, and its multipliers are the
    tight reference's."""
    rig, scene = SMALL_MARGIN["soft spring"]
    loss = contact_loss_speed(rig)
    ds = camdyn.continue_orbit(rig, scene, "speed_rpm", 0.85 * loss, 0.9 * loss)
    assert ds["resolved"].values.all()
    providers = ds.attrs["providers"].split()
    assert {providers[k] for k in ds["jacobian_provider"].values} == {"variational"}
    assert np.all(np.isnan(ds["difference_step"].values[:, :2])) and np.all(ds["difference_step"].values[:, 2] > 0)
    last = int(ds.sizes["point"]) - 1
    reference = camdyn.periodic_orbit(rig, scene, speed_rpm=float(ds["lambda"][last]), jacobian=variational,
                                      options=TIGHT)
    mu = ds["multiplier_real"].values[last] + 1j * ds["multiplier_imag"].values[last]
    assert np.max(np.abs(mu - reference.multipliers)) < AGREE
