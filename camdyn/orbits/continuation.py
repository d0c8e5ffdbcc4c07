"""Pseudo-arclength continuation of periodic orbits, with bifurcation and grazing detection.

A periodic orbit of period n T is a fixed point of the stroboscopic map P_n
(:mod:`camdyn.orbits.shooting`).  As a parameter lambda (the cam speed ``speed_rpm``, or any rig
parameter by name: ``k_s``, ``e``, ...) changes, the fixed points form branches
``G(x, lambda) = P_n(x; lambda) - x = 0`` that may turn back at folds, where a search at fixed
lambda fails.  :func:`continue_orbit` follows a branch in the unknowns z = (x, lambda), scaled
as ``(x / s, lambda / |end - start|)`` (s the size of the motion, as in :mod:`camdyn.orbits.shooting`):

* **predictor**: z_pred = z_k + ds t_k, with t_k the unit tangent, the null vector of the
  scaled Jacobian [dP/dx - I, dP/dlambda] (from its SVD), oriented along the previous one;
* **corrector**: the chord method on ``G(z) = 0, t_k . (z - z_pred) = 0`` (the arclength
  condition: the correction is orthogonal to the tangent), stopping at the scaled residual
  ``max_j |P_j(x) - x_j| / s_j <= tol``: it keeps the derivatives of the last point, one run
  per iteration, while the residual shrinks by ``CHORD_CONTRACTION`` per iteration, and takes
  Newton's step (the derivatives at the current z) when it does not; the derivatives are
  evaluated once more at the converged orbit, for its tangent and its multipliers.  Each run
  of the corrector is sampled along the orbit for the largest gap (below), which leaves its
  end state unchanged to the bit (:meth:`camdyn.orbits.section_map.StroboscopicMap.run`), so the
  converged orbit is run once: that run gives its gap, and P_n(x) to the Jacobian provider
  (:func:`camdyn.orbits.section_map.jacobian_at`), which runs only its columns: a step of k chord
  iterations costs k + 1 runs, and 2 n + 2 = 6 more for the derivatives by finite differences;
* **derivatives**: dP/dx from any Jacobian provider (:func:`camdyn.orbits.section_map.finite_differences`
  by default; the variational equations can replace it); dP/dlambda by central differences in
  lambda with the step ``h = rtol^(1/3) max(|lambda|, |end - start|)``, the rule of
  :func:`camdyn.orbits.section_map.finite_difference_steps` (truncation error h^2 against the map's
  noise rtol / h);
* **step size**: halved when the corrector fails, grown by 1.5 when it converges in at most
  ``easy_iterations`` steps, kept within [min_step, max_step] (scaled arclength).

The map is rebuilt for each lambda (T = 60 / speed_rpm changes with the speed); the section
is at ``phase_fraction`` T after each revolution's start, so that it stays at the same cam
angle along the branch.

**Detection.**  At every point the Floquet multipliers mu (eigenvalues of dP_n/dx) give test
functions whose sign change between two points marks an event, located in arclength (secant
trials with the Illinois rule, :func:`_locate`; grazing's below):

* ``fold``: the lambda-component of the tangent changes sign (a multiplier passes +1 and the
  branch turns back);
* ``branch_point``: det(M - I) changes sign while the branch does not turn (a multiplier
  through +1 at a crossing of branches);
* ``period_doubling``: det(M + I) changes sign (a real multiplier through -1);
* ``neimark_sacker``: det M - 1 changes sign between points with a complex pair (``|mu|^2 = det M``);
* ``multiplier_jump``: one of the above test functions changed sign but the multipliers jump
  across the located bracket, or are not at the critical value there (``CRITICAL``): the map
  is not smooth there (no branch is switched to);
* ``grazing``: the orbit's largest gap max psi_i (Eq. 6; psi_i < 0 is the contact deflection)
  over n T reaches zero: the follower leaves the cam for the first time.  The gap is the
  generated output ``OUT_PSI_I``, sampled ``GAP_SAMPLES`` times per period and refined by a
  parabola through the largest sample and its neighbours.  It has a corner at the event (the
  contact's deflection before, the flight's height after), so a secant across the bracket
  crawls in from the flat side; but on the contact side (gap < 0) it is smooth, the contact
  orbit continuing through the event: the trials aim at the root of the secant through the
  two latest contact-side trials, short of it while it still moves and then just past it, so
  that the bracket closes from both sides (:func:`_locate_grazing`: 7 trials where bisection
  took 14 on the leg up from 0.8 x the contact-loss speed of ``benchmarks/sweep_stop.py``).
  A trial needs the gap alone: its orbit is corrected without derivatives (6 runs less each),
  which only the two bracketing points get.

At a period doubling the branch of period 2 n T is switched to: Newton's method on P_2n from
x* +/- eps v (v the eigenvector of the multiplier near -1) on the side where P_n is unstable,
then on the other side, and that branch is continued too.

The result is an ``xarray.Dataset`` (:func:`continue_orbit`): dims ``point`` (every orbit on
every branch), ``multiplier``, ``revolution`` and ``event``.
"""
from __future__ import annotations

import math
from dataclasses import dataclass, field
from functools import cached_property
from typing import NamedTuple

import numpy as np

from ..model.cam import ConstantSpeed
from ..engine.config import SolverOptions
from ..engine.driver import Trajectory
from ..engine.loop import ALPHA, ALPHA_DOT
from ..errors import CamdynError, ParameterError
from ..model.model import Model
from .shooting import OrbitOutcome, ShootingSettings, newton, newton_matrix, periodic_orbit, sorted_multipliers
from ..outcome import ActionableOutcome
from ..model.rig import PARAMETERS, Rig
from ..model.scene import Scene
from .derivatives import Column, Unresolved, finite_differences, resolved_difference
from .section_map import DEFAULT_OPTIONS, MapFailure, MapValue, StroboscopicMap, derivative_at

