"""A step along a branch: the run of P_n over the orbit (its largest gap from the same run),
the scaled derivatives [dG/dx, dG/dlambda] (dP/dlambda under the rule of
:mod:`camdyn.orbits.derivatives`), the tangent, and the predictor and chord/Newton corrector."""
from __future__ import annotations

import math
from typing import NamedTuple

import numpy as np

from ...engine import Trajectory
from ...errors import CamdynError
from ..derivatives import Column, Unresolved, resolved_difference
from ..section_map import MapFailure, MapValue, StroboscopicMap, derivative_at
from ..shooting import newton_matrix
from .corners import landings
from .lift_off import lift_off
from .sampled import refined_max
from .problem import N_STATE, Z_LAMBDA, Z_SIZE, Z_STATE, Derivation, Leg, Point

#: samples of psi_i per cam period for the orbit's largest gap (:data:`camdyn.orbits.continuation.GAP_SAMPLES`),
#: at the least: see :func:`gap_samples`
GAP_SAMPLES = 256
#: samples of psi_i per period of the contact's fastest vibration (the model's fastest rate): a
#: ripple of the gap at that frequency (a cam whose jerk jumps rings the contact) has its peaks
#: found by the parabola through three samples to ~(pi/16)^4 of its amplitude
RING_SAMPLES = 16


def gap_samples(model) -> int:
    """Samples of psi_i per cam period: GAP_SAMPLES, or RING_SAMPLES per period of the model's
    fastest rate at its static equilibrium where that is more.  Sampled slower, a gap that rings
    (seen: a cycloidal cam, 256 samples per period, 4.6 per ring) has its largest value missed by
    ~1e-10 m near the grazing, and the grazing found 0.2 % of the speed late, reported converged."""
    rings = model.fastest_rate.value * model.period / (2 * np.pi)
    return int(max(GAP_SAMPLES, np.ceil(RING_SAMPLES * rings)))
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


class Scaled(NamedTuple):
    """G(z) scaled, the scaled Jacobian [dG/dx, dG/dlambda] (n x n + 1), dP/dx unscaled, and how."""

    G: np.ndarray
    A: np.ndarray
    J: np.ndarray
    derivation: Derivation


class Run(NamedTuple):
    """One run of P_n from x over the orbit's n T (:func:`orbit_run`): the map, its value
    (P_n(x) and the run's switches), the run's samples, and the revolutions' starts (s) among them."""

    section_map: StroboscopicMap
    value: MapValue
    trajectory: Trajectory
    starts: np.ndarray

    @property
    def P(self) -> np.ndarray:
        return self.value.state


class Corrected(NamedTuple):
    """The corrector's orbit, before its derivatives: z (scaled), the run that converged there
    (:func:`orbit_run`), and the iterations taken."""

    z: np.ndarray
    run: Run
    iterations: int


def orbit_run(leg: Leg, lam: float, x, mode) -> Run:
    """P_n(x; lambda) by one run sampled :func:`gap_samples` times per period and at the revolutions'
    starts (raises MapFailure).  The samples do not change P_n(x), bit for bit
    (:meth:`StroboscopicMap.run`), so every run of the corrector is this one: the run that
    converges gives the orbit's largest gap (:func:`gap`), and P_n(x) to the Jacobian
    provider, without a run of their own."""
    section_map = leg.section_map(lam, mode)
    t0, t1 = section_map.t_span
    T = section_map.model.period
    samples = np.linspace(t0, t1, gap_samples(section_map.model) * leg.periods + 1)
    starts = T * (np.arange(leg.periods) + (1 if t0 > 0 else 0))    # the k T in [t0, t1)
    t_eval = np.unique(np.concatenate([samples, starts]))
    value, tr = section_map.run(x, t_eval)
    return Run(section_map, value, tr, starts)


