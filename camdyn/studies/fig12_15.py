"""Figs. 12-15: relative sliding velocity v_r, friction force F_f and bearing force N_x for
Coulomb (model I) vs smoothed Coulomb friction (model II, s = 10), at e = 0.7 r_c: at a
constant 50 rev/min (Figs. 12-13) and for the oscillating cam, Theta_p = pi, omega_c = 40
rev/min (Figs. 14-15). With the printed v_r (misprint 8), as the paper did, and beside it
with the kinematically derived v_r."""
from __future__ import annotations

import math

import numpy as np

import camdyn
from camdyn.analysis.statics import contact_loss_speed

from .common import Context, StudyOutput, figure, fmt, md_table, reference_rig, save, simulate

NAME, TITLE = "fig12-15", "Figs. 12–15: friction models, printed and kinematic v_r"
FRICTION = [("coulomb", "Coulomb (model I)", "tab:blue", "-"), ("tanh", "smoothed, s = 10 (model II)", "tab:orange", "--")]
VR = [("printed", "printed v_r (as the paper)"), ("kinematic", "kinematic v_r (derived)")]


def _runs(rig, fast):
    periods = 1.0 if fast else 2.0
    out = {}
    for motion, cam in (("constant", camdyn.ConstantSpeed(50.0)), ("oscillating", camdyn.Oscillating(math.pi, 40.0))):
        for vr, _ in VR:
            for fr, *_ in FRICTION:
                scene = camdyn.Scene(contact="line", damping="D", friction=fr, motion=motion, sliding_velocity=vr)
                out[motion, vr, fr] = simulate(rig, scene, cam, revolutions=periods,
                                               sample_rate_Hz=5000.0 if fast else 20000.0)
    return out


def _sign_changes(v):
    s = np.sign(v[np.abs(v) > 1e-9])
    return int(np.count_nonzero(np.diff(s)))


def run(ctx: Context) -> StudyOutput:
    rig = reference_rig().replace(e=0.7 * reference_rig().r_c)
    loss = contact_loss_speed(rig)
    runs = _runs(rig, ctx.fast)
    numbers = {"/".join(key): _numbers(r) for key, r in runs.items()}
    pngs = [_figure(ctx, runs, motion, figs) for motion, figs in (("constant", "12-13"), ("oscillating", "14-15"))]
    md = _markdown(pngs, loss, _rows(runs, numbers), numbers, ctx.fast)
    numbers["contact_loss_rpm_e07"] = loss
    return StudyOutput(NAME, TITLE, md, numbers, pngs)


def _numbers(r) -> dict:
    """One run's outcome and ranges, and its sign changes of v_r and samples sticking."""
    return {"outcome": r.outcome.name, "backend": r.meta.get("backend"),
            "v_r_sign_changes": _sign_changes(r.v_r),
            "periods": float((r.t[-1] - r.t[0]) / r.period), "v_r_min": float(r.v_r.min()),
            "v_r_max": float(r.v_r.max()), "F_f_range": [float(r.F_f.min()), float(r.F_f.max())],
            "N_x_range": [float(r.N_x.min()), float(r.N_x.max())],
            "stick_samples": int(np.count_nonzero(np.char.find(r.regime.astype(str), "stick") >= 0)),
            "impacts": int(len(r.impacts()))}


def _rows(runs: dict, numbers: dict) -> list[list]:
    """The table's rows, in the figures' order (cam motion, then v_r, then friction)."""
    rows = []
    for key, r in runs.items():
        n = numbers["/".join(key)]
        rows.append([*key, r.outcome.name, n["v_r_sign_changes"],
                     f"{fmt(r.v_r.min(), 3)} … {fmt(r.v_r.max(), 3)}",
                     f"{fmt(r.F_f.min(), 3)} … {fmt(r.F_f.max(), 3)}",
                     f"{fmt(r.N_x.min(), 3)} … {fmt(r.N_x.max(), 3)}", n["stick_samples"]])
    return rows


