"""Signal processing of simulation results (NumPy only).

Units are SI; frequencies are in Hz unless a name ends in ``_rad``. Spectra
assume uniformly sampled, real signals.
"""
from __future__ import annotations

import numpy as np

from .._checks import is_integer

__all__ = [
    "rms",
    "peak_to_peak",
    "is_uniform",
    "sample_rate",
    "frequency_resolution",
    "spectrum",
    "peak_frequency",
    "harmonics",
    "whole_periods",
    "noise_floor",
]

_EPS = float(np.finfo(float).eps)
_WINDOWS = ("hann", "rect")
_DETRENDS = ("mean", "linear", None)


def _vector(x, name: str, min_len: int = 1) -> np.ndarray:
    """``x`` as a finite 1-D float array of at least ``min_len`` samples."""
    a = np.asarray(x, dtype=float)
    if a.ndim != 1 or a.size < min_len:
        raise ValueError(f"{name} must be 1-D with at least {min_len} samples, got shape {a.shape}")
    if not np.all(np.isfinite(a)):
        raise ValueError(f"{name} must be finite (contains NaN or inf)")
    return a


def rms(x, *, remove_mean: bool = False) -> float:
    """Root mean square of ``x``; of its fluctuation about the mean if ``remove_mean``."""
    a = _vector(x, "x")
    if remove_mean:
        a = a - a.mean()
    return float(np.sqrt(np.mean(a * a)))


def peak_to_peak(x) -> float:
    """``max(x) - min(x)``."""
    return float(np.ptp(_vector(x, "x")))


def is_uniform(t, rtol: float = 1e-9) -> bool:
    """Whether ``t`` is strictly increasing with a constant step.

    Every step may differ from the mean step by ``rtol * dt`` plus the rounding
    of the time values themselves (``4 * eps * max|t|``), so a grid built as
    ``t0 + k * dt`` far from ``t = 0`` still counts as uniform.
    """
    a = np.asarray(t, dtype=float)
    if a.ndim != 1 or a.size < 2 or not np.all(np.isfinite(a)):
        return False
    dt = (a[-1] - a[0]) / (a.size - 1)
    if not dt > 0:
        return False
    slack = rtol * dt + 4 * _EPS * np.max(np.abs(a))
    return bool(np.all(np.abs(np.diff(a) - dt) <= slack))


def _step(t) -> tuple[np.ndarray, float]:
    a = _vector(t, "t", min_len=2)
    if not is_uniform(a):
        raise ValueError("t must be uniformly sampled and strictly increasing")
    return a, (a[-1] - a[0]) / (a.size - 1)


def sample_rate(t) -> float:
    """Sampling rate ``1/dt`` in Hz of the uniform time grid ``t``."""
    return 1.0 / _step(t)[1]


def frequency_resolution(t) -> float:
    """Bin spacing ``1/(N*dt)`` in Hz of the unpadded spectrum of ``N`` samples."""
    a, dt = _step(t)
    return 1.0 / (a.size * dt)


def _window(name, n: int) -> np.ndarray:
    if name == "rect":
        return np.ones(n)
    if name == "hann":  # periodic (DFT-even) Hann: exact coherent gain N/2
        return 0.5 - 0.5 * np.cos(2 * np.pi * np.arange(n) / n)
    raise ValueError(f"window must be one of {_WINDOWS}, got {name!r}")


def spectrum(t, x, *, window: str = "hann", detrend: str | None = "mean", pad_to: int | None = None):
    """One-sided amplitude spectrum of a uniformly sampled real signal.

    Returns ``(f_Hz, amplitude)``. The signal is detrended (``"mean"``,
    ``"linear"`` or ``None``), windowed (``"hann"`` or ``"rect"``) and
    zero-padded to ``pad_to`` samples if given. Amplitudes are divided by the
    window's coherent gain, so a sinusoid ``A*sin(2*pi*f*t)`` with ``f`` at a
    bin centre shows a peak of exactly ``A`` (the Hann peak drops by up to
    ~15 % between bins: scalloping). The DC and Nyquist bins are not doubled.
    """
    x = _vector(x, "x", min_len=8)
    t = _vector(t, "t", min_len=8)
    if t.size != x.size:
        raise ValueError(f"t and x must have the same length, got {t.size} and {x.size}")
    t, dt = _step(t)
    n = x.size
    if detrend == "mean":
        x = x - x.mean()
    elif detrend == "linear":
        x = x - np.polyval(np.polyfit(t - t[0], x, 1), t - t[0])
    elif detrend is not None:
        raise ValueError(f"detrend must be one of {_DETRENDS}, got {detrend!r}")
    w = _window(window, n)
    nfft = n if pad_to is None else pad_to
    if not (is_integer(nfft) and nfft >= n):
        raise ValueError(f"pad_to must be an integer >= len(x) = {n}, got {pad_to!r}")

    amplitude = np.abs(np.fft.rfft(w * x, nfft)) * (2.0 / w.sum())
    amplitude[0] /= 2
    if nfft % 2 == 0:
        amplitude[-1] /= 2
    return np.fft.rfftfreq(nfft, dt), amplitude


