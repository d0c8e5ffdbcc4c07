"""Design charts: the curve of grazing orbits in two parameters (:func:`continue_grazing`) and
the jump chart, the jump (contact-loss) speed against a rig parameter beside its quasi-static
limit (:func:`jump_chart`).

:func:`continue_grazing` starts from the grazing that the one-parameter continuation
(:func:`camdyn.orbits.continuation.follow.run`, the engine of :func:`camdyn.continue_orbit`)
locates in the free parameter lambda1 (``free``, by default the cam speed) over ``search`` at
lambda2 = ``start``: the located orbit and the branch's point before it, the one on the contact
side first; or, where the branch's corrector stops short of the grazing (the step past it is
not smooth: a stiff contact), its last orbit when that orbit's largest gap is within
:data:`NEAR` of the first orbit's from zero.  From there it solves the extended system of
:mod:`.grazing` at lambda2 = start and follows it (:mod:`.grazing_curve`) to lambda2 = ``end``.
"""
from __future__ import annotations

import dataclasses
import math

import numpy as np

from ..._checks import finite, real
from ...engine import SolverOptions
from ...errors import CamdynError, ParameterError
from ...model.rig import PARAMETERS, Rig
from ...model.scene import Scene
from ..derivatives import finite_differences
from ..section_map import DEFAULT_OPTIONS
from ..tangent import variational
from .follow import check_warm, run
from .boundary import boundary_of
from .grazing import GrazingSystem, Layout, gap_maximum
from .grazing_curve import Curve, GrazingOutcome, GrazingSettings, Leg, first, follow
from .codim1 import (CORNER, DET_STEP, KINDS, Codim1System, CurveLeg, Layout as Codim1Layout, advance,
                     codim1_dataset, corner_of, free_at_corner, located)
from .codim1 import first as codim1_first
from .grazing_dataset import grazing_dataset, unit
from .problem import SPEED, ContinuationSettings, Problem

#: a one-parameter branch that stops short of its grazing starts the curve from its last orbit
#: when that orbit's largest gap is within this fraction of the branch's first orbit's from zero
NEAR = 0.05


def _names() -> list[str]:
    return [SPEED] + [p.name for p in PARAMETERS]


def _check(rig, scene, parameter, start, end, free, search, speed_rpm, phase_fraction) -> None:
    _check_scene(rig, scene)
    names = _names()
    for name, value in (("parameter", parameter), ("free", free)):
        if value not in names:
            raise ParameterError(name, value, f"'{SPEED}' or a rig parameter ({', '.join(names[1:])})")
    if parameter == free:
        raise ParameterError("free", free, f"a parameter other than parameter ({parameter!r}): two parameters vary")
    finite("start", start)
    finite("end", end)
    if start == end:
        raise ParameterError("end", end, f"a value other than start ({start})")
    if not (isinstance(search, (tuple, list)) and len(search) == 2):
        raise ParameterError("search", search, f"(low, high): the range of {free} the first grazing is searched in")
    lo, hi = (finite("search", v, f"two finite values of {free}, low != high") for v in search)
    if lo == hi:
        raise ParameterError("search", search, f"two finite values of {free}, low != high")
    if SPEED in (free, parameter):
        values = (lo, hi) if free == SPEED else (start, end)
        if speed_rpm is not None:
            raise ParameterError("speed_rpm", speed_rpm, "None: the speed is one of the two parameters")
        if not values[0] * values[1] > 0:
            raise ParameterError("search" if free == SPEED else "end", values[1],
                                 "speeds of one sign, neither zero (rev/min)")
    else:
        real("speed_rpm", speed_rpm, "a nonzero cam speed (rev/min) for two rig parameters",
             lambda v: v != 0 and math.isfinite(v))
    real("phase_fraction", phase_fraction, "0 <= phase_fraction < 1 (of the cam period)", lambda v: 0 <= v < 1)


def _check_scene(rig, scene) -> None:
    if not isinstance(rig, Rig):
        raise ParameterError("rig", rig, "a camdyn.Rig")
    if not isinstance(scene, Scene) or scene.motion != "constant":
        raise ParameterError("scene", scene, "a camdyn.Scene with motion 'constant' (a cam at constant speed)")


def _settings(settings, kind) -> None:
    if not isinstance(settings, kind):
        raise ParameterError("settings", settings, f"a camdyn.orbits.continuation.{kind.__name__}")


