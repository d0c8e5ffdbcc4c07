"""The rigid contact law (issue 28): Newton's impact law as a reset, the constrained mode and its
contact force, the chatter's end at its accumulation point, against closed forms."""
from __future__ import annotations

import math

import numpy as np
import pytest

import camdyn
from camdyn.analysis import contact_loss_speed
from camdyn.engine import EventSettings
from camdyn.errors import ParameterError, SceneError
from camdyn.model.presets import translating_example_rig

XI = 0.8
RIG = translating_example_rig().replace(xi=XI)
SCENE = camdyn.Scene(follower="translating", contact="rigid", damping="none", friction="none")
ROCKER = camdyn.example_rig().replace(xi=XI)
ROCKER_SCENE = camdyn.Scene(contact="rigid", damping="none", friction="none")


pytestmark = pytest.mark.usefixtures("quiet_compile")  # (tests/conftest.py)


@pytest.mark.parametrize("rig, scene", [(RIG, SCENE), (ROCKER, ROCKER_SCENE)], ids=["translating", "oscillating"])
def test_the_impact_reset_is_newtons_law(rig, scene):
    """At states with the cam turning, the generated impact reset leaves the normal relative velocity at
    -xi times its arrival (so the normal relative kinetic energy keeps xi^2 of itself: 1 - xi^2 is lost),
    the position unchanged; the plastic reset leaves it at 0.  Bound: rounding of the rates (1e-12)."""
    model = camdyn.Model(rig, scene, camdyn.ConstantSpeed(300))
    K = scene.kernels()
    q0 = model.static_state()[0]
    rng = np.random.default_rng(3)
    out = np.empty(2)
    for t, dq, v in zip(rng.uniform(0, 0.2, 20), rng.uniform(-1e-4, 1e-4, 20), rng.uniform(-0.5, 0.5, 20)):
        before = model.surface(K.MODE_FREE, K.SURFACE_GAP_RATE, t, q0 + dq, v)
        for reset, factor in ((K.RESET_IMPACT, -XI), (K.RESET_PLASTIC, 0.0)):
            K.reset(reset, t, q0 + dq, v, model.p, out)
            assert out[0] == q0 + dq
            after = model.surface(K.MODE_FREE, K.SURFACE_GAP_RATE, t, out[0], out[1])
            assert after == pytest.approx(factor * before, abs=1e-12 * max(1.0, abs(before)))


def _bounces(xi: float, drop: float, count: int) -> np.ndarray:
    """The closed form of the translating follower dropped by ``drop`` above its rest on the cam at rest:
    the flights are arcs of the spring's oscillation about y_c = y0 - F_p/k_s (frequency w = sqrt(k_s/m_f)),
    each leaving and landing at the same speed, which each impact multiplies by xi: the first landing at
    acos(d/(d + drop))/w with the speed w sqrt((d + drop)^2 - d^2), d = F_p/k_s; a flight at launch speed
    v lasts 2 atan2(v/w, d)/w.  Returns the first ``count`` impact times."""
    w, d = math.sqrt(RIG.k_s / RIG.m_f), RIG.F_p / RIG.k_s
    times, v = [math.acos(d / (d + drop)) / w], w * math.sqrt((d + drop) ** 2 - d ** 2)
    for _ in range(count - 1):
        v *= xi
        times.append(times[-1] + 2 * math.atan2(v / w, d) / w)
    return np.array(times)


