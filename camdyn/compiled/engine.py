"""The compiled hybrid loop: regimes, steps, events and switches all inside numba.

The discrete state is a regime index r (:mod:`.regimes`: the generated regimes and, with
Coulomb friction, their stick modes).  The switching rules are those of the SciPy backend
(:mod:`camdyn.integrate`, :mod:`camdyn.hybrid`): contact starts with the other flags set
from the state's side of their surfaces (looking ahead when exactly on one), and ends with
them out of scope; a slip reversal where both one-sided fields point at v_r = 0 sticks,
and sticking ends when one of them turns away; every other flag just flips.  After a
switch from free flight into contact the first step is capped at a tenth of a radian of
the contact mode, as in the SciPy backend (a free-flight step would blow up on the stiff
contact).  The state a switch restarts from is one step of the method to the located time
(:func:`state_at_crossing`); when that state is not yet across the surface, the run goes on
in the same regime from it, up to CROSSING_RETRIES steps in a row (then the crossing restarts
from the interpolant's state, which is across by construction: time always advances).

With a ledger (``out_y`` of 5 rows) the work of the drive, contact damping and friction is
integrated along the dense output (:mod:`.ledger`) and sampled with the state.

:func:`run` returns an outcome code (the position in ``OUTCOMES``), the samples written
into ``out_y``/``out_r``, the switch records and the counters.  Nothing here is global:
the rig, the cam and the tolerances arrive as arrays, so one compiled loop serves every
scene, rig and sweep point.
"""
from __future__ import annotations

import math

import numpy as np
from numba import njit

from ..events import CROSSING_RETRIES
from .events import NONFINITE, first_crossing, left_at_start
from .ledger import N_FLOWS, accumulate
from .regimes import N_EXTRA, accel, after, entering, on_true_side, value, watch
from .stepper import ACCEPTED, dense_coefficients, dense_eval, initial_step, step, step_impl

#: outcome codes of run(), by position: names of camdyn.outcome.Outcome members
OUTCOMES = ("SUCCESS", "STEP_FAILED", "MAX_EVENTS", "CHATTER", "NONFINITE", "ANGLE_LIMIT")
SUCCESS, STEP_FAILED, MAX_EVENTS, CHATTER, NONFINITE_STATE, ANGLE_LIMIT = range(6)
#: settings arrays: floats (rtol, atol, max_step, xtol, angle_limit, chatter_window,
#: contact_step: the first step's cap after a switch from free flight into contact, 0 for
#: none) and ints
#: (interior_points, max_events, chatter_switches, rate_check: gap-rate excursion check on,
#: stick: Coulomb stick modes exist, rate_flag: the flag whose surface is the gap rate or -1)
F_RTOL, F_ATOL, F_MAX_STEP, F_XTOL, F_ANGLE, F_CHATTER, F_CONTACT_STEP = range(7)
I_INTERIOR, I_MAX_EVENTS, I_CHATTER, I_RATE, I_STICK, I_RATE_FLAG = range(6)
#: columns of a switch record
SWITCH_COLUMNS = ("t", "flag", "before", "after", "alpha", "alpha_dot")
#: counters returned
STATS = ("nfev", "steps", "rejected_steps")


