"""Pseudo-arclength continuation of periodic orbits, with bifurcation and grazing detection.

A periodic orbit of period n T is a fixed point of the stroboscopic map P_n
(:mod:`camdyn.orbits.shooting`).  As a parameter lambda (the cam speed ``speed_rpm``, or any rig
parameter by name: ``k_s``, ``e``, ...) changes, the fixed points form branches
``G(x, lambda) = P_n(x; lambda) - x = 0`` that may turn back at folds, where a search at fixed
lambda fails.  :func:`continue_orbit` follows a branch in the unknowns z = (x, lambda), scaled
as ``(x / s, lambda / |end - start|)`` (s the size of the motion, as in :mod:`camdyn.orbits.shooting`):

* **predictor**: z_pred = z_k + ds t_k, with t_k the unit tangent, the null vector of the
  scaled Jacobian [dP/dx - I, dP/dlambda] (from its SVD), oriented along the previous one;
* **corrector**: the chord method on ``G(z) = 0, t_k . (z - z_pred) = 0`` (the arclength
  condition: the correction is orthogonal to the tangent), stopping at the scaled residual
  ``max_j |P_j(x) - x_j| / s_j <= tol``: it keeps the derivatives of the last point, one run
  per iteration, while the residual shrinks by ``CHORD_CONTRACTION`` per iteration, and takes
  Newton's step (the derivatives at the current z) when it does not; the derivatives are
  evaluated once more at the converged orbit, for its tangent and its multipliers.  Each run
  of the corrector is sampled along the orbit for the largest gap (below), which leaves its
  end state unchanged to the bit (:meth:`camdyn.orbits.section_map.StroboscopicMap.run`), so the
  converged orbit is run once: that run gives its gap, and P_n(x) to the Jacobian provider
  (:func:`camdyn.orbits.section_map.jacobian_at`), which runs only its columns: a step of k chord
  iterations costs k + 1 runs, and 2 n + 2 = 6 more for the derivatives by finite differences;
* **derivatives**: dP/dx from any Jacobian provider (:func:`camdyn.orbits.section_map.finite_differences`
  by default; the variational equations can replace it); dP/dlambda by central differences in
  lambda with the step ``h = rtol^(1/3) max(|lambda|, |end - start|)``, the rule of
  :func:`camdyn.orbits.section_map.finite_difference_steps` (truncation error h^2 against the map's
  noise rtol / h);
* **step size**: halved when the corrector fails, grown by 1.5 when it converges in at most
  ``easy_iterations`` steps, kept within [min_step, max_step] (scaled arclength).

The map is rebuilt for each lambda (T = 60 / speed_rpm changes with the speed); the section
is at ``phase_fraction`` T after each revolution's start, so that it stays at the same cam
angle along the branch.

**Detection.**  At every point the Floquet multipliers mu (eigenvalues of dP_n/dx) give test
functions whose sign change between two points marks an event, located in arclength (secant
trials with the Illinois rule, :func:`.events.secant_location`; grazing's below; every kind
with its test function and locator in one table, :data:`.events.KINDS`):

* ``fold``: the lambda-component of the tangent changes sign (a multiplier passes +1 and the
  branch turns back);
* ``branch_point``: det(M - I) changes sign while the branch does not turn (a multiplier
  through +1 at a crossing of branches);
* ``period_doubling``: det(M + I) changes sign (a real multiplier through -1);
* ``neimark_sacker``: det M - 1 changes sign between points with a complex pair (``|mu|^2 = det M``);
* ``multiplier_jump``: one of the above test functions changed sign but the multipliers jump
  across the located bracket, or are not at the critical value there (``CRITICAL``): the map
  is not smooth there (no branch is switched to);
* ``grazing``: the orbit's largest gap max psi_i (Eq. 6; psi_i < 0 is the contact deflection)
  over n T reaches zero: the follower leaves the cam for the first time.  The gap is the
  generated output ``OUT_PSI_I``, sampled ``GAP_SAMPLES`` times per period, or 16 times per
  period of the contact's fastest vibration where that is more (``corrector.gap_samples``: a cam
  whose jerk jumps rings the contact), and refined by a parabola through the largest sample and
  its neighbours.  It has a corner at the event (the
  contact's deflection before, the flight's height after), so a secant across the bracket
  crawls in from the flat side; but on the contact side (gap < 0) it is smooth, the contact
  orbit continuing through the event: the trials aim at the root of the secant through the
  two latest contact-side trials, short of it while it still moves and then just past it, so
  that the bracket closes from both sides (:func:`.events.grazing_location`; its trials against
  bisection's are measured in docs/continuation.md).
  A trial needs the gap alone: its orbit is corrected without derivatives (6 runs less each),
  which only the two bracketing points get;
* ``lift_off`` (a rigid scene, :mod:`.lift_off`): the rigid follower's contact orbit starts to
  leave the cam.  Its gap is 0 to rounding there (``grazing`` is not told on a rigid scene); the
  test function is -min F_n over the orbit (N, the constraint's force, ``OUT_F_N``, refined by a
  quartic, and just past each restart of the contact: a corner of a cam of arcs) on a contact
  orbit, the flight's largest gap (m, > 0) on one that leaves; located as grazing is;
* ``corner_impact`` (a rigid scene on a cam profile with junctions, :mod:`.corners`): a Newton
  impact's landing angle on the cam (the contact's body angle phi at the impact) crosses a
  junction of the profile, where its curvature jumps (Osorio, di Bernardo & Santini 2008): the
  signed angular distance of one impact to one junction changes sign between two points while
  both are within half the junctions' least spacing, the impacts matched by their order in the
  period (as many at both points); located by secant trials on that distance, corrected orbits
  without derivatives as grazing's, the located orbit the last trial before the event.

At a period doubling the branch of period 2 n T is switched to: Newton's method on P_2n from
x* +/- eps v (v the eigenvector of the multiplier near -1) on the side where P_n is unstable,
then on the other side, and that branch is continued too.

The result is an ``xarray.Dataset`` (:func:`continue_orbit`): dims ``point`` (every orbit on
every branch), ``multiplier``, ``revolution`` and ``event``.

The modules, one job each: ``problem`` (the problem, settings, outcomes, the records, and the
:class:`~.problem.Leg` every step of a branch shares, with the layout of z), ``corrector`` (the
orbit's run and gap, the derivatives, tangent, predictor and corrector), ``events`` (the event
table, detection and location), ``switching`` (branch switching at a period doubling),
``follow`` (the first orbit, the steps along each branch), ``corners`` (where impacts land
against the profile's junctions: the corner impact's test) and ``dataset`` (the result).

**Two parameters** (design charts, issue 29): :func:`continue_grazing` follows the grazing
orbit in two parameters and :func:`jump_chart` gives the jump speed against a rig parameter
beside the inverse-kinematics contact-loss speed (``charts``: the public functions and the
start; ``grazing``: the extended system, its residual and derivatives; ``grazing_curve``: the
steps, step control and codimension-2 points; ``grazing_dataset``: the result);
:func:`continue_bifurcation` follows a fold or a period doubling (``codim1``).
"""
from __future__ import annotations

