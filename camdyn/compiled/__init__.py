"""camdyn's compiled backend: the whole hybrid loop in numba.

``camdyn.simulate(..., backend="compiled")`` runs it.  Parts:

* :mod:`.tableau`  -- explicit Runge-Kutta methods (Dormand-Prince 5(4), DOP853) as frozen,
  self-checking data;
* :mod:`.stepper`  -- the adaptive step with dense output (SciPy's algorithm, compiled);
* :mod:`.events`   -- sign changes with direction, far-side roots on the interpolant;
* :mod:`.engine`   -- regimes, switches, sampling: the loop;
* :mod:`.kernels`  -- a scene's generated ``rhs_index``/``surface_index`` as cached cfuncs;
* :mod:`.backend`  -- Model in, Trajectory out.

Everything compiled is cached on disk (numba ``cache=True``): the first run on a machine
compiles (cold start), later processes load the cache (warm start).
"""
from __future__ import annotations

from .backend import integrate
from .tableau import DOP853, DOPRI5, TABLEAUS, Tableau, TableauError

__all__ = ["integrate", "Tableau", "TableauError", "DOPRI5", "DOP853", "TABLEAUS"]
