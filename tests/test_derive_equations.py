"""The derivation (camdyn.derive) against the paper's printed equations (tests/paper_printed.py).

Each test proves one equation (docs/equations.md) or names one misprint of docs/misprints.md.
"Proves" means exact symbolic equality: the difference is shown to be 0 by
``sp.expand`` / ``sp.expand_trig`` + ``sp.expand`` (cheap) or else ``sp.simplify``.
Where a test falls back to numbers, its docstring says so and why.

Runtime budget: the whole file in well under 60 s.
"""
from __future__ import annotations

import math

import mpmath
import numpy as np
import pytest
import sympy as sp

import paper_printed as PP
from camdyn.derive import dynamics, energy, equilibrium, geometry, laws, linear
from camdyn.derive import symbols as S

a, Th, t = S.alpha, S.Theta, S.t
a_dot, Th_dot = a.diff(t), Th.diff(t)
CR = dynamics.ContactRegime

#: Contact regimes covering the laws: line/point, damping none/A-E (both phases of D/E,
#: both signs of B/D), friction none/Coulomb (both directions)/tanh, both v_r forms.
REGIMES = [
    CR("line"),
    CR("point"),
    CR("line", "A"),
    CR("point", "D", "loading"),
    CR("line", "D", "unloading", "coulomb", 1),
    CR("line", "B", "loading", "coulomb", -1, "printed"),
    CR("point", "C", friction="tanh"),
    CR("line", "E", "loading", "tanh", sliding_velocity="printed"),
    CR("point", "E", "unloading", "coulomb", -1),
    CR("line", "D", "loading", "tanh", damping_sign="printed"),
]


def _rid(r):
    return None if r is None else "-".join(str(v) for v in (r.contact, r.damping, r.phase, r.friction,
                                                             r.direction, r.damping_sign, r.sliding_velocity))


def is_zero(expr) -> bool:
    """Exact zero test: expand, then expand_trig + expand, then simplify (slowest last)."""
    expr = sp.sympify(expr)
    if expr == 0 or sp.expand(expr) == 0:
        return True
    if sp.expand(sp.expand_trig(expr)) == 0:
        return True
    return sp.simplify(expr) == 0


def assert_zero(expr, what: str):
    assert is_zero(expr), f"{what}: difference does not vanish: {str(expr)[:400]}"


def unhertz(expr):
    """Write laws.SignedPow32(x) out as x |x|^(1/2), its definition."""
    return expr.replace(laws.SignedPow32, lambda x: x * sp.sqrt(sp.Abs(x)))


def example_values(**override) -> dict:
    """The shipped example rig as {symbol: value}, Y_e from Eq. 14."""
    from camdyn.model.presets import example_rig

    d = {k: v for k, v in example_rig().to_dict().items() if k in S.PARAMS and v is not None}
    d.update(override)
    vals = {S.PARAMS[k].symbol: sp.Float(v, 30) for k, v in d.items()}
    vals[laws.Y_e] = PP.Y_e_eq14.subs(vals)
    return vals


def value_at_random_point(expr, seed=0) -> float:
    """expr (time functions allowed) at one random point, all symbols in [0.1, 1]: a witness
    that a difference is NOT identically zero."""
    plain = unhertz(S.to_plain(expr))
    rng = np.random.default_rng(seed)
    point = {x: sp.Float(rng.uniform(0.1, 1.0), 30) for x in sorted(plain.free_symbols, key=str)}
    return float(plain.subs(point).evalf(30))


def lambdify_mp(args, expr):
    """lambdify to mpmath (for evaluation at 30+ digits), Hertz force written out."""
    return sp.lambdify(args, expr, modules=[{"SignedPow32": lambda z: z * mpmath.sqrt(abs(z))}, "mpmath"])


# --- Section 3.1: geometry --------------------------------------------------------------------

def test_eq5_P_to_E_from_zero_state():
    """Eq. 5: P->E from the loop in the 0-state equals the printed components."""
    v = geometry.P_to_E()
    assert_zero(v.dot(geometry.N.x) - PP.PE_x, "Eq. 5, e_x")
    assert_zero(v.dot(geometry.N.y) - PP.PE_y, "Eq. 5, e_y")


def test_eq6_eq7_loop_solution_and_conditioned_forms():
    """Eqs. 6-7: the solved vector loop, and the cancellation-free forms of the generated
    code, equal the printed psi_i and psi_j."""
    psi_i, psi_j = geometry.loop_solution()
    assert_zero(psi_i - PP.psi_i, "Eq. 6, loop solution")
    assert_zero(psi_j - PP.psi_j, "Eq. 7, loop solution")
    assert_zero(geometry.psi_i_conditioned() - PP.psi_i, "Eq. 6, conditioned form")
    assert_zero(geometry.psi_j_conditioned() - PP.psi_j, "Eq. 7, conditioned form")
    assert_zero(geometry.chi() - PP.chi, "chi = chi0 - psi_j")


