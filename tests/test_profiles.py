"""Cam profiles as support functions, followers in rigid contact, synthesis and tables (issue 27):
camdyn.model.{profiles, followers, synthesis, cam_tables}."""
from __future__ import annotations

import math

import numpy as np
import pytest

from camdyn.errors import ParameterError
from camdyn.model.cam_tables import MIN_ROWS, LiftTable, RadiusTable, cam_from_table, read_cam_table
from camdyn.model.followers import OscillatingFollower, TranslatingFollower, rigid_contact
from camdyn.model.motion_laws import LAWS, rise_dwell_return
from camdyn.model.profiles import ArcProfile, EccentricCircle, SplineProfile, profile_from_block
from camdyn.model.synthesis import cam_from_law, smallest_base_radius

EPS = np.finfo(float).eps
TWO_PI = 2 * math.pi
PHI = np.linspace(-TWO_PI, 2 * TWO_PI, 3001)          # beyond one turn: the periodic reduction too
THETA = np.linspace(0, TWO_PI, 20001)

#: the example rig's oscillating follower (camdyn/model/data/example.toml): P->E from Eq. 5 with
#: alpha0 = 0, theta0 = pi/2: (chi0, w_b/2 + e + r_c) = (0.1, 0.0375) m
EXAMPLE_P_TO_E, EXAMPLE_W_B, EXAMPLE_R_C, EXAMPLE_E = (0.1, 0.0375), 0.02, 0.025, 0.0025

#: the followers of the round trip, with a lift (m or rad) and a base circle that keeps the cams convex
FOLLOWERS = {
    "translating": (TranslatingFollower(), 0.010, 0.02),
    "translating-gamma": (TranslatingFollower(gamma=0.3, offset=0.004), 0.004, 0.01),
    "oscillating": (OscillatingFollower(EXAMPLE_P_TO_E, EXAMPLE_W_B), 0.1, 0.03),
}
RDR = np.radians([90.0, 60.0, 90.0, 120.0])


# --- the eccentric circle --------------------------------------------------------------------------

def test_eccentric_circle_closed_form():
    """h = r_c - e cos phi and its derivatives; rho = r_c; the contact point on the circle of centre
    (-e, 0) with the outward normal u(phi). Tolerances: a few ulps of r_c."""
    cam = EccentricCircle(EXAMPLE_R_C, EXAMPLE_E)
    r_c, e = EXAMPLE_R_C, EXAMPLE_E
    closed = [r_c - e * np.cos(PHI), e * np.sin(PHI), e * np.cos(PHI), -e * np.sin(PHI)]
    for d, expected in enumerate(closed):
        assert np.allclose(cam.h(PHI, d), expected, rtol=0, atol=4 * EPS * r_c), d
    assert np.allclose(cam.radius_of_curvature(PHI), r_c, rtol=0, atol=4 * EPS * r_c)
    c = cam.contact_point(PHI) - np.array([-e, 0.0])
    assert np.allclose(c, r_c * np.stack([np.cos(PHI), np.sin(PHI)], -1), rtol=0, atol=8 * EPS * r_c)
    assert cam.block().size == 0


@pytest.mark.parametrize("gamma", [math.pi / 2, 0.0, 2.0])
def test_translating_follower_on_the_eccentric_circle_is_harmonic(gamma):
    """y = r_c - e cos(gamma - Theta) exactly (to rounding: 4 ulp of r_c), its rates at the speed
    omega the closed forms omega e sin(...) ... : a harmonic lift."""
    cam, omega = EccentricCircle(EXAMPLE_R_C, EXAMPLE_E), 7.0
    r = rigid_contact(cam, TranslatingFollower(gamma=gamma), THETA, omega)
    x = gamma - THETA
    assert np.allclose(r.q, EXAMPLE_R_C - EXAMPLE_E * np.cos(x), rtol=0, atol=4 * EPS * EXAMPLE_R_C)
    assert np.allclose(r.q_dot, -omega * EXAMPLE_E * np.sin(x), rtol=0, atol=4 * EPS * omega * EXAMPLE_R_C)
    assert np.allclose(r.q_ddot, omega ** 2 * EXAMPLE_E * np.cos(x), rtol=0, atol=4 * EPS * omega ** 2 * EXAMPLE_R_C)
    # where the contact sits on the face: r_c along g from the circle's centre G = -e (cos, sin)(Theta),
    # so at G.t = -e sin(gamma - Theta) along the face's unit t = (sin gamma, -cos gamma)
    assert np.allclose(r.on_face, -EXAMPLE_E * np.sin(x), rtol=0, atol=8 * EPS * EXAMPLE_R_C)


