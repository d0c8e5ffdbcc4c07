"""The compiled hybrid loop: regimes, steps, events and switches all inside numba.

The discrete state is a regime index r.  Its flags come from the tables built by
:func:`camdyn.compiled.integrate.tables` from the generated ``FLAGS``, ``FLAG_SURFACES``
and ``REGIMES``: ``flags_of[r, k]`` is -1 (flag out of scope), 0 or 1; ``lookup`` maps a
flag combination (base-3 code of flag + 1) back to r; ``signs[k]`` is the sign of flag k's
surface where the flag is True.  The switching rules are those of the SciPy backend
(:mod:`camdyn.integrate`): contact starts with the other flags set from the state's side
of their surfaces (looking ahead when exactly on one), and ends with them out of scope;
every other flag just flips.

:func:`run` returns an outcome code (the position in ``OUTCOMES``), the samples written
into ``out_y``/``out_r``, the switch records and the counters.  Nothing here is global:
the rig, the cam and the tolerances arrive as arrays, so one compiled loop serves every
scene, rig and sweep point.
"""
from __future__ import annotations

import math

import numpy as np
from numba import njit

from .events import NONFINITE, first_crossing, left_at_start
from .stepper import ACCEPTED, dense_coefficients, dense_eval, initial_step, step

#: outcome codes of run(), by position: names of camdyn.outcome.Outcome members
OUTCOMES = ("SUCCESS", "STEP_FAILED", "MAX_EVENTS", "CHATTER", "NONFINITE", "ANGLE_LIMIT")
SUCCESS, STEP_FAILED, MAX_EVENTS, CHATTER, NONFINITE_STATE, ANGLE_LIMIT = range(6)
#: settings arrays: floats (rtol, atol, max_step, xtol, angle_limit, chatter_window) and
#: ints (interior_points, max_events, chatter_switches)
F_RTOL, F_ATOL, F_MAX_STEP, F_XTOL, F_ANGLE, F_CHATTER = range(6)
I_INTERIOR, I_MAX_EVENTS, I_CHATTER = range(3)
#: columns of a switch record
SWITCH_COLUMNS = ("t", "flag", "before", "after", "alpha", "alpha_dot")
#: counters returned
STATS = ("nfev", "steps", "rejected_steps")


@njit(cache=True)
def on_true_side(surf, k, sign, t, a, ad, p, default):
    """Whether the state is on the side of surface k where its flag is True; exactly on
    the surface, where it is heading (a look-ahead of alpha by its rate over 1e-9 s)."""
    g = surf(k, t, a, ad, p)
    if g == 0.0:
        h = 1e-9 * max(1.0, abs(t))
        g = surf(k, t + h, a + h * ad, ad, p)
    if g == 0.0:
        return default
    return (g > 0.0) == (sign > 0)


@njit(cache=True)
def regime_of(flags, lookup):
    code = 0
    scale = 1
    for k in range(flags.shape[0]):
        code += (flags[k] + 1) * scale
        scale *= 3
    return lookup[code]


@njit(cache=True)
def entering(surf, signs, lookup, t, a, ad, p, contact):
    """The regime when contact starts (other flags from the state) or ends (out of scope)."""
    nf = signs.shape[0]
    flags = np.full(nf, -1, dtype=np.int64)
    flags[0] = 1 if contact else 0
    if contact:
        for k in range(1, nf):
            flags[k] = 1 if on_true_side(surf, k, signs[k], t, a, ad, p, True) else 0
    return regime_of(flags, lookup)


@njit(cache=True)
def after(surf, flags_of, signs, lookup, r, k, t, a, ad, p):
    """The regime after flag k's surface is crossed in regime r."""
    if k == 0:
        return entering(surf, signs, lookup, t, a, ad, p, flags_of[r, 0] == 0)
    flags = flags_of[r].copy()
    flags[k] = 1 - flags[k]
    return regime_of(flags, lookup)


@njit(cache=True)
def watch(flags_of, signs, r, dirs):
    """Directions in which regime r watches each surface: leaving the flag's side; 0 if out of scope."""
    n = 0
    for k in range(signs.shape[0]):
        v = flags_of[r, k]
        dirs[k] = 0 if v < 0 else (-signs[k] if v == 1 else signs[k])
        n += dirs[k] != 0
    return n


@njit(cache=True)
def sample(t_eval, i, t_stop, t, h, y0, y1, Q, r, out_y, out_r):
    """Write the samples t_eval[i:] <= t_stop from the step's interpolant; the next index."""
    n = t_eval.shape[0]
    while i < n and t_eval[i] <= t_stop:
        out_y[0, i], out_y[1, i] = dense_eval(t_eval[i], t, h, y0, y1, Q)
        out_r[i] = r
        i += 1
    return i


