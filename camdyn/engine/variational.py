"""The tangent dynamics' augmented system (x, Phi, integral of the divergence) between two
switches, integrated by the engine's Runge-Kutta pair, compiled (numba).

The system: x' = (alpha_dot, alpha_ddot), Phi' = J Phi with J = [[0, 1], [a_alpha,
a_alpha_dot]] from the generated ``jacobian``, and the divergence a_alpha_dot integrated
(:mod:`camdyn.orbits.tangent` explains its use).  The step is the loop's (:mod:`.stepper`: its error
norms, first-step guesses, controller and smallest step, called here), with the stages summed
over the augmented state's N_AUGMENTED components.  At the segment's start the Jacobian is taken
LOOK_AHEAD along the motion (the limit from inside the segment: a segment starting on a surface
may start on a kink of the law).
"""
from __future__ import annotations

from typing import NamedTuple

import numpy as np
from numba import njit
from scipy.integrate import solve_ivp

from ..vocabulary import JAC_D_ALPHA, JAC_D_ALPHA_DOT, STATE, STATE_ALPHA, STATE_ALPHA_DOT
from . import cache
from .config import LOOK_AHEAD
from .jit import jitable
from .kernels import compiled_jacobian, compiled_kernels
from .tableau import method_of
from .stepper import ERR_FLOOR, accepted_factor, blended, first_guess, min_step, rejected_factor, rms, second_guess

cache.install()

#: the augmented state's rows: x in the vocabulary's STATE order, then Phi row by row
#: (Phi[i, j] at PHI_START + 2 i + j), then the integral of the divergence
AUG_ALPHA, AUG_ALPHA_DOT = STATE_ALPHA, STATE_ALPHA_DOT
PHI_START = len(STATE)
AUG_PHI = slice(PHI_START, PHI_START + 4)
AUG_DIVERGENCE = PHI_START + 4
N_AUGMENTED = AUG_DIVERGENCE + 1


@jitable
def fill_augmented(ad, add, jac, y, out):
    """out = the augmented field at y, given x' = (ad, add) and the Jacobian's second row ``jac``
    (JACOBIAN order): Phi' = [[0, 1], [a_alpha, a_alpha_dot]] Phi, column by column, and the
    divergence a_alpha_dot.  Compiled into :func:`augmented_field`; run as Python by camdyn.orbits.tangent."""
    j0, j1 = jac[JAC_D_ALPHA], jac[JAC_D_ALPHA_DOT]
    out[AUG_ALPHA], out[AUG_ALPHA_DOT] = ad, add
    for k in range(2):
        top, bottom = y[PHI_START + k], y[PHI_START + 2 + k]
        out[PHI_START + k] = bottom
        out[PHI_START + 2 + k] = j0 * top + j1 * bottom
    out[AUG_DIVERGENCE] = j1


@njit(cache=True, error_model="numpy")
def augmented_field(rhs, jacobian, p, m, t, y, t_start, look_ahead, jac, out):
    """out = the augmented field at (t, y) in mode m (see the module docstring)."""
    a, ad = y[AUG_ALPHA], y[AUG_ALPHA_DOT]
    add = rhs(m, t, a, ad, p)
    if t == t_start:
        jacobian(m, t + look_ahead, a + look_ahead * ad, ad + look_ahead * add, p, jac)
    else:
        jacobian(m, t, a, ad, p, jac)
    fill_augmented(ad, add, jac, y, out)


@njit(cache=True, error_model="numpy")
def _norm(v):
    return rms(np.sum(v * v), v.shape[0])


