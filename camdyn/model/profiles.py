"""Cam profiles as support functions h(phi) (issue 27).

A convex cam is described, in its body frame, by its support function h(phi): the distance from
the rotation centre E to the tangent line whose outward normal is u(phi) = (cos phi, sin phi), phi
counter-clockwise from the body x axis. Then

    contact point     c(phi) = h u + h' u',   u' = (-sin phi, cos phi),
    radius of curvature  rho = h + h''         (convex  <=>  rho > 0 at every phi).

In the fixed frame the body x axis sits at the cam angle Theta: a fixed-frame direction at angle
beta has the body angle phi = beta - Theta.

Three families, each frozen data with a vectorized ``h(phi, derivative)`` (derivative 0..3) and a
``block()``: the flat float64 array the generated kernels read.

- :class:`EccentricCircle` -- the paper's cam, h = r_c - e cos(phi) (the body axis along G_c->E);
  no block (its constants are the rig's r_c and e).
- :class:`SplineProfile` -- a periodic piecewise quintic in phi with non-uniform breakpoints,
  block ``[K, phi_0..phi_K, c_{0,0..5}, ..., c_{K-1,0..5}]``, phi_K = phi_0 + 2 pi, and on piece k
  h = sum_j c_{k,j} (phi - phi_k)^j (phi reduced into [phi_0, phi_0 + 2 pi)).
- :class:`ArcProfile` -- circular arcs, block ``[K, a_0..a_K, rho_0.., cx_0.., cy_0..]``: on
  [a_k, a_{k+1}) h = rho_k + cx_k cos(phi) + cy_k sin(phi) (a circle of radius rho_k centred at
  (cx_k, cy_k)), a_K = a_0 + 2 pi; C1 (h, h' continuous), the curvature jumps at the junctions.

Every constructor refuses a cam that is not convex (:func:`check_convex`).
"""
from __future__ import annotations

import math
from dataclasses import dataclass

import numpy as np

from .._checks import finite, integer
from ..errors import ParameterError
from ..vocabulary import ECCENTRIC

__all__ = ["EccentricCircle", "SplineProfile", "ArcProfile", "check_convex", "CONVEXITY_SAMPLES",
           "JUNCTION_RTOL", "profile_from_block", "hermite_coefficients", "quintic_pieces", "locate"]

TWO_PI = 2 * math.pi
#: angles at which convexity is checked, evenly spaced, besides every breakpoint and piece middle
CONVEXITY_SAMPLES = 4096
#: the jump of h, h' (and, for a spline, h'') allowed at a junction, relative to the cam's size
#: max abs(h): far above the rounding of a construction in double precision (~1e-15), far below any
#: real step of a cam drawing (a micrometre on a 10 mm cam is 1e-4)
JUNCTION_RTOL = 1e-9


def _derivative(derivative) -> int:
    return integer("derivative", derivative, "0, 1, 2 or 3", lambda d: 0 <= d <= 3)


class _Profile:
    """What every profile derives from h: curvature, contact point, convexity."""

    def radius_of_curvature(self, phi) -> np.ndarray:
        """rho = h + h'' (m): > 0 everywhere on a convex cam."""
        return self.h(phi) + self.h(phi, 2)

    def contact_point(self, phi) -> np.ndarray:
        """c(phi) = h u + h' u' in the body frame (m), shape ``phi.shape + (2,)``."""
        phi = np.asarray(phi, float)
        h, h1 = self.h(phi), self.h(phi, 1)
        c, s = np.cos(phi), np.sin(phi)
        return np.stack([h * c - h1 * s, h * s + h1 * c], axis=-1)

    def junctions(self) -> np.ndarray:
        """The angles where the profile's pieces meet (none for a circle)."""
        return np.empty(0)


def check_convex(profile, name: str = "profile", extra=()) -> None:
    """Refuse a cam that is not convex: rho = h + h'' <= 0 at any of :data:`CONVEXITY_SAMPLES`
    evenly spaced angles, the profile's junctions and piece middles, or ``extra`` angles. The
    ParameterError names the angle (deg, body frame) and the value of rho."""
    phi = np.concatenate([np.linspace(0, TWO_PI, CONVEXITY_SAMPLES, endpoint=False),
                          _with_middles(profile.junctions()), np.asarray(extra, float).ravel()])
    rho = profile.radius_of_curvature(phi)
    bad = ~(rho > 0)
    if np.any(bad):
        k = int(np.argmin(rho))
        deg = math.degrees(phi[k]) % 360
        raise ParameterError(name, float(rho[k]), "a convex cam: rho = h + h'' > 0 at every angle",
                             problem=f"is not convex: rho = {rho[k]:.6g} m at phi = {deg:.4f} deg "
                                     f"(body frame; the smallest rho found)")