def test_eq8_eq9_rates():
    """Eqs. 8-9: dynamics.gap_rate() and psi_j_rate() equal the printed time derivatives."""
    assert_zero(dynamics.gap_rate() - PP.psi_i_dot, "Eq. 8")
    assert_zero(dynamics.psi_j_rate() - PP.psi_j_dot, "Eq. 9")


# --- Section 3.2: laws and equations of motion -----------------------------------------------

def test_eq11_eq13_eq14_eq34_force_laws():
    """Eq. 11 (spring), Eq. 14 (Y_e), Eq. 13 (line stiffness, Y_e by Eq. 14) and the point
    elastic force -(4/3) Y_e (r_c |psi|)^0.5 psi (Eq. 34 in Eq. 12)."""
    assert laws.Y_e == PP.Y_e, "laws.Y_e is not the symbol the transcription uses"
    assert_zero(laws.spring_force(a) - PP.eq11_spring_force(a), "Eq. 11")
    assert_zero(laws.equivalent_modulus() - PP.Y_e_eq14, "Eq. 14")
    assert_zero(laws.CONSTANTS[laws.Y_e] - PP.Y_e_eq14, "Eq. 14 in laws.CONSTANTS")
    psi = sp.Symbol("psi", real=True)
    k_line = laws.contact_stiffness("line", psi).subs(laws.Y_e, laws.equivalent_modulus())
    assert_zero(k_line - PP.eq13_line_stiffness(PP.Y_e_eq14), "Eq. 13 with Eq. 14")
    assert_zero(laws.contact_stiffness("point", psi) - PP.eq34_point_stiffness(psi), "Eq. 34 (secant k)")
    F_point = unhertz(laws.elastic_force("point", psi))
    assert_zero(F_point - PP.eq12_normal_force(PP.eq34_point_stiffness(psi), 0, psi, 0), "Eq. 34 in Eq. 12")
    assert_zero(laws.elastic_force("line", psi) - PP.eq12_normal_force(PP.eq13_line_stiffness(), 0, psi, 0),
                "Eq. 13 in Eq. 12")


def _printed_damping(regime, k, psi):
    """c_lambda of Eqs. 24-28 for a regime; B/D with the regime's sign reading (misprint 2)."""
    model, phase = regime.damping, regime.phase
    if model == "none":
        return 0
    if model == "A" or (model in "DE" and phase == "unloading"):
        return PP.eq24_viscous({"A": S.zeta_A, "D": S.zeta_D, "E": S.zeta_E}[model])
    if model in ("C", "E"):
        return PP.eq26_impact_power(S.beta_C if model == "C" else S.beta_E, psi)
    beta = S.beta_B if model == "B" else S.beta_D
    if regime.damping_sign == "printed":
        return PP.eq25_impact_k(beta, k, psi)
    return PP.eq25_impact_k(beta, k, sp.Abs(psi))   # misprint 2: the dissipative reading, k |psi|


def test_eq24_to_eq28_damping_laws():
    """Eqs. 24-28: laws.damping_coefficient equals the printed laws (B/D 'printed' sign
    exactly as printed, 'dissipative' with |psi_i|: misprint 2)."""
    k, psi = sp.symbols("k psi", real=True)
    for model in laws.DAMPING_MODELS:
        for phase in ("loading", "unloading"):
            for sign in laws.DAMPING_SIGNS:
                reg = CR(damping=model, phase=phase, damping_sign=sign)
                got = laws.damping_coefficient(model, phase, k, psi, sign)
                assert_zero(got - _printed_damping(reg, k, psi), f"damping {model} {phase} {sign}")


@pytest.mark.parametrize("regime", REGIMES, ids=_rid)
def test_eq12_normal_force_and_friction(regime):
    """Eq. 12: F_n = -k psi_i - c psi_i_dot with the printed laws (Eqs. 13/34, 24-28), and
    F_f = mu F_n with mu of model I (mu_m sgn v_r) or II (mu_m tanh(s v_r)), v_r in the
    regime's form (the printed one transcribed from Section 3.4)."""
    f = dynamics.forces(regime)
    psi, psi_dot = dynamics.gap(), dynamics.gap_rate()
    k = PP.eq13_line_stiffness() if regime.contact == "line" else PP.eq34_point_stiffness(psi)
    F_n = PP.eq12_normal_force(k, _printed_damping(regime, k, psi), psi, psi_dot)
    assert_zero(unhertz(f.F_n) - F_n, "Eq. 12")
    if regime.friction == "none":
        assert f.F_f == 0
        return
    if regime.sliding_velocity == "printed":
        assert_zero(f.v_r - PP.v_r_printed(), "printed v_r (Section 3.4)")
    mu = regime.direction * S.mu_m if regime.friction == "coulomb" else S.mu_m * sp.tanh(S.s * f.v_r)
    assert_zero(f.F_f - mu * f.F_n, "F_f = mu F_n")


