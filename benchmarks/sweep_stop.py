"""Sweeps that stop once periodic, and shooting from the quasi-static warm start (issue 13).

    python benchmarks/sweep_stop.py            # writes docs/sweep-stopping.md
    python benchmarks/sweep_stop.py --quick    # 40 speeds, 100 revolutions (a smoke run)

In one run, side by side on the bifurcation benchmark of ``benchmarks/performance.py`` (line
16 mm, damping D, Coulomb, 0.8-1.6 x the contact-loss speed, rtol 1e-7, ProcessPoolExecutor(2)):
the diagram by brute force (every point to the end, ``stop=None``) and with convergence-aware
stopping (``camdyn.StopWhenPeriodic()``, the default of ``camdyn.sweep.api.bifurcation``), the
revolutions each ran and the agreement of their sections; then one permanent-contact orbit shot
from the quasi-static warm start against the warm-up run.  ``performance.py`` calls
:func:`measure` (perf/timing.py) and :func:`lines` (perf/report.py) for its Sweeps section.
"""
from __future__ import annotations

import argparse
import dataclasses
import os
import sys
import time
from concurrent.futures import ProcessPoolExecutor
from pathlib import Path

import numpy as np

import camdyn
from camdyn.sweep import api as S

RIG = camdyn.example_rig().replace(l_lambda=0.016)
SCENE = camdyn.Scene(damping="D", friction="coulomb")
#: the bifurcation benchmark's tolerances (also performance.py's sweeps and sweep_store.py's: read from here)
RTOL, ATOL = 1e-7, 1e-11          # atol = 1e-4 rtol
DOCS = Path(__file__).resolve().parent.parent / "docs"
#: the issue's goals
SHOOT_GOAL_S, DIAGRAM_GOAL_S = 0.05, 5.0


def _bifurcation(pool, grid, revolutions: int, stop):
    """The benchmark's diagram on ``pool`` (the second half of the revolutions as the section)."""
    return S.bifurcation(RIG, SCENE, grid, revolutions=revolutions, transient_revolutions=revolutions // 2,
                         executor=pool, progress=False, rtol=RTOL, atol=ATOL, stop=stop)


def _diagram(grid, revolutions: int, stop) -> tuple:
    t0 = time.perf_counter()
    with ProcessPoolExecutor(2) as pool:
        ds = _bifurcation(pool, grid, revolutions, stop)
    return ds, time.perf_counter() - t0


def _excess(a, b, stop, periods=None) -> np.ndarray:
    """Per point: max |a - b| of the sections over the stop's threshold at that point (b's
    values); with ``periods``, the least over b shifted by 0..p-1 revolutions (one cycle in
    another phase is the same cycle)."""
    A, B = a["alpha_section"].values, b["alpha_section"].values
    out = np.full(A.shape[0], np.nan)
    for i in range(A.shape[0]):
        x, y = A[i][np.isfinite(A[i])], B[i][np.isfinite(B[i])]
        n = min(x.size, y.size) - (periods[i] if periods is not None else 0)
        shifts = range(max(1, int(periods[i]))) if periods is not None else [0]
        if n > 0:
            out[i] = min(np.max(np.abs(x[:n] - y[k:k + n])) for k in shifts) / stop.threshold(y, RTOL, ATOL)
    return out


def _where(ds, factors: np.ndarray, score: np.ndarray) -> str:
    """The point of the highest score: its speed (x the contact-loss speed), period, revolutions run."""
    i = int(np.nanargmax(score))
    return (f"{factors[i]:.3f} x the contact-loss speed, period {ds['stop_period'].values[i]:.0f}, "
            f"{ds['revolutions_run'].values[i]:.0f} revolutions run")


