"""Figures in the style of the paper (needs matplotlib: ``pip install "camdyn[plot]"``).

Every function draws on ``ax`` when given (or creates a figure) and returns the
figure, so it works in a notebook, a script or the ``camdyn`` command alike.
matplotlib is imported inside the functions: ``import camdyn.io.plots`` works
without it, and a call says how to install it.

* :func:`time_history`  one quantity over t/T (cam revolutions), e.g. alpha_r (Figs. 5, 6a, 11-15)
* :func:`overview`      alpha_r, F_n and v_r of one run, free flight shaded
* :func:`spectrum`      amplitude spectra with the harmonics of Omega_c marked (Figs. 6b, 10, 16)
* :func:`poincare`      phase plane with the once-per-revolution Poincare section
* :func:`bifurcation`   Poincare section against cam speed
* :func:`branches`      continued branches (stable solid, unstable dashed) and their events,
                        over a brute-force bifurcation diagram
* :func:`contact_map`   sliding / impacting regimes over (cam speed, k_s) (Fig. 9)
* :func:`jump_chart`    the jump (grazing) speed against a rig parameter beside the inverse-kinematics
                        contact-loss speed, codimension-2 points marked
* :func:`basin_map`     basins of attraction over the starts (alpha, alpha_dot), attractors marked
* :func:`work_precision` error against run time, one line per solver set-up
* :func:`mechanism`     the cam (any profile) turned to a cam angle, and the follower touching it (Fig. 1)

:func:`poincare_section` (no matplotlib) samples a run once per cam period; :func:`style` gives
the same look to figures you build yourself.
"""
from __future__ import annotations

import math
from collections.abc import Mapping, Sequence

import numpy as np

from .metadata import describe_cam, describe_scene
from .metadata import units as _units

__all__ = ["PAPER_STYLE", "QUANTITIES", "MIN_FONT_PT", "REGIME_CODES", "style", "run_title", "time_history",
           "overview", "spectrum", "whole_period_samples", "poincare_section", "poincare", "bifurcation",
           "branches", "contact_map", "jump_chart", "basin_map", "work_precision"]

#: rcParams of the paper-like look: thin lines, inward ticks on all sides, no frame on legends.
PAPER_STYLE = {
    "figure.dpi": 110,
    "savefig.dpi": 150,
    "savefig.bbox": "tight",
    "font.size": 9.5,
    "axes.labelsize": 9.5,
    "axes.titlesize": 10,
    "axes.linewidth": 0.8,
    "axes.grid": True,
    "grid.linewidth": 0.4,
    "grid.alpha": 0.35,
    "lines.linewidth": 0.9,
    "xtick.direction": "in",
    "ytick.direction": "in",
    "xtick.top": True,
    "ytick.right": True,
    "legend.frameon": False,
    "legend.fontsize": 9,
}

_SYMBOLS = {
    "alpha": r"\alpha", "alpha_dot": r"\dot\alpha", "alpha_r": r"\alpha_r", "alpha_i": r"\alpha_i",
    "y": r"y", "y_dot": r"\dot y", "y_r": r"y_r", "y_i": r"y_i",
    "Theta": r"\Theta", "psi_i": r"\psi_i", "psi_j": r"\psi_j", "psi_i_dot": r"\dot\psi_i", "F_s": r"F_s",
    "F_n": r"F_n", "F_f": r"F_f", "v_r": r"v_r", "N_x": r"N_x", "energy": r"E", "P_in": r"P_{in}",
    "D_c": r"D_c", "D_f": r"D_f",
}
#: Display name (matplotlib mathtext) and SI unit (from :data:`camdyn.io.metadata.VARIABLES`) of
#: each time history of a Result.
QUANTITIES = {name: (symbol, _units(name)) for name, symbol in _SYMBOLS.items()}

#: the smallest font (pt) of any text in a figure: legends and labels stay readable when saved
MIN_FONT_PT = 8.5
_PREFIXES = ((1.0, ""), (1e-3, "m"), (1e-6, "µ"), (1e-9, "n"), (1e-12, "p"))
_SCALABLE = {"rad", "m", "m/s", "N", "J", "W"}
#: regime codes of contact_map, with their colours ("skipped": a point not run on purpose, e.g. a
#: sweep's INVALID point with invalid="skip"; rows and columns of nothing else are left out)
REGIME_CODES = {"sliding": 0, "impacting": 1, "failed": 2, "skipped": 3}
_REGIME_COLOURS = ("#cfe3f3", "#f4b183", "#bfbfbf", "#ffffff")
_FREE_SHADE = "0.9"
_MAX_HARMONIC_LINES = 60


def _pyplot():
    """matplotlib.pyplot, or an ImportError that says how to get it."""
    try:
        import matplotlib.pyplot as plt
    except ImportError as exc:  # pragma: no cover - exercised by test_plots with a blocked import
        raise ImportError("camdyn.io.plots needs matplotlib, which is not installed: "
                          "pip install \"camdyn[plot]\"") from exc
    return plt


def style():
    """A context manager with the paper-like look, for figures you build yourself.

    Example::

        with camdyn.io.plots.style():
            fig, axes = plt.subplots(1, 2)
    """
    return _style()


def _style():
    plt = _pyplot()
    from cycler import cycler
    style = dict(PAPER_STYLE)  # plus colour and line style cycled together
    style["axes.prop_cycle"] = (cycler(color=["k", "#c0392b", "#2e75b6", "#548235", "#7030a0", "#bf9000"])
                                + cycler(linestyle=["-", "--", "-.", ":", (0, (5, 1, 1, 1)), (0, (3, 1))]))
    return plt.rc_context(style)


