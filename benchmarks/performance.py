"""Work-precision report of camdyn's engine against a floor loop and peers: regenerates
docs/performance.md and docs/img/perf_*.png.  Run from the repository root:

    python benchmarks/performance.py              # full report
    python benchmarks/performance.py --quick      # fewer tolerances and repeats (smoke run, a few minutes)
    python benchmarks/performance.py --no-sweeps  # without the sweep timing section

Every number and figure in docs/performance.md comes from this script, and every comparison
of times is measured in one process, the solvers compared run in interleaved rounds (A B C,
C B A, ...) so that a busy spell of the machine falls on all of them alike.

* The floor (benchmarks/floor.py): a minimal event-capable DOP853 loop on the same generated
  kernels, against the engine's compiled loop on the "sliding" run, with a per-step breakdown.
* Work-precision per scene: camdyn's compiled engine (DOP853, RK45) at a range of rtol, error
  against the engine's DOP853 at rtol 1e-12 (checked against its RK45 at rtol 1e-12), against
  the peers numbalsoda (LSODA, DOP853) and SUNDIALS CVODE (scikit-sundae, BDF and Adams) where
  installed.  Peers get the same generated kernels: their field follows the scene's hybrid
  automaton without event location (a mode register in the RHS, moved on whenever the state is
  across one of the mode's surfaces; see :func:`peer_field`).
* Start-up: cold (empty numba cache) and warm, each in fresh processes.
* Sweeps (optional): the bifurcation diagram and contact-loss map timed with camdyn.sweep.api; the
  diagram stopping once periodic and shooting from the quasi-static warm start (sweep_stop.py).
* Kept as they are: the sections other scripts write with ``--report`` (jump_chart.py,
  second_rig_peers.py, basins.py; perf/sections.py), after the rest.

The script is this entry point; its parts are in benchmarks/perf/: what is measured (cases.py,
peers.py, precision.py, engine_costs.py, timing.py), the report's text (report.py) and its
figures (figures.py).
"""
from __future__ import annotations

import argparse
import os
import sys
import time

import floor
import profile_cost
from perf.cases import DOCS, IMG, Config, cases
from perf.engine_costs import floor_section
from perf.figures import plot_case, plot_floor, plot_sweeps
from perf.peers import peers_available
from perf.precision import measure_case
from perf.report import write_report
from perf.sections import kept_sections
from perf.timing import start_times, sweep_timing


def step(label: str, fn, *args):
    t0 = time.perf_counter()
    print(f"{label}...", flush=True)
    out = fn(*args)
    print(f"  {label}: {time.perf_counter() - t0:.1f} s", flush=True)
    return out


def main(argv=None) -> int:
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("--quick", action="store_true", help="fewer tolerances, repeats and sweep points")
    parser.add_argument("--no-sweeps", action="store_true", help="leave out the sweep timing section")
    parser.add_argument("--revolutions", type=int, default=None, help="revolutions per sweep point")
    cfg = Config.from_args(parser.parse_args(argv))
    t_start, load0 = time.perf_counter(), os.getloadavg()[0]
    IMG.mkdir(parents=True, exist_ok=True)
    peers = peers_available()
    fs = step("floor", floor_section, cfg)
    print(floor.summary(fs["floor"]), flush=True)
    plot_floor(fs, IMG / "perf_floor.png")
    results = []
    for case in cases():
        results.append(step(case.key, measure_case, case, cfg, peers))
        plot_case(results[-1], IMG / f"perf_{case.key}.png")
    profiles = step("profile cost", profile_cost.measure)
    cam_floor = step("floor on a cam", floor.measure, floor.SlidingRun(speed_rpm=profile_cost.CAM_FLOOR_RPM,
                                                                       on_cam=True), cfg.floor_rounds // 2)
    starts = step("start-up", start_times, cfg)
    sw = step("sweeps", sweep_timing, cfg) if cfg.sweeps else None
    if sw is not None:
        plot_sweeps(sw, IMG)
    parts = {"peers": peers, "load": (load0, os.getloadavg()[0]), "elapsed": time.perf_counter() - t_start,
             "floor": fs, "starts": starts, "results": results, "sweeps": sw, "profiles": profiles,
             "cam_floor": cam_floor}
    text = write_report(parts, cfg)
    report = DOCS / "performance.md"
    kept = kept_sections(report.read_text(encoding="utf-8")) if report.exists() else ""
    report.write_text(text + ("\n\n" + kept if kept else "") + "\n")
    print(text)
    return 0


if __name__ == "__main__":
    sys.exit(main())
