"""The events along a branch, in one table (:data:`KINDS`): each kind's test function, whose
sign change between two points marks it (a corner impact's: the continuous sign change of one
impact's distance to one junction, :func:`.corners.crossings`), the distance of the multipliers
from its critical value, and how it is located in arclength (the secant trials with the Illinois
rule, or the grazing trials from the contact side); their detection between two points and
location."""
from __future__ import annotations

import math
from dataclasses import dataclass
from typing import Callable, NamedTuple

import numpy as np

from ..shooting import sorted_multipliers
from .corners import crossings, distance_of, landings
from .corrector import completed, corrected, gap, step
from .lift_off import lift_off
from .problem import N_STATE, Z_LAMBDA, Event, Leg, Point

#: a located bifurcation's critical multiplier (+1, -1, ``|mu| = 1``) is within this of its value,
#: and the multipliers on both sides of the bracket differ by less: a bracket of locate_tol puts
#: them within ~``|d mu / ds| locate_tol`` (~1e-5) of each other, unless they jump
CRITICAL = 1e-2
#: an event's location stops after this many trials (each shrinks the bracket)
MAX_BISECTIONS = 40
#: a grazing's trial aims this fraction of locate_tol past the root extrapolated from the contact
#: side, and no nearer the far end of the bracket than the rest of locate_tol: with the root known
#: to within this fraction of locate_tol (the secant's error shrinks superlinearly on the smooth
#: contact side), one trial lands past the event and the next, a locate_tol from it, before it:
#: the bracket closes from both sides in two trials (:func:`grazing_trial`)
GRAZING_PAST = 0.25


class Kind(NamedTuple):
    """An event kind: its name; its test function at a point (a float, or what ``changed``
    reads; None: a kind only named after a location, ``multiplier_jump``); the distance of each
    multiplier from the kind's critical value (None: not an event of the multipliers, always
    smooth); its locator, ``(leg, kind, p, q, ds) -> (before, after)``; and the kind whose sign change at the same step masks it
    (``unless``: the +1 multiplier of a fold is no branch point); ``switch_branch``: whether the
    branch of period 2 n T is switched to there (:mod:`.switching`); ``changed(f_p, f_q)``:
    whether the test's values at two points mark the event (None: a strict sign change of two
    finite values); ``located_before``: the located orbit is the bracket's end on p's side (else
    the far end's, where it ran); ``of_run``: the test function from a corrected orbit's run
    (:class:`.corrector.Run`), for a locator whose trials are orbits without derivatives
    (:func:`grazing_location`)."""

    name: str
    test: Callable[[Point], object] | None
    distance: Callable[[np.ndarray], np.ndarray] | None
    locate: Callable | None
    unless: str | None = None
    switch_branch: bool = False
    changed: Callable | None = None
    located_before: bool = False
    of_run: Callable | None = None


class Found(NamedTuple):
    """A located event, the orbit it is at, and the points p and q of the step it lies in."""

    event: Event
    at: Point
    p: Point
    q: Point


# --- the test functions (a 2 x 2 monodromy M: det(M -+ I) = det M -+ tr M + 1) ----------------------
def _det_trace(p: Point) -> tuple[float, float]:
    M = p.jacobian
    return float(np.linalg.det(M)), float(np.trace(M))


def _fold(p: Point) -> float:
    """The lambda-component of the tangent: it changes sign where the branch turns back."""
    return float(p.tangent[Z_LAMBDA])


def _branch_point(p: Point) -> float:
    det, tr = _det_trace(p)
    return det - tr + 1.0


def _period_doubling(p: Point) -> float:
    det, tr = _det_trace(p)
    return det + tr + 1.0


def _neimark_sacker(p: Point) -> float:
    """det M - 1 (``|mu|^2 = det M``) where the multipliers are a complex pair; NaN elsewhere."""
    det, tr = _det_trace(p)
    return det - 1.0 if tr * tr - 4.0 * det < 0 else math.nan


def _grazing(p: Point) -> float:
    """The largest gap (m); NaN on a rigid scene (where the lift-off test is defined), whose
    contact orbits have a gap of 0 to rounding: its sign there is noise (:mod:`.lift_off`)."""
    return p.max_gap if math.isnan(p.lift_off) else math.nan


def _largest_gap(run) -> float:
    return gap(run)[0]


def _lift_off(p: Point) -> float:
    """-min F_n (N) on a rigid contact orbit, the flight's largest gap (m) past it; NaN on a
    compliant scene (:func:`.lift_off.lift_off`)."""
    return p.lift_off


def _corner_impact(p: Point):
    """Where the orbit's impacts land against the profile's junctions (:class:`.corners.Landings`),
    whose signed distances are the test function (:func:`.corners.signed_distances`)."""
    return p.landings


