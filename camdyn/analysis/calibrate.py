"""Calibration: fit unknown rig parameters to quantities camdyn computes.

The paper identified its damping constants by matching model output to measurements
(Section 4); the same is needed for any rig whose geometry or inertia is not known.
:func:`calibrate` fits chosen *unknowns* of a :class:`~camdyn.Rig` (with bounds, on a
log or linear scale) to *targets*: measured or reported values of quantities that camdyn
computes from a rig, by weighted non-linear least squares
(:func:`scipy.optimize.least_squares`, trust-region reflective, bounded).

Targets are built with the helpers below or from any callable of the rig::

    import camdyn
    from camdyn import calibrate as cal

    rig = camdyn.load_rig("example")
    result = cal.calibrate(
        rig,
        unknowns=[cal.Unknown("I_Pb", 1e-4, 1.0), cal.Unknown("w_b", 1e-3, 0.05)],
        targets=[
            cal.natural_frequency(2182.0, camdyn.Scene(), camdyn.ConstantSpeed(300), digits=4),
            cal.natural_frequency(2125.0, camdyn.Scene(), camdyn.ConstantSpeed(-300), digits=4),
        ],
        fixed={"chi0": "measured on the drawing"},
    )
    print(result.report())          # fitted values, residual per target, degrees of freedom
    fitted = result.rig

Each target has an uncertainty ``sigma`` (absolute, in the target's unit; by default the
value itself, i.e. a relative residual; ``digits=n`` makes it half a unit of the n-th
significant digit, the rounding of a printed number). The least-squares residual of a
target is ``(computed - value) / sigma``.

A target can be measured on a *variant* of the rig (another spring, another contact
length): ``settings={"k_s": 26.0, "l_lambda": 0.016}`` replaces those parameters before
computing it. A setting given as a string names an *extra unknown*, a parameter of the
variant only (e.g. the experiment's spring ``"k_s_exp"``), fitted with the others:
``Unknown("k_s_exp", 1, 2000)`` with ``settings={"k_s": "k_s_exp"}``.

``tied={"e": lambda p: 0.1 * p["r_c"]}`` keeps a parameter a fixed function of the
others (``p`` maps every rig parameter and extra unknown to its current value).

The result states the degrees of freedom: how many targets, how many unknowns, the
numerical rank of the weighted Jacobian at the solution (how many independent
combinations the targets actually pin down), and which parameters were fixed by
assumption and why (``fixed``). More unknowns than targets is an error unless
``allow_underdetermined=True``: fix the rest by assumption and say why.
"""
from __future__ import annotations

import difflib
import math
from dataclasses import dataclass, field
from typing import Any, Callable, Mapping, Sequence

import numpy as np
from scipy.optimize import least_squares

from . import statics as analysis
from ..model.cam import CamMotion
from ..errors import CamdynError
from ..model.rig import PARAMETERS, Rig
from ..model.scene import Scene

__all__ = [
    "CalibrationError",
    "Unknown",
    "Target",
    "TargetResidual",
    "DegreesOfFreedom",
    "Calibration",
    "calibrate",
    "evaluate",
    "rounding_sigma",
    "contact_stiffness",
    "natural_frequency",
    "contact_loss_speed",
    "equilibrium_angle",
    "energy_balance_saturation",
    "energy_balance_peak",
]

_RIG_PARAMS = tuple(p.name for p in PARAMETERS)
_BY_NAME = {p.name: p for p in PARAMETERS}


class CalibrationError(CamdynError, ValueError):
    """A calibration problem is ill-posed (bad unknowns, targets, bounds) or cannot be evaluated."""


def _suggest(name: str, known: Sequence[str]) -> str:
    close = difflib.get_close_matches(str(name), list(known), n=1)
    return f" (did you mean {close[0]!r}?)" if close else ""


