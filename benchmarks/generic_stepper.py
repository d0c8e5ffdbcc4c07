"""Why the loop keeps a 2-component stepper: a stepper over state arrays of any size, against it.

    python benchmarks/generic_stepper.py [--rounds N]

The stepper of camdyn's loop (:mod:`camdyn.engine.stepper`) holds the state (alpha, alpha_dot)
in two scalars; the tangent dynamics' augmented state has 7 components.  The obvious unification
is one stepper over arrays, the state size a compile-time constant of its closure (numba unrolls
nothing for it, but the loops are short).  This script runs both on the same problem (DOP853,
SciPy's controller, the sliding scene's contact mode from the static equilibrium plus 1e-6 rad,
at +300 rev/min on the example rig, 0.05 s, rtol 1e-8), checks that they give the same bits,
and prints the time of each, the minimum of interleaved rounds, and their ratio.
"""
from __future__ import annotations

import argparse
import time
import warnings

import numpy as np
from numba import njit

import camdyn
from camdyn.engine import stepper as S
from camdyn.engine.config import SolverOptions, settings
from camdyn.engine.kernels import compiled_kernels
from camdyn.engine.tableau import method_of
from camdyn.model.model import Model


@njit
def scalar_run(rhs, p, m, t, y0, y1, t_end, method, cfg):
    """The engine's stepper, accepted step after accepted step in one mode."""
    K = np.empty((method.n_rows, 2))
    K[0, 0], K[0, 1] = y1, rhs(m, t, y0, y1, p)
    h = S.initial_step(rhs, p, m, t, y0, y1, K[0, 1], t_end, method, cfg)
    err_prev, n, steps = S.ERR_FLOOR, method.n_stages, 0
    while t < t_end:
        r = S.accepted_step(rhs, p, m, t, y0, y1, h, t_end, method, K, cfg, err_prev)
        if r.status != S.ACCEPTED:
            break
        t, y0, y1, h, err_prev = r.t, r.y0, r.y1, r.h_next, r.err
        steps += 1
        K[0, 0], K[0, 1] = K[n, 0], K[n, 1]
    return t, y0, y1, steps


def _stages(N: int):
    """The field and one step's stages over a state array of N components (N a constant of the
    closure), the sums in the scalar stepper's order (so the bits can match)."""
    @njit
    def field(rhs, p, m, t, y, K, row):
        K[row, 0] = y[1]
        K[row, 1] = rhs(m, t, y[0], y[1], p)

    @njit
    def attempt(rhs, p, m, t, y, h, method, K, y_new, z, d):
        coef, b, n = method.coef, method.b_row, method.n_stages
        for s in range(1, n):
            for i in range(N):
                d[i] = 0.0
            for j in range(s):
                a = coef[s, j]
                for i in range(N):
                    d[i] += K[j, i] * a
            for i in range(N):
                z[i] = y[i] + d[i] * h
            field(rhs, p, m, t + coef[method.c_row, s] * h, z, K, s)
        for i in range(N):
            d[i] = 0.0
        for j in range(n):
            for i in range(N):
                d[i] += K[j, i] * coef[b, j]
        for i in range(N):
            y_new[i] = y[i] + h * d[i]
        field(rhs, p, m, t + h, y_new, K, n)
    return field, attempt


def _error_norm(N: int):
    """SciPy's DOP853 error norm over N components."""
    @njit
    def error_norm(K, h, y, y_new, rtol, atol, method):
        coef, n = method.coef, method.n_stages
        s5 = 0.0
        s3 = 0.0
        for i in range(N):
            scale = atol + max(abs(y[i]), abs(y_new[i])) * rtol
            a = 0.0
            b = 0.0
            for j in range(n + 1):
                a += K[j, i] * coef[method.e_row, j]
            for j in range(n + 1):
                b += K[j, i] * coef[method.e3_row, j]
            s5 += (a / scale) ** 2
            s3 += (b / scale) ** 2
        return S.blended(s5, s3, h, float(N))
    return error_norm


def generic(N: int):
    """The engine's step over a state array of N components: accepted step after accepted step
    in one mode, as :func:`scalar_run`."""
    field, attempt = _stages(N)
    error_norm = _error_norm(N)

    @njit
    def run(rhs, p, m, t, y0, y1, t_end, method, cfg):
        K = np.empty((method.n_rows, N))
        y, y_new, z, d = np.empty(N), np.empty(N), np.empty(N), np.empty(N)
        y[0], y[1] = y0, y1
        field(rhs, p, m, t, y, K, 0)
        h_abs = S.initial_step(rhs, p, m, t, y0, y1, K[0, 1], t_end, method, cfg)
        err_prev, n, steps = S.ERR_FLOOR, method.n_stages, 0
        while t < t_end:
            rejected = 0
            while True:
                t_new = min(t + h_abs, t_end)
                h = t_new - t
                h_abs = abs(h)
                attempt(rhs, p, m, t, y, h, method, K, y_new, z, d)
                err = error_norm(K, h, y, y_new, cfg.rtol, cfg.atol, method)
                if err < 1.0:
                    h_abs *= S.accepted_factor(err, err_prev, rejected, method.exponent, cfg.control_a, cfg.control_b)
                    err_prev = max(err, S.ERR_FLOOR)
                    break
                h_abs *= S.rejected_factor(err, method.exponent)
                rejected += 1
            t = t_new
            for i in range(N):
                y[i] = y_new[i]
                K[0, i] = K[n, i]
            steps += 1
        return t, y[0], y[1], steps
    return run


def main() -> None:
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("--rounds", type=int, default=15)
    rounds = parser.parse_args().rounds
    warnings.filterwarnings("ignore", category=camdyn.CompileNotice)
    rig, scene = camdyn.example_rig(), camdyn.Scene(damping="D", friction="coulomb")
    model = Model(rig, scene, camdyn.ConstantSpeed(300.0))
    modes = model.kernels.MODES
    m = next(i for i, name in enumerate(modes) if name.startswith("contact"))
    cfg = settings(SolverOptions(rtol=1e-8, atol=1e-12, step_control="scipy"), model.equilibrium.vartheta)
    args = (compiled_kernels(model.kernels, outputs=False).rhs, np.ascontiguousarray(model.p, dtype=float), m, 0.0,
            model.equilibrium.alpha + 1e-6, 0.0, 0.05, method_of("DOP853"), cfg)
    arrays = generic(2)
    a, b = scalar_run(*args), arrays(*args)
    times = {"scalar": [], "arrays": []}
    for _ in range(rounds):
        for name, run in (("scalar", scalar_run), ("arrays", arrays)):
            t0 = time.perf_counter()
            run(*args)
            times[name].append(time.perf_counter() - t0)
    best = {k: min(v) for k, v in times.items()}
    print(f"mode {modes[m]!r}: {a[3]} steps; the same bits: {a == b}")
    print(f"scalar stepper {best['scalar'] * 1e3:.3f} ms, array stepper {best['arrays'] * 1e3:.3f} ms "
          f"(minimum of {rounds} interleaved rounds): {best['arrays'] / best['scalar']:.2f} x")


if __name__ == "__main__":
    main()
