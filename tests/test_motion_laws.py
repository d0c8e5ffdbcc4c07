"""Follower motion laws (issue 27): camdyn.model.motion_laws against their defining properties and
against finite differences of themselves."""
from __future__ import annotations

import math

import numpy as np
import pytest

from camdyn.errors import ParameterError
from camdyn.model.motion_laws import LAWS, MotionLaw, Segment, normalized_law, rise_dwell_return

EPS = np.finfo(float).eps
ANGLES = np.radians([90.0, 60.0, 100.0, 110.0])      # rise, dwell, return, dwell
LIFT = 0.012

#: bounds of |S^(n)| on [0, 1], n = 3, 4, 5, from the closed forms: cycloidal (2 pi)^(n-1);
#: 3-4-5: S''' = 60 - 360 x + 360 x^2 (max 60), S'''' = 720 x - 360 (360), S^(5) = 720;
#: modified trapezoid: A w^(n-2), A = 4.888, w = 4 pi (its sine pieces)
BOUNDS = {
    "cycloidal": {n: (2 * math.pi) ** (n - 1) for n in (3, 4, 5)},
    "polynomial-345": {3: 60.0, 4: 360.0, 5: 720.0},
    "modified-trapezoid": {n: 4.8882 * (4 * math.pi) ** (n - 2) for n in (3, 4, 5)},
}


@pytest.mark.parametrize("law", LAWS)
def test_normalized_law_ends(law):
    """S(0) = 0, S(1) = 1 and S', S'' vanish at both ends (so s, s', s'' are continuous at
    every segment end). Tolerance: a few ulps of the largest term (modified trapezoid: S(1) sums
    five pieces' closed forms)."""
    ends = np.array([0.0, 1.0])
    assert np.allclose(normalized_law(law, ends, 0), [0, 1], rtol=0, atol=8 * EPS)
    for d in (1, 2):
        assert np.all(np.abs(normalized_law(law, ends, d)) <= 64 * EPS), (law, d)


def test_modified_trapezoid_constants():
    """The published constants of the modified trapezoid (Norton, Table 3-2): peak acceleration
    4.888, peak velocity 2.000 at x = 1/2, peak jerk 61.43. Three decimals as printed."""
    x = np.linspace(0, 1, 100001)
    assert normalized_law("modified-trapezoid", x, 2).max() == pytest.approx(4.888, abs=5e-4)
    assert normalized_law("modified-trapezoid", 0.5, 1) == pytest.approx(2.0, abs=1e-12)
    assert np.abs(normalized_law("modified-trapezoid", x, 3)).max() == pytest.approx(61.43, abs=5e-3)


@pytest.mark.parametrize("law", LAWS)
def test_rise_reaches_the_lift_and_returns(law):
    m = rise_dwell_return(LIFT, ANGLES, law)
    beta = ANGLES[0]
    # exact closed forms at the ends: s(0) = 0, s(beta) = L; rounding of L * S(1) only
    assert m.s(0.0) == 0.0
    assert m.s(beta) == pytest.approx(LIFT, rel=8 * EPS)
    assert m.s(ANGLES[:2].sum() + 0.3 * ANGLES[2]) < LIFT       # on the way back
    assert m.s(2 * math.pi - 1e-3) == 0.0 and m.lift == LIFT
    assert m.s(-1.0) == m.s(2 * math.pi - 1.0)                  # periodic


@pytest.mark.parametrize("law", LAWS)
@pytest.mark.parametrize("d", [0, 1, 2])
def test_continuous_at_segment_ends(law, d):
    """s^(d), d = 0, 1, 2, just before each segment end equals its value at the end: the change over
    delta is at most delta max|s^(d+1)| (the bound from BOUNDS, n = 3 for d = 2; s''' jumps)."""
    m = rise_dwell_return(LIFT, ANGLES, law)
    ends = m.starts[1:-1]
    delta = 1e-9
    # max|S'| <= 2, max|S''| <= 2 pi over the three laws (closed forms)
    step = {0: 2 * LIFT / min(ANGLES[0], ANGLES[2]), 1: 2 * math.pi * LIFT / min(ANGLES[0], ANGLES[2]) ** 2,
            2: BOUNDS[law][3] * LIFT / min(ANGLES[0], ANGLES[2]) ** 3}[d]
    jump = np.abs(m.s(ends - delta, d) - m.s(ends, d))
    assert np.all(jump <= delta * step + 16 * EPS * LIFT), (law, d, jump)


