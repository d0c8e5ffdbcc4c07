"""Hybrid integration with SciPy's Runge-Kutta and implicit steppers: the accuracy reference.

The loop steps a SciPy ``OdeSolver`` of the active regime one step at a time,
checks the regime's switching surfaces on the step's dense output
(:mod:`camdyn.events`), and on a crossing stops at the located time on the far
side of the surface, flips the flag, and restarts the solver in the new regime.
Restarting on the far side, with each surface watched only in the direction
that leaves the current regime, is what keeps a restart on a surface from
triggering again at once.
"""
from __future__ import annotations

import math
from dataclasses import dataclass, field

import numpy as np
from scipy.integrate import BDF, DOP853, LSODA, RK23, RK45, Radau

from .errors import ParameterError
from .events import Crossing, Event, EventSettings, first_crossing
from .model import ANGLE_LIMIT, Model
from .outcome import Outcome

METHODS = {"DOP853": DOP853, "RK45": RK45, "RK23": RK23, "Radau": Radau, "BDF": BDF, "LSODA": LSODA}
_IMPLICIT = {"Radau", "BDF", "LSODA"}


@dataclass(frozen=True)
class SolverOptions:
    """Tolerances and method of the SciPy backend (rtol, atol as in ``solve_ivp``)."""

    method: str = "DOP853"
    rtol: float = 1e-8
    atol: float = 1e-12
    max_step: float = math.inf
    events: EventSettings = field(default_factory=EventSettings)

    def __post_init__(self):
        if self.method not in METHODS:
            raise ParameterError("method", self.method, f"one of {sorted(METHODS)}")
        if not (isinstance(self.rtol, (int, float)) and 1e-14 <= self.rtol <= 1e-2):
            raise ParameterError("rtol", self.rtol, "1e-14 <= rtol <= 1e-2")
        if not (isinstance(self.atol, (int, float)) and 0 < self.atol <= 1e-2):
            raise ParameterError("atol", self.atol, "0 < atol <= 1e-2")
        if not (isinstance(self.max_step, (int, float)) and self.max_step > 0):
            raise ParameterError("max_step", self.max_step, "max_step > 0 (s)")


@dataclass(frozen=True)
class Switch:
    """One regime switch: when, which surface, between which regimes."""

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
    y: np.ndarray            # shape (2, n): alpha, alpha_dot
    regime: np.ndarray       # regime names, one per sample
    switches: list[Switch]
    outcome: Outcome
    stats: dict


class _Regimes:
    """The discrete state: flags, the regime they select, and the surfaces that end it."""

    def __init__(self, model: Model):
        self.model = model
        K = model.kernels
        self.flags = K.FLAGS
        self.surfaces = {f: (model.bind(getattr(K, K.FLAG_SURFACES[f][0])), K.FLAG_SURFACES[f][1])
                         for f in self.flags}

    def _side(self, flag, t, y, default=True) -> bool:
        """Whether the state is on the flag's side; on the surface itself, where it is heading.

        The look-ahead moves alpha by its rate over a tiny time (exact to first order for
        the gap, which depends on t and alpha only; a fair guess for the other surfaces).
        """
        g, true_sign = self.surfaces[flag]
        value = g(t, y[0], y[1])
        if value == 0:
            h = 1e-9 * max(1.0, abs(t))
            value = g(t + h, y[0] + h * y[1], y[1])
        return default if value == 0 else bool(np.sign(value) == true_sign)

    def initial(self, t, y) -> tuple:
        if not self.flags:
            return ()
        contact = self._side("contact", t, y, default=True)
        return self.entering(t, y, contact)

    def entering(self, t, y, contact: bool) -> tuple:
        """Flags when contact starts (others set from the state) or ends (others out of scope)."""
        rest = [self._side(f, t, y) if contact else None for f in self.flags[1:]]
        return (contact, *rest)

    def events(self, key: tuple) -> tuple[Event, ...]:
        out = []
        for i, f in enumerate(self.flags):
            if key[i] is None:
                continue
            g, true_sign = self.surfaces[f]
            # leaving the flag's side: from true_sign side to the other when True
            direction = -true_sign if key[i] else true_sign
            out.append(Event(f, lambda t, y, g=g: g(t, y[0], y[1]), direction))
        return tuple(out)

    def after(self, key: tuple, flag: str, t, y) -> tuple:
        i = self.flags.index(flag)
        if flag == "contact":
            return self.entering(t, y, not key[0]) if not key[0] else (False,) + (None,) * (len(key) - 1)
        return key[:i] + (not key[i],) + key[i + 1:]


def _fixed_regime(model: Model, t, y) -> tuple:
    """Linear models: sliding contact throughout; a Coulomb sign fixed by v_r at the start."""
    if len(model.regimes) == 1:
        return next(iter(model.regimes))
    v_r = model.bind(model.kernels.out_contact_fwd)(t, y[0], y[1])[6]
    return (bool(v_r >= 0),)