def rounding_sigma(value: float, digits: int) -> float:
    """Half a unit of the ``digits``-th significant digit of ``value``: the uncertainty
    of a number printed to that many significant digits (2182 with 4 -> 0.5)."""
    if not (isinstance(digits, int) and not isinstance(digits, bool) and digits >= 1):
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
            if isinstance(v, bool) or not isinstance(v, (int, float, np.floating, np.integer)) or math.isnan(v):
                raise CalibrationError(f"unknown {self.name!r}: {what} = {v!r} must be a number")
        if not self.lower < self.upper:
            raise CalibrationError(f"unknown {self.name!r}: lower = {self.lower!r} must be < upper = {self.upper!r}")
        if self.scale not in ("auto", "log", "linear"):
            raise CalibrationError(f"unknown {self.name!r}: scale = {self.scale!r} must be 'auto', 'log' or 'linear'")
        if self.scale == "log" and not self.lower > 0:
            raise CalibrationError(f"unknown {self.name!r}: a log scale needs lower > 0, got lower = {self.lower!r}")
        if self.initial is not None and not (
                isinstance(self.initial, (int, float, np.floating, np.integer)) and math.isfinite(self.initial)):
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
        if isinstance(self.value, bool) or not isinstance(self.value, (int, float, np.floating, np.integer)) \
                or not math.isfinite(self.value):
            raise CalibrationError(f"target {self.name!r}: value = {self.value!r} must be a finite number")
        if not callable(self.compute):
            raise CalibrationError(f"target {self.name!r}: compute must be a callable of the rig")
        if self.sigma is not None and self.digits is not None:
            raise CalibrationError(f"target {self.name!r}: give sigma or digits, not both")
        if self.sigma is not None and not (
                isinstance(self.sigma, (int, float, np.floating, np.integer)) and math.isfinite(self.sigma)
                and self.sigma > 0):
            raise CalibrationError(f"target {self.name!r}: sigma = {self.sigma!r} must be a finite number > 0")
        if self.digits is not None:
            rounding_sigma(self.value, self.digits)  # validates
        if self.sigma is None and self.digits is None and self.value == 0:
            raise CalibrationError(f"target {self.name!r}: a zero value needs an absolute sigma")
        for key, v in dict(self.settings).items():
            if key not in _BY_NAME:
                raise CalibrationError(f"target {self.name!r}: setting {key!r} is not a rig parameter"
                                       + _suggest(key, _RIG_PARAMS))
            if not isinstance(v, str) and (isinstance(v, bool) or not isinstance(v, (int, float, np.floating, np.integer))):
                raise CalibrationError(f"target {self.name!r}: setting {key} = {v!r} must be a number or the "
                                       "name of an extra unknown")

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
                                           + _suggest(v, list(extras)))
                changes[key] = extras[v]
            else:
                changes[key] = float(v)
        return rig.replace(**changes)


def _kw(name, default, kw):
    kw.setdefault("name", name or default)
    return kw


def contact_stiffness(value: float, contact: str = "line", *, name: str | None = None, **kw) -> Target:
    """Contact stiffness k_lambda(psi_i*) at the static equilibrium, N/m (Eq. 13 or 34; the
    secant stiffness, as the paper quotes it: misprint 5)."""
    kw = _kw(name, f"k_{contact}", kw)
    kw.setdefault("unit", "N/m")
    return Target(value=value, compute=lambda rig: analysis.static_equilibrium(rig, contact).contact_stiffness, **kw)


def natural_frequency(value_Hz: float, scene: Scene | None = None, cam: CamMotion | None = None, *,
                      name: str | None = None, **kw) -> Target:
    """Linearized natural frequency in Hz at the static equilibrium (Eqs. 21-23) for a scene;
    the cam's rotation sense sets the friction direction (Section 7.1)."""
    scene = scene or Scene(damping="none", friction="none")
    kw = _kw(name, f"f_{scene.slug}", kw)
    kw.setdefault("unit", "Hz")
    return Target(value=value_Hz, compute=lambda rig: analysis.natural_frequency(rig, scene, cam).Hz, **kw)


def contact_loss_speed(value_rpm: float, *, name: str | None = None, **kw) -> Target:
    """Cam speed (rev/min) above which the follower leaves the cam, by inverse kinematics
    (Section 4; :func:`camdyn.analysis.statics.contact_loss_speed`)."""
    kw = _kw(name, "contact_loss", kw)
    kw.setdefault("unit", "rev/min")
    return Target(value=value_rpm, compute=lambda rig: analysis.contact_loss_speed(rig), **kw)


def equilibrium_angle(value_rad: float, contact: str = "line", *, name: str | None = None, **kw) -> Target:
    """The static equilibrium angle alpha* in rad (Eqs. 16-18)."""
    kw = _kw(name, "alpha_star", kw)
    kw.setdefault("unit", "rad")
    return Target(value=value_rad, compute=lambda rig: analysis.static_equilibrium(rig, contact).alpha, **kw)


