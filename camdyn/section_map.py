"""The stroboscopic (Poincare) map of a periodically driven scene, and its Jacobian providers.

The cam drives the follower with period T (T = 60 / speed_rpm at constant speed), so the state
``x = (alpha, alpha_dot)`` at the section times ``t0 + k T`` defines the map

    P_n : x(t0) -> x(t0 + n T),

run by the engine (:func:`camdyn.engine.integrate`) from ``x`` **and** a mode of the scene's
hybrid automaton.  The mode is either given (the mode the orbit is in at the section, e.g.
the end mode of a warm-up run), or chosen from ``x`` by the automaton's own initial rule
(``INITIAL``, evaluated by :func:`camdyn.engine.rules.initial_mode`, as the engine does for a
run started without a mode).  A given mode is refused for a state outside its domain (across
a surface the mode watches, by :func:`camdyn.engine.rules.across`): the engine would integrate
the mode's law where it does not hold.

A *Jacobian provider* is any callable ``x -> (P(x), dP/dx)``; :func:`finite_differences`
makes one by central differences of the map; :func:`camdyn.tangent.variational` one by the
variational equations with saltation matrices, without change to the shooting
(:mod:`camdyn.orbits`).  A caller that has just run the map at x (the continuation's corrector)
tells the provider P(x) through :func:`jacobian_at`, so that the finite differences do not run
it again only to return it.
"""
from __future__ import annotations

import inspect
import math
from dataclasses import dataclass
from typing import Protocol

import numpy as np

from .engine.config import LOOK_AHEAD, SolverOptions
from .engine.driver import Trajectory, integrate
from .engine.kernels import python_kernels
from .engine.problem import Problem
from .engine.rules import across, initial_mode
from .engine.tables import tables
from .errors import CamdynError, ParameterError
from .model import Model

#: the map's default solver tolerances: the Newton tolerance of :mod:`camdyn.orbits` and the
#: finite-difference step below are chosen from them
DEFAULT_OPTIONS = SolverOptions(rtol=1e-10, atol=1e-13)
#: at most this many cam periods per map evaluation: the engine is called once, in its own
#: time, which stays below 2 x 100 kernel periods (camdyn.pieces integrates longer runs in pieces)
MAX_PERIODS = 100


class MapFailure(CamdynError):
    """The map could not be evaluated at a state: the run failed (``outcome`` is the engine's
    :class:`~camdyn.Outcome`), or the state is outside the given mode's domain (``outcome`` None)."""

    def __init__(self, message: str, outcome=None):
        super().__init__(message)
        self.outcome = outcome


@dataclass(frozen=True)
class MapValue:
    """One evaluation of P_n: the state after n periods, the modes at the start and the end,
    and the engine's step statistics."""

    state: np.ndarray
    start_mode: int
    end_mode: int
    steps: int