#: the parameter name of the cam speed (rev/min); any other is a rig parameter (SI)
SPEED = "speed_rpm"
#: samples of psi_i per cam period for the orbit's largest gap (refined by a parabola)
GAP_SAMPLES = 256
#: event kinds, in the order the test functions are evaluated; ``multiplier_jump``: a test
#: function changed sign but the located orbit's multipliers are not critical (the map is not
#: smooth there: the multipliers jump, e.g. where the orbit meets a new switching surface)
EVENTS = ("fold", "branch_point", "period_doubling", "neimark_sacker", "grazing", "multiplier_jump")
#: a located bifurcation's critical multiplier (+1, -1, ``|mu| = 1``) is within this of its value,
#: and the multipliers on both sides of the bracket differ by less: a bracket of locate_tol puts
#: them within ~``|d mu / ds| locate_tol`` (~1e-5) of each other, unless they jump
CRITICAL = 1e-2
#: the corrector keeps the last point's derivatives while each iteration shrinks the residual by
#: this factor or more (the chord method converges linearly, at a rate of the order of the
#: derivatives' change over the step); else it evaluates them at the current z (Newton's step)
CHORD_CONTRACTION = 0.25
#: a Newton step, from derivatives evaluated at the current z, that does not shrink the residual
#: by this factor ends the corrector as failed: Newton's step converges quadratically where the
#: map is smooth and the prediction is near, so the step is too long or the map not smooth there
#: (past a grazing); the step is retried shorter instead of spending max_corrector Newton steps
#: (2 n + 2 runs each with finite differences, besides the iteration's own) on it
NEWTON_CONTRACTION = 0.5
#: an event's location stops after this many trials (each shrinks the bracket)
MAX_BISECTIONS = 40
#: a grazing's trial aims this fraction of locate_tol past the root extrapolated from the contact
#: side, and no nearer the far end of the bracket than the rest of locate_tol: with the root known
#: to within this fraction of locate_tol (the secant's error shrinks superlinearly on the smooth
#: contact side), one trial lands past the event and the next, a locate_tol from it, before it:
#: the bracket closes from both sides in two trials (:func:`_grazing_trial`)
GRAZING_PAST = 0.25
#: branch switching tries these offsets along the eigenvector (in units of the motion's scale)
SWITCH_OFFSETS = (1e-3, 1e-2, 3e-2, 1e-1)


class ContinuationOutcome(ActionableOutcome):
    """How a branch ended (an actionable message each)."""

    END_REACHED = "the branch reached the end value of the parameter"
    LEFT_RANGE = ("the branch left the range at the start value (it turned back at a fold, or a switched "
                  "branch ran toward the start); continue from another start value to follow it further")
    MAX_POINTS = ("ContinuationSettings.max_points orbits were computed before the end value: raise "
                  "ContinuationSettings.max_points or ContinuationSettings.max_step")
    STEP_TOO_SMALL = ("the corrector failed at the minimum step (a non-smooth point such as grazing or a "
                      "sliding bifurcation, or a failed run, see the message): the branch ends here; "
                      "try another phase_fraction, a smaller ContinuationSettings.min_step, or continue from "
                      "beyond it")
    START_FAILED = ("no periodic orbit at the start value (see the message): try another start value, "
                    "phase_fraction or warmup_revolutions")


@dataclass(frozen=True)
class ContinuationSettings:
    """Step control (in scaled arclength: the whole parameter range is 1) and the corrector's
    tolerance; ``locate_tol``: events are bracketed to this arclength; ``switch_depth``: how many
    period doublings deep branches are switched (0: none)."""

    step: float = 0.01
    min_step: float = 1e-5
    max_step: float = 0.05
    max_points: int = 400
    tol: float = 1e-8
    max_corrector: int = 8
    easy_iterations: int = 3
    locate_tol: float = 1e-6
    switch_depth: int = 1

    def __post_init__(self):
        for name in ("step", "min_step", "max_step", "locate_tol"):
            v = getattr(self, name)
            if isinstance(v, bool) or not isinstance(v, (int, float)) or not 0 < v <= 1:
                raise ParameterError(name, v, "0 < value <= 1 (scaled arclength: the parameter range is 1)")
        if not self.min_step <= self.step <= self.max_step:
            raise ParameterError("step", self.step, f"min_step ({self.min_step}) <= step <= max_step ({self.max_step})")
        ShootingSettings(self.tol, self.max_corrector)          # checks tol and max_corrector
        for name, lo in (("max_points", 2), ("easy_iterations", 1), ("switch_depth", 0)):
            v = getattr(self, name)
            if isinstance(v, bool) or not isinstance(v, int) or not lo <= v <= 100_000:
                raise ParameterError(name, v, f"an integer, {lo} <= {name} <= 100000")


@dataclass(frozen=True)
class Problem:
    """What is continued: the rig, scene, parameter and its range, the speed when the parameter
    is a rig's, the period n and the section's phase (a fraction of T)."""

    rig: Rig
    scene: Scene
    parameter: str
    start: float
    end: float
    speed_rpm: float | None = None
    periods: int = 1
    phase_fraction: float = 0.0
    options: SolverOptions = DEFAULT_OPTIONS
    jacobian: object = finite_differences
    backend: str = "compiled"

    @property
    def span(self) -> float:
        return abs(self.end - self.start)

    def model(self, lam: float) -> Model:
        if self.parameter == SPEED:
            return self._rig_model.with_cam(ConstantSpeed(lam))
        return Model(self.rig.replace(**{self.parameter: lam}), self.scene, ConstantSpeed(self.speed_rpm))

    @cached_property
    def _rig_model(self) -> Model:
        """The rig's model (its equilibrium, its reach checked) once, when the speed is continued."""
        return Model(self.rig, self.scene, ConstantSpeed(self.start))

    def section_map(self, lam: float, mode: int | None, periods: int | None = None) -> StroboscopicMap:
        model = self.model(lam)
        return StroboscopicMap(model, periods or self.periods, self.phase_fraction * model.period, mode,
                               self.options, self.backend)


class Point(NamedTuple):
    """One orbit on a branch: lambda, x at the section, dP_n/dx, the unit tangent (scaled), the
    largest gap (m), alpha at the revolutions' starts (the brute-force diagram's section), the
    mode at the section, the scaled residual, the corrector's steps, the scaled derivatives
    of G there, and how they were obtained (:class:`Derivation`)."""

    lam: float
    x: np.ndarray
    jacobian: np.ndarray
    tangent: np.ndarray
    max_gap: float
    alpha_revolutions: np.ndarray
    mode: int
    residual: float
    iterations: int
    derivatives: np.ndarray     # the scaled [dG/dx, dG/dlambda] (2 x 3) at the point: the next corrector's
    derivation: "Derivation"

    @property
    def resolved(self) -> bool:
        return self.derivation.resolved


