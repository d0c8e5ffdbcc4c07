"""The arc cam of the second cam-follower rig (issue 28), as circular arcs and as lift laws.

    python benchmarks/second_rig_cam.py --check [--ref CF.ref]   # compares the laws, prints a summary
    python benchmarks/second_rig_cam.py --csv docs/data/second-rig-cam.csv

Plain NumPy, no camdyn import: it also runs under the system Python that
benchmarks/siconos_cam_follower.py needs (``/usr/bin/python3``). docs/second-rig.md explains it.

The cam's numbers are those hard-coded in the Siconos CamFollower example (siconos-tutorials,
examples/mechanics/CamFollower/CamState.h and FollowerPlugin/FollowerPlugin.cpp): lengths in metres
(the same file gives the spring in N/m and the mass in kg). The geometry below is our reading of
those numbers; nothing is copied from the example.

Cam angle ``theta`` (rad) is the cam's rotation since the example's time origin (theta = omega t):
theta = 0 is the start of the rise. Over one revolution the follower meets, for a flat face normal
to its guide,

    base circle (radius RB, concentric)    theta in [180, 360] deg
    flank arc   (RHO_F, centre at C_F)     theta in [0, TH_FN]         and its mirror image
    nose arc    (RHO_N, centre at C_N)     theta in [TH_FN, 70 deg]    and its mirror image
    top arc     (RHO_T, concentric)        theta in [70, 110] deg

and the cam is symmetric about theta = 90 deg. On an arc of radius rho whose centre lies at distance
c from the rotation centre, at angle psi(theta) from the follower's guide, a flat face normal to the
guide touches the arc where the arc's normal is parallel to the guide, so the face's height is
s = c cos(psi) + rho, with s' = -c sin(psi), s'' = rho - s (derivatives in theta).

``lift_flat`` is that law. ``lift_knife`` is the law the example's code evaluates; it is the law of
a knife-edge (point) follower on the guide line through the rotation centre (the height where the
guide line crosses the arc: s = -c cos(psi') + sqrt(rho^2 - (c sin(psi'))^2) in the example's
variables); it switches from flank to nose at another angle (TH_FN_KNIFE). The two laws agree on
the base, top and at the rise's ends, and differ on the flank and nose.
"""
from __future__ import annotations

import argparse
import math

import numpy as np

# -- the arcs (metres); the first four are the example's numbers, the rest follow from them ------
RB = 0.40                       # base circle radius (example: Rb)
C_F, RHO_F = 0.45, 0.85         # flank: centre distance, radius (example: k1, rho1)
RHO_N = 0.15                    # nose radius (example: rho3)
C_N = 0.40393320723821          # nose centre distance (example: k2)
RHO_T = C_N + RHO_N             # top (concentric) radius, 0.55393320723821 (example: rho2)
OFFSET = 0.30                   # example: hc - 0.3 (spring's free length, see docs/second-rig.md)

DEG = math.pi / 180.0
RISE = 70.0 * DEG               # the rise ends where the nose meets the top arc (example: beta3)
# Angle, in the cam, between the flank centre's direction and the nose centre's direction:
# the example writes the nose's angle as beta + pi/9 against the flank's beta (mirrored), i.e.
# the two centres are 110 deg apart.
GAMMA = 110.0 * DEG
# Flank-nose tangency for a flat face: where the guide is parallel to the line of centres. With
# the flank centre at angle pi + phi from the guide and the nose centre 110 deg further on, the line
# from the flank centre to the nose centre points at pi + phi + atan2(C_N sin G, C_N cos G - C_F).
TH_FN = math.pi - math.atan2(C_N * math.sin(GAMMA), C_N * math.cos(GAMMA) - C_F)   # 32.83 deg
TH_FN_KNIFE = 1.050328174371336   # example: beta2 (60.18 deg), the knife-edge's switch


def _fold(theta):
    """theta (any real, rad) -> (phi in [0, pi], sign): the cam is symmetric about theta = pi/2.

    phi is measured from the start of the rise (0) to the middle of the top (pi/2) and on to the
    bottom of the base circle (pi); sign is +1 on the rise side, -1 on the return side (s' flips)."""
    th = np.mod(np.asarray(theta, dtype=float) + math.pi / 2, 2 * math.pi)   # example's beta
    sign = np.where(th > math.pi, -1.0, 1.0)
    beta = np.where(th > math.pi, 2 * math.pi - th, th)                     # in [0, pi]
    phi = beta - math.pi / 2                                                  # rise start = 0
    return phi, sign


