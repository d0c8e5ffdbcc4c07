"""Fingerprints of engine runs, to show that a change of the code's layout changes no run.

``python tests/fingerprints.py`` writes tests/data/run_fingerprints.json from the tree as it is
(run it before a restructuring); ``tests/test_fingerprints.py`` recomputes every fingerprint and
compares.  A fingerprint is the SHA-256 of a run's bytes: sample times, states and modes, and
its switch records; beside it, the run's last state and switch count, to say how far a changed
run is off.  The runs: the seven cases of benchmarks/performance.py at three tolerances, with
each step-size controller, the hard cases of tests/test_hard_cases.py (the reach rule's), a
stroboscopic map's run with the tangent dynamics, and the python backend on one case.
"""
from __future__ import annotations

import hashlib
import json
import math
import sys
from pathlib import Path

import numpy as np

import camdyn
from camdyn.engine import SolverOptions, integrate
from camdyn.model.model import Model

PATH = Path(__file__).resolve().parent / "data" / "run_fingerprints.json"
RIG = camdyn.example_rig()
LOSS16 = None


def _benchmark_cases():
    """(name, model, t_end) of benchmarks/performance.py's cases (written out here: a benchmark
    may change; these runs must not)."""
    loss = camdyn.contact_loss_speed(RIG.replace(l_lambda=0.016))
    imp = round(1.1 * loss)
    wide = {"e": 0.7 * RIG.r_c}
    specs = [
        ("impacting", dict(damping="D", friction="coulomb"), {"l_lambda": 0.016}, camdyn.ConstantSpeed(imp), 3 * 60 / imp),
        ("sliding_de", dict(damping="D", friction="coulomb"), {}, camdyn.ConstantSpeed(300), 0.2),
        ("sliding_self", dict(damping="D", friction="coulomb"), {}, camdyn.ConstantSpeed(-300), 0.2),
        ("sliding_point", dict(contact="point", damping="D", friction="coulomb"), {}, camdyn.ConstantSpeed(300), 0.2),
        ("reversal_coulomb", dict(damping="D", friction="coulomb", sliding_velocity="printed"), wide,
         camdyn.ConstantSpeed(50), 0.3),
        ("reversal_tanh", dict(damping="D", friction="tanh", sliding_velocity="printed"), wide,
         camdyn.ConstantSpeed(50), 0.3),
        ("oscillating", dict(damping="D", friction="tanh", motion="oscillating"), {}, camdyn.Oscillating(math.pi, 40.0),
         0.3),
    ]
    for name, scene, rig, cam, t_end in specs:
        yield name, Model(RIG.replace(**rig) if rig else RIG, camdyn.Scene(**scene), cam), t_end


def _digest(*arrays) -> str:
    h = hashlib.sha256()
    for a in arrays:
        h.update(np.ascontiguousarray(a).tobytes())
    return h.hexdigest()


def _trajectory(tr) -> dict:
    return {"sha256": _digest(tr.t, tr.y, tr.mode, tr.switches.records), "switches": len(tr.switches),
            "end": [float(tr.y[0, -1]), float(tr.y[1, -1])], "outcome": tr.outcome.name}


def _result(r) -> dict:
    return {"sha256": _digest(r.t, r.alpha, r.alpha_dot, r.regime.astype("U"), r.switches.records),
            "switches": len(r.switches), "end": [float(r.alpha[-1]), float(r.alpha_dot[-1])],
            "outcome": r.outcome.name}


def benchmark_runs():
    for name, model, t_end in _benchmark_cases():
        t_eval = np.arange(int(math.floor(t_end * 5000 + 1e-9)) + 1) / 5000
        y0 = model.static_state()
        for rtol in (1e-6, 1e-8, 1e-10):
            for control in ("pi", "scipy"):
                options = SolverOptions(rtol=rtol, atol=rtol * 1e-4, step_control=control)
                yield f"{name} rtol={rtol:g} {control}", _trajectory(integrate(model, (0.0, t_end), y0, t_eval, options))


def hard_runs():
    """The reach rule's hard cases (tests/test_hard_cases.py::_reach_cases), by simulate."""
    loss = camdyn.contact_loss_speed(RIG)
    eq = camdyn.analysis.statics.static_equilibrium(RIG)
    d_coulomb = camdyn.Scene(damping="D", friction="coulomb")
    d_free = camdyn.Scene(damping="D", friction="none")
    preloaded = RIG.replace(e=0.7 * RIG.r_c)
    cases = {
        "grazing": (RIG, d_coulomb, dict(speed_rpm=1.001 * loss, revolutions=4, rtol=1e-8)),
        "cascade": (RIG, d_free, dict(speed_rpm=0, t_end=0.1, y0=(eq.alpha + 2e-5, 0.0))),
        "memoryless_loose": (RIG, camdyn.Scene(damping="D", friction="coulomb", damping_switch="memoryless"),
                             dict(speed_rpm=300, t_end=0.02, rtol=1e-5, atol=1e-9)),
        "reversal": (preloaded, camdyn.Scene(damping="D", friction="coulomb", motion="oscillating"),
                     dict(cam=camdyn.Oscillating(math.pi, 40), t_end=0.45)),
        "impacting": (RIG, d_coulomb, dict(speed_rpm=1.3 * loss, revolutions=3, rtol=1e-6)),
        "chaos_range": (RIG, d_coulomb, dict(speed_rpm=2.2 * loss, revolutions=6, rtol=1e-7)),
        "ledger_pieces": (RIG, d_coulomb, dict(speed_rpm=1300, revolutions=210, sample_rate_Hz=2000, energy_ledger=True)),
    }
    for name, (rig, scene, kw) in cases.items():
        yield f"hard {name}", _result(camdyn.simulate(rig, scene, **kw))
    yield "python backend sliding_de", _result(camdyn.simulate(RIG, d_coulomb, speed_rpm=300, t_end=0.02,
                                                               backend="python"))


def orbit_runs():
    """A stroboscopic map's run and its tangent dynamics (the variational provider's work)."""
    from camdyn.orbits.tangent import tangent
    model = Model(RIG, camdyn.Scene(damping="D", friction="coulomb"), camdyn.ConstantSpeed(1500.0))
    x = np.array([0.02898769, 6.93660094])
    r = tangent(model, (0.0, model.period), x, options=SolverOptions(rtol=1e-10, atol=1e-13))
    yield "tangent 1500 rev/min", {"sha256": _digest(r.state, r.phi, np.array([r.divergence, r.log_det_saltation])),
                                   "switches": r.switches, "end": [float(v) for v in r.phi.ravel()],
                                   "outcome": "SUCCESS"}


def fingerprints() -> dict:
    out = {}
    for runs in (benchmark_runs(), hard_runs(), orbit_runs()):
        out.update(dict(runs))
    return out


if __name__ == "__main__":
    import warnings
    warnings.filterwarnings("ignore", category=camdyn.CompileNotice)
    data = fingerprints()
    PATH.write_text(json.dumps(data, indent=1, sort_keys=True) + "\n")
    print(f"{len(data)} fingerprints written to {PATH}", file=sys.stderr)
