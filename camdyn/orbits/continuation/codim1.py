"""Fold, period-doubling and corner-impact curves in two parameters: the extended system, its
steps, its Dataset.

A fold (a multiplier through +1) or a period doubling (through -1) of a period-1 orbit is a
codimension-1 point, and so is a corner impact (an impact of a rigid follower landing on a
junction of a cam of arcs: :mod:`.corners`): with two parameters they form curves, the unknowns
z = (x, lambda1, lambda2) solving the defining system (Kuznetsov, *Elements of Applied
Bifurcation Theory*, 3rd ed., Springer 2004, Ch. 10: the test function appended to the orbit's
equations)::

    P(x; lambda) - x = 0
    det(M -+ I) = 0               (M = dP/dx; - for a fold, + for a period doubling)
    phi_i - a_j - s margin = 0    (a corner impact: impact i's landing angle by junction j)

scaled as the branch's z (x / s, lambda1 / sigma1, lambda2 / sigma2), the test's row
multiplied by tol / DET_TOL (a determinant) or tol / ANGLE_TOL (an angle, rad).  A corner impact
is followed for the impact and junction it was located with (:class:`Corner`; the impacts are
matched by their order in the period from the section, so the curve ends where their number
changes), held ANGLE_MARGIN on the side s it was located from: on the corner-impact set itself the
map's Jacobian jumps (the arc the impact lands on changes), and its differences would straddle it;
a margin to one side lets the differences' rule (:mod:`camdyn.orbits.derivatives`) shrink its steps
onto that side, where the map is smooth.  Pseudo-arclength on it is the grazing curve's loop
(:func:`.grazing_curve.follow`) with this module's step.

**Derivatives.**  The orbit's rows are the branch's (:func:`.corrector.evaluate`: dP/dx from the
problem's Jacobian provider, dP/dlambda1 and dP/dlambda2 by central differences under the rule
of :mod:`camdyn.orbits.derivatives`); the determinant's row by central differences of det(M -+ I)
with M from the provider at x +- h s_j and lambda +- h sigma, h = DET_STEP: second derivatives
of P, whose noise (M's, ~rtol^(2/3) of its scale by finite differences) is divided by h.
"""
from __future__ import annotations

import math
from dataclasses import dataclass, field
from typing import NamedTuple

import numpy as np

from ...errors import CamdynError
from ..derivatives import finite_differences
from ..section_map import derivative_at
from ..shooting import sorted_multipliers
from .corners import distance_of, landings, near_bound, signed_distances
from .corrector import bordered_step, chord, d_lambda, evaluate, gap, orbit_run, tangent
from .events import Bracket, grazing_bracket
from .grazing_curve import CODIM2, SIGNS, Codim2, Ended, GrazingOutcome, codim2_name, critical_det
from .grazing_dataset import codim2_variables, common_attributes, unit
from .problem import N_STATE, SPEED, ContinuationSettings, Leg as BranchLeg, Problem, TwoParameters

#: the determinant's tolerance: M by finite differences carries ~rtol^(2/3) (2e-7) of its scale,
#: a determinant of 2 x 2 entries of order one twice that; DET_TOL leaves a margin of 50
DET_TOL = 1e-5
#: the relative step of the determinant's differences (its truncation error ~DET_STEP^2, 1e-6;
#: M's noise over it ~2e-4 of the derivative): the default of ``Codim1System.det_step``, for M by
#: finite differences.  Where det(M -+ I) varies on a scale below it (a weakly damped stiff contact,
#: whose M changes on the scale of the contact's deflection, ~1e-3 of the motion's size), a
#: smaller step with M from the tangent dynamics (whose noise is ~rtol) resolves it
DET_STEP = 1e-3
#: the corner impact's tolerance on its landing angle (rad): an impact time ~1e-9 / Omega_c, far
#: above the engine's location of the impact (EventSettings.xtol, 1e-14 s)
ANGLE_TOL = 1e-9
#: the corner impact's margin (rad): its orbit is held this far from the junction, on the side it
#: was located from; the curve so offset, by margin over the size of d phi / d lambda1 in lambda1 (0.006 rev/min,
#: 1.8e-5 of the speed, on the second rig), is reported on the corner-impact set too, one Newton step
#: across the margin at the same lambda2 (:func:`free_at_corner`)
ANGLE_MARGIN = 1e-6
#: the relative step of the landing angle's differences: its change over it (~1e-7 rad) stays well
#: inside the margin, on the smooth side
ANGLE_STEP = 1e-8
#: the kinds of curve this module follows: the determinant's (grazing_curve.SIGNS) and the corner impact's
CORNER = "corner_impact"
KINDS = tuple(SIGNS) + (CORNER,)


