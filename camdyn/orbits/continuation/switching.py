"""Branch switching at a period doubling: the orbit of period 2 n T next to the located event,
by Newton's method on P_2n from the period-n orbit displaced along the critical eigenvector,
and the first point of the branch it is on."""
from __future__ import annotations

import math

import numpy as np

from ...errors import CamdynError
from ..section_map import MapFailure
from ..shooting import ShootingSettings, newton, sorted_multipliers
from .corrector import first_point
from .events import KIND, Found
from .problem import Branch, Leg, Point

#: branch switching tries these offsets along the eigenvector (in units of the motion's scale)
SWITCH_OFFSETS = (1e-3, 1e-2, 3e-2, 1e-1)
#: Newton's iterations on P_2n from each displaced start
SWITCH_ITERATIONS = 20
#: a period-2n orbit is accepted when P_n moves it by more than this many times tol (scaled):
#: not the period-n orbit itself
APART = 1e3


def switch(leg: Leg, e: Point, p: Point, q: Point):
    """The period-2n orbit next to a period doubling located at ``e`` between p and q: Newton on
    P_2n from the P_n orbit +/- eps v (v the eigenvector of the multiplier near -1, eps in
    SWITCH_OFFSETS times the motion's scale), on the side where P_n is unstable first.  Accepted
    when P_n(x) differs from x by more than APART tol (scaled): not the P_n orbit itself.
    Returns (lambda, x, mode) or None."""
    mu, V = np.linalg.eig(e.jacobian)
    v = V[:, int(np.argmin(np.abs(mu + 1.0)))].real
    v = v / np.max(np.abs(v / leg.scale))
    for side in sorted((p, q), key=lambda r: -np.max(np.abs(sorted_multipliers(r.jacobian)))):
        try:
            doubled = leg.doubled().section_map(side.lam, side.mode)
            single = leg.section_map(side.lam, side.mode)
        except CamdynError:
            continue
        x = _doubled_orbit(leg, doubled, single, side.x, v)
        if x is not None:
            return side.lam, x, side.mode
    return None


def _doubled_orbit(leg: Leg, doubled, single, x, v):
    """A fixed point of P_2n (``doubled``) that P_n (``single``) moves, by Newton's method from
    x +/- eps v; None."""
    provider = leg.problem.jacobian(doubled, leg.scale)
    settings = ShootingSettings(leg.settings.tol, SWITCH_ITERATIONS)
    for eps in SWITCH_OFFSETS:
        for sign in (1.0, -1.0):
            found = newton(doubled, provider, x + sign * eps * v, leg.scale, settings)
            if not found.outcome.ok:
                continue
            try:
                apart = np.max(np.abs(single(found.x) - found.x) / leg.scale)
            except MapFailure:
                continue
            if apart > APART * leg.settings.tol:
                return found.x
    return None


def switched(leg: Leg, branch: Branch, index: int, found: list[Found], first_event: int):
    """The branches of period 2 n T switched to at the events of ``found`` whose kind switches
    (:data:`camdyn.orbits.continuation.events.KINDS`) on ``branch`` (number ``index``; its events
    numbered from ``first_event``), each with its first point, its leg and its origin; where no
    such orbit is found, the branch's message says so."""
    out = []
    for k, (event, e, p, q) in enumerate(found):
        if not KIND[event.kind].switch_branch:
            continue
        orbit = switch(leg, e, p, q)
        if orbit is None:
            branch.message += f"; no period-{2 * branch.periods} orbit found at the period doubling " \
                              f"at {event.lam:.8g}"
            continue
        lam, x, mode = orbit
        doubled = leg.doubled()
        try:
            start = first_point(doubled, lam, x, mode, math.copysign(1.0, lam - event.lam))
        except MapFailure:
            continue
        out.append((doubled, Branch(doubled.periods, parent=index, origin=first_event + k), start))
    return out
