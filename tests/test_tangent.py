"""Tangent dynamics (issue 13): saltation matrices, the variational monodromy against finite
differences of the stroboscopic map, and the variational Jacobian provider in the shooting.

Cases (example rig, line contact, damping D, Coulomb friction; tests/test_orbits.py):
600 rev/min permanent contact (no switch), 1500 rev/min one impact per revolution (free ->
contact_loading -> contact_unloading -> free: the impact law's switch to the viscous law at
maximum compression, then separation), 1200 rev/min two impacts per revolution (unstable).
"""
from __future__ import annotations

import numpy as np
import pytest

import camdyn
from camdyn.engine.config import SolverOptions
from camdyn.engine.driver import integrate
from camdyn.engine.saltation import saltation_matrix, switch_saltation
from camdyn.model.model import Model
from camdyn.orbits.shooting import periodic_orbit
from camdyn.orbits.derivatives import finite_differences
from camdyn.orbits.section_map import StroboscopicMap
from camdyn.orbits.tangent import TangentSettings, tangent, variational

RIG = camdyn.example_rig()
SCENE = camdyn.Scene(contact="line", damping="D", friction="coulomb")
#: the finite-difference reference runs the map at rtol 1e-12 with a tenth of the default step
#: (h = 1e-5 of the motion's scale): truncation O(h^2) ~1e-8 (at the default step, 1e-4, it
#: was 5e-6 at 1200 rev/min, measured against step 1e-5), noise rtol / h ~ 1e-7
TIGHT = SolverOptions(rtol=1e-12, atol=1e-15)
FD_STEP = 0.1


@pytest.fixture(scope="module")
def orbits():
    """The orbits, found with the tangent dynamics' Jacobian provider."""
    return {speed: periodic_orbit(RIG, SCENE, speed_rpm=speed, warmup_revolutions=warm, jacobian=variational)
            for speed, warm in ((600.0, 20), (1500.0, 2), (1200.0, 2))}


def _scaled(J, s):
    return J * s[None, :] / s[:, None]


def _map(speed, orbit, options=TIGHT):
    model = Model(RIG, SCENE, camdyn.ConstantSpeed(speed))
    return StroboscopicMap(model, orbit.periods, orbit.phase, model.mode(orbit.mode), options)


@pytest.mark.parametrize("speed, switches", [(1500.0, 3), (1200.0, 6)])
def test_monodromy_agrees_with_finite_differences_across_impacts(orbits, speed, switches):
    orbit = orbits[speed]
    assert orbit.ok, orbit.message
    P = _map(speed, orbit)
    r = tangent(P.model, P.t_span, orbit.state, mode=P.mode, options=P.options)
    assert r.switches == switches                       # the damping law's switch and the gap's, per impact
    fd = finite_differences(P, orbit.scale, FD_STEP)(orbit.state)[1]
    # relative 1e-6 of the largest scaled entry (entries ~1-5), the brief's bound; the
    # reference's own error is ~1e-7 (TIGHT, FD_STEP)
    diff = np.max(np.abs(_scaled(r.phi, orbit.scale) - _scaled(fd, orbit.scale)))
    assert diff <= 1e-6 * np.max(np.abs(_scaled(fd, orbit.scale)))
    # the augmented integration's state, restarted from the engine's at each switch, ends
    # where the engine does, to the tolerances of both (rtol 1e-10 of alpha_dot ~ 5 rad/s)
    np.testing.assert_allclose(r.flow_state, r.state, rtol=0, atol=1e-8)


def test_monodromy_in_permanent_contact_obeys_liouville(orbits):
    """No switch over the period: det M = exp(integral of the divergence).  The entries are
    ~5e-7 (the contact's damping), below the finite differences' noise (~2e-7 of the scale at
    the map's default rtol 1e-10): they are compared to that noise, and det M to Liouville's
    formula, which the tangent dynamics meets to its own tolerance."""
    orbit = orbits[600.0]
    P = _map(600.0, orbit, options=StroboscopicMap(Model(RIG, SCENE, camdyn.ConstantSpeed(600.0))).options)
    r = tangent(P.model, P.t_span, orbit.state, mode=P.mode, options=P.options)
    assert r.switches == 0
    fd = finite_differences(P, orbit.scale)(orbit.state)[1]
    # 1e-6: five times the measured 4e-7, the finite differences' noise
    assert np.max(np.abs(_scaled(r.phi, orbit.scale) - _scaled(fd, orbit.scale))) <= 1e-6
    # det ~ 1e-13 is a product of entries known to rtol 1e-10: relative 1e-6
    assert np.linalg.det(r.phi) == pytest.approx(np.exp(r.divergence), rel=1e-6)


