"""The work-precision scenes, the configuration of a run of the report, and camdyn's runner and
error measure on a scene."""
from __future__ import annotations

import math
from dataclasses import dataclass
from pathlib import Path
from typing import Callable, NamedTuple

import numpy as np

import camdyn
from camdyn.engine.config import EventSettings, SolverOptions
from camdyn.engine.driver import integrate
from camdyn.model.model import Model

ROOT = Path(__file__).resolve().parent.parent.parent
DOCS, IMG = ROOT / "docs", ROOT / "docs" / "img"
RIG = camdyn.example_rig()
ATOL_PER_RTOL = 1e-4           # atol = 1e-4 rtol throughout
REFERENCE_RTOL = 1e-12         # engine DOP853: the reference; engine RK45: its check
#: camdyn's runs: label -> (method, reach factor of the crossing check, step-size controller);
#: the first two as camdyn runs by default; "every step sampled" the engine sampling every step's
#: interpolant at its interior points (EventSettings(reach_factor=inf)), as it did before the reach
#: rule, to show what the rule saves against the peers, which locate no events; "SciPy's step
#: control" the engine with SciPy's step-size controller instead of the default PI one
_REACH, _CONTROL = EventSettings().reach_factor, SolverOptions().step_control
CAMDYN = {"camdyn compiled DOP853": ("DOP853", _REACH, _CONTROL), "camdyn compiled RK45": ("RK45", _REACH, _CONTROL),
          "camdyn DOP853, every step sampled": ("DOP853", math.inf, _CONTROL),
          "camdyn DOP853, SciPy's step control": ("DOP853", _REACH, "scipy")}
MAIN, EVERY, SCIPY = ("camdyn compiled DOP853", "camdyn DOP853, every step sampled",
                      "camdyn DOP853, SciPy's step control")


@dataclass(frozen=True)
class Config:
    """What one run of the script measures."""

    quick: bool
    tols: tuple
    repeats: int               # interleaved rounds per (scene, rtol)
    floor_rounds: int
    start_runs: int            # fresh processes per start-up kind
    sweeps: bool
    speeds: int
    revolutions: int
    budget: float = 2.0        # s: a peer slower than this on one run is not run at tighter rtol

    @classmethod
    def from_args(cls, args) -> "Config":
        quick = args.quick
        return cls(quick, (1e-5, 1e-8, 1e-11) if quick else (1e-5, 1e-6, 1e-7, 1e-8, 1e-9, 1e-10, 1e-11),
                   2 if quick else 5, 10 if quick else 100, 1 if quick else 3, not args.no_sweeps,
                   20 if quick else 200, args.revolutions or (40 if quick else 200))


@dataclass(frozen=True)
class Case:
    key: str
    title: str
    scene: dict
    rig: dict
    cam: object
    t_end: float
    metric: str          # "impacts" (impact times + alpha) or "alpha" (max |alpha - ref|)
    fs: float = 5000.0

    def model(self) -> Model:
        return Model(RIG.replace(**self.rig) if self.rig else RIG, camdyn.Scene(**self.scene), self.cam)

    def t_eval(self) -> np.ndarray:
        return np.arange(int(math.floor(self.t_end * self.fs + 1e-9)) + 1) / self.fs


