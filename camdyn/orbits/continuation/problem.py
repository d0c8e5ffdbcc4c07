"""What a continuation is about: the problem (rig, scene, parameter, range, section), the
settings, how a branch ended, the records it returns (Point, Branch, Event), and the Leg: what
every step of one branch shares, with the one layout of the unknowns z = (x / s, lambda / span)."""
from __future__ import annotations

import dataclasses
from dataclasses import dataclass, field
from functools import cached_property
from typing import NamedTuple

import numpy as np

from ..._checks import integer, real
from ...engine import SolverOptions
from ...errors import ParameterError
from ...model.cam import ConstantSpeed
from ...model.model import Model
from ...model.rig import Rig
from ...model.scene import Scene
from ...outcome import ActionableOutcome
from ...vocabulary import STATE
from ..derivatives import finite_differences
from ..section_map import DEFAULT_OPTIONS, StroboscopicMap
from ..shooting import ShootingSettings
from .corners import Landings

#: the parameter name of the cam speed (:data:`camdyn.orbits.continuation.SPEED`)
SPEED = "speed_rpm"
#: the size n of the state x (:data:`camdyn.vocabulary.STATE`): of dP/dx (n x n) and its multipliers
N_STATE = len(STATE)
#: the layout of the scaled unknowns z (and of the tangent, and of the columns of the scaled
#: Jacobian [dG/dx, dG/dlambda]): x's components, then lambda's; only :class:`Leg` builds and
#: splits a z
Z_STATE = slice(0, N_STATE)
Z_LAMBDA = N_STATE
Z_SIZE = N_STATE + 1


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
            real(name, getattr(self, name), "0 < value <= 1 (scaled arclength: the parameter range is 1)",
                 lambda v: 0 < v <= 1)
        if not self.min_step <= self.step <= self.max_step:
            raise ParameterError("step", self.step, f"min_step ({self.min_step}) <= step <= max_step ({self.max_step})")
        ShootingSettings(self.tol, self.max_corrector)          # checks tol and max_corrector
        for name, lo in (("max_points", 2), ("easy_iterations", 1), ("switch_depth", 0)):
            integer(name, getattr(self, name), f"an integer, {lo} <= {name} <= 100000",
                    lambda n, lo=lo: lo <= n <= 100_000)


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


@dataclass(frozen=True)
class TwoParameters:
    """What a two-parameter curve is about: the rig and scene, the free parameter ``free``
    (lambda1) and the one followed from ``start`` to ``end`` (``parameter``, lambda2), each
    ``speed_rpm`` or a rig parameter, the cam speed when neither is the speed, the section's
    phase (a fraction of T), the solver options and the backend."""

    rig: Rig
    scene: Scene
    free: str
    parameter: str
    start: float
    end: float
    speed_rpm: float | None = None
    phase_fraction: float = 0.0
    options: SolverOptions = DEFAULT_OPTIONS
    backend: str = "compiled"

    @property
    def span(self) -> float:
        return abs(self.end - self.start)

    def model(self, free: float, lam: float) -> Model:
        """The model at lambda1 = ``free``, lambda2 = ``lam``."""
        values = {self.free: free, self.parameter: lam}
        speed = values.pop(SPEED, self.speed_rpm)
        return Model(self.rig.replace(**values) if values else self.rig, self.scene, ConstantSpeed(speed))


@dataclass(frozen=True, eq=False)
class Leg:
    """What every step of one branch shares: the problem, the period n of the branch's orbits
    (n T), the motion's scale s (x's unit in z and in the scaled residual) and the settings.

    The unknowns are z = (x / s, lambda / span) (:data:`Z_STATE`, :data:`Z_LAMBDA`): built by
    :meth:`z`, split by :meth:`split`, a direction along lambda alone by :meth:`along`."""

    problem: Problem         # (or anything with its span, parameter, options, section_map and jacobian)
    periods: int
    scale: np.ndarray
    settings: ContinuationSettings

    def section_map(self, lam: float, mode: int | None) -> StroboscopicMap:
        """P_n at lambda, started in ``mode``."""
        return self.problem.section_map(lam, mode, self.periods)

    def doubled(self) -> "Leg":
        """The leg of the orbits of period 2 n T (a branch switched to at a period doubling)."""
        return dataclasses.replace(self, periods=2 * self.periods)

    def z(self, lam: float, x) -> np.ndarray:
        """The scaled unknowns of the orbit (lambda, x)."""
        return np.concatenate([x / self.scale, [lam / self.problem.span]])

    def split(self, z: np.ndarray) -> tuple[float, np.ndarray]:
        """(lambda, x) of the scaled unknowns z."""
        return float(z[Z_LAMBDA] * self.problem.span), z[Z_STATE] * self.scale

    @staticmethod
    def along(direction: float) -> np.ndarray:
        """A z-direction along lambda alone (+1: increasing lambda)."""
        t = np.zeros(Z_SIZE)
        t[Z_LAMBDA] = direction
        return t


class Derivation(NamedTuple):
    """How a point's derivatives were obtained: the provider of dP/dx, the central-difference
    steps (alpha rad, alpha_dot rad/s, lambda; NaN where not by differences), whether both
    dP/dx and dP/dlambda are resolved (:mod:`camdyn.orbits.derivatives`), and a note (a fallback, or why not)."""

    provider: str
    steps: np.ndarray
    resolved: bool
    note: str


class Point(NamedTuple):
    """One orbit on a branch: lambda, x at the section, dP_n/dx, the unit tangent (scaled), the
    largest gap (m), alpha at the revolutions' starts (the brute-force diagram's section), the
    mode at the section, the scaled residual, the corrector's steps, the scaled derivatives
    of G there, how they were obtained (:class:`Derivation`), where its Newton impacts land
    on the cam against the profile's junctions (:class:`~.corners.Landings`: from the run that
    converged; no impacts on a compliant scene), and the lift-off test function (N where it is
    < 0, m where > 0; NaN on a compliant scene: :func:`.lift_off.lift_off`, from the same run)."""

    lam: float
    x: np.ndarray
    jacobian: np.ndarray
    tangent: np.ndarray
    max_gap: float
    alpha_revolutions: np.ndarray
    mode: int
    residual: float
    iterations: int
    derivatives: np.ndarray     # the scaled [dG/dx, dG/dlambda] (n x n + 1) at the point: the next corrector's
    derivation: Derivation
    landings: Landings
    lift_off: float

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
