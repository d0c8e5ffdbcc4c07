"""The floor (benchmarks/floor.py) and where the engine's time goes: its pieces in a bare one-mode
loop, the cost of a compiled call by how it passes arrays, and the rules' work per step."""
from __future__ import annotations

import types

import numpy as np
from numba import njit
from numba.extending import register_jitable

import floor
from camdyn.engine import rules, stepper
from camdyn.engine.jit import jitable
from camdyn.vocabulary import WITH_RATE_RATE, WITH_RATE_VALUE

from .cases import Config


def floor_section(cfg: Config) -> dict:
    """The floor's measurement (benchmarks/floor.py) and the engine diagnostics below."""
    run = floor.SlidingRun()
    rep = floor.measure(run, cfg.floor_rounds)
    model = run.model()
    args = floor.engine_args(model, run)
    mode = model.kernels.MODES.index(rep.mode)
    return {"floor": rep, "pieces": engine_pieces(model, run, args, mode, cfg.floor_rounds // 2),
            "calls": call_costs(model, args, mode), "counts": rule_work(model, run)}


@njit(error_model="numpy")
def _engine_partial(prob, method, cfg, m, t, t_end, y0, y1, level):
    """The engine's stepper in one mode (level 0), + its dense output every step (1), + its
    crossing check rules.first_crossing every step (2); the stepper + the reach rule's
    rules.clear_of_surfaces every step, no interpolant (3): a diagnostic, not the floor."""
    tab = prob.tables
    rhs, p = prob.kernels.rhs, prob.p
    K = np.empty((method.n_rows, 2))
    Q = np.empty((2, method.degree))
    work = rules.scratch(tab.n_transitions, tab.n_surfaces)
    K[0, 0], K[0, 1] = y1, rhs(m, t, y0, y1, p)
    h = stepper.initial_step(rhs, p, m, t, y0, y1, K[0, 1], t_end, method, cfg)
    steps, crossings, have_start, n, err = 0, 0, False, method.n_stages, stepper.ERR_FLOOR
    while t < t_end:
        _, t_new, n0, n1, h_next, _, _, err = stepper.accepted_step(rhs, p, m, t, y0, y1, h, t_end, method, K, cfg,
                                                                    err)
        steps += 1
        if level == 3:
            if not rules.clear_of_surfaces(prob, m, t, t_new, n0, n1, K[n, 1], cfg, have_start, work):
                crossings += 1
            have_start = True
        elif level >= 1:
            stepper.dense_coefficients(rhs, p, m, t, y0, y1, t_new - t, method, K, Q)
        if level == 2:
            w, _ = rules.first_crossing(prob, m, t, t_new, y0, y1, n0, n1, Q, cfg, have_start, work)
            have_start = True
            if w >= 0:
                crossings += 1
        t, y0, y1, h = t_new, n0, n1, h_next
        K[0, 0], K[0, 1] = K[n, 0], K[n, 1]
    return steps, crossings


PIECES = ("engine stepper alone", "+ dense output every step", "+ rules.first_crossing every step",
          "stepper + rules.clear_of_surfaces every step (no interpolant)")


def engine_pieces(model, run, args, mode: int, rounds: int) -> dict:
    """Best time per step of the engine's pieces run in one mode, interleaved with the full loop."""
    a = (args.prob, args.method, args.cfg, mode, 0.0, run.t_end, args.start.alpha, args.start.alpha_dot)
    fns, steps = {}, {}
    for level, label in enumerate(PIECES):
        steps[label] = _engine_partial(*a, level)[0]
        fns[label] = (lambda level=level: _engine_partial(*a, level))
    r = floor.run_engine(args)
    fns["engine loop as it runs (run_compiled)"], steps["engine loop as it runs (run_compiled)"] = (
        (lambda: floor.run_engine(args)), r.steps)
    times = floor.interleaved(fns, max(3, rounds))
    return {k: min(v) / steps[k] * 1e6 for k, v in times.items()}


def _values(prob, m, t, a, ad, work):
    """A mode's sampled surfaces (Tables.sampled) into work's VALUES row, as first_crossing
    computes them (a surface with a rate and its rate in one call), but in a called helper that
    takes the Problem and the work array."""
    tab = prob.tables
    pair = work[rules.WITH_RATE]
    for q in range(tab.data[tab.sampled_start + m], tab.data[tab.sampled_start + m + 1]):
        s = tab.data[tab.sampled + q]
        rate = tab.data[tab.surface_rate + s]
        if rate >= 0:
            prob.kernels.surface_with_rate(m, s, t, a, ad, prob.p, pair)
            work[rules.VALUES, s], work[rules.VALUES, rate] = pair[WITH_RATE_VALUE], pair[WITH_RATE_RATE]
        else:
            work[rules.VALUES, s] = prob.kernels.surface(m, s, t, a, ad, prob.p)


def _copy(fn, name):
    return types.FunctionType(fn.__code__, fn.__globals__, name)


#: _values compiled as numba compiles a helper by default (reference-counted), and as the engine's
#: helpers are (camdyn.engine.jit.jitable: no reference counts, the caller's arrays borrowed)
_values_counted = register_jitable(error_model="numpy")(_copy(_values, "_values_counted"))
_values_borrowed = jitable(_copy(_values, "_values_borrowed"))


def _sample_loop(helper):
    """A compiled loop that fills work's VALUES row n times through ``helper`` (a _values copy)."""
    @njit(error_model="numpy")
    def loop(prob, work, m, n, a, ad):
        acc = 0.0
        for i in range(n):
            helper(prob, m, i * 1e-8, a, ad, work)
            acc += work[rules.VALUES, 0]
        return acc
    return loop


_counted_loop, _borrowed_loop = _sample_loop(_values_counted), _sample_loop(_values_borrowed)


@njit(error_model="numpy")
def _direct_loop(prob, work, m, n, a, ad):
    """The same surface values as _counted_loop, by direct kernel calls in the loop."""
    tab = prob.tables
    surface, with_rate, p = prob.kernels.surface, prob.kernels.surface_with_rate, prob.p
    pair = work[rules.WITH_RATE]
    acc = 0.0
    for i in range(n):
        for q in range(tab.data[tab.sampled_start + m], tab.data[tab.sampled_start + m + 1]):
            s = tab.data[tab.sampled + q]
            rate = tab.data[tab.surface_rate + s]
            if rate >= 0:
                with_rate(m, s, i * 1e-8, a, ad, p, pair)
                work[rules.VALUES, s], work[rules.VALUES, rate] = pair[WITH_RATE_VALUE], pair[WITH_RATE_RATE]
            else:
                work[rules.VALUES, s] = surface(m, s, i * 1e-8, a, ad, p)
        acc += work[rules.VALUES, 0]
    return acc


CALLS = ("a helper(prob, ..., work), reference-counted", "the same helper without reference counts (jitable)",
         "the same kernel calls, direct")


def call_costs(model, args, mode: int, calls: int = 200_000) -> dict:
    """ns per sample: the mode's sampled surfaces through a called helper passing the Problem and
    the work array, compiled with and without numba's reference counting, against the same
    kernel calls made directly, all compiled."""
    work = rules.scratch(args.prob.tables.n_transitions, args.prob.tables.n_surfaces)
    a, ad = args.start.alpha, args.start.alpha_dot
    loops = (_counted_loop, _borrowed_loop, _direct_loop)
    fns = {k: (lambda f=f: f(args.prob, work, mode, calls, a, ad)) for k, f in zip(CALLS, loops)}
    for fn in fns.values():
        fn()
    times = floor.interleaved(fns, 7)
    return {k: min(v) / calls * 1e9 for k, v in times.items()}


def rule_work(model, run) -> dict:
    """Calls per accepted step of the engine's rules and kernels, counted on the interpreted
    backend (the same loop source, run by Python) on the floor's run; the rules are wrapped for
    the count and restored."""
    from camdyn.engine import loop
    from camdyn.engine.kernels import python_kernels
    from camdyn.engine.problem import Problem
    counts = {"rhs": 0, "surface": 0, "with_rate": 0, "extremum": 0, "locate": 0, "cleared": 0}
    kern = python_kernels(model.kernels)

    def counted(name, fn):
        def wrapper(*a):
            counts[name] += 1
            return fn(*a)
        return wrapper
    saved = {n: getattr(rules, n) for n in ("extremum", "locate")}
    clear = loop.clear_of_surfaces

    def cleared(*a):
        verdict = clear(*a)
        counts["cleared"] += verdict
        return verdict
    try:
        for n, fn in saved.items():
            setattr(rules, n, counted(n, fn))
        loop.clear_of_surfaces = cleared
        args = floor.engine_args(model, run)
        prob = Problem(kern._replace(rhs=counted("rhs", kern.rhs), surface=counted("surface", kern.surface),
                                     surface_with_rate=counted("with_rate", kern.surface_with_rate)),
                       args.prob.tables, args.prob.p)
        r = loop.run_interpreted(prob, args.method, args.cfg, args.start, args.samples)
    finally:
        for n, fn in saved.items():
            setattr(rules, n, fn)
        loop.clear_of_surfaces = clear
    return {**{k: v / r.steps for k, v in counts.items()}, "steps": r.steps}
