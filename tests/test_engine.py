"""The engine: one loop, compiled or interpreted, reading the generated automaton.

The compiled and the interpreted loop are the same source (camdyn.engine.jit), the cfuncs and
the Python kernels the same generated functions: they must give the same run, to rounding.
The independent check of the rules themselves is tests/test_oracle.py.
"""
from __future__ import annotations

import math
import subprocess
import sys

import mpmath
import numpy as np
import pytest

import camdyn
from camdyn.engine import loop
from camdyn.engine.config import SolverOptions, settings as loop_settings
from camdyn.engine.loop import SUCCESS, Samples, Start, run_compiled, run_interpreted
from camdyn.engine.tableau import DOP853, arrays
from camdyn.engine.tables import IDENTITY, tables
from camdyn.errors import ParameterError
from camdyn.model.model import Model
from registry import RIG, SCENES, cam_for, rig_for, scene_from_slug
from toy import bounce_problem, settings

COMPILED_SCENES = [s for s in SCENES if scene_from_slug(s).motion != "user"]
TIGHT = dict(rtol=1e-10, atol=1e-13)


def _both(scene, cam, rig=RIG, **kw):
    a = camdyn.simulate(rig, scene, cam, backend="compiled", **kw)
    b = camdyn.simulate(rig, scene, cam, backend="python", **kw)
    return a, b


def _assert_same(a, b):
    """Compiled and interpreted: the same switches and samples.  The two evaluate the same
    arithmetic; where a library function differs in its last bit between numba and Python's
    math, the difference stays at rounding level.  Measured: bit-identical on every scene's
    impacting run below; on the stick-slip run, switch times 3.9e-13 relative, alpha 7.4e-14,
    F_n 6.9e-9 of its peak (the stiff contact amplifies alpha's rounding ~1e5 times).  Bounds:
    about 10x those."""
    assert a.outcome == b.outcome
    assert [(s.surface, s.before, s.after) for s in a.switches] == [(s.surface, s.before, s.after) for s in b.switches]
    np.testing.assert_allclose([s.t for s in b.switches], [s.t for s in a.switches], rtol=5e-12, atol=0)
    np.testing.assert_allclose(b.q, a.q, rtol=0, atol=1e-12 * max(1.0, np.abs(a.q).max()))
    assert np.array_equal(a.regime, b.regime)
    for name in ("F_n", "v_r", "energy"):
        scale = max(1.0, np.abs(a.outputs[name]).max())
        np.testing.assert_allclose(b.outputs[name], a.outputs[name], rtol=0, atol=1e-7 * scale)


@pytest.mark.parametrize("slug", COMPILED_SCENES)
def test_compiled_and_interpreted_loops_give_the_same_run(slug):
    """Impacting at 1100 rev/min for 15 ms: free flight, impacts, both damping laws, friction."""
    scene = scene_from_slug(slug)
    a, b = _both(scene, cam_for(scene, 1100), rig_for(scene), t_end=0.015, sample_rate_Hz=10_000, **TIGHT)
    assert a.ok, a.outcome
    _assert_same(a, b)


def test_compiled_and_interpreted_agree_on_stick_slip_and_the_ledger():
    """Section 7.2's oscillating cam at its first friction reversal (e = 0.7 r_c, preloaded
    so that contact holds): sticks and slips again; the energy ledger on."""
    rig = RIG.replace(e=0.7 * RIG.r_c, L_us=0.2)
    scene = camdyn.Scene(damping="D", friction="coulomb", motion="oscillating")
    a, b = _both(scene, camdyn.Oscillating(math.pi, 40), rig=rig, t_end=0.41, sample_rate_Hz=2_000,
                 energy_ledger=True, **TIGHT)
    assert any(s.after.endswith("_stick") for s in a.switches)
    _assert_same(a, b)
    # measured 1.8e-12 of the largest work
    np.testing.assert_allclose(b.work_in, a.work_in, rtol=0, atol=2e-11 * np.abs(a.work_in).max())


