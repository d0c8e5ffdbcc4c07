"""The rules of the hybrid automaton, once, for every run of camdyn.

The automaton is data (:mod:`camdyn.engine.tables`, from ``camdyn.derive.automaton``); these
small functions are its semantics, called by the loop (:mod:`camdyn.engine.loop`) after every
accepted step, compiled or interpreted (:mod:`camdyn.engine.jit`):

*Crossings.*  Mode m watches the surfaces of its transitions.  In a step the reach rule does
not clear (*Reach*, below), each is sampled at the step's start, at ``interior_points``
equally spaced times on the interpolant, and at its end.  A
transition fires where its surface's value crosses zero in its direction: +1 from < 0 to
>= 0, -1 from > 0 to <= 0; a value exactly 0 at a sample never *starts* a crossing (a run
restarts on the far side of the surface it just crossed, and must not cross it again).  The
earliest crossing wins; ties go to the transition listed first.

*Far-side roots.*  A crossing is located on the interpolant (Illinois false position) to
``xtol * max(1, |t|)`` and returned at the end of its final bracket that lies across the
surface, so the restart state is across and time always advances.

*Excursions.*  A surface with a declared rate (``RATE_OF_SURFACE``: the gap and the gap rate) is
also checked between samples: when the rate turns from approaching zero to leaving it, the
extremum is located and, if the value there is across, the crossing out and back within one
step (a micro-hop) is found.  A sign change that starts moving *away* from the watched
direction can only follow a turn of the rate; if the rate never turns, it is rounding noise
(a restart just across the surface, where the gap is ~1e-19 m), not a crossing.

*Reach.*  A surface of value g moving at rate r at both ends of a span of time T is out of reach
of zero over it when ``|g| > reach_factor * |r| * T`` at both ends (:func:`beyond_reach`; exact,
with a factor 1, when the rate stays between its values at the ends).  A step in which every
watched surface is out of reach has no crossing: it is cleared from its ends alone
(:func:`clear_of_surfaces`), without its interpolant or interior samples.  An excursion whose
extremum is out of reach of the samples around it is not located.  The rate at a step's end is
the declared rate (``RATE_OF_SURFACE``) where the surface has one, else the surface's derivative
along the motion, by a forward difference along the field.

*Targets.*  A transition enters its first candidate whose conditions hold: (surface, sign)
holds where sign * value >= 0, the value taken under the candidate's laws; exactly 0, the value
a moment later along the motion (alpha moved by alpha_dot over ``look_ahead`` relative) decides.

*Starting on a surface.*  A step that starts exactly on a watched surface (value 0: a start
there, or a restart at a root located exactly) and ends strictly on its leaving side has left
the mode at its start.

*Chatter.*  More than ``chatter_switches`` switches within ``chatter_window`` (relative) of the
latest is a run making no progress: it stops (``Outcome.CHATTER``).

*A chatter's end.*  A scene with rigid impacts declares the transition a chatter end replaces (the
impact, ``CHATTER``).  At each impact through it the rate of approach v_k (its surface's declared
rate, < 0) is kept; where three impacts in a row shrink it by one ratio r (v_k / v_k-1 and
v_k-1 / v_k-2 within ``CHATTER_RATIO_SPREAD`` of each other, 0 < r < 1), the impacts are those of a
bouncing ball under the constant relative acceleration |a| = 2 |v_k| / dt_k (dt_k the last flight):
the next hop would rise H = r^2 |v_k| dt_k / 4 and the rest would end at the accumulation point
t_k + dt_k r / (1 - r).  Once H is below ``atol`` (the gap's metres against the coordinate's
tolerance: the hops are below what the integration resolves), or two impacts fall within the time
resolution ``xtol``, or one arrives with no approach (hops below rounding), the impact takes the
chatter end's targets and reset instead (:func:`chatter_ends`): the plastic impact into the constrained mode.
From there the constrained motion is the true one from the accumulation point on (both ride the
cam with no relative velocity) and differs from it before by at most H.  A sequence that does not
converge is followed impact by impact, up to the chatter and event limits above.
"""
from __future__ import annotations

import math
import numpy as np