@dataclass
class Branch:
    """A continued branch: its points (in order), period, parent (-1: none), the event it was
    switched to at (an index into the events; -1: none), and outcome."""

    periods: int
    points: list = field(default_factory=list)
    outcome: ContinuationOutcome | None = None
    message: str = ""
    parent: int = -1
    origin: int = -1


class Event(NamedTuple):
    kind: str
    lam: float
    x: np.ndarray
    branch: int
    point: int            # the branch point just before the event (index into the Dataset's point)
    multipliers: np.ndarray
    alpha_revolutions: np.ndarray
    max_gap: float


class Derivation(NamedTuple):
    """How a point's derivatives were obtained: the provider of dP/dx, the central-difference
    steps (alpha rad, alpha_dot rad/s, lambda; NaN where not by differences), whether both
    dP/dx and dP/dlambda are resolved (:mod:`camdyn.orbits.derivatives`), and a note (a fallback, or why not)."""

    provider: str
    steps: np.ndarray
    resolved: bool
    note: str


class _Scaled(NamedTuple):
    """G(z) scaled, the scaled Jacobian [dG/dx, dG/dlambda] (2 x 3), dP/dx unscaled, and how."""

    G: np.ndarray
    A: np.ndarray
    J: np.ndarray
    derivation: Derivation


class _Run(NamedTuple):
    """One run of P_n from x over the orbit's n T (:func:`_orbit_run`): the map, its value
    (P_n(x) and the run's switches), the run's samples, and the revolutions' starts (s) among them."""

    section_map: StroboscopicMap
    value: MapValue
    trajectory: Trajectory
    starts: np.ndarray

    @property
    def P(self) -> np.ndarray:
        return self.value.state


def _orbit_run(problem: Problem, lam: float, x, mode, periods: int) -> _Run:
    """P_n(x; lambda) by one run sampled GAP_SAMPLES times per period and at the revolutions'
    starts (raises MapFailure).  The samples do not change P_n(x), bit for bit
    (:meth:`StroboscopicMap.run`), so every run of the corrector is this one: the run that
    converges gives the orbit's largest gap (:func:`_gap`), and P_n(x) to the Jacobian
    provider, without a run of their own."""
    section_map = problem.section_map(lam, mode, periods)
    t0, t1 = section_map.t_span
    T = section_map.model.period
    samples = np.linspace(t0, t1, GAP_SAMPLES * periods + 1)
    starts = T * (np.arange(periods) + (1 if t0 > 0 else 0))    # the k T in [t0, t1)
    t_eval = np.unique(np.concatenate([samples, starts]))
    value, tr = section_map.run(x, t_eval)
    return _Run(section_map, value, tr, starts)


def _evaluate(problem: Problem, lam: float, x, mode, periods: int, scale, base: MapValue) -> _Scaled:
    """P_n(x; lambda) - x and its derivatives, scaled (raises MapFailure); ``base``: the map's
    value at (x, lambda), from the caller's run, told to the provider (a run less by finite
    differences) and the base of the difference in lambda (:func:`_d_lambda`)."""
    section_map = problem.section_map(lam, mode, periods)
    d = derivative_at(problem.jacobian(section_map, scale), x, base)
    dP_dlam, h, note = _d_lambda(problem, lam, x, mode, periods, scale, base)
    A = np.empty((2, 3))
    A[:, :2] = newton_matrix(d.jacobian, scale)
    A[:, 2] = dP_dlam * problem.span / scale
    if not np.all(np.isfinite(A)):
        raise MapFailure(f"no derivatives at {problem.parameter} = {lam:.8g}: {d.note or note}")
    notes = "; ".join(n for n in (d.note, note) if n)
    how = Derivation(d.provider, np.append(d.steps, h), d.resolved and not note, notes)
    return _Scaled((d.value - x) / scale, A, d.jacobian, how)


def _d_lambda(problem: Problem, lam: float, x, mode, periods: int, scale, base: MapValue):
    """dP_n/dlambda at (x, lambda) by a central difference under the rule of
    :mod:`camdyn.orbits.derivatives` (the runs at lambda +- h make the base run's switches and two steps
    agree; h from ``rtol^(1/3) max(|lambda|, span)`` down to the floor ``rtol^(1/2)`` of that):
    (derivative, step, '') or, when unresolved, the secant across the largest step that ran (a
    direction for the predictor and corrector, no derivative) and the reason."""
    def evaluate(offset: float) -> MapValue:
        return problem.section_map(lam + offset, mode, periods).evaluate(x)
    column = Column.of(max(abs(lam), problem.span), problem.span / scale, problem.options.rtol)
    try:
        difference, h = resolved_difference(evaluate, base, column)
        return difference, h, ""
    except Unresolved as why:
        if why.secant is None:
            raise
        return *why.secant, f"d/d{problem.parameter}: {why}"


def _tangent(A: np.ndarray, previous: np.ndarray) -> np.ndarray:
    """The unit null vector of the 2 x 3 scaled Jacobian, oriented along ``previous``."""
    t = np.linalg.svd(A)[2][-1]
    return t if float(t @ previous) >= 0 else -t


class _Corrected(NamedTuple):
    """The corrector's orbit, before its derivatives: z (scaled), the run that converged there
    (:func:`_orbit_run`), and the iterations taken."""

    z: np.ndarray
    run: _Run
    iterations: int


