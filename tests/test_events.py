"""Tests of camdyn.events: crossing logic, far-side root location, step scan."""
import math

import numpy as np
import pytest

from camdyn.events import Crossing, Event, EventSettings, crossed, first_crossing, locate


# --------------------------------------------------------------------------- crossed
@pytest.mark.parametrize(
    "g0, g1, direction, expected",
    [
        (-1.0, 1.0, +1, True),
        (-1.0, 0.0, +1, True),  # landing exactly on the surface counts
        (1.0, -1.0, +1, False),
        (-1.0, -0.5, +1, False),
        (1.0, -1.0, -1, True),
        (1.0, 0.0, -1, True),
        (-1.0, 1.0, -1, False),
        (1.0, 0.5, -1, False),
        (-1.0, 1.0, 0, True),
        (1.0, -1.0, 0, True),
        (1.0, 2.0, 0, False),
        # g0 == 0: the integrator restarted on the surface; never a crossing start
        (0.0, 1.0, +1, False),
        (0.0, -1.0, -1, False),
        (0.0, 1.0, 0, False),
        (0.0, -1.0, 0, False),
        (-0.0, 1.0, 0, False),
        (math.nan, 1.0, 0, False),
    ],
)
def test_crossed_truth_table(g0, g1, direction, expected):
    assert crossed(g0, g1, direction) is expected


# --------------------------------------------------------------------------- locate
def _far_side(g, t, gb):
    return g(t) == 0 or np.sign(g(t)) == np.sign(gb)


@pytest.mark.parametrize("sign", [+1, -1], ids=["down", "up"])
def test_locate_sin_near_pi(sign):
    def g(t):
        return sign * math.sin(t)  # sign=+1: g>0 before pi, crosses downward

    ta, tb = 3.0, 3.3
    t = locate(g, ta, tb, g(ta), g(tb), 1e-14)
    assert abs(t - math.pi) <= 1e-14 * math.pi
    assert ta < t <= tb
    assert _far_side(g, t, g(tb))


# Roots that are not exactly representable, on both sides of 1 in magnitude,
# with a flat (triple) root and a steep one, in both directions. The number of
# cases makes both code paths (brentq ending on the near and on the far side)
# certain to run; each case checks the far-side guarantee.
_ROOTS = [0.3 + 0.1 * k / 7 for k in range(7)] + [1.0, 17.0 / 3.0, 1000.0 / 7.0]


@pytest.mark.parametrize("root", _ROOTS)
@pytest.mark.parametrize("sign", [+1, -1], ids=["up", "down"])
@pytest.mark.parametrize(
    "shape",
    [
        pytest.param(lambda x: x**3, id="flat-cubic"),
        pytest.param(lambda x: math.tanh(1e9 * x), id="steep-tanh"),
        pytest.param(lambda x: 1e15 * x, id="steep-linear"),
        pytest.param(lambda x: math.expm1(x), id="smooth"),
    ],
)
def test_locate_far_side_and_accuracy(shape, sign, root):
    def g(t):
        return sign * shape(t - root)

    ta, tb = root - 0.37, root + 0.61
    t = locate(g, ta, tb, g(ta), g(tb), 1e-14)
    assert abs(t - root) <= 1e-14 * max(1.0, abs(t))
    assert _far_side(g, t, g(tb))
    assert np.sign(g(t)) != np.sign(g(ta))


def test_locate_flat_cubic_at_one():
    def g(t):
        return (t - 1.0) ** 3

    t = locate(g, 0.0, 1.7, g(0.0), g(1.7), 1e-14)
    assert abs(t - 1.0) <= 1e-14
    assert g(t) >= 0


def test_locate_uses_given_end_values_and_returns_tb_when_gb_zero():
    calls = []

    def g(t):
        calls.append(t)
        return t - 2.0  # would say g(tb) = -1, but the caller's exact gb is 0

    assert locate(g, 0.0, 1.0, -2.0, 0.0, 1e-14) == 1.0
    assert calls == []


@pytest.mark.parametrize("ga, gb", [(1.0, 2.0), (-1.0, -2.0), (0.0, 1.0), (0.0, 0.0)])
def test_locate_rejects_unbracketed(ga, gb):
    with pytest.raises(ValueError, match="ga"):
        locate(lambda t: t, 0.0, 1.0, ga, gb, 1e-14)


# --------------------------------------------------------------------------- first_crossing
def _clock(t):
    """Dense output of y' = 1, y(0) = 0: the state is the time itself."""
    return np.array([t])


def _scan(events, settings=EventSettings(), t0=0.0, t1=1.0, dense=_clock):
    return first_crossing(events, dense, t0, t1, dense(t0), dense(t1), settings)


def _hop(y):
    """Micro-hop: g > 0 at both step ends, g < 0 only for 0.49 < t < 0.51."""
    return (y[0] - 0.5) ** 2 - 1e-4


