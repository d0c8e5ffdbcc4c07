"""Toy automata for the engine's tests, built as a generated module would state them.

:func:`module` makes a namespace with the data a generated scene module holds (MODES,
SURFACES, TRANSITIONS, ...), so ``camdyn.engine.tables.tables`` reads it as it reads a real one;
the kernels are small Python functions (and, for compiled runs, their numba cfuncs).
"""
from __future__ import annotations

import math
from types import SimpleNamespace

import numba
import numpy as np

from camdyn.vocabulary import OUTPUTS, WITH_RATE_RATE, WITH_RATE_VALUE
from camdyn.engine.config import REACH_FACTOR, Settings
from camdyn.engine.kernels import FILL, RHS, SURFACE, SURFACE_FILL, no_fill
from camdyn.engine.problem import Kernels, Problem
from camdyn.engine.tables import tables


def module(surfaces, transitions, initial, n_modes=2, rates=None, contact=None):
    """A namespace with a generated module's automaton data.  transitions: (source, surface,
    direction, ((target, conditions), ...)); rates: {surface: its rate surface}."""
    rates = rates or {}
    return SimpleNamespace(
        MODES=tuple(f"m{i}" for i in range(n_modes)), CONTACT_OF_MODE=contact or (False,) + (True,) * (n_modes - 1),
        SURFACES=tuple(surfaces), RATE_OF_SURFACE=tuple(rates.get(s, -1) for s in range(len(surfaces))),
        RESETS=("identity",), INITIAL=initial, OUTPUTS=tuple(OUTPUTS),
        TRANSITIONS=tuple(tr + (0,) for tr in transitions))


def settings(interior_points=3, xtol=1e-14, **kw) -> Settings:
    base = dict(rtol=1e-8, atol=1e-12, max_step=math.inf, control_a=1.0, control_b=0.0, xtol=xtol,
                interior_points=interior_points,
                reach_factor=REACH_FACTOR,
                max_events=10_000, angle_limit=1e9, chatter_switches=20, chatter_window=1e-9, contact_step=0.0,
                crossing_retries=1, look_ahead=1e-9, ledger=False)
    base.update(kw)
    return Settings(**base)


def _no_outputs(m, t, a, ad, p, out):
    out[:] = 0.0


# --- a clock: the state's alpha is the time itself, surfaces are functions of it ---------------
def clock_problem(functions, directions, rates=None):
    """Mode 0 watches surface k (the function functions[k] of alpha = t) in direction
    directions[k] (None: not watched, e.g. a rate); every transition leads to mode 1.
    For the rules' tests, in Python."""
    mod = module([f"g{k}" for k in range(len(functions))],
                 [(0, k, d, ((1, ()),)) for k, d in enumerate(directions) if d is not None], ((0, ()),),
                 rates=rates)

    def surface(m, s, t, a, ad, p):
        return functions[s](a)

    def surface_with_rate(m, s, t, a, ad, p, out):
        out[WITH_RATE_VALUE], out[WITH_RATE_RATE] = functions[s](a), functions[mod.RATE_OF_SURFACE[s]](a)
    kern = Kernels(None, surface, _no_outputs, None, surface_with_rate)
    return Problem(kern, tables(mod), np.zeros(1))


def clock_step(t0, t1, scale=1.0):
    """(y0, y1, n0, n1, Q) of a step over which alpha = t (alpha_dot = 1): the interpolant's
    coefficients scaled by ``scale`` (1: exact)."""
    Q = np.zeros((2, 7))
    Q[0, 0] = scale
    return t0, 1.0, t1, 1.0, Q


# --- a bouncing point: free flight at constant acceleration, a stiff spring in contact -------------
def _toy_rhs(m, t, a, ad, p):
    """Mode 0 free: constant acceleration p0; mode 1 contact: p0 - p1 alpha; NaN above p2 in
    contact (a law undefined there: a stage overshooting into it)."""
    if m == 1 and a > p[2]:
        return math.nan
    return p[0] if m == 0 else p[0] - p[1] * a


def _toy_surface(m, s, t, a, ad, p):
    """Surface 0: the gap, alpha; surface 1: its rate, alpha_dot."""
    return a if s == 0 else ad


def _toy_surface_with_rate(m, s, t, a, ad, p, out):
    """The gap and its rate (surface 0 and 1) together."""
    out[WITH_RATE_VALUE] = a
    out[WITH_RATE_RATE] = ad


BOUNCE = module(["gap", "gap_rate"], [(0, 0, -1, ((1, ()),)), (1, 0, +1, ((0, ()),))],
                ((1, ((0, -1),)), (0, ())))
BOUNCE_WITH_RATE = module(["gap", "gap_rate"], [(0, 0, -1, ((1, ()),)), (1, 0, +1, ((0, ()),))],
                          ((1, ((0, -1),)), (0, ())), rates={0: 1})
_compiled_bounce = None


def bounce_problem(p, compiled: bool, rate: bool = False) -> Problem:
    global _compiled_bounce
    mod = BOUNCE_WITH_RATE if rate else BOUNCE
    if compiled:
        if _compiled_bounce is None:
            _compiled_bounce = Kernels(numba.cfunc(RHS)(_toy_rhs), numba.cfunc(SURFACE)(_toy_surface),
                                       numba.cfunc(FILL)(_no_outputs), no_fill,
                                       numba.cfunc(SURFACE_FILL)(_toy_surface_with_rate))
        kern = _compiled_bounce
    else:
        kern = Kernels(_toy_rhs, _toy_surface, _no_outputs, None, _toy_surface_with_rate)
    return Problem(kern, tables(mod), np.asarray(p, dtype=float))
