"""The translating flat-faced follower (issue 27): its derivation against closed forms, its statics and
inverse kinematics against closed forms, and runs on the eccentric circle and on a motion law's cam."""
from __future__ import annotations

import math

import numpy as np
import pytest

import camdyn
from camdyn.analysis import contact_loss_speed, static_equilibrium
from camdyn.analysis.statics import compliance_shift
from camdyn.errors import ParameterError, SceneError
from camdyn.model.presets import translating_cam_example_rig, translating_example_rig
from camdyn.orbits.continuation import events_table
from quasi_static_check import against_converged_run

sp = pytest.importorskip("sympy")

RIG = translating_example_rig()
SCENE = camdyn.Scene(follower="translating", friction="none")


pytestmark = pytest.mark.usefixtures("quiet_compile")  # (tests/conftest.py)


def loss_speed_closed_form(rig) -> float:
    """The eccentric circle's inverse kinematics by hand: y_i = r_c - e cos(phi), phi = gamma - Theta,
    y_i'' = e cos(phi); the contact force m_f y_i'' Omega^2 + F_s(y_i), F_s = F_p + k_s e (1 - cos phi)
    when the 0-state is the base circle (phi0 = 0), is least at phi = pi once m_f Omega^2 > k_s:
    zero at Omega^2 = (F_p + 2 k_s e) / (m_f e)."""
    omega2 = (rig.F_p + 2 * rig.k_s * rig.e) / (rig.m_f * rig.e)
    assert rig.m_f * omega2 > rig.k_s  # the branch of the closed form
    return math.sqrt(omega2) * 60 / (2 * math.pi)


# --- the derivation -----------------------------------------------------------------------------
def test_the_derived_gap_sliding_velocity_and_equation_of_motion_are_the_closed_forms():
    """From the vectors (derive.translating): psi_i = y - h(gamma - Theta), v_r = Theta_dot h (the
    cam's contact point turning at radius h across the face), m_f y_ddot = F_n - F_s (the face's
    friction acts across the ideal guide)."""
    from derive import dynamics, symbols as S, translating
    from derive.profile import h

    phi = S.gamma - S.Theta
    assert sp.simplify(translating.gap() - (S.y - h(phi))) == 0
    v_r = dynamics.sliding_velocity("kinematic", "spline", "translating")
    assert sp.simplify(v_r - S.Theta.diff(S.t) * h(phi)) == 0
    F_s, F_n, F_f = sp.symbols("F_s F_n F_f", real=True)
    assert sp.simplify(translating.force_along_guide(F_s, F_n, F_f) - (F_n - F_s)) == 0
    assert sp.simplify(translating.guide_force(F_s, F_n, F_f) - F_f) == 0
    assert sp.simplify(translating.spring_potential(S.y).diff(S.y) - translating.spring_force()) == 0


def test_the_translating_automaton_has_no_friction_direction_states():
    """Coulomb friction on the face changes no field of the translating follower, so its automaton has
    no slip modes or surfaces (derive.automaton._slips), and its outputs take the sign of v_r."""
    from derive.automaton import build

    A = build(camdyn.vocabulary.SceneSpec(follower="translating", friction="coulomb"))
    assert [m.name for m in A.modes] == ["free", "contact_loading", "contact_unloading"]
    assert A.surfaces == ("gap", "gap_rate")


# --- statics and inverse kinematics against closed forms ----------------------------------------
def test_the_rigid_lift_on_the_eccentric_circle_is_exactly_harmonic():
    theta = np.linspace(0.0, 2 * math.pi, 73)
    K = camdyn.Scene(follower="translating", damping="none", friction="none").kernels()
    from camdyn.model.model import static_parameters
    p = static_parameters(RIG, K)
    y_i, dy, d2y, spring = np.array([K.rigid_contact(th, p) for th in theta]).T
    phi = RIG.gamma - theta
    scale = RIG.r_c  # rounding of terms of the size of the geometry
    assert np.max(np.abs(y_i - (RIG.r_c - RIG.e * np.cos(phi)))) <= 4 * np.finfo(float).eps * scale
    assert np.max(np.abs(dy - (-RIG.e * np.sin(phi)))) <= 4 * np.finfo(float).eps * scale
    assert np.max(np.abs(d2y - RIG.e * np.cos(phi))) <= 4 * np.finfo(float).eps * scale
    y0 = RIG.r_c - RIG.e * math.cos(RIG.gamma - RIG.theta0)
    assert np.allclose(spring, RIG.F_p + RIG.k_s * (y_i - y0), rtol=1e-13, atol=0)


def test_the_contact_loss_speed_is_the_closed_form():
    assert contact_loss_speed(RIG) == pytest.approx(loss_speed_closed_form(RIG), rel=1e-12)
    stiff = RIG.replace(k_s=5000.0, F_p=5.0)  # another spring, still on the closed form's branch
    assert contact_loss_speed(stiff) == pytest.approx(loss_speed_closed_form(stiff), rel=1e-12)


