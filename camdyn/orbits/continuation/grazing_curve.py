"""Following the curve of grazing orbits in two parameters: its settings and outcomes, the
first point (from a one-parameter continuation's grazing), the steps with their step control,
and the codimension-2 points on it.

Pseudo-arclength on the extended system of :mod:`.grazing`: the predictor along the unit null
vector of its scaled Jacobian (4 x 5, :func:`camdyn.orbits.continuation.corrector.tangent`), the
corrector :func:`camdyn.orbits.continuation.corrector.chord` (chord/Newton with the arclength
condition), the step halved when the corrector fails and grown by
:data:`camdyn.orbits.continuation.follow.GROWTH` after an easy one, as for a branch.

**Codimension-2 points.**  At each point the Floquet multipliers of the grazing orbit (contact
side, M from :func:`.grazing.derivatives`) give det(M + I) and det(M - I); where one changes
sign between two points a multiplier at grazing passes -1 (``grazing_period_doubling``: the
grazing curve meets a period-doubling curve) or +1 (``grazing_fold``: it meets a fold curve),
located by secant trials in arclength (:func:`camdyn.orbits.continuation.events.trial`) to
``locate_tol``.
"""
from __future__ import annotations

import dataclasses
import math
from dataclasses import dataclass
from functools import partial
from typing import NamedTuple

import numpy as np

from ..._checks import real
from ...errors import CamdynError, ParameterError
from ...outcome import ActionableOutcome
from ..derivatives import Unresolved
from ..shooting import sorted_multipliers
from .corrector import bordered_step, chord, tangent
from .events import Bracket, secant_bracket
from .follow import AT_END, FLAT, GROWTH, clipped, left_range
from .grazing import (G_RANGE, G_SIZE, R_GAP, Derivatives, Evaluation, GrazingSystem, Layout, derivatives, evaluate,
                      flight_residual, free_at_zero_gap, is_largest)
from .problem import ContinuationSettings

#: the codimension-1 kinds a grazing curve meets, with the sign s of their test function
#: det(M + s I) of the monodromy matrix M: a period doubling (a multiplier through -1) and a fold
#: (through +1); the fold and period-doubling curves (:mod:`.codim1`) are continued on it
SIGNS = {"period_doubling": 1.0, "fold": -1.0}


def critical_det(kind: str, M) -> float:
    """det(M + s I), s the sign of ``kind`` (:data:`SIGNS`): zero where M has the kind's critical multiplier."""
    return float(np.linalg.det(M + SIGNS[kind] * np.eye(len(M))))


def codim2_name(kind: str) -> str:
    """The codimension-2 point where a grazing curve meets the curve of ``kind`` (a key of
    :data:`SIGNS`), by the same name on either curve."""
    return f"grazing_{kind}"


#: a step's prediction is moved to the contact side by this many times its expected error in the
#: gap's row (:func:`contact_side`): the last step's error, scaled by the square of the steps'
#: ratio, measured within a factor 3 of the next on reference-experiment against k_s
CONTACT_SIDE = 2.0
#: the prediction's error in the gap's row, in units of the corrector's ``tol``, that the step
#: control aims at (:func:`grown`): on reference-experiment against k_s, predictions 10 to 70 tol
#: off converged in one or two iterations from the contact side
EASY_MISS = 100.0
#: the step grows by at most this factor after a point (:func:`grown`)
MAX_GROWTH = 4.0
#: the codimension-2 points' kinds and their test functions of the monodromy matrix M
CODIM2 = {codim2_name(kind): partial(critical_det, kind) for kind in SIGNS}


class GrazingOutcome(ActionableOutcome):
    """How a grazing curve ended (an actionable message each)."""

    END_REACHED = "the curve reached the end value of the parameter"
    LEFT_RANGE = ("the curve turned back and left the range at the start value (a fold of the grazing curve "
                  "in the parameter); start from the other end to follow it further")
    MAX_POINTS = "GrazingSettings.continuation.max_points grazing orbits were computed before the end: raise it"
    STEP_TOO_SMALL = ("the corrector failed at the minimum step (the extended system is singular or not smooth "
                      "there, or a run failed, see the message): the curve ends here; try another "
                      "phase_fraction or a smaller min_step")
    MAXIMUM_MOVED = ("another maximum of the gap over the orbit has overtaken the grazing one: the follower "
                     "first leaves the cam at another cam angle beyond this point (a double grazing); start a "
                     "new curve beyond it")
    NO_DERIVATIVES = ("the grazing system's derivatives could not be evaluated (the tangent dynamics fail: "
                      "damping C and E's impact laws; or no parameter step keeps the contact side): the curve "
                      "ends here, see the message")
    START_FAILED = ("no grazing orbit at the start value (see the message): widen the search range of the free "
                    "parameter, or try another phase_fraction")