def _eq29(theta):
    """The paper's rigid contact angle (Eq. 29, as derive/geometry.py writes it):
    asin(R/|P->G_c|) - atan2(Y, X), (X, Y) = P->G_c = P->E - e (cos, sin)(Theta), R = r_c + w_b/2."""
    X = EXAMPLE_P_TO_E[0] - EXAMPLE_E * np.cos(theta)
    Y = EXAMPLE_P_TO_E[1] - EXAMPLE_E * np.sin(theta)
    return np.arcsin((EXAMPLE_R_C + EXAMPLE_W_B / 2) / np.hypot(X, Y)) - np.arctan2(Y, X)


def test_oscillating_follower_on_the_eccentric_circle_is_eq29():
    """The general path (Newton on the support function) against Eq. 29. Newton stops at a step of
    4 ulp of pi: 1e-14 rad is its reach."""
    cam = EccentricCircle(EXAMPLE_R_C, EXAMPLE_E)
    follower = OscillatingFollower(EXAMPLE_P_TO_E, EXAMPLE_W_B)
    omega = 3.0
    r = rigid_contact(cam, follower, THETA, omega)
    alpha = _eq29(THETA)
    assert np.abs(r.q - alpha).max() < 1e-14
    assert np.abs(follower.gap(cam, r.q, THETA)).max() < 1e-16      # rigid contact: 1e-14 rad x 0.1 m arm
    # rates against central differences of Eq. 29, step h = 1e-3: truncation h^2/6 |alpha'''| omega and
    # h^2/12 |alpha''''| omega^2 with |alpha^(n)| <~ 0.03 (alpha ~ (e/chi0) sin, e/chi0 = 0.025): ~2e-8;
    # rounding of asin, atan2 (~eps): 4 eps omega^2 / h^2 ~ 1e-8
    h = 1e-3
    fd1 = (_eq29(THETA + h) - _eq29(THETA - h)) / (2 * h) * omega
    fd2 = (_eq29(THETA + h) - 2 * alpha + _eq29(THETA - h)) / h ** 2 * omega ** 2
    assert np.abs(r.q_dot - fd1).max() < 1e-7
    assert np.abs(r.q_ddot - fd2).max() < 1e-7
    assert np.all(r.on_face > 0.09)                                    # the moment arm chi ~ chi0 = 0.1 m


# --- arcs --------------------------------------------------------------------------------------------

def _arc_cam():
    return ArcProfile.circular_arc_cam(r_b=0.02, r_n=0.008, d=0.02, R=0.05, nose_angle=0.4)


