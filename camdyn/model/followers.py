"""Flat-faced followers on a cam profile, and their rigid-contact inverse kinematics (issue 27).

Conventions (the derivation's): the fixed frame has its origin at the cam's rotation centre E; the
cam's body x axis is at the cam angle Theta (counter-clockwise); a fixed-frame direction at the angle
beta has the body angle phi = beta - Theta (:mod:`camdyn.model.profiles`).

- :class:`TranslatingFollower`: a face normal to a guide along g = (cos gamma, sin gamma), facing
  the cam; its coordinate y is the face's distance from E along g. The cam's outward normal at
  the contact is g, so phi = gamma - Theta and the gap is psi = y - h(phi).
- :class:`OscillatingFollower` (the paper's, Fig. 1): pivot P, bar direction
  u_b = (cos a, -sin a) (a = alpha, clockwise), n = (sin a, cos a) from the face towards the cam,
  face {P + chi u_b + (w_b/2) n}. The cam's outward normal at the contact is -n, so
  phi = 3 pi/2 - a - Theta and the gap is psi_i = (E - P).n - w_b/2 - h(phi); the moment arm is
  chi = (R(Theta) c(phi) + (E - P)).u_b = (E - P).u_b + h'(phi).

:func:`rigid_contact` solves psi = 0 for the follower coordinate at given cam angles, with its
first and second time derivatives at a constant cam speed: pure numpy, for checks.
"""
from __future__ import annotations

import math
from dataclasses import dataclass
from typing import NamedTuple

import numpy as np

from .._checks import finite
from ..errors import GeometryError, ParameterError

__all__ = ["TranslatingFollower", "OscillatingFollower", "RigidContact", "rigid_contact", "follower_of_rig",
           "rig_on_cam"]


@dataclass(frozen=True)
class TranslatingFollower:
    """A translating flat-faced follower: guide at the fixed-frame angle ``gamma`` (rad; pi/2: the
    follower above the cam), its axis ``offset`` (m) from E along the face's unit
    t = (sin gamma, -cos gamma) (for gamma = pi/2, t is +x). The offset does not change the lift,
    only where on the face the contact sits."""

    gamma: float = math.pi / 2
    offset: float = 0.0
    kind = "translating"

    def __post_init__(self):
        finite("gamma", self.gamma, "a finite guide angle, rad")
        finite("offset", self.offset, "a finite axis offset, m")

    @property
    def along_face(self) -> np.ndarray:
        return np.array([math.sin(self.gamma), -math.cos(self.gamma)])

    def contact_angle(self, q, Theta) -> np.ndarray:
        """phi = gamma - Theta (body angle of the contact normal)."""
        return self.gamma - np.asarray(Theta, float) + 0.0 * np.asarray(q, float)

    def gap(self, profile, q, Theta) -> np.ndarray:
        """psi = y - h(gamma - Theta) (m; < 0 in penetration)."""
        return np.asarray(q, float) - profile.h(self.contact_angle(q, Theta))


