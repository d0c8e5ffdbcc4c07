"""Work-precision report of camdyn's engine against a floor loop and peers: regenerates
docs/performance.md and docs/img/perf_*.png.  Run from the repository root:

    python benchmarks/performance.py              # full report
    python benchmarks/performance.py --quick      # fewer tolerances and repeats (smoke run, a few minutes)
    python benchmarks/performance.py --no-sweeps  # without the sweep timing section

Every number and figure in docs/performance.md comes from this script, and every comparison
of times is measured in one process, the solvers compared run in interleaved rounds (A B C,
C B A, ...) so that a busy spell of the machine falls on all of them alike.

* The floor (benchmarks/floor.py): a minimal event-capable DOP853 loop on the same generated
  kernels, against the engine's compiled loop on the "sliding" run, with a per-step breakdown.
* Work-precision per scene: camdyn's compiled engine (DOP853, RK45) at a range of rtol, error
  against the engine's DOP853 at rtol 1e-12 (checked against its RK45 at rtol 1e-12), against
  the peers numbalsoda (LSODA, DOP853) and SUNDIALS CVODE (scikit-sundae, BDF and Adams) where
  installed.  Peers get the same generated kernels: their field follows the scene's hybrid
  automaton without event location (a mode register in the RHS, moved on whenever the state is
  across one of the mode's surfaces; see :func:`peer_field`).
* Start-up: cold (empty numba cache) and warm, each in fresh processes.
* Sweeps (optional): the bifurcation diagram and contact-loss map timed with camdyn.sweep.api; the
  diagram stopping once periodic and shooting from the quasi-static warm start (sweep_stop.py).
"""
from __future__ import annotations

import argparse
import math
import os
import platform
import statistics
import subprocess
import sys
import tempfile
import time
import types
from concurrent.futures import ProcessPoolExecutor
from dataclasses import dataclass
from pathlib import Path
from typing import Callable, NamedTuple

import numba
import numpy as np
from numba import njit
from numba.extending import register_jitable

import camdyn
import floor
import sweep_stop
from camdyn.vocabulary import WITH_RATE_RATE, WITH_RATE_VALUE
from camdyn.engine import rules, stepper
from camdyn.engine.jit import jitable
from camdyn.engine.config import EventSettings, SolverOptions
from camdyn.engine.driver import integrate
from camdyn.engine.kernels import compiled_kernels
from camdyn.engine.tables import tables
from camdyn.model.model import Model

ROOT = Path(__file__).resolve().parent.parent
DOCS, IMG = ROOT / "docs", ROOT / "docs" / "img"
RIG = camdyn.example_rig()
ATOL_PER_RTOL = 1e-4           # atol = 1e-4 rtol throughout
REFERENCE_RTOL = 1e-12         # engine DOP853: the reference; engine RK45: its check
#: camdyn's runs: label -> (method, reach factor of the crossing check, step-size controller);
#: the first two as camdyn runs by default; "every step sampled" the engine sampling every step's
#: interpolant at its interior points (EventSettings(reach_factor=inf)), as it did before the reach
#: rule, to show what the rule saves against the peers, which locate no events; "SciPy's step
#: control" the engine with SciPy's step-size controller instead of the default PI one
_REACH, _CONTROL = EventSettings().reach_factor, SolverOptions().step_control
CAMDYN = {"camdyn compiled DOP853": ("DOP853", _REACH, _CONTROL), "camdyn compiled RK45": ("RK45", _REACH, _CONTROL),
          "camdyn DOP853, every step sampled": ("DOP853", math.inf, _CONTROL),
          "camdyn DOP853, SciPy's step control": ("DOP853", _REACH, "scipy")}
MAIN, EVERY, SCIPY = ("camdyn compiled DOP853", "camdyn DOP853, every step sampled",
                      "camdyn DOP853, SciPy's step control")


@dataclass(frozen=True)
class Config:
    """What one run of the script measures."""

    quick: bool
    tols: tuple
    repeats: int               # interleaved rounds per (scene, rtol)
    floor_rounds: int
    start_runs: int            # fresh processes per start-up kind
    sweeps: bool
    speeds: int
    revolutions: int
    budget: float = 2.0        # s: a peer slower than this on one run is not run at tighter rtol

    @classmethod
    def from_args(cls, args) -> "Config":
        quick = args.quick
        return cls(quick, (1e-5, 1e-8, 1e-11) if quick else (1e-5, 1e-6, 1e-7, 1e-8, 1e-9, 1e-10, 1e-11),
                   2 if quick else 5, 10 if quick else 100, 1 if quick else 3, not args.no_sweeps,
                   20 if quick else 200, args.revolutions or (40 if quick else 200))


@dataclass(frozen=True)
class Case:
    key: str
    title: str
    scene: dict
    rig: dict
    cam: object
    t_end: float
    metric: str          # "impacts" (impact times + alpha) or "alpha" (max |alpha - ref|)
    fs: float = 5000.0

    def model(self) -> Model:
        return Model(RIG.replace(**self.rig) if self.rig else RIG, camdyn.Scene(**self.scene), self.cam)

    def t_eval(self) -> np.ndarray:
        return np.arange(int(math.floor(self.t_end * self.fs + 1e-9)) + 1) / self.fs


def cases() -> list[Case]:
    loss = camdyn.contact_loss_speed(RIG.replace(l_lambda=0.016))
    imp = round(1.1 * loss)
    return [
        Case("impacting", f"impacting, line 16 mm, D, {imp} rev/min (1.1 x contact loss)",
             dict(damping="D", friction="coulomb"), {"l_lambda": 0.016}, camdyn.ConstantSpeed(imp),
             3 * 60 / imp, "impacts"),
        Case("sliding_de", "sliding, line 1.6 mm, D, +300 rev/min (de-energizing)",
             dict(damping="D", friction="coulomb"), {}, camdyn.ConstantSpeed(300), 0.2, "alpha"),
        Case("sliding_self", "sliding, line 1.6 mm, D, -300 rev/min (self-energizing)",
             dict(damping="D", friction="coulomb"), {}, camdyn.ConstantSpeed(-300), 0.2, "alpha"),
        Case("sliding_point", "sliding, point contact, D, +300 rev/min",
             dict(contact="point", damping="D", friction="coulomb"), {}, camdyn.ConstantSpeed(300), 0.2, "alpha"),
        Case("reversal_coulomb", "friction reversal, e = 0.7 r_c, 50 rev/min, Coulomb (printed v_r)",
             dict(damping="D", friction="coulomb", sliding_velocity="printed"), {"e": 0.7 * RIG.r_c},
             camdyn.ConstantSpeed(50), 0.3, "alpha"),
        Case("reversal_tanh", "friction reversal, e = 0.7 r_c, 50 rev/min, tanh (printed v_r)",
             dict(damping="D", friction="tanh", sliding_velocity="printed"), {"e": 0.7 * RIG.r_c},
             camdyn.ConstantSpeed(50), 0.3, "alpha"),
        Case("oscillating", "oscillating cam, Theta_p = pi, 40 rev/min, D, tanh",
             dict(damping="D", friction="tanh", motion="oscillating"), {}, camdyn.Oscillating(math.pi, 40.0),
             0.3, "alpha"),
    ]


