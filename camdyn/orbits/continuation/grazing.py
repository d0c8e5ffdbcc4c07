"""The extended system of a grazing orbit, its residual and its derivatives.

A period-1 orbit *grazes* where its largest gap psi_i (Eq. 6) reaches zero: the follower, in
permanent contact, touches zero deflection once per revolution and leaves the cam beyond it.
With two parameters lambda = (lambda1, lambda2) (the cam speed ``speed_rpm`` or rig parameters)
the grazing orbits form a curve, the unknowns z = (x, phi_g, lambda1, lambda2) solving::

    P(x; lambda) - x = 0            (the periodic orbit, x the state at the section t0)
    psi_i(t_g) + margin = 0         (it touches zero gap at t_g = t0 + phi_g T)
    psi_i_dot(t_g) = 0              (t_g is the gap's maximum; the rate as a central
                                     difference over t_g +- WINDOW T, see WINDOW)

4 equations in 5 unknowns: a curve.  On a rigid contact the gap is 0 to rounding along the
contact orbit: psi_i is replaced by -F_n, the constraint's force, whose largest value through 0
is the lift-off, and at a corner of a cam of arcs the rate's row by the phase pinned past the
junction (:mod:`.boundary`; the names below keep the gap's).  This is the defining system of a codimension-1 boundary
continued in two parameters, the boundary's test functions appended to the orbit's equations
(Kuznetsov, *Elements of Applied Bifurcation Theory*, 3rd ed., Springer 2004, Ch. 10), here
the grazing conditions of a periodic orbit of a hybrid system (Thota & Dankowicz, TC-HAT, SIAM
J. Appl. Dyn. Syst. 7 (2008) 1283).  ``margin`` is the boundary's ``margins`` ``gap_tol`` times the gap's
scale d, the largest deflection over the first orbit: the orbit is converged on the contact side,
so its run never lifts off and its derivatives are the contact flow's.

**Scaling.**  z = (x / s, phi_g, lambda1 / sigma1, lambda2 / sigma2): s the motion's size (as
in :mod:`camdyn.orbits.shooting`), phi_g the fraction of the period, sigma2 the range of
lambda2 and sigma1 the magnitude of lambda1 at the start.  The residual's rows are (P - x) / s,
psi / d and psi_dot / (d 2 pi / T), with d the largest deflection over the first orbit (m), the last two
multiplied by tol / gap_tol and tol / (RATE_TOL sqrt(gap_tol)): one tolerance ``tol`` on the
scaled residual is then gap_tol of the deflection on the gap, and RATE_TOL sqrt(gap_tol) on its
rate (an error e in psi_dot moves t_g by e / psi_ddot and psi(t_g) only by ~e^2 / (2 psi_ddot):
second order).

**Derivatives.**  Any finite difference of the map at a grazing orbit straddles the grazing:
one of x +- h (or lambda +- h) lifts the follower off, and the rule of
:mod:`camdyn.orbits.derivatives` rightly refuses that difference.  So the x-columns come from
the tangent dynamics of the contact side (:func:`camdyn.orbits.tangent.tangent`, run from t0
through the window's three times to t0 + T: Phi there for the gap's rows, M = Phi(t0 + T) for
the orbit's rows and the Floquet multipliers), with the gradient of psi_i at those times by
central differences of the generated output (no run); the phi_g-column is psi_dot and
psi_ddot at t_g (psi_ddot by a central difference along the field); the lambda-columns are
differences of the residual in lambda (:func:`contact_side_difference`): central under the
rule where both perturbed runs keep the base run's path, else one-sided from the side that
kept it (the contact side; truncation error O(h) instead of O(h^2), noted in the point's
derivation), at the steps of :func:`camdyn.orbits.derivatives.finite_difference_steps`.
"""
from __future__ import annotations

import math
from concurrent.futures import ThreadPoolExecutor
from dataclasses import dataclass
from functools import cached_property, partial
from typing import NamedTuple

import numpy as np

from ...model.model import Model
from ..derivatives import SHRINK, Column, Unresolved, same_path
from ..section_map import MapFailure, MapValue, StroboscopicMap
from ..shooting import newton_matrix
from ..tangent import TangentFailure, tangent
from .boundary import WINDOW, Boundary, boundary_of, onset
from .corrector import bordered_step, gap_samples
from .problem import N_STATE, TwoParameters