@dataclass(frozen=True)
class GrazingSettings:
    """``continuation``: the curve's step control, the corrector's tolerance ``tol`` and
    ``locate_tol`` of its codimension-2 points (scaled arclength: lambda2's range is 1);
    ``search``: the one-parameter continuation that finds the first grazing (its orbit only
    starts the extended system's Newton, which locates the grazing itself: a coarse one);
    ``gap_tol``: the gap's tolerance, a fraction of the largest deflection over the first orbit
    (the grazing orbit is converged to psi_i(t_g) within [-3, -1] gap_tol of it); ``threads``:
    how many of a point's independent runs (the tangent dynamics and the two parameter
    differences, :func:`.grazing.derivatives`) run at once; the curve is the same for any value."""

    continuation: ContinuationSettings = ContinuationSettings(switch_depth=0)
    gap_tol: float = 1e-6
    search: ContinuationSettings = ContinuationSettings(step=0.05, max_step=0.25, locate_tol=1e-5, switch_depth=0)
    threads: int = 2

    def __post_init__(self):
        for name in ("continuation", "search"):
            if not isinstance(getattr(self, name), ContinuationSettings):
                raise ParameterError(name, getattr(self, name), "a camdyn.orbits.continuation.ContinuationSettings")
        real("gap_tol", self.gap_tol, "1e-12 <= gap_tol <= 1e-2 (of the largest deflection over the orbit)",
             lambda v: 1e-12 <= v <= 1e-2)
        if not (isinstance(self.threads, int) and not isinstance(self.threads, bool) and 1 <= self.threads <= 64):
            raise ParameterError("threads", self.threads, "an integer from 1 to 64")


class GrazingPoint(NamedTuple):
    """One grazing orbit: z (scaled), lambda1 and lambda2, x at the section, the grazing's phase
    phi_g (t_g = t0 + phi_g T), M = dP/dx (contact side), the unit tangent (scaled), the
    derivatives, the evaluation that converged there (t_g, psi_i there...), the corrector's
    iterations, ``grazing``: lambda1 at zero gap (:func:`.grazing.free_at_zero_gap`; the
    orbit's own lambda1, ``free``, is at psi_i(t_g) = -margin), ``curvature``: the change of
    the unit tangent per unit arclength from the point before (zero at the first), and
    ``miss``: the error of the prediction that found it in the gap's row (the linearised
    residual there, scaled) per squared arclength step (NaN at the first point)."""

    z: np.ndarray
    free: float
    lam: float
    x: np.ndarray
    phase: float
    M: np.ndarray
    tangent: np.ndarray
    derivatives: Derivatives
    evaluation: Evaluation
    iterations: int
    grazing: float
    curvature: np.ndarray
    miss: float

    @property
    def tests(self) -> dict[str, float]:
        return {kind: f(self.M) for kind, f in CODIM2.items()}


class Ended(NamedTuple):
    """A step that ends the curve: the outcome and where and why."""

    outcome: GrazingOutcome
    message: str


class Codim2(NamedTuple):
    """A located codimension-2 point: its kind, the orbit there (a :class:`GrazingPoint` on a
    grazing curve, a :class:`.codim1.Codim1Point` on a fold or period-doubling curve), and the
    index of the curve's point just before it."""

    kind: str
    at: GrazingPoint
    point: int


@dataclass
class Curve:
    """A grazing curve: its points in order, the codimension-2 points, how it ended and why."""

    points: list
    found: list
    outcome: GrazingOutcome | None = None
    message: str = ""


class Leg(NamedTuple):
    """What every step shares: the system, the layout of z and the settings."""

    system: GrazingSystem
    layout: Layout
    settings: ContinuationSettings

    @property
    def start(self) -> float:
        return self.system.start

    @property
    def end(self) -> float:
        return self.system.end

    @property
    def span(self) -> float:
        return self.system.span


