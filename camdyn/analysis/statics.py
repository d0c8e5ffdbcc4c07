"""Analyses of Sections 3.3-6: equilibrium, natural frequency, rigid-contact angle,
contact loss by inverse kinematics, the energy balance, residual-response statistics."""
from __future__ import annotations

import math
from dataclasses import dataclass

import numpy as np
from scipy.optimize import brentq

from . import signal
from ..model.cam import RPM, CamMotion, ConstantSpeed
from ..model.followers import follower_of_rig, rigid_contact
from ..errors import GeometryError, ParameterError
from ..model.model import ANGLE_LIMIT, Equilibrium, Model, solve_equilibrium, static_parameters
from ..runs.result import Result
from ..model.rig import Rig
from ..model.scene import Scene
from ..vocabulary import ECCENTRIC


def _static_scene(contact: str, rig: Rig | None = None) -> Scene:
    """The undamped, frictionless scene of a contact law on the rig's cam family."""
    if contact not in ("line", "point"):
        raise ParameterError("contact", contact, "'line' or 'point'")
    profile = ECCENTRIC if rig is None or rig.profile_data is None else rig.profile_data[0]
    follower = "oscillating" if rig is None else rig.follower
    return Scene(contact=contact, damping="none", friction="none", profile=profile, follower=follower)


def rigid_kinematics(rig: Rig, theta) -> tuple[np.ndarray, np.ndarray, np.ndarray]:
    """(alpha_i, alpha_i'', F_s d_x) at the cam angles ``theta``: the follower angle in rigid
    contact, its second derivative in Theta (1/rad) and the spring's moment there (N m).  The
    paper's circle: Eq. 29's closed form (the generated ``rigid_contact``, after the reach check);
    any other cam: the root of the gap (camdyn.model.followers.rigid_contact, Newton) and the
    generated ``spring_moment``.  The translating follower on any cam: (y_i, y_i'', F_s), with
    y_i = h(gamma - Theta) in closed form (the generated ``rigid_contact``; m, m/rad^2, N)."""
    theta = np.atleast_1d(np.asarray(theta, dtype=float))
    K = _static_scene("line", rig).kernels()
    p = static_parameters(rig, K)
    if rig.follower == "translating":
        y_i, _, curvature, spring_force = _closed_form(K.rigid_contact, theta, p, rig.profile is None)
        return y_i, curvature, spring_force
    if rig.profile is None:
        if np.any(_closed_form(K.reach, theta, p, True)[0] <= 0):
            raise GeometryError("the follower cannot reach the cam at some cam angle (|PG_c| < r_c + w_b/2)")
        alpha_i, _, curvature, spring_moment = _closed_form(K.rigid_contact, theta, p, True)
        return alpha_i, curvature, spring_moment
    contact = rigid_contact(rig.profile, follower_of_rig(rig), theta)
    spring_moment = np.array([K.spring_moment(a, p) for a in contact.q])
    return contact.q, contact.q_ddot, spring_moment


def _closed_form(kernel, theta: np.ndarray, p: np.ndarray, closed: bool) -> np.ndarray:
    """The generated ``kernel(Theta, p)``'s results (rows) at the cam angles ``theta``: on the
    whole array at once where the kernel is a closed form (``closed``: a circular cam,
    :func:`camdyn.engine.kernels.on_arrays`), else angle by angle (a profile cam's spline)."""
    if closed:
        from ..engine import on_arrays      # (numba: loaded on first use, not with camdyn)
        return np.array(np.broadcast_arrays(*np.atleast_1d(on_arrays(kernel)(theta, p))), dtype=float)
    return np.array([np.atleast_1d(kernel(th, p)) for th in theta], dtype=float).T


def static_equilibrium(rig: Rig, contact: str = "line") -> Equilibrium:
    """alpha*, psi_i*, psi_j*, chi*, the contact stiffness and vartheta (Eqs. 16-18, 23)."""
    scene = _static_scene(contact, rig)
    if contact == "line":
        rig.require("l_lambda", why="line contact (Eq. 13)")
    return solve_equilibrium(rig, scene.kernels())


