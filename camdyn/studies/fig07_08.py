"""Figs. 7-8: alpha_rp against speed from the contact model (damping D, experiment's
settings) and from the approximate energy balance of Section 5 for several restitution
coefficients xi, at low speeds (Fig. 7) and over a broad range (Fig. 8, saturation at
1.36 rad as alpha reaches 90 degrees); near the contact-loss speed the period-1 branches
continued with their stability (camdyn.continue_orbit): the contact orbit through its grazing,
and the large flight orbit down to its fold."""
from __future__ import annotations

import math
from typing import NamedTuple

import numpy as np
from scipy.optimize import brentq

import camdyn
from camdyn.analysis.statics import energy_balance_peak, static_equilibrium
from camdyn.io.plots import EVENT_MARKERS, stability_runs

from .common import PAPER, Context, StudyOutput, experiment_rig, figure, fmt, impact_run, md_table, parallel_map, save

NAME, TITLE = "fig7-8", "Figs. 7–8: α_rp against speed, contact model and energy balance"
XI_LOW = (0.05, 0.2, 0.4, 0.6)
XI_BROAD = (0.2, 0.6, 1.0)
#: the samples per second of the run along a continued orbit for its alpha_rp (at 100-175 rev/min
#: at least 1,300 samples per revolution)
SAMPLE_RATE_HZ = 4000.0


def settings(fast: bool) -> dict:
    if fast:
        return dict(low=[135.0, 155.0], broad=[600.0], revolutions=6, transient=3, broad_revolutions=4,
                    branches=[BranchLeg("flight", 160.0, 150.0, "differences")])
    return dict(low=[110.0, 120.0, 130.0, 135.0, 140.0, 145.0, 150.0, 155.0, 160.0, 170.0, 180.0, 200.0],
                broad=[250.0, 350.0, 500.0, 700.0, 1000.0, 1500.0, 2000.0, 3000.0, 5000.0],
                revolutions=80, transient=40, broad_revolutions=40,
                branches=[BranchLeg("contact", 120.0, 175.0, "variational"),
                          BranchLeg("flight", 170.0, 100.0, "differences")])


class BranchLeg(NamedTuple):
    """One continuation in the cam speed (rev/min) from ``start`` toward ``end``: the contact
    orbit needs the variational Jacobian (its contact deflection, ~1e-11 m, is far below any
    finite-difference step the map's noise allows: the perturbed states leave the contact);
    the flight orbit is continued with finite differences."""

    name: str
    start: float
    end: float
    jacobian: str


def branch(leg: BranchLeg, rig=None) -> dict:
    """A leg continued (damping D, line contact, Coulomb, phase 0) with each orbit's alpha_rp:
    the peak-to-peak of alpha_r over one orbit, run by camdyn.simulate from the orbit's state
    at the section at SAMPLE_RATE_HZ.  JSON-able: lambda, stable, alpha_rp, max_gap, events."""
    from camdyn.orbits.continuation import continue_orbit, events_table
    from camdyn.orbits.tangent import variational

    rig = rig or experiment_rig()
    scene = camdyn.Scene(contact="line", damping="D", friction="coulomb")
    kw = {"jacobian": variational} if leg.jacobian == "variational" else {}
    ds = continue_orbit(rig, scene, "speed_rpm", leg.start, leg.end, **kw)
    rp = []
    for lam, a, ad, n in zip(ds["lambda"].values, ds["alpha"].values, ds["alpha_dot"].values, ds["periods"].values):
        r = camdyn.simulate(rig, scene, speed_rpm=float(lam), revolutions=int(n), y0=(float(a), float(ad)),
                            sample_rate_Hz=SAMPLE_RATE_HZ)
        rp.append(float(np.ptp(r.alpha_r)) if r.ok else None)
    outcomes = ds.attrs["outcomes"].split()
    return {"name": leg.name, "lambda": ds["lambda"].values.tolist(), "stable": ds["stable"].values.tolist(),
            "alpha_rp": rp, "max_gap": ds["max_gap"].values.tolist(), "branch": ds["point_branch"].values.tolist(),
            "periods": ds["periods"].values.tolist(),
            "events": [{"kind": k, "speed_rpm": lam, "branch": b} for k, lam, b, _ in events_table(ds)],
            "end": outcomes[int(ds["branch_outcome"].values[0])]}


def _job(args):
    rig, speed, revs, transient = args
    r = impact_run(rig, "D", speed, revs, transient)
    return r


