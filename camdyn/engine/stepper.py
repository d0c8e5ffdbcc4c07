"""The explicit Runge-Kutta step with dense output: SciPy's algorithm, one source for the
compiled and the interpreted loop (:mod:`camdyn.engine.jit`).

**The rules of a step, written once** for every state size: the error estimate's norm
(:func:`rms`, and DOP853's blend of its 5th- and 3rd-order estimates, :func:`blended`), the
first step's two guesses (:func:`first_guess`, :func:`second_guess`: SciPy's
``select_initial_step``), the factors of the step-size controller (a
:class:`~camdyn.engine.config.StepControl`: SciPy's integral controller or the PI controller)
after an accepted and a rejected attempt (:func:`accepted_factor`, :func:`rejected_factor`), and the smallest step
(:func:`min_step`).  The loop's 2-component state (below) and the tangent dynamics' augmented
state (:mod:`.variational`) each sum their stages in their own arithmetic and call these.  (A
stepper over state arrays of any size, one function for both, gives the loop's runs the same
bits but takes 1.6-1.7 times as long per step on its 2-component state: python
benchmarks/generic_stepper.py.)

The loop's state is ``y = (alpha, alpha_dot)`` and the ODE ``y' = (alpha_dot, rhs(m, t,
alpha, alpha_dot, p))`` in mode m (the generated kernel, a numba ``cfunc`` when compiled).  The
split is SciPy's ``RungeKutta``: :func:`attempt` computes one attempt (stages and solution),
:func:`error_norm` its error, and :func:`accepted_step` does the bookkeeping (accept or reject,
the next step size) as ``RungeKutta._step_impl`` does, so on a smooth problem the steps are
SciPy's; or, with the PI controller, the next step size also reads the previous accepted step's
error.  :func:`dense_coefficients` and :func:`dense_eval` are the interpolant (``RkDenseOutput``
/ ``Dop853DenseOutput`` in power form).  The method is a :class:`~camdyn.engine.tableau.Method`;
the stage buffer ``K`` has one row per stage, the FSAL stage and the interpolant's extra stages.

One deliberate difference from SciPy: an attempt whose error is not finite (a stage that
overshot into a region where a law is undefined) is rejected and retried with a step five
times smaller, instead of poisoning the step size with NaN.
"""
from __future__ import annotations

import math
from typing import NamedTuple

from .jit import jitable

SAFETY = 0.9
MIN_FACTOR = 0.2
MAX_FACTOR = 10.0


#: the previous error a run's first step reads, and the least one any step passes on (Hairer's
#: DOPRI codes' FACOLD): a tiny estimate does not unleash the next step's growth
ERR_FLOOR = 1e-4

#: accepted_step() status codes
ACCEPTED, TOO_SMALL = 0, 1


class StepResult(NamedTuple):
    """What :func:`accepted_step` returns (a named tuple: numba builds it as a plain struct)."""

    status: int          # ACCEPTED, or TOO_SMALL (the step size fell below min_step; nothing changed)
    t: float             # the step's end
    y0: float            # the state there
    y1: float
    h_next: float        # the next step's size
    nfev: int            # RHS evaluations spent, rejected attempts included
    rejected: int        # rejected attempts
    err: float           # the accepted attempt's error for the next step (at least ERR_FLOOR)


@jitable
def rms(sum_of_squares, n):
    """SciPy's RMS norm of an n-vector from the sum of its squares."""
    return math.sqrt(sum_of_squares / n)


@jitable
def blended(e5, e3, h, n):
    """DOP853's error norm (SciPy's ``_estimate_error_norm``) from the sums of the squared,
    scaled 5th- and 3rd-order estimates over n components."""
    if e5 == 0.0 and e3 == 0.0:
        return 0.0
    return abs(h) * e5 / math.sqrt((e5 + 0.01 * e3) * n)


@jitable
def first_guess(d0, d1):
    """The first trial step of SciPy's ``select_initial_step`` (Hairer, Norsett & Wanner II.4)
    from the scaled norms of the state (d0) and of its rate (d1); 0 where the rate overflows."""
    h0 = 1e-6 if (d0 < 1e-5 or d1 < 1e-5) else 0.01 * d0 / d1
    return h0 if h0 > 0.0 else 0.0


