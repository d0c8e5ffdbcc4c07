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
given"; a scene that needs one demands it with :meth:`Rig.require`. A constant that a model
edit adds to one of the paper's laws may declare a *neutral* value, the one that gives the
paper's law back (:data:`NEUTRAL`): it is still not a default (a rig that does not give it is
refused, with that value in the message); ``camdyn regenerate`` writes it into the shipped
rig files (docs/model-editing.md).

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
from pathlib import Path
from typing import Any, Collection, Mapping

if sys.version_info >= (3, 11):
    import tomllib
else:  # pragma: no cover
    import tomli as tomllib

import numpy as np

from ..vocabulary.parameters import FOLLOWER_TYPES, RIG_PARAMETERS, RigParameter, Rule
from ..vocabulary.scenes import PROFILES
from .._checks import is_real
from ..errors import ParameterError, RigFileError

__all__ = ["PARAMETERS", "NEUTRAL", "Parameter", "Rule", "Rig"]


#: the paper's follower (Fig. 1), a rig's type where its file names none
_OSCILLATING = FOLLOWER_TYPES[0]
#: the units of :data:`PARAMETERS` that people read differently ("1": a pure number)
_UNIT_WORDS = {"1": "dimensionless"}


@dataclass(frozen=True)
class Parameter(RigParameter):
    """One rig parameter's specification: its declaration in ``camdyn.vocabulary.parameters``
    (where it is declared once, beside the SymPy symbol the derivation makes of it; the same
    fields), with the unit in words, and what the rig's validation and messages need of it.

    ``rules``: the :class:`~camdyn.vocabulary.parameters.Rule` s its value must satisfy, in order;
    a rule may compare with a parameter declared before it (``e < r_c``).
    """

    @classmethod
    def declared(cls, row: RigParameter) -> Parameter:
        return cls(row.name, _UNIT_WORDS.get(row.unit, row.unit), row.description, row.required, row.ref,
                   row.rules, row.neutral, row.follower)

    @property
    def neutral_hint(self) -> str:
        """How to give a parameter that has a neutral value ('' for the others): the value
        that gives the paper's law, and where to write it."""
        if self.neutral is None:
            return ""
        return (f"{self.name} = {self.neutral!r} gives the paper's law: add the line '{self.name} = {self.neutral!r}' "
                f"to the [parameters] table of the rig file, or use rig.replace({self.name}={self.neutral!r})")

    def toml_line(self, value: float) -> str:
        """The line of a rig file that gives ``value``: name, value (``repr``: exact), meaning."""
        return f"{self.name:<8} = {value!r:<22} # {self.meaning}"

    @property
    def valid(self) -> str:
        """The valid range, e.g. ``"> 0"`` (unit guards not included)."""
        return " and ".join(r.text for r in self.rules if not r.guard) or "finite"

    @property
    def meaning(self) -> str:
        """Meaning and unit, e.g. ``"follower spring stiffness, N/m"``."""
        return f"{self.description}, {self.unit}"

    def check(self, value: Any, known: Mapping[str, float], follower: str = _OSCILLATING) -> float | None:
        """Return ``value`` as a float (``None`` if optional and not given) or raise
        :class:`ParameterError`; ``known``: the parameters validated before this one; ``follower``:
        the rig's follower type (a parameter of the other type may not be given)."""
        if value is None:
            if self.required_for(follower):
                raise ParameterError(self.name, None, "required", reason=f"{self.meaning} ({follower} follower)")
            return None
        if not self.belongs_to(follower):
            raise ParameterError(self.name, value, f"not given for a {follower} follower",
                                 reason=f"{self.meaning}: a parameter of the {self.follower} follower")
        x = math.nan
        if is_real(value):
            try:
                x = float(value)
            except OverflowError:  # an int beyond the float range
                x = math.inf
        if not math.isfinite(x):
            finite = "a finite real number" + ("" if self.valid == "finite" else f" {self.valid}")
            raise ParameterError(self.name, value, finite, reason=self.meaning)
        for rule in self.rules:
            if not rule.holds(x, known):
                reason = f"{self.meaning}; {rule.hint}" if rule.hint else self.meaning
                raise ParameterError(self.name, value, rule.text, reason=reason)
        return x


#: The rig parameters, in the paper's notation and SI units (Sec. 3, Fig. 1), as declared in
#: ``camdyn.vocabulary.parameters``; the "0-state" is the follower just touching the cam at
#: Theta = theta0, alpha = alpha0.
PARAMETERS: tuple[Parameter, ...] = tuple(Parameter.declared(row) for row in RIG_PARAMETERS)
#: The values that reduce the laws of a model edit to the paper's, by parameter (declared with
#: ``neutral=`` in ``camdyn.vocabulary.parameters``; empty for the paper's model): what a rig built
#: to reproduce the paper gives for them.
NEUTRAL: dict[str, float] = {p.name: p.neutral for p in PARAMETERS if p.neutral is not None}

_BY_NAME = {p.name: p for p in PARAMETERS}
_TEXT_FIELDS = ("name", "description", "follower")
_FIELDS = (*_BY_NAME, *_TEXT_FIELDS)


