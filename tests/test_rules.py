"""The hybrid rules (camdyn.engine.rules), run in Python on toy problems whose surfaces are
given functions of the state: crossings and their direction, far-side roots, the order of
transitions, micro-hops, rounding noise at a restart, targets, chatter."""
import math

import numpy as np
import pytest

from camdyn.engine import rules
from camdyn.engine.config import EventSettings
from camdyn.errors import ParameterError
from toy import clock_problem, clock_step, module, settings
from camdyn.engine.problem import Kernels, Problem
from camdyn.engine.tables import tables


# --------------------------------------------------------------------------- crossed
@pytest.mark.parametrize(
    "g0, g1, direction, expected",
    [(-1.0, 1.0, +1, True), (-1.0, 0.0, +1, True),  # landing exactly on the surface counts
     (1.0, -1.0, +1, False), (-1.0, -0.5, +1, False), (1.0, -1.0, -1, True), (1.0, 0.0, -1, True),
     (-1.0, 1.0, -1, False), (1.0, 0.5, -1, False), (-1.0, 1.0, 0, True), (1.0, -1.0, 0, True),
     (1.0, 2.0, 0, False),
     # g0 == 0: the run restarted on the surface; never a crossing start
     (0.0, 1.0, +1, False), (0.0, -1.0, -1, False), (0.0, 1.0, 0, False), (0.0, -1.0, 0, False),
     (-0.0, 1.0, 0, False), (math.nan, 1.0, 0, False)])
def test_crossed_truth_table(g0, g1, direction, expected):
    assert rules.crossed(g0, g1, direction) is expected


# --------------------------------------------------------------------------- locate
def _locate(g, ta, tb, xtol=1e-14):
    """rules.locate on the clock (alpha = t over the step [ta, tb])."""
    prob = clock_problem([g], [None])
    y0, y1, _, _, Q = clock_step(ta, tb)
    return rules.locate(prob, 0, 0, ta, tb - ta, y0, y1, Q, ta, tb, g(ta), g(tb), xtol)


@pytest.mark.parametrize("sign", [+1, -1], ids=["down", "up"])
def test_locate_sin_near_pi(sign):
    g = lambda t: sign * math.sin(t)  # noqa: E731
    t, _ = _locate(g, 3.0, 3.3)
    assert abs(t - math.pi) <= 1e-14 * math.pi and 3.0 < t <= 3.3
    assert g(t) == 0 or np.sign(g(t)) == np.sign(g(3.3))  # far side


#: roots not exactly representable, on both sides of 1 in magnitude
_ROOTS = [0.3 + 0.1 * k / 7 for k in range(7)] + [1.0, 17.0 / 3.0, 1000.0 / 7.0]


@pytest.mark.parametrize("root", _ROOTS)
@pytest.mark.parametrize("sign", [+1, -1], ids=["up", "down"])
@pytest.mark.parametrize("shape", [pytest.param(lambda x: x**3, id="flat-cubic"),
                                   pytest.param(lambda x: math.tanh(1e9 * x), id="steep-tanh"),
                                   pytest.param(lambda x: 1e15 * x, id="steep-linear"),
                                   pytest.param(lambda x: math.expm1(x), id="smooth")])
def test_locate_far_side_and_accuracy(shape, sign, root):
    """Within xtol max(1, |t|) of the root (the interpolant is the clock: the located time is
    the time where g changes sign, in doubles), on the far side of the surface."""
    g = lambda t: sign * shape(t - root)  # noqa: E731
    ta, tb = root - 0.37, root + 0.61
    t, _ = _locate(g, ta, tb)
    assert abs(t - root) <= 1e-14 * max(1.0, abs(t)) + 2 * np.spacing(root)
    assert np.sign(g(t)) != np.sign(g(ta))


def test_locate_returns_tb_when_gb_is_zero_without_evaluating():
    calls = []

    def g(t):
        calls.append(t)
        return t - 2.0
    prob = clock_problem([g], [None])
    y0, y1, _, _, Q = clock_step(0.0, 1.0)
    assert rules.locate(prob, 0, 0, 0.0, 1.0, y0, y1, Q, 0.0, 1.0, -2.0, 0.0, 1e-14) == (1.0, 0)
    assert calls == []


