"""camdyn's engine: the hybrid automaton of a scene, integrated by one loop.

* :mod:`.tables`   -- the generated automaton (modes, surfaces, transitions) as integer tables;
* :mod:`.rules`    -- its rules: crossings, far-side roots, excursions, targets, chatter;
* :mod:`.tableau`  -- explicit Runge-Kutta pairs (DOP853, Dormand-Prince 5(4)) as frozen,
  self-checking data; :mod:`.stepper` -- the adaptive step with dense output;
* :mod:`.ledger`   -- the energy ledger's quadrature along the dense output;
* :mod:`.loop`     -- the loop, one source run compiled (numba) or interpreted (:mod:`.jit`);
* :mod:`.kernels`  -- a scene's generated kernels as cached cfuncs or Python callables;
* :mod:`.config`   -- options, settings and the rules' constants; :mod:`.driver` -- Model in,
  Trajectory out; :mod:`.cache` -- where compiled code is kept.
"""
from __future__ import annotations

from .._lazy import lazy
from .config import BACKENDS, METHODS, PI_CONTROL, SCIPY_CONTROL, EventSettings, SolverOptions, StepControl

#: names loaded on first use (PEP 562): the driver imports numba, the settings do not
_LAZY = {"integrate": ".driver", "Switch": ".switches", "Switches": ".switches", "Trajectory": ".driver"}

__all__ = ["integrate", "SolverOptions", "EventSettings", "StepControl", "PI_CONTROL", "SCIPY_CONTROL", "Switch", "Switches",
           "Trajectory", "BACKENDS", "METHODS"]

__getattr__, __dir__ = lazy(__name__, _LAZY)