def diagrams(speeds: int, revolutions: int) -> dict:
    """The diagram by brute force and with stopping, in one run, and the same runs as the
    stopping ones (the same pieces of ``check_every`` revolutions) with a check that cannot hold
    (``revolutions`` more than the run has): what each stopped run would have given had it gone on."""
    loss = camdyn.contact_loss_speed(RIG)
    grid = np.linspace(0.8 * loss, 1.6 * loss, speeds)
    S.bifurcation(RIG, SCENE, grid[:2], revolutions=4, transient_revolutions=1, progress=False)  # load the code
    brute, brute_s = _diagram(grid, revolutions, None)
    stop = camdyn.StopWhenPeriodic()
    fast, fast_s = _diagram(grid, revolutions, stop)
    on, _ = _diagram(grid, revolutions, dataclasses.replace(stop, revolutions=revolutions + 1))
    stopped = fast["stop_period"].values > 0
    _, unstopped_s = _diagram(grid[~stopped], revolutions, stop)    # what no stopping rule may shorten
    same = _excess(fast, on, stop)
    brute_x = _excess(fast, brute, stop, fast["stop_period"].values.astype(int))
    apart = stopped & ~(brute_x <= 2)
    return {"loss": loss, "speeds": speeds, "revolutions": revolutions, "stop": stop,
            "brute_s": brute_s, "fast_s": fast_s, "unstopped_s": unstopped_s, "run": fast.attrs["revolutions_run_total"],
            "requested": fast.attrs["revolutions_requested_total"], "stopped": int(stopped.sum()),
            "periods": np.bincount(fast["stop_period"].values[stopped].astype(int)),
            "stopped_contact": int(np.sum(stopped & (grid <= loss))), "contact": int(np.sum(grid <= loss)),
            "same": float(np.nanmax(same[stopped])), "never_stopped": int(np.sum(on["stop_period"].values > 0)),
            "same_worst": _where(fast, grid / loss, np.where(stopped, same, -np.inf)),
            "brute_close": float(np.nanmax(brute_x[stopped & ~apart])) if (stopped & ~apart).any() else np.nan,
            "apart": int(apart.sum()), "apart_speeds": grid[apart] / loss,
            "apart_run": fast["revolutions_run"].values[apart],
            "outcomes_equal": bool(np.array_equal(fast["outcome"].values, brute["outcome"].values)),
            "fast": fast}


def _leg(leg: tuple) -> tuple:
    """One continuation (start, end, phase_fraction) and its wall time in its process."""
    from camdyn.orbits.continuation import continue_orbit
    start, end, phase = leg
    t0 = time.perf_counter()
    ds = continue_orbit(RIG, SCENE, "speed_rpm", start, end, phase_fraction=phase)
    return ds, time.perf_counter() - t0


#: the two continuation legs, (start, end, phase fraction of the section), start and end times
#: the contact-loss speed: down from 1.6 with the diagram's section, up from 0.8 with the section
#: at T/2 (see :func:`continued`)
LEGS = ((1.6, 0.8, 0.0), (0.8, 1.6, 0.5))


def together(grid, loss: float, revolutions: int) -> dict:
    """The whole job on one ``ProcessPoolExecutor(2)``: the two continuation legs submitted
    first, then the stopped diagram's chunks on the same pool (a worker done with its leg takes
    chunks): the wall time from the pool's start to the last result, and the diagram (equal to
    the one run alone: a point's values depend on the point only)."""
    t0 = time.perf_counter()
    with ProcessPoolExecutor(2) as pool:
        legs = [pool.submit(_leg, (start * loss, end * loss, phase)) for start, end, phase in LEGS]
        ds = _bifurcation(pool, grid, revolutions, camdyn.StopWhenPeriodic())
        done = [leg.result() for leg in legs]
    return {"seconds": time.perf_counter() - t0, "diagram": ds, "legs": done}


def continued(loss: float, fast) -> dict:
    """The branches over the benchmark's range (camdyn.continue_orbit, finite-difference monodromy):
    down from 1.6 x the contact-loss speed with the diagram's section (phase 0), and up from 0.8 x
    with the section at T/2 (at phase 0 the permanent-contact orbit barely loads the contact, and the
    finite-difference step leaves the contact mode); the wall time of both, their events, and the
    agreement of the stable period-1 points with the stopped diagram's period-1 sections, where
    both exist (the branch interpolated linearly to the diagram's speeds inside it)."""
    from camdyn.orbits.continuation import events_table
    out, events = {}, []
    t0 = time.perf_counter()
    with ProcessPoolExecutor(2) as pool:         # the two directions at once, one per core
        done = list(pool.map(_leg, [(start * loss, end * loss, phase) for start, end, phase in LEGS]))
    seconds = time.perf_counter() - t0
    for (_, _, phase), (ds, _) in zip(LEGS, done):
        events += [(kind, lam / loss) for kind, lam, _, _ in events_table(ds)]
        out[phase] = ds
    ds = out[0.0]
    on = (ds["point_branch"].values == 0) & ds["stable"].values.astype(bool)
    lam, alpha = ds["lambda"].values[on], ds["alpha_revolution"].values[on, 0]
    order = np.argsort(lam)
    grid = fast["speed_rpm"].values
    both = (fast["stop_period"].values == 1) & (grid >= lam.min()) & (grid <= lam.max()) if on.any() else grid < 0
    diff = np.abs(np.interp(grid[both], lam[order], alpha[order]) - fast["alpha_section"].values[both, 0])
    return {"seconds": seconds, "leg_seconds": [leg_s for _, leg_s in done], "events": events, "legs": done,
            "compared": int(both.sum()),
            "max_diff": float(diff.max()) if diff.size else np.nan,
            "points": int(sum(d.sizes["point"] for d in out.values()))}


