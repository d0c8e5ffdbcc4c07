"""Following the branches: the first orbit by shooting, the steps along a branch with their
step control and the events between them, until the branch leaves the range or fails, and the
branches switched to at period doublings, in turn."""
from __future__ import annotations

import math

from ...errors import ParameterError
from ..section_map import MapFailure
from ..shooting import OrbitOutcome, ShootingSettings, periodic_orbit
from .corrector import first_point, step
from .events import detect
from .problem import Z_LAMBDA, Branch, ContinuationOutcome, ContinuationSettings, Leg, Point, Problem
from .switching import switched

#: grow the step by this factor after a point the corrector found in at most ``easy_iterations``
GROWTH = 1.5
#: a tangent whose lambda-component is below this does not move lambda: the step is not clipped
FLAT = 1e-12
#: lambda is at an end of the range within this fraction of the range
AT_END = 1e-9
#: the first orbit's warm starts (:func:`camdyn.periodic_orbit`'s ``start``): a run of
#: ``warmup_revolutions`` from the static equilibrium, or the quasi-static contact orbit (which
#: finds the contact branch where a weakly damped run settles on another, impacting, orbit)
WARM_STARTS = ("run", "quasistatic")


def check_warm(warm) -> None:
    """Refuse a warm start not in :data:`WARM_STARTS` (raises ParameterError)."""
    if warm not in WARM_STARTS:
        raise ParameterError("warm", warm, f"one of {WARM_STARTS} (the first orbit's warm start)")


def clipped(start: float, end: float, span: float, lam: float, t_lam: float, ds: float) -> float:
    """ds shortened so that a predictor from ``lam`` whose tangent moves lambda by ``t_lam``
    (scaled by ``span``) per unit arclength stops at the end of the range [start, end] it moves
    toward."""
    if abs(t_lam) < FLAT:
        return ds
    bound = max(start, end) if t_lam > 0 else min(start, end)
    reach = (bound - lam) / span / t_lam
    return min(ds, reach) if reach > 0 else ds


def left_range(start: float, end: float, span: float, lam: float) -> ContinuationOutcome | None:
    """END_REACHED or LEFT_RANGE once lambda is at or past an end of the range (AT_END of it)."""
    slack = AT_END * span
    for bound, outcome in ((end, ContinuationOutcome.END_REACHED), (start, ContinuationOutcome.LEFT_RANGE)):
        other = start if bound == end else end
        if (lam - bound) * math.copysign(1.0, bound - other) >= -slack:
            return outcome
    return None


def _clipped(leg: Leg, p: Point, ds: float) -> float:
    """ds shortened so that the predictor stops at the end of the range it moves toward."""
    problem = leg.problem
    return clipped(problem.start, problem.end, problem.span, p.lam, p.tangent[Z_LAMBDA], ds)


def _left(problem: Problem, lam: float) -> ContinuationOutcome | None:
    """END_REACHED or LEFT_RANGE once lambda is at or past an end of the range (AT_END of it)."""
    return left_range(problem.start, problem.end, problem.span, lam)


def follow(leg: Leg, branch: Branch, index: int, first: Point, events: list) -> None:
    """Continue ``branch`` (number ``index``) from ``first`` until it leaves the range, fails, or
    max_points; the events found on the way are appended to ``events``
    (:class:`~camdyn.orbits.continuation.events.Found`)."""
    settings = leg.settings
    p, ds = first, settings.step
    branch.points.append(p)
    while True:
        if len(branch.points) >= settings.max_points:
            branch.outcome = ContinuationOutcome.MAX_POINTS
            return
        clipped = _clipped(leg, p, ds)
        q = step(leg, p, clipped)
        if q is None:
            if ds <= settings.min_step:
                branch.outcome = ContinuationOutcome.STEP_TOO_SMALL
                branch.message = f"at {leg.problem.parameter} = {p.lam:.8g}"
                return
            ds = max(ds / 2.0, settings.min_step)
            continue
        events += detect(leg, p, q, clipped, (index, len(branch.points) - 1))
        branch.points.append(q)
        done = _left(leg.problem, q.lam)
        if done is not None:
            branch.outcome = done
            return
        if q.iterations <= settings.easy_iterations:
            ds = min(GROWTH * ds, settings.max_step)
        p = q


def start(problem: Problem, warmup_revolutions: int, settings: ContinuationSettings,
          warm: str = "run") -> tuple[Point, Leg] | str:
    """The first orbit, by shooting at the start value from the warm start ``warm`` (``"run"``:
    ``warmup_revolutions`` from the static equilibrium; ``"quasistatic"``: the quasi-static
    contact orbit, :func:`camdyn.periodic_orbit`'s ``start``), and its leg; or why there is none."""
    model = problem.model(problem.start)
    orbit = periodic_orbit(model.rig, problem.scene, model.cam, periods=problem.periods,
                           phase=problem.phase_fraction * model.period, warmup_revolutions=warmup_revolutions,
                           settings=ShootingSettings(settings.tol, max(20, settings.max_corrector)),
                           options=problem.options, jacobian=problem.jacobian, backend=problem.backend, start=warm)
    if not (orbit.ok or orbit.outcome is OrbitOutcome.MULTIPLIERS_UNRESOLVED):   # the orbit, not its multipliers
        return orbit.message
    leg = Leg(problem, problem.periods, orbit.scale, settings)
    try:
        first = first_point(leg, problem.start, orbit.state, orbit.mode_index,
                            math.copysign(1.0, problem.end - problem.start))
    except MapFailure as failure:
        return str(failure)
    return first, leg


def _note_unresolved(problem: Problem, branch: Branch) -> None:
    """Say in the branch's message where its derivatives were unresolved (no multipliers, no
    events of the multipliers told there: :func:`camdyn.orbits.continuation.events.tests`)."""
    lost = [p.lam for p in branch.points if not p.resolved]
    if lost:
        branch.message += (f"; derivatives unresolved at {len(lost)} of {len(branch.points)} points "
                           f"({problem.parameter} {min(lost):.8g} to {max(lost):.8g}): no multipliers there, and "
                           "an event next to them is a multiplier_jump (the switches change within a difference step)")


def run(problem: Problem, settings: ContinuationSettings, warmup_revolutions: int, warm: str = "run"):
    """Every branch (the first, then those switched to at period doublings) and the events:
    (branches, events, the motion's scale; None when the start failed); ``warm``: the first
    orbit's warm start (:func:`start`)."""
    started = start(problem, warmup_revolutions, settings, warm)
    if isinstance(started, str):
        return [Branch(problem.periods, outcome=ContinuationOutcome.START_FAILED, message=started)], [], None
    first, leg = started
    scale = leg.scale
    branches, events, queue = [], [], [(leg, Branch(problem.periods), first, 0)]
    while queue:
        leg, branch, first, depth = queue.pop(0)
        index = len(branches)
        branches.append(branch)
        found: list = []
        follow(leg, branch, index, first, found)
        first_event = len(events)
        events += [f.event for f in found]
        _note_unresolved(problem, branch)
        if depth < settings.switch_depth:
            queue += [(*s, depth + 1) for s in switched(leg, branch, index, found, first_event)]
    return branches, events, scale
