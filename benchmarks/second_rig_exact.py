"""An event-driven solution of the second rig (issue 28), exact between events, to check the peer.

    python benchmarks/second_rig_exact.py --law knife --speed-rpm 160 --revolutions 30 \\
        [--compare docs/data/siconos-knife-160rpm.json]

Plain NumPy (runs under the venv or /usr/bin/python3). The model is docs/second-rig.md's: in flight
the follower is a harmonic oscillator about u_eq = u0 - m g / k, so its motion is written in closed
form; the only numerical steps are locating events, each to about 1e-13 s by bisection:

- flight -> impact: the first zero of the gap u(t) - s(omega t), found by sampling the gap on a grid
  (``--scan`` s, or a twentieth of the expected flight when that is shorter) and bisecting the
  first sign change. An excursion below the cam shorter than the grid spacing is missed (a graze
  deeper than about a h^2 / 8, i.e. ~2e-10 m at the default 2e-6 s and a = 500 m/s^2).
- impact: Newton's law on the relative velocity with restitution e. When the relative approach
  speed falls below ``--v-stick`` (1e-6 m/s) the chattering sequence is taken as ended: the
  follower rides the cam from there (the accumulation point is not extrapolated: the remaining
  flights add up to about 2 v_stick / (a (1 - e)), ~1e-7 s for a ~ 100 m/s^2).
- contact -> flight: the first cam angle where the contact force m omega^2 s'' + k (s - u0) + m g
  reaches zero (bisection inside an arc; exactly at a junction where s'' jumps it negative).

With ``--compare`` it reads a JSON of benchmarks/siconos_cam_follower.py (same law, speed and
start: at rest on the base circle at theta = 0) and prints, per step h, the distance of each exact
impact faster than the JSON's v_min to the nearest impact of the run (median, 90th percentile,
max), i.e. the peer's error against this solution rather than against its smallest step.
"""
from __future__ import annotations

import argparse
import json
import math
import os
import sys

import numpy as np

sys.path.insert(0, os.path.dirname(os.path.abspath(__file__)))
from second_rig_cam import LAWS, OFFSET, RISE, TH_FN, TH_FN_KNIFE  # noqa: E402

MASS, STIFFNESS = 1.221, 1430.8


class Rig:
    def __init__(self, law: str, rpm: float, e: float = 0.8, g: float = 0.0):
        self.law = LAWS[law]
        self.omega = rpm * 2 * math.pi / 60
        self.e, self.g = e, g
        self.W = math.sqrt(STIFFNESS / MASS)
        self.u_eq = OFFSET - MASS * g / STIFFNESS
        fn = TH_FN if law == "flat" else TH_FN_KNIFE
        # junction angles in one revolution (theta from the start of the rise)
        self.junctions = np.sort(np.array([0.0, fn, RISE, math.pi - RISE, math.pi - fn, math.pi]))

    def cam(self, t):
        s, d1, d2 = self.law(self.omega * np.asarray(t, dtype=float))
        return s, self.omega * d1, self.omega**2 * d2

    def force(self, t):
        s, _, a = self.cam(t)
        return MASS * a + STIFFNESS * (s - OFFSET) + MASS * self.g

    def flight(self, t0, u0, v0, t):
        tau = np.asarray(t, dtype=float) - t0
        x0 = u0 - self.u_eq
        c, sn = np.cos(self.W * tau), np.sin(self.W * tau)
        return self.u_eq + x0 * c + v0 / self.W * sn, -x0 * self.W * sn + v0 * c


def _bisect(f, a, b, fa, tol=1e-13):
    while b - a > tol:
        m = 0.5 * (a + b)
        fm = f(m)
        if (fm < 0) == (fa < 0):
            a, fa = m, fm
        else:
            b = m
    return b


