"""The quasi-static contact orbit: the contact deformation that carries the follower's inertia.

In permanent contact the follower moves with the cam up to a contact deformation of a few
1e-8 m.  The quasi-static orbit takes alpha_dot and alpha_ddot from the rigid kinematics,
alpha_i(Theta) of Eq. 29 and its Theta derivatives (``Model.rigid_coordinate``; on a cam
profile, the rocker's root of the gap):

    alpha_dot = alpha_i' Theta_dot,   alpha_ddot = alpha_i'' Theta_dot^2 + alpha_i' Theta_ddot,

and solves the contact mode's equation of motion (Eq. 10) for alpha at each time:
rhs(t, alpha, alpha_dot_i) = alpha_ddot_i, by Newton's method from alpha_i with the generated
Jacobian d alpha_ddot / d alpha (Eq. 21).  No integration: the transient of a run from rest
(which decays in the contact mode's damping time) is left out.  The contact mode is the
scene's viscous one after maximum compression (damping D, E: a follower that stays in contact
has passed t_b of Eqs. 27-28) with the friction direction of the rigid sliding velocity.

It is exact for the orbit only to the extent that the deformation's own rates are negligible
against the rigid ones.  Against the full model's converged run (``example_rig()`` with a 16 mm
line contact, damping D, Coulomb, 0.85 x the contact-loss speed, rtol 1e-10): 5.0e-13 rad at the
section, at most 3.2e-12 rad over a period, 2e-5 of the residual response max abs(alpha - alpha_i)
(the README; checked in tests/test_stopping.py).  Where F_n would turn tensile (<= 0)
the follower would leave the cam and the quasi-static orbit does not exist: the outcome says
where, and the full model must be used.
"""
from __future__ import annotations

import math
from dataclasses import dataclass

import numpy as np

from ..model.cam import CamMotion, cam_motion
from ..vocabulary import CAM_THETA, CAM_THETA_DDOT, CAM_THETA_DOT
from ..errors import ParameterError
from ..model.model import Model
from ..outcome import ActionableOutcome
from ..model.rig import Rig
from ..model.scene import Scene

#: Newton steps at most per time; the contact law is smooth and stiff, so the residual is linear
#: in alpha to a part in 1e6 of the deformation and 2-3 steps reach rounding
MAX_NEWTON = 30
#: a Newton step below this many ulps of alpha ends the iteration (rounding of alpha itself)
ULPS = 4
#: a Newton step that no longer shrinks, after one below this many ulps of alpha or below
#: NOISE_FRACTION of the contact deformation alpha - alpha_i, also ends it: the residual's own
#: rounding is reached (seen on a spline cam: steps that circle at 4-6 ulps of alpha = -0.025 rad,
#: and at 1e-11 of the deformation where alpha = 1e-4 rad, the gap's rounding being that of its
#: 0.1 m terms)
NOISE_ULPS = 1024
NOISE_FRACTION = 1e-9


class QuasiStaticOutcome(ActionableOutcome):
    """How the quasi-static orbit ended (an actionable message each)."""

    SUCCESS = "the quasi-static contact orbit holds at every time asked (F_n > 0 throughout)"
    TENSILE = ("the contact force F_n would turn tensile (<= 0): the follower leaves the cam there and the "
               "quasi-static orbit does not exist; use the full model (response='dynamic')")
    NEWTON_FAILED = ("Newton's method found no contact deformation that carries the inertia (no convergence): "
                     "the contact is too soft or the speed too high for a quasi-static contact; use the full model")


@dataclass(frozen=True)
class QuasiStaticOrbit:
    """``alpha`` (rad) at the times ``t`` (s), with ``alpha_dot`` and ``alpha_ddot`` of the rigid
    kinematics, the rigid-contact angle ``alpha_i``, the normal force ``F_n`` (N) and the mode
    (a name of the scene's MODES, and its index in ``mode_index``) at each; ``outcome`` and ``message`` (with where F_n turns
    tensile: ``t_tensile`` s and ``Theta_tensile`` rad, else NaN).  The arrays stop at the
    first time where the orbit fails."""

    t: np.ndarray
    alpha: np.ndarray
    alpha_dot: np.ndarray
    alpha_ddot: np.ndarray
    alpha_i: np.ndarray
    F_n: np.ndarray
    mode: tuple
    mode_index: np.ndarray       # the same modes as indices of MODES (int64)
    outcome: QuasiStaticOutcome
    message: str
    t_tensile: float = math.nan
    Theta_tensile: float = math.nan

    @property
    def ok(self) -> bool:
        return self.outcome.ok


def contact_mode(model: Model, t: float, alpha: float, alpha_dot: float) -> int:
    """The contact mode of a follower that stays on the cam: the viscous law of a switched
    damping (after maximum compression), sliding in the direction of v_r at this state."""
    K = model.kernels
    contact = [m for m, c in enumerate(K.CONTACT_OF_MODE) if c]
    phases = {K.PHASE_OF_MODE[m] for m in contact}
    contact = [m for m in contact if K.PHASE_OF_MODE[m] == ("viscous" if "viscous" in phases else None)]
    if all(K.SLIP_OF_MODE[m] is None for m in contact):
        return contact[0]
    v_r = model.surface(contact[0], K.SURFACE_SLIP, t, alpha, alpha_dot)
    want = "fwd" if v_r > 0 else "bwd"
    return next(m for m in contact if K.SLIP_OF_MODE[m] == want)


