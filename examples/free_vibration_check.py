"""Free vibration of the example rig: FFT peak against the Jacobian's natural frequency,
and energy conservation of an undamped, frictionless run, at three tolerances.

    python examples/free_vibration_check.py

The cam is at rest; the follower starts 2e-7 rad off its static equilibrium (inside the
static deflection, so it stays in sliding contact), or, for the bouncing case, at
equilibrium with 0.5 rad/s towards the cam (it impacts and bounces, energy conserved).
"""
from __future__ import annotations

import numpy as np

import camdyn
from camdyn.analysis import statics as analysis, signal


def main() -> None:
    rig = camdyn.example_rig()
    scene = camdyn.Scene(damping="none", friction="none")
    eq = analysis.static_equilibrium(rig)
    nf = analysis.natural_frequency(rig, scene)
    print(f"Jacobian at equilibrium: {nf.Hz:.4f} Hz ({nf.damped_rad_s:.2f} rad/s)")
    push = 2e-7
    scale = 0.5 * eq.stiffness * push**2
    print("rtol     FFT peak (Hz)   |peak - Jacobian| (Hz)   FFT bin (Hz)   energy drift / E_osc   bouncing: impacts, drift / T0")
    for rtol in (1e-6, 1e-8, 1e-10):
        r = camdyn.simulate(rig, scene, speed_rpm=0, t_end=0.2, y0=(eq.alpha + push, 0.0),
                            sample_rate_Hz=50_000, rtol=rtol, atol=1e-16)
        f, amp = signal.spectrum(r.t, r.alpha)
        peak = signal.peak_frequency(f, amp)
        b = camdyn.simulate(rig, scene, speed_rpm=0, t_end=0.5, y0=(eq.alpha, -0.5), sample_rate_Hz=20_000,
                            rtol=rtol, atol=1e-14)
        T0 = 0.5 * rig.I_Pb * 0.5**2
        print(f"{rtol:.0e}  {peak:14.4f}   {abs(peak - nf.Hz):22.4f}   {signal.frequency_resolution(r.t):12.3f}"
              f"   {np.ptp(r.energy) / scale:20.3e}   {b.impacts().size:5d}, {np.ptp(b.energy) / T0:.3e}")


if __name__ == "__main__":
    main()