def peak_frequency(f, amplitude, *, fmin: float | None = None, fmax: float | None = None,
                   interpolate: bool = True) -> float:
    """Frequency of the largest amplitude with ``fmin <= f <= fmax``.

    With ``interpolate``, a parabola through the logarithm of the three
    amplitudes around the maximum refines it between bins (exact for a
    Gaussian peak; for a Hann-windowed sinusoid the bias is a few hundredths
    of a bin). The bin frequency is returned when the maximum is at an end of
    the spectrum, is not a local maximum, or has a zero neighbour.
    """
    f = _vector(f, "f")
    amplitude = _vector(amplitude, "amplitude")
    if f.shape != amplitude.shape:
        raise ValueError(f"f and amplitude must have the same shape, got {f.shape} and {amplitude.shape}")
    mask = np.ones(f.size, dtype=bool)
    if fmin is not None:
        mask &= f >= fmin
    if fmax is not None:
        mask &= f <= fmax
    if not mask.any():
        raise ValueError(f"no frequency in [fmin, fmax] = [{fmin}, {fmax}]")
    k = int(np.flatnonzero(mask)[np.argmax(amplitude[mask])])
    if not interpolate or k == 0 or k == f.size - 1:
        return float(f[k])
    a, b, c = amplitude[k - 1 : k + 2]
    if min(a, c) <= 0 or b < max(a, c):
        return float(f[k])
    la, lb, lc = np.log([a, b, c])
    curvature = la - 2 * lb + lc
    offset = 0.0 if curvature == 0 else 0.5 * (la - lc) / curvature
    return float(f[k] + offset * 0.5 * (f[k + 1] - f[k - 1]))


def harmonics(fundamental_Hz: float, fmax_Hz: float) -> np.ndarray:
    """Multiples ``k * fundamental_Hz``, ``k = 1, 2, ...``, not above ``fmax_Hz``.

    ``fmax_Hz`` itself is included when it is a multiple up to rounding.
    """
    if not (np.isfinite(fundamental_Hz) and fundamental_Hz > 0):
        raise ValueError(f"fundamental_Hz must be finite and > 0, got {fundamental_Hz!r}")
    if not (np.isfinite(fmax_Hz) and fmax_Hz >= 0):
        raise ValueError(f"fmax_Hz must be finite and >= 0, got {fmax_Hz!r}")
    count = int(np.floor(fmax_Hz / fundamental_Hz * (1 + 1e-12)))
    return fundamental_Hz * np.arange(1, count + 1)


def whole_periods(t, period: float, skip_periods: float = 0.0) -> np.ndarray:
    """Boolean mask of the samples of ``t`` after the first ``skip_periods`` periods that
    cover the largest whole number of periods, so that the harmonics of ``1/period`` fall on
    frequency bins.

    Each sample stands for one step ``dt``: N samples span ``N dt``.  When the period is not
    a whole number of steps, no record is exactly k periods long; one within a step of k
    periods counts as k (the harmonics then lie within 1/N of a bin), so a run of 4
    revolutions less a transient of 1 keeps 3 periods, not 2.  Times are compared with half a
    step of slack (the period and the sample times carry rounding).  All samples after the
    skip are kept if ``period`` is not finite or longer than them.
    """
    a = np.asarray(t, dtype=float)
    if a.size < 2 or not (np.isfinite(period) and period > 0):
        return np.ones(a.size, dtype=bool)
    dt = (a[-1] - a[0]) / (a.size - 1)
    after = a >= a[0] + skip_periods * period - dt / 2
    if not after.any():
        return after
    first = a[after][0]
    k = int(np.floor((a[-1] - first + 2 * dt) / period + 1e-9))  # N dt, plus the step of slack
    if k < 1:
        return after
    return after & (a < first + k * period - dt / 2)


def noise_floor(amplitude) -> float:
    """The broadband level of an amplitude spectrum: the median amplitude of its bins (DC
    left out).  Peaks far above it are signal; amplitudes near it are numerical noise or
    broadband content, not lines."""
    a = _vector(amplitude, "amplitude", min_len=2)
    return float(np.median(a[1:]))