# --- the automaton's tables ------------------------------------------------------------------
@pytest.mark.parametrize("slug", SCENES)
def test_tables_encode_the_generated_automaton(slug):
    """Every transition of the generated module is a row of its source mode's block, with its
    surface, direction, candidates and conditions; the initial candidates follow the last row."""
    K = scene_from_slug(slug).kernels()
    tab = tables(K)
    data = {name: tab.data[getattr(tab, name):] for name in tab._fields if name != "data" and not name.startswith("n_")}
    rows = []
    for m in range(len(K.MODES)):
        for w in range(data["watch_start"][m], data["watch_start"][m + 1]):
            targets = tuple((int(data["target_mode"][c]), tuple(
                (int(data["condition_surface"][q]), int(data["condition_sign"][q]))
                for q in range(data["condition_start"][c], data["condition_start"][c + 1])))
                for c in range(data["target_start"][w], data["target_start"][w + 1]))
            rows.append((m, int(data["surface"][w]), int(data["direction"][w]), targets, int(data["reset"][w])))
    resets = [IDENTITY if K.RESETS[tr[4]] == "identity" else tr[4] for tr in K.TRANSITIONS]  # the rigid law's impacts
    assert rows == [tr[:4] + (j,) for tr, j in zip(K.TRANSITIONS, resets)]
    n = tab.n_transitions
    initial = [int(data["target_mode"][c]) for c in range(data["target_start"][n], data["target_start"][n + 1])]
    assert initial == [c[0] for c in K.INITIAL]
    assert data["mode_contact"][:tab.n_modes].tolist() == [int(c) for c in K.CONTACT_OF_MODE]
    assert [K.OUTPUTS[i] for i in data["flows"][:3]] == ["P_in", "D_c", "D_f"]
    for m in range(len(K.MODES)):  # each surface a mode's crossing check samples, once (a rate with its surface)
        sampled = data["sampled"][data["sampled_start"][m]:data["sampled_start"][m + 1]].tolist()
        evaluated = sampled + [K.RATE_OF_SURFACE[s] for s in sampled if K.RATE_OF_SURFACE[s] >= 0]
        watched = {tr[1] for tr in K.TRANSITIONS if tr[0] == m}
        assert len(evaluated) == len(set(evaluated))
        assert set(evaluated) == watched | {K.RATE_OF_SURFACE[s] for s in watched if K.RATE_OF_SURFACE[s] >= 0}
    assert tab.surface_timed == tab.sampled + data["sampled_start"][tab.n_modes] and tab.n_surfaces == len(K.SURFACES)
    timed = getattr(K, "TIMED_SURFACES", ())  # the surfaces of time alone, a flag per surface, last
    assert data["surface_timed"].tolist() == [int(s in timed) for s in range(len(K.SURFACES))]


# --- trap 1: the gap as a difference of nearly equal angles --------------------------------
def test_gap_is_well_conditioned_against_a_50_digit_oracle():
    """Eq. 6 as printed subtracts nearly equal terms near the surface (psi_i ~ 1e-12 m out of
    terms ~ 1e-2 m): in doubles it keeps ~4 digits.  The generated surface (the half-angle
    form) must match a 50-digit evaluation of Eq. 6 to ~1e-17 m."""
    scene = camdyn.Scene(damping="D", friction="coulomb")
    m = Model(RIG, scene, camdyn.ConstantSpeed(300))
    r = RIG
    mpmath.mp.dps = 50
    worst_kernel, worst_naive = 0.0, 0.0
    for da, t in [(1e-9, 1e-7), (-3e-10, 2e-6), (2e-11, 0.0), (5e-8, 1e-9)]:
        alpha = r.alpha0 + da
        theta = r.theta0 + m.cam.Omega_c * t
        A, A0, T, T0 = (mpmath.mpf(x) for x in (alpha, r.alpha0, theta, r.theta0))
        exact = (r.chi0 * mpmath.sin(A - A0) + (r.r_c + r.w_b / 2) * (mpmath.cos(A - A0) - 1)
                 + r.e * (mpmath.sin(A + T0) - mpmath.sin(A + T)))
        naive = (r.chi0 * math.sin(alpha - r.alpha0) + (r.r_c + r.w_b / 2) * (math.cos(alpha - r.alpha0) - 1)
                 + r.e * (math.sin(alpha + r.theta0) - math.sin(alpha + theta)))
        worst_kernel = max(worst_kernel, abs(m.surface(0, m.kernels.SURFACE_GAP, t, alpha, 0.0) - float(exact)))
        worst_naive = max(worst_naive, abs(naive - float(exact)))
    assert worst_kernel < 1e-17
    assert worst_naive > 100 * worst_kernel  # the trap is real