def rigid_kinematics(model: Model, t: float) -> tuple[float, float, float]:
    """(alpha_i, alpha_i_dot, alpha_i_ddot) at t: Eq. 29 and its Theta derivatives, chained."""
    cam = model.cam_state(t)
    theta, theta_dot, theta_ddot = (float(np.asarray(cam[i])) for i in (CAM_THETA, CAM_THETA_DOT, CAM_THETA_DDOT))
    a, da, dda = model.rigid_coordinate(theta)
    return a, da * theta_dot, dda * theta_dot ** 2 + da * theta_ddot


def solve_at(model: Model, t: float):
    """(alpha, alpha_dot, alpha_ddot, alpha_i, mode) of the quasi-static orbit at t; alpha NaN when
    Newton does not converge."""
    a_i, ad, add = rigid_kinematics(model, t)
    m = contact_mode(model, t, a_i, ad)
    alpha, last = a_i, math.inf
    for _ in range(MAX_NEWTON):
        g = model.rhs(m, t, alpha, ad) - add
        dg, _ = model.jacobian(m, t, alpha, ad)
        step = g / dg
        alpha -= step
        if not math.isfinite(alpha):
            break
        ulp = np.spacing(abs(alpha))
        noise = max(NOISE_ULPS * ulp, NOISE_FRACTION * abs(alpha - a_i))
        if abs(step) <= ULPS * ulp or (abs(step) >= abs(last) and abs(last) <= noise):
            return alpha, ad, add, a_i, m
        last = step
    return math.nan, ad, add, a_i, m


def quasi_static_orbit(rig: Rig, scene: Scene, cam: CamMotion | None = None, *, speed_rpm: float | None = None,
                       t=None) -> QuasiStaticOrbit:
    """The quasi-static contact orbit (see the module doc) at the times ``t`` (s; default 64
    per cam revolution over one revolution).  It raises only on bad input; where the orbit
    fails (F_n <= 0, or no deformation found) the outcome says when and where."""
    cam = cam_motion(cam, speed_rpm)
    model = Model(rig, scene, cam)
    if t is None:
        if not math.isfinite(model.period):
            raise ParameterError("t", t, "the times (s) for a cam without a period")
        t = model.period * np.arange(64) / 64
    t = np.atleast_1d(np.asarray(t, dtype=float))
    if t.ndim != 1 or t.size == 0 or not np.all(np.isfinite(t)):
        raise ParameterError("t", t, "a non-empty 1-D array of finite times (s)")
    return orbit_at(model, t)


def orbit_at(model: Model, t: np.ndarray) -> QuasiStaticOrbit:
    """The quasi-static orbit of a model at the times ``t`` (checked by the caller)."""
    K = model.kernels
    rows, modes = [], []
    outcome, where = QuasiStaticOutcome.SUCCESS, math.nan
    for ti in t:
        alpha, ad, add, a_i, m = solve_at(model, float(ti))
        if not math.isfinite(alpha):
            outcome, where = QuasiStaticOutcome.NEWTON_FAILED, float(ti)
            break
        F_n = model.outputs(m, float(ti), alpha, ad)["F_n"]
        if not F_n > 0:
            outcome, where = QuasiStaticOutcome.TENSILE, float(ti)
            break
        rows.append((alpha, ad, add, a_i, F_n))
        modes.append(m)
    cols = np.array(rows, dtype=float).reshape(-1, 5).T
    theta = float(np.asarray(model.cam_state(where)[CAM_THETA])) if math.isfinite(where) else math.nan
    message = outcome.message
    if not outcome.ok:
        message = (f"{outcome.message} (at t = {where:.6g} s, cam angle Theta = {theta:.6g} rad = "
                   f"{math.degrees(theta) % 360:.4g} deg mod 360)")
    tensile = outcome is QuasiStaticOutcome.TENSILE
    return QuasiStaticOrbit(t[:cols.shape[1]].copy(), *cols, tuple(K.MODES[m] for m in modes),
                            np.array(modes, dtype=np.int64), outcome, message,
                            where if tensile else math.nan, theta if tensile else math.nan)


def section_state(model: Model, phase: float) -> tuple[np.ndarray, int]:
    """(alpha, alpha_dot) of the quasi-static orbit at the section time ``phase`` and its mode:
    a warm start for shooting in permanent contact.  alpha_dot is the orbit's own rate (central
    difference over 1e-4 T, whose truncation error ~1e-8 of the deformation rate is below the
    shooting tolerance), not the rigid one."""
    h = 1e-4 * model.period
    alpha, _, _, _, m = solve_at(model, phase)
    ahead, behind = solve_at(model, phase + h)[0], solve_at(model, phase - h)[0]
    return np.array([alpha, (ahead - behind) / (2 * h)]), m


__all__ = ["quasi_static_orbit", "QuasiStaticOrbit", "QuasiStaticOutcome", "orbit_at", "solve_at",
           "rigid_kinematics", "contact_mode", "section_state"]
