"""A cycloidal rise-dwell-return cam on either flat-faced follower: where it jumps, and the orbit that grazes.

For each follower type (the paper's oscillating rocker, and a translating face on a guide) this
synthesizes the cam that gives the follower a cycloidal rise-dwell-return lift, finds the jump speed
by inverse kinematics (the rigid contact's force reaching zero), simulates 20 revolutions at 0.8 x
that speed from rest in the low dwell (320 degrees), and continues the periodic orbit in the cam speed from 0.8 x to 1.2 x, where the
continuation locates the grazing: the first speed at which the compliant follower leaves the cam.
Each step prints its time (the first run of each compiles its kernels, the first derivation of a
scene not in the catalog derives it).

    python examples/any_cam.py
"""
from __future__ import annotations

import math
import time
import warnings

import camdyn
from camdyn.analysis import contact_loss_speed
from camdyn.orbits.continuation import events_table
from camdyn.model.presets import cam_example_rig, translating_cam_example_rig

warnings.filterwarnings("ignore", category=camdyn.CompileNotice)

CASES = {
    "oscillating (0.05 rad lift, base circle 25 mm)": (cam_example_rig(theta0=math.radians(320)),
                                                       camdyn.Scene(profile="spline")),
    "translating (10 mm lift, base circle 15 mm)": (
        translating_cam_example_rig(), camdyn.Scene(follower="translating", friction="none", profile="spline")),
}


def timed(label: str, call):
    start = time.perf_counter()
    value = call()
    print(f"  {label}: {time.perf_counter() - start:.2f} s")
    return value


def main() -> None:
    for name, (rig, scene) in CASES.items():
        print(f"{name}, scene {scene.slug}")
        jump = timed("jump speed by inverse kinematics", lambda: contact_loss_speed(rig))
        print(f"    {jump:.3f} rev/min")
        run = timed("simulate 20 revolutions at 0.8 x", lambda: camdyn.simulate(rig, scene, speed_rpm=0.8 * jump,
                                                                               revolutions=20))
        print(f"    {run.outcome.name}, {run.impacts().size} impacts, largest residual {abs(run.residual).max():.3g}")
        branch = timed("continue the orbit from 0.8 x to 1.2 x", lambda: camdyn.continue_orbit(
            rig, scene, "speed_rpm", 0.8 * jump, 1.2 * jump))
        grazing = [speed for kind, speed, _, _ in events_table(branch) if kind == "grazing"]
        for speed in grazing:
            print(f"    grazing at {speed:.3f} rev/min ({speed / jump:.6f} x the inverse-kinematics speed)")
        if not grazing:
            print("    no grazing located")


if __name__ == "__main__":
    main()
