"""Follower motion laws s(theta): the lift of the follower as a function of the cam angle, over one
revolution, built of rise, dwell and return segments (issue 27).

A segment moves the follower by ``rise`` (> 0 a rise, < 0 a return, 0 a dwell) over a cam angle
``angle`` along a normalized law S(x), x in [0, 1], S(0) = 0, S(1) = 1, S'(0) = S'(1) = 0 and
S''(0) = S''(1) = 0, so that s, s' and s'' are continuous at every segment end:

    s(theta) = s_k + rise_k S((theta - theta_k) / beta_k),   s^(d) = rise_k S^(d)(x) / beta_k^d.

The laws (Norton, *Cam Design and Manufacturing Handbook*, ch. 3):

- ``"cycloidal"``:         S = x - sin(2 pi x) / (2 pi);
- ``"polynomial-345"``:    S = 10 x^3 - 15 x^4 + 6 x^5;
- ``"modified-trapezoid"``: the acceleration is a quarter sine over x in [0, 1/8], constant on
  [1/8, 3/8], a half cosine through zero on [3/8, 5/8], constant on [5/8, 7/8] and a quarter sine
  back to zero on [7/8, 1]; S is its double integral in closed form, peak S'' = 4.888.

The lift is in metres for a translating follower and in radians for an oscillating one; this
module does not care. Everything is exact (closed form) and vectorized over numpy arrays.
"""
from __future__ import annotations

import math
from dataclasses import dataclass

import numpy as np

from .._checks import finite, integer
from ..errors import ParameterError

__all__ = ["LAWS", "Segment", "MotionLaw", "rise_dwell_return", "normalized_law"]

TWO_PI = 2 * math.pi
#: the relative tolerance on "the segment angles sum to 2 pi": a few ulps of 2 pi per segment,
#: generous enough for angles typed in degrees and converted (math.radians rounds each to 1 ulp)
ANGLE_SUM_RTOL = 1e-12

#: the laws a rise or a return can follow
LAWS = ("cycloidal", "polynomial-345", "modified-trapezoid")


def _cycloidal(x: np.ndarray, d: int) -> np.ndarray:
    w = TWO_PI * x
    if d == 0:
        return x - np.sin(w) / TWO_PI
    if d == 1:
        return 2 * np.sin(w / 2) ** 2                  # 1 - cos(2 pi x), without cancellation near 0
    if d == 2:
        return TWO_PI * np.sin(w)
    return TWO_PI ** 2 * np.cos(w)


def _polynomial_345(x: np.ndarray, d: int) -> np.ndarray:
    if d == 0:
        return x ** 3 * (10 + x * (-15 + 6 * x))
    if d == 1:
        return 30 * x ** 2 * (1 - x) ** 2
    if d == 2:
        return 60 * x * (1 + x * (-3 + 2 * x))
    return 60 + x * (-360 + 360 * x)


class _SineConstantAcceleration:
    """A normalized law whose acceleration is, piece by piece, A (c0 + c1 sin(w t) + c2 cos(w t)),
    t = x - x_k: integrated in closed form, with A chosen so that S(1) = 1."""

    def __init__(self, starts, c0, c1, c2, omega: float):
        self.x = np.asarray(starts, float)
        self.c = np.array([c0, c1, c2], float)
        self.w = omega
        self.v = np.zeros(len(starts))
        self.p = np.zeros(len(starts))
        self.A = 1.0
        last = len(self.x) - 1
        for k in range(last):                        # the velocity and lift at each piece's start, A = 1
            end = np.array([self.x[k + 1]])
            self.v[k + 1] = self._eval(end, 1, np.array([k]))[0]
            self.p[k + 1] = self._eval(end, 0, np.array([k]))[0]
        scale = 1.0 / self._eval(np.array([1.0]), 0, np.array([last]))[0]   # S(1) = 1: S is linear in A
        self.A, self.v, self.p = scale, self.v * scale, self.p * scale

    def _eval(self, x: np.ndarray, d: int, k: np.ndarray) -> np.ndarray:
        t = x - self.x[k]
        c0, c1, c2 = self.c[:, k]
        w, A = self.w, self.A
        s, c = np.sin(w * t), np.cos(w * t)
        one_minus_cos = 2 * np.sin(w * t / 2) ** 2
        if d == 0:
            integral = c0 * t * t / 2 + c1 * (t / w - s / w ** 2) + c2 * one_minus_cos / w ** 2
            return self.p[k] + self.v[k] * t + A * integral
        if d == 1:
            return self.v[k] + A * (c0 * t + c1 * one_minus_cos / w + c2 * s / w)
        if d == 2:
            return A * (c0 + c1 * s + c2 * c)
        return A * w * (c1 * c - c2 * s)

    def __call__(self, x: np.ndarray, d: int) -> np.ndarray:
        k = np.clip(np.searchsorted(self.x, x, side="right") - 1, 0, len(self.x) - 1)
        return self._eval(x, d, k)


