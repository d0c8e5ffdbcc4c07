"""simulate(): one run of a scene on a rig, from the static equilibrium by default."""
from __future__ import annotations

import functools
import math
from typing import Callable

import numpy as np

from ..engine import SolverOptions, Switches, Trajectory, impact_transitions, integrate, transition_surfaces
from ..errors import CamdynError, ParameterError
from ..model.cam import CamMotion, cam_motion
from ..model.model import Model
from ..model.rig import PARAMETERS, Rig
from ..model.scene import Scene
from ..outcome import Outcome
from ..vocabulary import CAM_THETA, COORDINATES
from . import quasistatic, stopping
from .pieces import integrate_in_pieces
from .request import DEFAULT_BACKEND, RunRequest, Span, run_request
from .result import Outputs, Result
from .stopping import StopWhenPeriodic

#: the fastest rate (rad/s) of the linearized motion a run accepts (Model.fastest_rate): an
#: explicit Runge-Kutta step is at most a few times 1/rate, so a faster motion would take millions
#: of steps per simulated second (docs/design-notes.md, *The fastest motion a run accepts*)
MAX_RATE = 1e7


def simulate(rig: Rig, scene: Scene | None = None, cam: CamMotion | None = None, *,
             speed_rpm: float | None = None, span: Span | None = None, options: SolverOptions | None = None,
             y0=None, backend: str = DEFAULT_BACKEND, stop: StopWhenPeriodic | None = None,
             progress: Callable[[float], None] | None = None, **loose) -> Result:
    """Simulate the cam-follower of ``rig`` with the physics of ``scene``.

    The cam motion is ``cam`` (a ConstantSpeed, Oscillating or UserMotion), or
    ``speed_rpm`` for a constant speed.  ``span``, a :class:`~camdyn.runs.request.Span`, says how
    long the run lasts and where it is sampled: ``t_end`` seconds or ``revolutions`` cam periods
    from ``t_start`` (s), sampled at ``sample_rate_Hz`` (default 20 kHz).  ``options``, a
    :class:`camdyn.engine.SolverOptions`, says how it is integrated: ``method`` (``"DOP853"``, the
    default, or ``"RK45"``) integrates each mode of the scene's hybrid automaton, every switch
    located on the dense output, to ``rtol`` and ``atol`` (default 1e-8, 1e-12), with steps of at
    most ``max_step`` (s) and the event location of ``events`` (an EventSettings);
    ``step_control`` is the step-size controller (``"pi"``, the default: proportional-integral,
    fewer rejected steps where the error estimate jumps, as in a contact mode's ring-down; or
    ``"scipy"``: SciPy's, the steps of ``solve_ivp`` on a smooth stretch; docs/performance.md
    measures both); ``ledger=True`` also integrates the work of the cam drive and the energy
    dissipated by contact damping and by friction (``result.work_in``,
    ``result.dissipated_contact``, ``result.dissipated_friction``), so that
    energy(t) - energy(0) = work_in - dissipated_contact - dissipated_friction.

    The fields of both may be given as loose keywords instead (``revolutions=3, rtol=1e-10``;
    ``energy_ledger`` for ``ledger``): they build the two objects once
    (:func:`~camdyn.runs.request.run_request`).  A loose keyword of an object given whole, or an
    unknown keyword, is a :class:`~camdyn.errors.ParameterError` that names it.

    The run starts at ``y0 = (alpha, alpha_dot)`` (rad, rad/s), by default the static
    equilibrium (alpha*, 0) as in Section 4.  Check ``result.ok``: a run that could not finish
    says why.  ``backend="compiled"`` (default) runs the loop compiled by numba (the first call on
    a machine compiles for a few seconds, later ones load the cache); ``"python"`` runs the same
    loop in Python, for a :class:`~camdyn.model.cam.UserMotion` (its callables are Python).
    ``progress``, if given, is called with the share of the run done (0 to 1], after each
    piece of a long run (:mod:`camdyn.runs.pieces`: every 200 cam periods) and at its end; it
    does not change the run.  ``stop``, a :class:`camdyn.StopWhenPeriodic`, ends the run once its
    once-per-revolution section repeats (needs a whole number of samples per revolution) and
    completes the Result to the requested length by repeating the converged cycle
    (:mod:`camdyn.runs.stopping`; ``result.stats["revolutions_run"]``, ``["stop_period"]``).
    A scene with ``response="quasistatic"`` is not integrated: the Result holds the quasi-static
    contact orbit at the samples (:mod:`camdyn.runs.quasistatic`; alpha_dot the rigid rate), up to
    where it does not exist (``Outcome.CONTACT_TENSILE``, ``result.stats["where"]``).

    Raises :class:`~camdyn.errors.ParameterError`, before any work, for a run that could not
    finish: more than MAX_CONTACT_PERIODS periods of the contact mode, MAX_SAMPLES samples
    (:mod:`camdyn.runs.request`), or a linearized motion faster than MAX_RATE rad/s
    (:attr:`Model.fastest_rate`: a damping, spring or inertia value far outside a mechanism's, for
    which an explicit method needs millions of steps per millisecond); the message names the
    parameters.
    """
    request = run_request(span=span, options=options, y0=y0, backend=backend, stop=stop, **loose)
    return run(rig, scene, cam_motion(cam, speed_rpm), request, progress)