def shooting(repeats: int = 5) -> dict:
    """One permanent-contact orbit (0.85 x the contact-loss speed) shot from the quasi-static warm
    start and from the default warm-up run: best wall time of ``repeats``, and the agreement."""
    speed = 0.85 * camdyn.contact_loss_speed(RIG)
    out = {"speed": speed}
    for start in ("quasistatic", "run"):
        camdyn.periodic_orbit(RIG, SCENE, speed_rpm=speed, start=start)          # load the code
        times = []
        for _ in range(repeats):
            t0 = time.perf_counter()
            orbit = camdyn.periodic_orbit(RIG, SCENE, speed_rpm=speed, start=start)
            times.append(time.perf_counter() - t0)
        out[start] = (min(times), orbit)
    quasi, run = out["quasistatic"][1], out["run"][1]
    out["state_diff"] = np.abs(quasi.state - run.state)
    t0 = time.perf_counter()
    section = camdyn.quasi_static_orbit(RIG, SCENE, speed_rpm=speed, t=np.array([run.phase]))
    out["qs_seconds"] = time.perf_counter() - t0
    out["qs_section_diff"] = abs(section.alpha[0] - run.state[0])
    return out


def measure(quick: bool = False) -> dict:
    d = diagrams(40 if quick else 200, 100 if quick else 200)
    c = continued(d["loss"], d["fast"])
    job = together(d["fast"]["speed_rpm"].values, d["loss"], d["revolutions"])
    job["same_diagram"] = bool(np.array_equal(job["diagram"]["alpha_section"].values, d["fast"]["alpha_section"].values,
                                              equal_nan=True))
    job["same_branches"] = all(np.array_equal(a["lambda"].values, b["lambda"].values)
                               for (a, _), (b, _) in zip(job["legs"], c["legs"]))
    return {"diagram": d, "continued": c, "together": job, "shoot": shooting()}


