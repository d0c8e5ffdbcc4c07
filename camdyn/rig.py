"""The physical parameters of one cam-follower rig (Sundar, Dreyer & Singh 2013, Sec. 3).

:class:`Rig` holds the paper's parameters under the paper's names, in SI units, validated
once at construction. :data:`PARAMETERS` is the single table behind the dataclass
validation, the error messages and the generated documentation: each row gives a
parameter's name, unit, meaning, whether it is required, the paper's equation, and its
rules. Two kinds of rule:

- *range* rules state the valid range (``k_s > 0``);
- *unit guards* reject values that are almost surely in the wrong unit (a cam radius of
  50 m was meant as 50 mm, a Young's modulus of 200 Pa as 200 GPa, a follower angle of
  30 rad as 30 degrees) with an error message that says so.

Optional parameters (contact length, friction, damping) default to ``None``, meaning "not
given"; a scene that needs one demands it with :meth:`Rig.require`.

A rig file is TOML: top-level ``name`` and ``description`` strings and a ``[parameters]``
table of SI numbers::

    name = "steel line contact"
    description = "Sections 6-8 of the paper"

    [parameters]
    r_c = 0.05
    k_s = 2000.0
    ...
"""

from __future__ import annotations

import dataclasses
import difflib
import json
import math
import os
import sys
from dataclasses import dataclass
from numbers import Real
from pathlib import Path
from typing import Any, Callable, Collection, Mapping, NamedTuple

if sys.version_info >= (3, 11):
    import tomllib
else:  # pragma: no cover
    import tomli as tomllib

from .errors import ParameterError, RigFileError

__all__ = ["PARAMETERS", "Parameter", "Rule", "Rig"]


class Rule(NamedTuple):
    """One condition on a parameter's value.

    ``test(x, known)`` gets the value as a float and the already validated parameters
    before it in :data:`PARAMETERS` (so ``e`` can be compared with ``r_c``).
    ``text`` says what the value must be; ``hint`` explains a failure; ``guard`` marks a
    unit-plausibility check rather than a physical range.
    """

    text: str
    test: Callable[[float, Mapping[str, float]], bool]
    hint: str = ""
    guard: bool = False


@dataclass(frozen=True)
class Parameter:
    """One row of :data:`PARAMETERS`: a rig parameter's specification."""

    name: str
    unit: str
    description: str
    required: bool
    ref: str
    rules: tuple[Rule, ...] = ()

    @property
    def valid(self) -> str:
        """The valid range, e.g. ``"> 0"`` (unit guards not included)."""
        return " and ".join(r.text for r in self.rules if not r.guard) or "finite"

    @property
    def meaning(self) -> str:
        """Meaning and unit, e.g. ``"follower spring stiffness, N/m"``."""
        return f"{self.description}, {self.unit}"

    def check(self, value: Any, known: Mapping[str, float]) -> float | None:
        """Return ``value`` as a float (``None`` if optional and not given) or raise
        :class:`ParameterError`."""
        if value is None:
            if self.required:
                raise ParameterError(self.name, None, "required", reason=self.meaning)
            return None
        x = math.nan
        if isinstance(value, Real) and not isinstance(value, bool):
            try:
                x = float(value)
            except OverflowError:  # an int beyond the float range
                x = math.inf
        if not math.isfinite(x):
            finite = "a finite real number" + ("" if self.valid == "finite" else f" {self.valid}")
            raise ParameterError(self.name, value, finite, reason=self.meaning)
        for rule in self.rules:
            if not rule.test(x, known):
                reason = f"{self.meaning}; {rule.hint}" if rule.hint else self.meaning
                raise ParameterError(self.name, value, rule.text, reason=reason)
        return x


_MM = "given in mm? camdyn uses SI metres"
_DEGREES = "given in degrees? camdyn uses radians"
_POSITIVE = Rule("> 0", lambda x, _: x > 0)
_NON_NEGATIVE = Rule(">= 0", lambda x, _: x >= 0)
_LENGTH = (_POSITIVE, Rule("<= 10", lambda x, _: x <= 10.0, _MM, guard=True))
_MODULUS = (_POSITIVE, Rule(">= 1e6", lambda x, _: x >= 1e6, "given in GPa or MPa? camdyn uses SI pascals", guard=True))
_POISSON = (_NON_NEGATIVE, Rule("< 0.5", lambda x, _: x < 0.5))
_ALPHA_MAX = math.pi / 2 - 0.05

