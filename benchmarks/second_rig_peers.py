"""camdyn's rigid scene beside Siconos's Moreau-Jean time stepping on the second rig (issue 28), from one
script: time against the error of the impact times and of the Poincare section, both against the
event-driven solution of benchmarks/second_rig_exact.py (closed-form flights, events bisected to 1e-13 s).

    python benchmarks/second_rig_peers.py --speed-rpm 256 --revolutions 30 --run-siconos /tmp/siconos.json

With ``--run-siconos`` the Siconos runs are made in the same run, before camdyn's (so that the times
compare on the same machine, at the same load); with ``--siconos FILE`` they are read from the JSON
that ``/usr/bin/python3 benchmarks/siconos_cam_follower.py --law flat ... --out FILE`` writes (Debian's python3-siconos runs under the system Python, not camdyn's venv); camdyn's
are made here: ``camdyn.model.presets.second_rig()`` (the flat-faced follower on the six-arc cam,
restitution 0.8) with ``Scene(follower="translating", contact="rigid", damping="none", friction="none",
profile="arcs")`` at several tolerances, each timed as the least of three warm runs (compiled; its first
run compiles).  Impacts are compared where the relative approach speed exceeds the JSON's ``v_min`` (the
peer's threshold: below it Moreau-Jean's chattering is not resolved impact by impact); each exact impact's
error is its distance to the nearest impact of the run.  camdyn's start is a quarter turn before the
peer's (its 0-state is mid-base-circle, 90 degrees before the rise; both at rest on the dwell), so its
times are shifted by T/4.  Prints a Markdown table; ratios within this one run are what to compare.
"""
from __future__ import annotations

import argparse
import json
import math
import os
import sys
import time
import warnings

import numpy as np

sys.path.insert(0, os.path.dirname(os.path.abspath(__file__)))
from second_rig_exact import Rig as ExactRig, sample, solve  # noqa: E402

import camdyn  # noqa: E402
from camdyn.model.presets import second_rig  # noqa: E402
from camdyn.studies.second_rig import SCENE, approach_speeds  # noqa: E402

#: camdyn's rtol, each with atol = rtol / 10 (m): 1e-13 takes atol 1e-14, which failed before the junctions
#: were stepped to (docs/second-rig.md)
RTOLS = (1e-6, 1e-8, 1e-10, 1e-12, 1e-13)
#: camdyn's samples per cam revolution: every 10 degrees, so that its start (a quarter turn before the
#: peer's) and the section fall on samples (no interpolation between them)
SAMPLES_PER_TURN = 36


def camdyn_run(rig, speed_rpm: float, revolutions: int, rtol: float, repeats: int = 3):
    """The least wall time of ``repeats`` runs (after one to compile) and the last run."""
    kw = dict(speed_rpm=speed_rpm, revolutions=revolutions, rtol=rtol, atol=rtol * 0.1,
              sample_rate_Hz=SAMPLES_PER_TURN * speed_rpm / 60)
    camdyn.simulate(rig, SCENE, **kw)
    best, result = math.inf, None
    for _ in range(repeats):
        start = time.perf_counter()
        result = camdyn.simulate(rig, SCENE, **kw)
        best = min(best, time.perf_counter() - start)
    return best, result


def errors(reference: np.ndarray, times: np.ndarray) -> tuple[float, float]:
    """Median and largest distance of each reference impact to the nearest of ``times`` (s)."""
    if times.size == 0:
        return math.inf, math.inf
    d = np.min(np.abs(reference[:, None] - times[None, :]), axis=1)
    return float(np.median(d)), float(np.max(d))


def camdyn_rows(rig, exact, pieces, reference, args, v_min: float, section_deg: float) -> list[str]:
    """camdyn's rows of the table: each tolerance's least wall time and errors."""
    period, rows = 60.0 / args.speed_rpm, []
    for rtol in RTOLS:
        wall, result = camdyn_run(rig, args.speed_rpm, args.revolutions, rtol)
        times, speeds = approach_speeds(rig, result)
        fast = times[speeds < -v_min] - period / 4
        median, largest = errors(reference, fast)
        sec_t = (np.arange(args.revolutions) + section_deg / 360) * period
        exact_u, _ = sample(exact, pieces, sec_t)
        index = np.rint((sec_t + period / 4) / period * SAMPLES_PER_TURN).astype(int)
        rows.append(f"| camdyn (rigid, DOP853) | rtol {rtol:g} | {wall:.3g} | {fast.size} | {median:.2g} | "
                    f"{largest:.2g} | {np.max(np.abs(result.y[index] - exact_u)):.2g} |")
    return rows


