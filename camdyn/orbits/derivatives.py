"""Finite differences of the stroboscopic map, and the rule that says when one is a derivative.

A central difference (P(x + h e) - P(x - h e)) / 2h is a derivative of the map only where the
map is smooth between the perturbed states, that is where the runs from x + h e and x - h e take
the same hybrid path as the run from x: the same transitions of the automaton (surface,
direction, modes), in the same order, the same number of times, ending in the same mode
(:attr:`camdyn.orbits.section_map.MapValue.transitions`).  A perturbed run that separates from the cam
where the base run stays in contact (an orbit whose contact margin is smaller than the step), or
that gains or loses an impact, spans a jump of the map: its difference is no derivative, however
small the orbit's residual, and multipliers from it are wrong (issue 25: off by up to 0.96 on
rigs with a small contact margin, reported as converged).

**The rule** (:func:`resolved_difference`, the one place it is written): such a step is divided
by :data:`SHRINK` while it stays above the floor at which the map's own noise still lets the
difference resolve the derivative (:func:`step_floor`); a perturbed state outside the start
mode's domain (a stiff contact: the deflection is smaller than the step) is shrunk the same way.
Where no step above the floor works, :func:`finite_differences` falls back to the variational
provider (:func:`camdyn.orbits.tangent.variational`) where the scene has one; else its
:class:`~camdyn.orbits.section_map.MapDerivative` says ``resolved=False`` and why, and
:func:`camdyn.periodic_orbit` reports ``MULTIPLIERS_UNRESOLVED`` instead of multipliers.  The
continuation's derivative in its parameter (:mod:`camdyn.orbits.continuation`) is a central difference
of the map as well, under this rule.
"""
from __future__ import annotations

from typing import Callable, NamedTuple

import numpy as np

from ..errors import ParameterError
from .._checks import flag, real
from .section_map import MapDerivative, MapFailure, MapValue, StroboscopicMap, derivative_at
from .tangent import Variational

__all__ = ["finite_differences", "FiniteDifferences", "resolved_difference", "finite_difference_steps",
           "step_floor", "Unresolved", "SHRINK", "same_path"]

#: a step whose perturbed runs take another hybrid path than the base run (or leave the start
#: mode's domain) is divided by SHRINK, down to :func:`step_floor`
SHRINK = 4.0


class Unresolved(MapFailure):
    """No step above the floor gives a central difference along the base run's hybrid path.
    ``secant``: (difference, step) at the largest step whose runs ran, whatever their path (a
    direction for Newton's method or a predictor, no derivative), or None."""

    def __init__(self, message: str, secant=None):
        super().__init__(message)
        self.secant = secant


def finite_difference_steps(x, scale, rtol: float) -> np.ndarray:
    """The first central-difference steps ``h_j = rtol^(1/3) * max(|x_j|, scale_j)``.

    The map's value carries an error of the order of the solver's tolerance, rtol times the
    state's scale, that is not smooth in x (the accepted steps change with x); a central
    difference with step h has truncation error O(h^2) and this noise divided by h, balanced
    at h ~ rtol^(1/3) in units of the scale (Dennis & Schnabel 1983, Sec. 5.6; Press et al.,
    Numerical Recipes, Sec. 5.7): a relative error of about rtol^(2/3) in the Jacobian.
    """
    x, scale = np.asarray(x, dtype=float), np.asarray(scale, dtype=float)
    return float(rtol) ** (1.0 / 3.0) * np.maximum(np.abs(x), scale)


def step_floor(size: float, rtol: float) -> float:
    """The smallest step a central difference of the map is shrunk to: ``rtol^(1/2) size``.

    The map's noise, about rtol times the motion's size, divided by the step is the difference's
    error: at this floor it is rtol^(1/2) of the size (1e-5 at the default rtol 1e-10).  Below
    it the difference would be mostly noise."""
    return float(rtol) ** 0.5 * float(size)


