"""Hybrid integration with SciPy's Runge-Kutta and implicit steppers: the accuracy reference.

The loop steps a SciPy ``OdeSolver`` of the active regime (:mod:`camdyn.hybrid`) one
step at a time, checks the regime's switching surfaces on the step's dense output
(:mod:`camdyn.events`), and on a crossing stops at the located time on the far side of
the surface, asks the hybrid model for the next regime, and restarts the solver there.
Restarting on the far side, with each surface watched only in the direction that
leaves the current regime, keeps a restart from triggering itself again.
"""
from __future__ import annotations

import dataclasses
import math
from dataclasses import dataclass, field

import numpy as np
from scipy.integrate import BDF, DOP853, LSODA, RK23, RK45, Radau

from .errors import ParameterError
from .events import CROSSING_RETRIES, Crossing, EventSettings, first_crossing
from .hybrid import Hybrid
from .model import ANGLE_LIMIT, Model
from .outcome import Outcome

METHODS = {"DOP853": DOP853, "RK45": RK45, "RK23": RK23, "Radau": Radau, "BDF": BDF, "LSODA": LSODA}
_IMPLICIT = {"Radau", "BDF", "LSODA"}
_EXPLICIT = (DOP853, RK45, RK23)
#: this many switches with no progress in time (relative 1e-9) is chatter, not dynamics
CHATTER_SWITCHES = 20


@dataclass(frozen=True)
class SolverOptions:
    """Tolerances and method of the SciPy backend (rtol, atol as in ``solve_ivp``)."""

    method: str = "DOP853"
    rtol: float = 1e-8
    atol: float = 1e-12
    max_step: float = math.inf
    events: EventSettings = field(default_factory=EventSettings)
    ledger: bool = False   # integrate the work of the drive, contact damping and friction

    def __post_init__(self):
        if self.method not in METHODS:
            raise ParameterError("method", self.method, f"one of {sorted(METHODS)}")
        if isinstance(self.rtol, bool) or not (isinstance(self.rtol, (int, float)) and 1e-14 <= self.rtol <= 1e-2):
            raise ParameterError("rtol", self.rtol, "1e-14 <= rtol <= 1e-2")
        if isinstance(self.atol, bool) or not (isinstance(self.atol, (int, float)) and 0 < self.atol <= 1e-2):
            raise ParameterError("atol", self.atol, "0 < atol <= 1e-2")
        if isinstance(self.max_step, bool) or not (isinstance(self.max_step, (int, float)) and self.max_step > 0):
            raise ParameterError("max_step", self.max_step, "max_step > 0 (s)")


@dataclass(frozen=True)
class Switch:
    """One regime switch: when, which surface, between which regimes, and the state there."""

    t: float
    surface: str
    before: str
    after: str
    alpha: float
    alpha_dot: float


@dataclass
class Trajectory:
    """Samples of the state, with the regime active at each sample."""

    t: np.ndarray
    y: np.ndarray            # shape (2, n): alpha, alpha_dot (5, n with the ledger: + W_in, W_c, W_f)
    regime: np.ndarray       # regime names, one per sample
    keys: dict               # regime name -> discrete-state key
    switches: list[Switch]
    outcome: Outcome
    stats: dict


def _left_the_surface(events, t0, y0, t1, y1) -> Crossing | None:
    """A step that starts exactly on a watched surface (g = 0: a restart at a root located
    exactly, or a start on it) and ends strictly on the leaving side has left the regime at
    its start.  ``first_crossing`` does not count g0 = 0 as a crossing, so that a restart
    cannot re-trigger itself; this catches the genuine case.  The switch happens at t0,
    before any sample of the step is kept.
    """
    for index, ev in enumerate(events):
        if ev.fn(t0, y0) == 0 and ev.direction * ev.fn(t1, y1) > 0:
            return Crossing(ev, index, t0, np.array(y0, dtype=float))
    return None


class _Sampler:
    """Collects the samples t_eval that fall in each accepted piece of the trajectory."""

    def __init__(self, t_eval: np.ndarray, rows: int):
        self.t_eval, self.next, self.rows = t_eval, 0, rows
        self.t, self.y, self.names = [], [], []

    def take(self, dense, t_stop: float, name: str):
        hi = np.searchsorted(self.t_eval, t_stop, side="right")
        if hi > self.next:
            block = self.t_eval[self.next:hi]
            self.t.append(block)
            self.y.append(dense(block))
            self.names.append(np.full(block.size, name, dtype=object))
            self.next = hi

    def arrays(self):
        if not self.t:
            return np.empty(0), np.empty((self.rows, 0)), np.empty(0, dtype=object)
        return np.concatenate(self.t), np.concatenate(self.y, axis=1), np.concatenate(self.names)


def _rk_state(solver, fun, t: float, y: np.ndarray, f: np.ndarray, h: float) -> np.ndarray:
    """One step of size h of the solver's explicit Runge-Kutta tableau from (t, y), f = fun(t, y)."""
    K = np.empty((solver.n_stages, y.size))
    K[0] = f
    for s in range(1, solver.n_stages):
        K[s] = fun(t + solver.C[s] * h, y + h * (K[:s].T @ solver.A[s, :s]))
    return y + h * (K.T @ solver.B)