def continue_grazing(rig: Rig, scene: Scene, parameter: str, start: float, end: float, *, search: tuple,
                     free: str = SPEED, speed_rpm: float | None = None, phase_fraction: float = 0.5,
                     warmup_revolutions: int = 20, settings: GrazingSettings = GrazingSettings(),
                     options: SolverOptions = DEFAULT_OPTIONS, backend: str = "compiled",
                     guess: float | None = None):
    """The curve of grazing period-1 orbits (the follower first leaving the cam) in two
    parameters: ``free`` (lambda1, default the cam speed ``speed_rpm``, rev/min) and
    ``parameter`` (lambda2, a rig parameter, SI; or the speed) from ``start`` to ``end``, by
    pseudo-arclength continuation of the extended system of :mod:`.grazing`, with the
    codimension-2 points where a Floquet multiplier at grazing passes -1 or +1.

    ``search``: (low, high) of ``free``, over which :func:`camdyn.continue_orbit` (at lambda2 =
    start, from the orbit at low) finds the first grazing; ``speed_rpm``: the cam speed when
    neither parameter is the speed; ``phase_fraction``: the section's time in the period (choose it
    away from the gap's maximum); ``guess``: a value of ``free`` just on the contact side of the
    first grazing (the jump chart's: the contact-loss speed less its compliance shift), from whose
    periodic orbit the extended system is solved without the search, which runs only where that
    fails.  The scene needs the tangent dynamics (not damping C or E:
    :mod:`camdyn.orbits.tangent`).  On a rigid scene the curve is the lift-off's (the least
    contact force through 0; the search finds the event ``lift_off``): :mod:`.boundary`.  Raises only on bad input; how the curve ended is in the
    result (:class:`GrazingOutcome`).  Returns the ``xarray.Dataset`` of :func:`grazing_dataset`.
    """
    _check(rig, scene, parameter, start, end, free, search, speed_rpm, phase_fraction)
    _settings(settings, GrazingSettings)
    system = GrazingSystem(rig, scene, free, parameter, float(start), float(end), speed_rpm, float(phase_fraction),
                           options, backend, free_start=float(search[0]), deflection=math.nan,
                           tol=settings.continuation.tol, gap_tol=settings.gap_tol, threads=settings.threads)
    system.model(system.free_start, system.start)              # a rig value the rig refuses raises here
    system.model(float(search[1]), system.end)
    if guess is not None:
        finite("guess", guess)
    curve, layout, system = _curve(system, search, settings, warmup_revolutions, guess)
    return grazing_dataset(system, curve, layout, settings)


def _curve(system: GrazingSystem, search, settings: GrazingSettings, warmup_revolutions: int, guess=None):
    """(curve, layout, the system with lambda1 at the first grazing) from the candidate first
    orbits of the guess (:func:`_guessed`), else of the search (:func:`_search`): the extended
    system solved from each candidate in turn until one converges."""
    why = []
    sources = ([lambda: _guessed(system, guess)] if guess is not None else []) + [
        lambda: _search(system, search, settings, warmup_revolutions)]
    for source in sources:
        found = source()
        if isinstance(found, str):
            why.append(found)
            continue
        candidates, scale = found
        for x, free, mode in candidates:
            layout = Layout(np.asarray(scale, dtype=float), abs(free), system.span)
            started = _first_from(system, layout, settings, x, free, mode)
            if isinstance(started, str):
                why.append(started)
                continue
            point, at = started
            return follow(Leg(at, layout, settings.continuation), point), layout, at
    return Curve([], [], GrazingOutcome.START_FAILED, "; ".join(why)), None, system


def _first_from(system: GrazingSystem, layout: Layout, settings: GrazingSettings, x, free: float, mode):
    """(the first grazing point, the system with its gap's scale) from a candidate orbit, or why not."""
    try:
        near = gap_maximum(dataclasses.replace(system, free_start=free), x, free, mode)
    except CamdynError as failure:
        return f"the orbit at {system.free} = {free:.8g} cannot be run: {failure}"
    at = dataclasses.replace(system, free_start=free, deflection=near.scale, corner=near.corner)
    p = first(Leg(at, layout, settings.continuation), x, near.phase, free, mode)
    return p if isinstance(p, str) else (p, at)


