"""The floor: a minimal event-capable loop, to measure what camdyn's engine costs per step.

Run from the repository root (prints the comparison; ``benchmarks/performance.py`` imports it
for docs/performance.md):

    python benchmarks/floor.py [--repeats N]

The floor is DOP853 (the tableau of :mod:`camdyn.engine.tableau`) with SciPy's error norm and
step-size controller, ONE mode for the whole run (no switching), dense output, and on every
accepted step the mode's switching surfaces evaluated at ``n_interior`` equally spaced interior
points of the step on the interpolant and at its end (a sign change is counted, not located:
the run must have none).  It samples the interpolant at ``t_eval`` as the engine does.  It
calls the scene's generated ``rhs`` and ``surface`` as the same numba cfuncs the engine calls
(:func:`camdyn.engine.kernels.compiled_kernels`), passed in as first-class functions as the
engine passes them, and none of the engine's rules or stepper.

The benchmark run is the "sliding" scene: line contact, damping D, Coulomb friction on
``camdyn.example_rig()`` (line contact length l_lambda = 1.6 mm) at +300 rev/min from the static equilibrium, rtol
1e-8, atol 1e-12.  The floor's mode is the one the engine's run is in (read from its switch
list: :func:`run_mode`), and its trajectory is checked against the engine's.

The engine is timed as it runs (a step whose ends put every watched surface out of reach of
zero is cleared from them, without interpolant or interior samples: camdyn.engine.rules,
*Reach*) and doing the floor's work, every step sampled (``EventSettings(reach_factor=inf)``):
the loop's overhead, the ratio the issue's target bounds, is the second against the floor.  The
engine runs here with the floor's step-size controller, SciPy's (``step_control="scipy"``; camdyn's
default is the PI controller), so that both take the same steps.
"""
from __future__ import annotations

import argparse
import math
import statistics
import sys
import time
from dataclasses import dataclass
from typing import Callable, NamedTuple

import numpy as np
from numba import njit

import camdyn
from camdyn.engine.config import EventSettings, SolverOptions, settings
from camdyn.engine.kernels import compiled_kernels
from camdyn.engine.loop import Samples, Start, run_compiled
from camdyn.engine.problem import Problem
from camdyn.engine.tableau import TABLEAUS, arrays
from camdyn.engine.tables import tables, transition_rows
from camdyn.model.model import Model

# --- DOP853, from camdyn's tableau: rows of A are the 12 stages, the FSAL stage, the 3 extra
# stages of the interpolant; P the interpolant in power form over all 16 (numba freezes globals)
_M = arrays(TABLEAUS["DOP853"])
_c, _n = _M.coef, _M.n_rows
A, C, B, E5, E3, P = (np.ascontiguousarray(x, dtype=np.float64) for x in (
    _c[:_n, :_n], _c[_M.c_row, :_n], _c[_M.b_row, :_M.n_stages], _c[_M.e_row, :_M.n_stages + 1],
    _c[_M.e3_row, :_M.n_stages + 1], _c[_M.p_row:_M.p_row + _n, :_M.degree]))
N_STAGES, N_EXTRA, EXPONENT = _M.n_stages, _M.n_extra, _M.exponent
SAFETY, MIN_FACTOR, MAX_FACTOR = 0.9, 0.2, 10.0   # SciPy's step-size controller


def cycloidal_cam_rig():
    """The cycloidal cam of camdyn's presets, at rest on its first dwell (140 degrees)."""
    from camdyn.model.presets import cam_example_rig
    return cam_example_rig(theta0=140 * math.pi / 180)


#: the floor run on the cam: 0.8 x its jump speed (539.8 rev/min), in permanent contact
CAM_FLOOR_RPM = 432.0


@dataclass(frozen=True)
class SlidingRun:
    """The benchmark run (see the module docstring)."""

    speed_rpm: float = 300.0
    t_end: float = 0.2
    fs: float = 5000.0          # samples per second (as the work-precision cases)
    rtol: float = 1e-8
    atol: float = 1e-12
    interior_points: int = 3
    on_cam: bool = False        # the cycloidal cam of cycloidal_cam_rig (a spline), not the circle

    def model(self) -> Model:
        rig = camdyn.example_rig()
        scene = camdyn.Scene(contact="line", damping="D", friction="coulomb")
        if self.on_cam:
            rig, scene = cycloidal_cam_rig(), camdyn.Scene(contact="line", damping="D", friction="coulomb",
                                                           profile="spline")
        return Model(rig, scene, camdyn.ConstantSpeed(self.speed_rpm))

    def t_eval(self) -> np.ndarray:
        return np.arange(int(math.floor(self.t_end * self.fs + 1e-9)) + 1) / self.fs


