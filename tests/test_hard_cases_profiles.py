"""The hard cases of tests/test_hard_cases.py on cams that are not circles (issue 27): grazing
hops, the speed just below the jump, a bouncing cascade, a Coulomb reversal with stick-slip,
impacting point contact on a cam of arcs (its curvature jumps), and Floquet multipliers where the
contact margin is small.  Bounds say where they come from."""
from __future__ import annotations

import math

import numpy as np
import pytest

import camdyn
from camdyn.analysis.statics import contact_loss_speed, static_equilibrium
from camdyn.model.followers import rig_on_cam
from camdyn.model.presets import cam_example_rig
from camdyn.model.profiles import ArcProfile
from quasi_static_check import against_converged_run
from registry import METHODS

DEG = math.pi / 180
SPLINE = camdyn.Scene(damping="D", friction="coulomb", profile="spline")


pytestmark = pytest.mark.usefixtures("quiet_compile")  # (tests/conftest.py)


@pytest.fixture(scope="module")
def cam_rig():
    """The example rig's follower on a cycloidal rise-dwell-return cam (0.05 rad of lift, rise and
    return over 100 degrees, dwells of 80, base circle 25 mm: camdyn.model.presets.cam_example_rig),
    at rest on the first dwell (140 deg): a start with no kinematic jolt."""
    return cam_example_rig(theta0=140 * DEG)


@pytest.fixture(scope="module")
def loss(cam_rig):
    return contact_loss_speed(cam_rig)   # 539.77 rev/min; the compliant contact grazes at 0.99765 x


@pytest.fixture(scope="module")
def grazing_reference(cam_rig, loss):
    """0.1 % above the inverse-kinematics speed (0.3 % above the grazing) the follower barely hops
    (gaps ~1e-9 m); reference at rtol 1e-12."""
    return camdyn.simulate(cam_rig, SPLINE, speed_rpm=1.001 * loss, revolutions=6, rtol=1e-12, atol=1e-15
                           ).after(2 * 60 / (1.001 * loss))


@pytest.mark.parametrize("method", METHODS)
def test_grazing_hops_on_a_cam_are_neither_missed_nor_duplicated(cam_rig, loss, grazing_reference, method):
    """Every hop found once, matched to one reference hop within 1e-5 s: the bound of the circle's
    case (tests/test_hard_cases.py, measured there 3.3e-6 s at rtol 1e-8: grazing crossings are slow,
    so state errors move them a lot), far below the time between hops (a revolution, 0.11 s)."""
    r = camdyn.simulate(cam_rig, SPLINE, speed_rpm=1.001 * loss, revolutions=6, rtol=1e-8,
                        method=method).after(2 * 60 / (1.001 * loss))
    assert r.ok
    ref = grazing_reference.separations()
    assert ref.size >= 3 and np.diff(ref).min() > 4e-4
    np.testing.assert_allclose(r.separations(), ref, rtol=0, atol=1e-5)
    np.testing.assert_allclose(r.impacts(), grazing_reference.impacts(), rtol=0, atol=1e-5)


def test_just_below_the_grazing_speed_a_cam_never_lets_go(cam_rig, loss):
    """0.995 x the inverse-kinematics speed is below the compliant contact's grazing (0.99765 x;
    the largest gap there is -9e-10 m): after two revolutions, no separation."""
    r = camdyn.simulate(cam_rig, SPLINE, speed_rpm=0.995 * loss, revolutions=6, rtol=1e-10)
    assert r.ok and r.after(2 * r.period).separations().size == 0
    assert r.after(2 * r.period).outputs["psi_i"].max() < 0


def test_a_bouncing_cascade_on_a_cam_ends_in_permanent_contact(cam_rig):
    """Dropped 2e-5 rad above the cam at rest, damping D, no friction: impacts of decreasing height
    end in contact (the circle's case: 41 impacts; bound 200), then the contact mode rings down."""
    rig = cam_rig
    eq = static_equilibrium(rig)
    scene = camdyn.Scene(damping="D", friction="none", profile="spline")
    r = camdyn.simulate(rig, scene, speed_rpm=0, t_end=0.2, y0=(eq.alpha + 2e-5, 0.0), sample_rate_Hz=20_000)
    assert r.ok
    impacts = r.impacts()
    assert 5 < impacts.size < 200 and impacts[-1] < 0.1
    assert np.all(r.regime[r.t > impacts[-1] + 0.01] != "free")


