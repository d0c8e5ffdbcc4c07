"""Event detection on the dense output of one accepted integration step.

Modelled on SciPy's ``scipy/integrate/_ivp/ivp.py`` (``find_active_events``,
``solve_event_equation``, ``handle_events``), recast as pure functions. The
hybrid integrator calls :func:`first_crossing` once per accepted step.

Conventions
-----------
*Direction.* An event ``g(t, y) = 0`` with ``direction=+1`` fires only on an
upward crossing (``g < 0`` to ``g >= 0``), ``-1`` only on a downward one
(``g > 0`` to ``g <= 0``), ``0`` on either. A sample where ``g`` is exactly 0
never *starts* a crossing: the integrator restarts each regime on the surface
(``g = 0`` or tiny on the new side), and that must not re-trigger the event.

*Far-side root.* A located event time is the end of the final root bracket
that lies on the far side of the surface: ``g(t)`` has the sign of ``g`` at
the end of the step (or is 0), and ``t`` is within ``xtol * max(1, |t|)`` of a
root. The state ``dense(t)`` is therefore already across the surface, and
``t`` is strictly later than the step start, so the integrator always
progresses.
"""
from __future__ import annotations

from dataclasses import dataclass
from typing import Callable, Sequence

import numpy as np
from scipy.optimize import brentq

__all__ = ["Event", "EventSettings", "Crossing", "crossed", "locate", "first_crossing"]

_EPS = float(np.finfo(float).eps)


@dataclass(frozen=True)
class Event:
    """A switching surface ``g(t, y) = 0`` watched during one regime.

    ``direction``: +1 fires only on crossings from ``g < 0`` to ``g >= 0``,
    -1 only from ``g > 0`` to ``g <= 0``, 0 on both.
    ``rate``: optionally dg/dt(t, y).  With it, a sub-interval whose ends are on
    the same side but where the rate changes sign is searched for its extremum,
    so an excursion across the surface and back between two samples (a hop
    shorter than the sample spacing) is still found.
    """

    name: str
    fn: Callable[[float, np.ndarray], float]
    direction: int = 0
    rate: Callable[[float, np.ndarray], float] | None = None

    def __post_init__(self) -> None:
        if not callable(self.fn):
            raise TypeError(f"Event {self.name!r}: fn must be callable, got {type(self.fn).__name__}")
        if self.rate is not None and not callable(self.rate):
            raise TypeError(f"Event {self.name!r}: rate must be callable or None")
        if isinstance(self.direction, bool) or self.direction not in (-1, 0, 1):
            raise ValueError(
                f"Event {self.name!r}: direction must be one of {{-1, 0, +1}}, got {self.direction!r}"
            )


@dataclass(frozen=True)
class EventSettings:
    """Tolerances of event location.

    ``xtol``: relative time tolerance of a located root,
    ``|t_found - t_root| <= xtol * max(1, |t|)``; valid range ``[4*eps, 1)``.
    ``interior_points``: equally spaced samples of ``g`` inside each step in
    addition to its ends, so a double crossing within one step (a micro-hop:
    out and back) is still seen when a sample falls inside it; ``>= 0``.
    ``max_events``: cap on the number of events of one simulation (enforced
    by the integrator); ``>= 1``.
    """

    xtol: float = 1e-14
    interior_points: int = 3
    max_events: int = 1_000_000

    def __post_init__(self) -> None:
        if not (4 * _EPS <= self.xtol < 1):  # also rejects NaN
            raise ValueError(f"xtol must satisfy 4*eps = {4 * _EPS:.3g} <= xtol < 1, got {self.xtol!r}")
        for name, low in (("interior_points", 0), ("max_events", 1)):
            value = getattr(self, name)
            if isinstance(value, bool) or not isinstance(value, (int, np.integer)) or value < low:
                raise ValueError(f"{name} must be an integer >= {low}, got {value!r}")


#: steps in a row that may end short of a crossing their interpolant placed early, when one
#: step of the method to the located time is not yet across the surface (both backends:
#: camdyn.integrate, camdyn.compiled.engine); with 100, tests/test_bad_input.py ran for over
#: 10 minutes instead of 30 s
CROSSING_RETRIES = 1