def _correct(problem, z_pred, direction, A, mode, periods, scale, settings) -> _Corrected | None:
    """The chord method on G(z) = 0, direction . (z - z_pred) = 0, from the derivatives ``A`` of
    the last point: one run per iteration while the residual shrinks by CHORD_CONTRACTION or
    more, the derivatives evaluated anew at z when it does not (a Newton step, 2 n + 2 runs
    more with finite differences, told P_n(x) from the iteration's run).  Returns the converged
    orbit without its derivatives (:func:`_completed` adds them), or None when it fails (a run
    fails, the residual grows, a Newton step shrinks it by less than NEWTON_CONTRACTION, or
    max_corrector is reached)."""
    z, last, fresh = z_pred.copy(), math.inf, False
    for it in range(settings.max_corrector + 1):
        lam, x = z[2] * problem.span, z[:2] * scale
        try:                           # MapFailure, or a rig value the rig refuses
            run = _orbit_run(problem, lam, x, mode, periods)
            G = (run.P - x) / scale
            r = float(np.max(np.abs(G)))
            if r <= settings.tol:
                return _Corrected(z, run, it)
            if fresh and not r <= NEWTON_CONTRACTION * last:
                return None
            fresh = math.isfinite(r) and r > CHORD_CONTRACTION * last
            if fresh:
                A = _evaluate(problem, lam, x, mode, periods, scale, run.value).A
        except CamdynError:
            return None
        if not math.isfinite(r) or (it >= 2 and r > last):
            return None
        last = r
        H = np.vstack([A, direction])
        rhs = np.concatenate([G, [direction @ (z - z_pred)]])
        try:
            z = z - np.linalg.solve(H, rhs)
        except np.linalg.LinAlgError:
            return None
    return None


def _gap(run: _Run):
    """The largest psi_i over the orbit (m), alpha at the starts of its revolutions, and the end
    mode, from the samples of its run."""
    model, tr = run.section_map.model, run.trajectory
    psi = model.outputs_at(tr.mode, tr.t, tr.y[ALPHA], tr.y[ALPHA_DOT], run.section_map.backend)[model.kernels.OUT_PSI_I]
    return _refined_max(psi), tr.y[ALPHA, np.searchsorted(tr.t, run.starts)], int(tr.end_mode)


def _refined_max(v: np.ndarray) -> float:
    """The largest value of a periodic sampled curve, refined by a parabola through its neighbours."""
    v = v[:-1]                              # the last sample repeats the first (one period)
    k = int(np.argmax(v))
    a, b, c = v[k - 1], v[k], v[(k + 1) % v.size]
    curvature = a - 2 * b + c
    return float(b - (a - c) ** 2 / (8 * curvature)) if curvature < 0 else float(b)


def _point(lam: float, x, run: _Run, ev: _Scaled, tangent, iterations: int) -> Point:
    """The orbit (lam, x) as a Point: its gap from its run, its derivatives ``ev``."""
    gap, alphas, end_mode = _gap(run)
    return Point(lam, np.array(x, dtype=float), ev.J, tangent, gap, alphas, end_mode, float(np.max(np.abs(ev.G))),
                 iterations, ev.A, ev.derivation)


def _z(problem, p: Point, scale) -> np.ndarray:
    return np.concatenate([p.x / scale, [p.lam / problem.span]])


def _step(problem, p: Point, ds, periods, scale, settings) -> Point | None:
    """The point at arclength ds from p along its tangent, corrected; None when it fails."""
    found = _corrected(problem, p, ds, periods, scale, settings)
    return None if found is None else _completed(problem, p, found, periods, scale)


def _corrected(problem, p: Point, ds, periods, scale, settings) -> _Corrected | None:
    """The orbit at arclength ds from p along its tangent, corrected, without its derivatives;
    None when the corrector fails."""
    z_pred = _z(problem, p, scale) + ds * p.tangent
    return _correct(problem, z_pred, p.tangent, p.derivatives, p.mode, periods, scale, settings)


def _completed(problem, p: Point, found: _Corrected, periods, scale) -> Point | None:
    """The corrected orbit as a Point of p's branch: its derivatives (the provider told P_n(x)
    from the run that converged: 2 n + 2 runs by finite differences) and its tangent, oriented
    along p's; None when a run fails (or the rig refuses the value)."""
    lam, x = float(found.z[2] * problem.span), found.z[:2] * scale
    try:
        ev = _evaluate(problem, lam, x, p.mode, periods, scale, found.run.value)
    except CamdynError:
        return None
    return _point(lam, x, found.run, ev, _tangent(ev.A, p.tangent), found.iterations)


# --- detection -----------------------------------------------------------------------------------
def _tests(p: Point) -> dict[str, float]:
    """The test functions at a point (2 x 2 monodromy: det(M -+ I) = det M -+ tr M + 1).  Where
    the point's derivatives are unresolved they come from the differences across the first step
    (:mod:`camdyn.orbits.derivatives`): a sign change next to such a point is located but named a
    ``multiplier_jump``, never a bifurcation (:func:`_smooth`)."""
    M = p.jacobian
    det, tr = float(np.linalg.det(M)), float(np.trace(M))
    return {"fold": float(p.tangent[2]), "branch_point": det - tr + 1.0, "period_doubling": det + tr + 1.0,
            "neimark_sacker": det - 1.0 if tr * tr - 4.0 * det < 0 else math.nan, "grazing": p.max_gap}


def _changed(a: float, b: float) -> bool:
    return math.isfinite(a) and math.isfinite(b) and a * b < 0


@dataclass
class _Bracket:
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


def _locate(problem, p: Point, q: Point, ds: float, kind: str, periods, scale, settings):
    """The sign change of ``kind``'s test function f between p and q (``ds`` apart in arclength),
    bracketed in arclength from p to ``locate_tol``: the points on both sides of the event
    (after: None when the far end is a failure).  The next trial is the secant root of the
    bracket, with the Illinois rule (the value kept at an end twice in a row is halved, so that
    both ends close in: superlinear for a smooth f) and kept ``locate_tol`` / 2 inside it; the
    midpoint where an end has no value.  Grazing has its own trials (:func:`_locate_grazing`)."""
    if kind == "grazing":
        return _locate_grazing(problem, p, q, ds, periods, scale, settings)
    bracket = _Bracket(0.0, ds, _tests(p)[kind], _tests(q)[kind], p)
    for _ in range(MAX_BISECTIONS):
        if bracket.hi - bracket.lo <= settings.locate_tol:
            break
        s = _trial(bracket.lo, bracket.hi, bracket.f_lo, bracket.f_hi, settings.locate_tol)
        r = _step(problem, p, s, periods, scale, settings)
        bracket.narrow(s, math.nan if r is None else _tests(r)[kind], r)
    return bracket.before, bracket.after