def test_arc_cam_against_its_circles():
    """On each arc the contact point c(phi) lies on that arc's circle with outward normal u(phi)
    (h, h' from the circle), h'' = rho_k - h (the circle's curvature); the flank circles touch the
    base and the nose circles (distance of centres = difference of radii). Tolerances: 16 ulp of
    the cam's size (products of lengths ~ 0.05 m)."""
    cam = _arc_cam()
    size = 0.05
    k = np.clip(np.searchsorted(cam.angles, cam.angles[0] + np.mod(PHI - cam.angles[0], TWO_PI), side="right") - 1, 0, 3)
    centres = np.stack([cam.cx[k], cam.cy[k]], -1)
    u = np.stack([np.cos(PHI), np.sin(PHI)], -1)
    assert np.allclose(cam.contact_point(PHI) - centres, cam.rho[k, None] * u, rtol=0, atol=16 * EPS * size)
    assert np.allclose(cam.h(PHI, 2), cam.rho[k] - cam.h(PHI), rtol=0, atol=16 * EPS * size)
    nose, flank1, base, flank2 = (np.array([cam.cx[i], cam.cy[i]]) for i in range(4))
    assert np.hypot(*base) < 16 * EPS * size                                  # the base circle about E
    assert np.hypot(*nose) == pytest.approx(0.02, abs=16 * EPS * size)       # the nose centre d from E
    for flank in (flank1, flank2):
        assert np.hypot(*(flank - base)) == pytest.approx(0.05 - 0.02, abs=16 * EPS * size)
        assert np.hypot(*(flank - nose)) == pytest.approx(0.05 - 0.008, abs=16 * EPS * size)
    assert cam.h(0.4) == pytest.approx(0.02 + 0.008, abs=16 * EPS * size)   # the nose tip: lift d + r_n - r_b
    assert cam.h(0.4 + math.pi) == pytest.approx(0.02, abs=16 * EPS * size)


def test_arc_junctions_tangent():
    """Either side of each junction (+-delta) h and h' agree (C1: the same tangent line and contact
    point: they differ by at most delta max|h'|, delta max|h''| plus rounding) and h'' jumps by the
    difference of the radii (the curvature jump the automaton must see)."""
    cam = _arc_cam()
    delta = 1e-10
    for j in range(1, 5):
        a, before, after = cam.angles[j], j - 1, j % 4
        left = [cam.h(a - delta, d) for d in range(3)]
        right = [cam.h(a + delta, d) for d in range(3)]
        assert left[0] == pytest.approx(right[0], abs=2 * delta * 0.05 + 16 * EPS * 0.05)
        assert left[1] == pytest.approx(right[1], abs=2 * delta * 0.05 + 16 * EPS * 0.05)
        assert right[2] - left[2] == pytest.approx(cam.rho[after] - cam.rho[before], abs=2 * delta * 0.05 + 16 * EPS * 0.05)


def test_arcs_refused_when_not_tangent_or_not_convex():
    cam = _arc_cam()
    cx = cam.cx.copy()
    cx[1] += 1e-6                                       # a micrometre off: h jumps at the junctions
    with pytest.raises(ParameterError, match=r"jumps by .* in h.? at phi = "):
        ArcProfile(cam.angles, cam.rho, cx, cam.cy)
    with pytest.raises(ParameterError, match=r"rho = -0.001 m"):
        ArcProfile(cam.angles, np.array([-0.001, 0.05, 0.02, 0.05]), cam.cx, cam.cy)
    with pytest.raises(ParameterError, match=r"R = 0.02 .*must be > \(d \+ r_b \+ r_n\)/2 = 0.024"):
        ArcProfile.circular_arc_cam(r_b=0.02, r_n=0.008, d=0.02, R=0.02)


# --- blocks -------------------------------------------------------------------------------------------

def _spline_from_block(block, phi):
    """The generated kernels' reading of a spline block, written from its layout alone."""
    K = int(block[0])
    breaks, c = block[1:K + 2], block[K + 2:].reshape(K, 6)
    x = breaks[0] + np.mod(phi - breaks[0], TWO_PI)
    k = np.clip(np.searchsorted(breaks, x, side="right") - 1, 0, K - 1)
    t = x - breaks[k]
    return sum(c[k, j] * t ** j for j in range(6))


def _arcs_from_block(block, phi):
    K = int(block[0])
    a, rho, cx, cy = block[1:K + 2], block[K + 2:2 * K + 2], block[2 * K + 2:3 * K + 2], block[3 * K + 2:]
    x = a[0] + np.mod(phi - a[0], TWO_PI)
    k = np.clip(np.searchsorted(a, x, side="right") - 1, 0, K - 1)
    return rho[k] + cx[k] * np.cos(phi) + cy[k] * np.sin(phi)