@dataclass(frozen=True, eq=False)
class Crossing:
    """The earliest event crossing of a step.

    ``index`` is the position of ``event`` in the sequence passed to
    :func:`first_crossing`; ``t`` is the far-side root time and ``y`` the
    state there (``dense(t)``, or exactly the step's ``y1`` when ``t == t1``).
    """

    event: Event
    index: int
    t: float
    y: np.ndarray


def crossed(g0: float, g1: float, direction: int) -> bool:
    """Whether ``g`` going from ``g0`` to ``g1`` crosses zero in ``direction``.

    Upward (+1): ``g0 < 0 <= g1``; downward (-1): ``g0 > 0 >= g1``; 0: either.
    ``g0 == 0`` is never a crossing start; NaN never crosses.
    """
    up = g0 < 0 <= g1
    down = g0 > 0 >= g1
    if direction > 0:
        return up
    if direction < 0:
        return down
    return up or down


def locate(
    g: Callable[[float], float], ta: float, tb: float, ga: float, gb: float, xtol: float
) -> float:
    """Root of ``g`` in ``(ta, tb]``, returned on the far side of the surface.

    ``ga = g(ta)`` must be nonzero and ``gb = g(tb)`` of the opposite sign or 0;
    these values are used as given for the end points (the caller's exact step
    ends), ``g`` is called only strictly inside. The result ``t`` satisfies
    ``sign(g(t)) != sign(ga)`` (i.e. ``g(t)`` has the sign of ``gb`` or is 0)
    and lies within ``xtol * max(1, |t|)`` of a sign change of ``g``.
    """
    if not (ta < tb):
        raise ValueError(f"locate needs ta < tb, got ta={ta!r}, tb={tb!r}")
    if not (ga != 0 and ga * gb <= 0):
        raise ValueError(f"locate needs ga != 0 and gb of opposite sign or 0, got ga={ga!r}, gb={gb!r}")
    if gb == 0:
        return float(tb)

    near = np.sign(ga)

    def f(t: float) -> float:
        return ga if t == ta else gb if t == tb else float(g(t))

    def tol(t: float) -> float:
        return xtol * max(1.0, abs(t))

    # brentq can stall on a flat (multiple) root; its best estimate is still
    # a good start for the bracket refinement below, so don't raise.
    r, _ = brentq(f, ta, tb, xtol=xtol, rtol=max(xtol, 4 * _EPS), full_output=True, disp=False)
    fr = f(r)
    if fr == 0:
        return float(r)
    # Rebuild a bracket [lo, hi] with g(lo) on the near side and g(hi) not,
    # stepping away from r by doubling steps (brentq's own bracket is ~tol wide).
    step = tol(r)
    if fr * near > 0:
        lo, hi = r, min(r + step, tb)
        while f(hi) * near > 0:
            lo, step = hi, 2 * step
            hi = min(hi + step, tb)
    else:
        lo, hi = max(r - step, ta), r
        while f(lo) * near <= 0:
            hi, step = lo, 2 * step
            lo = max(lo - step, ta)
    # Bisect to tolerance, keeping the far-side end.
    while hi - lo > tol(hi):
        mid = 0.5 * (lo + hi)
        if not lo < mid < hi:
            break
        if f(mid) * near > 0:
            lo = mid
        else:
            hi = mid
    return float(hi)


def _extremum(event: Event, dense, ta: float, tb: float) -> tuple[float, float]:
    """(t, g) where the rate of ``g`` changes sign in (ta, tb), on the interpolant."""
    t_ext, _ = brentq(lambda s: event.rate(s, dense(s)), ta, tb, xtol=1e-15 * max(1.0, abs(tb)),
                      maxiter=100, full_output=True, disp=False)
    return t_ext, float(event.fn(t_ext, dense(t_ext)))


def _hidden_excursion(event: Event, dense, ta: float, tb: float, ga: float, ra: float, rb: float):
    """(t_ext, ga, g_ext) if g crosses the surface and comes back inside (ta, tb), else None.

    Both ends lie on the watched side (no sign change).  If the rate turns from moving
    towards the surface to moving away (a maximum for an upward watch, a minimum for a
    downward one), the extremum is located on the interpolant; when g there is across
    the surface, [ta, t_ext] brackets the first crossing.
    """
    up = event.direction >= 0 and ga < 0 and ra > 0 > rb
    down = event.direction <= 0 and ga > 0 and ra < 0 < rb
    if not (up or down):
        return None
    t_ext, g_ext = _extremum(event, dense, ta, tb)
    if (up and g_ext >= 0) or (down and g_ext <= 0):
        return t_ext, ga, g_ext
    return None


