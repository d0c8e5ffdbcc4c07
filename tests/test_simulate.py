"""The SciPy reference backend: physics checks with bounds from tolerance and FFT resolution."""
from __future__ import annotations

import math

import numpy as np
import pytest

import camdyn
from camdyn.analysis import statics as analysis, signal
from registry import METHODS, RIG, SCENES, cam_for, rig_for, scene_from_slug

FRICTIONLESS = camdyn.Scene(damping="none", friction="none")


@pytest.fixture(scope="module")
def eq():
    return analysis.static_equilibrium(RIG)


def test_free_vibration_peak_is_the_jacobian_natural_frequency(eq):
    """Cam at rest, small push off equilibrium: the FFT peak of alpha equals vartheta/2pi
    (Eq. 23, misprint 4: |Im eig J| without the square root) within one FFT bin."""
    r = camdyn.simulate(RIG, FRICTIONLESS, speed_rpm=0, t_end=0.1, y0=(eq.alpha + 2e-7, 0.0),
                        sample_rate_Hz=50_000, rtol=1e-9, atol=1e-16)
    assert r.ok and not r.switches  # stays in contact: the push is below the static deflection
    f, amp = signal.spectrum(r.t, r.alpha)
    peak = signal.peak_frequency(f, amp)
    nf = analysis.natural_frequency(RIG, FRICTIONLESS)
    assert abs(peak - nf.Hz) < signal.frequency_resolution(r.t)
    # the printed |Im|^0.5 would be ~118 rad^0.5/s, nowhere near the peak
    assert abs(peak - math.sqrt(nf.damped_rad_s) / (2 * math.pi)) > 1000


@pytest.mark.parametrize("push", [2e-7, None], ids=["sliding", "bouncing"])
def test_undamped_frictionless_conserves_energy(eq, push):
    """No damping, no friction, cam at rest: E = T + V_s + V_c is constant, across impacts too.

    Bound: 1e3 * rtol of the motion's energy scale (DOP853's global error over ~200
    contact periods; measured 2.5e-7 at rtol 1e-8, 8.5e-7 with SciPy's step control);
    tightening rtol by 100 must shrink it, unless it has reached the drift's floor, the
    energy measure's own error: the drift at rtol 1e-12 (measured 8.7e-8 of the sliding case's
    scale, the same at rtol 1e-10, 1e-11 and 1e-12 with either step control, so 1.5 x it is
    the floor reached).
    """
    y0 = (eq.alpha + push, 0.0) if push else (eq.alpha, -0.5)
    scale = 0.5 * eq.stiffness * push**2 if push else 0.5 * RIG.I_Pb * 0.5**2
    drift = {}
    for rtol in (1e-8, 1e-10, 1e-12):
        r = camdyn.simulate(RIG, FRICTIONLESS, speed_rpm=0, t_end=0.1, y0=y0, sample_rate_Hz=20_000,
                            rtol=rtol, atol=1e-16 if push else 1e-14)
        assert r.ok
        drift[rtol] = np.ptp(r.energy) / scale
        if not push:
            assert r.impacts().size > 10
    assert drift[1e-8] < 1e3 * 1e-8
    assert drift[1e-10] < drift[1e-8] / 5 or drift[1e-10] < 1.5 * drift[1e-12]


@pytest.fixture(scope="module")
def impacting():
    scene = camdyn.Scene(damping="D", friction="coulomb")
    return camdyn.simulate(RIG, scene, speed_rpm=1100, revolutions=2, sample_rate_Hz=50_000, rtol=1e-9)


def test_impacts_alternate_and_switch_on_the_surface(impacting):
    r = impacting
    assert r.ok and r.impacts().size >= 5
    from camdyn.model.model import Model
    m = Model(RIG, camdyn.Scene(damping="D", friction="coulomb"), camdyn.ConstantSpeed(1100))
    contact = [s for s in r.switches if s.surface == "gap"]
    for a, b in zip(contact, contact[1:]):
        assert (a.after == "free") != (b.after == "free")
    for s in contact:
        # located on the far side; the state there is one step of the method to the root of
        # the interpolant, so its gap is the interpolant's error at rtol 1e-9, not 0
        # (measured 3.1e-12 m; 9e-14 m at rtol 1e-11)
        g = m.surface(m.mode(s.before), m.kernels.SURFACE_GAP, s.t, s.alpha, s.alpha_dot)
        assert abs(g) < 1e-11
        assert (g >= 0) if s.after == "free" else (g <= 0)


