"""The check of a quasi-static orbit against the full model's converged run, for either follower."""
from __future__ import annotations

import numpy as np

import camdyn

#: samples per revolution of both runs (the quasi-static orbit is solved at each)
PER_REVOLUTION = 64
#: revolutions of the full model's run from its static equilibrium; the last one is compared
#: (its transient has decayed to the runs' tolerance on the tests' rigs by then)
REVOLUTIONS = 40


def against_converged_run(rig, dynamic: camdyn.Scene, quasi: camdyn.Scene, speed_rpm: float) -> tuple[float, float]:
    """(max |q - q_quasi-static|, max |q - q_i|) over the last of REVOLUTIONS revolutions of the full
    model's run (rtol 1e-10, atol 1e-14) at ``speed_rpm``: the quasi-static orbit's error and the
    residual response's amplitude it is measured against."""
    rate = PER_REVOLUTION * speed_rpm / 60
    q = camdyn.simulate(rig, quasi, speed_rpm=speed_rpm, revolutions=1, sample_rate_Hz=rate)
    d = camdyn.simulate(rig, dynamic, speed_rpm=speed_rpm, revolutions=REVOLUTIONS, sample_rate_Hz=rate,
                        rtol=1e-10, atol=1e-14)
    assert q.ok and d.ok, (q.outcome, d.outcome)
    last = slice((REVOLUTIONS - 1) * PER_REVOLUTION, REVOLUTIONS * PER_REVOLUTION)
    return float(np.max(np.abs(d.q[last] - q.q[:PER_REVOLUTION]))), float(np.max(np.abs(d.residual[last])))