# --- running and measuring ------------------------------------------------------------------------
class Sample(NamedTuple):
    """What a solver's run gives the error measure."""

    alpha: np.ndarray
    impacts: np.ndarray | None     # impact times (camdyn only), else None
    ok: bool
    switches: int


def camdyn_runner(case: Case, model: Model, method: str, rtol: float, reach_factor: float = _REACH,
                  step_control: str = _CONTROL) -> Callable[[], Sample]:
    """driver.integrate() on a model built once (as the peers' runners are): the work measured is
    integration, event location and sampling, not model set-up or output kernels."""
    t_eval, y0 = case.t_eval(), model.static_state()
    options = SolverOptions(method=method, rtol=rtol, atol=rtol * ATOL_PER_RTOL,
                            events=EventSettings(reach_factor=reach_factor), step_control=step_control)

    def run() -> Sample:
        tr = integrate(model, (0.0, case.t_end), y0, t_eval, options)
        hits = np.array([s.t for s in tr.switches if s.surface == "gap" and s.before == "free"])
        alpha = tr.y[0] if tr.t.size == t_eval.size else np.full(t_eval.size, np.nan)
        return Sample(alpha, hits, tr.outcome.ok, len(tr.switches))
    return run


def error(case: Case, ref: Sample, s: Sample) -> float:
    """max |alpha - alpha_ref| on the samples; for impacting runs with impact times (camdyn) also
    10 x the largest impact-time difference (s)."""
    if not s.ok or s.alpha.shape != ref.alpha.shape or not np.all(np.isfinite(s.alpha)):
        return math.inf
    e = float(np.max(np.abs(s.alpha - ref.alpha)))
    if case.metric == "impacts" and s.impacts is not None:
        same = s.impacts.size == ref.impacts.size
        e = max(e, float(np.max(np.abs(s.impacts - ref.impacts), initial=0.0)) * 10.0 if same else math.inf)
    return e


# --- peers: the same generated kernels, the automaton followed without event location -------------
#: transitions taken in a row within one evaluation of a peer's field, at most
MAX_HOPS = 4


def peer_field(model: Model):
    """A compiled ``field(t, alpha, alpha_dot, p, mem) -> alpha_ddot`` for solvers without event
    location.  ``mem[0]`` is the current mode (-1 at the start: the automaton's initial choice);
    each call first takes any transition of that mode whose surface the state is strictly
    across (direction * value > 0), into the first target whose conditions hold, then evaluates
    the generated rhs in the mode.  The register moves at every evaluation, trial stages
    included: what a solver without events can do with a hybrid model whose mode has memory
    (damping D's impact law lasts from contact to maximum compression, not while the gap closes)."""
    kern = compiled_kernels(model.kernels)
    tab = tables(model.kernels)
    rhs, surface = kern.rhs, kern.surface
    ws, sf, dr, ts, tm, cs, csf, csg = (np.ascontiguousarray(tab.data[offset:]) for offset in (
        tab.watch_start, tab.surface, tab.direction, tab.target_start, tab.target_mode, tab.condition_start,
        tab.condition_surface, tab.condition_sign))
    initial = tab.n_transitions

    @njit(error_model="numpy")
    def target(row, t, a, ad, p):
        for c in range(ts[row], ts[row + 1]):
            holds = True
            for q in range(cs[c], cs[c + 1]):
                if csg[q] * surface(tm[c], csf[q], t, a, ad, p) < 0.0:
                    holds = False
                    break
            if holds:
                return tm[c]
        return tm[ts[row + 1] - 1]

    @njit(error_model="numpy")
    def field(t, a, ad, p, mem):
        m = int(mem[0])
        if m < 0:
            m = target(initial, t, a, ad, p)
        for _ in range(MAX_HOPS):
            hit = -1
            for w in range(ws[m], ws[m + 1]):
                if dr[w] * surface(m, sf[w], t, a, ad, p) > 0.0:
                    hit = w
                    break
            if hit < 0:
                break
            m = target(hit, t, a, ad, p)
        mem[0] = m
        return rhs(m, t, a, ad, p)
    return field


def numbalsoda_rhs(field, n: int):
    """numbalsoda's cfunc: data = the parameter vector followed by the mode register."""
    import numbalsoda

    @numba.cfunc(numbalsoda.lsoda_sig)
    def rhs(t, u, du, data):
        arr = numba.carray(data, (n + 1,))
        du[0] = u[1]
        du[1] = field(t, u[0], u[1], arr[:n], arr[n:])
    return rhs


def numbalsoda_runner(case: Case, model: Model, rhs, method: str, rtol: float) -> Callable[[], Sample]:
    import numbalsoda
    solver = numbalsoda.dop853 if method == "DOP853" else numbalsoda.lsoda
    t_eval, y0 = case.t_eval(), model.static_state()
    data = np.append(model.p, -1.0)

    def run() -> Sample:
        data[-1] = -1.0
        usol, ok = solver(rhs.address, y0, t_eval, data=data, rtol=rtol, atol=rtol * ATOL_PER_RTOL)
        return Sample(usol[:, 0].copy(), None, bool(ok), 0)
    return run


def cvode_runner(case: Case, model: Model, field, method: str, rtol: float) -> Callable[[], Sample]:
    """SUNDIALS CVODE through scikit-sundae: its RHS is a Python callback calling the compiled field."""
    from sksundae.cvode import CVODE
    p, mem = model.p.copy(), np.array([-1.0])

    def rhsfn(t, y, yp):
        yp[0] = y[1]
        yp[1] = field(t, y[0], y[1], p, mem)
    t_eval = case.t_eval()
    solver = CVODE(rhsfn, method=method, rtol=rtol, atol=rtol * ATOL_PER_RTOL, max_num_steps=10**7)

    def run() -> Sample:
        mem[0] = -1.0
        sol = solver.solve(t_eval, model.static_state())
        ok = bool(sol.success) and sol.t.size == t_eval.size
        return Sample(sol.y[:, 0].copy() if ok else np.full(t_eval.size, np.nan), None, ok, 0)
    return run