def test_regime_agrees_with_gap_and_gap_rate(impacting):
    r = impacting
    contact = r.regime != "free"
    tol = 1e-12  # m: samples within this of the surface may be on either side
    assert np.all(r.psi_i[contact] < tol) and np.all(r.psi_i[~contact] > -tol)
    loading = np.char.find(r.regime.astype(str), "_loading") >= 0
    unloading = np.char.find(r.regime.astype(str), "_unloading") >= 0
    assert loading.any() and unloading.any()
    rate_tol = 1e-9  # m/s
    # the impact law acts from contact to the first maximum compression (Sec. 3.4), so the gap
    # is closing while it acts; the viscous law then holds until separation, whatever the rate
    assert np.all(r.psi_i_dot[loading] < rate_tol)
    # Coulomb direction follows the sign of v_r
    fwd = np.char.endswith(r.regime.astype(str), "_fwd")
    assert np.all(r.v_r[fwd] > -1e-9)


def test_D_force_is_continuous_at_maximum_compression(impacting):
    """At psi_i_dot = 0 both laws of model D give the same force, so the switch needs no jump."""
    switches = [s for s in impacting.switches if s.surface == "gap_rate"]
    assert switches
    from camdyn.model.model import Model
    scene = camdyn.Scene(damping="D", friction="coulomb")
    m = Model(RIG, scene, camdyn.ConstantSpeed(1100))
    for s in switches[:10]:
        F_before = m.outputs(m.mode(s.before), s.t, s.alpha, s.alpha_dot)["F_n"]
        F_after = m.outputs(m.mode(s.after), s.t, s.alpha, s.alpha_dot)["F_n"]
        assert abs(F_before - F_after) <= 1e-6 * max(1.0, abs(F_before))


@pytest.mark.parametrize("method", METHODS)
def test_methods_agree_on_impact_times(method):
    """Every method of the engine finds the same impacts as DOP853 at tight tolerance.

    Bound 2e-6 s: both runs at rtol 1e-10; impact times are sensitive to the
    state at a grazing-free crossing at about |dgap/dt|^-1 * state error."""
    scene = camdyn.Scene(damping="D", friction="none")
    kw = dict(speed_rpm=1100, revolutions=0.5, sample_rate_Hz=2000, rtol=1e-10, atol=1e-13)
    ref = camdyn.simulate(RIG, scene, **kw).impacts()
    r = camdyn.simulate(RIG, scene, method=method, **kw)
    assert r.ok, r.outcome
    assert r.impacts().size == ref.size > 2
    np.testing.assert_allclose(r.impacts(), ref, rtol=0, atol=2e-6)


@pytest.mark.parametrize("slug", SCENES)
def test_every_generated_scene_runs(slug):
    scene = scene_from_slug(slug)
    r = camdyn.simulate(rig_for(scene), scene, cam_for(scene), t_end=0.03, sample_rate_Hz=10_000,
                        backend="python" if scene.motion == "user" else "compiled")
    assert r.ok, r.outcome
    for name in ("q", "q_dot", "Theta"):
        assert np.all(np.isfinite(getattr(r, name)))
    for name, v in r.outputs.items():
        assert np.all(np.isfinite(v)), name