def energy_balance_saturation(value_rad: float, contact: str = "line", *, name: str | None = None, **kw) -> Target:
    """The value at which the energy-balance alpha_rp saturates as the speed grows
    (Section 5, Fig. 8): pi/2 - alpha*, the follower swung to 90 degrees."""
    kw = _kw(name, "alpha_rp_saturation", kw)
    kw.setdefault("unit", "rad")
    return Target(value=value_rad,
                  compute=lambda rig: math.pi / 2 - analysis.static_equilibrium(rig, contact).alpha, **kw)


def energy_balance_peak(value_rad: float, speed_rpm: float, xi: float, *, potential: str = "printed",
                        name: str | None = None, **kw) -> Target:
    """alpha_rp from the approximate energy balance at one speed and restitution xi (Eqs. 30-33)."""
    kw = _kw(name, f"alpha_rp_energy_{speed_rpm:g}rpm_xi{xi:g}", kw)
    kw.setdefault("unit", "rad")
    return Target(value=value_rad,
                  compute=lambda rig: analysis.energy_balance_peak(rig, speed_rpm, xi, potential=potential), **kw)


# ----------------------------------------------------------------------------- results


@dataclass(frozen=True)
class TargetResidual:
    """One target after the fit: computed value, difference, residual in sigmas."""

    name: str
    value: float
    computed: float
    sigma: float
    unit: str
    source: str

    @property
    def difference(self) -> float:
        return self.computed - self.value

    @property
    def relative(self) -> float:
        return self.difference / self.value if self.value else math.nan

    @property
    def normalized(self) -> float:
        """Residual in units of sigma (within the stated uncertainty when its abs() <= 1)."""
        return self.difference / self.sigma

    @property
    def within(self) -> bool:
        return abs(self.normalized) <= 1.0 + 1e-9


@dataclass(frozen=True)
class DegreesOfFreedom:
    """What the targets determine.

    ``rank`` is the numerical rank of the weighted Jacobian d(residual)/d(unknown) at the
    solution: the number of independent combinations of the unknowns the targets pin
    down.  ``unknowns - rank`` combinations are left free by the targets (the fit then
    depends on the initial values: fix more by assumption); ``targets - rank`` targets
    are redundant (consistency checks).  ``fixed`` names the parameters fixed by
    assumption, with the reason; ``tied`` those computed from others.
    """

    targets: int
    unknowns: int
    rank: int
    singular_values: tuple[float, ...]
    fixed: Mapping[str, str]
    tied: tuple[str, ...]
    at_bounds: tuple[str, ...]

    @property
    def free(self) -> int:
        return self.unknowns - self.rank

    @property
    def redundant(self) -> int:
        return self.targets - self.rank

    def statement(self) -> str:
        s = (f"{self.targets} target(s), {self.unknowns} unknown(s); the targets determine {self.rank} "
             f"independent combination(s) of the unknowns")
        if self.free:
            s += f", leaving {self.free} combination(s) undetermined (the fit depends on the initial values)"
        if self.redundant:
            s += f"; {self.redundant} target(s) are redundant and act as consistency checks"
        s += "."
        if self.fixed:
            s += f" {len(self.fixed)} parameter(s) fixed by assumption: " + "; ".join(
                f"{k} ({v})" for k, v in self.fixed.items()) + "."
        if self.tied:
            s += f" Tied to others: {', '.join(self.tied)}."
        if self.at_bounds:
            s += f" At a bound (the bound, not the targets, sets it): {', '.join(self.at_bounds)}."
        return s


