"""What one run is asked for, checked once: a :class:`RunRequest`.

A run of :func:`camdyn.simulate` is a rig, a scene and a cam motion, and a request: how long it
lasts and where it is sampled (a :class:`Span`), how it is integrated (a
:class:`~camdyn.engine.SolverOptions`), where it starts (``y0``), who runs the loop
(``backend``) and whether it stops once periodic (``stop``).  :func:`run_request` builds one from
simulate's keywords; a sweep builds its points' request with the same function, once
(:mod:`camdyn.sweep.check`).  The loose keywords ``t_end``, ``revolutions``, ``sample_rate_Hz``,
``t_start`` and ``method``, ``rtol``, ``atol``, ``max_step``, ``events``, ``energy_ledger``,
``step_control`` are the fields of the two objects (:data:`SPAN_KEYWORDS`,
:data:`SOLVER_KEYWORDS`), mapped here once; :func:`loose_keywords` spells the objects out in them
again, for the settings a saved run or a sweep records.

The checks that need the rig and the cam (a cam period for ``revolutions``, the run-length
limits) are :meth:`Span.duration` and :meth:`Span.samples`.
"""
from __future__ import annotations

import difflib
import math
from dataclasses import dataclass, field, fields
from typing import Mapping

import numpy as np

from .._checks import finite, real
from ..engine import BACKENDS, STEP_CONTROL, EventSettings, SolverOptions
from ..errors import ParameterError
from .stopping import StopWhenPeriodic

__all__ = ["Span", "RunRequest", "run_request", "loose_keywords", "SPAN_KEYWORDS", "SOLVER_KEYWORDS",
           "DEFAULT_BACKEND", "MAX_SAMPLES", "MAX_CONTACT_PERIODS"]

#: who runs a run's loop when not told: the compiled loop (camdyn.engine)
DEFAULT_BACKEND = "compiled"
#: samples one run may hold at the most (8 bytes each per quantity: beyond it, refused)
MAX_SAMPLES = 50_000_000
#: contact-mode periods one run may span: ~20 steps each, so about 2e9 steps at the most
#: (hours of SciPy stepping); beyond it the run is refused instead of hanging
MAX_CONTACT_PERIODS = 1e8


def _positive(name: str, value, valid: str) -> float:
    return real(name, value, valid, lambda v: 0 < v < math.inf)


@dataclass(frozen=True)
class Span:
    """How long a run lasts and where it is sampled: ``t_end`` seconds or ``revolutions`` cam
    periods (exactly one), from ``t_start`` (s), sampled at ``sample_rate_Hz`` (both ends included
    when they fall on a sample).  The numbers are stored as floats."""

    t_end: float | None = None
    revolutions: float | None = None
    sample_rate_Hz: float = 20_000.0
    t_start: float = 0.0

    def __post_init__(self) -> None:
        if (self.t_end is None) == (self.revolutions is None):
            raise ParameterError("t_end", self.t_end, "exactly one of t_end (s) or revolutions")
        if self.revolutions is not None:
            object.__setattr__(self, "revolutions", _positive("revolutions", self.revolutions, "revolutions > 0"))
        else:
            object.__setattr__(self, "t_end", _positive("t_end", self.t_end, "t_end > 0 (s)"))
        object.__setattr__(self, "t_start", finite("t_start", self.t_start, "a finite time (s)"))
        object.__setattr__(self, "sample_rate_Hz", _positive("sample_rate_Hz", self.sample_rate_Hz,
                                                             "sample_rate_Hz > 0"))

    def duration(self, cam, vartheta: float) -> float:
        """The run's length (s) with this cam motion; refused for ``revolutions`` of a cam without
        a period, and beyond MAX_CONTACT_PERIODS periods of the contact mode (angular frequency
        ``vartheta``, Eq. 23)."""
        if self.revolutions is not None and not math.isfinite(cam.period):
            raise ParameterError("revolutions", self.revolutions, "t_end (s): this cam has no period")
        duration = self.t_end if self.revolutions is None else self.revolutions * cam.period
        periods = duration * vartheta / (2 * math.pi)
        if periods > MAX_CONTACT_PERIODS:
            raise ParameterError(
                "t_end", duration, f"at most {MAX_CONTACT_PERIODS:.0e} periods of the contact mode "
                f"({vartheta / (2 * math.pi):.3g} Hz for this rig: check I_Pb, k_s, Y_c, Y_b, l_lambda); "
                f"this run spans {periods:.3g}")
        return duration

    def samples(self, duration: float) -> int:
        """Samples of a run of ``duration`` s; refused beyond MAX_SAMPLES."""
        fs = self.sample_rate_Hz
        n = int(math.floor(duration * fs + 1e-9)) + 1
        if n > MAX_SAMPLES:
            raise ParameterError("sample_rate_Hz", fs, f"at most {MAX_SAMPLES} samples over the run "
                                 f"(t_end * sample_rate_Hz = {duration * fs:.3g})")
        return n

    def times(self, duration: float) -> np.ndarray:
        """The sample times of a run of ``duration`` s."""
        return self.t_start + np.arange(self.samples(duration)) / self.sample_rate_Hz


