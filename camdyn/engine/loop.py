"""The hybrid loop: steps, crossings, switches and samples, compiled or interpreted.

From the start state, the loop steps mode m's field with the method (:mod:`.stepper`), checks
m's transitions on each accepted step (:mod:`.rules`: a step whose ends put every watched
surface out of reach of zero is cleared from its ends; the others are sampled on the step's
interpolant, which is computed only for them, for samples and for the energy ledger), and at a
crossing restarts from the state at the located time in the mode the transition leads to.
That restart state is one step of the method to the located time (the method's order; the
interpolant's error, an order lower and larger at loose tolerances, would otherwise be carried
into the next mode at every switch); when that state is not yet across the surface, the run
goes on in the same mode from it, up to ``crossing_retries`` steps in a row (then it restarts
from the interpolant's state, across by construction, so time always advances).  The first
step after contact starts is capped at ``contact_step``.

:func:`run` is written once (:mod:`.jit`): :func:`run_compiled` is the same code compiled
(numba, cached on disk; the kernels arrive as first-class functions, so one compiled loop
serves every scene, rig and sweep point) and :func:`run_interpreted` runs it in Python (a
user's cam motion, whose kernels call Python).
"""
from __future__ import annotations

import math
from typing import NamedTuple

import numpy as np
from numba import njit

from ..outcome import Outcome
from ..vocabulary import STATE, STATE_ALPHA, STATE_ALPHA_DOT
from . import cache
from .jit import allocating, jitable
from .ledger import N_FLOWS, accumulate
from .rules import (CHATTER_COUNT, NONFINITE, SHORTER, across, chatter_ends, chattering, clear_of_surfaces, first_crossing,
                    initial_mode, left_at_start, scratch, switch, time_bound, value, watches_timed, zero_at_start)
from .stepper import ACCEPTED, ERR_FLOOR, accepted_step, attempt, dense_coefficients, dense_eval, initial_step

cache.install()  # numba's cache of what follows: the per-user folder (cache.py)

#: the camdyn.Outcome members run() can end with; its outcome code is the member's index here
OUTCOMES = (Outcome.SUCCESS, Outcome.STEP_FAILED, Outcome.MAX_EVENTS, Outcome.CHATTER, Outcome.NONFINITE,
            Outcome.ANGLE_LIMIT, Outcome.OFF_FACE)
SUCCESS, STEP_FAILED, MAX_EVENTS, CHATTER, NONFINITE_STATE, ANGLE_LIMIT, OFF_FACE = (OUTCOMES.index(o) for o in OUTCOMES)
#: one switch: when, which transition (row of Tables), the modes before and after, the state after
SWITCH = np.dtype([("t", np.float64), ("transition", np.int64), ("before", np.int64), ("after", np.int64),
                   ("alpha", np.float64), ("alpha_dot", np.float64)])
#: inside the loop the switches are a float array with one row per field of SWITCH, in its order,
#: and one column per switch (integers held exactly as floats): a record array costs the cold
#: start the typing of its fields, its own allocation and its boxing
SW_T, SW_TRANSITION, SW_BEFORE, SW_AFTER, SW_ALPHA, SW_ALPHA_DOT = range(len(SWITCH.names))
SW_ROWS = len(SWITCH.names)


class Start(NamedTuple):
    t: float
    t_end: float
    alpha: float
    alpha_dot: float
    mode: int            # -1: chosen by the automaton's initial candidates


#: rows of Samples.y (and so of a Trajectory's y): the state, then, with the energy ledger, the
#: works of the flows P_in, D_c, D_f (camdyn.vocabulary.FLOWS) in rows WORK..WORK + N_FLOWS
ALPHA, ALPHA_DOT, WORK = STATE_ALPHA, STATE_ALPHA_DOT, len(STATE)
#: how many rows Samples.y has without and with the ledger
STATE_ROWS, LEDGER_ROWS = WORK, WORK + N_FLOWS


class Samples(NamedTuple):
    """The times to sample (t) and where the samples go: y rows ALPHA, ALPHA_DOT and, with the
    ledger, the works from row WORK on (the drive, contact damping, friction); mode the mode at each."""

    t: np.ndarray
    y: np.ndarray
    mode: np.ndarray


class Run(NamedTuple):
    outcome: int
    n_samples: int
    switches: np.ndarray      # SWITCH records
    nfev: int
    steps: int
    rejected: int
    mode: int                 # at the end
    t: float
    alpha: float
    alpha_dot: float


