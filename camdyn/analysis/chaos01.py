"""The 0-1 test for chaos (Gottwald & Melbourne), on a scalar series such as a Poincare section.

For an observable phi(j), j = 1..N (e.g. alpha at the section times k T), and a frequency c,
the translation variables

    p_c(n) = sum_{j<=n} phi(j) cos(j c),   q_c(n) = sum_{j<=n} phi(j) sin(j c)

are bounded when the dynamics is regular and behave like a Brownian motion when it is chaotic.
Their mean-square displacement M_c(n) (over j, for n <= n_cut = N / 10) is made the modified
D_c(n) = M_c(n) - (E phi)^2 (1 - cos n c) / (1 - cos c), removing the oscillating term that a
nonzero mean gives, and K_c is the correlation coefficient of D_c(n) with n (the correlation
method).  K, the median of K_c over random c in (pi/5, 4 pi/5) (away from the resonances
c = 0, pi), is near 0 for regular and near 1 for chaotic dynamics.

References: G. A. Gottwald, I. Melbourne, A new test for chaos in deterministic systems,
Proc. R. Soc. Lond. A 460 (2004) 603-611; On the implementation of the 0-1 test for chaos,
SIAM J. Appl. Dyn. Syst. 8 (2009) 129-145 (Sec. 3: the modified mean-square displacement and
the correlation method; the median over about 100 values of c).
"""
from __future__ import annotations

import math

import numpy as np

from ..errors import ParameterError
from .._checks import integer, is_integer, real

#: the shortest series the test accepts: n_cut = N/10 must leave a few tens of lags
MIN_LENGTH = 100
#: the interval of c (GM 2009, Sec. 3): away from the resonances at 0 and pi
C_RANGE = (math.pi / 5, 4 * math.pi / 5)


def _series(phi) -> np.ndarray:
    try:
        x = np.asarray(phi, dtype=float)
    except (TypeError, ValueError):
        raise ParameterError("series", None, "a 1-D sequence of real numbers",
                             problem=f"is a {type(phi).__name__} that is not a sequence of numbers") from None
    if x.ndim != 1 or x.size < MIN_LENGTH:
        raise ParameterError("series", None, f"a 1-D series of at least {MIN_LENGTH} values",
                             problem=f"has shape {x.shape}")
    bad = np.flatnonzero(~np.isfinite(x))
    if bad.size:
        what = "NaN" if np.isnan(x[bad[0]]) else "an infinite value"
        more = f" (and {bad.size - 1} more non-finite values)" if bad.size > 1 else ""
        raise ParameterError("series", None, "finite values only (no NaN, no inf)",
                             problem=f"has {what} at index {bad[0]}{more}")
    return x


def _generator(rng) -> np.random.Generator:
    if isinstance(rng, np.random.Generator):
        return rng
    if rng is None or (is_integer(rng) and rng >= 0):
        return np.random.default_rng(rng)
    raise ParameterError("rng", rng, "a numpy.random.Generator, a seed (integer >= 0) or None")


def _mean_square_displacement(z: np.ndarray, n_cut: int) -> np.ndarray:
    """``M(n) = mean over j of |z(j + n) - z(j)|^2`` for n = 1..n_cut, by
    ``|a - b|^2 = |a|^2 + |b|^2 - 2 Re(a conj b)``, the cross sums for all lags by one FFT."""
    N = z.size
    size = 1 << int(2 * N - 1).bit_length()
    f = np.fft.fft(z, size)
    cross = np.fft.ifft(f * np.conj(f))[1:n_cut + 1].real          # sum_j Re z(j + n) conj z(j)
    power = np.abs(z) ** 2
    head, tail = np.cumsum(power), np.cumsum(power[::-1])
    n = np.arange(1, n_cut + 1)
    # sum_{j < N - n} |z(j)|^2 + sum_{j >= n} |z(j)|^2 - 2 cross, over the N - n pairs
    return (head[N - n - 1] + tail[N - n - 1] - 2.0 * cross) / (N - n)


def k_of_c(phi: np.ndarray, c: float, n_cut: int) -> float:
    """K_c, the correlation of the modified mean-square displacement D_c(n) with n = 1..n_cut
    (GM 2009, Eqs. 3.3-3.5); 0 when D_c does not vary (a constant series)."""
    N = phi.size
    z = np.cumsum(phi * np.exp(1j * c * np.arange(1, N + 1)))       # p_c + i q_c
    n = np.arange(1, n_cut + 1)
    M = _mean_square_displacement(z, n_cut)
    D = M - np.mean(phi) ** 2 * (1.0 - np.cos(n * c)) / (1.0 - math.cos(c))
    if not np.std(D) > 0:
        return 0.0
    return float(np.corrcoef(n, D)[0, 1])


def zero_one_test(series, *, n_c: int = 100, rng=None, resolution: float = 0.0) -> float:
    """K of the 0-1 test for chaos: near 0 for a regular, near 1 for a chaotic series.

    Parameters
    ----------
    series : array_like
        phi(1..N), a 1-D finite series of N >= MIN_LENGTH values sampled once per period (e.g.
        the Poincare section of alpha); an oversampled continuous signal reads as regular.
    n_c : int
        How many random c in (pi/5, 4 pi/5) the median is taken over (GM 2009 use 100).
    rng : numpy.random.Generator, int or None
        The source of the c values (a seed makes K reproducible).
    resolution : float
        The series' own accuracy (e.g. the solver's error on the section, in the series'
        unit): a series whose values all lie within it is constant, K = 0.  Without it the
        test reads the rounding and integration noise on a periodic orbit's constant section
        as a random walk (measured: K = 0.2-0.6 on period-1 sections of tests/test_chaos01.py).

    Returns
    -------
    float
        K = median over c of K_c, clipped to [0, 1] (a correlation can be slightly negative).
        At finite N it approaches its limit slowly: see tests/test_chaos01.py for measured values.
    """
    phi = _series(series)
    integer("n_c", n_c, "an integer, 1 <= n_c <= 10000", lambda n: 1 <= n <= 10_000)
    real("resolution", resolution, "a finite number >= 0, in the series' unit", lambda v: 0 <= v < math.inf)
    cs = _generator(rng).uniform(*C_RANGE, size=int(n_c))
    if np.ptp(phi) <= resolution:
        return 0.0
    n_cut = phi.size // 10
    K = float(np.median([k_of_c(phi, c, n_cut) for c in cs]))
    return min(1.0, max(0.0, K))
