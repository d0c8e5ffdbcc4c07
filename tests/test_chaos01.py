"""The 0-1 test for chaos (Gottwald & Melbourne 2004, 2009): K near 0 for regular series, near 1
for chaotic ones, on textbook maps and on the cam-follower's Poincare section.

Tolerances: K converges to its limit 0 or 1 as the series grows, with finite-N deviations that
GM 2009 (Sec. 4, their Figs. 3-5) show to be a few hundredths at N ~ 10^3 for the logistic map.
Measured here with 5 seeds each (rng and start): logistic r = 3.97, N = 2000: K = 0.998-0.999;
period-8 logistic (r = 3.55): K <= 0.002; sin(n) and sin(n) + sin(sqrt(2) n): K <= 0.001;
N = 500 scatters more (period-8: up to 0.11).  The bounds K > 0.95 and K < 0.05 leave a margin
of 20x the measured scatter at N = 2000 and still separate the two verdicts.
"""
from __future__ import annotations

import math

import numpy as np
import pytest

import camdyn
from camdyn.analysis.chaos01 import _mean_square_displacement, zero_one_test
from camdyn.errors import ParameterError

N = 2000


def logistic(r, n, x0=0.3, transient=1000):
    x, out = x0, np.empty(n)
    for i in range(transient + n):
        x = r * x * (1 - x)
        if i >= transient:
            out[i - transient] = x
    return out


@pytest.mark.parametrize("seed", [0, 1, 2])
def test_logistic_map_at_3_97_is_chaotic(seed):
    assert zero_one_test(logistic(3.97, N, x0=0.1 + 0.1 * seed), rng=seed) > 0.95


@pytest.mark.parametrize("series", [logistic(3.55, N),                       # period 8
                                    np.sin(np.arange(1, N + 1)),             # periodic in a continuous sense
                                    np.sin(np.arange(1, N + 1)) + np.sin(math.sqrt(2) * np.arange(1, N + 1))],
                         ids=["logistic-period-8", "sin", "quasi-periodic"])
def test_regular_series_give_k_near_zero(series):
    assert zero_one_test(series, rng=0) < 0.05


def test_a_seed_makes_k_reproducible_and_c_matters():
    x = logistic(3.7, 500)
    assert zero_one_test(x, rng=7) == zero_one_test(x, rng=np.random.default_rng(7))
    assert zero_one_test(x, rng=7, n_c=3) != zero_one_test(x, rng=8, n_c=3)


def test_mean_square_displacement_by_fft_equals_the_direct_sum():
    rng = np.random.default_rng(1)
    z = np.cumsum(rng.normal(size=300) + 1j * rng.normal(size=300))
    direct = np.array([np.mean(np.abs(z[k:] - z[:-k]) ** 2) for k in range(1, 31)])
    # the FFT's rounding: ~eps * log2(N) * |z|^2 / M; measured 7e-14
    np.testing.assert_allclose(_mean_square_displacement(z, 30), direct, rtol=1e-10)


def test_a_constant_series_is_regular_within_its_resolution():
    noisy = 0.3 + 1e-12 * np.random.default_rng(0).normal(size=N)       # a fixed point plus noise
    # without a resolution the noise is taken for dynamics: K = 0.19 measured, above the regular
    # bound 0.05 of this file (neither verdict: pure noise with a large mean gives K in 0.2-0.6)
    assert zero_one_test(noisy, rng=0) > 0.05
    assert zero_one_test(noisy, rng=0, resolution=1e-9) == 0.0
    assert zero_one_test(np.full(N, 0.3), rng=0) == 0.0


@pytest.mark.parametrize("kw, name", [(dict(series=np.ones(50)), "series"), (dict(series=np.ones((20, 20))), "series"),
                                      (dict(series=[np.nan] * 200), "series"), (dict(series="abc"), "series"),
                                      (dict(n_c=0), "n_c"), (dict(rng=-1), "rng"), (dict(rng="x"), "rng"),
                                      (dict(resolution=-1.0), "resolution")])
def test_bad_input_names_the_parameter(kw, name):
    args = {"series": np.sin(np.arange(200)), **kw}
    with pytest.raises(ParameterError, match=name):
        zero_one_test(args.pop("series"), **args)


def test_the_chaotic_cam_follower_of_test_chaos_has_k_near_one():
    """tests/test_chaos.py's chaotic case (reference-experiment rig, damping D and Coulomb
    friction, 196 rev/min); alpha at t = k T after 100 revolutions of transient, 500 values
    (measured K = 0.998 over 3 seeds; about 1 s)."""
    rig = camdyn.load_rig("reference-experiment")
    scene = camdyn.Scene(contact="line", damping="D", friction="coulomb")
    T = 60.0 / 196.0
    r = camdyn.simulate(rig, scene, speed_rpm=196.0, revolutions=600, sample_rate_Hz=1.0 / T, rtol=1e-9, atol=1e-12)
    assert r.ok, r.outcome.message
    assert zero_one_test(r.alpha[100:], rng=0) > 0.95


def test_a_periodic_cam_follower_section_has_k_zero():
    """The example rig's stable period-1 orbit at 1500 rev/min (tests/test_orbits.py): the
    section settles to a constant within the solver's noise (measured spread 5e-12 rad after
    200 revolutions); with the resolution 1e-9 rad (10x rtol x the motion's 0.08 rad, rounded up)
    K = 0, and without it the noise alone gave 0.23."""
    T = 60.0 / 1500.0
    r = camdyn.simulate(camdyn.example_rig(), camdyn.Scene(contact="line", damping="D", friction="coulomb"),
                        speed_rpm=1500.0, revolutions=400, sample_rate_Hz=1.0 / T, rtol=1e-10, atol=1e-13)
    assert r.ok, r.outcome.message
    assert zero_one_test(r.alpha[200:], rng=0, resolution=1e-9) == 0.0