from ..vocabulary import STATE_ALPHA, STATE_ALPHA_DOT, WITH_RATE_RATE, WITH_RATE_VALUE
from .jit import allocating, jitable
from .stepper import dense_eval

#: first_crossing's transition index when a surface value is not finite
NONFINITE = -2
#: left_at_start's verdict: the step must be taken again, shorter (its crossing is inside it)
SHORTER = -3


#: rows of first_crossing's work array (:func:`scratch`): per watched transition of the mode
#: (k = w - watch_start[m]), its surface's value and rate at the previous sample; per surface,
#: its value at the current sample; the output of the kernel surface_with_rate (value, rate);
#: per watched transition, its surface's rate along the motion at the previous step's end
#: (:func:`clear_of_surfaces`)
G_PREV, R_PREV, VALUES, WITH_RATE, M_PREV = 0, 1, 2, 3, 4
WORK_ROWS = 5


@allocating
def scratch(n_transitions, n_surfaces):
    """The work array of :func:`first_crossing` and :func:`clear_of_surfaces`: rows G_PREV,
    R_PREV, VALUES, WITH_RATE, M_PREV (at least 2 long).  One array, not five: fewer arguments
    to pass down.  (np.empty and a loop, no np.zeros or max of ints: each compiles one more
    overload on a cold start.)"""
    n = n_transitions if n_transitions > n_surfaces else n_surfaces
    work = np.empty((WORK_ROWS, n if n > 2 else 2))
    for r in range(WORK_ROWS):
        for k in range(work.shape[1]):
            work[r, k] = 0.0
    return work


@jitable
def crossed(g0, g1, direction):
    """Whether g going from g0 to g1 crosses zero in direction (+1, -1, or 0 for both)."""
    up = g0 < 0.0 <= g1
    down = g0 > 0.0 >= g1
    if direction > 0:
        return up
    if direction < 0:
        return down
    return up or down


@jitable
def value(prob, m, s, t, a, ad):
    """Surface s's value at the state under mode m's laws."""
    return prob.kernels.surface(m, s, t, a, ad, prob.p)


# --- surfaces of time alone -----------------------------------------------------------------
#: how many equal parts of a step's span time_bound samples a surface of time alone at
TIME_SAMPLES = 4


@jitable
def watches_timed(tab, m):
    """Whether mode m watches a surface of time alone (``TIMED_SURFACES``): else :func:`time_bound`
    has nothing to look for, and the loop does not call it."""
    for w in range(tab.data[tab.watch_start + m], tab.data[tab.watch_start + m + 1]):
        if tab.data[tab.surface_timed + tab.data[tab.surface + w]] == 1:
            return True
    return False


@jitable
def time_bound(prob, m, t, t_far, a, ad):
    """The first crossing within (t, t_far] of a surface of time alone (``TIMED_SURFACES``: a cam
    of arcs' junction under a translating follower) that mode m watches, in its transition's
    direction: (w, t_before, t_after), the transition's row and the adjacent floats around the
    crossing (the old side at t_before, across at t_after); (-1, t_far, t_far) for none.

    The loop steps to t_before and takes the transition at t_after, as a field that jumps at the
    surface (a rigid follower's kinematic acceleration at a change of curvature) cannot be stepped
    across: a step over the jump errs by the jump times the time it spends beyond it, which the
    error control can only shrink down to the floats' spacing.  The crossing is found on
    TIME_SAMPLES samples of the span (a crossing and its return within one part is missed, as on a
    watched surface's samples), then bisected to adjacent floats.  The state does not enter."""
    tab = prob.tables
    best, t_before, t_after = -1, t_far, t_far
    for w in range(tab.data[tab.watch_start + m], tab.data[tab.watch_start + m + 1]):
        s = tab.data[tab.surface + w]
        if tab.data[tab.surface_timed + s] == 1:
            found, lo, hi = _timed_crossing(prob, m, s, tab.data[tab.direction + w], t, t_before, a, ad)
            if found:  # (searched up to the best so far only: it is the earlier)
                best, t_before, t_after = w, lo, hi
    return best, t_before, t_after