@pytest.mark.parametrize("regime", REGIMES, ids=_rid)
def test_eq10_moment_balance(regime):
    """Eq. 10: the moment about P of the force vectors is -F_s d_x + F_n chi - 0.5 F_f w_b,
    with F_s of Eq. 11 and chi = chi0 - psi_j (geometry.chi(), equal to chi0 - Eq. 7 by
    test_eq6_eq7_loop_solution_and_conditioned_forms).  F_n, F_f are the regime's forces
    (test_eq12_normal_force_and_friction ties them to the printed laws)."""
    f = dynamics.forces(regime)
    assert_zero(f.F_s - PP.eq11_spring_force(), "F_s, Eq. 11")
    M = dynamics.moment_about_P(f)
    assert_zero(M - PP.eq10_moment(f.F_s, f.F_n, f.F_f, geometry.chi()), "Eq. 10")
    assert_zero(dynamics.angular_acceleration(regime) * S.I_Pb - M, "I_Pb alpha_ddot = M_P")


def test_eq10_eq35_for_arbitrary_force_magnitudes():
    """Eqs. 10 and 35 hold for any force magnitudes: the vector moment and the bearing
    balance are linear in F_s, F_n, F_f with exactly the printed coefficients."""
    F_s, F_n, F_f, v = sp.symbols("F_s F_n F_f v", real=True)
    f = dynamics.Forces(F_s, F_n, F_f, v)
    assert_zero(dynamics.moment_about_P(f) - PP.eq10_moment(F_s, F_n, F_f, PP.chi), "Eq. 10")
    assert_zero(dynamics.bearing_force_x(f) - PP.eq35_bearing_force(F_f, F_n), "Eq. 35")


def test_eq15_free_flight_keeps_spring_misprint3():
    """Eq. 15 / misprint 3: with no contact the moment is -F_s d_x (F_n = F_f = 0; the
    spring is NOT zeroed although the text says 'F_s(t) = 0')."""
    f = dynamics.forces(None)
    assert f.F_n == 0 and f.F_f == 0
    M = dynamics.moment_about_P(f)
    assert_zero(M - PP.eq15_moment(PP.eq11_spring_force()), "Eq. 15")
    assert M.has(S.k_s) and abs(value_at_random_point(M)) > 1e-12, "the spring must stay in Eq. 15"


@pytest.mark.parametrize("regime", REGIMES[:6] + [None], ids=_rid)
def test_eq35_bearing_force(regime):
    """Eq. 35: dynamics.bearing_force_x(f) = F_f cos(alpha) + F_n sin(alpha)."""
    f = dynamics.forces(regime)
    assert_zero(dynamics.bearing_force_x(f) - PP.eq35_bearing_force(f.F_f, f.F_n), "Eq. 35")


# --- misprint 8: the sliding velocity --------------------------------------------------------

def test_misprint8_sliding_velocity_kinematic_vs_printed():
    """Misprint 8: the kinematic v_r (material points' relative velocity along u) is
    psi_j_dot - r_c (alpha_dot + Theta_dot) - alpha_dot psi_i (so psi_j_dot - r_c(alpha_dot +
    Theta_dot) in contact, psi_i = 0); printed minus kinematic is
    -e sin(alpha+Theta)(alpha_dot+Theta_dot) + alpha_dot psi_i: the e sin term counted twice."""
    kin = dynamics.sliding_velocity("kinematic")
    assert_zero(kin - (PP.psi_j_dot - S.r_c * (a_dot + Th_dot) - a_dot * PP.psi_i), "kinematic v_r")
    assert_zero(kin.subs(a_dot, 0) - (PP.psi_j_dot - S.r_c * Th_dot).subs(a_dot, 0),
                "kinematic v_r, alpha_dot = 0")
    assert_zero(dynamics.sliding_velocity("printed") - PP.v_r_printed(), "printed v_r as transcribed")
    diff = PP.v_r_printed() - kin
    assert_zero(diff - (-S.e * sp.sin(a + Th) * (a_dot + Th_dot) + a_dot * PP.psi_i), "printed - kinematic")
    assert abs(value_at_random_point(diff)) > 1e-12
    # the relative velocity from the two bodies' rotations, written out by hand:
    # follower about P at -alpha_dot: (omega x P->O_b) . u = alpha_dot w_b/2;
    # cam about E at Theta_dot:       (omega x E->O_c) . u = Theta_dot (r_c + e sin(alpha+Theta))
    assert_zero(kin - (a_dot * S.w_b / 2 - Th_dot * (S.r_c + S.e * sp.sin(a + Th))), "rigid-body v_r")


