"""The second rig (issue 28) by Siconos's Moreau-Jean time stepping: a work-precision table of the peer.

Needs Debian's Siconos (a system package, used by this script only; not a camdyn dependency and
not in pyproject.toml), run with the system Python 3.11 it is built for, not camdyn's venv:

    apt-get install python3-siconos
    /usr/bin/python3 benchmarks/siconos_cam_follower.py --speed-rpm 358 --revolutions 20 \\
        --out siconos-358.json

Other options: --law flat|knife (the cam's lift law, benchmarks/second_rig_cam.py: ``flat`` for a
translating flat-faced follower on the arc cam, the default; ``knife`` for the law the Siconos
CamFollower example codes), --steps (the fixed steps h, s; the smallest is the reference),
--section-deg (cam angle of the Poincare section), --v-min (smallest approach speed counted as an
impact), --restitution, --gravity; --selfcheck (the forcing against the constrained mode's contact
force, below the detachment speed); --scan-rpm N1 N2 ... (periodic or not, per speed, at one step).

The model (docs/second-rig.md): a follower of mass m on a spring k whose free length puts the
follower at u = 0.3 m from the cam's rotation centre (u is the follower face's height; on the cam,
u = s(theta), s from 0.4 to 0.554 m, so the spring always pushes the follower onto the cam), a
unilateral constraint u >= s(theta(t)) with theta = omega t, and Newton's impact law on the
relative velocity with restitution e. Siconos integrates it in the relative coordinate
q = u - s(theta(t)) (the translation the Siconos CamFollower documentation describes): a
LagrangianLinearTIDS (mass m, stiffness k, no damping) driven by
f(t) = -(m s''(t) + k (s(t) - 0.3)) - m g, a LagrangianLinearTIR y = q >= 0, a NewtonImpactNSL(e),
MoreauJeanOSI(theta = 0.5) and an LCP one-step problem (Siconos's default LCP solver, Lemke). The forcing
is passed as a vector set before every step to (f(t_k) + f(t_k+1)) / 2, which is what Moreau-Jean's
theta = 0.5 quadrature would evaluate with a plugin.

Measured per step h: the wall time of the stepping loop (the Siconos steps plus this script's
per-step Python: setting the forcing, reading the state); the impacts; the Poincare section.

- An impact is a step whose contact impulse is positive and whose relative velocity before the step
  is below -v_min (an approach faster than v_min). Its time is the start of the step plus the time
  the pre-impact state needs to close the gap, y_k / (-v_k), clipped to the step: Moreau-Jean only
  knows the impact lies in the step.
- The section is the follower's absolute position u and velocity du/dt at cam angle
  --section-deg (default 130 deg, in flight between two impacts in both runs of docs/second-rig.md),
  once per revolution, interpolated linearly between the steps around it.

Against the reference (the smallest h): for each reference impact the nearest impact of the run
(|t_h - t_ref|: median, 90th percentile and max over the reference impacts), and the section's largest difference
over the revolutions in position and in velocity. These are differences from the smallest step's
run, not from the exact solution: they bound the error of the coarser steps only while the
reference is much closer to the exact solution than they are.
"""
from __future__ import annotations

import argparse
import json
import math
import os
import platform
import sys
import time

import numpy as np

sys.path.insert(0, os.path.dirname(os.path.abspath(__file__)))
from second_rig_cam import LAWS, OFFSET  # noqa: E402  (plain NumPy, no camdyn)

MASS = 1.221        # kg, Siconos CamFollower example (and the issue)
STIFFNESS = 1430.8  # N/m, same source



def _moreau_jean(sk, h: float, n: int, restitution: float):
    """The follower's relative coordinate as a Siconos Lagrangian system (mass, spring), its unilateral
    contact with Newton's impact law, and Moreau-Jean time stepping (theta 0.5, LCP) over n steps of h:
    (the system, its external force buffer, the interaction, the simulation)."""
    ds = sk.LagrangianLinearTIDS(np.array([0.0]), np.array([0.0]), np.array([[MASS]]),
                                 np.array([[STIFFNESS]]), np.array([[0.0]]))
    fext = np.zeros(1)
    ds.setFExtPtr(fext)
    inter = sk.Interaction(sk.NewtonImpactNSL(restitution), sk.LagrangianLinearTIR(np.array([[1.0]])))
    nsds = sk.NonSmoothDynamicalSystem(0.0, n * h)
    nsds.insertDynamicalSystem(ds)
    nsds.link(inter, ds)
    return ds, fext, inter, sk.TimeStepping(nsds, sk.TimeDiscretisation(0.0, h), sk.MoreauJeanOSI(0.5), sk.LCP())