@dataclass(frozen=True)
class Calibration:
    """The outcome of :func:`calibrate`."""

    rig: Rig                                  # the fitted rig (base settings)
    values: Mapping[str, float]               # fitted value of every unknown (extras included)
    extras: Mapping[str, float]               # fitted extra unknowns (not rig parameters)
    residuals: tuple[TargetResidual, ...]
    dof: DegreesOfFreedom
    unknowns: tuple[Unknown, ...]
    targets: tuple[Target, ...]
    initial: Mapping[str, float]
    sensitivity: np.ndarray                   # d log(computed) / d log(unknown), targets x unknowns
    success: bool
    message: str
    cost: float
    nfev: int

    def residual(self, name: str) -> TargetResidual:
        for r in self.residuals:
            if r.name == name:
                return r
        raise KeyError(f"no target {name!r}; targets: {[r.name for r in self.residuals]}")

    def variant(self, target_or_settings: str | Mapping[str, Any]) -> Rig:
        """The fitted rig with a target's settings (or the given settings) applied."""
        if isinstance(target_or_settings, str):
            for t in self.targets:
                if t.name == target_or_settings:
                    return t.variant(self.rig, self.extras)
            raise KeyError(f"no target {target_or_settings!r}")
        return Target("settings", 1.0, lambda r: 1.0, settings=dict(target_or_settings)).variant(
            self.rig, self.extras)

    @property
    def all_within(self) -> bool:
        return all(r.within for r in self.residuals)

    def report(self) -> str:
        """A plain-text/Markdown report: unknowns, residual per target, degrees of freedom."""
        lines = ["| unknown | initial | fitted | bounds | scale |", "|---|---|---|---|---|"]
        for u in self.unknowns:
            lines.append(f"| {u.name} | {self.initial[u.name]:.6g} | {self.values[u.name]:.6g} | "
                         f"[{u.lower:.4g}, {u.upper:.4g}] | {'log' if u.log else 'linear'} |")
        lines += ["", "| target | value | computed | relative difference | residual / sigma |",
                  "|---|---|---|---|---|"]
        for r in self.residuals:
            lines.append(f"| {r.name} | {r.value:.6g} {r.unit} | {r.computed:.6g} {r.unit} | "
                         f"{r.relative:+.2e} | {r.normalized:+.3f} |")
        lines += ["", self.dof.statement(), "", f"least squares: {self.message} (cost {self.cost:.3g}, "
                                                  f"{self.nfev} evaluations)"]
        return "\n".join(lines)


# ----------------------------------------------------------------------------- the fit


def _validate(rig, unknowns, targets, fixed, tied, allow_underdetermined):
    if not isinstance(rig, Rig):
        raise CalibrationError(f"rig must be a camdyn.Rig, got {type(rig).__name__}")
    unknowns = tuple(unknowns)
    targets = tuple(targets)
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
    names = [u.name for u in unknowns]
    dup = sorted({n for n in names if names.count(n) > 1})
    if dup:
        raise CalibrationError(f"unknown(s) listed twice: {', '.join(dup)}")
    tnames = [t.name for t in targets]
    dup = sorted({n for n in tnames if tnames.count(n) > 1})
    if dup:
        raise CalibrationError(f"target name(s) used twice: {', '.join(dup)} (give each a distinct name=)")
    referenced = {v for t in targets for v in t.settings.values() if isinstance(v, str)}
    extras = [n for n in names if n not in _BY_NAME]
    for n in extras:
        if n not in referenced:
            raise CalibrationError(
                f"unknown {n!r} is not a rig parameter{_suggest(n, _RIG_PARAMS)} and no target's settings "
                "refer to it (an extra unknown is a parameter of a rig variant, e.g. settings={'k_s': "
                + repr(n) + "})")
    missing = sorted(referenced - set(names))
    if missing:
        raise CalibrationError(f"target settings refer to {', '.join(map(repr, missing))}, which "
                               f"{'is' if len(missing) == 1 else 'are'} not among the unknowns"
                               + _suggest(missing[0], names))
    clash = [n for n in extras if n in _BY_NAME]
    if clash:  # pragma: no cover - extras are by definition not rig names
        raise CalibrationError(f"extra unknown names clash with rig parameters: {clash}")
    fixed = dict(fixed or {})
    for k, why in fixed.items():
        if k not in _BY_NAME:
            raise CalibrationError(f"fixed parameter {k!r} is not a rig parameter" + _suggest(k, _RIG_PARAMS))
        if k in names:
            raise CalibrationError(f"{k!r} is both an unknown and fixed by assumption: choose one")
        if not isinstance(why, str) or not why.strip():
            raise CalibrationError(f"fixed parameter {k!r}: give the assumption as a non-empty string (why "
                                   "its value is plausible)")
        if getattr(rig, k) is None:
            raise CalibrationError(f"fixed parameter {k!r} has no value in the rig: set it first")
    tied = dict(tied or {})
    for k, fn in tied.items():
        if k not in _BY_NAME:
            raise CalibrationError(f"tied parameter {k!r} is not a rig parameter" + _suggest(k, _RIG_PARAMS))
        if k in names:
            raise CalibrationError(f"{k!r} is both an unknown and tied to others: choose one")
        if k in fixed:
            raise CalibrationError(f"{k!r} is both fixed and tied: choose one")
        if not callable(fn):
            raise CalibrationError(f"tied parameter {k!r}: give a callable of the parameter values")
    initial = {}
    for u in unknowns:
        x0 = u.initial
        if x0 is None and u.name in _BY_NAME:
            x0 = getattr(rig, u.name)
        if x0 is None:
            raise CalibrationError(f"unknown {u.name!r} has no initial value: the rig does not give it, so pass "
                                   f"Unknown({u.name!r}, ..., initial=...)")
        if not u.lower <= x0 <= u.upper:
            raise CalibrationError(f"unknown {u.name!r}: initial value {x0:g} is outside its bounds "
                                   f"[{u.lower:g}, {u.upper:g}]")
        if u.log and x0 <= 0:
            raise CalibrationError(f"unknown {u.name!r}: initial value {x0:g} must be > 0 on a log scale")
        initial[u.name] = float(x0)
    if len(unknowns) > len(targets) and not allow_underdetermined:
        raise CalibrationError(
            f"{len(unknowns)} unknowns ({', '.join(names)}) but only {len(targets)} target(s): the fit "
            f"cannot determine them. Fix {len(unknowns) - len(targets)} of them by assumption (leave them "
            "out of the unknowns and name them in fixed= with the reason), add targets, or pass "
            "allow_underdetermined=True")
    return unknowns, targets, fixed, tied, initial