def xi_needed(rig, speed, alpha_rp):
    """The restitution coefficient for which the energy balance gives alpha_rp (None: outside [0, 1])."""
    if alpha_rp is None or not math.isfinite(alpha_rp):
        return None
    lo, hi = energy_balance_peak(rig, speed, 0.0), energy_balance_peak(rig, speed, 1.0)
    if alpha_rp < lo:
        return "< 0"
    if alpha_rp > hi:
        return "> 1"
    return brentq(lambda xi: energy_balance_peak(rig, speed, xi) - alpha_rp, 0.0, 1.0, xtol=1e-6)


def _draw_branches(ax, legs: list[dict]) -> None:
    """alpha_rp along each continued branch: solid where stable, dashed where not; a switched
    branch (period 2) in its own colour; events marked."""
    colours = {("contact", 1): "tab:blue", ("flight", 1): "tab:green"}
    labelled = set()
    for b in legs:
        lam, ok = np.array(b["lambda"]), np.array(b["stable"], dtype=bool)
        rp = np.array([np.nan if v is None else v for v in b["alpha_rp"]])
        for k in np.unique(b["branch"]):
            on = np.flatnonzero(np.array(b["branch"]) == k)
            n = int(np.array(b["periods"])[on[0]])
            for i, j, stable in stability_runs(ok[on]):   # as plots.branches draws them
                label = f"{b['name']} orbit, period {n}, continued ({'stable' if stable else 'unstable'})"
                rows = on[i:j + 1]
                ax.plot(lam[rows], rp[rows], color=colours.get((b["name"], n), "tab:purple"),
                        ls="-" if stable else "--", lw=1.1, label=label if label not in labelled else None)
                labelled.add(label)
        for e in b["events"]:
            on = np.array(b["branch"]) == e["branch"]
            order = np.argsort(lam[on])
            y = np.interp(e["speed_rpm"], lam[on][order], rp[on][order])
            ax.plot(e["speed_rpm"], y, EVENT_MARKERS.get(e["kind"], "x"), mfc="none", color="tab:red", ms=6)
            ax.annotate(e["kind"].replace("_", " "), (e["speed_rpm"], y), fontsize=7, xytext=(4, 4),
                        textcoords="offset points")


def _jump(runs: list[dict], flight: dict) -> tuple[float, float] | None:
    """The consecutive speeds of the runs from rest between which alpha_rp first reaches half the
    least alpha_rp of the stable flight orbit (period 1): where the run lands on the flight orbit."""
    on = [v for v, ok, n in zip(flight["alpha_rp"], flight["stable"], flight["periods"]) if ok and n == 1 and v]
    if not on:
        return None
    done = sorted((r["speed_rpm"], r["p2p"]) for r in runs if r["outcome"] == "SUCCESS" and r["p2p"] is not None)
    return next(((a, b) for (a, pa), (b, pb) in zip(done, done[1:]) if pa < 0.5 * min(on) <= pb), None)


def _branch_text(legs: list[dict], runs: list[dict], rig) -> str:
    """What the continued branches say about the jump of alpha_rp (the report's paragraph)."""
    from camdyn.analysis.statics import compliance_shift, contact_loss_speed

    def events(b, kind):
        return [e["speed_rpm"] for e in b["events"] if e["kind"] == kind]

    parts = []
    for b in legs:
        found = ", ".join(f"{e['kind'].replace('_', ' ')} at {e['speed_rpm']:.2f} rev/min" for e in b["events"])
        last = b["lambda"][int(np.flatnonzero(np.array(b["branch"]) == 0)[-1])]
        parts.append(f"the {b['name']} orbit from {b['lambda'][0]:.0f} rev/min ({found or 'no event'}; its branch "
                     f"ends at {last:.2f} rev/min, `{b['end']}`)")
    text = ("**Branches** (`camdyn.continue_orbit` in the cam speed, period 1, phase 0; the contact orbit with "
            "the variational Jacobian, `camdyn.orbits.tangent.variational`, because its contact deflection is below "
            "any finite-difference step): " + "; ".join(parts) + ".")
    contact = next((b for b in legs if b["name"] == "contact"), None)
    flight = next((b for b in legs if b["name"] == "flight"), None)
    if contact and flight and events(flight, "fold"):
        low, high = min(events(flight, "fold")), max(np.array(contact["lambda"])[np.array(contact["branch"]) == 0])
        jump = _jump(runs, flight)
        text += (f" Both stable orbits coexist from the flight orbit's fold at {low:.1f} rev/min to at least "
                 f"{high:.1f} rev/min, where the contact orbit's branch ends: there a run from the static "
                 "equilibrium stays near the contact orbit, and α_rp jumps only where the run reaches the flight "
                 "orbit" + (f" (between {jump[0]:g} and {jump[1]:g} rev/min in the table)" if jump else "") + ".")
        loss, shift = contact_loss_speed(rig), compliance_shift(rig)
        text += (f" The contact orbit grazes (its largest gap reaches 0) at "
                 f"{', '.join(f'{v:.4f}' for v in events(contact, 'grazing')) or '-'} rev/min; the "
                 f"inverse-kinematics contact-loss speed (Fig. 9) is {loss:.4f} rev/min and the compliance shift "
                 f"`camdyn.analysis.statics.compliance_shift` predicts {shift:.1e} of it.")
    return text


