"""camdyn's engine: the hybrid automaton of a scene, integrated by one loop.

Its public face is this package; the rest of camdyn imports from it, never from its modules:

* running a model: :func:`integrate` (a Model in, a :class:`Trajectory` out: samples by name,
  :class:`Switches` of :class:`Switch` records) with :class:`SolverOptions` (method, tolerances,
  :class:`EventSettings`, the energy ledger, a :class:`StepControl`: ``PI_CONTROL``, ``SCIPY_CONTROL``);
  ``MAP_OPTIONS``, the periodic analyses' tolerances; ``BACKENDS``, ``METHODS``;
* a scene's modes seen from a state: :class:`Domain` (the initial mode, a mode's domain);
* the tangent dynamics' pieces: :func:`augmented_flow` and :func:`frozen_step` on an
  :class:`Augmented` state (x, Phi, the divergence's integral), :func:`record_saltation` and
  :func:`switch_saltation` (the saltation matrix of a switch);
* a scene's kernels for a caller that evaluates them on samples: :func:`compiled_kernels`,
  :func:`python_kernels`, :func:`outputs_on_samples`; where compiled code is kept:
  :func:`user_cache_root`, :func:`cache_dir`, :func:`source_hash`, :func:`remove_folders`.

Inside: :mod:`.tables` (the automaton as integer tables), :mod:`.rules` (crossings, far-side
roots, excursions, targets, chatter), :mod:`.tableau` (Runge-Kutta pairs as frozen,
self-checking data), :mod:`.stepper` (the adaptive step and its rules), :mod:`.ledger`,
:mod:`.loop` (one source, compiled or interpreted: :mod:`.jit`), :mod:`.kernels`, :mod:`.config`,
:mod:`.driver`, :mod:`.domain`, :mod:`.variational`, :mod:`.saltation`, :mod:`.cache`.
"""
from __future__ import annotations

from .._lazy import lazy
from .config import (ANGLE_LIMIT, BACKENDS, LOOK_AHEAD, MAP_OPTIONS, METHODS, PI_CONTROL, SCIPY_CONTROL, EventSettings,
                     SolverOptions, StepControl, step_control)

#: names loaded on first use (PEP 562): these modules import numba, the settings above do not
_LAZY = {"integrate": ".driver", "Trajectory": ".driver", "Switch": ".switches", "Switches": ".switches",
         "Domain": ".domain", "Augmented": ".variational", "augmented_flow": ".variational",
         "frozen_step": ".variational", "record_saltation": ".saltation", "switch_saltation": ".saltation",
         "saltation_matrix": ".saltation", "compiled_kernels": ".kernels", "python_kernels": ".kernels",
         "outputs_on_samples": ".kernels", "on_arrays": ".kernels", "transition_surfaces": ".tables",
         "impact_transitions": ".tables", "user_cache_root": ".cache",
         "cache_dir": ".cache", "source_hash": ".cache", "remove_folders": ".cache", "cache_entries": ".cache",
         "clear_cache": ".cache", "CACHE_ENV": ".cache", "STEP_CONTROL": ".config"}

__all__ = ["SolverOptions", "EventSettings", "StepControl", "PI_CONTROL", "SCIPY_CONTROL", "MAP_OPTIONS", "LOOK_AHEAD",
           "ANGLE_LIMIT", "BACKENDS", "METHODS", "step_control", *_LAZY]

__getattr__, __dir__ = lazy(__name__, _LAZY)
