"""Figs. 4-5: alpha_r rms and peak-to-peak against speed for damping models A-E, on the
experiment's settings; normalised alpha_r time histories at 155 rev/min; and the
periodicity of each run (Poincare section once per cam revolution), which is how the
paper's "chaos beyond 155 rev/min" statements are checked."""
from __future__ import annotations

import numpy as np

from .common import (CONFIDENCE_SE, EXPERIMENT_SPEEDS, Context, StudyOutput, chaos_by_lyapunov, continuation_start,
                     experiment_rig, figure, fmt, impact_run, md_table, parallel_map, save)

NAME, TITLE = "fig4-5", "Figs. 4–5: residual response against speed, damping models A–E"
MODELS = "ABCDE"
COLORS = dict(A="tab:blue", B="tab:orange", C="tab:green", D="tab:red", E="tab:purple")


def settings(fast: bool) -> dict:
    if fast:
        return dict(speeds=[135.0, 155.0], revolutions=6, transient=3, max_revolutions=9, history=2, batches=3)
    speeds = sorted(set(EXPERIMENT_SPEEDS) | {125.0, 130.0, 165.0})
    return dict(speeds=speeds, revolutions=200, transient=100, max_revolutions=500, history=6, batches=10)


def _job(args):
    """One damping model over the speeds, in increasing order, from two starts: the static
    equilibrium (Sec. 4) and, from the second speed on, the end state of the previous speed's
    up-sweep run (a slow up-sweep): different classes or amplitudes from the two starts reveal
    coexisting motions."""
    rig, d, s = args
    out, prev = [], None
    for sp in s["speeds"]:
        r = impact_run(rig, d, sp, s["revolutions"], s["transient"], max_revolutions=s["max_revolutions"],
                       keep_history=s["history"] if sp == 155.0 else 0.0)
        r.update(chaos_by_lyapunov(rig, d, sp, s["transient"], s["revolutions"] - s["transient"], s["batches"]))
        if prev is not None:
            y0, t_start = continuation_start(prev["end_state"], prev["speed_rpm"], sp)
            u = impact_run(rig, d, sp, s["revolutions"], s["transient"], max_revolutions=s["max_revolutions"],
                           y0=y0, t_start=t_start)
        else:
            u = r
        r["up"] = {k: u.get(k) for k in ("class", "rms", "p2p", "revolutions", "outcome")}
        out.append(r)
        # the sweep goes on from where this speed ended; after a stop (the follower thrown to 90
        # degrees) from the static-equilibrium run's end state instead
        prev = next((x for x in (u, r) if x.get("outcome") == "SUCCESS" and "end_state" in x), None)
    return out


def coexist(r) -> bool:
    """The two starts end on different motions (class, or peak-to-peak by more than 10 %)."""
    up = r.get("up") or {}
    if up.get("class") != r["class"]:
        return True
    a, b = r.get("p2p"), up.get("p2p")
    return a is not None and b is not None and abs(a - b) > 0.1 * max(abs(a), abs(b), 1e-12)


def run(ctx: Context) -> StudyOutput:
    rig = experiment_rig()
    s = settings(ctx.fast)
    jobs = [(rig, d, s) for d in MODELS]
    ctx.log(f"{NAME}: {len(MODELS)} models x {len(s['speeds'])} speeds x 2 starts, {s['revolutions']} revolutions "
            f"(up to {s['max_revolutions']} while aperiodic)")
    runs = [r for rs in parallel_map(_job, jobs, ctx.fast) for r in rs]
    by = {(r["damping"], r["speed_rpm"]): r for r in runs}
    png = _figure(ctx, by, s["speeds"])
    found = _findings(by, s)
    numbers = {"first_aperiodic_rpm": found["first_aperiodic"], "first_chaotic_rpm_lyapunov": found["first_chaotic"],
               "chaos_at_155_lyapunov": found["chaos155"], "first_aperiodic_rpm_upsweep": found["first_aperiodic_up"],
               "class_at_155": found["at155"], "coexisting_rpm": found["coexisting"],
               "runs": [{k: v for k, v in r.items() if k not in ("section", "t", "alpha_r", "end_state")} for r in runs]}
    return StudyOutput(NAME, TITLE, _markdown(png, rig, s, by, found), numbers, [png])