def test_misprint8_sign_change_only_with_printed_form():
    """Misprint 8 / Section 7.2: e = 0.7 r_c, alpha_dot = 0, constant Theta_dot (both
    directions): over Theta in [0, 2 pi) the kinematic v_r keeps its sign, the printed one
    changes sign (twice per revolution).  Numeric sweep (lambdify)."""
    vals = example_values()
    vals[S.e] = sp.Rational(7, 10) * vals[S.r_c]
    theta = np.linspace(0, 2 * np.pi, 3601)[:-1]
    for form in ("kinematic", "printed"):
        for w in (+2 * np.pi * 50 / 60, -2 * np.pi * 50 / 60):
            v = S.to_plain(dynamics.sliding_velocity(form)).subs(vals)
            v = v.subs({S.alpha_dot: 0, S.Theta_dot: w, S.alpha_s: vals[S.alpha0]})
            f = sp.lambdify(S.Theta_s, v, "numpy")
            vr = np.asarray(f(theta), dtype=float) * np.ones_like(theta)
            changes = np.count_nonzero(np.sign(vr) != np.sign(np.roll(vr, 1)))
            if form == "kinematic":
                assert changes == 0 and np.min(np.abs(vr)) > 0.29 * abs(w) * float(vals[S.r_c])
            else:
                assert changes == 2


# --- Section 3.3: static equilibrium ---------------------------------------------------------

def _static_gap_at_star():
    return tuple(x.subs(a, S.alpha_star) for x in equilibrium.static_gap())


def test_eq16_eq17_static_gap():
    """Eqs. 16-17: equilibrium.static_gap() solves the printed static loop equations."""
    pis, pjs = _static_gap_at_star()
    assert_zero(PP.eq16.subs(PP.psi_i_star, pis), "Eq. 16")
    assert_zero(PP.eq17.subs(PP.psi_j_star, pjs), "Eq. 17")


def test_eq18_static_moment_sign_misprint1():
    """Misprint 1 (Eq. 18): the derived static moment is -F_s d_x - k psi_i* chi*
    (from Eqs. 10, 12), NOT the printed -F_s d_x + k psi_i* (chi0 - psi_j*): the printed
    minus the derived is 2 k psi_i* chi*, which is nonzero in contact (psi_i* < 0, chi* > 0).
    With the printed sign the balance would need psi_i* > 0 (a gap) when the spring presses
    the follower onto the cam (F_s d_x > 0): a tensile contact force."""
    pis, pjs = _static_gap_at_star()
    k = PP.eq13_line_stiffness()
    chi_star = S.chi0 - pjs
    M = equilibrium.static_moment("line").subs(a, S.alpha_star)
    derived = -PP.eq11_spring_force(S.alpha_star) * S.d_x - k * pis * chi_star
    assert_zero(M - derived, "derived Eq. 18")
    # the same with the printed psi_i*, psi_j* of Eqs. 16-17
    pis_p = sp.solve(PP.eq16, PP.psi_i_star)[0]
    pjs_p = sp.solve(PP.eq17, PP.psi_j_star)[0]
    assert_zero(M - (-PP.eq11_spring_force(S.alpha_star) * S.d_x - k * pis_p * (S.chi0 - pjs_p)),
                "derived Eq. 18 with printed Eqs. 16-17")
    printed = PP.eq18.subs({PP.psi_i_star: pis, PP.psi_j_star: pjs})
    assert_zero(printed - M - 2 * k * pis * chi_star, "printed - derived Eq. 18")
    # at the example rig's derived equilibrium the printed residual is 2 k psi_i* chi* = -2 F_s* d_x != 0
    vals = example_values()
    a_star = sp.nsolve(M.subs(vals), S.alpha_star, 0, prec=30)
    residual = float(printed.subs(vals).subs(S.alpha_star, a_star))
    spring_moment = float((PP.eq11_spring_force(S.alpha_star) * S.d_x).subs(vals).subs(S.alpha_star, a_star))
    assert spring_moment > 1 and math.isclose(residual, -2 * spring_moment, rel_tol=1e-9)
    # sign of the gap each balance implies, for a spring moment F_s d_x > 0 and chi* > 0
    p, Fsdx, chi_ = sp.Symbol("p", real=True), sp.Symbol("Fsdx", positive=True), sp.Symbol("chi", positive=True)
    kk = sp.Symbol("k", positive=True)
    assert sp.solve(-Fsdx - kk * p * chi_, p)[0].is_negative          # derived: contact
    assert sp.solve(-Fsdx + kk * p * chi_, p)[0].is_positive          # printed: a gap