@njit(cache=True)
def sample(fns, tab, nr, p, t_eval, i, t_stop, t, h, y0, y1, Q, r, out_y, out_r, w, wq):
    """Write the samples t_eval[i:] <= t_stop from the step's interpolant; the next index.
    With a ledger, w is the work at the step's start t and rows 2-4 get the work at each
    sample (wq is a work array)."""
    n = t_eval.shape[0]
    ledger = out_y.shape[0] > 2
    while i < n and t_eval[i] <= t_stop:
        out_y[0, i], out_y[1, i] = dense_eval(t_eval[i], t, h, y0, y1, Q)
        if ledger:
            wq[:] = w
            accumulate(fns, tab, nr, r, t, h, y0, y1, Q, p, t, t_eval[i], wq)
            out_y[2:2 + N_FLOWS, i] = wq
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
def first_step(fns, method, p, tab, nr, r, t, y0, y1, t_end, fset, h_last, from_free, K):
    """K[0] = f(t, y) and the size of the first step in regime r: SciPy's initial step at
    the start, else the last step's size (capped after a switch from free flight into
    contact).  Returns (h_abs, RHS evaluations)."""
    K[0, 0], K[0, 1] = y1, accel(fns, nr, r, t, y0, y1, p)
    if h_last < 0.0:
        error_order = -1.0 / method[9] - 1.0
        return initial_step(fns, nr, r, t, y0, y1, K[0, 1], t_end, fset[F_MAX_STEP], error_order,
                            fset[F_RTOL], fset[F_ATOL], p), 2
    h_abs = min(h_last, t_end - t)
    if from_free and tab[0][r, 0] == 1:
        h_abs = min(h_abs, fset[F_CONTACT_STEP])
    return h_abs, 1


#: state_at_crossing's verdicts
ACROSS, NOT_YET, UNUSABLE = 1, 0, -1


@njit(cache=True)
def state_at_crossing(fns, tab, nr, r, k, direction, t, y0, y1, t_cross, method, p, K):
    """The state at a crossing located inside a step from (t, y): one Runge-Kutta step of
    size t_cross - t (the method's order; the interpolant's error, an order lower and larger
    at loose tolerances, would otherwise be carried into the next regime at every switch).
    Returns (alpha, alpha_dot, verdict): ACROSS; NOT_YET when that state is not yet across
    value k's surface (the interpolant's error put the root early: the run may go on in the
    same regime from it; K[n] then holds f there, the next step's FSAL stage); UNUSABLE when
    it is not finite.  K[0] must hold f(t, y); the other rows are overwritten."""
    c0, c1 = step_impl(fns, nr, r, t, y0, y1, t_cross - t, method, p, K)
    g = direction * value(fns, tab, nr, r, k, t_cross, c0, c1, p)
    if not (math.isfinite(c0) and math.isfinite(c1) and math.isfinite(g)):
        return c0, c1, UNUSABLE
    return c0, c1, ACROSS if g >= 0.0 else NOT_YET


@njit(cache=True)
def zero_at_start(dirs, g):
    """Whether a watched value is exactly 0 (a step starting on its surface)."""
    for k in range(dirs.shape[0]):
        if dirs[k] != 0 and g[k] == 0.0:
            return True
    return False