class FloorArgs(NamedTuple):
    rhs: Callable
    surface: Callable
    p: np.ndarray
    mode: int
    watch: np.ndarray        # surfaces checked on every step (int64)
    n_interior: int
    t0: float
    t_end: float
    alpha: float
    alpha_dot: float
    rtol: float
    atol: float
    t_eval: np.ndarray
    out: np.ndarray          # (2, samples)


class FloorStats(NamedTuple):
    steps: int
    rejected: int
    nfev: int
    sign_changes: int
    n_samples: int


# --- the floor loop ----------------------------------------------------------------------------
@njit(error_model="numpy")
def _attempt(rhs, p, m, t, y0, y1, h, K):
    """Stages 1..11, y_new and the FSAL stage f(t + h, y_new) in K[N_STAGES] (K[0] = f(t, y))."""
    for s in range(1, N_STAGES):
        d0 = 0.0
        d1 = 0.0
        for j in range(s):
            d0 += K[j, 0] * A[s, j]
            d1 += K[j, 1] * A[s, j]
        z1 = y1 + d1 * h
        K[s, 0] = z1
        K[s, 1] = rhs(m, t + C[s] * h, y0 + d0 * h, z1, p)
    d0 = 0.0
    d1 = 0.0
    for j in range(N_STAGES):
        d0 += K[j, 0] * B[j]
        d1 += K[j, 1] * B[j]
    n0 = y0 + h * d0
    n1 = y1 + h * d1
    K[N_STAGES, 0] = n1
    K[N_STAGES, 1] = rhs(m, t + h, n0, n1, p)
    return n0, n1


@njit(error_model="numpy")
def _error(K, h, y0, y1, n0, n1, rtol, atol):
    """SciPy's DOP853 error norm (5th-order estimate scaled by the 3rd-order one)."""
    s0 = atol + max(abs(y0), abs(n0)) * rtol
    s1 = atol + max(abs(y1), abs(n1)) * rtol
    e0 = e1 = f0 = f1 = 0.0
    for j in range(N_STAGES + 1):
        e0 += K[j, 0] * E5[j]
        e1 += K[j, 1] * E5[j]
        f0 += K[j, 0] * E3[j]
        f1 += K[j, 1] * E3[j]
    e5 = (e0 / s0) ** 2 + (e1 / s1) ** 2
    e3 = (f0 / s0) ** 2 + (f1 / s1) ** 2
    if e5 == 0.0 and e3 == 0.0:
        return 0.0
    return abs(h) * e5 / math.sqrt((e5 + 0.01 * e3) * 2.0)


@njit(error_model="numpy")
def _step(rhs, p, m, t, y0, y1, h_abs, t_end, rtol, atol, K):
    """One accepted step (SciPy's controller): (ok, t_new, y_new, next h, evaluations, rejections)."""
    min_step = 10.0 * abs(np.nextafter(t, math.inf) - t)
    h_abs = max(h_abs, min_step)
    nfev = 0
    rejected = 0
    while True:
        if h_abs < min_step:
            return False, t, y0, y1, h_abs, nfev, rejected
        t_new = min(t + h_abs, t_end)
        h = t_new - t
        n0, n1 = _attempt(rhs, p, m, t, y0, y1, h, K)
        nfev += N_STAGES
        err = _error(K, h, y0, y1, n0, n1, rtol, atol)
        if err < 1.0:
            factor = MAX_FACTOR if err == 0.0 else min(MAX_FACTOR, SAFETY * err ** EXPONENT)
            if rejected:
                factor = min(1.0, factor)
            return True, t_new, n0, n1, h * factor, nfev, rejected
        h_abs = h * (max(MIN_FACTOR, SAFETY * err ** EXPONENT) if math.isfinite(err) else MIN_FACTOR)
        rejected += 1