def run(ctx: Context) -> StudyOutput:
    rig = experiment_rig()
    s = settings(ctx.fast)
    jobs = [(rig, sp, s["revolutions"], s["transient"]) for sp in s["low"]]
    jobs += [(rig, sp, s["broad_revolutions"], s["broad_revolutions"] // 2) for sp in s["broad"]]
    ctx.log(f"{NAME}: {len(jobs)} runs")
    runs = parallel_map(_job, jobs, ctx.fast)
    legs = parallel_map(branch, s["branches"], ctx.fast)
    ctx.log(f"{NAME}: {sum(len(b['lambda']) for b in legs)} orbits continued")
    sat = math.pi / 2 - static_equilibrium(rig).alpha
    png = _figure(ctx, rig, s, runs, legs, sat)
    rows, numbers_runs = _table(rig, runs)
    found = _below_160(rig, numbers_runs)
    eb_top = energy_balance_peak(rig, 1e5, 1.0)
    md = "\n\n".join([
        f"![Figs. 7-8](img/{png.name})",
        "The paper (Sec. 5): 'below 160 rev/min, ξ should be less than 0.05 for successfully predicting α_rp "
        "with the approximate energy balance technique'; 'α_rp is very low for Ω_c < 160 rev/min. With an "
        "increase in speed, α_rp increases and saturates at 1.36 rad, which corresponds to α = 90°.'",
        f"camdyn (experiment's settings, damping D; energy balance of Eqs. 30–33 with the printed potential "
        f"(k_s/2) L²): the energy balance saturates at π/2 − α* = {sat:.4f} rad (at 10⁵ rev/min with ξ = 1 it "
        f"gives {eb_top:.4f} rad), the paper's 1.36 rad by construction of the reference rig (α* was fitted "
        f"to it). In the contact model the follower thrown towards 90° meets the singular spring of Eq. 11 "
        f"(tan α): camdyn stops such a run at 90° − 0.02 rad (`ANGLE_LIMIT`) and it is plotted at the "
        f"saturation value. " + found["verdict"] + " The last column gives the ξ for which the energy balance reproduces "
        "the contact model ('< 0': even ξ = 0 over-predicts).",
        "**Not compared with measurements:** the paper's Figs. 7–8 also plot the measured α_rp and the "
        "analytical results of Alzate et al. (2007); those data are not available here.",
        _branch_text(legs, runs, rig),
        md_table(["Ω_c (rev/min)", "α_rp contact model (rad)", "periodicity / outcome",
                  "α_rp energy balance ξ = 0.05 (rad)", "ξ that matches the contact model"], rows),
    ])
    numbers = {"saturation_rad": sat, "energy_balance_top": eb_top, "runs": numbers_runs,
               "xi_needed_below_160": found["xi_low"], "below_xi005_rpm": found["under"],
               "above_xi005_rpm": found["over"],
               "branches": [{k: b[k] for k in ("name", "events", "end")} | {"from": b["lambda"][0], "to": b["lambda"][-1]}
                            for b in legs]}
    return StudyOutput(NAME, TITLE, md, numbers, [png])


def _figure(ctx: Context, rig, s: dict, runs: list[dict], legs: list[dict], sat: float):
    """Fig. 7 (low speeds, with the continued branches) beside Fig. 8 (the broad range); the PNG path."""
    fig, ax = figure(1, 2, figsize=(11, 5.2))
    _draw_low(ax[0], rig, s, runs, legs)
    _draw_broad(ax[1], rig, runs, sat)
    for a in ax:
        a.set_xlabel("cam speed Ω_c (rev/min)")
        a.set_ylabel("α_rp (rad)")
        a.grid(alpha=0.3, which="both")
        a.legend(fontsize=7)
    ax[0].legend(fontsize=6.5, loc="upper center", bbox_to_anchor=(0.5, -0.16), ncol=2)   # below: the branches fill (a)
    return save(fig, ctx.png("fig7-8"))


def _draw_low(ax, rig, s: dict, runs: list[dict], legs: list[dict]) -> None:
    """Fig. 7: the energy balance for XI_LOW, the contact model's runs and the continued branches."""
    low = [r for r in runs if r["speed_rpm"] in s["low"]]
    grid_low = np.linspace(min(s["low"]) - 5, max(s["low"]) + 5, 80)
    for xi, ls in zip(XI_LOW, ("-", "--", "-.", ":")):
        ax.plot(grid_low, [energy_balance_peak(rig, w, xi) for w in grid_low], "k", ls=ls, lw=0.9,
                label=f"energy balance, ξ = {xi:g}")
    ax.plot([r["speed_rpm"] for r in low], [r["p2p"] or np.nan for r in low], "o", color="tab:red",
            label="contact model (damping D)")
    _draw_branches(ax, legs)
    ax.set_title("(a) Fig. 7: lower speeds, with the continued branches")


def _draw_broad(ax, rig, runs: list[dict], sat: float) -> None:
    """Fig. 8: the energy balance for XI_BROAD over the broad range, the runs (stopped ones at the
    saturation value) and the paper's saturation."""
    allspeeds = np.geomspace(100, 2e4, 200)
    for xi, ls in zip(XI_BROAD, ("-", "--", ":")):
        ax.plot(allspeeds, [energy_balance_peak(rig, w, xi) for w in allspeeds], "k", ls=ls, lw=0.9,
                label=f"energy balance, ξ = {xi:g}")
    ok = [r for r in runs if r["outcome"] == "SUCCESS"]
    stopped = [r for r in runs if r["outcome"] != "SUCCESS"]
    ax.plot([r["speed_rpm"] for r in ok], [r["p2p"] or np.nan for r in ok], "o", color="tab:red",
            label="contact model (damping D)")
    if stopped:
        ax.plot([r["speed_rpm"] for r in stopped], [sat] * len(stopped), "^", color="tab:red", mfc="none",
                label="contact model: follower reached 90° (run stopped)")
    ax.axhline(PAPER["alpha_rp_saturation"]["value"], color="tab:gray", lw=0.8, ls=(0, (1, 3)),
               label="paper: saturation at 1.36 rad")
    ax.set_xscale("log")
    ax.set_title("(b) Fig. 8: broad range of speeds")


def _table(rig, runs: list[dict]) -> tuple[list[list], list[dict]]:
    """The report's rows and the recorded numbers of each run, with the xi that matches it."""
    rows, numbers_runs = [], []
    for r in runs:
        xi = xi_needed(rig, r["speed_rpm"], r["p2p"]) if r["outcome"] == "SUCCESS" else None
        rows.append([fmt(r["speed_rpm"]), fmt(r["p2p"], 3) if r["outcome"] == "SUCCESS" else "–",
                     r["outcome"] if r["outcome"] != "SUCCESS" else r["class"],
                     fmt(energy_balance_peak(rig, r["speed_rpm"], 0.05), 3),
                     xi if isinstance(xi, str) or xi is None else f"{xi:.3f}"])
        numbers_runs.append({"speed_rpm": r["speed_rpm"], "alpha_rp": r["p2p"], "outcome": r["outcome"],
                             "class": r["class"], "xi_needed": xi})
    return rows, numbers_runs


def _below_160(rig, numbers_runs: list[dict]) -> dict:
    """Below 160 rev/min: the speeds where the contact model is at or under the xi = 0.05 energy
    balance and those where it is above, the xi that match, and the sentence saying so."""
    xi_low = [n["xi_needed"] for n in numbers_runs if n["speed_rpm"] < 160 and isinstance(n["xi_needed"], float)]
    below = [n for n in numbers_runs if n["speed_rpm"] < 160 and n["alpha_rp"] is not None]
    under = [n["speed_rpm"] for n in below if n["alpha_rp"] <= energy_balance_peak(rig, n["speed_rpm"], 0.05)]
    over = [n["speed_rpm"] for n in below if n["alpha_rp"] > energy_balance_peak(rig, n["speed_rpm"], 0.05)]
    verdict = (f"Below 160 rev/min the contact model's α_rp is at or below the ξ = 0.05 energy balance at "
               f"{', '.join(fmt(v) for v in under) or 'no speed'} rev/min (consistent with the paper's ξ < 0.05) "
               f"and above it at {', '.join(fmt(v) for v in over) or 'no speed'} rev/min, where the follower "
               "has settled on the large period-1 flight (see Figs. 4–5): there no ξ ≤ 1 matches.")
    return {"xi_low": xi_low, "under": under, "over": over, "verdict": verdict}
