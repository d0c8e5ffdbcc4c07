"""The ``camdyn`` command: simulate, equilibrium, contact-loss speed, regenerate.

Errors print as one line (``camdyn: error: ...``) with exit code 2; a simulation
that stops early (see ``Outcome``) exits with 3.  ``camdyn <command> --help``
lists each command's options.
"""
from __future__ import annotations

import argparse
import csv
import json
import subprocess
import sys

from .errors import CamdynError


def _rig(name):
    from .presets import load_rig
    return load_rig(name)


def _scene(args):
    from .scene import Scene
    return Scene(contact=args.contact, damping=args.damping, friction=args.friction)


def cmd_simulate(args) -> int:
    from .analysis import residual_stats
    from .simulation import simulate
    result = simulate(_rig(args.rig), _scene(args), speed_rpm=args.speed_rpm, revolutions=args.revolutions,
                      sample_rate_Hz=args.sample_rate_Hz, rtol=args.rtol)
    print(result.summary())
    if result.ok and result.t.size > 1:
        stats = residual_stats(result)
        print(f"  alpha_r: rms {stats.rms:.6g} rad, peak-to-peak {stats.peak_to_peak:.6g} rad")
    if args.csv:
        columns = ["t", "alpha", "alpha_dot", "Theta", "alpha_r"] + list(result.outputs)
        with open(args.csv, "w", newline="") as fh:
            writer = csv.writer(fh)
            writer.writerow(columns + ["regime"])
            data = [getattr(result, c) for c in columns]
            for i in range(result.t.size):
                writer.writerow([repr(float(col[i])) for col in data] + [result.regime[i]])
        print(f"  wrote {args.csv}")
    return 0 if result.ok else 3


def cmd_equilibrium(args) -> int:
    from .analysis import natural_frequency, static_equilibrium
    from .cam import ConstantSpeed
    rig = _rig(args.rig)
    eq = static_equilibrium(rig, args.contact)
    nf = natural_frequency(rig, _scene(args), ConstantSpeed(args.speed_rpm))
    out = {"alpha_star_rad": eq.alpha, "psi_i_star_m": eq.psi_i, "psi_j_star_m": eq.psi_j, "chi_star_m": eq.chi,
           "contact_stiffness_N_per_m": eq.contact_stiffness, "natural_frequency_Hz": nf.Hz,
           "natural_frequency_rad_s": nf.damped_rad_s, "damping_ratio": nf.damping_ratio}
    print(json.dumps(out, indent=2))
    return 0


def cmd_contact_loss(args) -> int:
    from .analysis import contact_loss_speed
    print(f"{contact_loss_speed(_rig(args.rig)):.6g}")
    return 0


def cmd_regenerate(args) -> int:
    command = [sys.executable, "-m", "camdyn.derive"] + (["--check"] if args.check else [])
    return subprocess.call(command)


def _parser() -> argparse.ArgumentParser:
    parser = argparse.ArgumentParser(prog="camdyn", description=__doc__.splitlines()[0])
    sub = parser.add_subparsers(dest="command", required=True)

    def physics(p, contact=True):
        p.add_argument("--rig", default="example", help="shipped rig name or path to a .toml file")
        if contact:
            p.add_argument("--contact", default="line", choices=["line", "point"])
        p.add_argument("--damping", default="D", choices=["none", "A", "B", "C", "D", "E"])
        p.add_argument("--friction", default="coulomb", choices=["none", "coulomb", "tanh"])

    p = sub.add_parser("simulate", help="simulate at a constant cam speed")
    physics(p)
    p.add_argument("--speed-rpm", type=float, required=True, dest="speed_rpm")
    p.add_argument("--revolutions", type=float, default=3.0)
    p.add_argument("--sample-rate-Hz", type=float, default=20_000.0, dest="sample_rate_Hz")
    p.add_argument("--rtol", type=float, default=1e-8)
    p.add_argument("--csv", help="write the time histories to this CSV file")
    p.set_defaults(func=cmd_simulate)

    p = sub.add_parser("equilibrium", help="static equilibrium and natural frequency (Eqs. 16-23)")
    physics(p)
    p.add_argument("--speed-rpm", type=float, default=0.0, dest="speed_rpm",
                   help="cam speed setting the friction direction (default: at rest)")
    p.set_defaults(func=cmd_equilibrium)

    p = sub.add_parser("contact-loss", help="contact-loss speed in rev/min by inverse kinematics")
    p.add_argument("--rig", default="example")
    p.set_defaults(func=cmd_contact_loss)

    p = sub.add_parser("regenerate", help="regenerate camdyn.generated (needs camdyn[derive])")
    p.add_argument("--check", action="store_true", help="only check that generated/ is up to date")
    p.set_defaults(func=cmd_regenerate)
    return parser


def main(argv: list[str] | None = None) -> int:
    parser = _parser()
    args = parser.parse_args(argv)
    try:
        return args.func(args)
    except (CamdynError, ValueError, OSError) as exc:
        print(f"camdyn: error: {exc}", file=sys.stderr)
        return 2


if __name__ == "__main__":
    sys.exit(main())