_MODIFIED_TRAPEZOID = _SineConstantAcceleration(
    starts=[0, 1 / 8, 3 / 8, 5 / 8, 7 / 8], c0=[0, 1, 0, -1, 0], c1=[1, 0, 0, 0, 0], c2=[0, 0, 1, 0, -1],
    omega=4 * math.pi)

#: law -> (S^(d)(x, d), the x in (0, 1) where S''' jumps: pieces of a spline must end there)
_NORMALIZED = {
    "cycloidal": (_cycloidal, ()),
    "polynomial-345": (_polynomial_345, ()),
    "modified-trapezoid": (_MODIFIED_TRAPEZOID, (1 / 8, 3 / 8, 5 / 8, 7 / 8)),
}


def normalized_law(law: str, x, derivative: int = 0) -> np.ndarray:
    """S^(derivative)(x) of a named law on x in [0, 1] (S(0) = 0, S(1) = 1)."""
    if law not in _NORMALIZED:
        raise ParameterError("law", law, f"one of {LAWS!r}")
    derivative = integer("derivative", derivative, "0, 1, 2 or 3", lambda d: 0 <= d <= 3)
    return _NORMALIZED[law][0](np.asarray(x, float), derivative)


@dataclass(frozen=True)
class Segment:
    """One segment of a motion law: over the cam angle ``angle`` (rad, > 0) the follower moves by
    ``rise`` (> 0 up, < 0 back, 0 for a dwell) along ``law`` (one of :data:`LAWS`, or ``"dwell"``)."""

    law: str
    angle: float
    rise: float = 0.0

    def __post_init__(self):
        valid = ("dwell",) + LAWS
        if self.law not in valid:
            raise ParameterError("law", self.law, f"one of {valid!r}")
        angle = finite("angle", self.angle, "a finite segment angle, rad")
        if not angle > 0:
            raise ParameterError("angle", angle, "> 0 rad (a segment's cam angle)")
        rise = finite("rise", self.rise, "a finite change of lift over the segment")
        if (self.law == "dwell") != (rise == 0):
            raise ParameterError("rise", rise, "0 for a dwell, nonzero for a rise or a return",
                                 reason=f"segment law {self.law!r}")

    @property
    def breakpoints(self) -> tuple[float, ...]:
        """The x in (0, 1) where the law's third derivative jumps (inside the segment)."""
        return () if self.law == "dwell" else _NORMALIZED[self.law][1]

    def s(self, x: np.ndarray, derivative: int) -> np.ndarray:
        """rise * S^(d)(x) / angle^d: the lift change (d = 0) or its derivative in theta."""
        if self.law == "dwell":
            return np.zeros_like(x)
        return self.rise * _NORMALIZED[self.law][0](x, derivative) / self.angle ** derivative


