"""A 100 x 100 basin map timed (issue 29): the bistable speed of the 16 mm experiment rig.

    python benchmarks/basins.py                 # 100 x 100, writes docs/img/basins_125rpm.png
    python benchmarks/basins.py --n 20          # a smaller map (a smoke run)
    python benchmarks/basins.py --speed-rpm 159 --damping D --n 40    # a coexistence of Figs. 4-5

The map: ``camdyn.basins`` on the ``reference-experiment`` preset (line contact 16 mm, damping D,
Coulomb friction, the experiment's k_s) at 125 rev/min, between the flight orbit's fold (116.2
rev/min) and the contact orbit's grazing (130 rev/min), where both coexist (docs/reproduction.md,
Figs. 7-8); starts alpha in alpha* + [0, 0.5] rad, alpha_dot in [-3, 3] rad/s at t = 0; each run
at most 200 revolutions, stopped once periodic (camdyn.StopWhenPeriodic() defaults), default
tolerances (rtol 1e-8, atol 1e-12); on ``process_pool(workers)``, streamed to a file in a
temporary folder; the attractors confirmed by shooting (included in the time).  Prints the
wall time, the cores and the load average before and after, the attractor table and the
revolutions integrated; the figure goes to docs/img/.
"""
from __future__ import annotations

import argparse
import os
import sys
import tempfile
import time
import warnings
from pathlib import Path

import numpy as np

sys.path.insert(0, os.path.dirname(os.path.abspath(__file__)))

import camdyn  # noqa: E402
from camdyn.model.presets import load_rig  # noqa: E402
from camdyn.sweep import process_pool  # noqa: E402
from camdyn.sweep.attractors import attractor_table  # noqa: E402

IMG = Path(__file__).resolve().parent.parent / "docs" / "img"


def main() -> None:
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("--n", type=int, default=100, help="starts per axis (default 100)")
    parser.add_argument("--speed-rpm", type=float, default=125.0, help="cam speed (default 125 rev/min)")
    parser.add_argument("--damping", default="D", help="damping model A-E (default D)")
    parser.add_argument("--lyapunov-revolutions", type=int, default=0,
                        help="revolutions of the largest Lyapunov exponent of a start that does not settle "
                             "(default 0: none; not for damping C and E)")
    parser.add_argument("--workers", type=int, default=2)
    parser.add_argument("--no-figure", action="store_true")
    parser.add_argument("--keep", metavar="FILE.nc", help="write the map to FILE.nc (default: a temporary file)")
    parser.add_argument("--report", action="store_true", help="write the basins section of docs/performance.md")
    args = parser.parse_args()
    warnings.filterwarnings("ignore", category=camdyn.CompileNotice)
    rig = load_rig("reference-experiment")
    speed, scene = args.speed_rpm, camdyn.Scene(contact="line", damping=args.damping, friction="coulomb")
    a_star = camdyn.static_equilibrium(rig).alpha
    camdyn.simulate(rig, scene, speed_rpm=speed, revolutions=1)   # the compiled loop loaded before timing
    alpha = a_star + np.linspace(0.0, 0.5, args.n)
    alpha_dot = np.linspace(-3.0, 3.0, args.n)
    load0 = os.getloadavg()
    t0 = time.perf_counter()
    with tempfile.TemporaryDirectory() as tmp, process_pool(args.workers) as pool:
        ds = camdyn.basins(rig, scene, alpha=alpha, alpha_dot=alpha_dot, speed_rpm=speed, executor=pool,
                           out=args.keep or Path(tmp) / "basins.nc", overwrite=True, progress=False,
                           lyapunov_revolutions=args.lyapunov_revolutions)
    wall = time.perf_counter() - t0
    load1 = os.getloadavg()
    lines = [f"{args.n} x {args.n} basin map at {speed:g} rev/min, damping {args.damping}: **{wall:.1f} s** wall on "
             f"{args.workers} workers ({os.cpu_count()} cores; load average {load0[0]:.2f} before, {load1[0]:.2f} after).",
             f"Revolutions integrated: {ds.attrs['revolutions_run_total']:.0f} of "
             f"{ds.attrs['revolutions_requested_total']:.0f}; {wall / ds.attrs['points'] * 1e3:.1f} ms per start.",
             *(f"Attractor: {row}" for row in attractor_table(ds))]
    print("\n".join(lines))
    if args.report:
        from perf.sections import write_section
        command = " ".join(["python benchmarks/basins.py"] + sys.argv[1:])
        head = ["## Basins: a basin map timed", "", f"`{command}` (the reference experiment rig, starts at t = 0 "
                "over alpha* + [0, 0.5] rad x [-3, 3] rad/s, each run stopped once periodic, at most 200 "
                "revolutions; the attractors confirmed by shooting, included in the time; docs/basins.md).", ""]
        print(f"wrote {write_section('basins', chr(10).join(head + [f'- {line}' for line in lines]))}")
    if not args.no_figure:
        from camdyn.io import plots
        fig = plots.basin_map(ds, title=f"basins at {speed:g} rev/min, reference-experiment, damping {args.damping}")
        suffix = "" if args.damping == "D" else f"_{args.damping}"
        path = IMG / f"basins_{speed:g}rpm{suffix}.png"
        fig.savefig(path)
        print(f"wrote {path}")


if __name__ == "__main__":
    main()