@dataclass(frozen=True)
class OscillatingFollower:
    """The paper's oscillating flat-faced follower: ``P_to_E`` = E - P (m, fixed frame), bar width
    ``w_b`` (m; the face is w_b/2 off the bar's axis, towards the cam)."""

    P_to_E: tuple[float, float]
    w_b: float
    kind = "oscillating"

    def __post_init__(self):
        try:
            x, y = self.P_to_E
        except (TypeError, ValueError):
            raise ParameterError("P_to_E", self.P_to_E, "a vector (x, y) from the pivot P to E, m") from None
        x, y = finite("P_to_E", x, "a finite vector, m"), finite("P_to_E", y, "a finite vector, m")
        if not math.hypot(x, y) > 0:
            raise ParameterError("P_to_E", (x, y), "a nonzero vector from the pivot P to E, m")
        object.__setattr__(self, "P_to_E", (x, y))
        w_b = finite("w_b", self.w_b, "a finite bar width >= 0, m")
        if w_b < 0:
            raise ParameterError("w_b", w_b, ">= 0 m (follower bar width)")

    def projections(self, a) -> tuple[np.ndarray, np.ndarray]:
        """(E - P).n(a) and (E - P).u_b(a)."""
        a = np.asarray(a, float)
        x, y = self.P_to_E
        return x * np.sin(a) + y * np.cos(a), x * np.cos(a) - y * np.sin(a)

    def base_angle(self, r_b: float) -> float:
        """The follower angle a on a circle of radius ``r_b`` about E: (E - P).n(a) - w_b/2 = r_b on
        the branch with the contact on the bar (chi = (E - P).u_b > 0), as Eq. 29's principal arcsine."""
        x, y = self.P_to_E
        reach = r_b + self.w_b / 2
        if not reach < math.hypot(x, y):
            raise ParameterError("r_b", r_b, f"< |E - P| - w_b/2 = {math.hypot(x, y) - self.w_b / 2!r} m",
                                 reason="a base circle the follower reaches")
        return math.asin(reach / math.hypot(x, y)) - math.atan2(y, x)

    def contact_angle(self, q, Theta) -> np.ndarray:
        """phi = 3 pi/2 - a - Theta (body angle of the contact normal -n)."""
        return 1.5 * math.pi - np.asarray(q, float) - np.asarray(Theta, float)

    def gap(self, profile, q, Theta) -> np.ndarray:
        """psi_i = (E - P).n - w_b/2 - h(phi) (m; < 0 in penetration)."""
        return self.projections(q)[0] - self.w_b / 2 - profile.h(self.contact_angle(q, Theta))


class RigidContact(NamedTuple):
    """The follower in rigid contact at cam angles Theta turning at the constant speed omega:
    its coordinate q (y in m, or a in rad), q_dot, q_ddot, the contact's body angle phi, and where
    the contact sits on the face (translating: from the guide's axis along the face's unit t;
    oscillating: the moment arm chi from P along the bar), m."""

    q: np.ndarray
    q_dot: np.ndarray
    q_ddot: np.ndarray
    phi: np.ndarray
    on_face: np.ndarray


def rigid_contact(profile, follower, Theta, omega: float = 1.0) -> RigidContact:
    """Solve the rigid contact (gap 0) for the follower coordinate at the cam angles ``Theta``
    (rad), and its time derivatives at the constant cam speed ``omega`` (rad/s).

    Translating: y = h(gamma - Theta), y' = -h', y'' = h'' (per rad of Theta). Oscillating: the
    root of F(a, Theta) = (E - P).n(a) - w_b/2 - h(3 pi/2 - a - Theta), whose a-derivative is the
    moment arm chi > 0; then a' = -F_Theta / F_a = -h'/chi and
    a'' = -(F_aa a'^2 + 2 F_aTheta a' + F_ThetaTheta)/chi with F_aa = -(E - P).n - h'',
    F_aTheta = F_ThetaTheta = -h''."""
    Theta = np.asarray(Theta, float)
    omega = finite("omega", omega, "a finite cam speed, rad/s")
    if follower.kind == "translating":
        phi = follower.gamma - Theta
        q, q1, q2 = profile.h(phi), -profile.h(phi, 1), profile.h(phi, 2)
        R = _rotation(Theta)
        on_face = np.einsum("...ij,...j->...i", R, profile.contact_point(phi)) @ follower.along_face - follower.offset
        return RigidContact(q, omega * q1, omega ** 2 * q2, phi, on_face)
    a = _oscillating_root(profile, follower, Theta)
    phi = follower.contact_angle(a, Theta)
    Dn, Du = follower.projections(a)
    h1, h2 = profile.h(phi, 1), profile.h(phi, 2)
    chi = Du + h1
    a1 = -h1 / chi
    a2 = -((-Dn - h2) * a1 ** 2 - 2 * h2 * a1 - h2) / chi
    return RigidContact(a, omega * a1, omega ** 2 * a2, phi, chi)


def _rotation(Theta: np.ndarray) -> np.ndarray:
    c, s = np.cos(Theta), np.sin(Theta)
    return np.stack([np.stack([c, -s], -1), np.stack([s, c], -1)], -2)


