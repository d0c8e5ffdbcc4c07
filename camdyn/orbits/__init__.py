"""Periodic orbits and their stability: the stroboscopic map (section_map), its derivatives
(derivatives), shooting with Floquet multipliers (shooting), tangent dynamics (tangent),
Lyapunov exponents (lyapunov), continuation with bifurcations (continuation)."""
from __future__ import annotations

from .._lazy import lazy

#: public name -> the module (relative to this package) that defines it; loaded on first use
_EXPORTS = {
    'FiniteDifferences': '.derivatives',
    'JacobianProvider': '.section_map',
    'MapDerivative': '.section_map',
    'MapFailure': '.section_map',
    'MapValue': '.section_map',
    'NewtonResult': '.shooting',
    'OrbitOutcome': '.shooting',
    'PeriodicOrbit': '.shooting',
    'SHRINK': '.derivatives',
    'ShootingSettings': '.shooting',
    'StroboscopicMap': '.section_map',
    'Unresolved': '.derivatives',
    'derivative_at': '.section_map',
    'finite_difference_steps': '.derivatives',
    'finite_differences': '.derivatives',
    'newton': '.shooting',
    'newton_matrix': '.shooting',
    'periodic_orbit': '.shooting',
    'resolved_difference': '.derivatives',
    'sorted_multipliers': '.shooting',
    'step_floor': '.derivatives',
    'warm_start': '.shooting',
    'warm_up': '.section_map',
}

__getattr__, __dir__ = lazy(__name__, _EXPORTS)
__all__ = sorted(_EXPORTS)
