"""Event location on the dense output of one compiled step: small pure ``njit`` functions.

The conventions are those of :mod:`camdyn.events` (the SciPy backend's): a crossing in
direction +1 goes from ``g < 0`` to ``g >= 0``, -1 from ``g > 0`` to ``g <= 0``; a sample
where ``g`` is exactly 0 never starts a crossing; a located time is the *far-side* end of
a bracket no wider than ``xtol * max(1, |t|)``, so the restart state is already across the
surface and a restart cannot trigger the same event again.

``surf(k, t, alpha, alpha_dot, p)`` is a compiled surface function of the flag index k
(a generated ``surface_index``); ``dirs[k]`` is the direction in which flag k's surface is
watched in the current regime, 0 for not watched.
"""
from __future__ import annotations

import math

from numba import njit

from .stepper import dense_eval

#: first_crossing's index when a surface value is not finite
NONFINITE = -2


@njit(cache=True)
def crossed(g0, g1, direction):
    """Whether g going from g0 to g1 crosses zero in direction (+1, -1, or 0 for both)."""
    up = g0 < 0.0 <= g1
    down = g0 > 0.0 >= g1
    if direction > 0:
        return up
    if direction < 0:
        return down
    return up or down


@njit(cache=True)
def surface_on_step(surf, k, tt, t, h, y0, y1, Q, p):
    """Surface k at time tt on the step's interpolant."""
    a, ad = dense_eval(tt, t, h, y0, y1, Q)
    return surf(k, tt, a, ad, p)


@njit(cache=True)
def locate(surf, k, t, h, y0, y1, Q, p, ta, tb, ga, gb, xtol):
    """Root of surface k on the interpolant in (ta, tb], returned on the far side.

    ga = g(ta) != 0 and gb = g(tb) of the other sign or 0.  Illinois false position keeps
    a bracket [lo, hi] with g(lo) on ga's side and g(hi) not; a bisection replaces any
    iteration that fails to halve the bracket.  Returns hi once hi - lo <= xtol max(1, |hi|).
    """
    if gb == 0.0:
        return tb
    lo, hi, glo, ghi = ta, tb, ga, gb
    near = 1.0 if ga > 0.0 else -1.0
    kept = 0  # +1: lo kept twice in a row, -1: hi kept twice in a row
    for _ in range(400):
        width = hi - lo
        if width <= xtol * max(1.0, abs(hi)):
            break
        tm = hi - ghi * width / (ghi - glo)
        if not (lo < tm < hi) or abs(tm - lo) < 0.05 * width or abs(hi - tm) < 0.05 * width:
            tm = 0.5 * (lo + hi)
            if not (lo < tm < hi):
                break
        g = surface_on_step(surf, k, tm, t, h, y0, y1, Q, p)
        if g == 0.0:
            return tm
        if g * near > 0.0:
            lo, glo = tm, g
            if kept == -1:
                ghi *= 0.5
            kept = -1
        else:
            hi, ghi = tm, g
            if kept == 1:
                glo *= 0.5
            kept = 1
    return hi


@njit(cache=True)
def first_crossing(surf, dirs, t0, t1, y0, y1, n0, n1, Q, p, n_interior, xtol, g_prev, g_next):
    """Earliest crossing of any watched surface over the step [t0, t1].

    Each watched g is sampled at t0 (state y), at n_interior equally spaced interior times
    (interpolant) and at t1 (state n): a micro-hop (out and back inside one step) is seen
    when a sample falls inside it.  Per surface the earliest crossing sub-interval is
    refined with :func:`locate`; the earliest time wins, ties to the lowest flag index.
    Returns (k, t): k = -1 when nothing crosses, NONFINITE when a g is not finite.
    g_prev, g_next: work arrays of length len(dirs).
    """
    h = t1 - t0
    nf = dirs.shape[0]
    for k in range(nf):
        if dirs[k] != 0:
            g_prev[k] = surf(k, t0, y0, y1, p)
    best_k = -1
    best_t = math.inf
    found = 0
    for i in range(1, n_interior + 2):
        ta = t0 + h * (i - 1) / (n_interior + 1)
        tb = t1 if i == n_interior + 1 else t0 + h * i / (n_interior + 1)
        if tb >= best_t:
            break  # a root in (ta, tb] cannot beat one already located before tb
        for k in range(nf):
            if dirs[k] == 0 or (found >> k) & 1:
                continue
            if i == n_interior + 1:
                g_next[k] = surf(k, t1, n0, n1, p)
            else:
                g_next[k] = surface_on_step(surf, k, tb, t0, h, y0, y1, Q, p)
            if not (math.isfinite(g_prev[k]) and math.isfinite(g_next[k])):
                return NONFINITE, tb
            if crossed(g_prev[k], g_next[k], dirs[k]):
                found |= 1 << k
                tk = locate(surf, k, t0, h, y0, y1, Q, p, ta, tb, g_prev[k], g_next[k], xtol)
                if tk < best_t:
                    best_k, best_t = k, tk
            g_prev[k] = g_next[k]
    return best_k, best_t


@njit(cache=True)
def left_at_start(surf, dirs, t0, t1, y0, y1, n0, n1, p):
    """A step that starts exactly on a watched surface (g = 0) and ends strictly on its
    leaving side has left the regime at its start (the rule of camdyn.integrate).
    Returns the flag index, or -1."""
    for k in range(dirs.shape[0]):
        if dirs[k] != 0 and surf(k, t0, y0, y1, p) == 0.0 and dirs[k] * surf(k, t1, n0, n1, p) > 0.0:
            return k
    return -1
