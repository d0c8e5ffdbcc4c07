"""Energy of the follower, power flows, and the energy balance of Section 5 (Eqs. 30-33).

The mechanical energy is E = T + V_s + V_c.  The spring's moment in Eq. 10,
-F_s(alpha) d_x, depends on alpha only, so it has the potential

    V_s(alpha) = integral of k_s d_x L(a) da,

which is what the equation of motion conserves.  The paper's Eq. 33 uses a
different one, Delta V = integral of k_s L L' da = (k_s/2)[L^2] (the spring's own
strain energy); both are generated, and the printed one serves Figs. 7-8.

Power flows (all >= 0 when the laws are dissipative):
  D_c = -F_d psi_i_dot       dissipated by contact damping (F_d = -c psi_i_dot),
  D_f = F_f v_r              dissipated by friction (kinematic v_r, even when the
                             law's sign follows the printed v_r),
  P_in                       delivered by the cam drive,
with dE/dt = P_in - D_c - D_f, an identity checked symbolically in the tests.
"""
from __future__ import annotations

from functools import lru_cache
from typing import Callable

import sympy as sp

from . import dynamics, laws
from . import symbols as S
from .symbols import alpha, t


def kinetic() -> sp.Expr:
    return S.I_Pb * alpha.diff(t) ** 2 / 2


class LogAbs(sp.Function):
    """log|u|: a real antiderivative of u'/u on any interval where u keeps its sign.

    Its derivative is written out, u'/u (d log|u| = du/u for real u != 0), so a potential
    built with it differentiates back to its integrand symbolically, and at a number it is
    log|u|, a real number (SymPy's log(-1) is i pi).  :func:`printable` writes it as
    log(Abs(u)) for code generation."""

    @classmethod
    def eval(cls, u):
        if u.is_number:
            return sp.log(sp.Abs(u))
        return None

    def fdiff(self, argindex=1):
        return 1 / self.args[0]


def real_logs(expr: sp.Expr) -> sp.Expr:
    """An antiderivative with its logarithms made real: log(u) -> log|u| (:class:`LogAbs`).

    SymPy's antiderivative of a real trigonometric-rational integrand holds each log(u) from
    the integral of u'/u with a real coefficient, and writes log(u) where the real
    antiderivative is log|u|: the two differ by the constant i pi where u < 0 (a cubic spring
    gives log(sin(a) - 1), negative for every follower angle).  log|u| has the same
    derivative u'/u, so it is an antiderivative too, and a real one."""
    return expr.replace(sp.log, LogAbs)


def _log_abs(u: sp.Expr) -> sp.Expr:
    """log|u| in SymPy's functions, with the logarithms of a cubic spring's antiderivative in
    log|cos x| where they can be: sin(x) - 1 as 2 log|cos x| - log|sin x + 1| (|sin x - 1|
    |sin x + 1| = cos^2 x), which keeps its precision near x = pi/2, and sec(x)^n as
    -n log|cos x|, one logarithm fewer."""
    x, n = sp.Wild("x"), sp.Wild("n", properties=[lambda k: k.is_Integer])
    match = u.match(sp.sin(x) - 1) or (-u).match(sp.sin(x) - 1)
    if match:
        return 2 * sp.log(sp.Abs(sp.cos(match[x]))) - sp.log(sp.Abs(sp.sin(match[x]) + 1))
    match = u.match(sp.sec(x) ** n)
    if match:
        return -match[n] * sp.log(sp.Abs(sp.cos(match[x])))
    return sp.log(sp.Abs(u))


def _cos_squared(term: sp.Expr) -> sp.Expr | None:
    """-c cos(x)^2 for a sum c sin(x)^2 - c (the denominators of SymPy's antiderivatives of
    powers of sec), else None."""
    x, c = sp.Wild("x"), sp.Wild("c", exclude=[0])
    match = term.match(c * sp.sin(x) ** 2 - c) if term.is_Add else None
    return -match[c] * sp.cos(match[x]) ** 2 if match else None