def run(h: float, args) -> dict:
    import siconos.kernel as sk

    law = LAWS[args.law]
    omega = args.speed_rpm * 2 * math.pi / 60
    period = 2 * math.pi / omega
    t_end = args.revolutions * period
    n = int(math.ceil(t_end / h - 1e-9))
    t = np.arange(n + 1) * h
    s, d1, d2 = law(omega * t)
    sdot = omega * d1
    force = -(MASS * omega**2 * d2 + STIFFNESS * (s - OFFSET)) - MASS * args.gravity
    f_step = 0.5 * (force[:-1] + force[1:])

    ds, fext, inter, sim = _moreau_jean(sk, h, n, args.restitution)

    q = np.empty(n + 1); v = np.empty(n + 1); p = np.zeros(n + 1)
    q[0] = 0.0; v[0] = 0.0
    k = 0
    t0 = time.perf_counter()
    while sim.hasNextEvent() and k < n:
        fext[0] = f_step[k]
        ds.setFExtPtr(fext)
        sim.computeOneStep()
        k += 1
        q[k] = ds.q()[0]
        v[k] = ds.velocity()[0]
        p[k] = inter.lambda_(1)[0]
        sim.nextStep()
    wall = time.perf_counter() - t0
    if k != n:
        raise RuntimeError(f"stopped after {k} of {n} steps")

    # impacts: positive impulse over step k-1 -> k, approach faster than v_min before it
    hit = np.nonzero((p[1:] > 0) & (v[:-1] < -args.v_min))[0]
    dt = np.clip(q[hit] / -v[hit], 0.0, h)
    impacts = [{"t": float(t[i] + d), "v_before": float(v[i]), "v_after": float(v[i + 1]),
                "impulse": float(p[i + 1])} for i, d in zip(hit, dt)]

    # Poincare section at the cam angle, once per revolution
    u = q + s
    udot = v + sdot
    section = []
    for r in range(args.revolutions + 1):
        ts = (math.radians(args.section_deg) % (2 * math.pi) + 2 * math.pi * r) / omega
        if ts > t[-1] + 1e-12:
            break
        i = min(int(ts / h), n - 1)
        w = (ts - t[i]) / h
        section.append({"revolution": r, "t": ts, "u": float((1 - w) * u[i] + w * u[i + 1]),
                        "udot": float((1 - w) * udot[i] + w * udot[i + 1])})
    return {"h": h, "steps": n, "wall_s": wall, "impacts": impacts, "section": section,
            "min_gap_m": float(q.min()), "contact_steps": int(np.count_nonzero(p > 0))}


