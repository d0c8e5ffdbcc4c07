"""Periodic orbits by shooting on the stroboscopic map, and their Floquet multipliers.

A periodic orbit of period n T (T the cam's period) is a fixed point of the stroboscopic map
P_n (:class:`camdyn.orbits.section_map.StroboscopicMap`): P_n(x) - x = 0.  :func:`periodic_orbit`
finds one by Newton's method from a warm start (the state at the section after a short
simulation), with a backtracking line search; the monodromy matrix M = dP_n/dx at the fixed
point comes from a Jacobian provider (central finite differences by default,
:func:`camdyn.orbits.derivatives.finite_differences`, whose entries carry ~rtol^(2/3) of the motion's
scale, and which are only taken across perturbed runs that make the base run's switches, else
shrunk, else replaced by the variational provider, else reported unresolved: :mod:`camdyn.orbits.derivatives`; or the variational equations with saltation matrices, ``jacobian=camdyn.orbits.tangent.variational``,
exact to the integration's tolerance and cheaper, but not for damping C and E, whose impact
laws have an unbounded Jacobian at first contact: see :mod:`camdyn.orbits.tangent`), and its eigenvalues are the Floquet multipliers: the orbit is
asymptotically stable when every multiplier has modulus < 1.

Newton's residual is scaled by the size of the motion s (per component, from the warm-up's
last revolution): ``r(x) = max_j |P_j(x) - x_j| / s_j``.  It stops when r <= ``tol`` (default
1e-8: a hundred times the default solver tolerance rtol 1e-10, the level of the map's own
integration error, below which a residual is noise).
"""
from __future__ import annotations

import math
from dataclasses import dataclass, field
from typing import NamedTuple

import numpy as np

from ..runs import quasistatic
from ..model.cam import CamMotion, periodic_cam
from ..engine import SolverOptions
from ..errors import ParameterError
from .._checks import integer, real
from ..model.model import Model
from ..outcome import ActionableOutcome
from ..model.rig import Rig
from ..model.scene import Scene
from .derivatives import finite_differences
from .section_map import DEFAULT_OPTIONS, MapDerivative, MapFailure, StroboscopicMap, derivative_at, warm_up

#: samples of the warm-up's last revolution, for the size of the motion (the residual's scale)
SCALE_SAMPLES = 64
#: the line search halves the Newton step at most this many times (down to 2^-10 of it)
MAX_HALVINGS = 10
#: M - I (scaled) with a singular value below this is singular: a multiplier this close to +1
#: (the orbit is not isolated: a fold) cannot be told from 1 by a finite-difference monodromy,
#: whose entries carry errors ~rtol^(2/3) = 2e-7 at the default rtol
SINGULAR_SIGMA = 1e-6


class OrbitOutcome(ActionableOutcome):
    """How the search for a periodic orbit ended (an actionable message each)."""

    CONVERGED = "P_n(x) = x to the stated tolerance: a periodic orbit of period n T"
    NEWTON_STALLED = ("no step along the Newton direction reduced the residual (line search exhausted): "
                      "the warm start is too far from an orbit, the map is not smooth there (grazing, "
                      "stick-slip), or tol is below the map's noise; raise tol, tighten rtol, or warm up longer")
    MAX_ITERATIONS = ("the residual still exceeded tol after max_iterations Newton steps: raise "
                      "max_iterations or tol, or warm up longer")
    RUN_FAILED = ("a run of the map failed (see the message: chatter, angle limit...) or left its mode's "
                  "domain at the warm start; try another phase, periods or speed")
    SINGULAR = ("M - I is singular (a Floquet multiplier at +1): the orbit is not isolated, e.g. at a fold; "
                "a continuation method is needed")
    MODE_CHANGED = ("the map ends in another mode than it starts in at the fixed point: the section "
                    "is on a switching surface; choose another phase")
    MULTIPLIERS_UNRESOLVED = ("P_n(x) = x to the stated tolerance, but no Jacobian provider resolved dP_n/dx there "
                              "(the message says why: perturbed runs cross other surfaces than the orbit at every "
                              "step above the noise floor, and the variational provider failed or the scene has "
                              "none): the orbit's state is given, its multipliers are not; tighten rtol (a lower "
                              "floor) or use jacobian=camdyn.orbits.tangent.variational where the scene allows it")


