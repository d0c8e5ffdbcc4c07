"""The engine against an independent integrator of the same automaton (tests/oracle.py: SciPy's
solve_ivp with terminal events, none of the engine's rules) on the paper's scenes: the same
switches in the same order, at the same times, to the same end state.

Bounds: the engine at rtol 1e-10, the oracle at rtol 1e-12 with steps of at most an eighth
of the contact mode's period (so that it sees every contact).  A switch time moves by the state
error divided by the surface's rate; measured when written: switch times within 1.9e-10 s,
end angle within 5e-12 rad over the six scenes.  Bounds: 2e-9 s and 5e-11 rad.
"""
from __future__ import annotations

import math

import numpy as np
import pytest

import camdyn
import oracle
from camdyn.model.model import Model
from registry import RIG

LINE_16 = RIG.replace(l_lambda=0.016)


def _loss_speed(rig):
    return round(1.1 * camdyn.contact_loss_speed(rig))


CASES = {  # name: (rig, scene, cam, t_end in s or None for 3 revolutions)
    "impacting, line 16 mm, D episode": (LINE_16, camdyn.Scene(damping="D", friction="coulomb"), None, None),
    "impacting, D memoryless": (LINE_16, camdyn.Scene(damping="D", damping_switch="memoryless"), None, None),
    "sliding, line 1.6 mm, 300 rev/min": (RIG, camdyn.Scene(damping="D", friction="coulomb"),
                                          camdyn.ConstantSpeed(300), 0.05),
    "point contact, 1500 rev/min": (RIG, camdyn.Scene(contact="point", damping="D", friction="coulomb"),
                                    camdyn.ConstantSpeed(1500), None),
    "friction reversal, printed v_r": (RIG.replace(e=0.7 * RIG.r_c),
                                       camdyn.Scene(damping="D", friction="coulomb", sliding_velocity="printed"),
                                       camdyn.ConstantSpeed(50), 0.3),
    "oscillating cam, stick-slip": (RIG.replace(e=0.7 * RIG.r_c),
                                    camdyn.Scene(damping="D", friction="coulomb", motion="oscillating"),
                                    camdyn.Oscillating(math.pi, 50.0), 0.5),
}


@pytest.mark.parametrize("name", CASES)
def test_engine_agrees_with_an_independent_solve_ivp_driver(name):
    rig, scene, cam, t_end = CASES[name]
    cam = cam or camdyn.ConstantSpeed(_loss_speed(rig))
    t_end = t_end or 3 * cam.period
    model = Model(rig, scene, cam)
    ref, _, y_end, outcome = oracle.run(model.kernels, model.p, (0.0, t_end), model.static_state(),
                                        max_step=0.125 / model.equilibrium.frequency_Hz)
    assert outcome == "SUCCESS"
    run = camdyn.simulate(rig, scene, cam, t_end=t_end, rtol=1e-10, atol=1e-14, sample_rate_Hz=1 / t_end)
    assert run.ok
    assert len(ref) >= 1
    assert [(s.surface, s.before, s.after) for s in run.switches] == [(s.surface, s.before, s.after) for s in ref]
    np.testing.assert_allclose([s.t for s in run.switches], [s.t for s in ref], rtol=0, atol=2e-9)
    assert abs(run.alpha[-1] - y_end[0]) < 5e-11
