"""Kinematics, forces and equations of motion of the follower (Sections 3.1-3.2, 7.2).

The equation of motion is the moment balance about the pivot P of the force
vectors acting on the follower (Eqs. 10 and 15 follow from it, not the other
way round): the spring force at horizontal distance d_x, the normal contact
force -F_n n and the friction force at O_b.  The friction force opposes the
sliding velocity of the follower's material point relative to the cam's.
"""
from __future__ import annotations

from dataclasses import dataclass
from functools import lru_cache
from types import SimpleNamespace

import sympy as sp
from sympy.physics.vector import Point, Vector

from . import laws, translating
from camdyn import vocabulary
from . import symbols as S
from .profile import as_eccentric
from .graph import Definition, flatten, quantity, substitutions
from .geometry import (N, E_to_Gc, E_to_Oc_general, P_to_Ob, curvature_radius, follower_frame, psi_i_conditioned,
                       psi_i_general, psi_j_conditioned, psi_j_general)
from .profile import h
from .symbols import Theta, alpha, t

B = follower_frame(alpha)
SLIDING_VELOCITY_FORMS = vocabulary.SLIDING_VELOCITY_FORMS


ECCENTRIC = vocabulary.ECCENTRIC  # the paper's cam
OSCILLATING, TRANSLATING = vocabulary.FOLLOWERS  # the paper's rocker (Fig. 1); a flat face on a guide


def _on_cam(profile: str, expr: sp.Expr) -> sp.Expr:
    """A translating follower's expression, written with the support function h, on the scene's cam:
    the paper's circle as its support function (derive.profile.eccentric_support), any other cam
    through its evaluator."""
    return as_eccentric(expr) if profile == ECCENTRIC else expr


@lru_cache(maxsize=None)
def gap(profile: str = ECCENTRIC, follower: str = OSCILLATING) -> sp.Expr:
    """psi_i(alpha(t), Theta(t)) (Eq. 6, cancellation-free form); for a cam other than the
    paper's circle, through its support function (geometry.psi_i_general); for the translating
    follower y(t) - h(gamma - Theta(t)) (derive.translating)."""
    if follower == TRANSLATING:
        return _on_cam(profile, translating.gap())
    return (psi_i_conditioned if profile == ECCENTRIC else psi_i_general)(alpha, Theta)


@lru_cache(maxsize=None)
def psi_j(profile: str = ECCENTRIC, follower: str = OSCILLATING) -> sp.Expr:
    """psi_j (Eq. 7), or geometry.psi_j_general for any other cam; the translating follower's
    sliding of the contact along its face (derive.translating.psi_j)."""
    if follower == TRANSLATING:
        return _on_cam(profile, translating.psi_j())
    return (psi_j_conditioned if profile == ECCENTRIC else psi_j_general)(alpha, Theta)


def chi(profile: str = ECCENTRIC) -> sp.Expr:
    """chi = chi0 - psi_j: the contact's distance from P along the bar (Eq. 2)."""
    return S.chi0 - psi_j(profile)


@lru_cache(maxsize=None)
def gap_rate(profile: str = ECCENTRIC, follower: str = OSCILLATING) -> sp.Expr:
    """psi_i_dot (Eq. 8), the time derivative of the gap."""
    return gap(profile, follower).diff(t)


@lru_cache(maxsize=None)
def psi_j_rate(profile: str = ECCENTRIC) -> sp.Expr:
    """psi_j_dot (Eq. 9)."""
    return psi_j(profile).diff(t)


def curvature_radius_at_contact(profile: str, follower: str) -> sp.Expr:
    """rho = h + h'' at the contact's body angle (the Hertz radius of a point contact on any cam)."""
    if follower == TRANSLATING:
        phi = translating.phi_contact()
        return h(phi) + h(phi, 2)
    return curvature_radius()


