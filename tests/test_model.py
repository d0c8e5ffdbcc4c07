"""Model setup, analyses, and bad input: every error names the parameter and the valid range."""
from __future__ import annotations

import math

import numpy as np
import pytest

import camdyn
from camdyn.analysis import statics as analysis
from camdyn.errors import EquilibriumError, GeometryError, ParameterError, SceneError
from camdyn.model.model import Model
from registry import RIG


def test_equilibrium_satisfies_eqs_16_to_18():
    eq = analysis.static_equilibrium(RIG)
    K = camdyn.Scene(damping="none", friction="none").kernels()
    m = Model(RIG, camdyn.Scene(damping="none", friction="none"), camdyn.ConstantSpeed(0))
    M, dM, psi_i, psi_j, k = K.static_moment(eq.alpha, m.p)
    scale = k * abs(eq.psi_i) * eq.chi  # the contact moment being balanced
    assert abs(M) < 1e-9 * scale
    assert psi_i < 0 and psi_i == eq.psi_i and eq.chi == pytest.approx(RIG.chi0 - psi_j, abs=0)
    # Eq. 18 derived (misprint 1): -F_s d_x - k psi_i* chi* = 0, evaluated independently
    L = RIG.L_us - RIG.d_y + RIG.d_x * math.tan(eq.alpha) - 0.5 * RIG.w_b / math.cos(eq.alpha)
    assert -RIG.k_s * L * RIG.d_x - k * psi_i * eq.chi == pytest.approx(0, abs=1e-8 * scale)


def test_line_contact_stiffness_is_the_papers_138_MN_per_m():
    """Eq. 13 with steel (200 GPa, 0.3) and l = 1.6 mm: the paper quotes 138 MN/m (3 digits)."""
    eq = analysis.static_equilibrium(RIG)
    assert eq.contact_stiffness == pytest.approx(138e6, rel=5e-3)  # paper's rounding
    Ye = 200e9 / (2 * (1 - 0.3**2))
    assert eq.contact_stiffness == pytest.approx(math.pi / 4 * Ye * 0.0016, rel=1e-12)


def test_point_contact_tangent_is_1_5_times_secant():
    """Misprint 5: the quoted point stiffness is the secant k(psi*); the dynamics see 1.5x it."""
    eq = analysis.static_equilibrium(RIG, "point")
    tangent = eq.stiffness / eq.chi**2  # -dM/dalpha / chi^2, up to spring and geometric terms
    spring = RIG.k_s * RIG.d_x**2  # spring's share of -dM/dalpha at alpha ~ 0
    assert (eq.stiffness - spring) / eq.chi**2 == pytest.approx(1.5 * eq.contact_stiffness, rel=2e-3)
    assert tangent > eq.contact_stiffness


def test_friction_direction_orders_the_natural_frequencies():
    """Section 7.1: de-energizing (cam counter-clockwise) above frictionless above self-energizing."""
    scene = camdyn.Scene(damping="D", friction="coulomb")
    de = analysis.natural_frequency(RIG, scene, camdyn.ConstantSpeed(300)).Hz
    self_ = analysis.natural_frequency(RIG, scene, camdyn.ConstantSpeed(-300)).Hz
    none = analysis.natural_frequency(RIG).Hz
    assert de > none > self_
    # the paper's ratio 2182/2125 comes from (chi* +/- 0.5 mu w_b); check that form
    ratio = (RIG.chi0 + 0.5 * RIG.mu_m * RIG.w_b) / (RIG.chi0 - 0.5 * RIG.mu_m * RIG.w_b)
    assert (de / self_) ** 2 == pytest.approx(ratio, rel=2e-3)


def test_rigid_contact_angle_is_alpha0_at_theta0_and_continuous():
    rig = RIG.replace(theta0=0.0)  # the 0-state mid-stroke, so alpha_i takes both signs
    th = rig.theta0 + np.linspace(0, 2 * math.pi, 2001)
    a = analysis.rigid_contact_angle(rig, th)
    assert a[0] == pytest.approx(rig.alpha0, abs=1e-15)
    assert np.max(np.abs(np.diff(a))) < 1e-3
    assert a.min() < 0 < a.max()  # both signs: the printed arccos would lose one (misprint 10)


