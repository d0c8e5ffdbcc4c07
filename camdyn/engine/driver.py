"""The engine's entry point: a Model in, a Trajectory out.

:func:`integrate` builds the loop's inputs (the scene's kernels and automaton tables, the
method, the settings, the start) as named tuples, runs the one loop (:mod:`.loop`) compiled or
interpreted, and names what comes back: sample times and states, the mode at each sample,
:class:`Switch` records and the :class:`~camdyn.outcome.Outcome`.
"""
from __future__ import annotations

import dataclasses
import warnings
from dataclasses import dataclass

import numpy as np

from ..errors import CompileNotice, ParameterError
from ..outcome import Outcome
from . import cache
from .config import BACKENDS, SolverOptions, settings
from .kernels import compiled_kernels, python_kernels
from .loop import (ALPHA, ALPHA_DOT, LEDGER_ROWS, OUTCOMES, STATE_ROWS, WORK, Samples, Start, loop_cached, loop_loaded,
                   run_compiled, run_interpreted)
from .problem import Problem
from .switches import Switches
from .tableau import method_of
from .tables import tables, transition_surfaces

#: "compiled": the loop and the kernels compiled by numba (built-in cam motions);
#: "python": the same loop run by Python (any cam motion, e.g. a user's callables; slow:
#: docs/design-notes.md, *The python backend*)


@dataclass
class Trajectory:
    """Samples of the state with the mode at each, the switches, how the run ended.

    Read the samples by name (:attr:`alpha`, :attr:`alpha_dot`, :attr:`works`, :meth:`end_state`):
    ``y``'s rows are the loop's layout (:mod:`.loop`: the state, then the ledger's works)."""

    t: np.ndarray
    y: np.ndarray            # rows loop.ALPHA, ALPHA_DOT (and with the ledger the works from loop.WORK on)
    mode: np.ndarray         # mode index at each sample (into modes)
    modes: tuple             # the scene's MODES
    switches: Switches
    outcome: Outcome
    stats: dict
    end_mode: int            # the mode at the end (to continue the run)

    @property
    def regime(self) -> np.ndarray:
        """The mode's name at each sample."""
        return np.asarray(self.modes, dtype=object)[self.mode] if self.mode.size else np.empty(0, dtype=object)

    @property
    def alpha(self) -> np.ndarray:
        """alpha (rad) at the samples."""
        return self.y[ALPHA]

    @property
    def alpha_dot(self) -> np.ndarray:
        """alpha_dot (rad/s) at the samples."""
        return self.y[ALPHA_DOT]

    @property
    def has_ledger(self) -> bool:
        """Whether the run integrated the energy ledger (the works of the flows, :attr:`works`)."""
        return self.y.shape[0] == LEDGER_ROWS

    @property
    def works(self) -> np.ndarray | None:
        """The ledger's works (J) of the flows P_in, D_c, D_f (vocabulary.FLOWS) at the samples, a
        row each; None without the ledger."""
        return self.y[WORK:LEDGER_ROWS] if self.has_ledger else None

    def end_state(self) -> np.ndarray:
        """(alpha, alpha_dot) at the last sample, a copy."""
        return self.y[:STATE_ROWS, -1].copy()

    def piece(self, t: np.ndarray, kept: int, shift: float, work_before: np.ndarray) -> "Trajectory":
        """This run as a piece of a longer one: its first ``kept`` samples at the absolute times
        ``t``, its switches ``shift`` later, its works offset by the works ``work_before`` of the
        pieces before it."""
        y = self.y[:, :kept].copy()
        if self.has_ledger:
            y[WORK:LEDGER_ROWS] += np.asarray(work_before)[:, None]
        return dataclasses.replace(self, t=np.asarray(t).copy(), y=y, mode=self.mode[:kept],
                                   switches=self.switches.shifted(shift))

    @staticmethod
    def joined(parts: list["Trajectory"], stats: dict) -> "Trajectory":
        """Consecutive pieces of one run as one (the last piece's outcome and end mode)."""
        return dataclasses.replace(parts[-1], t=np.concatenate([p.t for p in parts]),
                                   y=np.concatenate([p.y for p in parts], axis=1),
                                   mode=np.concatenate([p.mode for p in parts]),
                                   switches=Switches.joined([p.switches for p in parts]), stats=stats)


def _problem(model, backend: str, ledger: bool) -> Problem:
    K = model.kernels
    if backend == "compiled":
        kern = compiled_kernels(K, outputs=ledger)
    elif backend == "python":
        kern = python_kernels(K, model.cam if model.scene.motion == "user" else None)
    else:
        raise ParameterError("backend", backend, f"one of {BACKENDS}")
    return Problem(kern, tables(K), np.ascontiguousarray(model.p, dtype=float))


def integrate(model, t_span: tuple[float, float], y0, t_eval: np.ndarray,
              options: SolverOptions = SolverOptions(), mode: int | None = None,
              backend: str = "compiled") -> Trajectory:
    """Integrate the hybrid model from y0 = (alpha, alpha_dot) over t_span, sampling at t_eval.

    ``mode``: the mode to start in (a Trajectory's ``end_mode``, to continue a run); by default
    the automaton's initial rule chooses it from the state."""
    prob = _problem(model, backend, options.ledger)
    method = method_of(options.method)
    cfg = settings(options, model.equilibrium.vartheta, model.coordinate_limit, model.step_cap)
    t0, t_end = map(float, t_span)
    t_eval = np.ascontiguousarray(t_eval, dtype=float)
    samples = Samples(t_eval, np.empty((LEDGER_ROWS if options.ledger else STATE_ROWS, t_eval.size)),
                      np.zeros(t_eval.size, dtype=np.int64))
    y0 = np.asarray(y0, dtype=float)
    start = Start(t0, t_end, float(y0[0]), float(y0[1]), -1 if mode is None else int(mode))
    if backend == "compiled":
        _notice_compile()
    loop = run_compiled if backend == "compiled" else run_interpreted
    r = loop(prob, method, cfg, start, samples)
    return _trajectory(model, r, samples, backend)


def _notice_compile() -> None:
    """Say once, before it happens, that the loop is about to be compiled (a first run here)."""
    if loop_loaded() or loop_cached():
        return
    warnings.warn(f"camdyn compiles its integration loop on this first run (typically 5-15 s, once; later runs "
                  f"load it from {cache.cache_dir()}). Silence this with warnings.filterwarnings('ignore', "
                  "category=camdyn.CompileNotice).", CompileNotice, stacklevel=5)


def _trajectory(model, r, samples: Samples, backend: str) -> Trajectory:
    K = model.kernels
    switches = Switches(r.switches, transition_surfaces(K), K.MODES)
    n = r.n_samples
    stats = {"nfev": int(r.nfev), "steps": int(r.steps), "rejected_steps": int(r.rejected), "njev": 0,
             "switches": len(switches), "backend": backend}
    return Trajectory(samples.t[:n].copy(), samples.y[:, :n].copy(), samples.mode[:n].copy(), tuple(K.MODES),
                      switches, OUTCOMES[r.outcome], stats, int(r.mode))