def test_micro_hop_caught_by_interior_sample():
    # The interior samples 0.25, 0.5, 0.75 include 0.5, inside the dip.
    hit = _scan([Event("hop", lambda t, y: _hop(y), -1)], EventSettings(interior_points=3))
    assert isinstance(hit, Crossing)
    assert hit.index == 0 and hit.event.name == "hop"
    assert abs(hit.t - 0.49) <= 1e-14
    assert _hop(hit.y) <= 0  # far side: already in contact-lost state
    np.testing.assert_array_equal(hit.y, _clock(hit.t))


def test_micro_hop_missed_without_interior_samples():
    # Only the ends are sampled and g > 0 at both: the double crossing within
    # one step is invisible. This is why interior_points defaults to > 0.
    assert _scan([Event("hop", lambda t, y: _hop(y), -1)], EventSettings(interior_points=0)) is None


def test_micro_hop_direction_selects_which_crossing():
    up = _scan([Event("hop", lambda t, y: _hop(y), +1)])
    both = _scan([Event("hop", lambda t, y: _hop(y), 0)])
    assert abs(up.t - 0.51) <= 1e-14 and _hop(up.y) >= 0
    assert abs(both.t - 0.49) <= 1e-14


@pytest.mark.parametrize("order", [(0.7, 0.3), (0.3, 0.7)])
def test_earliest_event_wins_regardless_of_index(order):
    late_or_early = [Event(f"at{c}", lambda t, y, c=c: y[0] - c, +1) for c in order]
    hit = _scan(late_or_early)
    assert hit.index == order.index(0.3)
    assert abs(hit.t - 0.3) <= 1e-14


def test_two_events_in_same_subinterval_earliest_wins():
    # Both crossings lie between the same two samples (0.25, 0.5).
    events = [Event("b", lambda t, y: y[0] - 0.45, +1), Event("a", lambda t, y: y[0] - 0.3, +1)]
    hit = _scan(events)
    assert hit.event.name == "a" and hit.index == 1


def test_tie_goes_to_lowest_index():
    events = [Event(name, lambda t, y: y[0] - 0.3, +1) for name in ("first", "second")]
    assert _scan(events).index == 0


def test_earliest_subinterval_of_an_event_is_used():
    # sin(6*pi*t) crosses downward at 1/6, 1/2 and 5/6 within the step;
    # samples every 0.1 bracket each of them separately.
    hit = _scan([Event("osc", lambda t, y: math.sin(6 * math.pi * y[0]), -1)],
                EventSettings(interior_points=9))
    assert abs(hit.t - 1 / 6) <= 1e-14


def test_direction_filtering():
    rising = lambda t, y: y[0] - 0.5  # noqa: E731
    assert _scan([Event("r", rising, -1)]) is None
    assert _scan([Event("r", rising, +1)]).t == pytest.approx(0.5, abs=1e-14)
    assert _scan([Event("r", rising, 0)]).t == pytest.approx(0.5, abs=1e-14)


def test_crossing_exactly_at_step_end():
    hit = _scan([Event("end", lambda t, y: y[0] - 1.0, +1)])
    assert hit is not None and hit.t == 1.0
    np.testing.assert_array_equal(hit.y, [1.0])


def test_restart_on_surface_does_not_retrigger():
    # g(t0) == 0 on the new side, as after an impact: no event in this step.
    assert _scan([Event("s", lambda t, y: y[0], +1)]) is None
    assert _scan([Event("s", lambda t, y: y[0], 0)]) is None


def test_step_end_values_come_from_y0_y1_not_dense():
    # The interpolant is slightly off at t1 (g < 0 there) but the step's own
    # y1 lies exactly on the surface: the crossing at t1 must be reported,
    # with y equal to y1 itself.
    def dense(t):
        return np.array([t * (1 - 1e-9)])

    y1 = np.array([1.0])
    hit = first_crossing([Event("e", lambda t, y: y[0] - 1.0, +1)], dense, 0.0, 1.0,
                         np.array([0.0]), y1, EventSettings())
    assert hit is not None and hit.t == 1.0
    np.testing.assert_array_equal(hit.y, y1)


def test_no_events_and_quiet_step():
    assert _scan([]) is None
    assert _scan([Event("far", lambda t, y: y[0] - 5.0, 0)]) is None


def test_nonfinite_g_raises():
    with pytest.raises(ValueError, match="'bad'"):
        _scan([Event("bad", lambda t, y: math.nan if t > 0.4 else 1.0, 0)])


def test_located_time_on_nontrivial_interval():
    t0, t1 = 10.0, 10.5
    hit = _scan([Event("s", lambda t, y: math.sin(y[0]), -1)], t0=t0, t1=t1,
                dense=lambda t: np.array([t - 7.0]))
    assert abs(hit.t - (7.0 + math.pi)) <= 1e-14 * hit.t
    assert math.sin(hit.y[0]) <= 0