import math

from ..._checks import finite, integer, real
from ...engine import SolverOptions
from ...errors import ParameterError
from ...model.rig import PARAMETERS, Rig
from ...model.scene import Scene
from ..derivatives import finite_differences
from ..section_map import DEFAULT_OPTIONS
from . import corrector as _corrector, events as _events, follow as _follow, problem as _problem
from .dataset import branch_dataset, events_table
from .follow import check_warm, run
from .problem import Branch, ContinuationOutcome, ContinuationSettings, Event, Point, Problem

# the public constants, defined in the modules that use them and documented here
#: the parameter name of the cam speed (rev/min); any other is a rig parameter (SI)
SPEED = _problem.SPEED
#: samples of psi_i per cam period for the orbit's largest gap (refined by a parabola)
GAP_SAMPLES = _corrector.GAP_SAMPLES
#: the event kinds, in the order of the event table (:data:`.events.KINDS`, where each is
#: described) and of the Dataset's attribute ``event_kinds``; ``multiplier_jump``: a test function
#: changed sign but the located orbit's multipliers are not critical (the map is not smooth there:
#: the multipliers jump, e.g. where the orbit meets a new switching surface)
EVENTS = _events.EVENTS
#: the first orbit's warm starts (``warm`` of :func:`continue_orbit` and
#: :func:`continue_bifurcation`): ``"run"``, a run of ``warmup_revolutions`` from the static
#: equilibrium, or ``"quasistatic"``, the quasi-static contact orbit (which finds the contact branch
#: where a weakly damped run settles on another, impacting, orbit)
WARM_STARTS = _follow.WARM_STARTS