#: the layout of z: x's components, the grazing's phase phi_g, lambda1 (the free parameter),
#: lambda2 (the one whose range is followed)
G_STATE = slice(0, N_STATE)
G_PHASE = N_STATE
G_FREE = N_STATE + 1
G_RANGE = N_STATE + 2
G_SIZE = N_STATE + 3
#: the residual's rows: the orbit's (N_STATE), the gap's psi_i(t_g) + margin, and its rate
R_GAP = N_STATE
#: the central difference of the generated psi_i in alpha (rad) and alpha_dot (rad/s): an
#: analytic function, no run; its rounding error over this step is ~1e-10 of the derivative
OUTPUT_STEP = 1e-6
#: a parameter difference's run whose linearised gap lies past zero gap by more than this many
#: margins is not run (:func:`_lifts`): on reference-experiment against k_s (jump_chart's section)
#: the side of each difference that left the path lay, linearised, 250 margins or more past zero
#: gap, the side that kept it 250 or more inside
SURE_LIFT = 10.0
#: the rate row's tolerance, RATE_TOL sqrt(gap_tol) of its scale: a rate error e moves t_g by
#: e / psi_i'' and psi_i(t_g) from the maximum by only ~e^2 / (2 psi_i''), second order
RATE_TOL = 0.1


@dataclass(frozen=True, kw_only=True)
class GrazingSystem(TwoParameters):
    """What is continued (:class:`.problem.TwoParameters`), with lambda1 at the start
    (``free_start``), the gap's scale d (``deflection``, m, or N on a rigid contact:
    :func:`gap_maximum`), the corrector's tolerance ``tol`` on the scaled residual, the gap's
    ``gap_tol`` (a fraction of d), the ``threads`` :func:`derivatives` runs its independent runs
    on, and ``corner``: the grazing's phase pinned just past a junction of the cam (NaN: the
    gap's smooth maximum; :mod:`.boundary`)."""

    free_start: float
    deflection: float
    tol: float = 1e-8
    gap_tol: float = 1e-6
    threads: int = 1
    corner: float = math.nan

    @cached_property
    def boundary(self) -> Boundary:
        """The test output whose largest value is the "gap" (:mod:`.boundary`): psi_i, or -F_n on a rigid contact."""
        return boundary_of(self.scene.kernels())

    @property
    def pinned(self) -> bool:
        return not math.isnan(self.corner)

    def section_map(self, free: float, lam: float, mode: int | None) -> StroboscopicMap:
        model = self.model(free, lam)
        return StroboscopicMap(model, 1, self.phase_fraction * model.period, mode, self.options, self.backend)


class Layout(NamedTuple):
    """The scales of z = (x / s, phi_g, lambda1 / sigma1, lambda2 / sigma2) and of the residual's rows."""

    scale: np.ndarray          # s (rad, rad/s)
    sigma_free: float          # sigma1, lambda1's unit in z
    sigma_range: float         # sigma2, lambda2's

    def z(self, x, phase: float, free: float, lam: float) -> np.ndarray:
        return np.concatenate([np.asarray(x) / self.scale, [phase, free / self.sigma_free, lam / self.sigma_range]])

    def split(self, z: np.ndarray) -> tuple[np.ndarray, float, float, float]:
        """(x, phi_g, lambda1, lambda2) of the scaled unknowns z."""
        return (z[G_STATE] * self.scale, float(z[G_PHASE]), float(z[G_FREE] * self.sigma_free),
                float(z[G_RANGE] * self.sigma_range))


class Evaluation(NamedTuple):
    """The residual at one z from one run: the scaled residual (4), the map's value (the run's
    path; its ``state`` is the residual, for the rule's comparisons), P(x), t_g (s), the
    window's times t_g - delta, t_g, t_g + delta (s) with the states (2 x 3) and modes there,
    psi_i at them (m), the largest psi_i over the run (m), and the section's map."""

    residual: np.ndarray
    value: MapValue
    P: np.ndarray
    t_g: float
    times: np.ndarray
    states: np.ndarray
    modes: np.ndarray
    psi: np.ndarray
    max_gap: float
    section_map: StroboscopicMap

    @property
    def psi_g(self) -> float:
        """psi_i at t_g (m)."""
        return float(self.psi[1])


def _row_weights(system: GrazingSystem) -> np.ndarray:
    """The residual rows' factors: 1 on the orbit's, tol / gap_tol on the gap's and
    tol / (RATE_TOL sqrt(gap_tol)) on its rate's (see the module docstring); 1 on the pinned
    phase's row, which replaces the rate's at a corner."""
    rate = 1.0 if system.pinned else system.tol / (RATE_TOL * math.sqrt(system.gap_tol))
    return np.array([1.0] * N_STATE + [system.tol / system.gap_tol, rate])


