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
    - ``outputs(m, t, alpha, alpha_dot, p, out)``: the OUTPUTS written to ``out``
    - ``reset(j, t, alpha, alpha_dot, p, out)``: reset j's state written to ``out``
    """

    rhs: Any
    surface: Any
    outputs: Any
    reset: Any


class Problem(NamedTuple):
    kernels: Kernels
    tables: Tables
    p: np.ndarray
