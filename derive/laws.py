"""Constitutive laws: spring, Hertz contact, contact damping, dry friction (Sections 3.2, 3.4, 6).

Each law is a small function of the quantities it acts on, so a scene picks
the laws it needs and nothing else reaches its generated code.
"""
from __future__ import annotations

import sympy as sp

from . import symbols as S
from camdyn.vocabulary import CONTACT_LAWS, DAMPING_MODELS, DAMPING_SIGNS, FRICTION_MODELS  # noqa: F401


def spring_compression(a: sp.Expr) -> sp.Expr:
    """L(alpha) in Eq. 11: compression of the follower spring, acting as printed
    on the follower's cam-side surface (misprint 6 keeps the printed -0.5 w_b sec)."""
    return S.L_us - S.d_y + S.d_x * sp.tan(a) - S.w_b / 2 * sp.sec(a)


def spring_force(a: sp.Expr) -> sp.Expr:
    """F_s, Eq. 11 (vertical, upward on the follower, at horizontal distance d_x from P)."""
    return S.k_s * spring_compression(a)


#: Equivalent Young's modulus.  A symbol in the laws, defined once by
#: :data:`CONSTANTS`, so generated code computes it once per rig, not per call.
Y_e = sp.Symbol("Y_e", positive=True)


def equivalent_modulus() -> sp.Expr:
    """Y_e, Eq. 14, in terms of the materials' constants."""
    return 1 / ((1 - S.nu_c**2) / S.Y_c + (1 - S.nu_b**2) / S.Y_b)


#: Constants of the laws computed from rig parameters before a run.
CONSTANTS: dict[sp.Symbol, sp.Expr] = {Y_e: equivalent_modulus()}


def contact_stiffness(law: str, psi_i: sp.Expr, radius: sp.Expr = S.r_c) -> sp.Expr:
    """k_lambda(psi_i): Eq. 13 (line, constant) or Eq. 34 (point, Hertz, grows as |psi_i|^0.5).

    The point law uses |psi_i|, so inside the contact regime an integration stage
    that overshoots to psi_i > 0 gets a finite (odd, C1) extension, never a NaN.
    Misprint 11: the cam's radius of curvature is the only one, l_lambda does not enter;
    ``radius`` is r_c for the paper's circle, rho = h + h'' at the contact for any other cam.
    """
    if law == "line":
        return sp.pi / 4 * Y_e * S.l_lambda
    if law == "point":
        return sp.Rational(4, 3) * Y_e * sp.sqrt(radius * sp.Abs(psi_i))
    raise ValueError(f"contact law {law!r} is not one of {CONTACT_LAWS}")


class SignedPow32(sp.Function):
    """x |x|^(1/2): the Hertz point-contact force shape, odd and C1.

    Its derivative is written out, 1.5 |x|^(1/2), so generated Jacobians have no
    0/0 at x = 0 (SymPy's product rule on k(x) x with k ~ |x|^(1/2) would).
    """

    def fdiff(self, argindex=1):
        return sp.Rational(3, 2) * sp.sqrt(sp.Abs(self.args[0]))


def elastic_force(law: str, psi_i: sp.Expr, k_lambda: sp.Expr | None = None, radius: sp.Expr = S.r_c) -> sp.Expr:
    """-k_lambda(psi_i) psi_i, the elastic part of F_n in Eq. 12.

    ``k_lambda``: the stiffness as already computed (a named quantity), used as it is for the
    line law; the point law is written with :class:`SignedPow32` for a clean derivative.
    ``radius``: as in :func:`contact_stiffness`."""
    if law == "point":
        return -sp.Rational(4, 3) * Y_e * sp.sqrt(radius) * SignedPow32(psi_i)
    return -(contact_stiffness(law, psi_i) if k_lambda is None else k_lambda) * psi_i


def contact_potential(law: str, psi_i: sp.Expr, radius: sp.Expr = S.r_c) -> sp.Expr:
    """Elastic energy stored in the contact at deflection |psi_i| (psi_i <= 0 in contact).

    Built as the integral of the elastic normal force -k_lambda(psi) psi over the
    deflection, so that its derivative is the force of Eq. 12 by construction.  With a
    radius that varies along the cam (point contact on a cam other than a circle) it is the
    energy at the present radius: the Hertz force is then not exactly conservative.
    """
    x, delta = sp.symbols("x delta", nonnegative=True)  # deflection, its final value
    energy = sp.integrate(contact_stiffness(law, -x, radius) * x, (x, 0, delta))
    return energy.subs(delta, sp.Abs(psi_i))  # even in psi_i: finite on stage overshoot