def _point(leg: Leg, z, e: Evaluation, direction, iterations: int, previous=None) -> GrazingPoint:
    """The grazing orbit at z as a point: its derivatives (raises MapFailure; ``previous``: the
    last point's) and tangent."""
    d = derivatives(leg.system, leg.layout, z, e, previous)
    x, phase, free, lam = leg.layout.split(z)
    return GrazingPoint(z, free, lam, x, phase, d.M, tangent(d.A, direction), d, e, iterations,
                        free_at_zero_gap(leg.system, leg.layout, z, e, d.A), np.zeros(G_SIZE), math.nan)


class Prediction(NamedTuple):
    """A step's prediction: ``z`` on the curve's second-order expansion, ``direction`` of the
    arclength condition through it, and ``start``, the corrector's first iterate: z moved to the
    contact side (:func:`contact_side`; on the same hyperplane)."""

    z: np.ndarray
    direction: np.ndarray
    start: np.ndarray


def predicted(leg: Leg, p: GrazingPoint, ds: float, final: bool = False) -> Prediction:
    """The prediction ds from p: the second-order one, ``z + ds t + ds^2 / 2 curvature``, the
    arclength condition along the tangent (the jump speed's curve bends: the tangent's own error,
    ds^2 / 2 of the curvature, is 1e-3 of the deflection at ds = 0.01 on reference-experiment
    against k_s).  ``final``: the step reaches the range's end, and the prediction and the
    corrector hold lambda2 at it instead of the arclength condition: the prediction moved along
    the tangent to lambda2's end (where the tangent moves lambda2; setting lambda2 alone left the
    other unknowns ds^2 / 2 of the curvature behind it: on reference-experiment against k_s the
    last step's prediction lifted off, 1.5e-3 of the scaled residual in the gap's row, and was
    halved)."""
    z = p.z + ds * p.tangent + 0.5 * ds * ds * p.curvature
    if final:
        end = leg.end / leg.layout.sigma_range
        if abs(p.tangent[G_RANGE]) >= FLAT:
            z = z + (end - z[G_RANGE]) / p.tangent[G_RANGE] * p.tangent
        z[G_RANGE] = end
    direction = _along(1.0) if final else p.tangent
    return Prediction(z, direction, z + contact_side(p, direction, ds))


def contact_side(p: GrazingPoint, direction, ds: float) -> np.ndarray:
    """The move of a prediction ds from p to the contact side: CONTACT_SIDE times its expected
    error in the gap's row, ``p.miss ds^2`` (none at the first point, whose ``miss`` is NaN),
    along the direction that lowers the linearised gap row alone, on the arclength hyperplane
    (``[A; direction] dz = -e_gap``).  The extended system is smooth only on the contact side:
    a prediction past the grazing by more than the margin (:data:`.boundary.GAP_MARGINS`) lifts the
    follower off, and its run's residual is no smooth one (the flight's gap, :func:`in_contact`):
    the corrector steps back from it, one or more iterations lost (on reference-experiment
    against k_s, 12 of 50 steps' predictions lifted off, each then costing a Newton step's
    derivatives too; measured with this move at 0 and 2: 41 and 35 grazing orbits, 127 and 97
    corrector runs, 46 and 39 steps)."""
    if not math.isfinite(p.miss):
        return np.zeros(G_SIZE)
    gap = np.zeros(G_SIZE - 1)
    gap[R_GAP] = -1.0
    return CONTACT_SIDE * p.miss * ds * ds * bordered_step(p.derivatives.A, direction, gap)


def corrected(leg: Leg, p: GrazingPoint, prediction: Prediction):
    """The grazing orbit from ``prediction`` (chord corrector from its start: the arclength
    condition through it is the prediction's), without its derivatives: (z, evaluation,
    iterations), or None when the corrector fails."""
    mode = p.evaluation.value.start_mode
    return chord(lambda z: _residual(leg, z, mode),
                 lambda z, e: derivatives(leg.system, leg.layout, z, e, p.derivatives, False).A,
                 prediction.start, prediction.direction, p.derivatives.A, leg.settings, in_contact)


def _along(sign: float) -> np.ndarray:
    """A z-direction along lambda2 alone."""
    t = np.zeros(G_SIZE)
    t[G_RANGE] = sign
    return t


def in_contact(e: Evaluation) -> bool:
    """Whether the run of an evaluation kept the follower on the cam (its largest gap is
    negative): its residual is then the extended system's, smooth; past the grazing it is the
    flight's gap, above the smooth one, and the chord step from it lands on the contact side."""
    return e.max_gap < 0.0