@jitable
def _timed_crossing(prob, m, s, direction, t, t_far, a, ad):
    """Surface s's first crossing in ``direction`` within (t, t_far]: (True, t_before, t_after) as
    adjacent floats; (False, t_far, t_far) for none (see :func:`time_bound`)."""
    ta, ga = t, direction * value(prob, m, s, t, a, ad)
    for k in range(1, TIME_SAMPLES + 1):
        tb = t_far if k == TIME_SAMPLES else t + (t_far - t) * (k / TIME_SAMPLES)
        gb = direction * value(prob, m, s, tb, a, ad)
        if ga <= 0.0 < gb:
            while True:  # bisection to adjacent floats: direction * value <= 0 at ta, > 0 at tb
                mid = ta + (tb - ta) * 0.5
                if mid <= ta or mid >= tb:
                    return True, ta, tb
                if direction * value(prob, m, s, mid, a, ad) > 0.0:
                    tb = mid
                else:
                    ta = mid
        ta, ga = tb, gb
    return False, t_far, t_far


# --- targets ------------------------------------------------------------------------------
@jitable
def side(prob, m, s, t, a, ad, look_ahead):
    """Surface s's value; exactly 0, its value a moment later along the motion."""
    g = value(prob, m, s, t, a, ad)
    if g == 0.0:
        h = look_ahead * max(1.0, abs(t))
        g = value(prob, m, s, t + h, a + h * ad, ad)
    return g


@jitable
def target(prob, row, t, a, ad, look_ahead):
    """The first candidate of target row ``row`` whose conditions hold at the state."""
    tab = prob.tables
    first, last = tab.data[tab.target_start + row], tab.data[tab.target_start + row + 1]
    for c in range(first, last):
        m = tab.data[tab.target_mode + c]
        holds = True
        for q in range(tab.data[tab.condition_start + c], tab.data[tab.condition_start + c + 1]):
            s = tab.data[tab.condition_surface + q]
            if tab.data[tab.condition_sign + q] * side(prob, m, s, t, a, ad, look_ahead) < 0.0:
                holds = False
                break
        if holds:
            return m
    return tab.data[tab.target_mode + last - 1]


@jitable
def initial_mode(prob, t, a, ad, look_ahead):
    """The mode a run starts in: the initial candidates (the row after the transitions)."""
    return target(prob, prob.tables.n_transitions, t, a, ad, look_ahead)


# --- location on the interpolant ------------------------------------------------------------
@jitable
def value_on_step(prob, m, s, tt, t, h, y0, y1, Q):
    """Surface s's value at time tt on the interpolant of the step [t, t + h]."""
    a, ad = dense_eval(tt, t, h, y0, y1, Q)
    return value(prob, m, s, tt, a, ad)


@jitable
def locate(prob, m, s, t, h, y0, y1, Q, ta, tb, ga, gb, xtol):
    """Root of surface s on the interpolant in (ta, tb], returned on the far side; and the
    number of values computed.

    ga = g(ta) != 0 and gb = g(tb) of the other sign or 0.  Illinois false position keeps a
    bracket [lo, hi] with g(lo) on ga's side and g(hi) not, halving the value of an end kept
    twice in a row.  A trial point is kept at least half the tolerance inside the bracket, so
    that when the estimate lands next to the root the next value closes the bracket from the
    other side (Brent's rule: superlinear to the end).  If three iterations together fail to
    halve the bracket, the next one bisects.  Returns hi once hi - lo <= xtol max(1, |hi|).
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
        g = value_on_step(prob, m, s, tm, t, h, y0, y1, Q)
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


@jitable
def extremum(prob, m, s, rate, t, h, y0, y1, Q, ta, tb, ra, rb):
    """(t, value of s) where surface s's rate (ra at ta, rb at tb, of opposite signs) is 0."""
    t_ext, _ = locate(prob, m, rate, t, h, y0, y1, Q, ta, tb, ra, rb, 1e-15)
    return t_ext, value_on_step(prob, m, s, t_ext, t, h, y0, y1, Q)