def evaluate(leg: Leg, lam: float, x, mode, base: MapValue) -> Scaled:
    """P_n(x; lambda) - x and its derivatives, scaled (raises MapFailure); ``base``: the map's
    value at (x, lambda), from the caller's run, told to the provider (a run less by finite
    differences) and the base of the difference in lambda (:func:`d_lambda`)."""
    problem, scale = leg.problem, leg.scale
    d = derivative_at(problem.jacobian(leg.section_map(lam, mode), scale), x, base)
    dP_dlam, h, note = d_lambda(leg, lam, x, mode, base)
    A = np.empty((N_STATE, Z_SIZE))
    A[:, Z_STATE] = newton_matrix(d.jacobian, scale)
    A[:, Z_LAMBDA] = dP_dlam * problem.span / scale
    if not np.all(np.isfinite(A)):
        raise MapFailure(f"no derivatives at {problem.parameter} = {lam:.8g}: {d.note or note}")
    notes = "; ".join(n for n in (d.note, note) if n)
    how = Derivation(d.provider, np.append(d.steps, h), d.resolved and not note, notes)
    return Scaled((d.value - x) / scale, A, d.jacobian, how)


def d_lambda(leg: Leg, lam: float, x, mode, base: MapValue):
    """dP_n/dlambda at (x, lambda) by a central difference under the rule of
    :mod:`camdyn.orbits.derivatives` (the runs at lambda +- h make the base run's switches and two steps
    agree; h from ``rtol^(1/3) max(|lambda|, span)`` down to the floor ``rtol^(1/2)`` of that):
    (derivative, step, '') or, when unresolved, the secant across the largest step that ran (a
    direction for the predictor and corrector, no derivative) and the reason."""
    problem = leg.problem

    def value(offset: float) -> MapValue:
        return leg.section_map(lam + offset, mode).evaluate(x)
    column = Column.of(max(abs(lam), problem.span), problem.span / leg.scale, problem.options.rtol)
    try:
        difference, h = resolved_difference(value, base, column)
        return difference, h, ""
    except Unresolved as why:
        if why.secant is None:
            raise
        return *why.secant, f"d/d{problem.parameter}: {why}"


def tangent(A: np.ndarray, previous: np.ndarray) -> np.ndarray:
    """The unit null vector of the n x n + 1 scaled Jacobian, oriented along ``previous``."""
    t = np.linalg.svd(A)[2][-1]
    return t if float(t @ previous) >= 0 else -t


def correct(leg: Leg, z_pred, direction, A, mode) -> Corrected | None:
    """The chord method (:func:`chord`) on G(z) = 0, direction . (z - z_pred) = 0, from the
    derivatives ``A`` of the last point, each iteration one run of P_n (:func:`orbit_run`), the
    derivatives evaluated anew by :func:`evaluate` (2 n + 2 runs more with finite differences,
    told P_n(x) from the iteration's run).  Returns the converged orbit without its derivatives
    (:func:`completed` adds them), or None when it fails."""
    def residual(z):
        lam, x = leg.split(z)
        run = orbit_run(leg, lam, x, mode)
        return (run.P - x) / leg.scale, run

    def derivatives(z, run):
        lam, x = leg.split(z)
        return evaluate(leg, lam, x, mode, run.value).A
    found = chord(residual, derivatives, z_pred, direction, A, leg.settings)
    return None if found is None else Corrected(*found)


