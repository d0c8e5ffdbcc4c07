"""simulate(): one run of a scene on a rig, from the static equilibrium by default."""
from __future__ import annotations

import math

import numpy as np

from .cam import CamMotion, ConstantSpeed
from .errors import ParameterError
from .events import EventSettings
from .hybrid import Hybrid
from .integrate import SolverOptions, integrate
from .model import Model
from .pieces import integrate_in_pieces
from .result import Result
from .rig import Rig
from .scene import Scene

MAX_SAMPLES = 50_000_000
#: contact-mode periods one run may span: ~20 steps each, so about 2e9 steps at the most
#: (hours of SciPy stepping); beyond it the run is refused instead of hanging
MAX_CONTACT_PERIODS = 1e8
BACKENDS = ("scipy", "compiled")


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
             backend: str = "scipy") -> Result:
    """Simulate the cam-follower of ``rig`` with the physics of ``scene``.

    The cam motion is ``cam`` (a ConstantSpeed, Oscillating or UserMotion), or
    ``speed_rpm`` for a constant speed.  The run lasts ``t_end`` seconds or
    ``revolutions`` cam periods; it starts at ``y0 = (alpha, alpha_dot)`` (rad,
    rad/s), by default the static equilibrium (alpha*, 0) as in Section 4.
    The outputs are sampled at ``sample_rate_Hz``.  SciPy's ``method`` (DOP853,
    RK45, Radau, BDF, LSODA) integrates each regime; switches are located on
    its dense output.  Check ``result.ok``: a run that could not finish says why.
    ``energy_ledger=True`` also integrates the work of the cam drive and the energy
    dissipated by contact damping and by friction (``result.work_in``,
    ``result.dissipated_contact``, ``result.dissipated_friction``), so that
    energy(t) - energy(0) = work_in - dissipated_contact - dissipated_friction.
    ``backend="compiled"`` runs the whole hybrid loop in numba (:mod:`camdyn.compiled`;
    method DOP853 or RK45, built-in cam motions); ``"scipy"`` is the accuracy reference.
    """
    if backend not in BACKENDS:
        raise ParameterError("backend", backend, f"one of {BACKENDS}")
    scene = scene if scene is not None else Scene()
    if cam is None:
        if speed_rpm is None:
            raise ParameterError("cam", None, "a cam motion, or speed_rpm for a constant speed")
        cam = ConstantSpeed(speed_rpm)
    elif speed_rpm is not None:
        raise ParameterError("speed_rpm", speed_rpm, "not both cam and speed_rpm")
    model = Model(rig, scene, cam)
    if (t_end is None) == (revolutions is None):
        raise ParameterError("t_end", t_end, "exactly one of t_end (s) or revolutions")
    if revolutions is not None:
        revolutions = _positive("revolutions", revolutions, "revolutions > 0")
        if not math.isfinite(cam.period):
            raise ParameterError("revolutions", revolutions, "t_end (s): this cam has no period")
        t_end = revolutions * cam.period
    duration = _positive("t_end", t_end, "t_end > 0 (s)")
    periods = duration * model.equilibrium.vartheta / (2 * math.pi)
    if periods > MAX_CONTACT_PERIODS:
        raise ParameterError(
            "t_end", duration, f"at most {MAX_CONTACT_PERIODS:.0e} periods of the contact mode "
            f"({model.equilibrium.frequency_Hz:.3g} Hz for this rig: check I_Pb, k_s, Y_c, Y_b, l_lambda); "
            f"this run spans {periods:.3g}")
    if isinstance(t_start, bool) or not isinstance(t_start, (int, float)) or not math.isfinite(t_start):
        raise ParameterError("t_start", t_start, "a finite time (s)")
    fs = _positive("sample_rate_Hz", sample_rate_Hz, "sample_rate_Hz > 0")
    n = int(math.floor(duration * fs + 1e-9)) + 1
    if n > MAX_SAMPLES:
        raise ParameterError("sample_rate_Hz", fs, f"at most {MAX_SAMPLES} samples over the run "
                             f"(t_end * sample_rate_Hz = {duration * fs:.3g})")
    y0 = model.static_state() if y0 is None else np.asarray(y0, dtype=float)
    if y0.shape != (2,) or not np.all(np.isfinite(y0)):
        raise ParameterError("y0", y0, "two finite numbers (alpha rad, alpha_dot rad/s)")
    options = SolverOptions(method, rtol, atol, max_step, events or EventSettings(), bool(energy_ledger))
    t_eval = t_start + np.arange(n) / fs
    traj = integrate_in_pieces(_integrator(backend, options), model, (t_start, t_start + duration), y0, t_eval,
                               options)
    return _result(model, traj)


def _integrator(backend: str, options: SolverOptions):
    """The integrate() of a backend: camdyn.integrate (SciPy) or camdyn.compiled."""
    if backend == "scipy":
        return integrate
    from .compiled import integrate as compiled
    return compiled


def _result(model: Model, traj) -> Result:
    t, alpha, alpha_dot = traj.t, traj.y[0], traj.y[1]
    outputs = {name: np.empty(t.size) for name in model.kernels.OUTPUTS}
    if traj.y.shape[0] == 5:
        for i, name in enumerate(("work_in", "dissipated_contact", "dissipated_friction")):
            outputs[name] = traj.y[2 + i].copy()
    hybrid = Hybrid(model)
    for name in dict.fromkeys(traj.regime):
        mask = traj.regime == name
        values = hybrid.outputs(traj.keys[name], t[mask], alpha[mask], alpha_dot[mask])
        for key, v in zip(model.kernels.OUTPUTS, values):
            outputs[key][mask] = v
    theta = np.broadcast_to(model.cam_state(t)[0], t.shape).astype(float) if t.size else t.copy()
    return Result(t, alpha, alpha_dot, theta, traj.regime.astype(str), outputs, traj.switches,
                  traj.outcome, traj.stats, model.period, model.scene.slug, model.equilibrium.alpha,
                  {"rig": model.rig.name, "cam": model.cam})
