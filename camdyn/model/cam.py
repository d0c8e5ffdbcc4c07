"""Cam motions Theta(t) (Section 7): constant speed, oscillating, or given by the user.

The built-in motions are generated into the scene's kernels (their constants
travel in the parameter vector); a user motion is three callables evaluated by
the runtime and handed to the kernels as ``cam = (Theta, Theta_dot, Theta_ddot)``.
"""
from __future__ import annotations

import math
from dataclasses import dataclass
from typing import Callable


from ..errors import ParameterError
from .._checks import finite

RPM = 2 * math.pi / 60  # rad/s per rev/min


def _finite(name: str, value, valid: str = "a finite number") -> float:
    return finite(name, value, valid)


@dataclass(frozen=True)
class ConstantSpeed:
    """Theta(t) = Theta0 + Omega_c t.  ``speed_rpm`` > 0 turns the cam counter-clockwise
    ("de-energizing", Section 7.1); < 0 clockwise ("self-energizing"); 0 holds it still."""

    speed_rpm: float
    kind = "constant"

    def __post_init__(self):
        v = _finite("speed_rpm", self.speed_rpm, "a finite speed in rev/min, |speed_rpm| <= 1e5")
        if abs(v) > 1e5:
            raise ParameterError("speed_rpm", v, "|speed_rpm| <= 1e5 rev/min")

    @property
    def Omega_c(self) -> float:
        return self.speed_rpm * RPM

    @property
    def period(self) -> float:
        """One cam revolution (s); infinite for a cam at rest (or so slow that Omega_c underflows)."""
        omega = self.Omega_c
        return math.inf if omega == 0 else abs(2 * math.pi / omega)

    def values(self) -> dict[str, float]:
        return {"Omega_c": self.Omega_c}


@dataclass(frozen=True)
class Oscillating:
    """Theta(t) = Theta0 + 0.5 Theta_p sin(omega_c t) (Section 7.2: Theta_p = pi, 40 rev/min)."""

    amplitude_pp: float          # Theta_p, peak-to-peak cam angle (rad)
    frequency_rpm: float         # omega_c in oscillations per minute
    kind = "oscillating"

    def __post_init__(self):
        a = _finite("amplitude_pp", self.amplitude_pp)
        f = _finite("frequency_rpm", self.frequency_rpm)
        if not 0 < a <= 4 * math.pi:
            raise ParameterError("amplitude_pp", a, "0 < amplitude_pp <= 4 pi rad")
        if not 0 < f <= 1e5:
            raise ParameterError("frequency_rpm", f, "0 < frequency_rpm <= 1e5")

    @property
    def period(self) -> float:
        return 60.0 / self.frequency_rpm

    def values(self) -> dict[str, float]:
        return {"Theta_p": float(self.amplitude_pp), "omega_c": self.frequency_rpm * RPM}


@dataclass(frozen=True)
class UserMotion:
    """Any cam motion: three callables of time, for Theta (rad), its rate and acceleration.

    They must accept floats and NumPy arrays.  ``period`` (s), if given, sets what
    "one revolution" means for per-revolution outputs.
    """

    theta: Callable
    theta_dot: Callable
    theta_ddot: Callable
    period: float = math.inf
    kind = "user"

    def __post_init__(self):
        for name in ("theta", "theta_dot", "theta_ddot"):
            if not callable(getattr(self, name)):
                raise ParameterError(name, getattr(self, name), "a callable of time t (s)")

    def __call__(self, t):
        return self.theta(t), self.theta_dot(t), self.theta_ddot(t)

    def values(self) -> dict[str, float]:
        return {}


CamMotion = ConstantSpeed | Oscillating | UserMotion


def periodic_cam(cam, speed_rpm: float | None) -> CamMotion:
    """:func:`cam_motion` for an analysis that needs a cam period (a periodic orbit, its map, the
    Lyapunov exponents per revolution): a constant speed must be nonzero, a user's motion must
    give ``period``."""
    motion = cam_motion(cam, speed_rpm)
    if not math.isfinite(motion.period):
        if isinstance(motion, ConstantSpeed):
            raise ParameterError("speed_rpm", motion.speed_rpm, "nonzero (rev/min): this analysis works per cam "
                                 "revolution, and a cam at rest has none", problem="is zero")
        raise ParameterError("cam", None, "a cam motion with a period (UserMotion(..., period=T))",
                             problem=f"{motion!r} has no period")
    return motion


def cam_motion(cam, speed_rpm: float | None):
    """The cam motion of a call that takes ``cam`` or ``speed_rpm`` (a constant speed, rev/min):
    exactly one of them, else :class:`~camdyn.errors.ParameterError`."""
    if cam is None:
        if speed_rpm is None:
            raise ParameterError("cam", None, "a cam motion, or speed_rpm for a constant speed")
        return ConstantSpeed(speed_rpm)
    if speed_rpm is not None:
        raise ParameterError("speed_rpm", speed_rpm, "not both cam and speed_rpm")
    return cam
