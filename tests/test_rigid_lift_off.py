"""The lift-off event of a rigid scene (issue 28): where a continued period-1 contact orbit of a
rigid follower starts to leave the cam (:mod:`camdyn.orbits.continuation.lift_off`), against the
inverse-kinematics contact-loss speed, exact for a rigid contact (no compliance)."""
from __future__ import annotations

import camdyn
import pytest
from camdyn.analysis import contact_loss_speed
from camdyn.model.presets import second_rig
from camdyn.orbits.continuation import ContinuationOutcome, ContinuationSettings, continue_orbit, events_table

XI = 0.8                # neither rig below has a restitution: the one tests/test_rigid.py gives its rigs
ROCKER_SCENE = camdyn.Scene(contact="rigid", damping="none", friction="none")
SECOND_SCENE = camdyn.Scene(follower="translating", contact="rigid", damping="none", friction="none", profile="arcs")
#: the branch is continued over +-WIDTH of the contact-loss speed
WIDTH = 0.01

pytestmark = pytest.mark.usefixtures("quiet_compile")  # (tests/conftest.py)


def _lift_offs(rig, scene, **kw):
    """The lift-off speeds located along the period-1 branch continued in the speed over
    (1 -+ WIDTH) x the contact-loss speed, the loss speed and the location's bound in rev/min:
    the event is bracketed to locate_tol in scaled arclength, in which the speed moves by at most
    its span per unit (the tangent is a unit vector whose speed component is lambda / span)."""
    loss = contact_loss_speed(rig)
    ds = continue_orbit(rig, scene, "speed_rpm", (1 - WIDTH) * loss, (1 + WIDTH) * loss, **kw)
    outcome = ds.attrs["outcomes"].split()[int(ds["branch_outcome"].values[0])]
    assert outcome == ContinuationOutcome.END_REACHED.name, ds.attrs["branch_0_message"]
    assert "grazing" not in [kind for kind, *_ in events_table(ds)]
    speeds = [speed for kind, speed, branch, _ in events_table(ds) if kind == "lift_off"]
    return speeds, loss, ContinuationSettings().locate_tol * 2 * WIDTH * loss


@pytest.mark.parametrize("rig", [camdyn.example_rig().replace(xi=XI),
                                 camdyn.load_rig("reference-experiment").replace(xi=XI)],
                         ids=["example", "reference-experiment"])
def test_the_oscillating_followers_branch_lifts_off_at_the_inverse_kinematics_speed(rig):
    """One lift-off along the branch, at the contact-loss speed to the location's bound (the
    least force's sampling error, 5e-11 N by the quartic fit, moves it by ~1e-10 of the speed:
    negligible); no grazing (the largest gap of a rigid contact orbit is rounding)."""
    speeds, loss, bound = _lift_offs(rig, ROCKER_SCENE)
    assert len(speeds) == 1
    assert abs(speeds[0] - loss) <= bound


def test_the_second_rigs_branch_lifts_off_at_its_corner_at_the_inverse_kinematics_speed():
    """The translating follower of the second rig leaves at a corner of its cam (docs/second-rig.md),
    where the needed force jumps: the test function's contact side is the force just past the
    corner (:func:`camdyn.orbits.continuation.lift_off.restart_force`).  Its contact orbit starts
    (the section map's domain check reads the junction, watched in both directions, as a restart,
    not a side: camdyn.engine.Domain) and the lift-off is located at the inverse-kinematics speed to
    the location's bound; past it the impacting orbit flung at the corner is not smooth in the
    speed, and the branch may end there (its corrector at the minimum step), beyond the event.
    Section at half a turn (as jump_chart's): the corrector steps past the onset from sections at
    0, 0.05, 0.15, 0.25, 0.5, 0.6, 0.75 and 0.9 of the turn, but not from 0.4 (it ends at the
    minimum step 3e-5 of the speed short of the onset, no point beyond it to bracket the event),
    measured since the junctions are stepped to (camdyn.engine.rules.time_bound): before, the
    follower rode through the corner with the force negative, past the onset, unnoticed."""
    loss = contact_loss_speed(second_rig())
    ds = continue_orbit(second_rig(), SECOND_SCENE, "speed_rpm", (1 - WIDTH) * loss, (1 + WIDTH) * loss,
                        phase_fraction=0.5)
    events = events_table(ds)
    speeds = [speed for kind, speed, *_ in events if kind == "lift_off"]
    assert len(speeds) == 1 and "grazing" not in [kind for kind, *_ in events]
    assert abs(speeds[0] - loss) <= ContinuationSettings().locate_tol * 2 * WIDTH * loss
    assert ds["lambda"].values.max() > speeds[0]              # the branch went past the event