def test_a_coulomb_reversal_on_a_cam_sticks_then_slips(cam_rig):
    """The oscillating cam of Section 7.2 (Theta_p = pi, 40 rev/min) on the cycloidal cam: where the
    cam reverses, the sliding velocity would reverse; the follower sticks (Filippov sliding on
    v_r = 0, the equivalent friction coefficient inside +-mu_m), then slips the other way."""
    preloaded = cam_rig.replace(L_us=0.2)  # as the circle's case: enough normal force for friction to hold
    scene = camdyn.Scene(damping="D", friction="coulomb", motion="oscillating", profile="spline")
    r = camdyn.simulate(preloaded, scene, camdyn.Oscillating(math.pi, 40), t_end=0.45, sample_rate_Hz=100_000)
    assert r.ok
    kinds = [s.surface for s in r.switches if s.surface not in ("gap_rate", "gap")]
    assert kinds[:2] in (["slip", "slip_rate_bwd"], ["slip", "slip_rate_fwd"])
    stick = np.char.find(r.regime.astype(str), "_stick") >= 0
    assert stick.sum() >= 3
    assert np.abs(r.v_r[stick]).max() < 1e-9  # m/s: the sliding mode's drift at rtol 1e-8 (the circle's bound)
    assert np.all(np.abs(r.F_f[stick] / r.F_n[stick]) <= preloaded.mu_m * (1 + 1e-9))


@pytest.mark.parametrize("method", METHODS)
def test_impacting_point_contact_on_a_cam_of_arcs_stays_finite(method):
    """A circular-arc cam in point contact (Hertz with the arc's radius: it jumps at every junction)
    at twice its jump speed: impacts, junction restarts where the follower touches (in flight it
    passes most junctions unwatched: measured 2 in 3 revolutions), every output finite."""
    rig = camdyn.example_rig()
    rig = rig_on_cam(rig, ArcProfile.circular_arc_cam(r_b=0.022, r_n=0.008, d=0.018, R=0.06), theta0=math.pi)
    scene = camdyn.Scene(contact="point", damping="D", friction="coulomb", profile="arcs")
    speed = 2 * contact_loss_speed(rig)
    r = camdyn.simulate(rig, scene, speed_rpm=speed, revolutions=3, sample_rate_Hz=20_000, method=method)
    assert r.ok and r.impacts().size > 3
    assert sum(s.surface == "junction" for s in r.switches) >= 1
    assert all(np.all(np.isfinite(v)) for v in r.outputs.values())


def test_floquet_multipliers_on_a_cam_near_its_jump_agree_or_say_unresolved(cam_rig, loss):
    """Issue 25's fault on a cam: a permanent-contact orbit at 0.85 x the jump speed has a small
    contact margin; the default finite-difference provider either agrees with the variational one
    or falls back to it, never a wrong CONVERGED.  Agreement to 1e-5: the two providers' agreement
    on the circle's rigs below ~0.8 x the loss speed (issue 25)."""
    from camdyn.orbits.tangent import variational

    fd = camdyn.periodic_orbit(cam_rig, SPLINE, speed_rpm=0.85 * loss)
    var = camdyn.periodic_orbit(cam_rig, SPLINE, speed_rpm=0.85 * loss, jacobian=variational)
    assert fd.outcome == var.outcome == camdyn.OrbitOutcome.CONVERGED
    np.testing.assert_allclose(np.sort(np.abs(fd.multipliers)), np.sort(np.abs(var.multipliers)), rtol=0, atol=1e-5)


def test_the_continuation_s_grazing_on_a_cam_is_where_runs_start_to_let_go(cam_rig, loss):
    """The cycloidal cam's jerk jumps ring the contact (about 245 ring periods per revolution): the
    largest gap of an orbit must be found between samples of that ripple, or the grazing is
    reported late: at 256 samples per period it was 0.99836 x the inverse-kinematics speed with this
    section (0.99917 x with the section a quarter turn earlier), where runs separate from 0.998 x;
    with the ring resolved, 0.99765 x with either section.  The located grazing must split runs that
    stay in contact from runs that hop: 0.03 % below it none separates after two revolutions,
    0.03 % above every revolution hops (the largest gap moves by ~3e-10 m per 0.1 % of speed there,
    so 0.03 % is ~1e-10 m, against a located grazing good to ~1e-12 m)."""
    branch = camdyn.continue_orbit(cam_rig, SPLINE, "speed_rpm", 0.8 * loss, 1.2 * loss)
    kinds = branch.attrs["event_kinds"].split()
    grazing = [float(lam) for kind, lam in zip(branch["event_kind"].values, branch["event_lambda"].values)
               if kinds[int(kind)] == "grazing"]
    assert len(grazing) == 1
    below = camdyn.simulate(cam_rig, SPLINE, speed_rpm=0.9997 * grazing[0], revolutions=6, rtol=1e-10)
    above = camdyn.simulate(cam_rig, SPLINE, speed_rpm=1.0003 * grazing[0], revolutions=6, rtol=1e-10)
    assert below.after(2 * below.period).separations().size == 0
    assert above.after(2 * above.period).separations().size >= 4