def _turned_back(event: Event, dense, ta: float, tb: float, ga: float, gb: float, ra: float, rb: float):
    """The bracket of a sign change of ``g`` over (ta, tb] whose start moves *away* from the
    watched direction (rate * direction < 0): (ta, tb, ga, gb) unchanged otherwise.

    Moving away, g can reach the surface only after turning (a maximum of g for a downward
    watch): the sign change lies after the turn, in [t_ext, tb].  If the rate never turns,
    the "crossing" is rounding noise -- a restart just across a surface, where g is ~1e-19 m
    and the time's rounding alone moves it by more -- and there is none (None).
    """
    if ra * event.direction >= 0:
        return ta, tb, ga, gb
    if rb * event.direction < 0:
        return None
    t_ext, g_ext = _extremum(event, dense, ta, tb)
    if g_ext * event.direction < 0:  # still on the near side at the turn: the crossing follows it
        return t_ext, tb, g_ext, gb
    return ta, tb, ga, gb


def first_crossing(
    events: Sequence[Event],
    dense: Callable[[float], np.ndarray],
    t0: float,
    t1: float,
    y0: np.ndarray,
    y1: np.ndarray,
    settings: EventSettings,
) -> Crossing | None:
    """Earliest crossing of any event over the step ``[t0, t1]`` (``t1 > t0``).

    Each ``g`` is sampled at ``t0`` (with ``y0``), at
    ``settings.interior_points`` equally spaced interior times (with
    ``dense``) and at ``t1`` (with ``y1``). For each event the earliest
    sampled sub-interval that crosses in the event's direction is refined
    with :func:`locate` on the interpolant (for an event with a rate, after the
    turn if the sub-interval starts moving away, see :func:`_turned_back`). The earliest located time over
    all events wins; ties go to the lowest index. Returns None if no event
    crosses. A double crossing between two adjacent samples is invisible.
    """
    n = settings.interior_points
    times = [t0] + [t0 + (t1 - t0) * k / (n + 1) for k in range(1, n + 1)] + [t1]
    states = [y0] + [dense(t) for t in times[1:-1]] + [y1]

    candidates = []  # (ta, index, tb, ga, gb)
    for index, event in enumerate(events):
        g = [float(event.fn(t, y)) for t, y in zip(times, states)]
        if not np.all(np.isfinite(g)):
            raise ValueError(f"event {event.name!r}: g is not finite at samples {times} (values {g})")
        rates = [float(event.rate(t, y)) for t, y in zip(times, states)] if event.rate else None
        for k in range(n + 1):
            if crossed(g[k], g[k + 1], event.direction):
                bracket = (times[k], times[k + 1], g[k], g[k + 1])
                if rates is not None:
                    bracket = _turned_back(event, dense, *bracket, rates[k], rates[k + 1])
                    if bracket is None:  # rounding noise at a restart, not a crossing
                        continue
                ta, tb, ga, gb = bracket
                candidates.append((ta, index, tb, ga, gb))
                break
            if rates is not None:
                hidden = _hidden_excursion(event, dense, times[k], times[k + 1], g[k], rates[k], rates[k + 1])
                if hidden is not None:
                    candidates.append((times[k], index) + hidden)
                    break

    best: tuple[float, int] | None = None
    for ta, index, tb, ga, gb in sorted(candidates, key=lambda c: (c[0], c[1])):
        if best is not None and ta >= best[0]:
            break  # its root lies in (ta, tb], so it cannot be earlier
        fn = events[index].fn
        t = locate(lambda s: fn(s, dense(s)), ta, tb, ga, gb, settings.xtol)
        if best is None or t < best[0]:
            best = (t, index)

    if best is None:
        return None
    t, index = best
    y = np.array(y1 if t == t1 else dense(t), dtype=float)
    return Crossing(event=events[index], index=index, t=t, y=y)