def test_eq23_frequency_misprint4():
    """Misprint 4 (Eq. 23): for the undamped contact Jacobian J = [[0, 1], [-K/I, 0]] the
    eigenvalues are +-i sqrt(K/I), so vartheta = |Im eig J| (rad/s); the printed
    |Im eig J|^0.5 is its square root.  At the example rig's equilibrium: J from
    equilibrium.state_jacobian, K = -I J21 the exact stiffness, vartheta/2pi near the paper's
    2182 Hz (the rig's I_Pb was chosen so), printed value about 18.7 'Hz'."""
    w2 = sp.Symbol("w2", positive=True)
    J = sp.Matrix([[0, 1], [-w2, 0]])
    assert sorted(sp.Abs(sp.im(x)) for x in J.eigenvals(multiple=True)) == [sp.sqrt(w2)] * 2
    assert all(v == w2 ** sp.Rational(1, 4) for v in PP.eq23_vartheta(J))
    vals = example_values()
    J = equilibrium.state_jacobian(dynamics.angular_acceleration(CR("line")))
    a_star = sp.nsolve(S.to_plain(equilibrium.static_moment("line")).subs(vals), S.alpha_s, 0, prec=30)
    Jn = J.subs(vals).subs({S.alpha_s: a_star, S.alpha_dot: 0, S.Theta_s: vals[S.theta0], S.Theta_dot: 0})
    Jn = np.array(Jn.evalf(), dtype=float)
    assert Jn[1, 1] == 0 and Jn[1, 0] < 0
    vartheta = max(abs(np.linalg.eigvals(Jn).imag))
    assert math.isclose(vartheta, math.sqrt(-Jn[1, 0]), rel_tol=1e-12)
    assert 2000 < vartheta / (2 * math.pi) < 2400
    printed = max(float(v) for v in PP.eq23_vartheta(sp.Matrix(Jn)))
    assert math.isclose(printed**2, vartheta, rel_tol=1e-9) and printed / (2 * math.pi) < 20


# --- misprints 5 and 2: contact law details --------------------------------------------------

def test_misprint5_point_tangent_over_secant_is_three_halves():
    """Misprint 5: for point contact (Eq. 34), d(elastic force)/d(-psi) over the secant
    k_lambda(psi) is exactly 3/2, from the derivation's force (with SignedPow32's written-out
    derivative) and from the printed law; so 2182 Hz sqrt(1.5 * 34.2/138) is the paper's 1331 Hz."""
    psi = sp.Symbol("psi", negative=True)
    tangent = laws.elastic_force("point", psi).diff(psi) * -1
    assert sp.simplify(tangent / laws.contact_stiffness("point", psi)) == sp.Rational(3, 2)
    F_printed = PP.eq12_normal_force(PP.eq34_point_stiffness(psi), 0, psi, 0)
    assert sp.simplify(-F_printed.diff(psi) / PP.eq34_point_stiffness(psi)) == sp.Rational(3, 2)
    # SignedPow32's derivative is the derivative of its definition (both signs of psi)
    x = sp.Symbol("x", real=True)
    for xs in (sp.Symbol("xn", negative=True), sp.Symbol("xp", positive=True)):
        assert sp.simplify(laws.SignedPow32(x).diff(x).subs(x, xs) - (xs * sp.sqrt(sp.Abs(xs))).diff(xs)) == 0
    assert abs(2182 * math.sqrt(1.5 * 34.2 / 138) - 1331) < 2


def test_misprint2_printed_impact_damping_is_negative():
    """Misprint 2 (Eqs. 25, 27a): with psi_i < 0 (contact), k > 0, beta > 0 the printed
    c = beta k psi_i is negative, the dissipative beta k |psi_i| nonnegative; the damping power
    D_c = c psi_i_dot^2 (energy.power_flows) has the sign of c, so the printed law supplies energy."""
    k, beta = sp.Symbol("k", positive=True), sp.Symbol("beta", positive=True)
    psi, psi_dot = sp.Symbol("psi", negative=True), sp.Symbol("psi_dot", real=True)
    for model in ("B", "D"):
        c_p = laws.damping_coefficient(model, "loading", k, psi, "printed").subs({S.beta_B: beta, S.beta_D: beta})
        c_d = laws.damping_coefficient(model, "loading", k, psi, "dissipative").subs({S.beta_B: beta, S.beta_D: beta})
        assert c_p.is_negative, c_p
        assert c_d.is_nonnegative, c_d
    for sign, expect in (("printed", "nonpositive"), ("dissipative", "nonnegative")):
        reg = CR("line", "B", damping_sign=sign)
        _, D_c, _ = energy.power_flows(reg)
        c = laws.damping_coefficient("B", "loading", laws.contact_stiffness("line", 0), dynamics.gap(), sign)
        assert_zero(D_c - c * dynamics.gap_rate() ** 2, f"D_c = c psi_i_dot^2 ({sign})")
        D_sym = (c * dynamics.gap_rate() ** 2).xreplace({dynamics.gap(): psi, dynamics.gap_rate(): psi_dot})
        D_sym = D_sym.subs(S.beta_B, beta)
        assert getattr(D_sym, f"is_{expect}"), (sign, D_sym)


