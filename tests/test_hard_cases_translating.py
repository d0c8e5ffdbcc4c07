"""The hard cases of tests/test_hard_cases.py on the translating follower and a cam that is not a circle
(issue 27): its cycloidal rise-dwell-return cam (camdyn.model.presets.translating_cam_example_rig),
whose jerk jumps at the ends of each segment, with damping D (its episode switch) and a stiff steel
line contact (k = 1.57 GN/m against a 1.2 kg follower: a contact mode at 36,000 rad/s)."""
from __future__ import annotations

import math

import numpy as np
import pytest

import camdyn
from camdyn import analysis
from camdyn.engine import EventSettings
from camdyn.model.presets import translating_cam_example_rig

from registry import METHODS

RIG = translating_cam_example_rig()
SCENE = camdyn.Scene(follower="translating", friction="none", profile="spline")


pytestmark = pytest.mark.usefixtures("quiet_compile")  # (tests/conftest.py)


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


@pytest.mark.parametrize("method", METHODS)
def test_pieces_join_into_the_same_run_of_the_translating_follower(loss, method, monkeypatch):
    """A hopping run (1.1 x the jump speed, 340 impacts) cut into phase-wrapped pieces of one kernel period
    equals the run in one piece: each piece restarts the step size, so the runs differ by local errors
    (measured 5e-11 s and 2e-13 m; bounds those of tests/test_hard_cases.py, 1e-8 s and 1e-8 m).  At 1.3 x
    the motion amplifies them (5e-7 s over 10 revolutions): that speed would test the motion, not the join."""
    from camdyn.runs import pieces
    kw = dict(speed_rpm=1.1 * loss, revolutions=10, sample_rate_Hz=5000, rtol=1e-10, atol=1e-14, method=method)
    whole = camdyn.simulate(RIG, SCENE, **kw)
    monkeypatch.setattr(pieces, "PIECE_PERIODS", 1)
    cut = camdyn.simulate(RIG, SCENE, **kw)
    assert whole.ok and cut.ok and cut.stats["pieces"] == 5 and whole.impacts().size > 5
    assert [(s.surface, s.after) for s in cut.switches] == [(s.surface, s.after) for s in whole.switches]
    np.testing.assert_allclose([s.t for s in cut.switches], [s.t for s in whole.switches], rtol=0, atol=1e-8)
    assert np.abs(cut.y - whole.y).max() < 1e-8


@pytest.mark.parametrize("method, order, steps", [("DOP853", 8, [1.6e-4, 1.2e-4, 8e-5, 5e-5]),
                                                  ("RK45", 5, [8e-5, 5e-5, 3e-5, 2e-5])])
def test_observed_order_on_the_translating_follower(eq, method, order, steps):
    """Smooth contact (undamped, frictionless, cam at rest, 10 nm off equilibrium: the contact never
    opens) with the step fixed: the error against a tight reference falls as h^p, at least at the method's
    order less 0.5 (tests/test_hard_cases.py's bound) and at most one more (the field is linear here, where
    RK45's error falls a little faster over these steps: measured slopes RK45 5.65, DOP853 7.79)."""
    scene = camdyn.Scene(follower="translating", damping="none", friction="none", profile="spline")
    kw = dict(speed_rpm=0, t_end=0.005, sample_rate_Hz=3000, y0=(eq.q + 1e-8, 0.0))
    ref = camdyn.simulate(RIG, scene, rtol=1e-13, atol=1e-22, **kw).y
    errors = [np.abs(camdyn.simulate(RIG, scene, method=method, rtol=1e-2, atol=1e-2, max_step=h, **kw).y - ref).max()
              for h in steps]
    slope = np.polyfit(np.log(steps), np.log(errors), 1)[0]
    assert order - 0.5 <= slope <= order + 1.0