@njit(cache=True)
def run(fns, method, p, tab, nr, r0, t0, t_end, y_start, t_eval, fset, iset, out_y, out_r):
    """Integrate the hybrid model from (t0, y_start) to t_end (see the module docstring).

    fns, tab, nr: the scene's kernels, tables and number of generated regimes (.regimes).
    r0 >= 0 fixes the initial regime (linear models); -1 chooses it from the surfaces.
    Returns (outcome, samples written, switch records, counters [nfev, steps, rejected]).
    """
    rtol, atol, max_step, xtol = fset[F_RTOL], fset[F_ATOL], fset[F_MAX_STEP], fset[F_XTOL]
    n_int, max_events = iset[I_INTERIOR], iset[I_MAX_EVENTS]
    rate_check, stick = iset[I_RATE] != 0, iset[I_STICK] != 0
    ledger = out_y.shape[0] > 2
    n = method[6]
    K = np.empty((method[0].shape[0], 2))
    Q = np.empty((2, method[5].shape[1]))
    nv = tab[1].shape[0] + N_EXTRA
    dirs = np.zeros(nv, dtype=np.int64)
    g_prev, g_next, r_prev = np.empty(nv), np.empty(nv), np.empty(1)
    w, wq = np.zeros(N_FLOWS), np.empty(N_FLOWS)
    stats = np.zeros(3, dtype=np.int64)
    sw = np.empty((16, 6))
    n_sw, i_sample, outcome = 0, 0, SUCCESS
    t, y0, y1 = t0, y_start[0], y_start[1]
    r = r0 if r0 >= 0 else entering(fns, tab, t, y0, y1, p, on_true_side(fns, tab, 0, t, y0, y1, p, True))
    h_last = -1.0
    retries = 0  # steps in a row that ended short of a crossing their interpolant placed early
    while t < t_end and outcome == SUCCESS:
        from_free = n_sw > 0 and fset[F_CONTACT_STEP] > 0.0 and tab[0][int(sw[n_sw - 1, 2]), 0] == 0
        h_abs, nfev = first_step(fns, method, p, tab, nr, r, t, y0, y1, t_end, fset, h_last, from_free, K)
        stats[0] += nfev
        watched = watch(tab, nr, r, dirs)
        have_start = False
        while t < t_end:
            status, t_new, n0, n1, h_next, nfev, rejected = step(
                fns, nr, r, t, y0, y1, h_abs, t_end, method, p, K, rtol, atol, max_step)
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
            if watched or ledger or (i_sample < t_eval.shape[0] and t_eval[i_sample] <= t_new):
                stats[0] += dense_coefficients(fns, nr, r, t, y0, y1, h, method, p, K, Q)
            k, t_cross = -1, t_new
            if watched:
                maybe_on_surface = not have_start or zero_at_start(dirs, g_prev)
                k, t_cross = first_crossing(fns, tab, nr, r, dirs, t, t_new, y0, y1, n0, n1, Q, p, n_int, xtol,
                                            rate_check, iset[I_RATE_FLAG], have_start, g_prev, r_prev, g_next)
                if k == NONFINITE:
                    outcome = NONFINITE_STATE
                    break
                if k < 0:
                    t_cross = t_new
                    if maybe_on_surface:
                        k = left_at_start(fns, tab, nr, r, dirs, t, t_new, y0, y1, n0, n1, p)
                        t_cross = t if k >= 0 else t_new
                have_start = True
            if i_sample < t_eval.shape[0] and t_eval[i_sample] <= t_cross:
                i_sample = sample(fns, tab, nr, p, t_eval, i_sample, t_cross, t, h, y0, y1, Q, r, out_y, out_r, w, wq)
            if ledger:
                accumulate(fns, tab, nr, r, t, h, y0, y1, Q, p, t, t_cross, w)
            h_last = h
            if k >= 0:
                if t_cross == t_new:
                    c0, c1 = n0, n1
                elif t_cross == t:
                    c0, c1 = y0, y1
                else:
                    c0, c1, verdict = state_at_crossing(fns, tab, nr, r, k, dirs[k], t, y0, y1, t_cross, method, p, K)
                    stats[0] += n
                    if verdict == NOT_YET and retries < CROSSING_RETRIES:  # a step to t_cross in this regime
                        t, y0, y1, h_abs = t_cross, c0, c1, h
                        K[0, 0], K[0, 1] = K[n, 0], K[n, 1]
                        have_start, retries = False, retries + 1
                        continue
                    if verdict != ACROSS:  # the interpolant's state, across by construction
                        c0, c1 = dense_eval(t_cross, t, h, y0, y1, Q)
                retries = 0
                r_new = after(fns, tab, nr, stick, r, k, t_cross, c0, c1, p)
                sw = record(sw, n_sw, t_cross, k, r, r_new, c0, c1)
                n_sw += 1
                t, y0, y1, r = t_cross, c0, c1, r_new
                if n_sw >= max_events:
                    outcome = MAX_EVENTS
                elif chattering(sw, n_sw, fset[F_CHATTER], iset[I_CHATTER]):
                    outcome = CHATTER
                break
            t, y0, y1, h_abs = t_new, n0, n1, h_next
            retries = 0
            K[0, 0], K[0, 1] = K[n, 0], K[n, 1]
            if abs(y0) > fset[F_ANGLE]:
                outcome = ANGLE_LIMIT
                break
    return outcome, i_sample, sw[:n_sw].copy(), stats
