"""Corner impacts (issue 28): an impact landing on a junction of the cam's profile as a parameter
changes (Osorio, di Bernardo & Santini 2008), detected along a continued rigid branch
(camdyn.orbits.continuation.corners, the event kind ``corner_impact``).

The case, found by sweeping the second rig's speed (periodic orbits at 240-700 rev/min, their impact
angles against the junctions): its unstable period-1 orbit of three impacts per revolution lands
its third impact at 271.4 degrees at 320 rev/min and at 266.9 at 350, across the junction at 270
degrees (phi = -90 degrees, where the base circle meets a flank); the continuation from 310 to 360
rev/min locates it at 331.2 rev/min, where the multipliers jump (4.3 to 2.1)."""
from __future__ import annotations

import math

import numpy as np
import pytest

import camdyn
from camdyn.analysis import contact_loss_speed
from camdyn.model.followers import rig_on_cam
from camdyn.model.presets import second_rig
from camdyn.model.profiles import ArcProfile
from camdyn.orbits.continuation import EVENTS, ContinuationSettings, continue_orbit, events_table
from camdyn.orbits.continuation.corners import Landings, crossings, landings, near_bound, signed_distances, wrapped
from camdyn.orbits.continuation.corrector import Run
from camdyn.orbits.section_map import DEFAULT_OPTIONS, StroboscopicMap

SECOND = camdyn.Scene(follower="translating", contact="rigid", damping="none", friction="none", profile="arcs")
ROCKER_ON_ARCS = camdyn.Scene(contact="rigid", damping="none", friction="none", profile="arcs")
#: the second rig's branch across the junction at 270 degrees (the module's docstring)
CROSSING = (310.0, 360.0)
SETTINGS = ContinuationSettings(switch_depth=0)

pytestmark = pytest.mark.usefixtures("quiet_compile")  # (tests/conftest.py)


def _landing(angles, junctions=(0.5, 2.0, 4.0)) -> Landings:
    return Landings(np.asarray(angles, dtype=float), np.asarray(junctions, dtype=float))


def test_a_wrapped_distance_is_in_the_half_open_turn():
    """(-pi, pi]: pi stays, -pi and 3 pi go to pi, a small angle is itself."""
    assert wrapped([math.pi, -math.pi, 3 * math.pi, 0.25, -0.25]) == pytest.approx([math.pi] * 3 + [0.25, -0.25])


def test_an_impact_crossing_a_junction_counts_and_a_jump_or_the_far_side_does_not():
    """Made-up landings on junctions at 0.5, 2.0 and 4.0 rad (least spacing 1.5: near_bound 0.75 rad).
    An impact moving from 0.01 before to 0.02 past the junction at 0.5 counts; the other impact, still,
    does not; as many impacts are needed to match them; a distance that flips sign by passing the
    junction's far side (pi away) does not count, nor one that jumps from 0.7 before to 0.8 past."""
    assert near_bound(np.array([0.5, 2.0, 4.0])) == pytest.approx(0.75)
    before, after = _landing([0.49, 3.0]), _landing([0.52, 3.0])
    assert signed_distances(before)[0] == pytest.approx([-0.01, 0.49 - 2.0, 0.49 - 4.0 + 2 * math.pi])  # wrapped
    assert crossings(before, after) == [(0, 0)]
    assert crossings(after, before) == [(0, 0)]
    assert crossings(before, _landing([0.52])) == []                        # not as many impacts
    far, past = _landing([0.5 + math.pi - 0.01]), _landing([0.5 + math.pi + 0.01])
    assert signed_distances(far)[0, 0] * signed_distances(past)[0, 0] < 0    # the sign flips at the far side...
    assert crossings(far, past) == []                                       # ...but that is no corner impact
    assert crossings(_landing([0.5 - 0.7]), _landing([0.5 + 0.8])) == []    # a jump past near_bound
    assert crossings(_landing([0.5 - 0.7]), _landing([0.5 + 0.7])) == [(0, 0)]


def test_a_junction_at_the_turns_start_is_crossed_through_the_angles_wrap():
    """The landing angle is kept in [0, 2 pi): an impact moving from 2 pi - 0.01 to 0.01 crosses the
    junction at 0 (its distance -0.01 then +0.01), counted; without junctions nothing is."""
    before, after = _landing([2 * math.pi - 0.01], (0.0, 2.0, 4.0)), _landing([0.01], (0.0, 2.0, 4.0))
    assert signed_distances(before)[0, 0] == pytest.approx(-0.01)
    assert crossings(before, after) == [(0, 0)]
    assert crossings(_landing([0.49], ()), _landing([0.52], ())) == []


@pytest.mark.parametrize("follower", ["translating", pytest.param("oscillating", marks=pytest.mark.slow)])
def test_an_impact_lands_where_the_faces_normal_points_on_the_cam(follower):   # (the rocker's: its scene derived, ~7 s)
    """On a rigid scene over a cam of arcs at 1.5 x its jump speed (3 revolutions from rest), each
    impact's landing angle (camdyn.orbits.continuation.corners.landings) is the body angle of the
    face's normal toward the follower: the guide g = (cos gamma, sin gamma) for the translating face,
    -n = -(sin a, cos a) for the rocker at its angle a, less Theta at the impact.  Bound: rounding of
    the angles (1e-12 rad)."""
    if follower == "translating":
        rig, scene = second_rig(), SECOND
    else:
        cam = ArcProfile.circular_arc_cam(r_b=0.022, r_n=0.008, d=0.018, R=0.06)
        rig, scene = rig_on_cam(camdyn.example_rig().replace(xi=0.8), cam, theta0=math.pi), ROCKER_ON_ARCS
    model = camdyn.Model(rig, scene, camdyn.ConstantSpeed(1.5 * contact_loss_speed(rig)))
    section_map = StroboscopicMap(model, 3, 0.0, None, DEFAULT_OPTIONS)
    value, tr = section_map.run(model.static_state(), np.array([section_map.t_span[1]]))
    found = landings(Run(section_map, value, tr, np.zeros(0)))
    bounces = [s for s in tr.switches if s.after == "free" and s.before == "free"]
    assert found.angles.size == len(bounces) >= 3
    theta = np.array([rig.theta0 + model.cam.Omega_c * s.t for s in bounces])
    a = np.array([s.alpha for s in bounces])
    normal = np.full(a.size, rig.gamma) if follower == "translating" else np.arctan2(-np.cos(a), -np.sin(a))
    assert np.abs(wrapped(found.angles - (normal - theta))).max() < 1e-12
    assert found.junctions == pytest.approx(np.unique(np.mod(rig.profile.angles, 2 * math.pi)))