def test_the_continued_grazing_of_the_translating_follower_is_its_jump(loss):
    """The period-1 orbit continued in the speed from 0.8 x to 1.2 x the inverse-kinematics jump speed
    locates its grazing within 1e-4 of that speed (the contact's compliance moves it by 1.1e-5 here)."""
    from camdyn.orbits.continuation import events_table
    branch = camdyn.continue_orbit(RIG, SCENE, "speed_rpm", 0.8 * loss, 1.2 * loss)
    grazing = [speed for kind, speed, _, _ in events_table(branch) if kind == "grazing"]
    assert grazing and abs(grazing[0] / loss - 1) < 1e-4


@pytest.mark.parametrize("method", METHODS)
def test_a_loose_tolerance_invents_no_damping_law_switches_where_the_cam_moves(method):
    """Riding the cycloidal cam at 0.8 x its jump speed for 0.2 s at rtol 1e-6, damping D.  The memoryless
    reading switches laws where psi_i_dot crosses 0: on the rise and the return (cam angles 0-100 and
    180-280 degrees) the loose run has no more than 25 % (DOP853), 40 % (RK45) more switches than at rtol
    1e-12, tests/test_hard_cases.py's bounds (measured 80 and 72 against 67).  On the dwells, where the
    contact's vibration has died out and psi_i_dot is ~0, the memoryless law flips on the integration's
    noise (the README says so: about 4 x the reference's switches there, measured), which moves the motion
    by no more than 1e-10 m (measured 3e-11 m, 6e-4 of the residual); the episode reading, the default,
    switches once."""
    loss = analysis.contact_loss_speed(RIG)
    kw = dict(speed_rpm=0.8 * loss, t_end=0.2, sample_rate_Hz=5000)
    memoryless = camdyn.Scene(follower="translating", friction="none", profile="spline", damping_switch="memoryless")
    ref = camdyn.simulate(RIG, memoryless, rtol=1e-12, atol=1e-16, **kw)
    run = camdyn.simulate(RIG, memoryless, rtol=1e-6, atol=1e-10, method=method, **kw)
    assert run.ok

    def on_the_move(r) -> int:
        angle = np.degrees(np.mod(np.interp([s.t for s in r.switches], r.t, r.Theta), 2 * math.pi))
        return int(np.sum((angle < 100) | ((angle >= 180) & (angle < 280))))

    excess = {"DOP853": 0.25, "RK45": 0.40}[method]
    assert on_the_move(ref) > 10
    assert abs(on_the_move(run) - on_the_move(ref)) <= excess * on_the_move(ref)
    assert np.max(np.abs(run.y - ref.y)) < 1e-10
    episode = camdyn.simulate(RIG, SCENE, rtol=1e-6, atol=1e-10, method=method, **kw)
    assert [s.surface for s in episode.switches] == ["gap_rate"]


def test_a_translating_run_late_in_time_costs_what_it_costs_at_the_start(loss):
    """The same 20 hopping revolutions started at t = 0 and at t = 20000 T (the same cam phase), rtol 1e-11:
    with the phase-wrapped pieces the late run takes the steps the early one takes (without them the
    oscillating follower's took 857 x as many, tests/test_hard_cases.py), within 10 % (the bouncing cascades
    amplify the rounding of t, so the two runs part after a few revolutions: measured 3 %), and the same
    motion over the first 3 revolutions within 1e-9 m."""
    speed = 1.1 * loss
    T = 60.0 / speed
    kw = dict(speed_rpm=speed, revolutions=20, rtol=1e-11, atol=1e-14, sample_rate_Hz=2000)
    early = camdyn.simulate(RIG, SCENE, t_start=0.0, **kw)
    late = camdyn.simulate(RIG, SCENE, t_start=20_000 * T, **kw)
    assert early.ok and late.ok and early.impacts().size > 10
    assert late.stats["steps"] == pytest.approx(early.stats["steps"], rel=0.1)
    n = int(3 * T * 2000)
    assert np.abs(late.y[:n] - early.y[:n]).max() < 1e-9
