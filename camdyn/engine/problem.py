"""What the loop integrates: a scene's kernels, its automaton tables and the parameter vector."""
from __future__ import annotations

from typing import Any, NamedTuple

import numpy as np

from .tables import Tables


class Kernels(NamedTuple):
    """A scene's generated kernels (``camdyn.generated.scene_*``), compiled (numba ``cfunc``\\ s)
    or plain Python:

    - ``rhs(m, t, alpha, alpha_dot, p) -> alpha_ddot``
    - ``surface(m, s, t, alpha, alpha_dot, p) -> value``
    - ``surface_with_rate(m, s, t, alpha, alpha_dot, p, out)``: surface s's value and its declared
      rate's (RATE_OF_SURFACE[s]), computed together, written to ``out`` as SURFACE_WITH_RATE
      names them (``out[WITH_RATE_VALUE]``, ``out[WITH_RATE_RATE]``, camdyn.vocabulary)
    - ``outputs(m, t, alpha, alpha_dot, p, out)``: the OUTPUTS written to ``out``
    - ``reset(j, t, alpha, alpha_dot, p, out)``: reset j's state written to ``out``
    """

    rhs: Any
    surface: Any
    outputs: Any
    reset: Any
    surface_with_rate: Any = None   # None: no surface of the scene has a rate (never called)


class Problem(NamedTuple):
    kernels: Kernels
    tables: Tables
    p: np.ndarray