class StroboscopicMap:
    """P_n of ``model`` at the section times ``phase + k T`` (s), from a given mode or not.

    Parameters
    ----------
    model : camdyn.Model
        A scene on a rig with a periodic cam motion (period T = ``model.period``).
    periods : int
        n, the cam periods per map (1 <= n <= MAX_PERIODS).
    phase : float
        t0 (s) of the section, 0 <= phase < T.
    mode : int or None
        The mode every run starts in (an index into the scene's ``MODES``); None: the
        automaton's initial rule chooses it from each state.
    options : SolverOptions
        The engine's method and tolerances (default rtol 1e-10, atol 1e-13).
    backend : str
        ``"compiled"`` or ``"python"``, as for :func:`camdyn.simulate`.
    """

    def __init__(self, model: Model, periods: int = 1, phase: float = 0.0, mode: int | None = None,
                 options: SolverOptions = DEFAULT_OPTIONS, backend: str = "compiled"):
        T = model.period
        if not (math.isfinite(T) and T > 0):
            raise ParameterError("model", model.cam, "a periodic cam motion (a nonzero speed)")
        if isinstance(periods, bool) or not isinstance(periods, (int, np.integer)) or not 1 <= periods <= MAX_PERIODS:
            raise ParameterError("periods", periods, f"an integer, 1 <= periods <= {MAX_PERIODS}")
        if isinstance(phase, bool) or not isinstance(phase, (int, float)) or not 0.0 <= phase < T:
            raise ParameterError("phase", phase, f"0 <= phase < T = {T:.6g} s")
        modes = model.kernels.MODES
        if mode is not None and (isinstance(mode, bool) or not isinstance(mode, (int, np.integer))
                                 or not 0 <= mode < len(modes)):
            raise ParameterError("mode", mode, f"None or an index into the scene's MODES {modes}")
        if not isinstance(options, SolverOptions):
            raise ParameterError("options", options, "a camdyn.engine.SolverOptions")
        self.model, self.periods, self.phase = model, int(periods), float(phase)
        self.mode = None if mode is None else int(mode)
        self.options, self.backend = options, backend
        K = model.kernels
        self._rules = Problem(python_kernels(K), tables(K), np.ascontiguousarray(model.p, dtype=float))

    @property
    def t_span(self) -> tuple[float, float]:
        """(t0, t0 + n T) in s."""
        return self.phase, self.phase + self.periods * self.model.period

    def start_mode(self, x) -> int:
        """The mode a run from ``x`` starts in: the given mode (refused outside its domain), or
        the automaton's initial rule's choice."""
        t0, (a, ad) = self.phase, map(float, x)
        if self.mode is None:
            return int(initial_mode(self._rules, t0, a, ad, LOOK_AHEAD))
        tab = self._rules.tables
        for w in range(tab.data[tab.watch_start + self.mode], tab.data[tab.watch_start + self.mode + 1]):
            if across(self._rules, self.mode, w, t0, a, ad):
                surface = self.model.kernels.SURFACES[tab.data[tab.surface + w]]
                raise MapFailure(f"the state {tuple(map(float, x))} is across surface {surface!r} of mode "
                                 f"{self.model.kernels.MODES[self.mode]!r} at the section: outside the mode's domain")
        return self.mode

    def evaluate(self, x) -> MapValue:
        """P_n(x) with the start and end modes; raises :class:`MapFailure` when the run fails."""
        return self.run(x, np.array([self.t_span[1]]))[0]

    def run(self, x, t_eval) -> tuple[MapValue, Trajectory]:
        """P_n(x) as :meth:`evaluate` gives it, and the run's samples at ``t_eval`` (increasing,
        within :attr:`t_span`, the last at its end t0 + n T).

        The value is the last sample, the same to the bit as :meth:`evaluate`'s, which is this
        run sampled at t0 + n T alone: the engine's steps do not depend on the sample times
        (each sample is read off its step's interpolant; checked in tests/test_orbits.py).
        So a caller that needs the orbit's samples (the continuation's largest gap) and P_n(x)
        runs it once.  Raises :class:`MapFailure` when the run fails."""
        x = np.asarray(x, dtype=float)
        if x.shape != (2,) or not np.all(np.isfinite(x)):
            raise ParameterError("x", x, "two finite numbers (alpha rad, alpha_dot rad/s)")
        t0, t1 = self.t_span
        t_eval = np.asarray(t_eval, dtype=float)
        if t_eval.ndim != 1 or not t_eval.size or t_eval[0] < t0 or t_eval[-1] != t1 \
                or not (t_eval[1:] > t_eval[:-1]).all():
            raise ParameterError("t_eval", t_eval, f"increasing times in [{t0:.6g}, {t1:.6g}] s ending at {t1:.6g}")
        m = self.start_mode(x)
        tr = integrate(self.model, (t0, t1), x, t_eval, self.options, mode=m, backend=self.backend)
        if not tr.outcome.ok or tr.t.size != t_eval.size:
            raise MapFailure(f"the run from {tuple(map(float, x))} over {self.periods} period(s) failed: "
                             f"{tr.outcome.message}", tr.outcome)
        return MapValue(tr.y[:2, -1].copy(), m, int(tr.end_mode), int(tr.stats["steps"])), tr

    def __call__(self, x) -> np.ndarray:
        """P_n(x), the state after n periods."""
        return self.evaluate(x).state