def peers_available() -> dict[str, bool]:
    out = {}
    for name, module in (("numbalsoda", "numbalsoda"), ("scikit-sundae", "sksundae")):
        try:
            __import__(module)
            out[name] = True
        except Exception:  # noqa: BLE001 - any import failure means "not installed here"
            out[name] = False
    return out


# --- work-precision ----------------------------------------------------------------------------------
class Prepared(NamedTuple):
    """A case's model and the compiled peer functions, built once for all tolerances."""

    case: Case
    model: Model
    field: object
    nbs_rhs: object


def prepare(case: Case, peers: dict) -> Prepared:
    model = case.model()
    field = peer_field(model) if any(peers.values()) else None
    if field is not None:
        field(0.0, *model.static_state(), model.p, np.array([-1.0]))
    nbs = numbalsoda_rhs(field, model.p.size) if peers.get("numbalsoda") else None
    return Prepared(case, model, field, nbs)


def solvers(pc: Prepared, peers: dict, rtol: float, skip: set) -> dict[str, Callable[[], Sample]]:
    """Every solver's runner at rtol (those in ``skip`` left out)."""
    out = {label: camdyn_runner(pc.case, pc.model, method, rtol, *how) for label, (method, *how) in CAMDYN.items()}
    if peers.get("numbalsoda"):
        for m in ("DOP853", "LSODA"):
            out[f"numbalsoda {m}"] = numbalsoda_runner(pc.case, pc.model, pc.nbs_rhs, m, rtol)
    if peers.get("scikit-sundae"):
        for m in ("BDF", "Adams"):
            out[f"CVODE {m}"] = cvode_runner(pc.case, pc.model, pc.field, m, rtol)
    return {k: v for k, v in out.items() if k not in skip}


def reference(pc: Prepared) -> tuple[Sample, Sample, dict]:
    """The engine's DOP853 at REFERENCE_RTOL, its RK45 at the same rtol, and the reference's stats."""
    case, model = pc.case, pc.model
    ref = camdyn_runner(case, model, "DOP853", REFERENCE_RTOL)()
    check = camdyn_runner(case, model, "RK45", REFERENCE_RTOL)()
    tr = integrate(model, (0.0, case.t_end), model.static_state(), case.t_eval(),
                   SolverOptions("DOP853", REFERENCE_RTOL, REFERENCE_RTOL * ATOL_PER_RTOL))
    modes = sorted(set(tr.regime.tolist()) | {s.before for s in tr.switches} | {s.after for s in tr.switches})
    return ref, check, {"switches": len(tr.switches), "modes": modes, "outcome": tr.outcome.name}


def measure_case(case: Case, cfg: Config, peers: dict) -> dict:
    """Per rtol, all solvers in interleaved rounds; per solver the best time and the error."""
    pc = prepare(case, peers)
    ref, check, info = reference(pc)
    curves: dict[str, list] = {}
    skip: set = set()
    for rtol in cfg.tols:
        runs = solvers(pc, peers, rtol, skip)
        first = {k: fn() for k, fn in runs.items()}            # warm-up, and the result measured
        times = floor.interleaved(runs, cfg.repeats)
        for label, sample in first.items():
            best = min(times[label])
            curves.setdefault(label, []).append((rtol, best, error(case, ref, sample)))
            if best > cfg.budget and not label.startswith("camdyn"):
                skip.add(label)
    return {"case": case, "curves": curves, "agreement": error(case, ref, check), "info": info,
            "ref_impacts": ref.impacts.size, "skipped": sorted(skip)}


def time_at_error(points, target: float) -> float:
    """Wall time a solver needs for error <= target, interpolated in log-log along its curve."""
    pts = sorted((e, s) for _, s, e in points if math.isfinite(e) and e > 0)
    ok = [(e, s) for e, s in pts if e <= target]
    if not ok:
        return math.nan
    e_hi = [(e, s) for e, s in pts if e > target]
    best = min(s for _, s in ok)
    if e_hi:  # interpolate between the tightest-failing and loosest-passing points
        (e1, s1), (e0, s0) = max(ok), min(e_hi)
        if e0 > e1 > 0:
            w = (math.log(target) - math.log(e1)) / (math.log(e0) - math.log(e1))
            best = min(best, math.exp(math.log(s1) + w * (math.log(s0) - math.log(s1))))
    return best


class Ratio(NamedTuple):
    rtol: float
    error: float
    seconds: float
    numbalsoda: float      # numbalsoda's best time at this error / camdyn's (nan: never reached it)
    nbs_reached: bool
    best_peer: str | None
    peer: float            # the fastest peer's time at this error / camdyn's


def ratios(result: dict, label: str = MAIN) -> list[Ratio]:
    """Per point of camdyn's run ``label``: the peers' time at the error it reached, over its time
    (> 1: ahead)."""
    curves = result["curves"]
    peers = [k for k in curves if not k.startswith("camdyn")]
    rows = []
    for rtol, s, e in curves[label]:
        if not math.isfinite(e):
            continue
        target = max(e, 1e-300)
        at = {k: time_at_error(curves[k], target) for k in peers}
        reached = {k: v for k, v in at.items() if math.isfinite(v)}
        nbs = [v for k, v in reached.items() if k.startswith("numbalsoda")]
        best = min(reached, key=reached.get) if reached else None
        rows.append(Ratio(rtol, e, s, min(nbs) / s if nbs else math.nan, bool(nbs), best,
                          reached[best] / s if best else math.nan))
    return rows


# --- the floor and where the engine's time goes ---------------------------------------------------
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
        _, t_new, n0, n1, h_next, _, _, err = stepper.step(rhs, p, m, t, y0, y1, h, t_end, method, K, cfg, err)
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


# --- start-up ---------------------------------------------------------------------------------------
START_CODE = ("import time; t0 = time.perf_counter(); import camdyn; "
              "camdyn.simulate(camdyn.example_rig(), camdyn.Scene(), speed_rpm=300, t_end=0.01); "
              "print(time.perf_counter() - t0)")
START_COMMAND = f'CAMDYN_CACHE_DIR=<dir> python -c "{START_CODE}"'


def _fresh_process(cache: str) -> tuple[float, float]:
    """(in-process s from before `import camdyn` to the end of the run, whole process wall s)."""
    env = {**os.environ, "CAMDYN_CACHE_DIR": cache}
    t0 = time.perf_counter()
    out = subprocess.run([sys.executable, "-c", START_CODE], env=env, capture_output=True, text=True, check=True)
    return float(out.stdout.split()[-1]), time.perf_counter() - t0