# --- trap 2: a whole micro-hop inside one step ---------------------------------------------
def _bounce(y0, t_end, interior, compiled, p=(1.0, 1e4, math.inf), rtol=1e-8, max_step=math.inf, rate=False):
    """The loop on the toy: mode 0 free (constant acceleration), mode 1 contact (a spring)."""
    prob = bounce_problem(p, compiled, rate)
    cfg = settings(interior, rtol=rtol, max_step=max_step)
    samples = Samples(np.linspace(0, t_end, 11), np.empty((2, 11)), np.zeros(11, dtype=np.int64))
    run = run_compiled if compiled else run_interpreted
    return run(prob, arrays(DOP853), cfg, Start(0.0, t_end, y0[0], y0[1], -1), samples)


@pytest.mark.parametrize("compiled", [True, False], ids=["compiled", "python"])
def test_micro_hop_inside_one_step_is_caught_by_interior_points(compiled):
    """Free flight on an exact parabola alpha = 0.5 - 1.01 t + t^2/2 (zero local error, so steps
    grow tenfold up to max_step = 1 s) dips below the surface between t = 0.868 and 1.152 and
    comes back: both ends of the step over it are above it.  Three interior samples (0.25 s
    apart, closer than the dip is wide) find the contact at the exact root; without them it
    is missed -- the trap the interior points exist for."""
    root = 1.01 - math.sqrt(1.01**2 - 1)
    missed = _bounce((0.5, -1.01), 4.0, 0, compiled, max_step=1.0)
    caught = _bounce((0.5, -1.01), 4.0, 3, compiled, max_step=1.0)
    assert missed.outcome == SUCCESS and missed.switches.size == 0
    assert caught.outcome == SUCCESS and caught.switches.size >= 2
    assert caught.switches["t"][0] == pytest.approx(root, abs=1e-12)
    assert (caught.switches["before"][0], caught.switches["after"][0]) == (0, 1)  # free -> contact


@pytest.mark.parametrize("compiled", [True, False], ids=["compiled", "python"])
def test_micro_hop_between_samples_is_caught_by_the_gap_rate(compiled):
    """The same dip with no interior points: only the gap's declared rate, which turns from
    approaching to leaving inside the step, can find it -- and does, at the exact root."""
    root = 1.01 - math.sqrt(1.01**2 - 1)
    caught = _bounce((0.5, -1.01), 4.0, 0, compiled, max_step=1.0, rate=True)
    assert caught.outcome == SUCCESS and caught.switches.size >= 2
    assert caught.switches["t"][0] == pytest.approx(root, abs=1e-12)