def _with_middles(breaks: np.ndarray) -> np.ndarray:
    if breaks.size < 2:
        return breaks
    return np.concatenate([breaks, (breaks[:-1] + breaks[1:]) / 2])


@dataclass(frozen=True)
class EccentricCircle(_Profile):
    """The paper's cam: a circle of radius ``r_c`` whose centre G_c is ``e`` from the rotation
    centre E; the body x axis along G_c->E (Eq. 3), so G_c = (-e, 0) and h = r_c - e cos(phi)."""

    r_c: float
    e: float
    kind = ECCENTRIC

    def __post_init__(self):
        r_c = finite("r_c", self.r_c, "a finite cam radius > 0, m")
        if not r_c > 0:
            raise ParameterError("r_c", r_c, "> 0 m (cam radius)")
        e = finite("e", self.e, "a finite eccentricity, 0 <= e < r_c, m")
        if not 0 <= e < r_c:
            raise ParameterError("e", e, f"0 <= e < r_c = {r_c} m (the rotation centre inside the cam)")

    def h(self, phi, derivative: int = 0) -> np.ndarray:
        """h^(derivative)(phi) = d^k/dphi^k (r_c - e cos phi)."""
        phi = np.asarray(phi, float)
        d = _derivative(derivative)
        trig = (np.cos, np.sin, np.cos, np.sin)[d](phi)
        sign = (-1, 1, 1, -1)[d]
        return (self.r_c if d == 0 else 0.0) + sign * self.e * trig

    def block(self) -> np.ndarray:
        """No block: the generated kernels read r_c and e from the rig's parameters."""
        return np.empty(0)


def _frozen(array, name: str, shape_text: str, ndim: int) -> np.ndarray:
    try:
        a = np.array(array, dtype=float)
    except (TypeError, ValueError):
        raise ParameterError(name, array, shape_text) from None
    if a.ndim != ndim or not np.all(np.isfinite(a)):
        raise ParameterError(name, array, f"finite values, {shape_text}",
                             problem=f"has shape {a.shape}" if a.ndim != ndim else "has a value that is not finite")
    a.setflags(write=False)
    return a


def _periodic_breaks(breaks: np.ndarray, name: str) -> None:
    if breaks.size < 2 or not np.all(np.diff(breaks) > 0):
        raise ParameterError(name, tuple(breaks), "strictly increasing angles (rad), at least two",
                             problem="is not strictly increasing" if breaks.size >= 2 else "has fewer than two angles")
    span = breaks[-1] - breaks[0]
    if abs(span - TWO_PI) > 1e-12 * TWO_PI:
        raise ParameterError(name, float(span), "a last angle 2 pi after the first (relative tolerance 1e-12)",
                             problem=f"spans {span!r} rad, not 2 pi")


#: d^d/dt^d t^j = j!/(j-d)! t^(j-d): the factor of c_j in the d-th derivative, d = 0..3
_DFACTOR = np.array([[math.perm(j, d) for j in range(6)] for d in range(4)], float)


def quintic_pieces(coeffs: np.ndarray, k: np.ndarray, t, d: int) -> np.ndarray:
    """The d-th derivative of piece(s) k of a piecewise quintic at t = phi - phi_k (Horner)."""
    c = coeffs[k] * _DFACTOR[d]
    out = np.zeros(np.shape(t)) + c[..., 5]
    for j in range(4, d - 1, -1):
        out = out * t + c[..., j]
    return out


def hermite_coefficients(breaks: np.ndarray, h: np.ndarray, h1: np.ndarray, h2: np.ndarray) -> np.ndarray:
    """The (K, 6) coefficients of the quintic Hermite spline matching h, h', h'' at the K + 1
    ``breaks``. On a piece of width D, with r0, r1 D, r2 D^2 the misfits at the right end of the
    left end's quadratic Taylor polynomial in h, h', h'', the cubic, quartic and quintic
    coefficients are c3 D^3 = 10 r0 - 4 r1 + r2/2, c4 D^4 = -15 r0 + 7 r1 - r2,
    c5 D^5 = 6 r0 - 3 r1 + r2/2 (the three end conditions solved once)."""
    D = np.diff(breaks)
    c0, c1, c2 = h[:-1], h1[:-1], h2[:-1] / 2
    r0 = h[1:] - (c0 + D * (c1 + D * c2))
    r1 = (h1[1:] - (c1 + 2 * c2 * D)) * D
    r2 = (h2[1:] - 2 * c2) * D * D
    return np.stack([c0, c1, c2, (10 * r0 - 4 * r1 + r2 / 2) / D ** 3,
                     (-15 * r0 + 7 * r1 - r2) / D ** 4, (6 * r0 - 3 * r1 + r2 / 2) / D ** 5], axis=-1)


