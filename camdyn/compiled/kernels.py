"""A scene's generated kernels compiled for the engine: numba ``cfunc``s, cached on disk.

The generated modules carry ``rhs_index(r, t, alpha, alpha_dot, p)`` (the regime's
alpha_ddot by index) and ``surface_index(k, t, alpha, alpha_dot, p)`` (flag k's switching
surface).  Compiled as ``cfunc``s of one fixed signature, they reach the engine as
first-class function values whose numba type is that signature alone: the engine is
compiled once for every scene (and cached), and each scene's kernels once (and cached,
in the generated package's ``__pycache__`` or numba's user cache).
"""
from __future__ import annotations

import math
from functools import lru_cache
from types import ModuleType

import numba
from numba import types

from ..errors import SceneError

#: (regime or flag index, t, alpha, alpha_dot, p) -> float
SIGNATURE = types.float64(types.int64, types.float64, types.float64, types.float64, types.float64[::1])


def _no_surface(k, t, alpha, alpha_dot, p):
    """Linear models switch nothing: no surface exists."""
    return math.nan


no_surface = numba.cfunc(SIGNATURE, cache=True)(_no_surface)


@lru_cache(maxsize=None)
def _compiled(module_name: str):
    import importlib
    K = importlib.import_module(module_name)
    rhs = numba.cfunc(SIGNATURE, cache=True)(K.rhs_index)
    surface = numba.cfunc(SIGNATURE, cache=True)(K.surface_index) if K.FLAGS else no_surface
    return rhs, surface


def scene_functions(kernels: ModuleType):
    """(rhs, surface) cfuncs of a generated scene module.

    Raises SceneError for a scene without index kernels: the user cam motion, whose
    kernels take the user's Python callables, cannot run compiled.
    """
    if getattr(kernels, "SCENE", {}).get("motion") == "user":
        raise SceneError(
            f"scene {kernels.SLUG!r} has a user cam motion: its Theta(t) is a Python callable, which "
            "the compiled backend cannot call. Use backend='scipy' (or a built-in motion: "
            "ConstantSpeed, Oscillating).")
    if not hasattr(kernels, "rhs_index"):
        raise SceneError(f"scene {kernels.SLUG!r} was generated without rhs_index; "
                         "regenerate with 'python -m camdyn.derive'")
    return _compiled(kernels.__name__)
