"""Where shooting converges: periodic orbits of the example rig over cam speed.

Run from the repository root:

    python benchmarks/orbit_scan.py [--warmup 2 20] [--periods 1] [--speeds 600 900 ...]

For each speed and warm-up length, :func:`camdyn.periodic_orbit` (line contact, damping D,
Coulomb friction, DOP853 at rtol 1e-10, atol 1e-13, Newton tolerance 1e-8) is run once; the
table gives the outcome, the mode at the section, the Newton steps, the moduli of the Floquet
multipliers, the verdict, the cost (map runs, provider calls) and the wall time (which includes
the warm-up run; the compiled loop is loaded before the first timing).  Beside it the 0-1 test's
K on 500 section values after 200 revolutions (resolution 1e-9 rad).
"""
from __future__ import annotations

import argparse
import time
import warnings

import numpy as np

import camdyn

SPEEDS = [600.0, 900.0, 1000.0, 1100.0, 1200.0, 1300.0, 1400.0, 1500.0, 1700.0, 2000.0, 2500.0]


def k_of_speed(rig, scene, speed):
    T = 60.0 / speed
    r = camdyn.simulate(rig, scene, speed_rpm=speed, revolutions=700, sample_rate_Hz=1.0 / T, rtol=1e-10, atol=1e-13)
    return camdyn.zero_one_test(r.alpha[200:], rng=0, resolution=1e-9) if r.ok else float("nan")


def main(argv=None):
    ap = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    ap.add_argument("--warmup", type=int, nargs="+", default=[2, 20])
    ap.add_argument("--periods", type=int, default=1)
    ap.add_argument("--speeds", type=float, nargs="+", default=SPEEDS)
    args = ap.parse_args(argv)
    warnings.filterwarnings("ignore", category=camdyn.CompileNotice)
    rig, scene = camdyn.example_rig(), camdyn.Scene(contact="line", damping="D", friction="coulomb")
    camdyn.simulate(rig, scene, speed_rpm=600.0, revolutions=1)          # load the compiled loop
    print("speed_rpm warmup outcome mode iterations |mu| stable residual maps jacobians seconds K")
    for speed in args.speeds:
        K = k_of_speed(rig, scene, speed)
        for warmup in args.warmup:
            t0 = time.perf_counter()
            o = camdyn.periodic_orbit(rig, scene, speed_rpm=speed, warmup_revolutions=warmup, periods=args.periods)
            dt = time.perf_counter() - t0
            mu = np.array2string(np.abs(o.multipliers), precision=3)
            print(f"{speed:g} {warmup} {o.outcome.name} {o.mode} {o.iterations} {mu} {o.stable} {o.residual:.1e} "
                  f"{o.map_evaluations} {o.jacobian_evaluations} {dt:.3f} {K:.3f}")


if __name__ == "__main__":
    main()
