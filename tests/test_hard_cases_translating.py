"""The hard cases of tests/test_hard_cases.py on the translating follower and a cam that is not a circle
(issue 27): its cycloidal rise-dwell-return cam (camdyn.model.presets.translating_cam_example_rig),
whose jerk jumps at the ends of each segment, with damping D (its episode switch) and a stiff steel
line contact (k = 1.57 GN/m against a 1.2 kg follower: a contact mode at 36,000 rad/s)."""
from __future__ import annotations

import math
import warnings

import numpy as np
import pytest

import camdyn
from camdyn import analysis
from camdyn.engine import EventSettings
from camdyn.model.presets import translating_cam_example_rig

from registry import METHODS

RIG = translating_cam_example_rig()
SCENE = camdyn.Scene(follower="translating", friction="none", profile="spline")


@pytest.fixture(autouse=True)
def _quiet():
    with warnings.catch_warnings():
        warnings.simplefilter("ignore", camdyn.CompileNotice)
        yield


@pytest.fixture(scope="module")
def loss():
    return analysis.contact_loss_speed(RIG)


@pytest.fixture(scope="module")
def eq():
    return analysis.static_equilibrium(RIG)


@pytest.fixture(scope="module")
def grazing_reference(loss):
    """0.1 % above the inverse-kinematics jump speed the follower barely hops; rtol 1e-12 reference."""
    return camdyn.simulate(RIG, SCENE, speed_rpm=1.001 * loss, revolutions=4, sample_rate_Hz=5000,
                           rtol=1e-12, atol=1e-15).after(2 * 60 / (1.001 * loss))


@pytest.mark.parametrize("method", METHODS)
def test_grazing_hops_on_the_translating_follower_are_neither_missed_nor_duplicated(loss, grazing_reference,
                                                                                    method):
    """Each hop at rtol 1e-8 matches one reference hop within 1e-5 s (the grazing crossings are slow, so
    the state's error moves them; the oscillating follower's bound, tests/test_hard_cases.py)."""
    r = camdyn.simulate(RIG, SCENE, speed_rpm=1.001 * loss, revolutions=4, sample_rate_Hz=5000, rtol=1e-8,
                        method=method).after(2 * 60 / (1.001 * loss))
    assert r.ok
    ref = grazing_reference.separations()
    assert ref.size >= 2 and np.diff(ref).min() > 20 * 1e-5  # hops far apart against the bound: matched one to one
    np.testing.assert_allclose(r.separations(), ref, rtol=0, atol=1e-5)
    np.testing.assert_allclose(r.impacts(), grazing_reference.impacts(), rtol=0, atol=1e-5)


def test_just_below_the_jump_speed_the_translating_follower_never_separates(loss):
    """0.1 % below: the compliance moves the jump by ~1e-5 of the speed (the continuation's grazing,
    docs/model-editing.md), far less than the margin."""
    r = camdyn.simulate(RIG, SCENE, speed_rpm=0.999 * loss, revolutions=4, sample_rate_Hz=5000, rtol=1e-10)
    assert r.ok and r.after(2 * r.period).separations().size == 0


@pytest.mark.parametrize("method", METHODS)
def test_a_bouncing_cascade_of_the_translating_follower_ends_in_permanent_contact(eq, method):
    """Dropped 20 um above its equilibrium on the cam at rest: impacts of decreasing height end in
    contact in finite time (damping D's impact law takes energy at each), the contact mode rings down."""
    r = camdyn.simulate(RIG, SCENE, speed_rpm=0, t_end=0.3, y0=(eq.q + 2e-5, 0.0), sample_rate_Hz=20_000,
                        method=method)
    assert r.ok
    impacts = r.impacts()
    assert 3 < impacts.size < 400
    assert impacts[-1] < 0.2
    assert np.all(r.regime[r.t > impacts[-1] + 0.01] != "free")


@pytest.mark.parametrize("method", METHODS)
def test_damping_D_switches_once_per_contact_episode_on_the_translating_follower(loss, method):
    """Hopping at 1.3 x the jump speed: each contact episode has one impact-law-to-viscous switch at its
    maximum compression (Sec. 3.4, the episode reading), never more."""
    r = camdyn.simulate(RIG, SCENE, speed_rpm=1.3 * loss, revolutions=3, sample_rate_Hz=5000, method=method)
    assert r.ok and r.impacts().size > 3
    episodes = r.impacts().size + 1  # the start is in contact
    compressions = sum(1 for s in r.switches if s.surface == "gap_rate")
    assert compressions <= episodes


@pytest.mark.parametrize("method", METHODS)
def test_the_energy_ledger_balances_on_the_translating_follower(loss, method):
    """energy(t) - energy(0) = work of the drive - contact damping (no friction in this scene), the works
    integrated with the state; bound 1e-6 of the largest flow at rtol 1e-10 (the oscillating follower's)."""
    r = camdyn.simulate(RIG, SCENE, speed_rpm=1.2 * loss, revolutions=2, sample_rate_Hz=5000, rtol=1e-10,
                        atol=1e-14, energy_ledger=True, method=method)
    assert r.ok and r.impacts().size > 0
    balance = r.energy - r.energy[0] - (r.work_in - r.dissipated_contact - r.dissipated_friction)
    scale = max(np.abs(r.work_in).max(), r.dissipated_contact.max())
    assert np.abs(balance).max() < 1e-6 * scale
    assert np.all(np.diff(r.dissipated_contact) >= -1e-12 * scale)


@pytest.mark.parametrize("method", METHODS)
def test_the_stiffest_contact_and_an_extreme_speed_stay_finite_on_the_translating_follower(loss, method):
    """A 16 mm steel line contact (2.5 GN/m) impacting, and a cam at 30 x the jump speed flinging the
    follower: the runs end cleanly (no angle limit: the translating follower has no singular coordinate)."""
    stiff = camdyn.simulate(RIG.replace(l_lambda=0.016), SCENE, speed_rpm=1.5 * loss, revolutions=2,
                            sample_rate_Hz=20_000, method=method)
    assert stiff.ok and stiff.impacts().size > 3
    for name in ("y", "F_n", "energy", "y_r"):
        assert np.all(np.isfinite(getattr(stiff, name)))
    flung = camdyn.simulate(RIG, SCENE, speed_rpm=30 * loss, revolutions=20, sample_rate_Hz=20_000, method=method)
    assert flung.ok and np.all(np.isfinite(flung.y))


@pytest.mark.parametrize("case", ["grazing", "cascade", "impacting"])
def test_the_reach_rule_changes_no_run_of_the_translating_follower(loss, eq, case):
    """A step cleared by the reach rule: the runs are bit for bit those that sample every step."""
    kw = {"grazing": dict(speed_rpm=1.001 * loss, revolutions=4, rtol=1e-8),
          "cascade": dict(speed_rpm=0, t_end=0.1, y0=(eq.q + 2e-5, 0.0)),
          "impacting": dict(speed_rpm=1.3 * loss, revolutions=3, rtol=1e-6)}[case]
    runs = [camdyn.simulate(RIG, SCENE, sample_rate_Hz=5000, events=EventSettings(reach_factor=f), **kw)
            for f in (math.inf, EventSettings().reach_factor)]
    assert runs[0].ok and len(runs[0].switches) > 0
    assert list(runs[1].switches) == list(runs[0].switches)
    np.testing.assert_array_equal(runs[1].y, runs[0].y)
    np.testing.assert_array_equal(runs[1].y_dot, runs[0].y_dot)