@jitable
def hidden_excursion(prob, m, s, rate, direction, t, h, y0, y1, Q, ta, tb, ga, gb, ra, rb, reach):
    """(t_ext, g_ext) when surface s crosses zero and comes back inside (ta, tb), else (-1, 0).

    Both ends are on the watched side; if the rate turns from approaching zero to leaving it,
    and the extremum is not out of reach (:func:`beyond_reach` with factor ``reach``), the
    extremum is located and the value read there.  A rate exactly 0 at an end is no turn."""
    if not _turns(direction, ga, ra, rb):
        return -1.0, 0.0
    if beyond_reach(ga, ra, tb - ta, reach) and beyond_reach(gb, rb, tb - ta, reach):
        return -1.0, 0.0
    up = ga < 0.0
    t_ext, g_ext = extremum(prob, m, s, rate, t, h, y0, y1, Q, ta, tb, ra, rb)
    if (up and g_ext >= 0.0) or (not up and g_ext <= 0.0):
        return t_ext, g_ext
    return -1.0, 0.0


@jitable
def turned_back(prob, m, s, rate, direction, t, h, y0, y1, Q, ta, tb, ga, ra, rb):
    """Start (t, g) of the bracket of a sign change of surface s over (ta, tb], and whether it
    is a crossing: if s moves away from the watched direction at ta it can reach zero only
    after its rate turns (the bracket then starts at the turn); if the rate never turns, the
    sign change is rounding noise.  A rate exactly 0 at ta (a restart with no relative velocity: the rigid
    law's plastic reset as the follower leaves the cam) moves towards the watched direction only if the
    rate at tb does."""
    if ra * direction > 0.0 or (ra == 0.0 and rb * direction >= 0.0):
        return ta, ga, True
    if rb * direction < 0.0:
        return ta, ga, False
    t_ext, g_ext = extremum(prob, m, s, rate, t, h, y0, y1, Q, ta, tb, ra, rb)
    if g_ext * direction < 0.0:
        return t_ext, g_ext, True
    return ta, ga, True


@jitable
def _changes(direction, ga, gb, rate, ra, rb):
    """Whether a sample may hide a crossing: a sign change in the direction, or (with a rate
    surface) a turn of the rate (:func:`_turns`), or a hop from the surface (:func:`_hops_back`);
    :func:`_crossing_in` decides."""
    return crossed(ga, gb, direction) or (rate >= 0 and (_turns(direction, ga, ra, rb)
                                                         or _hops_back(direction, ga, gb, ra, rb)))


@jitable
def _hops_back(direction, ga, gb, ra, rb):
    """A value on the surface or just across it at ta (a restart at a located crossing) that leaves
    towards the watched side (its rate away from the far side: a reset turned the motion, the rigid
    law's impact) and is across again at tb, the rate turned: a hop out and back inside (ta, tb],
    which no sign change of the samples shows (*Crossings*)."""
    return ga * direction >= 0.0 and ra * direction < 0.0 and rb * direction > 0.0 and gb * direction >= 0.0


@jitable
def _turns(direction, ga, ra, rb):
    """Whether a surface on the watched side at both ends (value ga) has a rate that turns from
    approaching zero (ra) to leaving it (rb): the only way it can cross and come back."""
    return (direction >= 0 and ga < 0.0 and ra > 0.0 > rb) or (direction <= 0 and ga > 0.0 and ra < 0.0 < rb)