class Corner(NamedTuple):
    """Which corner impact a curve follows: impact ``impact`` (by order from the section) of an orbit
    with ``impacts`` of them, on junction ``junction`` (an index of :func:`.corners.profile_junctions`),
    from the ``side`` (+1 or -1) of the signed distance it was located on."""

    impacts: int
    impact: int
    junction: int
    side: float


@dataclass(frozen=True, kw_only=True)
class Codim1System(TwoParameters):
    """What is continued (:class:`.problem.TwoParameters`), with the ``kind`` (one of
    :data:`KINDS`), the Jacobian provider of dP/dx, the relative step of the determinant's
    differences ``det_step`` (:data:`DET_STEP`) and, for a corner impact, which one (``corner``)."""

    kind: str
    jacobian: object = finite_differences
    det_step: float = DET_STEP
    corner: Corner | None = None

    @property
    def test_step(self) -> float:
        """The relative step of the test function's differences: det_step, or ANGLE_STEP."""
        return ANGLE_STEP if self.kind == CORNER else self.det_step

    def along(self, name: str, free: float, lam: float, sigma: float) -> Problem:
        """The branch problem in ``name`` (lambda1 or lambda2) with the other held, its span sigma."""
        held = (self.parameter, lam) if name == self.free else (self.free, free)
        value = free if name == self.free else lam
        rig = self.rig if held[0] == SPEED else self.rig.replace(**{held[0]: held[1]})
        speed = held[1] if held[0] == SPEED else (None if name == SPEED else self.speed_rpm)
        return Problem(rig, self.scene, name, value, value + sigma, speed, 1, self.phase_fraction, self.options,
                       self.jacobian, self.backend)


class Layout(NamedTuple):
    scale: np.ndarray
    sigma_free: float
    sigma_range: float

    def z(self, x, free: float, lam: float) -> np.ndarray:
        return np.concatenate([np.asarray(x) / self.scale, [free / self.sigma_free, lam / self.sigma_range]])

    def split(self, z) -> tuple[np.ndarray, float, float]:
        return z[:N_STATE] * self.scale, float(z[N_STATE] * self.sigma_free), float(z[N_STATE + 1] * self.sigma_range)


@dataclass(frozen=True, eq=False)
class CurveLeg:
    """What every step shares (the interface of :func:`.grazing_curve.follow`)."""

    system: Codim1System
    layout: Layout
    settings: ContinuationSettings
    start: float = field(init=False)
    end: float = field(init=False)
    span: float = field(init=False)

    def __post_init__(self):
        for name in ("start", "end", "span"):
            object.__setattr__(self, name, getattr(self.system, name))

    def branch(self, name: str, free: float, lam: float) -> BranchLeg:
        sigma = self.layout.sigma_free if name == self.system.free else self.layout.sigma_range
        return BranchLeg(self.system.along(name, free, lam, sigma), 1, self.layout.scale, self.settings)


class Evaluation(NamedTuple):
    residual: np.ndarray
    M: np.ndarray
    run: object
    mode: int


class Codim1Point(NamedTuple):
    """One orbit of the curve: z, lambda1, lambda2, x, M, the unit tangent, the scaled Jacobian
    A, its evaluation, the corrector's iterations, the tangent's change per arclength, and the
    prediction's error (not estimated here: NaN; :func:`.grazing_curve.grown`)."""

    z: np.ndarray
    free: float
    lam: float
    x: np.ndarray
    M: np.ndarray
    tangent: np.ndarray
    A: np.ndarray
    evaluation: Evaluation
    iterations: int
    curvature: np.ndarray
    miss: float = math.nan


