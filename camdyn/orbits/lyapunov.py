"""Lyapunov exponents of a hybrid trajectory, from its tangent dynamics (Benettin et al. 1980).

Along a run, the tangent vectors of the state x = (alpha, alpha_dot) evolve by the variational
equation between switches and jump by the saltation matrices at them (:mod:`camdyn.orbits.tangent`).
Every cam period T the basis Q of two tangent vectors is propagated, Phi Q = Q' R (QR
re-orthonormalisation), and log abs(R_ii) is the stretching of the i-th direction over that
revolution; the exponents are their sums over the revolutions divided by the time.  Within a
revolution the basis is re-orthonormalised as well, after every switch and every stretch of
contact that could contract it by e^100 (``tangent(..., renormalise=True)``: a stiff contact's
damping contracts Phi by more than the range of a double in one revolution), and R is the
product of those factors:

    lambda_i = sum_k log abs(R_ii^(k)) / (N T)   (1/s),  lambda_1 >= lambda_2.

lambda_1 is the largest exponent (the first column of Q is a single tangent vector
renormalised every period, Benettin's algorithm); lambda_1 + lambda_2 = log abs(det Phi) / (N T),
the time mean of the field's divergence d(alpha_ddot)/d(alpha_dot) plus the switches' log abs(det S)
divided by the time (Liouville).  A stick entry (a Filippov sliding mode) has det S = 0: the
second exponent is then -inf.

The run starts after ``transient`` revolutions from ``y0`` (default the static equilibrium).
Each revolution is integrated in the kernels' periodic time (they are periodic in t with 2 T,
:mod:`camdyn.runs.pieces`), so a long run does not lose accuracy to the rounding of large t.  The
estimate's uncertainty: the revolutions are grouped in batches; the standard error of the
batch means (:attr:`LyapunovExponents.standard_error`) assumes the batches are independent.
"""
from __future__ import annotations

import math
from dataclasses import dataclass
from typing import NamedTuple

import numpy as np

from ..model.cam import CamMotion, periodic_cam
from ..engine import Domain, SolverOptions, integrate
from ..errors import ParameterError
from .._checks import integer
from ..model.model import Model
from ..model.rig import Rig
from ..model.scene import Scene
from .section_map import DEFAULT_OPTIONS, MapFailure, warm_up
from .tangent import TangentFailure, TangentSettings, tangent

__all__ = ["lyapunov_exponents", "spectrum", "largest_by_differences", "LyapunovExponents", "LyapunovSettings",
           "DifferenceEstimate"]


@dataclass(frozen=True)
class LyapunovSettings:
    """How long: ``revolutions`` measured after ``transient`` discarded, in ``batches`` batches
    (for the standard error; ``revolutions`` must be a multiple of it)."""

    revolutions: int = 200
    transient: int = 50
    batches: int = 10

    def __post_init__(self):
        checks = (("revolutions", 1), ("transient", 0), ("batches", 2))
        for name, low in checks:
            integer(name, getattr(self, name), f"an integer >= {low}", lambda n: n >= low)
        if self.revolutions % self.batches:
            raise ParameterError("revolutions", self.revolutions, f"a multiple of batches = {self.batches}")


@dataclass(frozen=True)
class LyapunovExponents:
    """The Lyapunov spectrum of a run.

    ``exponents``: (lambda_1, lambda_2) in 1/s, largest first; ``standard_error``: the batch
    means' standard error of each (1/s; nan for an infinite exponent); ``per_revolution``:
    the exponents times T (nats per cam revolution); ``revolutions``: N measured;
    ``transient``: revolutions discarded before; ``period``: T (s); ``divergence_mean``: the
    time mean of d(alpha_ddot)/d(alpha_dot) over the measured run (1/s); ``saltation_rate``:
    sum of log abs(det S) over its switches divided by its time (1/s); ``switches``: how many."""

    exponents: np.ndarray
    standard_error: np.ndarray
    revolutions: int
    transient: int
    period: float
    divergence_mean: float
    saltation_rate: float
    switches: int

    @property
    def largest(self) -> float:
        return float(self.exponents[0])

    @property
    def per_revolution(self) -> np.ndarray:
        return self.exponents * self.period


def _start(model: Model, transient: int, y0, options, backend):
    """The state and mode after ``transient`` revolutions from y0 (None: the equilibrium)."""
    if transient == 0:
        return (model.static_state() if y0 is None else np.asarray(y0, dtype=float)), None
    t_end = transient * model.period
    try:
        tr = warm_up(model, t_end, y0, np.array([t_end]), options, backend)
    except MapFailure as failure:
        raise ParameterError("transient", transient, f"a run that succeeds ({failure})") from None
    return tr.y[:2, -1].copy(), int(tr.end_mode)


