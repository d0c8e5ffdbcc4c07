"""Cam synthesis: from a follower motion law s(theta) to the cam's support function h(phi), exact at
the spline's breakpoints, for each follower type (issue 27).

The conversion, theta the cam angle at which the follower has the lift s(theta) (cam turning
counter-clockwise):

- translating follower, guide at gamma: the contact normal is phi = gamma - theta and the face is
  y = r_b + s(theta) from E, so h(phi) = r_b + s(gamma - phi) exactly; h_phi = -s', h_phiphi = s''.
- oscillating follower (pivot P, width w_b): on the base circle the follower angle a_base solves
  (E - P).n(a) - w_b/2 = r_b with the contact on the bar; then a(theta) = a_base + s(theta),
  phi(theta) = 3 pi/2 - a - theta, H(theta) = (E - P).n(a) - w_b/2 = h(phi(theta)). With
  D = E - P, H' = (D.u_b) s', H'' = -(D.n) s'^2 + (D.u_b) s'', phi' = -(1 + s'), phi'' = -s'':
  h_phi = H'/phi', h_phiphi = (H'' - h_phi phi'')/phi'^2. phi must be monotone (1 + s' > 0).

The spline's breakpoints are the law's knots (segment ends and the laws' own breakpoints, mapped to
phi) and pieces in between; on each piece the quintic Hermite interpolant of h, h', h'' at both ends
(C2; between the knots of the law C-infinity up to interpolation error).
"""
from __future__ import annotations

import math

import numpy as np

from .._checks import integer, real
from ..errors import GeometryError, ParameterError
from .followers import OscillatingFollower, TranslatingFollower
from .profiles import CONVEXITY_SAMPLES, SplineProfile, hermite_coefficients, locate, quintic_pieces

__all__ = ["cam_from_law", "smallest_base_radius", "law_profile", "PIECE_LIMIT"]

TWO_PI = 2 * math.pi
#: the most pieces between two knots of a law the automatic choice makes
PIECE_LIMIT = 4096
#: where, between a piece's ends (as fractions of its cam angle), the spline is compared with the law
_PROBES = np.array([1, 2, 3, 4, 5]) / 6


def law_profile(law, follower, r_b: float):
    """The exact profile of ``law`` on ``follower`` with base circle radius ``r_b``, parametrized by
    the cam angle: a function theta -> (phi, h, h_phi, h_phiphi) (module docstring)."""
    if isinstance(follower, TranslatingFollower):
        def exact(theta):
            s0, s1, s2 = (law.s(theta, d) for d in range(3))
            return follower.gamma - theta, r_b + s0, -s1, s2
        return exact
    if not isinstance(follower, OscillatingFollower):
        raise ParameterError("follower", follower, "a TranslatingFollower or an OscillatingFollower")
    a_base = follower.base_angle(r_b)

    def exact(theta):
        s0, s1, s2 = (law.s(theta, d) for d in range(3))
        a = a_base + s0
        Dn, Du = follower.projections(a)
        H1, H2 = Du * s1, -Dn * s1 ** 2 + Du * s2
        phi1 = -(1 + s1)
        h1 = H1 / phi1
        return 1.5 * math.pi - a - theta, Dn - follower.w_b / 2, h1, (H2 + h1 * s2) / phi1 ** 2
    return exact


def _dense(law) -> np.ndarray:
    knots = np.asarray(law.knots, float)
    return np.unique(np.concatenate([np.linspace(0, TWO_PI, CONVEXITY_SAMPLES, endpoint=False),
                                     knots[:-1], (knots[:-1] + knots[1:]) / 2]))


def _min_rho(law, follower, r_b: float, theta: np.ndarray) -> tuple[float, float]:
    """The smallest rho = h + h_phiphi of the exact profile and the cam angle where it is: the
    dense angles' three lowest local minima each refined by a bounded scalar search between its
    neighbours (sampling alone misses a sharp minimum by ~ rho'' spacing^2 / 8, 1e-7 m here)."""
    from scipy.optimize import minimize_scalar
    exact = law_profile(law, follower, r_b)

    def rho(t):
        _, h, _, h2 = exact(np.atleast_1d(t))
        return h + h2
    values = rho(theta)
    lower = np.flatnonzero((values <= np.roll(values, 1)) & (values <= np.roll(values, -1)))
    best_value, best_theta = float(values.min()), float(theta[np.argmin(values)])
    for k in lower[np.argsort(values[lower])[:3]]:
        lo = theta[k - 1] if k > 0 else theta[-1] - TWO_PI
        hi = theta[k + 1] if k + 1 < theta.size else theta[0] + TWO_PI
        found = minimize_scalar(lambda t: rho(t)[0], bounds=(lo, hi), method="bounded", options={"xatol": 1e-12})
        if found.fun < best_value:
            best_value, best_theta = float(found.fun), float(found.x)
    return best_value, best_theta