@dataclass(frozen=True)
class PeriodicOrbit:
    """A periodic orbit found by shooting (or the last iterate of a failed search).

    ``state``: (alpha rad, alpha_dot rad/s) at the section time ``phase`` (s), NaN only when
    the warm-up run itself failed (outcome RUN_FAILED, the message says why); ``mode``: the
    automaton's mode there (a name of the scene's MODES); ``periods``: n; ``multipliers``: the
    Floquet multipliers (eigenvalues of ``monodromy``), only for a converged orbit (else empty:
    a failed search's last iterate is no orbit); ``stable``: ``max |mu| < 1``, None unless
    converged; ``monodromy``: dP_n/dx at ``state`` (also at a failed search's last iterate); ``residual``: the scaled residual r (see the module);
    ``scale``: s; ``iterations``: Newton steps taken; ``outcome`` and ``message``: how it ended;
    ``map_evaluations`` (runs of P_n outside the provider) and ``jacobian_evaluations`` (provider
    calls: 5 runs each by finite differences, one run and its tangent dynamics by the variational
    provider) give the cost; ``jacobian_provider`` names the provider that gave ``monodromy``
    (``"finite_differences"``, ``"variational"``, a caller's), ``difference_steps`` its
    central-difference steps (rad, rad/s; NaN when not by differences) and ``jacobian_note`` what
    happened on the way (a fallback, or why it is unresolved).
    """

    state: np.ndarray
    mode: str
    periods: int
    phase: float
    multipliers: np.ndarray
    stable: bool | None
    residual: float
    iterations: int
    outcome: OrbitOutcome
    message: str
    monodromy: np.ndarray | None = None
    scale: np.ndarray = field(default_factory=lambda: np.ones(2))
    map_evaluations: int = 0
    jacobian_evaluations: int = 0
    mode_index: int = -1         # ``mode`` as an index of MODES (-1: no orbit, mode "")
    jacobian_provider: str = ""
    difference_steps: np.ndarray = field(default_factory=lambda: np.full(2, np.nan))
    jacobian_note: str = ""

    @property
    def ok(self) -> bool:
        return self.outcome.ok


@dataclass(frozen=True)
class ShootingSettings:
    """Newton's settings: stop at scaled residual <= ``tol``, after at most ``max_iterations``."""

    tol: float = 1e-8
    max_iterations: int = 20

    def __post_init__(self):
        real("tol", self.tol, "0 < tol < 1 (scaled residual)", lambda v: 0 < v < 1)
        integer("max_iterations", self.max_iterations, "an integer, 1 <= max_iterations <= 1000",
                lambda n: 1 <= n <= 1000)


def warm_start(model: Model, revolutions: float, phase: float, y0=None,
               options: SolverOptions = DEFAULT_OPTIONS, backend: str = "compiled"):
    """The state and mode at the section time ``phase + revolutions T`` after a run from ``y0``
    (default the static equilibrium) at t = 0 (:func:`~camdyn.orbits.section_map.warm_up`), and the
    size of the motion over its last revolution (``max |alpha - alpha*|`` and ``max |alpha_dot|``:
    the residual's scale)."""
    T = model.period
    integer("warmup_revolutions", revolutions, "an integer >= 1", lambda n: n >= 1)
    t_end = phase + revolutions * T
    t_eval = t_end - T + T * np.arange(SCALE_SAMPLES + 1) / SCALE_SAMPLES
    t_eval[-1] = t_end                       # the section itself, not t_end - T + T rounded
    tr = warm_up(model, t_end, y0, t_eval, options, backend)
    return tr.y[:2, -1].copy(), int(tr.end_mode), motion_scale(model, tr.y[0], tr.y[1])


def quasi_static_warm_start(model: Model, phase: float):
    """The warm start of ``periodic_orbit(..., start="quasistatic")``: the quasi-static contact
    orbit's state and mode at the section time ``phase`` (:func:`camdyn.runs.quasistatic.section_state`)
    and the size of the motion over one revolution of it; MapFailure where the orbit does not exist."""
    orbit = quasistatic.orbit_at(model, phase + model.period * np.arange(SCALE_SAMPLES) / SCALE_SAMPLES)
    if not orbit.ok:
        raise MapFailure(f"no quasi-static warm start: {orbit.message}")
    x0, mode = quasistatic.section_state(model, phase)
    return x0, mode, motion_scale(model, orbit.alpha, orbit.alpha_dot)


def motion_scale(model: Model, alpha: np.ndarray, alpha_dot: np.ndarray) -> np.ndarray:
    """The size of a motion, per state component: ``max |alpha - alpha*|`` (rad) and ``max
    |alpha_dot|`` (rad/s) over its samples, at least 1e-12 of each's unit (a motion at rest):
    the scale of shooting's residual and of the finite-difference steps."""
    scale = np.array([np.max(np.abs(alpha - model.equilibrium.q)), np.max(np.abs(alpha_dot))])
    tiny = np.array([1e-12, 1e-12 * model.equilibrium.vartheta])
    return np.maximum(scale, tiny)


def _residual(F: np.ndarray, scale: np.ndarray) -> float:
    return float(np.max(np.abs(F) / scale))


