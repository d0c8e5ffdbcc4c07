"""A scene's generated kernels bound to one rig and one cam motion.

:class:`Model` checks that the rig has every parameter the scene needs, that
the geometry is possible, solves the static equilibrium (Eqs. 16-18), and
packs the parameter vector once.  Nothing here is recomputed per kernel call.
"""
from __future__ import annotations

import math
from dataclasses import dataclass
from functools import cached_property, lru_cache
from types import ModuleType
from typing import NamedTuple

import numpy as np
from scipy.optimize import brentq

from .cam import CamMotion, ConstantSpeed
from ..vocabulary.parameters import CAM_NAMES, EQUILIBRIUM_NAMES
from ..vocabulary import (COORDINATES, ECCENTRIC, FOLLOWERS, JAC_D_ALPHA, JAC_D_ALPHA_DOT, RESET_JACOBIAN, STATIC_LOAD,
                          SURFACE_GRADIENT)
from ..engine import ANGLE_LIMIT  # |alpha| beyond it: the singular 90 degrees of Eq. 11
from ..errors import EquilibriumError, GeometryError, SceneError
from .rig import Rig
from .followers import cam_of, follower_of_rig, rigid_contact
from .scene import Scene, variational_kernels

_DERIVED = EQUILIBRIUM_NAMES  # computed here, not given by the rig
_CAM = CAM_NAMES              # given by the cam motion
_PROFILE = "profile"          # a scene's input for the cam's profile data (derive.profile_code)
_OSCILLATING, _TRANSLATING = FOLLOWERS
#: each follower type's coordinate: its name and unit (for messages)
_COORDINATE = {f: (name, unit) for f, (name, unit, _) in COORDINATES.items()}


def _rig_values(rig: Rig) -> dict:
    """The rig's parameters by name, and its cam profile's data block where it has one."""
    values = rig.to_dict()
    if rig.profile_data is not None:
        values[_PROFILE] = np.array(rig.profile_data[1])
    return values


@dataclass(frozen=True)
class Equilibrium:
    """Static equilibrium at Theta = Theta0, all rates zero (Eqs. 16-18, 23)."""

    q: float                 # the follower's coordinate: alpha* (rad), or the translating follower's y* (m)
    psi_i: float             # psi_i* (m), negative: the contact deflection
    psi_j: float             # psi_j* (m)
    chi: float               # chi* = chi0 - psi_j* (m); NaN for the translating follower (no moment arm)
    stiffness: float         # -dM/dalpha at alpha* (N m/rad), or -dF/dy at y* (N/m): undamped, frictionless
    contact_stiffness: float  # k_lambda(psi_i*) (N/m), the secant stiffness (misprint 5)
    vartheta: float          # sqrt(stiffness / I_Pb) (rad/s), Eq. 23 with misprint 4 and 7; / m_f translating

    @property
    def alpha(self) -> float:
        """alpha* (rad): the coordinate q of the paper's oscillating follower."""
        return self.q

    @property
    def frequency_Hz(self) -> float:
        return self.vartheta / (2 * math.pi)


class Rate(NamedTuple):
    """:attr:`Model.fastest_rate`: the rate (rad/s), the mode it is found in, and whether the
    damping term d(alpha_ddot)/d(alpha_dot) dominates it (else the stiffness term)."""

    value: float
    mode: str
    damping: bool


def static_parameters(rig: Rig, kernels: ModuleType) -> np.ndarray:
    """The parameter vector for the kernels that do not depend on a run (``static_moment``,
    ``reach``, ``rigid_contact``, ``spring_potential``): the rig's values, and NaN in the slots
    those kernels never read (equilibrium results, cam constants, optional parameters not
    given), so that a read of one would show as NaN rather than pass as a made-up number."""
    given = _rig_values(rig)
    values = {name: given.get(name) for name in kernels.INPUTS}
    return kernels.pack({name: math.nan if v is None else v for name, v in values.items()})