@njit(cache=True)
def record(sw, n, t, k, before, after_r, a, ad):
    """Append a switch record, doubling the buffer when full; returns the buffer."""
    if n == sw.shape[0]:
        bigger = np.empty((2 * n, sw.shape[1]))
        bigger[:n] = sw[:n]
        sw = bigger
    sw[n, 0], sw[n, 1], sw[n, 2], sw[n, 3], sw[n, 4], sw[n, 5] = t, k, before, after_r, a, ad
    return sw


@njit(cache=True)
def chattering(sw, n, window, count):
    """More than ``count`` switches within ``window`` (relative) of the latest: no progress."""
    if n <= count:
        return False
    t = sw[n - 1, 0]
    return t - sw[n - 1 - count, 0] < window * max(1.0, abs(t))


@njit(cache=True)
def run(rhs, surf, method, p, flags_of, signs, lookup, r0, t0, t_end, y_start, t_eval, fset, iset,
        out_y, out_r):
    """Integrate the hybrid model from (t0, y_start) to t_end (see the module docstring).

    r0 >= 0 fixes the initial regime (linear models); -1 chooses it from the surfaces.
    Returns (outcome, samples written, switch records, counters [nfev, steps, rejected]).
    """
    rtol, atol, max_step, xtol = fset[F_RTOL], fset[F_ATOL], fset[F_MAX_STEP], fset[F_XTOL]
    n_int, max_events = iset[I_INTERIOR], iset[I_MAX_EVENTS]
    n, error_order = method[6], -1.0 / method[9] - 1.0
    K = np.empty((method[0].shape[0], 2))
    Q = np.empty((2, method[5].shape[1]))
    nf = signs.shape[0]
    dirs, g0, g1 = np.zeros(nf, dtype=np.int64), np.empty(nf), np.empty(nf)
    stats = np.zeros(3, dtype=np.int64)
    sw = np.empty((16, 6))
    n_sw, i_sample, outcome = 0, 0, SUCCESS
    t, y0, y1 = t0, y_start[0], y_start[1]
    r = r0 if r0 >= 0 else entering(surf, signs, lookup, t, y0, y1, p,
                                    on_true_side(surf, 0, signs[0], t, y0, y1, p, True))
    h_abs, h_last = -1.0, -1.0
    while t < t_end and outcome == SUCCESS:
        K[0, 0], K[0, 1] = y1, rhs(r, t, y0, y1, p)
        stats[0] += 1
        if h_last < 0.0:
            h_abs = initial_step(rhs, r, t, y0, y1, K[0, 1], t_end, max_step, error_order, rtol, atol, p)
            stats[0] += 1
        else:
            h_abs = min(h_last, t_end - t)
        watched = watch(flags_of, signs, r, dirs)
        while t < t_end:
            status, t_new, n0, n1, h_next, nfev, rejected = step(
                rhs, r, t, y0, y1, h_abs, t_end, method, p, K, rtol, atol, max_step)
            stats[0] += nfev
            stats[2] += rejected
            if status != ACCEPTED:
                outcome = STEP_FAILED
                break
            stats[1] += 1
            if not (math.isfinite(n0) and math.isfinite(n1)):
                outcome = NONFINITE_STATE
                break
            h = t_new - t
            if watched or (i_sample < t_eval.shape[0] and t_eval[i_sample] <= t_new):
                stats[0] += dense_coefficients(rhs, r, t, y0, y1, h, method, p, K, Q)
            k, t_cross = -1, t_new
            if watched:
                k, t_cross = first_crossing(surf, dirs, t, t_new, y0, y1, n0, n1, Q, p, n_int, xtol, g0, g1)
                if k == NONFINITE:
                    outcome = NONFINITE_STATE
                    break
                if k < 0:
                    k = left_at_start(surf, dirs, t, t_new, y0, y1, n0, n1, p)
                    t_cross = t if k >= 0 else t_new
            i_sample = sample(t_eval, i_sample, t_cross, t, h, y0, y1, Q, r, out_y, out_r)
            h_last = h
            if k >= 0:
                if t_cross == t_new:
                    c0, c1 = n0, n1
                elif t_cross == t:
                    c0, c1 = y0, y1
                else:
                    c0, c1 = dense_eval(t_cross, t, h, y0, y1, Q)
                r_new = after(surf, flags_of, signs, lookup, r, k, t_cross, c0, c1, p)
                sw = record(sw, n_sw, t_cross, k, r, r_new, c0, c1)
                n_sw += 1
                t, y0, y1, r = t_cross, c0, c1, r_new
                if n_sw >= max_events:
                    outcome = MAX_EVENTS
                elif chattering(sw, n_sw, fset[F_CHATTER], iset[I_CHATTER]):
                    outcome = CHATTER
                break
            t, y0, y1, h_abs = t_new, n0, n1, h_next
            K[0, 0], K[0, 1] = K[n, 0], K[n, 1]
            if abs(y0) > fset[F_ANGLE]:
                outcome = ANGLE_LIMIT
                break
    return outcome, i_sample, sw[:n_sw].copy(), stats