def test_a_follower_bouncing_on_a_dwell_is_the_closed_form_and_its_chatter_ends_at_the_accumulation_point():
    """Dropped 1 mm on the cam at rest (a dwell): the impact times are the closed form's (bound 1e-9 s at
    rtol 1e-11; measured 4e-12 s over 40 impacts), the chatter ends in the constrained mode where the hops
    fall below atol, before the closed form's accumulation point and within the time the remaining flights
    take (a geometric tail below 1e-6 s here), and the follower rests on the cam."""
    y0 = RIG.r_c - RIG.e  # the 0-state: the base circle
    r = camdyn.simulate(RIG, SCENE, speed_rpm=0, t_end=0.3, y0=(y0 + 1e-3, 0.0), rtol=1e-11, atol=1e-14,
                        sample_rate_Hz=1000)
    assert r.ok
    impacts = r.impacts()
    closed = _bounces(XI, 1e-3, 400)
    assert impacts.size > 40
    np.testing.assert_allclose(impacts[:40], closed[:40], rtol=0, atol=1e-9)
    end = r.switches[-1]
    assert (end.surface, end.before, end.after) == ("gap", "free", "contact")
    accumulation = closed[-1]  # the flights after 400 impacts last < 1e-30 s
    assert end.t <= accumulation and accumulation - end.t < 1e-6
    assert r.y[-1] == y0 and r.y_dot[-1] == 0.0


def test_a_perfectly_elastic_bounce_never_ends_as_chatter():
    """xi = 1: every bounce rises as high as the first; the chatter rule must never end it (ratio 1)."""
    rig = RIG.replace(xi=1.0)
    y0 = rig.r_c - rig.e
    r = camdyn.simulate(rig, SCENE, speed_rpm=0, t_end=0.5, y0=(y0 + 1e-4, 0.0), rtol=1e-11, atol=1e-14,
                        sample_rate_Hz=1000)
    assert r.ok and "contact" not in set(r.regime)
    np.testing.assert_allclose(r.impacts(), _bounces(1.0, 1e-4, r.impacts().size), rtol=0, atol=1e-9)


def test_a_chatter_that_does_not_converge_in_time_is_refused():
    """A chatter followed impact by impact up to the event limit ends the run with its outcome."""
    y0 = RIG.r_c - RIG.e
    r = camdyn.simulate(RIG.replace(xi=0.99), SCENE, speed_rpm=0, t_end=2.0, y0=(y0 + 1e-3, 0.0),
                        events=EventSettings(max_events=30))
    assert r.outcome is camdyn.Outcome.MAX_EVENTS and len(r.switches) == 30


@pytest.mark.parametrize("rig, scene", [(RIG, SCENE), (ROCKER, ROCKER_SCENE)], ids=["translating", "oscillating"])
def test_the_rigid_follower_leaves_the_cam_at_the_inverse_kinematics_speed(rig, scene):
    """No compliance: 0.1 % below the inverse-kinematics speed the follower rides the cam (it never leaves;
    the rocker, released at rest where the cam recedes more slowly than it would fall, is put on the cam
    by the chatter's end within the time resolution of the start), 0.1 % above it leaves the constrained
    mode where its contact force turns negative."""
    loss = contact_loss_speed(rig)
    below = camdyn.simulate(rig, scene, speed_rpm=0.999 * loss, revolutions=3)
    assert below.ok and below.separations().size == 0 and np.all(below.switches.t < 1e-12)
    assert set(below.regime[1:]) == {"contact"}
    above = camdyn.simulate(rig, scene, speed_rpm=1.001 * loss, revolutions=3)
    assert above.ok and above.separations().size > 0


def test_the_translating_follower_leaves_where_the_closed_form_says():
    """At 1.1 x the loss speed the constrained force F_p + k_s e - (k_s e - m_f Omega^2 e) cos(phi) first
    reaches zero at phi = 2 pi - acos(-(F_p + k_s e) / (m_f Omega^2 e - k_s e)); the rigid run leaves there
    (bound 1e-7 rad: the engine's location of the force's root)."""
    loss = contact_loss_speed(RIG)
    omega = 1.1 * loss * 2 * math.pi / 60
    r = camdyn.simulate(RIG, SCENE, speed_rpm=1.1 * loss, revolutions=1, rtol=1e-11)
    leave = r.separations()[0]
    phi = (RIG.gamma - (RIG.theta0 + omega * leave)) % (2 * math.pi)
    kse = RIG.k_s * RIG.e
    assert phi == pytest.approx(2 * math.pi - math.acos(-(RIG.F_p + kse) / (RIG.m_f * omega**2 * RIG.e - kse)),
                                abs=1e-7)