def _gap_rows(system: GrazingSystem, T: float, psi: np.ndarray) -> np.ndarray:
    """psi_i(t_g) / d and the gap's rate over the window, (psi_i(t_g + delta) - psi_i(t_g -
    delta)) / (2 delta), over d 2 pi / T, of psi_i at the window's times (linear in them): the
    gap's rows before the margin and the row weights.  At a corner (``system.pinned``) the rate's
    row is the phase's distance from the junction instead (:func:`_pin`), 0 here."""
    d, delta = system.deflection, system.boundary.window * T
    rate = 0.0 if system.pinned else (psi[2] - psi[0]) / (2 * delta) * T / (2 * math.pi * d)
    return np.array([psi[1] / d, rate])


def _pin(system: GrazingSystem, phase: float) -> np.ndarray:
    """The pinned phase's row at a corner, phi_g less the junction's phase (else 0), after the gap's."""
    return np.array([0.0, phase - system.corner if system.pinned else 0.0])


def _gap_residual(system: GrazingSystem, T: float, psi: np.ndarray, phase: float | None = None) -> np.ndarray:
    """The residual's gap rows, weighted, from psi_i at the window's times (m): psi_i(t_g) / d +
    margins gap_tol (zero at psi_i(t_g) = -margin; the boundary's ``margins``) and the gap's rate
    (:func:`_gap_rows`), or at a corner the phase's distance from it (:func:`_pin`; none without
    ``phase``)."""
    pin = np.zeros(2) if phase is None else _pin(system, phase)
    with np.errstate(invalid="ignore"):                                          # (inf - inf in flight)
        rows = _gap_rows(system, T, psi) + np.array([system.boundary.margins * system.gap_tol, 0.0]) + pin
    return rows * _row_weights(system)[N_STATE:]


def _zero_gap(system: GrazingSystem) -> float:
    """The gap's row (weighted) of an orbit at zero gap, psi_i(t_g) = 0: the margin in the
    residual's units."""
    return float(_gap_residual(system, 1.0, np.zeros(3))[0])


def evaluate(system: GrazingSystem, layout: Layout, z: np.ndarray, mode: int | None,
             dense: bool = True) -> Evaluation:
    """The scaled residual at z by one run of P from x (raises MapFailure, or the rig's error for
    a value it refuses), sampled over the window at t_g and, ``dense``, :func:`gap_samples` times
    per period for the largest gap (else NaN: a parameter difference's run needs only the
    residual and its path, which the samples do not change, bit for bit:
    :meth:`camdyn.orbits.section_map.StroboscopicMap.run`)."""
    x, phase, free, lam = layout.split(z)
    sm = system.section_map(free, lam, mode)
    t0, t1 = sm.t_span
    T = t1 - t0
    window = system.boundary.window
    if not window < phase < 1.0 - window:
        raise MapFailure(f"the grazing's phase {phase:.6g} left the period (0, 1)")
    t_g = t0 + phase * T
    times = t_g + window * T * np.array([-1.0, 0.0, 1.0])
    samples = np.linspace(t0, t1, gap_samples(sm.model) + 1) if dense else np.array([t1])
    t_eval, sampled = _merged(samples, times)
    value, tr = sm.run(x, t_eval)
    k = np.searchsorted(tr.t, times)
    boundary = system.boundary
    psi_all = boundary.values(sm.model, sm.model.outputs_at(tr.mode, tr.t, tr.alpha, tr.alpha_dot, sm.backend),
                              tr.mode)
    psi = psi_all[k]                  # inf where a rigid follower is in flight (.boundary._far): so is the residual
    residual = np.concatenate([(value.state - x) / layout.scale * _row_weights(system)[:N_STATE],
                               _gap_residual(system, T, psi, phase)])
    path = MapValue(residual, value.start_mode, value.end_mode, value.steps, value.transitions)
    # a pinned corner is a restart even where the run stepped over its junction without a record
    restarts = np.append(tr.switches.records["t"], t_g if system.pinned else [])
    largest = boundary.largest(sm.model, psi_all[sampled], tr.mode[sampled], tr.t[sampled],
                               restarts) if dense else math.nan
    return Evaluation(residual, path, value.state, t_g, times, np.vstack([tr.alpha[k], tr.alpha_dot[k]]),
                      tr.mode[k].astype(int), psi, largest, sm)