def lift_flat(theta):
    """(s, s', s'') of a translating flat-faced follower, s measured from the rotation centre.

    phi < 0: base circle; 0..TH_FN: flank; TH_FN..RISE: nose; RISE..pi/2: top arc."""
    phi, sign = _fold(theta)
    s = np.empty_like(phi); d1 = np.zeros_like(phi); d2 = np.zeros_like(phi)
    base = phi <= 0
    flank = (phi > 0) & (phi <= TH_FN)
    nose = (phi > TH_FN) & (phi <= RISE)
    top = phi > RISE
    s[base] = RB
    # flank centre at angle pi + phi from the guide: s = -C_F cos(phi) + RHO_F
    s[flank] = -C_F * np.cos(phi[flank]) + RHO_F
    d1[flank] = C_F * np.sin(phi[flank])
    # nose centre at angle phi - RISE from the guide: s = C_N cos(phi - RISE) + RHO_N
    s[nose] = C_N * np.cos(phi[nose] - RISE) + RHO_N
    d1[nose] = -C_N * np.sin(phi[nose] - RISE)
    s[top] = RHO_T
    for m, rho in ((flank, RHO_F), (nose, RHO_N)):
        d2[m] = rho - s[m]
    return s, sign * d1, d2


def lift_knife(theta):
    """(s, s', s'') of the law in the Siconos example's code (a knife-edge follower), our own
    transcription in the same variables as lift_flat; s'' by central differences of s'."""
    phi, sign = _fold(theta)

    def s_and_d1(p):
        s = np.full_like(p, RB); d1 = np.zeros_like(p)
        flank = (p > 0) & (p <= TH_FN_KNIFE)
        nose = (p > TH_FN_KNIFE) & (p <= RISE)
        top = p > RISE
        # flank centre (distance C_F) at angle pi + p from the guide line
        a = C_F * np.sin(p[flank]); b = -C_F * np.cos(p[flank])
        r = np.sqrt(RHO_F**2 - a**2)
        s[flank] = b + r
        d1[flank] = C_F * np.sin(p[flank]) - a * C_F * np.cos(p[flank]) / r
        a = C_N * np.sin(p[nose] - RISE); b = C_N * np.cos(p[nose] - RISE)
        r = np.sqrt(RHO_N**2 - a**2)
        s[nose] = b + r
        d1[nose] = -C_N * np.sin(p[nose] - RISE) - a * C_N * np.cos(p[nose] - RISE) / r
        s[top] = RHO_T
        return s, d1

    s, d1 = s_and_d1(phi)
    eps = 1e-6
    d2 = (s_and_d1(phi + eps)[1] - s_and_d1(phi - eps)[1]) / (2 * eps)
    return s, sign * d1, d2


LAWS = {"flat": lift_flat, "knife": lift_knife}


def detachment_speed(law, mass=1.221, stiffness=1430.8, gravity=0.0, samples=720000):
    """Lowest constant cam speed (rev/min) at which the constrained mode's contact force,
    m omega^2 s''(theta) + k (s - OFFSET) + m g, reaches zero somewhere on the cam, and that angle
    (deg). Sampled on ``samples`` angles; where s'' jumps the larger deceleration counts."""
    th = np.linspace(0, 2 * math.pi, samples, endpoint=False)
    s, _, d2 = law(th)
    dec = d2 < 0
    w2 = (stiffness * (s[dec] - OFFSET) + mass * gravity) / (-mass * d2[dec])
    i = int(np.argmin(w2))
    return math.sqrt(w2[i]) * 60 / (2 * math.pi), th[dec][i] / DEG