def test_user_motion_equals_the_builtin_constant_speed():
    base = camdyn.Scene(damping="D", friction="tanh")
    user = camdyn.Scene(damping="D", friction="tanh", motion="user")
    a = camdyn.simulate(RIG, base, speed_rpm=300, t_end=0.05, rtol=1e-10)
    b = camdyn.simulate(RIG, user, cam_for(user, 300), t_end=0.05, rtol=1e-10, backend="python")
    # the same ODE, rounded differently (the user's Theta passed in; the built-in motion's
    # half-angle economy, derive/trig.py), integrated at rtol 1e-10: measured 1.3e-12 rad
    np.testing.assert_allclose(b.alpha, a.alpha, rtol=0, atol=1e-11)
    # F_n ~ k chi alpha: the contact stiffness (1.4e8 N/m times a 0.1 m arm) turns the 1.3e-12 rad
    # into 1.8e-5 N (measured); bound 1e-4 N on forces of ~15 N
    np.testing.assert_allclose(b.F_n, a.F_n, rtol=0, atol=1e-4)


def test_contact_loss_speed_separates_sliding_from_impacting():
    """Inverse kinematics (Section 6) against simulation: 10% below the predicted speed the
    follower never leaves the cam after the start-up transient; 10% above it does.

    Starting from rest at equilibrium, the required contact force steps at t = 0 and the
    lightly damped contact mode (zeta_D = 0.01) overshoots, so the first revolution may bounce.
    """
    loss = analysis.contact_loss_speed(RIG)
    scene = camdyn.Scene(damping="D", friction="coulomb")
    below = camdyn.simulate(RIG, scene, speed_rpm=0.9 * loss, revolutions=3, sample_rate_Hz=5000)
    above = camdyn.simulate(RIG, scene, speed_rpm=1.1 * loss, revolutions=3, sample_rate_Hz=5000)
    assert below.ok and above.ok
    assert below.after(below.period).impacts().size == 0
    assert above.after(above.period).impacts().size > 0


@pytest.mark.parametrize("sign, loses", [("dissipative", True), ("printed", False)])
def test_misprint_2_damping_B_sign_by_energy_over_an_impact(eq, sign, loses):
    """Misprint 2: c = beta k psi_i as printed is negative in contact and adds energy over an
    impact; the dissipative c = beta k |psi_i| removes it.  Cam at rest, no friction: the
    energy in free flight after the first impact is compared with that before it."""
    scene = camdyn.Scene(damping="B", friction="none", damping_sign=sign)
    r = camdyn.simulate(RIG, scene, speed_rpm=0, t_end=0.05, y0=(eq.alpha + 1e-5, -1.0),
                        sample_rate_Hz=200_000, rtol=1e-10, atol=1e-14)
    # the printed sign pumps energy in at every impact until the follower swings to 90 degrees
    assert r.ok if loses else r.outcome in (camdyn.Outcome.SUCCESS, camdyn.Outcome.ANGLE_LIMIT)
    assert r.impacts().size >= 1 and r.separations().size >= 1
    t_in, t_out = r.impacts()[0], r.separations()[0]
    E_before = r.energy[(r.t < t_in)][-1]
    E_after = r.energy[(r.t > t_out) & (r.regime == "free")][0]
    change = (E_after - E_before) / E_before
    assert abs(change) > 1e-3  # far above the solver's ~1e-8 energy error
    assert (change < 0) == loses


@pytest.mark.parametrize("speed", [0.0, 1.0])
def test_start_exactly_on_the_cam_moving_away_separates(speed):
    """Regression: a start with gap psi_i = 0 exactly and the follower moving away must
    switch to free flight at once, not stay in contact pulled by a tensile force."""
    r = camdyn.simulate(RIG, camdyn.Scene(damping="D", friction="none"), speed_rpm=speed,
                        t_end=0.002, y0=(RIG.alpha0, 5.0), sample_rate_Hz=100_000)
    assert r.ok
    assert np.all(r.regime == "free") and np.all(r.psi_i[1:] > 0)
    assert np.all(r.F_n == 0)  # the viscous law of D would give tension at psi_i = 0 here