# --- the public function ---------------------------------------------------------------------------
def _check(rig, scene, parameter, start, end, speed_rpm, periods, phase_fraction, settings):
    if not isinstance(rig, Rig):
        raise ParameterError("rig", rig, "a camdyn.Rig")
    if not isinstance(scene, Scene) or scene.motion != "constant":
        raise ParameterError("scene", scene, "a camdyn.Scene with motion 'constant' (a cam at constant speed)")
    names = [p.name for p in PARAMETERS]
    if parameter != SPEED and parameter not in names:
        raise ParameterError("parameter", parameter, f"'{SPEED}' or a rig parameter ({', '.join(names)})")
    finite("start", start)
    finite("end", end)
    if start == end:
        raise ParameterError("end", end, f"a value other than start ({start})")
    if parameter == SPEED:
        if speed_rpm is not None:
            raise ParameterError("speed_rpm", speed_rpm, "None when the speed itself is continued")
        if not start * end > 0:
            raise ParameterError("end", end, "a speed of the same sign as start, and neither zero (rev/min)")
    else:
        real("speed_rpm", speed_rpm, f"a nonzero cam speed (rev/min) to continue {parameter} at",
             lambda v: v != 0 and math.isfinite(v))
    integer("periods", periods, "an integer, 1 <= periods <= 50", lambda n: 1 <= n <= 50)
    real("phase_fraction", phase_fraction, "0 <= phase_fraction < 1 (of the cam period)", lambda v: 0 <= v < 1)
    if not isinstance(settings, ContinuationSettings):
        raise ParameterError("settings", settings, "a camdyn.orbits.continuation.ContinuationSettings")


def continue_orbit(rig: Rig, scene: Scene, parameter: str, start: float, end: float, *,
                 speed_rpm: float | None = None, periods: int = 1, phase_fraction: float = 0.0,
                 warmup_revolutions: int = 20, settings: ContinuationSettings = ContinuationSettings(),
                 options: SolverOptions = DEFAULT_OPTIONS, jacobian=finite_differences,
                 backend: str = "compiled", warm: str = "run"):
    """Follow the branch of period-``periods`` orbits through the orbit found at ``start`` as
    ``parameter`` goes toward ``end``; detect and locate folds, branch points, period doublings,
    Neimark-Sacker bifurcations and grazing, and switch to the doubled branches.

    ``parameter``: ``"speed_rpm"`` (the cam speed, rev/min), or a rig parameter by name (SI),
    continued at the constant cam speed ``speed_rpm``.  The first orbit is found by
    :func:`camdyn.periodic_orbit` after ``warmup_revolutions`` from the static equilibrium, or,
    with ``warm="quasistatic"``, from the quasi-static contact orbit (:data:`WARM_STARTS`).
    ``phase_fraction``: the section's time after each revolution's start, a fraction of T
    (0 gives the sections of :func:`camdyn.sweep.api.bifurcation`; choose another where the
    orbit is near a switching surface at 0).  ``jacobian(map, scale)`` makes the Jacobian
    provider (any :class:`camdyn.orbits.section_map.JacobianProvider`).  Raises only on bad input; how
    each branch ended is in the result (:class:`ContinuationOutcome`).

    Returns an ``xarray.Dataset`` described in :func:`branch_dataset`.
    """
    _check(rig, scene, parameter, start, end, speed_rpm, periods, phase_fraction, settings)
    check_warm(warm)
    problem = Problem(rig, scene, parameter, float(start), float(end), speed_rpm, periods, float(phase_fraction),
                      options, jacobian, backend)
    problem.model(problem.start)                 # a rig value the rig refuses raises here
    problem.model(problem.end)
    branches, events, scale = run(problem, settings, warmup_revolutions, warm)
    return branch_dataset(problem, branches, events, scale)


from .charts import continue_bifurcation, continue_grazing, jump_chart  # noqa: E402  (it calls continue_orbit, defined above)
from .grazing_curve import GrazingOutcome, GrazingSettings  # noqa: E402

__all__ = ["continue_grazing", "jump_chart", "continue_bifurcation", "GrazingSettings", "GrazingOutcome", "continue_orbit", "ContinuationSettings", "ContinuationOutcome", "branch_dataset", "events_table",
           "Problem", "Point", "Branch", "Event", "SPEED", "EVENTS", "GAP_SAMPLES", "WARM_STARTS"]
