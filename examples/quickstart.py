"""Quickstart: simulate the example rig at two cam speeds and save a plot.

    python examples/quickstart.py [--out FILE]

At 300 rev/min the follower slides on the cam (Section 6); at 1100 rev/min, above the
contact-loss speed, it leaves the cam and hits it again, several times a revolution: the
run prints how often.  The figure goes to ``--out`` (default: quickstart.png in the current
folder); the script prints where it wrote it.
"""
from __future__ import annotations

import argparse
from pathlib import Path

import matplotlib

matplotlib.use("Agg")
import matplotlib.pyplot as plt

import camdyn
from camdyn.io import plots
from camdyn.analysis.statics import contact_loss_speed, natural_frequency
from camdyn.io.metadata import describe_scene

SPEEDS_RPM = (300.0, 1100.0)
REVOLUTIONS = 3


def contact_report(result) -> str:
    """How the run touched the cam, counted from the run itself."""
    impacts = result.impacts().size
    if impacts == 0:
        return "the follower stays on the cam (no impacts)"
    return (f"the follower leaves the cam and hits it {impacts} times in {REVOLUTIONS} revolutions "
            f"({impacts / REVOLUTIONS:.3g} per revolution)")


def main(argv: list[str] | None = None) -> Path:
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("--out", default="quickstart.png", help="figure file to write (default: %(default)s "
                                                                "in the current folder)")
    args = parser.parse_args(argv)
    out = Path(args.out).resolve()

    rig = camdyn.example_rig()
    scene = camdyn.Scene(contact="line", damping="D", friction="coulomb")
    loss = contact_loss_speed(rig)
    nf = natural_frequency(rig, scene, camdyn.ConstantSpeed(300))
    print(f"rig {rig.name!r}: contact lost above {loss:.0f} rev/min; "
          f"natural frequency {nf.Hz:.0f} Hz in sliding contact at 300 rev/min")

    with plots.style():
        fig, axes = plt.subplots(2, 2, figsize=(10, 6), constrained_layout=True)
    for column, speed in enumerate(SPEEDS_RPM):
        result = camdyn.simulate(rig, scene, speed_rpm=speed, revolutions=REVOLUTIONS, sample_rate_Hz=50_000)
        print(result.summary())
        print(f"  at {speed:.0f} rev/min {contact_report(result)}")
        plots.time_history(result, "alpha_r", ax=axes[0, column], shade_free=True, title=f"{speed:.0f} rev/min")
        plots.time_history(result, "F_n", ax=axes[1, column], shade_free=True)
        axes[0, column].set_xlabel("")
    fig.suptitle(f"camdyn quickstart: residual response and normal force ({describe_scene(scene)})")
    fig.savefig(out, dpi=120)
    plt.close(fig)
    print(f"saved {out}")
    return out


if __name__ == "__main__":
    main()
