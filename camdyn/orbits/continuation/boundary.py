"""Where a period-1 orbit's follower starts to leave the cam, as a two-parameter curve
(:mod:`.grazing`) follows it: the largest value over the orbit of a test output g through zero.

* A compliant contact (:data:`GRAZING`): g = psi_i, the gap (m; Eq. 6).
* A rigid contact (:data:`LIFT_OFF`; the scene's kernels switch on the contact force,
  :func:`.lift_off.constrained`): g = -F_n (N), the constraint's force, which the follower riding
  the cam needs: the gap is identically 0 there (rounding), so it cannot tell, and the follower
  leaves where the least F_n reaches 0 (:mod:`.lift_off`, the one-parameter event ``lift_off``).

Where g's largest value lies just past a junction of a cam of arcs (a corner: the needed force
jumps there, :func:`.lift_off.restart_force`), g has no smooth maximum and the rate condition of
:mod:`.grazing` no root at it: the onset's time is then pinned to the junction, RESTART_NUDGE T
past it (:func:`onset`; the junction's time is a fixed fraction of the period at a constant cam
speed: a flat face on the second rig's cam touches it at an angle of the cam alone).
"""
from __future__ import annotations

import math
from typing import Callable, NamedTuple

import numpy as np

from .lift_off import RESTART_NUDGE, constrained, forces_after, least_force
from .sampled import refined_max

#: the gap's rate at t_g is its central difference over t_g +- WINDOW T, not the pointwise
#: psi_i_dot: on a stiff contact the state carries a ripple at the contact's frequency (period
#: 1.5e-4 s on reference-experiment, whose deflection is 2e-10 m) that puts ~2e-4 of the rate's
#: scale d 2 pi / T of noise on psi_i_dot and makes psi_i_ddot meaningless, while psi_i's own
#: noise is ~2e-17 m (1e-7 d); over WINDOW T the difference's noise is ~1e-6 of the scale (it
#: enters the parameter derivatives divided by their relative step, ~3e-5).  The difference
#: vanishes at the maximum of a parabola exactly; a cubic term moves its root by ~(2 pi WINDOW)^2
#: / 6 of the period's radian, and psi_i(t_g) from the maximum by the square of that: ~1e-7 d
WINDOW = 1e-2
#: the rate's window of a rigid contact's force (:data:`LIFT_OFF`): F_n has no contact ripple
#: (no compliance; the constrained mode's drift decays), so the cubic term's error, ~1e-7 d at
#: WINDOW, sets the window: at WINDOW the lift-off speed on the example rig lay 1.6e-8 of itself
#: above the inverse kinematics', at 3e-3 3e-10 (the fourth power of the window)
FORCE_WINDOW = 1e-3
#: a rigid orbit is converged at FORCE_MARGINS margins from the lift-off, within one: past the
#: lift-off g is inf (:func:`_far`), not a continuation of the contact side that the corrector can
#: come back from, so the band it accepts must not reach 0 (at 1, [-2, 0] margins, the accepted
#: points drifted to F_n = 0+ along the second rig's corner curve and every step from there flew)
FORCE_MARGINS = 2.0


class Boundary(NamedTuple):
    """A test output g = ``sign`` times a generated output (``row``: the kernels' OUT_<NAME>),
    its ``unit``, the one-parameter event ``kind`` that locates its crossing along a branch
    (:data:`.events.KINDS`) and ``of_point``, that event's test value at a branch's point (< 0
    on the contact side), the Dataset attribute of its scale, what it is, ``contact_only``:
    g is defined in the contact modes alone (a sample in flight: the orbit has left), the
    ``window`` (a fraction of T) of the rate's central difference at the grazing's time, and
    ``largest(model, g, modes, t, restarts)``: the largest of g over a periodic sampled orbit
    (the samples' modes and times, the last the first's repeat; the times of its switches), and
    ``margins``: the orbit is converged at g(t_g) = -margins gap_tol d, within gap_tol d."""

    kind: str
    row: Callable
    sign: float
    unit: str
    scale_attribute: str
    meaning: str
    contact_only: bool
    of_point: Callable
    window: float
    largest: Callable
    margins: float

    def values(self, model, out: np.ndarray, modes: np.ndarray) -> np.ndarray:
        """g at samples in ``modes``, from the rows of :meth:`camdyn.model.model.Model.outputs_at`;
        where ``contact_only``, inf at a sample in flight (:func:`_far`)."""
        return _far(self, model, modes, self.sign * out[self.row(model.kernels)])

    def at(self, model, m: int, t: float, y) -> float:
        """g at one state y in mode m (the generated output, no run; inf in flight where ``contact_only``)."""
        g = self.sign * model.outputs(m, t, *y)[model.kernels.OUTPUTS[self.row(model.kernels)]]
        return float(_far(self, model, np.array([m]), np.array([g]))[0])


