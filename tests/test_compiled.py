"""The compiled backend: agreement with the SciPy backend, the issue's traps, bad input, caching.

Bounds: both backends at rtol 1e-10 take nearly the same steps (the RK core is SciPy's,
tests/test_rk_tableau.py), so states agree to ~1e3 rtol of the motion's scale and switch
times to the root tolerance amplified by the state difference (measured: alpha <= 1.3e-10 rad,
switch times <= 1e-11 s over 0.05 s of impacting).
"""
from __future__ import annotations

import math
import subprocess
import sys

import mpmath
import numba
import numpy as np
import pytest

import camdyn
from camdyn.compiled import engine, regimes
from camdyn.compiled.backend import tables
from camdyn.compiled.kernels import SIGNATURE, scene_functions
from camdyn.compiled.tableau import DOP853, arrays
from camdyn.errors import ParameterError, SceneError
from camdyn.model import Model
from registry import RIG, SCENES, cam_for, scene_from_slug

COMPILED_SCENES = [s for s in SCENES if scene_from_slug(s).motion != "user"]
TIGHT = dict(rtol=1e-10, atol=1e-13)


def _both(scene, cam, rig=RIG, **kw):
    a = camdyn.simulate(rig, scene, cam, **kw)
    b = camdyn.simulate(rig, scene, cam, backend="compiled", **kw)
    return a, b


def _assert_agree(a, b, alpha_tol=1e-8, t_tol=1e-8, force_tol=1e-5):
    """force_tol: of the largest |F_n| (a stiff contact amplifies alpha differences ~1e9 times)."""
    assert a.outcome == b.outcome
    assert [(s.surface, s.before, s.after) for s in a.switches] == [(s.surface, s.before, s.after) for s in b.switches]
    np.testing.assert_allclose([s.t for s in b.switches], [s.t for s in a.switches], rtol=0, atol=t_tol)
    np.testing.assert_allclose(b.alpha, a.alpha, rtol=0, atol=alpha_tol)
    assert np.array_equal(a.regime, b.regime)
    np.testing.assert_allclose(b.F_n, a.F_n, rtol=0, atol=force_tol * max(1.0, np.abs(a.F_n).max()))


@pytest.mark.parametrize("slug", COMPILED_SCENES)
@pytest.mark.parametrize("speed", [300, 1100], ids=["sliding", "impacting"])
def test_agrees_with_scipy_on_every_scene(slug, speed):
    scene = scene_from_slug(slug)
    a, b = _both(scene, cam_for(scene, speed), t_end=0.03, sample_rate_Hz=10_000, **TIGHT)
    assert a.ok, a.outcome
    _assert_agree(a, b)


PAPER = {  # the work-precision report's scenes (benchmarks/performance.py), a few revolutions each
    "impacting D, 16 mm": (dict(damping="D", friction="coulomb"), {"l_lambda": 0.016}, 1300.0, 4),
    "sliding line, de-energizing": (dict(damping="D", friction="coulomb"), {}, 300.0, 1),
    "sliding line, self-energizing": (dict(damping="D", friction="coulomb"), {}, -300.0, 1),
    "sliding point": (dict(contact="point", damping="D", friction="coulomb"), {}, 300.0, 1),
    "friction reversal, tanh": (dict(damping="D", friction="tanh", sliding_velocity="printed"),
                                {"e": 0.0175}, 50.0, 0.2),
}


@pytest.mark.slow
@pytest.mark.parametrize("name", PAPER)
def test_agrees_with_scipy_on_the_paper_scenes(name):
    options, changes, speed, revs = PAPER[name]
    scene = camdyn.Scene(**options)
    rig = RIG.replace(**changes) if changes else RIG
    kw = dict(speed_rpm=speed, revolutions=revs, sample_rate_Hz=20_000, **TIGHT)
    a = camdyn.simulate(rig, scene, **kw)
    b = camdyn.simulate(rig, scene, backend="compiled", **kw)
    assert a.ok, a.outcome
    _assert_agree(a, b, alpha_tol=1e-7, t_tol=1e-6, force_tol=1e-4)