@jitable
def second_guess(h0, d1, d2, exponent):
    """The step from the rate's change over the first trial step (d2, scaled, per second), as
    ``select_initial_step`` takes it; the caller bounds it by 100 h0 and the span."""
    if d1 <= 1e-15 and d2 <= 1e-15:
        return max(1e-6, h0 * 1e-3)
    return (0.01 / max(d1, d2)) ** (-exponent)


@jitable
def min_step(t):
    """The smallest step at time t, SciPy's: 10 times the spacing of the floats there."""
    return 10.0 * spacing(t)


@jitable
def _norm(x0, x1):
    """The RMS norm of a 2-vector."""
    return rms(x0 * x0 + x1 * x1, 2.0)


@jitable
def spacing(t):
    """np.nextafter(t, inf) - t, SciPy's unit of the smallest step, from frexp (a NumPy ufunc
    costs a second of the compiled loop's first compile)."""
    if t == 0.0:
        return 5e-324
    m, e = math.frexp(t)
    if m == -0.5:  # t < 0 a power of two: the next float towards +inf is half as far
        e -= 1
    return max(math.ldexp(1.0, e - 53), 5e-324)


@jitable
def stages(rhs, p, m, t, y0, y1, h, coef, c_row, K, first, last):
    """Fill K[first:last] with the stages f(t + c_s h, y + h sum_j a_sj K_j) (K[0] = f(t, y));
    a_sj = coef[s, j], c_s = coef[c_row, s] (a :class:`~camdyn.engine.tableau.Method`'s)."""
    for s in range(first, last):
        d0 = 0.0
        d1 = 0.0
        for j in range(s):
            a = coef[s, j]
            d0 += K[j, 0] * a
            d1 += K[j, 1] * a
        z1 = y1 + d1 * h
        K[s, 0] = z1
        K[s, 1] = rhs(m, t + coef[c_row, s] * h, y0 + d0 * h, z1, p)


@jitable
def attempt(rhs, p, m, t, y0, y1, h, method, K):
    """One attempt of size h: stages, y_new and the FSAL stage f(t + h, y_new) in K[n_stages]."""
    coef, b, n = method.coef, method.b_row, method.n_stages
    stages(rhs, p, m, t, y0, y1, h, coef, method.c_row, K, 1, n)
    d0 = 0.0
    d1 = 0.0
    for j in range(n):
        d0 += K[j, 0] * coef[b, j]
        d1 += K[j, 1] * coef[b, j]
    n0 = y0 + h * d0
    n1 = y1 + h * d1
    K[n, 0] = n1
    K[n, 1] = rhs(m, t + h, n0, n1, p)
    return n0, n1


@jitable
def error_norm(K, h, y0, y1, n0, n1, rtol, atol, method):
    """SciPy's error norm of the attempt (RK45: embedded difference; DOP853: 5th/3rd blend)."""
    coef, e, e3, n = method.coef, method.e_row, method.e3_row, method.n_stages
    s0 = atol + max(abs(y0), abs(n0)) * rtol
    s1 = atol + max(abs(y1), abs(n1)) * rtol
    e0 = 0.0
    e1 = 0.0
    for j in range(n + 1):
        e0 += K[j, 0] * coef[e, j]
        e1 += K[j, 1] * coef[e, j]
    if method.error_kind == 0:
        x0, x1 = e0 * h / s0, e1 * h / s1
        return rms(x0 * x0 + x1 * x1, 2.0)
    f0 = 0.0
    f1 = 0.0
    for j in range(n + 1):
        f0 += K[j, 0] * coef[e3, j]
        f1 += K[j, 1] * coef[e3, j]
    return blended((e0 / s0) ** 2 + (e1 / s1) ** 2, (f0 / s0) ** 2 + (f1 / s1) ** 2, h, 2.0)


@jitable
def accepted_factor(err, err_prev, rejected, exponent, a, b):
    """The next step size over the accepted one's: SAFETY err^(a exponent) err_prev^(-b exponent)
    (CONTROLS; b = 0: SciPy's), at most MAX_FACTOR, and at most 1 right after a rejection."""
    if err == 0.0:
        factor = MAX_FACTOR
    else:
        factor = SAFETY * err ** (a * exponent)
        if b != 0.0:
            factor *= err_prev ** (-b * exponent)
        factor = min(MAX_FACTOR, factor)
    return min(1.0, factor) if rejected else factor


