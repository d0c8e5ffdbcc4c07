"""The rigid contact law (issue 28; the scene option ``contact="rigid"``): Newton's impact law as a reset,
the constrained mode in which the follower rides the cam, and the contact force as its multiplier.

The compliant laws (Eqs. 12-14, 24-28, 34) let the follower sink into the cam.  The rigid law does
not: the gap psi_i is never negative.

* **Impact.**  Where the gap closes (psi_i = 0, psi_i_dot < 0) the follower's rate jumps so that the
  normal relative velocity leaves at -xi times its arrival (Newton's law, xi the coefficient of
  restitution, the paper's Eq. 31), the position unchanged.  psi_i_dot is affine in the follower's
  rate q_dot, psi_i_dot = A q_dot + B (A = dpsi_i/dq, B = dpsi_i/dt at a fixed q: the cam's motion), so
  the reset is q_dot+ = q_dot- - (1 + xi) psi_i_dot- / A (:func:`impact_rate`): a reset of the automaton.
* **Constrained mode.**  While the follower rides the cam, psi_i = psi_i_dot = 0 for all t, so
  psi_i_ddot = 0 gives its acceleration: q_ddot = -(dpsi_i_dot/dt + dpsi_i_dot/dq q_dot) / A
  (:func:`constrained_acceleration`, the rigid-contact kinematics of Eq. 29 along the motion), with
  Baumgarte's stabilization so that numerical drift off the cam decays.
* **Contact force.**  The equation of motion is linear in the normal force, q_ddot = a0 + a1 F_n
  (derive.dynamics.acceleration), so the force that keeps the constraint is F_n = (q_ddot - a0) / a1
  (:func:`contact_force`): the follower leaves the cam where it turns negative.
* **Chatter.**  A sequence of impacts whose rates shrink geometrically ends at its accumulation point in
  the constrained mode, with the plastic reset q_dot+ = q_dot- - psi_i_dot- / A (:func:`plastic_rate`):
  the rule is the engine's (camdyn.engine.rules.chatter_ends), the automaton declares which transition
  it replaces (derive.automaton).
"""
from __future__ import annotations

import sympy as sp

from . import dynamics
from . import symbols as S
from .graph import Definition, quantity

#: the named quantities of the rigid law (as they appear in generated code)
PSI_DOT_PARTIALS = tuple(quantity(n) for n in ("dpsi_i_dot_dt", "dpsi_i_dot_dq", "dpsi_i_dot_dq_dot"))


def gap_rate_partials(gap_rate: sp.Expr, coordinate: S.Coordinate) -> tuple[Definition, ...]:
    """psi_i_dot's partial derivatives at a fixed state: by t (the cam's motion), by q and by q_dot (= A)."""
    notes = ("dpsi_i_dot/dt at a fixed state", "dpsi_i_dot/dq", "dpsi_i_dot/dq_dot = dpsi_i/dq")
    return tuple(Definition(sym, gap_rate.diff(x), note)
                 for sym, x, note in zip(PSI_DOT_PARTIALS, (S.t_s, coordinate.plain, coordinate.rate), notes))


def constrained_acceleration(coordinate: S.Coordinate, psi_i: sp.Expr, psi_i_dot: sp.Expr) -> sp.Expr:
    """q_ddot that keeps the follower on the cam, in the partials' names: psi_i_ddot = 0, stabilized
    (Baumgarte 1972): psi_i_ddot + 2 vartheta psi_i_dot + vartheta^2 psi_i = 0, so that the rounding and
    the integration's error, which a plain psi_i_ddot = 0 lets drift off the cam at a constant rate (1e-7 m
    a revolution seen at rtol 1e-8), decay at the rate vartheta (the follower's frequency on its spring,
    camdyn.model.model._rigid_equilibrium) instead; on the cam (psi_i = psi_i_dot = 0) it is the rigid
    kinematics exactly."""
    d_t, d_q, d_qd = PSI_DOT_PARTIALS
    beta = S.vartheta
    return -(d_t + d_q * coordinate.rate + 2 * beta * psi_i_dot + beta**2 * psi_i) / d_qd


def impact_rate(gap_rate_value: sp.Expr, coordinate: S.Coordinate, xi: sp.Expr = S.xi) -> sp.Expr:
    """q_dot after an impact: Newton's law psi_i_dot+ = -xi psi_i_dot- (psi_i_dot- the named gap rate)."""
    return coordinate.rate - (1 + xi) * gap_rate_value / PSI_DOT_PARTIALS[2]


def plastic_rate(gap_rate_value: sp.Expr, coordinate: S.Coordinate) -> sp.Expr:
    """q_dot after a plastic impact (psi_i_dot+ = 0): the end of a chatter, into the constrained mode."""
    return impact_rate(gap_rate_value, coordinate, sp.Integer(0))


def contact_force(regime: dynamics.ContactRegime, acceleration: sp.Symbol) -> sp.Expr:
    """The normal force that produces the constrained ``acceleration``: the equation of motion (Eq. 10, or
    the translating follower's along its guide) is linear in F_n, q_ddot = a0 + a1 F_n."""
    a = dynamics.acceleration(regime).expr
    a0, a1 = a.subs(dynamics.Q.F_n, 0), a.diff(dynamics.Q.F_n)
    if a1 == 0 or a1.has(dynamics.Q.F_n):
        raise RuntimeError(f"the equation of motion is not linear in F_n: {a}")
    return (acceleration - a0) / a1
