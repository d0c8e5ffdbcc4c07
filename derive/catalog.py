"""The scenes generated into ``camdyn.generated`` and committed.

One entry per study of the paper (and the checks the tests need).  To add a
scene, add a line here and run ``python -m camdyn.derive``; the runtime finds
it by its options, with no edit in ``camdyn/``.
"""
from __future__ import annotations

from camdyn.vocabulary import SceneSpec

_IMPACT = [SceneSpec(contact="line", damping=d, friction="coulomb") for d in ("none", "A", "B", "C", "D", "E")]

CATALOG: tuple[SceneSpec, ...] = tuple(_IMPACT + [
    # Section 4: the printed, anti-dissipative sign of models B and D (misprint 2)
    SceneSpec(damping="B", damping_sign="printed"),
    SceneSpec(damping="D", damping_sign="printed"),
    # models D and E with the memoryless law switch (the sign of psi_i_dot at every instant),
    # beside the default episode reading of Sec. 3.4
    SceneSpec(damping="D", damping_switch="memoryless"),
    SceneSpec(damping="E", damping_switch="memoryless"),
    # frictionless: free vibration, energy conservation, damping energy tests
    SceneSpec(damping="none", friction="none"),
    SceneSpec(damping="D", friction="none"),
    SceneSpec(damping="B", friction="none"),
    SceneSpec(damping="B", friction="none", damping_sign="printed"),
    SceneSpec(damping="D", friction="none", damping_sign="printed"),
    # Section 6: point contact
    SceneSpec(contact="point", damping="D", friction="coulomb"),
    SceneSpec(contact="point", damping="none", friction="none"),
    # Section 7: friction models, kinematic and printed v_r, constant and oscillating cam
    SceneSpec(damping="D", friction="tanh"),
    SceneSpec(damping="D", friction="coulomb", sliding_velocity="printed"),
    SceneSpec(damping="D", friction="tanh", sliding_velocity="printed"),
    SceneSpec(damping="D", friction="coulomb", motion="oscillating"),
    SceneSpec(damping="D", friction="tanh", motion="oscillating"),
    SceneSpec(damping="D", friction="coulomb", motion="oscillating", sliding_velocity="printed"),
    SceneSpec(damping="D", friction="tanh", motion="oscillating", sliding_velocity="printed"),
    # Section 8: the paper's linear model and the exact linearization
    SceneSpec(damping="D", friction="coulomb", model="linear_paper"),
    SceneSpec(damping="D", friction="coulomb", model="linear_exact"),
    # a cam motion given by the user as a function of time
    SceneSpec(damping="D", friction="tanh", motion="user"),
    # the translating flat-faced follower (issue 27): on the eccentric circle (its lift is harmonic)
    # and on a cam given by its support function (a motion law's cam)
    SceneSpec(damping="D", friction="none", follower="translating"),
    SceneSpec(damping="D", friction="none", follower="translating", profile="spline"),
    # its statics (equilibrium, inverse kinematics: camdyn.analysis.statics) on either cam
    SceneSpec(damping="none", friction="none", follower="translating"),
    SceneSpec(damping="none", friction="none", follower="translating", profile="spline"),
    # the rigid contact law (issue 28): Newton's impacts, the constrained mode, chatter's end
    SceneSpec(contact="rigid", damping="none", friction="none"),
    SceneSpec(contact="rigid", damping="none", friction="none", follower="translating"),
])