def start_times(cfg: Config) -> dict:
    """Cold start: a fresh process on a new, empty CAMDYN_CACHE_DIR (numba compiles the engine
    and the scene's kernels); warm start: a fresh process on a filled one.  Alternated, so a busy
    spell falls on both."""
    cold, warm = [], []
    with tempfile.TemporaryDirectory() as filled:
        _fresh_process(filled)                      # fill it
        for _ in range(cfg.start_runs):
            with tempfile.TemporaryDirectory() as empty:
                cold.append(_fresh_process(empty))
            warm.append(_fresh_process(filled))
    med = lambda xs, i: statistics.median(x[i] for x in xs)  # noqa: E731
    return {"cold": med(cold, 0), "cold_process": med(cold, 1), "warm": med(warm, 0), "warm_process": med(warm, 1),
            "runs": cfg.start_runs, "cold_all": [c[0] for c in cold], "warm_all": [w[0] for w in warm]}


# --- sweeps -----------------------------------------------------------------------------------------
#: the bifurcation sweep's tolerance (permanent_contact_tolerance shows rtol against cost and error)
SWEEP_RTOL = 1e-7


def permanent_contact_tolerance(revolutions: int) -> dict:
    """One permanent-contact point of the sweep (0.85 x the contact-loss speed) at several
    tolerances: wall time, steps, switches and the largest error of its Poincare section
    (the second half of the revolutions) against rtol 1e-10."""
    rig = RIG.replace(l_lambda=0.016)
    scene = camdyn.Scene(damping="D", friction="coulomb")
    speed = 0.85 * camdyn.contact_loss_speed(rig)
    rows = []
    for rtol in (1e-10, 1e-6, 1e-7, 1e-8):
        t0 = time.perf_counter()
        res = camdyn.simulate(rig, scene, camdyn.ConstantSpeed(speed), revolutions=revolutions,
                              sample_rate_Hz=speed / 60.0, rtol=rtol, atol=rtol * ATOL_PER_RTOL)
        rows.append((rtol, time.perf_counter() - t0, res.stats["steps"], len(res.switches), res.alpha))
    ref = rows[0][4]
    half = ref.size // 2
    return {"speed": speed, "rows": [(rtol, secs, steps, sw, float(np.max(np.abs(a[half:] - ref[half:]))))
                                     for rtol, secs, steps, sw, a in rows[1:]]}


def _bifurcation_parts(rig, scene, grid, loss, revolutions) -> tuple[list, dict]:
    from camdyn.sweep import api as S
    parts, seconds = [], {}
    for name, part in (("permanent contact", grid[grid <= loss]), ("impacting", grid[grid > loss])):
        t0 = time.perf_counter()
        with ProcessPoolExecutor(2) as pool:
            parts.append(S.bifurcation(rig, scene, part, revolutions=revolutions,
                                       transient_revolutions=revolutions // 2, executor=pool, progress=False,
                                       rtol=SWEEP_RTOL, atol=SWEEP_RTOL * ATOL_PER_RTOL, stop=None))
        seconds[name] = (part.size, time.perf_counter() - t0, float(np.sum(revolutions * 60.0 / part)))
    return parts, seconds


def sweep_timing(cfg: Config) -> dict:
    """The bifurcation sweep timed in two parts, below the contact-loss speed (permanent contact)
    and above it (impacting), every point to the end (stop=None); the contact-loss map; the
    tolerance study of one point; the same diagram stopping once periodic (benchmarks/sweep_stop.py)."""
    import xarray as xr
    from camdyn.analysis import statics as analysis
    from camdyn.sweep import api as S
    rig, scene = RIG.replace(l_lambda=0.016), camdyn.Scene(damping="D", friction="coulomb")
    loss = camdyn.contact_loss_speed(rig)
    grid = np.linspace(0.8 * loss, 1.6 * loss, cfg.speeds)
    S.bifurcation(rig, scene, grid[:2], revolutions=2, transient_revolutions=1, progress=False)  # load
    parts, seconds = _bifurcation_parts(rig, scene, grid, loss, cfg.revolutions)
    t0 = time.perf_counter()
    with ProcessPoolExecutor(2) as pool:
        cmap = S.contact_loss_map(RIG, scene, np.linspace(1000, 5000, 9), np.linspace(400, 2000, 17), executor=pool,
                                  progress=False, rtol=SWEEP_RTOL, atol=SWEEP_RTOL * ATOL_PER_RTOL)
    return {"bif": xr.concat(parts, dim="speed_rpm"), "seconds": sum(v[1] for v in seconds.values()),
            "parts": seconds, "cmap": cmap, "map_seconds": time.perf_counter() - t0, "loss": loss,
            "frequency_Hz": analysis.natural_frequency(rig, scene, camdyn.ConstantSpeed(loss)).Hz,
            "tolerance": permanent_contact_tolerance(cfg.revolutions), "stopping": sweep_stop.measure(cfg.quick)}


# --- the report ----------------------------------------------------------------------------------------
def fmt(x, spec=".3g"):
    return "n/a" if x is None or (isinstance(x, float) and not math.isfinite(x)) else format(x, spec)


def machine_line(peers: dict, load: tuple) -> str:
    cpu = platform.processor() or platform.machine()
    try:
        cpu = next(line.split(":", 1)[1].strip() for line in open("/proc/cpuinfo") if line.startswith("model name"))
    except (OSError, StopIteration):
        pass
    versions = []
    for name, module in (("numbalsoda", "numbalsoda"), ("scikit-sundae", "sksundae")):
        if peers.get(name):
            from importlib.metadata import version
            versions.append(f"{name} {version(name)}")
        else:
            versions.append(f"{name} not installed")
    return (f"Machine: {cpu}, {os.cpu_count()} cores, Python {platform.python_version()}, numpy {np.__version__}, "
            f"numba {numba.__version__}; peers: {', '.join(versions)}.  Load average (1 min) at the start and end "
            f"of the run: {load[0]:.2f}, {load[1]:.2f} (the machine is shared: only ratios measured within one "
            "run, interleaved, are compared).")