@njit(cache=True, error_model="numpy")
def _initial_step(rhs, jacobian, p, m, t, y, f0, t_end, rtol, atol, exponent, look_ahead, jac, work):
    """The first step (:func:`~camdyn.engine.stepper.first_guess`, :func:`~camdyn.engine.stepper.second_guess`)."""
    scale = atol + np.abs(y) * rtol
    d1 = _norm(f0 / scale)
    h0 = min(first_guess(_norm(y / scale), d1), t_end - t)
    if h0 == 0.0:
        return 0.0
    augmented_field(rhs, jacobian, p, m, t + h0, y + h0 * f0, t, look_ahead, jac, work)
    h1 = second_guess(h0, d1, _norm((work - f0) / scale) / h0, exponent)
    return min(100.0 * h0, h1, t_end - t)


@njit(cache=True, error_model="numpy")
def _error(K, h, y, y_new, rtol, atol, method):
    """The attempt's error norm (:func:`~camdyn.engine.stepper.error_norm` over N_AUGMENTED
    components), summed component by component in the order NumPy's array expressions take."""
    coef, e, e3 = method.coef, method.e_row, method.e3_row
    s5, s3 = 0.0, 0.0
    for i in range(N_AUGMENTED):
        scale = atol[i] + np.maximum(abs(y[i]), abs(y_new[i])) * rtol
        a5, a3 = 0.0, 0.0
        for j in range(method.n_stages + 1):
            a5 += coef[e, j] * K[j, i]
            a3 += coef[e3, j] * K[j, i]
        if method.error_kind == 0:
            x = a5 * h / scale
            s5 += x * x
        else:
            s5 += (a5 / scale) ** 2
            s3 += (a3 / scale) ** 2
    if method.error_kind == 0:
        return rms(s5, N_AUGMENTED)
    return blended(s5, s3, h, N_AUGMENTED)


@njit(cache=True, error_model="numpy")
def _stages(rhs, jacobian, p, m, t, t0, y, h, method, look_ahead, K, z, jac):
    """The stages of one attempt of size h into K[1..n_stages] (the last, at the attempt's end,
    the FSAL stage), z the state of the last: the solution."""
    coef, n = method.coef, method.n_stages
    for s in range(1, n + 1):
        for i in range(N_AUGMENTED):
            v = y[i]
            for j in range(s):
                v += (h * coef[s, j]) * K[j, i]
            z[i] = v
        augmented_field(rhs, jacobian, p, m, t + coef[method.c_row, s] * h, z, t0, look_ahead, jac, K[s])


@njit(cache=True, nogil=True, error_model="numpy")   # nogil: the grazing curve runs it beside other runs
def integrate_segment(rhs, jacobian, p, m, t0, t_end, y, rtol, atol, method, look_ahead, control):
    """y (N_AUGMENTED) at t_end from y at t0 in mode m, the step size set by ``control`` (a
    :class:`~camdyn.engine.config.StepControl`); returns (y, ok)."""
    n = method.n_stages
    K = np.empty((n + 1, N_AUGMENTED))
    jac, z, y_new = np.empty(2), np.empty(N_AUGMENTED), np.empty(N_AUGMENTED)
    y = y.copy()
    t = t0
    augmented_field(rhs, jacobian, p, m, t, y, t0, look_ahead, jac, K[0])
    h_abs = _initial_step(rhs, jacobian, p, m, t, y, K[0].copy(), t_end, rtol, atol, method.exponent,
                          look_ahead, jac, z)
    err_prev = ERR_FLOOR
    while t < t_end:
        rejected = False
        while True:
            if h_abs < min_step(t):
                return y, False
            t_new = min(t + h_abs, t_end)
            h = t_new - t
            _stages(rhs, jacobian, p, m, t, t0, y, h, method, look_ahead, K, y_new, jac)
            err = _error(K, h, y, y_new, rtol, atol, method)
            if err < 1.0:
                h_abs = h * accepted_factor(err, err_prev, rejected, method.exponent, control.a, control.b)
                err_prev = max(err, ERR_FLOOR)
                break
            h_abs = h * rejected_factor(err, method.exponent)
            rejected = True
        t = t_new
        for i in range(N_AUGMENTED):
            y[i] = y_new[i]
            K[0, i] = K[n, i]
    return y, True