def _guessed(system: GrazingSystem, guess: float):
    """The candidate first orbit at lambda1 = ``guess`` and lambda2 = start, ([(x, guess, None)],
    the motion's scale): the period-1 orbit there by shooting from the quasi-static start
    (camdyn.periodic_orbit), the section at the system's phase; or why there is none."""
    from ..shooting import OrbitOutcome, periodic_orbit

    try:
        model = system.model(float(guess), system.start)
        orbit = periodic_orbit(model.rig, system.scene, model.cam, phase=system.phase_fraction * model.period,
                               options=system.options, jacobian=variational, backend=system.backend,
                               start="quasistatic")
    except CamdynError as failure:
        return f"no periodic orbit at the guess {system.free} = {guess:.8g}: {failure}"
    if orbit.outcome is not OrbitOutcome.CONVERGED:
        return f"no periodic orbit at the guess {system.free} = {guess:.8g}: {orbit.message or orbit.outcome.name}"
    return [(orbit.state, float(guess), None)], orbit.scale


def _search(system: GrazingSystem, search, settings: GrazingSettings, warmup_revolutions: int):
    """The candidate first orbits, (x, lambda1, mode) each, and the motion's scale, from the
    branch the one-parameter continuation in lambda1 follows at lambda2 = start (its first; the
    derivatives by the tangent dynamics, as the extended system's); or why there are none.  The
    candidates: the located grazing's orbit and the branch's point before it (the one on the
    contact side first); without a grazing, the branch's last orbit when it is within NEAR."""
    rig = system.rig if system.parameter == SPEED else system.rig.replace(**{system.parameter: system.start})
    speed = system.start if system.parameter == SPEED else system.speed_rpm
    problem = Problem(rig, system.scene, system.free, float(search[0]), float(search[1]),
                      None if system.free == SPEED else speed, 1, system.phase_fraction, system.options, variational,
                      system.backend)
    branches, events, scale = run(problem, settings.search, warmup_revolutions)
    points, boundary = branches[0].points, system.boundary
    grazing = [e for e in events if e.branch == 0 and e.kind == boundary.kind]
    if grazing:
        e, before = grazing[0], points[grazing[0].point]
        pair = [(e.x, e.lam, before.mode), (before.x, before.lam, before.mode)]
        in_contact = e.max_gap < 0 and not boundary.contact_only     # a rigid orbit's gap is rounding: no side
        return (pair if in_contact else pair[::-1]), scale
    why = f"{branches[0].outcome.message if branches[0].outcome else ''} {branches[0].message}".strip()
    if not points:
        return f"no orbit at {system.free} = {search[0]:.8g}: {why}"
    last, test = points[-1], boundary.of_point
    if not (test(last) < 0 and -test(last) <= NEAR * -test(points[0])):
        return (f"the branch in {system.free} over {search[0]:.8g} to {search[1]:.8g} has no {boundary.kind}: its last "
                f"orbit's largest {boundary.meaning} is {test(last):.3g} {boundary.unit} ({why})")
    return [(last.x, last.lam, last.mode)], scale


#: the default search range of the jump chart's first grazing, in units of the
#: inverse-kinematics contact-loss speed at the start: the grazing lies below it by the
#: contact's compliance (:func:`camdyn.analysis.compliance_shift`: 2e-6 to 5e-8 of it on the
#: shipped rigs), and the contact orbit exists from the low end
JUMP_SEARCH = (0.9, 1.05)
#: the jump chart's first orbit is guessed this fraction below the contact-loss speed less its
#: compliance shift (the grazing's first-order estimate, within 3 % of the shift on a stiff contact,
#: tests/test_charts.py): on the contact side unless the estimate is off by more than this, and then
#: the search over ``search`` runs instead (on reference-experiment the guess's orbit and its Newton
#: solve took ~1 s against the search's ~7 s)
GUESS_BELOW = 1e-4
#: cam angles of compliance_shift's search for the spring moment's minimum and its second
#: difference there (its default, 20000, costs 0.18 s a point; with 3600, 0.1 degree apart, the
#: second difference's truncation error is ~(0.1 degree)^2 of the curvature's scale, 3e-6)
SHIFT_SAMPLES = 3600
#: why the event kinds that no two-parameter curve follows are refused as ``kind``
NOT_FOLLOWED = {
    "grazing": "a grazing curve is continue_grazing's, a lift-off one too (on a rigid scene)",
    "lift_off": "a lift-off curve is continue_grazing's on a rigid scene",
}