@allocating
def _record(sw, n, t, w, before, after, a, ad):
    """Append a switch as column n of sw (rows SW_*), doubling the buffer when full; returns it."""
    if n == sw.shape[1]:
        bigger = np.empty((sw.shape[0], 2 * n))
        for r in range(sw.shape[0]):  # element by element (docs/design-notes.md, *Element-by-element
            for k in range(n):        # copies in compiled code*)
                bigger[r, k] = sw[r, k]
        sw = bigger
    sw[SW_T, n], sw[SW_TRANSITION, n], sw[SW_BEFORE, n], sw[SW_AFTER, n] = t, w, before, after
    sw[SW_ALPHA, n], sw[SW_ALPHA_DOT, n] = a, ad
    return sw


def _switch_records(sw: np.ndarray, n: int) -> np.ndarray:
    """The loop's first n switches (columns of sw) as SWITCH records."""
    out = np.empty(n, dtype=SWITCH)
    for k, name in enumerate(SWITCH.names):
        out[name] = sw[k, :n]
    return out


@jitable
def _sample(prob, samples, i, t_stop, m, t, h, y0, y1, Q, ledger_work, ledger_tmp, buf):
    """Write the samples at times <= t_stop from the step's interpolant; the next index.  With a
    ledger, ledger_work is the work at the step's start t."""
    n = samples.t.shape[0]
    ledger = samples.y.shape[0] > STATE_ROWS
    while i < n and samples.t[i] <= t_stop:
        ts = samples.t[i]
        samples.y[ALPHA, i], samples.y[ALPHA_DOT, i] = dense_eval(ts, t, h, y0, y1, Q)
        if ledger:
            for k in range(N_FLOWS):  # element by element, as in _record
                ledger_tmp[k] = ledger_work[k]
            accumulate(prob, m, t, h, y0, y1, Q, t, ts, buf, ledger_tmp)
            for k in range(N_FLOWS):
                samples.y[WORK + k, i] = ledger_tmp[k]
        samples.mode[i] = m
        i += 1
    return i


@jitable
def _held(samples, i, t_stop, m, y0, y1, ledger_work):
    """Write the samples at times <= t_stop as the state (y0, y1) held, with the works so far: the
    float a transition of time alone steps over (rules.time_bound); the next index."""
    n = samples.t.shape[0]
    ledger = samples.y.shape[0] > STATE_ROWS
    while i < n and samples.t[i] <= t_stop:
        samples.y[ALPHA, i], samples.y[ALPHA_DOT, i] = y0, y1
        if ledger:
            for k in range(N_FLOWS):  # element by element, as in _record
                samples.y[WORK + k, i] = ledger_work[k]
        samples.mode[i] = m
        i += 1
    return i


@allocating
def _switched(prob, cfg, w, t_cross, c0, c1, m, history, sw, n_sw, buf):
    """Transition w fires at t_cross from (c0, c1) in mode m: the chatter's end in place of an impact
    where its sequence has converged (rules.chatter_ends), the reset, the record, and whether the run
    ends there.  (mode, state after, sw, n_sw, capped: contact starts, outcome)."""
    tab = prob.tables
    row = w
    if w == tab.chatter:  # an impact
        rate = value(prob, m, tab.data[tab.surface_rate + tab.data[tab.surface + w]], t_cross, c0, c1)
        if chatter_ends(history, t_cross, rate, cfg.atol, cfg.xtol * max(1.0, abs(t_cross))):
            row = tab.n_transitions + 1
    else:
        history[CHATTER_COUNT] = 0.0
    m_new, c0, c1 = switch(prob, row, t_cross, c0, c1, cfg, buf)
    capped = tab.data[tab.mode_contact + m] == 0 and tab.data[tab.mode_contact + m_new] == 1
    sw = _record(sw, n_sw, t_cross, row, m, m_new, c0, c1)
    n_sw += 1
    outcome = SUCCESS
    if tab.data[tab.mode_terminal + m_new] == 1:
        outcome = OFF_FACE
    elif n_sw >= cfg.max_events:
        outcome = MAX_EVENTS
    elif chattering(sw[SW_T], n_sw, cfg.chatter_window, cfg.chatter_switches):
        outcome = CHATTER
    return m_new, c0, c1, sw, n_sw, capped, outcome


@jitable
def _first_step(prob, method, cfg, m, t, y0, y1, t_end, h_last, capped, K):
    """K[0] = f(t, y) and the first step in mode m: SciPy's estimate at the start, else the
    last step's size (capped at contact_step when contact just started).  (h, evaluations)."""
    K[0, 0], K[0, 1] = y1, prob.kernels.rhs(m, t, y0, y1, prob.p)
    if h_last < 0.0:
        return initial_step(prob.kernels.rhs, prob.p, m, t, y0, y1, K[0, 1], t_end, method, cfg), 2
    h_abs = min(h_last, t_end - t)
    if capped and cfg.contact_step > 0.0:
        h_abs = min(h_abs, cfg.contact_step)
    return h_abs, 1


