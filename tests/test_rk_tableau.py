"""The engine's Runge-Kutta core against SciPy and against the mathematics.

Same coefficients as SciPy's RK45 and DOP853; the tableau refuses a corrupted coefficient;
on a smooth problem the compiled stepper takes SciPy's steps (same times, same RHS count);
the measured order of convergence of the step and of the dense output is the method's.
"""
from __future__ import annotations

import dataclasses
import math

import numba
import numpy as np
import pytest
from scipy.integrate import DOP853 as SciDOP853
from scipy.integrate import RK45 as SciRK45
from scipy.integrate._ivp import dop853_coefficients as sci853

from camdyn.engine import stepper, tableau
from camdyn.engine.config import PI_CONTROL, SCIPY_CONTROL
from camdyn.engine.kernels import RHS
from camdyn.engine.problem import Kernels, Problem
from camdyn.engine.tables import tables
from toy import BOUNCE, settings

METHODS = {"RK45": SciRK45, "DOP853": SciDOP853}


# --- a smooth test problem: damped Duffing oscillator, alpha'' = -p0 alpha - p1 alpha^3 - p2 alpha'
@numba.cfunc(RHS)
def duffing(m, t, a, ad, p):
    p[3] += 1.0  # counts evaluations in the caller's array (no global state)
    return -p[0] * a - p[1] * a ** 3 - p[2] * ad


def _duffing_py(t, y, p=(4.0, 1.0, 0.1)):
    return np.array([y[1], -p[0] * y[0] - p[1] * y[0] ** 3 - p[2] * y[1]])


def _problem(p) -> Problem:
    """The Duffing oscillator as a one-mode problem (the toy automaton's tables are not used)."""
    return Problem(Kernels(duffing, duffing, duffing, duffing), tables(BOUNCE), np.asarray(p, dtype=float))


@numba.njit
def _adaptive(prob, method, cfg, t0, t_end, y0, y1, times):
    """Drive stepper.accepted_step like SciPy's solver loop; records the accepted times."""
    K = np.empty((method.n_rows, 2))
    K[0, 0], K[0, 1] = y1, prob.kernels.rhs(0, t0, y0, y1, prob.p)
    h = stepper.initial_step(prob.kernels.rhs, prob.p, 0, t0, y0, y1, K[0, 1], t_end, method, cfg)
    t, n, nfev, err = t0, 0, 2, stepper.ERR_FLOOR
    while t < t_end:
        r = stepper.accepted_step(prob.kernels.rhs, prob.p, 0, t, y0, y1, h, t_end, method, K, cfg, err)
        t, y0, y1, h, err = r.t, r.y0, r.y1, r.h_next, r.err
        nfev += r.nfev
        times[n] = t
        n += 1
        K[0, 0], K[0, 1] = K[method.n_stages, 0], K[method.n_stages, 1]
    return n, nfev, y0, y1


@numba.njit
def _fixed(prob, method, h, n_steps, y0, y1, theta):
    """n_steps fixed steps of size h; returns the end state and the interpolant at theta of the last step."""
    K = np.empty((method.n_rows, 2))
    Q = np.empty((2, method.degree))
    t = 0.0
    d0 = d1 = 0.0
    for _ in range(n_steps):
        K[0, 0], K[0, 1] = y1, prob.kernels.rhs(0, t, y0, y1, prob.p)
        n0, n1 = stepper.attempt(prob.kernels.rhs, prob.p, 0, t, y0, y1, h, method, K)
        stepper.dense_coefficients(prob.kernels.rhs, prob.p, 0, t, y0, y1, h, method, K, Q)
        d0, d1 = stepper.dense_eval(t + theta * h, t, h, y0, y1, Q)
        t, y0, y1 = t + h, n0, n1
    return y0, y1, d0, d1


def test_rk45_coefficients_are_scipys():
    tab = tableau.DOPRI5
    np.testing.assert_array_equal(np.array(tab.c), SciRK45.C)
    np.testing.assert_array_equal(np.array(tab.a)[:, :5], SciRK45.A)
    np.testing.assert_array_equal(np.array(tab.b), SciRK45.B)
    np.testing.assert_array_equal(np.array(tab.e), SciRK45.E)
    np.testing.assert_array_equal(np.array(tab.dense), SciRK45.P)