def _first(speeds: list, test) -> float | None:
    """The least speed that passes ``test`` (None: none does)."""
    hits = [sp for sp in speeds if test(sp)]
    return min(hits) if hits else None


def _findings(by: dict, s: dict) -> dict:
    """Per model: the first aperiodic speed from each start, the class and the chaos verdict at
    155 rev/min, the first chaotic speed (by lambda_1), whether lambda_1 judged any run, the speeds
    where the two starts end on different motions, and the runs continued past s["revolutions"]."""
    speeds = s["speeds"]
    return {
        "first_aperiodic": {d: _first(speeds, lambda sp: by[d, sp]["class"] == "aperiodic") for d in MODELS},
        "first_aperiodic_up": {d: _first(speeds, lambda sp: (by[d, sp].get("up") or {}).get("class") == "aperiodic")
                               for d in MODELS},
        "at155": {d: by[d, 155.0]["class"] for d in MODELS if (d, 155.0) in by},
        "chaos155": {d: by[d, 155.0].get("chaos") for d in MODELS if (d, 155.0) in by},
        "first_chaotic": {d: next((sp for sp in speeds if by[d, sp].get("chaos") == "chaotic"), None) for d in MODELS},
        "judged": {d: any(by[d, sp].get("chaos") not in (None, "n/a") for sp in speeds) for d in MODELS},
        "coexisting": {d: [sp for sp in speeds[1:] if coexist(by[d, sp])] for d in MODELS},
        "extended": {d: [sp for sp in speeds if by[d, sp].get("revolutions", 0) > s["revolutions"]] for d in MODELS},
    }


def _cell(r: dict, s: dict) -> str:
    """One run in the table: its class and statistics, lambda_1, its length if continued, and the
    up-sweep's motion where it differs."""
    text = f"{r['class']}, rms {fmt(r['rms'], 3)}, p-p {fmt(r['p2p'], 3)}"
    if r.get("lyapunov") is not None:
        text += f", λ1 {fmt(r['lyapunov'], 3)} ± {fmt(r['lyapunov_se'], 2)} 1/s ({r['chaos']})"
    if r.get("revolutions", s["revolutions"]) > s["revolutions"]:
        text += f" ({r['revolutions']:g} rev)"
    if r.get("up") and r["up"] is not r and coexist(r):
        text += f"; up-sweep: {r['up']['class']}, p-p {fmt(r['up']['p2p'], 3)}"
    return text


def _markdown(png, rig, s: dict, by: dict, found: dict) -> str:
    """The study's section: the figure, the protocol, the paper's statements checked, the table."""
    speeds = s["speeds"]
    rows = [[f"{sp:g}"] + [_cell(by[d, sp], s) for d in MODELS] for sp in speeds]
    checks = (_checks(found["first_aperiodic"], found["at155"], speeds)
              + _lyapunov_checks(found["first_chaotic"], found["chaos155"], found["judged"]))
    coexisting, extended, first_aperiodic_up = found["coexisting"], found["extended"], found["first_aperiodic_up"]
    n_co = sum(len(v) for v in coexisting.values())
    co_text = "; ".join(f"{d}: {', '.join(f'{v:g}' for v in coexisting[d])}" for d in MODELS if coexisting[d])
    return "\n\n".join([
        f"![Figs. 4-5](img/{png.name})",
        _protocol(rig, s),
        "**Not compared with measurements:** the paper's Figs. 4–5 plot the measured α_r of Alzate et al. "
        "(2007) and their analytical results; those data are not available here, so only the paper's "
        "statements are compared.",
        md_table(["the paper states (Sec. 4)", "camdyn", "reproduced"], checks),
        "Up-sweep start, first aperiodic speed: " + ", ".join(
            f"{d} {fmt(first_aperiodic_up[d]) if first_aperiodic_up[d] else 'none'}" for d in MODELS) + ". "
        + (f"The two starts end on different motions at {n_co} model-speed pairs ({co_text})." if n_co else
           "The two starts end on the same motion at every speed.")
        + (" Runs continued beyond " + f"{s['revolutions']} revolutions: "
           + "; ".join(f"{d}: {', '.join(f'{v:g}' for v in extended[d])}" for d in MODELS if extended[d]) + "."
           if any(extended.values()) else ""),
        "Whether another assumed geometry (r_c, χ0, d_x, Θ0) of the reference rig reproduces the paper's onsets "
        "is scanned by `python -m camdyn.studies chaos-scan` (next section).",
        md_table(["Ω_c (rev/min)"] + [f"model {d}" for d in MODELS], rows),
    ])