def check(ref: str | None = None) -> None:
    """Prints the laws' features; with ``ref`` (the example's committed output CF.ref: columns t,
    ..., CamPosition = s - 0.3, CamVelocity = ds/dt, at 358 rev/min) compares them with it."""
    th = np.linspace(0, 2 * math.pi, 72001)[:-1]
    sk = lift_knife(th)[0]; sf, d1f, d2f = lift_flat(th)
    print(f"flank-nose switch: flat {TH_FN / DEG:.4f} deg, knife (example beta2) {TH_FN_KNIFE / DEG:.4f} deg")
    i = np.argmax(np.abs(sf - sk))
    print(f"max |flat - knife| = {np.abs(sf - sk)[i]:.6e} m at theta = {th[i] / DEG:.2f} deg")
    print(f"lift range (flat) {np.min(sf) - RB:.6f} .. {np.max(sf) - RB:.6f} m")
    for name, a in (("base-flank", 0.0), ("flank-nose", TH_FN), ("nose-top", RISE)):
        lo = lift_flat(a - 1e-9); hi = lift_flat(a + 1e-9)
        print(f"flat {name:10s} at {a / DEG:8.4f} deg: s jump {float(hi[0] - lo[0]):+.1e}, "
              f"s' jump {float(hi[1] - lo[1]):+.1e}, s'' {float(lo[2]):+.5f} -> {float(hi[2]):+.5f} m/rad^2")
    for name, a in (("flank-nose", TH_FN_KNIFE), ("nose-top", RISE)):
        lo = lift_knife(a - 1e-5); hi = lift_knife(a + 1e-5)
        print(f"knife {name:10s} at {a / DEG:8.4f} deg: s'' {float(lo[2]):+.5f} -> {float(hi[2]):+.5f} m/rad^2 "
              f"(1e-5 rad either side)")
    for name, law in LAWS.items():
        rpm, at = detachment_speed(law)
        print(f"{name}: detachment at {rpm:.2f} rev/min (m 1.221 kg, k 1430.8 N/m, spring free at 0.3 m, "
              f"no gravity), first at theta = {at:.2f} deg")
    h = th[1] - th[0]
    for name, law in LAWS.items():
        s, d1, _ = law(th)
        fd1 = (np.roll(s, -1) - np.roll(s, 1)) / (2 * h)
        ok = np.ones_like(th, bool)
        for a in (0.0, TH_FN, TH_FN_KNIFE, RISE, math.pi - RISE, math.pi - TH_FN, math.pi - TH_FN_KNIFE, math.pi):
            ok &= np.abs(np.angle(np.exp(1j * (th - a)))) > 2 * h
        print(f"{name}: max |s' - central difference of s| = {np.max(np.abs(fd1 - d1)[ok]):.2e} m/rad "
              f"(step {h / DEG:.4f} deg, junctions excluded)")
    if ref:
        data = np.loadtxt(ref, skiprows=1)
        t, pos, vel = data[:, 0], data[:, 5], data[:, 6]
        omega = 2 * math.pi * 358 / 60
        for name, law in LAWS.items():
            s, d1, _ = law(omega * t)
            print(f"{name} vs CF.ref ({t.size} rows, 358 rev/min): max |s - 0.3 - CamPosition| = "
                  f"{np.max(np.abs(s - OFFSET - pos)):.3e} m, max |omega s' - CamVelocity| = "
                  f"{np.max(np.abs(omega * d1 - vel)):.3e} m/s")


def write_csv(path: str, step_deg: float = 0.25) -> None:
    th_deg = np.arange(0.0, 360.0 + 1e-9, step_deg)
    s, d1, d2 = lift_flat(th_deg * DEG)
    sk = lift_knife(th_deg * DEG)[0]
    with open(path, "w") as fh:
        fh.write("# Arc cam of the second rig (docs/second-rig.md), generated by benchmarks/second_rig_cam.py\n")
        fh.write("# theta_deg: cam angle from the start of the rise; lift = s - base radius (0.4 m)\n")
        fh.write("# flat: translating flat-faced follower (s' in mm/rad, s'' in mm/rad^2); "
                 "knife: the law coded in the Siconos CamFollower example\n")
        fh.write("theta_deg,lift_mm,dlift_mm_per_rad,d2lift_mm_per_rad2,lift_knife_mm\n")
        for row in zip(th_deg, (s - RB) * 1e3, d1 * 1e3, d2 * 1e3, (sk - RB) * 1e3):
            fh.write("{:.2f},{:.6f},{:.6f},{:.6f},{:.6f}\n".format(*row))


if __name__ == "__main__":
    ap = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    ap.add_argument("--check", action="store_true")
    ap.add_argument("--ref", help="the example's CF.ref, to compare the laws with its CamPosition column")
    ap.add_argument("--csv")
    a = ap.parse_args()
    if a.check:
        check(a.ref)
    if a.csv:
        write_csv(a.csv)