@pytest.mark.parametrize("cubic, most", [((1e-2, 0.5e-2, 0.3e-2), 10), ((3e-2, -2e-2, 1e-2), 10),
                                          ((0.0, 0.0, 1.0), 20)])
def test_root_is_located_superlinearly_on_the_far_side(cubic, most):
    """The gap alpha(theta) = -1e-6 + h theta (q0 + q1 theta + q2 theta^2) on a step of
    h = 1e-4 s: the root within xtol = 1e-14 s of the one 200 bisections find, on the far side,
    in few evaluations, where bisection alone needs log2(1e-4 / 1e-14) = 33.  Simple roots:
    <= 10 (8 measured); a strongly curved gap (theta^3, where false position is slowest): <= 20
    (16 measured)."""
    h, y0 = 1e-4, -1e-6
    Q = np.zeros((2, 7))
    Q[0, :3] = cubic

    def gap(theta):
        return y0 + h * theta * (cubic[0] + cubic[1] * theta + cubic[2] * theta ** 2)
    prob = clock_problem([lambda a: a], [None])
    t, evaluations = rules.locate(prob, 0, 0, 0.0, h, y0, 0.0, Q, 0.0, h, y0, gap(1.0), 1e-14)
    lo, hi = 0.0, 1.0
    for _ in range(200):
        lo, hi = (0.5 * (lo + hi), hi) if gap(0.5 * (lo + hi)) < 0 else (lo, 0.5 * (lo + hi))
    assert gap(t / h) >= 0.0
    assert abs(t - hi * h) <= 1e-14
    assert evaluations <= most


# --------------------------------------------------------------------------- first_crossing
def _scan(functions, directions, interior=3, t0=0.0, t1=1.0, rates=None, scale=1.0):
    prob = clock_problem(functions, directions, rates)
    y0, y1, n0, n1, Q = clock_step(t0, t1, scale)
    work = rules.scratch(8, 8)
    return rules.first_crossing(prob, 0, t0, t1, y0, y1, n0, n1, Q, settings(interior), False, work)


def _hop(a):
    """A micro-hop: g > 0 at both step ends, g < 0 only for 0.49 < t < 0.51."""
    return (a - 0.5) ** 2 - 1e-4


def test_micro_hop_caught_by_an_interior_sample_and_missed_without():
    w, t = _scan([_hop], [-1], interior=3)  # samples 0.25, 0.5, 0.75: 0.5 is inside the dip
    assert w == 0 and abs(t - 0.49) <= 1e-14
    assert _scan([_hop], [-1], interior=0)[0] == -1


def test_micro_hop_direction_selects_which_crossing():
    w, t = _scan([_hop], [+1])
    assert abs(t - 0.51) <= 1e-14 and _hop(t) >= 0
    assert abs(_scan([_hop], [0])[1] - 0.49) <= 1e-14


@pytest.mark.parametrize("order", [(0.7, 0.3), (0.3, 0.7)])
def test_earliest_crossing_wins_regardless_of_order(order):
    w, t = _scan([lambda a, c=c: a - c for c in order], [+1, +1])
    assert w == order.index(0.3) and abs(t - 0.3) <= 1e-14


def test_two_crossings_between_the_same_samples_earliest_wins():
    w, _ = _scan([lambda a: a - 0.45, lambda a: a - 0.3], [+1, +1])
    assert w == 1


def test_tie_goes_to_the_transition_listed_first():
    assert _scan([lambda a: a - 0.3, lambda a: a - 0.3], [+1, +1])[0] == 0


def test_earliest_subinterval_of_a_surface_is_used():
    # sin(6 pi t) crosses downward at 1/6, 1/2 and 5/6; samples every 0.1 bracket each
    w, t = _scan([lambda a: math.sin(6 * math.pi * a)], [-1], interior=9)
    assert abs(t - 1 / 6) <= 1e-14