def _merged(samples: np.ndarray, times: np.ndarray) -> tuple[np.ndarray, np.ndarray]:
    """The increasing ``samples`` with the increasing ``times`` (within them) inserted where they
    are not samples already, and which of the merged times are samples: the sorted union and its
    membership test without sorting the ~5e4 samples of a stiff contact's period (np.unique and
    np.isin took a fifth of a dense evaluation on reference-experiment)."""
    at = np.searchsorted(samples, times)
    new = samples[at] != times
    return np.insert(samples, at[new], times[new]), np.insert(np.ones(samples.size, bool), at[new], False)


class Derivatives(NamedTuple):
    """The scaled Jacobian of the residual (4 x 5), the monodromy matrix M = dP/dx (contact
    side), the lambda steps, and a note (a one-sided difference, or empty)."""

    A: np.ndarray
    M: np.ndarray
    steps: np.ndarray
    note: str


def derivatives(system: GrazingSystem, layout: Layout, z: np.ndarray, base: Evaluation,
                previous: Derivatives | None = None, strict: bool = True) -> Derivatives:
    """The derivatives of the residual at z (see the module docstring; raises MapFailure where
    the tangent dynamics or a difference cannot be evaluated).  ``previous``: the last point's
    derivatives, which start each difference (:func:`_parameter_column`); ``strict``: False at a
    corrector's iterate (:func:`contact_side_difference`).  The tangent dynamics and the two
    differences are independent runs: they run on ``system.threads`` threads at once (the same
    numbers as in turn: each run is the same computation).  A failure raises from the first of
    them that failed, in that order: the tangent dynamics, then each column."""
    A = np.zeros((N_STATE + 2, G_SIZE))
    columns = ((0, G_FREE, layout.sigma_free), (1, G_RANGE, layout.sigma_range))

    tasks = [partial(_fundamental, base, layout.split(z)[0])] + [
        partial(_parameter_column, system, layout, z, base, index, previous, strict) for _, index, _ in columns]
    if system.threads > 1:
        with ThreadPoolExecutor(system.threads) as pool:      # the compiled loop releases the GIL
            futures = [pool.submit(task) for task in tasks]
            (*window, M), *found = [f.result() for f in futures]
    else:
        (*window, M), *found = [task() for task in tasks]
    A[:, G_STATE] = _state_columns(system, layout, base, M, window)
    A[:, G_PHASE] = _phase_column(system, base)
    steps, notes = np.empty(2), []
    for (column, index, sigma), (d, step, note) in zip(columns, found):
        A[:, index] = d * sigma
        steps[column] = step
        if note:
            notes.append(f"d/d{(system.free, system.parameter)[column]}: {note}")
    if not np.all(np.isfinite(A)):
        raise MapFailure("the grazing system's derivatives are not finite")
    return Derivatives(A, M, steps, "; ".join(notes))


def _fundamental(base: Evaluation, x) -> list[np.ndarray]:
    """Phi(t) = dx(t)/dx(t0) at the window's three times and at t0 + T (M), by the tangent
    dynamics run from each time to the next."""
    sm = base.section_map
    t, y, m, phi, out = sm.t_span[0], np.asarray(x, dtype=float), sm.start_mode(x), np.eye(N_STATE), []
    try:
        for t_next in (*base.times, sm.t_span[1]):
            r = tangent(sm.model, (t, t_next), y, mode=m, options=sm.options, backend=sm.backend)
            phi = r.phi @ phi
            out.append(phi)
            t, y, m = t_next, r.state, r.end_mode
    except TangentFailure as failure:
        raise MapFailure(f"no tangent dynamics at the grazing orbit: {failure}", failure.outcome) from failure
    return out


def _psi_gradient(boundary: Boundary, model: Model, m: int, t: float, y) -> np.ndarray:
    """d(psi_i)/d(alpha, alpha_dot) at (t, y) in mode m (the boundary's test output: -F_n on a
    rigid contact), by central differences of the generated output (no run)."""
    g = np.empty(N_STATE)
    for j in range(N_STATE):
        h = OUTPUT_STEP * max(abs(float(y[j])), 1.0)
        e = np.zeros(N_STATE)
        e[j] = h
        g[j] = (boundary.at(model, m, t, y + e) - boundary.at(model, m, t, y - e)) / (2 * h)
    return g


