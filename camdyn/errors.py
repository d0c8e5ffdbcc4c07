"""Exceptions raised by camdyn.

Every exception camdyn raises on purpose derives from :class:`CamdynError`. The concrete
ones are also :class:`ValueError`, so ``except ValueError`` keeps working for callers that
do not know camdyn. All of them can be pickled (for process pools).
"""

from __future__ import annotations

import difflib
import functools
import re
from numbers import Real
from typing import Any

__all__ = [
    "CamdynError",
    "ParameterError",
    "RigFileError",
    "GeometryError",
    "EquilibriumError",
    "SceneError",
]


class CamdynError(Exception):
    """Base class of all camdyn errors (a plain mixin base; catch this to catch them all)."""


class ParameterError(CamdynError, ValueError):
    """A model parameter is not given, not a real number, or outside its valid range.

    Parameters
    ----------
    name : str
        The parameter's name in the paper's notation, e.g. ``"k_s"``.
    value : object
        The offending value; ``None`` when the parameter was not given.
    valid : str
        What the value must be, e.g. ``"> 0"``, or why it is needed, e.g.
        ``"required by damping model D"`` when ``value`` is ``None``.
    reason : str, optional
        Appended in parentheses: the parameter's meaning and unit, and the likely mistake.
    problem : str, optional
        What is wrong with the value, in words, when that says more than the value itself
        (a series: ``"has NaN at index 0"``): the message is ``"<name> <problem>: must be <valid>"``.

    Example messages:

    - a value out of range:
      ``k_s = -5.0 is out of range: must be > 0 (follower spring stiffness, N/m)``;
    - a string where a number is asked for:
      ``k_s = '2000' is not a real number (str): must be > 0``;
    - a string that is not one of the names ``valid`` lists:
      ``method = 'RK54' is not valid (did you mean 'RK45'?): must be one of ('RK45', 'DOP853')``.
    """

    def __init__(self, name: str, value: Any, valid: str, *, reason: str | None = None, problem: str | None = None):
        self.name, self.value, self.valid, self.reason, self.problem = name, value, valid, reason, problem
        if problem:
            message = f"{name} {problem}: must be {valid}"
        elif value is None:
            message = f"{name} is not given: {valid}"
        elif isinstance(value, Real) and not isinstance(value, bool):
            message = f"{name} = {value} is out of range: must be {valid}"
        elif isinstance(value, str) and not _NUMERIC.search(valid):
            # a name chosen from a list (a method, a backend, a preset): not a number problem
            message = f"{name} = {value!r} is not valid{_did_you_mean(value, valid)}: must be {valid}"
        elif isinstance(value, (str, bool)) or _NUMERIC.search(valid):
            kind = type(value).__name__
            message = f"{name} = {value!r} is not a real number ({kind}): must be {valid}"
        else:
            message = f"{name} = {value!r} is not valid: must be {valid}"
        if reason:
            message += f" ({reason})"
        super().__init__(message)

    def __reduce__(self):
        rebuild = functools.partial(type(self), reason=self.reason, problem=self.problem)
        return rebuild, (self.name, self.value, self.valid)


#: words of a ``valid`` text that asks for a number (a string value is then "not a real number")
_NUMERIC = re.compile(r"number|finite|integer|[<>]|^\s*[-+0-9]")


def _did_you_mean(value: str, valid: str) -> str:
    """`` (did you mean 'X'?)`` for the closest of the quoted names in ``valid``, else ''."""
    names = re.findall(r"'([^']+)'", valid)
    close = difflib.get_close_matches(value, names, n=1) or [n for n in names if n.lower() == value.lower()]
    return f" (did you mean {close[0]!r}?)" if close else ""


class RigFileError(CamdynError, ValueError):
    """A rig description cannot be used: a TOML file that is unreadable or not valid TOML,
    or a file, dict or keyword set with unknown, missing or wrongly typed keys.

    ``source`` names the file (or ``"<dict>"``, ``"Rig.replace()"``...), ``key`` the
    offending key when there is one. The message is ``"<source>: <problem>"``.
    """

    def __init__(self, source: str, problem: str, *, key: str | None = None):
        self.source, self.problem, self.key = str(source), problem, key
        super().__init__(f"{source}: {problem}")

    def __reduce__(self):
        return functools.partial(type(self), key=self.key), (self.source, self.problem)


class GeometryError(CamdynError, ValueError):
    """The rig's geometry is impossible, e.g. the follower cannot touch the cam (Sec. 3.1)."""


class EquilibriumError(CamdynError, ValueError):
    """No static equilibrium of the follower exists or it cannot be found (Sec. 3.3)."""


class SceneError(CamdynError, ValueError):
    """A scene (simulation set-up) option is invalid or inconsistent with the rig."""


class CompileNotice(UserWarning):
    """Issued once when camdyn is about to make code on first use: compile its integration
    loop (a first run on this machine, or after an upgrade), or derive a scene that is not
    in the catalog (:mod:`camdyn.model.ondemand`): the run takes seconds longer, once.  Silence it with
    ``warnings.filterwarnings("ignore", category=camdyn.CompileNotice)``."""