def _figure(ax, nrows=1, figsize=(6.4, 3.0), sharex=False):
    plt = _pyplot()
    if ax is not None:
        axes = np.atleast_1d(ax)
        return axes.flat[0].figure, axes
    fig, axes = plt.subplots(nrows, 1, figsize=figsize, sharex=sharex, constrained_layout=True, squeeze=False)
    return fig, axes[:, 0]


def _labelled(results) -> list[tuple[str | None, object]]:
    """A Result, a sequence of Results or a {label: Result} mapping as (label, result) pairs."""
    if isinstance(results, Mapping):
        return [(str(k), v) for k, v in results.items()]
    if isinstance(results, Sequence) and not isinstance(results, (str, bytes)):
        return [(getattr(r, "scene", None), r) for r in results]
    return [(None, results)]


def _values(result, quantity: str) -> np.ndarray:
    if quantity not in QUANTITIES:
        raise ValueError(f"quantity {quantity!r} is not one of {sorted(QUANTITIES)}")
    return np.asarray(getattr(result, quantity), dtype=float)


def _prefix(values, unit: str) -> tuple[float, str]:
    """(scale, unit label) so that the largest |value| reads between 1 and 1000."""
    finite = np.asarray(values, dtype=float)
    finite = finite[np.isfinite(finite)]
    if unit not in _SCALABLE or finite.size == 0:
        return 1.0, unit
    peak = float(np.max(np.abs(finite)))
    for scale, p in _PREFIXES:
        if peak >= scale:
            return scale, p + unit
    return _PREFIXES[-1][0], _PREFIXES[-1][1] + unit


def _label(quantity: str, unit: str) -> str:
    return f"${QUANTITIES[quantity][0]}$ ({unit})" if unit else f"${QUANTITIES[quantity][0]}$"


def _revolutions(result) -> tuple[np.ndarray, str]:
    """Time axis: t/T counted from the first sample, or t in seconds when the cam has no period."""
    t = np.asarray(result.t, dtype=float)
    period = float(getattr(result, "period", math.inf))
    if math.isfinite(period) and period > 0:
        return (t - t[0]) / period if t.size else t, r"$t/T$ (cam revolutions)"
    return t, r"$t$ (s)"


def _free_intervals(result) -> list[tuple[float, float]]:
    """(start, end) sample indices of the runs of samples in free flight."""
    free = np.asarray(result.regime) == "free"
    if not free.any():
        return []
    edges = np.flatnonzero(np.diff(np.r_[0, free.astype(int), 0]))
    return list(zip(edges[::2], edges[1::2] - 1))


def time_history(results, quantity: str = "alpha_r", *, revolutions: tuple[float, float] | None = None,
                 mark_impacts: bool = False, shade_free: bool = False, ax=None, title: str | None = None):
    """``quantity`` over t/T, the time normalised by one cam revolution (Figs. 5, 6a, 11-15).

    ``results``: a Result, a list of them, or ``{label: Result}`` to overlay runs (e.g. damping
    models A-E).  ``revolutions=(a, b)`` shows only a <= t/T <= b.  ``mark_impacts`` ticks the
    impact times; ``shade_free`` shades free flight (one run only).  The unit gets an SI prefix
    (µrad, mN...) so the numbers read between 1 and 1000.
    """
    pairs = _labelled(results)
    with _style():
        fig, (ax,) = _figure(ax)
        unit = QUANTITIES.get(quantity, (None, ""))[1]
        scale, unit_label = _prefix(np.concatenate([_values(r, quantity) for _, r in pairs]), unit)
        for label, r in pairs:
            x, xlabel = _revolutions(r)
            y = _values(r, quantity) / scale
            keep = np.ones(x.size, bool) if revolutions is None else (x >= revolutions[0]) & (x <= revolutions[1])
            line, = ax.plot(x[keep], y[keep], label=label)
            if mark_impacts and r.impacts().size:
                period = r.period if math.isfinite(r.period) else 1.0
                xi = (r.impacts() - r.t[0]) / period
                if revolutions is not None:
                    xi = xi[(xi >= revolutions[0]) & (xi <= revolutions[1])]
                ax.plot(xi, np.full(xi.size, np.nanmin(y[keep])), "|", color=line.get_color(), ms=7,
                        label=None)
            if shade_free and len(pairs) == 1:
                for i, j in _free_intervals(r):
                    ax.axvspan(x[i], x[j], color=_FREE_SHADE, lw=0, zorder=0)
        ax.set(xlabel=xlabel, ylabel=_label(quantity, unit_label))
        if revolutions is not None:
            ax.set_xlim(*revolutions)
        if any(label for label, _ in pairs):
            ax.legend(loc="best")
        if title:
            ax.set_title(title)
    return fig