def _locate_grazing(problem, p: Point, q: Point, ds: float, periods, scale, settings):
    """The grazing between p and q bracketed as :func:`_locate` does, the trials aimed from the
    contact side (:func:`_grazing_trial`): its test function, the largest gap, has a corner at
    the event (the contact's deflection before it, the flight's height after), so secant trials
    across the bracket crawl in from the flat side, while on the contact side (gap < 0) it is
    smooth, the contact orbit continuing through the event.  A trial needs the gap alone: it is
    a corrected orbit without derivatives (6 runs less by finite differences); the two points
    returned get theirs (after: None when a run fails there, as for a failed step; before: p
    then, the bracket's start, the location lost for that rare case)."""
    bracket = _Bracket(0.0, ds, p.max_gap, q.max_gap, p)
    contact = [(0.0, p.max_gap) if p.max_gap < 0 else (ds, q.max_gap)]
    far = 1.0 if p.max_gap < 0 else -1.0
    for _ in range(MAX_BISECTIONS):
        if bracket.hi - bracket.lo <= settings.locate_tol:
            break
        s = _grazing_trial(bracket.lo, bracket.hi, contact[-3:], far, settings.locate_tol)
        r = _corrected(problem, p, s, periods, scale, settings)
        f = math.nan if r is None else _gap(r.run)[0]
        if f < 0:
            contact.append((s, f))
        bracket.narrow(s, f, r)
    before = bracket.before if bracket.before is p else _completed(problem, p, bracket.before, periods, scale)
    after = None if bracket.after is None else _completed(problem, p, bracket.after, periods, scale)
    return before or p, after


def _grazing_trial(lo: float, hi: float, contact: list, far: float, tol: float) -> float:
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


def _trial(lo: float, hi: float, f_lo: float, f_hi: float, tol: float) -> float:
    """The secant root of f over [lo, hi] (the midpoint when an end has no finite value), kept
    tol / 2 inside the bracket so that each trial shrinks it by at least that."""
    if not (math.isfinite(f_lo) and math.isfinite(f_hi)) or f_lo == f_hi:
        return 0.5 * (lo + hi)
    s = lo - f_lo * (hi - lo) / (f_hi - f_lo)
    return min(max(s, lo + 0.5 * tol), hi - 0.5 * tol)


def _detect(problem, p: Point, q: Point, ds: float, where: tuple[int, int], periods, scale, settings):
    """The events between consecutive points p and q (ds apart), located; ``where``: (branch, index of p)."""
    f0, f1 = _tests(p), _tests(q)
    events = []
    for kind in f0:
        if not _changed(f0[kind], f1[kind]):
            continue
        if kind == "branch_point" and _changed(f0["fold"], f1["fold"]):
            continue                                   # the +1 multiplier of the fold itself
        before, after = _locate(problem, p, q, ds, kind, periods, scale, settings)
        e = after or before
        mu = sorted_multipliers(e.jacobian) if e.resolved else np.full(2, np.nan, dtype=complex)
        named = kind if _smooth(kind, before, after) else "multiplier_jump"
        events.append((Event(named, e.lam, e.x, where[0], where[1], mu, e.alpha_revolutions, e.max_gap), e, p, q))
    return events


def _smooth(kind: str, before: Point, after: Point | None) -> bool:
    """Whether an event of the multipliers is a bifurcation: at the located orbit the kind's
    critical multiplier (+1, -1, modulus 1) is within CRITICAL, and the multipliers on both
    sides of the bracket (``locate_tol`` apart) differ by less than CRITICAL (they do not jump)."""
    if kind == "grazing":
        return True
    e = after or before
    if not (e.resolved and before.resolved):
        return False                        # the switches change within a difference step: not smooth
    mu = sorted_multipliers(e.jacobian)
    distance = {"fold": np.abs(mu - 1.0), "branch_point": np.abs(mu - 1.0), "period_doubling": np.abs(mu + 1.0),
                "neimark_sacker": np.abs(np.abs(mu) - 1.0)}[kind]
    jump = 0.0 if after is None else float(np.max(np.abs(mu - sorted_multipliers(before.jacobian))))
    return float(np.min(distance)) < CRITICAL and jump < CRITICAL


# --- following a branch ----------------------------------------------------------------------------
def _clipped(problem, p: Point, ds: float) -> float:
    """ds shortened so that the predictor stops at the end of the range it moves toward."""
    t_lam = p.tangent[2]
    if abs(t_lam) < 1e-12:
        return ds
    bound = max(problem.start, problem.end) if t_lam > 0 else min(problem.start, problem.end)
    reach = (bound - p.lam) / problem.span / t_lam
    return min(ds, reach) if reach > 0 else ds


def _left(problem, lam: float) -> ContinuationOutcome | None:
    """END_REACHED or LEFT_RANGE once lambda is at or past an end of the range (1e-9 of it)."""
    slack = 1e-9 * problem.span
    for bound, outcome in ((problem.end, ContinuationOutcome.END_REACHED),
                           (problem.start, ContinuationOutcome.LEFT_RANGE)):
        other = problem.start if bound == problem.end else problem.end
        if (lam - bound) * math.copysign(1.0, bound - other) >= -slack:
            return outcome
    return None


def _follow(problem, branch: Branch, index: int, first: Point, scale, settings, events: list):
    """Continue ``branch`` from ``first`` until it leaves the range, fails, or max_points."""
    p, ds = first, settings.step
    branch.points.append(p)
    while True:
        if len(branch.points) >= settings.max_points:
            branch.outcome = ContinuationOutcome.MAX_POINTS
            return
        step = _clipped(problem, p, ds)
        q = _step(problem, p, step, branch.periods, scale, settings)
        if q is None:
            if ds <= settings.min_step:
                branch.outcome = ContinuationOutcome.STEP_TOO_SMALL
                branch.message = f"at {problem.parameter} = {p.lam:.8g}"
                return
            ds = max(ds / 2.0, settings.min_step)
            continue
        where = (index, len(branch.points) - 1)
        events += _detect(problem, p, q, step, where, branch.periods, scale, settings)
        branch.points.append(q)
        done = _left(problem, q.lam)
        if done is not None:
            branch.outcome = done
            return
        if q.iterations <= settings.easy_iterations:
            ds = min(1.5 * ds, settings.max_step)
        p = q