def viscous_coefficient(zeta: sp.Expr, mass: sp.Expr | None = None) -> sp.Expr:
    """Eqs. 24, 27b, 28b: c = 2 zeta vartheta I_Pb / chi*^2 (vartheta in rad/s, misprint 4/7):
    2 zeta vartheta times the follower's inertia reduced to the contact, ``mass`` (default the
    rocker's I_Pb / chi*^2; a translating follower's m_f)."""
    return 2 * zeta * S.vartheta * (S.I_Pb / S.chi_star**2 if mass is None else mass)


def impact_coefficient_k(beta: sp.Expr, k_lambda: sp.Expr, psi_i: sp.Expr, sign: str) -> sp.Expr:
    """Eqs. 25, 27a: c = beta k_lambda psi_i as printed, or beta k_lambda |psi_i|.

    Misprint 2: with psi_i < 0 in contact the printed coefficient is negative, so
    F_n = k|psi_i|(1 + beta psi_i_dot) adds energy on approach.  The dissipative
    reading is the Hunt-Crossley law F_n = k|psi_i|(1 - beta psi_i_dot);
    ``tests/test_simulate.py`` (misprint 2) proves which one loses energy over an impact.
    """
    if sign == "dissipative":
        return beta * k_lambda * sp.Abs(psi_i)
    if sign == "printed":
        return beta * k_lambda * psi_i
    raise ValueError(f"damping sign {sign!r} is not one of {DAMPING_SIGNS}")


def impact_coefficient_power(beta: sp.Expr, psi_i: sp.Expr) -> sp.Expr:
    """Eqs. 26, 28a: c = beta |psi_i|^0.25."""
    return beta * sp.Abs(psi_i) ** sp.Rational(1, 4)


def damping_coefficient(model: str, phase: str, k_lambda: sp.Expr, psi_i: sp.Expr,
                        sign: str = "dissipative", mass: sp.Expr | None = None) -> sp.Expr:
    """c_lambda for damping model A-E (Eqs. 24-28) in contact phase ``phase``.

    ``phase`` is "loading" (from first contact t_a to maximum compression t_b,
    psi_i_dot < 0) or "unloading" (t_b to separation t_c); only D and E use it.
    ``mass``: the follower's inertia at the contact of the viscous laws (:func:`viscous_coefficient`).
    """
    if model == "none":
        return sp.Integer(0)
    if model == "A":
        return viscous_coefficient(S.zeta_A, mass)
    if model == "B":
        return impact_coefficient_k(S.beta_B, k_lambda, psi_i, sign)
    if model == "C":
        return impact_coefficient_power(S.beta_C, psi_i)
    if model in ("D", "E"):
        if phase == "unloading":
            return viscous_coefficient(S.zeta_D if model == "D" else S.zeta_E, mass)
        if phase != "loading":
            raise ValueError(f"damping {model} needs phase 'loading' or 'unloading', got {phase!r}")
        if model == "D":
            return impact_coefficient_k(S.beta_D, k_lambda, psi_i, sign)
        return impact_coefficient_power(S.beta_E, psi_i)
    raise ValueError(f"damping model {model!r} is not one of {DAMPING_MODELS}")


def friction_coefficient(model: str, v_r: sp.Expr, direction: int = 0) -> sp.Expr:
    """mu(t): model I (Coulomb, mu_m sgn v_r) or model II (smoothed, mu_m tanh(s v_r)).

    Coulomb friction is discontinuous at v_r = 0; the integrator keeps the sign of
    v_r as a discrete state, so the law is generated once per ``direction`` (+1/-1)
    with the sign folded in as a constant.
    """
    if model == "none":
        return sp.Integer(0)
    if model == "coulomb":
        if direction == 0:  # where friction does no work on the motion (a translating follower's face,
            return S.mu_m * sp.sign(v_r)  # derive.translating): no direction state, the sign itself
        if direction not in (1, -1):
            raise ValueError("Coulomb friction needs the sliding direction +1 or -1, or 0 for its sign")
        return direction * S.mu_m
    if model == "tanh":
        return S.mu_m * sp.tanh(S.s * v_r)
    raise ValueError(f"friction model {model!r} is not one of {FRICTION_MODELS}")