def section_away_from_loss(rig: Rig, loss_rpm: float) -> float:
    """The jump chart's default section: half a period from the cam angle at which the inverse
    kinematics lose contact (:func:`camdyn.analysis.statics.contact_loss_angle`; the cam turning
    forward, at the contact-loss speed ``loss_rpm``), where the grazing orbit's gap has its
    maximum (reference-experiment: at 0.4794 of the period against its grazing's 0.4795).  Near
    the grazing a stiff contact's state lies within a prediction's error of the loading /
    unloading surface (reference-experiment at phase_fraction 0.5, 0.02 T after it: a gap rate of
    -4e-10 m/s), so that iterates and parameter differences left the start mode's domain or
    switched there: 40 % more parameter-difference runs and 20 % more corrector runs than here."""
    from ...analysis.statics import contact_loss_angle

    theta = contact_loss_angle(rig, samples=SHIFT_SAMPLES, loss_rpm=loss_rpm)
    return float(((theta - rig.theta0) / (2.0 * math.pi) + 0.5) % 1.0)


def jump_chart(rig: Rig, scene: Scene, parameter: str, start: float, end: float, *, search: tuple | None = None,
               phase_fraction: float | None = None, warmup_revolutions: int = 20,
               settings: GrazingSettings = GrazingSettings(), options: SolverOptions = DEFAULT_OPTIONS,
               backend: str = "compiled"):
    """The jump chart: the jump speed (the grazing speed, where the follower first leaves the
    cam) against the rig parameter ``parameter`` from ``start`` to ``end``
    (:func:`continue_grazing` in (``speed_rpm``, ``parameter``)), beside its quasi-static
    limit, the inverse-kinematics contact-loss speed (:func:`camdyn.analysis.contact_loss_speed`)
    at each point's parameter value, and the first-order shift between them by the contact's
    compliance (:func:`camdyn.analysis.compliance_shift`).  On a rigid contact (:mod:`.boundary`)
    the jump is the lift-off, where the least contact force of the contact orbit reaches 0, and
    the inverse kinematics is that orbit: the shift is 0 and the jump speed is the contact-loss
    speed to the continuation's tolerance (docs/continuation.md).

    The first grazing is solved for from the orbit at the guess :data:`GUESS_BELOW` below the
    contact-loss speed less its compliance shift at ``start``; where that fails it is searched
    for between the speeds ``search`` (rev/min; default :data:`JUMP_SEARCH` times the contact-loss
    speed at ``start``).  ``phase_fraction``: the section's time in the period (:func:`continue_grazing`;
    default :func:`section_away_from_loss`'s).  Returns the Dataset of :func:`continue_grazing` with
    ``contact_loss_rpm`` and ``compliance_shift`` per point.
    """
    from ...analysis.statics import compliance_shift, contact_loss_speed

    if parameter == SPEED or parameter not in _names():
        raise ParameterError("parameter", parameter, f"a rig parameter ({', '.join(_names()[1:])}): the jump "
                                                     "speed is charted against it")
    finite("start", start)
    _check_scene(rig, scene)
    at_start = rig.replace(**{parameter: float(start)})
    loss = contact_loss_speed(at_start)
    if not (math.isfinite(loss) and loss > 0):
        raise ParameterError("start", start, f"a value of {parameter} at which the follower leaves the cam "
                                             f"at some speed (contact-loss speed {loss} rev/min there)")
    if search is None:
        search = (JUMP_SEARCH[0] * loss, JUMP_SEARCH[1] * loss)
    rigid = boundary_of(scene.kernels()).contact_only

    def shift(r, loss_rpm) -> float:          # a rigid contact does not deflect: its contact orbit is the IK's
        return 0.0 if rigid else compliance_shift(r, scene, samples=SHIFT_SAMPLES, loss_rpm=loss_rpm)
    guess = loss * (1.0 + shift(at_start, loss)) * (1.0 - GUESS_BELOW)
    if phase_fraction is None:
        phase_fraction = section_away_from_loss(at_start, loss)
    ds = continue_grazing(rig, scene, parameter, start, end, search=search, phase_fraction=phase_fraction,
                          warmup_revolutions=warmup_revolutions, settings=settings, options=options,
                          backend=backend, guess=guess)
    rigs = [rig.replace(**{parameter: float(v)}) for v in ds[parameter].values]
    losses = [contact_loss_speed(r) for r in rigs]
    ds["contact_loss_rpm"] = ("point", np.array(losses),
                              {"units": "rev/min", "long_name": "contact-loss speed by inverse kinematics "
                                                                "(the quasi-static limit)"})
    why = ("0: a rigid contact does not deflect (its contact orbit is the inverse kinematics')" if rigid else
           "first-order relative shift of the contact-loss speed by the contact's compliance")
    ds["compliance_shift"] = ("point", np.array([shift(r, v) for r, v in zip(rigs, losses)]),
                              {"units": "1", "long_name": why})
    ds.attrs["title"] = f"camdyn jump chart: the jump speed against {parameter}, rig {rig.name}"
    return ds