def overview(result, *, quantities: Sequence[str] | None = None, title: str | None = None):
    """A stacked view of one run over t/T: alpha_r, F_n and (with friction) v_r; free flight shaded."""
    if quantities is None:
        quantities = [result.meta.get("coordinate", "alpha") + "_r", "F_n"]
        if np.any(np.asarray(result.F_f) != 0):
            quantities.append("v_r")
    with _style():
        fig, axes = _figure(None, nrows=len(quantities), figsize=(6.4, 1.9 * len(quantities) + 0.4), sharex=True)
        for ax, q in zip(axes, quantities):
            time_history(result, q, ax=ax, shade_free=True)
            if ax is not axes[-1]:
                ax.set_xlabel("")
        summary = run_title(result)
        axes[0].set_title(title or summary + ("" if result.ok else f" ({result.outcome.name})"))
        if _free_intervals(result):
            from matplotlib.patches import Patch
            fig.legend(handles=[Patch(color=_FREE_SHADE, label="free flight (no contact)")], loc="outside lower right",
                       fontsize=MIN_FONT_PT)
    return fig


def run_title(result) -> str:
    """The physics of a run in words, for a title: ``line contact, damping D, Coulomb friction,
    1100 rev/min, rig example`` (empty for a series with no scene)."""
    if not getattr(result, "scene", None):
        return ""
    meta = getattr(result, "meta", {}) or {}
    words = [describe_scene(result.scene), describe_cam(meta.get("cam"))]
    rig = meta.get("rig")
    if rig is not None:
        words.append(f"rig {getattr(rig, 'name', rig)}")
    return ", ".join(w for w in words if w)


def _fundamental_Hz(result) -> float:
    period = float(getattr(result, "period", math.inf))
    return 1.0 / period if math.isfinite(period) and period > 0 else math.nan


def spectrum(results, quantity: str = "alpha", *, bands: Sequence[tuple[float, float]] | None = None,
             fmax: float | None = None, harmonics: int | bool = True, mark_Hz: Mapping[str, float] | None = None,
             transient_revolutions: float = 0.0, whole_periods: bool = True, log: bool = True,
             window: str = "hann", noise_floor: bool = True, ax=None, title: str | None = None):
    """One-sided amplitude spectrum of ``quantity`` with the harmonics of Omega_c marked (Figs. 10, 16).

    ``bands=[(f0, f1), ...]`` draws one panel per frequency band (Fig. 10: (a) the low
    harmonics, (b) around the natural frequency); else one panel up to ``fmax``.  All panels
    share one unit, chosen for the largest amplitude shown.
    ``harmonics``: mark k Omega_c (True: all in view, labelled while there is room; an int:
    the first n; False: none).  ``mark_Hz={"vartheta": 2182.0}`` marks other frequencies.
    ``transient_revolutions`` are dropped first; with ``whole_periods`` the record is then cut
    to a whole number of cam periods, so that the harmonics fall on frequency bins.  The
    signal's mean is removed.  ``noise_floor`` draws the spectrum's median level
    (:func:`camdyn.analysis.signal.noise_floor`): amplitudes near it are not lines.  The title
    defaults to the run's physics (one run).
    """
    _pyplot()
    spectra = _spectra(_labelled(results), quantity, transient_revolutions, whole_periods, window)
    if bands is None:
        top = fmax if fmax is not None else max(f[-1] for _, f, _, _ in spectra)
        bands = [(0.0, top)]
    unit = QUANTITIES[quantity][1]
    shown = [a[(f >= lo) & (f <= hi)] for lo, hi in bands for _, f, a, _ in spectra]
    scale, unit_label = _prefix([max(float(np.max(a, initial=0.0)) for a in shown)], unit)
    floor = _noise_floor(spectra[0][2]) if noise_floor else None
    with _style():
        fig, axes = _figure(ax, nrows=len(bands), figsize=(6.4, 2.6 * len(bands) + 0.3))
        for ax_, (lo, hi) in zip(axes, bands):
            for label, f, amp, _ in spectra:
                keep = (f >= lo) & (f <= hi)
                ax_.plot(f[keep], amp[keep] / scale, label=label)
            if log:
                ax_.set_yscale("log")
            ax_.set_xlim(lo, hi)
            ax_.set(xlabel="frequency (Hz)", ylabel=f"|${QUANTITIES[quantity][0]}$| ({unit_label})")
            handles = [h for h in ax_.get_lines() if not h.get_label().startswith("_")]
            handles += _mark_harmonics(ax_, spectra[0][3], lo, hi, harmonics)
            for name, fm in (mark_Hz or {}).items():
                if lo <= fm <= hi:
                    handles.append(ax_.axvline(fm, color="#c0392b", lw=0.8, ls="--", zorder=0,
                                               label=f"{name} = {fm:.5g} Hz"))
            if floor:
                handles.append(ax_.axhline(floor / scale, color="0.45", lw=0.8, ls="-.", zorder=0,
                                           label=f"noise floor (median level) = {floor / scale:.2g} {unit_label}"))
            if handles:
                ax_.legend(handles=handles, loc="best")
        heading = title if title is not None else (run_title(_labelled(results)[0][1]) if len(spectra) == 1 else "")
        if heading:
            axes[0].set_title(heading)
    return fig


def _spectra(pairs, quantity: str, transient_revolutions: float, whole_periods: bool, window: str):
    """(label, f, amplitude, fundamental) of each run, after the transient (whole periods)."""
    from ..analysis import signal

    out = []
    for label, r in pairs:
        t, x = np.asarray(r.t, dtype=float), _values(r, quantity)
        if whole_periods:
            keep = signal.whole_periods(t, r.period, transient_revolutions)
        else:
            dt = (t[-1] - t[0]) / max(t.size - 1, 1)
            keep = t >= t[0] + transient_revolutions * r.period - dt / 2
        f, amp = signal.spectrum(t[keep], x[keep], window=window)
        out.append((label, f, amp, _fundamental_Hz(r)))
    return out


