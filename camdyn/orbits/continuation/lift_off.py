"""Lift-off (issue 28): where a rigid follower's period-n contact orbit starts to leave the cam.

On a rigid scene the follower rides the cam in the constrained mode (``CONTACT_OF_MODE``) with
psi_i = 0 to rounding, so the largest gap (``grazing``'s test) is noise on every contact orbit.
The contact there is the constraint's multiplier, the force F_n (``OUT_F_N``) it needs to keep
the follower on the cam; the follower leaves where F_n turns negative (the transition on
``SURFACE_CONTACT_FORCE``).  The test function of :func:`lift_off` is

* on a contact orbit (every sample and switch in a contact mode): ``-min F_n`` over the orbit
  (N, <= 0), the least of the samples' F_n refined by the quartic through it and its
  neighbours (:func:`quartic_least`) and of F_n just after each restart of the contact (a
  junction of a cam of arcs, where the needed force jumps: the sampled minimum would miss it);
* on an orbit that leaves the cam (a sample or a switch in a flight mode): the flight's largest
  gap psi_i (m, > 0; at least the least positive float, a flight between two samples).

It is continuous at the onset: the needed force along the constrained orbit is a smooth
function of the parameter, so its least value reaches 0 continuously (at a corner of the cam,
its one-sided value after the corner does), and just past the onset the follower flies for a
time and a height that vanish with the excess of the parameter (it is pulled off by a force
that vanishes there), so the flight's largest gap tends to 0 too.  It has a corner at 0 and
different units on its two sides (N before, m after): only its sign is read on the far side,
and the location extrapolates from the contact side alone (:func:`.events.grazing_location`),
where it is smooth.  NaN on a compliant scene (no constraint, no ``SURFACE_CONTACT_FORCE``)."""
from __future__ import annotations

import math

import numpy as np
from numpy.polynomial import polynomial as P

from .sampled import refined_max

#: F_n just after a restart of the contact at t is read at t + RESTART_NUDGE T: past the switch's
#: located time (~1e-15 T) onto the arc the follower rides on, near enough that the force
#: changes by ~1e-9 of its range over a period (far below the location's resolution)
RESTART_NUDGE = 1e-9
#: the least force is refined by the quartic through its sample and FIT_HALF samples on each side
FIT_HALF = 2
#: the least positive float: the flight side's value where a flight falls between two samples
FLIES = 5e-324


def constrained(kernels) -> bool:
    """Whether the scene's contact is a constraint whose force is a switching surface (rigid)."""
    return hasattr(kernels, "SURFACE_CONTACT_FORCE")


def lift_off(run) -> float:
    """The lift-off test function of the orbit of ``run`` (:class:`.corrector.Run`; module docstring): -min F_n (N) on a
    contact orbit, the flight's largest gap psi_i (m, > 0) on one that leaves; NaN on a compliant
    scene.  From the run's samples and switch records, with the generated outputs kernel."""
    model, tr = run.section_map.model, run.trajectory
    K = model.kernels
    if not constrained(K):
        return math.nan
    touching = np.asarray(K.CONTACT_OF_MODE, dtype=bool)
    records = tr.switches.records
    out = model.outputs_at(tr.mode, tr.t, tr.alpha, tr.alpha_dot, run.section_map.backend)
    if not (np.all(touching[tr.mode]) and np.all(touching[records["after"]])):
        return max(refined_max(out[K.OUT_PSI_I]), FLIES)
    return -min(least_force(out[K.OUT_F_N], tr.t, records["t"]), restart_force(run, records))


def least_force(force: np.ndarray, t: np.ndarray, restarts: np.ndarray) -> float:
    """The least of a periodic sampled F_n (N) at times t (the last sample repeats the first),
    refined by :func:`quartic_least` through the least sample and two neighbours on each side,
    unless a restart of the contact (a switch at ``restarts``: a corner of the cam, where the
    force jumps) lies among them, where the fit would overshoot across the jump: the sample is
    kept, and :func:`restart_force` gives the value just past the corner."""
    n = force.size - 1
    k = int(np.argmin(force[:n]))
    window = (k + np.arange(-FIT_HALF, FIT_HALF + 1)) % n
    lo, hi = t[window[0]], t[window[-1]]                 # the period wraps where lo > hi
    between = (restarts >= lo) & (restarts <= hi) if lo < hi else (restarts >= lo) | (restarts <= hi)
    if np.any(between):
        return float(force[k])
    return quartic_least(force[window])


def quartic_least(v: np.ndarray) -> float:
    """The least value of the quartic through five equally spaced samples v (the middle one
    the least) within one spacing of the middle.  Its error is O(h^6) of the curve's sixth
    derivative: the parabola through three (:func:`.sampled.refined_max`, O(h^4)) leaves
    8e-8 N on reference-experiment's least force at 256 samples a period (measured against
    20000 samples of the constrained force), 1.1e-7 of the contact-loss speed."""
    u = np.arange(-FIT_HALF, FIT_HALF + 1, dtype=float)
    c = P.polyfit(u, v, 2 * FIT_HALF)
    roots = P.polyroots(P.polyder(c))
    inside = roots[(np.abs(roots.imag) < 1e-12) & (np.abs(roots.real) <= 1.0)].real
    return float(min(v[FIT_HALF], *P.polyval(inside, c))) if inside.size else float(v[FIT_HALF])


def restart_force(run, records: np.ndarray) -> float:
    """The least F_n (N) just after the switches of a contact orbit (RESTART_NUDGE T past each:
    a junction of a cam of arcs restarts the contact on the next arc, where the needed force
    has jumped); inf without switches."""
    if not records.size:
        return math.inf
    return float(np.min(forces_after(run.section_map.model, run.section_map.backend, records)))


def forces_after(model, backend: str, records: np.ndarray) -> np.ndarray:
    """F_n (N) RESTART_NUDGE T past each switch record (``t``, ``after``, ``alpha``,
    ``alpha_dot``) of a rigid contact orbit of ``model``: the force on the arc the follower rides on next."""
    t = records["t"] + RESTART_NUDGE * model.period
    out = model.outputs_at(records["after"], t, records["alpha"], records["alpha_dot"], backend)
    return out[model.kernels.OUT_F_N]