def spectrum(model: Model, settings: LyapunovSettings = LyapunovSettings(), y0=None,
             options: SolverOptions = DEFAULT_OPTIONS, backend: str = "compiled",
             tangent_settings: TangentSettings = TangentSettings()) -> LyapunovExponents:
    """The Lyapunov spectrum of ``model``'s run (see the module docstring)."""
    T = model.period
    if not (math.isfinite(T) and T > 0):
        raise ParameterError("cam", None, "a periodic cam motion (a nonzero speed, or a period)",
                             problem=f"{model.cam!r} has no period")
    x, mode = _start(model, settings.transient, y0, options, backend)
    Q = np.eye(2)
    logs = np.empty((settings.revolutions, 2))
    divergence, log_det, switches = 0.0, 0.0, 0
    for k in range(settings.revolutions):
        t0 = ((settings.transient + k) % 2) * T        # the kernels' period is 2 T
        r = tangent(model, (t0, t0 + T), x, Q, mode, options, backend, tangent_settings, renormalise=True)
        Q, logs[k] = r.phi, r.log_growth   # Q R_k with log abs(diag R_k) = log_growth: Q is orthonormal
        x, mode = r.state, r.end_mode
        divergence, log_det, switches = divergence + r.divergence, log_det + r.log_det_saltation, switches + r.switches
    time = settings.revolutions * T
    exponents = logs.sum(axis=0) / time
    batch = logs.reshape(settings.batches, -1, 2).sum(axis=1) / (time / settings.batches)
    with np.errstate(invalid="ignore"):
        se = batch.std(axis=0, ddof=1) / math.sqrt(settings.batches)
    return LyapunovExponents(exponents, np.where(np.isfinite(exponents), se, np.nan), settings.revolutions,
                             settings.transient, T, divergence / time, log_det / time, switches)


def lyapunov_exponents(rig: Rig, scene: Scene, cam: CamMotion | None = None, *, speed_rpm: float | None = None,
                       settings: LyapunovSettings = LyapunovSettings(), y0=None,
                       options: SolverOptions = DEFAULT_OPTIONS, backend: str = "compiled") -> LyapunovExponents:
    """The Lyapunov exponents (1/s) of the run of ``scene`` on ``rig`` driven by ``cam`` (or at
    ``speed_rpm``), after ``settings.transient`` revolutions from ``y0`` (default the static
    equilibrium), over ``settings.revolutions`` (see the module docstring)."""
    if not isinstance(settings, LyapunovSettings):
        raise ParameterError("settings", settings, "a camdyn.orbits.lyapunov.LyapunovSettings")
    return spectrum(Model(rig, scene, periodic_cam(cam, speed_rpm)), settings, y0, options, backend)


# --- the largest exponent without a Jacobian: two neighbouring runs ----------------------------
#: the neighbour's distance, in the state scaled to radians, (alpha, alpha_dot / Omega_c): far
#: above the runs' own error at DEFAULT_OPTIONS (rtol 1e-10: ~1e-11 rad), far below the motion's
#: size (1e-2 rad); the estimate is repeated at 10 times it, and the two must agree
DELTA = 1e-7


@dataclass(frozen=True)
class DifferenceEstimate:
    """lambda_1 (1/s) by two neighbouring runs (:func:`largest_by_differences`) at the distance
    ``delta`` and at 10 ``delta``: ``largest`` (the first), its batch means' ``standard_error``,
    ``at_ten_delta`` and ``delta_difference`` = largest - at_ten_delta (what the finite distance
    changes: the estimate's error from the method, beside the statistical one)."""

    largest: float
    standard_error: float
    at_ten_delta: float
    revolutions: int
    transient: int
    period: float
    delta: float

    @property
    def delta_difference(self) -> float:
        return self.largest - self.at_ten_delta

    def verdict(self, confidence: float) -> str:
        """:func:`verdict` of both estimates (at ``delta`` and 10 ``delta``): 'chaotic' where both
        are positive by ``confidence`` standard errors, 'regular' where both are negative by as
        many, else 'undecided'.  The neighbour's distance may change the estimate's size (on a strongly
        contracting orbit the neighbour sinks to the runs' error floor within a revolution, and
        the estimate measures that floor's ratio to delta: in the chaos scan of docs/reproduction.md
        a period-1 orbit of damping C at 140 rev/min gave -13.6 +- 0.24 1/s at delta and a
        different value at 10 delta), but a verdict that holds at both distances does not depend
        on it."""
        return verdict((self.largest, self.at_ten_delta), self.standard_error, confidence)


def verdict(estimates, standard_error: float, confidence: float) -> str:
    """The chaos verdict of one or more estimates of lambda_1 with the standard error of their
    batch means: 'chaotic' where every estimate is positive by ``confidence`` standard errors,
    'regular' where every one is negative by as many, else 'undecided' (NaN estimates: undecided)."""
    values = np.asarray(estimates, dtype=float)
    bound = confidence * standard_error
    if values.size and np.all(values > bound) and np.all(values > 0):
        return "chaotic"
    if values.size and np.all(values < -bound) and np.all(values < 0):
        return "regular"
    return "undecided"