@pytest.mark.slow  # derives the oscillating cam's tanh scene on a spline on first use (SymPy)
def test_tanh_friction_approaches_coulomb_as_s_grows_on_a_cam(cam_rig):
    """On the cycloidal cam, the oscillating cam of Section 7.2: model II with a growing smoothing factor s
    approaches model I (stick-slip included) around the first reversal, the difference shrinking
    monotonically (tests/test_hard_cases.py's check on the circle)."""
    preloaded = cam_rig.replace(L_us=0.2)
    cam = camdyn.Oscillating(math.pi, 40)
    kw = dict(t_end=0.45, sample_rate_Hz=100_000)
    coulomb = camdyn.simulate(preloaded, camdyn.Scene(damping="D", friction="coulomb", motion="oscillating",
                                                      profile="spline"), cam, **kw)
    assert coulomb.ok
    scene = camdyn.Scene(damping="D", friction="tanh", motion="oscillating", profile="spline")
    window = (coulomb.t > 0.35) & (coulomb.t < 0.45)
    errors = []
    for s in (10.0, 100.0, 1000.0):
        r = camdyn.simulate(preloaded.replace(s=s), scene, cam, **kw)
        assert r.ok
        errors.append(np.abs(r.alpha[window] - coulomb.alpha[window]).max())
    assert errors[0] > errors[1] > errors[2]


def test_the_rockers_quasi_static_orbit_on_a_cam_is_the_converged_run(cam_rig, loss):
    """response='quasistatic' for the rocker on a profile, whose rigid angle is the root of the gap
    (Model.rigid_coordinate, with its implicit derivatives): against the full model's run after 39
    revolutions at 0.8 x the jump speed (rtol 1e-10), the same alpha to 1e-2 of the residual's amplitude
    (measured: 1.0e-8 rad against 2.3e-6 rad, the ringing that the cycloidal cam's jerk steps start, which the
    quasi-static orbit leaves out); the shooting started from it finds the orbit that a warm-up run finds, to
    the shooting's tolerance (measured 2.5e-12 of the scale); above the jump it says where F_n turns tensile."""
    quasi = camdyn.Scene(damping="D", friction="coulomb", profile="spline", response="quasistatic")
    speed = 0.8 * loss
    error, amplitude = against_converged_run(cam_rig, SPLINE, quasi, speed)
    assert error <= 1e-2 * amplitude
    started = camdyn.periodic_orbit(cam_rig, SPLINE, speed_rpm=speed, start="quasistatic")
    warmed = camdyn.periodic_orbit(cam_rig, SPLINE, speed_rpm=speed)
    assert started.outcome is warmed.outcome is camdyn.OrbitOutcome.CONVERGED
    assert np.all(np.abs(started.state - warmed.state) <= 1e-8 * warmed.scale)  # ShootingSettings' default tol
    above = camdyn.simulate(cam_rig, quasi, speed_rpm=1.1 * loss, revolutions=1)
    assert above.outcome is camdyn.Outcome.CONTACT_TENSILE and "cam angle" in above.stats["where"]


def test_the_rockers_quasi_static_orbit_holds_up_to_the_inverse_kinematics_jump(cam_rig, loss):
    """The quasi-static orbit carries the rigid kinematics' inertia, so F_n > 0 exactly while the rigid
    contact force of the inverse kinematics is positive: it holds 1e-5 below the jump speed (F_n down to a
    few mN, the contact deformation there ~1e-11 of the lengths whose rounding enters the gap, where Newton
    has to stop at the residual's rounding) and turns tensile 1e-4 above it (F_n is checked at the samples
    asked, 720 a revolution: 1e-5 above, the tensile window falls between them)."""
    quasi = camdyn.Scene(damping="D", friction="coulomb", profile="spline", response="quasistatic")
    rate = 720 * loss / 60
    below = camdyn.simulate(cam_rig, quasi, speed_rpm=(1 - 1e-5) * loss, revolutions=1, sample_rate_Hz=rate)
    above = camdyn.simulate(cam_rig, quasi, speed_rpm=(1 + 1e-4) * loss, revolutions=1, sample_rate_Hz=rate)
    assert below.ok, below.stats["where"]
    assert above.outcome is camdyn.Outcome.CONTACT_TENSILE