def zero_state(rig: Rig) -> float:
    """The follower's coordinate in the 0-state (touching the cam at theta0): alpha0, or the translating
    follower's y0 = h(gamma - theta0) on the rig's cam."""
    if rig.follower == _TRANSLATING:
        return float(cam_of(rig).h(rig.gamma - rig.theta0))
    return rig.alpha0


def _rigid_equilibrium(rig: Rig, at_rest: tuple) -> Equilibrium:
    """The rigid law's equilibrium: the 0-state itself (no deflection), the spring pressing the follower
    onto the cam; its stiffness and frequency those of the follower on its spring alone (the contact has
    none: vartheta sets only the step's cap and the run-length checks there)."""
    _, dM, psi_i, psi_j, _ = at_rest
    q0 = zero_state(rig)
    chi = rig.chi0 if rig.follower == _OSCILLATING else math.nan
    return Equilibrium(float(q0), float(psi_i), float(psi_j), float(chi), float(-dM), math.inf,
                       math.sqrt(abs(dM) / rig.inertia))


def solve_equilibrium(rig: Rig, kernels: ModuleType) -> Equilibrium:
    """q* from M(q*) = 0 near the 0-state, with M the generated static load (``static_moment``, the
    moment about P, Eqs. 16-18; the translating follower's ``static_force`` along its guide).

    At the 0-state q0 (alpha0, y0) the gap is zero at Theta0, so M(q0) is the spring's load alone:
    the spring must press the follower onto the cam (F_s > 0), else there is no contact at rest.
    The contact's load grows as the coordinate moves into the cam (q < q0), so the root is
    bracketed by stepping down from q0.
    """
    p = static_parameters(rig, kernels)
    load = getattr(kernels, STATIC_LOAD[rig.follower])
    q0, (name, unit) = zero_state(rig), _COORDINATE[rig.follower]

    def moment(a):
        return load(a, p)[0]

    M0 = moment(q0)
    if kernels.SCENE.get("contact") == "rigid" and M0 < 0:
        return _rigid_equilibrium(rig, load(q0, p))
    if not M0 < 0:
        hint = "increase L_us or lower d_y" if rig.follower == _OSCILLATING else "give a preload F_p > 0"
        raise EquilibriumError(
            f"no static equilibrium in contact: at the 0-state ({name}0 = {q0:g} {unit}) the spring's load is "
            f"{-M0:g}, so the spring does not press the follower onto the cam. It needs F_s > 0 there (Eq. 11): "
            f"{hint}.")
    step, lo = 1e-9, q0
    while moment(lo) <= 0:
        lo = q0 - step
        step *= 4
        if q0 - lo > 0.5:
            raise EquilibriumError(f"no static equilibrium within 0.5 {unit} of {name}0: the contact "
                                   "cannot balance the spring (check l_lambda, Y_c, Y_b, k_s)")
    a_star = brentq(moment, lo, q0, xtol=1e-15, rtol=4 * np.finfo(float).eps, maxiter=200)
    _, dM, psi_i, psi_j, k_lambda = load(a_star, p)
    if rig.follower == _OSCILLATING and abs(a_star) > ANGLE_LIMIT:
        raise GeometryError(f"static equilibrium alpha* = {a_star:g} rad is within "
                            f"{math.pi / 2 - abs(a_star):.3g} rad of 90 degrees, where Eq. 11 is singular")
    if not dM < 0:
        raise EquilibriumError(f"the static equilibrium {name}* = {a_star:g} {unit} is unstable (d load/d{name} = {dM:g})")
    chi = rig.chi0 - psi_j if rig.follower == _OSCILLATING else math.nan
    return Equilibrium(float(a_star), float(psi_i), float(psi_j), float(chi), float(-dM),
                       float(k_lambda), math.sqrt(-dM / rig.inertia))


