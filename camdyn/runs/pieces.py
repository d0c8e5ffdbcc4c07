"""Long runs in pieces of whole kernel periods, each integrated in phase-wrapped time.

The generated kernels see time only through the cam motion and are periodic in t with
P = 2 T (T the cam's period; the half-angle forms carry Omega t / 2, whose sines change sign
over one T, in products that do not).  At large t the rounding of t itself perturbs every
stage time by ~1e-16 t, which the stiff contact turns into state errors above a tight
tolerance: the step size collapses and the cost grows with t (docs/design-notes.md, *Long
runs in pieces*).  Here a run longer than PIECE_PERIODS * P is integrated in pieces of
that length, each in a local time tau = phase + (t - piece start), with phase = t0 mod P, so
tau stays below about PIECE_PERIODS * P and the cam phase, hence the motion, is the same.
Each piece starts in the regime the previous one ended in; the samples, switches and (with
the ledger) works are joined back in absolute time.
"""
from __future__ import annotations

import dataclasses
import math
from typing import Callable

import numpy as np

from ..engine import SolverOptions
from ..engine import Trajectory
from ..model.model import Model
from ..outcome import Outcome

#: kernel periods (2 T) per piece: each piece restarts the step size once (a few steps)
PIECE_PERIODS = 100


def kernel_period(model: Model) -> float:
    """The period in t of every generated kernel of the model (inf for a non-periodic cam)."""
    return 2.0 * model.period


def integrate_in_pieces(integrate: Callable, model: Model, t_span: tuple[float, float], y0,
                        t_eval: np.ndarray, options: SolverOptions,
                        progress: Callable[[float], None] | None = None, watch=None) -> Trajectory:
    """``integrate`` (the engine's integrate(model, t_span, y0, t_eval, options, mode=...), its
    backend chosen) over t_span in phase-wrapped pieces; a short run, or a cam without a
    period, in one call.  ``progress(fraction)`` is told the share of t_span done after each
    piece (the pieces do not depend on it: a run with a progress report is the same run).
    ``watch`` (a :class:`camdyn.runs.stopping.Watch`) makes the pieces ``watch.piece_revolutions``
    cam periods long and is told each piece in absolute time: when it answers True the run
    ends there (``stats["stopped"]``)."""
    t0, t_end = map(float, t_span)
    P = kernel_period(model)
    length = PIECE_PERIODS * P if watch is None else watch.piece_revolutions * model.period
    periodic = math.isfinite(P) and P > 0
    if not periodic or (watch is None and t_end <= length and t0 >= 0.0 and t_end - t0 <= length):
        tr = integrate(model, (t0, t_end), y0, t_eval, options)
        if progress is not None:
            progress(1.0)
        return tr
    phase = math.fmod(t0, P) % P
    t_eval = np.asarray(t_eval, dtype=float)
    parts: list[Trajectory] = []
    work = np.zeros(3)
    y, mode, start, i = np.asarray(y0, dtype=float), None, t0, 0
    budget = options.events.max_events
    while start < t_end:
        end = min(start + length, t_end)
        hi = int(np.searchsorted(t_eval, end, side="right")) if end < t_end else t_eval.size
        own = t_eval[i:hi]
        extra = own.size == 0 or own[-1] != end        # a sample at the piece's end gives its end state
        local_end = phase + (end - start)
        local = np.append(phase + (own - start), local_end) if extra else phase + (own - start)
        opts = dataclasses.replace(options, events=dataclasses.replace(options.events, max_events=budget))
        tr = integrate(model, (phase, local_end), y, local, opts, mode=mode)
        kept = min(tr.t.size, own.size)
        shift = start - phase
        parts.append(tr.piece(own[:kept], kept, shift, work))
        budget -= len(tr.switches)
        if progress is not None:
            progress((end - t0) / (t_end - t0))
        if watch is not None and tr.outcome is Outcome.SUCCESS and end < t_end and watch(parts[-1]):
            return _joined(parts, stopped=True)
        if tr.outcome is not Outcome.SUCCESS or tr.t.size < local.size or budget <= 0:
            break
        y = tr.end_state()
        if options.ledger:
            work = work + tr.works[:, -1]
        mode = tr.end_mode
        start, i = end, hi
    return _joined(parts)


def _joined(parts: list[Trajectory], stopped: bool = False) -> Trajectory:
    stats = {}
    for p in parts:
        for name, value in p.stats.items():
            stats[name] = stats.get(name, 0) + value if isinstance(value, (int, float)) else value
    stats["pieces"] = len(parts)
    stats["stopped"] = stopped
    return Trajectory.joined(parts, stats)