def run(rig: Rig, scene: Scene | None, cam: CamMotion, request: RunRequest,
        progress: Callable[[float], None] | None = None) -> Result:
    """The run of ``request`` (checked already) on a rig, a scene (None: the default Scene) and a
    cam motion: :func:`simulate` once it has built the request, and each point of a sweep."""
    scene = scene if scene is not None else Scene()
    if request.backend == "compiled" and getattr(cam, "kind", None) == "user":
        raise ParameterError("backend", request.backend, "'python' for a UserMotion: its Theta(t) is a Python "
                             "callable, which compiled code cannot call")
    model = checked_model(rig, scene, cam)
    span = request.span
    duration = span.duration(cam, model.equilibrium.vartheta)
    t_eval = span.times(duration)
    if scene.response == "quasistatic":
        return _quasi_static(model, t_eval, request)
    y0 = model.static_state() if request.y0 is None else np.asarray(request.y0, dtype=float)
    integrate_with = functools.partial(integrate, backend=request.backend)
    watch = _watch(request, model.period)
    t_span = (span.t_start, span.t_start + duration)
    traj = integrate_in_pieces(integrate_with, model, t_span, y0, t_eval, request.options, progress, watch)
    result = _result(model, traj, request.backend)
    if watch is None:
        return result
    # integrated up to: the end, unless it stopped (periodic, or early: its last sample); the last
    # sample of a run to the end can fall a sample interval short of it (the samples' rounding)
    stopped = traj.stats.get("stopped")
    ran_to = t_span[1] if result.ok and not stopped else (result.t[-1] if result.t.size else span.t_start)
    result.stats["revolutions_run"] = round((ran_to - span.t_start) / model.period, 6)
    result.stats["stop_period"] = watch.period if stopped else 0
    if stopped:
        # the samples the full run would have: the engine gives none past t_end (one rounded beyond it)
        t_eval = t_eval[t_eval <= t_span[1]]
        return stopping.extend(result, t_eval, watch.period, watch.per_revolution, t_span[1])
    return result


def _quasi_static(model: Model, t_eval: np.ndarray, request: RunRequest) -> Result:
    """The scene option response="quasistatic": the quasi-static contact orbit at the samples
    (:mod:`camdyn.runs.quasistatic`, no integration), its outputs from the generated kernel; the
    samples end before a time where it does not exist (the outcome says why, stats["where"] where)."""
    refused = {"y0": request.y0, "energy_ledger": request.options.ledger, "stop": request.stop}
    for name, value in refused.items():
        if value is not None and value is not False:
            raise ParameterError(name, value, "not given with response='quasistatic' (no integration: the orbit "
                                 "has no start, ledger or stop)")
    orbit = quasistatic.orbit_at(model, t_eval)
    K = model.kernels
    mode = orbit.mode_index
    outcome = {"SUCCESS": Outcome.SUCCESS, "TENSILE": Outcome.CONTACT_TENSILE,
               "NEWTON_FAILED": Outcome.NO_QUASI_STATIC}[orbit.outcome.name]
    stats = {"nfev": 0, "steps": 0, "rejected_steps": 0, "njev": 0, "switches": 0, "backend": request.backend,
             "response": "quasistatic", "where": "" if orbit.ok else orbit.message}
    traj = Trajectory(orbit.t, np.vstack([orbit.alpha, orbit.alpha_dot]), mode, tuple(K.MODES),
                      Switches.none(transition_surfaces(K), K.MODES), outcome,
                      stats, int(mode[-1]) if mode.size else 0)
    return _result(model, traj, request.backend)


