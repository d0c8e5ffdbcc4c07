"""Event location on the dense output of one compiled step: small pure ``njit`` functions.

The conventions are those of :mod:`camdyn.events` (the SciPy backend's): a crossing in
direction +1 goes from ``g < 0`` to ``g >= 0``, -1 from ``g > 0`` to ``g <= 0``; a sample
where ``g`` is exactly 0 never starts a crossing; a located time is the *far-side* end of
a bracket no wider than ``xtol * max(1, |t|)``, so the restart state is already across the
surface and a restart cannot trigger the same event again.

Values are read through :func:`camdyn.compiled.regimes.value` (index k: a flag's surface,
a stick mode's exit, or the gap rate); ``dirs[k]`` is the direction in which value k is
watched in the current regime, 0 for not watched.  Like the SciPy backend, the contact
surface (k = 0) is also checked for an excursion hidden between two samples: when the gap
rate turns from approaching to leaving, the extremum is located and the gap there read.
"""
from __future__ import annotations

import math

from numba import njit

from .regimes import GAP_RATE, value
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


@njit(cache=True, inline="always")
def value_on_step(fns, tab, nr, r, k, tt, t, h, y0, y1, Q, p):
    """Value k at time tt on the step's interpolant."""
    a, ad = dense_eval(tt, t, h, y0, y1, Q)
    return value(fns, tab, nr, r, k, tt, a, ad, p)


@njit(cache=True)
def locate(fns, tab, nr, r, k, t, h, y0, y1, Q, p, ta, tb, ga, gb, xtol):
    """Root of value k on the interpolant in (ta, tb], returned on the far side; and the
    number of values computed.

    ga = g(ta) != 0 and gb = g(tb) of the other sign or 0.  Illinois false position keeps
    a bracket [lo, hi] with g(lo) on ga's side and g(hi) not, halving the value of an end
    kept twice in a row.  A trial point is kept at least half the tolerance inside the
    bracket, so that when the estimate lands next to the root, the next value closes the
    bracket from the other side (Brent's rule; superlinear to the end, where pushing the
    trial point to the midpoint would fall back to bisection).  If three iterations together
    fail to halve the bracket, the next one bisects.  Returns hi once
    hi - lo <= xtol max(1, |hi|).
    """
    if gb == 0.0:
        return tb, 0
    lo, hi, glo, ghi = ta, tb, ga, gb
    near = 1.0 if ga > 0.0 else -1.0
    kept = 0  # +1: lo kept twice in a row, -1: hi kept twice in a row
    evaluations = 0
    w3, w2, w1 = math.inf, math.inf, math.inf  # the bracket's widths 3, 2 and 1 iterations ago
    for _ in range(400):
        width = hi - lo
        tol = xtol * max(1.0, abs(hi))
        if width <= tol:
            break
        if 2.0 * width > w3:
            tm = 0.5 * (lo + hi)
        else:
            tm = hi - ghi * width / (ghi - glo)
            margin = 0.5 * tol
            if not tm >= lo + margin:  # also a NaN estimate
                tm = lo + margin
            if not tm <= hi - margin:
                tm = hi - margin
        if not (lo < tm < hi):
            break
        w3, w2, w1 = w2, w1, width
        g = value_on_step(fns, tab, nr, r, k, tm, t, h, y0, y1, Q, p)
        evaluations += 1
        if g == 0.0:
            return tm, evaluations
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
    return hi, evaluations


@njit(cache=True)
def extremum(fns, tab, nr, r, t, h, y0, y1, Q, p, ta, tb, ra, rb):
    """(t, gap) where the gap rate (ra at ta, rb at tb, of opposite signs) changes sign."""
    k_rate = tab[1].shape[0] + GAP_RATE
    t_ext, _ = locate(fns, tab, nr, r, k_rate, t, h, y0, y1, Q, p, ta, tb, ra, rb, 1e-15)
    return t_ext, value_on_step(fns, tab, nr, r, 0, t_ext, t, h, y0, y1, Q, p)


@njit(cache=True)
def hidden_excursion(fns, tab, nr, r, direction, t, h, y0, y1, Q, p, ta, tb, ga, ra, rb):
    """(t_ext, g_ext) when the gap crosses its surface and comes back inside (ta, tb), else
    (-1, 0).  Both ends are on the watched side; if the rate turns from approaching the
    surface to leaving it, the extremum is located (root of the rate) and the gap read there.
    Rates exactly 0 at an end do not count as a turn (camdyn.events._hidden_excursion)."""
    up = direction >= 0 and ga < 0.0 and ra > 0.0 > rb
    down = direction <= 0 and ga > 0.0 and ra < 0.0 < rb
    if not (up or down):
        return -1.0, 0.0
    t_ext, g_ext = extremum(fns, tab, nr, r, t, h, y0, y1, Q, p, ta, tb, ra, rb)
    if (up and g_ext >= 0.0) or (down and g_ext <= 0.0):
        return t_ext, g_ext
    return -1.0, 0.0