# --- Section 8: linearized model -------------------------------------------------------------

@pytest.fixture(scope="module")
def paper_models():
    return (linear.paper_linear_model(PP.c_lambda, PP.mu, "printed"),
            linear.paper_linear_model(PP.c_lambda, PP.mu, "derived"))


def test_eq38_paper_linear_model_as_printed_misprint9(paper_models):
    """Eqs. 38a-c: paper_linear_model(c, mu, 'printed') gives the printed C_l, K_l, F_l(t);
    forcing_arm='derived' replaces chi0 by chi* in F_l's contact arm, nothing else (misprint 9)."""
    printed, derived = paper_models
    assert_zero(printed.C_l - PP.C_l, "Eq. 38a")
    assert_zero(printed.K_l - PP.K_l, "Eq. 38b")
    assert_zero(printed.F_l - PP.F_l(), "Eq. 38c")
    assert_zero(derived.K_l - PP.K_l, "Eq. 38b (derived arm)")
    assert_zero(derived.C_l - PP.C_l, "Eq. 38a (derived arm)")
    assert_zero(derived.F_l - PP.F_l(S.chi_star), "Eq. 38c with chi* in the contact arm")
    psi_at_star = S.to_plain(PP.psi_i).subs(S.alpha_s, S.alpha_star)     # Eq. 6 at alpha*, Theta(t)
    k = PP.eq13_line_stiffness()
    assert_zero(derived.F_l - printed.F_l + k * (S.chi_star - S.chi0) * psi_at_star, "F_l derived - printed")
    assert abs(value_at_random_point(derived.F_l - printed.F_l)) > 1e-12


def _exact_stiffness_and_damping(direction):
    """K, C of the exact Jacobian (Eqs. 21-22) of the line-contact regime with constant
    damping (model A) and Coulomb friction, at alpha*, alpha_dot = 0, Theta = Theta0, Theta_dot = 0."""
    reg = CR("line", "A", friction="coulomb", direction=direction)
    J = equilibrium.state_jacobian(dynamics.angular_acceleration(reg))
    at = {S.alpha_s: S.alpha_star, S.alpha_dot: 0, S.Theta_s: S.theta0, S.Theta_dot: 0}
    return (-S.I_Pb * J[1, 0]).subs(at), (-S.I_Pb * J[1, 1]).subs(at)


@pytest.mark.parametrize("direction", [1, -1])
def test_misprint9_paper_stiffness_vs_exact_jacobian(direction):
    """Misprint 9: at equilibrium (alpha*, Theta0, at rest) the exact Jacobian's stiffness is
        K_exact = K_l - k (chi* - 0.5 mu w_b) e cos(alpha* + Theta0) - F_n* dchi/dalpha,
    i.e. the paper's K_l (Eq. 38b) keeps +e cos(alpha*+Theta0) whose parametric partner
    -e cos(alpha*+Theta(t)) it drops (they cancel at Theta0), and drops the geometric
    stiffness F_n* dchi/dalpha (F_n* = -k psi_i*); likewise C_exact = C_l - c (chi* - 0.5 mu w_b)
    e cos(alpha* + Theta0).  Proven symbolically; then at the example rig (Theta0 = pi/2, so
    cos(alpha*+Theta0) = -sin(alpha*) ~ 1e-6) K_l and K_exact differ, by about 5e-7 relative:
    there the geometric term dominates (~0.7 N m/rad of ~1.4e6 N m/rad).  With Theta0 = 0 the
    e term alone would be k chi* e, about 2.5 % of K_l."""
    mu = direction * S.mu_m
    K_x, C_x = _exact_stiffness_and_damping(direction)
    pis, pjs = (S.to_plain(x).subs(S.alpha_s, S.alpha_star) for x in equilibrium.static_gap())
    chi_star = S.chi0 - pjs
    k = PP.eq13_line_stiffness()
    c = laws.viscous_coefficient(S.zeta_A)                        # constant: contains chi_star
    F_n_star = -k * pis
    dchi = S.to_plain(geometry.chi()).diff(S.alpha_s).subs({S.alpha_s: S.alpha_star, S.Theta_s: S.theta0})
    arm = chi_star - mu * S.w_b / 2
    K_l = PP.K_l.subs(PP.mu, mu).subs(S.chi_star, chi_star)
    C_l = PP.C_l.subs(PP.mu, mu).subs(S.chi_star, chi_star).subs(PP.c_lambda, c)
    e_term = S.e * sp.cos(S.alpha_star + S.theta0)
    assert_zero(K_x - (K_l - k * arm * e_term - F_n_star * dchi), "exact K vs Eq. 38b")
    assert_zero(C_x - (C_l - c * arm * e_term), "exact C vs Eq. 38a")
    # numbers at the example rig
    vals = example_values()
    a_star = sp.nsolve(S.to_plain(equilibrium.static_moment("line")).subs(vals), S.alpha_s, 0, prec=30)
    num = {**vals, S.alpha_star: a_star}
    num[S.chi_star] = chi_star.subs(num)
    K_l_n, K_x_n = (float(x.subs(num)) for x in (K_l, K_x))
    geo, e_n = float((F_n_star * dchi).subs(num)), float((k * arm * e_term).subs(num))
    assert K_l_n != K_x_n
    assert math.isclose(K_l_n - K_x_n, geo + e_n, rel_tol=1e-9)
    assert 1e-8 < abs(K_l_n - K_x_n) / K_l_n < 1e-5
    assert abs(geo) > abs(e_n)
    # the e term at Theta0 = 0 (same rig otherwise) is a percent-level stiffness error
    e_at_0 = float((k * arm * S.e * sp.cos(S.alpha_star)).subs(num))
    assert 0.01 < e_at_0 / K_l_n < 0.05