def _check_profile(rig: Rig, scene: Scene) -> None:
    """The scene's cam family must be the rig's: the paper's circle needs no profile, any other
    family the rig's ``profile`` of that family."""
    kind = None if rig.profile_data is None else rig.profile_data[0]
    if scene.profile == ECCENTRIC and kind is not None:
        raise SceneError(f"the rig's cam is a {kind!r} profile but the scene is the paper's eccentric circle: "
                         f"use Scene(..., profile={kind!r})")
    if scene.profile != ECCENTRIC and kind != scene.profile:
        raise SceneError(f"the scene's cam is a {scene.profile!r} profile but the rig has "
                         f"{'none (the eccentric circle)' if kind is None else repr(kind)}: give the rig a "
                         f"profile of that family (Rig(..., profile=...), camdyn.model.profiles)")


def _check_follower(rig: Rig, scene: Scene) -> None:
    """The scene's follower type must be the rig's (``Rig.follower``)."""
    if scene.follower != rig.follower:
        raise SceneError(f"the rig's follower is {rig.follower!r} but the scene's is {scene.follower!r}: use "
                         f"Scene(..., follower={rig.follower!r}), or a rig of a {scene.follower} follower")


def _check_cam(scene: Scene, cam) -> None:
    if getattr(cam, "kind", None) != scene.motion:
        raise SceneError(f"the scene's motion is {scene.motion!r} but the cam given is "
                         f"{type(cam).__name__} ({getattr(cam, 'kind', '?')!r})")


@lru_cache(maxsize=16)
def _worst_reach(rig: Rig, kernels: ModuleType) -> tuple[float, float]:
    """(Theta, margin) of the least reach margin |PG_c| - (r_c + w_b/2) over a turn of the cam
    (the generated ``reach``, 721 angles): a property of the rig alone, kept for the last rigs
    seen, so that a sweep in the speed does not redo it for every point (docs/design-notes.md)."""
    thetas = rig.theta0 + np.linspace(0, 2 * math.pi, 721)
    p = static_parameters(rig, kernels)
    from ..engine import on_arrays      # (numba: loaded with the first model, not with camdyn)
    margins = np.broadcast_to(on_arrays(kernels.reach)(thetas, p), thetas.shape)
    worst = int(np.argmin(margins))
    return float(thetas[worst]), float(margins[worst])