def test_blocks_round_trip():
    """A reader of the block layout alone reproduces h (rounding of the evaluation order: 64 ulp of
    the cam's size); from_block gives back the same profile."""
    spline = cam_from_law(rise_dwell_return(0.01, RDR), TranslatingFollower(), 0.02)
    arcs = _arc_cam()
    for profile, reader, size in ((spline, _spline_from_block, 0.03), (arcs, _arcs_from_block, 0.03)):
        block = profile.block()
        assert block.dtype == np.float64 and block.ndim == 1
        assert np.allclose(reader(block, PHI), profile.h(PHI), rtol=0, atol=64 * EPS * size)
        again = profile_from_block(profile.kind, block)
        assert np.array_equal(again.h(PHI), profile.h(PHI))
    K = int(spline.block()[0])
    assert spline.block().size == 1 + (K + 1) + 6 * K
    assert spline.breaks[-1] - spline.breaks[0] == pytest.approx(TWO_PI, abs=4 * EPS * TWO_PI)


# --- synthesis round trip ------------------------------------------------------------------------------

def _round_trip(law_name, follower_name, angles=RDR):
    follower, lift, r_b = FOLLOWERS[follower_name]
    law = rise_dwell_return(lift, angles, law_name)
    cam = cam_from_law(law, follower, r_b)
    base = r_b if follower.kind == "translating" else follower.base_angle(r_b)
    return law, cam, base, follower, lift


@pytest.mark.parametrize("follower_name", list(FOLLOWERS))
@pytest.mark.parametrize("law_name", LAWS)
def test_synthesis_round_trip(law_name, follower_name):
    """motion law -> cam -> rigid-contact kinematics gives back the law, on 20001 cam angles.

    Tolerances, relative to the lift, per rad^k of cam angle: the construction holds the spline's h
    to 1e-12 and h'' to 1e-8 of the cam's h-range between its breakpoints (cam_from_law), and
    measured worst over these cases: lift 6.6e-13, velocity 3.3e-11 (not controlled: between the
    two orders), acceleration 9.5e-9; h'' cannot be much better than ~1e-9 (Hermite interpolation
    of values rounded to eps r_b). At the knots the spline is exact: 4e-15."""
    law, cam, base, follower, lift = _round_trip(law_name, follower_name)
    omega = 2.5
    r = rigid_contact(cam, follower, THETA, omega)
    assert np.abs(r.q - base - law.s(THETA)).max() <= 2e-12 * lift
    assert np.abs(r.q_dot / omega - law.s(THETA, 1)).max() <= 1e-10 * lift
    assert np.abs(r.q_ddot / omega ** 2 - law.s(THETA, 2)).max() <= 3e-8 * lift
    knots = law.knots
    k = rigid_contact(cam, follower, knots, omega)
    assert np.abs(k.q - base - law.s(knots)).max() <= 16 * EPS * max(base, lift)
    assert np.abs(k.q_ddot / omega ** 2 - law.s(knots, 2)).max() <= 1e-14 * lift / RDR[0] ** 2 * 1e2


def test_translating_cam_is_the_lift_itself():
    """h(phi) = r_b + s(gamma - phi) at any phi (not only at the breakpoints), and a 3-4-5 law, a
    quintic, is reproduced by as few pieces as it has segments (the Hermite data fix a quintic)."""
    follower, lift, r_b = FOLLOWERS["translating-gamma"]
    law = rise_dwell_return(lift, RDR, "polynomial-345")
    cam = cam_from_law(law, follower, r_b)
    assert cam.breaks.size - 1 == 4
    assert np.abs(cam.h(PHI) - (r_b + law.s(follower.gamma - PHI))).max() <= 16 * EPS * (r_b + lift)


def test_pieces_per_segment_given():
    law = rise_dwell_return(0.01, RDR, "modified-trapezoid")
    cam = cam_from_law(law, TranslatingFollower(), 0.02, pieces_per_segment=3)
    assert cam.breaks.size - 1 == 3 * (law.knots.size - 1)
    with pytest.raises(ParameterError, match="pieces_per_segment"):
        cam_from_law(law, TranslatingFollower(), 0.02, pieces_per_segment=0)