def _oscillating_root(profile, follower: OscillatingFollower, Theta: np.ndarray, iterations: int = 60) -> np.ndarray:
    """a with F(a, Theta) = 0 on the branch chi > 0: a fixed-point start on the principal arcsine
    (a = asin((h + w_b/2)/|E - P|) - atan2(y, x), contracting while |h'| < chi), then Newton's
    method with F_a = chi until the step is below 4 ulp of pi."""
    x, y = follower.P_to_E
    length, tilt = math.hypot(x, y), math.atan2(y, x)
    a = np.full(Theta.shape, follower.base_angle(float(np.min(profile.h(np.linspace(0, 2 * math.pi, 64))))))
    for _ in range(8):
        reach = profile.h(follower.contact_angle(a, Theta)) + follower.w_b / 2
        a = np.arcsin(np.clip(reach / length, -1, 1)) - tilt
    for _ in range(iterations):
        F = follower.gap(profile, a, Theta)
        chi = follower.projections(a)[1] + profile.h(follower.contact_angle(a, Theta), 1)
        if not np.all(chi > 0):
            raise GeometryError("rigid contact: the contact left the bar (chi <= 0) while solving for the "
                                "follower angle")
        step = F / chi
        a = a - step
        if np.all(np.abs(step) <= 4 * np.finfo(float).eps * math.pi):
            return a
    raise GeometryError(f"rigid contact: Newton's method did not converge in {iterations} steps "
                        f"(largest step {np.max(np.abs(step)):.3g} rad)")


def cam_of(rig):
    """The rig's cam: its profile, or the paper's circle (r_c, e)."""
    from .profiles import EccentricCircle
    return rig.profile if rig.profile is not None else EccentricCircle(rig.r_c, rig.e)


def follower_of_rig(rig) -> OscillatingFollower | TranslatingFollower:
    """The rig's follower.  Oscillating: E - P from its 0-state (Eq. 5 for any cam: the bar's surface
    touches the cam's support line of normal angle phi0 = 3 pi/2 - alpha0 - theta0 at chi0, so
    E - P = (chi0 - h'(phi0)) u0 + (w_b/2 + h(phi0)) n0; derive.geometry.P_to_E_general).
    Translating: its guide's angle gamma and axis offset (the rig's)."""
    if rig.follower == TranslatingFollower.kind:
        return TranslatingFollower(rig.gamma, rig.offset)
    cam, a0 = cam_of(rig), rig.alpha0
    phi0 = 1.5 * math.pi - a0 - rig.theta0
    along, across = rig.chi0 - float(cam.h(phi0, 1)), rig.w_b / 2 + float(cam.h(phi0))
    u0, n0 = (math.cos(a0), -math.sin(a0)), (math.sin(a0), math.cos(a0))
    return OscillatingFollower((along * u0[0] + across * n0[0], along * u0[1] + across * n0[1]), rig.w_b)


def rig_on_cam(rig, profile, *, follower: OscillatingFollower | None = None, theta0: float | None = None):
    """``rig`` with the cam ``profile`` (:mod:`camdyn.model.profiles`), its pivot where ``follower``
    puts it (default: where it is on the rig's present cam, :func:`follower_of_rig`), and its
    0-state (Eq. 5) re-stated on the new cam: at the cam angle ``theta0`` (default the rig's) the
    follower in rigid contact, alpha0 its angle and chi0 its moment arm there.  A translating
    follower keeps its guide; its 0-state is y0 = h(gamma - theta0) on the new cam, where its
    preload F_p is given."""
    theta0 = rig.theta0 if theta0 is None else finite("theta0", theta0, "a finite cam angle, rad")
    if rig.follower == TranslatingFollower.kind:
        if follower is not None:
            raise ParameterError("follower", follower, "None for a translating follower's rig (its guide is the rig's "
                                 "gamma and offset)")
        return rig.replace(profile=profile, theta0=theta0)
    follower = follower or follower_of_rig(rig)
    contact = rigid_contact(profile, follower, np.array([theta0]))
    return rig.replace(profile=profile, theta0=theta0, alpha0=float(contact.q[0]), chi0=float(contact.on_face[0]))