class LargestExponent(NamedTuple):
    """lambda_1 (1/s) by :func:`largest_exponent`: ``largest`` and its batch means'
    ``standard_error``; ``check``, a second estimate (two runs: the one at 10 delta; the tangent
    dynamics: ``largest`` itself); the cam ``period`` (s); ``method``, "variational" or "differences"."""

    largest: float
    standard_error: float
    check: float
    period: float
    method: str

    def verdict(self, confidence: float) -> str:
        """:func:`verdict` of both estimates."""
        return verdict((self.largest, self.check), self.standard_error, confidence)


def largest_exponent(model: Model, settings: LyapunovSettings = LyapunovSettings(), y0=None,
                     options: SolverOptions = DEFAULT_OPTIONS, backend: str = "compiled") -> LargestExponent:
    """lambda_1 of ``model``'s run by the tangent dynamics (:func:`spectrum`), or, where they
    cannot pass first contact (damping C and E: :class:`camdyn.orbits.tangent.TangentFailure`), by
    two neighbouring runs at two distances (:func:`largest_by_differences`)."""
    try:
        found = spectrum(model, settings, y0, options, backend)
        lam = found.largest
        return LargestExponent(lam, float(found.standard_error[0]), lam, found.period, "variational")
    except TangentFailure:
        d = largest_by_differences(model, settings, y0, options, backend)
        return LargestExponent(d.largest, d.standard_error, d.at_ten_delta, d.period, "differences")


def largest_by_differences(model: Model, settings: LyapunovSettings = LyapunovSettings(), y0=None,
                           options: SolverOptions = DEFAULT_OPTIONS, backend: str = "compiled",
                           delta: float = DELTA) -> DifferenceEstimate:
    """lambda_1 of ``model``'s run by Benettin's two-trajectory method: every cam period a
    neighbour at the distance ``delta`` (scaled state (alpha, alpha_dot / Omega_c), rad) runs
    beside the run, the log of its distance's growth is summed, and it is put back at ``delta``
    along its new direction.  No Jacobian: for the damping laws whose tangent dynamics cannot
    pass first contact (C, E: ``c ~ abs(psi_i)^(1/4)``, an unbounded d(alpha_ddot)/d(alpha) at psi_i = 0),
    and as a check of :func:`spectrum` where both work.  Two neighbours run, at ``delta`` and at
    10 ``delta``, so that the distance's effect on the estimate is measured, not assumed."""
    T = model.period
    if not (math.isfinite(T) and T > 0):
        raise ParameterError("cam", None, "a periodic cam motion (a nonzero speed, or a period)",
                             problem=f"{model.cam!r} has no period")
    scale = np.array([1.0, 2 * math.pi / T])            # alpha_dot / Omega_c is in rad
    x, mode = _start(model, settings.transient, y0, options, backend)
    domain = Domain(model)
    neighbours = [np.array([delta, 0.0]), np.array([10 * delta, 0.0])]
    logs = np.empty((settings.revolutions, 2))
    for k in range(settings.revolutions):
        t0 = ((settings.transient + k) % 2) * T        # the kernels' period is 2 T
        x_next, mode_next = _revolution(model, (t0, t0 + T), x, mode, options, backend)
        for j, (d, size) in enumerate(zip(neighbours, (delta, 10 * delta))):
            start = x + d * scale
            m = mode if mode is not None and domain.surface_crossed(mode, t0, *map(float, start)) < 0 else None
            apart = (_revolution(model, (t0, t0 + T), start, m, options, backend)[0] - x_next) / scale
            grown = float(np.hypot(*apart))
            logs[k, j] = math.log(grown / size)
            neighbours[j] = apart * (size / grown)
        x, mode = x_next, mode_next
    time = settings.revolutions * T
    estimates = logs.sum(axis=0) / time
    batch = logs[:, 0].reshape(settings.batches, -1).sum(axis=1) / (time / settings.batches)
    return DifferenceEstimate(float(estimates[0]), float(batch.std(ddof=1) / math.sqrt(settings.batches)),
                              float(estimates[1]), settings.revolutions, settings.transient, T, delta)


def _revolution(model: Model, span, x, mode, options, backend) -> tuple[np.ndarray, int]:
    """The state and mode one cam period on (raises MapFailure when the run fails)."""
    tr = integrate(model, span, np.asarray(x, dtype=float), np.array([span[1]]), options, mode=mode, backend=backend)
    if not tr.outcome.ok or tr.t.size != 1:
        raise MapFailure(f"the run from {tuple(map(float, x))} over a period failed: {tr.outcome.message}",
                         tr.outcome)
    return tr.y[:2, -1].copy(), int(tr.end_mode)