@njit(error_model="numpy")
def _initial_step(rhs, p, m, t, y0, y1, f1, t_end, rtol, atol):
    """SciPy's select_initial_step (one RHS evaluation)."""
    s0 = atol + abs(y0) * rtol
    s1 = atol + abs(y1) * rtol
    d0 = math.sqrt(0.5 * ((y0 / s0) ** 2 + (y1 / s1) ** 2))
    d1 = math.sqrt(0.5 * ((y1 / s0) ** 2 + (f1 / s1) ** 2))
    h0 = 1e-6 if d0 < 1e-5 or d1 < 1e-5 else 0.01 * d0 / d1
    h0 = min(h0, t_end - t)
    z0 = y0 + h0 * y1
    z1 = y1 + h0 * f1
    g1 = rhs(m, t + h0, z0, z1, p)
    d2 = math.sqrt(0.5 * (((z1 - y1) / s0) ** 2 + ((g1 - f1) / s1) ** 2)) / h0
    h1 = max(1e-6, h0 * 1e-3) if d1 <= 1e-15 and d2 <= 1e-15 else (0.01 / max(d1, d2)) ** (-EXPONENT)
    return min(100.0 * h0, h1, t_end - t)


@njit(error_model="numpy")
def _dense(rhs, p, m, t, y0, y1, h, K, Q):
    """The 3 extra stages and Q = K^T P: y(t + theta h) = y + h theta (Q0 + Q1 theta + ...)."""
    for s in range(N_STAGES + 1, N_STAGES + 1 + N_EXTRA):
        d0 = 0.0
        d1 = 0.0
        for j in range(s):
            d0 += K[j, 0] * A[s, j]
            d1 += K[j, 1] * A[s, j]
        z1 = y1 + d1 * h
        K[s, 0] = z1
        K[s, 1] = rhs(m, t + C[s] * h, y0 + d0 * h, z1, p)
    for k in range(P.shape[1]):
        q0 = 0.0
        q1 = 0.0
        for j in range(P.shape[0]):
            q0 += K[j, 0] * P[j, k]
            q1 += K[j, 1] * P[j, k]
        Q[0, k] = q0
        Q[1, k] = q1


@njit(error_model="numpy")
def _interpolate(tt, t, h, y0, y1, Q):
    theta = (tt - t) / h
    v0 = Q[0, Q.shape[1] - 1]
    v1 = Q[1, Q.shape[1] - 1]
    for k in range(Q.shape[1] - 2, -1, -1):
        v0 = v0 * theta + Q[0, k]
        v1 = v1 * theta + Q[1, k]
    return y0 + h * theta * v0, y1 + h * theta * v1


@njit(error_model="numpy")
def _check(surface, p, m, watch, n_interior, t, h, y0, y1, n0, n1, Q, g_prev):
    """The watched surfaces at the interior points and the end; sign changes since the previous
    sample (g_prev holds the values at the step's start and, on return, at its end)."""
    changes = 0
    for i in range(1, n_interior + 2):
        if i <= n_interior:
            tb = t + h * i / (n_interior + 1)
            a, ad = _interpolate(tb, t, h, y0, y1, Q)
        else:
            tb, a, ad = t + h, n0, n1
        for k in range(watch.shape[0]):
            g = surface(m, watch[k], tb, a, ad, p)
            if (g_prev[k] < 0.0 <= g) or (g_prev[k] > 0.0 >= g):
                changes += 1
            g_prev[k] = g
    return changes


@njit(error_model="numpy")
def _sample(t_eval, out, i, t, h, y0, y1, Q):
    while i < t_eval.shape[0] and t_eval[i] <= t + h:
        out[0, i], out[1, i] = _interpolate(t_eval[i], t, h, y0, y1, Q)
        i += 1
    return i