def _profile_data(profile) -> tuple | None:
    """A cam profile's family and data block (``profile.kind``, ``profile.block()``: see
    :mod:`camdyn.model.profiles`), as a hashable tuple: what rigs are compared by; None for the
    paper's circle (no profile given)."""
    if profile is None:
        return None
    kind, block = getattr(profile, "kind", None), getattr(profile, "block", None)
    if kind not in PROFILES[1:] or not callable(block):
        raise ParameterError("profile", profile, f"a cam profile of a family in {PROFILES[1:]} "
                             "(camdyn.model.profiles), or None for the paper's eccentric circle")
    data = np.ascontiguousarray(block(), dtype=float)
    if data.ndim != 1 or not np.all(np.isfinite(data)):
        raise ParameterError("profile", profile, "a profile whose block() is a finite 1-D array")
    return (kind, tuple(data.tolist()))


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


def _with_declared_fields(cls: type) -> type:
    """Make ``cls`` a frozen, keyword-only dataclass with one float field per row of
    :data:`PARAMETERS` (optional ones default to ``None``), then ``name`` and ``description``:
    the fields come from the declaration in ``camdyn.vocabulary.parameters``, not from a second list."""
    notes: dict[str, str] = {}
    for p in PARAMETERS:
        always = p.required and not p.follower  # required of every rig, whatever its follower
        notes[p.name] = "float" if always else "float | None"
        if not always:
            setattr(cls, p.name, None)
    notes.update(name="str", description="str", follower="str", origin="str", profile="object",
                 profile_data="tuple")
    cls.name, cls.description, cls.follower = "unnamed", "", _OSCILLATING
    cls.origin = dataclasses.field(default="", compare=False)  # provenance, not physics
    # the cam's shape when it is not the paper's circle; compared and hashed by its data
    cls.profile = dataclasses.field(default=None, compare=False, repr=False)
    cls.profile_data = dataclasses.field(default=None, init=False, repr=False)
    cls.__annotations__ = notes
    return dataclass(frozen=True, kw_only=True)(cls)


