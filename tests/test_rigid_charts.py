"""Design charts on rigid scenes (issue 29 over issue 28's scenes): the jump chart and the
two-parameter curve it follows (camdyn.orbits.continuation.continue_grazing), whose boundary on a
rigid contact is the lift-off, where the least contact force of the contact orbit reaches 0
(camdyn.orbits.continuation.boundary), not a gap maximum through 0.

For a rigid follower the quasi-static limit is exact: the contact orbit is the inverse
kinematics, so the chart's speeds are camdyn.analysis.contact_loss_speed's, and the compliance
shift is 0.  Three rigs: the example rig (oscillating follower, eccentric cam: the least force at
a smooth minimum), the second rig (translating flat face on a cam of arcs: the least force just
past a junction, a corner, where the onset's time is pinned) and a soft rig (k_s = 400 N/m, a 3 mm
preload: L_us = 0.115 m, contact-loss speed 315 rev/min) charted against the spring's free length.
Measured while writing it (jump_chart, ~1 s each here): 24, 25 and 26 orbits to the end, the
speeds within 3.4e-10, 1.06e-8 and 2.3e-10 of contact_loss_speed's (relative).
"""
from __future__ import annotations

import functools

import numpy as np
import pytest

import camdyn
from camdyn.analysis import contact_loss_speed
from camdyn.errors import ParameterError
from camdyn.model.presets import second_rig
from camdyn.orbits.continuation import (EVENTS, ContinuationSettings, GrazingOutcome, continue_bifurcation,
                                        continue_orbit, jump_chart)

ROCKER = camdyn.Scene(contact="rigid", damping="none", friction="none")
SECOND = camdyn.Scene(follower="translating", contact="rigid", damping="none", friction="none", profile="arcs")
#: the speeds' agreement with the inverse kinematics where the least force is a smooth minimum:
#: the rate's window (boundary.FORCE_WINDOW, its cubic term ~4e-11 of the force's scale), the
#: margin's zero-gap step (second order, gap_tol^2) and the integration (rtol 1e-8; the result
#: moved by < 1e-11 at rtol 1e-10) leave ~3e-10; at the compliant window (1e-2) it was 1.6e-8
SMOOTH_TOL = 1e-9
#: at a corner contact_loss_speed is the limit of its minimiser (scipy's bounded Brent, whose
#: tolerance near the junction is ~sqrt(eps) |theta| ~ 4e-8 rad): measured against a 1e-12 rad
#: grid it stands 1.08e-8 of itself above the corner's speed, the chart 0.26e-8 above that
CORNER_TOL = 3e-8

#: (rig, scene, parameter, start, end, phase_fraction, tolerance) per case
CASES = {
    "example": (camdyn.example_rig().replace(xi=0.8), ROCKER, "k_s", 2000.0, 2400.0, 0.5, SMOOTH_TOL),
    "second-rig": (second_rig(), SECOND, "k_s", 1430.8, 1716.96, 0.5, CORNER_TOL),
    "soft": (camdyn.example_rig().replace(k_s=400.0, L_us=0.115, xi=0.5), ROCKER, "L_us", 0.115, 0.12, 0.5,
             SMOOTH_TOL),
}

pytestmark = pytest.mark.usefixtures("quiet_compile")  # (tests/conftest.py)


@functools.lru_cache(maxsize=None)
def chart_of(name: str):
    """The jump chart of a case, once per session."""
    rig, scene, parameter, start, end, phase_fraction, _ = CASES[name]
    return jump_chart(rig, scene, parameter, start, end, phase_fraction=phase_fraction)


@pytest.fixture(params=list(CASES))
def case(request):
    return request.param, chart_of(request.param), CASES[request.param][-1]


def test_the_chart_follows_the_lift_off_to_its_end(case):
    name, chart, _ = case
    rig, _, parameter, start, end, *_ = CASES[name]
    assert chart.attrs["outcome"] == GrazingOutcome.END_REACHED.name, chart.attrs["outcome_message"]
    assert chart.attrs["boundary"] == "lift_off" and chart["grazing_gap"].attrs["units"] == "N"
    values = chart[parameter].values
    assert values[0] == pytest.approx(start, rel=1e-12) and values[-1] == pytest.approx(end, rel=1e-9) and np.all(np.diff(values) > 0)
    # each orbit converged on the contact side: F_n at its least (grazing_gap = -F_n) within
    # [1, 3] margins of gap_tol times the force's scale, converged at 2 (boundary.FORCE_MARGINS)
    margin = chart.attrs["settings_gap_tol"] * chart.attrs["force_scale_n"]
    force = -chart["grazing_gap"].values
    assert np.all(force >= 0.99 * margin) and np.all(force <= 3.01 * margin)
    # the second rig's least force is past a junction: its onset pinned there; the others' are smooth
    assert chart.attrs["phase_pinned_at_corner"] == int(name == "second-rig")


def test_the_rigid_jump_speed_is_the_inverse_kinematics_one(case):
    """The chart's speeds against contact_loss_speed at each point's parameter value (the
    tolerances: SMOOTH_TOL, CORNER_TOL); the compliance shift is 0 on a rigid contact."""
    name, chart, tol = case
    rig, _, parameter, *_ = CASES[name]
    loss = np.array([contact_loss_speed(rig.replace(**{parameter: float(v)})) for v in chart[parameter].values])
    assert np.array_equal(chart["contact_loss_rpm"].values, loss)
    assert np.all(chart["compliance_shift"].values == 0.0)
    assert np.max(np.abs(chart["speed_rpm"].values / loss - 1.0)) <= tol
    assert loss[-1] != pytest.approx(loss[0], rel=100 * tol)       # the speed moved along the chart