@pytest.mark.parametrize("compiled", [True, False], ids=["compiled", "python"])
def test_nan_in_a_stage_is_rejected_and_retried_smaller(compiled):
    """Toy contact law undefined above alpha = 0.02: big steps in contact overshoot there; the
    loop rejects them (instead of failing or propagating NaN) and still finishes."""
    out = _bounce((0.0, -0.5), 0.5, 3, compiled, p=(1.0, 1e2, 0.02), rtol=1e-6)
    clean = _bounce((0.0, -0.5), 0.5, 3, compiled, p=(1.0, 1e2, math.inf), rtol=1e-6)
    assert out.outcome == SUCCESS
    assert out.rejected > clean.rejected
    assert out.switches.size == clean.switches.size


# --- trap 3: ping-pong when restarting exactly on the surface ------------------------------
@pytest.mark.parametrize("alpha_dot, first", [(5.0, "free"), (-5.0, None)])
def test_start_exactly_on_the_surface_does_not_ping_pong(alpha_dot, first):
    """gap = 0 exactly at the start: moving away separates at once and stays free; moving in
    enters contact and bounces.  No switch re-triggers at its own restart point."""
    scene = camdyn.Scene(damping="D", friction="none")
    r = camdyn.simulate(RIG, scene, speed_rpm=0.0, t_end=0.004, y0=(RIG.alpha0, alpha_dot),
                        sample_rate_Hz=100_000, **TIGHT)
    if first:
        assert np.all(r.regime == first) and np.all(r.F_n == 0)
    else:
        assert r.regime[0] != "free" and r.separations().size >= 1
    times = np.array([s.t for s in r.switches])
    same = [(x.surface == y.surface) for x, y in zip(r.switches, r.switches[1:])]
    assert not any(s and dt < 1e-12 for s, dt in zip(same, np.diff(times)))


def test_every_switch_restarts_on_the_far_side_of_its_surface():
    """Each switch's state is across (or on) the surface it crossed, in the transition's
    direction, under the mode it left."""
    scene = camdyn.Scene(damping="D", friction="coulomb")
    r = camdyn.simulate(RIG, scene, speed_rpm=1100, revolutions=1, **TIGHT)
    m = Model(RIG, scene, camdyn.ConstantSpeed(1100))
    K = m.kernels
    direction = {(K.MODES[tr[0]], K.SURFACES[tr[1]]): tr[2] for tr in K.TRANSITIONS}
    assert r.ok and r.impacts().size > 3
    for s in r.switches:
        g = m.surface(m.mode(s.before), K.SURFACES.index(s.surface), s.t, s.alpha, s.alpha_dot)
        assert direction[s.before, s.surface] * g >= 0, s


# --- trap 4: Hertz (-psi_i)^1.5 when a stage overshoots ------------------------------------
def test_point_contact_force_is_finite_and_continuous_beyond_the_surface():
    """A stage of a step that leaves contact evaluates the contact law at psi_i > 0: a naive
    (-psi_i)**1.5 is NaN (or complex) there.  The generated contact modes are finite and
    continuous across psi_i = 0."""
    scene = camdyn.Scene(contact="point", damping="D", friction="coulomb")
    m = Model(RIG, scene, camdyn.ConstantSpeed(300))
    a0 = RIG.alpha0
    for i, name in enumerate(m.kernels.MODES):
        if not m.kernels.CONTACT_OF_MODE[i]:
            continue
        values = [m.rhs(i, 0.0, a0 + d, 0.0) for d in (-1e-12, 0.0, 1e-12, 1e-5)]
        assert all(math.isfinite(v) for v in values), name
        if m.kernels.SLIP_OF_MODE[i] != "stick":  # a stuck follower's field has no contact law in it
            assert values[0] == pytest.approx(values[2], rel=1e-8)
    assert isinstance((-1e-6) ** 1.5, complex)  # what the naive form would give


# --- trap 5: the D/E switch --------------------------------------------------------------
def test_D_switch_in_permanent_contact_is_one_switch_per_episode():
    """At 300 rev/min the follower slides without impacts: one contact episode, so the episode
    reading (Sec. 3.4) switches the law once, at the first maximum compression."""
    scene = camdyn.Scene(damping="D", friction="none")
    r = camdyn.simulate(RIG, scene, speed_rpm=300, revolutions=1, sample_rate_Hz=5000, **TIGHT)
    assert r.ok and r.impacts().size == 0
    assert [(s.surface, s.before, s.after) for s in r.switches] == [("gap_rate", "contact_loading", "contact_unloading")]


