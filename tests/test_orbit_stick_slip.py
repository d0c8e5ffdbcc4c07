"""Shooting on a stick-slip orbit: Section 7.2's oscillating cam (Theta_p = pi, 40 rev/min,
e = 0.7 r_c, the preloaded rig of tests/test_hard_cases.py), where the follower sticks at each
reversal of the cam (Filippov sliding on v_r = 0) and slips again.

The periodic orbit crosses the slip surface into the stuck mode and leaves it through a
slip-rate surface twice per cam period, so the map P_1 is composed of sliding-mode entries:
each maps a neighbourhood of the orbit onto the curve v_r = 0, and the monodromy matrix has
rank <= 1 in exact arithmetic (one multiplier 0); the other is contracted by the contact
damping over the 1.5 s period (thousands of contact oscillations).  Both multipliers are
therefore zero to the accuracy of the finite-difference monodromy.
"""
from __future__ import annotations

import math
import warnings

import numpy as np
import pytest

import camdyn
from camdyn import periodic_orbit
from camdyn.model.model import Model
from camdyn.orbits.shooting import OrbitOutcome
from camdyn.orbits.section_map import DEFAULT_OPTIONS

RIG = camdyn.example_rig()
PRELOADED = RIG.replace(e=0.7 * RIG.r_c, L_us=0.2)  # keeps contact over the oscillating cam's stroke
SCENE = camdyn.Scene(damping="D", friction="coulomb", motion="oscillating")
CAM = camdyn.Oscillating(math.pi, 40)
#: the finite-difference monodromy's entries carry errors ~rtol^(2/3) = 2e-7 at the map's
#: rtol 1e-10 (camdyn.orbits.shooting.SINGULAR_SIGMA): a multiplier below 5 times that is zero to it
FD_ZERO = 1e-6


@pytest.fixture(scope="module")
def orbit():
    with warnings.catch_warnings():
        warnings.simplefilter("ignore", camdyn.CompileNotice)
        return periodic_orbit(PRELOADED, SCENE, CAM, warmup_revolutions=3)


@pytest.fixture(scope="module")
def one_period(orbit):
    """One cam period from the fixed point, at the map's tolerances."""
    return camdyn.simulate(PRELOADED, SCENE, CAM, t_start=orbit.phase, t_end=orbit.phase + CAM.period,
                           y0=orbit.state, rtol=DEFAULT_OPTIONS.rtol, atol=DEFAULT_OPTIONS.atol)


def test_shooting_converges_on_the_stick_slip_orbit(orbit):
    assert orbit.outcome is OrbitOutcome.CONVERGED, orbit.message
    assert orbit.residual <= 1e-8  # ShootingSettings' default tol


def test_the_orbit_sticks_and_slips_twice_per_period(one_period):
    """Into a stuck mode through the slip surface, out through a slip-rate surface, at each of
    the cam's two reversals per period."""
    K = Model(PRELOADED, SCENE, CAM).kernels
    stuck = {K.MODES[m] for m in range(len(K.MODES)) if K.SLIP_OF_MODE[m] == "stick"}
    entries = [s for s in one_period.switches if s.after in stuck]
    exits = [s for s in one_period.switches if s.before in stuck]
    assert [s.surface for s in entries] == ["slip", "slip"]
    assert {s.surface for s in exits} <= {"slip_rate_fwd", "slip_rate_bwd"} and len(exits) == 2
    # one reversal in each half of the period (the cam turns back at T/4 and 3T/4)
    assert entries[0].t < CAM.period / 2 < entries[1].t


def test_the_fixed_point_reproduces_itself_over_a_period(orbit, one_period):
    """The run from the fixed point returns to it: to the Newton tolerance 1e-8 times the scale
    of the motion (the residual's definition), the run's own error far below it."""
    end = np.array([one_period.alpha[-1], one_period.alpha_dot[-1]])
    assert np.all(np.abs(end - orbit.state) <= 1e-8 * orbit.scale)


def test_the_sliding_mode_collapses_the_monodromy(orbit):
    """Both Floquet multipliers are zero to the finite-difference accuracy (module docstring),
    so the orbit is stable."""
    assert orbit.stable is True
    assert np.max(np.abs(orbit.multipliers)) < FD_ZERO
