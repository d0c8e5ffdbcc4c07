"""The guards of every public entry point, written once: a value is a real number (not a bool,
which Python counts as an int), an integer, or a flag, within what a test allows; else a
:class:`~camdyn.errors.ParameterError` that names the parameter and what it must be.

    tol = real("tol", tol, "0 < tol < 1 (scaled residual)", lambda v: 0 < v < 1)
    periods = integer("periods", periods, "an integer, 1 <= periods <= 50", lambda n: 1 <= n <= 50)
"""
from __future__ import annotations

import math
from numbers import Integral, Real
from typing import Callable

from .errors import ParameterError

__all__ = ["is_real", "is_integer", "real", "integer", "finite", "flag"]


def is_real(value) -> bool:
    """Whether ``value`` is a real number (NumPy's included), not a bool."""
    return isinstance(value, Real) and not isinstance(value, bool)


def is_integer(value) -> bool:
    """Whether ``value`` is an integer (NumPy's included), not a bool."""
    return isinstance(value, Integral) and not isinstance(value, bool)


def real(name: str, value, valid: str, test: Callable[[float], bool] = lambda v: True) -> float:
    """``value`` as a float, when it is a real number that passes ``test`` (NaN passes no
    comparison); else ParameterError(name, value, valid)."""
    if not is_real(value) or not test(float(value)):
        raise ParameterError(name, value, valid)
    return float(value)


def finite(name: str, value, valid: str = "a finite real number") -> float:
    """``value`` as a float, when it is a finite real number."""
    return real(name, value, valid, math.isfinite)


def integer(name: str, value, valid: str, test: Callable[[int], bool] = lambda n: True) -> int:
    """``value`` as an int, when it is an integer that passes ``test``; else ParameterError."""
    if not is_integer(value) or not test(int(value)):
        raise ParameterError(name, value, valid)
    return int(value)


def flag(name: str, value) -> bool:
    """``value`` when it is True or False (not 0, 1 or a string)."""
    if not isinstance(value, bool):
        raise ParameterError(name, value, "True or False")
    return value