@njit(error_model="numpy")
def _floor(rhs, surface, p, m, watch, n_interior, t0, t_end, a0, ad0, rtol, atol, t_eval, out):
    K = np.empty((N_STAGES + 1 + N_EXTRA, 2))
    Q = np.empty((2, P.shape[1]))
    g_prev = np.empty(watch.shape[0])
    t, y0, y1 = t0, a0, ad0
    for k in range(watch.shape[0]):
        g_prev[k] = surface(m, watch[k], t, y0, y1, p)
    K[0, 0], K[0, 1] = y1, rhs(m, t, y0, y1, p)
    h_abs = _initial_step(rhs, p, m, t, y0, y1, K[0, 1], t_end, rtol, atol)
    nfev, steps, rejected, changes, i_s = 2, 0, 0, 0, 0
    while t < t_end:
        ok, t_new, n0, n1, h_next, f, rej = _step(rhs, p, m, t, y0, y1, h_abs, t_end, rtol, atol, K)
        nfev += f
        rejected += rej
        if not ok:
            break
        steps += 1
        h = t_new - t
        if (watch.shape[0] > 0 and n_interior > 0) or (i_s < t_eval.shape[0] and t_eval[i_s] <= t_new):
            _dense(rhs, p, m, t, y0, y1, h, K, Q)
            nfev += N_EXTRA
        if watch.shape[0] > 0:
            changes += _check(surface, p, m, watch, n_interior, t, h, y0, y1, n0, n1, Q, g_prev)
        i_s = _sample(t_eval, out, i_s, t, h, y0, y1, Q)
        t, y0, y1, h_abs = t_new, n0, n1, h_next
        K[0, 0], K[0, 1] = K[N_STAGES, 0], K[N_STAGES, 1]
    return steps, rejected, nfev, changes, i_s


def run_floor(args: FloorArgs) -> FloorStats:
    """The floor loop on prepared arguments."""
    return FloorStats(*_floor(*args))


# --- the same run on the engine -------------------------------------------------------------------
class EngineArgs(NamedTuple):
    """The arguments of camdyn.engine.loop.run_compiled, prepared as driver.integrate does."""

    prob: Problem
    method: object
    cfg: object
    start: Start
    samples: Samples


def engine_args(model: Model, run: SlidingRun, interior_points: int | None = None,
                reach_factor: float = EventSettings().reach_factor) -> EngineArgs:
    """The compiled loop's arguments for the run; reach_factor inf: every step sampled, as the floor."""
    K = model.kernels
    events = EventSettings(interior_points=run.interior_points if interior_points is None else interior_points,
                           reach_factor=reach_factor)
    options = SolverOptions("DOP853", run.rtol, run.atol, events=events, step_control="scipy")  # the floor's
    prob = Problem(compiled_kernels(K), tables(K), np.ascontiguousarray(model.p, dtype=float))
    y0 = model.static_state()
    t_eval = run.t_eval()
    samples = Samples(t_eval, np.empty((2, t_eval.size)), np.zeros(t_eval.size, dtype=np.int64))
    return EngineArgs(prob, arrays(TABLEAUS["DOP853"]), settings(options, model.equilibrium.vartheta),
                      Start(0.0, run.t_end, float(y0[0]), float(y0[1]), -1), samples)


def run_engine(args: EngineArgs):
    """camdyn's compiled loop (a camdyn.engine.loop.Run)."""
    return run_compiled(*args)


def run_mode(model: Model, args: EngineArgs) -> tuple[int, list]:
    """The mode the engine's run is in after its last switch, and its switches as
    (t, surface, before, after); the samples after the last switch must all be in that mode."""
    K = model.kernels
    r = run_engine(args)
    surfaces = [K.SURFACES[row[1]] for row in transition_rows(K)]
    switches = [(float(s["t"]), surfaces[int(s["transition"])], K.MODES[int(s["before"])], K.MODES[int(s["after"])])
                for s in r.switches]
    t_last = switches[-1][0] if switches else -math.inf
    after = args.samples.mode[:r.n_samples][args.samples.t[:r.n_samples] > t_last]
    if not np.all(after == r.mode):
        raise RuntimeError("the engine's run changes mode between samples after its last switch")
    return int(r.mode), switches


def watched_surfaces(model: Model, mode: int, rates: bool = False) -> np.ndarray:
    """The surfaces of mode's transitions (with ``rates``, also their declared rate surfaces,
    which the engine samples too)."""
    K = model.kernels
    out = [tr[1] for tr in transition_rows(K) if tr[0] == mode]
    if rates:
        out += [K.RATE_OF_SURFACE[s] for s in out if K.RATE_OF_SURFACE[s] >= 0]
    return np.array(sorted(set(out)), dtype=np.int64)


