"""A scene's generated kernels for the loop: numba ``cfunc``\\ s (compiled, cached on disk) or
plain Python callables (interpreted, bound to a user's cam motion).

Compiled as ``cfunc``\\ s of fixed signatures, the kernels reach the compiled loop as
first-class function values whose numba type is the signature alone: the loop is compiled
once for every scene, and each scene's kernels once, both cached (:mod:`.cache`).
"""
from __future__ import annotations

import math
import importlib
from functools import lru_cache
from types import ModuleType

import numba
import numpy as np
from numba import njit, types

from ..errors import SceneError
from . import cache
from .problem import Kernels

cache.install()  # numba's cache of what follows: the per-user folder (cache.py)

#: rhs(m, t, alpha, alpha_dot, p) -> alpha_ddot
RHS = types.float64(types.int64, types.float64, types.float64, types.float64, types.float64[::1])
#: surface(m, s, t, alpha, alpha_dot, p) -> value
SURFACE = types.float64(types.int64, types.int64, types.float64, types.float64, types.float64, types.float64[::1])
#: outputs(m, ..., p, out), reset(j, ..., p, out): results written to out
FILL = types.void(types.int64, types.float64, types.float64, types.float64, types.float64[::1], types.float64[::1])


def _cfunc(signature, kernel):
    """``kernel`` compiled as a cfunc of ``signature`` (cached on disk) with NumPy's error model:
    a division by zero gives inf or nan, which the loop and the tangent dynamics test for, as in
    the compiled loop itself; with Python's model it raises inside the cfunc, where numba prints
    the exception and returns an unset value (seen: damping C's impact law at psi_i = 0)."""
    return numba.cfunc(signature, cache=True, error_model="numpy")(kernel)


def _no_surface(m, s, t, alpha, alpha_dot, p):
    """A scene without switching surfaces (the linear models)."""
    return math.nan


def _no_fill(j, t, alpha, alpha_dot, p, out):
    """A kernel of FILL's signature that a run never calls (a scene whose transitions all keep
    the state, identity resets; the outputs of a compiled run without the energy ledger): NaN."""
    for k in range(out.shape[0]):
        out[k] = math.nan


no_fill = _cfunc(FILL, _no_fill)


@lru_cache(maxsize=None)
def no_surface():
    """The cfunc of :func:`_no_surface`, compiled only for a scene that needs it."""
    return _cfunc(SURFACE, _no_surface)


def _check_compilable(K: ModuleType) -> None:
    if K.SCENE.get("motion") == "user":
        raise SceneError(f"scene {K.SLUG!r} has a user cam motion: its Theta(t) is a Python callable, which "
                         "compiled code cannot call. Run it with backend='python'.")


@lru_cache(maxsize=None)
def _compiled(module_name: str) -> Kernels:
    """rhs, surface and reset of a scene as cfuncs; outputs is :func:`_compiled_outputs`'s."""
    K = importlib.import_module(module_name)
    surface = _cfunc(SURFACE, K.surface) if hasattr(K, "surface") else no_surface()
    reset = _cfunc(FILL, K.reset) if hasattr(K, "reset") else no_fill
    return Kernels(_cfunc(RHS, K.rhs), surface, no_fill, reset)


@lru_cache(maxsize=None)
def _compiled_outputs(module_name: str):
    return _cfunc(FILL, importlib.import_module(module_name).outputs)


def compiled_kernels(K: ModuleType, outputs: bool = True) -> Kernels:
    """The cfuncs of a generated scene module (compiled on first use, then from the disk cache).

    ``outputs=False``: the ``outputs`` kernel is a placeholder that is never called, for a loop
    that does not integrate the energy ledger (the only use of outputs inside the loop); the
    scene's outputs, the largest of its kernels, are then compiled only when a result's output
    quantities are read (:class:`camdyn.result.Outputs`), about a second of a cold start."""
    _check_compilable(K)
    kernels = _compiled(K.__name__)
    return kernels._replace(outputs=_compiled_outputs(K.__name__)) if outputs else kernels


@lru_cache(maxsize=None)
def _compiled_jacobian(module_name: str):
    return _cfunc(FILL, importlib.import_module(module_name).jacobian)


def compiled_jacobian(K: ModuleType):
    """The generated ``jacobian`` kernel of a scene module as a cfunc (the tangent dynamics',
    :mod:`camdyn.tangent`; compiled on first use, then from the disk cache)."""
    _check_compilable(K)
    return _compiled_jacobian(K.__name__)


def _guarded(fn):
    """A Python kernel that gives NaN where a law is undefined (a trial stage far outside its
    domain: log of a negative, sin of inf), as compiled code does, instead of raising."""
    def kernel(*args):
        try:
            return fn(*args)
        except (ValueError, OverflowError, ZeroDivisionError):
            return math.nan
    return kernel


def _guarded_fill(fn):
    def kernel(*args):
        try:
            fn(*args)
        except (ValueError, OverflowError, ZeroDivisionError):
            args[-1][:] = math.nan
    return kernel


def python_kernels(K: ModuleType, cam=None) -> Kernels:
    """The Python kernels of a generated module; ``cam`` (a ``camdyn.UserMotion``) for a scene
    with a user cam motion, whose kernels take (Theta, Theta_dot, Theta_ddot) at t."""
    if K.SCENE.get("motion") == "user":
        if cam is None:
            raise SceneError(f"scene {K.SLUG!r} needs the user's cam motion")
        rhs = lambda m, t, a, ad, p: K.rhs(m, t, a, ad, p, cam(t))  # noqa: E731
        surface = lambda m, s, t, a, ad, p: K.surface(m, s, t, a, ad, p, cam(t))  # noqa: E731
        outputs = lambda m, t, a, ad, p, out: K.outputs(m, t, a, ad, p, cam(t), out)  # noqa: E731
    else:
        rhs, surface, outputs = K.rhs, getattr(K, "surface", _no_surface), K.outputs
    reset = getattr(K, "reset", _no_fill)
    return Kernels(_guarded(rhs), _guarded(surface), _guarded_fill(outputs), _guarded_fill(reset))


@njit(cache=True, error_model="numpy")
def fill_outputs(outputs, modes, t, alpha, alpha_dot, p, out):
    """out[:, i] = the outputs at sample i in mode modes[i] (compiled: ``outputs`` a cfunc)."""
    row = np.empty(out.shape[0])
    for i in range(t.shape[0]):
        outputs(modes[i], t[i], alpha[i], alpha_dot[i], p, row)
        for k in range(row.shape[0]):  # element by element: a slice assignment compiles numba's
            out[k, i] = row[k]         # shape-error formatting (seconds of the cold start)
    return out


def outputs_on_samples(kernels: Kernels, compiled: bool, modes, t, alpha, alpha_dot, p, n_outputs: int) -> np.ndarray:
    """The output quantities at every sample: an array (n_outputs, samples)."""
    out = np.empty((n_outputs, t.size))
    if compiled:
        return fill_outputs(kernels.outputs, np.ascontiguousarray(modes, dtype=np.int64), np.ascontiguousarray(t),
                            np.ascontiguousarray(alpha), np.ascontiguousarray(alpha_dot), p, out)
    row = np.empty(n_outputs)
    for i in range(t.size):
        kernels.outputs(int(modes[i]), float(t[i]), float(alpha[i]), float(alpha_dot[i]), p, row)
        out[:, i] = row
    return out