class Column(NamedTuple):
    """How one column of a derivative is differenced: the first step, the floor (both in the
    input's unit), the weights that put a column in the scaled Jacobian's units (the input's
    size over each output's size), and the tolerance two estimates must agree to in those units."""

    first: float
    floor: float
    weights: np.ndarray
    tol: float

    @classmethod
    def of(cls, size: float, weights, rtol: float, first: float | None = None) -> "Column":
        """The steps of :func:`finite_difference_steps` and :func:`step_floor` for an input of
        size ``size`` (``first``: another first step), the ``weights``, and the tolerance
        rtol^(1/2), the noise at the floor."""
        first = float(rtol) ** (1.0 / 3.0) * size if first is None else first
        floor = min(step_floor(size, rtol), first)
        return cls(first, floor, np.asarray(weights, dtype=float), float(rtol) ** 0.5)


def same_path(a: MapValue, b: MapValue) -> bool:
    """Whether two runs of the map took the same hybrid path: the same transitions, in the same
    order, ending in the same mode (the rule's test)."""
    return a.transitions == b.transitions and a.end_mode == b.end_mode


def _path_change(base: MapValue, plus: MapValue, minus: MapValue, h: float) -> str:
    """'' when both perturbed runs took the base run's path, else what differs."""
    if same_path(plus, base) and same_path(minus, base):
        return ""
    other = minus if same_path(plus, base) else plus
    if len(other.transitions) != len(base.transitions):
        return f"at step {h:.3g} a perturbed run made {len(other.transitions)} switches against the base run's " \
               f"{len(base.transitions)}"
    return f"at step {h:.3g} a perturbed run crossed other surfaces than the base run"


def resolved_difference(evaluate: Callable[[float], MapValue], base: MapValue, column: Column,
                        admits: Callable[[float], bool] | None = None):
    """The central difference (P(+h) - P(-h)) / 2h of ``evaluate`` (the map at a signed offset
    along one direction) and its step h, under the module's rule: from ``column.first``, h is
    divided by :data:`SHRINK` while a perturbed run takes another hybrid path than ``base`` or
    leaves its mode's domain, and until the differences at h and h / SHRINK agree to
    ``column.tol`` (scaled): the smaller one is returned, its truncation error about 1/15 of their
    difference.  ``admits(offset)``, when given, tells without a run whether the perturbed state
    is in the start mode's domain: a step is then shrunk before either of its runs is made.
    Raises :class:`Unresolved`, saying why, when no step above ``column.floor`` works, and the
    :class:`~camdyn.orbits.section_map.MapFailure` of a run that fails."""
    why, secant, last = "the first step is below the floor", None, None
    h = column.first
    while h >= column.floor:
        try:
            if admits is not None and not (admits(h) and admits(-h)):
                raise MapFailure(f"at step {h:.3g} a perturbed state is outside it")
            plus, minus = evaluate(h), evaluate(-h)
        except MapFailure as failure:
            if failure.outcome is not None:
                raise
            why, last = f"a perturbed state left the start mode's domain: {failure}", None
        else:
            difference = (plus.state - minus.state) / (2.0 * h)
            secant = secant or (difference, h)
            why = _path_change(base, plus, minus, h)
            if why:
                last = None
            elif last is not None:
                change = float(np.max(np.abs(difference - last) * column.weights))
                if change <= column.tol:
                    return difference, h
                why, last = (f"the differences at steps {SHRINK * h:.3g} and {h:.3g} differ by {change:.2g} "
                             f"(scaled), more than {column.tol:.2g}: the map is not smooth at that scale"), difference
            else:
                why, last = f"the runs at step {h:.3g} keep the path, but no smaller step above the floor confirms it", \
                    difference
        h /= SHRINK
    raise Unresolved(f"no step down to {column.floor:.3g} gives a resolved difference ({why})", secant)


def _perturbed(x: np.ndarray, j: int, offset: float) -> np.ndarray:
    y = x.copy()
    y[j] += offset
    return y