#: a step whose crossing is inside it but read at its start (rules.left_at_start's SHORTER) is taken
#: again from its start this much shorter, down to the event time resolution (EventSettings.xtol)
SHORTEN = 0.125


#: _restart_state's verdicts
ACROSS, NOT_YET, UNUSABLE = 1, 0, -1


@jitable
def _restart_state(prob, method, m, w, t, y0, y1, h, Q, t_cross, K, may_retry):
    """The state at a crossing inside the step [t, t + h] from (t, y): one step of the method to
    t_cross, and whether it is ACROSS transition w's surface or NOT_YET (only when
    ``may_retry``; K[n] then holds f there, the next step's first stage).  A state that is not
    across (no retry left) or not finite is replaced by the interpolant's, across by
    construction (verdict UNUSABLE).  K[0] must hold f(t, y)."""
    c0, c1 = attempt(prob.kernels.rhs, prob.p, m, t, y0, y1, t_cross - t, method, K)
    if math.isfinite(c0) and math.isfinite(c1):
        if across(prob, m, w, t_cross, c0, c1):
            return c0, c1, ACROSS
        if may_retry:
            return c0, c1, NOT_YET
    c0, c1 = dense_eval(t_cross, t, h, y0, y1, Q)
    return c0, c1, UNUSABLE


@jitable
def _crossed(prob, m, t, t_new, y0, y1, n0, n1, Q, cfg, have_start, on_surface, work):
    """The first transition whose surface the step [t, t_new] crosses, and when: (w, t_cross); w
    NONFINITE for a non-finite value, -1 for none (t_cross = t_new).  A step that starts on a
    surface (``on_surface``) and leaves it at once is a crossing at its start; one that turns back
    across it within the step is SHORTER (rules.left_at_start), to be taken again shorter."""
    w, t_cross = first_crossing(prob, m, t, t_new, y0, y1, n0, n1, Q, cfg, have_start, work)
    if w == NONFINITE or w >= 0:
        return w, t_cross
    if on_surface:
        w = left_at_start(prob, m, t, t_new, y0, y1, n0, n1, t_new - t > cfg.xtol * max(1.0, abs(t)))
        return w, (t if w >= 0 else t_new)
    return w, t_new


@jitable
def _crossing_state(prob, method, m, w, t, t_new, y0, y1, n0, n1, h, Q, t_cross, K, may_retry):
    """The state at transition w's crossing at t_cross in the step [t, t_new] (the step's end or
    start as they are, else :func:`_restart_state`): (c0, c1, verdict, RHS evaluations)."""
    if t_cross == t_new:
        return n0, n1, ACROSS, 0
    if t_cross == t:
        return y0, y1, ACROSS, 0
    c0, c1, verdict = _restart_state(prob, method, m, w, t, y0, y1, h, Q, t_cross, K, may_retry)
    return c0, c1, verdict, method.n_stages


@allocating
def _buffers(method, tab):
    """The loop's work arrays: the stages K, the interpolant Q, first_crossing's work, the
    kernels' output buffer, the ledger's works (0) and its scratch, the switches (rows SW_*)."""
    K = np.empty((method.n_rows, 2))
    Q = np.empty((2, method.degree))
    work = scratch(tab.n_transitions, tab.n_surfaces)
    buf = np.empty(tab.n_outputs if tab.n_outputs > 2 else 2)
    ledger_work, ledger_tmp = np.empty(N_FLOWS), np.empty(N_FLOWS)
    for k in range(N_FLOWS):  # not np.zeros: one overload less to compile on a cold start
        ledger_work[k] = 0.0
    return K, Q, work, buf, ledger_work, ledger_tmp, np.empty((SW_ROWS, 16))


@jitable
def _account(prob, m, t, h, y0, y1, Q, t_cross, buf, ledger_work):
    """The ledger's works over [t, t_cross] of the step [t, t + h]."""
    accumulate(prob, m, t, h, y0, y1, Q, t, t_cross, buf, ledger_work)