@pytest.mark.parametrize("law", LAWS)
@pytest.mark.parametrize("d", [1, 2, 3])
def test_derivatives_against_finite_differences(law, d):
    """s^(d) against the central difference of s^(d-1) with step h: truncation h^2/6 max|s^(d+2)|
    (the next-but-one derivative; BOUNDS) plus rounding: each s^(d-1) is rounded to ~ eps of its size,
    and the angle (up to 2 pi) to eps 2 pi, which moves s^(d-1) by eps 2 pi |s^(d)|; divided by
    2h, a factor 4 for the terms of the closed forms. Probes at least 2h from the knots (s''' jumps)."""
    m = rise_dwell_return(LIFT, ANGLES, law)
    theta = np.linspace(0, 2 * math.pi, 3001)
    h = 1e-5
    theta = theta[np.min(np.abs(theta[:, None] - m.knots[None, :]), axis=1) > 2 * h]
    fd = (m.s(theta + h, d - 1) - m.s(theta - h, d - 1)) / (2 * h)
    beta = min(ANGLES[0], ANGLES[2])
    bound_next = {1: BOUNDS[law][3], 2: BOUNDS[law][4], 3: BOUNDS[law][5]}[d] * LIFT / beta ** (d + 2)
    grid = np.linspace(0, 2 * math.pi, 3001)
    largest = np.abs(m.s(grid, d - 1)).max() + 2 * math.pi * np.abs(m.s(grid, d)).max()
    tolerance = h * h / 6 * bound_next + 4 * EPS * largest / h
    error = np.abs(fd - m.s(theta, d)).max()
    assert error <= tolerance, (law, d, error, tolerance)
    assert np.abs(m.s(theta, d)).max() > 100 * tolerance          # the comparison is not vacuous


def test_segments_of_a_general_law():
    """A law of segments: a rise in two steps with a dwell between, back in one."""
    third = 2 * math.pi / 3
    m = MotionLaw((Segment("cycloidal", third / 2, 0.004), Segment("dwell", third / 2),
                   Segment("polynomial-345", third / 2, 0.006), Segment("modified-trapezoid", third + third / 2, -0.01)))
    assert m.lift == pytest.approx(0.01, rel=4 * EPS)
    assert m.s(third) == pytest.approx(0.004, rel=4 * EPS)
    assert m.s(third * 1.5) == pytest.approx(0.01, rel=4 * EPS)
    assert m.knots.size == 5 + 4                         # 4 segment ends + 0, and the trapezoid's 4 breakpoints


@pytest.mark.parametrize("call, name", [
    (lambda: rise_dwell_return(0.0, ANGLES), "lift"),
    (lambda: rise_dwell_return(-0.01, ANGLES), "lift"),
    (lambda: rise_dwell_return(0.01, np.radians([90, -10, 100, 180])), "angles"),
    (lambda: rise_dwell_return(0.01, np.radians([90, 60, 100, 100])), "segments"),
    (lambda: rise_dwell_return(0.01, np.radians([0, 60, 100, 200])), "angles"),
    (lambda: rise_dwell_return(0.01, ANGLES, law="harmonic"), "law"),
    (lambda: rise_dwell_return(0.01, ANGLES[:3]), "angles"),
    (lambda: MotionLaw((Segment("cycloidal", math.pi, 0.01), Segment("cycloidal", math.pi, -0.02))), "segments"),
    (lambda: Segment("dwell", 1.0, 0.01), "rise"),
    (lambda: Segment("cycloidal", -1.0, 0.01), "angle"),
])
def test_bad_input_refused(call, name):
    with pytest.raises(ParameterError) as info:
        call()
    assert info.value.name == name, str(info.value)


def test_angle_sum_message():
    with pytest.raises(ParameterError, match=r"angles sum to 6\.10\d* rad \(350\.0\d* deg\): must be .*2 pi"):
        rise_dwell_return(0.01, np.radians([90, 60, 100, 100]))
