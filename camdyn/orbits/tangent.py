"""Tangent dynamics of the hybrid model: the state's sensitivity to its start, across switches.

The fundamental matrix Phi(t) = dx(t)/dx(t0) of a run, x = (alpha, alpha_dot), obeys the
variational equation Phi' = J(t, x) Phi between switches, J = [[0, 1], [a_alpha, a_alpha_dot]]
with the second row from the generated ``jacobian`` kernel (Eqs. 21-22), and jumps by the
saltation matrix S of each switch (:mod:`camdyn.engine.saltation`): Phi+ = S Phi-.

:func:`tangent` runs the engine once (:func:`camdyn.engine.integrate`), which locates the
switches and records, for each, the time, the transition, the modes before and after and the
state; then it integrates the augmented system (x, Phi) mode by mode between consecutive switch
times with DOP853 (``TangentSettings``: tight tolerances; compiled, :mod:`camdyn.engine.variational`,
with the compiled backend, else SciPy's ``solve_ivp`` over the Python kernels), restarting x at each switch
from the engine's recorded state (so the augmented x never drifts from the engine's trajectory)
and applying S evaluated there.  The augmented system also integrates the divergence of the
field, d(alpha_ddot)/d(alpha_dot), whose integral with the switches' log abs(det S) is log abs(det Phi)
(Liouville's formula).

:func:`variational` is a Jacobian provider for :mod:`camdyn.orbits.shooting`: x -> (P_n(x), dP_n/dx).

Limitation: damping C and E's impact laws, c proportional to abs(psi_i)^(1/4) (Eqs. 26, 28a),
have a Jacobian that grows without bound as psi_i -> 0 at first contact (an integrable
singularity: Phi stays finite, but grows like (t - t_a)^(1/4)); the step-size control of an
explicit method cannot pass it, and :func:`tangent` raises :class:`TangentFailure` there.  Use
finite differences (:func:`camdyn.orbits.derivatives.finite_differences`) for those scenes.  This is
why the finite differences stay :func:`camdyn.periodic_orbit`'s default provider (which falls
back to this one where its differences cannot be resolved: :mod:`camdyn.orbits.derivatives`).
"""
from __future__ import annotations

import math
from dataclasses import dataclass, field

import numpy as np

from ..engine import (SCIPY_CONTROL, Augmented, SolverOptions, StepControl, augmented_flow, frozen_step, integrate,
                      record_saltation, step_control)
from ..vocabulary import STATE_ALPHA, STATE_ALPHA_DOT
from ..errors import CamdynError
from .._checks import real
from ..model.model import Model
from .section_map import DEFAULT_OPTIONS, MapDerivative, MapFailure, MapValue, StroboscopicMap

__all__ = ["tangent", "variational", "Variational", "TangentResult", "TangentSettings", "TangentFailure"]

#: a segment whose integration fails on an unbounded Jacobian at its end (damping B's impact law
#: as psi_i -> 0 at separation) is integrated to END_GAP (s) before its end and the Jacobian
#: frozen over the rest: an integrable singularity's share of Phi over it vanishes with END_GAP
#: (docs/design-notes.md, *The tangent integration's end gap*; tests/test_tangent.py)
END_GAP = 1e-9
#: ... unless Phi changes by more than this (relative) when the gap shrinks 100-fold: damping C's
#: abs(psi_i)^(1/4) law, whose singular share of Phi is ~gap^(1/4), is refused (the tests' bound
#: on a monodromy against finite differences is 1e-6)
END_GAP_CHANGE = 1e-6


class TangentFailure(CamdynError):
    """The tangent dynamics could not be integrated: the engine's run failed (``outcome`` is its
    :class:`~camdyn.Outcome`), a segment's integration failed, or a switch grazed its surface
    (a non-finite saltation matrix)."""

    def __init__(self, message: str, outcome=None):
        super().__init__(message)
        self.outcome = outcome


@dataclass(frozen=True)
class TangentSettings:
    """The tolerances of the augmented (x, Phi) integration between switches (DOP853); atol is
    scaled by max abs(Phi) at the segment's start for the entries of Phi.  (rtol 1e-11, atol 1e-13
    failed on a contact segment of the chaotic test case: "required step size is less than
    spacing between numbers", where Phi grew from 1 to 4e4 within 3e-5 s.)"""

    rtol: float = 1e-10
    atol: float = 1e-12
    step_control: StepControl = SCIPY_CONTROL      # or its name; SciPy's: the steps of solve_ivp's DOP853

    def __post_init__(self):
        for name in ("rtol", "atol"):
            real(name, getattr(self, name), "0 < value < 1", lambda v: 0 < v < 1)
        object.__setattr__(self, "step_control", step_control(self.step_control))


