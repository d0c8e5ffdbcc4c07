"""The jump chart of the reference experiment rig against k_s over one decade, timed, beside the
cost of its brute-force answer (a speed x k_s grid of simulations).

Run from the repository root:

    python benchmarks/jump_chart.py [--points 30] [--resolution 1e-6] [--window 0.01] [--netcdf chart.nc]
                                    [--threads 2] [--compare-threads] [--report]

The rig: ``reference-experiment`` (line contact 16 mm, damping D, Coulomb friction), k_s from its
own value to ten times it.  camdyn.orbits.continuation.jump_chart follows the grazing orbit in
(speed, k_s), its arclength step set for about ``--points`` grazing orbits; it prints the wall time
(the compiled loop is loaded before the first timing), the orbits, how the curve ended, and the
jump speed against the inverse-kinematics contact-loss speed with the first-order compliance
shift (camdyn.analysis.statics.compliance_shift).  ``--compare-threads`` times the chart again on one
thread (GrazingSettings.threads = 1) in the same run and checks the curve is the same; ``--report``
writes the results as the "jump-chart" section of docs/performance.md (benchmarks/perf/sections.py).

The brute-force answer finds each jump speed by simulations on a grid of speeds: a grid of
relative spacing ``--resolution`` over a window of +- ``--window`` of the contact-loss speed
(known beforehand, a generous assumption) at each of the chart's k_s, each simulation run
``--revolutions`` revolutions from the static equilibrium and judged by whether the follower leaves
the cam in its last revolution.  The script times such simulations (at the chart's first and
last k_s, just below and just above the chart's jump speed, by --resolution: they must keep and
lose contact, which checks that the grid would give the chart's jump speeds to that
resolution) and states the grid's time as their mean time times the grid's size: it does not
run the grid.
"""
from __future__ import annotations

import argparse
import os
import sys
import time
import warnings

import numpy as np

sys.path.insert(0, os.path.dirname(os.path.abspath(__file__)))

import camdyn  # noqa: E402
from camdyn.orbits.continuation import ContinuationSettings, GrazingSettings, jump_chart  # noqa: E402

SCENE = camdyn.Scene(contact="line", damping="D", friction="coulomb")
#: the scaled arclength of the curve over the decade (measured on a run: lambda2's range is 1,
#: the speed's change 2.2 times its start value), divided among the points (the first step,
#: predicted along the tangent alone, is halved until it converges and the step then regrown:
#: 32 orbits for 30 points)
ARCLENGTH = 2.5


def chart(rig, points: int, threads: int = 2):
    step = ARCLENGTH / (points - 1)
    settings = GrazingSettings(continuation=ContinuationSettings(step=step, max_step=step, switch_depth=0),
                               threads=threads)
    t0 = time.perf_counter()
    ds = jump_chart(rig, SCENE, "k_s", rig.k_s, 10 * rig.k_s, settings=settings)
    return ds, time.perf_counter() - t0


def leaves(rig, speed_rpm: float, revolutions: int) -> tuple[bool, float]:
    """Whether the follower leaves the cam in the last revolution of a run from the static
    equilibrium, and the run's wall time."""
    t0 = time.perf_counter()
    result = camdyn.simulate(rig, SCENE, speed_rpm=speed_rpm, revolutions=revolutions)
    seconds = time.perf_counter() - t0
    if not result.ok:
        raise RuntimeError(result.outcome.message)
    return bool(np.any(result.separations() > (revolutions - 1) * result.period)), seconds


def chart_lines(rig, ds, seconds: float, threads: int) -> list[str]:
    """What the chart found, and its time."""
    ratio = ds["speed_rpm"].values / ds["contact_loss_rpm"].values - 1.0
    shift = ds["compliance_shift"].values
    codim2 = ds.sizes.get("codim2", 0)
    return [f"jump chart, reference-experiment, k_s {rig.k_s:.6g} -> {10 * rig.k_s:.6g} N/m: **{seconds:.1f} s** on "
            f"{threads} thread(s), {ds.sizes['point']} grazing orbits, {codim2} codimension-2 point(s); "
            f"{ds.attrs['outcome_message']}.",
            f"Jump speed {ds['speed_rpm'].values[0]:.6f} -> {ds['speed_rpm'].values[-1]:.6f} rev/min; jump / inverse "
            f"kinematics - 1: {ratio.min():.3e} to {ratio.max():.3e}; compliance shift {shift.min():.3e} to "
            f"{shift.max():.3e}; largest |difference| {np.max(np.abs(ratio - shift)):.2e}."]