def _residual(leg: Leg, z, mode):
    """The chord's residual: (the scaled residual, the evaluation), the run starting in ``mode``
    (the last point's start mode), or in the automaton's initial rule's where z's state is
    outside that mode's domain at the section (a prediction across a surface the orbit passes
    close to there: on reference-experiment against k_s at phase_fraction 0.5, 0.02 T after
    the grazing, the gap's rate is -4e-10 m/s and an iterate's error reverses it, which ended
    3 of the curve's steps).  Where the run left the cam (:func:`in_contact`), the residual is
    :func:`.grazing.flight_residual`'s: the chord step from it moves z to the contact side along
    the gap's row alone."""
    x, _, free, lam = leg.layout.split(z)
    if mode is not None and not leg.system.section_map(free, lam, mode).admits(x):
        mode = None
    e = evaluate(leg.system, leg.layout, z, mode)
    return (e.residual if in_contact(e) else flight_residual(leg.system, e)), e


def step(leg: Leg, p: GrazingPoint, ds: float, final: bool = False):
    """The point at arclength ds from p (``final``: at the range's end, :func:`predicted`): a
    GrazingPoint, None when the corrector fails or when no parameter step keeps the converged
    orbit's path (an orbit lifted off at the psi_i noise of a stiff contact: the step is retried
    shorter, as a failed one; seen on reference-experiment at k_s = 30 N/m, where it ended the
    chart), or :class:`Ended` (MAXIMUM_MOVED, NO_DERIVATIVES) with where and why."""
    prediction = predicted(leg, p, ds, final)
    found = corrected(leg, p, prediction)
    if found is None:
        return None
    z, e, iterations = found
    if not is_largest(leg.system, e):
        unit = leg.system.boundary.unit
        return Ended(GrazingOutcome.MAXIMUM_MOVED, f"at {_where(leg, z)}: a gap of {e.max_gap:.3g} {unit} over the "
                                                   f"orbit against {e.psi_g:.3g} {unit} at the grazing's t_g")
    try:
        q = _point(leg, z, e, p.tangent, iterations, p.derivatives)
    except Unresolved:
        return None
    except CamdynError as failure:
        return Ended(GrazingOutcome.NO_DERIVATIVES, f"at {_where(leg, z)}: {failure}")
    miss = abs(float(q.derivatives.A[R_GAP] @ (prediction.z - z))) / (ds * ds)
    return q._replace(curvature=(q.tangent - p.tangent) / ds, miss=miss)


def _where(leg: Leg, z) -> str:
    _, _, free, lam = leg.layout.split(z)
    return f"{leg.system.free} = {free:.8g}, {leg.system.parameter} = {lam:.8g}"


def first(leg: Leg, x, phase: float, free: float, mode: int) -> GrazingPoint | str:
    """The grazing orbit at lambda2 = start from a near-grazing orbit (x, its gap's maximum at
    ``phase``, lambda1 = ``free``): the corrector with the arclength condition fixing lambda2;
    its tangent oriented toward the end.  Or why there is none."""
    layout, system = leg.layout, leg.system
    z0 = layout.z(x, phase, free, system.start)
    along = _along(math.copysign(1.0, system.end - system.start))
    try:
        e0 = evaluate(system, layout, z0, mode)
        A0 = derivatives(system, layout, z0, e0, None, False).A
    except CamdynError as failure:
        return f"the start orbit cannot be evaluated: {failure}"
    found = chord(lambda z: _residual(leg, z, mode), lambda z, e: derivatives(system, layout, z, e, None, False).A, z0,
                  along, A0, dataclasses.replace(leg.settings, max_corrector=max(20, leg.settings.max_corrector)),
                  in_contact)
    if found is None:
        return (f"the extended system's corrector did not converge from the near-grazing orbit at "
                f"{system.free} = {free:.8g}")
    z, e, iterations = found
    if not is_largest(system, e):
        unit = system.boundary.unit
        return f"the located orbit's largest gap is not at its t_g ({e.max_gap:.3g} {unit} against {e.psi_g:.3g} {unit})"
    try:
        return _point(leg, z, e, along, iterations)
    except CamdynError as failure:
        return f"no derivatives at the first grazing orbit: {failure}"