def test_oscillating_cam_agrees_with_scipy():
    scene = camdyn.Scene(damping="D", friction="tanh", motion="oscillating")
    a, b = _both(scene, camdyn.Oscillating(math.pi, 40.0), t_end=0.05, sample_rate_Hz=20_000, **TIGHT)
    _assert_agree(a, b)


def test_coulomb_stick_slip_agrees_with_scipy():
    """Section 7.2's oscillating cam at its first reversal (e = 0.7 r_c, preloaded so contact
    holds): both backends stick (Filippov mode on v_r = 0) and slip again at the same times,
    and sample the same friction states, including the stick mode's.

    The damping law's switches (surface 'loading', psi_i_dot = 0) are not compared one by
    one: in this run psi_i_dot hovers near -4e-9 m/s, at the integration's noise level, and
    some of its zero touches come in pairs whose existence and spacing depend on rounding
    (measured: one pair 0 s apart on the SciPy backend, 9.7 us apart compiled, absent from a
    SciPy run at rtol 1e-13).  The law they switch multiplies psi_i_dot, so the motion does
    not see them: alpha and v_r are compared at every sample."""
    rig = RIG.replace(e=0.7 * RIG.r_c, L_us=0.2)
    scene = camdyn.Scene(damping="D", friction="coulomb", motion="oscillating")
    a, b = _both(scene, camdyn.Oscillating(math.pi, 40), rig=rig, t_end=0.41, sample_rate_Hz=50_000, **TIGHT)
    assert any(s.after.endswith("_stick") for s in a.switches)
    assert a.outcome == b.outcome

    def friction(res):
        return [s for s in res.switches if s.surface != "loading"]

    def sliding(names):  # the friction part of a regime name: fwd, bwd or stick
        return [str(n).rsplit("_", 1)[-1] for n in names]
    fa, fb = friction(a), friction(b)
    assert [(s.surface, sliding([s.before, s.after])) for s in fa] == \
        [(s.surface, sliding([s.before, s.after])) for s in fb]
    np.testing.assert_allclose([s.t for s in fb], [s.t for s in fa], rtol=0, atol=1e-7)
    assert sliding(a.regime) == sliding(b.regime)
    np.testing.assert_allclose(b.alpha, a.alpha, rtol=0, atol=1e-9)
    np.testing.assert_allclose(b.v_r, a.v_r, rtol=0, atol=1e-9)


def test_energy_ledger_agrees_with_scipy():
    """The compiled ledger (Gauss-Legendre quadrature of the flows on the dense output) and the
    SciPy one (three extra states) give the same works, and each balances the energy.

    Bounds, relative to the largest work, measured at rtol 1e-10: 6e-10 at the end of the
    revolution, after the impacts (bound 1e-8); 1.2e-8 at samples inside an impact, where
    the flows are kilowatts for microseconds and the backends' 1e-10 rad state difference is
    amplified as in F_n (bound 1e-7, as _assert_agree's 1e-5 on F_n is for forces); each
    backend's balance 2e-11 of the largest work (bound 1e-9)."""
    scene = camdyn.Scene(damping="D", friction="coulomb")
    a, b = _both(scene, camdyn.ConstantSpeed(1200), revolutions=1, sample_rate_Hz=5000, energy_ledger=True, **TIGHT)
    _assert_agree(a, b)
    for name in ("work_in", "dissipated_contact", "dissipated_friction"):
        scale = np.abs(a.outputs[name]).max()
        assert scale > 0
        assert abs(b.outputs[name][-1] - a.outputs[name][-1]) < 1e-8 * scale
        np.testing.assert_allclose(b.outputs[name], a.outputs[name], rtol=0, atol=1e-7 * scale)
    balance = b.energy - b.energy[0] - (b.work_in - b.dissipated_contact - b.dissipated_friction)
    assert np.abs(balance).max() < 1e-9 * np.abs(b.work_in).max()


# --- trap 1: the gap as a difference of nearly equal angles --------------------------------
def test_gap_is_well_conditioned_against_a_50_digit_oracle():
    """Eq. 6 as printed subtracts nearly equal terms near the surface (psi_i ~ 1e-12 m out of
    terms ~ 1e-2 m): in doubles it keeps ~4 digits.  The compiled surface (the generated,
    half-angle form) must match a 50-digit evaluation of Eq. 6 to ~1e-16 m."""
    scene = camdyn.Scene(damping="D", friction="coulomb")
    m = Model(RIG, scene, camdyn.ConstantSpeed(300))
    _, surface = scene_functions(m.kernels)
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
        worst_kernel = max(worst_kernel, abs(surface(0, t, alpha, 0.0, m.p) - float(exact)))
        worst_naive = max(worst_naive, abs(naive - float(exact)))
    assert worst_kernel < 1e-17
    assert worst_naive > 100 * worst_kernel  # the trap is real