@jitable
def _crossing_in(prob, m, s, rate, direction, t, h, y0, y1, Q, ta, tb, ga, gb, ra, rb, cfg):
    """The far-side time of transition's surface s crossing zero in ``direction`` inside
    (ta, tb] of the step [t, t + h], or -1.0: a sign change (unless it is rounding noise, see
    :func:`turned_back`) or a hidden excursion (:func:`hidden_excursion`), located."""
    if crossed(ga, gb, direction):
        lo, glo, genuine = ta, ga, True
        if rate >= 0:
            lo, glo, genuine = turned_back(prob, m, s, rate, direction, t, h, y0, y1, Q, ta, tb, ga, ra, rb)
        if genuine:
            return locate(prob, m, s, t, h, y0, y1, Q, lo, tb, glo, gb, cfg.xtol)[0]
    elif rate >= 0 and _hops_back(direction, ga, gb, ra, rb):
        t_ext, g_ext = extremum(prob, m, s, rate, t, h, y0, y1, Q, ta, tb, ra, rb)
        if g_ext * direction < 0.0:  # the hop's apex, on the watched side: the landing follows it
            return locate(prob, m, s, t, h, y0, y1, Q, t_ext, tb, g_ext, gb, cfg.xtol)[0]
        return t_ext  # an apex that never cleared the surface: it lands there (a hop below rounding)
    elif rate >= 0 and _turns(direction, ga, ra, rb):
        t_ext, g_ext = hidden_excursion(prob, m, s, rate, direction, t, h, y0, y1, Q, ta, tb, ga, gb, ra, rb,
                                        cfg.reach_factor)
        if t_ext >= 0.0:
            return locate(prob, m, s, t, h, y0, y1, Q, ta, t_ext, ga, g_ext, cfg.xtol)[0]
    return -1.0


@jitable
def sample_surfaces(prob, m, t, a, ad, work):
    """Mode m's sampled surfaces (Tables.sampled) at the state into work's VALUES row: a surface
    with a declared rate together with that rate, in one kernel call (``surface_with_rate``)."""
    tab = prob.tables
    data, pair = tab.data, work[WITH_RATE]
    for q in range(data[tab.sampled_start + m], data[tab.sampled_start + m + 1]):
        s = data[tab.sampled + q]
        rate = data[tab.surface_rate + s]
        if rate >= 0:
            prob.kernels.surface_with_rate(m, s, t, a, ad, prob.p, pair)
            work[VALUES, s], work[VALUES, rate] = pair[WITH_RATE_VALUE], pair[WITH_RATE_RATE]
        else:
            work[VALUES, s] = prob.kernels.surface(m, s, t, a, ad, prob.p)


# --- reach ----------------------------------------------------------------------------------
#: the forward difference of a rate along the motion steps this fraction of the span it serves:
#: its rounding error then stays near 1e-10 |value| / span, far below what reach compares
MOTION_DIFFERENCE = 1e-6


@jitable
def beyond_reach(g, r, span, factor):
    """Whether a surface of value g moving at rate r stays clear of zero over ``span`` seconds by
    the reach rule (module docstring, *Reach*): |g| > factor |r| span.  False for a NaN."""
    return abs(g) > factor * abs(r) * span


@jitable
def rate_along_motion(prob, m, s, t, a, ad, add, g, span):
    """Surface s's derivative in time along mode m's motion at the state (alpha_ddot = add,
    value g there): a forward difference along the field, over MOTION_DIFFERENCE * span."""
    tt = t + MOTION_DIFFERENCE * span
    d = tt - t
    if not d > 0.0:
        return math.inf
    return (value(prob, m, s, tt, a + d * ad, ad + d * add) - g) / d


@jitable
def clear_of_surfaces(prob, m, t0, t1, n0, n1, add1, cfg, have_start, work):
    """Whether every surface mode m watches is out of reach of zero over the step [t0, t1]
    (module docstring, *Reach*): then no transition crosses in it, and it needs neither its
    interpolant nor interior samples.  n0, n1, add1: alpha, alpha_dot, alpha_ddot at its end.

    Reads the values at t0 from work's G_PREV and M_PREV: a step with ``have_start`` False
    (the first after a start or restart) is never clear.  On return, M_PREV holds the rates at
    t1; G_PREV and R_PREV hold the values at t1 if the step is clear (as first_crossing leaves
    them after a step without crossing), else still those at t0.
    """
    tab = prob.tables
    data = tab.data
    w0, w1 = data[tab.watch_start + m], data[tab.watch_start + m + 1]
    h = t1 - t0
    factor = cfg.reach_factor
    sample_surfaces(prob, m, t1, n0, n1, work)
    clear = have_start
    for w in range(w0, w1):
        k = w - w0
        s = data[tab.surface + w]
        rate = data[tab.surface_rate + s]
        ga, gb = work[G_PREV, k], work[VALUES, s]
        if rate >= 0:
            mb = work[VALUES, rate]
        else:
            mb = rate_along_motion(prob, m, s, t1, n0, n1, add1, gb, h)
        if not (ga * gb > 0.0 and beyond_reach(ga, work[M_PREV, k], h, factor) and beyond_reach(gb, mb, h, factor)):
            clear = False
        work[M_PREV, k] = mb
    if clear:
        for w in range(w0, w1):
            s = data[tab.surface + w]
            rate = data[tab.surface_rate + s]
            work[G_PREV, w - w0] = work[VALUES, s]
            work[R_PREV, w - w0] = work[VALUES, rate] if rate >= 0 else 0.0
    return clear


