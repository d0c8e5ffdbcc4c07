"""The jump chart of the reference experiment rig against k_s over one decade, timed, beside the
cost of its brute-force answer (a speed x k_s grid of simulations).

Run from the repository root:

    python benchmarks/jump_chart.py [--points 30] [--resolution 1e-6] [--window 0.01] [--netcdf chart.nc]

The rig: ``reference-experiment`` (line contact 16 mm, damping D, Coulomb friction), k_s from its
own value to ten times it.  camdyn.orbits.continuation.jump_chart follows the grazing orbit in
(speed, k_s), its arclength step set for about ``--points`` grazing orbits; it prints the wall time
(the compiled loop is loaded before the first timing), the orbits, how the curve ended, and the
jump speed against the inverse-kinematics contact-loss speed with the first-order compliance
shift (camdyn.analysis.statics.compliance_shift).

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
import time
import warnings

import numpy as np

import camdyn
from camdyn.orbits.continuation import ContinuationSettings, GrazingSettings, jump_chart

SCENE = camdyn.Scene(contact="line", damping="D", friction="coulomb")
#: the scaled arclength of the curve over the decade (measured on a run: lambda2's range is 1,
#: the speed's change 2.2 times its start value), divided among the points
ARCLENGTH = 2.5


def chart(rig, points: int):
    step = ARCLENGTH / (points - 1)
    settings = GrazingSettings(continuation=ContinuationSettings(step=step, max_step=step, switch_depth=0))
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


def main(argv=None):
    ap = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    ap.add_argument("--points", type=int, default=30)
    ap.add_argument("--resolution", type=float, default=1e-6, help="the grid's relative speed spacing")
    ap.add_argument("--window", type=float, default=0.01, help="the grid's half-width, relative to the speed")
    ap.add_argument("--revolutions", type=int, default=3)
    ap.add_argument("--netcdf", help="save the chart here")
    args = ap.parse_args(argv)
    warnings.filterwarnings("ignore", category=camdyn.CompileNotice)
    rig = camdyn.load_rig("reference-experiment")
    camdyn.simulate(rig, SCENE, speed_rpm=100.0, revolutions=1)                  # load the compiled loop
    ds, seconds = chart(rig, args.points)
    if args.netcdf:
        ds.to_netcdf(args.netcdf, engine="scipy")
    ratio = ds["speed_rpm"].values / ds["contact_loss_rpm"].values - 1.0
    shift = ds["compliance_shift"].values
    print(f"jump chart, reference-experiment, k_s {rig.k_s:.6g} -> {10 * rig.k_s:.6g} N/m: {seconds:.1f} s, "
          f"{ds.sizes['point']} grazing orbits; {ds.attrs['outcome_message']}")
    print(f"  jump speed {ds['speed_rpm'].values[0]:.6f} -> {ds['speed_rpm'].values[-1]:.6f} rev/min; "
          f"jump / inverse kinematics - 1: {ratio.min():.3e} to {ratio.max():.3e}; compliance shift "
          f"{shift.min():.3e} to {shift.max():.3e}; largest |difference| {np.max(np.abs(ratio - shift)):.2e}")
    times = []
    for i in (0, ds.sizes["point"] - 1):
        k, jump = float(ds["k_s"].values[i]), float(ds["speed_rpm"].values[i])
        below, t_below = leaves(rig.replace(k_s=k), jump * (1 - args.resolution), args.revolutions)
        above, t_above = leaves(rig.replace(k_s=k), jump * (1 + args.resolution), args.revolutions)
        times += [t_below, t_above]
        print(f"  k_s {k:.6g}: at (1 -+ {args.resolution:g}) x {jump:.6f} rev/min the follower "
              f"{'leaves' if below else 'keeps'} / {'leaves' if above else 'keeps'} the cam "
              f"({args.revolutions} revolutions, {t_below:.2f} s and {t_above:.2f} s)")
    per_k = int(round(2 * args.window / args.resolution)) + 1
    runs = per_k * ds.sizes["point"]
    grid = runs * float(np.mean(times))
    print(f"brute force at that resolution: {per_k} speeds x {ds.sizes['point']} k_s = {runs} simulations, "
          f"~{grid:.3g} s at {np.mean(times):.2f} s each ({grid / 3600:.3g} h): {grid / seconds:.3g} x the chart")


if __name__ == "__main__":
    main()
