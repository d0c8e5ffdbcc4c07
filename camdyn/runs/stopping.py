"""Runs that stop once they have converged to a periodic motion (camdyn issue 13, item 3).

A run with ``stop=StopWhenPeriodic(...)`` (:func:`camdyn.simulate`, :func:`camdyn.sweep.api.sweep`,
on by default in :func:`camdyn.sweep.api.bifurcation`) is integrated in pieces of
``check_every`` revolutions (:func:`camdyn.runs.pieces.integrate_in_pieces`); after each piece the
once-per-revolution section (the samples at t = t_start + j T) is checked, and the run stops
when its last ``revolutions`` section values form a cycle of period p <= ``max_period``
revolutions: the values of each phase (mod p) lie within ``tol (rtol max abs(alpha) + atol)`` of
each other (rtol and atol the run's own) in one mode, and no shorter cycle is still settling into
it (:meth:`StopWhenPeriodic.period_of`): p is the minimal period of the converged cycle within
that threshold.
The Result is then completed to the requested length by repeating its last p revolutions
(samples, outputs, regimes and switches shifted by whole multiples of p T; the cam angle and the
energy ledger's works grow by their increment over the cycle), so that every measure sees a
full-length run.  ``result.stats`` says what happened: ``revolutions_run`` (integrated) and
``stop_period`` (p, 0 where the run did not converge and ran to its end).  A run that has not
converged is never stopped.  It ran in pieces of ``check_every`` revolutions, each restarting
the step size: its values differ from a run in one piece at the level of the solver's error,
and at a chaotic speed, after that difference has grown, by as much as the attractor's size
(as a change of rtol would make them).
"""
from __future__ import annotations

import dataclasses
import math
from dataclasses import dataclass

import numpy as np

from ..engine import Switches, Trajectory
from ..errors import ParameterError
from .._checks import integer, is_real

#: outputs that accumulate over a run (the energy ledger's works): extended by their increment
ACCUMULATED = ("work_in", "dissipated_contact", "dissipated_friction")