def _noise_floor(amplitude) -> float | None:
    from ..analysis import signal

    level = signal.noise_floor(amplitude)
    return level if level > 0 else None


def _mark_harmonics(ax, f0: float, lo: float, hi: float, harmonics) -> list:
    """Dotted lines at k f0 in [lo, hi], numbered while there is room; their legend handle."""
    from matplotlib.lines import Line2D

    if not harmonics or not math.isfinite(f0):
        return []
    ks = np.arange(max(1, math.ceil(lo / f0)), math.floor(hi / f0) + 1)
    if harmonics is not True:
        ks = ks[ks <= int(harmonics)]
    if ks.size > _MAX_HARMONIC_LINES:
        return [Line2D([], [], color="none", label=rf"harmonics of $\Omega_c$ = {f0:.4g} Hz: too dense to mark here")]
    if ks.size == 0:
        return []
    numbered = ks.size <= 15
    for k in ks:
        ax.axvline(k * f0, color="0.55", lw=0.6, ls=":", zorder=0)
        if numbered:
            ax.text(k * f0, 0.985, f"{k}", transform=ax.get_xaxis_transform(), ha="center", va="top",
                    fontsize=MIN_FONT_PT, color="0.3", bbox=dict(fc="white", ec="none", pad=0.3, alpha=0.8))
    return [Line2D([], [], color="0.55", lw=0.6, ls=":",
                   label=rf"$k\,\Omega_c$, $\Omega_c$ = {f0:.4g} Hz" + (" (k on top)" if numbered else ""))]


def whole_period_samples(t, period: float) -> np.ndarray:
    """Boolean mask of the first samples of ``t`` covering a whole number of periods (as many
    as fit, N samples spanning N dt); all samples if the period is not finite or longer than
    the record.  See :func:`camdyn.analysis.signal.whole_periods`."""
    from ..analysis.signal import whole_periods

    return whole_periods(t, period)


def poincare_section(result, quantities: Sequence[str] = ("alpha", "alpha_dot"), *,
                     transient_revolutions: float = 0.0, phase: float = 0.0) -> dict[str, np.ndarray]:
    """The run sampled once per cam period, at t = t0 + (n + phase) T after the transient.

    Values between samples are interpolated linearly; they are exact when the sample rate
    is a whole multiple of the cam frequency (``sample_rate_Hz = k / T``).  Returns
    ``{"t": times, quantity: values, ...}``.
    """
    period = float(result.period)
    if not (math.isfinite(period) and period > 0):
        raise ValueError("a Poincare section needs a periodic cam (result.period is not finite)")
    t = np.asarray(result.t, dtype=float)
    first = math.ceil(transient_revolutions - phase - 1e-9)
    n_last = math.floor((t[-1] - t[0]) / period - phase + 1e-9)
    times = t[0] + (np.arange(max(first, 0), n_last + 1) + phase) * period
    return {"t": times, **{q: np.interp(times, t, _values(result, q)) for q in quantities}}


def poincare(result, *, transient_revolutions: float = 0.0, phase: float = 0.0, ax=None, title: str | None = None):
    """Phase plane (alpha, alpha_dot) of one run, grey, with its Poincare section once per revolution, black."""
    sec = poincare_section(result, transient_revolutions=transient_revolutions, phase=phase)
    with _style():
        fig, (ax,) = _figure(ax, figsize=(4.6, 3.6))
        keep = result.t >= result.t[0] + transient_revolutions * result.period
        a_scale, a_unit = _prefix(result.q[keep] - result.q_star, "rad")
        ax.plot((result.q[keep] - result.q_star) / a_scale, result.q_dot[keep], color="0.75", lw=0.5)
        ax.plot((sec["alpha"] - result.q_star) / a_scale, sec["alpha_dot"], "o", color="k", ms=3.5,
                label=f"once per revolution ({sec['t'].size} points)")
        ax.set(xlabel=rf"$\alpha - \alpha^*$ ({a_unit})", ylabel=r"$\dot\alpha$ (rad/s)")
        ax.legend(loc="best")
        if title:
            ax.set_title(title)
    return fig


def bifurcation(speed_rpm, points, *, quantity: str = "alpha", relative_to: float | None = None,
                contact_loss_rpm: float | None = None, ax=None, title: str | None = None):
    """Poincare section against cam speed: one column of points per speed.

    ``points``: a list of arrays (one per speed), a 2-D array (speed x revolution; NaN for
    missing points), or an xarray DataArray with the speed as its first dimension.
    ``relative_to`` is subtracted (e.g. alpha*), to show the deviation.
    ``contact_loss_rpm`` (e.g. :func:`camdyn.analysis.statics.contact_loss_speed`) is marked with a
    dashed line where it falls in the range of speeds, and named in the legend.
    """
    speeds = np.asarray(speed_rpm, dtype=float)
    if hasattr(points, "values") and not isinstance(points, np.ndarray):
        points = points.values
    columns = [np.asarray(p, dtype=float).ravel() for p in points]
    if len(columns) != speeds.size:
        raise ValueError(f"{speeds.size} speeds but {len(columns)} columns of points")
    xs = np.concatenate([np.full(c.size, s) for s, c in zip(speeds, columns)]) if columns else np.empty(0)
    ys = np.concatenate(columns) if columns else np.empty(0)
    ok = np.isfinite(ys)
    xs, ys = xs[ok], ys[ok] - (relative_to or 0.0)
    unit = QUANTITIES.get(quantity, (None, "rad"))[1]
    scale, unit_label = _prefix(ys, unit)
    with _style():
        fig, (ax,) = _figure(ax, figsize=(6.4, 3.4))
        ax.plot(xs, ys / scale, ",", color="k", alpha=0.9)
        ax.plot(xs, ys / scale, "o", color="k", ms=1.2, alpha=0.6)
        symbol = QUANTITIES.get(quantity, (quantity, ""))[0]
        if relative_to is not None:
            symbol += r" - " + symbol + "^*"
        ax.set(xlabel=r"cam speed $\Omega_c$ (rev/min)", ylabel=f"${symbol}$ once per revolution ({unit_label})")
        if contact_loss_rpm is not None and speeds.size and speeds.min() <= contact_loss_rpm <= speeds.max():
            ax.axvline(contact_loss_rpm, color="#c0392b", lw=1.0, ls="--",
                       label=f"contact loss (inverse kinematics): {contact_loss_rpm:.4g} rev/min")
            ax.legend(loc="best", frameon=True, framealpha=0.9)
        if title:
            ax.set_title(title)
    return fig