@pytest.mark.parametrize("preset", ["reference", "example", "translating-example"])
def test_closed_forms_on_arrays_are_the_scalar_kernels(preset):
    """rigid_kinematics evaluates the generated closed forms (reach, rigid_contact) on the whole
    array of cam angles at once (camdyn.engine.kernels.on_arrays): the same values as the scalar
    kernels angle by angle, to a few ulps (NumPy's sin and cos against libm's, 1 ulp each, through
    the derivative's ~40 operations: 1e-12 relative)."""
    from camdyn.model.model import static_parameters
    rig = camdyn.load_rig(preset)
    K = analysis._static_scene("line", rig).kernels()
    p = static_parameters(rig, K)
    th = rig.theta0 + np.linspace(0, 2 * math.pi, 257)
    scalar = np.array([K.rigid_contact(t, p) for t in th]).T
    q, curvature, load = analysis.rigid_kinematics(rig, th)
    for got, want in ((q, scalar[0]), (curvature, scalar[2]), (load, scalar[3])):
        np.testing.assert_allclose(got, want, rtol=1e-12, atol=1e-12 * np.max(np.abs(want)))
    if hasattr(K, "reach"):
        margins = np.array([K.reach(t, p) for t in th])
        np.testing.assert_allclose(camdyn.engine.kernels.on_arrays(K.reach)(th, p), margins, rtol=1e-12)


def test_closed_forms_on_arrays_refuse_branching_code():
    """A kernel with a branch on its argument cannot run on an array: NumPy says so, no silent result."""
    from camdyn.engine.kernels import on_arrays

    def branching(x, p):
        return 2.0 * x if x > 0 else 0.0
    with pytest.raises(ValueError, match="ambiguous"):
        on_arrays(branching)(np.linspace(-1, 1, 5), None)


def test_energy_balance_grows_with_speed_towards_90_degrees():
    """Eqs. 31-33: alpha_p rises with speed and xi, and stays below 90 degrees (L ~ sec alpha)."""
    eq = analysis.static_equilibrium(RIG)
    peaks = [analysis.energy_balance_peak(RIG, speed, 1.0) for speed in (150, 1e3, 1e4, 1e5)]
    assert 0 < peaks[0] and np.all(np.diff(peaks) > 0)
    assert peaks[-1] < math.pi / 2 - eq.alpha and peaks[-1] > 1.4
    assert analysis.energy_balance_peak(RIG, 150, 0.2) > analysis.energy_balance_peak(RIG, 150, 0.05)


# --- bad input ---------------------------------------------------------------------

def _message(excinfo):
    return str(excinfo.value)


def test_spring_that_does_not_press_the_follower_has_no_equilibrium():
    rig = RIG.replace(L_us=RIG.d_y - 0.05)
    with pytest.raises(EquilibriumError, match="does not press the follower"):
        analysis.static_equilibrium(rig)


def test_cam_that_the_follower_cannot_reach():
    """Pivot E below the contact (Theta0 = -pi/2) and P almost over it: the eccentric swings
    the cam centre to within r_c + w_b/2 of P, where no follower angle touches the cam."""
    rig = RIG.replace(chi0=0.01, e=0.02, r_c=0.025, theta0=-math.pi / 2)
    with pytest.raises(GeometryError, match="cannot|too close"):
        Model(rig, camdyn.Scene(), camdyn.ConstantSpeed(100))


def test_alpha_near_90_degrees_is_refused_early():
    with pytest.raises(ParameterError, match="alpha0"):
        RIG.replace(alpha0=math.pi / 2 - 0.01)


