"""simulate(): one run of a scene on a rig, from the static equilibrium by default."""
from __future__ import annotations

import functools
import math
from typing import Callable

import numpy as np

from ..model.cam import CamMotion, cam_motion
from ..vocabulary import CAM_THETA
from ..engine.config import STEP_CONTROL, EventSettings, SolverOptions
from ..engine.driver import BACKENDS, Trajectory, integrate
from ..engine.loop import ALPHA, ALPHA_DOT, LEDGER_ROWS, WORK
from ..engine.switches import Switches
from ..engine.tables import transition_surfaces
from . import quasistatic, stopping
from ..errors import CamdynError, ParameterError
from ..model.model import Model
from ..outcome import Outcome
from .pieces import integrate_in_pieces
from .result import Outputs, Result
from ..model.rig import PARAMETERS, Rig
from ..model.scene import Scene

MAX_SAMPLES = 50_000_000
#: contact-mode periods one run may span: ~20 steps each, so about 2e9 steps at the most
#: (hours of SciPy stepping); beyond it the run is refused instead of hanging
MAX_CONTACT_PERIODS = 1e8
#: the fastest rate (rad/s) of the linearized motion a run accepts (Model.fastest_rate): an
#: explicit Runge-Kutta step is at most a few times 1/rate (measured with DOP853: 4.4e8 steps per
#: simulated second at 2.75e9 rad/s, zeta_D = 1e5 on the example rig; far from equilibrium many
#: more: 3.3e9 per second at 1.2e7 rad/s, k_s = 1e14), so 1e7 rad/s is ~2e6 steps per simulated
#: second and more; the shipped rigs are below 5e4 rad/s (reference-experiment: 4.3e4)
MAX_RATE = 1e7


def _positive(name, value, valid):
    if isinstance(value, bool) or not isinstance(value, (int, float, np.floating, np.integer)) \
            or not math.isfinite(value) or value <= 0:
        raise ParameterError(name, value, valid)
    return float(value)


def simulate(rig: Rig, scene: Scene | None = None, cam: CamMotion | None = None, *,
             speed_rpm: float | None = None, t_end: float | None = None,
             revolutions: float | None = None, sample_rate_Hz: float = 20_000.0,
             y0=None, t_start: float = 0.0, method: str = "DOP853", rtol: float = 1e-8,
             atol: float = 1e-12, max_step: float = math.inf,
             events: EventSettings | None = None, energy_ledger: bool = False,
             backend: str = "compiled", progress: Callable[[float], None] | None = None,
             stop=None, step_control=STEP_CONTROL) -> Result:
    """Simulate the cam-follower of ``rig`` with the physics of ``scene``.

    The cam motion is ``cam`` (a ConstantSpeed, Oscillating or UserMotion), or
    ``speed_rpm`` for a constant speed.  The run lasts ``t_end`` seconds or
    ``revolutions`` cam periods; it starts at ``y0 = (alpha, alpha_dot)`` (rad,
    rad/s), by default the static equilibrium (alpha*, 0) as in Section 4.
    The outputs are sampled at ``sample_rate_Hz``.  ``method`` (``"DOP853"`` or
    ``"RK45"``) integrates each mode of the scene's hybrid automaton; every switch is
    located on the dense output.  ``step_control``: the step-size controller, a
    :class:`camdyn.engine.StepControl` or its name: ``PI_CONTROL`` / ``"pi"`` (default:
    proportional-integral, fewer rejected steps where the error estimate jumps, as in a contact
    mode's ring-down) or ``SCIPY_CONTROL`` / ``"scipy"`` (SciPy's: the steps are ``solve_ivp``'s
    on a smooth stretch);
    docs/performance.md measures both.  Check ``result.ok``: a run that could not finish says why.
    ``energy_ledger=True`` also integrates the work of the cam drive and the energy
    dissipated by contact damping and by friction (``result.work_in``,
    ``result.dissipated_contact``, ``result.dissipated_friction``), so that
    energy(t) - energy(0) = work_in - dissipated_contact - dissipated_friction.
    ``backend="compiled"`` (default) runs the loop compiled by numba (the first call on a
    machine compiles for a few seconds, later ones load the cache); ``"python"`` runs the
    same loop in Python, for a :class:`~camdyn.model.cam.UserMotion` (its callables are Python).
    ``progress``, if given, is called with the share of the run done (0 to 1], after each
    piece of a long run (:mod:`camdyn.runs.pieces`: every 200 cam periods) and at its end; it
    does not change the run.  ``stop``, a :class:`camdyn.StopWhenPeriodic`, ends the run once its
    once-per-revolution section repeats (needs a whole number of samples per revolution) and
    completes the Result to the requested length by repeating the converged cycle
    (:mod:`camdyn.runs.stopping`; ``result.stats["revolutions_run"]``, ``["stop_period"]``).
    A scene with ``follower="quasistatic"`` is not integrated: the Result holds the quasi-static
    contact orbit at the samples (:mod:`camdyn.runs.quasistatic`; alpha_dot the rigid rate), up to
    where it does not exist (``Outcome.CONTACT_TENSILE``, ``result.stats["where"]``).

    Raises :class:`~camdyn.errors.ParameterError`, before any work, for a run that could not
    finish: more than MAX_CONTACT_PERIODS periods of the contact mode, MAX_SAMPLES samples, or a
    linearized motion faster than MAX_RATE rad/s (:attr:`Model.fastest_rate`: a damping, spring
    or inertia value far outside a mechanism's, for which an explicit method needs millions of
    steps per millisecond); the message names the parameters.
    """
    if backend not in BACKENDS:
        raise ParameterError("backend", backend, f"one of {BACKENDS}")
    scene = scene if scene is not None else Scene()
    cam = cam_motion(cam, speed_rpm)
    if backend == "compiled" and getattr(cam, "kind", None) == "user":
        raise ParameterError("backend", backend, "'python' for a UserMotion: its Theta(t) is a Python "
                             "callable, which compiled code cannot call")
    model = checked_model(rig, scene, cam)
    duration = run_duration(cam, model.equilibrium.vartheta, t_end, revolutions)
    check_start(t_start, y0)
    t_eval = t_start + np.arange(sample_count(duration, sample_rate_Hz)) / float(sample_rate_Hz)
    options = solver_options(method, rtol, atol, max_step, events, energy_ledger, step_control)
    if scene.follower == "quasistatic":
        return _quasi_static(model, t_eval, backend, y0=y0, energy_ledger=energy_ledger, stop=stop)
    y0 = model.static_state() if y0 is None else np.asarray(y0, dtype=float)
    run = functools.partial(integrate, backend=backend)
    watch = _watch(stop, sample_rate_Hz, model.period, options)
    traj = integrate_in_pieces(run, model, (t_start, t_start + duration), y0, t_eval, options, progress, watch)
    result = _result(model, traj, backend)
    if watch is None:
        return result
    # integrated up to: the end, unless it stopped (periodic, or early: its last sample); the last
    # sample of a run to the end can fall a sample interval short of it (the samples' rounding)
    ran_to = t_start + duration if result.ok and not traj.stats.get("stopped") else \
        (result.t[-1] if result.t.size else t_start)
    result.stats["revolutions_run"] = round((ran_to - t_start) / model.period, 6)
    result.stats["stop_period"] = watch.period if traj.stats.get("stopped") else 0
    if traj.stats.get("stopped"):
        # the samples the full run would have: the engine gives none past t_end (one rounded beyond it)
        t_eval = t_eval[t_eval <= t_start + duration]
        return stopping.extend(result, t_eval, watch.period, watch.per_revolution, t_start + duration)
    return result