def test_direction_filtering():
    rising = lambda a: a - 0.5  # noqa: E731
    assert _scan([rising], [-1])[0] == -1
    assert _scan([rising], [+1])[1] == pytest.approx(0.5, abs=1e-14)
    assert _scan([rising], [0])[1] == pytest.approx(0.5, abs=1e-14)


def test_crossing_exactly_at_the_step_end_uses_the_step_state():
    """The interpolant is slightly off at t1 (g < 0 there) but the step's own end state lies
    exactly on the surface: the crossing at t1 is reported."""
    w, t = _scan([lambda a: a - 1.0], [+1], scale=1 - 1e-9)
    assert w == 0 and t == 1.0


def test_restart_on_the_surface_does_not_retrigger():
    # g(t0) == 0 on the new side, as after an impact: no crossing in this step
    assert _scan([lambda a: a], [+1])[0] == -1
    assert _scan([lambda a: a], [0])[0] == -1


def test_quiet_step_and_nonfinite_value():
    assert _scan([lambda a: a - 5.0], [0])[0] == -1
    assert _scan([lambda a: math.nan if a > 0.4 else 1.0], [0])[0] == rules.NONFINITE


def test_located_time_on_a_later_interval():
    w, t = _scan([lambda a: math.sin(a - 7.0)], [-1], t0=10.0, t1=10.5)
    assert abs(t - (7.0 + math.pi)) <= 1e-14 * t and math.sin(t - 7.0) <= 0


def test_rate_finds_an_excursion_between_samples():
    """A hop narrower than the sample spacing: g = 1e-6 - (t - 0.3)^2 is positive only on
    (0.299, 0.301), between samples at 0.25 and 0.5.  Without the rate it is invisible; with
    dg/dt declared (RATE_OF_SURFACE) the maximum is located and the up-crossing found at 0.299."""
    g = lambda a: 1e-6 - (a - 0.3) ** 2  # noqa: E731
    rate = lambda a: -2 * (a - 0.3)  # noqa: E731
    assert _scan([g, rate], [+1, None])[0] == -1
    w, t = _scan([g, rate], [+1, None], rates={0: 1})
    assert w == 0 and t == pytest.approx(0.299, abs=1e-12) and g(t) >= 0
    low = lambda a: -1e-6 - (a - 0.3) ** 2  # noqa: E731  (a maximum below the surface)
    assert _scan([low, rate], [+1, None], rates={0: 1})[0] == -1


def test_rate_tells_rounding_noise_at_a_restart_from_a_crossing():
    """A restart just across the surface (g = 3e-19 > 0, watched downward) while moving away
    (rate > 0): rounding flips g's sign right after the restart.  Without the rate the flip is
    a crossing; with it, a sign change while moving away with no turn is noise, and when the
    motion does turn back, the crossing found is the one after the turn."""
    ends = lambda a: 3e-19 if a == 0.0 else -1e-19  # noqa: E731  (noise at both samples)
    away = lambda a: 1.0  # noqa: E731
    assert _scan([ends, away], [-1, None], interior=0)[0] == 0
    assert _scan([ends, away], [-1, None], interior=0, rates={0: 1})[0] == -1
    hop = lambda a: 3e-19 if a == 0.0 else (-1e-19 if a < 1e-12 else a * (1 - 1e-9 - a))  # noqa: E731
    rate = lambda a: 1 - 1e-9 - 2 * a  # noqa: E731
    w, t = _scan([hop, rate], [-1, None], interior=0, rates={0: 1})
    assert w == 0 and t == pytest.approx(1 - 1e-9, abs=1e-13)