def header(cfg: Config, peers: dict, load: tuple, elapsed: float) -> list[str]:
    flags = (" --quick" if cfg.quick else "") + ("" if cfg.sweeps else " --no-sweeps")
    return ["# Performance: camdyn's engine against a floor loop and peers", "",
            f"Generated by `python benchmarks/performance.py{flags}` in {elapsed / 60:.1f} min -- do not edit by "
            "hand; every number and figure below comes from that command.", "", machine_line(peers, load), "",
            "Rig: `camdyn.example_rig()` (the paper's rig geometry is not available); the paper's regimes are "
            "reproduced at the speeds where this rig shows them (impacting just above its contact-loss speed).", "",
            "**Error**: max |alpha - alpha_ref| (rad) over the samples (5 kHz), against camdyn's engine, DOP853 at "
            f"rtol {REFERENCE_RTOL:.0e}; that reference is checked against the engine's RK45 at the same rtol (a "
            "different method): their disagreement is the error floor column of the scene table, below which "
            "errors mean nothing.  For the impacting scene camdyn's error is the larger of that and 10 x the "
            f"largest impact-time difference (s).  atol = {ATOL_PER_RTOL:g} rtol throughout.", "",
            "**Work**: wall time of one run, best of interleaved rounds (every solver of a scene and rtol run in "
            f"turn, {cfg.repeats} rounds), compiled code loaded.  camdyn: `camdyn.engine.driver.integrate()` on a "
            "model built once (set-up and output kernels excluded, as for the peers).  Peers get the same "
            "generated kernels: their field follows the scene's automaton without event location (a mode "
            "register in the RHS, moved whenever the state is across a surface of the mode, trial stages "
            "included); numbalsoda through a numba cfunc, CVODE through a Python callback calling compiled code.", ""]


def floor_lines(fs: dict) -> list[str]:
    rep = fs["floor"]
    run = rep.run
    sw = "; ".join(f"t = {t:.3g} s, {s}: {b} -> {a}" for t, s, b, a in rep.switches) or "none"
    met = "met" if rep.ratio_median <= 1.3 else "**NOT met**"
    lines = ["## The floor: camdyn's loop against a minimal event-capable loop", "",
             "`benchmarks/floor.py`: DOP853 (camdyn's tableau), SciPy's error norm and step-size controller, one "
             "mode for the whole run, dense output, the mode's switching surfaces evaluated on the interpolant at "
             "3 interior points of every accepted step and at its end (sign changes counted, not located), "
             "samples from the interpolant; it calls the scene's generated `rhs` and `surface` as the same numba "
             "cfuncs the engine calls, and none of the engine's rules.  The engine is timed as it runs (a step "
             "whose ends put every watched surface out of reach of zero cleared from them, without interpolant "
             "or interior samples: camdyn.engine.rules, *Reach*) and doing the floor's work, every step sampled "
             "(`EventSettings(reach_factor=inf)`); the loop's overhead, which the issue's target bounds, is the "
             "second against the floor.  Here the engine uses the floor's step-size controller, SciPy's "
             "(`step_control=\"scipy\"`; camdyn's default is the PI controller), so that both take the same steps.", "",
             f"Run: line contact (l_lambda = {RIG.l_lambda * 1e3:g} mm), damping D, Coulomb, `example_rig()`, "
             f"{run.speed_rpm:+g} rev/min, {run.t_end:g} s from the static equilibrium, rtol {run.rtol:.0e}, "
             f"atol {run.atol:.0e}, samples at {run.fs:g} Hz (the work-precision scene sliding_de below).  "
             f"The engine's switches on this run: {sw}.  So the run is in "
             f"**{rep.mode}** after its first {rep.switches[-1][0] if rep.switches else 0:.2g} s (sliding "
             "*backward* in the generated model's sign convention, v_r < 0, not forward); the floor integrates "
             f"that mode throughout, watching {', '.join(rep.watch)}.  Max |alpha_engine - alpha_floor| over the "
             f"samples: {rep.max_alpha_diff:.1e} rad.", "",
             f"**Ratio engine / floor, the same work (every step sampled), time per run: {rep.ratio_median:.2f}** "
             f"(median of {len(rep.times[floor.SAME])} back-to-back pairs; best / best {rep.ratio_best:.2f}); per "
             f"accepted step {rep.us_per_step(floor.SAME):.2f} us against {rep.us_per_step(floor.FLOOR):.2f} us.  "
             f"The issue's target, <= 1.3, is {met}.  The engine as it runs: **{rep.default_ratio:.2f}** x the "
             f"floor's time, {rep.us_per_step(floor.ENGINE):.2f} us per accepted step.", "",
             "| run | best time (ms) | accepted steps | rejected | RHS evaluations | RHS per step | us per step |",
             "|---|---|---|---|---|---|---|"]
    for label, v in rep.variants.items():
        lines.append(f"| {label} | {min(rep.times[label]) * 1e3:.3f} | {v.steps} | {v.rejected} | {v.nfev} | "
                     f"{v.nfev / v.steps:.2f} | {rep.us_per_step(label):.2f} |")
    return lines + [""] + breakdown_lines(fs) + [""] + safety_lines(fs) + [""] + engine_time_lines(fs) + \
        ["", "![floor](img/perf_floor.png)", ""]


def breakdown_lines(fs: dict) -> list[str]:
    rep = fs["floor"]
    v = rep.variants
    per = {k: rep.us_per_step(k) for k in v}
    rhs_us = lambda k: v[k].nfev / v[k].steps * rep.rhs_ns / 1e3  # noqa: E731
    plain, end_only = "floor (no surfaces: plain ODE loop)", "floor (0 interior points: step ends only)"
    checks = per[floor.FLOOR] - per[plain]
    return ["Per accepted step:", "",
            f"- one evaluation of the generated contact RHS (cfunc, in a compiled loop): {rep.rhs_ns:.1f} ns; one "
            f"surface evaluation (mean over {', '.join(rep.watch)}): {rep.surface_ns:.1f} ns;",
            f"- RHS evaluations per step: engine as it runs {v[floor.ENGINE].nfev / v[floor.ENGINE].steps:.2f}, "
            f"every step sampled {v[floor.SAME].nfev / v[floor.SAME].steps:.2f}, floor "
            f"{v[floor.FLOOR].nfev / v[floor.FLOOR].steps:.2f} (12 stages per attempt, rejected attempts included, "
            f"and 3 extra stages for each interpolant): {rhs_us(floor.ENGINE):.2f} us of the engine's "
            f"{per[floor.ENGINE]:.2f} us ({100 * rhs_us(floor.ENGINE) / per[floor.ENGINE]:.0f} %), "
            f"{rhs_us(floor.FLOOR):.2f} us of the floor's {per[floor.FLOOR]:.2f} us "
            f"({100 * rhs_us(floor.FLOOR) / per[floor.FLOOR]:.0f} %);",
            f"- the floor's surface checks (3 interior points and the end, with the interpolant every step): "
            f"{checks:.2f} us per step, {100 * checks / per[floor.FLOOR]:.0f} % of the floor (floor minus plain ODE "
            f"loop); at the step ends only: {per[end_only] - per[plain]:.2f} us; adding the rate surfaces the engine "
            f"also samples: {per['floor (3 interior points, + rate surfaces)'] - per[floor.FLOOR]:+.2f} us."]