def solve(rig: Rig, t_end: float, scan: float = 2e-6, v_stick: float = 1e-6):
    """Impacts (t, relative approach velocity, relative rebound velocity) and a sampler u(t)."""
    impacts, pieces = [], []          # pieces: (t_start, kind, data)
    t, mode = 0.0, "contact"
    u, v = float(rig.cam(0.0)[0]), 0.0
    a_max = rig.omega**2 * 2.0 + rig.W**2 * 0.3          # bound on the relative acceleration
    while t < t_end:
        if mode == "contact":
            pieces.append((t, "contact", None))
            # first angle after t where the contact force is <= 0
            th0 = rig.omega * t
            grid = np.arange(th0, th0 + 2 * math.pi + 1e-3, 2e-4)
            rev = math.floor(th0 / (2 * math.pi))
            extra = np.concatenate([rig.junctions + 2 * math.pi * k for k in (rev, rev + 1)])
            extra = extra[(extra > th0) & (extra < grid[-1])]
            grid = np.unique(np.concatenate([grid, extra - 1e-12, extra + 1e-12]))
            tt = grid / rig.omega
            lam = rig.force(tt)
            bad = np.nonzero(lam[1:] <= 0)[0]
            if bad.size == 0:
                t = tt[-1]
                continue
            i = bad[0] + 1
            if abs(tt[i] - tt[i - 1]) < 1e-11:         # a junction: the force jumps below zero
                t_d = tt[i]
            else:
                t_d = _bisect(lambda x: float(rig.force(x)), tt[i - 1], tt[i], lam[i - 1])
            t = t_d
            s, sd, _ = rig.cam(t)
            u, v = float(s), float(sd)
            mode = "flight"
            continue
        # flight from (t, u, v)
        pieces.append((t, "flight", (t, u, v)))
        _, sd0, _ = rig.cam(t)
        rel = v - float(sd0)
        step = scan if rel <= 0 else min(scan, max(2 * rel / a_max / 20, 1e-12))
        t_a, found = t, None
        start = t + step
        while found is None and start < t_end:
            ts = start + step * np.arange(4000)
            uu, _ = rig.flight(t_a, u, v, ts)
            gap = uu - rig.cam(ts)[0]
            neg = np.nonzero(gap < 0)[0]
            if neg.size:
                j = neg[0]
                lo = ts[j - 1] if j > 0 else t_a
                glo = gap[j - 1] if j > 0 else 1.0
                found = _bisect(lambda x: float(rig.flight(t_a, u, v, x)[0] - rig.cam(x)[0]), lo, ts[j], glo)
            else:
                start = ts[-1] + step
                step = min(scan, step * 2)
        if found is None:
            t = t_end
            break
        t = found
        uu, vv = rig.flight(t_a, u, v, t)
        s, sd, _ = rig.cam(t)
        v_in = float(vv) - float(sd)
        if -v_in < v_stick and rig.force(t) > 0:
            mode = "contact"
            u, v = float(s), float(sd)
            continue
        v_out = -rig.e * v_in
        impacts.append((t, v_in, v_out))
        u, v = float(s), float(sd) + v_out
    return impacts, pieces


def sample(rig: Rig, pieces, ts):
    """(u, du/dt) at the times ts from the solution's pieces."""
    starts = np.array([p[0] for p in pieces])
    out_u, out_v = np.empty(len(ts)), np.empty(len(ts))
    for n, t in enumerate(ts):
        k = int(np.searchsorted(starts, t, side="right")) - 1
        _, kind, data = pieces[k]
        if kind == "contact":
            s, sd, _ = rig.cam(t)
            out_u[n], out_v[n] = s, sd
        else:
            uu, vv = rig.flight(*data, t)
            out_u[n], out_v[n] = uu, vv
    return out_u, out_v


def main() -> None:
    ap = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    ap.add_argument("--law", choices=sorted(LAWS), default="flat")
    ap.add_argument("--speed-rpm", type=float, required=True)
    ap.add_argument("--revolutions", type=int, default=30)
    ap.add_argument("--scan", type=float, default=2e-6)
    ap.add_argument("--v-stick", type=float, default=1e-6)
    ap.add_argument("--compare")
    args = ap.parse_args()
    rig = Rig(args.law, args.speed_rpm)
    period = 2 * math.pi / rig.omega
    impacts, pieces = solve(rig, args.revolutions * period, args.scan, args.v_stick)
    t_imp = np.array([i[0] for i in impacts])
    v_imp = np.array([i[1] for i in impacts])
    print(f"law {args.law}, {args.speed_rpm} rev/min, {args.revolutions} revolutions: {len(impacts)} impacts "
          f"(chattering ended below {args.v_stick} m/s), {np.count_nonzero(v_imp < -0.5)} faster than 0.5 m/s")
    last = t_imp >= (args.revolutions - 1) * period
    print("last revolution, impacts faster than 0.5 m/s (theta deg, relative approach m/s):",
          ", ".join(f"{360 * ((t / period) % 1):.2f} {v:.3f}" for t, v in zip(t_imp[last], v_imp[last]) if v < -0.5))
    if not args.compare:
        return
    data = json.load(open(args.compare))
    meta = data["meta"]
    assert meta["law"] == args.law and meta["speed_rpm"] == args.speed_rpm, "not the same run"
    ref = t_imp[v_imp < -meta["v_min"]]
    ref = ref[ref <= meta["revolutions"] * period]
    sec_t = [x["t"] for x in data["runs"][0]["section"]]
    su, sv = sample(rig, pieces, sec_t)
    print(f"against {args.compare}: {ref.size} exact impacts faster than {meta['v_min']} m/s; section at "
          f"{meta['section_deg']} deg, {len(sec_t)} revolutions")
    print("| h (s) | impacts | impact-time error median (s) | 90th pct (s) | max (s) | section u error max (m) | "
          "section du/dt error max (m/s) |")
    print("|---|---|---|---|---|---|---|")
    for r in data["runs"]:
        th = np.array([i["t"] for i in r["impacts"]])
        err = np.min(np.abs(ref[:, None] - th[None, :]), axis=1)
        du = max(abs(x["u"] - a) for x, a in zip(r["section"], su))
        dv = max(abs(x["udot"] - b) for x, b in zip(r["section"], sv))
        print(f"| {r['h']:g} | {th.size} | {np.median(err):.2e} | {np.percentile(err, 90):.2e} | {err.max():.2e} | "
              f"{du:.2e} | {dv:.2e} |")


if __name__ == "__main__":
    main()
