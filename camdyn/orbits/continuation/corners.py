"""Corner impacts (issue 28): where an orbit's Newton impacts land on the cam, against the
profile's junctions (the corners of a cam of arcs, where its curvature jumps).

An impact lands on the cam at the contact's body angle phi (:mod:`camdyn.model.profiles`): the
translating flat face at phi = gamma - Theta, the paper's oscillating face at
phi = 3 pi/2 - a - Theta, with Theta and the follower's coordinate at the impact's time
(:meth:`camdyn.model.followers.TranslatingFollower.contact_angle`, ``OscillatingFollower``'s: the gap
is zero there, so the contact is that of the rigid follower).  A *corner impact* is an impact
landing exactly on a junction of the profile as a parameter changes (Osorio, di Bernardo &
Santini, SIAM J. Appl. Dyn. Syst. 2008): the test function is the signed angular distance of
each impact's landing angle to each junction (:func:`signed_distances`), and the event is a sign
change of one of them between two consecutive orbits that is continuous (:func:`crossings`).
"""
from __future__ import annotations

import math
from typing import NamedTuple

import numpy as np

from ...engine import impact_transitions
from ...model.followers import follower_of_rig

TWO_PI = 2 * math.pi


class Landings(NamedTuple):
    """Where an orbit's impacts land on the cam: ``angles``, the contact's body angle phi (rad, in
    [0, 2 pi)) of each switch whose reset is Newton's impact law, in time order from the section;
    ``junctions``, the profile's junction angles (rad, in [0, 2 pi), sorted, each once).  Either is
    empty where there is none: a compliant scene has no impacts, the paper's circle no junctions."""

    angles: np.ndarray
    junctions: np.ndarray


#: no impacts and no junctions: never a corner impact
NO_LANDINGS = Landings(np.empty(0), np.empty(0))


def profile_junctions(rig) -> np.ndarray:
    """The junction angles of the rig's profile (rad, in [0, 2 pi), sorted, each once): the
    profile's ``junctions()`` (whose last repeats the first a turn on), reduced; empty on the
    paper's circle (no profile) or a profile without junctions."""
    if rig.profile is None:
        return np.empty(0)
    return np.unique(np.mod(np.asarray(rig.profile.junctions(), dtype=float), TWO_PI))


def landings(run) -> Landings:
    """The landings of a run of the stroboscopic map (:class:`~.corrector.Run`): the impacts are
    the switch records whose ``transition`` resets by Newton's law
    (:func:`camdyn.engine.impact_transitions`), their phi from the follower's contact angle at the
    record's time and coordinate (the coordinate is not changed by the reset).  Empty angles in a
    scene without Newton impacts; empty junctions on a cam without them."""
    model = run.section_map.model
    records = run.trajectory.switches.records
    impacts = records[np.isin(records["transition"], impact_transitions(model.kernels))]
    junctions = profile_junctions(model.rig)
    if not impacts.size:
        return Landings(np.empty(0), junctions)
    theta = model.cam_state(impacts["t"])[0]
    phi = follower_of_rig(model.rig).contact_angle(impacts["alpha"], theta)
    return Landings(np.mod(phi, TWO_PI), junctions)


def wrapped(angle) -> np.ndarray:
    """An angle (rad) wrapped to (-pi, pi]."""
    return math.pi - np.mod(math.pi - np.asarray(angle, dtype=float), TWO_PI)


def signed_distances(landing: Landings) -> np.ndarray:
    """The test function: d[i, j] = phi_i - a_j wrapped to (-pi, pi] (rad), the signed angular
    distance of impact i's landing angle phi_i from junction a_j, shape (impacts, junctions)."""
    return wrapped(landing.angles[:, None] - landing.junctions[None, :])


def near_bound(junctions: np.ndarray) -> float:
    """How near a junction an impact lands for its distance to change sign continuously: half the
    least angular spacing of neighbouring junctions (around the turn), at most a quarter turn.
    Within it the junction is the impact's nearest, and the wrap of the distance at +-pi (the far
    side of the cam) is excluded; NaN without junctions."""
    if not junctions.size:
        return math.nan
    spacing = np.diff(np.append(junctions, junctions[0] + TWO_PI))
    return 0.5 * min(float(np.min(spacing)), math.pi)


def crossings(a: Landings, b: Landings) -> list[tuple[int, int]]:
    """The corner impacts between two consecutive orbits a and b: the pairs (i, j) of an impact
    and a junction whose signed distance (:func:`signed_distances`) changes sign strictly
    (d_a d_b < 0) and continuously: both |d_a| and |d_b| are below :func:`near_bound` of the
    junctions.  Impacts are matched by their order in the period from the section: only when
    both orbits have as many impacts (else none is matched: no corner impact is told across a
    change of the impact count).  None without junctions or impacts."""
    if a.angles.size != b.angles.size or not a.angles.size or not a.junctions.size:
        return []
    da, db = signed_distances(a), signed_distances(b)
    near = near_bound(a.junctions)
    hit = (da * db < 0) & (np.abs(da) < near) & (np.abs(db) < near)
    return [(int(i), int(j)) for i, j in zip(*np.nonzero(hit))]


def distance_of(landing: Landings, impacts: int, pair: tuple[int, int]) -> float:
    """The signed distance of impact i to junction j, ``pair = (i, j)``, on an orbit whose impacts
    are matched to those of an orbit with ``impacts`` of them (the same count, by order); NaN
    when the count differs (no match)."""
    i, j = pair
    if landing.angles.size != impacts:
        return math.nan
    return float(wrapped(landing.angles[i] - landing.junctions[j]))