def brute_force_lines(rig, ds, seconds: float, args) -> list[str]:
    """The brute-force grid's cost at the resolution the chart's jump speeds are checked to."""
    times, lines = [], []
    for i in (0, ds.sizes["point"] - 1):
        k, jump = float(ds["k_s"].values[i]), float(ds["speed_rpm"].values[i])
        below, t_below = leaves(rig.replace(k_s=k), jump * (1 - args.resolution), args.revolutions)
        above, t_above = leaves(rig.replace(k_s=k), jump * (1 + args.resolution), args.revolutions)
        times += [t_below, t_above]
        lines.append(f"k_s {k:.6g}: at (1 -+ {args.resolution:g}) x {jump:.6f} rev/min the follower "
                     f"{'leaves' if below else 'keeps'} / {'leaves' if above else 'keeps'} the cam "
                     f"({args.revolutions} revolutions, {t_below:.2f} s and {t_above:.2f} s).")
    per_k = int(round(2 * args.window / args.resolution)) + 1
    runs = per_k * ds.sizes["point"]
    grid = runs * float(np.mean(times))
    return lines + [f"Brute force at that resolution: {per_k} speeds x {ds.sizes['point']} k_s = {runs} simulations, "
                    f"~{grid:.3g} s at {np.mean(times):.2f} s each ({grid / 3600:.3g} h): {grid / seconds:.3g} x the "
                    f"chart."]


def report(lines: list[str], args, load: tuple) -> None:
    from perf.sections import write_section
    head = ["## Design charts: the jump chart", "",
            f"`python benchmarks/jump_chart.py{' --compare-threads' if args.compare_threads else ''} --report` "
            f"({os.cpu_count()} cores, load average {load[0]:.2f} before, {load[1]:.2f} after). Issue 29's target: "
            "the jump curve of the 16 mm experiment rig against k_s over one decade, 30 points with the folds and "
            "period doublings detected along it, under 10 s on 2 cores.", ""]
    print(f"wrote {write_section('jump-chart', chr(10).join(head + [f'- {line}' for line in lines]))}")


def main(argv=None):
    ap = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    ap.add_argument("--points", type=int, default=30)
    ap.add_argument("--resolution", type=float, default=1e-6, help="the grid's relative speed spacing")
    ap.add_argument("--window", type=float, default=0.01, help="the grid's half-width, relative to the speed")
    ap.add_argument("--revolutions", type=int, default=3)
    ap.add_argument("--threads", type=int, default=2, help="GrazingSettings.threads (default 2)")
    ap.add_argument("--compare-threads", action="store_true", help="time the chart on one thread too")
    ap.add_argument("--netcdf", help="save the chart here")
    ap.add_argument("--report", action="store_true", help="write the section of docs/performance.md")
    args = ap.parse_args(argv)
    warnings.filterwarnings("ignore", category=camdyn.CompileNotice)
    rig = camdyn.load_rig("reference-experiment")
    camdyn.simulate(rig, SCENE, speed_rpm=100.0, revolutions=1)                  # load the compiled loop
    load0 = os.getloadavg()[0]
    ds, seconds = chart(rig, args.points, args.threads)
    lines = chart_lines(rig, ds, seconds, args.threads)
    if args.compare_threads:
        one, one_seconds = chart(rig, args.points, 1)
        same = all(np.array_equal(one[v].values, ds[v].values) for v in ("speed_rpm", "k_s", "alpha", "alpha_dot"))
        lines.append(f"The same chart on 1 thread: {one_seconds:.1f} s ({one_seconds / seconds:.2f} x the "
                     f"{args.threads}-thread time); the curves {'are identical' if same else '**differ**'}.")
    if args.netcdf:
        ds.to_netcdf(args.netcdf, engine="scipy")
    lines += brute_force_lines(rig, ds, seconds, args)
    print("\n".join(lines))
    if args.report:
        report(lines, args, (load0, os.getloadavg()[0]))


if __name__ == "__main__":
    main()