@dataclass(frozen=True)
class TangentResult:
    """The end of a run with its fundamental matrix.

    ``state``: x(t1) from the engine; ``phi``: dx(t1)/dx(t0) times the start's ``phi0``;
    ``end_mode``: the mode at t1 (index into MODES); ``switches``: the saltation matrices
    applied; ``divergence``: the integral of d(alpha_ddot)/d(alpha_dot) over the run (1);
    ``log_det_saltation``: the sum of log abs(det S) over the switches (-inf after a stick entry,
    whose S is singular); ``flow_state``: x(t1) of the augmented integration's last segment (a
    check against ``state``); ``log_growth``: with ``renormalise``, the logs of the diagonals of
    the triangular factors taken out of Phi (dx(t1)/dx(t0) phi0 = phi R, log abs(diag R) = log_growth),
    else zeros."""

    state: np.ndarray
    phi: np.ndarray
    end_mode: int
    switches: int
    divergence: float
    log_det_saltation: float
    flow_state: np.ndarray
    log_growth: np.ndarray = field(default_factory=lambda: np.zeros(2))


def _segment(model: Model, m: int, t0: float, t1: float, x, phi, settings: TangentSettings, compiled: bool):
    """(x, Phi, integral of the divergence) at t1 from (x, Phi) at t0 in mode m
    (:func:`camdyn.engine.augmented_flow`, compiled or by SciPy over the Python kernels)."""
    if t1 <= t0:
        return np.asarray(x, dtype=float), phi, 0.0
    start = Augmented(np.asarray(x, dtype=float), np.asarray(phi, dtype=float), 0.0)
    a, ok, message = _flow_to(model, m, t0, t1, start, settings, compiled)
    if not ok and t1 - t0 > 2 * END_GAP:          # an unbounded Jacobian at the segment's end
        a, ok, message = _short_of_end(model, m, t0, t1, start, settings, compiled, END_GAP)
        if ok:
            fine, ok, message = _short_of_end(model, m, t0, t1, start, settings, compiled, END_GAP / 100)
            change = np.max(np.abs(a.phi - fine.phi)) / max(np.max(np.abs(fine.phi)), np.finfo(float).tiny)
            if ok and not change <= END_GAP_CHANGE:
                ok, message = False, (f"Phi with the Jacobian frozen over the last {END_GAP:g} s and the last "
                                      f"{END_GAP / 100:g} s differs by {change:.1e}: a singularity that matters")
    if not ok or not a.finite():
        raise TangentFailure(f"the tangent integration in mode {model.kernels.MODES[m]!r} from t = {t0:g} s "
                             f"failed: {message} (an unbounded Jacobian, e.g. damping C or E's impact law at "
                             "first contact: use camdyn.orbits.derivatives.finite_differences)")
    return a.x, a.phi, a.divergence


def _flow_to(model: Model, m: int, t0: float, t1: float, start: Augmented, settings: TangentSettings, compiled: bool):
    return augmented_flow(model, m, t0, t1, start, settings.rtol, settings.atol, settings.step_control, compiled)


def _short_of_end(model: Model, m: int, t0: float, t1: float, start: Augmented, settings, compiled: bool, gap: float):
    """The augmented system to ``gap`` before t1, then Phi and the divergence over the gap with
    the Jacobian frozen there (:func:`camdyn.engine.frozen_step`)."""
    a, ok, message = _flow_to(model, m, t0, t1 - gap, start, settings, compiled)
    if not ok:
        return a, ok, message
    return frozen_step(model, m, t1 - gap, a, gap), True, message


#: with renormalisation, a segment is integrated in pieces over which Phi grows or shrinks by at
#: most about e^RENORMALISE_NATS (rate bound below), and Phi is re-orthonormalised after each:
#: a contact segment's damping contracts Phi by e^-700 within a revolution on a stiff rig, below
#: the smallest double (e^-745), where Phi would underflow to 0
RENORMALISE_NATS = 100.0


def _piece_end(model: Model, m: int, t: float, x, t1: float) -> float:
    """The end of the next piece of a segment to t1: its rate bound is abs(a_alpha_dot) (the
    divergence) plus sqrt(a_alpha) where the stiffness term repels (Eqs. 21-22 at the start)."""
    d_alpha, d_alpha_dot = model.jacobian(m, t, float(x[STATE_ALPHA]), float(x[STATE_ALPHA_DOT]))
    rate = abs(d_alpha_dot) + math.sqrt(max(d_alpha, 0.0))
    if not math.isfinite(rate) or rate <= 0.0:
        return t1
    return min(t1, t + RENORMALISE_NATS / rate)


def _orthonormalised(phi, log_growth):
    """phi = Q R with diag R >= 0: (Q, log_growth + log diag R)."""
    Q, R = np.linalg.qr(phi)
    signs = np.where(np.diag(R) < 0, -1.0, 1.0)
    with np.errstate(divide="ignore"):
        return Q * signs[None, :], log_growth + np.log(np.abs(np.diag(R)))