def newton_matrix(J: np.ndarray, scale: np.ndarray) -> np.ndarray:
    """dP/dx - I in the variables scaled by the motion's size (x_j / scale_j): the Jacobian of
    the scaled residual (P(x) - x) / scale, which shooting and the continuation's corrector solve."""
    return (J - np.eye(J.shape[0])) * scale[None, :] / scale[:, None]


def _newton_step(J: np.ndarray, F: np.ndarray, scale: np.ndarray):
    """The Newton step of P(x) - x = 0, solved in scaled variables; None when M - I is singular."""
    A = newton_matrix(J, scale)
    if not np.all(np.isfinite(A)) or np.linalg.svd(A, compute_uv=False)[-1] < SINGULAR_SIGMA:
        return None
    return -np.linalg.solve(A, F / scale) * scale


def _line_search(section_map, x, dx, r0, scale):
    """Backtracking on the scaled residual: the first of dx, dx/2, ... (MAX_HALVINGS) whose
    residual is below (1 - lambda/4) r0, or None; a step whose run fails is halved too."""
    lam, evaluations = 1.0, 0
    for _ in range(MAX_HALVINGS + 1):
        trial = x + lam * dx
        try:
            evaluations += 1
            F = section_map(trial) - trial
        except MapFailure:
            lam /= 2
            continue
        r = _residual(F, scale)
        if r < (1.0 - lam / 4.0) * r0:
            return trial, F, r, evaluations
        lam /= 2
    return None, None, r0, evaluations


class NewtonResult(NamedTuple):
    """What :func:`newton` returns: the last iterate, the provider's derivative there, the scaled
    residual, the steps taken, the outcome, and the cost (line-search map runs, provider calls)."""

    x: np.ndarray               # the last iterate
    derivative: MapDerivative | None  # P and dP/dx there, and how (None when the provider failed)
    residual: float
    iterations: int
    outcome: OrbitOutcome
    map_evaluations: int        # by the line search
    jacobian_evaluations: int   # provider calls (each also gives P)
    failure: str = ""           # with RUN_FAILED: why the run failed (the MapFailure's message)

    @property
    def jacobian(self) -> np.ndarray | None:
        """dP/dx at the last iterate (None when the provider failed)."""
        return None if self.derivative is None else self.derivative.jacobian


def newton(section_map: StroboscopicMap, jacobian, x0, scale,
           settings: ShootingSettings = ShootingSettings()) -> NewtonResult:
    """Newton's method on P(x) - x = 0 from x0, with the line search of :func:`_line_search`.
    ``jacobian`` is a provider (:func:`camdyn.orbits.section_map.derivative_at`); an unresolved
    derivative still gives Newton's direction (:attr:`OrbitOutcome.MULTIPLIERS_UNRESOLVED` is
    decided from the last one, in :func:`periodic_orbit`)."""
    x, d, maps, calls = np.asarray(x0, dtype=float), None, 0, 0
    try:
        calls += 1
        d = derivative_at(jacobian, x)
    except MapFailure as failure:
        return NewtonResult(x, None, math.inf, 0, OrbitOutcome.RUN_FAILED, maps, calls, str(failure))
    r = _residual(d.value - x, scale)
    for it in range(settings.max_iterations + 1):
        if r <= settings.tol:
            return NewtonResult(x, d, r, it, OrbitOutcome.CONVERGED, maps, calls)
        if it == settings.max_iterations:
            break
        if not np.all(np.isfinite(d.jacobian)):
            return NewtonResult(x, d, r, it, OrbitOutcome.RUN_FAILED, maps, calls, f"no Newton direction: {d.note}")
        dx = _newton_step(d.jacobian, d.value - x, scale)
        if dx is None:
            return NewtonResult(x, d, r, it, OrbitOutcome.SINGULAR, maps, calls)
        trial, _, r_new, n = _line_search(section_map, x, dx, r, scale)
        maps += n
        if trial is None:
            return NewtonResult(x, d, r, it, OrbitOutcome.NEWTON_STALLED, maps, calls)
        try:
            calls += 1
            d = derivative_at(jacobian, trial)
        except MapFailure as failure:
            return NewtonResult(trial, None, r_new, it + 1, OrbitOutcome.RUN_FAILED, maps, calls, str(failure))
        x, r = trial, _residual(d.value - trial, scale)
    return NewtonResult(x, d, r, settings.max_iterations, OrbitOutcome.MAX_ITERATIONS, maps, calls)