def test_variational_provider_finds_the_same_orbit_and_multipliers(orbits):
    """The variational provider and finite differences (the default) find the same orbit."""
    var = orbits[1500.0]
    fd = periodic_orbit(RIG, SCENE, speed_rpm=1500.0, warmup_revolutions=2, jacobian=finite_differences)
    assert var.ok and fd.ok, (var.message, fd.message)
    # the same fixed point within both searches' tolerance (Newton's tol 1e-8, scaled)
    assert np.max(np.abs(var.state - fd.state) / fd.scale) <= 1e-7
    # multipliers: the finite differences' error ~rtol^(2/3) = 2e-7 of the scale, times the
    # eigenvalue's condition: 1e-5
    np.testing.assert_allclose(np.abs(var.multipliers), np.abs(fd.multipliers), rtol=1e-5)


def test_saltation_matrix_formula_on_a_known_case():
    """f+ - f- = (0, 1), grad_h = (2, 3), dh/dt = 1, f- = (4, 5): denominator 2*4 + 3*5 + 1 = 24."""
    S = saltation_matrix((4.0, 5.0), (4.0, 6.0), (2.0, 3.0, 1.0))
    np.testing.assert_allclose(S, [[1.0, 0.0], [2 / 24, 1 + 3 / 24]], rtol=1e-15)


def _separation(orbit, model):
    """The 1500 rev/min orbit's separation switch (contact_unloading -> free across the gap)."""
    tr = integrate(model, (orbit.phase, orbit.phase + model.period), orbit.state, np.array([model.period]),
                   TIGHT, mode=model.mode(orbit.mode))
    return next(s for s in tr.switches if s.after == "free")


def test_saltation_matrix_against_sympy(orbits):
    """S of the separation from the fields and the gap as SymPy derives them (derive.fields,
    flattened), differentiated and assembled here: the generated gradient and fields agree."""
    sp = pytest.importorskip("sympy")
    from camdyn.derive import fields
    from camdyn.derive import symbols as Sy
    from camdyn.derive.automaton import build
    from camdyn.vocabulary import SceneSpec
    model = Model(RIG, SCENE, camdyn.ConstantSpeed(1500.0))
    sw = _separation(orbits[1500.0], model)
    spec = SceneSpec(**model.kernels.SCENE)
    A = build(spec)
    before, after = A.mode(sw.before), A.mode(sw.after)
    a_minus = fields.field(spec, before).flat()[0]
    a_plus = fields.field(spec, after).flat()[0]
    h = fields.surface(spec, before, "gap").flat()[0]
    values = dict(zip(model.kernels.PARAMS, model.p))
    values.update({k: v for k, v in zip(model.kernels.INPUTS, [getattr(RIG, k, None) for k in model.kernels.INPUTS])
                   if v is not None and k not in values})
    x = (Sy.alpha_s, Sy.alpha_dot)
    grad = sp.Matrix([[h.diff(x[0]), h.diff(x[1])]])
    f_minus, f_plus = sp.Matrix([Sy.alpha_dot, a_minus]), sp.Matrix([Sy.alpha_dot, a_plus])
    S_sym = sp.eye(2) + (f_plus - f_minus) * grad / ((grad * f_minus)[0] + h.diff(Sy.t_s))
    point = {Sy.t_s: sw.t, Sy.alpha_s: sw.alpha, Sy.alpha_dot: sw.alpha_dot}
    subs = {s: values[s.name] for s in S_sym.free_symbols if s.name in values}
    expected = np.array(S_sym.subs(subs).subs(point).evalf(), dtype=float)
    got = switch_saltation(model, model.mode(sw.before), model.mode(sw.after), model.kernels.SURFACES.index("gap"),
                           sw.t, (sw.alpha, sw.alpha_dot))
    assert np.max(np.abs(got - np.eye(2))) > 1e-3          # a real jump: F_n = -c psi_i_dot at separation
    # the same expressions evaluated two ways (CSE'd generated code, SymPy's evalf): rounding
    np.testing.assert_allclose(got, expected, rtol=1e-9, atol=1e-12 * np.max(np.abs(expected)))


def test_saltation_matrix_against_finite_differences_across_one_switch(orbits):
    """Phi over a short window holding only the separation, against central differences of the
    engine's flow over the window: the jump S is what the perturbed runs see."""
    model = Model(RIG, SCENE, camdyn.ConstantSpeed(1500.0))
    sw = _separation(orbits[1500.0], model)
    d = 2e-5                                        # s; the contact lasts ~2e-4 s
    start = integrate(model, (orbits[1500.0].phase, sw.t - d), orbits[1500.0].state, np.array([sw.t - d]), TIGHT,
                      mode=model.mode(orbits[1500.0].mode))
    x0, m0 = start.y[:2, -1], start.end_mode
    r = tangent(model, (sw.t - d, sw.t + d), x0, mode=m0, options=TIGHT)
    assert r.switches == 1
    scale = np.array([1e-3, 1.0])                   # rad, rad/s: the perturbations
    J = np.empty((2, 2))
    for j in range(2):
        e = np.zeros(2)
        e[j] = 1e-6 * scale[j]
        ends = [integrate(model, (sw.t - d, sw.t + d), x0 + s * e, np.array([sw.t + d]), TIGHT, mode=m0).y[:2, -1]
                for s in (1, -1)]
        J[:, j] = (ends[0] - ends[1]) / (2 * e[j])
    without = tangent(model, (sw.t - d, sw.t - 1e-9), x0, mode=m0, options=TIGHT).phi
    assert np.max(np.abs(r.phi - without)) > 1e-2 * np.max(np.abs(r.phi))   # the window's Phi is not ~I
    # step 1e-6 of the scale: truncation ~1e-12, noise rtol 1e-12 / 1e-6 = 1e-6 relative
    np.testing.assert_allclose(_scaled(r.phi, scale), _scaled(J, scale), rtol=0,
                               atol=1e-5 * np.max(np.abs(_scaled(J, scale))))


