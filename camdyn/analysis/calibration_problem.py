"""What a calibration is given, and the checks that it is well posed: the unknowns
(:class:`Unknown`), the targets (:class:`Target`) and :func:`validate`, which turns a problem
that cannot be fitted into a :class:`CalibrationError` naming the unknown, target or parameter.
The public names are those of :mod:`camdyn.analysis.calibrate`."""
from __future__ import annotations

import difflib
import math
from dataclasses import dataclass, field
from typing import Any, Callable, Mapping, NamedTuple, Sequence

from .._checks import is_integer, is_real
from ..errors import CamdynError
from ..model.rig import PARAMETERS, Rig

RIG_PARAMS = tuple(p.name for p in PARAMETERS)
BY_NAME = {p.name: p for p in PARAMETERS}


class CalibrationError(CamdynError, ValueError):
    """A calibration problem is ill-posed (bad unknowns, targets, bounds) or cannot be evaluated."""


def suggest(name: str, known: Sequence[str]) -> str:
    """" (did you mean 'x'?)" for the closest of ``known``, or ""."""
    close = difflib.get_close_matches(str(name), list(known), n=1)
    return f" (did you mean {close[0]!r}?)" if close else ""


def rounding_sigma(value: float, digits: int) -> float:
    """Half a unit of the ``digits``-th significant digit of ``value``: the uncertainty
    of a number printed to that many significant digits (2182 with 4 -> 0.5)."""
    if not (is_integer(digits) and digits >= 1):
        raise CalibrationError(f"digits = {digits!r}: must be an integer >= 1 (significant digits)")
    if not (math.isfinite(value) and value != 0):
        raise CalibrationError(f"cannot take {digits} significant digits of {value!r}")
    exponent = math.floor(math.log10(abs(value))) - digits + 1
    return 0.5 * 10.0 ** exponent


# ----------------------------------------------------------------------------- unknowns


@dataclass(frozen=True)
class Unknown:
    """A parameter to fit, within ``[lower, upper]``.

    ``name`` is a rig parameter (``"I_Pb"``) or an extra unknown that some target's
    ``settings`` refers to (``"k_s_exp"``).  ``scale``: ``"log"`` fits log(x) (natural
    for positive magnitudes spanning decades: stiffness, inertia), ``"linear"`` fits x
    (lengths measured from a datum, angles); ``"auto"`` chooses log when ``lower > 0``
    and ``upper / lower >= 10``.  ``initial`` defaults to the rig's value (required for
    an extra unknown or a parameter the rig does not give).
    """

    name: str
    lower: float
    upper: float
    scale: str = "auto"
    initial: float | None = None
    unit: str = ""

    def __post_init__(self):
        if not isinstance(self.name, str) or not self.name:
            raise CalibrationError(f"Unknown name must be a non-empty string, got {self.name!r}")
        for what in ("lower", "upper"):
            v = getattr(self, what)
            if not is_real(v) or math.isnan(v):
                raise CalibrationError(f"unknown {self.name!r}: {what} = {v!r} must be a number")
        if not self.lower < self.upper:
            raise CalibrationError(f"unknown {self.name!r}: lower = {self.lower!r} must be < upper = {self.upper!r}")
        if self.scale not in ("auto", "log", "linear"):
            raise CalibrationError(f"unknown {self.name!r}: scale = {self.scale!r} must be 'auto', 'log' or 'linear'")
        if self.scale == "log" and not self.lower > 0:
            raise CalibrationError(f"unknown {self.name!r}: a log scale needs lower > 0, got lower = {self.lower!r}")
        if self.initial is not None and not (is_real(self.initial) and math.isfinite(self.initial)):
            raise CalibrationError(f"unknown {self.name!r}: initial = {self.initial!r} must be a finite number")

    @property
    def log(self) -> bool:
        if self.scale == "auto":
            return self.lower > 0 and math.isfinite(self.upper) and self.upper / self.lower >= 10
        return self.scale == "log"

    def to_internal(self, x: float) -> float:
        if self.log:
            return math.log(x)
        width = self.upper - self.lower
        return x / width if math.isfinite(width) else x

    def from_internal(self, z: float) -> float:
        if self.log:
            return math.exp(z)
        width = self.upper - self.lower
        return z * width if math.isfinite(width) else z

    def internal_bounds(self) -> tuple[float, float]:
        if self.log:
            return math.log(self.lower), (math.log(self.upper) if math.isfinite(self.upper) else math.inf)
        lo, hi = self.to_internal(self.lower), self.to_internal(self.upper)
        return lo, hi


# ----------------------------------------------------------------------------- targets