#: the marker of each event kind of :func:`camdyn.orbits.continuation.continue_orbit`
#: (every kind of camdyn.orbits.continuation.EVENTS: tests/test_plots.py)
EVENT_MARKERS = {"fold": "s", "branch_point": "D", "period_doubling": "^", "neimark_sacker": "o", "grazing": "v",
                 "lift_off": "<", "corner_impact": "*", "multiplier_jump": "x"}


def stability_runs(flags: np.ndarray) -> list[tuple[int, int, bool]]:
    """Maximal runs [i, j] of equal flags, each sharing its last index with the next run's first."""
    cuts = [0] + [k for k in range(1, flags.size) if flags[k] != flags[k - 1]] + [flags.size]
    return [(a, min(b, flags.size - 1), bool(flags[a])) for a, b in zip(cuts[:-1], cuts[1:])]


def branches(ds, *, diagram=None, contact_loss_rpm: float | None = None, ax=None, title: str | None = None):
    """Continued branches (:func:`camdyn.orbits.continuation.continue_orbit`) against their parameter: alpha
    at the starts of the orbit's revolutions (the brute-force diagram's sections), solid where
    the orbit is stable, dashed where not, one colour per period; the events marked and named.

    ``diagram``: the Dataset of :func:`camdyn.sweep.api.bifurcation` drawn underneath (points), for
    a continuation in speed_rpm.  ``contact_loss_rpm`` as in :func:`bifurcation`.
    """
    scale, unit_label = _prefix(ds["alpha_revolution"].values, "rad")
    if diagram is not None:
        fig = bifurcation(diagram["speed_rpm"].values, diagram["alpha_section"], ax=ax,
                          contact_loss_rpm=contact_loss_rpm, title=title)
        ax = fig.axes[0]
        scale, unit_label = _prefix(diagram["alpha_section"].values, "rad")     # the diagram's axis
    kinds = ds.attrs["event_kinds"].split()
    with _style():
        fig, (ax,) = _figure(ax, figsize=(6.4, 3.4))
        lam, stable = ds["lambda"].values, ds["stable"].values.astype(bool)
        alphas = ds["alpha_revolution"].values / scale
        colours = ["k", "#2e75b6", "#548235", "#7030a0"]
        for b in ds["branch"].values:
            idx = np.flatnonzero(ds["point_branch"].values == b)
            n = int(ds["periods"].values[idx[0]])
            colour = colours[min(n.bit_length() - 1, len(colours) - 1)]
            x, y = _from_origin(ds, int(b), lam[idx], alphas[idx, :n], scale)
            start = x.size - idx.size                     # 1: the branch is drawn from its period doubling
            for i, j, ok in stability_runs(stable[idx]):
                rows = slice(i + start if i else 0, j + start + 1)
                ax.plot(x[rows], y[rows], color=colour, lw=1.0, ls="-" if ok else "--")
            ax.plot([], [], color=colour, lw=1.0, ls="-", label=f"period {n} T (dashed: unstable)")
        for k, kind in enumerate(kinds):
            sel = ds["event_kind"].values == k
            if np.any(sel):
                y = ds["event_alpha_revolution"].values[sel] / scale
                x = np.repeat(ds["event_lambda"].values[sel][:, None], y.shape[1], axis=1)
                ax.plot(x.ravel(), y.ravel(), EVENT_MARKERS.get(kind, "x"), mfc="none", color="#c0392b", ms=6,
                        label=kind.replace("_", " "))
        unit = ds["lambda"].attrs.get("units", "")
        ax.set(xlabel=f"{ds.attrs['parameter']} ({unit})", ylabel=rf"$\alpha$ once per revolution ({unit_label})")
        ax.legend(loc="best", frameon=True, framealpha=0.9)
        if title:
            ax.set_title(title)
    return fig