@_with_declared_fields
class Rig:
    """The parameters of one cam-follower rig, in the paper's notation and SI units.

    Build one with keywords (``Rig(r_c=0.05, e=0.005, ...)``), :meth:`from_dict` or
    :meth:`from_toml`. Values are validated once, here: each must be a real number (not a
    bool), finite and in range, else :class:`~camdyn.errors.ParameterError`. Ints and
    numpy scalars are stored as floats. Instances are immutable; use :meth:`replace`.
    Its fields are the rows of :data:`PARAMETERS` (declared in ``camdyn.vocabulary.parameters``),
    then ``name``, ``description`` and ``origin``: where the values came from (``"file
    /path/rig.toml"``, ``"camdyn preset 'example' (camdyn 0.1.0)"``, then ``"; changed k_s"``
    after :meth:`replace`), kept in saved runs; it takes no part in equality.
    """

    def __post_init__(self) -> None:
        if self.follower not in FOLLOWER_TYPES:
            raise ParameterError("follower", self.follower, f"one of {FOLLOWER_TYPES}",
                                 reason="the follower's type (Scene option follower)")
        known: dict[str, float] = {}
        for p in PARAMETERS:
            known[p.name] = p.check(getattr(self, p.name), known, self.follower)
            object.__setattr__(self, p.name, known[p.name])
        for field in (*_TEXT_FIELDS, "origin"):
            if not isinstance(getattr(self, field), str):
                raise ParameterError(field, getattr(self, field), "a string")
        object.__setattr__(self, "profile_data", _profile_data(self.profile))

    @property
    def Y_e(self) -> float:
        """Equivalent Young's modulus of the contact, Pa (Eq. 14):
        ``1 / ((1 - nu_c**2) / Y_c + (1 - nu_b**2) / Y_b)``."""
        return 1.0 / ((1.0 - self.nu_c**2) / self.Y_c + (1.0 - self.nu_b**2) / self.Y_b)

    @property
    def inertia(self) -> float:
        """The follower's inertia along its coordinate: I_Pb (kg m^2, Eq. 10) for the oscillating
        follower, m_f (kg) for the translating one."""
        return self.m_f if self.follower == "translating" else self.I_Pb

    def require(self, *names: str, why: str = "") -> None:
        """Raise :class:`ParameterError` if any of the named parameters is not given.

        ``why`` names the user, e.g. ``rig.require("beta_D", "zeta_D", why="damping model D")``.
        """
        _check_names(names, "Rig.require()", _BY_NAME)
        missing = [n for n in names if getattr(self, n) is None]
        if missing:
            first, *others = missing
            reason = "; ".join(x for x in (_BY_NAME[first].meaning, f"valid: {_BY_NAME[first].valid}",
                                           _BY_NAME[first].neutral_hint,
                                           f"also not given: {', '.join(others)}" if others else "") if x)
            raise ParameterError(first, None, f"required by {why}" if why else "required", reason=reason)

    def replace(self, **changes: Any) -> Rig:
        """A validated copy with some fields changed; unknown names raise
        :class:`~camdyn.errors.RigFileError` with a suggestion.  The copy's ``origin`` says
        which parameters changed (unless ``origin`` is given)."""
        _check_names(changes, "Rig.replace()", (*_FIELDS, "origin", "profile"))
        changed = sorted(k for k in changes if k in _BY_NAME)
        if "origin" not in changes and self.origin and changed:
            changes["origin"] = f"{self.origin}; changed {', '.join(changed)}"
        return dataclasses.replace(self, **changes)

    def to_dict(self) -> dict[str, Any]:
        """The parameters, ``name`` and ``description`` as a flat dict, optional ones not given
        as ``None`` (``origin`` left out: it is not a value of the rig); see :meth:`from_dict`."""
        out = {f.name: getattr(self, f.name) for f in dataclasses.fields(self)}
        for key in ("origin", "profile", "profile_data"):
            del out[key]
        return out

    @classmethod
    def from_dict(cls, d: Mapping[str, Any], *, source: str = "<dict>") -> Rig:
        """Build a rig from a flat mapping of field names to values (as :meth:`to_dict` gives).

        Unknown keys, missing required keys and invalid values raise
        :class:`~camdyn.errors.RigFileError` naming ``source`` and the key (an invalid value's
        :class:`~camdyn.errors.ParameterError` is chained as its cause).
        """
        if not isinstance(d, Mapping):
            raise RigFileError(source, f"expected a table of parameters, got {type(d).__name__}")
        _check_names(d, source, (*_FIELDS, "origin"))
        follower = d.get("follower", _OSCILLATING)
        missing = [p.name for p in PARAMETERS if p.required_for(str(follower)) and p.name not in d]
        if missing:
            raise RigFileError(source, f"missing required parameter(s): {', '.join(missing)}", key=missing[0])
        try:
            return cls(**d)
        except ParameterError as exc:
            raise RigFileError(source, str(exc), key=exc.name) from exc

    @classmethod
    def from_toml(cls, path: str | os.PathLike[str]) -> Rig:
        """Read a rig file: top-level ``name`` and ``description``, SI numbers in ``[parameters]``,
        and, for a cam that is not the paper's circle, a ``[cam]`` table (:mod:`camdyn.model.cam_files`)."""
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
        _check_names(doc, source, (*_TEXT_FIELDS, "parameters", "cam"), what="top-level key")
        params = doc.get("parameters")
        if not isinstance(params, dict):
            problem = "missing [parameters] table" if params is None else "'parameters' must be a table"
            raise RigFileError(source, problem, key="parameters")
        _check_names(params, source, _BY_NAME)
        values = {**params, **{k: doc[k] for k in _TEXT_FIELDS if k in doc}}
        rig = cls.from_dict({**values, "origin": f"file {Path(path).resolve()}"}, source=source)
        if "cam" not in doc:
            return rig
        from .cam_files import rig_with_cam
        return rig_with_cam(rig, doc["cam"], source, Path(path).parent)

    def to_toml(self, path: str | os.PathLike[str]) -> None:
        """Write the rig file read by :meth:`from_toml` (floats written with ``repr``, so the
        round trip is exact); parameters not given are left out; a cam profile as its data
        (``[cam]`` with ``kind`` and ``block``)."""
        lines = [
            "# camdyn rig file: SI units (see camdyn.model.rig.PARAMETERS)",
            f"name = {_toml_string(self.name)}",
            f"description = {_toml_string(self.description)}",
        ]
        if self.follower != _OSCILLATING:
            lines.append(f"follower = {_toml_string(self.follower)}")
        lines += [
            "",
            "[parameters]",
        ]
        for p in PARAMETERS:
            value = getattr(self, p.name)
            if value is not None:
                lines.append(p.toml_line(value))
        if self.profile is not None:
            from .cam_files import cam_lines
            lines += cam_lines(self.profile)
        Path(path).write_text("\n".join(lines) + "\n", encoding="utf-8")


def _parameter_docs() -> str:
    """The numpydoc "Parameters" section of :class:`Rig`, generated from :data:`PARAMETERS`."""
    out = ["", "    Parameters", "    ----------"]
    for p in PARAMETERS:
        need = ("required" if not p.follower else f"required for a {p.follower} follower") if p.required \
            else "optional (None: not given)"
        out.append(f"    {p.name} : float, {p.unit}, {need}")
        text = f"{p.description[0].upper()}{p.description[1:]} ({p.ref}). Valid: {p.valid}."
        if p.neutral is not None:
            text += f" {p.name} = {p.neutral!r} gives the paper's law."
        for rule in p.rules:
            if rule.guard:
                text += f" Rejected unless {rule.text} ({rule.hint})."
        out.append(f"        {text}")
    out += ["    name : str", "        Short name of the rig.", "    description : str", "        Free text.",
            "    follower : str", f"        The follower's type, one of {FOLLOWER_TYPES} (default: the paper's "
            "oscillating follower); the Scene's option follower must be the same."]
    return "\n".join(out) + "\n"


if Rig.__doc__:  # None under python -OO
    Rig.__doc__ += _parameter_docs()