def test_bad_input_for_the_rigid_law_is_refused_with_the_reason():
    with pytest.raises(ParameterError, match="xi"):
        RIG.replace(xi=1.2)
    with pytest.raises(SceneError, match="damping"):
        camdyn.Scene(contact="rigid", damping="D")
    with pytest.raises(ParameterError, match="xi"):
        camdyn.simulate(translating_example_rig(), SCENE, speed_rpm=100, revolutions=1)


@pytest.mark.parametrize("factor", [1.2, 1.5])
def test_saltation_multipliers_of_an_impacting_orbit_are_those_of_finite_differences(factor):
    """An impacting period-1 orbit of the rigid translating follower: its Floquet multipliers by the
    tangent dynamics, through the generalized saltation matrix of each impact (the reset's Jacobian,
    generated), against central differences of the map.  Bound 1e-6: the differences' truncation and the
    map's noise at the default tolerances (measured 2e-8)."""
    from camdyn.orbits.derivatives import finite_differences
    from camdyn.orbits.tangent import variational
    speed = factor * contact_loss_speed(RIG)
    by_differences = camdyn.periodic_orbit(RIG, SCENE, speed_rpm=speed, jacobian=finite_differences)
    by_saltation = camdyn.periodic_orbit(RIG, SCENE, speed_rpm=speed, jacobian=variational)
    assert by_differences.ok and by_saltation.ok
    assert np.max(np.abs(np.sort_complex(by_saltation.multipliers) - np.sort_complex(by_differences.multipliers))) < 1e-6
    assert np.max(np.abs(by_saltation.multipliers)) > 0.1  # an orbit the impacts leave room to move in


def test_the_second_rig_leaves_its_arc_cam_at_the_inverse_kinematics_speed_and_corners_fling_it():
    """The second published rig (camdyn.model.presets.second_rig: six arcs, docs/second-rig.md): its
    inverse-kinematics detachment speed is where the rigid follower starts to leave, and above it the
    follower leaves at the flank-nose junction, where the curvature's jump turns the needed contact force
    negative at once (a corner of the cam: the junction's restart goes to free flight)."""
    from camdyn.model.presets import second_rig
    rig = second_rig()
    scene = camdyn.Scene(follower="translating", contact="rigid", damping="none", friction="none", profile="arcs")
    loss = contact_loss_speed(rig)
    below = camdyn.simulate(rig, scene, speed_rpm=0.999 * loss, revolutions=3)
    assert below.ok and below.separations().size == 0
    above = camdyn.simulate(rig, scene, speed_rpm=1.07 * loss, revolutions=3)  # 256 rev/min
    assert above.ok and above.separations().size >= 3
    leaves = np.array([s.t for s in above.switches if s.before == "contact" and s.after == "free"])
    assert any(s.surface == "junction" for s in above.switches if s.after == "free" and s.before == "contact")
    phase = np.mod(leaves - leaves[0] + 0.5 * above.period, above.period) - 0.5 * above.period
    assert np.max(np.abs(phase)) < 1e-9  # every revolution at the same corner (the junction or the force's jump
    # there: the two surfaces cross at the same instant, which one is found first is rounding)


#: speeds of the second rig just above its detachment at which a warm-up run (20 revolutions, the
#: orbits' default options) once ended in Outcome.CHATTER: every point 0.05 rev/min apart from 238.9 to
#: 245 was run, and these five failed (commit 569f601; a grazing release read as an impact at its start)
GRAZING_RELEASES_RPM = tuple(float(np.linspace(238.9, 245.0, 123)[k]) for k in (6, 37, 55, 57, 92))
#: and one where the flight's first step (the contact mode's last, 4 ms) spanned the whole brief flight
#: after a mid-arc lift-off: its end inside the cam was read as an impact at its start (rules.SHORTER)
LONG_FIRST_FLIGHT_RPM = 239.03003


