"""The cam as its support function h(phi): the geometry of any convex cam, for a flat face.

A convex cam is described exactly, for a flat-faced follower, by its support function
h(phi): the distance from the rotation centre E to the tangent line whose outward normal
makes the angle phi with the cam's body axis (counter-clockwise).  With u(phi) = (cos phi,
sin phi) and u'(phi) = (-sin phi, cos phi), in the body frame,

    contact point    c(phi) = h(phi) u(phi) + h'(phi) u'(phi),
    curvature radius rho(phi) = h(phi) + h''(phi)   (convex: rho > 0).

The body axis is at the cam angle Theta in the fixed frame (counter-clockwise), so a fixed
direction at angle beta has the body angle phi = beta - Theta.

The paper's cam (Eqs. 3-4) is the circle of radius r_c whose centre G_c lies at the distance
e from E, on the side opposite to the body axis (E -> G_c = -e (cos Theta, sin Theta), Eq. 3):
h(phi) = r_c - e cos(phi) (:func:`eccentric_support`).

In the derivation h is :class:`SupportFunction` ``h(n, phi)``, the n-th derivative of an
undefined function: SymPy differentiates through it (d/dphi raises n), and the generated code
calls the scene's profile evaluator for it (:mod:`derive.codegen`), once per distinct call.
"""
from __future__ import annotations

import sympy as sp

from . import symbols as S

#: the highest derivative of h a kernel may need: h'' enters the Hertz radius (point contact),
#: the Jacobian differentiates once more, a saltation gradient of a slip-rate surface twice more
MAX_ORDER = 4


class _Derivatives(sp.Function):
    """f^(n)(phi), the n-th derivative (n an integer, 0 <= n <= ``max_order``) of a function of the
    cam's profile, evaluated by the scene's evaluator: unevaluated in SymPy, where d/dphi raises n,
    so the chain rule runs through any argument (the loop's time derivatives, the Jacobians)."""

    nargs = 2
    is_real = True
    max_order = 0

    @classmethod
    def eval(cls, n, phi):
        if not (n.is_Integer and 0 <= n <= cls.max_order):
            raise ValueError(f"{cls.__name__}: a kernel needs the derivative of order {n}; the evaluators give "
                             f"the orders 0 to {cls.max_order}")
        return None  # unevaluated: the profile is data of the rig

    def fdiff(self, argindex=2):
        if argindex != 2:
            raise sp.ArgumentIndexError(self, argindex)
        n, phi = self.args
        return type(self)(n + 1, phi)

    @property
    def order(self) -> int:
        return int(self.args[0])


class SupportFunction(_Derivatives):
    """h^(n)(phi), the n-th derivative of the cam's support function.  Printed in generated code
    as a call of the scene's evaluator ``profile``."""

    max_order = MAX_ORDER


class JunctionFunction(_Derivatives):
    """j^(n)(phi): the junction indicator of a cam of circular arcs (its n-th derivative), zero
    at each junction of two arcs, where the curvature jumps, and of alternating sign between
    them: (-1)^k sin(pi (phi - a_k) / (a_(k+1) - a_k)) on arc k (an even number of arcs).
    Its zeros are the automaton's surface ``junction`` (derive.automaton)."""

    max_order = 2


def junction(phi: sp.Expr) -> sp.Expr:
    """The junction indicator of a cam of arcs at the body angle phi (:class:`JunctionFunction`)."""
    return JunctionFunction(sp.Integer(0), phi)


def h(phi: sp.Expr, n: int = 0) -> sp.Expr:
    """h^(n)(phi): the support function (n = 0) or its n-th derivative."""
    return SupportFunction(sp.Integer(n), phi)


def eccentric_support(x: sp.Expr) -> sp.Expr:
    """The paper's circle: h(phi) = r_c - e cos(phi) (body axis along G_c -> E, Eq. 3)."""
    return S.r_c - S.e * sp.cos(x)


def as_eccentric(expr: sp.Expr) -> sp.Expr:
    """``expr`` with every h^(n)(phi) replaced by the derivative of :func:`eccentric_support`."""
    x = sp.Dummy("phi")
    return sp.sympify(expr).replace(
        SupportFunction, lambda n, phi: eccentric_support(x).diff(x, int(n)).subs(x, phi))


def calls(expr) -> set:
    """The distinct h^(n)(phi) calls in ``expr``."""
    return set(sp.sympify(expr).atoms(SupportFunction))


def is_constant_call(call: sp.Expr, state=(S.t_s, S.alpha_s, S.alpha_dot, S.y_s, S.y_dot, S.Theta_s, S.Theta_dot,
                                           S.Theta_ddot)) -> bool:
    """Whether a call's angle is made of parameters only (then ``pack()`` computes it once)."""
    return not call.args[1].has(*state)