# --------------------------------------------------------------------------- validation
@pytest.mark.parametrize("direction", [2, -2, 0.5, True])
def test_event_direction_validated(direction):
    with pytest.raises(ValueError, match=r"direction.*\{-1, 0, \+1\}"):
        Event("e", lambda t, y: 0.0, direction)


def test_event_fn_must_be_callable():
    with pytest.raises(TypeError, match="fn"):
        Event("e", 3.0)


def test_event_is_frozen():
    e = Event("e", lambda t, y: 0.0)
    with pytest.raises(AttributeError):
        e.direction = 1


@pytest.mark.parametrize(
    "kwargs, field",
    [
        ({"xtol": 0.0}, "xtol"),
        ({"xtol": -1e-10}, "xtol"),
        ({"xtol": 1e-17}, "xtol"),
        ({"xtol": 1.0}, "xtol"),
        ({"xtol": math.nan}, "xtol"),
        ({"interior_points": -1}, "interior_points"),
        ({"interior_points": 2.5}, "interior_points"),
        ({"max_events": 0}, "max_events"),
        ({"max_events": 1e6}, "max_events"),
    ],
)
def test_settings_validated(kwargs, field):
    with pytest.raises(ValueError, match=field) as info:
        EventSettings(**kwargs)
    assert repr(next(iter(kwargs.values()))) in str(info.value)


def test_settings_defaults_valid():
    s = EventSettings()
    assert (s.xtol, s.interior_points, s.max_events) == (1e-14, 3, 1_000_000)
    EventSettings(xtol=1e-6, interior_points=0, max_events=1)


def test_rate_finds_an_excursion_between_samples():
    """A hop narrower than the sample spacing: g = 1e-6 - (t - 0.3)^2 is positive only on
    (0.299, 0.301), between samples at 0.25 and 0.5 (interior_points=3).  Without the rate
    it is invisible; with dg/dt the maximum is located and the up-crossing found at 0.299."""
    from camdyn.events import Event, EventSettings, first_crossing

    def dense(t):
        return np.array([t])

    g = lambda t, y: 1e-6 - (y[0] - 0.3) ** 2  # noqa: E731
    rate = lambda t, y: -2 * (y[0] - 0.3)  # noqa: E731
    settings = EventSettings(interior_points=3)
    y0, y1 = np.array([0.0]), np.array([1.0])
    assert first_crossing((Event("gap", g, +1),), dense, 0.0, 1.0, y0, y1, settings) is None
    hit = first_crossing((Event("gap", g, +1, rate),), dense, 0.0, 1.0, y0, y1, settings)
    assert hit is not None and hit.t == pytest.approx(0.299, abs=1e-12) and g(hit.t, hit.y) >= 0
    # a maximum that stays below the surface is no crossing
    low = lambda t, y: -1e-6 - (y[0] - 0.3) ** 2  # noqa: E731
    assert first_crossing((Event("gap", low, +1, rate),), dense, 0.0, 1.0, y0, y1, settings) is None


def test_rate_tells_rounding_noise_at_a_restart_from_a_crossing():
    """A restart just across the surface (g = 3e-19 > 0, watched downward) while moving away
    (rate > 0): rounding flips g's sign right after the restart (found in a full test: a
    separation and re-impact 1.5e-14 s apart).  Without the rate the flip is a crossing; with
    it, a sign change while moving away with no turn is noise (None), and when the motion does
    turn back, the crossing found is the one after the turn."""
    settings = EventSettings(interior_points=0)
    y0, y1 = np.array([0.0]), np.array([1.0])
    noisy = lambda t, y: 3e-19 if y[0] == 0.0 else (-1e-19 if y[0] < 1e-12 else 1e-3 * y[0])  # noqa: E731
    away = lambda t, y: 1.0  # noqa: E731
    ends = lambda t, y: 3e-19 if y[0] == 0.0 else -1e-19  # noqa: E731  (noise at both samples)
    assert first_crossing((Event("gap", ends, -1),), _clock, 0.0, 1.0, y0, y1, settings) is not None
    assert first_crossing((Event("gap", ends, -1, away),), _clock, 0.0, 1.0, y0, y1, settings) is None
    assert first_crossing((Event("gap", noisy, -1, away),), _clock, 0.0, 1.0, y0, y1, settings) is None
    # a hop: up from the surface, turning at t = 0.5, back down through it at t = 1 - 1e-9
    hop = lambda t, y: 3e-19 if y[0] == 0.0 else (-1e-19 if y[0] < 1e-12 else y[0] * (1 - 1e-9 - y[0]))  # noqa: E731
    rate = lambda t, y: 1 - 1e-9 - 2 * y[0]  # noqa: E731
    hit = first_crossing((Event("gap", hop, -1, rate),), _clock, 0.0, 1.0, y0, y1, settings)
    assert hit is not None and hit.t == pytest.approx(1 - 1e-9, abs=1e-13)