def material_point_velocities(profile: str = ECCENTRIC) -> tuple[Vector, Vector]:
    """Velocities of the follower's and the cam's material points at the contact.

    The follower turns about the fixed P at -alpha_dot (clockwise); the cam
    about the fixed E at Theta_dot.  The cam's point is on its surface,
    O_c = G_c - r_c n (any cam: E + h' u - h n); the follower's is O_b on the bar's surface.
    """
    P, E = Point("P"), Point("E")
    P.set_vel(N, 0)
    E.set_vel(N, 0)
    Ob = P.locatenew("O_b", P_to_Ob(B, chi(profile)))
    Oc = E.locatenew("O_c", E_to_Gc(Theta) - S.r_c * B.y if profile == ECCENTRIC else E_to_Oc_general(B))
    follower = N.orientnew("follower_body", "Axis", (-alpha, N.z))
    cam = N.orientnew("cam_body", "Axis", (Theta, N.z))
    v_b = Ob.v2pt_theory(P, N, follower)
    v_c = Oc.v2pt_theory(E, N, cam)
    return v_b, v_c


@lru_cache(maxsize=None)
def sliding_velocity(form: str = "kinematic", profile: str = ECCENTRIC, follower: str = OSCILLATING) -> sp.Expr:
    """v_r, the velocity of the follower relative to the cam along the bar (u).

    "kinematic": from the material points' velocities (rigid-body kinematics).
    "printed":   the paper's v_r = psi_j_dot - (r_c + e sin(alpha+Theta))(alpha_dot + Theta_dot),
                 which counts the e sin(alpha+Theta) term twice (misprint 8); kept so
                 Figs. 12-15 can be reproduced.  The sign convention is the paper's:
                 v_r > 0 for a cam turning clockwise (self-energizing).
    """
    if follower == TRANSLATING and form == "kinematic":
        return _on_cam(profile, translating.sliding_velocity())
    if form == "kinematic":
        v_b, v_c = material_point_velocities(profile)
        return sp.simplify((v_b - v_c).dot(B.x))
    if form == "printed" and profile == ECCENTRIC:
        return psi_j_rate() - (S.r_c + S.e * sp.sin(alpha + Theta)) * (alpha.diff(t) + Theta.diff(t))
    raise ValueError(f"sliding velocity form {form!r} is not one of {SLIDING_VELOCITY_FORMS}")


@dataclass(frozen=True)
class ContactRegime:
    """The physics of one contact regime: which laws, which discrete phase and direction."""

    contact: str = "line"            # "line" | "point"
    damping: str = "none"            # "none" | "A".."E"
    phase: str = "loading"           # D/E only: "loading" | "unloading"
    friction: str = "none"           # "none" | "coulomb" | "tanh"
    direction: int = 0               # Coulomb only: sign of v_r, +1 | -1
    damping_sign: str = "dissipative"
    sliding_velocity: str = "kinematic"
    profile: str = ECCENTRIC        # the cam: vocabulary.PROFILES
    follower: str = OSCILLATING     # the follower: vocabulary.FOLLOWERS


@dataclass(frozen=True)
class Forces:
    """Force magnitudes on the follower, as functions of alpha(t), Theta(t)."""

    F_s: sp.Expr   # spring (Eq. 11)
    F_n: sp.Expr   # normal contact force (Eq. 12), positive when pressing
    F_f: sp.Expr   # friction force, F_f = mu F_n
    v_r: sp.Expr   # sliding velocity used by the friction law


#: Symbols of the named quantities of the contact mechanics (as they appear in generated code).
Q = SimpleNamespace(**{name: quantity(name) for name in (
    "psi_i", "psi_i_dot", "psi_j", "chi", "F_s", "rho", "k_lambda", "c_lambda", "F_n", "v_r", "mu", "F_f",
    "alpha_ddot")})


def spring_force(follower: str = OSCILLATING, profile: str = ECCENTRIC) -> sp.Expr:
    """F_s: Eq. 11 at alpha(t), or the translating follower's F_p + k_s (y - y0) (derive.translating,
    y0 on the scene's cam)."""
    if follower == TRANSLATING:
        return _on_cam(profile, translating.spring_force())
    return laws.spring_force(alpha)


def contact_mass(follower: str = OSCILLATING) -> sp.Expr:
    """The follower's inertia reduced to the contact, the mass of the viscous damping laws: I_Pb / chi*^2
    (Eq. 24), or the translating follower's mass m_f (its contact moves with it, arm 1)."""
    return S.m_f if follower == TRANSLATING else S.I_Pb / S.chi_star**2