def _test(leg: CurveLeg, z, mode, run=None) -> float:
    """The test function's row at z, scaled (tol / DET_TOL or tol / ANGLE_TOL): det(M -+ I), or the
    corner impact's landing angle less its junction's less the margin on its side (rad; raises
    CamdynError where the orbit has another number of impacts).  ``run``: the orbit's run at z,
    where it is made already."""
    system, (x, free, lam) = leg.system, leg.layout.split(z)
    if system.kind != CORNER:
        M = _monodromy(leg, x, free, lam, mode, None if run is None else run.value)
        return critical_det(system.kind, M) * leg.settings.tol / DET_TOL
    run = orbit_run(leg.branch(system.free, free, lam), free, x, mode) if run is None else run
    corner = system.corner
    d = distance_of(landings(run), corner.impacts, (corner.impact, corner.junction))
    if not math.isfinite(d):
        raise CamdynError(f"the orbit has not {corner.impacts} impacts a period: the corner impact's impact is lost")
    return (d - corner.side * ANGLE_MARGIN) * leg.settings.tol / ANGLE_TOL


def _monodromy(leg: CurveLeg, x, free: float, lam: float, mode, base=None) -> np.ndarray:
    branch = leg.branch(leg.system.free, free, lam)
    provider = leg.system.jacobian(branch.section_map(free, mode), leg.layout.scale)
    return derivative_at(provider, x, base).jacobian


def residual(leg: CurveLeg, z, mode) -> Evaluation:
    """The scaled residual at z (raises CamdynError)."""
    x, free, lam = leg.layout.split(z)
    run = orbit_run(leg.branch(leg.system.free, free, lam), free, x, mode)
    M = _monodromy(leg, x, free, lam, mode, run.value)
    return Evaluation(np.append((run.P - x) / leg.layout.scale, _test(leg, z, mode, run)), M, run, mode)


def jacobian(leg: CurveLeg, z, e: Evaluation) -> np.ndarray:
    """The scaled Jacobian (n + 1) x (n + 2) at z (see the module docstring)."""
    x, free, lam = leg.layout.split(z)
    A = np.zeros((N_STATE + 1, N_STATE + 2))
    A[:N_STATE, :N_STATE + 1] = evaluate(leg.branch(leg.system.free, free, lam), free, x, e.mode, e.run.value).A
    dP, _, _ = d_lambda(leg.branch(leg.system.parameter, free, lam), lam, x, e.mode, e.run.value)
    A[:N_STATE, N_STATE + 1] = dP * leg.layout.sigma_range / leg.layout.scale
    for j in range(N_STATE + 2):
        h = leg.system.test_step
        plus, minus = z.copy(), z.copy()
        plus[j] += h
        minus[j] -= h
        A[N_STATE, j] = (_test(leg, plus, e.mode) - _test(leg, minus, e.mode)) / (2 * h)
    if not np.all(np.isfinite(A)):
        raise CamdynError("the extended system's derivatives are not finite")
    return A


def _point(leg: CurveLeg, z, e: Evaluation, direction, iterations: int) -> Codim1Point:
    A = jacobian(leg, z, e)
    x, free, lam = leg.layout.split(z)
    return Codim1Point(z, free, lam, x, e.M, tangent(A, direction), A, e, iterations, np.zeros(N_STATE + 2))


def _residual(leg: CurveLeg, mode):
    """The chord's residual function: z -> (the scaled residual, the evaluation)."""
    def at(z):
        e = residual(leg, z, mode)
        return e.residual, e
    return at


def trial(leg: CurveLeg, p: Codim1Point, ds: float) -> Codim1Point | None:
    """The orbit at arclength ds from p by the chord method, as a point with p's derivatives and
    tangent (a trial of :func:`located`, which needs its largest gap alone): where the derivatives
    cannot be evaluated (near a grazing the determinant's differences straddle it) the chord
    keeps the last ones, the orbit itself still found; None when the chord fails."""
    def derivatives(z, e):
        try:
            return jacobian(leg, z, e)
        except CamdynError:
            return p.A
    z_pred = p.z + ds * p.tangent + 0.5 * ds * ds * p.curvature
    found = chord(_residual(leg, p.evaluation.mode), derivatives, z_pred, p.tangent, p.A, leg.settings)
    if found is None:
        return None
    z, e, iterations = found
    x, free, lam = leg.layout.split(z)
    return p._replace(z=z, free=free, lam=lam, x=x, M=e.M, evaluation=e, iterations=iterations)