# --- trap 2: a whole micro-hop inside one step ---------------------------------------------
@numba.cfunc(SIGNATURE)
def _toy_rhs(r, t, a, ad, p):
    """Regime 0: free, constant upward acceleration p0; regime 1: contact, p0 - p1 a.
    NaN above p2 in contact (a law undefined there: a stage overshooting into it)."""
    if r == 1 and a > p[2]:
        return math.nan
    return p[0] if r == 0 else p[0] - p[1] * a


@numba.cfunc(SIGNATURE)
def _toy_gap(k, t, a, ad, p):
    return a


@numba.cfunc(SIGNATURE)
def _toy_rate(j, t, a, ad, p):
    return ad if j == 0 else math.nan


def _toy_run(y0, t_end, interior, p=(1.0, 1e4, math.inf), rtol=1e-8, max_step=math.inf, rate_check=False):
    """The engine on the toy: regimes free (0) and contact (1), the gap alpha, its rate alpha_dot."""
    tab = (np.array([[0], [1]], dtype=np.int64), np.array([-1], dtype=np.int64),
           np.array([-1, 0, 1], dtype=np.int64), np.array([-1, -1], dtype=np.int64))
    t_eval = np.linspace(0, t_end, 11)
    fset = np.array([rtol, 1e-12, max_step, 1e-14, 1e9, 1e-9, 0.0])
    iset = np.array([interior, 10_000, 20, rate_check, 0, -1], dtype=np.int64)
    out_y, out_r = np.empty((2, 11)), np.empty(11, dtype=np.int64)
    fns = (_toy_rhs, _toy_gap, _toy_rate, _toy_rate)
    return engine.run(fns, arrays(DOP853), np.array(p), tab, 2, -1, 0.0, t_end,
                      np.array(y0, dtype=float), t_eval, fset, iset, out_y, out_r)


def test_micro_hop_inside_one_step_is_caught_by_interior_points():
    """Free flight on an exact parabola alpha = 0.5 - 1.01 t + t^2/2 (zero local error, so steps
    grow tenfold up to max_step = 1 s) dips below the surface between t = 0.868 and 1.152 and
    comes back: both ends of the step over it are above it.  Three interior samples (0.25 s
    apart, closer than the dip is wide) find the contact, at the exact root; without them it
    is missed -- the trap the interior points exist for."""
    root = 1.01 - math.sqrt(1.01**2 - 1)
    missed = _toy_run((0.5, -1.01), 4.0, interior=0, max_step=1.0)
    caught = _toy_run((0.5, -1.01), 4.0, interior=3, max_step=1.0)
    assert missed[0] == engine.SUCCESS and missed[2].shape[0] == 0
    assert caught[0] == engine.SUCCESS and caught[2].shape[0] >= 2
    assert caught[2][0, 0] == pytest.approx(root, abs=1e-12)
    assert caught[2][0, 2:4].tolist() == [0, 1]  # free -> contact


def test_micro_hop_between_samples_is_caught_by_the_gap_rate():
    """The same dip with no interior points: both ends of the step over it are above the
    surface, so only the gap rate, which turns from approaching to leaving inside the step,
    can find it -- and does, at the exact root, as the SciPy backend does
    (camdyn.events._hidden_excursion)."""
    root = 1.01 - math.sqrt(1.01**2 - 1)
    missed = _toy_run((0.5, -1.01), 4.0, interior=0, max_step=1.0)
    caught = _toy_run((0.5, -1.01), 4.0, interior=0, max_step=1.0, rate_check=True)
    assert missed[2].shape[0] == 0
    assert caught[0] == engine.SUCCESS and caught[2].shape[0] >= 2
    assert caught[2][0, 0] == pytest.approx(root, abs=1e-12)
    assert caught[2][0, 2:4].tolist() == [0, 1]


