"""The second published rig (issue 28): a flat-faced translating follower on a cam of six circular arcs,
with rigid impacts (camdyn.model.presets.second_rig, docs/second-rig.md): its detachment speed, its
bifurcation diagram against the cam speed, and where on the cam the follower leaves and lands, beside the
cam's corners (the arcs' junctions, where the curvature jumps: the corner-impact scenario)."""
from __future__ import annotations

import math

import numpy as np

import camdyn
from camdyn.analysis.statics import contact_loss_speed
from camdyn.engine import impact_transitions
from camdyn.model.presets import second_rig

from .common import Context, StudyOutput, figure, fmt, md_table, parallel_map, save, simulate

NAME, TITLE = "second-rig", "The second rig: a flat face on a cam of arcs, rigid impacts"
SCENE = camdyn.Scene(follower="translating", contact="rigid", damping="none", friction="none", profile="arcs")


def _cam_angle_deg(rig, t: np.ndarray, speed_rpm: float) -> np.ndarray:
    """The cam angle from the start of the rise (deg, in [0, 360)): the rise starts a quarter turn after the
    0-state (the preset's theta0, mid-base-circle)."""
    turns = t * speed_rpm / 60.0 - 0.25
    return np.mod(turns, 1.0) * 360.0


def _run(args) -> dict:
    """One speed: the section (y at the start of each revolution after the transient), and the cam angles of
    the impacts faster than 0.5 m/s and of the separations over the kept revolutions."""
    rig, speed, revolutions, kept = args
    per_turn = 36
    r = simulate(rig, SCENE, speed_rpm=speed, revolutions=revolutions, sample_rate_Hz=per_turn * speed / 60)
    keep_from = (revolutions - kept) * 60.0 / speed
    section = r.q[::per_turn][revolutions - kept:revolutions].tolist()
    K = SCENE.kernels()
    times, approach = approach_speeds(rig, r)
    impacts = times[(times >= keep_from) & (approach < -0.5)]
    kept_switches = r.switches.records[r.switches.t >= keep_from]
    leaves = kept_switches["t"][(kept_switches["before"] == K.MODE_CONTACT) & (kept_switches["after"] == K.MODE_FREE)]
    return {"speed_rpm": speed, "outcome": r.outcome.name, "section": section,
            "impact_deg": _cam_angle_deg(rig, impacts, speed).tolist(),
            "leave_deg": _cam_angle_deg(rig, leaves, speed).tolist()}


def approach_speeds(rig, result) -> tuple[np.ndarray, np.ndarray]:
    """The Newton impacts of a run of the rigid scene (the switches whose reset is the impact law,
    camdyn.engine.impact_transitions): their times and relative approach speeds (m/s, < 0). A
    record holds the state after the reset, so the approach is -1/xi times the gap's rate there
    (Newton's law), read under the free mode's laws."""
    model = camdyn.Model(rig, SCENE, result.meta["cam"])
    K = SCENE.kernels()
    records = result.switches.records
    bounces = records[np.isin(records["transition"], impact_transitions(K))]
    after = np.array([model.surface(K.MODE_FREE, K.SURFACE_GAP_RATE, b["t"], b["alpha"], b["alpha_dot"])
                      for b in bounces], dtype=float)
    return bounces["t"].copy(), -after / rig.xi


def _junctions_deg(rig) -> list[float]:
    """The cam angles (from the start of the rise) at which the flat face passes the arcs' junctions:
    phi = gamma - Theta, the rise starting where phi = 90 degrees."""
    angles = np.degrees(rig.profile.angles[:-1])
    return sorted(float(np.mod(90.0 - a, 360.0)) for a in angles)