def floor_args(model: Model, run: SlidingRun, mode: int, n_interior: int, watch: np.ndarray) -> FloorArgs:
    kern = compiled_kernels(model.kernels)
    y0 = model.static_state()
    t_eval = run.t_eval()
    return FloorArgs(kern.rhs, kern.surface, np.ascontiguousarray(model.p, dtype=float), mode, watch, n_interior,
                     0.0, run.t_end, float(y0[0]), float(y0[1]), run.rtol, run.atol, t_eval,
                     np.empty((2, t_eval.size)))


# --- timing ---------------------------------------------------------------------------------------
def interleaved(fns: dict[str, Callable], rounds: int) -> dict[str, list[float]]:
    """Wall times of each function, run in rounds (A B C, then C B A, ...) so that a slow spell of
    the machine falls on all of them alike."""
    names = list(fns)
    times: dict[str, list[float]] = {k: [] for k in names}
    for r in range(rounds):
        for name in (names if r % 2 == 0 else names[::-1]):
            t0 = time.perf_counter()
            fns[name]()
            times[name].append(time.perf_counter() - t0)
    return times


def pair_ratios(times: dict[str, list[float]], num: str, den: str) -> list[float]:
    """Round-by-round ratios num/den (each pair measured back to back)."""
    return [a / b for a, b in zip(times[num], times[den])]


@njit(error_model="numpy")
def _rhs_loop(rhs, m, n, a, ad, p):
    acc = 0.0
    for i in range(n):
        acc += rhs(m, i * 1e-8, a + 1e-12 * i, ad, p)
    return acc


@njit(error_model="numpy")
def _surface_loop(surface, m, watch, n, a, ad, p):
    acc = 0.0
    for i in range(n):
        for k in range(watch.shape[0]):
            acc += surface(m, watch[k], i * 1e-8, a + 1e-12 * i, ad, p)
    return acc


def kernel_ns(model: Model, mode: int, watch: np.ndarray, calls: int = 200_000, rounds: int = 7) -> tuple[float, float]:
    """ns per call of the rhs cfunc and per surface-cfunc call (averaged over ``watch``), in a
    compiled loop at the static equilibrium; best of interleaved rounds."""
    kern = compiled_kernels(model.kernels)
    a, ad = map(float, model.static_state())
    p = np.ascontiguousarray(model.p, dtype=float)
    _rhs_loop(kern.rhs, mode, 10, a, ad, p)
    _surface_loop(kern.surface, mode, watch, 10, a, ad, p)
    t = interleaved({"rhs": lambda: _rhs_loop(kern.rhs, mode, calls, a, ad, p),
                     "surface": lambda: _surface_loop(kern.surface, mode, watch, calls, a, ad, p)}, rounds)
    return min(t["rhs"]) / calls * 1e9, min(t["surface"]) / (calls * max(1, watch.size)) * 1e9


# --- the measurement --------------------------------------------------------------------------------
class Variant(NamedTuple):
    label: str
    fn: Callable
    steps: int
    rejected: int
    nfev: int
    switches: int       # engine: switches; floor: sign changes seen


@dataclass
class FloorReport:
    run: SlidingRun
    mode: str
    switches: list                  # the engine's, as (t, surface, before, after)
    watch: list                     # names of the floor's surfaces
    max_alpha_diff: float
    variants: dict                  # label -> Variant
    times: dict                     # label -> wall times (s), interleaved rounds
    ratio_median: float             # median of round-by-round engine/floor, the same work (SAME)
    ratio_best: float               # best engine time / best floor time, the same work
    default_ratio: float            # median of round-by-round engine as it runs (ENGINE) / floor
    rhs_ns: float
    surface_ns: float
    integrate_s: float              # best time of driver.integrate() on the same run (Python set-up included)

    def us_per_step(self, label: str) -> float:
        return min(self.times[label]) / self.variants[label].steps * 1e6


#: the engine as it runs (steps out of reach cleared from their ends), the engine doing the
#: floor's work (every step's interpolant and interior samples: reach_factor inf), the floor
ENGINE = "engine (default: steps out of reach cleared)"
SAME = "engine (every step sampled at 3 interior points)"
FLOOR = "floor (every step sampled at 3 interior points)"


def _engine_variant(label, model, run, interior, reach_factor=EventSettings().reach_factor):
    args = engine_args(model, run, interior, reach_factor)
    r = run_engine(args)
    return Variant(label, lambda: run_engine(args), r.steps, r.rejected, r.nfev, len(r.switches))