def _figure(ctx: Context, runs: dict, motion: str, figs: str):
    """v_r, F_f and N_x of one cam motion, printed v_r left and kinematic right; the PNG path."""
    fig, ax = figure(3, 2, figsize=(12, 8.5), sharex=True)
    for j, (vr, vr_label) in enumerate(VR):
        for fr, fr_label, color, ls in FRICTION:
            r = runs[motion, vr, fr]
            x = (r.t - r.t[0]) / r.period
            for i, (q, unit) in enumerate((("v_r", "m/s"), ("F_f", "N"), ("N_x", "N"))):
                ax[i, j].plot(x, getattr(r, q), color=color, ls=ls, lw=0.9,
                              label=f"{fr_label}" + ("" if r.ok else f" — stopped: {r.outcome.name}"))
                ax[i, j].set_ylabel(f"{q} ({unit})")
                ax[i, j].grid(alpha=0.3)
        ax[0, j].set_title(vr_label)
        ax[0, j].legend(fontsize=7)
        ax[2, j].set_xlabel("t / T (cam revolutions)" if motion == "constant" else "t / T (oscillation periods)")
    what = ("constant speed 50 rev/min" if motion == "constant"
            else "oscillating cam, Θ_p = π, ω_c = 40 rev/min")
    fig.suptitle(f"Figs. {figs}: e = 0.7 r_c, {what}, damping D (ζ_D = 0.01, β_D = 4.25 s/m)")
    return save(fig, ctx.png(f"fig{figs}"))


def _markdown(pngs: list, loss: float, rows: list, c: dict, fast: bool) -> str:
    """The figures, the settings, the paper's statements against camdyn's runs (``c``: their
    numbers by "motion/v_r/friction"), the table."""
    return "\n\n".join([
        f"![Figs. 12-13](img/{pngs[0].name})",
        f"![Figs. 14-15](img/{pngs[1].name})",
        f"Reference rig with e = 0.7 r_c (contact lost only above {loss:.4g} rev/min by inverse kinematics, so "
        "50 rev/min is in sliding contact, as the paper verified), line contact 1.6 mm, damping D, "
        "μ_m = 0.3. Left: the paper's printed sliding velocity v_r = ψ̇_j − (r_c + e sin(α+Θ))(α̇ + Θ̇); "
        "right: the relative velocity of the two material points at the contact (misprint 8). Coulomb "
        "friction switches sign with v_r; where v_r reaches zero and both sides' fields point at it, "
        "both backends follow the Filippov sticking motion (`stick` regimes); the backend of each run "
        "is recorded with its numbers.",
        "The paper (Sec. 7.2): at e = 0.7 r_c and 50 rev/min 'a change in direction in v_r(t) is introduced "
        "(twice per revolution of the cam)'; F_f and N_x with model I are 'discontinuous during the change in "
        "direction of v_r(t) followed by some high frequency oscillations', smoothed by model II; for the "
        "oscillating cam v_r < 0 for nearly half the period and > 0 for the other part, and when |v_r| ≫ 0 "
        "the two models are very close.",
        f"camdyn: with the **printed** v_r at constant speed, v_r changes sign "
        f"{c['constant/printed/tanh']['v_r_sign_changes'] / c['constant/printed/tanh']['periods']:g} times per "
        f"revolution with model II (the paper's "
        f"twice per revolution); with the **kinematic** v_r it keeps its sign "
        f"({c['constant/kinematic/tanh']['v_r_sign_changes']} changes: v_r = −Ω_c (r_c + e sin(α+Θ)) + "
        f"α̇ w_b/2 stays negative for e < r_c), so at constant speed the friction force never reverses and "
        f"models I and II differ only by tanh(s v_r) < 1. What changes: the discontinuity of Figs. 12–13 "
        f"exists only through the printed v_r. For the oscillating cam v_r reverses with Θ̇ under either "
        f"form (kinematic: {c['oscillating/kinematic/tanh']['v_r_sign_changes']} changes over "
        f"{'one period' if fast else 'two periods'}, model II), so the discontinuity of Figs. 14–15 is "
        f"physical; the two forms differ in the size and timing of v_r.",
        md_table(["cam", "v_r", "friction", "outcome", "v_r sign changes over the run", "v_r (m/s)", "F_f (N)", "N_x (N)",
                  "samples sticking"], rows),
    ])