@jitable
def rejected_factor(err, exponent):
    """The retry's step size over the rejected attempt's (SciPy's; NaN or inf: a stage left the
    domain of a law, retry five times smaller)."""
    if math.isfinite(err):
        return max(MIN_FACTOR, SAFETY * err ** exponent)
    return MIN_FACTOR


@jitable
def accepted_step(rhs, p, m, t, y0, y1, h_abs, t_bound, method, K, cfg, err_prev):
    """One accepted step from (t, y) towards t_bound, K[0] = f(t, y) on entry; ``err_prev``: the
    previous accepted step's error (ERR_FLOOR at a run's start), read by the PI controller.

    Returns a :class:`StepResult`; K then holds the accepted attempt's stages with f(t_new,
    y_new) in row n_stages.
    """
    exponent = method.exponent
    smallest = min_step(t)
    if h_abs > cfg.max_step:
        h_abs = cfg.max_step
    elif h_abs < smallest:
        h_abs = smallest
    nfev = 0
    rejected = 0
    while True:
        if h_abs < smallest:
            return StepResult(TOO_SMALL, t, y0, y1, h_abs, nfev, rejected, err_prev)
        t_new = t + h_abs
        if t_new - t_bound > 0:
            t_new = t_bound
        h = t_new - t
        h_abs = abs(h)
        n0, n1 = attempt(rhs, p, m, t, y0, y1, h, method, K)
        nfev += method.n_stages
        err = error_norm(K, h, y0, y1, n0, n1, cfg.rtol, cfg.atol, method)
        if err < 1.0:
            factor = accepted_factor(err, err_prev, rejected, exponent, cfg.control_a, cfg.control_b)
            return StepResult(ACCEPTED, t_new, n0, n1, h_abs * factor, nfev, rejected, max(err, ERR_FLOOR))
        h_abs *= rejected_factor(err, exponent)
        rejected += 1


@jitable
def initial_step(rhs, p, m, t, y0, y1, f1, t_bound, method, cfg):
    """SciPy's ``select_initial_step`` (Hairer, Norsett & Wanner II.4), one RHS evaluation."""
    length = abs(t_bound - t)
    if length == 0.0:
        return 0.0
    rtol, atol = cfg.rtol, cfg.atol
    s0 = atol + abs(y0) * rtol
    s1 = atol + abs(y1) * rtol
    d1 = _norm(y1 / s0, f1 / s1)
    h0 = first_guess(_norm(y0 / s0, y1 / s1), d1)
    if h0 == 0.0:  # an overflowing field (d1 = inf or NaN): SciPy's estimate is 0 too
        return 0.0
    h0 = min(h0, length)
    z0 = y0 + h0 * y1
    z1 = y1 + h0 * f1
    g1 = rhs(m, t + h0, z0, z1, p)
    d2 = _norm((z1 - y1) / s0, (g1 - f1) / s1) / h0
    h1 = second_guess(h0, d1, d2, method.exponent)
    return min(100.0 * h0, h1, length, cfg.max_step)


@jitable
def dense_coefficients(rhs, p, m, t, y0, y1, h, method, K, Q):
    """Q = K^T P after computing the extra stages (DOP853): y(t + theta h) = y + h theta (Q0 + Q1 theta + ...).

    Returns the number of RHS evaluations spent (the extra stages)."""
    coef, n, n_extra, p0 = method.coef, method.n_stages, method.n_extra, method.p_row
    if n_extra:
        stages(rhs, p, m, t, y0, y1, h, coef, method.c_row, K, n + 1, n + 1 + n_extra)
    for k in range(method.degree):
        q0 = 0.0
        q1 = 0.0
        for j in range(method.n_rows):
            q0 += K[j, 0] * coef[p0 + j, k]
            q1 += K[j, 1] * coef[p0 + j, k]
        Q[0, k] = q0
        Q[1, k] = q1
    return n_extra


@jitable
def dense_eval(tt, t, h, y0, y1, Q):
    """The interpolant at time tt of the step [t, t + h] (Horner in theta)."""
    theta = (tt - t) / h
    deg = Q.shape[1]
    v0 = Q[0, deg - 1]
    v1 = Q[1, deg - 1]
    for k in range(deg - 2, -1, -1):
        v0 = v0 * theta + Q[0, k]
        v1 = v1 * theta + Q[1, k]
    return y0 + h * theta * v0, y1 + h * theta * v1