def _from_origin(ds, branch: int, lam: np.ndarray, alphas: np.ndarray, scale: float):
    """A branch's parameter values and sections, preceded by the event it was switched to at
    (``branch_origin``: the period doubling, where the doubled orbit's n sections are the parent
    orbit's, repeated)."""
    origin = int(ds["branch_origin"].values[branch]) if "branch_origin" in ds else -1
    if origin < 0:
        return lam, alphas
    parent = int(ds["branch_periods"].values[int(ds["branch_parent"].values[branch])])
    at = ds["event_alpha_revolution"].values[origin, :parent] / scale
    first = np.tile(at, alphas.shape[1] // parent + 1)[:alphas.shape[1]]
    return np.concatenate([[ds["event_lambda"].values[origin]], lam]), np.vstack([first, alphas])


def jump_chart(ds, *, ax=None, title: str | None = None):
    """A grazing curve (:func:`camdyn.orbits.continuation.continue_grazing`, or the jump chart of
    :func:`camdyn.orbits.continuation.jump_chart`): its free parameter (the jump speed) against
    its parameter, solid where the grazing orbit is stable on its contact side, dashed where
    not, codimension-2 points marked; with the chart's ``contact_loss_rpm``, the
    inverse-kinematics contact-loss speed beside it (dotted) and, on a second axis below, the
    relative difference between the two against the first-order compliance shift.  A parameter
    spanning more than a decade is drawn on a log axis.  ``ax``: the (upper) axes to draw on.
    """
    free, parameter = ds.attrs["free"], ds.attrs["parameter"]
    x, y = ds[parameter].values, ds[free].values
    quasi_static = "contact_loss_rpm" in ds and ax is None
    with _style():
        fig, axes = _figure(ax, nrows=2 if quasi_static else 1, figsize=(6.4, 4.6 if quasi_static else 3.2),
                            sharex=True)
        top = axes[0]
        for i, j, ok in stability_runs(ds["stable"].values.astype(bool)) if x.size else ():
            top.plot(x[i:j + 1], y[i:j + 1], color="k", lw=1.1, ls="-" if ok else "--")
        top.plot([], [], color="k", lw=1.1, label="grazing (dashed: unstable)")
        if "contact_loss_rpm" in ds:
            top.plot(x, ds["contact_loss_rpm"].values, color="#c0392b", lw=1.0, ls=":",
                     label="contact loss, inverse kinematics")
        kinds = ds.attrs.get("codim2_kinds", "").split()
        for k, kind in enumerate(kinds):
            sel = ds["codim2_kind"].values == k
            if np.any(sel):
                top.plot(ds[f"codim2_{parameter}"].values[sel], ds[f"codim2_{free}"].values[sel],
                         "^" if "doubling" in kind else "s", mfc="none", color="#2e75b6", label=kind.replace("_", " "))
        name = "jump speed" if free == "speed_rpm" else free
        top.set(ylabel=f"{name} ({ds[free].attrs.get('units', '')})")
        top.legend(loc="best", frameon=True, framealpha=0.9)
        if quasi_static:
            _quasi_static_panel(axes[1], ds, x)
        axes[-1].set(xlabel=f"{parameter} ({ds[parameter].attrs.get('units', '')})")
        if x.size and np.all(x > 0) and x.max() > 10 * x.min():
            axes[-1].set_xscale("log")
        if title:
            top.set_title(title)
    return fig


def _quasi_static_panel(ax, ds, x):
    """The jump speed relative to the contact-loss speed, minus one, beside the compliance shift."""
    ratio = ds[ds.attrs["free"]].values / ds["contact_loss_rpm"].values - 1.0
    ax.plot(x, ratio, color="k", lw=1.0, label="grazing / inverse kinematics - 1")
    if "compliance_shift" in ds:
        ax.plot(x, ds["compliance_shift"].values, color="#c0392b", lw=1.0, ls=":",
                label="compliance shift (first order)")
    ax.set(ylabel="relative shift")
    ax.legend(loc="best", frameon=True, framealpha=0.9)


def contact_map(speed_rpm, k_s, regime, *, loss_curve: tuple | None = None, log_k: bool = True, ax=None,
                title: str | None = None):
    """Contact regimes over the (cam speed, k_s) plane, as in Fig. 9.

    ``regime[i, j]`` is the regime at ``k_s[i]``, ``speed_rpm[j]``: a code of
    :data:`REGIME_CODES` (0 sliding, 1 impacting, 2 failed, 3 skipped; NaN: failed) or its name.
    A row or column of skipped points only is left out of the axes (and of ``loss_curve``'s
    k_s range); other skipped points are drawn blank.  ``loss_curve=(speeds, k_s)`` overlays a
    curve, e.g. the contact-loss speed by inverse kinematics for each k_s.
    """
    _pyplot()
    from matplotlib.colors import BoundaryNorm, ListedColormap
    from matplotlib.patches import Patch

    speeds, ks = np.asarray(speed_rpm, dtype=float), np.asarray(k_s, dtype=float)
    codes = np.asarray(regime)
    if codes.dtype.kind in "US":
        codes = np.vectorize(lambda name: REGIME_CODES[str(name)])(codes)
    codes = np.asarray(codes, dtype=float)
    if codes.shape != (ks.size, speeds.size):
        raise ValueError(f"regime has shape {codes.shape}; expected (len(k_s), len(speed_rpm)) = "
                         f"{(ks.size, speeds.size)}")
    codes = np.where(np.isfinite(codes), codes, REGIME_CODES["failed"])
    speeds, ks, codes, loss_curve = _without_skipped(speeds, ks, codes, loss_curve)
    with _style():
        fig, (ax,) = _figure(ax, figsize=(5.6, 3.8))
        cmap = ListedColormap(_REGIME_COLOURS)
        bounds = np.arange(len(_REGIME_COLOURS) + 1) - 0.5
        ax.pcolormesh(speeds, ks, codes, cmap=cmap, norm=BoundaryNorm(bounds, len(_REGIME_COLOURS)), shading="nearest")
        handles = [Patch(facecolor=_REGIME_COLOURS[c], edgecolor="0.6" if name == "skipped" else _REGIME_COLOURS[c],
                         label=name) for name, c in REGIME_CODES.items() if np.any(codes == c)]
        if loss_curve is not None:
            ls, lk = (np.asarray(v, dtype=float) for v in loss_curve)
            handles.append(ax.plot(ls, lk, color="k", lw=1.2, label="contact loss (inverse kinematics)")[0])
            ax.set_xlim(speeds.min() - 0.5 * np.ptp(speeds) / max(speeds.size - 1, 1),
                        speeds.max() + 0.5 * np.ptp(speeds) / max(speeds.size - 1, 1))
        if log_k:
            ax.set_yscale("log")
        ax.grid(False)
        ax.set(xlabel=r"cam speed $\Omega_c$ (rev/min)", ylabel=r"spring stiffness $k_s$ (N/m)")
        ax.legend(handles=handles, loc="upper left", frameon=True, framealpha=0.85)
        if title:
            ax.set_title(title)
    return fig


def _without_skipped(speeds, ks, codes, loss_curve):
    """contact_map's grid without the rows and columns that hold skipped points only; the loss
    curve within the k_s range left."""
    skipped = codes == REGIME_CODES["skipped"]
    rows, columns = ~skipped.all(axis=1), ~skipped.all(axis=0)
    if rows.all() and columns.all():
        return speeds, ks, codes, loss_curve
    if not rows.any():
        raise ValueError("every point of the map is skipped: nothing to draw")
    ks, speeds, codes = ks[rows], speeds[columns], codes[rows][:, columns]
    if loss_curve is not None:
        ls, lk = (np.asarray(v, dtype=float) for v in loss_curve)
        inside = (lk >= ks.min()) & (lk <= ks.max())
        loss_curve = (ls[inside], lk[inside])
    return speeds, ks, codes, loss_curve


#: colours of the basin map's verdicts (camdyn.sweep.attractors.VERDICTS); attractors take tab10's
_VERDICT_COLOURS = {"chaotic": "#222222", "not_settled": "#9e9e9e", "no_run": "#ffffff"}


def basin_map(ds, *, speed_rpm: float | None = None, ax=None, title: str | None = None):
    """The basin map of :func:`camdyn.sweep.attractors.basins` over the starts (alpha_start,
    alpha_dot_start), each start coloured by the attractor it reaches (chaotic, not settled and
    no run in black, grey and white), each attractor's section points marked with a star
    (labelled with its id, period and share of the map).  With a speed axis, ``speed_rpm`` picks
    the speed drawn (the nearest on the grid)."""
    _pyplot()
    from matplotlib.colors import BoundaryNorm, ListedColormap
    from matplotlib.patches import Patch

    from ..sweep.attractors import VERDICTS

    if "speed_rpm" in ds.dims:
        if speed_rpm is None and ds.sizes["speed_rpm"] > 1:
            raise ValueError(f"the map has {ds.sizes['speed_rpm']} speeds: give speed_rpm= (one of "
                             f"{ds['speed_rpm'].values.tolist()})")
        ds = ds.sel(speed_rpm=speed_rpm, method="nearest") if speed_rpm is not None else ds.isel(speed_rpm=0)
    codes = ds["attractor"]
    for dim in set(codes.dims) - {"alpha_start", "alpha_dot_start"}:
        if codes.sizes[dim] > 1:
            raise ValueError(f"the map has {codes.sizes[dim]} values of {dim}: draw one (ds.isel({dim}=...))")
        codes = codes.isel({dim: 0})
    codes = codes.transpose("alpha_dot_start", "alpha_start").values
    n = int(ds.attrs.get("attractors", 0))
    ids = [i for i in range(n) if np.any(codes == i)]
    palette = [_tab10(k) for k in range(max(n, 1))]
    colours = [_VERDICT_COLOURS[name] for name in VERDICTS][::-1] + palette  # codes -3 .. n - 1
    with _style():
        fig, (ax,) = _figure(ax, figsize=(5.6, 4.2))
        bounds = np.arange(-3, max(n, 1) + 1) - 0.5
        ax.pcolormesh(ds["alpha_start"].values, ds["alpha_dot_start"].values, codes, cmap=ListedColormap(colours),
                      norm=BoundaryNorm(bounds, len(colours)), shading="nearest")
        handles = []
        for i in ids:
            share = 100.0 * np.mean(codes == i)
            p = int(ds["attractor_period"].values[i])
            a, ad = ds["attractor_alpha"].values[i, :p], ds["attractor_alpha_dot"].values[i, :p]
            handles.append(ax.plot(a, ad, "*", ms=11, mfc=palette[i], mec="k", mew=0.8,
                                   label=f"attractor {i}: P{p}, {share:.0f} % of starts")[0])
        handles += [Patch(facecolor=_VERDICT_COLOURS[name], edgecolor="0.5", label=name.replace("_", " "))
                    for name, code in VERDICTS.items() if np.any(codes == code)]
        ax.grid(False)
        ax.set(xlabel=r"$\alpha$ at the start, $t = 0$ (rad)", ylabel=r"$\dot\alpha$ at the start (rad/s)")
        ax.legend(handles=handles, loc="upper right", frameon=True, framealpha=0.85, fontsize=MIN_FONT_PT)
        if title:
            ax.set_title(title)
    return fig


def _tab10(k: int):
    from matplotlib import colormaps

    return colormaps["tab10"](k % 10)


def work_precision(records, *, ax=None, title: str | None = None, error_label: str = "error"):
    """Run time against error, log-log, one line per set-up (label), points annotated with rtol.

    ``records``: an iterable of mappings with keys ``label``, ``error``, ``seconds`` and
    optionally ``rtol``.  Lower left is better: less time for the same error.
    """
    groups: dict[str, list] = {}
    for rec in records:
        groups.setdefault(str(rec["label"]), []).append(rec)
    with _style():
        fig, (ax,) = _figure(ax, figsize=(6.0, 3.8))
        for label, recs in groups.items():
            recs = sorted(recs, key=lambda r: r["error"])
            err = np.array([max(float(r["error"]), 1e-300) for r in recs])
            sec = np.array([float(r["seconds"]) for r in recs])
            line, = ax.plot(err, sec, marker="o", ms=4, label=label)
            for r, x, y in zip(recs, err, sec):
                if r.get("rtol") is not None:
                    ax.annotate(f"{r['rtol']:.0e}", (x, y), textcoords="offset points", xytext=(3, 3),
                                fontsize=MIN_FONT_PT, color=line.get_color())
        ax.set_xscale("log")
        ax.set_yscale("log")
        ax.set(xlabel=error_label, ylabel="run time (s)")
        ax.legend(loc="best")
        if title:
            ax.set_title(title)
    return fig


def mechanism(rig, theta: float | None = None, *, ax=None, title: str | None = None):
    """The cam (its profile turned to the cam angle ``theta``, rad; default the rig's theta0) and
    the follower in rigid contact with it: the oscillating follower (Fig. 1: the bar from the pivot
    P along the follower angle, its cam-side face) or the translating one (its guide's axis and its
    face, normal to the guide), and the contact point.  Any cam: the paper's circle or the rig's
    profile (camdyn.model.profiles), drawn from its support function (contact points c(phi))."""
    from ..model.followers import cam_of, follower_of_rig, rigid_contact

    cam, follower = cam_of(rig), follower_of_rig(rig)
    theta = rig.theta0 if theta is None else float(theta)
    fig, axes = _figure(ax, figsize=(4.8, 4.0))
    ax = axes[0]
    body = cam.contact_point(np.linspace(0.0, 2 * math.pi, 721))
    c, s = math.cos(theta), math.sin(theta)
    x, y = c * body[:, 0] - s * body[:, 1], s * body[:, 0] + c * body[:, 1]
    ax.fill(x * 1e3, y * 1e3, color="0.85", edgecolor="0.2", lw=1.0)
    ax.plot([0], [0], "k+", ms=8)
    contact = rigid_contact(cam, follower, np.array([theta]))
    draw = _translating_follower if follower.kind == "translating" else _oscillating_follower
    where = draw(ax, rig, follower, contact, np.abs(body).max())
    ax.set_aspect("equal")
    ax.set_xlabel("x (mm)")
    ax.set_ylabel("y (mm)")
    ax.set_title(title or f"cam at {math.degrees(theta) % 360:.0f} deg, {where}")
    return fig


def _oscillating_follower(ax, rig, follower, contact, size: float) -> str:
    """The paper's follower on ``ax`` (mm): its bar's axis from P, its face, P and the contact."""
    a, chi = float(contact.q[0]), float(contact.on_face[0])
    u, n = np.array([math.cos(a), -math.sin(a)]), np.array([math.sin(a), math.cos(a)])
    P = -np.asarray(follower.P_to_E)
    reach = max(chi * 1.3, size * 2.5)
    face = np.array([P + t * u + rig.w_b / 2 * n for t in (0.0, reach)])
    axis = np.array([P, P + reach * u])
    ax.plot(axis[:, 0] * 1e3, axis[:, 1] * 1e3, color="C0", lw=0.8, ls="--")
    ax.plot(face[:, 0] * 1e3, face[:, 1] * 1e3, color="C0", lw=2.0)
    ax.plot([P[0] * 1e3], [P[1] * 1e3], "o", color="C0")
    O = P + chi * u + rig.w_b / 2 * n
    ax.plot([O[0] * 1e3], [O[1] * 1e3], "o", color="C3", ms=4)
    return f"follower at {math.degrees(a):.2f} deg"


def _translating_follower(ax, rig, follower, contact, size: float) -> str:
    """The translating follower on ``ax`` (mm): its guide's axis, its face at y along the guide, the
    contact (at ``on_face`` from the axis along the face's unit t)."""
    y, along = float(contact.q[0]), float(contact.on_face[0])
    g = np.array([math.cos(follower.gamma), math.sin(follower.gamma)])
    t = follower.along_face
    axis0 = follower.offset * t
    half = max(abs(along) * 1.3, size)
    face = np.array([axis0 + y * g + k * half * t for k in (-1.0, 1.0)])
    axis = np.array([axis0 + y * g, axis0 + (y + 2 * size) * g])
    ax.plot(axis[:, 0] * 1e3, axis[:, 1] * 1e3, color="C0", lw=0.8, ls="--")
    ax.plot(face[:, 0] * 1e3, face[:, 1] * 1e3, color="C0", lw=2.0)
    O = axis0 + y * g + along * t
    ax.plot([O[0] * 1e3], [O[1] * 1e3], "o", color="C3", ms=4)
    return f"follower at y = {y * 1e3:.2f} mm"