@dataclass(frozen=True)
class NaturalFrequency:
    """Eigen-analysis of the state Jacobian at the static equilibrium (Eqs. 21-23).

    ``damped_rad_s`` is ``|Im(eig J)|`` (misprint 4: no square root), ``undamped_rad_s``
    is ``|eig J| = sqrt(-J21)``; ``Hz`` is ``damped_rad_s / 2 pi``.
    """

    eigenvalues: tuple[complex, complex]
    damped_rad_s: float
    undamped_rad_s: float
    damping_ratio: float
    regime: str

    @property
    def Hz(self) -> float:
        return self.damped_rad_s / (2 * math.pi)

    @property
    def undamped_Hz(self) -> float:
        return self.undamped_rad_s / (2 * math.pi)


def natural_frequency(rig: Rig, scene: Scene | None = None, cam: CamMotion | None = None) -> NaturalFrequency:
    """Linearized natural frequency in sliding contact at the static equilibrium.

    The Jacobian is that of the scene's contact regime at (alpha*, 0) and t = 0,
    with the cam moving as ``cam`` (default: at rest).  The cam's direction sets the
    sign of Coulomb friction, which is why de- and self-energizing rigs differ
    (Section 7.1).  For damping D and E the viscous (unloading) law is used.
    """
    scene = scene or Scene(damping="none", friction="none")
    model = Model(rig, scene, cam or ConstantSpeed(0.0))
    m = sliding_mode(model, 0.0, model.equilibrium.alpha, 0.0)
    name = model.kernels.MODES[m]
    d0, d1 = model.jacobian(m, 0.0, model.equilibrium.alpha, 0.0)
    eig = np.linalg.eigvals(np.array([[0.0, 1.0], [d0, d1]]))
    wn = math.sqrt(max(-d0, 0.0))
    return NaturalFrequency((complex(eig[0]), complex(eig[1])), float(abs(eig[0].imag)), wn,
                            float(-d1 / (2 * wn)) if wn else math.nan, name)


def sliding_mode(model: Model, t: float, alpha: float, alpha_dot: float) -> int:
    """The mode of sliding contact at a state: in contact, under the viscous law of models D
    and E (their law after maximum compression), sliding in the direction of v_r there (not
    stuck).  Read from the automaton's mode tables, not from names."""
    K = model.kernels
    modes = [i for i, contact in enumerate(K.CONTACT_OF_MODE)
             if contact and K.PHASE_OF_MODE[i] in (None, "viscous") and K.SLIP_OF_MODE[i] != "stick"]
    if any(K.SLIP_OF_MODE[i] is not None for i in modes):
        v_r = model.surface(modes[0], K.SURFACE_SLIP, t, alpha, alpha_dot)
        side = "fwd" if v_r >= 0 else "bwd"
        modes = [i for i in modes if K.SLIP_OF_MODE[i] == side]
    return modes[0]


def rigid_contact_angle(rig: Rig, theta, contact: str = "line") -> np.ndarray:
    """alpha_i(Theta): the follower angle if it stayed in rigid contact (Eq. 29, misprint 10)."""
    theta = np.asarray(theta, dtype=float)
    return rigid_kinematics(rig, theta.ravel())[0].reshape(theta.shape)