def advance(leg: CurveLeg, p: Codim1Point, ds: float, final: bool = False):
    """The point at arclength ds from p (the second-order predictor and the chord corrector, as
    :func:`.grazing_curve.corrected`): a point, None, or :class:`.grazing_curve.Ended`."""
    z_pred = p.z + ds * p.tangent + 0.5 * ds * ds * p.curvature
    direction = p.tangent
    if final:
        z_pred[-1] = leg.end / leg.layout.sigma_range
        direction = np.zeros(N_STATE + 2)
        direction[-1] = 1.0
    found = chord(_residual(leg, p.evaluation.mode), lambda z, e: jacobian(leg, z, e), z_pred, direction, p.A,
                  leg.settings)
    if found is None:
        return None
    z, e, iterations = found
    try:
        q = _point(leg, z, e, p.tangent, iterations)
    except CamdynError as failure:
        return Ended(GrazingOutcome.NO_DERIVATIVES, str(failure))
    return q._replace(curvature=(q.tangent - p.tangent) / ds)


def first(leg: CurveLeg, x, free: float, mode: int) -> Codim1Point | str:
    """The bifurcation at lambda2 = start from the one-parameter branch's located orbit."""
    along = np.zeros(N_STATE + 2)
    along[-1] = math.copysign(1.0, leg.end - leg.start)
    z0 = leg.layout.z(x, free, leg.start)
    try:
        e0 = residual(leg, z0, mode)
        A0 = jacobian(leg, z0, e0)
    except CamdynError as failure:
        return f"the start orbit cannot be evaluated: {failure}"
    found = chord(_residual(leg, mode), lambda z, e: jacobian(leg, z, e), z0, along, A0, leg.settings)
    if found is None:
        return f"the extended system's corrector did not converge from the orbit at {leg.system.free} = {free:.8g}"
    try:
        return _point(leg, found[0], found[1], along, found[2])
    except CamdynError as failure:
        return f"no derivatives at the first orbit: {failure}"


def corner_of(leg: CurveLeg, x, free: float, mode: int) -> Corner | str:
    """The corner impact of the orbit from x at lambda1 = ``free``, lambda2 = start, located by the
    one-parameter continuation (its last orbit before the crossing): the impact and junction nearest
    each other (:func:`.corners.signed_distances`, within :func:`.corners.near_bound`) and the side it
    lies on; or why there is none."""
    orbit = orbit_run(leg.branch(leg.system.free, free, leg.start), free, x, mode)
    at = landings(orbit)
    if not (at.angles.size and at.junctions.size):
        return "the located orbit has no impact or its cam no junction"
    d = signed_distances(at)
    i, j = np.unravel_index(int(np.argmin(np.abs(d))), d.shape)
    if not abs(d[i, j]) < near_bound(at.junctions):
        return f"no impact of the located orbit lands near a junction (the nearest {abs(d[i, j]):.3g} rad away)"
    return Corner(int(at.angles.size), int(i), int(j), math.copysign(1.0, d[i, j]))


def free_at_corner(leg: CurveLeg, p: Codim1Point) -> float:
    """lambda1 where the corner-impact curve's point p, held ANGLE_MARGIN off the junction, would
    land its impact on it at the same lambda2: one Newton step of the system without the margin,
    ``[A; e_lambda2] dz = -(residual without the margin)`` (its error second order in the margin)."""
    margin = np.zeros(N_STATE + 1)
    margin[N_STATE] = leg.system.corner.side * ANGLE_MARGIN * leg.settings.tol / ANGLE_TOL
    along = np.zeros(N_STATE + 2)
    along[-1] = 1.0
    return leg.layout.split(p.z + bordered_step(p.A, along, -(p.evaluation.residual + margin)))[1]


