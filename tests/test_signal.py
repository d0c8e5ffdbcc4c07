"""Tests of camdyn.analysis.signal."""
import math

import numpy as np
import pytest

from camdyn.analysis.signal import (frequency_resolution, harmonics, is_uniform, peak_frequency, peak_to_peak, rms,
                                    sample_rate, spectrum, whole_periods, noise_floor)

FS = 1000.0  # Hz
N = 1024
T = np.arange(N) / FS
DF = FS / N  # bin spacing


def _sine(amplitude, f_Hz, phase=0.3, t=T):
    return amplitude * np.sin(2 * np.pi * f_Hz * t + phase)


# --------------------------------------------------------------------------- rms, p2p
def test_rms_known_values():
    assert rms([3.0, 4.0]) == pytest.approx(math.sqrt(12.5), rel=1e-15)
    assert rms([-2.0, -2.0, -2.0]) == pytest.approx(2.0, rel=1e-15)
    assert rms([-2.0, -2.0, -2.0], remove_mean=True) == 0.0


def test_rms_of_sinusoid_over_whole_periods():
    x = _sine(3.0, 40 * DF)  # 40 whole periods in the record
    assert rms(x) == pytest.approx(3.0 / math.sqrt(2), rel=1e-12)
    assert rms(x + 5.0, remove_mean=True) == pytest.approx(3.0 / math.sqrt(2), rel=1e-12)
    assert rms(x + 5.0) == pytest.approx(math.sqrt(25.0 + 4.5), rel=1e-12)


def test_peak_to_peak_known_values():
    assert peak_to_peak([-2.0, 5.0, 1.0]) == 7.0
    assert peak_to_peak([4.0]) == 0.0


@pytest.mark.parametrize("func", [rms, peak_to_peak])
def test_rms_p2p_reject_nan(func):
    with pytest.raises(ValueError, match="x"):
        func([1.0, math.nan])


# --------------------------------------------------------------------------- sampling
def test_uniform_grid_and_rate():
    assert is_uniform(T)
    assert sample_rate(T) == pytest.approx(FS, rel=1e-12)
    assert frequency_resolution(T) == pytest.approx(DF, rel=1e-12)


def test_uniform_grid_far_from_origin():
    # Time values of order 1e4 s with 1 us steps: the steps themselves carry
    # rounding of eps*|t|/dt ~ 2e-6 relative, far above rtol, yet t is uniform.
    t = 1e4 + np.arange(100) * 1e-6
    assert is_uniform(t)
    assert sample_rate(t) == pytest.approx(1e6, rel=1e-6)


@pytest.mark.parametrize(
    "t",
    [
        np.array([0.0, 0.1, 0.2, 0.31, 0.4]),
        np.array([0.0, 0.2, 0.1, 0.3]),
        np.array([0.0, 0.0, 0.0]),
        np.array([1.0]),
        np.array([0.0, 0.1, np.nan]),
    ],
    ids=["jitter", "unsorted", "constant", "single", "nan"],
)
def test_non_uniform_t(t):
    assert not is_uniform(t)
    with pytest.raises(ValueError, match=r"\bt\b"):
        sample_rate(t)