def printable(expr: sp.Expr) -> sp.Expr:
    """A potential as generated code computes it: :class:`LogAbs` written log(Abs(u)) with SymPy's
    functions, and two forms of SymPy's antiderivatives that lose all precision near
    alpha = pi/2 written as exact identities in cos(x), which keeps it: sin(x) - 1 in a log
    (:func:`_log_abs`) and c (sin(x)^2 - 1) (as -c cos(x)^2).  In floats sin(x) rounds to 1
    within 1e-8 rad of pi/2, so those are 0 there (log(0), 1/0: an error in Python, inf in
    compiled code); camdyn.analysis.statics.energy_balance_peak evaluates the potential at
    pi/2 - 1e-9.  (Near -pi/2, log|sin x + 1| and the paper's spring's log|tan x + sec x| lose
    it alike: the follower does not swing there.)"""
    expr = expr.replace(LogAbs, _log_abs)
    return expr.replace(lambda e: _cos_squared(e) is not None, _cos_squared)


def moment_potential(force: Callable[[sp.Expr], sp.Expr]) -> sp.Expr:
    """V(alpha) = F(alpha) - F(0), the potential of the moment d_x force(alpha) of a vertical
    spring force at arm d_x (Eq. 10), with F a real antiderivative (:func:`real_logs`).

    Not SymPy's definite integral: its F(0) keeps log(-1) = i pi for a law whose antiderivative
    has log(u) with u(0) < 0 (the cubic spring of docs/model-editing.md: log(sin(a) - 1)), a
    complex constant that compiled code cannot store in a real output.  A potential is defined
    up to a constant; this one is real, 0 at alpha = 0, and its derivative is the moment
    (checked by :func:`camdyn.derive.fields.checked_potential`)."""
    a = sp.Symbol("a", real=True)
    F = real_logs(sp.integrate(S.d_x * force(a), a))
    return F.subs(a, alpha) - F.subs(a, 0)


@lru_cache(maxsize=None)  # pure: an integral, asked for by every scene
def spring_potential() -> sp.Expr:
    """V_s(alpha), the potential of the spring moment of Eq. 10 (zero at alpha = 0), real; it
    follows an edited spring law (:func:`camdyn.derive.laws.spring_force`)."""
    return moment_potential(laws.spring_force)


def spring_potential_printed() -> sp.Expr:
    """(k_s/2) L(alpha)^2, whose differences are Delta V of Eq. 33 in closed form."""
    return S.k_s * laws.spring_compression(alpha) ** 2 / 2


def contact_potential(contact: str) -> sp.Expr:
    return laws.contact_potential(contact, dynamics.gap())


def power_flows(regime: dynamics.ContactRegime) -> tuple[sp.Expr, sp.Expr, sp.Expr]:
    """(P_in, D_c, D_f) in a contact regime.

    P_in is the rate at which the contact forces do work on the follower's
    energy minus what they dissipate, i.e. the power the cam delivers:
    P_in = dE/dt + D_c + D_f with dE/dt from the equation of motion.
    """
    f = dynamics.forces(regime)
    F_elastic = laws.elastic_force(regime.contact, dynamics.gap())
    F_damping = f.F_n - F_elastic
    D_c = -F_damping * dynamics.gap_rate()
    # the friction force does work through the true relative velocity of the contact
    # points, whatever v_r its law uses for its sign (misprint 8's printed form)
    D_f = f.F_f * dynamics.sliding_velocity("kinematic")
    alpha_ddot = dynamics.moment_about_P(f) / S.I_Pb
    energy = kinetic() + spring_potential() + contact_potential(regime.contact)
    dE_dt = energy.diff(t).subs(alpha.diff(t, 2), alpha_ddot)
    return dE_dt + D_c + D_f, D_c, D_f


def drive_power(regime: dynamics.ContactRegime) -> sp.Expr:
    """Power of the cam drive from the forces on the cam: -(F_n n + F_f u) . v_c.

    The follower pushes the cam with +F_n n + F_f u at its contact point; the
    drive supplies the opposite power to keep the prescribed motion.
    """
    f = dynamics.forces(regime)
    _, v_c = dynamics.material_point_velocities()
    B = dynamics.B
    return -(f.F_n * B.y + f.F_f * B.x).dot(v_c)


def impact_kinetic_energy(xi: sp.Expr) -> sp.Expr:
    """T_b of Eq. 32: the follower leaves the impact at (1 + xi) e Omega_c / chi* (Eq. 31)."""
    return S.I_Pb * ((1 + xi) * S.e * S.Omega_c / S.chi_star) ** 2 / 2