def _flow(model, m, t0, t1, x, phi, settings, compiled, log_growth):
    """_segment from t0 to t1, in renormalised pieces when log_growth is not None."""
    if log_growth is None:
        x, phi, d = _segment(model, m, t0, t1, x, phi, settings, compiled)
        return x, phi, d, None
    divergence, t = 0.0, t0
    while t < t1:
        t_next = _piece_end(model, m, t, x, t1)
        x, phi, d = _segment(model, m, t, t_next, x, phi, settings, compiled)
        phi, log_growth = _orthonormalised(phi, log_growth)
        divergence, t = divergence + d, t_next
    return x, phi, divergence, log_growth


def tangent(model: Model, t_span, y0, phi0=None, mode: int | None = None,
            options: SolverOptions = DEFAULT_OPTIONS, backend: str = "compiled",
            settings: TangentSettings = TangentSettings(), renormalise: bool = False) -> TangentResult:
    """x(t1) and Phi(t1) = dx(t1)/dx(t0) phi0 of a run of ``model`` over t_span from y0 (see
    the module docstring).  ``mode`` is the mode to start in (default: the automaton's initial
    rule), ``options`` the engine's, ``settings`` the augmented integration's tolerances.
    With ``renormalise`` (for Lyapunov exponents), Phi is re-orthonormalised (QR) after every
    switch and every piece of RENORMALISE_NATS, so that it neither underflows nor overflows; the
    result's ``phi`` is then the last Q and its ``log_growth`` the logs taken out."""
    t0, t1 = map(float, t_span)
    x = np.asarray(y0, dtype=float)
    tr = integrate(model, (t0, t1), x, np.array([t1]), options, mode=mode, backend=backend)
    if not tr.outcome.ok or tr.t.size != 1:
        raise TangentFailure(f"the run from {tuple(map(float, x))} failed: {tr.outcome.message}", tr.outcome)
    compiled = backend == "compiled"
    phi = np.eye(2) if phi0 is None else np.array(phi0, dtype=float).reshape(2, 2)
    records = tr.switches.records
    m = int(records["before"][0]) if len(records) else tr.end_mode
    t, divergence, log_det = t0, 0.0, 0.0
    growth = np.zeros(2) if renormalise else None
    for sw in records:
        t_sw, after = float(sw["t"]), int(sw["after"])
        x_before, phi, d, growth = _flow(model, m, t, t_sw, x, phi, settings, compiled, growth)
        divergence += d
        x = np.array([sw["alpha"], sw["alpha_dot"]], dtype=float)
        S, surface = record_saltation(model, sw, x_before)
        if not np.all(np.isfinite(S)):
            raise TangentFailure(f"the switch at t = {t_sw:g} s across {model.kernels.SURFACES[surface]!r} grazes it "
                                 "(the field is tangent to the surface): no saltation matrix")
        phi = S @ phi
        if renormalise:
            phi, growth = _orthonormalised(phi, growth)
        det = abs(np.linalg.det(S))
        log_det += math.log(det) if det > 0 else -math.inf
        t, m = t_sw, after
    flow_x, phi, d, growth = _flow(model, m, t, t1, x, phi, settings, compiled, growth)
    return TangentResult(tr.end_state(), phi, int(tr.end_mode), len(records), divergence + d, log_det,
                         flow_x, np.zeros(2) if growth is None else growth)


class Variational:
    """The Jacobian provider by the tangent dynamics (:func:`tangent`): one engine run and one
    augmented integration per call, against 4-5 runs by finite differences.  Raises
    :class:`~camdyn.orbits.section_map.MapFailure` where the map cannot be evaluated or the tangent
    dynamics cannot be integrated (damping C and E's impact laws, a grazing switch)."""

    name = "variational"

    def __init__(self, section_map: StroboscopicMap, settings: TangentSettings = TangentSettings()):
        self.section_map, self.settings = section_map, settings

    def __call__(self, x) -> tuple[np.ndarray, np.ndarray]:
        """(P_n(x), dP_n/dx), the plain protocol."""
        d = self.derivative(x)
        return d.value, d.jacobian

    def derivative(self, x, base: MapValue | None = None) -> MapDerivative:
        """The :class:`~camdyn.orbits.section_map.MapDerivative` at x (``base`` is not used: the one run
        gives the switches the tangent dynamics need besides P_n(x))."""
        sm, x = self.section_map, np.asarray(x, dtype=float)
        try:
            r = tangent(sm.model, sm.t_span, x, mode=sm.start_mode(x), options=sm.options, backend=sm.backend,
                        settings=self.settings)
        except TangentFailure as failure:
            raise MapFailure(str(failure), failure.outcome) from failure
        return MapDerivative(r.state, r.phi, self.name, end_mode=r.end_mode)


def variational(section_map: StroboscopicMap, scale=None, settings: TangentSettings = TangentSettings()) -> Variational:
    """The variational Jacobian provider of ``section_map`` (:class:`Variational`).  ``scale`` is
    accepted for the signature of a provider factory, ``jacobian(map, scale)`` (as
    :func:`camdyn.periodic_orbit` takes it), and not used."""
    return Variational(section_map, settings)
