"""The engine's entry point: a Model in, a Trajectory out.

:func:`integrate` builds the loop's inputs (the scene's kernels and automaton tables, the
method, the settings, the start) as named tuples, runs the one loop (:mod:`.loop`) compiled or
interpreted, and names what comes back: sample times and states, the mode at each sample,
:class:`Switch` records and the :class:`~camdyn.outcome.Outcome`.
"""
from __future__ import annotations

import warnings
from dataclasses import dataclass

import numpy as np

from ..errors import CompileNotice, ParameterError
from ..outcome import Outcome
from . import cache
from .config import BACKENDS, SolverOptions, settings
from .kernels import compiled_kernels, python_kernels
from .loop import LEDGER_ROWS, OUTCOMES, STATE_ROWS, Samples, Start, loop_loaded, run_compiled, run_interpreted
from .problem import Problem
from .switches import Switches
from .tableau import method_of
from .tables import tables, transition_surfaces

#: "compiled": the loop and the kernels compiled by numba (built-in cam motions);
#: "python": the same loop run by Python (any cam motion, e.g. a user's callables; ~100x slower)


@dataclass
class Trajectory:
    """Samples of the state with the mode at each, the switches, how the run ended."""

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
    cfg = settings(options, model.equilibrium.vartheta)
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
    if loop_loaded() or cache.loop_cached():
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
                      switches, Outcome[OUTCOMES[r.outcome]], stats, int(r.mode))