def _floor_variant(label, args: FloorArgs):
    s = run_floor(args)
    return Variant(label, lambda: run_floor(args), s.steps, s.rejected, s.nfev, s.sign_changes)


def variants(model: Model, run: SlidingRun, mode: int) -> tuple[dict, FloorArgs]:
    """The runs compared: the engine as it runs, and sampling every step as the floor does, with
    3 interior points and with none; the floor with 3, with none (the end of each step only),
    with none of the surfaces (a plain ODE loop), and with the rate surfaces the engine also
    samples; and the floor's own arguments (its samples)."""
    watch, with_rates = watched_surfaces(model, mode), watched_surfaces(model, mode, rates=True)
    fa = floor_args(model, run, mode, run.interior_points, watch)
    out = [_engine_variant(ENGINE, model, run, 3), _engine_variant(SAME, model, run, 3, math.inf),
           _floor_variant(FLOOR, fa),
           _engine_variant("engine (every step, 0 interior points: step ends only)", model, run, 0, math.inf),
           _floor_variant("floor (0 interior points: step ends only)", floor_args(model, run, mode, 0, watch)),
           _floor_variant("floor (no surfaces: plain ODE loop)", floor_args(model, run, mode, 0, watch[:0])),
           _floor_variant("floor (3 interior points, + rate surfaces)", floor_args(model, run, mode, 3, with_rates))]
    return {v.label: v for v in out}, fa


def measure(run: SlidingRun = SlidingRun(), rounds: int = 30) -> FloorReport:
    """Everything the report's floor section says, measured in this process."""
    from camdyn.engine.driver import integrate
    model = run.model()
    eng = engine_args(model, run)
    mode, switches = run_mode(model, eng)
    vs, fa = variants(model, run, mode)
    r = run_engine(eng)
    n = min(r.n_samples, fa.t_eval.size)
    diff = float(np.max(np.abs(eng.samples.y[0, :n] - fa.out[0, :n])))
    fns = {k: v.fn for k, v in vs.items()}
    options = SolverOptions("DOP853", run.rtol, run.atol, step_control="scipy")
    y0, t_eval = model.static_state(), run.t_eval()
    fns["integrate()"] = lambda: integrate(model, (0.0, run.t_end), y0, t_eval, options)
    fns["integrate()"]()
    times = interleaved(fns, rounds)
    rhs_ns, surf_ns = kernel_ns(model, mode, fa.watch)
    ratios = pair_ratios(times, SAME, FLOOR)
    names = [model.kernels.SURFACES[s] for s in fa.watch]
    return FloorReport(run, model.kernels.MODES[mode], switches, names, diff, vs,
                       {k: v for k, v in times.items() if k in vs}, statistics.median(ratios),
                       min(times[SAME]) / min(times[FLOOR]), statistics.median(pair_ratios(times, ENGINE, FLOOR)),
                       rhs_ns, surf_ns, min(times["integrate()"]))


def summary(rep: FloorReport) -> str:
    lines = [f"mode: {rep.mode}; engine switches: {rep.switches}",
             f"floor watches {rep.watch}; max |alpha_engine - alpha_floor| = {rep.max_alpha_diff:.2e} rad",
             f"{'run':48s} {'best ms':>8s} {'steps':>6s} {'rej':>5s} {'nfev':>7s} {'us/step':>8s}"]
    for k, v in rep.variants.items():
        lines.append(f"{k:48s} {min(rep.times[k]) * 1e3:8.3f} {v.steps:6d} {v.rejected:5d} {v.nfev:7d} "
                     f"{rep.us_per_step(k):8.3f}")
    lines += [f"ratio engine/floor, the same work: median of rounds {rep.ratio_median:.3f}, best/best "
              f"{rep.ratio_best:.3f} (target <= 1.3); the engine as it runs / floor: {rep.default_ratio:.3f}",
              f"rhs {rep.rhs_ns:.1f} ns/call, surface {rep.surface_ns:.1f} ns/call, "
              f"integrate() {rep.integrate_s * 1e3:.3f} ms"]
    return "\n".join(lines)


def main(argv=None) -> int:
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("--repeats", type=int, default=30, help="interleaved rounds of every run")
    args = parser.parse_args(argv)
    print(summary(measure(SlidingRun(), args.repeats)))
    return 0


if __name__ == "__main__":
    sys.exit(main())