@allocating
def run(prob, method, cfg, start, samples):
    """Integrate the hybrid model from ``start`` (see the module docstring): the fields of a
    :class:`Run` as a plain tuple, with the switch buffer (rows SW_*) and their count in
    place of ``switches`` (:func:`_finish` makes the Run)."""
    tab = prob.tables
    rhs, p = prob.kernels.rhs, prob.p  # taken out once: a call passing prob pays a count per array it holds
    n = method.n_stages
    K, Q, work, buf, ledger_work, ledger_tmp, sw = _buffers(method, tab)
    ledger = samples.y.shape[0] > STATE_ROWS
    n_sw, i_sample, outcome, nfev, steps, rejected = 0, 0, SUCCESS, 0, 0, 0
    history = np.empty(4)  # the impacts of a chatter (rules.chatter_ends; scenes with rigid impacts)
    for k in range(4):  # not np.zeros: one overload less to compile on a cold start
        history[k] = 0.0
    t, t_end, y0, y1 = start.t, start.t_end, start.alpha, start.alpha_dot
    m = start.mode if start.mode >= 0 else initial_mode(prob, t, y0, y1, cfg.look_ahead)
    if tab.data[tab.mode_terminal + m] == 1:  # it starts where the model ends (a contact beyond the face)
        outcome = OFF_FACE
    h_last, retries, capped, err_prev = -1.0, 0, False, ERR_FLOOR
    screen = cfg.reach_factor < math.inf  # clear a step from its ends (rules.clear_of_surfaces)
    while t < t_end and outcome == SUCCESS:
        h_abs, f = _first_step(prob, method, cfg, m, t, y0, y1, t_end, h_last, capped, K)
        nfev += f
        n_watched = tab.data[tab.watch_start + m + 1] - tab.data[tab.watch_start + m]
        watched = n_watched > 0
        timed = watches_timed(tab, m)  # (once a mode: most watch no surface of time alone)
        have_start = False
        while t < t_end:
            w, t_before, t_after = -1, t_end, t_end
            if timed:
                w, t_before, t_after = time_bound(prob, m, t, min(t_end, t + min(h_abs, cfg.max_step)), y0, y1)
            if w >= 0 and t_before <= t:  # at a surface of time alone: its transition, just past it
                i_sample = _held(samples, i_sample, t_after, m, y0, y1, ledger_work)
                m, y0, y1, sw, n_sw, capped, outcome = _switched(prob, cfg, w, t_after, y0, y1, m, history, sw, n_sw,
                                                                 buf)
                t = t_after
                break
            r = accepted_step(rhs, p, m, t, y0, y1, h_abs, t_before if w >= 0 else t_end, method, K, cfg, err_prev)
            t_new, n0, n1, h_next, err_prev = r.t, r.y0, r.y1, r.h_next, r.err
            nfev += r.nfev
            rejected += r.rejected
            if r.status != ACCEPTED:
                outcome = STEP_FAILED
                break
            steps += 1
            if not (math.isfinite(n0) and math.isfinite(n1)):
                outcome = NONFINITE_STATE
                break
            h = t_new - t
            interpolant = ledger or (i_sample < samples.t.shape[0] and samples.t[i_sample] <= t_new)
            if interpolant:
                nfev += dense_coefficients(rhs, p, m, t, y0, y1, h, method, K, Q)
            w, t_cross = -1, t_new
            if watched:
                on_surface = not have_start or zero_at_start(work, n_watched)
                if not (screen and clear_of_surfaces(prob, m, t, t_new, n0, n1, K[n, 1], cfg, have_start, work)):
                    if not interpolant:
                        nfev += dense_coefficients(rhs, p, m, t, y0, y1, h, method, K, Q)
                    w, t_cross = _crossed(prob, m, t, t_new, y0, y1, n0, n1, Q, cfg, have_start, on_surface, work)
                    if w == NONFINITE:
                        outcome = NONFINITE_STATE
                        break
                    if w == SHORTER:  # the step again from its start (K[0] = f there still), shorter
                        h_abs = SHORTEN * h
                        continue
                have_start = True
            if i_sample < samples.t.shape[0] and samples.t[i_sample] <= t_cross:
                i_sample = _sample(prob, samples, i_sample, t_cross, m, t, h, y0, y1, Q, ledger_work, ledger_tmp, buf)
            if ledger:
                _account(prob, m, t, h, y0, y1, Q, t_cross, buf, ledger_work)
            h_last = h
            if w >= 0:
                c0, c1, verdict, f = _crossing_state(prob, method, m, w, t, t_new, y0, y1, n0, n1, h, Q, t_cross, K,
                                                     retries < cfg.crossing_retries)
                nfev += f
                if verdict == NOT_YET:  # on in this mode from there
                    t, y0, y1, h_abs = t_cross, c0, c1, h
                    K[0, 0], K[0, 1] = K[n, 0], K[n, 1]
                    have_start, retries = False, retries + 1
                    continue
                retries = 0
                m, y0, y1, sw, n_sw, capped, outcome = _switched(prob, cfg, w, t_cross, c0, c1, m, history, sw, n_sw,
                                                                 buf)
                t = t_cross
                break
            t, y0, y1, h_abs = t_new, n0, n1, h_next
            retries = 0
            capped = False
            K[0, 0], K[0, 1] = K[n, 0], K[n, 1]
            if abs(y0) > cfg.angle_limit:
                outcome = ANGLE_LIMIT
                break
    # a plain tuple, in the order of RAW_FIELDS: numba boxes a NamedTuple by calling its Python
    # __new__, and a Ctrl-C pending when the loop returns makes that call fail, which numba's
    # boxing does not check (a crash)
    return outcome, i_sample, sw, n_sw, nfev, steps, rejected, m, t, y0, y1