def _contact_geometry(regime: ContactRegime) -> list[Definition]:
    """The gap and its rate (Eqs. 6, 8), psi_j (Eq. 7) and, for the rocker, the moment arm chi (Eq. 2)."""
    profile, follower = regime.profile, regime.follower
    defs = [Definition(Q.psi_i, gap(profile, follower), "gap (Eq. 6); contact deflection where negative"),
            Definition(Q.psi_i_dot, gap_rate(profile, follower), "gap rate (Eq. 8)"),
            Definition(Q.psi_j, psi_j(profile, follower), "sliding of the contact point along the "
                       + ("bar (Eq. 7)" if follower == OSCILLATING else "face"))]
    if follower == OSCILLATING:
        defs.append(Definition(Q.chi, S.chi0 - Q.psi_j, "moment arm of F_n about P (Eq. 2)"))
    return defs


@lru_cache(maxsize=None)  # pure (ContactRegime is frozen), shared by the scenes of a regime
def mechanics(regime: ContactRegime | None, follower: str = OSCILLATING, profile: str = ECCENTRIC
              ) -> tuple[Definition, ...]:
    """The named quantities of one mode, in the order they are computed: the gap and its rate
    (Eqs. 6, 8), psi_j and the moment arm chi (Eqs. 7, 2), the spring force (Eq. 11), the
    contact stiffness and damping (Eqs. 13/34, 24-28), the normal force (Eq. 12), the sliding
    velocity, the friction coefficient and force.  With no contact (``regime=None``, Eq. 15)
    only the spring acts (of ``follower`` on the cam ``profile``; in contact the regime's).  Expressions
    are in alpha(t) (the translating follower's y(t)), Theta(t) and earlier quantities."""
    if regime is not None:
        follower, profile = regime.follower, regime.profile
    F_s = Definition(Q.F_s, spring_force(follower, profile), "spring force (Eq. 11)")
    if regime is None:
        return (F_s,)
    defs = _contact_geometry(regime) + [F_s]
    if _radius(regime) is Q.rho:
        defs.append(Definition(Q.rho, curvature_radius_at_contact(profile, follower),
                               "the cam's radius of curvature at the contact, h + h''"))
    defs += [Definition(Q.k_lambda, laws.contact_stiffness(regime.contact, Q.psi_i, _radius(regime)),
                        "contact stiffness (Eq. 13 line, Eq. 34 point)"),
            Definition(Q.c_lambda, laws.damping_coefficient(regime.damping, regime.phase, _stiffness(regime), Q.psi_i,
                                                            regime.damping_sign, contact_mass(follower)),
                       f"contact damping, model {regime.damping} (Eqs. 24-28)"),
             Definition(Q.F_n, laws.elastic_force(regime.contact, Q.psi_i, Q.k_lambda, _radius(regime))
                        - Q.c_lambda * Q.psi_i_dot, "normal contact force (Eq. 12)")]
    if regime.friction != "none":
        defs += [Definition(Q.v_r, sliding_velocity(regime.sliding_velocity, profile, follower),
                            f"sliding velocity ({regime.sliding_velocity} form)"),
                 Definition(Q.mu, laws.friction_coefficient(regime.friction, Q.v_r, regime.direction),
                            f"friction coefficient ({regime.friction})"),
                 Definition(Q.F_f, Q.mu * Q.F_n, "friction force")]
    return tuple(defs)


def _stiffness(regime: ContactRegime) -> sp.Expr:
    """k_lambda as the damping laws of models B and D read it: the named quantity where it is
    smooth (line contact: a constant); for point contact its law in psi_i itself, because
    k ~ |psi_i|^0.5 has no derivative at psi_i = 0 while beta k |psi_i| ~ |psi_i|^1.5 does, and
    the chain rule through the named k would give 0 * inf there (Jacobians, by forward mode)."""
    if regime.contact == "line":
        return Q.k_lambda
    return laws.contact_stiffness(regime.contact, Q.psi_i, _radius(regime))


def _radius(regime: ContactRegime) -> sp.Expr:
    """The Hertz radius of a point contact: r_c on the paper's circle, the named rho = h + h''
    on any other cam (None for line contact, whose stiffness has no radius, Eq. 13)."""
    if regime.contact != "point":
        return None
    return S.r_c if regime.profile == ECCENTRIC else Q.rho


def named_forces(regime: ContactRegime | None) -> Forces:
    """The forces as the symbols of :func:`mechanics` (zero where a mode has none)."""
    zero = sp.Integer(0)
    if regime is None:
        return Forces(Q.F_s, zero, zero, zero)
    friction = regime.friction != "none"
    return Forces(Q.F_s, Q.F_n, Q.F_f if friction else zero, Q.v_r if friction else zero)