@jitable
def first_crossing(prob, m, t0, t1, y0, y1, n0, n1, Q, cfg, have_start, work):
    """Earliest crossing of mode m's watched transitions over the step [t0, t1].

    Returns (w, t): the transition's row and the located far-side time; w = -1 when nothing
    crosses, NONFINITE when a value is not finite.  ``have_start``: work's rows G_PREV and
    R_PREV already hold the values at t0 (the previous step's end); with no crossing, they
    hold the values at t1 on return.  Each sample is :func:`sample_surfaces`.  (Runs on the
    steps :func:`clear_of_surfaces` does not clear: only a sample that may hide a crossing
    calls the locating helpers, :func:`_crossing_in`.)
    """
    tab = prob.tables
    data = tab.data
    w0, w1 = data[tab.watch_start + m], data[tab.watch_start + m + 1]
    h = t1 - t0
    n_int = cfg.interior_points
    best_w, best_t = -1, math.inf
    found = 0
    tb = t0  # sample i - 1's time, i >= 1 (h * 0 / (n_int + 1) = 0: the same value, one division less)
    for i in range(1 if have_start else 0, n_int + 2):  # sample 0: the start, when not known yet
        ta = tb
        last = i == n_int + 1
        tb = t1 if last else t0 + h * i / (n_int + 1)
        if tb >= best_t:
            break  # a root in (ta, tb] cannot beat one already located before tb
        if i == 0:
            a, ad = y0, y1
        elif last:
            a, ad = n0, n1
        else:
            a, ad = dense_eval(tb, t0, h, y0, y1, Q)
        sample_surfaces(prob, m, tb, a, ad, work)
        for w in range(w0, w1):
            k = w - w0
            if (found >> k) & 1:
                continue
            s = data[tab.surface + w]
            rate = data[tab.surface_rate + s]
            gb = work[VALUES, s]
            rb = work[VALUES, rate] if rate >= 0 else 0.0
            if i > 0:
                ga, ra, direction = work[G_PREV, k], work[R_PREV, k], data[tab.direction + w]
                if not (math.isfinite(ga) and math.isfinite(gb)):
                    return NONFINITE, tb
                if _changes(direction, ga, gb, rate, ra, rb):
                    tk = _crossing_in(prob, m, s, rate, direction, t0, h, y0, y1, Q, ta, tb, ga, gb, ra, rb, cfg)
                    if tk >= 0.0:
                        found |= 1 << k
                        if tk < best_t:
                            best_w, best_t = w, tk
            work[G_PREV, k] = gb
            work[R_PREV, k] = rb
    return best_w, best_t


@jitable
def left_at_start(prob, m, t0, t1, y0, y1, n0, n1, may_shorten):
    """A step that starts exactly on a watched surface (value 0) and ends strictly on its
    leaving side has left mode m at its start, the transition's row, where the surface's
    declared rate leaves at the start too (or the surface has none, or ``may_shorten`` is False:
    the step is already at the time resolution); -1 for none.

    Where the rate does not leave at the start (a rigid follower released at rest on the cam: the
    plastic reset's zero relative velocity) the value first moves the other way or not at all:
    if the rate at the end leaves, the value turns back within the step, and the crossing is inside
    it, not at its start: SHORTER, the step must be taken again shorter (a long first step of a
    flight after a lift-off that grazes spans the whole brief flight); if it does not, the end's
    value is rounding (~1e-15 m of the gap below zero after a short first step while the rate
    already separates), no crossing.  Read as an impact at the start, either had its chatter end
    release the follower at the same instant again and again until the chatter guard ended the
    run."""
    tab = prob.tables
    for w in range(tab.data[tab.watch_start + m], tab.data[tab.watch_start + m + 1]):
        s = tab.data[tab.surface + w]
        direction = tab.data[tab.direction + w]
        leaving = direction * value(prob, m, s, t1, n0, n1) > 0.0
        if leaving and value(prob, m, s, t0, y0, y1) == 0.0:
            rate = tab.data[tab.surface_rate + s]
            if rate < 0 or not may_shorten or direction * value(prob, m, rate, t0, y0, y1) > 0.0:
                return w
            if direction * value(prob, m, rate, t1, n0, n1) > 0.0:
                return SHORTER
    return -1