@dataclass(frozen=True)
class MotionLaw:
    """A follower motion law over one cam revolution: ``segments`` one after the other from
    theta = 0, their angles summing to 2 pi, starting at lift 0, never below 0 and back at 0 after
    the last (so that s is periodic and C2: s, s', s'' continuous everywhere, s''' jumps at the
    segment ends and at the laws' own breakpoints, :attr:`knots`)."""

    segments: tuple[Segment, ...]

    def __post_init__(self):
        segments = tuple(self.segments)
        if not segments or not all(isinstance(g, Segment) for g in segments):
            raise ParameterError("segments", self.segments, "a non-empty sequence of Segment")
        object.__setattr__(self, "segments", segments)
        total = math.fsum(g.angle for g in segments)
        if abs(total - TWO_PI) > ANGLE_SUM_RTOL * TWO_PI:
            raise ParameterError("segments", total, "segment angles summing to 2 pi = 6.283185307179586 rad",
                                 problem=f"angles sum to {total!r} rad ({math.degrees(total)!r} deg)")
        levels = np.cumsum([0.0] + [g.rise for g in segments])
        lift = float(levels.max())
        if not lift > 0:
            raise ParameterError("segments", lift, "a law that lifts the follower (maximum lift > 0)",
                                 problem=f"never lift the follower (maximum lift {lift!r})")
        if levels.min() < -1e-12 * lift or abs(levels[-1]) > 1e-12 * lift:
            raise ParameterError("segments", tuple(levels), "lifts >= 0, back at 0 after the last segment "
                                 "(rises and returns summing to 0; relative tolerance 1e-12)",
                                 problem=f"reach the lifts {tuple(float(v) for v in levels)}")

    @property
    def lift(self) -> float:
        """The largest lift (m or rad)."""
        return float(np.cumsum([0.0] + [g.rise for g in self.segments]).max())

    @property
    def starts(self) -> np.ndarray:
        """The cam angle at which each segment starts, and 2 pi at the end (K + 1 values)."""
        ends = np.cumsum([g.angle for g in self.segments])
        return np.concatenate([[0.0], ends[:-1], [TWO_PI]])

    @property
    def knots(self) -> np.ndarray:
        """The cam angles in [0, 2 pi] where s''' may jump: every segment end and each law's
        internal breakpoints; the pieces of a spline of this law must end there."""
        starts = self.starts
        inner = [starts[k] + x * g.angle for k, g in enumerate(self.segments) for x in g.breakpoints]
        return np.unique(np.concatenate([starts, inner]))

    def s(self, theta, derivative: int = 0) -> np.ndarray:
        """The lift s(theta) (derivative 0) or d^k s / d theta^k, k = 1..3, at cam angles theta
        (rad, any real: reduced modulo 2 pi). At a segment end s''' is the next segment's."""
        derivative = integer("derivative", derivative, "0, 1, 2 or 3", lambda d: 0 <= d <= 3)
        shape = np.shape(theta)
        theta = np.mod(np.asarray(theta, float), TWO_PI).ravel()
        starts = self.starts
        k = np.clip(np.searchsorted(starts, theta, side="right") - 1, 0, len(self.segments) - 1)
        levels = np.cumsum([0.0] + [g.rise for g in self.segments])[:-1]
        out = np.zeros_like(theta) + (levels[k] if derivative == 0 else 0.0)
        for j, g in enumerate(self.segments):
            on = k == j
            if np.any(on) and g.law != "dwell":
                out[on] += g.s((theta[on] - starts[j]) / g.angle, derivative)
        return out.reshape(shape)

    __call__ = s


def rise_dwell_return(lift: float, angles, law: str = "cycloidal", return_law: str | None = None) -> MotionLaw:
    """The classic cam: rise by ``lift`` over ``angles[0]``, dwell ``angles[1]``, return over
    ``angles[2]``, dwell ``angles[3]`` (rad; the four sum to 2 pi; a dwell may be 0 and is then
    left out). The return follows ``return_law`` (default: ``law``)."""
    lift = finite("lift", lift, "> 0 (m for a translating follower, rad for an oscillating one)")
    if not lift > 0:
        raise ParameterError("lift", lift, "> 0 (m for a translating follower, rad for an oscillating one)")
    try:
        rise, top, back, rest = (float(a) if not isinstance(a, bool) else a for a in angles)
    except (TypeError, ValueError):
        raise ParameterError("angles", angles, "four angles (rise, dwell, return, dwell) in rad") from None
    for name, a, smallest in (("rise angle", rise, "> 0"), ("dwell angle", top, ">= 0"),
                              ("return angle", back, "> 0"), ("dwell angle", rest, ">= 0")):
        if not math.isfinite(a) or a < 0 or (smallest == "> 0" and a == 0):
            raise ParameterError("angles", angles, "rise, dwell, return, dwell angles: finite, rise and "
                                 "return > 0, dwells >= 0 (rad)", problem=f"has the {name} {a!r}")
    segments = [Segment(law, rise, lift)]
    if top > 0:
        segments.append(Segment("dwell", top))
    segments.append(Segment(return_law or law, back, -lift))
    if rest > 0:
        segments.append(Segment("dwell", rest))
    return MotionLaw(tuple(segments))