@dataclass(frozen=True)
class Target:
    """A value that camdyn computes from a rig, and the value it should have.

    ``compute(rig) -> float`` computes it; ``value`` is the measurement; ``sigma`` its
    uncertainty (absolute, same unit; default ``|value|``, a relative residual), or
    ``digits`` significant digits (sigma = half a unit of the last digit).  ``settings``
    replaces rig parameters before computing (a variant of the rig: another spring,
    another contact length); a string setting names an extra unknown.  ``source`` says
    where the value comes from (e.g. ``"paper, Sec. 6"``).
    """

    name: str
    value: float
    compute: Callable[[Rig], float]
    sigma: float | None = None
    digits: int | None = None
    unit: str = ""
    settings: Mapping[str, float | str] = field(default_factory=dict)
    source: str = ""
    description: str = ""

    def __post_init__(self):
        if not isinstance(self.name, str) or not self.name:
            raise CalibrationError(f"Target name must be a non-empty string, got {self.name!r}")
        if not is_real(self.value) or not math.isfinite(self.value):
            raise CalibrationError(f"target {self.name!r}: value = {self.value!r} must be a finite number")
        if not callable(self.compute):
            raise CalibrationError(f"target {self.name!r}: compute must be a callable of the rig")
        self._check_uncertainty()
        for key, v in dict(self.settings).items():
            if key not in BY_NAME:
                raise CalibrationError(f"target {self.name!r}: setting {key!r} is not a rig parameter"
                                       + suggest(key, RIG_PARAMS))
            if not isinstance(v, str) and not is_real(v):
                raise CalibrationError(f"target {self.name!r}: setting {key} = {v!r} must be a number or the "
                                       "name of an extra unknown")

    def _check_uncertainty(self) -> None:
        """sigma or digits (not both), or a non-zero value (its own scale)."""
        if self.sigma is not None and self.digits is not None:
            raise CalibrationError(f"target {self.name!r}: give sigma or digits, not both")
        if self.sigma is not None and not (is_real(self.sigma) and math.isfinite(self.sigma) and self.sigma > 0):
            raise CalibrationError(f"target {self.name!r}: sigma = {self.sigma!r} must be a finite number > 0")
        if self.digits is not None:
            rounding_sigma(self.value, self.digits)  # validates
        if self.sigma is None and self.digits is None and self.value == 0:
            raise CalibrationError(f"target {self.name!r}: a zero value needs an absolute sigma")

    @property
    def uncertainty(self) -> float:
        """The absolute uncertainty used to weight the residual."""
        if self.sigma is not None:
            return float(self.sigma)
        if self.digits is not None:
            return rounding_sigma(float(self.value), self.digits)
        return abs(float(self.value))

    def variant(self, rig: Rig, extras: Mapping[str, float] | None = None) -> Rig:
        """The rig this target is computed on (``settings`` applied)."""
        if not self.settings:
            return rig
        extras = extras or {}
        changes = {}
        for key, v in self.settings.items():
            if isinstance(v, str):
                if v not in extras:
                    raise CalibrationError(f"target {self.name!r}: setting {key} = {v!r} names no extra unknown"
                                           + suggest(v, list(extras)))
                changes[key] = extras[v]
            else:
                changes[key] = float(v)
        return rig.replace(**changes)


# ----------------------------------------------------------------------------- the problem, checked


class Problem(NamedTuple):
    """A calibration problem that passed :func:`validate`: what :func:`~camdyn.analysis.calibrate.calibrate`
    fits."""

    unknowns: tuple[Unknown, ...]
    targets: tuple[Target, ...]
    fixed: dict[str, str]             # parameter -> the assumption that fixes it
    tied: dict[str, Callable]         # parameter -> its function of the others
    initial: dict[str, float]         # unknown -> its starting value


def validate(rig: Rig, unknowns: Sequence[Unknown], targets: Sequence[Target], fixed: Mapping[str, str] | None,
             tied: Mapping[str, Callable] | None, allow_underdetermined: bool) -> Problem:
    """The problem, or a CalibrationError naming what makes it ill posed."""
    if not isinstance(rig, Rig):
        raise CalibrationError(f"rig must be a camdyn.Rig, got {type(rig).__name__}")
    unknowns, targets = _checked_lists(unknowns, targets)
    names = [u.name for u in unknowns]
    _check_extras(names, targets)
    fixed = _checked_fixed(rig, fixed, names)
    tied = _checked_tied(tied, names, fixed)
    initial = {u.name: _initial_value(rig, u) for u in unknowns}
    if len(unknowns) > len(targets) and not allow_underdetermined:
        raise CalibrationError(
            f"{len(unknowns)} unknowns ({', '.join(names)}) but only {len(targets)} target(s): the fit "
            f"cannot determine them. Fix {len(unknowns) - len(targets)} of them by assumption (leave them "
            "out of the unknowns and name them in fixed= with the reason), add targets, or pass "
            "allow_underdetermined=True")
    return Problem(unknowns, targets, fixed, tied, initial)


