"""Fig. 16: alpha spectra of the linearized and the non-linear model (300 rev/min, line
contact 1.6 mm, Coulomb friction, damping D): super-harmonics and side bands only in the
non-linear one. The paper's linear model (Eqs. 36-38, as printed) and camdyn's exact
Jacobian linearization are both shown."""
from __future__ import annotations

from types import SimpleNamespace

import numpy as np

import camdyn
from camdyn.analysis.signal import peak_frequency, spectrum

from .common import Context, StudyOutput, figure, fmt, md_table, reference_rig, save, simulate, spectrum_panels

NAME, TITLE = "fig16", "Fig. 16: linearized vs non-linear model"
FS = 20_000.0
SPEED_RPM = 300.0
MODELS = [("nonlinear", "non-linear", "tab:blue"), ("linear_paper", "linear, Eqs. 36–38 as printed", "tab:red"),
          ("linear_exact", "linear, exact Jacobian linearization", "tab:green")]


def instantaneous_frequency(rig, scene, cam, result) -> np.ndarray:
    """sqrt(-d alpha_ddot / d alpha) / 2 pi (Hz) along the run: the stiffness the follower sees
    as the cam turns (the contact point moves along the follower); NaN where no kernel applies."""
    from camdyn.model.model import Model
    model = Model(rig, scene, cam)
    out = np.full(result.t.size, np.nan)
    for name in set(result.regime.tolist()):
        m = model.mode(name)
        if not model.kernels.CONTACT_OF_MODE[m]:
            continue
        for i in np.flatnonzero(result.regime == name):
            d0 = model.jacobian(m, result.t[i], result.alpha[i], result.alpha_dot[i])[0]
            out[i] = np.sqrt(-d0) / (2 * np.pi) if d0 < 0 else np.nan
    return out


def instantaneous_frequency_at(rig, scene, cam, result, rows) -> np.ndarray:
    """:func:`instantaneous_frequency` on the samples ``rows`` of ``result`` only."""
    sub = SimpleNamespace(t=result.t[rows], alpha=result.alpha[rows], alpha_dot=result.alpha_dot[rows],
                          regime=result.regime[rows])
    return instantaneous_frequency(rig, scene, cam, sub)


def run(ctx: Context) -> StudyOutput:
    rig = reference_rig()
    revs = 2 if ctx.fast else 10
    fig, ax = figure(1, 2, figsize=(11, 4))
    rows, numbers = [], {}
    for model, label, color in MODELS:
        row, numbers[model] = _model_run(rig, revs, model, label, color, ax)
        rows.append(row)
    spectrum_panels(ax, "(a) harmonics of Ω_c", "(b) around the natural frequency")
    png = save(fig, ctx.png("fig16"))
    return StudyOutput(NAME, TITLE, _markdown(png, revs, rows, numbers), numbers, [png])


def _model_run(rig, revs: int, model: str, label: str, color: str, ax) -> tuple[list, dict]:
    """One model at SPEED_RPM drawn on both panels; its table row and its numbers (the harmonics,
    the resonance peak, the natural frequency along the last revolution)."""
    fc = SPEED_RPM / 60.0
    scene = camdyn.Scene(contact="line", damping="D", friction="coulomb", model=model)
    r = simulate(rig, scene, speed_rpm=SPEED_RPM, revolutions=revs, sample_rate_Hz=FS)
    n = int(round(revs * r.period * FS))
    f, A = spectrum(r.t[:n], r.alpha[:n], window="rect")
    h = np.array([A[np.argmin(np.abs(f - k * fc))] for k in range(1, 7)])
    peak = peak_frequency(f, A, fmin=1700.0, fmax=2700.0)
    step = max(1, int(FS / 2000))  # the stiffness along one revolution, every 0.5 ms
    last = np.flatnonzero(r.t >= r.t[-1] - r.period)[::step]
    finst = instantaneous_frequency_at(rig, scene, camdyn.ConstantSpeed(SPEED_RPM), r, last)
    fmin_i, fmax_i = float(np.nanmin(finst)), float(np.nanmax(finst))
    low = f <= 40
    ax[0].semilogy(f[low], A[low], ".-", ms=3, lw=0.7, color=color, label=label)
    band = (f > 1800) & (f < 2600)
    ax[1].semilogy(f[band], A[band], lw=0.7, color=color, label=f"{label}: peak {peak:.0f} Hz")
    row = [label, fmt(h[0], 3), fmt(h[1] / h[0], 3), fmt(h[2] / h[0], 3), f"{peak:.0f}",
           f"{fmin_i:.0f} … {fmax_i:.0f}", r.outcome.name]
    return row, {"fundamental": float(h[0]), "harmonics_over_fundamental": (h[1:] / h[0]).tolist(),
                 "peak_Hz": peak, "instantaneous_Hz": [fmin_i, fmax_i],
                 "outcome": r.outcome.name, "backend": r.meta.get("backend")}


def _markdown(png, revs: int, rows: list, numbers: dict) -> str:
    """The figure, the paper's statement, camdyn's harmonics and side bands, and the table."""
    nl, lp = numbers["nonlinear"], numbers["linear_paper"]
    return "\n\n".join([
        f"![Fig. 16](img/{png.name})",
        "The paper (Sec. 8): 'the linear system has only the fundamental harmonic of Ω_c while the non-linear "
        "system exhibits the super-harmonics of Ω_c ... The linear system has a single peak at the natural "
        "frequency of the system, but the non-linear system displays side bands associated with this peak.'",
        f"camdyn (reference rig, 300 rev/min, {revs} revolutions, rectangular window over whole revolutions): "
        f"the second harmonic is {fmt(nl['harmonics_over_fundamental'][0], 3)} of the fundamental in the "
        f"non-linear model against {fmt(lp['harmonics_over_fundamental'][0], 3)} in the printed linear model. "
        "Eq. 38c keeps sin(α* + Θ(t)) exactly in the forcing, so the printed linear model is not purely "
        "sinusoidal in its forcing either: its forcing is a pure first harmonic of Ω_c because the parametric "
        "term is dropped from K_l (misprint 9) — the super-harmonics of the non-linear model come from the "
        "kinematic non-linearity (sin, cos of α) and from the parametric stiffness. Side bands at ϑ ± k Ω_c "
        "come from that parametric modulation: the stiffness the follower sees changes as the contact point "
        f"moves along it, so its natural frequency sweeps {nl['instantaneous_Hz'][0]:.0f}–"
        f"{nl['instantaneous_Hz'][1]:.0f} Hz over a revolution in the non-linear model, against a constant "
        f"{lp['instantaneous_Hz'][0]:.0f} Hz in the printed linear one. With f_c = 5 Hz the side bands are "
        "spaced closer than the resonance's half-power bandwidth (2 ζ ϑ ≈ 44 Hz at ζ_D = 0.01), so in camdyn's "
        "spectrum they merge into a broadened, shifted peak rather than separate lines.",
        md_table(["model", "α amplitude at f_c (rad)", "2 f_c / f_c", "3 f_c / f_c", "peak (Hz)",
                  "natural frequency along the run (Hz)", "outcome"], rows),
    ])