def _far(boundary: Boundary, model, modes, g: np.ndarray) -> np.ndarray:
    """g with inf at the samples in a flight mode where the boundary is ``contact_only``: a rigid
    follower in flight needs no force (F_n = 0 there, g = 0), which the extended system would take
    for an orbit at the lift-off, within its margin of the converged -margin; inf puts it beyond
    (the corrector fails there and its step is retried shorter, as past a grazing)."""
    if not boundary.contact_only:
        return g
    return np.where(np.asarray(model.kernels.CONTACT_OF_MODE, dtype=bool)[np.asarray(modes, dtype=int)], g, math.inf)



def _largest_gap(model, g, modes, t, restarts) -> float:
    """The largest sampled gap, refined by the parabola through its neighbours."""
    return refined_max(g)


def _largest_force(model, g, modes, t, restarts) -> float:
    """The largest of -F_n: less the least sampled force (:func:`.lift_off.least_force`: refined
    unless a restart of the contact lies among its neighbours, where the force jumps); inf where
    a sample is in flight (the orbit leaves the cam)."""
    if not np.all(np.asarray(model.kernels.CONTACT_OF_MODE, dtype=bool)[modes]):
        return math.inf
    return -least_force(-g, t, restarts)


#: a compliant orbit is converged at GAP_MARGINS margins from grazing: the corrector's tolerance on the
#: gap's row is gap_tol d either side, so the converged orbit has psi_i(t_g) within [-3, -1] gap_tol d,
#: on the contact side, and an iterate lifts off only when it lies more than 2 gap_tol d past the
#: target (at 1, the band reached zero gap: on reference-experiment against k_s, the chord's last
#: iterates landed past it at 24 of its 45 steps, the flight's gap and rate then no residual to converge on)
GAP_MARGINS = 2.0
GRAZING = Boundary("grazing", lambda K: K.OUT_PSI_I, 1.0, "m", "deflection_scale_m",
                   "psi_i, the gap (0 at grazing)", False, lambda p: p.max_gap, WINDOW, _largest_gap, GAP_MARGINS)
LIFT_OFF = Boundary("lift_off", lambda K: K.OUT_F_N, -1.0, "N", "force_scale_n",
                    "-F_n, less the rigid contact's force (0 at lift-off)", True, lambda p: p.lift_off,
                    FORCE_WINDOW, _largest_force, FORCE_MARGINS)


def boundary_of(kernels) -> Boundary:
    """The boundary of a scene's generated module: LIFT_OFF on a rigid contact, else GRAZING."""
    return LIFT_OFF if constrained(kernels) else GRAZING


class Onset(NamedTuple):
    """Where the orbit comes nearest the boundary: ``phase`` (of the period, after the section),
    g's scale d (-min g over the orbit: the largest deflection, m, or force, N), and ``corner``:
    the phase is pinned just past a junction (NaN: g's smooth maximum)."""

    phase: float
    scale: float
    corner: float


def onset(boundary: Boundary, model, backend: str, tr, t_span) -> Onset:
    """The :class:`Onset` of an orbit's run ``tr`` over one period ``t_span`` (its samples
    equally spaced, the last the first's repeat): g's largest sample refined by the parabola
    through its neighbours; on a rigid contact, where the force just past a junction (a switch
    record) is less than every sample's, that junction, RESTART_NUDGE T past it."""
    t0, t1 = t_span
    g = boundary.values(model, model.outputs_at(tr.mode, tr.t, tr.alpha, tr.alpha_dot, backend), tr.mode)[:-1]
    k = int(np.argmax(g))
    a, b, c = g[k - 1], g[k], g[(k + 1) % g.size]
    shift = 0.5 * (a - c) / (a - 2 * b + c) if a - 2 * b + c < 0 else 0.0
    phase, corner = float(((k + shift) / g.size) % 1.0), math.nan
    records = tr.switches.records
    if boundary.contact_only and records.size:
        after = boundary.sign * forces_after(model, backend, records)
        j = int(np.argmax(after))
        if after[j] > np.max(g):
            corner = float(((records["t"][j] - t0) / (t1 - t0) + RESTART_NUDGE) % 1.0)
    return Onset(phase if math.isnan(corner) else corner, float(-np.min(g)), corner)