def _watch(request: RunRequest, period: float):
    """The stopping check of one run (None without ``stop``)."""
    if request.stop is None:
        return None
    if not math.isfinite(period):
        raise ParameterError("stop", request.stop, "None for a cam without a period")
    per_revolution = stopping.per_revolution(request.span.sample_rate_Hz, period)
    return stopping.Watch(request.stop, per_revolution, request.options.rtol, request.options.atol)


# --- the check of simulate that needs the model, also run on every rig of a sweep (camdyn.sweep.check) ---
def checked_model(rig: Rig, scene: Scene, cam: CamMotion) -> Model:
    """The Model of a run, refused (:class:`ParameterError`) where its linearized motion is
    faster than MAX_RATE: an explicit method would take minutes or hours for milliseconds."""
    model = Model(rig, scene, cam)
    rate = model.fastest_rate
    if rate.value > MAX_RATE:
        drivers = ", ".join(f"{n} = {getattr(rig, n):g} (rate ~ {n}^{e:.2g})"
                            for n, e in _rate_drivers(model)[:6]) or "no single parameter"
        raise ParameterError("the fastest rate of the linearized motion (rad/s)", float(f"{rate.value:.3g}"),
                             f"<= {MAX_RATE:.0e} (an explicit method needs about rate/6 steps per simulated "
                             "second)", reason=f"in mode {rate.mode}; most sensitive to {drivers}")
    return model


def _rate_drivers(model: Model, factor: float = 1.1) -> list[tuple[str, float]]:
    """The rig parameters the fastest rate grows or falls with, with d log rate / d log value
    (where its size is >= 0.2, the largest first), found by changing each by ``factor``: what
    the error names."""
    base, rig = model.fastest_rate.value, model.rig
    found = []
    for name in sorted(set(model.kernels.INPUTS) & _RIG_NAMES):
        value = getattr(rig, name)
        if not value:
            continue
        try:
            other = Model(rig.replace(**{name: value * factor}), model.scene, model.cam).fastest_rate.value
        except CamdynError:
            continue
        elasticity = math.log(other / base) / math.log(factor)
        if abs(elasticity) >= 0.2:
            found.append((-abs(elasticity), name, elasticity))
    return [(name, elasticity) for _, name, elasticity in sorted(found)]


_RIG_NAMES = {p.name for p in PARAMETERS}


def _result(model: Model, traj, backend: str) -> Result:
    """The Result of a run: its output quantities (the generated ``outputs`` kernel, in each
    sample's mode, computed when first read: :class:`~camdyn.runs.result.Outputs`) and the ledger's
    works."""
    K = model.kernels
    t, alpha, alpha_dot = traj.t, traj.alpha, traj.alpha_dot
    names = list(K.OUTPUTS)
    if traj.has_ledger:  # the works of FLOWS (P_in, D_c, D_f), in that order
        names += list(LEDGER_OUTPUTS)
    outputs = Outputs(names, functools.partial(_output_values, model, traj, backend))
    theta = np.broadcast_to(model.cam_state(t)[CAM_THETA], t.shape).astype(float) if t.size else t.copy()
    contact = dict(zip(K.MODES, map(bool, K.CONTACT_OF_MODE)))
    follower = model.scene.follower
    return Result(t, alpha, alpha_dot, theta, traj.regime.astype(str), outputs, traj.switches,
                  traj.outcome, traj.stats, model.period, model.scene.slug, model.equilibrium.q,
                  {"rig": model.rig.name, "cam": model.cam, "contact": contact, "follower": follower,
                   "coordinate": COORDINATES[follower][0], "impact_transitions": impact_transitions(K)})


#: Result.outputs' names of the energy ledger's works of FLOWS (P_in, D_c, D_f), in that order
LEDGER_OUTPUTS = ("work_in", "dissipated_contact", "dissipated_friction")


def _output_values(model: Model, traj, backend: str) -> dict:
    """The output quantities at every sample of ``traj`` and the ledger's works, by name."""
    values = model.outputs_at(traj.mode, traj.t, traj.alpha, traj.alpha_dot, backend)
    outputs = dict(zip(model.kernels.OUTPUTS, values))
    if traj.has_ledger:
        for name, work in zip(LEDGER_OUTPUTS, traj.works):
            outputs[name] = work.copy()
    return outputs