@dataclass(frozen=True)
class RunRequest:
    """Everything of one run besides the rig, the scene and the cam motion, checked once:
    ``span`` (a :class:`Span`), ``options`` (a :class:`~camdyn.engine.SolverOptions`), ``y0``
    (None: the static equilibrium; else (alpha rad, alpha_dot rad/s), stored as a tuple of
    floats), ``backend`` (``"compiled"`` or ``"python"``) and ``stop`` (None or a
    :class:`camdyn.StopWhenPeriodic`)."""

    span: Span
    options: SolverOptions = field(default_factory=SolverOptions)
    y0: tuple[float, float] | None = None
    backend: str = DEFAULT_BACKEND
    stop: StopWhenPeriodic | None = None

    def __post_init__(self) -> None:
        if self.backend not in BACKENDS:
            raise ParameterError("backend", self.backend, f"one of {BACKENDS}")
        if not isinstance(self.span, Span):
            raise ParameterError("span", self.span, "a camdyn.runs.Span")
        if not isinstance(self.options, SolverOptions):
            raise ParameterError("options", self.options, "a camdyn.engine.SolverOptions")
        if self.y0 is not None:
            try:
                y = np.asarray(self.y0, dtype=float)
            except (TypeError, ValueError):  # a string, a ragged list...
                y = np.full(1, np.nan)
            if y.shape != (2,) or not np.all(np.isfinite(y)):
                raise ParameterError("y0", self.y0, "two finite numbers (alpha rad, alpha_dot rad/s)")
            object.__setattr__(self, "y0", (float(y[0]), float(y[1])))
        if self.stop is not None and not isinstance(self.stop, StopWhenPeriodic):
            raise ParameterError("stop", self.stop, "None or a camdyn.StopWhenPeriodic")


#: simulate's loose keywords for the fields of a Span (the same names)
SPAN_KEYWORDS = tuple(f.name for f in fields(Span))
#: simulate's loose keywords for the fields of a SolverOptions: keyword -> field
SOLVER_KEYWORDS = {"method": "method", "rtol": "rtol", "atol": "atol", "max_step": "max_step", "events": "events",
                   "energy_ledger": "ledger", "step_control": "step_control"}
#: the keywords run_request takes besides the loose ones
_WHOLE = ("span", "options", "y0", "backend", "stop")


def run_request(*, span: Span | None = None, options: SolverOptions | None = None, y0=None,
                backend: str = DEFAULT_BACKEND, stop: StopWhenPeriodic | None = None, **loose) -> RunRequest:
    """The RunRequest of simulate's keywords.  ``span`` and ``options`` are taken whole, or built
    once from the loose keywords of their fields (``revolutions=3, rtol=1e-10``); a loose keyword
    of an object given whole, or a keyword that is neither, is a :class:`ParameterError`."""
    for name, value in loose.items():
        if name not in SPAN_KEYWORDS and name not in SOLVER_KEYWORDS:
            raise _unknown(name, value)
    if span is None:
        span = Span(**{k: v for k, v in loose.items() if k in SPAN_KEYWORDS})
    else:
        _refuse_loose(loose, SPAN_KEYWORDS, "span", "Span")
    if options is None:
        options = SolverOptions(**{SOLVER_KEYWORDS[k]: _solver_value(k, v) for k, v in loose.items()
                                   if k in SOLVER_KEYWORDS and not (k == "events" and v is None)})
    else:
        _refuse_loose(loose, SOLVER_KEYWORDS, "options", "SolverOptions")
    return RunRequest(span, options, y0, backend, stop)


def _solver_value(keyword: str, value):
    return bool(value) if keyword == "energy_ledger" else value


def _refuse_loose(loose: Mapping, keywords, whole: str, kind: str) -> None:
    given = [k for k in loose if k in keywords]
    if given:
        raise ParameterError(given[0], loose[given[0]], f"set in the {kind} or given as a keyword, not both",
                             problem=f"= {loose[given[0]]!r} is given beside {whole}=")


def _unknown(name: str, value) -> ParameterError:
    valid = (*_WHOLE, *SPAN_KEYWORDS, *SOLVER_KEYWORDS)
    close = difflib.get_close_matches(name, valid, n=1)
    problem = "is not a keyword of camdyn.simulate" + (f" (did you mean {close[0]!r}?)" if close else "")
    return ParameterError(name, value, f"one of {', '.join(valid)}", problem=problem)


def loose_keywords(keywords: Mapping) -> dict:
    """simulate's keywords with ``span=`` and ``options=`` spelled out as the loose keywords that
    build them again, as a saved run or a sweep records its settings: of a Span its length and
    sample rate (and t_start when not 0), of a SolverOptions its method and tolerances (and the
    other fields where they are not the defaults)."""
    out = {k: v for k, v in keywords.items() if k not in ("span", "options")}
    span, options = keywords.get("span"), keywords.get("options")
    if span is not None:
        out["sample_rate_Hz"] = span.sample_rate_Hz
    if options is not None:
        out.update(method=options.method, rtol=options.rtol, atol=options.atol)
        defaults = {"max_step": math.inf, "events": EventSettings(), "energy_ledger": False,
                    "step_control": STEP_CONTROL}
        for keyword, default in defaults.items():
            value = getattr(options, SOLVER_KEYWORDS[keyword])
            if value != default:
                out[keyword] = value.name if keyword == "step_control" else value
    if span is not None:
        out.update({"t_end": span.t_end} if span.revolutions is None else {"revolutions": span.revolutions})
        if span.t_start:
            out["t_start"] = span.t_start
    return out
