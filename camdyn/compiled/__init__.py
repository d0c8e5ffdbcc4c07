"""camdyn's compiled backend: the whole hybrid loop in numba.

``camdyn.simulate(..., backend="compiled")`` runs it.  Parts:

* :mod:`.tableau`  -- explicit Runge-Kutta methods (Dormand-Prince 5(4), DOP853) as frozen,
  self-checking data;
* :mod:`.stepper`  -- the adaptive step with dense output (SciPy's algorithm, compiled);
* :mod:`.regimes`  -- the discrete state: regimes and stick modes, their fields, surfaces, switches;
* :mod:`.events`   -- sign changes with direction, hidden excursions, far-side roots on the interpolant;
* :mod:`.ledger`   -- the energy ledger's quadrature along the dense output;
* :mod:`.engine`   -- steps, switches, sampling: the loop;
* :mod:`.kernels`  -- a scene's generated index kernels as cached cfuncs;
* :mod:`.backend`  -- Model in, Trajectory out;
* :mod:`.cache`    -- the disk cache kept in step with the package's sources.

Everything compiled is cached on disk (numba ``cache=True``): the first run on a machine
compiles (cold start), later processes load the cache (warm start).
"""
from __future__ import annotations

import warnings

from numba.core.errors import NumbaExperimentalFeatureWarning

# the kernels reach the loop as first-class function values, a feature numba still labels
# experimental; the tests pin its behaviour (tests/test_compiled.py), so users are not warned at every compile
warnings.filterwarnings("ignore", category=NumbaExperimentalFeatureWarning,
                        message="First-class function type feature is experimental")

from . import engine  # noqa: E402
from .backend import integrate  # noqa: E402
from .cache import cache_dir_of, refresh  # noqa: E402
from .tableau import DOP853, DOPRI5, TABLEAUS, Tableau, TableauError  # noqa: E402

# before numba loads anything cached: drop the cache if any module of the loop changed
refresh(cache_dir_of(engine.run))

__all__ = ["integrate", "Tableau", "TableauError", "DOPRI5", "DOP853", "TABLEAUS"]