def test_missing_parameter_for_the_scene_names_it():
    rig = RIG.replace(beta_D=None)
    with pytest.raises(ParameterError, match="beta_D"):
        camdyn.simulate(rig, camdyn.Scene(damping="D"), speed_rpm=100, t_end=0.01)
    camdyn.simulate(rig, camdyn.Scene(damping="none", friction="none"), speed_rpm=100, t_end=0.001)


@pytest.mark.parametrize("options, text", [
    ({"damping": "F"}, "damping='F' is not one of"),
    ({"contact": "edge"}, "contact='edge'"),
])
def test_scene_errors(options, text):
    with pytest.raises(SceneError, match=text):
        camdyn.Scene(**options)


def test_unknown_scene_says_how_to_generate_it(monkeypatch, tmp_path):
    from camdyn.model import ondemand
    monkeypatch.setenv("CAMDYN_CACHE_DIR", str(tmp_path))  # nothing derived earlier
    monkeypatch.setattr(ondemand, "sympy_version", lambda: None)  # and it cannot be derived here
    with pytest.raises(SceneError) as info:
        camdyn.Scene(damping="C", friction="tanh")
    assert "derive/catalog.py" in _message(info) and "python -m camdyn.derive" in _message(info)
    assert 'pip install "camdyn[derive]"' in _message(info)


def test_cam_kind_must_match_the_scene():
    with pytest.raises(SceneError, match="motion"):
        camdyn.simulate(RIG, camdyn.Scene(), camdyn.Oscillating(math.pi, 40), t_end=0.01)


@pytest.mark.parametrize("kwargs, name", [
    ({"speed_rpm": float("nan"), "t_end": 0.1}, "speed_rpm"),
    ({"speed_rpm": 100, "t_end": -1.0}, "t_end"),
    ({"speed_rpm": 100, "t_end": 0.1, "revolutions": 2}, "t_end"),
    ({"speed_rpm": 100, "t_end": 0.1, "rtol": 0.5}, "rtol"),
    ({"speed_rpm": 100, "t_end": 0.1, "atol": 0.0}, "atol"),
    ({"speed_rpm": 100, "t_end": 0.1, "method": "Euler"}, "method"),
    ({"speed_rpm": 100, "t_end": 0.1, "sample_rate_Hz": 0}, "sample_rate_Hz"),
    ({"speed_rpm": 100, "t_end": 1e3, "sample_rate_Hz": 1e6}, "sample_rate_Hz"),
    ({"speed_rpm": 100, "t_end": 1e6}, "t_end"),  # 2e9 contact-mode periods: refused, not a hang
    ({"speed_rpm": 100, "t_end": 0.1, "y0": (0.1,)}, "y0"),
    ({"speed_rpm": 0, "revolutions": 2}, "revolutions"),
    ({"t_end": 0.1}, "cam"),
])
def test_simulate_rejects_bad_arguments_by_name(kwargs, name):
    with pytest.raises(ParameterError) as info:
        camdyn.simulate(RIG, camdyn.Scene(), **kwargs)
    assert info.value.name == name
    assert name in _message(info)


def test_follower_leaving_for_good_stops_with_a_clear_outcome():
    """A violent start (300 rad/s away from the cam) swings the follower towards 90 degrees:
    the run stops with ANGLE_LIMIT and says why, instead of overflowing tan/sec."""
    r = camdyn.simulate(RIG, camdyn.Scene(damping="D", friction="none"), speed_rpm=100, t_end=1.0,
                        y0=(0.0, 300.0))
    assert r.outcome is camdyn.Outcome.ANGLE_LIMIT and not r.ok
    assert "90 degrees" in r.outcome.message
    assert np.all(np.isfinite(r.alpha)) and np.all(np.abs(r.alpha) < math.pi / 2)