def safety_lines(fs: dict) -> list[str]:
    rep, counts = fs["floor"], fs["counts"]
    v = rep.variants
    e = v[floor.SAME]
    extra = e.nfev - 12 * (e.steps + e.rejected) - 3 * e.steps - 2
    interior = rep.us_per_step(floor.SAME) - rep.us_per_step("engine (every step, 0 interior points: step ends only)")
    floor_interior = rep.us_per_step(floor.FLOOR) - rep.us_per_step("floor (0 interior points: step ends only)")
    saved = rep.us_per_step(floor.SAME) - rep.us_per_step(floor.ENGINE)
    return ["What the engine's safety costs on this run:", "",
            f"- interior points, every step sampled: with 3 minus with 0: {interior:.2f} us per step "
            f"({100 * interior / rep.us_per_step(floor.SAME):.0f} % of that engine); the same 3 points cost the floor "
            f"{floor_interior:.2f} us per step;",
            f"- the reach rule: {100 * counts['cleared']:.1f} % of the accepted steps cleared from their ends; the "
            f"engine as it runs takes {saved:.2f} us per step less than sampling every step "
            f"({100 * saved / rep.us_per_step(floor.SAME):.0f} %), with the same run (switches and samples bit "
            "for bit: tests/test_hard_cases.py checks it on hard cases);",
            f"- restarts: {e.switches} switch(es); RHS evaluations beyond the steps' stages, interpolants and the "
            f"start: {extra} in all (one step of the method to the located time, 12, and f at the restart, 1, "
            "per switch), a negligible share here;",
            f"- rule work per accepted step of the engine as it runs (counted on the interpreted backend, same "
            f"loop source, {counts['steps']} steps): {counts['surface'] + 2 * counts['with_rate']:.2f} surface "
            f"evaluations (the floor: {4 * len(rep.watch)}) in {counts['surface'] + counts['with_rate']:.2f} "
            f"kernel calls ({counts['with_rate']:.2f} of them surface_with_rate: the gap and its rate in one call; "
            "the others include the forward difference of the slip's rate along the motion), "
            f"{counts['extremum']:.3f} extremum searches of the gap rate's turns (micro-hop checks), "
            f"{counts['locate'] - counts['extremum']:.3f} root locations, {counts['rhs']:.2f} RHS evaluations."]


def engine_time_lines(fs: dict) -> list[str]:
    pieces, calls, rep = fs["pieces"], fs["calls"], fs["floor"]
    lines = ["Where the engine's time goes (diagnostic: the engine's own functions in a bare one-mode loop, "
             "interleaved with its full loop; us per accepted step):", "",
             "| engine pieces | us per step |", "|---|---|"]
    lines += [f"| {k} | {v:.2f} |" for k, v in pieces.items()]
    counted, borrowed, direct = (calls[k] for k in CALLS)
    lines += ["", f"A sample's surface values through a helper taking the Problem and the work array cost "
              f"{counted:.0f} ns compiled as numba compiles a helper by default, {borrowed:.0f} ns compiled as the "
              f"engine's helpers are (`camdyn.engine.jit.jitable`), and {direct:.0f} ns for the same kernel calls "
              "made directly (all in a compiled loop).  By default every compiled call increments and decrements, "
              "atomically, the reference count of each array it is passed, those in tuples included; the "
              "engine's helpers are compiled without reference counting (they borrow their caller's arrays), "
              "the automaton's tables, the method and first_crossing's work are one array each, and only a "
              "sample that may hide a crossing calls the locating helpers.", "",
              f"`integrate()` on the same run (Python set-up of the tables, method and settings, and the "
              f"Trajectory, included): {rep.integrate_s * 1e3:.2f} ms against "
              f"{min(rep.times[floor.ENGINE]) * 1e3:.2f} ms for `run_compiled` alone."]
    return lines


def start_lines(st: dict) -> list[str]:
    each = lambda xs: ", ".join(f"{x:.1f}" for x in xs)  # noqa: E731
    return ["## Start-up", "",
            f"Median of {st['runs']} fresh processes each (cold and warm alternated); the in-process time runs from "
            "before `import camdyn` to the end of one short run, the process time adds the interpreter's own "
            "start.  Command (`<dir>`: a new empty folder for cold, a filled one for warm):", "",
            f"    {START_COMMAND}", "",
            f"- cold start (empty numba cache: the engine and the scene's kernels compiled): **{st['cold']:.1f} s** "
            f"in process, {st['cold_process']:.1f} s whole process (runs: {each(st['cold_all'])} s); the issue's "
            f"target, <= 8 s, is {'met' if st['cold'] <= 8 else '**NOT met**'};",
            f"- warm start (cache filled): **{st['warm']:.2f} s** in process, {st['warm_process']:.2f} s whole "
            f"process (runs: {each(st['warm_all'])} s).", ""]


def ratio_lines(results: list) -> list[str]:
    lines = ["## Ratios at equal error", "",
             "Per camdyn DOP853 run: the time the peers need for the error it reached, over its time (> 1: camdyn "
             "ahead), interpolated in log-log along each peer's curve; \"never\": that peer reached no error that "
             "small at any rtol measured (camdyn ahead).", "",
             "| scene | rtol | camdyn error | camdyn time (s) | x numbalsoda (best of 2) | fastest peer | x fastest peer |",
             "|---|---|---|---|---|---|---|"]
    installed = peers_available()["numbalsoda"]
    for res in results:
        for r in ratios(res):
            nbs = fmt(r.numbalsoda, ".2f") if r.nbs_reached else "never" if installed else "not installed"
            lines.append(f"| {res['case'].key} | {r.rtol:.0e} | {r.error:.2e} | {r.seconds:.2e} | {nbs} | "
                         f"{r.best_peer or 'none reached it'} | {fmt(r.peer, '.2f')} |")
    return lines + [""]


def _span(values: list) -> str:
    """min-max of the finite ratios; none: the peer never reached camdyn's error at any point."""
    if not values:
        return "never reached"
    return f"{fmt(min(values), '.2f')}-{fmt(max(values), '.2f')}"