@dataclass(frozen=True)
class StopWhenPeriodic:
    """Stop a run once its section repeats with period <= ``max_period`` revolutions over its last
    ``revolutions`` revolutions, to ``tol`` times the solver's tolerance at the section,
    ``rtol max abs(alpha) + atol`` (the run's rtol and atol; alpha over those section values);
    checked every ``check_every`` revolutions (an even number: a piece of the run is a whole
    number of the kernels' period 2 T, :mod:`camdyn.runs.pieces`).

    Why a multiple of the solver's tolerance, and why 10: a converged run's section still
    scatters from revolution to revolution, and two runs with other steps differ, at the level
    of the solver's error (docs/design-notes.md, *The stop threshold's factor 10*); below that
    scatter the check would never hold, and a size of the motion alone cannot say where it is.  A
    stopped run's section values differ from the full run's by at most about
    ``tol (rtol abs(alpha) + atol) / (1 - abs(mu))`` (mu the orbit's largest Floquet multiplier per period:
    the transient still left) plus the full run's own scatter.  ``revolutions`` >= 2
    ``max_period`` makes every value of a cycle repeat at least twice before the run stops.
    """

    max_period: int = 8
    tol: float = 10.0
    revolutions: int = 16
    check_every: int = 4

    def __post_init__(self):
        for name, least in (("max_period", 1), ("check_every", 2)):
            integer(name, getattr(self, name), f"an integer >= {least}", lambda n: n >= least)
        if self.check_every % 2:
            raise ParameterError("check_every", self.check_every, "an even number of revolutions (whole kernel "
                                 "periods 2 T)")
        r = self.revolutions
        integer("revolutions", r, f"an integer >= 2 max_period ({2 * self.max_period})",
                lambda n: n >= 2 * self.max_period)
        if not (is_real(self.tol) and 1 <= self.tol <= 1e6):
            raise ParameterError("tol", self.tol, "1 <= tol <= 1e6 (times the solver's tolerance rtol abs(alpha) + atol: "
                                 "below 1 the check would ask for more than the solver gives)")

    def threshold(self, section: np.ndarray, rtol: float, atol: float) -> float:
        """The largest difference (rad) of two section values that count as equal."""
        return self.tol * (rtol * float(np.max(np.abs(section))) + atol)

    def period_of(self, section: np.ndarray, modes: np.ndarray, rtol: float, atol: float) -> int:
        """The period the run has converged to: the smallest p <= max_period such that

        * the last ``revolutions`` section values form a cycle of period p: every value is within
          :meth:`threshold` of every other value of its phase (mod p), with the same mode; and
        * no shorter cycle is still settling into it (:func:`settling`): near a period doubling
          the section alternates about a period-q orbit with an amplitude that shrinks (below
          the doubling) or grows (above it) by a multiplier near -1; over a window that
          alternation can be within the threshold of a 2q-cycle before the motion has
          converged to either.

        0 when there is none (the run has not converged)."""
        k = self.revolutions
        if section.size < k:
            return 0
        tail, tail_modes = section[-k:], modes[-k:]
        limit = self.threshold(tail, rtol, atol)
        for p in range(1, self.max_period + 1):
            if _cycle(tail, tail_modes, p, limit) and not settling(section, p, limit, max(SETTLE_BLOCKS, -(-k // p))):
                return p
        return 0


#: a cycle of period p counts only when, over at least SETTLE_BLOCKS blocks of p values (and the
#: whole window), the amplitude of every shorter cycle q = p / r within it (r a prime factor of p)
#: is stationary: it changes by no more than the threshold and is not strictly monotone.  A
#: stationary cycle's amplitudes scatter, so a strictly monotone run of them is a transient (by
#: chance from scatter alone with probability 2 / SETTLE_BLOCKS! = 0.3 %: the stop is then put
#: off by a check)
SETTLE_BLOCKS = 6


def _cycle(a: np.ndarray, modes: np.ndarray, p: int, limit: float) -> bool:
    """Whether ``a`` (with ``modes``) is p-periodic to ``limit``: each phase class, counted from the
    end, spans at most ``limit`` and keeps one mode."""
    if abs(a[-1] - a[-1 - p]) > limit or modes[-1] != modes[-1 - p]:      # the last pair rules most p out
        return False
    for c in range(p):
        values, kinds = a[-1 - c::-p], modes[-1 - c::-p]
        if values.max() - values.min() > limit or np.any(kinds != kinds[0]):
            return False
    return True


def _prime_factors(p: int) -> list[int]:
    factors, r = [], 2
    while r * r <= p:
        while p % r == 0:
            factors.append(r)
            p //= r
        r += 1
    return sorted(set(factors + ([p] if p > 1 else [])))


def settling(section: np.ndarray, p: int, limit: float, blocks: int = SETTLE_BLOCKS) -> bool:
    """Whether a shorter cycle within a period-p cycle is still settling: for a prime factor r of
    p and q = p / r, the largest ``abs(alpha_j - alpha_(j-q))`` in each of the last ``blocks`` blocks of
    p values changes by more than ``limit`` over them, or strictly decreases or increases (see
    :data:`SETTLE_BLOCKS`).  True also while the run is too short to tell (fewer than
    ``blocks`` p + q values)."""
    for r in _prime_factors(p):
        q = p // r
        need = blocks * p + q
        if section.size < need:
            return True
        a = section[-need:]
        amplitude = np.abs(a[q:] - a[:-q]).reshape(blocks, p).max(axis=1)
        change = np.diff(amplitude)
        if amplitude.max() - amplitude.min() > limit or np.all(change < 0) or np.all(change > 0):
            return True
    return False


class Watch:
    """One run's check (stateful): told each piece of the run in absolute time, it keeps the
    section samples (every ``per_revolution``-th sample from the first) and says when to stop
    (with the run's ``rtol`` and ``atol``)."""

    def __init__(self, stop: StopWhenPeriodic, per_revolution: int, rtol: float, atol: float):
        self.stop, self.per_revolution, self.rtol, self.atol = stop, per_revolution, rtol, atol
        self.piece_revolutions = stop.check_every
        self.alpha: list[float] = []
        self.modes: list[int] = []
        self.seen = 0                   # samples seen so far
        self.period = 0

    def __call__(self, piece: Trajectory) -> bool:
        first = (-self.seen) % self.per_revolution
        self.alpha.extend(piece.alpha[first::self.per_revolution].tolist())
        self.modes.extend(piece.mode[first::self.per_revolution].tolist())
        self.seen += piece.t.size
        self.period = self.stop.period_of(np.asarray(self.alpha), np.asarray(self.modes), self.rtol, self.atol)
        return self.period > 0


def per_revolution(sample_rate_Hz: float, period: float) -> int:
    """Samples per cam revolution, which a stopping run needs to be a whole number."""
    n = sample_rate_Hz * period
    if not (math.isfinite(n) and round(n) >= 1 and abs(n - round(n)) <= 1e-9 * n):
        raise ParameterError("sample_rate_Hz", sample_rate_Hz, "a whole number of samples per cam revolution "
                             f"(a multiple of {1 / period:.6g} Hz) to stop a run once it is periodic (stop=)")
    return int(round(n))


def extend(result, t_eval: np.ndarray, period: int, per_rev: int, t_end: float):
    """``result`` (a run stopped after a cycle of ``period`` revolutions) completed to the
    samples ``t_eval`` and the switches up to ``t_end`` by repeating its last cycle (see the
    module doc)."""
    run, total, L = result.t.size, t_eval.size, period * per_rev
    if total <= run:
        return result
    extra = np.arange(run, total)
    shifts = (extra - (run - 1) + L - 1) // L          # cycles each new sample lies beyond its source
    source = extra - shifts * L

    def grown(x, accumulates=False):
        tail = x[source] + shifts * (x[run - 1] - x[run - 1 - L]) if accumulates else x[source]
        return np.concatenate([x, tail])

    cycle, end = result.t[run - 1] - result.t[run - 1 - L], result.t[run - 1]
    switches = result.switches
    kept = switches[switches.t <= end]         # the run's last piece may go on past its last sample
    last = kept[kept.t > end - cycle]
    cycles = int(math.ceil((t_end - end) / cycle))
    continued = Switches.joined([kept, last.repeated(cycle, cycles)])
    outputs = {k: grown(v, k in ACCUMULATED) for k, v in result.outputs.items()}
    return dataclasses.replace(result, t=t_eval.copy(), q=grown(result.q), q_dot=grown(result.q_dot),
                               Theta=grown(result.Theta, True), regime=grown(result.regime), outputs=outputs,
                               switches=continued[continued.t <= t_end])


__all__ = ["StopWhenPeriodic", "Watch", "per_revolution", "extend", "settling", "SETTLE_BLOCKS"]