class JacobianProvider(Protocol):
    """The interface of a Jacobian provider: ``x -> (P(x), dP/dx at x)``, raising
    :class:`MapFailure` where P cannot be evaluated (finite differences, or later the
    variational equations with saltation matrices).

    A provider may also take the keyword ``P``: P(x) when the caller already has it (from a
    run of the map at x it made anyway); the provider then returns that P and need not run the
    map for it.  Callers pass it through :func:`jacobian_at`, which calls a provider that does
    not take it with x alone: a provider written for ``x`` alone keeps working."""

    def __call__(self, x: np.ndarray, P: np.ndarray | None = None) -> tuple[np.ndarray, np.ndarray]: ...


def jacobian_at(provider, x, P=None) -> tuple[np.ndarray, np.ndarray]:
    """``provider(x)``, told the map's value ``P`` at x when it is known and the provider takes
    the keyword ``P`` (:class:`JacobianProvider`): :func:`finite_differences` then spares its
    base run (4 runs instead of 5); the variational provider does not take it, as its one run
    gives the switches it needs besides P."""
    if P is not None and "P" in inspect.signature(provider).parameters:
        return provider(x, P=P)
    return provider(x)


def finite_difference_steps(x, scale, rtol: float) -> np.ndarray:
    """Central-difference steps ``h_j = rtol^(1/3) * max(|x_j|, scale_j)``.

    The map's value carries an error of the order of the solver's tolerance, rtol times the
    state's scale, that is not smooth in x (the accepted steps change with x); a central
    difference with step h has truncation error O(h^2) and this noise divided by h, balanced
    at h ~ rtol^(1/3) in units of the scale (Dennis & Schnabel 1983, Sec. 5.6; Press et al.,
    Numerical Recipes, Sec. 5.7): a relative error of about rtol^(2/3) in the Jacobian.
    """
    x, scale = np.asarray(x, dtype=float), np.asarray(scale, dtype=float)
    return float(rtol) ** (1.0 / 3.0) * np.maximum(np.abs(x), scale)


def finite_differences(section_map: StroboscopicMap, scale, step_factor: float = 1.0) -> JacobianProvider:
    """A Jacobian provider by central differences of ``section_map``.

    ``scale`` (per state component: rad, rad/s) is the size of the motion, below which the
    step does not shrink (see :func:`finite_difference_steps`); ``step_factor`` multiplies every
    step (to check the Jacobian against a second step size).  Each call costs 2 n + 1 = 5 runs,
    4 when told P(x) (the keyword ``P``, :func:`jacobian_at`): the columns are central
    differences, which do not use the base run.
    """
    scale = np.asarray(scale, dtype=float)
    if scale.shape != (2,) or not np.all(np.isfinite(scale)) or not np.all(scale > 0):
        raise ParameterError("scale", scale, "two positive numbers (rad, rad/s)")
    if not (isinstance(step_factor, (int, float)) and 0 < step_factor < 1e6):
        raise ParameterError("step_factor", step_factor, "0 < step_factor < 1e6")

    def provider(x, P=None):
        x = np.asarray(x, dtype=float)
        base = section_map(x) if P is None else np.array(P, dtype=float)
        h = step_factor * finite_difference_steps(x, scale, section_map.options.rtol)
        J = np.empty((2, 2))
        for j in range(2):
            J[:, j] = _column(section_map, x, j, h[j])
        return base, J

    return provider


#: a step whose perturbed states leave the mode's domain is divided by DOMAIN_SHRINK, at most
#: DOMAIN_TRIES times (a stiff contact: the deflection is far smaller than the motion)
DOMAIN_SHRINK, DOMAIN_TRIES = 4.0, 6


def _column(section_map: StroboscopicMap, x: np.ndarray, j: int, h: float) -> np.ndarray:
    """(P(x + h e_j) - P(x - h e_j)) / 2h, the step shrunk while x +- h e_j is outside the mode."""
    for _ in range(DOMAIN_TRIES):
        e = np.zeros(2)
        e[j] = h
        try:
            return (section_map(x + e) - section_map(x - e)) / (2.0 * h)
        except MapFailure as failure:
            if failure.outcome is not None:
                raise
            h /= DOMAIN_SHRINK
    raise MapFailure(f"no finite-difference step in component {j} keeps the state in its mode "
                     f"(down to {h * DOMAIN_SHRINK:.3g})")