def target_lines(results: list) -> list[str]:
    if not peers_available()["numbalsoda"]:  # a peer that did not run is not one camdyn is ahead of
        return ["## Targets", "",
                "The issue's goal, ahead of numbalsoda at equal error at every tolerance on every scene, was **not "
                "measured in this run**: numbalsoda is not installed here (`pip install -e \".[bench]\"`, which "
                "builds it from source and needs gfortran).", ""]
    lines = ["## Targets", "",
             "The issue's goal: ahead of numbalsoda at equal error at every tolerance on every scene.  Per scene, "
             "over the tolerances measured (\"never\" counts as ahead):", "",
             "| scene | x numbalsoda min-max | tolerances where behind numbalsoda | ahead at every tolerance | "
             "x fastest peer min-max | x numbalsoda, every step sampled, min-max | x numbalsoda, SciPy's step "
             "control, min-max |", "|---|---|---|---|---|---|---|"]
    for res in results:
        rows = ratios(res)
        nbs = [r.numbalsoda for r in rows if r.nbs_reached]
        behind = [f"{r.rtol:.0e} ({r.numbalsoda:.2f})" for r in rows if r.nbs_reached and r.numbalsoda < 1]
        peer = [r.peer for r in rows if math.isfinite(r.peer)]
        every = [v for v in versus(res, EVERY, "numbalsoda") if math.isfinite(v)]
        scipy = [v for v in versus(res, SCIPY, "numbalsoda") if math.isfinite(v)]
        lines.append(f"| {res['case'].key} | {_span(nbs)} | {', '.join(behind) or 'none'} | "
                     f"{'yes' if rows and not behind else 'no'} | {_span(peer)} | {_span(every)} | {_span(scipy)} |")
    return lines + [""] + summary_lines(results) + [""]


def versus(result: dict, label: str, peer_prefix: str) -> list[float]:
    """Per point of camdyn's run ``label``: the best time of the peers named ``peer_prefix...`` at
    the error it reached, over its time (nan: none of them reached that error)."""
    curves = result["curves"]
    peers = [k for k in curves if k.startswith(peer_prefix)]
    out = []
    for _, s, e in curves[label]:
        if math.isfinite(e):
            at = [time_at_error(curves[k], max(e, 1e-300)) for k in peers]
            out.append(min((v for v in at if math.isfinite(v)), default=math.nan) / s)
    return out


def numbalsoda_summary(results: list, label: str = MAIN, peer_prefix: str = "numbalsoda") -> str:
    """One sentence: at how many (scene, rtol) points camdyn's run ``label`` is ahead of the peers
    ``peer_prefix...`` (numbalsoda: its best of LSODA and DOP853), and by how much."""
    rows = [v for res in results for v in versus(res, label, peer_prefix)]
    never = sum(not math.isfinite(v) for v in rows)
    behind = [v for v in rows if v < 1]
    name = "numbalsoda" if peer_prefix == "numbalsoda" else peer_prefix
    text = (f"{label} is ahead of {name} at {len(rows) - len(behind)} of {len(rows)} (scene, rtol) points "
            f"({never} of them where {name} never reached camdyn's error)")
    if behind:
        text += (f" and behind at {len(behind)}, where {name} needs {min(behind):.2f}-{max(behind):.2f} x "
                 f"camdyn's time (median {statistics.median(behind):.2f})")
    return text + "."


def summary_lines(results: list) -> list[str]:
    """The Targets section's summary: camdyn as it runs, sampling every step, with SciPy's step
    control, and its DOP853 against numbalsoda's (the same method): where the difference lies."""
    return [f"- {numbalsoda_summary(results)}", f"- {numbalsoda_summary(results, EVERY)}",
            f"- {numbalsoda_summary(results, SCIPY)}",
            f"- {numbalsoda_summary(results, MAIN, 'numbalsoda DOP853')}",
            f"- {numbalsoda_summary(results, MAIN, 'numbalsoda LSODA')}"]


def scene_lines(results: list) -> list[str]:
    lines = ["## Scenes", "",
             "| scene | description | reference: modes visited | switches | impacts | error floor (RK45 vs DOP853) | "
             "peers stopped (slower than the budget) |", "|---|---|---|---|---|---|---|"]
    for res in results:
        c, info = res["case"], res["info"]
        lines.append(f"| {c.key} | {c.title}, {c.t_end:.4g} s | {', '.join(info['modes'])} | {info['switches']} | "
                     f"{res['ref_impacts']} | {fmt(res['agreement'], '.1e')} | {', '.join(res['skipped']) or '-'} |")
    lines += ["", "## All runs", "", "| scene | solver | rtol | time (s) | error |", "|---|---|---|---|---|"]
    for res in results:
        for label, pts in res["curves"].items():
            for rtol, s, e in pts:
                lines.append(f"| {res['case'].key} | {label} | {rtol:.0e} | {s:.3g} | {fmt(e, '.2e')} |")
    lines += ["", "## Figures", ""]
    return lines + [f"![{res['case'].key}](img/perf_{res['case'].key}.png)" for res in results] + [""]


def sweep_lines(sw: dict | None, cfg: Config) -> list[str]:
    if sw is None:
        return ["## Sweeps", "", "Not run (`--no-sweeps`).", ""]
    bif = sw["bif"]
    lines = ["## Sweeps", "",
             f"Bifurcation diagram: {bif.sizes['speed_rpm']} speeds x {cfg.revolutions} revolutions (line 16 mm, D, "
             f"Coulomb, rtol {SWEEP_RTOL:.0e}, atol {SWEEP_RTOL * ATOL_PER_RTOL:.0e}, speeds 0.8-1.6 x the "
             f"contact-loss speed {sw['loss']:.0f} rev/min), `ProcessPoolExecutor(2)`: **{sw['seconds']:.1f} s**.", "",
             "| part | speeds | wall time (s) | simulated time (s) | simulated s per wall s |", "|---|---|---|---|---|"]
    for name, (n, secs, simulated) in sw["parts"].items():
        lines.append(f"| {name} | {n} | {secs:.1f} | {simulated:.0f} | {simulated / secs:.0f} |")
    tol = sw["tolerance"]
    lines += ["", f"In permanent contact every step resolves the contact mode ({sw['frequency_Hz']:.0f} Hz here, "
              "16 mm line contact), so the cost is set by the number of contact periods, not by the revolutions.", "",
              f"Tolerance of one permanent-contact point ({tol['speed']:.0f} rev/min, {cfg.revolutions} revolutions, "
              "one process); section error: the largest difference of the Poincare section (second half of the "
              "revolutions) from the same run at rtol 1e-10.", "",
              "| rtol | wall time (s) | steps | switches | section error (rad) |", "|---|---|---|---|---|"]
    lines += [f"| {r:.0e} | {s:.2f} | {n} | {k} | {e:.1e} |" for r, s, n, k, e in tol["rows"]]
    return lines + ["", f"Contact-loss map: 9 k_s x 17 speeds x 6 revolutions: {sw['map_seconds']:.1f} s.", "",
                    "![bifurcation](img/perf_bifurcation.png)", "", "![contact loss](img/perf_contact_loss.png)", ""] + \
        ["#" + line if line.startswith("## ") else line for line in sweep_stop.lines(sw["stopping"])]


