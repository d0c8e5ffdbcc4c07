"""Work-precision: every solver on a scene at each rtol in interleaved rounds, against the
engine's reference; the peers' time at camdyn's error (the ratios at equal error)."""
from __future__ import annotations

import math
from typing import Callable, NamedTuple

import numpy as np

import floor
from camdyn.engine.config import SolverOptions
from camdyn.engine.driver import integrate
from camdyn.model.model import Model

from .cases import ATOL_PER_RTOL, CAMDYN, MAIN, REFERENCE_RTOL, Case, Config, Sample, camdyn_runner, error
from .peers import cvode_runner, numbalsoda_rhs, numbalsoda_runner, peer_field


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