# --- refusals --------------------------------------------------------------------------------------------

def test_non_convex_spline_refused_naming_angle_and_rho():
    """h = 1 + 0.2 cos(3 phi): rho = 1 - 1.6 cos(3 phi), smallest -0.6 at 0, 120, 240 deg."""
    phi = np.linspace(0, TWO_PI, 61)
    h = [1 + 0.2 * np.cos(3 * phi), -0.6 * np.sin(3 * phi), -1.8 * np.cos(3 * phi)]
    with pytest.raises(ParameterError) as info:
        SplineProfile.hermite(phi, *h)
    message = str(info.value)
    assert "not convex" in message and "rho = -0.6 m" in message, message
    assert any(f"phi = {a:.4f} deg" in message for a in (0.0, 120.0, 240.0)), message


@pytest.mark.parametrize("follower_name", ["translating", "oscillating"])
def test_undercut_law_refused_with_the_smallest_base_circle(follower_name):
    """A steep cycloidal rise on a small base circle: refused, the message giving the smallest base
    radius X; X (1 + 1e-6) makes a convex cam, X (1 - 1e-6) does not (the margin: the spline's
    curvature is within 1e-8 of the lift of the law's, far inside 1e-6 X)."""
    follower, lift, _ = FOLLOWERS[follower_name]
    law = rise_dwell_return(lift, RDR, "cycloidal")
    small = 0.01 if follower_name == "translating" else 0.015
    with pytest.raises(ParameterError) as info:
        cam_from_law(law, follower, small)
    X = smallest_base_radius(law, follower)
    assert info.value.name == "r_b" and f"> {X!r} m, the smallest base circle radius" in str(info.value)
    assert X > small
    cam = cam_from_law(law, follower, X * (1 + 1e-6))
    assert cam.radius_of_curvature(np.linspace(0, TWO_PI, 100001)).min() > 0
    with pytest.raises(ParameterError, match="undercuts"):
        cam_from_law(law, follower, X * (1 - 1e-6))
    if follower_name == "translating":            # the closed form: r_b > max(-(s + s'')), on a fine grid
        fine = np.linspace(0, TWO_PI, 2_000_001)
        assert X == pytest.approx((-(law.s(fine) + law.s(fine, 2))).max(), rel=1e-9)


def test_oscillating_law_that_turns_back_refused():
    """A return of 1 rad over 30 deg: s' = -3.8 somewhere, 1 + s' < 0, phi(theta) not monotone."""
    law = rise_dwell_return(1.0, np.radians([200, 100, 30, 30]))
    with pytest.raises(ParameterError, match="not a valid flat-faced cam"):
        cam_from_law(law, FOLLOWERS["oscillating"][0], 0.03)


# --- tables ----------------------------------------------------------------------------------------------

def _write(tmp_path, name, text):
    path = tmp_path / name
    path.write_text(text)
    return path


def _lift_csv(law, degrees, scale=1e3, unit="lift_mm"):
    return f"# cam angle, lift\ntheta_deg, {unit}\n" + "".join(f"{float(d)!r}, {float(scale * law.s(math.radians(d)))!r}\n"
                                                                for d in degrees)


def test_lift_table_translating_round_trip(tmp_path):
    """A CSV of lifts (mm) of a cycloidal law every 5 deg: the cam reproduces the table's spline
    (its pieces are quintics: exact to rounding, 1e-12 of the lift) and the law itself to the
    spline's interpolation error (measured 1.5e-5 of the lift at 5 deg, largest at the segment ends
    where s''' jumps; asserted 3e-5)."""
    law = rise_dwell_return(0.01, RDR)
    path = _write(tmp_path, "cam.csv", _lift_csv(law, np.arange(0, 360, 5.0)))
    table = read_cam_table(path)
    assert isinstance(table, LiftTable) and table.kind == "length"
    follower = TranslatingFollower()
    cam = cam_from_table(path, follower, 0.02)
    r = rigid_contact(cam, follower, THETA)
    assert np.abs(r.q - 0.02 - table.s(THETA)).max() <= 1e-12 * 0.01
    assert np.abs(r.q_ddot - table.s(THETA, 2)).max() <= 1e-12 * 0.01 * 100   # s'' ~ 100x the lift per rad^2
    assert np.abs(r.q - 0.02 - law.s(THETA)).max() <= 3e-5 * 0.01
    rows = np.radians(np.arange(0, 360, 5.0))
    assert np.abs(table.s(rows) - law.s(rows)).max() <= 1e-15             # through the rows: mm -> m rounding