def siconos_rows(siconos: dict, exact, pieces, reference) -> list[str]:
    """The peer's rows, from its JSON."""
    rows = []
    for run in siconos["runs"]:
        times = np.array([i["t"] for i in run["impacts"]])
        median, largest = errors(reference, times)
        exact_u, _ = sample(exact, pieces, [x["t"] for x in run["section"]])
        du = max(abs(x["u"] - a) for x, a in zip(run["section"], exact_u))
        rows.append(f"| Siconos (Moreau-Jean) | h {run['h']:g} s | {run['wall_s']:.3g} | {times.size} | {median:.2g} | "
                    f"{largest:.2g} | {du:.2g} |")
    return rows


def run_siconos(args) -> None:
    import subprocess
    here = os.path.dirname(os.path.abspath(__file__))
    subprocess.run(["/usr/bin/python3", os.path.join(here, "siconos_cam_follower.py"), "--law", "flat",
                    "--speed-rpm", f"{args.speed_rpm:g}", "--revolutions", str(args.revolutions), "--steps",
                    "1e-3", "3e-4", "1e-4", "3e-5", "1e-5", "3e-6", "--out", args.run_siconos], check=True,
                   stdout=subprocess.DEVNULL)


def report(lines: list[str], args) -> None:
    from perf.sections import write_section
    command = (f"python benchmarks/second_rig_peers.py --speed-rpm {args.speed_rpm:g} --revolutions {args.revolutions}"
               + (" --run-siconos FILE" if args.run_siconos else "") + " --report")
    head = ["## The rigid scene: work-precision beside Siconos", "",
            f"`{command}`: the second rig (docs/second-rig.md) with `contact=\"rigid\"`, camdyn at {len(RTOLS)} tolerances "
            "against Siconos's Moreau-Jean time stepping at six steps, both against an event-driven solution with "
            "closed-form flights (benchmarks/second_rig_exact.py): wall time against the error of the impact times "
            "(impacts faster than the peer's threshold) and of the follower's position at a section once a "
            "revolution. Compare ratios within this one run.", ""]
    print(f"wrote {write_section('rigid-scene', chr(10).join(head + lines))}")


def main() -> None:
    ap = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    ap.add_argument("--speed-rpm", type=float, default=256.0)
    ap.add_argument("--revolutions", type=int, default=30)
    ap.add_argument("--siconos", help="a JSON of benchmarks/siconos_cam_follower.py (law flat, same speed)")
    ap.add_argument("--run-siconos", metavar="JSON", help="run the Siconos peer now (/usr/bin/python3, its steps "
                    "1e-3 .. 3e-6 s), in this run, into JSON, and compare with it")
    ap.add_argument("--report", action="store_true", help="write the section of docs/performance.md")
    args = ap.parse_args()
    load0 = os.getloadavg()[0]
    if args.run_siconos:
        run_siconos(args)
        args.siconos = args.run_siconos
    warnings.filterwarnings("ignore", category=camdyn.CompileNotice)
    exact = ExactRig("flat", args.speed_rpm)
    impacts, pieces = solve(exact, args.revolutions * 60.0 / args.speed_rpm)
    siconos, v_min = None, 0.5
    if args.siconos:
        siconos = json.load(open(args.siconos))
        meta = siconos["meta"]
        if (meta["law"], meta["speed_rpm"], meta["revolutions"]) != ("flat", args.speed_rpm, args.revolutions):
            raise SystemExit(f"{args.siconos} is not the flat law at {args.speed_rpm} rev/min over {args.revolutions}")
        v_min = meta["v_min"]
    reference = np.array([t for t, v, _ in impacts if v < -v_min])
    section_deg = siconos["meta"]["section_deg"] if siconos else 130.0
    lines = [f"Second rig, flat face, {args.speed_rpm:g} rev/min, {args.revolutions} revolutions: {reference.size} "
             f"exact impacts faster than {v_min} m/s; section at {section_deg:g} deg.", "",
             "| peer | setting | wall (s) | impacts | impact-time error median (s) | max (s) | section y error max (m) |",
             "|---|---|---|---|---|---|---|"]
    lines += camdyn_rows(second_rig(), exact, pieces, reference, args, v_min, section_deg)
    lines += siconos_rows(siconos, exact, pieces, reference) if siconos else []
    lines += ["", f"Load average {load0:.2f} before, {os.getloadavg()[0]:.2f} after ({os.cpu_count()} cores)."]
    print("\n".join(lines))
    if args.report:
        report(lines, args)


if __name__ == "__main__":
    main()