def test_bad_tangent_settings_name_the_parameter():
    with pytest.raises(camdyn.ParameterError, match="rtol"):
        TangentSettings(rtol=0.0)


def test_compiled_and_python_tangent_dynamics_agree(orbits):
    """The compiled segment integrator (camdyn.engine.variational) and SciPy's DOP853 over the
    Python kernels: the same Phi to their tolerances (rtol 1e-10; measured 5e-11 relative)."""
    orbit = orbits[1500.0]
    model = Model(RIG, SCENE, camdyn.ConstantSpeed(1500.0))
    span, m = (0.0, model.period), model.mode(orbit.mode)
    compiled = tangent(model, span, orbit.state, mode=m)
    python = tangent(model, span, orbit.state, mode=m, backend="python")
    assert compiled.switches == python.switches == 3
    np.testing.assert_allclose(compiled.phi, python.phi, rtol=0, atol=1e-7 * np.max(np.abs(python.phi)))
    assert compiled.divergence == pytest.approx(python.divergence, rel=1e-8)


def test_a_user_cam_motion_gives_the_built_in_motions_tangent_dynamics():
    """The user motion's dh/dt goes through Theta_dot and Theta_ddot (derive.fields.surface_gradient):
    a user motion equal to the constant speed gives the constant-speed scene's Phi (tanh friction:
    the gap and gap-rate surfaces), to the integrations' tolerances (measured 1e-9 relative)."""
    w = 1500.0 * 2 * np.pi / 60
    user = camdyn.UserMotion(lambda t: RIG.theta0 + w * t, lambda t: w + 0 * t, lambda t: 0 * t, period=2 * np.pi / w)
    as_user = Model(RIG, camdyn.Scene(damping="D", friction="tanh", motion="user"), user)
    built_in = Model(RIG, camdyn.Scene(damping="D", friction="tanh"), camdyn.ConstantSpeed(1500.0))
    x0, span = built_in.static_state(), (0.0, 3 * built_in.period)
    a = tangent(as_user, span, x0, backend="python")
    b = tangent(built_in, span, x0)
    assert a.switches == b.switches > 0
    np.testing.assert_allclose(a.phi, b.phi, rtol=0, atol=1e-7 * np.max(np.abs(b.phi)))


def test_damping_b_separation_with_its_unbounded_jacobian_agrees_with_finite_differences():
    """Damping B's impact law c = beta_B k_lambda abs(psi_i) acts up to separation, where the 16 mm
    line contact of the reference experiment makes the Jacobian unbounded as psi_i -> 0: the
    segment's integration stalls 7e-15 s short of the switch, and the last END_GAP of it is
    taken with the Jacobian frozen (camdyn.orbits.tangent.END_GAP).  Phi over one revolution with six
    switches agrees with finite differences of the map to their own error, estimated by the
    spread of two steps (FD steps 0.1 and 0.03 of the default), times 3."""
    from camdyn.orbits.lyapunov import _start
    rig = camdyn.load_rig("reference-experiment")
    model = Model(rig, camdyn.Scene(contact="line", damping="B", friction="coulomb"), camdyn.ConstantSpeed(135.0))
    x, mode = _start(model, 20, None, TIGHT, "compiled")
    P = StroboscopicMap(model, 1, 0.0, mode, TIGHT)
    r = tangent(model, P.t_span, x, mode=mode, options=TIGHT)
    assert r.switches >= 2
    scale = np.array([1e-3, 1e-1])                      # rad, rad/s: the motion's size here
    coarse, fine = (finite_differences(P, scale, f)(x)[1] for f in (0.1, 0.03))
    spread = np.max(np.abs(coarse - fine))
    assert np.max(np.abs(r.phi - fine)) <= 3 * spread + 1e-6 * np.max(np.abs(fine))


def test_damping_e_impact_law_is_refused_with_the_way_out():
    """Damping E's impact law c = beta_E abs(psi_i)^(1/4) has an unbounded Jacobian at first
    contact: the tangent dynamics raise, naming finite differences (camdyn.orbits.tangent's docstring)."""
    from camdyn.orbits.tangent import TangentFailure
    scene = camdyn.Scene(contact="line", damping="E", friction="coulomb")
    model = Model(RIG, scene, camdyn.ConstantSpeed(1500.0))
    with pytest.raises(TangentFailure, match="finite_differences"):
        tangent(model, (0.0, 3 * model.period), model.static_state())
