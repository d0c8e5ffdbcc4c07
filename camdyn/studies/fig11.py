"""Fig. 11: F_n(t) for the two directions of cam rotation (line contact 1.6 mm, 300 rev/min):
the self-energizing rig has the higher mean normal force."""
from __future__ import annotations

import numpy as np

import camdyn

from .common import Context, StudyOutput, figure, fmt, md_table, reference_rig, save, simulate

NAME, TITLE = "fig11", "Fig. 11: F_n(t), de- vs self-energizing"


def run(ctx: Context) -> StudyOutput:
    rig = reference_rig()
    revs, skip = (1.5, 0.5) if ctx.fast else (4.0, 2.0)
    scene = camdyn.Scene(contact="line", damping="D", friction="coulomb")
    fig, ax = figure(1, 1, figsize=(8, 3.8))
    rows, numbers = [], {}
    for speed, label, color in ((300.0, "de-energizing (+300 rev/min)", "tab:blue"),
                                (-300.0, "self-energizing (−300 rev/min)", "tab:orange")):
        r = simulate(rig, scene, speed_rpm=speed, revolutions=revs, sample_rate_Hz=20_000.0)
        s = r.after(r.t[0] + skip * r.period)
        x = (s.t - s.t[0]) / r.period
        ax.plot(x, s.F_n, lw=0.9, color=color, label=label)
        mean = float(np.mean(s.F_n))
        ax.axhline(mean, color=color, ls=":", lw=1)
        rows.append([label, fmt(mean, 4), fmt(float(s.F_n.min()), 4), fmt(float(s.F_n.max()), 4),
                     fmt(float(np.mean(s.F_f)), 4), r.outcome.name])
        numbers["de" if speed > 0 else "se"] = {"mean_F_n": mean, "min_F_n": float(s.F_n.min()),
                                                "max_F_n": float(s.F_n.max()), "mean_F_f": float(np.mean(s.F_f)),
                                                "outcome": r.outcome.name}
    ax.set_xlabel("t / T (cam revolutions, after the start-up)")
    ax.set_ylabel("F_n (N)")
    ax.set_title("Fig. 11: normal contact force, line contact 1.6 mm, μ_m = 0.3 (dotted: means)")
    ax.grid(alpha=0.3)
    ax.legend(fontsize=8)
    png = save(fig, ctx.png("fig11"))
    de, se = numbers["de"]["mean_F_n"], numbers["se"]["mean_F_n"]
    numbers["se_over_de_mean"] = se / de
    md = "\n\n".join([
        f"![Fig. 11](img/{png.name})",
        "The paper (Sec. 7.1): 'The self-energizing system has a higher mean component of F_n(t) compared to "
        "the de-energizing system; this is because the F_f(t) increases the F_n(t) in the self-energizing "
        "system which in turn increases F_f(t).'",
        f"camdyn (reference rig, damping D, Coulomb friction, {revs - skip:g} revolutions after {skip:g} "
        f"dropped): mean F_n = {fmt(se, 4)} N self-energizing against {fmt(de, 4)} N de-energizing "
        f"({100 * (se / de - 1):+.2f} %): "
        + ("**agrees**." if se > de else "**disagrees**.")
        + " With a friction moment −½ F_f w_b, the contact must carry the spring moment through the arm "
          "χ* ∓ μ w_b / 2, so the ratio is about (χ* + μ w_b/2)/(χ* − μ w_b/2).",
        md_table(["rotation", "mean F_n (N)", "min F_n (N)", "max F_n (N)", "mean F_f (N)", "outcome"], rows),
    ])
    return StudyOutput(NAME, TITLE, md, numbers, [png])