def _corner_crossed(a, b) -> bool:
    return bool(crossings(a, b))


def tests(p: Point) -> dict:
    """The test functions at a point, by kind (a float each; a corner impact's: the point's
    landings, :func:`_corner_impact`).  Where the point's derivatives are unresolved they
    come from the differences across the first step (:mod:`camdyn.orbits.derivatives`): a sign
    change next to such a point is located but named a ``multiplier_jump``, never a bifurcation
    (:func:`smooth`)."""
    return {kind.name: kind.test(p) for kind in DETECTED}


def _changed(a: float, b: float) -> bool:
    return math.isfinite(a) and math.isfinite(b) and a * b < 0


def marked(kind: Kind, a, b) -> bool:
    """Whether ``kind``'s test values a and b at two consecutive points mark an event between them."""
    return (kind.changed or _changed)(a, b)


# --- location ----------------------------------------------------------------------------------------
@dataclass
class Bracket:
    """An event's bracket [lo, hi] in arclength from p: the test function's values at its ends
    (their signs: p's at lo), the orbits there (after: None while hi is q's step or a failed
    one), and ``kept``: how many trials in a row kept hi (> 0) or lo (< 0), for the Illinois rule."""

    lo: float
    hi: float
    f_lo: float
    f_hi: float
    before: object
    after: object = None
    kept: int = 0

    def narrow(self, s: float, f: float, orbit) -> None:
        """Move the end on the side of the trial at s (f there; NaN, a failed step: past the
        event, the map is not smooth beyond a grazing) to it, halving the value kept at the
        other end when it was kept before (the Illinois rule)."""
        if math.isfinite(f) and math.copysign(1.0, f) == math.copysign(1.0, self.f_lo):
            self.lo, self.f_lo, self.before = s, f, orbit
            self.f_hi, self.kept = (self.f_hi / 2.0, self.kept + 1) if self.kept > 0 else (self.f_hi, 1)
        else:
            self.hi, self.f_hi, self.after = s, f, orbit
            self.f_lo, self.kept = (self.f_lo / 2.0, self.kept - 1) if self.kept < 0 else (self.f_lo, -1)


def locate(leg: Leg, kind: Kind, p: Point, q: Point, ds: float):
    """The sign change of ``kind``'s test function between p and q (``ds`` apart in arclength),
    bracketed in arclength from p to ``locate_tol`` by the kind's locator: the points on both
    sides of the event (after: None when the far end is a failure)."""
    return kind.locate(leg, kind, p, q, ds)


def secant_location(leg: Leg, kind: Kind, p: Point, q: Point, ds: float):
    """The location of a smooth test function f: the next trial is the secant root of the
    bracket, with the Illinois rule (the value kept at an end twice in a row is halved, so that
    both ends close in: superlinear for a smooth f) and kept ``locate_tol`` / 2 inside it; the
    midpoint where an end has no value."""
    def at(s: float):
        r = step(leg, p, s)
        return (math.nan if r is None else kind.test(r)), r
    bracket = secant_bracket(Bracket(0.0, ds, kind.test(p), kind.test(q), p), at, leg.settings.locate_tol)
    return bracket.before, bracket.after


def secant_bracket(bracket: Bracket, at: Callable, tol: float) -> Bracket:
    """``bracket`` shrunk to ``tol`` (or MAX_BISECTIONS trials) by secant trials with the Illinois
    rule (:func:`trial`, :meth:`Bracket.narrow`); ``at(s)``: the test function's value at a
    trial s and the orbit there (NaN: a failed step)."""
    for _ in range(MAX_BISECTIONS):
        if bracket.hi - bracket.lo <= tol:
            break
        s = trial(bracket.lo, bracket.hi, bracket.f_lo, bracket.f_hi, tol)
        bracket.narrow(s, *at(s))
    return bracket


def corner_location(leg: Leg, kind: Kind, p: Point, q: Point, ds: float):
    """The corner impact between p and q: the first crossing of :func:`.corners.crossings` (by
    impact, then junction; one per step), bracketed by :func:`secant_bracket` on that impact's
    signed distance to that junction.  It is continuous through the event (the gap is C1 across
    a junction: the impact's time is) and smooth on either side, its slope jumping there as the
    branch's tangent does (the reset's derivative sees the curvature's jump: the multipliers
    jump); the Illinois rule closes the bracket from both sides all the same.  A trial's
    impacts are matched to p's by order (NaN where their count differs: taken as the far side).
    A trial needs the landings alone: it is a corrected orbit without derivatives, which only
    the two points returned get (:func:`completed_ends`)."""
    pair, impacts = crossings(p.landings, q.landings)[0], p.landings.angles.size

    def at(s: float):
        r = corrected(leg, p, s)
        return (math.nan if r is None else distance_of(landings(r.run), impacts, pair)), r
    f_p, f_q = (distance_of(o.landings, impacts, pair) for o in (p, q))
    return completed_ends(leg, p, secant_bracket(Bracket(0.0, ds, f_p, f_q, p), at, leg.settings.locate_tol))