def continue_bifurcation(rig: Rig, scene: Scene, kind: str, parameter: str, start: float, end: float, *,
                         search: tuple, free: str = SPEED, speed_rpm: float | None = None,
                         phase_fraction: float = 0.0, warmup_revolutions: int = 20,
                         settings: ContinuationSettings = ContinuationSettings(switch_depth=0),
                         options: SolverOptions = DEFAULT_OPTIONS, jacobian=finite_differences,
                         backend: str = "compiled", warm: str = "run", det_step: float = DET_STEP):
    """The curve of a ``kind`` (``"fold"``, ``"period_doubling"`` or ``"corner_impact"``:
    :data:`.codim1.KINDS`) of period-1 orbits in two parameters, ``free`` (lambda1, default the cam
    speed) and ``parameter`` (lambda2) from ``start`` to ``end``: pseudo-arclength on the extended
    system of :mod:`.codim1`, from the bifurcation that the one-parameter continuation in ``free``
    over ``search`` locates at lambda2 = start (a corner impact: its impact and junction,
    :func:`.codim1.corner_of`), with the points where the curve's orbit grazes (the codimension-2
    points where it meets the grazing curve of :func:`continue_grazing`, :func:`.codim1.located`).
    ``jacobian``: the provider of dP/dx, ``warm``: the first orbit's warm start (both as
    :func:`camdyn.continue_orbit`'s); ``det_step``: the relative step of the determinant's
    differences (:data:`.codim1.DET_STEP`).
    Raises only on bad input; how the curve ended is in the result's ``outcome``.  Returns the
    ``xarray.Dataset`` of :func:`.codim1.codim1_dataset`."""
    _check(rig, scene, parameter, start, end, free, search, speed_rpm, phase_fraction)
    _settings(settings, ContinuationSettings)
    if kind not in KINDS:
        raise ParameterError("kind", kind, f"one of {KINDS}", reason=NOT_FOLLOWED.get(kind))
    check_warm(warm)
    real("det_step", det_step, "0 < det_step <= 0.1 (a relative step of the scaled unknowns)",
         lambda v: 0 < v <= 0.1)
    system = Codim1System(rig, scene, free, parameter, float(start), float(end), speed_rpm, float(phase_fraction),
                          options, backend, kind=kind, jacobian=jacobian, det_step=float(det_step))
    problem = system.along(free, float(search[0]), float(start), float(search[1]) - float(search[0]))
    problem.model(float(search[1]))                            # a rig value the rig refuses raises here
    branches, events, scale = run(problem, settings, warmup_revolutions, warm)
    found = [e for e in events if e.branch == 0 and e.kind == kind]
    if not found:
        why = f"no {kind} of the branch in {free} over {search[0]:.8g} to {search[1]:.8g} ({branches[0].message})"
        return codim1_dataset(system, Curve([], [], GrazingOutcome.START_FAILED, why), None)
    e = found[0]
    layout = Codim1Layout(np.asarray(scale, dtype=float), abs(e.lam), system.span)
    leg = CurveLeg(system, layout, settings)
    mode = branches[0].points[e.point].mode
    if kind == CORNER:
        corner = corner_of(leg, e.x, e.lam, mode)
        if isinstance(corner, str):
            return codim1_dataset(system, Curve([], [], GrazingOutcome.START_FAILED, corner), layout)
        system = dataclasses.replace(system, corner=corner)
        leg = CurveLeg(system, layout, settings)
    p = codim1_first(leg, e.x, e.lam, mode)
    if isinstance(p, str):
        return codim1_dataset(system, Curve([], [], GrazingOutcome.START_FAILED, p), layout)
    curve = follow(leg, p, advance, located)
    ds = codim1_dataset(system, curve, layout)
    if kind == CORNER:    # the curve held ANGLE_MARGIN off the corner, and on it (codim1.free_at_corner)
        ds[f"{free}_at_corner"] = ("point", np.array([free_at_corner(leg, q) for q in curve.points], dtype=float),
                                   {"units": unit(free), "long_name": f"{free} with the impact on the junction"})
    return ds