def _left_the_surface(events, t0, y0, t1, y1) -> Crossing | None:
    """A step that starts exactly on a watched surface (g = 0: the initial state, or a
    restart at a root located exactly) and ends strictly on the leaving side has left the
    regime at its start.  ``first_crossing`` does not count g0 = 0 as a crossing (so a
    restart cannot re-trigger itself); this catches the genuine case, e.g. a follower
    starting on the cam and moving away, which would otherwise stay in contact with a
    tensile force.  The switch happens at t0, before any sample of the step is kept.
    """
    for index, ev in enumerate(events):
        if ev.fn(t0, y0) == 0 and ev.direction * ev.fn(t1, y1) > 0:
            return Crossing(ev, index, t0, np.array(y0, dtype=float))
    return None


def integrate(model: Model, t_span: tuple[float, float], y0, t_eval: np.ndarray,
              options: SolverOptions = SolverOptions()) -> Trajectory:
    """Integrate the hybrid model from y0 = (alpha, alpha_dot) over t_span, sampling at t_eval."""
    t, t_end = map(float, t_span)
    y = np.asarray(y0, dtype=float)
    regimes = _Regimes(model)
    linear = not regimes.flags
    name_of = model.regimes
    key = _fixed_regime(model, t, y) if linear else regimes.initial(t, y)
    method = METHODS[options.method]
    ts, ys, names, switches = [], [], [], []
    t_eval = np.asarray(t_eval, dtype=float)
    next_sample = 0
    stats = {"nfev": 0, "njev": 0, "steps": 0, "rejected_restarts": 0}
    outcome = Outcome.SUCCESS
    h = None
    recent = []  # times of the last switches, to detect chatter

    while t < t_end:
        name = name_of[key]
        rhs, jac, _ = model.regime_functions(name)
        f, jf = model.bind(rhs), model.bind(jac)

        def fun(tt, yy, f=f):
            return np.array([yy[1], f(tt, yy[0], yy[1])])

        kwargs = dict(rtol=options.rtol, atol=options.atol, max_step=options.max_step)
        if options.method in _IMPLICIT:
            def jacobian(tt, yy, jf=jf):
                d0, d1 = jf(tt, yy[0], yy[1])
                return np.array([[0.0, 1.0], [d0, d1]])
            kwargs["jac"] = jacobian
        if h is not None and options.method != "LSODA":
            kwargs["first_step"] = min(h, t_end - t)
        solver = method(fun, t, y, t_end, **kwargs)
        events = () if linear else regimes.events(key)
        switched = False
        while solver.status == "running":
            message = solver.step()
            if solver.status == "failed":
                outcome = Outcome.STEP_FAILED
                break
            stats["steps"] += 1
            t_old, t_new = solver.t_old, solver.t
            y_new = solver.y
            if not np.all(np.isfinite(y_new)):
                outcome = Outcome.NONFINITE
                break
            dense = solver.dense_output()
            crossing = first_crossing(events, dense, t_old, t_new, y, y_new, options.events) if events else None
            crossing = crossing or _left_the_surface(events, t_old, y, t_new, y_new)
            t_stop = crossing.t if crossing else t_new
            hi = np.searchsorted(t_eval, t_stop, side="right")
            if hi > next_sample:
                block = t_eval[next_sample:hi]
                ts.append(block)
                ys.append(dense(block) if block.size else np.empty((2, 0)))
                names.append(np.full(block.size, name, dtype=object))
                next_sample = hi
            h = abs(t_new - t_old)
            if crossing:
                t, y = crossing.t, np.asarray(crossing.y, dtype=float)
                new_key = regimes.after(key, crossing.event.name, t, y)
                switches.append(Switch(t, crossing.event.name, name, name_of[new_key], float(y[0]), float(y[1])))
                key = new_key
                switched = True
                recent = [s for s in recent if t - s < 1e-9 * max(1.0, abs(t))] + [t]
                break
            t, y = t_new, y_new
            if abs(y[0]) > ANGLE_LIMIT:
                outcome = Outcome.ANGLE_LIMIT
                break
        stats["nfev"] += solver.nfev
        stats["njev"] += getattr(solver, "njev", 0)
        if outcome is not Outcome.SUCCESS:
            break
        if switched:
            if len(switches) >= options.events.max_events:
                outcome = Outcome.MAX_EVENTS
                break
            if len(recent) > 20:
                outcome = Outcome.CHATTER
                break
        elif solver.status == "finished":
            t = t_end
    t_all = np.concatenate(ts) if ts else np.empty(0)
    y_all = np.concatenate(ys, axis=1) if ys else np.empty((2, 0))
    r_all = np.concatenate(names) if names else np.empty(0, dtype=object)
    stats["switches"] = len(switches)
    return Trajectory(t_all, y_all, r_all, switches, outcome, stats)