def _checked_lists(unknowns, targets) -> tuple[tuple[Unknown, ...], tuple[Target, ...]]:
    """Both non-empty, of the right types, no name twice."""
    unknowns, targets = tuple(unknowns), tuple(targets)
    if not unknowns:
        raise CalibrationError("no unknowns: give at least one Unknown to fit")
    if not targets:
        raise CalibrationError("no targets: give at least one Target to fit to")
    for u in unknowns:
        if not isinstance(u, Unknown):
            raise CalibrationError(f"unknowns must be Unknown(...), got {u!r}")
    for t in targets:
        if not isinstance(t, Target):
            raise CalibrationError(f"targets must be Target(...), got {t!r}")
    dup = _twice([u.name for u in unknowns])
    if dup:
        raise CalibrationError(f"unknown(s) listed twice: {', '.join(dup)}")
    dup = _twice([t.name for t in targets])
    if dup:
        raise CalibrationError(f"target name(s) used twice: {', '.join(dup)} (give each a distinct name=)")
    return unknowns, targets


def _twice(names: list[str]) -> list[str]:
    return sorted({n for n in names if names.count(n) > 1})


def _check_extras(names: list[str], targets: tuple[Target, ...]) -> None:
    """Every unknown that is not a rig parameter is an extra some target's settings name, and
    every extra the settings name is an unknown."""
    referenced = {v for t in targets for v in t.settings.values() if isinstance(v, str)}
    for n in names:
        if n not in BY_NAME and n not in referenced:
            raise CalibrationError(
                f"unknown {n!r} is not a rig parameter{suggest(n, RIG_PARAMS)} and no target's settings "
                "refer to it (an extra unknown is a parameter of a rig variant, e.g. settings={'k_s': "
                + repr(n) + "})")
    missing = sorted(referenced - set(names))
    if missing:
        raise CalibrationError(f"target settings refer to {', '.join(map(repr, missing))}, which "
                               f"{'is' if len(missing) == 1 else 'are'} not among the unknowns"
                               + suggest(missing[0], names))


def _check_not_fitted(k: str, kind: str, role: str, names: list[str]) -> None:
    """A fixed or tied parameter (``kind``) is a rig parameter and not one of the unknowns."""
    if k not in BY_NAME:
        raise CalibrationError(f"{kind} parameter {k!r} is not a rig parameter" + suggest(k, RIG_PARAMS))
    if k in names:
        raise CalibrationError(f"{k!r} is both an unknown and {role}: choose one")


def _checked_fixed(rig: Rig, fixed: Mapping[str, str] | None, names: list[str]) -> dict[str, str]:
    """Rig parameters with a value, not fitted, each with its assumption in words."""
    fixed = dict(fixed or {})
    for k, why in fixed.items():
        _check_not_fitted(k, "fixed", "fixed by assumption", names)
        if not isinstance(why, str) or not why.strip():
            raise CalibrationError(f"fixed parameter {k!r}: give the assumption as a non-empty string (why "
                                   "its value is plausible)")
        if getattr(rig, k) is None:
            raise CalibrationError(f"fixed parameter {k!r} has no value in the rig: set it first")
    return fixed


def _checked_tied(tied: Mapping[str, Callable] | None, names: list[str], fixed: dict[str, str]) -> dict:
    """Rig parameters neither fitted nor fixed, each a callable of the others."""
    tied = dict(tied or {})
    for k, fn in tied.items():
        _check_not_fitted(k, "tied", "tied to others", names)
        if k in fixed:
            raise CalibrationError(f"{k!r} is both fixed and tied: choose one")
        if not callable(fn):
            raise CalibrationError(f"tied parameter {k!r}: give a callable of the parameter values")
    return tied


def _initial_value(rig: Rig, u: Unknown) -> float:
    """The unknown's own initial value, else the rig's; within its bounds."""
    x0: Any = u.initial
    if x0 is None and u.name in BY_NAME:
        x0 = getattr(rig, u.name)
    if x0 is None:
        raise CalibrationError(f"unknown {u.name!r} has no initial value: the rig does not give it, so pass "
                               f"Unknown({u.name!r}, ..., initial=...)")
    if not u.lower <= x0 <= u.upper:
        raise CalibrationError(f"unknown {u.name!r}: initial value {x0:g} is outside its bounds "
                               f"[{u.lower:g}, {u.upper:g}]")
    if u.log and x0 <= 0:
        raise CalibrationError(f"unknown {u.name!r}: initial value {x0:g} must be > 0 on a log scale")
    return float(x0)
