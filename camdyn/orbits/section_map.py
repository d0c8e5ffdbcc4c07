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

A *Jacobian provider* gives P_n(x) and dP_n/dx at x as a :class:`MapDerivative`, which says
how it was obtained and whether it is resolved: :func:`camdyn.orbits.derivatives.finite_differences`
by central differences of the map (under the rule of :mod:`camdyn.orbits.derivatives`),
:func:`camdyn.orbits.tangent.variational` by the variational equations with saltation matrices.  A
caller that has just run the map at x (the continuation's corrector) passes that
:class:`MapValue` to :func:`derivative_at`, so that the finite differences do not run it again.
"""
from __future__ import annotations

import functools
import math
from dataclasses import dataclass, field
from typing import Protocol

import numpy as np

from ..engine import MAP_OPTIONS, Domain, SolverOptions, Trajectory, integrate
from ..errors import CamdynError, ParameterError
from .._checks import integer, real
from ..model.model import Model
from ..runs.pieces import integrate_in_pieces

#: the map's default solver tolerances (camdyn.engine.config.MAP_OPTIONS: rtol 1e-10, atol 1e-13)
DEFAULT_OPTIONS = MAP_OPTIONS
#: at most this many cam periods per map evaluation: the engine is called once, in its own
#: time, which stays below 2 x 100 kernel periods (camdyn.runs.pieces integrates longer runs in pieces)
MAX_PERIODS = 100


def warm_up(model: Model, t_end: float, y0, t_eval, options: SolverOptions = DEFAULT_OPTIONS,
            backend: str = "compiled") -> Trajectory:
    """The run every periodic analysis starts from: ``model`` from ``y0`` (None: the static
    equilibrium) at t = 0 to ``t_end``, in pieces (:mod:`camdyn.runs.pieces`), sampled at ``t_eval``
    (ending at t_end).  Raises :class:`MapFailure` when it fails."""
    y0 = model.static_state() if y0 is None else np.asarray(y0, dtype=float)
    run = functools.partial(integrate, backend=backend)
    tr = integrate_in_pieces(run, model, (0.0, t_end), y0, np.asarray(t_eval, dtype=float), options)
    if not tr.outcome.ok or tr.t.size != len(t_eval):
        raise MapFailure(f"the warm-up run failed: {tr.outcome.message}", tr.outcome)
    return tr


class MapFailure(CamdynError):
    """The map could not be evaluated at a state: the run failed (``outcome`` is the engine's
    :class:`~camdyn.Outcome`), or the state is outside the given mode's domain (``outcome`` None)."""

    def __init__(self, message: str, outcome=None):
        super().__init__(message)
        self.outcome = outcome


@dataclass(frozen=True)
class MapValue:
    """One evaluation of P_n: the state after n periods, the modes at the start and the end,
    the engine's step count, and the hybrid path the run took: the index of each transition of
    the automaton it made, in order (the rule of :mod:`camdyn.orbits.derivatives` compares them)."""

    state: np.ndarray
    start_mode: int
    end_mode: int
    steps: int
    transitions: tuple = ()


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
            raise ParameterError("model", None, "a periodic cam motion (a nonzero speed, or a period)",
                                 problem=f"{model.cam!r} has no period")
        integer("periods", periods, f"an integer, 1 <= periods <= {MAX_PERIODS}", lambda n: 1 <= n <= MAX_PERIODS)
        real("phase", phase, f"0 <= phase < T = {T:.6g} s", lambda v: 0.0 <= v < T)
        modes = model.kernels.MODES
        if mode is not None:
            integer("mode", mode, f"None or an index into the scene's MODES {modes}", lambda n: 0 <= n < len(modes))
        if not isinstance(options, SolverOptions):
            raise ParameterError("options", options, "a camdyn.engine.SolverOptions")
        self.model, self.periods, self.phase = model, int(periods), float(phase)
        self.mode = None if mode is None else int(mode)
        self.options, self.backend = options, backend
        self._domain = Domain(model)

    @property
    def t_span(self) -> tuple[float, float]:
        """(t0, t0 + n T) in s."""
        return self.phase, self.phase + self.periods * self.model.period

    def start_mode(self, x) -> int:
        """The mode a run from ``x`` starts in: the given mode (refused outside its domain), or
        the automaton's initial rule's choice."""
        t0, (a, ad) = self.phase, map(float, x)
        if self.mode is None:
            return self._domain.initial_mode(t0, a, ad)
        s = self._surface_crossed(x)
        if s >= 0:
            raise MapFailure(f"the state {tuple(map(float, x))} is across surface {self._domain.surfaces[s]!r} of "
                             f"mode {self._domain.modes[self.mode]!r} at the section: outside the mode's domain")
        return self.mode

    def _surface_crossed(self, x) -> int:
        """The surface of the given mode's domain that ``x`` is across at the section, else -1."""
        return self._domain.surface_crossed(self.mode, self.phase, float(x[0]), float(x[1]))

    def admits(self, x) -> bool:
        """Whether a run can start from ``x``: it is in the given mode's domain at the section
        (always, when the automaton's initial rule chooses the mode).  No run is made."""
        return self.mode is None or self._surface_crossed(x) < 0

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
        return MapValue(tr.y[:2, -1].copy(), m, int(tr.end_mode), int(tr.stats["steps"]),
                        tuple(tr.switches.records["transition"].tolist())), tr

    def __call__(self, x) -> np.ndarray:
        """P_n(x), the state after n periods."""
        return self.evaluate(x).state


@dataclass(frozen=True)
class MapDerivative:
    """P_n(x) and dP_n/dx at x, and how they were obtained.

    ``provider``: ``"finite_differences"``, ``"variational"`` or a caller's provider's name;
    ``steps``: the central-difference step of each column (rad, rad/s; NaN for a derivative not
    taken by differences); ``resolved``: False when the finite differences could not be resolved
    and no fallback could (``jacobian`` is then a secant across the largest step that ran: a
    direction for Newton's method, not for multipliers); ``note``: why, or which fallback was taken;
    ``end_mode``: the mode the run from x ends in, where the provider ran it (else None)."""

    value: np.ndarray
    jacobian: np.ndarray
    provider: str
    steps: np.ndarray = field(default_factory=lambda: np.full(2, np.nan))
    resolved: bool = True
    note: str = ""
    end_mode: int | None = None


class JacobianProvider(Protocol):
    """What a provider is: ``derivative(x, base)`` gives the :class:`MapDerivative` at x; ``base``
    is the map's value at x when the caller has run it (a provider may then skip that run).  A
    plain callable ``x -> (P(x), dP/dx)`` is accepted too (:func:`derivative_at`)."""

    def derivative(self, x: np.ndarray, base: MapValue | None = None) -> MapDerivative: ...


def derivative_at(provider, x, base: MapValue | None = None) -> MapDerivative:
    """The derivative of ``provider`` at x.  A provider with a ``derivative`` method is asked for
    it (told ``base``); a plain callable ``x -> (P, J)`` is called with x and its result taken as
    given, its name as ``provider`` and a note that nothing checked it."""
    x = np.asarray(x, dtype=float)
    method = getattr(provider, "derivative", None)
    if method is not None:
        return method(x, base)
    P, J = provider(x)
    name = getattr(provider, "__name__", type(provider).__name__)
    return MapDerivative(np.asarray(P, dtype=float), np.asarray(J, dtype=float), name,
                         note="a provider of the caller's: its derivative is taken as given")