@pytest.mark.parametrize("speed_rpm", GRAZING_RELEASES_RPM + (LONG_FIRST_FLIGHT_RPM,))
def test_a_follower_released_where_the_force_just_turns_negative_flies_instead_of_chattering_in_place(speed_rpm):
    """Flung at a corner where the needed force is barely negative (-0.66 N at 239.2 rev/min), the
    follower starts its flight at rest on the cam (the plastic reset); its first, short step ends
    with the gap ~1e-15 m below zero by rounding while its rate already separates; or a long first
    step ends inside the cam after the brief flight.  Neither is an impact at the flight's start
    (camdyn.engine.rules.left_at_start reads the rate at both ends: the first, no crossing; the
    second, the step again shorter): read as one, its chatter end released the follower at the same
    instant again and again until the chatter guard ended the run.  The run must reach its end,
    and no switch may repeat another's instant and state."""
    from camdyn.model.presets import second_rig
    from camdyn.orbits.section_map import DEFAULT_OPTIONS
    scene = camdyn.Scene(follower="translating", contact="rigid", damping="none", friction="none", profile="arcs")
    run = camdyn.simulate(second_rig(), scene, speed_rpm=speed_rpm, revolutions=21, options=DEFAULT_OPTIONS)
    assert run.ok, run.outcome.message
    records = run.switches.records
    same = (np.diff(records["t"]) == 0) & (np.diff(records["alpha"]) == 0) & (np.diff(records["alpha_dot"]) == 0)
    assert not np.any(same)


def test_the_compliant_orbit_converges_to_the_rigid_one_as_the_contact_stiffens():
    """The translating follower's impacting period-1 orbit at 1.2 x its jump speed: with a line contact
    and the viscous damping A of the same restitution (a linear spring-dashpot contact leaves at
    exp(-zeta pi / sqrt(1 - zeta^2)) of its approach speed: zeta = 0.0709 for xi = 0.8), the orbit's section
    state tends to the rigid scene's as the contact stiffness k (proportional to l_lambda) grows, its
    distance falling as k^(-1/2) (the contact's duration): by sqrt(10) per decade (measured 3.1-3.2 over
    l_lambda 1e-2 .. 1 m), and the Floquet multipliers with it."""
    zeta = -math.log(XI) / math.sqrt(math.pi**2 + math.log(XI) ** 2)
    rig = RIG.replace(zeta_A=zeta)
    speed = 1.2 * contact_loss_speed(rig)
    rigid = camdyn.periodic_orbit(rig, SCENE, speed_rpm=speed)
    soft = camdyn.Scene(follower="translating", contact="line", damping="A", friction="none")
    distances, multipliers = [], []
    for length in (1e-2, 1e-1, 1.0):
        orbit = camdyn.periodic_orbit(rig.replace(l_lambda=length), soft, speed_rpm=speed, y0=rigid.state,
                                      warmup_revolutions=2)
        assert orbit.ok
        distances.append(abs(orbit.state[0] - rigid.state[0]))
        multipliers.append(np.max(np.abs(np.sort_complex(orbit.multipliers) - np.sort_complex(rigid.multipliers))))
    ratios = np.array(distances[:-1]) / np.array(distances[1:])
    assert np.all((ratios > 2.5) & (ratios < 4.0)), ratios  # sqrt(10) = 3.16
    assert multipliers[0] > multipliers[1] > multipliers[2] and multipliers[2] < 1e-3