@pytest.mark.parametrize("damping", ["B", "D"])
@pytest.mark.parametrize("sign", ["dissipative", "printed"])
def test_misprint_2_damping_power_sign_during_approach(eq, damping, sign):
    """Misprint 2, power view: while the gap closes (t_a..t_b), the impact law of B and D
    dissipates (D_c = c psi_i_dot^2 >= 0) with |psi_i|, and feeds energy in (D_c <= 0) as printed."""
    scene = camdyn.Scene(damping=damping, friction="none", damping_sign=sign)
    r = camdyn.simulate(RIG, scene, speed_rpm=0, t_end=0.004, y0=(eq.alpha + 1e-5, -1.0),
                        sample_rate_Hz=1_000_000, rtol=1e-10, atol=1e-14)
    approach = (r.regime != "free") & (r.psi_i_dot < 0)
    assert approach.sum() > 20
    D_c = r.D_c[approach]
    assert np.all(D_c >= 0) if sign == "dissipative" else np.all(D_c <= 0)
    assert np.abs(D_c).max() > 0


def test_progress_reports_the_share_done_after_each_piece_and_does_not_change_the_run():
    """A long run is integrated in pieces (camdyn.runs.pieces); progress hears after each one."""
    from camdyn.runs.pieces import PIECE_PERIODS
    rig, scene = camdyn.example_rig(), camdyn.Scene(damping="D", friction="coulomb")
    revolutions = 2 * PIECE_PERIODS * 2 + 10  # 2 T per kernel period: two whole pieces and a part
    kwargs = dict(speed_rpm=3000, revolutions=revolutions, sample_rate_Hz=50.0, rtol=1e-6, atol=1e-10)
    heard = []
    reported = camdyn.simulate(rig, scene, progress=heard.append, **kwargs)
    assert reported.ok, reported.outcome.message
    assert len(heard) == reported.stats["pieces"] == 3
    expected = [2 * PIECE_PERIODS / revolutions, 4 * PIECE_PERIODS / revolutions, 1.0]
    assert np.allclose(heard, expected, rtol=1e-12)  # rounding of the piece ends in t only
    silent = camdyn.simulate(rig, scene, **kwargs)
    assert np.array_equal(silent.alpha, reported.alpha)


def test_the_cli_bar_shows_the_percentage(capsys, monkeypatch):
    import argparse
    import time

    from camdyn.cli import common as cli
    monkeypatch.setattr(cli, "_progress_enabled", lambda args: False)  # as on a terminal
    with cli._busy("simulating", argparse.Namespace(), after=0.05) as share:
        share(0.5)  # before the bar first draws (after 0.05 s), which it then does every 0.5 s
        time.sleep(1.2)
    assert "50 % done" in capsys.readouterr().err


def test_outputs_are_computed_when_first_read_and_equal_the_kernel_at_the_samples():
    """Result.outputs is computed on first use (a run nobody reads the outputs of does not
    compile the outputs kernel); the values are the outputs kernel at each sample, bitwise
    (the same compiled kernel on the same samples), and a pickled Result carries them."""
    import pickle

    from camdyn.engine.kernels import compiled_kernels, outputs_on_samples
    from camdyn.model.model import Model

    r = camdyn.simulate(RIG, camdyn.Scene(), speed_rpm=1100, t_end=0.02, sample_rate_Hz=5_000)
    assert r.ok and r.switches  # impacting: several modes among the samples
    assert "not computed yet" in repr(r.outputs) and "F_n" in r.outputs and len(r.outputs) > 5
    model = Model(RIG, camdyn.Scene(), camdyn.model.cam.cam_motion(None, 1100))
    mode = np.array([model.kernels.MODES.index(name) for name in r.regime])
    expected = outputs_on_samples(compiled_kernels(model.kernels), True, mode, r.t, r.alpha, r.alpha_dot, model.p,
                                  len(model.kernels.OUTPUTS))
    for name, row in zip(model.kernels.OUTPUTS, expected):
        np.testing.assert_array_equal(r.outputs[name], row)
    assert "not computed yet" not in repr(r.outputs)
    again = pickle.loads(pickle.dumps(r))
    assert type(again.outputs) is dict and again.outputs.keys() == r.outputs.keys()
    np.testing.assert_array_equal(again.F_n, r.F_n)