def locate(breaks: np.ndarray, phi) -> tuple[np.ndarray, np.ndarray]:
    """The piece k holding each phi (reduced into [breaks[0], breaks[0] + 2 pi)) and phi - breaks[k]."""
    phi = np.asarray(phi, float)
    inside = (phi >= breaks[0]) & (phi < breaks[0] + TWO_PI)      # kept as is: a breakpoint stays one
    reduced = np.where(inside, phi, breaks[0] + np.mod(phi - breaks[0], TWO_PI))
    k = np.clip(np.searchsorted(breaks, reduced, side="right") - 1, 0, breaks.size - 2)
    return k, reduced - breaks[k]


def _jumps(values_left: np.ndarray, values_right: np.ndarray, scale: float, name: str, what: str, at: np.ndarray):
    jump = np.abs(values_left - values_right)
    if np.any(jump > JUNCTION_RTOL * scale):
        k = int(np.argmax(jump))
        raise ParameterError(name, float(jump[k]), f"continuous {what} at every junction (jump <= "
                             f"{JUNCTION_RTOL:g} x max|h| = {JUNCTION_RTOL * scale:.3g} m)",
                             problem=f"jumps by {jump[k]:.3g} m in {what} at phi = {math.degrees(at[k]) % 360:.4f} deg")


@dataclass(frozen=True, eq=False)
class SplineProfile(_Profile):
    """A periodic piecewise quintic h(phi): ``breaks`` phi_0 < ... < phi_K = phi_0 + 2 pi (rad),
    ``coeffs`` (K, 6), h = sum_j coeffs[k, j] (phi - phi_k)^j on [phi_k, phi_{k+1}).

    Checked on construction: C2 at every breakpoint including the wrap-around (h, h', h'' jump by
    at most :data:`JUNCTION_RTOL` x max abs(h)), and convex (:func:`check_convex`)."""

    breaks: np.ndarray
    coeffs: np.ndarray
    kind = "spline"

    def __post_init__(self):
        breaks = _frozen(self.breaks, "breaks", "K + 1 angles (rad)", 1)
        coeffs = _frozen(self.coeffs, "coeffs", "a (K, 6) array of polynomial coefficients", 2)
        _periodic_breaks(breaks, "breaks")
        if coeffs.shape != (breaks.size - 1, 6):
            raise ParameterError("coeffs", coeffs.shape,
                                 f"shape (K, 6) = ({breaks.size - 1}, 6) for {breaks.size} breaks")
        object.__setattr__(self, "breaks", breaks)
        object.__setattr__(self, "coeffs", coeffs)
        scale = float(np.abs(coeffs[:, 0]).max())
        pieces, width = np.arange(breaks.size - 1), np.diff(breaks)
        for d, what in enumerate(("h", "h'", "h''")):      # each piece's right end against the next one's left
            right_ends = quintic_pieces(coeffs, pieces, width, d)
            _jumps(right_ends, np.roll(coeffs[:, d] * math.factorial(d), -1), scale, "coeffs", what, breaks[1:])
        check_convex(self)

    def h(self, phi, derivative: int = 0) -> np.ndarray:
        """h^(derivative)(phi), derivative 0..3 (m; per rad^derivative)."""
        d = _derivative(derivative)
        k, t = locate(self.breaks, phi)
        return quintic_pieces(self.coeffs, k, t, d)

    def junctions(self) -> np.ndarray:
        return self.breaks

    def block(self) -> np.ndarray:
        """``[K, phi_0, ..., phi_K, c_{0,0..5}, ..., c_{K-1,0..5}]`` (float64)."""
        return np.concatenate([[self.breaks.size - 1.0], self.breaks, self.coeffs.ravel()])

    @classmethod
    def from_block(cls, block) -> "SplineProfile":
        """The inverse of :meth:`block`."""
        block = np.asarray(block, float)
        K = _block_count(block, lambda K: 1 + (K + 1) + 6 * K)
        return cls(block[1:K + 2], block[K + 2:].reshape(K, 6))

    @classmethod
    def hermite(cls, breaks, h, h1, h2) -> "SplineProfile":
        """The quintic Hermite spline matching h, h', h'' at every breakpoint exactly (C2).

        ``breaks`` phi_0..phi_K (phi_K = phi_0 + 2 pi) and the values h, h', h'' there (K + 1 each;
        the last equal to the first: the profile is periodic); :func:`hermite_coefficients`."""
        breaks = _frozen(breaks, "breaks", "K + 1 angles (rad)", 1)
        _periodic_breaks(breaks, "breaks")
        values = [_frozen(v, name, f"{breaks.size} values", 1) for v, name in ((h, "h"), (h1, "h'"), (h2, "h''"))]
        if any(v.size != breaks.size for v in values):
            raise ParameterError("h", [v.size for v in values], f"{breaks.size} values each of h, h', h''")
        coeffs = hermite_coefficients(breaks, *values)
        return cls(breaks, coeffs)