# --------------------------------------------------------------------------- spectrum
def test_spectrum_frequencies():
    f, a = spectrum(T, _sine(1.0, 100 * DF))
    assert f.shape == a.shape == (N // 2 + 1,)
    np.testing.assert_allclose(f, np.arange(N // 2 + 1) * DF, rtol=1e-12)


def test_bin_centre_amplitude_rect():
    f, a = spectrum(T, _sine(1.7, 100 * DF), window="rect")
    k = int(np.argmax(a))
    assert f[k] == pytest.approx(100 * DF, rel=1e-12)
    assert abs(a[k] - 1.7) <= 1e-12


def test_bin_centre_amplitude_hann_coherent_gain():
    # Without the coherent-gain correction (sum(w) = N/2) the peak would be 0.85.
    f, a = spectrum(T, _sine(1.7, 100 * DF), window="hann")
    assert abs(a.max() - 1.7) <= 1e-3
    assert f[np.argmax(a)] == pytest.approx(100 * DF, rel=1e-12)


def test_dc_and_linear_detrend():
    x = 2.0 + 0.5 * T + _sine(1.0, 64 * DF)
    _, kept = spectrum(T, x, window="rect", detrend=None)
    _, removed = spectrum(T, x, window="rect", detrend="linear")
    assert kept[0] > 2.0
    assert removed[0] < 1e-12
    # The fitted line also absorbs the sine's small correlation with t.
    assert removed[64] == pytest.approx(1.0, rel=1e-3)


def test_dc_and_nyquist_bins_not_doubled():
    # A constant c and an alternating c*(-1)^n are their own amplitudes.
    _, a = spectrum(T, np.full(N, 0.7) + 0.2 * (-1.0) ** np.arange(N), window="rect", detrend=None)
    assert a[0] == pytest.approx(0.7, rel=1e-12)
    assert a[-1] == pytest.approx(0.2, rel=1e-12)


def test_zero_padding_refines_grid_and_keeps_amplitude():
    f, a = spectrum(T, _sine(1.0, 100 * DF), window="hann", pad_to=4 * N)
    assert f[1] == pytest.approx(DF / 4, rel=1e-12)
    assert a.max() == pytest.approx(1.0, abs=1e-3)


@pytest.mark.parametrize("offset", [-0.43, -0.25, 0.1, 0.31, 0.5])
def test_off_bin_peak_frequency_interpolated(offset):
    # Log-parabolic interpolation is exact only for Gaussian peaks; for the
    # Hann main lobe its bias is <= ~0.016 bin, so 0.05 bin is a safe bound
    # that still fails for the uninterpolated bin frequency (error >= 0.1 bin).
    f_true = (100 + offset) * DF
    f, a = spectrum(T, _sine(1.0, f_true))
    assert abs(peak_frequency(f, a) - f_true) <= 0.05 * DF
    assert peak_frequency(f, a, interpolate=False) == f[np.argmax(a)]


def test_peak_frequency_band_limits():
    x = _sine(2.0, 50 * DF) + _sine(0.5, 200.3 * DF)
    f, a = spectrum(T, x)
    assert peak_frequency(f, a) == pytest.approx(50 * DF, abs=0.05 * DF)
    assert peak_frequency(f, a, fmin=150.0) == pytest.approx(200.3 * DF, abs=0.05 * DF)
    with pytest.raises(ValueError, match="fmin"):
        peak_frequency(f, a, fmin=600.0)


def test_spectrum_non_uniform_t_raises():
    t = T.copy()
    t[10] += 0.3 / FS
    with pytest.raises(ValueError, match=r"\bt\b"):
        spectrum(t, _sine(1.0, 100 * DF, t=t))


@pytest.mark.parametrize("bad", ["x", "t"])
def test_spectrum_nan_raises(bad):
    t, x = T.copy(), _sine(1.0, 100 * DF)
    {"x": x, "t": t}[bad][5] = np.nan
    with pytest.raises(ValueError, match=rf"\b{bad}\b.*finite"):
        spectrum(t, x)


@pytest.mark.parametrize(
    "kwargs, match",
    [
        ({"t": T[:7], "x": np.zeros(7)}, "at least 8"),
        ({"t": T, "x": np.zeros(N - 1)}, "same length"),
        ({"window": "hamming"}, "window"),
        ({"detrend": "quadratic"}, "detrend"),
        ({"pad_to": N - 1}, "pad_to"),
    ],
)
def test_spectrum_argument_validation(kwargs, match):
    args = {"t": T, "x": np.zeros(N), **kwargs}
    with pytest.raises(ValueError, match=match):
        spectrum(args.pop("t"), args.pop("x"), **args)


# --------------------------------------------------------------------------- harmonics
def test_harmonics():
    np.testing.assert_allclose(harmonics(12.5, 50.0), [12.5, 25.0, 37.5, 50.0])
    np.testing.assert_allclose(harmonics(0.1, 0.3), [0.1, 0.2, 0.3])  # 0.3/0.1 < 3 in floats
    assert harmonics(10.0, 5.0).size == 0
    with pytest.raises(ValueError, match="fundamental_Hz"):
        harmonics(0.0, 5.0)


# --------------------------------------------------------------------------- whole periods
@pytest.mark.parametrize("samples_per_period", [80.0, 272.7272727, 545.4545454])
def test_whole_periods_after_a_transient_keeps_every_period(samples_per_period):
    """4 periods sampled, 1 skipped: 3 periods are kept (to within one sample when a period is not
    a whole number of samples), not 2 (issue 14, G)."""
    fs, period = 5000.0, samples_per_period / 5000.0
    t = np.arange(int(np.floor(4 * period * fs + 1e-9)) + 1) / fs
    keep = whole_periods(t, period, 1)
    kept = keep.sum() / fs / period
    assert abs(kept - 3) <= 1 / samples_per_period + 1e-9
    assert t[keep][0] == pytest.approx(period, abs=1 / fs)
    assert whole_periods(t, period).sum() / fs / period == pytest.approx(4, abs=1 / samples_per_period + 1e-9)


def test_whole_periods_without_a_period_keeps_what_follows_the_skip():
    t = np.arange(100) / 100.0
    assert whole_periods(t, math.inf).all()
    assert whole_periods(t, 5.0, 0).all()  # longer than the record


def test_noise_floor_is_the_median_level():
    f, amp = spectrum(T, _sine(1.0, 100 * DF) + 1e-9 * np.random.default_rng(1).standard_normal(N))
    level = noise_floor(amp)
    assert 1e-12 < level < 1e-9  # the noise, far below the line at 1
    assert amp.max() > 1e8 * level