def completed_ends(leg: Leg, p: Point, bracket: Bracket):
    """The ends of a bracket whose trials are corrected orbits without derivatives, as Points
    (:func:`completed`): (before, after); before is p where no trial landed on its side or its
    completion fails (the location lost for that rare case), after None where a run fails."""
    before = bracket.before if bracket.before is p else completed(leg, p, bracket.before)
    after = None if bracket.after is None else completed(leg, p, bracket.after)
    return before or p, after


def grazing_location(leg: Leg, kind: Kind, p: Point, q: Point, ds: float):
    """The grazing (or rigid lift-off) between p and q bracketed as :func:`secant_location` does,
    the trials aimed from the contact side (:func:`grazing_trial`): its test function (the
    largest gap; a rigid orbit's lift-off test, :mod:`.lift_off`) has a corner at the event (the
    contact's deflection or least force before it, the flight's height after), so secant trials
    across the bracket crawl in from the flat side, while on the contact side (test < 0) it is
    smooth, the contact orbit continuing through the event.  A trial needs the test alone
    (``kind.of_run``): it is a corrected orbit without derivatives (6 runs less by finite
    differences); the two points returned get theirs (after: None when a run fails there, as
    for a failed step; before: p then, the bracket's start, the location lost for that rare case)."""
    def at(s: float):
        r = corrected(leg, p, s)
        return (math.nan if r is None else kind.of_run(r.run)), r
    bracket = grazing_bracket(Bracket(0.0, ds, kind.test(p), kind.test(q), p), at, leg.settings.locate_tol)
    return completed_ends(leg, p, bracket)


def grazing_bracket(bracket: Bracket, at: Callable, tol: float) -> Bracket:
    """``bracket`` of a grazing's test function (negative on the contact side, smooth there, with
    a corner at the event) shrunk to ``tol`` (or MAX_BISECTIONS trials) by the trials aimed from
    the contact side (:func:`grazing_trial`); ``at(s)``: the test function's value at a trial s
    and the orbit there (NaN: a failed step, taken as past the event)."""
    contact = [(bracket.lo, bracket.f_lo) if bracket.f_lo < 0 else (bracket.hi, bracket.f_hi)]
    far = 1.0 if bracket.f_lo < 0 else -1.0
    for _ in range(MAX_BISECTIONS):
        if bracket.hi - bracket.lo <= tol:
            break
        s = grazing_trial(bracket.lo, bracket.hi, contact[-3:], far, tol)
        f, orbit = at(s)
        if f < 0:
            contact.append((s, f))
        bracket.narrow(s, f, orbit)
    return bracket


def grazing_trial(lo: float, hi: float, contact: list, far: float, tol: float) -> float:
    """The next trial of a grazing's location in [lo, hi], from the latest contact-side points
    ``contact`` (arclength, largest gap < 0; ``far``: +1 when the far side is hi, -1 when lo).

    The root of the secant through the last two is the estimate; its change from the estimate
    of the two before bounds its error (the secant's error shrinks superlinearly).  The trial
    is that much short of it, to land on the contact side and improve it (halfway to it when
    that is past the contact end), and once it has settled (a change below GRAZING_PAST tol)
    GRAZING_PAST tol past it, to land on the far side.  It stays GRAZING_PAST tol from the
    contact end and (1 - GRAZING_PAST) tol from the far end, so that every trial shrinks the
    bracket by as much and one landing on the contact side next to the far end closes it.  The
    midpoint with one contact-side point, or an estimate outside (lo, hi)."""
    root = _secant_root(contact[-2:])
    if not lo < root < hi:
        return 0.5 * (lo + hi)
    change = abs(root - _secant_root(contact[-3:-1])) if len(contact) > 2 else 0.0
    short = change if change > GRAZING_PAST * tol else 0.0      # NaN (a flat secant before): not short
    near = lo if far > 0 else hi                                # the contact end
    u = (root - near) * far                                     # the estimate's distance from it
    aim = u + GRAZING_PAST * tol - short
    aim = aim if aim > 0 else 0.5 * u
    return near + far * min(max(aim, GRAZING_PAST * tol), hi - lo - (1.0 - GRAZING_PAST) * tol)


def _secant_root(points: list) -> float:
    """The root of the line through two points (s, f); NaN with fewer, or a flat line."""
    if len(points) < 2 or points[0][1] == points[1][1]:
        return math.nan
    (s0, f0), (s1, f1) = points
    return s1 - f1 * (s1 - s0) / (f1 - f0)