def test_dop853_coefficients_are_scipys():
    tab = tableau.DOP853
    n = sci853.N_STAGES
    np.testing.assert_array_equal(np.array(tab.c), sci853.C[:n])
    np.testing.assert_array_equal(np.array(tab.a), sci853.A[:n, :n])
    np.testing.assert_array_equal(np.array(tab.b), sci853.B)
    np.testing.assert_array_equal(np.array(tab.e), sci853.E5)
    np.testing.assert_array_equal(np.array(tab.e3), sci853.E3)
    np.testing.assert_array_equal(np.array(tab.a_extra), sci853.A[n + 1:])
    np.testing.assert_array_equal(np.array(tab.c_extra), sci853.C[n + 1:])


def test_dop853_power_form_interpolant_equals_scipys_nested_form():
    """The P matrix re-expresses SciPy's Dop853DenseOutput exactly (to rounding)."""
    from scipy.integrate._ivp.rk import Dop853DenseOutput
    rng = np.random.default_rng(1)
    K = rng.normal(size=(16, 2))
    h, y_old = 0.3, np.array([0.2, -1.0])
    b = np.array(sci853.B)
    dy = h * K[:12].T @ b
    F = np.empty((7, 2))
    F[0], F[1], F[2] = dy, h * K[0] - dy, 2 * dy - h * (K[0] + K[12])
    F[3:] = h * sci853.D @ K
    ref = Dop853DenseOutput(0.0, h, y_old, F)
    P = np.array(tableau.DOP853.dense)
    for x in np.linspace(0, 1, 11):
        ours = y_old + h * (K.T @ P) @ x ** np.arange(1, 8)
        np.testing.assert_allclose(ours, ref(x * h), rtol=1e-13, atol=1e-14)


@pytest.mark.parametrize("name", ["RK45", "DOP853"])
@pytest.mark.parametrize("field, index", [("b", 2), ("a", (3, 1)), ("e", 0), ("dense", (2, 1))])
def test_a_corrupted_coefficient_is_refused(name, field, index):
    tab = tableau.TABLEAUS[name]
    value = [list(r) if isinstance(r, tuple) else r for r in getattr(tab, field)]
    if isinstance(index, tuple):
        value[index[0]][index[1]] += 1e-6  # additive: zeros matter too
        value = tuple(tuple(r) for r in value)
    else:
        value[index] += 1e-6
        value = tuple(value)
    with pytest.raises(tableau.TableauError):
        dataclasses.replace(tab, **{field: value})


@pytest.mark.parametrize("name", ["RK45", "DOP853"])
@pytest.mark.parametrize("rtol", [1e-4, 1e-6, 1e-8])
def test_same_steps_and_evaluations_as_scipy_on_a_smooth_problem(name, rtol):
    """Same number of accepted steps and RHS evaluations as SciPy's solver, at the same times
    to 1e-6 (relative).  Not bitwise: the error estimate is a sum with heavy cancellation, and
    on the first, tiny steps it sits near the rounding floor, so NumPy's summation order vs
    ours moves err ** (-1/(q+1)) in the 7th-10th digit."""
    atol, t_end, y0 = rtol, 10.0, (1.0, 0.0)
    solver = METHODS[name](lambda t, y: _duffing_py(t, y), 0.0, np.array(y0), t_end, rtol=rtol, atol=atol)
    ref = []
    while solver.status == "running":
        solver.step()
        ref.append(solver.t)
    prob = _problem([4.0, 1.0, 0.1, 0.0])
    times = np.empty(100_000)
    n, nfev, a, ad = _adaptive(prob, tableau.arrays(tableau.TABLEAUS[name]), settings(rtol=rtol, atol=atol), 0.0,
                               t_end, *y0, times)
    assert n == len(ref) > 10
    np.testing.assert_allclose(times[:n], ref, rtol=1e-6, atol=0)
    np.testing.assert_allclose([a, ad], solver.y, rtol=0, atol=10 * rtol)
    assert nfev == solver.nfev == prob.p[3]  # the stepper's count, SciPy's, and the calls counted by the RHS


