"""Static equilibrium (Eqs. 16-18) and the state-space Jacobian (Eqs. 19-22).

At rest the cam stands at Theta = Theta0 and every rate is zero.  Eqs. 16-17
are the loop (Eqs. 6-7) there; Eq. 18 is the moment balance, Eq. 10, with no
rates: -F_s d_x + F_n chi = 0.  With psi_i* and psi_j* written as functions
of alpha*, the three equations reduce to one, M(alpha*) = 0, which the runtime
solves with M and dM/dalpha from here.  Friction is absent at rest (v_r = 0),
as in the paper's Eq. 18.  Misprint 1: the printed Eq. 18 has the contact term
with the wrong sign; ``tests/test_derive_equations.py`` (Eq. 18) shows the derived one.
"""
from __future__ import annotations

import sympy as sp

from . import dynamics, translating
from . import symbols as S
from .symbols import Theta, alpha, t, y


def at_rest(expr: sp.Expr) -> sp.Expr:
    """Set the cam to Theta0 and every time derivative to zero."""
    return expr.subs({alpha.diff(t): 0, y.diff(t): 0, Theta.diff(t): 0}).subs(Theta, S.theta0)


def static_gap(profile: str = dynamics.ECCENTRIC, follower: str = dynamics.OSCILLATING) -> tuple[sp.Expr, sp.Expr]:
    """(psi_i*, psi_j*) as functions of the follower's coordinate: Eqs. 16 and 17."""
    return at_rest(dynamics.gap(profile, follower)), at_rest(dynamics.psi_j(profile, follower))


def static_moment(contact: str, profile: str = dynamics.ECCENTRIC) -> sp.Expr:
    """M(alpha) at rest, undamped and frictionless: Eq. 18 is M(alpha*) = 0.  The rigid law has no
    deflection to balance the spring: its M is the spring's alone (negative where the spring presses the
    follower onto the cam), and its equilibrium is the 0-state."""
    regime = None if contact == "rigid" else dynamics.ContactRegime(contact=contact, profile=profile)
    return at_rest(dynamics.moment_about_P(dynamics.forces(regime, profile=profile), profile=profile))


def static_load(contact: str, profile: str = dynamics.ECCENTRIC, follower: str = dynamics.OSCILLATING) -> sp.Expr:
    """The static load at rest whose zero is the equilibrium: the rocker's moment M(alpha) (Eq. 18), or
    the translating follower's force along its guide, F_n - F_s at Theta0 (undamped, frictionless)."""
    if follower == dynamics.OSCILLATING:
        return static_moment(contact, profile)
    regime = None if contact == "rigid" else dynamics.ContactRegime(contact=contact, profile=profile, follower=follower)
    f = dynamics.forces(regime, follower, profile)
    return at_rest(translating.force_along_guide(f.F_s, f.F_n, f.F_f))


def state_jacobian(alpha_ddot: sp.Expr) -> sp.Matrix:
    """J = d(alpha_dot, alpha_ddot)/d(alpha, alpha_dot), Eqs. 21-22, in plain symbols."""
    h2 = S.to_plain(alpha_ddot)
    return sp.Matrix([[0, 1], [h2.diff(S.alpha_s), h2.diff(S.alpha_dot)]])