# --- what a run is asked for: simulate's keywords build a Span and a SolverOptions once -----------
def test_loose_keywords_and_the_objects_given_whole_are_the_same_run():
    """``revolutions=..., rtol=..., energy_ledger=...`` build the Span and SolverOptions that
    ``span=`` and ``options=`` pass whole: the same run, bit for bit, and the same request."""
    from camdyn.engine import EventSettings, SolverOptions
    from camdyn.runs.request import Span, run_request

    loose = dict(revolutions=1.5, sample_rate_Hz=4000.0, t_start=0.25, method="RK45", rtol=1e-9, atol=1e-13,
                 max_step=1e-3, events=EventSettings(max_events=5000), energy_ledger=True, step_control="scipy")
    span = Span(revolutions=1.5, sample_rate_Hz=4000.0, t_start=0.25)
    options = SolverOptions(method="RK45", rtol=1e-9, atol=1e-13, max_step=1e-3, events=EventSettings(max_events=5000),
                            ledger=True, step_control="scipy")
    assert run_request(**loose) == run_request(span=span, options=options)
    a = camdyn.simulate(RIG, camdyn.Scene(), speed_rpm=1100, **loose)
    b = camdyn.simulate(RIG, camdyn.Scene(), speed_rpm=1100, span=span, options=options)
    assert a.ok and a.switches and a.t[0] == 0.25
    for name in ("t", "alpha", "alpha_dot", "work_in"):
        assert np.array_equal(getattr(a, name), getattr(b, name)), name
    assert a.stats["steps"] == b.stats["steps"] and a.stats["rejected_steps"] == b.stats["rejected_steps"]


@pytest.mark.parametrize("kwargs, match", [
    (dict(revolution=2), r"^revolution is not a keyword of camdyn.simulate \(did you mean 'revolutions'\?\): "
                         r"must be one of span, options, y0, backend, stop, t_end, revolutions, .*energy_ledger"),
    (dict(ledger=True, revolutions=2), r"^ledger is not a keyword .*did you mean 'energy_ledger'"),
    (dict(span="span", t_end=0.1), r"^t_end = 0.1 is given beside span=: must be set in the Span or given as a "
                                   r"keyword, not both"),
    (dict(revolutions=2, options="options", rtol=1e-9), r"^rtol = 1e-09 is given beside options="),
    (dict(revolutions=2, options="options"), r"^options = 'options' is not valid: must be a camdyn.engine.SolverOptions"),
    (dict(span=2.0), r"^span = 2.0 is out of range: must be a camdyn.runs.Span"),
    (dict(revolutions=2, stop=16), r"^stop = 16 .*must be None or a camdyn.StopWhenPeriodic"),
])
def test_an_unknown_doubled_or_wrong_keyword_is_refused_naming_it(kwargs, match, monkeypatch):
    """Before any work: no model is built."""
    import camdyn.runs.simulation
    from camdyn.errors import ParameterError

    def no_model(*args):
        raise AssertionError("a model was built")

    monkeypatch.setattr(camdyn.runs.simulation, "checked_model", no_model)
    with pytest.raises(ParameterError, match=match):
        camdyn.simulate(RIG, camdyn.Scene(), speed_rpm=300, **kwargs)


def test_the_span_is_checked_and_stored_as_floats():
    from camdyn.errors import ParameterError
    from camdyn.runs.request import Span

    span = Span(revolutions=np.int64(3), sample_rate_Hz=np.float32(1000), t_start=1)
    assert (span.revolutions, span.sample_rate_Hz, span.t_start) == (3.0, 1000.0, 1.0)
    assert all(type(v) is float for v in (span.revolutions, span.sample_rate_Hz, span.t_start))
    for kwargs, match in ((dict(), "t_end is not given: exactly one of"), (dict(t_end=1.0, revolutions=2), "exactly one"),
                          (dict(revolutions=True), "revolutions = True is not a real number"),
                          (dict(t_end=math.inf), r"t_end = inf is out of range: must be t_end > 0 \(s\)"),
                          (dict(t_end=1.0, t_start=math.nan), "t_start = nan is out of range: must be a finite time")):
        with pytest.raises(ParameterError, match=match):
            Span(**kwargs)