def _quasi_static(model: Model, t_eval: np.ndarray, backend: str, **refused) -> Result:
    """The scene option follower="quasistatic": the quasi-static contact orbit at the samples
    (:mod:`camdyn.runs.quasistatic`, no integration), its outputs from the generated kernel; the
    samples end before a time where it does not exist (the outcome says why, stats["where"] where)."""
    for name, value in refused.items():
        if value is not None and value is not False:
            raise ParameterError(name, value, "not given with follower='quasistatic' (no integration: the orbit "
                                 "has no start, ledger or stop)")
    orbit = quasistatic.orbit_at(model, t_eval)
    K = model.kernels
    mode = orbit.mode_index
    outcome = {"SUCCESS": Outcome.SUCCESS, "TENSILE": Outcome.CONTACT_TENSILE,
               "NEWTON_FAILED": Outcome.NO_QUASI_STATIC}[orbit.outcome.name]
    stats = {"nfev": 0, "steps": 0, "rejected_steps": 0, "njev": 0, "switches": 0, "backend": backend,
             "follower": "quasistatic", "where": "" if orbit.ok else orbit.message}
    traj = Trajectory(orbit.t, np.vstack([orbit.alpha, orbit.alpha_dot]), mode, tuple(K.MODES),
                      Switches.none(transition_surfaces(K), K.MODES), outcome,
                      stats, int(mode[-1]) if mode.size else 0)
    return _result(model, traj, backend)


def _watch(stop, sample_rate_Hz, period: float, options: SolverOptions):
    """The stopping check of one run (None without ``stop``)."""
    if stop is None:
        return None
    if not isinstance(stop, stopping.StopWhenPeriodic):
        raise ParameterError("stop", stop, "None or a camdyn.StopWhenPeriodic")
    if not math.isfinite(period):
        raise ParameterError("stop", stop, "None for a cam without a period")
    return stopping.Watch(stop, stopping.per_revolution(sample_rate_Hz, period), options.rtol, options.atol)