def follow(leg, p, advance=None, detect=None) -> Curve:
    """The curve from its first point ``p`` until lambda2 leaves the range, or it ends (see
    :class:`GrazingOutcome`); codimension-2 points located on the way.  ``advance(leg, p, ds,
    final)`` takes a step (default :func:`step`), ``detect(leg, p, q, ds, index)`` lists the
    points found between two (default :func:`located`): another extended system's curve
    (:mod:`.codim1`) is followed by the same loop; its points have ``free``, ``lam``, ``z``,
    ``tangent``, ``curvature``, ``iterations`` and ``miss`` (:func:`grown`), lambda2 last in z,
    and its leg ``start``, ``end``, ``span``, ``settings``, ``system`` and ``layout.sigma_range``."""
    advance, detect = advance or step, detect or located
    settings, curve, ds = leg.settings, Curve([p], []), leg.settings.step
    while True:
        if len(curve.points) >= settings.max_points:
            curve.outcome = GrazingOutcome.MAX_POINTS
            return curve
        h = clipped(leg.start, leg.end, leg.span, p.lam, p.tangent[-1], ds)
        q = advance(leg, p, h, _reaches_end(leg, p, h))
        if isinstance(q, Ended):
            curve.outcome, curve.message = q
            return curve
        if q is None:
            if ds <= settings.min_step:
                curve.outcome = GrazingOutcome.STEP_TOO_SMALL
                curve.message = f"at {leg.system.free} = {p.free:.8g}, {leg.system.parameter} = {p.lam:.8g}"
                return curve
            ds = max(ds / 2.0, settings.min_step)
            continue
        curve.found += detect(leg, p, q, h, len(curve.points) - 1)
        curve.points.append(q)
        done = left_range(leg.start, leg.end, leg.span, q.lam)
        if done is not None:
            curve.outcome = GrazingOutcome[done.name]
            return curve
        if q.iterations <= settings.easy_iterations:
            ds = grown(settings, q, ds)
        p = q


def grown(settings: ContinuationSettings, q, ds: float) -> float:
    """The step after an easy point q (found in at most ``easy_iterations``) at step ds: GROWTH
    times ds, or more, up to MAX_GROWTH times, where the prediction's error per ds^2 (``q.miss``;
    NaN where the curve does not estimate it) puts the step whose expected error is EASY_MISS
    ``tol`` further; at most ``max_step``.  After a first step halved to where its prediction
    (the tangent's alone) stays on the contact side, the step regains the asked one sooner: on
    reference-experiment against k_s (the predictions' error there, 1e-7 to 1e-6 of the scaled
    residual, is the tangent's noise more than the step's), 33 grazing orbits against 34 with
    GROWTH alone."""
    longer = GROWTH * ds
    if math.isfinite(q.miss) and q.miss > 0:
        longer = max(longer, min(MAX_GROWTH * ds, math.sqrt(EASY_MISS * settings.tol / q.miss)))
    return min(longer, settings.max_step)


def _reaches_end(leg, p, ds: float) -> bool:
    """Whether the prediction ds from p reaches lambda2's end (within AT_END of the range;
    lambda2 is z's last component)."""
    lam = p.lam + leg.layout.sigma_range * (ds * p.tangent[-1] + 0.5 * ds * ds * p.curvature[-1])
    return (lam - leg.end) * math.copysign(1.0, leg.end - leg.start) >= -AT_END * leg.span


def located(leg: Leg, p: GrazingPoint, q: GrazingPoint, ds: float, index: int) -> list[Codim2]:
    """The codimension-2 points between p and q (ds apart), each located in arclength to
    ``locate_tol`` by secant trials with the Illinois rule (:func:`.events.secant_bracket`); the
    located orbit is the last trial on p's side of the sign change."""
    out = []
    f0, f1 = p.tests, q.tests
    for kind in CODIM2:
        a, b = f0[kind], f1[kind]
        if not (math.isfinite(a) and math.isfinite(b) and a * b < 0):
            continue
        def at(s: float, test=CODIM2[kind]):
            r = step(leg, p, s)
            return (test(r.M), r) if isinstance(r, GrazingPoint) else (math.nan, None)
        bracket = secant_bracket(Bracket(0.0, ds, a, b, p), at, leg.settings.locate_tol)
        out.append(Codim2(kind, bracket.before, index))
    return out


def multipliers(p: GrazingPoint) -> np.ndarray:
    """The Floquet multipliers of the grazing orbit (contact side), by decreasing modulus."""
    return sorted_multipliers(p.M)