# --- Section 5 and energy --------------------------------------------------------------------

def test_eq32_eq33_spring_potentials():
    """dV_s/dalpha = k_s d_x L(alpha) (the potential of Eq. 10's spring moment -F_s d_x),
    d(V_s_printed)/dalpha = k_s L L' (Eq. 33's integrand), and T_b of Eq. 32."""
    x = sp.Symbol("x", real=True)
    V_s = energy.spring_potential().subs(a, x)
    assert_zero(V_s.diff(x) - S.d_x * PP.eq11_spring_force(x), "dV_s/dalpha = F_s d_x")
    assert V_s.subs(x, 0) == 0
    V_p = energy.spring_potential_printed().subs(a, x)
    assert_zero(V_p.diff(x) - PP.eq33_integrand(x), "Eq. 33 integrand")
    assert abs(value_at_random_point(V_s.diff(x) - V_p.diff(x))) > 1e-12
    xi = sp.Symbol("xi", nonnegative=True)
    assert_zero(energy.impact_kinetic_energy(xi) - PP.eq32_kinetic(xi), "Eq. 32")


def _power_difference_at_random_points(regime, n=20, seed=0):
    """max |P_in - P_drive| / |P_drive| at n random points, evaluated at 40 digits."""
    P_in = S.to_plain(energy.power_flows(regime)[0])
    P_drive = S.to_plain(energy.drive_power(regime))
    args = sorted(P_in.free_symbols | P_drive.free_symbols, key=str)
    f_diff, f_ref = lambdify_mp(args, P_in - P_drive), lambdify_mp(args, P_drive)
    rng = np.random.default_rng(seed)
    worst = 0.0
    with mpmath.workdps(40):
        for row in rng.uniform(0.1, 1.0, size=(n, len(args))):
            pt = [mpmath.mpf(float(v)) for v in row]
            worst = max(worst, float(abs(f_diff(*pt)) / abs(f_ref(*pt))))
    return worst


@pytest.mark.parametrize("regime", [CR("line", "A", friction="tanh"),
                                    CR("point", "D", "loading", "coulomb", 1),
                                    CR("line", "B", "loading", "coulomb", -1, "printed"),
                                    CR("line", "A", friction="tanh", sliding_velocity="printed"),
                                    CR("point", "E", "unloading", "coulomb", -1, sliding_velocity="printed")],
                         ids=_rid)
def test_energy_input_power_is_drive_power(regime):
    """P_in of energy.power_flows (dE/dt + D_c + D_f from the equation of motion) equals the
    power of the forces on the cam, -(F_n n + F_f u) . v_c (energy.drive_power), for both v_r
    laws (the friction power is F_f times the kinematic slip even under the printed law).
    NUMERIC (last resort, 20 random points, 1e-12 relative, at 40 digits): the expressions have
    several hundred operations with tanh/Abs/Hertz terms and simplify does not finish within
    the file's time budget; double precision loses ~1e-11 to cancellation."""
    assert _power_difference_at_random_points(regime) < 1e-12


