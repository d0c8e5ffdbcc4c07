"""Continuation over the bifurcation benchmark's range, timed, with its events and the grazing speed.

Run from the repository root:

    python benchmarks/continuation_scan.py [--l-lambda 0.016 0.0016]

For each line-contact length (0.016 m: the rig of benchmarks/performance.py's bifurcation sweep;
0.0016 m: the example preset), line contact, damping D, Coulomb friction, DOP853 at rtol 1e-10,
atol 1e-13: camdyn.continue_orbit in speed over 0.8-1.6 x the inverse-kinematics contact-loss
speed L, in two runs (the two period-1 branches the brute-force diagram shows):

* up from 0.8 L, section at T/2 (in permanent contact the section at t = 0 is where the contact is
  barely loaded): the permanent-contact branch to its grazing;
* down from 1.6 L, section at t = 0 (the diagram's): the impacting branch.

It prints the wall time of each (the compiled loop is loaded before the first timing), the
outcome, the events, and the grazing speed against L with the first-order compliance shift
(camdyn.analysis.statics.compliance_shift).
"""
from __future__ import annotations

import argparse
import time
import warnings

import camdyn
from camdyn.analysis.statics import compliance_shift
from camdyn.orbits.continuation import continue_orbit, events_table


def main(argv=None):
    ap = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    ap.add_argument("--l-lambda", type=float, nargs="+", default=[0.016, 0.0016], dest="l_lambda")
    args = ap.parse_args(argv)
    warnings.filterwarnings("ignore", category=camdyn.CompileNotice)
    scene = camdyn.Scene(contact="line", damping="D", friction="coulomb")
    camdyn.periodic_orbit(camdyn.example_rig(), scene, speed_rpm=1500.0)          # load the compiled loop
    for length in args.l_lambda:
        rig = camdyn.example_rig().replace(l_lambda=length)
        loss = camdyn.contact_loss_speed(rig)
        print(f"l_lambda {length} m: contact loss (inverse kinematics) L = {loss:.6f} rev/min")
        for start, end, phase in ((0.8, 1.6, 0.5), (1.6, 0.8, 0.0)):
            t0 = time.perf_counter()
            ds = continue_orbit(rig, scene, "speed_rpm", start * loss, end * loss, phase_fraction=phase)
            seconds = time.perf_counter() - t0
            print(f"  {start} L -> {end} L, phase {phase} T: {seconds:.1f} s, {ds.sizes['point']} orbits, "
                  f"{ds.sizes['branch']} branch(es)")
            for i in range(ds.sizes["branch"]):
                print(f"    branch {i}: {ds.attrs[f'branch_{i}_message']}")
            for kind, lam, branch, point in events_table(ds):
                print(f"    {kind} at {lam:.6f} rev/min (branch {branch}, after point {point})")
                if kind == "grazing":
                    shift = compliance_shift(rig, scene)
                    print(f"      (grazing - L) / L = {(lam - loss) / loss:.3e}; first-order compliance shift "
                          f"{shift:.3e}: L (1 + shift) = {loss * (1 + shift):.6f} rev/min")


if __name__ == "__main__":
    main()