def test_the_static_equilibrium_is_the_closed_form():
    """Line contact: F_p + k_s (y* - y0) = -k (y* - y0), so y* = y0 - F_p / (k_s + k), k = pi/4 Y_e l_lambda,
    and vartheta = sqrt((k_s + k) / m_f)."""
    eq = static_equilibrium(RIG, "line")
    k = math.pi / 4 * RIG.Y_e * RIG.l_lambda
    y0 = RIG.r_c - RIG.e * math.cos(RIG.gamma - RIG.theta0)
    assert eq.q == pytest.approx(y0 - RIG.F_p / (RIG.k_s + k), abs=1e-17)  # rounding of y0's size (2e-2 m)
    assert eq.psi_i == pytest.approx(-RIG.F_p / (RIG.k_s + k), rel=1e-8)  # y* - y0: y0's rounding, 1e-18 m
    assert eq.vartheta == pytest.approx(math.sqrt((RIG.k_s + k) / RIG.m_f), rel=1e-12)
    assert math.isnan(eq.chi)


# --- runs ---------------------------------------------------------------------------------------
def test_below_the_loss_speed_the_follower_rides_the_harmonic_lift_and_above_it_hops():
    """At 0.9 x the inverse-kinematics speed: one switch (the start), the residual y - y_i within the
    contact's static deflection range (|F_n| / k, F_n at most F_p + 2 k_s e + m_f e Omega^2); at 1.1 x:
    impacts, the first separation where the rigid contact force F_p + k_s e - (k_s e - m_f Omega^2 e)
    cos(phi) first reaches zero as phi = gamma - Theta falls from 2 pi."""
    loss = contact_loss_speed(RIG)
    below = camdyn.simulate(RIG, SCENE, speed_rpm=0.9 * loss, revolutions=4)
    assert below.ok and below.impacts().size == 0 and len(below.switches) <= 1
    k = math.pi / 4 * RIG.Y_e * RIG.l_lambda
    omega = 0.9 * loss * 2 * math.pi / 60
    largest_force = RIG.F_p + 2 * RIG.k_s * RIG.e + RIG.m_f * RIG.e * omega**2
    assert np.max(np.abs(below.y_r)) <= 1.5 * largest_force / k  # 1.5: the ring-down of the start
    above = camdyn.simulate(RIG, SCENE, speed_rpm=1.1 * loss, revolutions=4)
    assert above.ok and above.impacts().size > 0
    first = above.separations()[0]
    theta = np.interp(first, above.t, above.Theta)
    phi = (RIG.gamma - theta) % (2 * math.pi)
    omega = 1.1 * loss * 2 * math.pi / 60
    kse = RIG.k_s * RIG.e
    predicted = 2 * math.pi - math.acos(-(RIG.F_p + kse) / (RIG.m_f * omega**2 * RIG.e - kse))
    assert abs(phi - predicted) < 0.01  # rad: the compliance and the start's ring-down move it (1.2e-3 seen)


def test_the_motion_law_comes_back_from_the_cam_in_a_run():
    """Synthesis round trip through the dynamics: a cycloidal rise-dwell-return cam for the translating
    follower, run at half its jump speed: y - (r_b + s(Theta)) stays within the contact deflection."""
    rig = translating_cam_example_rig()
    scene = camdyn.Scene(follower="translating", friction="none", profile="spline")
    speed = 0.5 * contact_loss_speed(rig)
    r = camdyn.simulate(rig, scene, speed_rpm=speed, revolutions=2)
    assert r.ok and r.impacts().size == 0
    from camdyn.model.motion_laws import rise_dwell_return
    deg = math.pi / 180
    law = rise_dwell_return(0.01, (100 * deg, 80 * deg, 100 * deg, 80 * deg), law="cycloidal")
    lift = 0.015 + law.s(np.mod(r.Theta, 2 * math.pi), 0)
    k = math.pi / 4 * rig.Y_e * rig.l_lambda
    deflection = np.max(np.abs(r.F_n)) / k
    assert np.max(np.abs(r.y - lift)) <= 2 * deflection  # 2: the start's ring-down and the spline's 1e-12 m


# --- the vocabulary and bad input ---------------------------------------------------------------
def test_a_result_names_the_translating_state_y():
    r = camdyn.simulate(RIG, SCENE, speed_rpm=300, revolutions=1, sample_rate_Hz=2000)
    assert np.array_equal(r.y, r.q) and np.array_equal(r.y_dot, r.q_dot) and r.y_star == r.q_star
    with pytest.raises(AttributeError, match="coordinate is 'y'"):
        r.alpha


def test_bad_input_is_refused_with_the_reason():
    with pytest.raises(ParameterError, match="chi0"):
        RIG.replace(chi0=0.1)
    with pytest.raises(camdyn.errors.RigFileError, match="F_p"):
        camdyn.Rig.from_dict({k: v for k, v in RIG.to_dict().items() if k != "F_p" and v is not None})
    with pytest.raises(SceneError, match="follower"):
        camdyn.simulate(camdyn.example_rig(), SCENE, speed_rpm=100, revolutions=1)
    with pytest.raises(SceneError, match="follower"):
        camdyn.simulate(RIG, camdyn.Scene(friction="none"), speed_rpm=100, revolutions=1)
    with pytest.raises(SceneError, match="response='quasistatic'"):
        camdyn.Scene(follower="quasistatic")
    with pytest.raises(ParameterError, match="F_p"):
        RIG.replace(F_p=0.0)