@pytest.mark.parametrize("cubic, most", [((1e-2, 0.5e-2, 0.3e-2), 10), ((3e-2, -2e-2, 1e-2), 10),
                                          ((0.0, 0.0, 1.0), 20)])
def test_root_is_located_superlinearly_on_the_far_side(cubic, most):
    """engine's locate on a step's interpolant: the toy gap is alpha(theta) = -1e-6 + h theta
    (q0 + q1 theta + q2 theta^2) over a step of h = 1e-4 s.  The root is returned on the far
    side, within xtol = 1e-14 s of the root (found by 200 bisections), in few evaluations:
    bisection alone needs log2(1e-4 / 1e-14) = 33.  Simple roots: <= 10 (8 measured); a
    strongly curved gap (theta^3, where false position is slowest): <= 20 (16 measured)."""
    from camdyn.compiled.events import locate
    tab = (np.array([[0], [1]], dtype=np.int64), np.array([-1], dtype=np.int64),
           np.array([-1, 0, 1], dtype=np.int64), np.array([-1, -1], dtype=np.int64))
    fns = (_toy_rhs, _toy_gap, _toy_rate, _toy_rate)
    h, y0 = 1e-4, -1e-6
    Q = np.zeros((2, 7))
    Q[0, :3] = cubic

    def gap(theta):
        return y0 + h * theta * (cubic[0] + cubic[1] * theta + cubic[2] * theta ** 2)
    t, evaluations = locate(fns, tab, 2, 1, 0, 0.0, h, y0, 0.0, Q, np.zeros(3), 0.0, h, y0, gap(1.0), 1e-14)
    lo, hi = 0.0, 1.0
    for _ in range(200):
        lo, hi = (0.5 * (lo + hi), hi) if gap(0.5 * (lo + hi)) < 0 else (lo, 0.5 * (lo + hi))
    assert gap(t / h) >= 0.0  # far side
    assert abs(t - hi * h) <= 1e-14
    assert evaluations <= most


# --- trap 3: ping-pong when restarting exactly on the surface ------------------------------
@pytest.mark.parametrize("alpha_dot, first", [(5.0, "free"), (-5.0, None)])
def test_start_exactly_on_the_surface_does_not_ping_pong(alpha_dot, first):
    """gap = 0 exactly at the start: moving away separates at once and stays free; moving in
    enters contact and bounces.  No switch re-triggers at its own restart point."""
    scene = camdyn.Scene(damping="D", friction="none")
    kw = dict(speed_rpm=0.0, t_end=0.004, y0=(RIG.alpha0, alpha_dot), sample_rate_Hz=100_000, **TIGHT)
    a, b = _both(scene, None, **kw)
    _assert_agree(a, b)
    if first:
        assert np.all(b.regime == first) and np.all(b.F_n == 0)
    else:
        assert b.regime[0] != "free" and b.separations().size >= 1
    times = np.array([s.t for s in b.switches])
    same = [(x.surface == y.surface) for x, y in zip(b.switches, b.switches[1:])]
    assert not any(s and dt < 1e-12 for s, dt in zip(same, np.diff(times)))


def test_every_switch_restarts_on_the_far_side_of_its_surface():
    scene = camdyn.Scene(damping="D", friction="coulomb")
    b = camdyn.simulate(RIG, scene, speed_rpm=1100, revolutions=1, backend="compiled", **TIGHT)
    m = Model(RIG, scene, camdyn.ConstantSpeed(1100))
    K = m.kernels
    assert b.ok and b.impacts().size > 3
    for s in b.switches:
        k = K.FLAGS.index(s.surface)
        g = K.surface_index(k, s.t, s.alpha, s.alpha_dot, m.p)
        key_after = next(key for key, name in K.REGIMES.items() if name == s.after)
        sign = K.FLAG_SURFACES[s.surface][1]
        if key_after[k] is not None:  # the new regime's side of this surface, or on it
            assert g * sign >= 0 if key_after[k] else g * sign <= 0