@jitable
def zero_at_start(work, n_watched):
    """Whether a watched value was exactly 0 at the step's start (a start on its surface):
    work[G_PREV, :n_watched] are the values first_crossing kept."""
    for k in range(n_watched):
        if work[G_PREV, k] == 0.0:
            return True
    return False


# --- switching ------------------------------------------------------------------------------
@jitable
def across(prob, m, w, t, a, ad):
    """Whether the state is across transition w's surface (or on it), in its direction."""
    tab = prob.tables
    return tab.data[tab.direction + w] * value(prob, m, tab.data[tab.surface + w], t, a, ad) >= 0.0


#: the spread of successive impact ratios (relative) within which a sequence counts as geometric
CHATTER_RATIO_SPREAD = 0.05
#: the slots of a chatter's history (:func:`chatter_ends`): the last impact's time and rate of approach,
#: the last ratio of rates, and how many impacts in a row are kept
CHATTER_T, CHATTER_V, CHATTER_RATIO, CHATTER_COUNT = range(4)


@jitable
def chatter_ends(history, t, v, atol, resolution):
    """Whether the impact at time t with the rate of approach v (< 0) ends a chatter (*A chatter's end*,
    the module docstring); ``history`` (CHATTER_* slots) is updated with it.  An impact with no approach
    (v >= 0), or one within the time ``resolution`` of the last, also ends it: the follower cannot leave
    the cam by more than rounding (released on a cam that recedes more slowly than it falls)."""
    n = history[CHATTER_COUNT]
    ends = v >= 0.0 or (n >= 1 and t - history[CHATTER_T] <= resolution)
    if not ends and n >= 1 and history[CHATTER_V] < 0.0 and v < 0.0:
        r = v / history[CHATTER_V]
        dt = t - history[CHATTER_T]
        if n >= 2 and 0.0 < r < 1.0 and dt > 0.0 and abs(r - history[CHATTER_RATIO]) <= CHATTER_RATIO_SPREAD * r:
            ends = r * r * (-v) * dt / 4.0 <= atol
        history[CHATTER_RATIO] = r
    history[CHATTER_T], history[CHATTER_V] = t, v
    history[CHATTER_COUNT] = 0.0 if ends else n + 1.0
    return ends


@jitable
def row_reset(tab, w):
    """The reset (an index into RESETS) of target row w: a transition's own, or past the
    transitions the chatter end's (row n_transitions + 1).  A switch record's ``transition`` is
    such a row, so the saltation of a recorded switch reads its reset here too."""
    return tab.data[tab.reset + w] if w < tab.n_transitions else tab.chatter_reset


@jitable
def switch(prob, w, t, a, ad, cfg, buf):
    """The mode after transition w fires at (t, a, ad), and the state after its reset; ``w`` past the
    transitions, the chatter end's row (n_transitions + 1, with its reset)."""
    m_new = target(prob, w, t, a, ad, cfg.look_ahead)
    j = row_reset(prob.tables, w)
    if j >= 0:
        prob.kernels.reset(j, t, a, ad, prob.p, buf)
        return m_new, buf[STATE_ALPHA], buf[STATE_ALPHA_DOT]
    return m_new, a, ad


@jitable
def chattering(times, n, window, count):
    """More than ``count`` switches within ``window`` (relative) of the latest, switches at
    times[:n]: no progress."""
    if n <= count:
        return False
    t = times[n - 1]
    return t - times[n - 1 - count] < window * max(1.0, abs(t))