# --- a bounded face (Scene(face="bounded")) --------------------------------------------------------
@pytest.mark.parametrize("follower", ["translating", "oscillating"])
def test_a_contact_that_reaches_the_end_of_the_face_ends_the_run_with_off_face(follower):
    """The contact's position on the face (the translating follower's -h'(phi) - offset = -e sin(phi); the
    rocker's chi) sweeps a range over a turn; a face that covers it runs to the end, one that stops short
    ends the run with Outcome.OFF_FACE at the switch onto the terminal mode, where the contact is at the end."""
    if follower == "translating":
        rig, scene = RIG, camdyn.Scene(follower="translating", friction="none", face="bounded")
        wide, short = (-1.2 * RIG.e, 1.2 * RIG.e), (-0.8 * RIG.e, 1.2 * RIG.e)
    else:
        rig, scene = camdyn.example_rig(), camdyn.Scene(friction="none", face="bounded")  # (derived on first use: no
        # Coulomb modes, a few seconds of SymPy)
        wide, short = (rig.chi0 - 0.01, rig.chi0 + 0.01), (rig.chi0 - 0.01, rig.chi0 + 1e-3)
    ok = camdyn.simulate(rig.replace(face_start=wide[0], face_end=wide[1]), scene, speed_rpm=300, revolutions=2)
    assert ok.ok and "off_face" not in set(ok.regime)
    edge = rig.replace(face_start=short[0], face_end=short[1])
    stopped = camdyn.simulate(edge, scene, speed_rpm=300, revolutions=2)
    assert stopped.outcome is camdyn.Outcome.OFF_FACE and stopped.t[-1] < 2 * stopped.period
    last = stopped.switches[-1]
    assert (last.surface, last.after) == ("face", "off_face")
    K = scene.kernels()
    model = camdyn.Model(edge, scene, camdyn.ConstantSpeed(300))
    margin = model.surface(K.MODE_FREE, K.SURFACE_FACE, last.t, last.alpha, last.alpha_dot)
    assert abs(margin) <= 1e-10 * (short[1] - short[0]) ** 2  # located on the end: the engine's xtol


def test_a_bounded_face_needs_its_ends():
    scene = camdyn.Scene(follower="translating", friction="none", face="bounded")
    with pytest.raises(ParameterError, match="face_start"):
        camdyn.simulate(RIG, scene, speed_rpm=300, revolutions=1)
    with pytest.raises(ParameterError, match="face_end"):
        RIG.replace(face_start=0.01, face_end=-0.01)


def test_the_quasi_static_orbit_of_the_translating_follower_is_the_converged_run():
    """response='quasistatic' on a translating follower, on any cam (its rigid lift is h itself): against
    the full model's run after 39 revolutions at 0.8 x the jump speed (rtol 1e-10), the same y to 1e-3 of the
    residual's amplitude (measured 2.2e-11 m against 4.9e-8 m: the ringing that the cycloidal cam's jerk
    steps start in the contact, which the quasi-static orbit leaves out); above the jump speed it says where
    the contact force would turn tensile."""
    rig = translating_cam_example_rig()
    dynamic = camdyn.Scene(follower="translating", friction="none", profile="spline")
    quasi = camdyn.Scene(follower="translating", friction="none", profile="spline", response="quasistatic")
    speed = 0.8 * contact_loss_speed(rig)
    error, amplitude = against_converged_run(rig, dynamic, quasi, speed)
    assert error <= 1e-3 * amplitude
    above = camdyn.simulate(rig, quasi, speed_rpm=1.1 * speed / 0.8, revolutions=1)
    assert above.outcome is camdyn.Outcome.CONTACT_TENSILE and "cam angle" in above.stats["where"]


@pytest.mark.parametrize("profile", ["eccentric", "spline"])
def test_the_compliance_shift_predicts_the_translating_followers_grazing(profile):
    """camdyn.analysis.statics.compliance_shift on the translating follower (its inertia m_f): the grazing
    that continuation finds lies below the inverse-kinematics speed by the first-order compliance shift,
    to 10 % of the shift (measured 6 % on the eccentric circle, 4 % on the cycloidal cam; 3 % on the
    paper's rocker, tests/test_charts.py: the remainder is second order in the deflection)."""
    rig = translating_example_rig() if profile == "eccentric" else translating_cam_example_rig()
    scene = camdyn.Scene(follower="translating", friction="none", profile=profile)
    loss, shift = contact_loss_speed(rig), compliance_shift(rig)
    assert shift < 0
    branch = camdyn.continue_orbit(rig, scene, "speed_rpm", 0.8 * loss, 1.2 * loss)
    grazing = [speed for kind, speed, _, _ in events_table(branch) if kind == "grazing"]
    assert len(grazing) == 1
    assert abs(grazing[0] / loss - 1 - shift) <= 0.1 * abs(shift)