@njit(cache=True)
def turned_back(fns, tab, nr, r, direction, t, h, y0, y1, Q, p, ta, tb, ga, ra, rb):
    """Start (t, g) of the bracket of a gap sign change over (ta, tb], and whether it is one.

    If the gap moves away from the watched direction at ta (rate * direction < 0), it can
    reach the surface only after turning: the bracket starts at the turn (the rate's root)
    when the gap is still on the near side there.  If the rate never turns, the sign change
    is rounding noise (a restart just across the surface, where the gap is ~1e-19 m and the
    time's rounding alone moves it by more): not a crossing.  camdyn.events._turned_back.
    """
    if ra * direction >= 0.0:
        return ta, ga, True
    if rb * direction < 0.0:
        return ta, ga, False
    t_ext, g_ext = extremum(fns, tab, nr, r, t, h, y0, y1, Q, p, ta, tb, ra, rb)
    if g_ext * direction < 0.0:
        return t_ext, g_ext, True
    return ta, ga, True


@njit(cache=True, inline="always")
def first_crossing(fns, tab, nr, r, dirs, t0, t1, y0, y1, n0, n1, Q, p, n_interior, xtol, rate_check,
                   rate_flag, have_start, g_prev, r_prev, g_next):
    """Earliest crossing of any watched value over the step [t0, t1].

    Each watched g is sampled at t0 (state y), at n_interior equally spaced interior times
    (interpolant) and at t1 (state n): a micro-hop (out and back inside one step) is seen
    when a sample falls inside it, and, with ``rate_check``, also between two samples from
    the turn of the gap rate (which also tells a gap sign change that is rounding noise from
    a crossing, :func:`turned_back`).  Per value the earliest crossing sub-interval is refined with
    :func:`locate`; the earliest time wins, ties to the lowest index.
    Returns (k, t): k = -1 when nothing crosses, NONFINITE when a g is not finite.

    ``rate_flag``: the flag whose surface is the gap rate itself (damping D/E), or -1: its
    value is the rate already computed for the excursion check.
    ``have_start``: g_prev (and r_prev, the gap rate) already hold the values at t0 (the
    previous step's end).  With no crossing, they hold the values at t1 on return.
    g_next is a work array.  All three have one entry per value index.
    """
    h = t1 - t0
    nv = dirs.shape[0]
    rate = rate_check and dirs[0] != 0
    if not have_start:
        for k in range(nv):
            if dirs[k] != 0:
                g_prev[k] = value(fns, tab, nr, r, k, t0, y0, y1, p)
        if rate:
            r_prev[0] = value(fns, tab, nr, r, nv - 1, t0, y0, y1, p)
    best_k = -1
    best_t = math.inf
    found = 0
    for i in range(1, n_interior + 2):
        ta = t0 + h * (i - 1) / (n_interior + 1)
        last = i == n_interior + 1
        tb = t1 if last else t0 + h * i / (n_interior + 1)
        if tb >= best_t:
            break  # a root in (ta, tb] cannot beat one already located before tb
        if last:
            a, ad = n0, n1
        else:
            a, ad = dense_eval(tb, t0, h, y0, y1, Q)
        rb_known = False
        rb = 0.0
        for k in range(nv):
            if dirs[k] == 0 or (found >> k) & 1:
                continue
            if k == rate_flag and rb_known:
                g_next[k] = rb
            else:
                g_next[k] = value(fns, tab, nr, r, k, tb, a, ad, p)
            if not (math.isfinite(g_prev[k]) and math.isfinite(g_next[k])):
                return NONFINITE, tb
            tk = -1.0
            if crossed(g_prev[k], g_next[k], dirs[k]):
                lo, glo, genuine = ta, g_prev[k], True
                if k == 0 and rate:
                    rb = value(fns, tab, nr, r, nv - 1, tb, a, ad, p)
                    rb_known = True
                    lo, glo, genuine = turned_back(fns, tab, nr, r, dirs[0], t0, h, y0, y1, Q, p, ta, tb,
                                                   g_prev[0], r_prev[0], rb)
                    r_prev[0] = rb
                if genuine:
                    tk, _ = locate(fns, tab, nr, r, k, t0, h, y0, y1, Q, p, lo, tb, glo, g_next[k], xtol)
            elif k == 0 and rate:
                rb = value(fns, tab, nr, r, nv - 1, tb, a, ad, p)
                rb_known = True
                t_ext, g_ext = hidden_excursion(fns, tab, nr, r, dirs[0], t0, h, y0, y1, Q, p, ta, tb,
                                                g_prev[0], r_prev[0], rb)
                if t_ext >= 0.0:
                    tk, _ = locate(fns, tab, nr, r, 0, t0, h, y0, y1, Q, p, ta, t_ext, g_prev[0], g_ext, xtol)
                r_prev[0] = rb
            if tk >= 0.0:
                found |= 1 << k
                if tk < best_t:
                    best_k, best_t = k, tk
            g_prev[k] = g_next[k]
    return best_k, best_t


@njit(cache=True)
def left_at_start(fns, tab, nr, r, dirs, t0, t1, y0, y1, n0, n1, p):
    """A step that starts exactly on a watched surface (g = 0) and ends strictly on its
    leaving side has left the regime at its start (the rule of camdyn.integrate).
    Returns the value index, or -1."""
    for k in range(dirs.shape[0]):
        if dirs[k] != 0 and value(fns, tab, nr, r, k, t0, y0, y1, p) == 0.0 \
                and dirs[k] * value(fns, tab, nr, r, k, t1, n0, n1, p) > 0.0:
            return k
    return -1