def selfcheck(args) -> None:
    """Below the detachment speed the follower must ride the cam: the contact impulse per step over
    h must match the contact force of the constrained mode, m s''(t) + k (s - 0.3) + m g."""
    import siconos.kernel as sk

    h = 1e-4
    law = LAWS[args.law]
    omega = args.speed_rpm * 2 * math.pi / 60
    n = int(round(2 * math.pi / omega / h))
    t = np.arange(n + 1) * h
    s, _, d2 = law(omega * t)
    force = -(MASS * omega**2 * d2 + STIFFNESS * (s - OFFSET)) - MASS * args.gravity
    ds, fext, inter, sim = _moreau_jean(sk, h, n, args.restitution)
    p = np.zeros(n + 1); q = np.zeros(n + 1)
    for k in range(n):
        fext[0] = 0.5 * (force[k] + force[k + 1])
        ds.setFExtPtr(fext)
        sim.computeOneStep()
        p[k + 1] = inter.lambda_(1)[0]; q[k + 1] = ds.q()[0]
        sim.nextStep()
    lam = -0.5 * (force[:-1] + force[1:])          # contact force the constrained mode needs
    # With e > 0 Moreau-Jean's impulse in persistent contact oscillates about the force (each step
    # reflects a fraction e of the last step's velocity), so compare means over 50-step windows.
    w = 50
    m = (n // w) * w
    mean_p = (p[1:m + 1] / h).reshape(-1, w).mean(axis=1)
    mean_l = lam[:m].reshape(-1, w).mean(axis=1)
    print(f"selfcheck {args.law} {args.speed_rpm} rev/min, h = {h}: contact force {lam.min():.3f} .. "
          f"{lam.max():.3f} N; over {w}-step windows max |mean impulse/h - mean force| = "
          f"{np.abs(mean_p - mean_l).max():.3e} N; single steps max {np.abs(p[1:] / h - lam).max():.3e} N; "
          f"max |q| = {np.abs(q).max():.2e} m")


def scan(args) -> None:
    """One run per speed at h = the first of --steps: is the section periodic (period <= 8, every
    coordinate repeating to --scan-tol in m and m/s over the last third of the revolutions), how many
    impacts per revolution there, the fastest approach."""
    h = args.steps[0]
    print(f"law {args.law}, h = {h:g} s, {args.revolutions} revolutions, section at {args.section_deg} deg, "
          f"last {args.revolutions // 3} revolutions, impacts faster than {args.v_min} m/s")
    print("| rev/min | period | impacts / rev | fastest approach (m/s) | section u range (m) |")
    print("|---|---|---|---|---|")
    for rpm in args.scan_rpm:
        args.speed_rpm = rpm
        r = run(h, args)
        w = args.revolutions // 3
        sec = np.array([(x["u"], x["udot"]) for x in r["section"]])[-w:]
        period = next((p for p in range(1, 9) if p < len(sec)
                       and np.max(np.abs(sec[p:] - sec[:-p])) < args.scan_tol), None)
        t_from = (args.revolutions - w) * 60.0 / rpm
        imp = [x for x in r["impacts"] if x["t"] >= t_from]
        fastest = max((abs(x["v_before"]) for x in imp), default=0.0)
        print(f"| {rpm:g} | {period or 'none <= 8'} | {len(imp) / w:g} | {fastest:.3g} | {np.ptp(sec[:, 0]):.2e} |",
              flush=True)


def compare(res: dict, ref: dict) -> dict:
    tr = np.array([i["t"] for i in ref["impacts"]])
    th = np.array([i["t"] for i in res["impacts"]])
    if tr.size and th.size:
        err = np.min(np.abs(tr[:, None] - th[None, :]), axis=1)
        imp = {"impact_t_err_max": float(err.max()), "impact_t_err_median": float(np.median(err)),
               "impact_t_err_p90": float(np.percentile(err, 90))}
    else:
        imp = {"impact_t_err_max": None, "impact_t_err_median": None, "impact_t_err_p90": None}
    m = min(len(res["section"]), len(ref["section"]))
    du = [abs(a["u"] - b["u"]) for a, b in zip(res["section"][:m], ref["section"][:m])]
    dv = [abs(a["udot"] - b["udot"]) for a, b in zip(res["section"][:m], ref["section"][:m])]
    return {**imp, "section_u_err_max": max(du) if du else None, "section_udot_err_max": max(dv) if dv else None}


def main() -> None:
    ap = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    ap.add_argument("--speed-rpm", type=float)
    ap.add_argument("--revolutions", type=int, default=20)
    ap.add_argument("--steps", type=float, nargs="+", default=[1e-3, 3e-4, 1e-4, 3e-5, 1e-5])
    ap.add_argument("--law", choices=sorted(LAWS), default="flat")
    ap.add_argument("--section-deg", type=float, default=130.0)
    ap.add_argument("--v-min", type=float, default=0.5, help="m/s")
    ap.add_argument("--restitution", type=float, default=0.8)
    ap.add_argument("--gravity", type=float, default=0.0, help="m/s^2 along -u (the example has none)")
    ap.add_argument("--out")
    ap.add_argument("--selfcheck", action="store_true",
                    help="compare the contact impulse with the constrained mode's force over one revolution")
    ap.add_argument("--scan-rpm", type=float, nargs="+",
                    help="instead of the table: one run per speed at the first --steps, periodic or not")
    ap.add_argument("--scan-tol", type=float, default=1e-3)
    args = ap.parse_args()
    if args.scan_rpm:
        scan(args)
        return
    if args.selfcheck:
        selfcheck(args)
        return
    if not args.out or args.speed_rpm is None:
        ap.error("--speed-rpm and --out are required")

    steps = sorted(args.steps, reverse=True)
    runs = [run(h, args) for h in steps]
    ref = runs[-1]
    rows = []
    for r in runs:
        r["vs_reference"] = compare(r, ref) if r is not ref else None
        rows.append(r)
    import siconos
    meta = {"speed_rpm": args.speed_rpm, "revolutions": args.revolutions, "law": args.law,
            "section_deg": args.section_deg, "v_min": args.v_min, "restitution": args.restitution,
            "gravity": args.gravity, "mass": MASS, "stiffness": STIFFNESS, "spring_free_u": OFFSET,
            "reference_h": ref["h"], "siconos": getattr(siconos, "__version__", "?"),
            "python": platform.python_version(), "loadavg": os.getloadavg(), "command": " ".join(sys.argv)}
    with open(args.out, "w") as fh:
        json.dump({"meta": meta, "runs": rows}, fh, separators=(",", ":"))

    print(f"law {args.law}, {args.speed_rpm} rev/min, {args.revolutions} revolutions, section at "
          f"{args.section_deg} deg, impacts faster than {args.v_min} m/s; reference h = {ref['h']:g} s")
    print("| h (s) | steps | wall (s) | impacts | impact-time diff median (s) | 90th pct (s) | max (s) | "
          "section u diff max (m) | section du/dt diff max (m/s) | deepest gap (m) |")
    print("|---|---|---|---|---|---|---|---|---|---|")
    f = lambda x: "—" if x is None else f"{x:.2e}"  # noqa: E731
    for r in rows:
        c = r["vs_reference"] or {}
        print(f"| {r['h']:g} | {r['steps']} | {r['wall_s']:.3f} | {len(r['impacts'])} | "
              f"{f(c.get('impact_t_err_median'))} | {f(c.get('impact_t_err_p90'))} | {f(c.get('impact_t_err_max'))} | "
              f"{f(c.get('section_u_err_max'))} | {f(c.get('section_udot_err_max'))} | {r['min_gap_m']:.2e} |")


if __name__ == "__main__":
    main()