class Augmented(NamedTuple):
    """The augmented state, by name: x = (alpha, alpha_dot), Phi (2 x 2) and the integral of the
    field's divergence d(alpha_ddot)/d(alpha_dot)."""

    x: np.ndarray
    phi: np.ndarray
    divergence: float

    def packed(self) -> np.ndarray:
        """The rows of :func:`integrate_segment`'s y (AUG_* indices)."""
        return np.concatenate([self.x, self.phi.ravel(), [self.divergence]])

    @staticmethod
    def unpacked(y: np.ndarray) -> "Augmented":
        return Augmented(y[[AUG_ALPHA, AUG_ALPHA_DOT]], y[AUG_PHI].reshape(2, 2), float(y[AUG_DIVERGENCE]))

    def finite(self) -> bool:
        return bool(np.all(np.isfinite(self.x)) and np.all(np.isfinite(self.phi)) and np.isfinite(self.divergence))


def augmented_flow(model, m: int, t0: float, t1: float, start: Augmented, rtol: float, atol: float, control,
                   compiled: bool) -> tuple[Augmented, bool, str]:
    """The augmented state at t1 from ``start`` at t0 in mode m of ``model``: (state, ok, why not).
    ``atol`` scales with the size of Phi at the start for its entries; ``compiled``: by
    :func:`integrate_segment` with ``control`` (a StepControl), else by SciPy's DOP853 over the
    Python kernels."""
    y0 = start.packed()
    tol = atol * np.concatenate([[1.0, 1.0], np.full(4, max(1.0, np.max(np.abs(start.phi)))), [1.0]])
    if compiled:
        K = model.kernels
        y, ok = integrate_segment(compiled_kernels(K, outputs=False).rhs, compiled_jacobian(K), model.p, m, t0, t1, y0,
                                  rtol, tol, method_of("DOP853"), LOOK_AHEAD, control)
        return Augmented.unpacked(y), bool(ok), "the step size fell below the spacing of t"
    sol = solve_ivp(_python_field(model, m, t0), (t0, t1), y0, method="DOP853", rtol=rtol, atol=tol)
    return Augmented.unpacked(sol.y[:, -1]), bool(sol.success), sol.message


def frozen_step(model, m: int, t: float, a: Augmented, gap: float) -> Augmented:
    """``a`` carried over ``gap`` seconds with the Jacobian frozen at (t, a.x): one Euler step of
    Phi and the divergence, x kept (the engine's recorded state restarts it after)."""
    jac = np.array(model.jacobian(m, t, float(a.x[0]), float(a.x[1])))
    y = a.packed()
    slope = np.empty(N_AUGMENTED)
    fill_augmented(0.0, 0.0, jac, y, slope)
    y[AUG_PHI] += gap * slope[AUG_PHI]
    y[AUG_DIVERGENCE] += gap * slope[AUG_DIVERGENCE]
    return Augmented.unpacked(y)


def _python_field(model, m: int, t_start: float):
    """The augmented field in mode m for SciPy (the Python kernels).  At the segment's start the
    Jacobian is its limit from inside the segment, taken LOOK_AHEAD along the motion as the
    rules do: a segment that starts on a surface may start on a kink of the law (the impact
    damping's abs(psi_i) at first contact, whose generated derivative is 0 at psi_i = 0), and a
    first stage with the kink's value would stall the step-size control."""
    def f(t, y):
        a, ad = y[AUG_ALPHA], y[AUG_ALPHA_DOT]
        add = model.rhs(m, t, a, ad)
        if t == t_start:
            d = LOOK_AHEAD
            jac = np.array(model.jacobian(m, t + d, a + d * ad, ad + d * add))
        else:
            jac = np.array(model.jacobian(m, t, a, ad))
        out = np.empty(N_AUGMENTED)
        fill_augmented(ad, add, jac, y, out)
        return out
    return f