def write_report(parts: dict, cfg: Config) -> str:
    lines = header(cfg, parts["peers"], parts["load"], parts["elapsed"]) + floor_lines(parts["floor"]) + \
        start_lines(parts["starts"]) + ratio_lines(parts["results"]) + target_lines(parts["results"]) + \
        scene_lines(parts["results"]) + sweep_lines(parts["sweeps"], cfg)
    return "\n".join(lines)


# --- figures ---------------------------------------------------------------------------------------------
def _pyplot():
    import matplotlib
    matplotlib.use("Agg")
    import matplotlib.pyplot as plt
    return plt


def plot_case(result: dict, path: Path):
    plt = _pyplot()
    fig, ax = plt.subplots(figsize=(6.4, 4.4))
    for label, pts in result["curves"].items():
        pts = [(s, e) for _, s, e in sorted(pts, reverse=True) if math.isfinite(e) and e > 0]
        if pts:  # joined in tolerance order, loosest first: the solver's curve as rtol tightens
            s, e = zip(*pts)
            ax.loglog(e, s, "-o" if label.startswith("camdyn") else ":^", label=label, ms=4)
    ax.axvline(result["agreement"], color="0.6", lw=0.8, ls="--", label="error floor (RK45 vs DOP853)")
    ax.set_xlabel("error (rad; impacting, camdyn: max of alpha error and 10 x impact-time error in s)")
    ax.set_ylabel("wall time (s)")
    ax.set_title(result["case"].title, fontsize=9)
    ax.grid(True, which="both", alpha=0.3)
    ax.legend(fontsize=7)
    fig.tight_layout()
    fig.savefig(path, dpi=110)
    plt.close(fig)


def plot_floor(fs: dict, path: Path):
    plt = _pyplot()
    rep = fs["floor"]
    labels = list(rep.variants) + [f"diagnostic: {k}" for k in fs["pieces"]]
    values = [rep.us_per_step(k) for k in rep.variants] + list(fs["pieces"].values())
    fig, ax = plt.subplots(figsize=(7.5, 4.4))
    colors = ["C0" if k.startswith("engine") else "C1" if k.startswith("floor") else "0.6" for k in labels]
    ax.barh(range(len(labels)), values, color=colors)
    ax.set_yticks(range(len(labels)), labels, fontsize=7)
    ax.invert_yaxis()
    ax.set_xlabel("wall time per accepted step (us), best of interleaved rounds")
    ax.set_title(f"sliding run, mode {rep.mode}, rtol {rep.run.rtol:.0e}: engine / floor = {rep.ratio_median:.2f} "
                 f"(same work), {rep.default_ratio:.2f} (as it runs)", fontsize=9)
    fig.tight_layout()
    fig.savefig(path, dpi=110)
    plt.close(fig)


def plot_sweeps(sw: dict):
    plt = _pyplot()
    bif, cmap = sw["bif"], sw["cmap"]
    fig, ax = plt.subplots(figsize=(6.4, 4.4))
    for v, row in zip(bif["speed_rpm"].values, bif["alpha_section"].values):
        ax.plot(np.full(row.size, v), row, ",k")
    ax.axvline(sw["loss"], color="r", lw=0.8, label="contact loss (inverse kinematics)")
    ax.set(xlabel="cam speed (rev/min)", ylabel="alpha once per revolution (rad)")
    ax.set_title("bifurcation diagram, line 16 mm, D, Coulomb (Poincare section)", fontsize=9)
    ax.legend(fontsize=7)
    fig.tight_layout()
    fig.savefig(IMG / "perf_bifurcation.png", dpi=110)
    plt.close(fig)
    fig, ax = plt.subplots(figsize=(6.4, 4.4))
    ax.pcolormesh(cmap["speed_rpm"], cmap["k_s"], cmap["impacts_per_rev"], shading="nearest", cmap="viridis")
    ax.plot(cmap["loss_speed_predicted"], cmap["k_s"], "r-", label="contact loss, inverse kinematics")
    ax.set(xlabel="cam speed Omega_c (rev/min)", ylabel="k_s (N/m)")
    ax.set_title("contact-loss map: impacts per revolution after 3 revolutions (cf. Fig. 9)", fontsize=9)
    ax.legend(fontsize=7)
    fig.tight_layout()
    fig.savefig(IMG / "perf_contact_loss.png", dpi=110)
    plt.close(fig)


# --- main --------------------------------------------------------------------------------------------------
def step(label: str, fn, *args):
    t0 = time.perf_counter()
    print(f"{label}...", flush=True)
    out = fn(*args)
    print(f"  {label}: {time.perf_counter() - t0:.1f} s", flush=True)
    return out


def main(argv=None) -> int:
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("--quick", action="store_true", help="fewer tolerances, repeats and sweep points")
    parser.add_argument("--no-sweeps", action="store_true", help="leave out the sweep timing section")
    parser.add_argument("--revolutions", type=int, default=None, help="revolutions per sweep point")
    cfg = Config.from_args(parser.parse_args(argv))
    t_start, load0 = time.perf_counter(), os.getloadavg()[0]
    IMG.mkdir(parents=True, exist_ok=True)
    peers = peers_available()
    fs = step("floor", floor_section, cfg)
    print(floor.summary(fs["floor"]), flush=True)
    plot_floor(fs, IMG / "perf_floor.png")
    results = []
    for case in cases():
        results.append(step(case.key, measure_case, case, cfg, peers))
        plot_case(results[-1], IMG / f"perf_{case.key}.png")
    starts = step("start-up", start_times, cfg)
    sw = step("sweeps", sweep_timing, cfg) if cfg.sweeps else None
    if sw is not None:
        plot_sweeps(sw)
    parts = {"peers": peers, "load": (load0, os.getloadavg()[0]), "elapsed": time.perf_counter() - t_start,
             "floor": fs, "starts": starts, "results": results, "sweeps": sw}
    text = write_report(parts, cfg)
    (DOCS / "performance.md").write_text(text + "\n")
    print(text)
    return 0


if __name__ == "__main__":
    sys.exit(main())