def _state_columns(system: GrazingSystem, layout: Layout, base: Evaluation, M, window) -> np.ndarray:
    """d(residual)/dx: M - I on the orbit's rows; the gap's rows from d psi_i(t)/dx =
    grad psi_i(t) Phi(t) at the window's times."""
    model = base.section_map.model
    dpsi = np.array([_psi_gradient(system.boundary, model, int(base.modes[i]), float(base.times[i]), base.states[:, i]) @ window[i]
                     for i in range(3)])
    out = np.empty((N_STATE + 2, N_STATE))
    out[:N_STATE] = newton_matrix(M, layout.scale)
    out[N_STATE:] = np.array([_gap_rows(system, model.period, dpsi[:, j]) for j in range(N_STATE)]).T \
        * layout.scale[None, :]
    return out * _row_weights(system)[:, None]


def _phase_column(system: GrazingSystem, base: Evaluation) -> np.ndarray:
    """d(residual)/d(phi_g) from the window's samples: T psi_i' and T psi_i'' at t_g by central
    differences over delta (psi_i'' over delta^2); at a corner, T psi_i' by the forward
    difference (the window's first time is before the junction) and 1 on the pinned phase's row."""
    T = base.section_map.model.period
    psi, delta = base.psi, system.boundary.window * T
    if system.pinned:
        rows = np.array([(psi[2] - psi[1]) / delta * T / system.deflection, 1.0])
        return np.concatenate([np.zeros(N_STATE), rows]) * _row_weights(system)
    second = (psi[2] - 2 * psi[1] + psi[0]) / delta ** 2
    rows = np.array([(psi[2] - psi[0]) / (2 * delta) * T / system.deflection,
                     second * T * T / (2 * math.pi * system.deflection)])
    return np.concatenate([np.zeros(N_STATE), rows]) * _row_weights(system)


def _parameter_column(system: GrazingSystem, layout: Layout, z, base: Evaluation, index: int,
                      previous: Derivatives | None, strict: bool):
    """d(residual)/d(lambda) in the parameter's unit (:func:`contact_side_difference`), from the
    rule's step ``rtol^(1/3) max(|lambda|, sigma)`` down to its floor, or, after a point
    (``previous``), from SHRINK times its step (not at the rule's first step, which a grazing
    orbit lifts off at on both sides: 2-4 runs per column instead of ~6; starting at the step
    itself, the steps only shrink along the curve, and on reference-experiment against k_s the
    curve took 48 orbits instead of 38), not running a side that surely lifts off
    (:func:`_lifts`, for ``strict`` differences)."""
    sigma = layout.sigma_free if index == G_FREE else layout.sigma_range
    lam = float(z[index] * sigma)
    column_of = index - G_FREE                                   # the lambda's place in Derivatives.steps

    def value(offset: float) -> MapValue:
        shifted = z.copy()
        shifted[index] = (lam + offset) / sigma
        return evaluate(system, layout, shifted, base.value.start_mode, dense=False).value
    column = Column.of(max(abs(lam), sigma), np.ones(N_STATE + 2), system.options.rtol)
    if previous is None:
        return contact_side_difference(value, base.value, column, strict)
    first = SHRINK * float(previous.steps[column_of])
    if column.floor <= first < column.first:
        column = column._replace(first=first)
    lifts = _lifts(system, base, previous.A[R_GAP, index] / sigma) if strict else None
    return contact_side_difference(value, base.value, column, strict, lifts)


def _lifts(system: GrazingSystem, base: Evaluation, slope: float):
    """Whether the run at a parameter offset surely leaves the cam, told without the run: the
    gap's row there, linearised with ``slope`` (its derivative in the parameter at the last
    point), lies past zero gap by more than SURE_LIFT times the margin."""
    edge = _zero_gap(system)
    return lambda offset: float(base.residual[R_GAP]) + slope * offset - edge > SURE_LIFT * edge


