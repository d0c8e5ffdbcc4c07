"""Analyses of a rig and of runs: statics (equilibrium, natural frequency, contact-loss speed),
calibration of unknown parameters (calibrate), the 0-1 test for chaos (chaos01), signal
processing of runs (signal)."""
from __future__ import annotations

from .._lazy import lazy

#: public name -> the module (relative to this package) that defines it; loaded on first use
_EXPORTS = {
    'NaturalFrequency': '.statics',
    'ResidualStats': '.statics',
    'alpha_spectrum': '.statics',
    'compliance_shift': '.statics',
    'contact_loss_angle': '.statics',
    'contact_loss_speed': '.statics',
    'energy_balance_peak': '.statics',
    'natural_frequency': '.statics',
    'residual_stats': '.statics',
    'rigid_contact_angle': '.statics',
    'sliding_mode': '.statics',
    'static_equilibrium': '.statics',
}

__getattr__, __dir__ = lazy(__name__, _EXPORTS)
__all__ = sorted(_EXPORTS)