def chord(residual, derivatives, z_pred, direction, A, settings, smooth=None):
    """The pseudo-arclength corrector of any extended system: the chord method on
    ``residual(z) = 0, direction . (z - z_pred) = 0`` from the derivatives ``A`` of the last
    point, stopping at ``max |residual| <= settings.tol``.  It keeps ``A`` while each
    iteration shrinks the residual by CHORD_CONTRACTION or more and evaluates it anew at z when
    it does not (a Newton step); ``residual(z)`` gives (the scaled residual, a payload: the
    run), ``derivatives(z, payload)`` the scaled Jacobian; both raise CamdynError where they
    cannot be evaluated.  ``smooth(payload)``, when given, tells whether an iterate's residual is
    the smooth system's: one that is not (a grazing orbit's run that left the cam, whose gap is
    the flight's) is stepped from with the same derivatives, never new ones, and the next
    iterate's contraction is not measured against it.  Returns (z, payload, iterations), or None
    when it fails (an evaluation fails, the residual grows, a Newton step shrinks it by less than
    NEWTON_CONTRACTION, or ``settings.max_corrector`` is reached), before any new derivatives."""
    z, last, fresh = z_pred.copy(), math.inf, False
    for it in range(settings.max_corrector + 1):
        try:                           # MapFailure, or a rig value the rig refuses
            G, payload = residual(z)
            r = float(np.max(np.abs(G)))
            if r <= settings.tol:
                return z, payload, it
            if (fresh and not r <= NEWTON_CONTRACTION * last) or not math.isfinite(r) or (it >= 2 and r > last):
                return None
            on_side = smooth is None or smooth(payload)
            fresh = on_side and r > CHORD_CONTRACTION * last
            if fresh:
                A = derivatives(z, payload)
        except CamdynError:
            return None
        last = r if on_side else math.inf
        try:
            z = z - bordered_step(A, direction, G, direction @ (z - z_pred))
        except np.linalg.LinAlgError:
            return None
    return None


def bordered_step(A: np.ndarray, border: np.ndarray, rhs: np.ndarray, last: float = 0.0) -> np.ndarray:
    """dz solving ``[A; border] dz = [rhs; last]``: a step of an extended system (Jacobian A, one
    unknown more than rows) under one more condition on it, ``border``: the arclength hyperplane's
    direction, or a unit vector holding an unknown (raises numpy's LinAlgError where singular)."""
    return np.linalg.solve(np.vstack([A, border]), np.append(rhs, last))


def gap(run: Run):
    """The largest psi_i over the orbit (m), alpha at the starts of its revolutions, and the end
    mode, from the samples of its run."""
    model, tr = run.section_map.model, run.trajectory
    psi = model.outputs_at(tr.mode, tr.t, tr.alpha, tr.alpha_dot,
                           run.section_map.backend)[model.kernels.OUT_PSI_I]
    return refined_max(psi), tr.alpha[np.searchsorted(tr.t, run.starts)], int(tr.end_mode)


def _point(lam: float, x, run: Run, ev: Scaled, direction, iterations: int) -> Point:
    """The orbit (lam, x) as a Point: its gap, its impacts' landings and its lift-off test
    function from its run, its derivatives ``ev``, its tangent oriented along ``direction``."""
    max_gap, alphas, end_mode = gap(run)
    return Point(lam, np.array(x, dtype=float), ev.J, tangent(ev.A, direction), max_gap, alphas, end_mode,
                 float(np.max(np.abs(ev.G))), iterations, ev.A, ev.derivation, landings(run), lift_off(run))


def step(leg: Leg, p: Point, ds: float) -> Point | None:
    """The point at arclength ds from p along its tangent, corrected; None when it fails."""
    found = corrected(leg, p, ds)
    return None if found is None else completed(leg, p, found)


def corrected(leg: Leg, p: Point, ds: float) -> Corrected | None:
    """The orbit at arclength ds from p along its tangent, corrected, without its derivatives;
    None when the corrector fails."""
    z_pred = leg.z(p.lam, p.x) + ds * p.tangent
    return correct(leg, z_pred, p.tangent, p.derivatives, p.mode)


def completed(leg: Leg, p: Point, found: Corrected) -> Point | None:
    """The corrected orbit as a Point of p's branch: its derivatives (the provider told P_n(x)
    from the run that converged: 2 n + 2 runs by finite differences) and its tangent, oriented
    along p's; None when a run fails (or the rig refuses the value)."""
    lam, x = leg.split(found.z)
    try:
        ev = evaluate(leg, lam, x, p.mode, found.run.value)
    except CamdynError:
        return None
    return _point(lam, x, found.run, ev, p.tangent, found.iterations)


def first_point(leg: Leg, lam: float, x, mode, direction: float) -> Point:
    """The point (lam, x) with its tangent oriented toward increasing lambda times ``direction``
    (raises MapFailure)."""
    run = orbit_run(leg, lam, x, mode)
    ev = evaluate(leg, lam, x, mode, run.value)
    return _point(lam, x, run, ev, leg.along(direction), 0)
