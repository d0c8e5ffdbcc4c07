"""The translating flat-faced follower: its geometry, its sliding velocity and its equation of motion
(issue 27; the scene option ``follower="translating"``).

The follower is a flat face normal to a straight guide, of mass m_f, pressed onto the cam by a
spring along the guide.  Frames: ``N`` is the fixed frame with its origin at the cam's rotation
centre E (derive.geometry); ``G`` is the guide's frame, turned by gamma counter-clockwise:

    g = G.x = (cos gamma, sin gamma)     along the guide, away from the cam,
    G.y = (-sin gamma, cos gamma).

The coordinate y is the face's distance from E along g.  The cam's outward normal at the contact
is g, so the contact's body angle is phi = gamma - Theta (derive.profile's conventions) and the
cam's contact point is E + h(phi) g + h'(phi) G.y.  Nothing below is transcribed: the gap, the
relative velocity and the force along the guide are projections of these vectors.

The face's unit along it is t = -G.y = (sin gamma, -cos gamma), and the guide's axis passes through
E + offset t (camdyn.model.followers.TranslatingFollower uses the same t and offset); the contact
sits at (E->O_c) . t - offset = -h'(phi) - offset from the axis.

The spring: F_s = F_p + k_s (y - y0), with y0 = h(gamma - theta0) the face's position in the
0-state (the follower just touching the cam at theta0) and F_p the preload there; it acts on the
follower as -F_s g.  The guide is ideal: it takes every force across it, so the friction on the
face (along t) does no work on y, and the equation of motion is m_f y_ddot = F_n - F_s.
"""
from __future__ import annotations

import sympy as sp
from sympy.physics.vector import Point, Vector

from . import symbols as S
from .geometry import N
from .profile import h
from .symbols import Theta, t, y

#: the guide's frame: G.x = g along the guide (away from the cam), G.y its normal
G = N.orientnew("G", "Axis", (S.gamma, N.z))
#: the face's unit along it, t = -G.y (the runtime's TranslatingFollower.along_face)
FACE = -G.y


def phi_contact(cam_angle: sp.Expr = Theta) -> sp.Expr:
    """The body angle of the cam's outward normal g at the contact: phi = gamma - Theta."""
    return S.gamma - cam_angle


def E_to_Oc(cam_angle: sp.Expr = Theta) -> Vector:
    """The cam's contact point from E: R(Theta) c(phi) = h(phi) g + h'(phi) G.y (derive.profile)."""
    phi = phi_contact(cam_angle)
    return h(phi) * G.x + h(phi, 1) * G.y


def y0() -> sp.Expr:
    """The face's position in the 0-state: in rigid contact at theta0, y0 = h(gamma - theta0)."""
    return h(phi_contact(S.theta0))


def gap(coordinate: sp.Expr = y, cam_angle: sp.Expr = Theta) -> sp.Expr:
    """psi_i: the face's distance from the cam's support line of normal g, (E->O_b - E->O_c) . g
    with O_b on the face (E->O_b . g = y): y - h(phi).  Negative: the contact deflection."""
    return sp.expand((coordinate * G.x - E_to_Oc(cam_angle)).dot(G.x))


def on_face(cam_angle: sp.Expr = Theta) -> sp.Expr:
    """Where the contact sits on the face, from the guide's axis along t: (E->O_c) . t - offset."""
    return sp.expand(E_to_Oc(cam_angle).dot(FACE)) - S.offset


def psi_j(cam_angle: sp.Expr = Theta) -> sp.Expr:
    """The contact's sliding along the face from its 0-state position (on_face(theta0) - on_face(Theta),
    as the oscillating follower's psi_j = chi0 - chi, Eq. 7)."""
    return on_face(S.theta0) - on_face(cam_angle)


def material_point_velocities() -> tuple[Vector, Vector]:
    """The velocities of the follower's and the cam's material points at the contact: the follower
    translates along g at y_dot; the cam turns about the fixed E at Theta_dot."""
    E = Point("E")
    E.set_vel(N, 0)
    cam = N.orientnew("cam_body", "Axis", (Theta, N.z))
    Oc = E.locatenew("O_c", E_to_Oc())
    v_c = Oc.v2pt_theory(E, N, cam)
    v_b = y.diff(t) * G.x
    return v_b, v_c


def sliding_velocity() -> sp.Expr:
    """v_r: the follower's material point relative to the cam's, along the face's unit t."""
    v_b, v_c = material_point_velocities()
    return sp.simplify((v_b - v_c).dot(FACE))


def spring_force(coordinate: sp.Expr = y) -> sp.Expr:
    """F_s = F_p + k_s (y - y0): the spring's push on the follower towards the cam (along -g)."""
    return S.F_p + S.k_s * (coordinate - y0())


def spring_potential(coordinate: sp.Expr) -> sp.Expr:
    """V_s(y) = F_p (y - y0) + k_s (y - y0)^2 / 2, zero in the 0-state: its derivative is F_s."""
    d = coordinate - y0()
    return S.F_p * d + S.k_s * d**2 / 2


def applied_forces(F_s: sp.Expr, F_n: sp.Expr, F_f: sp.Expr) -> Vector:
    """The forces on the follower besides the guide's: the spring -F_s g, the normal force F_n g
    (the cam pushes the face away) and the friction -F_f t, opposing the sliding velocity v_r t."""
    return -F_s * G.x + F_n * G.x - F_f * FACE


def force_along_guide(F_s: sp.Expr, F_n: sp.Expr, F_f: sp.Expr) -> sp.Expr:
    """The applied forces' component along the guide, m_f y_ddot (the guide takes the rest)."""
    return sp.expand(applied_forces(F_s, F_n, F_f).dot(G.x))


def guide_force(F_s: sp.Expr, F_n: sp.Expr, F_f: sp.Expr) -> sp.Expr:
    """The guide's reaction across itself (along t) that balances the applied forces there."""
    return -sp.expand(applied_forces(F_s, F_n, F_f).dot(FACE))


def rigid_coordinate(cam_angle: sp.Expr = Theta) -> sp.Expr:
    """y_i: the follower in rigid contact (psi_i = 0), y = h(gamma - Theta) (the lift law)."""
    return h(phi_contact(cam_angle))
