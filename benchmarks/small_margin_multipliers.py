"""Floquet multipliers on rigs with a small contact margin, by every provider (issue 25).

    python benchmarks/small_margin_multipliers.py      # prints a Markdown table

For the small-margin rigs of tests/test_derivatives.py, at 0.8, 0.9 and 0.95 x their
contact-loss speed: the multipliers of the default provider (finite differences with the
variational fallback; which one gave them), of finite differences alone (or "unresolved"), of the
variational provider at the default rtol 1e-10, and of the variational provider at rtol 1e-12
(the tight reference), with the largest difference from the reference.
"""
from __future__ import annotations

import functools
import sys
import warnings

from pathlib import Path

import numpy as np

import camdyn
from camdyn.analysis.statics import contact_loss_speed
from camdyn.engine import SolverOptions
from camdyn.orbits.derivatives import finite_differences
from camdyn.orbits.tangent import variational

sys.path.insert(0, str(Path(__file__).resolve().parent.parent / "tests"))
from registry import SMALL_MARGIN as RIGS  # noqa: E402  (the rigs of tests/test_derivatives.py, defined once)

TIGHT = SolverOptions(rtol=1e-12, atol=1e-15)


def _mu(orbit) -> str:
    if orbit.multipliers.size == 0:
        return orbit.outcome.name.lower()
    return ", ".join(f"{m.real:.6g}{m.imag:+.3g}j" if abs(m.imag) > 0 else f"{m.real:.6g}"
                     for m in sorted(orbit.multipliers, key=abs, reverse=True))


def row(name: str, fraction: float) -> list[str]:
    rig, scene = RIGS[name]
    speed = fraction * contact_loss_speed(rig)
    default = camdyn.periodic_orbit(rig, scene, speed_rpm=speed)
    alone = camdyn.periodic_orbit(rig, scene, speed_rpm=speed,
                                  jacobian=functools.partial(finite_differences, fallback=False))
    var = camdyn.periodic_orbit(rig, scene, speed_rpm=speed, jacobian=variational)
    ref = camdyn.periodic_orbit(rig, scene, speed_rpm=speed, jacobian=variational, options=TIGHT)
    diff = np.max(np.abs(default.multipliers - ref.multipliers)) if default.multipliers.size else np.nan
    return [name, f"{fraction:g}", f"{_mu(default)} ({default.jacobian_provider})", _mu(alone), _mu(var), _mu(ref),
            f"{diff:.1e}"]


def main() -> int:
    warnings.simplefilter("ignore", camdyn.CompileNotice)
    head = ["rig", "x loss speed", "default (provider)", "finite differences alone", "variational, rtol 1e-10",
            "variational, rtol 1e-12", "max |default - 1e-12|"]
    print("| " + " | ".join(head) + " |")
    print("|" + "---|" * len(head))
    for name in RIGS:
        for fraction in (0.8, 0.9, 0.95):
            print("| " + " | ".join(row(name, fraction)) + " |", flush=True)
    return 0


if __name__ == "__main__":
    sys.exit(main())