def test_misprint8_printed_law_makes_friction_supply_energy():
    """Misprint 8, energy side: D_f = F_f v_r_kinematic with F_f = mu_m tanh(s v_r) F_n.  With
    the printed v_r in the law, at e = 0.7 r_c, alpha_dot = 0, constant Theta_dot, the factor
    tanh(s v_r_law) v_r_kinematic is negative over part of each revolution (friction pushes
    along the slip and supplies energy); with the kinematic law it is never negative.
    Symbolic structure, then a numeric sweep over Theta (lambdify)."""
    vals = example_values()
    vals[S.e] = sp.Rational(7, 10) * vals[S.r_c]
    theta = np.linspace(0, 2 * np.pi, 3601)[:-1]
    v_kin = dynamics.sliding_velocity("kinematic")
    for form, negative_somewhere in (("kinematic", False), ("printed", True)):
        reg = CR("line", friction="tanh", sliding_velocity=form)
        f = dynamics.forces(reg)
        D_f = energy.power_flows(reg)[2]
        factor = sp.tanh(S.s * dynamics.sliding_velocity(form)) * v_kin
        assert_zero(D_f - S.mu_m * f.F_n * factor, f"D_f = mu_m F_n tanh(s v_r) v_r_kin ({form})")
        for w in (+2 * np.pi * 50 / 60, -2 * np.pi * 50 / 60):
            g = S.to_plain(factor).subs(vals).subs({S.alpha_dot: 0, S.Theta_dot: w, S.alpha_s: vals[S.alpha0]})
            y = np.asarray(sp.lambdify(S.Theta_s, g, "numpy")(theta), dtype=float) * np.ones_like(theta)
            assert (np.min(y) < 0) == negative_somewhere, (form, w, np.min(y))


# --- Section 4: rigid-contact angle ----------------------------------------------------------

def test_eq29_rigid_contact_angle_misprint10():
    """Eq. 29 / misprint 10: geometry.rigid_contact_angle(Theta) satisfies the rigid-contact
    condition P->G_c . n = r_c + w_b/2 and equals alpha0 at Theta = Theta0, on random rigs
    (alpha0 in (-0.5, 0.5), e < r_c), including cases with alpha_i < 0 where the printed
    arccos returns -alpha_i (it equals |alpha_i| throughout).  NUMERIC (random rigs at 30
    digits): a branch choice of asin/atan2 is a statement about numbers, not an identity."""
    alpha_i = S.to_plain(geometry.rigid_contact_angle(Th))
    r = geometry.P_to_Gc(S.Theta_s)
    X, Y = r.dot(geometry.N.x), r.dot(geometry.N.y)
    n = geometry.follower_frame(S.alpha_s).y
    contact = r.dot(n) - (S.r_c + S.w_b / 2)
    rig_syms = [S.r_c, S.e, S.w_b, S.chi0, S.alpha0, S.theta0]
    f_ai = lambdify_mp(rig_syms + [S.Theta_s], alpha_i)
    f_contact = lambdify_mp(rig_syms + [S.Theta_s, S.alpha_s], contact)
    f_X = lambdify_mp(rig_syms + [S.Theta_s], X)
    f_printed = lambdify_mp(rig_syms + [S.Theta_s], PP.eq29_alpha_i(X, Y))
    rng = np.random.default_rng(2)
    negatives = 0
    with mpmath.workdps(30):
        for _ in range(20):
            r_c = rng.uniform(0.02, 0.05)
            rig = [r_c, rng.uniform(0, 0.9) * r_c, rng.uniform(0.005, 0.03), rng.uniform(0.08, 0.2),
                   rng.uniform(-0.5, 0.5), rng.uniform(0, 2 * np.pi)]
            rig = [mpmath.mpf(v) for v in rig]
            assert abs(f_ai(*rig, rig[5]) - rig[4]) < 1e-25            # alpha_i(Theta0) = alpha0
            for Theta in rng.uniform(0, 2 * np.pi, 3):
                ai = f_ai(*rig, Theta)
                assert abs(f_contact(*rig, Theta, ai)) < 1e-25 * (rig[0] + rig[2])
                assert f_X(*rig, Theta) > 0
                if abs(ai) > 1e-3:
                    assert abs(f_printed(*rig, Theta) - abs(ai)) < 1e-20
                    negatives += ai < 0
    assert negatives >= 5, "the sample must contain alpha_i < 0 cases"
    # the explicit case: alpha0 = -0.3, at Theta0 the printed arccos gives +0.3
    with mpmath.workdps(30):
        rig = [mpmath.mpf(v) for v in ("0.025", "0.0025", "0.02", "0.1", "-0.3", "1.0")]
        assert abs(f_ai(*rig, rig[5]) + mpmath.mpf("0.3")) < 1e-25
        assert abs(f_printed(*rig, rig[5]) - mpmath.mpf("0.3")) < 1e-20