def _first_point(problem, lam, x, mode, periods, scale, direction: float) -> Point:
    """The point (lam, x) with its tangent oriented toward increasing lambda times ``direction``."""
    run = _orbit_run(problem, lam, x, mode, periods)
    ev = _evaluate(problem, lam, x, mode, periods, scale, run.value)
    return _point(lam, x, run, ev, _tangent(ev.A, np.array([0.0, 0.0, direction])), 0)


def _switch(problem, e: Point, p: Point, q: Point, periods: int, scale, settings):
    """The period-2n orbit next to a period doubling located at ``e`` between p and q: Newton on
    P_2n from the P_n orbit +/- eps v (v the eigenvector of the multiplier near -1, eps in
    SWITCH_OFFSETS times the motion's scale), on the side where P_n is unstable first.  Accepted
    when P_n(x) differs from x by more than 1000 tol (scaled): not the P_n orbit itself.
    Returns (lambda, x, mode) or None."""
    mu, V = np.linalg.eig(e.jacobian)
    v = V[:, int(np.argmin(np.abs(mu + 1.0)))].real
    v = v / np.max(np.abs(v / scale))
    for side in sorted((p, q), key=lambda r: -np.max(np.abs(sorted_multipliers(r.jacobian)))):
        try:
            doubled = problem.section_map(side.lam, side.mode, 2 * periods)
            single = problem.section_map(side.lam, side.mode, periods)
        except CamdynError:
            continue
        provider = problem.jacobian(doubled, scale)
        for eps in SWITCH_OFFSETS:
            for sign in (1.0, -1.0):
                found = newton(doubled, provider, side.x + sign * eps * v, scale, ShootingSettings(settings.tol, 20))
                if not found.outcome.ok:
                    continue
                try:
                    apart = np.max(np.abs(single(found.x) - found.x) / scale)
                except MapFailure:
                    continue
                if apart > 1e3 * settings.tol:
                    return side.lam, found.x, side.mode
    return None


def _start(problem: Problem, warmup_revolutions: int, settings):
    """The first orbit, by shooting at the start value: (point, scale) or (None, message)."""
    model = problem.model(problem.start)
    rig = model.rig
    orbit = periodic_orbit(rig, problem.scene, model.cam, periods=problem.periods,
                           phase=problem.phase_fraction * model.period, warmup_revolutions=warmup_revolutions,
                           settings=ShootingSettings(settings.tol, max(20, settings.max_corrector)), options=problem.options,
                           jacobian=problem.jacobian, backend=problem.backend)
    if not (orbit.ok or orbit.outcome is OrbitOutcome.MULTIPLIERS_UNRESOLVED):   # the orbit, not its multipliers
        return None, orbit.message
    direction = math.copysign(1.0, problem.end - problem.start)
    try:
        first = _first_point(problem, problem.start, orbit.state, orbit.mode_index, problem.periods,
                             orbit.scale, direction)
    except MapFailure as failure:
        return None, str(failure)
    return first, orbit.scale


def _note_unresolved(problem: Problem, branch: Branch) -> None:
    """Say in the branch's message where its derivatives were unresolved (no multipliers, no
    events of the multipliers told there: :func:`_tests`)."""
    lost = [p.lam for p in branch.points if not p.resolved]
    if lost:
        branch.message += (f"; derivatives unresolved at {len(lost)} of {len(branch.points)} points "
                           f"({problem.parameter} {min(lost):.8g} to {max(lost):.8g}): no multipliers there, and "
                           "an event next to them is a multiplier_jump (the switches change within a difference step)")


def _run(problem: Problem, settings: ContinuationSettings, warmup_revolutions: int):
    """Every branch (the first, then those switched to at period doublings) and the events."""
    first, scale = _start(problem, warmup_revolutions, settings)
    if first is None:
        return [Branch(problem.periods, outcome=ContinuationOutcome.START_FAILED, message=scale)], [], None
    branches, events, queue = [], [], [(Branch(problem.periods), first, 0)]
    while queue:
        branch, first, depth = queue.pop(0)
        index = len(branches)
        branches.append(branch)
        found: list = []
        _follow(problem, branch, index, first, scale, settings, found)
        first_event = len(events)
        events += [f[0] for f in found]
        _note_unresolved(problem, branch)
        for k, (event, e, p, q) in enumerate(found):
            if event.kind != "period_doubling" or depth >= settings.switch_depth:
                continue
            switched = _switch(problem, e, p, q, branch.periods, scale, settings)
            if switched is None:
                branch.message += f"; no period-{2 * branch.periods} orbit found at the period doubling " \
                                  f"at {event.lam:.8g}"
                continue
            lam, x, mode = switched
            try:
                start = _first_point(problem, lam, x, mode, 2 * branch.periods, scale,
                                     math.copysign(1.0, lam - event.lam))
            except MapFailure:
                continue
            queue.append((Branch(2 * branch.periods, parent=index, origin=first_event + k), start, depth + 1))
    return branches, events, scale


# --- the public function ---------------------------------------------------------------------------
def _check(rig, scene, parameter, start, end, speed_rpm, periods, phase_fraction, settings):
    if not isinstance(rig, Rig):
        raise ParameterError("rig", rig, "a camdyn.Rig")
    if not isinstance(scene, Scene) or scene.motion != "constant":
        raise ParameterError("scene", scene, "a camdyn.Scene with motion 'constant' (a cam at constant speed)")
    names = [p.name for p in PARAMETERS]
    if parameter != SPEED and parameter not in names:
        raise ParameterError("parameter", parameter, f"'{SPEED}' or a rig parameter ({', '.join(names)})")
    for name, v in (("start", start), ("end", end)):
        if isinstance(v, bool) or not isinstance(v, (int, float, np.floating)) or not math.isfinite(v):
            raise ParameterError(name, v, "a finite real number")
    if start == end:
        raise ParameterError("end", end, f"a value other than start ({start})")
    if parameter == SPEED:
        if speed_rpm is not None:
            raise ParameterError("speed_rpm", speed_rpm, "None when the speed itself is continued")
        if not start * end > 0:
            raise ParameterError("end", end, "a speed of the same sign as start, and neither zero (rev/min)")
    elif isinstance(speed_rpm, bool) or not isinstance(speed_rpm, (int, float)) or not speed_rpm != 0 \
            or not math.isfinite(speed_rpm):
        raise ParameterError("speed_rpm", speed_rpm, f"a nonzero cam speed (rev/min) to continue {parameter} at")
    if isinstance(periods, bool) or not isinstance(periods, int) or not 1 <= periods <= 50:
        raise ParameterError("periods", periods, "an integer, 1 <= periods <= 50")
    if isinstance(phase_fraction, bool) or not isinstance(phase_fraction, (int, float)) \
            or not 0 <= phase_fraction < 1:
        raise ParameterError("phase_fraction", phase_fraction, "0 <= phase_fraction < 1 (of the cam period)")
    if not isinstance(settings, ContinuationSettings):
        raise ParameterError("settings", settings, "a camdyn.orbits.continuation.ContinuationSettings")