class Model:
    """Scene kernels + rig + cam motion, ready to integrate."""

    def __init__(self, rig: Rig, scene: Scene, cam: CamMotion):
        if not isinstance(rig, Rig):
            raise TypeError(f"rig must be a camdyn.Rig, got {type(rig).__name__}")
        if not isinstance(scene, Scene):
            raise TypeError(f"scene must be a camdyn.Scene, got {type(scene).__name__}")
        _check_cam(scene, cam)
        self.rig, self.scene, self.cam = rig, scene, cam
        _check_follower(rig, scene)
        _check_profile(rig, scene)
        self.kernels = scene.kernels()
        optional = [n for n in self.kernels.INPUTS if n not in _DERIVED + _CAM + (_PROFILE,) and getattr(rig, n) is None]
        if optional:
            rig.require(*optional, why=f"scene {scene.slug}")
        self.equilibrium = solve_equilibrium(rig, self.kernels)
        if scene.friction != "none" and scene.follower == _OSCILLATING and self.equilibrium.chi <= rig.mu_m * rig.w_b / 2:
            raise GeometryError(f"chi* = {self.equilibrium.chi:g} m <= mu_m w_b / 2: friction would lock "
                                "the follower (the moment arm of Eq. 10 changes sign)")
        self._check_reach()
        self.p = self._packed(cam)

    def with_cam(self, cam: CamMotion) -> "Model":
        """The same rig and scene driven by another cam motion of the scene's kind.  The static
        equilibrium and the reach check depend on the rig only, so they are not redone (a
        continuation in the cam speed builds one model per speed)."""
        _check_cam(self.scene, cam)
        other = object.__new__(Model)
        other.rig, other.scene, other.cam = self.rig, self.scene, cam
        other.kernels, other.equilibrium = self.kernels, self.equilibrium
        other._static_values = self._static_values
        other.p = other._packed(cam)
        return other

    @cached_property
    def _static_values(self) -> dict:
        """The rig's parameters and its static equilibrium by name: p without the cam's constants."""
        eq = self.equilibrium
        at_rest = {"alpha_star": eq.q, "chi_star": eq.chi} if self.scene.follower == _OSCILLATING else {"y_star": eq.q}
        return {**_rig_values(self.rig), **at_rest, "vartheta": eq.vartheta}

    def _packed(self, cam: CamMotion) -> np.ndarray:
        """The kernels' parameter vector p: the rig, its static equilibrium and the cam's constants."""
        values = {**self._static_values, **cam.values()}
        return self.kernels.pack({k: values[k] for k in self.kernels.INPUTS})

    def _check_reach(self):
        """The cam must stay where the follower can touch it: |PG_c| > r_c + w_b/2 all round
        (the paper's circle; another cam's profile is checked convex where it is built)."""
        if not hasattr(self.kernels, "reach"):
            return
        theta, margin = _worst_reach(self.rig, self.kernels)
        if not margin > 0:
            raise GeometryError(
                f"at cam angle Theta = {theta:.4g} rad the cam centre is {-margin:.3g} m "
                "too close to the pivot P: no follower angle touches the cam there (|PG_c| < r_c + w_b/2); "
                "check e, r_c, w_b, chi0 and alpha0")

    @property
    def coordinate_limit(self) -> float:
        """The bound on the coordinate's size past which a run ends (Outcome.ANGLE_LIMIT): the paper's follower
        near 90 degrees, where tan and sec of Eq. 11 blow up (ANGLE_LIMIT); none (inf) for the
        translating follower, whose laws have no singularity."""
        return ANGLE_LIMIT if self.scene.follower == _OSCILLATING else math.inf

    @property
    def step_cap(self) -> float:
        """The longest step a run may take (s): on a cam of arcs, half the turn time of its shortest arc, so
        that no step spans two of its junctions (their surface alternates its sign from arc to arc: a step
        across two would see none; a field that barely changes, a rigid follower on a dwell, otherwise grows
        the steps past them); no cap (inf) on any other cam or a cam at rest."""
        if self.rig.profile is None or self.rig.profile.kind != "arcs" or self.cam.kind != "constant":
            return math.inf
        omega = abs(self.cam.Omega_c)
        return math.inf if omega == 0 else float(np.min(np.diff(self.rig.profile.angles))) / (2 * omega)

    @cached_property
    def period(self) -> float:
        return self.cam.period

    def cam_state(self, t):
        """(Theta, Theta_dot, Theta_ddot) at t (scalar or array)."""
        if self.scene.motion == "user":
            return self.cam(t)
        return self.kernels.cam(t, self.p)

    def mode(self, name: str) -> int:
        """The index of a mode of the scene's automaton (``MODES``)."""
        return self.kernels.MODES.index(name)

    def _extra(self, t) -> tuple:
        """The kernels' argument after p: the user cam's state at t, or nothing."""
        return (self.cam(t),) if self.scene.motion == "user" else ()

    def rhs(self, m: int, t: float, alpha: float, alpha_dot: float) -> float:
        """alpha_ddot in mode m (the generated ``rhs``)."""
        return self.kernels.rhs(m, t, alpha, alpha_dot, self.p, *self._extra(t))

    def surface(self, m: int, s: int, t: float, alpha: float, alpha_dot: float) -> float:
        """Surface s's value under mode m's laws (the generated ``surface``)."""
        return self.kernels.surface(m, s, t, alpha, alpha_dot, self.p, *self._extra(t))

    def jacobian(self, m: int, t: float, alpha: float, alpha_dot: float) -> tuple[float, float]:
        """(d alpha_ddot/d alpha, d alpha_ddot/d alpha_dot) in mode m (Eqs. 21-22)."""
        out = np.empty(2)
        self.kernels.jacobian(m, t, alpha, alpha_dot, self.p, *self._extra(t), out)
        return float(out[JAC_D_ALPHA]), float(out[JAC_D_ALPHA_DOT])

    def outputs_at(self, modes, t, alpha, alpha_dot, backend: str = "compiled") -> np.ndarray:
        """The output quantities (rows in the order of ``OUTPUTS``: ``OUT_<NAME>``) at samples of
        a run (its modes, times and states), by the compiled outputs kernel or, with backend
        "python", the generated Python one."""
        from ..engine import compiled_kernels, outputs_on_samples, python_kernels
        K = self.kernels
        compiled = backend == "compiled"
        kern = compiled_kernels(K) if compiled else python_kernels(K, self.cam if self.scene.motion == "user" else None)
        values = outputs_on_samples(kern, compiled, modes, t, alpha, alpha_dot, self.p, len(K.OUTPUTS))
        return self._with_rigid_contact(t, values)

    @property
    def _rigid_contact_in_closed_form(self) -> bool:
        """The generated kernels hold q_i(Theta) in closed form (``rigid_contact``, ``OUT_ALPHA_I``):
        Eq. 29 on the paper's circle, y_i = h(gamma - Theta) for the translating follower on any
        cam.  The rocker on any other cam has none: its q_i is the root of the gap."""
        return self.rig.profile is None or self.scene.follower != _OSCILLATING

    @cached_property
    def _follower(self):
        """The rig's follower geometry (camdyn.model.followers), for the root of the gap on a profile."""
        return follower_of_rig(self.rig)

    def rigid_coordinate(self, theta: float) -> tuple[float, float, float]:
        """The follower in rigid contact at the cam angle ``theta`` (rad): its coordinate q_i
        (Eq. 29's alpha_i, or y_i) and its first and second derivatives in Theta (per rad and
        rad^2): the generated ``rigid_contact`` where it is in closed form, else the root of the
        gap and its implicit derivatives (camdyn.model.followers.rigid_contact)."""
        if self._rigid_contact_in_closed_form:
            q, dq, ddq, _ = self.kernels.rigid_contact(theta, self.p)
            return float(q), float(dq), float(ddq)
        found = rigid_contact(self.rig.profile, self._follower, np.array([theta], dtype=float))
        return float(found.q[0]), float(found.q_dot[0]), float(found.q_ddot[0])

    def _with_rigid_contact(self, t, values: np.ndarray) -> np.ndarray:
        """On a cam other than the circle the generated ``outputs`` has no closed form of alpha_i
        (Eq. 29): it is the root of the gap at the cam angle Theta(t), solved here
        (camdyn.model.followers.rigid_contact) into row OUT_ALPHA_I."""
        if self._rigid_contact_in_closed_form:
            return values
        theta = self.cam_state(np.asarray(t, dtype=float))[0]
        values[self.kernels.OUT_ALPHA_I] = rigid_contact(self.rig.profile, self._follower,
                                                         np.asarray(theta, dtype=float)).q
        return values

    @cached_property
    def fastest_rate(self) -> "Rate":
        """The fastest rate of the linearized motion (rad/s) at the static equilibrium (alpha*, 0,
        t = 0): the largest abs(eigenvalue) of the state matrix [[0, 1], [J_alpha, J_alpha_dot]]
        (Eqs. 21-22, the generated Jacobian) over the scene's modes.  An explicit Runge-Kutta
        step cannot be much longer than a few times 1/rate (its stability region), so the rate
        sets the work per simulated second; in an undamped contact mode it is vartheta (Eq. 23),
        a strong damping law or a steep friction law raises it."""
        alpha = self.equilibrium.q
        best = Rate(0.0, self.kernels.MODES[0], False)
        for m, name in enumerate(self.kernels.MODES):
            ja, jad = self.jacobian(m, 0.0, alpha, 0.0)
            if not (math.isfinite(ja) and math.isfinite(jad)):
                continue
            disc = jad * jad + 4.0 * ja   # eigenvalues (jad +- sqrt(disc)) / 2
            rate = (abs(jad) + math.sqrt(disc)) / 2 if disc >= 0 else math.sqrt(-ja)
            if rate > best.value:
                best = Rate(rate, name, jad * jad > abs(ja))
        return best

    @cached_property
    def variational(self) -> ModuleType | None:
        """The scene's variational kernels (``surface_gradient``, ``field_sensitivity``): the
        companion of its generated module, imported on first use
        (:func:`camdyn.model.scene.variational_kernels`), so that a run never loads them; None for a
        scene without them (the linear models)."""
        return variational_kernels(self.kernels)

    def field_sensitivity(self, m: int, t: float, alpha: float, alpha_dot: float) -> dict[str, float]:
        """d(alpha_ddot)/d(q) in mode m at a fixed state and time for the scene's continuation
        parameters q (the generated ``field_sensitivity``; its module's ``SENSITIVITY`` names
        them, in the order of ``CONTINUATION_PARAMETERS``: the cam's speed constant in rad/s, k_s,
        e, the damping constants), total derivatives: the static equilibrium follows the rig.
        Raises :class:`SceneError` for a scene without it (the linear models)."""
        kernel = getattr(self.variational, "field_sensitivity", None)
        if kernel is None:
            raise SceneError(f"scene {self.kernels.SLUG!r} has no parameter derivatives (non-linear model only)")
        out = np.empty(len(self.variational.SENSITIVITY))
        kernel(m, t, alpha, alpha_dot, self.p, *self._extra(t), out)
        return dict(zip(self.variational.SENSITIVITY, map(float, out)))

    def surface_gradient(self, m: int, s: int, t: float, alpha: float, alpha_dot: float) -> np.ndarray:
        """(dh/dalpha, dh/dalpha_dot, dh/dt) of surface s's value h under mode m's laws (the
        generated ``surface_gradient``, order ``SURFACE_GRADIENT``), for a surface m watches.
        Raises :class:`SceneError` where the scene has none (no switching surfaces) or it is
        not defined (a surface m does not watch; a user cam motion where dh/dt needs the
        derivative of Theta_ddot)."""
        kernel = getattr(self.variational, "surface_gradient", None)
        if kernel is None:
            raise SceneError(f"scene {self.kernels.SLUG!r} has no switching surfaces to differentiate")
        out = np.empty(len(SURFACE_GRADIENT))
        kernel(m, s, t, alpha, alpha_dot, self.p, *self._extra(t), out)
        if not np.all(np.isfinite(out)):
            raise SceneError(f"the gradient of surface {self.kernels.SURFACES[s]!r} in mode "
                             f"{self.kernels.MODES[m]!r} of scene {self.kernels.SLUG!r} is not defined at "
                             f"t = {t:g} s: a surface the mode does not watch, or a user cam motion whose "
                             "Theta_ddot would have to be differentiated (give the scene a built-in motion)")
        return out

    def reset_jacobian(self, j: int, t: float, alpha: float, alpha_dot: float) -> np.ndarray:
        """The derivatives of the state after reset j (RESETS) by the state before it and by t, in the
        order of RESET_JACOBIAN (the generated ``reset_jacobian``: the rigid law's impacts)."""
        kernel = getattr(self.variational, "reset_jacobian", None)
        if kernel is None:
            raise SceneError(f"scene {self.kernels.SLUG!r} has no resets to differentiate")
        out = np.empty(len(RESET_JACOBIAN))
        kernel(j, t, alpha, alpha_dot, self.p, out)
        return out

    def outputs(self, m: int, t: float, alpha: float, alpha_dot: float) -> dict[str, float]:
        """The output quantities (``OUTPUTS``) in mode m at one state, by name."""
        out = np.empty(len(self.kernels.OUTPUTS))
        self.kernels.outputs(m, t, alpha, alpha_dot, self.p, *self._extra(t), out)
        out = self._with_rigid_contact(np.array([t]), out[:, None])[:, 0]
        return dict(zip(self.kernels.OUTPUTS, map(float, out)))

    def static_state(self) -> np.ndarray:
        return np.array([self.equilibrium.q, 0.0])


def at_rest(rig: Rig, scene: Scene) -> Model:
    """The model with the cam held still at Theta0 (for equilibrium-based analyses)."""
    if scene.motion != "constant":
        scene = Scene(**{**scene.__dict__, "motion": "constant"})
    return Model(rig, scene, ConstantSpeed(0.0))
