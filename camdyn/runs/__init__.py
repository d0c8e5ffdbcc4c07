"""Runs of the hybrid model: simulate and its Result (simulation, result), what a run is asked
for (request: Span, RunRequest), long runs in pieces (pieces), runs that stop once periodic
(stopping), the quasi-static contact orbit (quasistatic)."""
from __future__ import annotations

from .._lazy import lazy

#: public name -> the module (relative to this package) that defines it; loaded on first use
_EXPORTS = {
    'Outputs': '.result',
    'QuasiStaticOrbit': '.quasistatic',
    'QuasiStaticOutcome': '.quasistatic',
    'Result': '.result',
    'RunRequest': '.request',
    'SETTLE_BLOCKS': '.stopping',
    'Span': '.request',
    'StopWhenPeriodic': '.stopping',
    'Watch': '.stopping',
    'checked_model': '.simulation',
    'contact_mode': '.quasistatic',
    'extend': '.stopping',
    'orbit_at': '.quasistatic',
    'per_revolution': '.stopping',
    'quasi_static_orbit': '.quasistatic',
    'rigid_kinematics': '.quasistatic',
    'run': '.simulation',
    'run_request': '.request',
    'section_state': '.quasistatic',
    'settling': '.stopping',
    'simulate': '.simulation',
    'solve_at': '.quasistatic',
}

__getattr__, __dir__ = lazy(__name__, _EXPORTS)
__all__ = sorted(_EXPORTS)