def continue_orbit(rig: Rig, scene: Scene, parameter: str, start: float, end: float, *,
                 speed_rpm: float | None = None, periods: int = 1, phase_fraction: float = 0.0,
                 warmup_revolutions: int = 20, settings: ContinuationSettings = ContinuationSettings(),
                 options: SolverOptions = DEFAULT_OPTIONS, jacobian=finite_differences,
                 backend: str = "compiled"):
    """Follow the branch of period-``periods`` orbits through the orbit found at ``start`` as
    ``parameter`` goes toward ``end``; detect and locate folds, branch points, period doublings,
    Neimark-Sacker bifurcations and grazing, and switch to the doubled branches.

    ``parameter``: ``"speed_rpm"`` (the cam speed, rev/min), or a rig parameter by name (SI),
    continued at the constant cam speed ``speed_rpm``.  The first orbit is found by
    :func:`camdyn.periodic_orbit` after ``warmup_revolutions`` from the static equilibrium.
    ``phase_fraction``: the section's time after each revolution's start, a fraction of T
    (0 gives the sections of :func:`camdyn.sweep.api.bifurcation`; choose another where the
    orbit is near a switching surface at 0).  ``jacobian(map, scale)`` makes the Jacobian
    provider (any :class:`camdyn.orbits.section_map.JacobianProvider`).  Raises only on bad input; how
    each branch ended is in the result (:class:`ContinuationOutcome`).

    Returns an ``xarray.Dataset`` described in :func:`branch_dataset`.
    """
    _check(rig, scene, parameter, start, end, speed_rpm, periods, phase_fraction, settings)
    problem = Problem(rig, scene, parameter, float(start), float(end), speed_rpm, periods, float(phase_fraction),
                      options, jacobian, backend)
    problem.model(problem.start)                 # a rig value the rig refuses raises here
    problem.model(problem.end)
    branches, events, scale = _run(problem, settings, warmup_revolutions)
    return branch_dataset(problem, branches, events, scale)


def _unit(parameter: str) -> str:
    return "rev/min" if parameter == SPEED else next(p.unit for p in PARAMETERS if p.name == parameter)


def branch_dataset(problem: Problem, branches: list, events: list, scale=None):
    """The branches and events as an ``xarray.Dataset``.

    Dims: ``point`` (every orbit of every branch, branch by branch, in the order continued),
    ``multiplier`` (2, by decreasing modulus), ``revolution`` (n of the longest period, NaN
    beyond a point's own), ``event``, ``branch`` (a coordinate: 0, 1, ...).  Per point:
    ``lambda`` (the parameter, its unit), ``alpha`` and ``alpha_dot`` at the section,
    ``multiplier_real``/``_imag``/``_modulus`` (NaN where unresolved), ``resolved`` (the point's
    derivatives passed the rule of :mod:`camdyn.orbits.derivatives`), ``stable`` (resolved and every
    ``|mu| < 1``), ``jacobian_provider`` (code into attrs ``providers``), ``difference_step``
    (the central-difference steps, dim ``difference``: alpha rad, alpha_dot rad/s, lambda; NaN
    where not by differences), ``max_gap`` (the largest psi_i over the orbit, m: < 0 in
    permanent contact), ``point_branch`` (the branch it is on), ``periods``, ``mode`` (code into
    attrs ``modes``), ``residual``, ``alpha_revolution`` (alpha at the starts of the orbit's
    revolutions: the points of the brute-force diagram).  Per event: ``event_kind`` (code into
    ``event_kinds``), ``event_lambda``, ``event_alpha``, ``event_alpha_dot``, ``event_branch``,
    ``event_point`` (the point just before it), ``event_max_gap``, ``event_multiplier_real``/
    ``_imag``, ``event_alpha_revolution``.  Per branch: ``branch_periods``, ``branch_parent``
    (-1: none), ``branch_origin`` (the event it was switched to at, -1: none: a period-doubled
    branch is drawn from there), ``branch_outcome`` (code into ``outcomes``), and the messages as
    attrs ``branch_<i>_message``; attrs ``scale_alpha`` (rad) and ``scale_alpha_dot`` (rad/s): the
    size of the motion at the start, the residual's scale.
    """
    import xarray as xr

    unit, outcomes = _unit(problem.parameter), list(ContinuationOutcome)
    n_rev = max([b.periods for b in branches] + [1])
    providers = sorted({p.derivation.provider for b in branches for p in b.points})
    data = {**_point_variables(problem, branches, unit, n_rev, providers),
            **_event_variables(problem, branches, events, unit, n_rev), **_branch_variables(branches, outcomes)}
    s = np.full(2, np.nan) if scale is None else np.asarray(scale, dtype=float)
    attrs = {"parameter": problem.parameter, "parameter_units": unit, "start": problem.start, "end": problem.end,
             "speed_rpm": problem.speed_rpm if problem.speed_rpm is not None else math.nan,
             "phase_fraction": problem.phase_fraction, "rig": problem.rig.name, "scene": problem.scene.slug,
             "modes": " ".join(problem.model(problem.start).kernels.MODES), "event_kinds": " ".join(EVENTS),
             "outcomes": " ".join(o.name for o in outcomes), "providers": " ".join(providers),
             "scale_alpha": float(s[0]), "scale_alpha_dot": float(s[1])}
    for i, b in enumerate(branches):
        attrs[f"branch_{i}_message"] = f"{b.outcome.message}" + (f" ({b.message.strip('; ')})" if b.message else "")
    return xr.Dataset(data, coords={"branch": np.arange(len(branches))}, attrs=attrs)