def test_lyapunov_exponents_of_a_rigid_impacting_orbit_sum_to_its_multipliers():
    """On the stable impacting period-1 orbit at 1.2 x the jump speed, the Lyapunov exponents (the tangent
    dynamics through each impact's saltation matrix, renormalised) sum to log|det M| / T of the orbit's
    Floquet multipliers (Liouville over a period; measured 2e-3 relative), each below zero."""
    from camdyn.orbits.lyapunov import lyapunov_exponents
    speed = 1.2 * contact_loss_speed(RIG)
    orbit = camdyn.periodic_orbit(RIG, SCENE, speed_rpm=speed)
    exponents = lyapunov_exponents(RIG, SCENE, speed_rpm=speed).exponents
    period = 60.0 / speed
    expected = math.log(abs(np.prod(orbit.multipliers))) / period
    assert np.all(exponents < 0)
    assert float(np.sum(exponents)) == pytest.approx(expected, rel=1e-2)  # the exponents' finite-time error


def test_continuation_of_a_rigid_impacting_branch_finds_its_period_doubling():
    """The translating follower's impacting period-1 branch, continued in the speed from 1.2 x to 3 x its
    jump speed (saltation-free finite differences, the default provider): the first period doubling it
    locates is where shooting finds a multiplier leaving the unit circle through -1 (1 % on either side:
    |mu| < 1 below, a real mu < -1 above; measured -0.75 +- 0.28i and -1.28)."""
    from camdyn.orbits.continuation import events_table
    loss = contact_loss_speed(RIG)
    branch = camdyn.continue_orbit(RIG, SCENE, "speed_rpm", 1.2 * loss, 3 * loss)
    doublings = [speed for kind, speed, b, _ in events_table(branch) if kind == "period_doubling" and b == 0]
    assert doublings
    below = camdyn.periodic_orbit(RIG, SCENE, speed_rpm=0.99 * doublings[0])
    above = camdyn.periodic_orbit(RIG, SCENE, speed_rpm=1.01 * doublings[0])
    assert below.ok and above.ok
    assert np.max(np.abs(below.multipliers)) < 1
    real = above.multipliers[np.abs(above.multipliers.imag) < 1e-12].real
    assert real.size and real.min() < -1


def test_a_junction_of_time_alone_is_stepped_to_so_the_tightest_tolerances_hold():
    """Under a translating follower a cam of arcs' junction is a function of the cam angle alone
    (derived: TIMED_SURFACES), and the rigid follower's kinematic acceleration jumps there (0 to
    323 m/s^2 at the dwell's end): the loop steps to the float before it and switches just past it
    (camdyn.engine.rules.time_bound), so no step straddles the jump.  Stepping across it, atol 1e-14
    needed a step below 10 float spacings of t and failed (Outcome.STEP_FAILED at t = 2.40 s,
    docs/second-rig.md).  Now it holds, and the impacts agree with atol 1e-13's to the location's
    resolution (1e-10 s: a tenth of the impact-time error at rtol 1e-6 against the exact solution)."""
    from camdyn.model.presets import second_rig
    from camdyn.studies.second_rig import approach_speeds
    scene = camdyn.Scene(follower="translating", contact="rigid", damping="none", friction="none", profile="arcs")
    runs = {atol: camdyn.simulate(second_rig(), scene, speed_rpm=256, revolutions=30, rtol=1e-12, atol=atol)
            for atol in (1e-13, 1e-14)}
    assert all(run.ok for run in runs.values())
    impacts = {}
    for atol, run in runs.items():  # the impacts faster than 0.5 m/s (a chatter's tail depends on atol)
        t, speed = approach_speeds(second_rig(), run)
        impacts[atol] = t[speed < -0.5]
    assert impacts[1e-13].size == impacts[1e-14].size > 0
    assert np.max(np.abs(impacts[1e-13] - impacts[1e-14])) < 1e-10
    assert scene.kernels().TIMED_SURFACES == (scene.kernels().SURFACE_JUNCTION,)
    rocker = camdyn.Scene(contact="rigid", damping="none", friction="none", profile="arcs")
    assert not hasattr(rocker.kernels(), "TIMED_SURFACES")  # its contact angle moves with alpha