def test_memoryless_D_switch_in_permanent_contact_does_not_chatter():
    """The memoryless reading: psi_i_dot crosses 0 twice per contact-mode period, each a switch,
    none closer than a microsecond to the previous one, no CHATTER."""
    scene = camdyn.Scene(damping="D", friction="coulomb", damping_switch="memoryless")
    r = camdyn.simulate(RIG, scene, speed_rpm=300, revolutions=1, sample_rate_Hz=5000, **TIGHT)
    assert r.ok and r.impacts().size == 0
    law = np.array([s.t for s in r.switches if s.surface == "gap_rate"])
    assert law.size > 20 and np.diff(law).min() > 1e-6


def test_D_switch_at_rest_on_the_surface():
    """Cam at rest at the static equilibrium: psi_i_dot = 0 exactly, the D/E surface itself.
    The run must not chatter and the follower must stay at alpha* (the force is continuous
    across the switch)."""
    scene = camdyn.Scene(damping="D", friction="coulomb", damping_switch="memoryless")
    r = camdyn.simulate(RIG, scene, speed_rpm=0.0, t_end=0.02, **TIGHT)
    assert r.ok
    assert np.abs(r.alpha - r.alpha_star).max() < 1e-12
    assert len(r.switches) < 4 * 0.02 * 2200  # at most a few per contact-mode period


# --- bad input, one loop for all, the disk cache ------------------------------------------
def test_bad_input_names_the_parameter():
    scene = camdyn.Scene(damping="D", friction="coulomb")
    with pytest.raises(ParameterError, match="backend"):
        camdyn.simulate(RIG, scene, speed_rpm=300, t_end=0.01, backend="numba")
    with pytest.raises(ParameterError, match="method"):
        camdyn.simulate(RIG, scene, speed_rpm=300, t_end=0.01, method="Radau")


def test_user_motion_needs_the_python_backend():
    scene = camdyn.Scene(damping="D", friction="tanh", motion="user")
    with pytest.raises(ParameterError, match="python"):
        camdyn.simulate(RIG, scene, cam_for(scene, 300), t_end=0.01)
    assert camdyn.simulate(RIG, scene, cam_for(scene, 300), t_end=0.002, backend="python").ok


def test_one_compiled_loop_for_every_scene_rig_and_speed():
    """Parameters travel as arrays and kernels as typed function values: running other scenes,
    rigs and speeds adds no compiled specialisation of the loop."""
    for slug, speed, k_s in [("line_d_coulomb_constant_nonlinear", 300, 2000.0),
                             ("line_d_coulomb_constant_nonlinear", 1200, 3000.0),
                             ("point_d_coulomb_constant_nonlinear", 500, 2500.0),
                             ("line_d_coulomb_constant_linear_paper", 300, 2000.0),
                             ("line_none_none_constant_nonlinear", 300, 2000.0)]:
        r = camdyn.simulate(RIG.replace(k_s=k_s), scene_from_slug(slug), speed_rpm=speed, t_end=0.005)
        assert r.ok
    assert len(loop._run_compiled.signatures) == 1


def test_warm_start_loads_the_compiled_loop_from_the_disk_cache():
    code = ("import camdyn\nfrom camdyn.engine import loop\n"
            "r = camdyn.simulate(camdyn.example_rig(), camdyn.Scene(), speed_rpm=300, t_end=0.002)\n"
            "assert r.ok\nprint(sum(loop._run_compiled.stats.cache_hits.values()), "
            "sum(loop._run_compiled.stats.cache_misses.values()))")
    subprocess.run([sys.executable, "-c", code], capture_output=True, text=True, check=True)  # fills the cache
    out = subprocess.run([sys.executable, "-c", code], capture_output=True, text=True, check=True)
    hits, misses = map(int, out.stdout.split())
    assert (hits, misses) == (1, 0)