def _branch_variables(branches: list, outcomes: list) -> dict:
    B = ("branch",)
    return {
        "branch_periods": (B, np.array([b.periods for b in branches], dtype=int),
                           {"long_name": "period n of the branch's orbits, in cam periods"}),
        "branch_parent": (B, np.array([b.parent for b in branches], dtype=int),
                          {"long_name": "the branch it was switched from (-1: none)"}),
        "branch_origin": (B, np.array([b.origin for b in branches], dtype=int),
                          {"long_name": "the event it was switched to at (index into event; -1: none)"}),
        "branch_outcome": (B, np.array([outcomes.index(b.outcome) for b in branches], dtype=int),
                           {"long_name": "how the branch ended (index into the attribute outcomes)"}),
    }


def _point_variables(problem: Problem, branches: list, unit: str, n_rev: int, providers: list) -> dict:
    points = [p for b in branches for p in b.points]
    resolved = np.array([p.resolved for p in points], dtype=bool)
    mu = np.array([sorted_multipliers(p.jacobian) for p in points]).reshape(len(points), 2)
    mu[~resolved] = np.nan
    counts = [len(b.points) for b in branches]
    P, PM = ("point",), ("point", "multiplier")
    return {
        "lambda": (P, np.array([p.lam for p in points]), {"units": unit, "long_name": problem.parameter}),
        "alpha": (P, np.array([p.x[0] for p in points]), {"units": "rad", "long_name": "alpha at the section"}),
        "alpha_dot": (P, np.array([p.x[1] for p in points]), {"units": "rad/s",
                                                              "long_name": "alpha_dot at the section"}),
        "multiplier_real": (PM, mu.real, {"units": "1", "long_name": "Floquet multiplier, real part"}),
        "multiplier_imag": (PM, mu.imag, {"units": "1", "long_name": "Floquet multiplier, imaginary part"}),
        "multiplier_modulus": (PM, np.abs(mu), {"units": "1", "long_name": "|Floquet multiplier|"}),
        "resolved": (P, resolved, {"long_name": "the derivatives are resolved (camdyn.orbits.derivatives): multipliers given"}),
        "stable": (P, resolved & np.all(np.abs(mu) < 1.0, axis=1),
                   {"long_name": "resolved and every |multiplier| < 1"}),
        "jacobian_provider": (P, np.array([providers.index(p.derivation.provider) for p in points], dtype=int),
                              {"long_name": "the provider of dP/dx (index into the attribute providers)"}),
        "difference_step": (("point", "difference"), np.array([p.derivation.steps for p in points]).reshape(-1, 3),
                            {"long_name": "central-difference steps in alpha (rad), alpha_dot (rad/s) and the "
                                          "parameter (its unit); NaN: not by differences"}),
        "max_gap": (P, np.array([p.max_gap for p in points]),
                    {"units": "m", "long_name": "largest gap psi_i over the orbit (Eq. 6); < 0: deflection, "
                                                "the follower never leaves the cam"}),
        "point_branch": (P, np.repeat(np.arange(len(branches)), counts), {"long_name": "the branch of the point"}),
        "periods": (P, np.repeat([b.periods for b in branches], counts),
                    {"long_name": "period n of the orbit, in cam periods"}),
        "mode": (P, np.array([p.mode for p in points], dtype=int),
                 {"long_name": "mode at the section (index into the attribute modes)"}),
        "residual": (P, np.array([p.residual for p in points]), {"units": "1", "long_name": "scaled residual"}),
        "alpha_revolution": (("point", "revolution"), _padded([p.alpha_revolutions for p in points], n_rev),
                             {"units": "rad", "long_name": "alpha at the starts of the orbit's revolutions "
                                                           "(the brute-force diagram's sections)"}),
    }


def _event_variables(problem: Problem, branches: list, events: list, unit: str, n_rev: int) -> dict:
    offsets = np.cumsum([0] + [len(b.points) for b in branches])
    E, EM = ("event",), ("event", "multiplier")
    mu = np.array([e.multipliers for e in events], dtype=complex).reshape(-1, 2)
    return {
        "event_kind": (E, np.array([EVENTS.index(e.kind) for e in events], dtype=int),
                       {"long_name": "event kind (index into the attribute event_kinds)"}),
        "event_lambda": (E, np.array([e.lam for e in events]), {"units": unit, "long_name": problem.parameter}),
        "event_alpha": (E, np.array([e.x[0] for e in events]), {"units": "rad"}),
        "event_alpha_dot": (E, np.array([e.x[1] for e in events]), {"units": "rad/s"}),
        "event_branch": (E, np.array([e.branch for e in events], dtype=int), {"long_name": "the branch of the event"}),
        "event_point": (E, np.array([offsets[e.branch] + e.point for e in events], dtype=int),
                        {"long_name": "index of the point just before the event"}),
        "event_alpha_revolution": (("event", "revolution"), _padded([e.alpha_revolutions for e in events], n_rev),
                                   {"units": "rad", "long_name": "alpha at the starts of the revolutions at the event"}),
        "event_max_gap": (E, np.array([e.max_gap for e in events]),
                          {"units": "m", "long_name": "largest gap psi_i over the orbit at the event (0 at grazing)"}),
        "event_multiplier_real": (EM, mu.real, {"units": "1"}),
        "event_multiplier_imag": (EM, mu.imag, {"units": "1"}),
    }


def _padded(rows, width: int) -> np.ndarray:
    out = np.full((len(rows), width), np.nan)
    for i, row in enumerate(rows):
        out[i, :row.size] = row
    return out


def events_table(ds) -> list[tuple[str, float, int, int]]:
    """The events of a :func:`continue_orbit` Dataset as (kind, lambda, branch, point) rows."""
    kinds = ds.attrs["event_kinds"].split()
    return [(kinds[int(k)], float(lam), int(b), int(p)) for k, lam, b, p in
            zip(ds["event_kind"].values, ds["event_lambda"].values, ds["event_branch"].values,
                ds["event_point"].values)]


__all__ = ["continue_orbit", "ContinuationSettings", "ContinuationOutcome", "branch_dataset", "events_table",
           "Problem", "Point", "Branch", "Event", "SPEED", "EVENTS", "GAP_SAMPLES"]