def test_lift_table_toml_oscillating(tmp_path):
    """A TOML table of lifts in degrees on the oscillating follower: round trip against the table's
    spline (same tolerances as the law's round trip)."""
    law = rise_dwell_return(0.1, RDR)
    deg = np.arange(0.0, 360.0, 4.0)
    lifts = [float(math.degrees(law.s(math.radians(d)))) for d in deg]
    path = _write(tmp_path, "cam.toml", f"name = 'test'\ntheta_deg = {deg.tolist()}\nlift_deg = {lifts}\n")
    follower = OscillatingFollower(EXAMPLE_P_TO_E, EXAMPLE_W_B)
    cam = cam_from_table(path, follower, 0.03)
    table = read_cam_table(path)
    r = rigid_contact(cam, follower, THETA)
    assert np.abs(r.q - follower.base_angle(0.03) - table.s(THETA)).max() <= 2e-12 * 0.1
    assert np.abs(r.q_ddot - table.s(THETA, 2)).max() <= 3e-8 * 0.1


def test_radius_table(tmp_path):
    """A table of radii of the eccentric circle every 5 deg: the spline profile interpolates the rows
    exactly (rounding of mm -> m) and the circle to the quintic spline's error (measured 7e-14 m)."""
    deg = np.arange(0.0, 360.0, 5.0)
    h = 25.0 - 2.5 * np.cos(np.radians(deg))
    path = _write(tmp_path, "radii.csv", "phi_deg,h_mm\n" + "".join(f"{float(d)!r},{float(v)!r}\n" for d, v in zip(deg, h)))
    assert isinstance(read_cam_table(path), RadiusTable)
    cam = cam_from_table(path)
    assert np.abs(cam.h(np.radians(deg)) - h * 1e-3).max() <= 4 * EPS * 0.025
    assert np.abs(cam.h(PHI) - (0.025 - 0.0025 * np.cos(PHI))).max() <= 1e-12


@pytest.mark.parametrize("rows, problem", [
    ("theta_deg, lift_mm\n" + "".join(f"{d}, {d / 100}\n" for d in range(0, 361, 10)), "not periodic"),
    ("theta_deg, lift_mm\n" + "".join(f"{d}, 1.0\n" for d in range(0, 360, 360 // (MIN_ROWS - 1) + 1)), "too coarse"),
    ("theta_deg, lift_mm\n" + "".join(f"{d}, 1.0\n" for d in [0, 10, 20, 15] + list(range(30, 360, 10))), "not increasing"),
    ("theta_deg, lift_mm\n" + "".join(f"{d}, 1.0\n" for d in range(0, 400, 10)), "spans"),
    ("theta, lift\n" + "".join(f"{d}, 1.0\n" for d in range(0, 360, 10)), "columns"),
    ("theta_deg, lift_mm\n0, 1.0\n10, abc\n", "'abc' in row 3"),
])
def test_bad_tables_refused(tmp_path, rows, problem):
    path = _write(tmp_path, "bad.csv", rows)
    with pytest.raises(ParameterError, match=problem):
        cam_from_table(path, TranslatingFollower(), 0.02)


def test_table_and_follower_must_agree(tmp_path):
    law = rise_dwell_return(0.01, RDR)
    path = _write(tmp_path, "cam.csv", _lift_csv(law, np.arange(0, 360, 5.0)))
    with pytest.raises(ParameterError, match="does not go with lifts that are lengths"):
        cam_from_table(path, OscillatingFollower(EXAMPLE_P_TO_E, EXAMPLE_W_B), 0.03)