def contact_loss_speed(rig: Rig, *, friction_coefficient: float = 0.0, samples: int = 3600) -> float:
    """Cam speed (rev/min) above which the follower leaves the cam: inverse kinematics [36].

    In rigid contact alpha = alpha_i(Theta(t)); the contact must supply
    F_n (chi - mu w_b/2) = I_Pb alpha_i_ddot + F_s d_x, and it can only push.
    At constant speed alpha_i_ddot = alpha_i''(Theta) Omega^2, so contact is lost
    first where I_Pb alpha_i'' Omega^2 + F_s d_x = 0 with alpha_i'' < 0:
    Omega_loss^2 = min over Theta of F_s d_x / (-I_Pb alpha_i'').  Friction only
    scales F_n, as long as chi > mu w_b / 2, so it does not move the loss speed.
    The translating follower: m_f y_i'' Omega^2 + F_s = F_n >= 0, the same with m_f and F_s
    (its face's friction acts across the guide).
    Returns inf when no cam angle decelerates the follower (e = 0).
    """
    thetas = rig.theta0 + np.linspace(0.0, 2 * math.pi, samples, endpoint=False)
    alpha_i, curvature, spring_moment = rigid_kinematics(rig, thetas)
    I = rig.inertia
    if rig.follower != "translating" and np.any(np.abs(alpha_i) > ANGLE_LIMIT):
        raise GeometryError("in rigid contact the follower would pass 90 degrees over a revolution")
    if np.any(spring_moment <= 0):
        return 0.0
    pulling = curvature < 0
    if not np.any(pulling):
        return math.inf

    def ratio(th):
        _, c, m = (float(x[0]) for x in rigid_kinematics(rig, th))
        return m / (-I * c) if c < 0 else math.inf

    i = int(np.argmin(np.where(pulling, spring_moment / (-I * np.where(pulling, curvature, -1)), np.inf)))
    from scipy.optimize import minimize_scalar
    step = 2 * math.pi / samples
    best = minimize_scalar(ratio, bracket=None, bounds=(thetas[i] - step, thetas[i] + step),
                           method="bounded", options={"xatol": 1e-12})
    omega2 = min(best.fun, ratio(thetas[i]))
    return math.sqrt(omega2) / RPM


def _contact_moment(rig: Rig, omega: float, samples: int):
    """The moment rigid contact needs, M_c(Theta) = I_Pb alpha_i''(Theta) Omega^2 + F_s d_x
    (:func:`contact_loss_speed`), at ``samples`` cam angles over a revolution at Omega (rad/s):
    (Theta, M_c, alpha_i'')."""
    theta = rig.theta0 + np.linspace(0.0, 2 * math.pi, samples, endpoint=False)
    _, curvature, spring = rigid_kinematics(rig, theta)
    return theta, rig.inertia * curvature * omega ** 2 + spring, curvature


def contact_loss_angle(rig: Rig, *, samples: int = 3600, loss_rpm: float | None = None) -> float:
    """The cam angle Theta* (rad, from theta0 over a revolution) at which rigid contact is lost
    first: where the moment M_c is least at the contact-loss speed (:func:`contact_loss_speed`;
    ``loss_rpm`` where the caller has it), to one of ``samples`` angles.  NaN when the follower
    never leaves the cam."""
    loss = contact_loss_speed(rig) if loss_rpm is None else float(loss_rpm)
    if not math.isfinite(loss) or loss == 0:
        return math.nan
    theta, M, _ = _contact_moment(rig, loss * RPM, samples)
    return float(theta[int(np.argmin(M))])


def compliance_shift(rig: Rig, scene: Scene | None = None, *, samples: int = 20000,
                     loss_rpm: float | None = None) -> float:
    """The relative shift of the contact-loss speed by the contact's compliance, to first order:
    ``(Omega_loss - Omega_ik) / Omega_ik`` (negative: a compliant contact lets go earlier).

    Rigid contact needs the moment M_c(Theta) = I_Pb alpha_i''(Theta) Omega^2 + F_s d_x >= 0
    (:func:`contact_loss_speed`); it vanishes first at Theta*, its minimum, at Omega_ik.  A
    compliant contact deflects by delta = -M_c / K into the cam (quasi-static; K = I_Pb vartheta^2,
    the linearized stiffness of Eq. 23, which the contact's dominates), so the follower
    accelerates by delta'' = -Omega^2 M_c''(Theta) / K more and needs I_Pb delta'' more moment:
    at Theta* that is -I_Pb Omega^2 M_c'' / K < 0.  With dM_c/d(Omega^2) = I_Pb alpha_i''(Theta*) < 0,
    the loss speed moves by ``-M_c''(Theta*) / (2 K |alpha_i''(Theta*)|)``, that is
    ``-(1/2) (Omega/vartheta)^2 m`` with ``m = M_c'' / (I_Pb |alpha_i''| Omega^2)``, a number of the
    cam's profile.  ``scene`` gives vartheta (default: line contact; vartheta is the static
    equilibrium's, which no damping or friction law changes).
    ``loss_rpm``: Omega_ik (rev/min) where the caller has it already, else :func:`contact_loss_speed`.
    Returns 0 when the follower never leaves the cam (no decelerating cam angle).
    """
    loss = contact_loss_speed(rig) if loss_rpm is None else float(loss_rpm)
    if not math.isfinite(loss) or loss == 0:
        return 0.0
    scene = scene or _static_scene("line", rig)
    theta, M, curvature = _contact_moment(rig, loss * RPM, samples)
    k, h = int(np.argmin(M)), theta[1] - theta[0]
    M2 = (M[k - 1] - 2 * M[k] + M[(k + 1) % samples]) / h ** 2
    vartheta = Model(rig, scene, ConstantSpeed(0.0)).equilibrium.vartheta
    return float(-0.5 * M2 / (rig.inertia * vartheta ** 2 * abs(curvature[k])))