def _apply(rig: Rig, unknowns, values: Mapping[str, float], tied) -> tuple[Rig, dict]:
    rig_changes = {u.name: values[u.name] for u in unknowns if u.name in _BY_NAME}
    extras = {u.name: values[u.name] for u in unknowns if u.name not in _BY_NAME}
    if tied:
        current = {**{k: v for k, v in rig.to_dict().items() if k in _BY_NAME}, **rig_changes, **extras}
        for k, fn in tied.items():
            rig_changes[k] = float(fn(current))
            current[k] = rig_changes[k]
    return rig.replace(**rig_changes), extras


def evaluate(rig: Rig, targets: Sequence[Target], extras: Mapping[str, float] | None = None
             ) -> tuple[TargetResidual, ...]:
    """Compute every target on ``rig`` (with its settings), without fitting."""
    out = []
    for t in targets:
        try:
            computed = float(t.compute(t.variant(rig, extras)))
        except CalibrationError:
            raise
        except (CamdynError, ValueError, ArithmeticError) as exc:
            raise CalibrationError(f"target {t.name!r} cannot be computed on this rig: {exc}") from exc
        out.append(TargetResidual(t.name, float(t.value), computed, t.uncertainty, t.unit, t.source))
    return tuple(out)


def calibrate(rig: Rig, unknowns: Sequence[Unknown], targets: Sequence[Target], *,
              fixed: Mapping[str, str] | None = None,
              tied: Mapping[str, Callable[[Mapping[str, float]], float]] | None = None,
              allow_underdetermined: bool = False, rank_rtol: float = 1e-6,
              name: str | None = None, description: str | None = None,
              **least_squares_options) -> Calibration:
    """Fit ``unknowns`` of ``rig`` so that the ``targets`` computed from it match their values.

    Parameters
    ----------
    rig : Rig
        The starting rig: every parameter not fitted keeps its value here.
    unknowns : sequence of Unknown
        The parameters to fit, with bounds and scale.
    targets : sequence of Target
        The quantities to match (see :func:`contact_stiffness`, :func:`natural_frequency`,
        :func:`contact_loss_speed`, :func:`energy_balance_saturation`, or ``Target`` with
        any callable of the rig).
    fixed : mapping, optional
        Parameters fixed by assumption, each with the reason its value is plausible; they
        are recorded in the degrees-of-freedom statement.
    tied : mapping, optional
        Parameters computed from the others, e.g. ``{"e": lambda p: 0.1 * p["r_c"]}``.
    allow_underdetermined : bool
        Allow more unknowns than targets (the result then depends on the initial values).
    rank_rtol : float
        Singular values of the weighted Jacobian below ``rank_rtol`` times the largest
        count as zero in the rank.
    name, description : str, optional
        Name and description of the fitted rig.
    **least_squares_options
        Passed to :func:`scipy.optimize.least_squares` (``xtol``, ``ftol``, ``max_nfev``...).

    Raises
    ------
    CalibrationError
        On an ill-posed problem (naming the parameter or target), or if a target cannot be
        computed on the starting rig.
    """
    unknowns, targets, fixed, tied, initial = _validate(rig, unknowns, targets, fixed, tied, allow_underdetermined)
    sigmas = np.array([t.uncertainty for t in targets])
    values = np.array([float(t.value) for t in targets])

    def unpack(z) -> dict[str, float]:
        return {u.name: min(max(u.from_internal(zi), u.lower), u.upper) for u, zi in zip(unknowns, z)}

    def compute(z) -> np.ndarray:
        current, extras = _apply(rig, unknowns, unpack(z), tied)
        return np.array([float(t.compute(t.variant(current, extras))) for t in targets])

    z0 = np.array([u.to_internal(initial[u.name]) for u in unknowns])
    try:
        start_rig, start_extras = _apply(rig, unknowns, initial, tied)
    except CamdynError as exc:
        raise CalibrationError(f"the starting values give an invalid rig: {exc}") from exc
    evaluate(start_rig, targets, start_extras)  # raises a clear error naming the target

    penalty = 1e6
    failures: list[str] = []

    def residuals(z):
        try:
            computed = compute(z)
        except (CamdynError, ValueError, ArithmeticError) as exc:
            failures.append(str(exc))
            return np.full(len(targets), penalty)
        r = (computed - values) / sigmas
        return np.where(np.isfinite(r), r, penalty)

    lower, upper = zip(*(u.internal_bounds() for u in unknowns))
    options = {"method": "trf", "x_scale": 1.0, "xtol": 1e-12, "ftol": 1e-12, "gtol": 1e-12,
               "diff_step": 1e-7, "max_nfev": 400 * (len(unknowns) + 1)}
    options.update(least_squares_options)
    if len(targets) < len(unknowns) and options["method"] == "lm":
        raise CalibrationError("method='lm' needs at least as many targets as unknowns")
    sol = least_squares(residuals, z0, bounds=(np.array(lower), np.array(upper)), **options)
    fitted = unpack(sol.x)
    final_rig, extras = _apply(rig, unknowns, fitted, tied)
    changes = {}
    if name is not None:
        changes["name"] = name
    if description is not None:
        changes["description"] = description
    if changes:
        final_rig = final_rig.replace(**changes)
    results = evaluate(final_rig, targets, extras)

    # degrees of freedom from the weighted Jacobian at the solution (internal variables)
    J = np.asarray(sol.jac, dtype=float)
    s = np.linalg.svd(J, compute_uv=False) if J.size else np.zeros(0)
    rank = int(np.sum(s > rank_rtol * s.max())) if s.size and s.max() > 0 else 0
    at_bounds = tuple(u.name for u, active in zip(unknowns, sol.active_mask) if active != 0)
    dof = DegreesOfFreedom(len(targets), len(unknowns), rank, tuple(float(v) for v in s), dict(fixed),
                           tuple(tied), at_bounds)

    # sensitivities d log(computed) / d log(unknown): J is d((c - v)/sigma)/dz
    computed = np.array([r.computed for r in results])
    sens = np.full((len(targets), len(unknowns)), np.nan)
    for j, u in enumerate(unknowns):
        dz_dlogx = 1.0 if u.log else fitted[u.name] / (u.upper - u.lower if math.isfinite(u.upper - u.lower) else 1.0)
        with np.errstate(divide="ignore", invalid="ignore"):
            sens[:, j] = J[:, j] * sigmas * dz_dlogx / computed
    message = sol.message if sol.success else f"did not converge: {sol.message}"
    if failures:
        message += f" ({len(failures)} trial point(s) could not be evaluated, e.g.: {failures[0]})"
    return Calibration(final_rig, fitted, extras, results, dof, unknowns, targets, initial, sens,
                       bool(sol.success), message, float(sol.cost), int(sol.nfev))