def smallest_base_radius(law, follower) -> float:
    """The infimum of the base circle radii r_b for which ``law`` on ``follower`` gives a convex cam
    (0 when any r_b > 0 does).

    The smallest rho over the dense angles, refined near its lowest minima (:func:`_min_rho`).
    Translating: rho(phi) = r_b + s + s'' at theta = gamma - phi, so r_b > max(-(s + s'')).
    Oscillating: Brent's root of the smallest rho as a function of r_b (to 1e-12 relative),
    assuming rho grows with r_b (it does for a follower whose contact stays on the bar)."""
    theta = _dense(law)
    if isinstance(follower, TranslatingFollower):            # rho = r_b + (s + s''): r_b > -min(s + s'')
        return max(0.0, -_min_rho(law, follower, 0.0, theta)[0])
    x, y = follower.P_to_E
    top = math.hypot(x, y) - follower.w_b / 2             # the largest circle the follower reaches
    if not top > 0:
        raise GeometryError(f"the follower reaches no circle about E: |E - P| - w_b/2 = {top} m")
    from scipy.optimize import brentq
    rho = lambda r: _min_rho(law, follower, r, theta)[0]   # noqa: E731
    lo, hi = top * 1e-9, top * (1 - 1e-9)
    if not rho(hi) > 0:
        raise GeometryError("no base circle the follower reaches keeps this law's cam convex "
                            f"(tried up to r_b = {hi} m)")
    if rho(lo) > 0:
        return 0.0
    root = brentq(rho, lo, hi, xtol=1e-12 * top, rtol=1e-12)
    while not rho(root) > 0:                               # the side of the root where the cam is convex
        root = np.nextafter(root, math.inf) + 1e-12 * top
    return float(root)


def _check_law_on_follower(law, follower, r_b: float) -> None:
    """Refuse a cam that is not convex (saying the smallest base circle that works), and for an
    oscillating follower a contact normal that turns back or a contact off the bar."""
    theta = _dense(law)
    if isinstance(follower, OscillatingFollower):
        turn = 1 + law.s(theta, 1)
        if not np.all(turn > 0):
            k = int(np.argmin(turn))
            raise ParameterError("law", float(turn[k]), "1 + s'(theta) > 0 at every cam angle (the contact "
                                 "normal turning one way)",
                                 problem=f"is not a valid flat-faced cam: 1 + s' = {turn[k]:.6g} at theta = "
                                         f"{math.degrees(theta[k]):.4f} deg (the follower turns back faster than the cam)")
        a = follower.base_angle(r_b) + law.s(theta)
        chi = follower.projections(a)[1] / turn
        if not np.all(chi > 0):
            k = int(np.argmin(chi))
            raise GeometryError(f"the contact leaves the bar (chi = {chi[k]:.6g} m <= 0) at theta = "
                                f"{math.degrees(theta[k]):.4f} deg")
    rho, where = _min_rho(law, follower, r_b, theta)
    if not rho > 0:
        phi = law_profile(law, follower, r_b)(np.array([where]))[0][0]
        smallest = smallest_base_radius(law, follower)
        unit = "m" if isinstance(follower, TranslatingFollower) else "rad"
        raise ParameterError("r_b", r_b, f"> {smallest!r} m, the smallest base circle radius that keeps this "
                             f"cam convex", problem=f"= {r_b!r} m undercuts the cam (lift {law.lift!r} {unit}): rho = "
                             f"{rho:.6g} m at phi = {math.degrees(phi) % 360:.4f} deg (cam angle theta = "
                             f"{math.degrees(where) % 360:.4f} deg)")


def cam_from_law(law, follower, r_b: float, *, pieces_per_segment: int | None = None,
                 tol: float = 1e-12, tol_curvature: float = 1e-8) -> SplineProfile:
    """The cam (a :class:`~camdyn.model.profiles.SplineProfile`) that gives ``follower`` the lift
    ``law`` (anything with ``s(theta, derivative)``, ``knots`` and ``lift``: a
    :class:`~camdyn.model.motion_laws.MotionLaw` or a table's spline) on a base circle of radius
    ``r_b`` (m).

    The breakpoints are the law's knots mapped to phi, each interval between two knots cut into
    ``pieces_per_segment`` equal pieces of cam angle, or, by default, into as many as it takes for
    the spline to match the exact profile between its breakpoints (at five probes per piece) to
    ``tol`` x (max h - min h) in h and ``tol_curvature`` x (max h - min h) in h'' (m/rad^2).
    h'' cannot be much better than ~1e-10 of the lift: Hermite interpolation of values rounded to
    eps r_b gives h'' errors ~ eps r_b / width^2, growing as the pieces shrink.

    Refused: a cam that is not convex (naming the angle, rho, and the smallest base circle that
    works), an oscillating follower whose contact normal would turn back (1 + s' <= 0), a contact
    off the bar."""
    r_b = real("r_b", r_b, "> 0 m (base circle radius)", lambda v: 0 < v < math.inf)
    tol = real("tol", tol, "0 < tol < 1 (relative to the cam's lift)", lambda v: 0 < v < 1)
    tol_curvature = real("tol_curvature", tol_curvature, "0 < tol_curvature < 1", lambda v: 0 < v < 1)
    _check_law_on_follower(law, follower, r_b)
    exact = law_profile(law, follower, r_b)
    knots = np.asarray(law.knots, float)
    if pieces_per_segment is not None:
        n = integer("pieces_per_segment", pieces_per_segment, f"an integer, 1 <= n <= {PIECE_LIMIT}",
                    lambda n: 1 <= n <= PIECE_LIMIT)
        counts = np.full(knots.size - 1, n)
    else:
        counts = _choose_pieces(exact, knots, tol, tol_curvature)
    return SplineProfile(*_hermite(exact, _grid(knots, counts)))