def energy_balance_peak(rig: Rig, speed_rpm: float, xi: float, *, potential: str = "printed",
                        contact: str = "line") -> float:
    """alpha_rp from the approximate energy balance of Section 5 (Eqs. 30-33).

    The follower leaves the impact with kinetic energy T_b = 0.5 I_Pb ((1+xi) e Omega_c / chi*)^2
    and swings away from the cam until the spring has taken it: V(alpha_p) - V(alpha*) = T_b.
    ``potential="printed"`` uses Eq. 33 ((k_s/2) L^2); "consistent" the potential of
    Eq. 10's spring moment.  Returns alpha_p - alpha*.  Both potentials grow without
    bound towards 90 degrees (tan, sec in L), so alpha_p approaches but never reaches it.
    """
    if not (isinstance(xi, (int, float)) and 0 <= xi <= 1):
        raise ParameterError("xi", xi, "0 <= xi <= 1 (coefficient of restitution)")
    if potential not in ("printed", "consistent"):
        raise ParameterError("potential", potential, "'printed' or 'consistent'")
    if rig.profile is not None:
        raise GeometryError("Section 5's energy balance is written for the eccentric circle (the impact speed "
                            "e Omega_c): it has no meaning for the rig's cam profile")
    eq = static_equilibrium(rig, contact)
    K = _static_scene(contact).kernels()
    p = static_parameters(rig, K)
    col = 1 if potential == "printed" else 0
    T_b = 0.5 * rig.I_Pb * ((1 + xi) * rig.e * ConstantSpeed(speed_rpm).Omega_c / eq.chi) ** 2
    V0 = K.spring_potential(eq.alpha, p)[col]

    def excess(a):
        return K.spring_potential(a, p)[col] - V0 - T_b

    top = math.pi / 2 - 1e-9
    if T_b == 0:
        return 0.0
    if excess(top) <= 0:
        return top - eq.alpha
    return brentq(excess, eq.alpha, top, xtol=1e-14) - eq.alpha


@dataclass(frozen=True)
class ResidualStats:
    """rms and peak-to-peak of the residual response alpha_r (Section 4, Fig. 4)."""

    rms: float
    peak_to_peak: float


def residual_stats(result: Result, *, transient_revolutions: float = 0.0) -> ResidualStats:
    """The rms and peak-to-peak of the residual response alpha_r (Section 4, Fig. 4; the translating
    follower's y_r).

    Parameters
    ----------
    result : camdyn.Result
        A run.
    transient_revolutions : float, optional
        Cam revolutions left out at the start (0 for a cam with no period).

    Returns
    -------
    ResidualStats
        ``rms`` (of alpha_r about its mean) and ``peak_to_peak``, in rad (y_r: m).

    Raises
    ------
    camdyn.ParameterError
        If a transient is asked for on a cam with no period.
    """
    if not math.isfinite(result.period) and transient_revolutions:
        raise ParameterError("transient_revolutions", transient_revolutions, "0 for a cam with no period")
    r = result.after(result.t[0] + transient_revolutions * result.period) if transient_revolutions else result
    return ResidualStats(signal.rms(r.residual, remove_mean=True), signal.peak_to_peak(r.residual))


def alpha_spectrum(result: Result, *, window: str = "hann"):
    """One-sided amplitude spectrum of alpha (f in Hz), Figs. 10 and 16."""
    return signal.spectrum(result.t, result.alpha, window=window)
