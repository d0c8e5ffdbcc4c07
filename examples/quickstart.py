"""Quickstart: simulate the example rig at two cam speeds and save a plot.

    python examples/quickstart.py [--out quickstart.png]

At 300 rev/min the follower slides on the cam (Section 6); at 1100 rev/min,
above the contact-loss speed, it leaves the cam and impacts once per revolution.
"""
from __future__ import annotations

import argparse

import matplotlib

matplotlib.use("Agg")
import matplotlib.pyplot as plt

import camdyn
from camdyn.analysis import contact_loss_speed, natural_frequency


def main() -> None:
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("--out", default="quickstart.png", help="PNG file to write")
    args = parser.parse_args()

    rig = camdyn.example_rig()
    scene = camdyn.Scene(contact="line", damping="D", friction="coulomb")
    loss = contact_loss_speed(rig)
    nf = natural_frequency(rig, scene, camdyn.ConstantSpeed(300))
    print(f"rig {rig.name!r}: contact lost above {loss:.0f} rev/min; "
          f"natural frequency {nf.Hz:.0f} Hz in sliding contact at 300 rev/min")

    fig, axes = plt.subplots(2, 2, figsize=(10, 6), constrained_layout=True)
    for column, speed in enumerate((300.0, 1100.0)):
        result = camdyn.simulate(rig, scene, speed_rpm=speed, revolutions=3, sample_rate_Hz=50_000)
        print(result.summary())
        revs = (result.t - result.t[0]) / result.period
        axes[0, column].plot(revs, result.alpha_r * 1e6, lw=0.8)
        axes[0, column].set(title=f"{speed:.0f} rev/min", ylabel=r"$\alpha_r$ (µrad)")
        axes[1, column].plot(revs, result.F_n, lw=0.8)
        axes[1, column].set(xlabel="t / T (cam revolutions)", ylabel=r"$F_n$ (N)")
    fig.suptitle("camdyn quickstart: residual response and normal force (line contact, damping D, Coulomb)")
    fig.savefig(args.out, dpi=120)
    print(f"saved {args.out}")


if __name__ == "__main__":
    main()
