"""A scene's generated kernels compiled for the engine: numba ``cfunc``s, cached on disk.

The generated modules carry ``rhs_index(r, t, alpha, alpha_dot, p)`` (the regime's
alpha_ddot by index), ``surface_index(k, ...)`` (flag k's switching surface),
``aux_index(j, ...)`` (the gap rate; the partials of v_r with Coulomb friction) and
``power_index(c, ...)`` (the energy ledger's flows).  Compiled as ``cfunc``s of one fixed signature, they reach the engine as
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


def _absent(k, t, alpha, alpha_dot, p):
    """A kernel family the scene does not have (linear models switch nothing: no surface,
    no gap rate)."""
    return math.nan


absent = numba.cfunc(SIGNATURE, cache=True)(_absent)


@lru_cache(maxsize=None)
def _compiled(module_name: str):
    import importlib
    K = importlib.import_module(module_name)

    def compiled(name):
        fn = getattr(K, name, None)
        return absent if fn is None else numba.cfunc(SIGNATURE, cache=True)(fn)
    return tuple(compiled(name) for name in ("rhs_index", "surface_index", "aux_index", "power_index"))


def scene_functions(kernels: ModuleType):
    """(rhs, surface) cfuncs of a generated scene module (see :func:`scene_kernels` for all four)."""
    return scene_kernels(kernels)[:2]


def scene_kernels(kernels: ModuleType):
    """(rhs, surface, aux, power) cfuncs of a generated scene module, ``absent`` for a family
    the scene does not have.

    Raises SceneError for a scene without index kernels: the user cam motion, whose
    kernels take the user's Python callables, cannot run compiled.
    """
    if getattr(kernels, "SCENE", {}).get("motion") == "user":
        raise SceneError(
            f"scene {kernels.SLUG!r} has a user cam motion: its Theta(t) is a Python callable, which "
            "the compiled backend cannot call. Use backend='scipy' (or a built-in motion: "
            "ConstantSpeed, Oscillating).")
    if not hasattr(kernels, "rhs_index") or not hasattr(kernels, "power_index"):
        raise SceneError(f"scene {kernels.SLUG!r} was generated without the index kernels (rhs_index, "
                         "power_index); regenerate with 'python -m camdyn.derive'")
    return _compiled(kernels.__name__)