def test_settings_carry_the_rules_constants_by_name():
    cfg = loop_settings(SolverOptions(rtol=1e-7, atol=1e-11), contact_frequency=1e4)
    assert (cfg.rtol, cfg.atol, cfg.contact_step) == (1e-7, 1e-11, 0.1 / 1e4)
    assert cfg._fields[:3] == ("rtol", "atol", "max_step")
    # the loop's codes are indices of camdyn.Outcome members; the members it never returns come
    # only from the quasi-static follower (no integration)
    quasi_static = (camdyn.Outcome.CONTACT_TENSILE, camdyn.Outcome.NO_QUASI_STATIC)
    assert set(loop.OUTCOMES) | set(quasi_static) == set(camdyn.Outcome)
    assert [loop.OUTCOMES[code] for code in (loop.SUCCESS, loop.CHATTER, loop.ANGLE_LIMIT)] == \
        [camdyn.Outcome.SUCCESS, camdyn.Outcome.CHATTER, camdyn.Outcome.ANGLE_LIMIT]


def test_a_run_that_will_compile_the_loop_says_so_once(monkeypatch):
    """Issue 14 (N): an empty cache and a loop not yet in memory give one CompileNotice, naming
    how to silence it; a loaded loop gives none."""
    import warnings

    from camdyn.engine import driver

    camdyn.simulate(RIG, camdyn.Scene(), speed_rpm=300, t_end=1e-4)  # the loop is in memory now
    with warnings.catch_warnings():
        warnings.simplefilter("error", camdyn.CompileNotice)
        camdyn.simulate(RIG, camdyn.Scene(), speed_rpm=300, t_end=1e-4)
    index = loop._run_compiled._cache._cache_file  # numba's index of the loop in the cache
    monkeypatch.setattr(index, "_load_index", lambda: {})  # as for an empty cache or another checkout ...
    monkeypatch.setattr(driver, "loop_loaded", lambda: False)  # ... and a fresh process
    assert not loop.loop_cached()
    with pytest.warns(camdyn.CompileNotice, match="compiles its integration loop.*filterwarnings"):
        camdyn.simulate(RIG, camdyn.Scene(), speed_rpm=300, t_end=1e-4)


def test_pi_step_control_rejects_fewer_attempts_at_the_same_accuracy():
    """The sliding run's start-up transient (line contact, damping D, Coulomb, +300 rev/min,
    rtol 1e-8): the DOP853 error estimate dips and jumps with the contact vibration's phase, so
    SciPy's controller grows the step after a dip and is rejected (measured: 350 rejected attempts
    for 1869 steps); the PI controller damps that growth (measured: 46).  Both stay within 1e-9
    rad of a run at rtol 1e-12 (measured 9e-11 and 6e-12: the bound leaves a factor 10)."""
    rig, scene = camdyn.example_rig(), camdyn.Scene(damping="D", friction="coulomb")
    kw = dict(speed_rpm=300, t_end=0.2, sample_rate_Hz=5000)
    ref = camdyn.simulate(rig, scene, rtol=1e-12, atol=1e-16, **kw)
    runs = {c: camdyn.simulate(rig, scene, rtol=1e-8, atol=1e-12, step_control=c, **kw) for c in ("scipy", "pi")}
    assert runs["pi"].stats["rejected_steps"] < 0.5 * runs["scipy"].stats["rejected_steps"]
    for r in runs.values():
        assert r.ok and np.max(np.abs(r.alpha - ref.alpha)) < 1e-9


def test_step_control_is_validated():
    with pytest.raises(ParameterError, match="step_control"):
        SolverOptions(step_control="PID")