def largest_gap(p: Codim1Point) -> float:
    """The largest gap psi_i over the point's orbit (m; > 0: the follower leaves the cam), from
    the run of its residual (:func:`.corrector.gap`)."""
    return gap(p.evaluation.run)[0]


def located(leg: CurveLeg, p: Codim1Point, q: Codim1Point, ds: float, index: int) -> list[Codim2]:
    """The grazing of the curve's orbit between p and q (ds apart): its largest gap changes sign,
    where the curve meets the grazing curve at the codimension-2 point named as on that curve
    (:func:`.grazing_curve.codim2_name`: the mirror of :func:`.grazing_curve.located`), located in
    arclength to ``locate_tol`` by the grazing trials from the contact side
    (:func:`.events.grazing_bracket`; each trial an orbit of the curve without derivatives,
    :func:`trial`, a failed one taken as past the grazing).  The located orbit is the last trial
    on p's side."""
    a, b = largest_gap(p), largest_gap(q)
    if not (math.isfinite(a) and math.isfinite(b) and a * b < 0):
        return []

    def at(s: float):
        r = trial(leg, p, s)
        return (math.nan, None) if r is None else (largest_gap(r), r)
    bracket = grazing_bracket(Bracket(0.0, ds, a, b, p), at, leg.settings.locate_tol)
    return [Codim2(codim2_name(leg.system.kind), bracket.before, index)]


def codim1_dataset(system: Codim1System, curve, layout):
    """The curve as an ``xarray.Dataset``: per point the two parameters by their names,
    ``alpha``, ``alpha_dot``, the multipliers, ``max_gap`` (the orbit's largest gap),
    ``residual`` and ``iterations``; dim ``codim2``: where the orbit grazes
    (:func:`located`), with the variables of :func:`.grazing_dataset.codim2_variables` and
    ``codim2_max_gap``; attrs
    ``kind``, ``codim2_kinds``, ``free``, ``parameter``, their units, the range, the scene,
    ``outcome`` and ``outcome_message``, the rig's parameters, ``camdyn_version``, ``det_step``
    (as :func:`.grazing_dataset.grazing_dataset`)."""
    import xarray as xr

    points, P, PM = curve.points, ("point",), ("point", "multiplier")
    mu = np.array([sorted_multipliers(p.M) for p in points], dtype=complex).reshape(len(points), N_STATE)
    data = {
        system.free: (P, np.array([p.free for p in points]), {"units": unit(system.free)}),
        system.parameter: (P, np.array([p.lam for p in points]), {"units": unit(system.parameter)}),
        "alpha": (P, np.array([p.x[0] for p in points]), {"units": "rad", "long_name": "alpha at the section"}),
        "alpha_dot": (P, np.array([p.x[1] for p in points]), {"units": "rad/s",
                                                             "long_name": "alpha_dot at the section"}),
        "multiplier_real": (PM, mu.real, {"units": "1"}),
        "multiplier_imag": (PM, mu.imag, {"units": "1"}),
        "max_gap": (P, np.array([largest_gap(p) for p in points]),
                    {"units": "m", "long_name": "largest psi_i over the orbit (> 0: the follower leaves the cam)"}),
        "residual": (P, np.array([float(np.max(np.abs(p.evaluation.residual))) for p in points]), {"units": "1"}),
        "iterations": (P, np.array([p.iterations for p in points], dtype=int)),
        **codim2_variables(system, curve.found, lambda at: at.free),
        "codim2_max_gap": (("codim2",), np.array([largest_gap(c.at) for c in curve.found]),
                           {"units": "m", "long_name": "largest psi_i over the located orbit (its distance "
                                                       "from grazing)"}),
    }
    scale = np.full(N_STATE, math.nan) if layout is None else layout.scale
    attrs = {**common_attributes(system, curve, scale), "kind": system.kind, "codim2_kinds": " ".join(CODIM2),
             "det_step": system.det_step,
             **({} if system.corner is None else {f"corner_{k}": v for k, v in system.corner._asdict().items()}),
             **({} if system.corner is None else {"corner_margin_rad": ANGLE_MARGIN}),
             "title": f"camdyn {system.kind} curve in ({system.free}, {system.parameter}), rig {system.rig.name}"}
    return xr.Dataset(data, attrs=attrs)