def _grid(knots: np.ndarray, counts: np.ndarray) -> np.ndarray:
    """Cam angles: each knot interval cut into counts[i] equal pieces; ends at 2 pi."""
    cuts = [np.linspace(knots[i], knots[i + 1], n + 1)[:-1] for i, n in enumerate(counts)]
    return np.concatenate(cuts + [[TWO_PI]])


def _hermite(exact, theta: np.ndarray) -> tuple[np.ndarray, np.ndarray]:
    """Breakpoints and coefficients of the quintic Hermite spline through the exact profile at the
    cam angles ``theta`` (phi decreases as theta grows: the order reversed; phi at theta = 2 pi is
    set to exactly phi at theta = 0 minus 2 pi)."""
    phi, h, h1, h2 = exact(theta)
    breaks = phi[::-1].copy()
    breaks[0] = breaks[-1] - TWO_PI
    return breaks, hermite_coefficients(breaks, h[::-1], h1[::-1], h2[::-1])


def _interval_errors(exact, theta, breaks, coeffs, counts) -> tuple[np.ndarray, np.ndarray]:
    """The largest |error| of h and h'' at the probes, per knot interval."""
    probes = (theta[:-1, None] + np.diff(theta)[:, None] * _PROBES).ravel()
    phi, h, _, h2 = exact(probes)
    k, t = locate(breaks, phi)
    shape = (theta.size - 1, _PROBES.size)
    e0 = np.abs(quintic_pieces(coeffs, k, t, 0) - h).reshape(shape).max(axis=1)
    e2 = np.abs(quintic_pieces(coeffs, k, t, 2) - h2).reshape(shape).max(axis=1)
    starts = np.concatenate([[0], np.cumsum(counts)[:-1]])
    return np.maximum.reduceat(e0, starts), np.maximum.reduceat(e2, starts)


def _choose_pieces(exact, knots: np.ndarray, tol: float, tol_curvature: float) -> np.ndarray:
    """Pieces per knot interval: start at 1, grow each failing interval by the ratio its error
    exceeds the tolerance to the power 1/6 (h) or 1/4 (h''), the interpolation's orders, until
    all pass; refuse when an interval stops improving (the rounding floor) or needs more than
    :data:`PIECE_LIMIT` pieces."""
    _, h, _, _ = exact(np.linspace(0, TWO_PI, CONVEXITY_SAMPLES))
    scale = float(h.max() - h.min())
    counts = np.full(knots.size - 1, 1)
    worst = np.inf
    while True:
        theta = _grid(knots, counts)
        e0, e2 = _interval_errors(exact, theta, *_hermite(exact, theta), counts)
        ratio = np.maximum((e0 / (tol * scale)) ** (1 / 6), (e2 / (tol_curvature * scale)) ** (1 / 4))
        if np.all(ratio <= 1):
            return counts
        if not ratio.max() < worst or np.any(counts[ratio > 1] >= PIECE_LIMIT):
            k = int(np.argmax(ratio))
            name, value = ("tol", tol) if e0[k] > tol * scale else ("tol_curvature", tol_curvature)
            raise ParameterError(name, value, "a tolerance the spline can meet (or give pieces_per_segment)",
                                 problem=f"is not met: {counts[k]} pieces between the knots at theta = "
                                 f"{math.degrees(knots[k]):.4f} and {math.degrees(knots[k + 1]):.4f} deg leave errors "
                                 f"{e0[k] / scale:.3g} (h) and {e2[k] / scale:.3g} (h'') of the lift, tolerances "
                                 f"{tol:g} and {tol_curvature:g}")
        worst = ratio.max()
        grown = np.ceil(counts * ratio * 1.15).astype(int)
        counts = np.where(ratio > 1, np.minimum(grown, PIECE_LIMIT), counts)