#: The rig parameters, in the paper's notation and SI units (Sec. 3, Fig. 1); the
#: "0-state" is the follower just touching the cam at Theta = theta0, alpha = alpha0.
PARAMETERS: tuple[Parameter, ...] = (
    # required
    Parameter("r_c", "m", "cam radius", True, "Eq. 4", _LENGTH),
    Parameter("e", "m", "cam eccentricity, distance from the cam pivot E to the cam centre", True, "Eq. 3", (
        _NON_NEGATIVE,
        Rule("< r_c", lambda x, known: x < known["r_c"], "the cam pivot E must lie inside the cam disk"),
    )),
    Parameter("w_b", "m", "follower bar width", True, "Eq. 2", _LENGTH),
    Parameter("chi0", "m", "distance from the follower pivot P to the contact along the bar in the 0-state", True, "Eq. 2, 5", _LENGTH),
    Parameter("alpha0", "rad", "follower angle from the horizontal, clockwise, in the 0-state", True, "Eq. 5", (
        Rule("in [-pi/2, pi/2]", lambda x, _: abs(x) <= math.pi / 2, _DEGREES, guard=True),
        Rule("in (-pi/2 + 0.05, pi/2 - 0.05)", lambda x, _: abs(x) < _ALPHA_MAX, "tan and sec in Eq. 11 blow up near 90 degrees"),
    )),
    Parameter("theta0", "rad", "cam angle in the 0-state, counter-clockwise from the horizontal", True, "Eq. 5", (
        Rule("in [-2 pi, 2 pi]", lambda x, _: abs(x) <= 2 * math.pi, _DEGREES, guard=True),
    )),
    Parameter("d_x", "m", "horizontal distance from the follower pivot P to the spring", True, "Eq. 10, 11", _LENGTH),
    Parameter("d_y", "m", "height of the follower pivot P above the ground", True, "Eq. 11", (
        Rule("in [-10, 10]", lambda x, _: abs(x) <= 10.0, _MM, guard=True),
    )),
    Parameter("L_us", "m", "free length of the follower spring", True, "Eq. 11", _LENGTH),
    Parameter("k_s", "N/m", "follower spring stiffness", True, "Eq. 11", (_POSITIVE,)),
    Parameter("I_Pb", "kg m^2", "moment of inertia of the follower about its pivot P", True, "Eq. 10",
              (_POSITIVE, Rule(">= 1e-9", lambda x, _: x >= 1e-9,
                               "given in g mm^2 or kg mm^2? camdyn uses SI kg m^2 (a follower lighter "
                               "than 1e-9 kg m^2 has a contact mode too fast to integrate)", guard=True))),
    Parameter("Y_c", "Pa", "Young's modulus of the cam", True, "Eq. 14", _MODULUS),
    Parameter("Y_b", "Pa", "Young's modulus of the follower", True, "Eq. 14", _MODULUS),
    Parameter("nu_c", "dimensionless", "Poisson's ratio of the cam", True, "Eq. 14", _POISSON),
    Parameter("nu_b", "dimensionless", "Poisson's ratio of the follower", True, "Eq. 14", _POISSON),
    # optional: None means "not given"
    Parameter("l_lambda", "m", "length of the line contact", False, "Eq. 13", _LENGTH),
    Parameter("mu_m", "dimensionless", "friction coefficient", False, "Sec. 3.2, friction models I and II", (_NON_NEGATIVE,)),
    Parameter("s", "s/m", "smoothing factor of the tanh friction model", False, "Sec. 3.2, friction model II", (_POSITIVE,)),
    Parameter("zeta_A", "dimensionless", "viscous damping ratio of damping model A", False, "Eq. 24", (_NON_NEGATIVE,)),
    Parameter("zeta_D", "dimensionless", "viscous damping ratio of damping model D after maximum compression", False, "Eq. 27", (_NON_NEGATIVE,)),
    Parameter("zeta_E", "dimensionless", "viscous damping ratio of damping model E after maximum compression", False, "Eq. 28", (_NON_NEGATIVE,)),
    Parameter("beta_B", "s/m", "impact damping factor of damping model B", False, "Eq. 25", (_NON_NEGATIVE,)),
    Parameter("beta_D", "s/m", "impact damping factor of damping model D up to maximum compression", False, "Eq. 27", (_NON_NEGATIVE,)),
    Parameter("beta_C", "N s/m^1.25", "impact damping coefficient of damping model C", False, "Eq. 26", (_NON_NEGATIVE,)),
    Parameter("beta_E", "N s/m^1.25", "impact damping coefficient of damping model E up to maximum compression", False, "Eq. 28", (_NON_NEGATIVE,)),
)