# --------------------------------------------------------------------------- reach
def _clear(functions, directions, rates=None, factor=2.0):
    """rules.clear_of_surfaces over the clock step [0, 1] (alpha = t, alpha_dot = 1, alpha_ddot
    = 0), after the step [-1, 0] as the loop runs it (the first after a start: never clear,
    then first_crossing, which must find no crossing there): (clear, work)."""
    prob = clock_problem(functions, directions, rates)
    cfg, work = settings(reach_factor=factor), rules.scratch(8, 8)
    y0, y1, n0, n1, Q = clock_step(-1.0, 0.0)
    assert not rules.clear_of_surfaces(prob, 0, -1.0, 0.0, n0, n1, 0.0, cfg, False, work)
    assert rules.first_crossing(prob, 0, -1.0, 0.0, y0, y1, n0, n1, Q, cfg, False, work)[0] in (-1, rules.NONFINITE)
    y0, y1, n0, n1, _ = clock_step(0.0, 1.0)
    return rules.clear_of_surfaces(prob, 0, 0.0, 1.0, n0, n1, 0.0, cfg, True, work), work


@pytest.mark.parametrize("g, rate, clear", [
    (lambda a: a + 2.5, lambda a: 1.0, True),     # |g| >= 2.5 > 2 |rate| h = 2 at both ends
    (lambda a: a + 1.5, lambda a: 1.0, False),    # 1.5 < 2: within reach (though it never crosses)
    (lambda a: -3 * a - 6.5, lambda a: -3.0, True),   # 6.5 and 9.5 > 2 * 3 * 1 = 6
    (lambda a: (a - 0.5) ** 2 - 1e-4, lambda a: 2 * (a - 0.5), False),   # the micro-hop: |g| 0.25 < 2 at the ends
    (lambda a: math.nan, lambda a: 1.0, False),
], ids=["far", "near", "far-steep", "hop", "nan"])
def test_a_step_is_cleared_only_where_every_surface_is_out_of_reach(g, rate, clear):
    """The reach rule (rules, *Reach*) with factor 2, on a surface with a declared rate."""
    assert _clear([g, rate], [+1, None], rates={0: 1})[0] is clear


def test_without_a_declared_rate_the_rate_along_the_motion_is_used():
    """g = 3 alpha + c has no declared rate: its rate along the motion (3, by a forward
    difference along the field) decides, so c = 6.5 is clear (6.5 > 2 * 3 * 1) and c = 5.5 not."""
    assert _clear([lambda a: 3 * a + 6.5], [-1])[0] is True
    assert _clear([lambda a: 3 * a + 5.5], [-1])[0] is False
    prob = clock_problem([lambda a: 3 * a + 1.0], [None])
    assert rules.rate_along_motion(prob, 0, 0, 2.0, 2.0, 1.0, 0.0, 7.0, 0.1) == pytest.approx(3.0, rel=1e-8)


def test_a_cleared_step_leaves_the_values_first_crossing_would():
    """After a clear step, work's G_PREV and R_PREV hold the values at its end, as
    first_crossing leaves them after a step without crossing; M_PREV the rates there."""
    fs = [lambda a: a + 5.0, lambda a: 1.0 + 0 * a, lambda a: -2 * a - 9.0]
    clear, work = _clear(fs, [+1, None, -1], rates={0: 1})
    assert clear
    prob = clock_problem(fs, [+1, None, -1], {0: 1})
    y0, y1, n0, n1, Q = clock_step(0.0, 1.0)
    ref = rules.scratch(8, 8)
    assert rules.first_crossing(prob, 0, 0.0, 1.0, y0, y1, n0, n1, Q, settings(), False, ref)[0] == -1
    assert rules.clear_of_surfaces(prob, 0, 0.0, 1.0, n0, n1, 0.0, settings(), False, ref) is False  # no start
    np.testing.assert_array_equal(work[[rules.G_PREV, rules.R_PREV], :2], ref[[rules.G_PREV, rules.R_PREV], :2])
    np.testing.assert_allclose(work[rules.M_PREV, :2], [1.0, -2.0], rtol=1e-8)