# --- simulate's checks, also run on every point of a sweep before any work (camdyn.sweep.check) ---
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


def run_duration(cam: CamMotion, vartheta: float, t_end, revolutions) -> float:
    """The run's length (s) from ``t_end`` or ``revolutions``; refused beyond
    MAX_CONTACT_PERIODS periods of the contact mode (angular frequency ``vartheta``, Eq. 23)."""
    if (t_end is None) == (revolutions is None):
        raise ParameterError("t_end", t_end, "exactly one of t_end (s) or revolutions")
    if revolutions is not None:
        revolutions = _positive("revolutions", revolutions, "revolutions > 0")
        if not math.isfinite(cam.period):
            raise ParameterError("revolutions", revolutions, "t_end (s): this cam has no period")
        t_end = revolutions * cam.period
    duration = _positive("t_end", t_end, "t_end > 0 (s)")
    periods = duration * vartheta / (2 * math.pi)
    if periods > MAX_CONTACT_PERIODS:
        raise ParameterError(
            "t_end", duration, f"at most {MAX_CONTACT_PERIODS:.0e} periods of the contact mode "
            f"({vartheta / (2 * math.pi):.3g} Hz for this rig: check I_Pb, k_s, Y_c, Y_b, l_lambda); "
            f"this run spans {periods:.3g}")
    return duration


def sample_count(duration: float, sample_rate_Hz) -> int:
    """Samples of a run of ``duration`` s at ``sample_rate_Hz`` (both ends included when they fall
    on a sample); refused beyond MAX_SAMPLES."""
    fs = _positive("sample_rate_Hz", sample_rate_Hz, "sample_rate_Hz > 0")
    n = int(math.floor(duration * fs + 1e-9)) + 1
    if n > MAX_SAMPLES:
        raise ParameterError("sample_rate_Hz", fs, f"at most {MAX_SAMPLES} samples over the run "
                             f"(t_end * sample_rate_Hz = {duration * fs:.3g})")
    return n


def check_start(t_start, y0) -> None:
    """A finite start time; ``y0`` None (the static equilibrium) or (alpha rad, alpha_dot rad/s)."""
    if isinstance(t_start, bool) or not isinstance(t_start, (int, float)) or not math.isfinite(t_start):
        raise ParameterError("t_start", t_start, "a finite time (s)")
    if y0 is not None:
        y = np.asarray(y0, dtype=float)
        if y.shape != (2,) or not np.all(np.isfinite(y)):
            raise ParameterError("y0", y0, "two finite numbers (alpha rad, alpha_dot rad/s)")


def solver_options(method, rtol, atol, max_step, events, energy_ledger, step_control=STEP_CONTROL) -> SolverOptions:
    """simulate's solver keywords as validated :class:`SolverOptions`."""
    return SolverOptions(method, rtol, atol, max_step, events or EventSettings(), bool(energy_ledger), step_control)


def _result(model: Model, traj, backend: str) -> Result:
    """The Result of a run: its output quantities (the generated ``outputs`` kernel, in each
    sample's mode, computed when first read: :class:`~camdyn.runs.result.Outputs`) and the ledger's
    works."""
    K = model.kernels
    t, alpha, alpha_dot = traj.t, traj.y[ALPHA], traj.y[ALPHA_DOT]
    names = list(K.OUTPUTS)
    if traj.y.shape[0] == LEDGER_ROWS:  # the works of FLOWS (P_in, D_c, D_f), in that order
        names += list(LEDGER_OUTPUTS)
    outputs = Outputs(names, functools.partial(_output_values, model, traj, backend))
    theta = np.broadcast_to(model.cam_state(t)[CAM_THETA], t.shape).astype(float) if t.size else t.copy()
    contact = dict(zip(K.MODES, map(bool, K.CONTACT_OF_MODE)))
    return Result(t, alpha, alpha_dot, theta, traj.regime.astype(str), outputs, traj.switches,
                  traj.outcome, traj.stats, model.period, model.scene.slug, model.equilibrium.alpha,
                  {"rig": model.rig.name, "cam": model.cam, "contact": contact})


#: Result.outputs' names of the energy ledger's works of FLOWS (P_in, D_c, D_f), in that order
LEDGER_OUTPUTS = ("work_in", "dissipated_contact", "dissipated_friction")


def _output_values(model: Model, traj, backend: str) -> dict:
    """The output quantities at every sample of ``traj`` and the ledger's works, by name."""
    values = model.outputs_at(traj.mode, traj.t, traj.y[ALPHA], traj.y[ALPHA_DOT], backend)
    outputs = dict(zip(model.kernels.OUTPUTS, values))
    if traj.y.shape[0] == LEDGER_ROWS:
        for i, name in enumerate(LEDGER_OUTPUTS):
            outputs[name] = traj.y[WORK + i].copy()
    return outputs