@pytest.mark.parametrize("at", [0, -1], ids=["start", "end"])
def test_the_curve_meets_the_one_parameter_lift_off(at):
    """At either end of the example's chart (k_s fixed there), continue_orbit in the speed over
    +-1 % of the chart's speed locates one lift_off at it: the event is bracketed to locate_tol
    in scaled arclength, within which the speed moves by at most locate_tol x its span; the
    chart's own error (SMOOTH_TOL of the speed, 1e-6 rev/min) is below that (2e-5 rev/min)."""
    rig, scene, *_ = CASES["example"]
    example_chart = chart_of("example")
    k_s, speed = float(example_chart["k_s"].values[at]), float(example_chart["speed_rpm"].values[at])
    settings = ContinuationSettings(switch_depth=0)
    lo, hi = 0.99 * speed, 1.01 * speed
    ds = continue_orbit(rig.replace(k_s=k_s), scene, "speed_rpm", lo, hi, settings=settings)
    lift = [float(lam) for kind, lam in zip(ds["event_kind"].values, ds["event_lambda"].values)
            if EVENTS[kind] == "lift_off"]
    assert len(lift) == 1, ds.attrs["branch_0_message"]
    assert abs(lift[0] - speed) <= settings.locate_tol * (hi - lo) + SMOOTH_TOL * speed


def test_a_rigid_scene_without_restitution_is_refused_with_its_range():
    """A rigid scene's impacts need xi: the chart refuses a rig without it, naming it and its range."""
    with pytest.raises(ParameterError, match=r"^xi is not given: required by scene rigid_.*valid: >= 0 and <= 1"):
        jump_chart(camdyn.example_rig(), ROCKER, "k_s", 2000.0, 2400.0)


#: the second rig's corner impact: the unstable period-1 orbit with three impacts a turn between these
#: speeds (rev/min), one of whose impacts lands on a junction at 331.204 (docs/second-rig.md)
CORNER_SEARCH = (310.0, 360.0)


def test_the_corner_impact_curve_meets_the_one_parameter_corner_impacts():
    """The second rig's corner impact followed in (speed, k_s) over 1 % of k_s (continue_bifurcation,
    kind corner_impact): the curve's speed with the impact on the junction (``speed_rpm_at_corner``:
    one Newton step across the ANGLE_MARGIN the curve is held at, off the set where the map's
    Jacobian jumps) against continue_orbit's corner_impact event at the curve's two ends.  Tolerance:
    the one-parameter location's bracket (locate_tol of its 50 rev/min range) plus the Newton step's
    own size (a one-step correction across the margin errs by less than the step it takes)."""
    from camdyn.orbits.continuation import events_table

    settings = ContinuationSettings(step=0.1, max_step=0.25, switch_depth=0)
    ds = continue_bifurcation(second_rig(), SECOND, "corner_impact", "k_s", 1430.8, 1.01 * 1430.8,
                              search=CORNER_SEARCH, settings=settings)
    assert ds.attrs["outcome"] == GrazingOutcome.END_REACHED.name, ds.attrs["outcome_message"]
    assert ds.attrs["corner_impacts"] == 3
    bracket = ContinuationSettings().locate_tol * (CORNER_SEARCH[1] - CORNER_SEARCH[0])
    for i in (0, -1):
        k_s = float(ds["k_s"].values[i])
        one = continue_orbit(second_rig().replace(k_s=k_s), SECOND, "speed_rpm", *CORNER_SEARCH,
                             settings=ContinuationSettings(switch_depth=0))
        located = [speed for kind, speed, *_ in events_table(one) if kind == "corner_impact"]
        at_corner, held = float(ds["speed_rpm_at_corner"].values[i]), float(ds["speed_rpm"].values[i])
        assert len(located) == 1
        assert abs(at_corner - located[0]) <= bracket + abs(held - at_corner)
    assert ds["speed_rpm"].values[-1] > ds["speed_rpm"].values[0] + 1.0   # it moved: 1.37 rev/min over the 1 %


@pytest.mark.parametrize("name", ["example", "second-rig"])
def test_the_searched_start_finds_the_lift_off_too(name):
    """Without the jump chart's guess, continue_grazing starts from the lift_off event that the
    one-parameter continuation locates over its search range (the contact side's orbit first):
    the first point is the same lift-off, at the inverse-kinematics speed to the case's tolerance."""
    from camdyn.orbits.continuation import continue_grazing

    rig, scene, parameter, start, end, phase_fraction, tol = CASES[name]
    loss = contact_loss_speed(rig.replace(**{parameter: start}))
    ds = continue_grazing(rig, scene, parameter, start, start + 0.1 * (end - start), search=(0.9 * loss, 1.05 * loss),
                          phase_fraction=phase_fraction)
    assert ds.attrs["outcome"] == GrazingOutcome.END_REACHED.name, ds.attrs["outcome_message"]
    assert abs(ds["speed_rpm"].values[0] / loss - 1.0) <= tol