@lru_cache(maxsize=None)  # pure (ContactRegime is frozen): a trigsimp, shared by the scenes of a regime
def acceleration(regime: ContactRegime | None, follower: str = OSCILLATING) -> Definition:
    """alpha_ddot from I_Pb alpha_ddot = M_P (Eq. 10 in contact, Eq. 15 free), in the named forces;
    the translating follower's y_ddot from m_f y_ddot = the applied forces along its guide."""
    follower = regime.follower if regime is not None else follower
    if follower == TRANSLATING:
        f = named_forces(regime)
        return Definition(S.COORDINATES[TRANSLATING].acceleration, translating.force_along_guide(f.F_s, f.F_n, f.F_f)
                          / S.m_f, "acceleration along the guide (m_f y_ddot = F_n - F_s)" if regime else
                          "acceleration along the guide, no contact (m_f y_ddot = -F_s)")
    chi_ = S.chi0 if regime is None else Q.chi  # no normal force in free flight: chi does not enter
    moment = sp.expand(sp.trigsimp(moment_about_P(named_forces(regime), chi_)))
    return Definition(Q.alpha_ddot, moment / S.I_Pb,
                      "angular acceleration (Eq. 10)" if regime else "angular acceleration (Eq. 15)")


def forces(regime: ContactRegime | None, follower: str = OSCILLATING, profile: str = ECCENTRIC) -> Forces:
    """Forces in a contact regime, or with no contact (``regime=None``, Eq. 15), as functions
    of alpha(t), Theta(t): :func:`mechanics` with every quantity substituted."""
    flat = substitutions(mechanics(regime, follower, profile))
    zero = sp.Integer(0)
    follower = regime.follower if regime is not None else follower
    kinematic = sliding_velocity("kinematic", ECCENTRIC if regime is None else regime.profile, follower)
    return Forces(flat[Q.F_s], flat.get(Q.F_n, zero), flat.get(Q.F_f, zero), flat.get(Q.v_r, kinematic))


def applied_forces(f: Forces, chi_: sp.Expr | None = None, profile: str = ECCENTRIC) -> list[tuple[Vector, Vector]]:
    """(point relative to P, force vector on the follower) pairs.

    Spring: vertical, at horizontal distance d_x (Eq. 11 acts as a vertical force).
    Normal force: -F_n n at O_b (the cam pushes the bar away from itself).
    Friction: -F_f u at O_b, opposing the follower's sliding velocity v_r u
    relative to the cam (F_f = mu F_n with mu of the sign of v_r).
    """
    r_Ob = P_to_Ob(B, chi(profile) if chi_ is None else chi_)
    r_spring = S.d_x * N.x + (-S.d_x * sp.tan(alpha)) * N.y
    return [
        (r_spring, f.F_s * N.y),
        (r_Ob, -f.F_n * B.y),
        (r_Ob, -f.F_f * B.x),
    ]


def moment_about_P(f: Forces, chi_: sp.Expr | None = None, profile: str = ECCENTRIC) -> sp.Expr:
    """Clockwise moment about P of the applied forces (alpha is clockwise); ``chi_`` the moment
    arm of the contact forces (default: chi0 - psi_j of the profile's cam, Eq. 2)."""
    total = sum((r.cross(F) for r, F in applied_forces(f, chi_, profile)), Vector(0))
    return -total.dot(N.z)


def bearing_force_x(f: Forces, follower: str = OSCILLATING) -> sp.Expr:
    """N_x (Eq. 35): horizontal force of the bearing at P on the follower.

    The follower's centre of gravity P is fixed, so the bearing balances the
    horizontal components of the applied forces.  The translating follower: the guide's
    reaction across itself (derive.translating.guide_force).
    """
    if follower == TRANSLATING:
        return translating.guide_force(f.F_s, f.F_n, f.F_f)
    total = sum((F for _, F in applied_forces(f)), Vector(0))
    return -total.dot(N.x)


def angular_acceleration(regime: ContactRegime | None) -> sp.Expr:
    """alpha_ddot from I_Pb alpha_ddot = M_P (Eq. 10 in contact, Eq. 15 free), in alpha(t), Theta(t)."""
    return flatten(acceleration(regime).expr, mechanics(regime))