class FiniteDifferences:
    """The Jacobian provider by central differences of ``section_map``, under the module's rule.

    ``scale`` (rad, rad/s): the size of the motion, below which the first step does not shrink
    (:func:`finite_difference_steps`) and from which the floor is set (:func:`step_floor`);
    ``step_factor`` multiplies the first steps (to check a Jacobian against a second step);
    ``fallback``: the provider factory used where a column cannot be resolved (None: the
    derivative is returned with ``resolved=False``).  A call costs 4 runs of the map given
    ``base``, 5 without, more when a step is shrunk (none for a step whose perturbed state is
    outside the start mode's domain); after a column that cannot be resolved, the fallback's
    cost instead of the other column's."""

    name = "finite_differences"

    def __init__(self, section_map: StroboscopicMap, scale, step_factor: float = 1.0,
                 fallback: Callable | None = None):
        scale = np.asarray(scale, dtype=float)
        if scale.shape != (2,) or not np.all(np.isfinite(scale)) or not np.all(scale > 0):
            raise ParameterError("scale", scale, "two positive numbers (rad, rad/s)")
        real("step_factor", step_factor, "0 < step_factor < 1e6", lambda v: 0 < v < 1e6)
        self.section_map, self.scale, self.step_factor, self.fallback = section_map, scale, float(step_factor), fallback

    def __call__(self, x) -> tuple[np.ndarray, np.ndarray]:
        """(P_n(x), dP_n/dx), the plain protocol."""
        d = self.derivative(x)
        return d.value, d.jacobian

    def derivative(self, x, base: MapValue | None = None) -> MapDerivative:
        """The :class:`~camdyn.orbits.section_map.MapDerivative` at x (``base``: the map's value there)."""
        x = np.asarray(x, dtype=float)
        base = self.section_map.evaluate(x) if base is None else base
        rtol = self.section_map.options.rtol
        first = self.step_factor * finite_difference_steps(x, self.scale, rtol)
        J, steps, notes = np.empty((2, 2)), np.empty(2), []
        for j in range(2):
            column = Column.of(max(abs(x[j]), self.scale[j]), self.scale[j] / self.scale, rtol, first[j])
            try:
                J[:, j], steps[j] = resolved_difference(self._along(x, j), base, column, self._admits(x, j))
            except Unresolved as failure:
                notes.append(f"column {j}: {failure}")
                J[:, j], steps[j] = failure.secant or (np.full(2, np.nan), first[j])
                if self.fallback is not None:     # the fallback gives every column: no run for the others
                    break
        if not notes:
            return MapDerivative(base.state, J, self.name, steps, end_mode=base.end_mode)
        return self._fall_back(x, base, J, steps, "; ".join(notes))

    def _along(self, x: np.ndarray, j: int) -> Callable[[float], MapValue]:
        return lambda offset: self.section_map.evaluate(_perturbed(x, j, offset))

    def _admits(self, x: np.ndarray, j: int) -> Callable[[float], bool]:
        return lambda offset: self.section_map.admits(_perturbed(x, j, offset))

    def _fall_back(self, x, base: MapValue, J, steps, note: str) -> MapDerivative:
        if self.fallback is not None:
            try:
                d = derivative_at(self.fallback(self.section_map), x, base)
            except MapFailure as failure:
                note = f"{note}; the fallback failed: {failure}"
            else:
                return MapDerivative(d.value, d.jacobian, d.provider, d.steps, d.resolved,
                                     f"finite differences unresolved ({note}), so {d.provider}", d.end_mode)
        return MapDerivative(base.state, J, self.name, steps, False, f"finite differences unresolved: {note}",
                             base.end_mode)


def _variational_fallback(section_map: StroboscopicMap) -> Variational:
    if getattr(section_map.model.kernels, "VARIATIONAL", None) is None:
        raise MapFailure("the scene has no variational kernels (a linear model)")
    return Variational(section_map)


def finite_differences(section_map: StroboscopicMap, scale, step_factor: float = 1.0,
                       fallback: bool = True) -> FiniteDifferences:
    """The Jacobian provider by central differences of ``section_map`` (:class:`FiniteDifferences`),
    falling back to the variational provider where a column cannot be resolved (``fallback=False``:
    the derivative is reported unresolved instead)."""
    flag("fallback", fallback)
    return FiniteDifferences(section_map, scale, step_factor, _variational_fallback if fallback else None)