def _protocol(rig, s: dict) -> str:
    """The settings, the classifier, the Lyapunov verdict, the continued runs and the two starts."""
    return (
        f"Experiment's settings (`reference-experiment`: line contact 16 mm, k_s = {rig.k_s:.3g} N/m, "
        f"Coulomb friction μ_m = 0.3, the damping constants of Section 4), constant cam speed, started from "
        f"the static equilibrium (as in Sec. 4); {s['revolutions']} revolutions per run, statistics over the last "
        f"{s['revolutions'] - s['transient']} (the first {s['transient']} are dropped as transient). "
        "A run is *periodic (Pn)* when its Poincaré section (α_r once per cam revolution) repeats with period "
        "n ≤ 8 to 0.2 % of its peak-to-peak, else *aperiodic* (chaotic or a long transient). "
        f"Chaos is judged by the largest Lyapunov exponent λ1 of the same window (tangent dynamics with "
        f"saltation matrices, `camdyn.orbits.lyapunov`, renormalised every revolution, from the static equilibrium "
        f"after the same {s['transient']} transient revolutions; ± the standard error of {s['batches']} batch "
        f"means): *chaotic* where λ1 > {CONFIDENCE_SE:g} standard errors, *regular* where λ1 < −{CONFIDENCE_SE:g} "
        "standard errors, else *undecided*. Where the tangent integration cannot pass an impact law's unbounded "
        "Jacobian at first contact (damping C and E, c ∝ |ψ_i|^(1/4), at every impact; D's β k_λ|ψ_i| on some "
        "runs), λ1 is measured by two neighbouring runs instead (`largest_by_differences`: Benettin's "
        "two-trajectory method on the same window, the neighbour 1e-7 rad away and again 1e-6 rad away; the "
        "verdict must hold at both distances, else it is *undecided* (`DifferenceEstimate.verdict`): on a "
        "strongly contracting orbit the neighbour falls below the runs' own error within a revolution and λ1 "
        "reads as that floor's, e.g. −28 1/s where the tangent dynamics give −800, its sign kept, its size not "
        "the orbit's). "
        f"A run whose last {s['revolutions'] - s['transient']} revolutions are aperiodic "
        f"is continued, {s['revolutions'] - s['transient']} revolutions at a time, up to {s['max_revolutions']} "
        "in all, and classed by its last window, so that a motion wandering between coexisting attractors "
        "before it settles is classed by where it settles (the run length is then given in the table). Each "
        "speed is also run from a second start, the end state of the next slower speed's run (a slow "
        "up-sweep; after a run that stopped, the sweep goes on from the static-equilibrium run's end state); where the two starts end on different motions (class, or peak-to-peak differing by more "
        "than 10 %) the table gives both: the rig is multistable there. The first-aperiodic speeds below are "
        "those of the static-equilibrium start, the paper's protocol.")