def contact_side_difference(evaluate_at, base: MapValue, column: Column, strict: bool = True, lifts=None):
    """The derivative of ``evaluate_at`` (the value at a signed offset) at 0, under the rule of
    :mod:`camdyn.orbits.derivatives` as far as a grazing orbit allows: from ``column.first``,
    the central difference where the runs at +-h both take ``base``'s path; where one of them
    leaves it (it lifts off: the other side is the contact side), the one-sided difference
    from the side that kept it; h divided by SHRINK while neither keeps it, down to
    ``column.floor``.  Without ``strict`` (a corrector's iterate, which may lie past the
    grazing, lifted off), where neither run keeps the base path the one with fewer switches
    (the contact side) gives the one-sided difference: a direction for the corrector, no
    derivative.  ``lifts(offset)``, when given (``strict`` differences), tells without a run that
    the run at that offset leaves the cam: it is not run, and that side does not keep the path
    (the difference is the one its run would have given, whenever it would have lifted off).
    Returns (derivative, h, note: '' or why one-sided); raises
    :class:`~camdyn.orbits.derivatives.Unresolved` when no step works."""
    h = column.first
    while h >= column.floor:
        values = []
        for sign in (1.0, -1.0):
            if lifts is not None and lifts(sign * h):
                values.append(None)
                continue
            try:
                values.append(evaluate_at(sign * h))
            except MapFailure as failure:
                if failure.outcome is not None:
                    raise
                values.append(None)
        kept = [v is not None and same_path(v, base) for v in values]
        if not (strict or any(kept) or None in values):
            fewer = len(values[0].transitions) - len(values[1].transitions)
            kept = [fewer < 0, fewer > 0]
        if all(kept):
            return (values[0].state - values[1].state) / (2 * h), h, ""
        if any(kept):
            sign = 1.0 if kept[0] else -1.0
            side = values[0] if kept[0] else values[1]
            return (side.state - base.state) / (sign * h), h, \
                f"one-sided at step {h:.3g} (the run at {-sign * h:+.3g} lifts off)"
        h /= SHRINK
    raise Unresolved(f"no step down to {column.floor:.3g} keeps the grazing orbit's path on either side")


def gap_maximum(system: GrazingSystem, x, free: float, mode: int | None):
    """Where the orbit from x at lambda1 = ``free``, lambda2 = start comes nearest the boundary
    (:func:`.boundary.onset` of its :func:`gap_samples` samples over one period): phi_g of the
    largest psi_i (the first guess of the extended system's phase, or a corner's pinned one), the
    largest deflection -min psi_i over the period (m, or the largest force on a rigid contact,
    N: the gap's scale d) and the corner (NaN: none).  Raises MapFailure."""
    sm = system.section_map(free, system.start, mode)
    t0, t1 = sm.t_span
    samples = np.linspace(t0, t1, gap_samples(sm.model) + 1)
    _, tr = sm.run(x, samples)
    return onset(system.boundary, sm.model, sm.backend, tr, sm.t_span)


def free_at_zero_gap(system: GrazingSystem, layout: Layout, z, e: Evaluation, A: np.ndarray) -> float:
    """lambda1 where the orbit at z, converged at psi_i(t_g) = -margin, would touch zero gap at
    the same lambda2: one Newton step of the system without the margin, ``[A; e_lambda2] dz =
    -(residual without the margin)`` (the error is second order in the margin, (margins gap_tol)^2 d)."""
    margin = np.zeros(N_STATE + 2)
    margin[R_GAP] = _zero_gap(system)
    along = np.zeros(G_SIZE)
    along[G_RANGE] = 1.0
    return layout.split(z + bordered_step(A, along, margin - e.residual))[2]


def flight_residual(system: GrazingSystem, evaluation: Evaluation) -> np.ndarray:
    """The residual the corrector is given for a run that left the cam (its largest gap
    positive): the gap's row from the run's largest gap, the flight's, which lies above the
    smooth system's psi_i(t_g) (a follower held to the cam stays closer to it), and zeros in the
    other rows: the orbit's and the rate's, after the flight and its impact, say nothing of the
    smooth system (a chord step from them sent the grazing's phase out of the period at each
    try of the first step on reference-experiment against k_s, and the step was halved 4 times)."""
    out = np.zeros(N_STATE + 2)
    out[N_STATE:] = _gap_residual(system, evaluation.section_map.model.period, np.full(3, evaluation.max_gap))
    return out


def is_largest(system: GrazingSystem, evaluation: Evaluation) -> bool:
    """Whether t_g is the orbit's largest gap: the largest over the run's samples (refined by a
    parabola) stays below gap_tol d, else another maximum of the gap has overtaken the one at
    t_g and the follower first leaves the cam elsewhere.  Not below zero: the orbit is converged
    with psi_i(t_g) within [-3, -1] gap_tol d (the boundary's ``margins``, 2), so a largest sample up to
    +gap_tol d is that maximum (or another within the corrector's tolerance of it) and the psi_i
    noise of a stiff contact (measured: 1.9e-17 m against -4.3e-18 m at t_g, gap_tol d 4.7e-16 m, on
    reference-experiment at k_s = 30 N/m, which ended the jump chart there as a double grazing)."""
    return evaluation.max_gap < system.gap_tol * system.deflection