def test_static_kernels_get_the_rigs_zeros_and_nan_for_what_they_never_read():
    """Regression: placeholders were once filled with `value or 1.0`, turning alpha0 = 0.0 into
    1.0 rad in the reach check.  Zeros must pass through; unread slots are NaN, never a number."""
    from camdyn.model.model import static_parameters
    K = camdyn.Scene().kernels()
    rig = RIG.replace(alpha0=0.0, e=0.0)
    p = static_parameters(rig, K)
    assert p[K.PARAMS.index("alpha0")] == 0.0 and p[K.PARAMS.index("e")] == 0.0
    for name in ("chi_star", "vartheta", "Omega_c"):
        assert math.isnan(p[K.PARAMS.index(name)])
    assert all(math.isfinite(v) for v in K.rigid_contact(0.3, p)) and math.isfinite(K.reach(0.3, p))


def test_a_model_under_another_cam_speed_is_the_model_built_for_it():
    """Model.with_cam keeps the rig's equilibrium and packs the new cam's constants: the same
    parameter vector and period as a model built from scratch for that speed (exact: the same
    arithmetic), and a cam of another kind than the scene's is refused."""
    scene = camdyn.Scene(damping="D", friction="coulomb")
    built = Model(RIG, scene, camdyn.ConstantSpeed(700.0))
    moved = Model(RIG, scene, camdyn.ConstantSpeed(300.0)).with_cam(camdyn.ConstantSpeed(700.0))
    assert np.array_equal(moved.p, built.p)
    assert moved.period == built.period and moved.equilibrium == built.equilibrium
    with pytest.raises(SceneError, match="motion"):
        built.with_cam(camdyn.Oscillating(amplitude_pp=math.pi, frequency_rpm=40.0))


def test_fastest_rate_of_the_undamped_frictionless_contact_is_vartheta():
    """Eq. 23: without damping or friction the contact mode's linearized motion at alpha* is an
    undamped oscillator of angular frequency vartheta (the same -dM/dalpha, from the generated
    Jacobian here and the equilibrium solver there); bound 1e-6: the equilibrium's own solve."""
    model = Model(RIG, camdyn.Scene(damping="none", friction="none"), camdyn.ConstantSpeed(0.0))
    rate = model.fastest_rate
    assert rate.mode == "contact" and not rate.damping
    assert rate.value == pytest.approx(model.equilibrium.vartheta, rel=1e-6)


@pytest.mark.parametrize("preset", camdyn.model.presets.available())
def test_no_shipped_rig_comes_near_the_rate_limit(preset):
    """simulation.MAX_RATE refuses runs an explicit method cannot finish; the shipped rigs, in
    every generated scene with a constant-speed cam, stay 100x below it."""
    from camdyn.runs.simulation import MAX_RATE
    from registry import SCENES, cam_for, scene_from_slug
    rig = camdyn.model.presets.load_rig(preset)
    rates = {}
    for slug in SCENES:
        scene = scene_from_slug(slug)
        if scene.motion != "constant" or scene.model != "nonlinear" or scene.follower != rig.follower \
                or scene.profile != "eccentric":  # another follower's, or a cam the preset does not have
            continue
        try:
            rates[slug] = Model(rig, scene, cam_for(scene)).fastest_rate.value
        except ParameterError:  # a parameter the preset does not give (e.g. damping C's beta_C)
            continue
    assert rates and max(rates.values()) < MAX_RATE / 100


@pytest.mark.parametrize("changes, culprit", [({"zeta_D": 1e6}, "zeta_D"), ({"k_s": 1e14}, "k_s"),
                                              ({"I_Pb": 1e-9}, "I_Pb")])
def test_a_run_too_stiff_for_an_explicit_method_is_refused_naming_the_parameter(changes, culprit):
    """Found by tests/test_bad_input.py: zeta_D = 1e6 made a 2 ms run take ~9e6 steps (15 s
    compiled, far longer interpreted), k_s = 1e14 ~7e6; now refused before the run, naming the
    rate's parameters."""
    rig = RIG.replace(**changes)
    with pytest.raises(ParameterError, match="fastest rate of the linearized motion") as err:
        camdyn.simulate(rig, camdyn.Scene(), speed_rpm=300, t_end=0.002)
    assert f"{culprit} = " in str(err.value) and "<= 1e+07" in str(err.value)