def _figure(ctx: Context, by: dict, speeds: list):
    """Figs. 4-5: rms and peak-to-peak against speed, the Poincare sections, and the normalised
    alpha_r histories at 155 rev/min; returns the PNG path."""
    fig, ax = figure(2, 2, figsize=(11, 7.5))
    for d in MODELS:
        rms = [by[d, sp]["rms"] for sp in speeds]
        p2p = [by[d, sp]["p2p"] for sp in speeds]
        ax[0, 0].plot(speeds, [np.nan if v is None else v for v in rms], "o-", ms=3, color=COLORS[d], label=f"model {d}")
        ax[0, 1].plot(speeds, [np.nan if v is None else v for v in p2p], "o-", ms=3, color=COLORS[d], label=f"model {d}")
        for k, sp in enumerate(speeds):
            sec = np.asarray(by[d, sp].get("section", []))
            off = (MODELS.index(d) - 2) * 0.35
            ax[1, 0].plot(np.full(sec.size, sp + off), sec, ".", ms=2, color=COLORS[d],
                          label=f"model {d}" if k == 0 else None)
    for a, lab in ((ax[0, 0], "α_r rms (rad)"), (ax[0, 1], "α_r peak-to-peak (rad)")):
        a.set_xlabel("cam speed Ω_c (rev/min)")
        a.set_ylabel(lab)
        a.set_yscale("log")
        a.grid(alpha=0.3)
        a.legend(fontsize=8)
    ax[0, 0].set_title("(a) Fig. 4(a): rms of α_r after the transient")
    ax[0, 1].set_title("(b) Fig. 4(b): peak-to-peak of α_r")
    ax[1, 0].set_title("(c) α_r once per revolution (Poincaré): one dot = periodic")
    ax[1, 0].set_xlabel("cam speed Ω_c (rev/min), models offset for legibility")
    ax[1, 0].set_ylabel("α_r at Θ = Θ0 + 2πk (rad)")
    ax[1, 0].grid(alpha=0.3)
    ax[1, 0].legend(fontsize=8, markerscale=4)
    offset = 0.0
    for d in MODELS:
        r = by.get((d, 155.0))
        if r and "t" in r:
            ar = np.asarray(r["alpha_r"])
            mean = float(np.mean(ar)) if np.mean(ar) > 0 else 1.0
            ax[1, 1].plot(r["t"], ar / mean + offset, color=COLORS[d], lw=0.8, label=f"model {d}")
            offset += float(np.max(ar / mean)) * 1.1
    ax[1, 1].set_title("(d) Fig. 5: α_r / mean(α_r) at 155 rev/min (stacked)")
    ax[1, 1].set_xlabel("t / cam period")
    ax[1, 1].set_yticks([])
    ax[1, 1].legend(fontsize=8, loc="upper right")
    return save(fig, ctx.png("fig4-5"))


def _lyapunov_checks(first_chaotic: dict, chaos155: dict, judged: dict) -> list[list[str]]:
    """The statements of Sec. 4 on chaos judged by the largest Lyapunov exponent, for the
    models that have one (judged[d])."""

    def yes(ok):
        return "yes" if ok else "**no**"

    def first(d):
        if not judged[d]:
            return f"{d}: no exponent (n/a)"
        return f"{d}: first chaotic (λ1 > 0) at {fmt(first_chaotic[d])} rev/min" if first_chaotic[d] \
            else f"{d}: none chaotic"

    bd = all(judged[d] and first_chaotic[d] is not None and first_chaotic[d] >= 155.0 for d in "BD")
    ac = [d for d in "AC" if judged[d]]
    e_ok = judged["E"] and first_chaotic["E"] is not None and first_chaotic["E"] < 155.0
    return [
        ["B and D chaotic above about 155 rev/min (by λ1)", ", ".join(first(d) for d in "BD"), yes(bd)],
        ["E chaotic before 155 rev/min (by λ1)", first("E"), yes(e_ok)],
        ["A and C still periodic at 155 rev/min (by λ1)",
         ", ".join(f"{d}: {chaos155.get(d)}" for d in ac) + ("; C: n/a" if "C" not in ac else ""),
         yes(bool(ac) and all(chaos155.get(d) == "regular" for d in ac))],
    ]


def _checks(first_aperiodic: dict, at155: dict, speeds: list) -> list[list[str]]:
    """The paper's Section 4 statements, camdyn's result and whether it reproduces them."""

    def yes(ok):
        return "yes" if ok else "**no**"

    above = [sp for sp in speeds if sp >= 155.0]
    bd_ok = all(first_aperiodic[d] is not None and first_aperiodic[d] >= 155.0 for d in "BD")
    return [
        ["B and D chaotic above about 155 rev/min (periodic below 155, aperiodic from 155 on)", ", ".join(
            f"{d}: first aperiodic at {fmt(first_aperiodic[d])} rev/min" if first_aperiodic[d] else f"{d}: none aperiodic"
            for d in "BD"), yes(bd_ok and bool(above))],
        ["E chaotic before 155 rev/min", f"E: first aperiodic at {fmt(first_aperiodic['E'])} rev/min"
         if first_aperiodic["E"] else "E: none aperiodic",
         yes(first_aperiodic["E"] is not None and first_aperiodic["E"] < 155.0)],
        ["A and C still periodic at 155 rev/min", f"A: {at155.get('A')}, C: {at155.get('C')}",
         yes(str(at155.get("A", "")).startswith("P") and str(at155.get("C", "")).startswith("P"))],
    ]