#: run()'s plain tuple, field by field: Run's fields with the switch buffer and its count (SW_*
#: rows) in place of ``switches``
RAW_FIELDS = ("outcome", "n_samples", "switch_buffer", "n_switches", "nfev", "steps", "rejected", "mode", "t", "alpha",
              "alpha_dot")


#: run's own body compiled as the entry point, not a function calling it: numba optimizes and
#: generates the machine code of a function together with everything it calls, once per
#: compiled function, so one level less is one pass less over the whole loop on a cold start.
#: numba compiles a helper once per set of compile options of its callers, and the entry's
#: differ from the helpers' (it has a Python wrapper): so run calls no helper that another
#: helper also calls (allocations in _buffers, the ledger through _account, the interpolant's
#: restart state in _restart_state), else that helper is compiled twice
_run_compiled = njit(cache=True, nogil=True, error_model="numpy")(run)


#: the compiled loop's machine-code entry per layout of its arguments (:func:`_layout`), found by
#: the dispatcher on the first call with that layout and called directly after it: numba's
#: dispatcher types every argument on every call, which costs a short run more than its
#: integration (docs/design-notes.md, *Typing the loop's arguments on every call*)
_ENTRIES: dict = {}


def loop_loaded() -> bool:
    """Whether the compiled loop is in memory (compiled or loaded from the cache already)."""
    return bool(_ENTRIES) or bool(_run_compiled.signatures)


def loop_cached() -> bool:
    """Whether the compiled loop of this camdyn, engine and source file is in the cache: numba's
    index for this module's entry point exists and matches the file (numba keys it by the file's
    path and time stamp, so another checkout of the same engine does not count)."""
    try:
        return bool(_run_compiled._cache._cache_file._load_index())
    except (AttributeError, OSError):  # numba's internals moved: any index of the loop
        return any((cache.cache_dir() / "numba").rglob("loop.run-*.nbi"))


def _layout(value):
    """What numba's type of an argument depends on: a tuple by its class and fields, an array by
    its dtype, dimensions and contiguity, anything else by its class (a cfunc's signature is the
    one :mod:`.kernels` compiles its position in ``Kernels`` with)."""
    if isinstance(value, tuple):
        return (type(value),) + tuple(_layout(v) for v in value)
    if isinstance(value, np.ndarray):
        return value.dtype.char, value.ndim, value.flags.c_contiguous
    return type(value)


def run_compiled(prob, method, cfg, start, samples) -> Run:
    """:func:`run`, compiled; the kernels of ``prob`` must be numba cfuncs.  The first call with a
    layout of arguments goes through numba's dispatcher (which compiles or loads the loop); later
    ones enter the compiled code directly."""
    args = (prob, method, cfg, start, samples)
    key = _layout(args)
    entry = _ENTRIES.get(key)
    if entry is None:
        raw = _run_compiled(*args)
        signature = tuple(_run_compiled.typeof_pyval(a) for a in args)
        _ENTRIES[key] = _run_compiled.overloads[signature].entry_point
        return _finish(raw)
    return _finish(entry(*args))


def run_interpreted(prob, method, cfg, start, samples) -> Run:
    """:func:`run` in Python, with Python kernels."""
    with np.errstate(divide="ignore", invalid="ignore", over="ignore"):
        return _finish(run(prob, method, cfg, start, samples))


def _finish(raw: tuple) -> Run:
    """The :class:`Run` of :func:`run`'s tuple (RAW_FIELDS; switches as SWITCH records)."""
    fields = dict(zip(RAW_FIELDS, raw))
    switches = _switch_records(fields.pop("switch_buffer"), fields.pop("n_switches"))
    return Run(switches=switches, **fields)