# --- trap 4: Hertz (-psi_i)^1.5 when a stage overshoots ------------------------------------
def test_point_contact_force_is_finite_and_continuous_beyond_the_surface():
    """A stage of a step that leaves contact evaluates the contact law at psi_i > 0: a naive
    (-psi_i)**1.5 is NaN (or complex) there.  The compiled contact regimes are finite and
    continuous across psi_i = 0."""
    scene = camdyn.Scene(contact="point", damping="D", friction="coulomb")
    m = Model(RIG, scene, camdyn.ConstantSpeed(300))
    rhs, surface = scene_functions(m.kernels)
    names = m.kernels.REGIME_NAMES
    a0 = RIG.alpha0
    for r, name in enumerate(names):
        if name == "free":
            continue
        values = [rhs(r, 0.0, a0 + d, 0.0, m.p) for d in (-1e-12, 0.0, 1e-12, 1e-5)]
        assert all(math.isfinite(v) for v in values), name
        assert values[0] == pytest.approx(values[2], rel=1e-8)
    assert isinstance((-1e-6) ** 1.5, complex)  # what the naive form would give


def test_nan_in_a_stage_is_rejected_and_retried_smaller():
    """Toy contact law undefined above alpha = 0.02: big steps in contact overshoot there; the
    engine rejects them (instead of failing or propagating NaN) and still finishes."""
    out = _toy_run((0.0, -0.5), 0.5, interior=3, p=(1.0, 1e2, 0.02), rtol=1e-6)
    assert out[0] == engine.SUCCESS
    clean = _toy_run((0.0, -0.5), 0.5, interior=3, p=(1.0, 1e2, math.inf), rtol=1e-6)
    assert out[3][2] > clean[3][2]  # more rejected steps
    assert out[2].shape[0] == clean[2].shape[0]


def test_point_contact_impacting_runs_compiled():
    scene = camdyn.Scene(contact="point", damping="D", friction="coulomb")
    a, b = _both(scene, camdyn.ConstantSpeed(1300), t_end=0.05, sample_rate_Hz=10_000, **TIGHT)
    assert b.ok and b.impacts().size > 2
    _assert_agree(a, b)


# --- trap 5: the D/E switch at maximum compression in permanent contact --------------------
def test_D_switch_in_permanent_contact_does_not_chatter():
    """At 300 rev/min the follower slides without impacts; psi_i_dot crosses 0 twice per
    contact-mode period.  Each crossing is one switch: same switches as SciPy, none closer
    than a microsecond to the previous one, no CHATTER."""
    scene = camdyn.Scene(damping="D", friction="none")
    a, b = _both(scene, camdyn.ConstantSpeed(300), revolutions=1, sample_rate_Hz=5000, **TIGHT)
    assert b.ok and b.impacts().size == 0
    loading = np.array([s.t for s in b.switches if s.surface == "loading"])
    assert loading.size > 20 and np.diff(loading).min() > 1e-6
    # late crossings are near-tangential (the contact mode has decayed): time ~ dpsi / psi_ddot
    _assert_agree(a, b, alpha_tol=1e-7, t_tol=1e-5)


def test_D_switch_at_rest_on_the_surface():
    """Cam at rest at the static equilibrium: psi_i_dot = 0 exactly, the D/E surface itself.
    Rounding-level motion may cross it, but the run must not chatter (no progress in time)
    and the follower must stay at alpha* (the force is continuous across the switch)."""
    scene = camdyn.Scene(damping="D", friction="none")
    b = camdyn.simulate(RIG, scene, speed_rpm=0.0, t_end=0.02, backend="compiled", **TIGHT)
    assert b.ok
    assert np.abs(b.alpha - b.alpha_star).max() < 1e-12
    assert len(b.switches) < 4 * 0.02 * 2200  # at most a few per contact-mode period


# --- bad input, parameters as arrays, disk cache -------------------------------------------
def test_bad_input_names_the_parameter():
    scene = camdyn.Scene(damping="D", friction="coulomb")
    with pytest.raises(ParameterError, match="backend"):
        camdyn.simulate(RIG, scene, speed_rpm=300, t_end=0.01, backend="numba")
    with pytest.raises(ParameterError, match="method"):
        camdyn.simulate(RIG, scene, speed_rpm=300, t_end=0.01, backend="compiled", method="Radau")