def _state_at_crossing(crossing: Crossing, solver, fun, t0: float, y0: np.ndarray, f0: np.ndarray):
    """The state at a crossing located inside an explicit Runge-Kutta step from (t0, y0): one
    step of the method of size crossing.t - t0, not the interpolant (whose error, an order
    lower and larger at loose tolerances, would be carried into the next regime at every
    switch).  Returns (state, across): across is False when that state is not yet across the
    surface -- the interpolant's error put the root early -- and the run may go on in the same
    regime from there (up to CROSSING_RETRIES steps in a row; then integrate() takes the
    interpolant's state, across by construction).  A state that is not finite gives the interpolant's.
    camdyn.compiled.engine.state_at_crossing is the compiled twin."""
    y = _rk_state(solver, fun, t0, y0, f0, crossing.t - t0)
    g, direction = crossing.event.fn(crossing.t, y), crossing.event.direction
    if not (np.all(np.isfinite(y)) and math.isfinite(g)):
        return crossing.y, True  # unusable: the interpolant's state, across by construction
    if direction == 0:
        g0 = crossing.event.fn(t0, y0)
        return y, g0 == 0 or g * g0 <= 0
    return y, direction * g >= 0


def _solver(options: SolverOptions, regime, t, y, t_end, h):
    kwargs = dict(rtol=options.rtol, atol=options.atol, max_step=options.max_step)
    if options.method in _IMPLICIT:
        kwargs["jac"] = regime.jac
    if h is not None and options.method != "LSODA":
        kwargs["first_step"] = min(h, t_end - t)
    return METHODS[options.method](regime.fun, t, y, t_end, **kwargs)


def integrate(model: Model, t_span: tuple[float, float], y0, t_eval: np.ndarray,
              options: SolverOptions = SolverOptions(), key: tuple | None = None) -> Trajectory:
    """Integrate the hybrid model from y0 = (alpha, alpha_dot) over t_span, sampling at t_eval.

    ``key``: the regime to start in (a Trajectory's ``keys`` value, to continue a run);
    by default it is read off the state's side of each switching surface."""
    t, t_end = map(float, t_span)
    y = np.asarray(y0, dtype=float)
    if options.ledger:
        y = np.concatenate([y, np.zeros(3)])
    hybrid = Hybrid(model)
    key = hybrid.initial(t, y) if key is None else key
    sampler = _Sampler(np.asarray(t_eval, dtype=float), y.size)
    switches: list[Switch] = []
    keys: dict[str, tuple] = {}
    stats = {"nfev": 0, "njev": 0, "steps": 0}
    outcome, h, recent = Outcome.SUCCESS, None, []
    retries = 0  # steps in a row that ended short of a crossing their interpolant placed early
    contact_time_scale = 0.1 / model.equilibrium.vartheta  # s: a tenth of a radian of the contact mode

    while t < t_end and outcome is Outcome.SUCCESS:
        regime = hybrid.regime(key, options.ledger)
        keys[regime.name] = key
        if h is not None and switches and switches[-1].before == "free":
            h = min(h, contact_time_scale)  # a free-flight step would blow up the stiff contact
        solver = _solver(options, regime, t, y, t_end, h)
        crossing = not_yet = None
        explicit = isinstance(solver, _EXPLICIT)
        while solver.status == "running":
            f_old = solver.f if explicit else None
            solver.step()
            if solver.status == "failed":
                outcome = Outcome.STEP_FAILED
                break
            stats["steps"] += 1
            t_old, t_new, y_new = solver.t_old, solver.t, solver.y
            if not np.all(np.isfinite(y_new)):
                outcome = Outcome.NONFINITE
                break
            dense = solver.dense_output()
            if regime.events:
                crossing = (first_crossing(regime.events, dense, t_old, t_new, y, y_new, options.events)
                            or _left_the_surface(regime.events, t_old, y, t_new, y_new))
            if crossing and explicit and t_old < crossing.t < t_new:
                y_cross, across = _state_at_crossing(crossing, solver, regime.fun, t_old, y, f_old)
                stats["nfev"] += solver.n_stages - 1
                if across:
                    crossing = dataclasses.replace(crossing, y=y_cross)
                elif retries < CROSSING_RETRIES:
                    crossing, not_yet = None, (crossing.t, y_cross)
            retries = retries + 1 if not_yet else 0
            sampler.take(dense, crossing.t if crossing else not_yet[0] if not_yet else t_new, regime.name)
            h = abs(t_new - t_old)
            if crossing or not_yet:
                break
            t, y = t_new, y_new
            if abs(y[0]) > ANGLE_LIMIT:
                outcome = Outcome.ANGLE_LIMIT
                break
        stats["nfev"] += solver.nfev
        stats["njev"] += getattr(solver, "njev", 0)
        if not_yet and outcome is Outcome.SUCCESS:  # not across yet: the same regime from there
            t, y = not_yet
        elif crossing and outcome is Outcome.SUCCESS:
            t, y = crossing.t, np.asarray(crossing.y, dtype=float)
            key = hybrid.after(key, crossing.event.name, t, y)
            switches.append(Switch(t, crossing.event.name, regime.name, hybrid.name(key),
                                   float(y[0]), float(y[1])))
            recent = [s for s in recent if t - s < 1e-9 * max(1.0, abs(t))] + [t]
            if len(switches) >= options.events.max_events:
                outcome = Outcome.MAX_EVENTS
            elif len(recent) > CHATTER_SWITCHES:
                outcome = Outcome.CHATTER
        elif solver.status == "finished":
            t = t_end
    t_all, y_all, names = sampler.arrays()
    stats["switches"] = len(switches)
    stats["backend"] = "scipy"
    return Trajectory(t_all, y_all, names, keys, switches, outcome, stats)