def lines(m: dict) -> list[str]:
    d, s, c, j = m["diagram"], m["shoot"], m["continued"], m["together"]
    saved = 1 - d["run"] / d["requested"]
    periods = ", ".join(f"{n} of period {p}" for p, n in enumerate(d["periods"]) if p and n)
    q_s, q = s["quasistatic"]
    r_s, r = s["run"]
    out = ["## Sweeps that stop once periodic", "",
           f"`python benchmarks/sweep_stop.py` (also run by `benchmarks/performance.py` with its sweeps): the "
           f"bifurcation benchmark, {d['speeds']} speeds 0.8-1.6 x the contact-loss speed {d['loss']:.0f} rev/min, "
           f"{d['revolutions']} revolutions, the second half as the section, line 16 mm, D, Coulomb, rtol "
           f"{RTOL:.0e}, atol {ATOL:.0e}, `ProcessPoolExecutor(2)`; both diagrams in the same run.", "",
           "| diagram | wall time (s) | revolutions run |", "|---|---|---|",
           f"| brute force (`stop=None`) | {d['brute_s']:.1f} | {d['requested']:.0f} |",
           f"| stopping once periodic (`{d['stop']!r}`) | {d['fast_s']:.1f} | {d['run']:.0f} |", "",
           f"Revolutions saved: {100 * saved:.0f} % ({d['stopped']} of {d['speeds']} points stopped: {periods}; "
           f"{d['stopped_contact']} of the {d['contact']} permanent-contact speeds).  Wall time "
           f"{d['brute_s'] / d['fast_s']:.1f} x shorter.  Outcomes equal point for point: {d['outcomes_equal']}.", "",
           f"Agreement of the stopped points with the same runs gone on to the end (the same pieces of "
           f"{d['stop'].check_every} revolutions; a check that cannot hold, `revolutions` > the run): max |difference| "
           f"of the sections {d['same']:.2f} x the stop's threshold tol (rtol max |alpha| + atol) at that point "
           f"(tol = {d['stop'].tol:g}; at {d['same_worst']}; {d['never_stopped']} of those runs stopped).", "",
           f"Against brute force (one piece of 200 cam periods per point: other steps; a cycle compared in every "
           f"phase): {d['stopped'] - d['apart']} of the {d['stopped']} stopped points agree within twice the "
           f"threshold (at most {d['brute_close']:.2f} x it); {d['apart']} do not, at "
           f"{', '.join(f'{v:.3f}' for v in d['apart_speeds']) or '-'} x the contact-loss speed, after "
           f"{', '.join(f'{r:.0f}' for r in d['apart_run']) or '-'} revolutions run: there the two runs reached "
           "different attractors after a transient, as a change of rtol can make them do (the stopped run agrees "
           "with its own continuation above).  The points that did not stop differ from brute force for the same "
           "reason at chaotic speeds.", "",
           f"**Continuation of the branches** (`camdyn.continue_orbit`, finite-difference monodromy, rtol 1e-10, "
           f"the two directions at once in `ProcessPoolExecutor(2)`): down from 1.6 x the contact-loss speed (the "
           f"diagram's section) and up from 0.8 x (section at T/2), {c['points']} orbits in {c['seconds']:.1f} s "
           f"(each direction alone {' and '.join(f'{v:.1f}' for v in c['leg_seconds'])} s); events (x the "
           f"contact-loss speed): "
           f"{', '.join(f'{k} {v:.4f}' for k, v in c['events']) or 'none'}.  The stable period-1 branch against the "
           f"stopped diagram's period-1 sections at the {c['compared']} speeds both cover: max |difference| "
           f"{c['max_diff']:.1e} rad (the branch interpolated linearly between its points: a bound that includes "
           f"the interpolation's error).", "",
           f"**Stopping plus continuation against the goal of < {DIAGRAM_GOAL_S:g} s on 2 cores.**  One after the "
           f"other, each on the pool of 2: {d['fast_s']:.1f} + {c['seconds']:.1f} = {d['fast_s'] + c['seconds']:.1f} s "
           f"({'met' if d['fast_s'] + c['seconds'] < DIAGRAM_GOAL_S else 'not met'}).  As one job on one "
           f"`ProcessPoolExecutor(2)` (the two legs submitted first, then the diagram's chunks, which the worker done "
           f"with the short leg starts at once): **{j['seconds']:.1f} s, "
           f"{'met' if j['seconds'] < DIAGRAM_GOAL_S else 'not met'}**; the same diagram ({j['same_diagram']}, every "
           f"section value equal) and the same branches ({j['same_branches']}) as the runs apart.  The "
           f"{d['speeds'] - d['stopped']} speeds that do not stop (chaotic, of a period above "
           f"{d['stop'].max_period}, or still in a transient) run all their {d['revolutions']} revolutions, which "
           f"no stopping rule may shorten: those speeds alone, the same way, take {d['unstopped_s']:.1f} s.", "",
           f"Shooting one permanent-contact orbit ({s['speed']:.0f} rev/min, `camdyn.periodic_orbit`, rtol 1e-10, "
           "best of 5):", "",
           "| warm start | wall time (ms) | Newton steps | map runs | residual |", "|---|---|---|---|---|",
           f"| quasi-static (`start=\"quasistatic\"`) | {q_s * 1e3:.1f} | {q.iterations} | "
           f"{q.map_evaluations + 5 * q.jacobian_evaluations} | {q.residual:.1e} |",
           f"| warm-up run of 20 revolutions (default) | {r_s * 1e3:.1f} | {r.iterations} | "
           f"{r.map_evaluations + 5 * r.jacobian_evaluations} | {r.residual:.1e} |", "",
           f"Goal < {SHOOT_GOAL_S * 1e3:.0f} ms: {'met' if q_s < SHOOT_GOAL_S else '**not met**'}.  The two fixed "
           f"points differ by {s['state_diff'][0]:.1e} rad and {s['state_diff'][1]:.1e} rad/s.  The quasi-static "
           f"orbit alone at the section ({s['qs_seconds'] * 1e3:.1f} ms in Python, the model built included) is "
           f"{s['qs_section_diff']:.1e} rad from the shot orbit's alpha.", ""]
    return out


def main(argv=None) -> int:
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("--quick", action="store_true", help="40 speeds, 100 revolutions")
    args = parser.parse_args(argv)
    load0 = os.getloadavg()[0]
    t0 = time.perf_counter()
    text = lines(measure(args.quick))
    flags = " --quick" if args.quick else ""
    head = ["# Sweeps that stop once periodic", "",
            f"Generated by `python benchmarks/sweep_stop.py{flags}` in {(time.perf_counter() - t0) / 60:.1f} min -- "
            f"do not edit by hand.  Load average (1 min) at the start and end: {load0:.2f}, "
            f"{os.getloadavg()[0]:.2f} (a shared 2-core machine: the two diagrams are compared within one run).", ""]
    page = "\n".join(head + text[1:])
    (DOCS / "sweep-stopping.md").write_text(page + "\n")
    print(page)
    return 0


if __name__ == "__main__":
    sys.exit(main())