def test_user_motion_points_to_the_scipy_backend():
    scene = camdyn.Scene(damping="D", friction="tanh", motion="user")
    with pytest.raises(SceneError, match="backend='scipy'"):
        camdyn.simulate(RIG, scene, cam_for(scene, 300), t_end=0.01, backend="compiled")


def test_one_compiled_loop_for_every_scene_rig_and_speed():
    """Parameters travel as arrays and kernels as typed function values: running other scenes,
    rigs and speeds adds no compiled specialisation of the loop."""
    for slug, speed, k_s in [("line_d_coulomb_constant_nonlinear", 300, 2000.0),
                             ("line_d_coulomb_constant_nonlinear", 1200, 3000.0),
                             ("point_d_coulomb_constant_nonlinear", 500, 2500.0),
                             ("line_d_coulomb_constant_linear_paper", 300, 2000.0)]:
        r = camdyn.simulate(RIG.replace(k_s=k_s), scene_from_slug(slug), speed_rpm=speed, t_end=0.005,
                            backend="compiled")
        assert r.ok
    assert len(engine.run.signatures) == 1


def test_warm_start_loads_the_compiled_loop_from_the_disk_cache():
    code = ("import camdyn\nfrom camdyn.compiled import engine\n"
            "r = camdyn.simulate(camdyn.example_rig(), camdyn.Scene(), speed_rpm=300, t_end=0.002, backend='compiled')\n"
            "assert r.ok\nprint(sum(engine.run.stats.cache_hits.values()), sum(engine.run.stats.cache_misses.values()))")
    subprocess.run([sys.executable, "-c", code], capture_output=True, text=True, check=True)  # fills the cache
    out = subprocess.run([sys.executable, "-c", code], capture_output=True, text=True, check=True)
    hits, misses = map(int, out.stdout.split())
    assert (hits, misses) == (1, 0)


def test_cache_is_dropped_when_any_module_of_the_loop_changes(tmp_path):
    """numba checks only a function's own file: an edit of events.py would leave engine.run's
    stale machine code in use.  cache.refresh drops the package's cache files when the hash
    of its sources changes, and only then."""
    from camdyn.compiled import cache
    pkg, store = tmp_path / "pkg", tmp_path / "store"
    pkg.mkdir()
    (pkg / "a.py").write_text("x = 1\n")
    store.mkdir()
    files = [store / "a.f-1.py311.nbi", store / "a.f-1.py311.0.nbc"]
    for f in files:
        f.write_text("cached")
    (store / "a.cpython-311.pyc").write_text("bytecode")
    assert cache.refresh(store, pkg)          # no stamp yet: dropped
    assert not any(f.exists() for f in files) and (store / "a.cpython-311.pyc").exists()
    for f in files:
        f.write_text("cached")
    assert not cache.refresh(store, pkg)      # same sources: kept
    assert all(f.exists() for f in files)
    (pkg / "b.py").write_text("y = 2\n")   # another module of the package changed
    assert cache.refresh(store, pkg)
    assert not any(f.exists() for f in files)
    assert cache.cache_dir_of(engine.run) is not None  # numba's locator is still where we look


def test_tables_encode_the_generated_regimes():
    K = camdyn.Scene(damping="D", friction="coulomb").kernels()
    flags_of, signs, lookup, partner = tables(K)
    nr = len(K.REGIME_NAMES)
    assert flags_of.shape == (2 * nr, len(K.FLAGS))  # Coulomb: a stick mode per regime
    for key, name in K.REGIMES.items():
        r = K.REGIME_NAMES.index(name)
        assert [None if v < 0 else bool(v) for v in flags_of[r]] == list(key)
        code = sum((v + 1) * 3 ** k for k, v in enumerate(flags_of[r]))
        assert lookup[code] == r
        if key[-1] is not None:  # the partner flips the forward flag only
            assert K.REGIME_NAMES[partner[r]] == K.REGIMES[key[:-1] + (not key[-1],)]
        if key[-1]:
            assert flags_of[nr + r, -1] == regimes.STICK and list(flags_of[nr + r, :-1]) == list(flags_of[r, :-1])
        code = sum((v + 1) * 3**k for k, v in enumerate(flags_of[r]))
        assert lookup[code] == r
    assert signs.tolist() == [K.FLAG_SURFACES[f][1] for f in K.FLAGS]
