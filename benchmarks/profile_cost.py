"""The cost of a cam profile in the contact RHS (issue 27): ns per call of the generated ``rhs``
cfunc in a compiled loop, for the paper's circle and for scenes whose kernels call a profile
evaluator (a spline, arcs), interleaved rounds, the ratios within one run.

    python benchmarks/profile_cost.py      # prints a Markdown section (docs/performance.md quotes it)

The state sweeps one cam revolution (the time runs over a period, so the evaluator's piece
search meets every piece, as in a run), at the static equilibrium's alpha.
"""
from __future__ import annotations

import math
import os
import sys
import warnings

import numpy as np
from numba import njit

import camdyn
from camdyn.engine.kernels import compiled_kernels
from camdyn.model.profiles import ArcProfile, EccentricCircle, SplineProfile

sys.path.insert(0, os.path.dirname(__file__))
from floor import CAM_FLOOR_RPM, interleaved  # noqa: E402

SPEED_RPM = 600
CALLS = 200_000
ROUNDS = 7


@njit(error_model="numpy")
def _rhs_over_a_turn(rhs, m, n, period, a, ad, p):
    acc = 0.0
    for i in range(n):
        acc += rhs(m, period * i / n, a, ad, p)
    return acc


def circle_spline(rig, pieces: int) -> SplineProfile:
    circle = EccentricCircle(rig.r_c, rig.e)
    phi = np.linspace(0.0, 2 * math.pi, pieces + 1)
    return SplineProfile.hermite(phi, *(circle.h(phi, d) for d in range(3)))


def cases(rig) -> dict[str, tuple]:
    """label -> (rig, scene) for each measured profile."""
    arcs = ArcProfile.circular_arc_cam(r_b=0.022, r_n=0.008, d=0.018, R=0.06)
    return {"eccentric circle (the paper's kernels)": (rig, camdyn.Scene(contact="point")),
            "spline, 64 pieces": (rig.replace(profile=circle_spline(rig, 64)), camdyn.Scene(contact="point", profile="spline")),
            "spline, 1024 pieces": (rig.replace(profile=circle_spline(rig, 1024)),
                                    camdyn.Scene(contact="point", profile="spline")),
            "circular-arc cam, 4 arcs": (rig.replace(profile=arcs), camdyn.Scene(contact="point", profile="arcs"))}


def measure() -> dict[str, float]:
    """ns per rhs call for each case, best of interleaved rounds."""
    rig = camdyn.example_rig()
    loops = {}
    for label, (r, scene) in cases(rig).items():
        model = camdyn.Model(r, scene, camdyn.ConstantSpeed(SPEED_RPM))
        kern = compiled_kernels(model.kernels)
        m = model.kernels.MODE_CONTACT_LOADING_FWD
        a, ad = map(float, model.static_state())
        p = np.ascontiguousarray(model.p, dtype=float)
        _rhs_over_a_turn(kern.rhs, m, 10, model.period, a, ad, p)
        loops[label] = (lambda k=kern, m=m, T=model.period, a=a, ad=ad, p=p:
                        _rhs_over_a_turn(k.rhs, m, CALLS, T, a, ad, p))
    times = interleaved(loops, ROUNDS)
    return {label: min(t) / CALLS * 1e9 for label, t in times.items()}


def report(ns: dict[str, float], floor_on_cam=None) -> str:
    base = next(iter(ns.values()))
    rows = [f"| {label} | {v:.1f} | {v / base:.2f} |" for label, v in ns.items()]
    worst = max(v / base for v in list(ns.values())[1:])
    verdict = "met" if worst <= 1.5 else "**not met**"
    return "\n".join([
        "## The cost of a cam profile in the RHS",
        "",
        f"`python benchmarks/profile_cost.py`: one call of the generated contact `rhs` (point contact, damping D, "
        f"Coulomb, loading, forward) as a numba cfunc in a compiled loop, {CALLS} calls over one cam revolution "
        f"at {SPEED_RPM} rev/min (the evaluator's piece search meets every piece), best of {ROUNDS} interleaved "
        f"rounds; load average {os.getloadavg()[0]:.2f}.",
        "",
        "| profile | ns per call | x the circle |", "|---|---|---|", *rows, "",
        f"Issue 27's target, at most 1.5 x the circle's: {verdict} (worst {worst:.2f} x)."]
        + ([] if floor_on_cam is None else [
            "", f"The floor comparison on that cam (`benchmarks/floor.py`'s run on the cycloidal cam of "
                f"`benchmarks/profile_cost.py`, {CAM_FLOOR_RPM:g} rev/min, permanent contact, spline scene): "
                f"engine / floor, the same work, **{floor_on_cam.ratio_median:.2f}** (median of rounds; best/best "
                f"{floor_on_cam.ratio_best:.2f}); the engine as it runs / floor: {floor_on_cam.default_ratio:.2f}; "
                f"RHS {floor_on_cam.rhs_ns:.1f} ns per call; max |alpha_engine - alpha_floor| "
                f"{floor_on_cam.max_alpha_diff:.1e} rad."]))


def main() -> int:
    warnings.simplefilter("ignore", camdyn.CompileNotice)
    print(report(measure()))
    return 0


if __name__ == "__main__":
    sys.exit(main())