_BY_NAME = {p.name: p for p in PARAMETERS}
_TEXT_FIELDS = ("name", "description")
_FIELDS = (*_BY_NAME, *_TEXT_FIELDS)


def _check_names(names: Collection[Any], source: str, known: Collection[str], what: str = "parameter") -> None:
    """Raise :class:`RigFileError` for names not in ``known``, suggesting close matches."""
    unknown = [n for n in names if n not in known]
    if not unknown:
        return
    by_lower = {k.lower(): k for k in known}
    problems = []
    for name in unknown:
        text = str(name)
        close = [by_lower[text.lower()]] if text.lower() in by_lower else difflib.get_close_matches(text, known, n=1)
        problems.append(f"unknown {what} {text!r}" + (f" (did you mean {close[0]!r}?)" if close else ""))
    raise RigFileError(source, "; ".join(problems), key=str(unknown[0]))


def _toml_string(text: str) -> str:
    """A TOML basic string (JSON escapes are TOML escapes; TOML also wants DEL escaped)."""
    return json.dumps(text, ensure_ascii=False).replace("\x7f", "\\u007f")


@dataclass(frozen=True, kw_only=True)
class Rig:
    """The parameters of one cam-follower rig, in the paper's notation and SI units.

    Build one with keywords (``Rig(r_c=0.05, e=0.005, ...)``), :meth:`from_dict` or
    :meth:`from_toml`. Values are validated once, here: each must be a real number (not a
    bool), finite and in range, else :class:`~camdyn.errors.ParameterError`. Ints and
    numpy scalars are stored as floats. Instances are immutable; use :meth:`replace`.
    """

    r_c: float
    e: float
    w_b: float
    chi0: float
    alpha0: float
    theta0: float
    d_x: float
    d_y: float
    L_us: float
    k_s: float
    I_Pb: float
    Y_c: float
    Y_b: float
    nu_c: float
    nu_b: float
    l_lambda: float | None = None
    mu_m: float | None = None
    s: float | None = None
    zeta_A: float | None = None
    zeta_D: float | None = None
    zeta_E: float | None = None
    beta_B: float | None = None
    beta_D: float | None = None
    beta_C: float | None = None
    beta_E: float | None = None
    name: str = "unnamed"
    description: str = ""

    def __post_init__(self) -> None:
        known: dict[str, float] = {}
        for p in PARAMETERS:
            known[p.name] = p.check(getattr(self, p.name), known)
            object.__setattr__(self, p.name, known[p.name])
        for field in _TEXT_FIELDS:
            if not isinstance(getattr(self, field), str):
                raise ParameterError(field, getattr(self, field), "a string")

    @property
    def Y_e(self) -> float:
        """Equivalent Young's modulus of the contact, Pa (Eq. 14):
        ``1 / ((1 - nu_c**2) / Y_c + (1 - nu_b**2) / Y_b)``."""
        return 1.0 / ((1.0 - self.nu_c**2) / self.Y_c + (1.0 - self.nu_b**2) / self.Y_b)

    def require(self, *names: str, why: str = "") -> None:
        """Raise :class:`ParameterError` if any of the named parameters is not given.

        ``why`` names the user, e.g. ``rig.require("beta_D", "zeta_D", why="damping model D")``.
        """
        _check_names(names, "Rig.require()", _BY_NAME)
        missing = [n for n in names if getattr(self, n) is None]
        if missing:
            first, *others = missing
            reason = _BY_NAME[first].meaning + (f"; also not given: {', '.join(others)}" if others else "")
            raise ParameterError(first, None, f"required by {why}" if why else "required", reason=reason)

    def replace(self, **changes: Any) -> Rig:
        """A validated copy with some fields changed; unknown names raise
        :class:`~camdyn.errors.RigFileError` with a suggestion."""
        _check_names(changes, "Rig.replace()", _FIELDS)
        return dataclasses.replace(self, **changes)

    def to_dict(self) -> dict[str, Any]:
        """All fields as a flat dict, optional ones not given as ``None``; see :meth:`from_dict`."""
        return dataclasses.asdict(self)

    @classmethod
    def from_dict(cls, d: Mapping[str, Any], *, source: str = "<dict>") -> Rig:
        """Build a rig from a flat mapping of field names to values (as :meth:`to_dict` gives).

        Unknown keys, missing required keys and invalid values raise
        :class:`~camdyn.errors.RigFileError` naming ``source`` and the key (an invalid value's
        :class:`~camdyn.errors.ParameterError` is chained as its cause).
        """
        if not isinstance(d, Mapping):
            raise RigFileError(source, f"expected a table of parameters, got {type(d).__name__}")
        _check_names(d, source, _FIELDS)
        missing = [p.name for p in PARAMETERS if p.required and p.name not in d]
        if missing:
            raise RigFileError(source, f"missing required parameter(s): {', '.join(missing)}", key=missing[0])
        try:
            return cls(**d)
        except ParameterError as exc:
            raise RigFileError(source, str(exc), key=exc.name) from exc

    @classmethod
    def from_toml(cls, path: str | os.PathLike[str]) -> Rig:
        """Read a rig file: top-level ``name`` and ``description``, SI numbers in ``[parameters]``."""
        source = os.fspath(path)
        try:
            with open(path, "rb") as f:
                doc = tomllib.load(f)
        except OSError as exc:
            raise RigFileError(source, f"cannot read rig file: {exc.strerror or exc}") from exc
        except (tomllib.TOMLDecodeError, UnicodeDecodeError) as exc:
            raise RigFileError(source, f"not valid TOML: {exc}") from exc
        for key in doc:
            if key in _BY_NAME:
                raise RigFileError(source, f"parameter {key!r} must be inside the [parameters] table", key=key)
        _check_names(doc, source, (*_TEXT_FIELDS, "parameters"), what="top-level key")
        params = doc.get("parameters")
        if not isinstance(params, dict):
            problem = "missing [parameters] table" if params is None else "'parameters' must be a table"
            raise RigFileError(source, problem, key="parameters")
        _check_names(params, source, _BY_NAME)
        return cls.from_dict({**params, **{k: doc[k] for k in _TEXT_FIELDS if k in doc}}, source=source)

    def to_toml(self, path: str | os.PathLike[str]) -> None:
        """Write the rig file read by :meth:`from_toml` (floats written with ``repr``, so the
        round trip is exact); parameters not given are left out."""
        lines = [
            "# camdyn rig file: SI units (see camdyn.rig.PARAMETERS)",
            f"name = {_toml_string(self.name)}",
            f"description = {_toml_string(self.description)}",
            "",
            "[parameters]",
        ]
        for p in PARAMETERS:
            value = getattr(self, p.name)
            if value is not None:
                lines.append(f"{p.name:<8} = {value!r:<22} # {p.meaning}")
        Path(path).write_text("\n".join(lines) + "\n", encoding="utf-8")


def _parameter_docs() -> str:
    """The numpydoc "Parameters" section of :class:`Rig`, generated from :data:`PARAMETERS`."""
    out = ["", "    Parameters", "    ----------"]
    for p in PARAMETERS:
        out.append(f"    {p.name} : float, {p.unit}, {'required' if p.required else 'optional (None: not given)'}")
        text = f"{p.description[0].upper()}{p.description[1:]} ({p.ref}). Valid: {p.valid}."
        for rule in p.rules:
            if rule.guard:
                text += f" Rejected unless {rule.text} ({rule.hint})."
        out.append(f"        {text}")
    out += ["    name : str", "        Short name of the rig.", "    description : str", "        Free text."]
    return "\n".join(out) + "\n"


if Rig.__doc__:  # None under python -OO
    Rig.__doc__ += _parameter_docs()