@pytest.mark.parametrize("name, order, dense_order", [("RK45", 5, 4), ("DOP853", 8, 7)])
def test_measured_order_of_convergence(name, order, dense_order):
    """Harmonic oscillator (p1 = p2 = 0), exact solution cos(2t): the global error of fixed
    steps falls as h^order, the interpolant's local error at mid-step as h^(dense_order+1)."""
    method = tableau.arrays(tableau.TABLEAUS[name])
    prob = _problem([4.0, 0.0, 0.0, 0.0])
    T = 1.0
    hs = [T / 8, T / 16] if name == "DOP853" else [T / 32, T / 64]
    glob, local = [], []
    for h in hs:
        a, _, _, _ = _fixed(prob, method, h, int(round(T / h)), 1.0, 0.0, 0.5)
        glob.append(abs(a - math.cos(2 * T)))
        _, _, d, _ = _fixed(prob, method, 4 * h, 1, 1.0, 0.0, 0.5)  # one step, interpolant at 2h
        local.append(abs(d - math.cos(2 * 2 * h)))
    assert math.log2(glob[0] / glob[1]) == pytest.approx(order, abs=0.35)
    assert math.log2(local[0] / local[1]) >= dense_order + 1 - 0.35


@pytest.mark.parametrize("t", [0.0, 1.0, -1.0, 2.0, -2.0, 0.5, -0.5, 3.0, -4.0, 1e-310, -1e-310, 5e-324, 1e300,
                               -1e300, 0.1, -0.1, 123.456])
def test_spacing_is_numpys_distance_to_the_next_float(t):
    """The step-size floor's unit (stepper.spacing, from frexp) is np.nextafter(t, inf) - t exactly."""
    assert stepper.spacing(t) == np.nextafter(t, np.inf) - t


SCIPY, PI = SCIPY_CONTROL[1:], PI_CONTROL[1:]      # (a, b): the factors' coefficients


# --- the step-size controllers (engine.config.StepControl) ------------------------------------------------
@pytest.mark.parametrize("err, err_prev, rejected", [(0.43, 0.2, 0), (1e-3, 0.5, 0), (0.9, 1e-4, 0), (0.3, 0.3, 1)])
def test_scipy_control_is_scipys_formula_and_pi_reads_the_previous_error(err, err_prev, rejected):
    """SciPy's controller ignores the previous error (bitwise the formula of scipy's
    RungeKutta._step_impl); the PI controller multiplies err^(-0.7/k) by err_prev^(0.4/k)."""
    exponent = -1 / 8
    scipy_factor = min(stepper.MAX_FACTOR, stepper.SAFETY * err ** exponent)
    if rejected:
        scipy_factor = min(1.0, scipy_factor)
    assert stepper.accepted_factor(err, err_prev, rejected, exponent, *SCIPY) == scipy_factor
    pi = min(stepper.MAX_FACTOR, stepper.SAFETY * err ** (-0.7 / 8) * err_prev ** (0.4 / 8))
    assert stepper.accepted_factor(err, err_prev, rejected, exponent, *PI) == pytest.approx(
        min(1.0, pi) if rejected else pi, rel=1e-15)


def test_a_step_after_a_dip_of_the_error_grows_less_under_pi():
    """After err_prev = 0.4, a step whose estimate dips to 1e-3 (an erratic estimate) grows the
    next step 2.1x under SciPy's controller and 1.6x under PI; err 0 grows it MAX_FACTOR."""
    scipy_f = stepper.accepted_factor(1e-3, 0.4, 0, -1 / 8, *SCIPY)
    pi_f = stepper.accepted_factor(1e-3, 0.4, 0, -1 / 8, *PI)
    assert 1.0 < pi_f < scipy_f
    assert stepper.accepted_factor(0.0, 0.4, 0, -1 / 8, *PI) == stepper.MAX_FACTOR
    assert stepper.rejected_factor(float("nan"), -1 / 8) == stepper.MIN_FACTOR