def run(ctx: Context) -> StudyOutput:
    rig = second_rig()
    loss = contact_loss_speed(rig)
    speeds = np.linspace(200.0, 700.0, 11 if ctx.fast else 201)
    revolutions, kept = (12, 6) if ctx.fast else (60, 30)
    rows = parallel_map(_run, [(rig, float(s), revolutions, kept) for s in speeds], ctx.fast)
    junctions = _junctions_deg(rig)
    fig, (ax, bx) = figure(1, 2, figsize=(11, 4.4))
    for row in rows:
        ax.plot(np.full(len(row["section"]), row["speed_rpm"]), 1e3 * np.asarray(row["section"]), ",k")
        bx.plot(np.full(len(row["impact_deg"]), row["speed_rpm"]), row["impact_deg"], ".", color="tab:red", ms=2)
        bx.plot(np.full(len(row["leave_deg"]), row["speed_rpm"]), row["leave_deg"], ".", color="tab:blue", ms=2)
    for ax_ in (ax, bx):
        ax_.axvline(loss, color="0.5", lw=0.8, ls="--")
    for j in junctions:
        bx.axhline(j, color="0.7", lw=0.6)
    ax.set(xlabel="cam speed (rev/min)", ylabel="y at each revolution's start (mm)",
           title=f"sections after the transient (detachment {loss:.4g} rev/min, dashed)")
    bx.set(xlabel="cam speed (rev/min)", ylabel="cam angle from the rise (deg)", ylim=(0, 360),
           title="impacts > 0.5 m/s (red), leaving the cam (blue); corners (grey)")
    png = save(fig, ctx.png(NAME))
    at_corner = [row for row in rows if row["leave_deg"] and all(
        min(abs(a - j) for j in junctions) < 1e-3 for a in row["leave_deg"])]
    periods = [_period(row["section"]) for row in rows]
    corner_text, corners = _corner_impacts(rig)
    table = [[fmt(row["speed_rpm"], 4), row["outcome"], p or "none within the kept revolutions",
              len(row["impact_deg"]) // kept if kept else 0,
              "corner" if row in at_corner else ("smooth" if row["leave_deg"] else "never leaves")]
             for row, p in zip(rows, periods)]
    md = "\n\n".join([
        f"![second rig](img/{png.name})",
        "The papers (Alzate et al. 2007; Osorio, di Bernardo & Santini 2008): their detachment speed, bifurcation "
        "diagram and corner-impact speeds could not be read here (docs/second-rig.md, *Sources read*), so this "
        "section states camdyn's results on the rig as the Siconos example gives it, to be set beside the papers'.",
        f"camdyn: the rigid follower leaves the cam above {loss:.6g} rev/min (inverse kinematics, the flat-face "
        "law; the preset `second_rig`, scene `contact='rigid'`, restitution 0.8). The right panel shows where it "
        "leaves and where it lands against the cam's corners (the arcs' junctions, at "
        + ", ".join(f"{j:.2f}" for j in junctions) + " degrees from the rise; blue: where it leaves, red: where "
        "impacts faster than 0.5 m/s land). Where it leaves at a corner (the table's last column), the curvature's "
        "jump there turns the contact force it needs negative at once; an impact landing on a corner as the speed "
        "changes is the corner-impact scenario.",
        md_table(["speed (rev/min)", "outcome", "period of the section", "impacts > 0.5 m/s per revolution",
                  "leaves the cam at"], table),
        corner_text,
    ])
    numbers = {"detachment_rpm": loss, "junctions_deg": junctions, "corner_impacts": corners,
               "speeds": [{"speed_rpm": row["speed_rpm"], "outcome": row["outcome"], "period": p,
                           "impacts_per_revolution": len(row["impact_deg"]) / kept,
                           "leaves": "corner" if row in at_corner else ("smooth" if row["leave_deg"] else "never")}
                          for row, p in zip(rows, periods)]}
    return StudyOutput(NAME, TITLE, md, numbers, [png])


#: the speeds (rev/min) over which the corner impact is continued: the unstable period-1 orbit of three
#: impacts per revolution lands its third impact at 271.4 degrees at 320 rev/min and 266.9 at 350
#: (tests/test_corner_impact.py), across the junction at 270
CORNER_RANGE = (310.0, 360.0)


def _corner_impacts(rig) -> tuple[str, list[dict]]:
    """The corner impacts located by continuing the period-1 branch in the speed over CORNER_RANGE
    (camdyn.continue_orbit; event kind ``corner_impact``): a paragraph and their numbers."""
    from camdyn.orbits.continuation import ContinuationSettings, continue_orbit, events_table

    ds = continue_orbit(rig, SCENE, "speed_rpm", *CORNER_RANGE, settings=ContinuationSettings(switch_depth=0))
    found = [{"speed_rpm": float(speed)} for kind, speed, *_ in events_table(ds) if kind == "corner_impact"]
    text = (f"Corner impacts, located by continuing the period-1 orbit in the speed from {CORNER_RANGE[0]:g} to "
            f"{CORNER_RANGE[1]:g} rev/min (`camdyn.continue_orbit`, event kind `corner_impact`: an impact's landing "
            "angle crossing a junction, docs/continuation.md): "
            + (", ".join(f"{c['speed_rpm']:.6f} rev/min" for c in found) if found else "none")
            + ". The orbit there is unstable (three impacts per revolution); whether it is the orbit of the 2008 "
            "paper's scenario could not be checked (the paper's text was not available).")
    return text, found


def _period(section: list[float], tol: float = 1e-7) -> int | None:
    """The smallest period (in revolutions) of the kept sections, within ``tol`` m, or None."""
    x = np.asarray(section)
    for p in range(1, x.size // 2 + 1):
        if np.all(np.abs(x[p:] - x[:-p]) <= tol):
            return p
    return None