def test_an_excursion_out_of_reach_is_not_searched():
    """A maximum of g far below the surface (-10 at t = 0.3, rate turning between samples):
    with the reach rule the extremum is not located (no surface evaluations beyond the
    samples'); with reach_factor inf it is, and the verdict is the same: no crossing."""
    calls = []
    g = lambda a: calls.append(a) or -10.0 - (a - 0.3) ** 2  # noqa: E731
    rate = lambda a: -2 * (a - 0.3)  # noqa: E731
    prob = clock_problem([g, rate], [+1, None], {0: 1})
    y0, y1, n0, n1, Q = clock_step(0.0, 1.0)
    verdicts = []
    for factor in (2.0, math.inf):
        calls.clear()
        verdicts.append(rules.first_crossing(prob, 0, 0.0, 1.0, y0, y1, n0, n1, Q, settings(reach_factor=factor),
                                             False, rules.scratch(8, 8))[0])
        verdicts.append(len(calls))
    assert verdicts[0] == verdicts[2] == -1
    assert verdicts[1] == 5 < verdicts[3]    # the 5 samples; the search adds evaluations


# --------------------------------------------------------------------------- targets
def _choice(g_values, candidates):
    """rules.target over one transition whose candidates test the given surface values
    (each a function of alpha; mode-independent)."""
    mod = module([f"g{k}" for k in range(len(g_values))], [(0, 0, -1, candidates)], ((0, ()),), n_modes=4)
    kern = Kernels(None, lambda m, s, t, a, ad, p: g_values[s](a), None, None)
    return Problem(kern, tables(mod), np.zeros(1))


def test_target_is_the_first_candidate_whose_conditions_hold():
    candidates = ((1, ((0, -1), (1, +1))), (2, ((0, -1),)), (3, ()))
    prob = _choice([lambda a: -1.0, lambda a: 2.0], candidates)
    assert rules.target(prob, 0, 0.0, 0.0, 0.0, 1e-9) == 1
    prob = _choice([lambda a: -1.0, lambda a: -2.0], candidates)
    assert rules.target(prob, 0, 0.0, 0.0, 0.0, 1e-9) == 2
    prob = _choice([lambda a: 1.0, lambda a: 2.0], candidates)
    assert rules.target(prob, 0, 0.0, 0.0, 0.0, 1e-9) == 3


def test_target_on_a_surface_looks_ahead_along_the_motion():
    """Exactly 0 at the state: the value a moment later (alpha moved by alpha_dot) decides."""
    candidates = ((1, ((0, -1),)), (2, ()))
    prob = _choice([lambda a: a], candidates)
    assert rules.target(prob, 0, 0.0, 0.0, -1.0, 1e-9) == 1   # heading below
    assert rules.target(prob, 0, 0.0, 0.0, +1.0, 1e-9) == 2   # heading above
    assert rules.target(prob, 0, 0.0, 0.0, 0.0, 1e-9) == 1    # at rest on it: the condition holds at 0


def test_chatter_is_many_switches_with_no_progress():
    times = np.array([1.0] * 21)
    assert rules.chattering(times, 21, 1e-9, 20)
    assert not rules.chattering(times, 20, 1e-9, 20)
    assert not rules.chattering(np.linspace(0, 1, 30), 30, 1e-9, 20)


# --------------------------------------------------------------------------- settings
@pytest.mark.parametrize("kwargs, field", [({"xtol": 0.0}, "xtol"), ({"xtol": -1e-10}, "xtol"),
                                           ({"xtol": 1e-17}, "xtol"), ({"xtol": 1.0}, "xtol"),
                                           ({"xtol": math.nan}, "xtol"), ({"interior_points": -1}, "interior_points"),
                                           ({"interior_points": 2.5}, "interior_points"),
                                           ({"max_events": 0}, "max_events"), ({"max_events": 1e6}, "max_events"),
                                           ({"reach_factor": 0.5}, "reach_factor"),
                                           ({"reach_factor": math.nan}, "reach_factor"),
                                           ({"reach_factor": True}, "reach_factor")])
def test_event_settings_validated(kwargs, field):
    with pytest.raises(ParameterError, match=field):
        EventSettings(**kwargs)


def test_event_settings_defaults():
    s = EventSettings()
    assert (s.xtol, s.interior_points, s.max_events, s.reach_factor) == (1e-14, 3, 1_000_000, 2.0)
    EventSettings(xtol=1e-6, interior_points=0, max_events=1, reach_factor=math.inf)