def _block_count(block: np.ndarray, length) -> int:
    if block.ndim != 1 or block.size < 1 or block[0] != int(block[0]) or block[0] < 1:
        raise ParameterError("block", block, "a flat array starting with the piece count K >= 1")
    K = int(block[0])
    if block.size != length(K):
        raise ParameterError("block", block.size, f"{length(K)} values for K = {K} pieces",
                             problem=f"has {block.size} values")
    return K


@dataclass(frozen=True, eq=False)
class ArcProfile(_Profile):
    """A cam of circular arcs: on [angles[k], angles[k+1]) (rad) the circle of radius ``rho[k]``
    centred at (``cx[k]``, ``cy[k]``) in the body frame, h = rho_k + cx_k cos(phi) + cy_k sin(phi);
    angles[-1] = angles[0] + 2 pi.

    Checked on construction: every rho_k > 0 (convex) and C1 at every junction (h and h' jump by at
    most :data:`JUNCTION_RTOL` x max abs(h): neighbouring circles tangent where they meet)."""

    angles: np.ndarray
    rho: np.ndarray
    cx: np.ndarray
    cy: np.ndarray
    kind = "arcs"

    def __post_init__(self):
        angles = _frozen(self.angles, "angles", "K + 1 junction angles (rad)", 1)
        _periodic_breaks(angles, "angles")
        K = angles.size - 1
        for name in ("rho", "cx", "cy"):
            value = _frozen(getattr(self, name), name, f"{K} values (m)", 1)
            if value.size != K:
                raise ParameterError(name, value.size, f"{K} values, one per arc", problem=f"has {value.size} values")
            object.__setattr__(self, name, value)
        object.__setattr__(self, "angles", angles)
        if not np.all(self.rho > 0):
            k = int(np.argmin(self.rho))
            raise ParameterError("rho", float(self.rho[k]), "> 0 m for every arc (a convex cam)",
                                 problem=f"is not convex: rho = {self.rho[k]:.6g} m on the arc from "
                                         f"phi = {math.degrees(angles[k]) % 360:.4f} deg")
        ends = np.arange(K)
        at = angles[1:]
        scale = float(np.abs(self._arc(ends, angles[:-1], 0)).max())
        for d, what in enumerate(("h", "h'")):
            _jumps(self._arc(ends, at, d), self._arc(np.roll(ends, -1), at, d), scale, "angles", what, at)

    def _arc(self, k: np.ndarray, phi: np.ndarray, d: int) -> np.ndarray:
        c, s = np.cos(phi), np.sin(phi)
        cx, cy = self.cx[k], self.cy[k]
        trig = (cx * c + cy * s, -cx * s + cy * c, -cx * c - cy * s, cx * s - cy * c)[d]
        return (self.rho[k] if d == 0 else 0.0) + trig

    def h(self, phi, derivative: int = 0) -> np.ndarray:
        """h^(derivative)(phi), derivative 0..3; at a junction the next arc's value."""
        d = _derivative(derivative)
        k, _ = locate(self.angles, phi)
        return self._arc(k, np.asarray(phi, float), d)

    def junctions(self) -> np.ndarray:
        return self.angles

    def block(self) -> np.ndarray:
        """``[K, a_0..a_K, rho_0..rho_{K-1}, cx_0..cx_{K-1}, cy_0..cy_{K-1}]`` (float64), with an
        even K: a cam of an odd number of arcs has its longest arc given as two halves of the
        same circle, since the junction indicator of the generated kernels alternates its sign
        from arc to arc (derive.profile.JunctionFunction), which needs an even count to close."""
        angles, rho, cx, cy = self.angles, self.rho, self.cx, self.cy
        if rho.size % 2:
            k = int(np.argmax(np.diff(angles)))
            angles = np.insert(angles, k + 1, 0.5 * (angles[k] + angles[k + 1]))
            rho, cx, cy = (np.insert(v, k, v[k]) for v in (rho, cx, cy))
        return np.concatenate([[rho.size * 1.0], angles, rho, cx, cy])

    @classmethod
    def from_block(cls, block) -> "ArcProfile":
        """The inverse of :meth:`block`."""
        block = np.asarray(block, float)
        K = _block_count(block, lambda K: 1 + (K + 1) + 3 * K)
        a, rest = block[1:K + 2], block[K + 2:]
        return cls(a, rest[:K], rest[K:2 * K], rest[2 * K:])

    @classmethod
    def circular_arc_cam(cls, r_b: float, r_n: float, d: float, R: float, nose_angle: float = 0.0) -> "ArcProfile":
        """The classic circular-arc cam: base circle ``r_b`` centred at E, nose circle ``r_n``
        centred ``d`` from E at the body angle ``nose_angle``, and two flank arcs of radius ``R``
        tangent to both (internally: each flank circle holds both). Lift d + r_n - r_b.

        A flank circle's centre F is R - r_b from E and R - r_n from the nose centre N; the
        tangency with a circle of centre C is on the line from F through C, so the junction's
        outward normal is (C - F)/norm(C - F). Four arcs: nose, flank, base, flank."""
        lengths = (("r_b", r_b), ("r_n", r_n), ("d", d), ("R", R))
        r_b, r_n, d, R = (finite(n, v, "a finite length > 0, m") for n, v in lengths)
        nose_angle = finite("nose_angle", nose_angle, "a finite angle, rad")
        for name, value in (("r_b", r_b), ("r_n", r_n), ("d", d)):
            if not value > 0:
                raise ParameterError(name, value, "> 0 m")
        if not abs(r_b - r_n) < d:
            raise ParameterError("d", d, f"> |r_b - r_n| = {abs(r_b - r_n):.6g} m (neither circle inside the other)")
        smallest = (d + r_b + r_n) / 2                  # |F - E| + |F - N| > d: the flank circle reaches both
        if not R > smallest:
            raise ParameterError("R", R, f"> (d + r_b + r_n)/2 = {smallest:.6g} m: a flank radius whose circle "
                                 "holds both the base and the nose circle and touches each once")
        fb, fn = R - r_b, R - r_n                      # |F - E|, |F - N|
        x = (d * d + fb * fb - fn * fn) / (2 * d)       # F along the nose axis ...
        y = math.sqrt(fb * fb - x * x)                  # ... and across it (> 0 by the checks above)
        return cls._four_arcs(r_b, r_n, d, R, x, y, nose_angle)

    @classmethod
    def _four_arcs(cls, r_b, r_n, d, R, x, y, nose_angle) -> "ArcProfile":
        """Nose, upper flank (centre below the axis), base, lower flank, in the nose's frame, then
        turned by ``nose_angle``."""
        def normal_angle(centre, flank):   # outward normal at the tangency of a flank with a circle
            return math.atan2(centre[1] - flank[1], centre[0] - flank[0])
        upper, lower = (x, -y), (x, y)     # the flank whose arc is above the nose axis has its centre below it
        a0 = normal_angle((d, 0.0), lower) # nose starts where the lower flank leaves it (a negative angle)
        a1 = normal_angle((d, 0.0), upper)
        a2 = normal_angle((0.0, 0.0), upper)
        a3 = normal_angle((0.0, 0.0), lower) % TWO_PI
        angles = np.array([a0, a1, a2, a3, a0 + TWO_PI])      # increasing, for any valid R
        centres = np.array([(d, 0.0), upper, (0.0, 0.0), lower])
        c, s = math.cos(nose_angle), math.sin(nose_angle)
        turned = centres @ np.array([[c, s], [-s, c]])
        return cls(angles + nose_angle, np.array([r_n, R, r_b, R]), turned[:, 0], turned[:, 1])


def profile_from_block(kind: str, block) -> _Profile:
    """The spline or arc profile a block describes (the eccentric circle has none)."""
    makers = {"spline": SplineProfile.from_block, "arcs": ArcProfile.from_block}
    if kind not in makers:
        raise ParameterError("kind", kind, f"one of {tuple(makers)!r} (the eccentric circle has no block)")
    return makers[kind](block)