def cases() -> list[Case]:
    loss = camdyn.contact_loss_speed(RIG.replace(l_lambda=0.016))
    imp = round(1.1 * loss)
    return [
        Case("impacting", f"impacting, line 16 mm, D, {imp} rev/min (1.1 x contact loss)",
             dict(damping="D", friction="coulomb"), {"l_lambda": 0.016}, camdyn.ConstantSpeed(imp),
             3 * 60 / imp, "impacts"),
        Case("sliding_de", "sliding, line 1.6 mm, D, +300 rev/min (de-energizing)",
             dict(damping="D", friction="coulomb"), {}, camdyn.ConstantSpeed(300), 0.2, "alpha"),
        Case("sliding_self", "sliding, line 1.6 mm, D, -300 rev/min (self-energizing)",
             dict(damping="D", friction="coulomb"), {}, camdyn.ConstantSpeed(-300), 0.2, "alpha"),
        Case("sliding_point", "sliding, point contact, D, +300 rev/min",
             dict(contact="point", damping="D", friction="coulomb"), {}, camdyn.ConstantSpeed(300), 0.2, "alpha"),
        Case("reversal_coulomb", "friction reversal, e = 0.7 r_c, 50 rev/min, Coulomb (printed v_r)",
             dict(damping="D", friction="coulomb", sliding_velocity="printed"), {"e": 0.7 * RIG.r_c},
             camdyn.ConstantSpeed(50), 0.3, "alpha"),
        Case("reversal_tanh", "friction reversal, e = 0.7 r_c, 50 rev/min, tanh (printed v_r)",
             dict(damping="D", friction="tanh", sliding_velocity="printed"), {"e": 0.7 * RIG.r_c},
             camdyn.ConstantSpeed(50), 0.3, "alpha"),
        Case("oscillating", "oscillating cam, Theta_p = pi, 40 rev/min, D, tanh",
             dict(damping="D", friction="tanh", motion="oscillating"), {}, camdyn.Oscillating(math.pi, 40.0),
             0.3, "alpha"),
        cycloidal_cam_case(),
    ]


def cycloidal_cam_case() -> Case:
    """A cam that is not a circle (issue 27): the example rig's follower on a cycloidal
    rise-dwell-return cam (0.05 rad of lift, 100/80/100/80 degrees, base circle 25 mm; a spline of
    h through the profile evaluator), from rest on its dwell, at 0.8 x its jump speed."""
    from floor import cycloidal_cam_rig

    on_cam = cycloidal_cam_rig()
    speed = round(0.8 * camdyn.contact_loss_speed(on_cam))
    changes = {name: getattr(on_cam, name) for name in ("profile", "theta0", "alpha0", "chi0")}
    return Case("cycloidal_cam", f"cycloidal rise-dwell-return cam (spline), line 1.6 mm, D, {speed} rev/min",
                dict(damping="D", friction="coulomb", profile="spline"), changes, camdyn.ConstantSpeed(speed),
                0.2, "alpha")


class Sample(NamedTuple):
    """What a solver's run gives the error measure."""

    alpha: np.ndarray
    impacts: np.ndarray | None     # impact times (camdyn only), else None
    ok: bool
    switches: int


def camdyn_runner(case: Case, model: Model, method: str, rtol: float, reach_factor: float = _REACH,
                  step_control: str = _CONTROL) -> Callable[[], Sample]:
    """driver.integrate() on a model built once (as the peers' runners are): the work measured is
    integration, event location and sampling, not model set-up or output kernels."""
    t_eval, y0 = case.t_eval(), model.static_state()
    options = SolverOptions(method=method, rtol=rtol, atol=rtol * ATOL_PER_RTOL,
                            events=EventSettings(reach_factor=reach_factor), step_control=step_control)

    def run() -> Sample:
        tr = integrate(model, (0.0, case.t_end), y0, t_eval, options)
        hits = np.array([s.t for s in tr.switches if s.surface == "gap" and s.before == "free"])
        alpha = tr.y[0] if tr.t.size == t_eval.size else np.full(t_eval.size, np.nan)
        return Sample(alpha, hits, tr.outcome.ok, len(tr.switches))
    return run


def error(case: Case, ref: Sample, s: Sample) -> float:
    """max |alpha - alpha_ref| on the samples; for impacting runs with impact times (camdyn) also
    10 x the largest impact-time difference (s)."""
    if not s.ok or s.alpha.shape != ref.alpha.shape or not np.all(np.isfinite(s.alpha)):
        return math.inf
    e = float(np.max(np.abs(s.alpha - ref.alpha)))
    if case.metric == "impacts" and s.impacts is not None:
        same = s.impacts.size == ref.impacts.size
        e = max(e, float(np.max(np.abs(s.impacts - ref.impacts), initial=0.0)) * 10.0 if same else math.inf)
    return e