def trial(lo: float, hi: float, f_lo: float, f_hi: float, tol: float) -> float:
    """The secant root of f over [lo, hi] (the midpoint when an end has no finite value), kept
    tol / 2 inside the bracket so that each trial shrinks it by at least that."""
    if not (math.isfinite(f_lo) and math.isfinite(f_hi)) or f_lo == f_hi:
        return 0.5 * (lo + hi)
    s = lo - f_lo * (hi - lo) / (f_hi - f_lo)
    return min(max(s, lo + 0.5 * tol), hi - 0.5 * tol)


# --- detection ---------------------------------------------------------------------------------------
def detect(leg: Leg, p: Point, q: Point, ds: float, where: tuple[int, int]) -> list[Found]:
    """The events between consecutive points p and q (ds apart), located; ``where``: (branch, index of p)."""
    f0, f1 = tests(p), tests(q)
    found = []
    for kind in DETECTED:
        if not marked(kind, f0[kind.name], f1[kind.name]):
            continue
        if kind.unless is not None and marked(KIND[kind.unless], f0[kind.unless], f1[kind.unless]):
            continue
        before, after = locate(leg, kind, p, q, ds)
        e = before if kind.located_before else (after or before)
        mu = sorted_multipliers(e.jacobian) if e.resolved else np.full(N_STATE, np.nan, dtype=complex)
        named = kind.name if smooth(kind, before, after) else MULTIPLIER_JUMP.name
        event = Event(named, e.lam, e.x, where[0], where[1], mu, e.alpha_revolutions, e.max_gap)
        found.append(Found(event, e, p, q))
    return found


def smooth(kind: Kind, before: Point, after: Point | None) -> bool:
    """Whether an event of the multipliers is a bifurcation: at the located orbit the kind's
    critical multiplier (+1, -1, modulus 1) is within CRITICAL, and the multipliers on both
    sides of the bracket (``locate_tol`` apart) differ by less than CRITICAL (they do not jump).
    A kind not of the multipliers (grazing) is always one."""
    if kind.distance is None:
        return True
    e = after or before
    if not (e.resolved and before.resolved):
        return False                        # the switches change within a difference step: not smooth
    mu = sorted_multipliers(e.jacobian)
    jump = 0.0 if after is None else float(np.max(np.abs(mu - sorted_multipliers(before.jacobian))))
    return float(np.min(kind.distance(mu))) < CRITICAL and jump < CRITICAL


def _from_one(mu: np.ndarray) -> np.ndarray:
    return np.abs(mu - 1.0)


def _from_minus_one(mu: np.ndarray) -> np.ndarray:
    return np.abs(mu + 1.0)


def _from_unit_circle(mu: np.ndarray) -> np.ndarray:
    return np.abs(np.abs(mu) - 1.0)


#: the event table, in the order the test functions are evaluated: ``fold`` (a multiplier
#: through +1, the branch turning back), ``branch_point`` (through +1 while the branch does not
#: turn: a crossing of branches), ``period_doubling`` (a real multiplier through -1),
#: ``neimark_sacker`` (a complex pair through the unit circle), ``grazing`` (the orbit's largest
#: gap through 0; compliant scenes), ``lift_off`` (a rigid orbit's least contact force through 0,
#: to a flight: :mod:`.lift_off`), ``corner_impact`` (an impact landing on a junction of the cam's profile:
#: :func:`.corners.crossings`; the located orbit is the last trial on p's side);
#: ``multiplier_jump``: a test function of the multipliers changed sign but the located orbit's
#: multipliers are not critical or jump across the bracket (the map is not smooth there, e.g.
#: where the orbit meets a new switching surface)
KINDS = (
    Kind("fold", _fold, _from_one, secant_location),
    Kind("branch_point", _branch_point, _from_one, secant_location, unless="fold"),
    Kind("period_doubling", _period_doubling, _from_minus_one, secant_location, switch_branch=True),
    Kind("neimark_sacker", _neimark_sacker, _from_unit_circle, secant_location),
    Kind("grazing", _grazing, None, grazing_location, of_run=_largest_gap),
    Kind("lift_off", _lift_off, None, grazing_location, of_run=lift_off),
    Kind("corner_impact", _corner_impact, None, corner_location, changed=_corner_crossed, located_before=True),
    Kind("multiplier_jump", None, None, None),
)
#: the event kinds' names, in the table's order (:data:`camdyn.orbits.continuation.EVENTS`)
EVENTS = tuple(kind.name for kind in KINDS)
#: the kinds by name
KIND = {kind.name: kind for kind in KINDS}
#: the kinds that have a test function, in the table's order
DETECTED = tuple(kind for kind in KINDS if kind.test is not None)
MULTIPLIER_JUMP = KIND["multiplier_jump"]
