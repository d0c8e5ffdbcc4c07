"""An independent integrator of a scene's hybrid automaton, for the tests: SciPy's ``solve_ivp``
with terminal events over the generated kernels, and nothing of camdyn's engine.

It reads the automaton's data (``TRANSITIONS``, ``INITIAL``) and the kernels (``rhs``,
``surface``) of a generated module and applies the rules in the plainest way: integrate the
current mode with DOP853 at tight tolerances, let ``solve_ivp`` find the first watched surface
that crosses zero in its direction (a terminal event), take its state there, enter the first
candidate whose conditions hold at that state, and start again.  No interior samples, no
excursion checks, no restart from a step of the method, no far-side placement: it is meant to
be checked against on runs where those refinements do not decide anything (no grazing).
"""
from __future__ import annotations

from dataclasses import dataclass

import numpy as np
from scipy.integrate import solve_ivp


@dataclass(frozen=True)
class OracleSwitch:
    t: float
    surface: str
    before: str
    after: str
    alpha: float
    alpha_dot: float


def _holds(K, p, mode, conditions, t, y) -> bool:
    for s, sign in conditions:
        g = K.surface(mode, s, t, y[0], y[1], p)
        if g == 0.0:  # on the surface: where the motion goes next
            h = 1e-9 * max(1.0, abs(t))
            g = K.surface(mode, s, t + h, y[0] + h * y[1], y[1], p)
        if sign * g < 0:
            return False
    return True


def _target(K, p, candidates, t, y) -> int:
    for mode, conditions in candidates:
        if _holds(K, p, mode, conditions, t, y):
            return mode
    return candidates[-1][0]


def _event(K, p, mode, surface, direction):
    def g(t, y):
        return K.surface(mode, surface, t, y[0], y[1], p)
    g.terminal, g.direction = True, direction
    return g


def run(K, p, t_span, y0, max_step, rtol=1e-12, atol=1e-15, max_switches=100_000):
    """Integrate from y0 over t_span; (switches, t_end, y_end, outcome) with ``outcome`` "SUCCESS",
    "MAX" (too many switches) or the solver's message.

    ``max_step`` (s) must be short against the shortest excursion to resolve: solve_ivp checks an
    event's sign at step ends only, so a contact shorter than a step would go unseen (free flight
    allows long steps; take a fraction of the contact mode's period)."""
    t, t_end = map(float, t_span)
    y = np.asarray(y0, dtype=float)
    mode = _target(K, p, K.INITIAL, t, y)
    switches: list[OracleSwitch] = []
    while t < t_end:
        watched = [tr for tr in K.TRANSITIONS if tr[0] == mode]
        events = [_event(K, p, mode, tr[1], tr[2]) for tr in watched]
        sol = solve_ivp(lambda tt, yy: [yy[1], K.rhs(mode, tt, yy[0], yy[1], p)], (t, t_end), y,
                        method="DOP853", rtol=rtol, atol=atol, max_step=max_step, events=events or None)
        if sol.status == -1:
            return switches, t, y, sol.message
        if sol.status == 0:
            return switches, t_end, sol.y[:, -1], "SUCCESS"
        hit = next(i for i, te in enumerate(sol.t_events) if te.size)
        t, y = float(sol.t_events[hit][0]), sol.y_events[hit][0].copy()
        tr = watched[hit]
        new = _target(K, p, tr[3], t, y)
        switches.append(OracleSwitch(t, K.SURFACES[tr[1]], K.MODES[mode], K.MODES[new], float(y[0]), float(y[1])))
        mode = new
        if len(switches) >= max_switches:
            return switches, t, y, "MAX"
    return switches, t, y, "SUCCESS"