@pytest.fixture(scope="module")
def crossing():
    """The second rig's branch over CROSSING (about 1 s)."""
    return continue_orbit(second_rig(), SECOND, "speed_rpm", *CROSSING, settings=SETTINGS)


def test_the_second_rigs_branch_has_its_corner_impact_where_a_run_lands_on_the_junction(crossing):
    """The second rig's period-1 branch of three impacts per revolution, continued from 310 to 360 rev/min
    (the module's docstring): one corner_impact is reported, between two points whose third impact lands
    on either side of the junction at 270 degrees.  Checked independently: camdyn.simulate from the event's
    state at its speed, one revolution at the continuation's tolerances (rtol 1e-10), has an impact whose
    angle gamma - Theta (Theta = theta0 + Omega t, from its time) is within the location's tolerance of a
    junction of the profile (rig.profile.angles).

    That tolerance: the event is bracketed in scaled arclength to locate_tol, the located orbit the
    bracket's end before it, so its landing angle is within |dphi/ds| locate_tol of the junction.
    |dphi/ds|: the largest secant of the angle over the step that holds the event and its neighbours on
    either side (the angle is continuous there but its slope jumps, with the branch's tangent: measured
    -0.086 before, -0.135 rad per unit arclength after), doubled for its change along a step.  The
    simulation's own error in the angle (Omega times the impact time's error at rtol 1e-10) is far
    below it."""
    rig, ds = second_rig(), crossing
    corners = [row for row in events_table(ds) if row[0] == "corner_impact"]
    assert len(corners) == 1
    e = int(np.flatnonzero(ds["event_kind"].values == EVENTS.index("corner_impact"))[0])
    k = int(ds["event_point"][e])
    junctions = np.mod(rig.profile.angles[:-1], 2 * math.pi)
    p, q = (ds["impact_angle"].values[i] for i in (k, k + 1))
    d_p, d_q = (wrapped(angles[:, None] - junctions[None, :]) for angles in (p, q))
    i, j = np.unravel_index(np.argmin(np.abs(d_p)), d_p.shape)
    assert d_p[i, j] * d_q[i, j] < 0 and math.degrees(junctions[j]) == pytest.approx(270.0)
    lam = ds["lambda"].values
    assert min(lam[k], lam[k + 1]) < corners[0][1] < max(lam[k], lam[k + 1]) and 1 <= k < lam.size - 2
    angle = ds["impact_angle"].values[:, i]
    rate = max(abs(wrapped(angle[n + 1] - angle[n])) / _arclength(ds, n) for n in (k - 1, k, k + 1))
    tolerance = 2 * rate * SETTINGS.locate_tol

    speed = float(ds["event_lambda"][e])
    x = (float(ds["event_alpha"][e]), float(ds["event_alpha_dot"][e]))
    r = camdyn.simulate(rig, SECOND, speed_rpm=speed, revolutions=1, y0=x, rtol=DEFAULT_OPTIONS.rtol,
                        atol=DEFAULT_OPTIONS.atol, sample_rate_Hz=1000)
    assert r.ok
    theta = rig.theta0 + speed * 2 * math.pi / 60 * r.impacts()
    miss = np.abs(wrapped((rig.gamma - theta)[:, None] - junctions[None, :])).min()
    assert miss < tolerance, (miss, tolerance)


def _arclength(ds, k: int) -> float:
    """The scaled arclength from point k to k + 1 of a continue_orbit Dataset: the state over the
    motion's scale (attrs scale_alpha, scale_alpha_dot) and the parameter over its range."""
    dx = [(ds[name].values[k + 1] - ds[name].values[k]) / ds.attrs[f"scale_{name}"] for name in ("alpha", "alpha_dot")]
    dlam = (ds["lambda"].values[k + 1] - ds["lambda"].values[k]) / abs(ds.attrs["end"] - ds.attrs["start"])
    return math.sqrt(sum(v * v for v in dx) + dlam * dlam)


def test_a_rigid_branch_with_its_impact_angles_round_trips_and_plots(crossing, tmp_path):
    """The Dataset of a rigid branch (impact angles, a corner_impact) through netCDF, and its plot marks the
    event by name (camdyn.io.plots.EVENT_MARKERS)."""
    xr = pytest.importorskip("xarray")
    pytest.importorskip("matplotlib")
    from camdyn.io import plots
    path = tmp_path / "branch.nc"
    crossing.to_netcdf(path, engine="scipy")
    with xr.open_dataset(path, engine="scipy") as back:
        np.testing.assert_array_equal(back["impact_angle"].values, crossing["impact_angle"].values)
        assert [EVENTS[k] for k in back["event_kind"].values] == [e[0] for e in events_table(crossing)]
    labels = [t.get_text() for t in plots.branches(crossing).axes[0].get_legend().get_texts()]
    assert "corner impact" in labels