def periodic_orbit(rig: Rig, scene: Scene, cam: CamMotion | None = None, *, speed_rpm: float | None = None,
                   periods: int = 1, phase: float = 0.0, warmup_revolutions: int = 20, y0=None,
                   settings: ShootingSettings = ShootingSettings(), options: SolverOptions = DEFAULT_OPTIONS,
                   jacobian=finite_differences, backend: str = "compiled", start: str = "run") -> PeriodicOrbit:
    """A periodic orbit of period ``periods`` cam periods, by Newton shooting on P_n.

    The warm start is the state and mode at the section time ``phase + warmup_revolutions T``
    (s) of a run from ``y0`` (default the static equilibrium) at t = 0; the map starts every
    run in that mode (:class:`~camdyn.orbits.section_map.StroboscopicMap`).  ``jacobian(map, scale)``
    makes the Jacobian provider (default: central finite differences; :func:`camdyn.orbits.tangent.variational`
    for the tangent dynamics).  ``settings`` holds
    Newton's tolerance and iteration limit, ``options`` the solver's (default rtol 1e-10,
    atol 1e-13).  The result says how the search ended (:class:`OrbitOutcome`); it raises
    only on bad input.  ``start="quasistatic"`` warms up with no run: the quasi-static contact
    orbit's state at the section (:mod:`camdyn.runs.quasistatic`), for an orbit in permanent contact
    (RUN_FAILED, saying where, when the contact force would turn tensile).
    """
    cam = periodic_cam(cam, speed_rpm)
    if not isinstance(settings, ShootingSettings):
        raise ParameterError("settings", settings, "a camdyn.orbits.shooting.ShootingSettings")
    model = Model(rig, scene, cam)
    StroboscopicMap(model, periods, phase, None, options, backend)       # checks periods, phase, options
    if start not in ("run", "quasistatic"):
        raise ParameterError("start", start, "'run' (a warm-up run) or 'quasistatic' (the quasi-static contact orbit)")
    try:
        if start == "quasistatic":
            x0, mode, scale = quasi_static_warm_start(model, phase)
        else:
            x0, mode, scale = warm_start(model, warmup_revolutions, phase, y0, options, backend)
    except MapFailure as failure:
        return _failed(model, np.full(2, np.nan), periods, phase, str(failure))
    section_map = StroboscopicMap(model, periods, phase, mode, options, backend)
    found = newton(section_map, jacobian(section_map, scale), x0, scale, settings)
    return _orbit(section_map, found, scale)


def _failed(model, x, periods, phase, message) -> PeriodicOrbit:
    return PeriodicOrbit(x, "", periods, phase, np.empty(0, dtype=complex), None, math.inf, 0,
                         OrbitOutcome.RUN_FAILED, f"{OrbitOutcome.RUN_FAILED.message}: {message}")


def _orbit(section_map: StroboscopicMap, found: NewtonResult, scale) -> PeriodicOrbit:
    """The result of a Newton search: multipliers and verdict when it converged in one mode with
    a resolved derivative."""
    outcome, message = _verdict(section_map, found)
    d = found.derivative
    multipliers, stable = np.empty(0, dtype=complex), None
    if outcome is OrbitOutcome.CONVERGED and np.all(np.isfinite(d.jacobian)):
        multipliers = sorted_multipliers(d.jacobian)
        stable = bool(np.max(np.abs(multipliers)) < 1.0)
    provider = (d.provider, d.steps.copy(), d.note) if d is not None else ("", np.full(2, np.nan), "")
    return PeriodicOrbit(found.x.copy(), section_map.model.kernels.MODES[section_map.mode], section_map.periods,
                         section_map.phase, multipliers, stable, found.residual, found.iterations, outcome, message,
                         found.jacobian, np.asarray(scale, dtype=float).copy(),
                         found.map_evaluations + 1, found.jacobian_evaluations, section_map.mode, *provider)


def _verdict(section_map: StroboscopicMap, found: NewtonResult) -> tuple[OrbitOutcome, str]:
    """How the search ended: Newton's outcome, made MODE_CHANGED when the converged orbit ends in
    another mode, or MULTIPLIERS_UNRESOLVED when its derivative is not resolved."""
    outcome, message = found.outcome, found.outcome.message
    if found.failure:
        message = f"{message}: {found.failure}"
    if outcome is not OrbitOutcome.CONVERGED:
        return outcome, message
    end = found.derivative.end_mode
    if end is None:                          # a provider that does not say: the run once more
        end = section_map.evaluate(found.x).end_mode
    if end != section_map.mode:
        modes = section_map.model.kernels.MODES
        outcome = OrbitOutcome.MODE_CHANGED
        return outcome, f"{outcome.message} (starts in {modes[section_map.mode]!r}, ends in {modes[end]!r})"
    if not found.derivative.resolved:
        outcome = OrbitOutcome.MULTIPLIERS_UNRESOLVED
        return outcome, f"{outcome.message}: {found.derivative.note}"
    return outcome, message


def sorted_multipliers(J: np.ndarray) -> np.ndarray:
    """The eigenvalues of a monodromy matrix J, complex, by decreasing modulus: the Floquet
    multipliers as every result reports them."""
    mu = np.linalg.eigvals(J).astype(complex)
    return mu[np.argsort(-np.abs(mu))]
